r"""The entry points: :func:`solve`, :func:`max_flow_rate`, :func:`select_coupler` and :class:`Problem`.

Every call takes one path: validate the arguments, build the :class:`~tubefsi.scene.Scene`
(:func:`~tubefsi.scene.make_scene`), pick the coupler (``"auto"``: the cheapest registered one
that supports the pair and meets the accuracy contract, or the user's), run it (wrapped in
:class:`~tubefsi.couplers.Checked` when it checks itself) on chunks of at most ``CHUNK`` points,
check the result against the model's assumptions and return a :class:`~tubefsi.Solution`.
Nothing here computes physics. A :class:`Problem` is the first two steps done once, for a
script that solves the same scene again and again.
"""

from __future__ import annotations

import math

import attrs
import numpy as np
from numpy.typing import ArrayLike

from . import registry
from .registry import PluginWarning
from ._keywords import Function, checked_keywords
from ._progress import bar
from ._validation import as_load
from .couplers.base import Coupler
from .couplers.checked import checked
from .couplers.graded import Graded
from .couplers.rescaled import Rescaled, in_units
from .errors import InvalidParameterError, NoSteadyStateError, warn_user
from .geometry import Tube
from .rheology.base import Rheology
from .rheology.power_law import FactorRangeError
from .scene import Scene, State, _resolve, make_scene, resolve
from .solution import Solution, max_flow_rate_of
from .validity import check_and_warn
from .walls.base import WallModel

__all__ = ["solve", "max_flow_rate", "select_coupler", "Problem", "CHUNK"]

#: Points per coupler call: bounds the working memory (a few tens of MB) of any sweep.
CHUNK = 1 << 14
_STATE_FIELDS = State._fields


def _ranked(couplers):
    """The registered couplers that meet the accuracy contract, one instance each, cheapest first
    (a plugin coupler that cannot be built with its defaults is left out, with a PluginWarning)."""
    ranked = sorted((couplers[name].cost_rank, name) for name in couplers if couplers[name].meets_accuracy_contract)
    out = []
    for _, name in ranked:
        try:
            out.append((couplers[name](), name))
        except Exception as exc:          # noqa: BLE001 (a plugin's failure, whatever it is, is its own)
            warn_user(f"coupler {name!r} is left out of 'auto': building it raised {type(exc).__name__}: {exc}",
                      PluginWarning)
    return tuple(out)


def _supports(instance, name, rheology, wall) -> bool:
    """Whether ``auto``'s candidate supports the pair; a plugin coupler whose ``supports`` raises
    does not (with a PluginWarning)."""
    try:
        return bool(instance.supports(rheology, wall))
    except Exception as exc:              # noqa: BLE001
        warn_user(f"coupler {name!r} is passed over by 'auto': its supports() raised {type(exc).__name__}: {exc}",
                  PluginWarning)
        return False


@checked_keywords
def select_coupler(rheology: Rheology | type[Rheology] | str, wall: WallModel | type[WallModel] | str,
                   coupler: str | Coupler | type[Coupler] = "auto") -> Coupler:
    """The coupler ``solve`` would use for ``rheology`` and ``wall`` (instances, classes or
    registered names, as ``solve`` takes them): a name, an instance, or ``"auto"`` (cheapest
    accurate)."""
    return _select(resolve("rheology", rheology), resolve("wall", wall), coupler)[0]


def _select(rheology, wall, coupler):
    """``(coupler, name)``: the coupler that answers for the pair and its registered name."""
    if type(coupler) is str and coupler == "auto":
        for instance, name in registry.couplers.derived("auto", _ranked):
            if _supports(instance, name, rheology, wall):
                return instance, name
        raise InvalidParameterError("coupler", "a coupler that supports this pair", "auto",
                                    "no registered coupler supports it")
    inst = _resolve("coupler", coupler, Coupler, registry.couplers)
    if not inst.supports(rheology, wall):
        raise InvalidParameterError("coupler", "a coupler that supports this pair", coupler,
                                    f"{type(inst).__name__} does not support {type(rheology).__name__} "
                                    f"with {type(wall).__name__}")
    return inst, registry.couplers.name_of(inst) or type(inst).__name__


