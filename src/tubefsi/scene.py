r"""The scene: resolved models, the tube and the boundary state; and what a coupler returns.

A :class:`Scene` is everything a coupler needs except the load: the rheology, the wall,
the tube and the outlet pressure, plus the outlet state derived from them once. The wall
responds to the transmural pressure: with an external pressure :math:`p_e` the scene's
``outlet_pressure`` is the transmural :math:`p(L) - p_e`, which is all a coupler sees (the
fluid does not feel a uniform offset), and ``gauge_outlet_pressure`` keeps the fluid's own. Build one
with :func:`make_scene`, which accepts registered names, classes or instances and
validates every argument. A coupler returns a :class:`State`: arrays of one shape.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import attrs
import numpy as np

from ._validation import as_array
from .errors import BucklingError, InvalidParameterError, NoSteadyStateError
from .geometry import Tube
from .registry import rheologies as _rheologies
from .registry import walls as _walls
from .rheology.flow_map import kind as flow_map_kind
from .rheology.base import Rheology
from .walls.base import WallModel
from .walls.hyperelastic import InstalledTube
from .fields import _array_fields, _replace, at_position, model_at, parameter_shape, varies
from .profiles import Profile

__all__ = ["Scene", "State", "Points", "make_scene", "resolve"]


class State(NamedTuple):
    r"""What a coupler returns: four numbers or four arrays of one shape (the loads' shape).

    Attributes
    ----------
    flow_rate : ndarray
        Flow rate q (m^3/s).
    pressure_drop : ndarray
        Pressure drop p(0) - p(L) (Pa).
    inlet_strain : ndarray
        Hoop strain at the inlet, R(0)/a - 1, never formed by subtraction.
    log_stretch : ndarray
        :math:`v = \ln(\lambda_{in}/\lambda_{out})`, the inlet log-stretch relative to the outlet.
    """

    flow_rate: np.ndarray
    pressure_drop: np.ndarray
    inlet_strain: np.ndarray
    log_stretch: np.ndarray

    def arrays(self, n: int) -> dict:
        """Every field as a float array of ``n`` entries (broadcast, not copied), by name."""
        return {name: np.broadcast_to(np.asarray(value, dtype=float), (n,)) for name, value in zip(self._fields, self)}

    def first(self) -> State:
        """The state of the first (for one point: the only) entry of its arrays, as floats."""
        return State(*(float(np.ravel(value)[0]) for value in self))

    def take(self, index) -> State:
        """The state at the entries ``index`` of its (flat) arrays."""
        n = np.size(self.flow_rate)
        return State(**{name: value[index] for name, value in self.arrays(n).items()})


_FLOATS, _ARRAYS, _ALONG_Z = 0, 1, 2


def _kind(*models) -> int:
    """``_FLOATS`` where every parameter of ``models`` that may be an array is a float, ``_ALONG_Z``
    where one is a function of z (a :class:`~tubefsi.Profile`), else ``_ARRAYS``."""
    kind = _FLOATS
    for model in models:
        for name in _array_fields(type(model)):
            value = getattr(model, name)
            if type(value) is not float:
                if isinstance(value, Profile):
                    return _ALONG_Z
                kind = _ARRAYS
    return kind


def _value_eq(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and bool(np.all(a == b))


@attrs.define(kw_only=True)
class Scene:
    r"""A rheology, a wall, a tube and an outlet pressure: everything but the load.

    ``outlet_pressure`` is the *transmural* pressure at the outlet, :math:`p(L) - p_e` (what the
    wall sees and the couplers use); ``external_pressure`` is :math:`p_e` and
    ``gauge_outlet_pressure`` the fluid's outlet pressure :math:`p(L)` (by default
    ``outlet_pressure + external_pressure``; :func:`make_scene` passes the exact value).

    Build it with :func:`make_scene` (which validates); treat it as read-only (couplers, solutions
    and threads share it; it is not frozen only so that the commonest scene, one per scalar solve,
    is cheap to build). Every model parameter, every tube field
    and the outlet pressure may be an array: the scene's :attr:`shape` is their broadcast shape,
    and the loads of a solve broadcast against it. :meth:`flat` broadcasts everything to a shape
    and flattens it (what couplers work on: one entry per point), :meth:`take` selects points of a
    flat scene, and :meth:`at` gathers the per-point quantities of some points for an integrand.
    The outlet state is derived once:

    Attributes
    ----------
    shape : tuple
        The broadcast shape of the scene's array parameters (``()`` when all are scalars).
    graded : bool
        Whether the tube or the wall varies along z (``docs/graded.md``).
    outlet_strain, outlet_stretch : float or ndarray
        The hoop strain and stretch at the outlet, under ``outlet_pressure``.
    log_stretch_max : float or ndarray
        :math:`\ln(\lambda_{max}/\lambda_{out})`, the largest log-stretch the wall admits
        (``inf`` unless it locks or its tube law peaks).
    """

    rheology: Rheology
    wall: WallModel
    tube: Tube
    outlet_pressure: float = attrs.field(default=0.0, eq=attrs.cmp_using(eq=_value_eq), hash=False)
    external_pressure: float = attrs.field(default=0.0, eq=attrs.cmp_using(eq=_value_eq), hash=False)
    gauge_outlet_pressure: float = attrs.field(default=None, eq=False, hash=False)

    shape: tuple = attrs.field(init=False, eq=False)
    graded: bool = attrs.field(init=False, eq=False)
    outlet_strain: float = attrs.field(init=False, eq=False, hash=False)
    outlet_stretch: float = attrs.field(init=False, eq=False, hash=False)
    log_stretch_max: float = attrs.field(init=False, eq=False, hash=False)

    def __attrs_post_init__(self):
        p_out, p_e = self.outlet_pressure, self.external_pressure
        if self.gauge_outlet_pressure is None:
            if type(p_out) is float and type(p_e) is float:
                gauge = p_out + p_e
            else:
                gauge = np.add(p_out, p_e)
                gauge = float(gauge) if np.ndim(gauge) == 0 else gauge
            self.gauge_outlet_pressure = gauge
        shapes = [parameter_shape(self.rheology), parameter_shape(self.wall), parameter_shape(self.tube)]
        shapes += [np.shape(v) for v in (p_out, p_e, self.gauge_outlet_pressure) if type(v) is not float]
        self.shape = np.broadcast_shapes(*shapes) if any(shapes) else ()
        self.graded = self.tube.graded or varies(self.wall)
        if self.graded:                     # the outlet state of the tube law at z = L
            wall, tb = self.at_outlet()
            strain = wall.strain(p_out, tb) if np.any(np.asarray(p_out) != 0) else 0.0
            lam_max = math.inf
        else:                               # the outlet state, once: every J evaluation needs it
            strain = self._outlet_strain()
            lam_max = self._max_stretch()
        self.outlet_strain = strain
        self.outlet_stretch = 1.0 + strain
        if type(lam_max) is float and type(strain) is float:
            v_max = math.log(lam_max / (1.0 + strain)) if lam_max < math.inf else math.inf
        else:
            with np.errstate(divide="ignore"):
                v_max = np.log(np.asarray(lam_max, dtype=float) / (1.0 + np.asarray(strain)))
            v_max = float(v_max) if v_max.ndim == 0 else v_max
        self.log_stretch_max = v_max

    def _outlet_strain(self):
        """The hoop strain under the (transmural) outlet pressure: 0 where it is 0."""
        p_out, tb = self.outlet_pressure, self.tb
        if np.ndim(p_out) == 0 and p_out == 0:
            return 0.0
        if self.shape == ():
            return float(self.wall._strain(np.asarray(p_out), tb))
        return np.where(np.asarray(p_out) == 0, 0.0, self.wall.strain(p_out, tb))

    def _max_stretch(self):
        """The wall's maximum stretch at every point: the hook first (a wall that never locks says
        inf whatever its parameters), else the per-point, validated evaluation."""
        tb = self.tb
        try:
            lam_max = self.wall._max_stretch(tb)
        except Exception:                    # noqa: BLE001 (the evaluation below raises what is real)
            lam_max = None
        if self.shape == () and lam_max is not None or type(lam_max) is float and lam_max == math.inf:
            return lam_max
        return self.wall.max_stretch(tb)

    @classmethod
    def unloaded(cls, rheology, wall, tube) -> Scene:
        """The scene of validated models whose parameters are all floats, in a uniform tube of float
        fields, with an unloaded outlet: the commonest scene, whose derived fields need no
        broadcasting (what ``__attrs_post_init__`` derives, directly)."""
        scene = object.__new__(cls)
        lam_max = wall._max_stretch(tube.thickness / tube.radius)
        scene.rheology = rheology
        scene.wall = wall
        scene.tube = tube
        scene.outlet_pressure = 0.0
        scene.external_pressure = 0.0
        scene.gauge_outlet_pressure = 0.0
        scene.shape = ()
        scene.graded = False
        scene.outlet_strain = 0.0
        scene.outlet_stretch = 1.0
        scene.log_stretch_max = math.log(lam_max) if lam_max < math.inf else math.inf
        return scene

    @property
    def tb(self):
        """The reduced thickness t/a of the tube (a :class:`~tubefsi.Profile` for a graded tube)."""
        return self.tube.reduced_thickness

    def at_position(self, z, index=None):
        """``(wall, radius, tb)`` at the positions ``z`` (aligned with the flat points ``index`` if
        given): the wall with its profiles evaluated there, a(z) and t(z)/a(z)."""
        a, t = self.tube.at(z)
        if index is not None:
            a = a if isinstance(self.tube.radius, Profile) or np.ndim(a) == 0 else a[index]
            t = t if isinstance(self.tube.thickness, Profile) or np.ndim(t) == 0 else t[index]
        return at_position(self.wall, z, index), a, t / a

    def at_outlet(self):
        """``(wall, tb)`` at z = L: the tube law at the outlet."""
        L = np.asarray(self.tube.length, dtype=float)
        wall, _, tb = self.at_position(L)
        return _scalars(wall), (float(tb) if np.ndim(tb) == 0 else tb)

    def uniform_at(self, z) -> Scene:
        """The uniform scene of the tube's section at the position ``z`` (a float, m): every profile
        evaluated there (the validity checks of a graded solve use the inlet's, z = 0)."""
        wall, a, tb = self.at_position(np.asarray(float(z)))
        wall = _scalars(wall)
        a = float(a) if np.ndim(a) == 0 else a
        t = a * (float(tb) if np.ndim(tb) == 0 else tb)
        tube = attrs.evolve(self.tube, radius=a, thickness=t) if type(self.tube) is not Tube else \
            Tube(radius=a, thickness=t, length=self.tube.length)
        return Scene(rheology=self.rheology, wall=wall, tube=tube, outlet_pressure=self.outlet_pressure,
                     external_pressure=self.external_pressure, gauge_outlet_pressure=self.gauge_outlet_pressure)

    @property
    def size(self) -> int:
        """The number of points of the scene (1 when all its parameters are scalars)."""
        return math.prod(self.shape)           # a tuple of ints: no NumPy call (asked several times a solve)

    def flat(self, shape) -> Scene:
        """This scene broadcast to ``shape`` and flattened: every array quantity becomes a 1-D
        array with one entry per point of ``shape`` (scalars stay scalars). A shape of one point
        gives a scene of scalars (arrays of one entry, of any dimensions: the couplers' route of
        one point takes floats)."""
        if self.shape == () or (len(self.shape) == 1 and tuple(shape) == self.shape and self.size > 1):
            return self
        if math.prod(shape) == 1:
            return _evolve_arrays(self, lambda v: float(np.ravel(v)[0]))
        return _evolve_arrays(self, lambda v: np.broadcast_to(v, shape).ravel())

    def take(self, index) -> Scene:
        """The points ``index`` of a flat scene (a scene whose arrays are 1-D)."""
        if self.shape == ():
            return self
        return _evolve_arrays(self, lambda v: v[index])

    def point(self, i: int) -> Scene:
        """Point ``i`` of a flat scene as a scene of scalars."""
        if self.shape == ():
            return self
        return _evolve_arrays(self, lambda v: float(v[i]))

    def split(self, todo):
        """``[(index, scene), ...]``: the points ``todo`` of a flat scene with, for each part, the
        flat scene of those points. A model that needs it — a rheology of the generic
        (non-separable) path, whose flow table is built per parameter set, or a model whose hooks
        do not broadcast (``broadcasts = False``) — has one parameter set per part, as scalars."""
        todo = np.asarray(todo)
        if self.size == 1 or todo.size == 0:
            return [(todo, self)]
        grouped = self._grouped()
        if not grouped:
            # (every point in order, the common case: the scene itself, not a gathered copy of it)
            return [(todo, self if _every_point(todo, self.size) else self.take(todo))]
        keys = [np.broadcast_to(v, (self.size,))[todo] for m in grouped for v in _array_values(m).values()]
        _, inverse = np.unique(np.stack(keys, axis=1), axis=0, return_inverse=True)
        inverse = inverse.ravel()
        order = np.argsort(inverse, kind="stable")
        bounds = np.searchsorted(inverse[order], np.arange(int(inverse.max()) + 2))
        parts = []
        for j in range(len(bounds) - 1):
            index = todo[order[bounds[j]:bounds[j + 1]]]
            part = self.take(index)
            for name in ("rheology", "wall"):
                if any(getattr(self, name) is m for m in grouped):
                    model = getattr(part, name)
                    scalar = _replace(model, {k: float(v[0]) for k, v in _array_values(model).items()})
                    setattr(part, name, scalar)
            parts.append((index, _refresh(part)))
        return parts

    def is_one_part(self) -> bool:
        """Whether :meth:`split` keeps every point in one part (no model needs one parameter set
        per part)."""
        return self.size == 1 or not self._grouped()

    def _grouped(self):
        """The models whose array parameters must be split into parameter sets: a non-separable
        rheology (its flow table is per fluid) or a model whose hooks do not broadcast."""
        grouped = []
        for model in (self.rheology, self.wall):
            broadcasts = getattr(type(model), "broadcasts", True)
            if model is self.rheology:       # (a law that a flow map serves needs no table per fluid)
                broadcasts = broadcasts and (model.separable or flow_map_kind(model) is not None)
            if not broadcasts and _array_values(model):
                grouped.append(model)
        return grouped

    def at(self, index, *, column=False) -> Points:
        """The per-point quantities of a flat scene at ``index``, as columns (shape ``(n, 1)``, to
        broadcast against ``(n, nodes)`` arrays) if ``column``."""
        return Points(self, index, column)


def _evolve_arrays(scene, transform):
    """The scene with ``transform`` applied to every array it holds (models, tube, outlet state)."""
    def models(m):
        arrays = {n: transform(v) for n, v in _array_values(m).items()}
        return _replace(m, arrays) if arrays else m

    new = object.__new__(Scene)
    for name, value in (("rheology", models(scene.rheology)), ("wall", models(scene.wall)),
                        ("tube", models(scene.tube))):
        setattr(new, name, value)
    for name in ("outlet_pressure", "external_pressure", "gauge_outlet_pressure", "outlet_strain", "outlet_stretch",
                 "log_stretch_max"):
        value = getattr(scene, name)
        setattr(new, name, transform(np.asarray(value)) if np.ndim(value) else value)
    probe = transform(np.zeros(scene.shape)) if scene.shape else None
    new.shape = np.shape(probe) if probe is not None else ()
    new.graded = scene.graded
    return new


def _refresh(scene):
    """A scene whose derived shape is recomputed after a model was made scalar in place."""
    shape = np.broadcast_shapes(parameter_shape(scene.rheology), parameter_shape(scene.wall),
                                parameter_shape(scene.tube), np.shape(scene.outlet_pressure),
                                np.shape(scene.external_pressure), np.shape(scene.gauge_outlet_pressure),
                                np.shape(scene.outlet_strain), np.shape(scene.log_stretch_max))
    scene.shape = shape
    return scene


def _scalars(model):
    """``model`` with its 0-d array parameters as floats."""
    values = {n: float(v) for n in _array_fields(type(model))
              if isinstance(v := getattr(model, n), np.ndarray) and v.ndim == 0}
    return _replace(model, values) if values else model


def _array_values(model) -> dict:
    return {n: v for n in _array_fields(type(model)) if isinstance(v := getattr(model, n), np.ndarray)}


class Points:
    """The per-point quantities of some points of a flat scene (see :meth:`Scene.at`)."""

    __slots__ = ("wall", "rheology", "radius", "length", "tb", "outlet_stretch", "outlet_strain",
                 "outlet_pressure", "log_stretch_max")

    def __init__(self, scene, index, column):
        if scene.shape == ():                 # every quantity shared: nothing to gather (a curve)
            self.wall, self.rheology = scene.wall, scene.rheology
            self.radius, self.length, self.tb = scene.tube.radius, scene.tube.length, scene.tb
            self.outlet_stretch, self.outlet_strain = scene.outlet_stretch, scene.outlet_strain
            self.outlet_pressure, self.log_stretch_max = scene.outlet_pressure, scene.log_stretch_max
            return

        if _every_point(index, scene.size):
            # the identity (a whole flat scene, the common case): read-only views, not copies
            def pick(value):
                if np.ndim(value) == 0:
                    return value
                return _read_only(value[:, None] if column else value[:])

            self.wall, self.rheology = _viewed(scene.wall, column), _viewed(scene.rheology, column)
        else:
            def pick(value):
                if np.ndim(value) == 0:
                    return value
                v = value[index]
                return v[:, None] if column else v

            self.wall = model_at(scene.wall, index, column=column)
            self.rheology = model_at(scene.rheology, index, column=column)
        self.radius = pick(scene.tube.radius)
        self.length = pick(scene.tube.length)
        self.tb = pick(scene.tb)
        self.outlet_stretch = pick(scene.outlet_stretch)
        self.outlet_strain = pick(scene.outlet_strain)
        self.outlet_pressure = pick(scene.outlet_pressure)
        self.log_stretch_max = pick(scene.log_stretch_max)


def _every_point(index, n) -> bool:
    """Whether ``index`` is ``0, 1, ..., n - 1`` (one comparison pass instead of a gather per
    quantity: a flat scene's points are most often asked for all at once)."""
    return (type(index) is np.ndarray and index.ndim == 1 and index.size == n and n > 1
            and index.dtype.kind in "iu" and index[0] == 0 and index[-1] == n - 1
            and bool(np.all(index[1:] > index[:-1])))     # n increasing integers from 0 to n - 1


def _read_only(view):
    view.flags.writeable = False          # a view of the scene's own array: never written through
    return view


def _viewed(model, column):
    """``model_at(model, every point)``: its array parameters as read-only views (columns if ``column``)."""
    arrays = {name: _read_only(v[:, None] if column else v[:]) for name in _array_fields(type(model))
              if isinstance(v := getattr(model, name), np.ndarray)}
    return _replace(model, arrays) if arrays else model


def resolve(kind: str, value):
    """A model instance from a registered name, a class (built with its defaults) or an instance.

    ``kind`` is ``"rheology"`` or ``"wall"``; anything else raises
    :class:`~tubefsi.InvalidParameterError` naming ``kind``.
    """
    base, registry = (Rheology, _rheologies) if kind == "rheology" else (WallModel, _walls)
    return _resolve(kind, value, base, registry)


def _resolve(kind, value, base, registry):
    if isinstance(value, str):
        try:
            value = registry[value]
        except KeyError as exc:
            close = registry.closest(value)
            raise InvalidParameterError(kind, "{" + ", ".join(registry) + "}", value,
                                        f"did you mean {close!r}?" if close else "") from exc
    if isinstance(value, type) and issubclass(value, base):
        try:
            value = value()
        except TypeError as exc:
            raise InvalidParameterError(kind, f"an instance of {base.__name__}", value,
                                        f"{value.__name__} needs parameters: {exc}") from None
    if not isinstance(value, base):
        raise InvalidParameterError(kind, f"an instance of {base.__name__} or a registered name", value)
    return value


def make_scene(rheology, wall, tube, *, outlet_pressure=0.0, external_pressure=0.0) -> Scene:
    """Resolve and validate the models, the tube and the outlet and external pressures into a
    :class:`Scene` (whose ``outlet_pressure`` is the transmural one, ``outlet_pressure -
    external_pressure``).

    Raises
    ------
    InvalidParameterError
        For an unknown name, a wrong type, an outlet pressure outside ``[0, inf)``, a non-finite
        external pressure, or a negative transmural outlet pressure on a wall that only inflates.
    NoSteadyStateError
        If the transmural outlet pressure already reaches the wall's limit pressure.
    BucklingError
        If it is below the wall's minimum pressure (minus its buckling pressure).
    """
    if not isinstance(rheology, Rheology):
        rheology = resolve("rheology", rheology)
    if not isinstance(wall, WallModel):
        wall = resolve("wall", wall)
    if not isinstance(tube, Tube):
        raise InvalidParameterError("tube", "a tubefsi.Tube", tube)
    kind = _kind(rheology, wall, tube)
    if kind == _ALONG_Z:
        if _kind(rheology) == _ALONG_Z:
            name = next(n for n in _array_fields(type(rheology)) if isinstance(getattr(rheology, n), Profile))
            raise InvalidParameterError(name, "a number or an array (a fluid's parameters do not vary along "
                                        "the tube)", getattr(rheology, name))
        return _graded_scene(rheology, wall, tube, outlet_pressure, external_pressure)
    installed = tube
    tube = wall._installed_tube(tube)        # an axial pre-stretch installs the tube longer and narrower
    if (type(outlet_pressure) is float and outlet_pressure == 0.0 and type(external_pressure) is float
            and external_pressure == 0.0):   # the common case: an unloaded outlet is below every limit
        if kind == _FLOATS and (tube is installed or _kind(tube) == _FLOATS):
            return Scene.unloaded(rheology, wall, tube)
        return Scene(rheology=rheology, wall=wall, tube=tube, outlet_pressure=0.0)
    p_out, p_e, gauge = _outlet(wall, tube.reduced_thickness, outlet_pressure, external_pressure)
    if np.ndim(p_e) == 0 and p_e == 0:
        return Scene(rheology=rheology, wall=wall, tube=tube, outlet_pressure=p_out)
    return Scene(rheology=rheology, wall=wall, tube=tube, outlet_pressure=p_out, external_pressure=p_e,
                 gauge_outlet_pressure=gauge)


def _outlet(wall, tb, outlet_pressure, external_pressure):
    """``(transmural outlet pressure, external pressure, gauge outlet pressure)``, validated: the
    outlet below the wall's limit pressure and above its minimum (buckling) pressure."""
    p_out = as_array("outlet_pressure", outlet_pressure, "[0, inf)", lambda a: a >= 0)
    p_out = float(p_out) if p_out.ndim == 0 else p_out
    p_e = as_array("external_pressure", external_pressure, "the real numbers", lambda a: a == a)
    p_e = float(p_e) if p_e.ndim == 0 else p_e
    gauge = p_out
    if np.any(p_e != 0):
        p_out = _transmural(wall, tb, p_out, p_e)
    lim = wall.limit_pressure(tb)
    beyond = np.asarray(p_out >= lim)
    if np.any(beyond):
        i = np.unravel_index(int(np.argmax(beyond.ravel())), beyond.shape) if beyond.ndim else ()
        raise NoSteadyStateError("pressure", float(np.broadcast_to(lim, beyond.shape)[i]),
                                 float(np.broadcast_to(p_out, beyond.shape)[i]),
                                 "the outlet pressure already reaches it", name="the outlet pressure")
    return p_out, p_e, gauge


#: Positions (fractions of L) where a graded scene's profiles are validated when it is made.
_CHECK_NODES = np.linspace(0.0, 1.0, 65)


def _graded_scene(rheology, wall, tube, outlet_pressure, external_pressure):
    """:func:`make_scene` for a tube or wall that varies along z: installed at the axial stretch
    (positions and radii rescaled), validated at 65 positions and the breakpoints (every later
    evaluation validates itself), the outlet checked with the tube law at z = L."""
    tube, wall = _install_graded(tube, wall)
    length = np.asarray(tube.length, dtype=float)
    _check_along(tube, wall, length)
    p_out = as_array("outlet_pressure", outlet_pressure, "[0, inf)", lambda a: a >= 0)
    p_out = float(p_out) if p_out.ndim == 0 else p_out
    p_e = as_array("external_pressure", external_pressure, "the real numbers", lambda a: a == a)
    p_e = float(p_e) if p_e.ndim == 0 else p_e
    outlet_wall, _, tb_out = _at(tube, wall, length)
    outlet_wall = _scalars(outlet_wall)
    gauge = p_out
    if np.any(p_e != 0):
        p_out = _transmural(outlet_wall, tb_out, p_out, p_e)
    lim = outlet_wall.limit_pressure(tb_out)
    if np.any(np.asarray(p_out >= lim)):
        raise NoSteadyStateError("pressure", float(np.min(lim)), float(np.max(p_out)),
                                 "the outlet pressure already reaches it", name="the outlet pressure")
    return Scene(rheology=rheology, wall=wall, tube=tube, outlet_pressure=p_out, external_pressure=p_e,
                 gauge_outlet_pressure=gauge)


def _install_graded(tube, wall):
    """A graded tube and wall as installed at the wall's axial stretch (positions stretched, radii
    and thickness over its square root)."""
    lz = getattr(wall, "axial_stretch", 1.0)
    if np.ndim(lz) != 0:
        raise InvalidParameterError("axial_stretch", "a number for a tube or wall that varies along z", lz)
    if lz == 1.0:
        return tube, wall
    if not getattr(wall, "_homogeneous_rest", lambda: True)():
        raise InvalidParameterError("axial_stretch", "1 for a pre-stretched fibre wall on a tube or wall that varies "
                                    "along z", lz, "its installed rest state depends on the local geometry")
    shrink = 1.0 / math.sqrt(lz)
    fields = {n: (v.scaled(shrink, 1.0 / lz) if isinstance(v, Profile) else v * shrink)
              for n in ("radius", "thickness") for v in [getattr(tube, n)]}
    tube = InstalledTube(**fields, length=tube.length * lz, axial_stretch=lz)
    wall = _replace(wall, {n: v.scaled(1.0, 1.0 / lz) for n in _array_fields(type(wall))
                           if isinstance(v := getattr(wall, n), Profile)})
    return tube, wall


def _profiles_of(model):
    return {n: v for n in _array_fields(type(model)) if isinstance(v := getattr(model, n), Profile)}


def _check_along(tube, wall, length):
    """Validate a graded tube and wall at 65 positions and every breakpoint: t/a finite and
    positive, the wall's validators and cross-checks at each position."""
    top = float(np.max(length))
    for model in (tube, wall):
        for profile in _profiles_of(model).values():
            profile.check_span(top)
    breaks = [b for m in (tube, wall) for v in _profiles_of(m).values() for b in v.breakpoints if 0 < b < top]
    z = np.concatenate([top * _CHECK_NODES, breaks]).reshape((-1,) + (1,) * max(
        len(parameter_shape(wall)), np.ndim(length)))
    a, t = tube.at(z)
    tb = np.asarray(t / a)
    if not np.all(np.isfinite(tb) & (tb > 0)):
        raise InvalidParameterError("thickness", "values with a finite, nonzero t/a along the tube",
                                    tube.thickness)
    profiles = _profiles_of(wall)
    if profiles:
        checked = {n: v(z) for n, v in profiles.items()}
        attrs.evolve(_replace(wall, profiles), **checked)   # validators, cross-checks


def _at(tube, wall, z):
    a, t = tube.at(z)
    return at_position(wall, z), a, (float(t / a) if np.ndim(t / a) == 0 else t / a)


def _transmural(wall, tb, p_out, p_e):
    """The transmural outlet pressure ``p_out - p_e``, checked against the wall's minimum pressure
    (the outlet has the lowest pressure of the tube: only there can it buckle)."""
    transmural = np.subtract(p_out, p_e)
    transmural = float(transmural) if np.ndim(transmural) == 0 else transmural
    negative = np.asarray(transmural < 0)
    if not np.any(negative):
        return transmural
    low = np.asarray(wall.min_pressure(tb), dtype=float)
    shape = np.broadcast_shapes(negative.shape, low.shape)
    low, values = np.broadcast_to(low, shape), np.broadcast_to(transmural, shape)
    inflating = (values < 0) & (low == 0)
    if np.any(inflating):
        i = np.unravel_index(int(np.argmax(inflating.ravel())), shape) if shape else ()
        raise InvalidParameterError("external_pressure", "(-inf, outlet_pressure]",
                                    float(np.broadcast_to(p_e, shape)[i]),
                                    f"{type(wall).__name__} holds no negative transmural pressure")
    below = values < low
    if np.any(below):
        i = np.unravel_index(int(np.argmax(below.ravel())), shape) if shape else ()
        raise BucklingError(float(low[i]), float(values[i]),
                            "the transmural outlet pressure, outlet_pressure - external_pressure, is below it")
    return transmural