def _choose(scene, coupler):
    """``(coupler, name)`` for a scene: a graded tube's is :class:`Graded` (with the user's coupler
    for the equivalent uniform tube of a separable taper)."""
    if not scene.graded:
        return _select(scene.rheology, scene.wall, coupler)
    if isinstance(coupler, Graded):
        chosen = coupler
    elif type(coupler) is str and coupler == "auto":
        chosen = Graded()
    else:
        chosen = Graded(uniform=_select(scene.rheology, scene.wall, coupler)[0])
    return chosen, registry.couplers.name_of(chosen) or type(chosen).__name__


def _load(flow_rate, pressure_drop):
    """``(controlled, load)``: which load was given and its values (a float for one value)."""
    if (flow_rate is None) == (pressure_drop is None):
        raise InvalidParameterError("flow_rate / pressure_drop", "exactly one of the two",
                                    None, "give flow_rate= or pressure_drop=, not both or neither")
    controlled = "flow_rate" if flow_rate is not None else "pressure_drop"
    value = flow_rate if flow_rate is not None else pressure_drop
    if isinstance(value, float):               # a Python or NumPy float (an int may leave the doubles)
        number = float(value)
        if 0.0 <= number < math.inf:
            return controlled, number
    load = as_load(controlled, value)
    return controlled, (float(load) if load.ndim == 0 else load)


def _options(on_infeasible, density):
    if not (isinstance(on_infeasible, str) and on_infeasible in ("raise", "nan")):    # (not an array: ambiguous)
        raise InvalidParameterError("on_infeasible", "{'raise', 'nan'}", on_infeasible)
    return None if density is None else as_load("density", density, allow_zero=False)


def _in_radius_units(function: Function) -> Function:
    """:func:`~tubefsi._keywords.checked_keywords`, recovering from
    :class:`~tubefsi.rheology.power_law.FactorRangeError` (a factor of the separated form left the
    doubles: a power law of a large index) by solving again in units of the tube's radius
    (:mod:`tubefsi.couplers.rescaled`); the error stands where that cannot help."""
    return checked_keywords(function, recover=(FactorRangeError, lambda f, a, k: _radius_units(f, a, k)))


@_in_radius_units
def solve(rheology: Rheology | type[Rheology] | str, wall: WallModel | type[WallModel] | str, tube: Tube, *,
          flow_rate: float | ArrayLike | None = None, pressure_drop: float | ArrayLike | None = None,
          coupler: str | Coupler | type[Coupler] = "auto", outlet_pressure: float | ArrayLike = 0.0,
          external_pressure: float | ArrayLike = 0.0, on_infeasible: str = "raise",
          density: float | ArrayLike | None = None, progress: bool | str = False) -> Solution:
    r"""Solve steady flow of ``rheology`` through ``tube`` with wall ``wall``.

    Exactly one of ``flow_rate`` (flow-controlled) and ``pressure_drop`` (pressure-controlled) is
    given, as a number or an array (every entry >= 0). Every model parameter, every ``Tube`` field
    and the outlet pressure may be arrays too: all broadcast together with the load by NumPy's
    rules (as :mod:`scipy.stats` broadcasts its shape parameters), the results have the broadcast
    shape, and scalars in give floats out. A Python float, an int, a NumPy scalar, a 0-d and a
    1-element array take the same route and give the same bits.

    Parameters
    ----------
    rheology, wall : model instance, class, or registered name
    tube : Tube
    flow_rate : float or array_like, optional
        Volumetric flow rate q (m^3/s).
    pressure_drop : float or array_like, optional
        Pressure drop p(0) - p(L) (Pa).
    coupler : "auto", registered name, or Coupler instance
        ``"auto"`` takes the cheapest coupler that supports the pair and meets the accuracy
        contract (``closed-form`` where it exists, else ``quadrature``); only it answers.
    outlet_pressure : float or array_like
        Gauge pressure of the fluid at the outlet, p(L) >= 0 (Pa).
    external_pressure : float or array_like
        Pressure outside the tube, p_e (Pa; any sign): the wall responds to the transmural
        pressure p - p_e. A negative transmural pressure is admitted down to the wall's
        :meth:`~tubefsi.walls.WallModel.min_pressure` (minus the buckling pressure of an
        axisymmetric wall, unbounded for ``shapiro``), else :class:`~tubefsi.BucklingError`.
    on_infeasible : {"raise", "nan"}
        What a point beyond a limit (the maximum flow rate, the limit pressure) gets:
        ``"raise"`` (the default) raises :class:`NoSteadyStateError` for the whole call;
        ``"nan"`` gives that point NaN results and ``False`` in :attr:`Solution.feasible`.
    density : float or array_like, optional
        The fluid's density (kg/m^3): adds the reduced Reynolds number to the validity checks.
    progress : bool or "auto"
        Show a progress bar over the points (tqdm, ``pip install 'tubefsi[progress]'``) for a
        long sweep; ``"auto"``: only if tqdm is installed and standard error is a terminal.

    Returns
    -------
    Solution
        Its results are checked against the model's assumptions on the *deformed* tube
        (:mod:`tubefsi.validity`); each that fails is a :class:`~tubefsi.ModelValidityWarning`.

    Raises
    ------
    InvalidParameterError
        For any input outside its admissible range.
    NoSteadyStateError
        Beyond the wall's limit pressure or the maximum flow rate (``on_infeasible="raise"``).
    StretchRangeError
        Below the maximum flow rate but beyond the solver's range (an inlet stretch over
        ``1e15``), whatever ``on_infeasible``.
    """
    return _solve(True, rheology, wall, tube, flow_rate, pressure_drop, coupler, outlet_pressure, external_pressure,
                  on_infeasible, density, progress)


@_in_radius_units
def solve_unchecked(rheology, wall, tube, *, flow_rate=None, pressure_drop=None, coupler="auto",
                    outlet_pressure=0.0, external_pressure=0.0, on_infeasible="raise", density=None,
                    progress=False) -> Solution:
    """:func:`solve` without the model-validity warnings: for the trial solves of :func:`tubefsi.fit`
    and :func:`tubefsi.advise`, whose own results are checked (no process-wide warning filter,
    which would silence other threads too)."""
    return _solve(False, rheology, wall, tube, flow_rate, pressure_drop, coupler, outlet_pressure, external_pressure,
                  on_infeasible, density, progress)


def _solve(validity, rheology, wall, tube, flow_rate, pressure_drop, coupler, outlet_pressure, external_pressure,
           on_infeasible, density, progress):
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure, external_pressure=external_pressure)
    controlled, load = _load(flow_rate, pressure_drop)
    rho = _options(on_infeasible, density)
    chosen, name = _choose(scene, coupler)
    return _solve_scene(scene, chosen, name, controlled, load, on_infeasible, rho, progress, validity=validity)


def _solve_scene(scene, chosen, name, controlled, load, on_infeasible, density, progress, *,
                 validity=True) -> Solution:
    """The solve of a validated scene with its coupler: one point, or chunks of points; the
    checks; the Solution."""
    if not scene.graded:
        _radius_power_in_range(scene)
    runner = checked(chosen)            # a self-checking coupler is re-solved finer (AccuracyWarning)
    if scene.shape == () and type(load) is float and (density is None or density.ndim == 0):
        return _solve_point(runner, scene, chosen, name, controlled, load, on_infeasible,
                            None if density is None else float(density), validity)
    shape = _result_shape(scene, controlled, load, density)
    state, feasible = _solve_points(runner, scene, controlled, load, shape, on_infeasible, progress)
    _check_finite(state, feasible, controlled, load)
    if density is not None:
        density = float(density) if density.ndim == 0 else np.broadcast_to(density, shape).ravel()
    if validity:
        flat = scene.flat(shape) if shape != () else scene
        strain = state.inlet_strain if shape == () else np.ravel(state.inlet_strain)
        check_and_warn(flat.uniform_at(0.0) if scene.graded else flat, np.ravel(state.flow_rate), strain,
                       density=density)
    return Solution(scene=scene, coupler=chosen, state=state, scalar=shape == (), coupler_name=name,
                    feasible=None if feasible is None or np.all(feasible) else np.asarray(feasible).reshape(shape),
                    density=density, controlled=controlled)


def _solve_point(runner, scene, chosen, name, controlled, load, on_infeasible, density, validity) -> Solution:
    """One load (a float) through a scene of scalars: one coupler call (its ``_point`` method for
    a flow rate), the checks, the Solution of floats."""
    feasible = None
    try:
        if controlled == "flow_rate" and on_infeasible == "raise":
            state = runner.flow_controlled_point(scene, load)
        else:
            state, feasible = _run(runner, scene, controlled, np.array([load], dtype=float), on_infeasible)
            state = state.first()
            feasible = None if feasible is None else bool(np.ravel(feasible)[0])
    except OverflowError:                  # a scene beyond double precision: a typed error
        raise _beyond_range(controlled, load, "an intermediate quantity overflows") from None
    _check_finite(state, feasible, controlled, load)
    if validity:
        check_and_warn(scene.uniform_at(0.0) if scene.graded else scene, state.flow_rate, state.inlet_strain,
                       density=density)
    return Solution(scene=scene, coupler=chosen, state=state, scalar=True, coupler_name=name,
                    feasible=None if feasible is None or feasible else np.asarray(feasible),
                    density=density, controlled=controlled)


def _result_shape(scene, controlled, load, density):
    try:
        shape = np.broadcast_shapes(scene.shape, np.shape(load))
    except ValueError:
        raise InvalidParameterError(controlled, f"arrays that broadcast with the parameters' shape {scene.shape}",
                                    load, f"shape {np.shape(load)}") from None
    if density is not None and np.broadcast_shapes(shape, density.shape) != shape:
        raise InvalidParameterError("density", f"an array that broadcasts to the result's shape {shape}", density)
    return shape


def _run(runner, scene, controlled, values, on_infeasible):
    """``(State, feasible)`` of one coupler call on the flat ``values``."""
    try:
        if on_infeasible == "nan":
            return runner.solve_feasible(scene, values, controlled)
        if controlled == "flow_rate":          # (the coupler sees a point beyond the limit itself)
            return runner.flow_controlled(scene, values), None
        _below_limit_pressure(runner, scene, values)
        return runner.pressure_controlled(scene, values), None
    except OverflowError:                  # a scene beyond double precision: a typed error
        raise _beyond_range(controlled, values, "an intermediate quantity overflows") from None


def _below_limit_pressure(runner, scene, drop):
    """Raise the NoSteadyStateError of the first pressure drop whose inlet pressure reaches the
    largest one with a steady state (the coupler's :meth:`~tubefsi.couplers.Coupler.limit_pressure`)."""
    limit = np.asarray(runner.limit_pressure(scene), dtype=float)
    if not np.any(np.isfinite(limit)):
        return
    outlet = np.broadcast_to(np.asarray(scene.outlet_pressure, dtype=float), drop.shape)
    beyond = drop >= np.broadcast_to(limit, drop.shape) - outlet
    if np.any(beyond):
        i = int(np.argmax(beyond))
        raise NoSteadyStateError("pressure", float(np.broadcast_to(limit, drop.shape)[i]), float(outlet[i] + drop[i]),
                                 "the inlet pressure is the outlet pressure plus the pressure drop",
                                 name="the inlet pressure")


def _solve_points(runner, scene, controlled, load, shape, on_infeasible, progress):
    """Every point of ``shape``, in chunks of at most ``CHUNK`` points (one parameter set per chunk
    where a model needs it): ``(State of arrays of shape, feasible or None)``."""
    flat = scene.flat(shape)
    values = np.broadcast_to(np.asarray(load, dtype=float), shape).ravel()
    n = values.size
    if n == 0:                           # an empty array (NumPy's convention): empty results, no coupler call
        return State(*(np.zeros(shape) for _ in _STATE_FIELDS)), None
    if n <= CHUNK and flat.is_one_part():                # one coupler call on every point
        state, feasible = _run(runner, flat, controlled, values.copy(), on_infeasible)
        shown = bar(n, progress, "tubefsi.solve")
        shown.update(n)
        shown.close()
        return State(*(_own_array(value, n, shape) for value in state)), feasible
    out = {f: np.full(n, np.nan) for f in _STATE_FIELDS}
    feasible = np.ones(n, dtype=bool)
    shown = bar(n, progress, "tubefsi.solve")
    done = 0
    for index, part in flat.split(np.arange(n)):
        for start in range(0, index.size, CHUNK):
            idx = index[start:start + CHUNK]
            chunk = part if part.size == 1 or idx.size == index.size else part.take(np.arange(start, start + idx.size))
            state, ok = _run(runner, chunk, controlled, values[idx].copy(), on_infeasible)
            for f in _STATE_FIELDS:
                out[f][idx] = np.broadcast_to(np.asarray(getattr(state, f), dtype=float), idx.shape)
            if ok is not None:
                feasible[idx] = ok
            shown.update(idx.size)
            done += idx.size
    shown.update(n - done)          # (points no part holds: the bar still ends at its total)
    shown.close()
    state = State(*(out[f].reshape(shape) for f in _STATE_FIELDS))
    return state, (None if np.all(feasible) else feasible)


def _own_array(value, n, shape):
    """A coupler's result of ``n`` points as a writable array of ``shape`` (its own, not a view)."""
    value = np.asarray(value, dtype=float)
    if value.size == n and value.flags.writeable and value.base is None:
        return value.reshape(shape)
    return np.array(np.broadcast_to(value, (n,))).reshape(shape)


def _check_finite(state, feasible, controlled, load):
    """A typed error where a feasible point's result is not a finite double."""
    computed = "pressure_drop" if controlled == "flow_rate" else "flow_rate"
    if type(state.inlet_strain) is float and math.isfinite(getattr(state, computed) + state.inlet_strain):
        return                              # (one point)
    with np.errstate(over="ignore", invalid="ignore"):
        if math.isfinite(float(np.sum(getattr(state, computed)) + np.sum(state.inlet_strain))):
            return
    finite = np.isfinite(np.asarray(state.pressure_drop)) & np.isfinite(np.asarray(state.flow_rate)) \
        & np.isfinite(np.asarray(state.inlet_strain))
    ok = finite if feasible is None else finite | ~np.asarray(feasible)
    if not np.all(ok):
        i = int(np.argmax(~np.ravel(ok)))
        raise _beyond_range(controlled, np.ravel(np.broadcast_to(load, np.shape(ok)))[i:i + 1],
                            "the result is not a finite double")


def _beyond_range(controlled, values, why):
    """The typed error of a load (with its scene) whose solution leaves double precision."""
    return InvalidParameterError(controlled, "loads whose solution is within double precision",
                                 float(np.ravel(values)[0]) if np.size(values) else None,
                                 f"{why} (outlet pressure and load must keep every pressure, stretch and "
                                 "flow rate below 1.8e308)")


@checked_keywords
def max_flow_rate(rheology: Rheology | type[Rheology] | str, wall: WallModel | type[WallModel] | str, tube: Tube, *,
                  outlet_pressure: float | ArrayLike = 0.0, external_pressure: float | ArrayLike = 0.0,
                  coupler: str | Coupler | type[Coupler] = "auto") -> float | np.ndarray:
    r"""The largest flow rate with a steady state (m^3/s); ``inf`` where every flow rate has one.

    Finite only for a wall with a limit pressure (thick or thin-current Mooney–Rivlin/neo-Hookean)
    and a fluid whose :math:`G(q,R)` falls off fast enough in :math:`R`: for a power law, exactly
    when :math:`n < 1`. Then :math:`L\,\phi(q_{max}) = \int_0^\infty s P'(s)/\psi(as)\,du`. Array
    parameters broadcast (an array of the scene's shape comes back).
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure, external_pressure=external_pressure)
    try:
        if not scene.graded:
            _radius_power_in_range(scene)
    except FactorRangeError:
        if type(tube.radius) is not float or not (_plain(tube.thickness) and _plain(tube.length)):
            raise
        unit = tube.radius       # in units of the radius (the limit is a flow rate: times unit^3)
        return max_flow_rate(rheology, wall, in_units(tube, unit), outlet_pressure=outlet_pressure,
                             external_pressure=external_pressure, coupler=coupler) * unit**3
    return max_flow_rate_of(scene, _choose(scene, coupler)[0])


@attrs.frozen(init=False)
class Problem:
    r"""A prepared problem: the models, the tube and the outlet resolved and validated, and the
    coupler picked, once; :meth:`solve` then takes only the load.

    ``Problem(rheology, wall, tube, coupler="auto", outlet_pressure=0.0, external_pressure=0.0)``
    takes what :func:`solve` takes besides the load; ``problem.solve(flow_rate=q)`` is
    ``tubefsi.solve(rheology, wall, tube, flow_rate=q, ...)`` without the per-call validation and
    coupler choice, the same answer to the bit. A script that loops over loads holds it::

        problem = tubefsi.Problem(fluid, wall, tube)
        for q in np.linspace(1e-10, 1e-9, 50):
            drops.append(problem.solve(flow_rate=q).pressure_drop)

    (one broadcast call, ``tubefsi.solve(..., flow_rate=np.linspace(...))``, is faster still). The
    problem is immutable; its tables live in the one cache behind :func:`solve`
    (:func:`tubefsi.cache_info`).
    """

    scene: Scene
    coupler: Coupler
    coupler_name: str

    @checked_keywords
    def __init__(self, rheology: Rheology | type[Rheology] | str, wall: WallModel | type[WallModel] | str,
                 tube: Tube, *, coupler: str | Coupler | type[Coupler] = "auto",
                 outlet_pressure: float | ArrayLike = 0.0, external_pressure: float | ArrayLike = 0.0):
        scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure, external_pressure=external_pressure)
        chosen, name = _choose(scene, coupler)
        self.__attrs_init__(scene=scene, coupler=chosen, coupler_name=name)

    @checked_keywords
    def solve(self, *, flow_rate: float | ArrayLike | None = None, pressure_drop: float | ArrayLike | None = None,
              on_infeasible: str = "raise", density: float | ArrayLike | None = None,
              progress: bool | str = False) -> Solution:
        """:func:`tubefsi.solve` of this problem at the given load (see there)."""
        controlled, load = _load(flow_rate, pressure_drop)
        rho = _options(on_infeasible, density)
        return _solve_scene(self.scene, self.coupler, self.coupler_name, controlled, load, on_infeasible, rho,
                            progress)

    def max_flow_rate(self) -> float | np.ndarray:
        """:func:`tubefsi.max_flow_rate` of this problem (m^3/s; ``inf`` where there is none)."""
        return max_flow_rate_of(self.scene, self.coupler)


def _radius_units(function, args, kwargs):
    """The solve of ``function(*args, **kwargs)`` in units of the tube's (scalar, constant)
    radius, as a Solution of the original scene, or None where it does not apply or fails too."""
    import inspect

    call = inspect.signature(function).bind(*args, **kwargs)
    call.apply_defaults()
    given = dict(call.arguments)
    tube = given["tube"]
    if type(tube) is not Tube or given["density"] is not None or type(tube.radius) is not float:
        return None
    if not (_plain(tube.thickness) and _plain(tube.length)):     # a tapered or graded tube: the error stands
        return None
    scene = make_scene(given["rheology"], given["wall"], tube, outlet_pressure=given["outlet_pressure"],
                       external_pressure=given["external_pressure"])
    if scene.graded:             # a model varying along z: z would need the change of unit too
        return None
    unit = tube.radius
    if 3.0 * math.log(unit) > 709.0:   # unit**3 would overflow (a radius over 5e102 m): the error stands
        return None
    if given["flow_rate"] is not None:
        given["flow_rate"] = as_load("flow_rate", given["flow_rate"]) / unit**3
    given["tube"] = in_units(tube, unit)
    try:
        inner = function(**given)
    except FactorRangeError:
        return None
    q = np.asarray(inner.state.flow_rate, dtype=float) * unit**3
    live = np.isfinite(q) & (np.asarray(inner.state.pressure_drop) > 0)
    if np.any(live & ~((q >= np.finfo(float).tiny) & (q < math.inf))):
        return None                    # the flow rate itself leaves the doubles: the error stands
    state = State(q if q.ndim else float(q), inner.state.pressure_drop, inner.state.inlet_strain,
                  inner.state.log_stretch)
    return Solution(scene=scene, coupler=Rescaled(inner=inner.coupler, unit=unit), state=state, scalar=inner.scalar,
                    coupler_name=inner.coupler_name, feasible=inner._feasible, controlled=inner.controlled)


def _radius_power_in_range(scene):
    """Raise FactorRangeError where a power law's :math:`a^{3n+1}` leaves the normal doubles (the
    engine's normalization of the separated integral; then :func:`solve` works in units of the
    radius). One scalar test for a scalar radius."""
    k = scene.rheology.radius_exponent
    if type(k) is not float:
        return
    a = scene.tube.radius
    if type(a) is float:
        if k * abs(math.log(a)) <= 700.0:
            return
    elif not isinstance(a, np.ndarray) or k * float(np.max(np.abs(np.log(a)), initial=0.0)) <= 700.0:
        return                       # (a radius along z: the graded coupler's own range checks)
    raise FactorRangeError("index", "indices with a^(3n+1) within double precision at radius a", k,
                           "R^-(3n+1) leaves the range of double precision")


def _plain(value) -> bool:
    """A tube field of numbers (not a profile along z)."""
    return type(value) is float or isinstance(value, np.ndarray)
