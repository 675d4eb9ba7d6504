r"""Transients: :func:`evolve` integrates the inflation, settling and relaxation of a soft tube.

The model (``docs/theory.md``, section "Transients"): lubrication flow with the wall in
quasi-static equilibrium and no fluid inertia,

.. math::

    \frac{\partial A}{\partial t} + \frac{\partial q}{\partial z} = 0, \qquad
    A = \pi a^2 \lambda(p - p_e)^2, \qquad q = Q\Bigl(-\frac{\partial p}{\partial z}, a\lambda\Bigr),

with :math:`Q(G, R)` the rheology's tube flow function (:meth:`Rheology.flow_rate`, signed with
:math:`G`) and :math:`\lambda(p)` the wall's tube law (:meth:`WallModel.pressure` is its inverse
:math:`P(\lambda)`). Eliminating :math:`A` gives the nonlinear diffusion equation
:math:`C(p)\,\partial_t p = \partial_z Q(-\partial_z p, R(p))`, :math:`C = dA/dp`.

**Discretization.** ``n`` equal finite volumes; the unknowns are the cell averages of the area
strain :math:`s = A/(\pi a^2) - 1` (the conserved quantity: the discrete volume changes exactly by
the boundary fluxes), the pressure of a cell is the wall's :math:`P(\sqrt{1+s}) + p_e` (the
natural hook of every registered wall: no inversion of the tube law in the loop), the flux
through a face is :math:`Q(-(p_{i+1} - p_i)/\Delta z, a\bar\lambda)` with the mean stretch of
the two cells (at a boundary: the half cell to the boundary pressure, the stretch of the cell),
second order in :math:`\Delta z`. A graded tube (``docs/transients.md``, "Graded tubes") has
per cell its undeformed radius :math:`a_i = a(z_i)`, :math:`\bar t(z_i)` and wall parameters
:math:`\theta(z_i)` (the strain :math:`s_i` relative to :math:`\pi a_i^2`, the cell's own tube law),
and per face the undeformed radius :math:`a(z_{i+1/2})`. Time: :func:`scipy.integrate.solve_ivp` (``BDF`` or
``Radau``) with the exact sparse Jacobian (tridiagonal plus the chamber and the volume
counters): the face flows' slopes :math:`\partial Q/\partial G = (\pi R^3\dot\gamma_w - 3Q)/G`,
:math:`\partial Q/\partial R = \pi R^2\dot\gamma_w` from the rheology's shear rate at the wall
stress, the cells' :math:`dp/ds` from the wall's stiffness; about two right-hand sides per Jacobian.

**Error control.** The inlet history (the flow rate for a pressure inlet, the pressure for a pump)
is computed on ``n``, ``2n`` and ``4n`` cells at the integrator tolerance :math:`\tau/10`; the
reported boundary histories are the Richardson extrapolation :math:`E_{2n,4n} = h_{4n} + (h_{4n} -
h_{2n})/3` (third order), the space estimate :math:`\tfrac13|E_{n,2n} - E_{2n,4n}|` (the difference
is the coarser extrapolation's error minus the reported one's: at an order :math:`p \ge 2` the
reported one's is at most :math:`1/(2^p - 1) \le 1/3` of it); the time estimate is
:math:`\tfrac53|h_{n,\tau} - h_{n,\tau/10}|` (the error of a run at :math:`\tau`, conservative for the
reported runs at :math:`\tau/10`; :math:`\tfrac53` bounds the extrapolation's weights). The cells
grow and the tolerance falls until their sum, relative to the history's scale (its largest value,
at least the flow :math:`Q(p_s/L, a)` under the problem's pressure scale :math:`p_s`, or :math:`p_s` behind
a pump: not pointwise, a relaxation's history decays to ~0), meets ``rtol``, else an :class:`~tubefsi.AccuracyWarning` states the estimate. The fields inside the tube
are the ``4n`` run's.

**Batches.** Arrays of scene parameters (boundary values, external and starting pressures, the
tube's sizes, the models' parameters) broadcast to the scenes' shape and run as one system: the
scenes' states one after the other, per-scene numbers as columns against the cells, a
block-diagonal Jacobian, shared output times, cells and integrator steps; the error estimates are
the largest over the scenes (``docs/transients.md``, "Batches of scenes").
"""

from __future__ import annotations

import math
import warnings
from typing import Callable

import attrs
import numpy as np

from ._keywords import checked_keywords
from ._lazy import lazy_module
from ._validation import as_scalar, positive_scalar, real_array
from .fields import _array_fields, _replace, at_position, broadcast_model, varies
from .errors import (AccuracyWarning, BucklingError, ConvergenceError, InvalidParameterError, ModelValidityWarning,
                     NoSteadyStateError, TubefsiError, warn_user)
from .geometry import Tube
from .profiles import Profile
from .rheology.flow_map import kind as flow_map_kind
from .scene import resolve
from .solution import Solution
from .solve import solve
from .validity import REDUCED_REYNOLDS

integrate = lazy_module("scipy.integrate", globals(), "integrate")
sparse = lazy_module("scipy.sparse", globals(), "sparse")

__all__ = ["evolve", "Transient", "Chamber", "WOMERSLEY", "MAX_CELLS"]

#: Largest Womersley number :math:`a\sqrt{\rho/(\mu t_c)}` for the flow to be quasi-steady.
WOMERSLEY = 0.5
#: The most cells the error control refines to.
MAX_CELLS = 4096
#: The smallest integrator tolerance the error control goes down to.
_MIN_RTOL = 1e-12


# ---------------------------------------------------------------------------------------- chamber
@attrs.frozen
class Chamber:
    r"""A lumped chamber at the outlet (a soft actuator, a reservoir): its volume :math:`V(p)`
    (m^3) at the fluid's gauge pressure :math:`p` (Pa), filled by the outlet flow,
    :math:`dV/dt = q(L, t)`.

    Parameters
    ----------
    volume : callable
        :math:`V(p)`, increasing (a measured or modelled pressure–volume curve).
    compliance : callable, optional
        :math:`dV/dp` (m^3/Pa), checked at construction against a fourth-order central
        difference of ``volume`` at 0, 100 and 1000 Pa (relative 1e-6; else
        :class:`InvalidParameterError` naming ``compliance``). Without it, a fourth-order central
        difference of ``volume`` at a step of 1e-3 of the problem's pressure scale.

    Notes
    -----
    A chamber whose volume becomes negative during a run (emptied by suction) raises
    :class:`InvalidParameterError` naming ``outlet``.
    """

    volume: Callable = attrs.field()
    compliance: Callable | None = attrs.field(default=None)

    @volume.validator
    def _callable(self, attribute, value):
        if not callable(value):
            raise InvalidParameterError("volume", "a callable V(p) (m^3)", value)

    @compliance.validator
    def _consistent(self, attribute, value):
        r"""A given ``compliance`` must be :math:`dV/dp`: checked against a fourth-order central
        difference of ``volume`` (step 0.1 to 10 Pa) at 0, 100 and 1000 Pa, to a relative 1e-6."""
        if value is None:
            return
        if not callable(value):
            raise InvalidParameterError("compliance", "a callable dV/dp (m^3/Pa) or None", value)
        v = lambda x: _elementwise(self.volume, x, "volume", "p")         # noqa: E731
        for p in (0.0, 100.0, 1000.0):
            try:                  # (a curve not defined there, e.g. only for p > 0: not checked there)
                given = float(_elementwise(value, p, "compliance", "p"))
                volume = abs(float(v(p)))
                # the step: C h ~ 1e-4 V (rounding of V far below 1e-6), within [0.1, 10] Pa
                h = min(max(0.1, 1e-4 * volume / abs(given)), 10.0) if given else 0.1
                difference = float((8.0 * (v(p + h) - v(p - h)) - (v(p + 2 * h) - v(p - 2 * h))) / (12.0 * h))
            except TubefsiError:
                continue
            rounding = 10.0 * np.finfo(float).eps * volume / h
            if abs(given - difference) > 1e-6 * max(abs(difference), abs(given)) + rounding:
                raise InvalidParameterError("compliance", "dV/dp of the chamber's volume V(p)", given,
                                            f"at p = {p:g} Pa, while a difference of volume gives {difference:.6g}")

    @classmethod
    def linear(cls, volume: float, compliance: float) -> Chamber:
        r"""The linear chamber :math:`V = V_0 + C p` (``volume`` :math:`V_0` m^3, ``compliance`` :math:`C` m^3/Pa)."""
        c = positive_scalar("compliance", compliance)
        v0 = as_scalar("volume", volume, "[0, inf) m^3", lambda v: v >= 0)
        return cls(volume=lambda p: v0 + c * np.asarray(p, dtype=float), compliance=lambda p: c + 0.0 * np.asarray(p))

    def volume_at(self, p):
        """:math:`V(p)` (m^3), elementwise."""
        return _elementwise(self.volume, p, "outlet", "p")

    def compliance_at(self, p, scale: float = 1.0):
        """:math:`dV/dp` (m^3/Pa), elementwise (a difference of ``volume`` at steps ``1e-3 scale``
        where no ``compliance`` is given)."""
        if self.compliance is not None:
            c = _elementwise(self.compliance, p, "outlet", "p")
        else:
            h = 1e-3 * scale
            p = np.asarray(p, dtype=float)
            c = (8.0 * (self.volume_at(p + h) - self.volume_at(p - h))
                 - (self.volume_at(p + 2 * h) - self.volume_at(p - 2 * h))) / (12.0 * h)
        if not (np.asarray(c) > 0).all():
            raise InvalidParameterError("chamber compliance", "dV/dp > 0 (an increasing V(p))", float(np.min(c)))
        return c


def _elementwise(function, t, name, argument="t"):
    """``function`` at the array ``t``: called on the array, or point by point where it does not
    broadcast (a function written for one number); a float array of the shape of ``t``. A call
    that raises, returns no real number (an array, a string) or a non-finite value raises
    :class:`InvalidParameterError` naming ``name``, with the value and the argument."""
    t = np.asarray(t, dtype=float)
    try:
        out = np.asarray(function(t), dtype=float)
        if out.shape != t.shape:
            out = np.broadcast_to(out, t.shape).astype(float)
    except Exception:                     # (a function of one number: called point by point below)
        out = np.array([_one(function, float(x), name, argument) for x in t.ravel()]).reshape(t.shape)
    if not np.isfinite(out).all():
        k = int(np.argmin(np.isfinite(out).ravel()))
        raise InvalidParameterError(name, "finite values", float(out.ravel()[k]),
                                    f"at {argument} = {float(t.ravel()[k]):.6g}")
    return out


def _one(function, x, name, argument):
    """``function(x)`` as one float (see :func:`_elementwise`)."""
    try:
        value = function(x)
    except TubefsiError:
        raise
    except Exception as error:
        raise InvalidParameterError(name, "a callable returning one finite number", None,
                                    f"at {argument} = {x:.6g} it raised {type(error).__name__}: {error}") from error
    v = real_array(name, value, "one finite number")
    if v.ndim:
        raise InvalidParameterError(name, "a callable returning one finite number", None,
                                    f"at {argument} = {x:.6g} it returned an array of shape {v.shape}")
    return float(v)


def _finite(name, value, admissible):
    """``value`` as a float array of finite numbers (one per scene, or one number); a non-finite
    entry raises :class:`InvalidParameterError` naming ``name`` and the entry."""
    v = real_array(name, value, admissible)
    if not np.all(np.isfinite(v)):
        if v.ndim == 0:
            raise InvalidParameterError(name, admissible, float(v))
        where = tuple(int(i) for i in np.argwhere(~np.isfinite(v))[0])
        raise InvalidParameterError(name, admissible, float(v[where]), f"entry {where} of an array of shape {v.shape}")
    return v


def _broadcast(values, shape):
    """``values`` as a float array of ``shape`` (a view; no call to broadcast_to where the shape
    already fits: the right-hand side's one state)."""
    values = np.asarray(values, dtype=float)
    return values if values.shape == shape else np.broadcast_to(values, shape)


def _boundary(name, value):
    """``(function of t, scenes' shape)``: a callable (shared by the scenes; its shape ``()``), a
    number (constant) or an array of numbers (one constant per scene, its values flattened: the
    function takes times of shape ``(..., S)``)."""
    if callable(value):
        return value, ()
    v = _finite(name, value, "a finite number, an array of them (one per scene) or a callable of t")
    if v.ndim == 0:
        v = float(v)
        return (lambda t: v + 0.0 * np.asarray(t, dtype=float)), ()
    return v, v.shape


def _per_scene_function(value, shape):
    """A boundary of :func:`_boundary` as a function of t: an array of constants broadcast to the
    scenes' ``shape`` and flattened (the function takes times of shape ``(..., S)``)."""
    if callable(value):
        return value
    flat = np.broadcast_to(value, shape).ravel()
    return lambda t: flat + 0.0 * np.asarray(t, dtype=float)


# ------------------------------------------------------------------------------ discrete system
def _aligned(model, shape):
    """``model`` with its array parameters (per cell, per scene) broadcast to ``shape``, the shape
    of the arguments of a hook call (the hooks get parameters aligned with their arguments, as
    :func:`tubefsi.fields.evaluate` gives them); the model itself if its parameters are scalars."""
    arrays = {name: v for name in _array_fields(type(model))
              if isinstance(v := getattr(model, name), np.ndarray) and v.shape != tuple(shape)}
    return _replace(model, {k: np.broadcast_to(v, shape) for k, v in arrays.items()}) if arrays else model


def _scene_model(model, shape):
    """``model`` with its array parameters broadcast to the scenes' ``shape`` and flattened (one
    entry per scene); the model itself for one scene."""
    return broadcast_model(model, shape) if shape != () else model


def _column_model(model, shape):
    """``model`` with one parameter per scene as a column ``(S, 1)`` (to broadcast against per-cell
    arrays ``(..., S, n)``); the model itself for one scene."""
    if shape == ():
        return model
    flat = broadcast_model(model, shape)
    arrays = {k: v[:, None] for k in _array_fields(type(flat)) if isinstance(v := getattr(flat, k), np.ndarray)}
    return _replace(flat, arrays) if arrays else flat


def _tube_at(tube, z, shape):
    """The undeformed radius and thickness at the positions ``z`` (a profile evaluated there; an
    array of scenes as a column ``(S, 1)``; a number as itself)."""
    out = []
    for v in (tube.radius, tube.thickness):
        if isinstance(v, Profile):
            out.append(v(z))
        elif shape == ():
            out.append(float(v))
        else:
            out.append(np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1, 1))
    return out


def _section(wall, tube, z, shape=()):
    """``(wall, a, tb)`` at the positions ``z`` (m; for scenes, ``(S, k)``): the wall with its
    profiles evaluated there and one parameter per scene as a column, the undeformed radius and t/a."""
    z = np.asarray(z, dtype=float)
    a, t = _tube_at(tube, z, shape)
    wall = _column_model(wall, shape)
    return at_position(wall, z) if varies(wall) else wall, a, t / a


@attrs.frozen
class _System:
    r"""The semi-discrete system on ``n`` cells of ``S`` independent scenes: the state of a scene is
    ``[s_1..s_n, (p_chamber), V_in, V_out]`` with :math:`s_i = A_i/(\pi a_i^2) - 1` the area strain
    of cell :math:`i` relative to its own undeformed radius :math:`a_i = a(z_i)`, ``V_in``, ``V_out``
    the volumes that entered and left; the state of a batch is the scenes' states one after the
    other (its Jacobian block-diagonal, each block banded).

    A graded tube (radius, thickness or wall parameters functions of z) has them per cell, taken
    at the cell's centre :math:`z_i` (the tube law of cell :math:`i` is the wall's at
    :math:`\bar t(z_i)` and the wall parameters there), and the undeformed radius per face
    :math:`a(z_{i+1/2})`. One scene (``shape == ()``) keeps its numbers as floats; a batch has
    the per-scene numbers (``external``, ``pressure_scale``, :attr:`radius`, :attr:`tb`,
    :attr:`length`) as arrays ``(S,)`` and, for the cells, as columns ``(S, 1)`` (or ``(S, n)``
    where graded). The derived quantities are built for the given ``n``
    (``attrs.evolve(system, n=...)`` builds them again)."""

    rheology: object         # the model as given (array parameters: per scene)
    wall: object             # the wall as given (parameters: profiles along z, arrays per scene)
    tube: Tube               # the tube as given (graded or uniform, arrays per scene)
    external: object         # float, or (S,) per scene
    n: int
    inlet_kind: str          # "pressure" or "flow"
    inlet: Callable          # a function of t (its values: one number, or per scene)
    outlet_kind: str         # "pressure", "closed" or "chamber"
    outlet: object           # callable p(t), None, or Chamber
    pressure_scale: object   # float, or (S,) per scene
    #: The scenes' shape (``()``: one scene).
    shape: tuple = ()
    #: The inlet's undeformed radius a(0) (m) and t(0)/a(0): the uniform tube's, and the scales
    #: of a graded one; the length (m). Floats, or ``(S,)`` per scene.
    radius: object = attrs.field(init=False)
    tb: object = attrs.field(init=False)
    length: object = attrs.field(init=False)
    #: Per cell: the undeformed radius, t/a and the wall with its profiles evaluated at the
    #: centres (scalars and the wall itself for a uniform tube); per face: the undeformed radius.
    a_cells: object = attrs.field(init=False, repr=False)
    tb_cells: object = attrs.field(init=False, repr=False)
    wall_cells: object = attrs.field(init=False, repr=False)
    a_faces: object = attrs.field(init=False, repr=False)
    #: The rheology with one parameter per scene, flat ``(S,)`` and as columns ``(S, 1)``.
    scene_rheology: object = attrs.field(init=False, repr=False)
    face_rheology: object = attrs.field(init=False, repr=False)

    def __attrs_post_init__(self):
        shape = self.shape
        set_ = object.__setattr__
        length = float(self.tube.length) if shape == () else np.broadcast_to(self.tube.length, shape).astype(float).ravel()
        a0, t0 = _tube_at(self.tube, self._column(np.zeros(self.scenes)) if shape else np.asarray(0.0), shape)
        if shape == ():
            a0, t0 = float(a0), float(t0)
        else:
            a0, t0 = np.broadcast_to(a0, (self.scenes, 1))[:, 0], np.broadcast_to(t0, (self.scenes, 1))[:, 0]
        set_(self, "radius", a0)
        set_(self, "tb", t0 / a0)
        set_(self, "length", length)
        set_(self, "scene_rheology", _scene_model(self.rheology, shape))
        set_(self, "face_rheology", _column_model(self.rheology, shape))
        if not self.graded:
            a_c = self._column(a0)
            set_(self, "a_cells", a_c)
            set_(self, "tb_cells", self._column(t0 / a0))
            set_(self, "wall_cells", _column_model(self.wall, shape))
            set_(self, "a_faces", a_c)
            return
        cells = self.z
        wall, a_c, tb_c = _section(self.wall, self.tube, cells, shape)
        set_(self, "a_cells", np.broadcast_to(a_c, cells.shape).astype(float))
        set_(self, "tb_cells", np.broadcast_to(tb_c, cells.shape).astype(float))
        set_(self, "wall_cells", wall)
        faces = np.arange(self.n + 1) * self._column(self.dz)
        set_(self, "a_faces", np.broadcast_to(_tube_at(self.tube, faces, shape)[0], faces.shape).astype(float))

    def _column(self, value):
        """A per-scene value as a column ``(S, 1)`` for a batch; itself for one scene."""
        return value if self.shape == () else np.asarray(value)[:, None]

    @property
    def scenes(self) -> int:
        """The number of scenes ``S`` (1 for one)."""
        return math.prod(self.shape)

    @property
    def graded(self) -> bool:
        """Whether the tube or the wall varies along z."""
        return self.tube.graded or varies(self.wall)

    def section(self, z):
        """``(wall, a, tb)`` at the positions ``z`` (m; a batch: ``(S, k)``): the wall with its
        profiles evaluated there, the undeformed radius and t/a (a batch: per scene, as columns)."""
        return _section(self.wall, self.tube, z, self.shape)

    def boundary(self, function, t, name):
        """A boundary function at the times ``t``: shape ``t.shape`` (one scene) or ``t.shape + (S,)``."""
        t = np.asarray(t, dtype=float)
        if self.shape != ():
            t = np.broadcast_to(t[..., None], t.shape + (self.scenes,))
        return _elementwise(function, t, name)

    @property
    def dz(self):
        return self.length / self.n

    @property
    def size(self) -> int:
        """The unknowns of one scene."""
        return self.n + (1 if self.outlet_kind == "chamber" else 0) + 2

    @property
    def z(self):
        """The cell centres (m): ``(n,)``, or ``(S, n)`` for a batch."""
        return (np.arange(self.n) + 0.5) * self._column(self.dz)

    @property
    def cell_volumes(self):
        r"""The cells' undeformed volumes :math:`\pi a_i^2 \Delta z` (m^3)."""
        return math.pi * self.a_cells**2 * self._column(self.dz)

    def stretch(self, s):
        return np.sqrt(1.0 + s)

    def cell_pressure(self, s, strict=True):
        r"""The cells' pressure :math:`P_i(\lambda) + p_e` at area strain ``s`` (the tube law of each
        cell), from the wall's strain hook at :math:`\lambda - 1 = s/(1 + \sqrt{1+s})` (no rounding
        of :math:`1 + \varepsilon`: full accuracy at tiny strains); a stretch outside the wall's
        range gets the public method's error (``strict``), else NaN there: the integrator's trial
        states (a Newton iterate may overshoot beyond the wall's range; the integrator rejects a
        non-finite right-hand side and takes a smaller step)."""
        with np.errstate(invalid="ignore"):
            strain = s / (1.0 + np.sqrt(1.0 + s))
        wall = _aligned(self.wall_cells, strain.shape)
        tb = self.tb_cells
        with np.errstate(all="ignore"):
            p = wall._pressure_at_strain(strain, tb)
        if strict and not np.isfinite(p).all():
            self.wall_cells.pressure(1.0 + strain, tb)        # raises the typed error
            raise InvalidParameterError("stretch", "stretches the wall holds", float(np.max(1.0 + strain)))
        return p + self._column(self.external)

    def face_flow(self, radius, gradient):
        r""":math:`\operatorname{sign}(G)\,Q(R, |G|)` by the rheology's flow hook ``_flow_rate``:
        the physics of :meth:`Rheology.flow_rate` without its argument checks (the radii and
        gradients here are the scheme's own; the checks cost more than the flow law of a power
        law). A flow beyond the doubles gets the public method's typed error."""
        g = np.abs(gradient)
        radius = _broadcast(radius, g.shape)
        live = g > 0
        rheology = _aligned(self.face_rheology, g.shape)
        with np.errstate(all="ignore"):
            if live.all():                # (the usual case: no masked copies)
                q = rheology._flow_rate(radius, g)
            else:
                if rheology is not self.face_rheology:          # (per-scene parameters: at the live faces)
                    rheology = _replace(rheology, {k: v[live] for k in _array_fields(type(rheology))
                                                   if isinstance(v := getattr(rheology, k), np.ndarray)})
                q = np.zeros(g.shape)
                q[live] = rheology._flow_rate(radius[live], g[live])
        if not np.isfinite(q).all():
            self.face_rheology.flow_rate(radius, g)          # raises the typed error
            raise InvalidParameterError("pressure gradient", "gradients of a finite flow", float(np.max(g)))
        return np.copysign(q, gradient)

    def faces(self, t, s, p_chamber=None, strict=True):
        """``(p, lam, h, G, lam_f)``: cell pressures and stretches, and at the ``n + 1`` faces the
        distances between the pressures they join (half a cell at the ends), the pressure
        gradients and the mean stretches, for states ``s`` of shape ``(..., S, n)`` (``(..., n)``
        for one scene) at times ``t`` (broadcast with ``s[..., 0]``). A pump's inlet face and a
        closed end get a zero gradient here; :meth:`fluxes` sets their flow."""
        with np.errstate(invalid="ignore"):
            lam = self.stretch(s)
        p = self.cell_pressure(s, strict)
        lead = p.shape[:-1]
        t = _broadcast(t, lead)
        if self.inlet_kind == "pressure":
            p0 = _elementwise(self.inlet, t, "inlet_pressure")
        else:
            p0 = p[..., 0]
        if self.outlet_kind == "pressure":
            pl = _elementwise(self.outlet, t, "outlet_pressure")
        elif self.outlet_kind == "chamber":
            pl = _broadcast(p_chamber, lead)
        else:
            pl = p[..., -1]
        P = np.concatenate([np.asarray(p0)[..., None], p, np.asarray(pl)[..., None]], axis=-1)
        ends = np.ones(self.n + 1)
        ends[0] = ends[-1] = 0.5
        h = self._column(self.dz) * ends
        G = (P[..., :-1] - P[..., 1:]) / h
        lam_f = np.concatenate([lam[..., :1], 0.5 * (lam[..., :-1] + lam[..., 1:]), lam[..., -1:]], axis=-1)
        return p, lam, h, G, lam_f

    def fluxes(self, t, s, p_chamber=None, strict=True):
        """``(p, lam, q)``: cell pressures and stretches and the ``n + 1`` face flow rates, for
        states ``s`` of shape ``(..., S, n)`` (``(..., n)``) at times ``t`` (broadcast with ``s[..., 0]``);
        ``strict``: :meth:`cell_pressure`'s."""
        p, lam, _, G, lam_f = self.faces(t, s, p_chamber, strict)
        q = self.face_flow(self.a_faces * lam_f, G)
        t = _broadcast(t, p.shape[:-1])
        if self.inlet_kind == "flow":
            q[..., 0] = _elementwise(self.inlet, t, "inlet_flow_rate")
        if self.outlet_kind == "closed":
            q[..., -1] = 0.0
        return p, lam, q

    def _states(self, y):
        """The flat state ``y`` of all scenes as ``(S, size)`` (a view)."""
        return y.reshape(self.scenes, self.size)

    def rhs(self, t, y):
        n = self.n
        chamber = self.outlet_kind == "chamber"
        Y = self._states(y)
        if self.shape == ():
            Y = Y[0]                      # (one scene: its own state, the numbers as floats)
        # (a trial state beyond the wall's range: NaN, which the integrator rejects)
        p, lam, q = self.fluxes(t, Y[..., :n], Y[..., n] if chamber else None, strict=False)
        out = np.empty(Y.shape)
        out[..., :n] = (q[..., :-1] - q[..., 1:]) / self.cell_volumes
        if chamber:
            out[..., n] = q[..., -1] / self.outlet.compliance_at(Y[..., n], self.pressure_scale)
        out[..., -2], out[..., -1] = q[..., 0], q[..., -1]
        return out.reshape(-1)

    def face_slopes(self, radius, gradient):
        r"""The derivatives of the face flow :math:`q = \operatorname{sign}(G)\,Q(R, |G|)`:
        ``(dq/dG, dq/dR)``, from the Rabinowitsch–Mooney form :math:`Q = \pi R^3\Gamma(\tau_w)/4`,
        :math:`\tau_w = GR/2`, whose slope :math:`d\Gamma/d\tau_w` follows from
        :math:`\Gamma = (4/\tau_w^3)\int_0^{\tau_w}\tau^2\dot\gamma(\tau)\,d\tau`:

        .. math::

            \frac{\partial Q}{\partial G} = \frac{\pi R^3\dot\gamma_w - 3Q}{G}, \qquad
            \frac{\partial Q}{\partial R} = \pi R^2\dot\gamma_w, \qquad \dot\gamma_w = \dot\gamma(\tau_w)

        (the rheology's flow hook and its shear rate at the wall stress; Newtonian:
        :math:`\pi R^4/8\mu` and :math:`4Q/R`). At rest (:math:`G = 0`, where the first is a limit)
        both are taken at a gradient of :math:`10^{-8}` of the problem's scale :math:`p_s/L`. Below
        :math:`10^{-5}\,p_s/L` the first is at least its value there: a shear-thinning law's slope
        vanishes at rest (:math:`Q \propto G^{1/n}`), and Newton's iteration with it overshoots
        where a front reaches resting cells (it failed and rebuilt the Jacobian every other step on
        fine grids; a shear-thickening law's slope, growing towards rest, is kept). The Jacobian
        steers Newton's iteration; the residual stays exact."""
        scale = self._column(self.pressure_scale / self.length)
        g = np.maximum(np.abs(gradient), 1e-8 * scale)
        q = self.face_flow(radius, g)
        rate = self.face_rheology.shear_rate(0.5 * g * radius)
        d_gradient = (math.pi * radius**3 * rate - 3.0 * q) / g
        d_radius = np.copysign(math.pi * radius**2 * rate, gradient)
        low = g < 1e-5 * scale
        if low.any():
            if self.shape == ():          # (one scene: at the low faces only)
                g_low, r_low = np.full(int(np.sum(low)), 1e-5 * scale), radius[low]
                slope = (math.pi * r_low**3 * self.face_rheology.shear_rate(0.5 * g_low * r_low)
                         - 3.0 * self.face_flow(r_low, g_low)) / g_low
                d_gradient[low] = np.maximum(d_gradient[low], slope)
            else:                         # (a batch: every face, the parameters per scene as columns)
                g_low = np.broadcast_to(1e-5 * scale, g.shape)
                slope = (math.pi * radius**3 * self.face_rheology.shear_rate(0.5 * g_low * radius)
                         - 3.0 * self.face_flow(radius, g_low)) / g_low
                d_gradient = np.where(low, np.maximum(d_gradient, slope), d_gradient)
        return d_gradient, d_radius

    def jacobian(self, t, y):
        r"""The exact Jacobian of :meth:`rhs`: the cells' tridiagonal band from the face flows'
        slopes (:meth:`face_slopes`), the cells' :math:`dp/ds = P'(\lambda)/(2\lambda)` (the wall's
        stiffness) and :math:`d\lambda/ds = 1/(2\lambda)`, the chamber's coupling to the last cell,
        the counters' to the end cells; one such block per scene on the diagonal. Costs about two
        right-hand sides."""
        n, m, S = self.n, self.size, self.scenes
        chamber = self.outlet_kind == "chamber"
        Y = self._states(y)
        if self.shape == ():
            Y = Y[0]
        p, lam, h, G, lam_f = self.faces(t, Y[..., :n], Y[..., n] if chamber else None, strict=False)
        dp = self.wall_cells.stiffness(lam, self.tb_cells) / (2.0 * lam)     # dp_i/ds_i
        dlam = 0.5 / lam                                                  # dlambda_i/ds_i
        weight = np.full(n + 1, 0.5)
        weight[0] = weight[-1] = 1.0
        a_f = np.broadcast_to(self.a_faces, G.shape)
        h = np.broadcast_to(h, G.shape)
        q_g, q_r = self.face_slopes(a_f * lam_f, G)
        # face j sits between cell j-1 (left) and cell j (right); its radius a(z_j) lam_f
        left = q_g[..., 1:] / h[..., 1:] * dp + q_r[..., 1:] * a_f[..., 1:] * weight[1:] * dlam       # dq_j/ds_{j-1}
        right = -q_g[..., :-1] / h[..., :-1] * dp + q_r[..., :-1] * a_f[..., :-1] * weight[:-1] * dlam  # dq_j/ds_j
        if self.inlet_kind == "flow":
            right[..., 0] = 0.0
        if self.outlet_kind == "closed":
            left[..., -1] = 0.0
        volume = np.broadcast_to(self.cell_volumes, lam.shape)
        i = np.arange(n)
        rows = [i, i[1:], i[:-1], [m - 2], [m - 1]]
        cols = [i, i[:-1], i[1:], [0], [n - 1]]
        vals = [(right - left) / volume, left[..., :-1] / volume[..., 1:], -right[..., 1:] / volume[..., :-1],
                right[..., :1], left[..., -1:]]
        if chamber:
            pc = Y[..., n]
            c = self.outlet.compliance_at(pc, self.pressure_scale)
            step = 1e-4 * np.maximum(np.abs(pc), self.pressure_scale)
            dc = (self.outlet.compliance_at(pc + step, self.pressure_scale)
                  - self.outlet.compliance_at(pc - step, self.pressure_scale)) / (2.0 * step)
            dq_dpl = -q_g[..., -1] / h[..., -1]                           # dq_n/dp_chamber
            q_end = self.face_flow(a_f * lam_f, G)[..., -1]                 # the chamber's inflow
            rows += [[n], [n], [n - 1], [m - 1]]
            cols += [[n - 1], [n], [n], [n]]
            vals += [left[..., -1:] / c[..., None], (dq_dpl / c - q_end * dc / c**2)[..., None],
                     (-dq_dpl / volume[..., -1])[..., None], dq_dpl[..., None]]
        # the scenes' blocks on the diagonal: scene k's unknowns start at k m
        offset = (np.arange(S) * m)[:, None]
        vals = np.concatenate([np.broadcast_to(np.asarray(v, dtype=float), (S, len(r))).ravel()
                               for v, r in zip(vals, rows)])
        rows = np.concatenate([(np.asarray(r) + offset).ravel() for r in rows])
        cols = np.concatenate([(np.asarray(c_) + offset).ravel() for c_ in cols])
        return sparse.csc_matrix((vals, (rows, cols)), shape=(S * m, S * m))

    def scene(self, k: int) -> _System:
        """Scene ``k`` (flat index) of a batch as a system of one scene: its parameters as numbers,
        its boundary functions those of the batch at that scene."""
        def number(value):
            return float(np.broadcast_to(value, self.shape).reshape(-1)[k]) if isinstance(value, np.ndarray) else value

        def one(model):
            values = {name: number(v) for name in _array_fields(type(model))
                      if isinstance(v := getattr(model, name), np.ndarray)}
            return _replace(model, values) if values else model

        def at_scene(function, name):
            return lambda t: np.asarray(self.boundary(function, t, name))[..., k]

        tube = self.tube
        arrays = {name: number(v) for name in ("length", "radius", "thickness")
                  if isinstance(v := getattr(tube, name), np.ndarray)}
        if arrays:
            tube = attrs.evolve(tube, **arrays)
        outlet = at_scene(self.outlet, "outlet_pressure") if self.outlet_kind == "pressure" else self.outlet
        return _System(rheology=one(self.rheology), wall=one(self.wall), tube=tube, external=float(self.external[k]),
                       n=self.n, inlet_kind=self.inlet_kind, inlet=at_scene(self.inlet, self.inlet_kind),
                       outlet_kind=self.outlet_kind, outlet=outlet, pressure_scale=float(self.pressure_scale[k]))

    def initial_state(self, initial, t0):
        """The state at ``t0``: at rest at ``initial`` (a pressure, Pa; a batch: per scene) or
        from a steady Solution (one scene)."""
        n = self.n
        y = np.zeros((self.scenes, self.size))
        if isinstance(initial, Solution):
            lam = np.asarray(initial.radius(self.z), dtype=float) / self.a_cells
            p_end = float(initial.pressure(self.length))
        else:
            p0 = float(initial) if self.shape == () else np.broadcast_to(initial, (self.scenes,))
            strain = self.wall_cells.strain(self._column(p0) - self._column(self.external), self.tb_cells)
            lam = np.broadcast_to(1.0 + np.asarray(strain), (self.scenes, n))
            p_end = p0
        y[:, :n] = lam * lam - 1.0
        if self.outlet_kind == "chamber":
            y[:, n] = p_end
        return y.reshape(-1)


# ------------------------------------------------------------------------------------ the result
@attrs.frozen(kw_only=True)
class Transient:
    r"""The transient of :func:`evolve`: the fields at the output ``times`` and the boundary histories.

    Fields are stored at the nodes ``z`` (the inlet, the cell centres, the outlet) and the flow
    rate at the cell faces; :meth:`pressure`, :meth:`radius` and :meth:`flow_rate` interpolate
    linearly in z and in t (exact at the nodes and the output times, to the error estimate). With
    error control the values at the ends (z = 0 and L) and the volume histories are the Richardson
    extrapolation of the two finest runs, the values inside the tube the finest run's.

    A batch of scenes (:func:`evolve` with arrays of scene parameters) has the scenes' axes first:
    ``shape`` is their broadcast shape, the fields are ``(*shape, len(times), nodes)``, the
    histories ``(*shape, len(times))``, ``z`` and ``z_faces`` ``(*shape, nodes)`` (each scene its
    own length); the cells, the output times and the error estimates (the largest over the scenes)
    are shared. :meth:`steady` (one solve of the scenes' shape), :meth:`steady_volume` and
    :meth:`settling_time` are vectorized over the scenes (arrays of their shape); :meth:`scene`
    gives one scene as a :class:`Transient` of its own, with every method; on a batch the methods
    that read one scene's fields (at ``(z, t)``, export, plots) raise
    :class:`~tubefsi.InvalidParameterError` pointing there."""

    #: The output times (s).
    times: np.ndarray = attrs.field(repr=False)
    #: The nodes (m): 0, the cell centres, L.
    z: np.ndarray = attrs.field(repr=False)
    #: The cell faces (m).
    z_faces: np.ndarray = attrs.field(repr=False)
    #: Pressure at the nodes (Pa), shape ``(len(times), len(z))``.
    pressure_nodes: np.ndarray = attrs.field(repr=False)
    #: Radius at the nodes (m).
    radius_nodes: np.ndarray = attrs.field(repr=False)
    #: Flow rate at the faces (m^3/s), shape ``(len(times), len(z_faces))``.
    flow_faces: np.ndarray = attrs.field(repr=False)
    #: Volume in the tube and the chamber (m^3) at the output times.
    stored: np.ndarray = attrs.field(repr=False)
    #: Volume that entered and left (m^3) since ``times[0]``.
    volume_in: np.ndarray = attrs.field(repr=False)
    volume_out: np.ndarray = attrs.field(repr=False)
    #: Pressure in the outlet chamber (Pa; None without one).
    chamber_pressure: np.ndarray | None = attrs.field(repr=False)
    #: The number of cells and the integrator's relative tolerance of the reported run.
    cells: int
    integrator_rtol: float
    #: The a-posteriori relative error estimates of the inlet history: space and time (``inf``:
    #: not estimated, ``error_control=False``).
    space_error: float
    time_error: float
    #: The largest :math:`|\Delta V_{stored} - \int (q_{in} - q_{out})dt|` relative to the
    #: largest stored-volume change: the mass balance of the reported run.
    mass_error: float
    #: Right-hand-side evaluations of every run of the error control.
    evaluations: int
    _system: _System = attrs.field(repr=False, alias="system")
    _final: tuple = attrs.field(repr=False, alias="final")   # (inlet value, outlet value) at the last time
    #: The scenes' shape (``()``: one scene).
    shape: tuple = ()

    # -------------------------------------------------------------- scenes
    def scene(self, index) -> Transient:
        """Scene ``index`` of a batch (an int or a tuple of ints into :attr:`shape`; a flat int is
        accepted too) as a :class:`Transient` of one scene: the batch's values at that scene, the
        shared cells, times and error estimates."""
        if self.shape == ():
            raise InvalidParameterError("index", "no index: this transient is one scene", index)
        try:
            k = int(np.ravel_multi_index(index, self.shape)) if isinstance(index, tuple) else int(index)
            if isinstance(index, (bool, np.bool_)) or not 0 <= k < math.prod(self.shape):
                raise ValueError
        except (ValueError, TypeError):
            raise InvalidParameterError("index", f"a scene of the batch of shape {self.shape}", index) from None
        sy = self._system
        size = math.prod(self.shape)

        def take(value):
            return None if value is None else value.reshape((size,) + value.shape[len(self.shape):])[k]

        arrays = {f: take(getattr(self, f)) for f in ("z", "z_faces", "pressure_nodes", "radius_nodes", "flow_faces",
                                                      "stored", "volume_in", "volume_out", "chamber_pressure")}
        final = tuple(float(np.ravel(v)[k]) for v in self._final)
        return Transient(times=self.times, cells=self.cells, integrator_rtol=self.integrator_rtol,
                         space_error=self.space_error, time_error=self.time_error, mass_error=self.mass_error,
                         evaluations=self.evaluations, system=sy.scene(k), final=final, **arrays)

    def _one_scene(self, what):
        """Refuse ``what`` on a batch: it is a method of one scene."""
        if self.shape != ():
            raise InvalidParameterError("scene", f"one scene for {what}: take r.scene(k) of the batch of shape "
                                        f"{self.shape}", None)

    # -------------------------------------------------------------- histories
    @property
    def inlet_flow_rate(self) -> np.ndarray:
        """:math:`q(0, t)` (m^3/s) at the output times."""
        return self.flow_faces[..., 0]

    @property
    def outlet_flow_rate(self) -> np.ndarray:
        """:math:`q(L, t)` (m^3/s) at the output times."""
        return self.flow_faces[..., -1]

    @property
    def inlet_pressure(self) -> np.ndarray:
        """:math:`p(0, t)` (Pa) at the output times."""
        return self.pressure_nodes[..., 0]

    @property
    def outlet_pressure(self) -> np.ndarray:
        """:math:`p(L, t)` (Pa) at the output times."""
        return self.pressure_nodes[..., -1]

    @property
    def error_estimate(self) -> float:
        """The estimated relative error of the inlet history (space plus time)."""
        return self.space_error + self.time_error

    # -------------------------------------------------------------- fields
    def _interp(self, nodes, values, z, t):
        self._one_scene("the fields at (z, t)")
        z, t = np.broadcast_arrays(np.asarray(z, dtype=float), np.asarray(t, dtype=float))
        if np.any((z < 0) | (z > nodes[-1])) or not np.all(np.isfinite(z)):
            bad = z[(z < 0) | (z > nodes[-1]) | ~np.isfinite(z)].flat[0]
            raise InvalidParameterError("z", f"[0, L] (m), L = {nodes[-1]:g}", float(bad))
        if np.any((t < self.times[0]) | (t > self.times[-1])) or not np.all(np.isfinite(t)):
            bad = t[(t < self.times[0]) | (t > self.times[-1]) | ~np.isfinite(t)].flat[0]
            raise InvalidParameterError("t", f"[{self.times[0]:g}, {self.times[-1]:g}] (s), the output times' span",
                                        float(bad))
        jz = np.clip(np.searchsorted(nodes, z, side="right") - 1, 0, nodes.size - 2)
        wz = (z - nodes[jz]) / (nodes[jz + 1] - nodes[jz])
        if self.times.size == 1:
            jt, wt = np.zeros(t.shape, dtype=int), np.zeros(t.shape)
        else:
            jt = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self.times.size - 2)
            wt = (t - self.times[jt]) / (self.times[jt + 1] - self.times[jt])
        j1 = jt + (self.times.size > 1)
        at0 = values[jt, jz] * (1 - wz) + values[jt, jz + 1] * wz
        at1 = values[j1, jz] * (1 - wz) + values[j1, jz + 1] * wz
        out = at0 * (1 - wt) + at1 * wt
        return float(out) if out.ndim == 0 else out

    def pressure(self, z, t):
        """Pressure :math:`p(z, t)` (Pa); ``z`` and ``t`` broadcast."""
        return self._interp(self.z, self.pressure_nodes, z, t)

    def radius(self, z, t):
        """Deformed radius :math:`R(z, t)` (m); ``z`` and ``t`` broadcast."""
        return self._interp(self.z, self.radius_nodes, z, t)

    def flow_rate(self, z, t):
        """Flow rate :math:`q(z, t)` (m^3/s); ``z`` and ``t`` broadcast."""
        return self._interp(self.z_faces, self.flow_faces, z, t)

    def stored_volume(self, t=None):
        """Fluid volume in the tube (and the chamber) (m^3), at the output times or at ``t``
        (linear interpolation)."""
        if t is None:
            return self.stored
        self._one_scene("stored_volume(t)")
        t = np.asarray(t, dtype=float)
        if np.any((t < self.times[0]) | (t > self.times[-1])):
            raise InvalidParameterError("t", f"[{self.times[0]:g}, {self.times[-1]:g}] (s)",
                                        float(t[(t < self.times[0]) | (t > self.times[-1])].flat[0]))
        out = np.interp(t, self.times, self.stored)
        return float(out) if out.ndim == 0 else out

    # -------------------------------------------------------------- the steady state
    def _per_scene(self, value):
        """A per-scene number of the system (flat ``(S,)`` for a batch) in the scenes' shape."""
        return value if self.shape == () else np.asarray(value).reshape(self.shape)

    def steady(self) -> Solution | None:
        """The steady state of the boundary values at the last output time.

        - open outlet: a :class:`Solution` of :func:`~tubefsi.solve` with the final inlet pressure
          (a pressure drop to the final outlet pressure) or the final pump flow rate (a batch: one
          solve of the scenes' shape);
        - closed end or chamber behind a pressure inlet: None (no flow; the pressure is uniform,
          the final inlet pressure);
        - closed end or chamber behind a pump that has stopped (final flow rate 0): None (no flow;
          the volume held is what was pumped in, see :meth:`steady_volume`);
        - a pump still running into a closed end or a chamber: no steady state,
          :class:`~tubefsi.NoSteadyStateError` (a batch: naming the first such scene)."""
        sy = self._system
        inlet, outlet = self._final
        where = _scene_text(self.shape)
        if sy.outlet_kind != "pressure":
            running = np.ravel(inlet) != 0.0
            if sy.inlet_kind == "flow" and np.any(running):
                k = int(np.argmax(running))
                raise NoSteadyStateError("flow_rate", 0.0, float(np.ravel(inlet)[k]), "a pump into a closed end or a "
                                         f"chamber fills it without bound{where(k)}", name="the inlet flow rate")
            return None
        common = dict(outlet_pressure=outlet, external_pressure=self._per_scene(sy.external))   # (gauge pressures)
        if sy.inlet_kind == "pressure":
            drop = inlet - outlet
            if np.any(drop < 0):
                k = int(np.argmax(np.ravel(drop) < 0))
                raise InvalidParameterError("inlet_pressure", "a final inlet pressure >= the outlet pressure "
                                            "(for the steady state)", float(np.ravel(inlet)[k]), where(k).strip())
            return solve(sy.rheology, sy.wall, sy.tube, pressure_drop=drop, **common)
        if np.any(np.asarray(inlet) < 0):
            k = int(np.argmax(np.ravel(inlet) < 0))
            raise InvalidParameterError("inlet_flow_rate", "a final flow rate >= 0 (for the steady state)",
                                        float(np.ravel(inlet)[k]), where(k).strip())
        return solve(sy.rheology, sy.wall, sy.tube, flow_rate=inlet, **common)

    def steady_volume(self):
        """The stored volume of :meth:`steady` (m^3; a batch: an array of the scenes' shape):
        :math:`\\int_0^L \\pi R^2 dz` by 64-point Gauss–Legendre quadrature of the steady profile
        (open outlet), the tube (:math:`\\pi a(z)^2\\lambda(p_{in}; z)^2` integrated alike where
        graded) and the chamber at the final inlet pressure (a pressure inlet into a closed end or
        a chamber), or :math:`V(t_0) + \\int q_{in}\\,dt` (a stopped pump into a closed end or a
        chamber: what was pumped in stays). Raises :class:`~tubefsi.NoSteadyStateError` where
        :meth:`steady` does."""
        sy = self._system
        inlet, _ = self._final
        sol = self.steady()
        if sol is None and sy.inlet_kind == "flow":
            # a stopped pump into a closed end or a chamber: mass, V(t0) + the volume pumped in
            held = self.stored[..., 0] + self.volume_in[..., -1]
            return float(held) if self.shape == () else held
        x, w = np.polynomial.legendre.leggauss(64)
        if sol is None:
            chamber = sy.outlet.volume_at(inlet) if sy.outlet_kind == "chamber" else 0.0
            if not sy.graded and self.shape == ():
                lam = 1.0 + float(sy.wall.strain(inlet - sy.external, sy.tb))
                return math.pi * (sy.radius * lam) ** 2 * sy.length + float(chamber)
            # the tube at the uniform pressure: the integral of pi a(z)^2 lambda(p; z)^2 (per scene,
            # the positions (S, 64) and the scenes' numbers as columns)
            z = 0.5 * sy._column(sy.length) * (x + 1.0)
            wall_z, a_z, tb_z = sy.section(z)
            radius = a_z * (1.0 + wall_z.strain(sy._column(np.ravel(inlet) if self.shape else inlet)
                                                - sy._column(sy.external), tb_z))
            volume = 0.5 * sy.length * np.sum(w * math.pi * radius**2, axis=-1)
            return float(volume) + float(chamber) if self.shape == () else self._per_scene(volume) + chamber
        if self.shape == ():
            z = 0.5 * sy.length * (x + 1.0)
            return float(0.5 * sy.length * np.sum(w * math.pi * np.asarray(sol.radius(z)) ** 2))
        # a batch: the nodes (64, *shape) against the Solution of the scenes' shape
        length = self._per_scene(sy.length)
        nodes = (x + 1.0).reshape((64,) + (1,) * len(self.shape))
        radius = np.asarray(sol.radius(0.5 * length * nodes))
        return 0.5 * length * np.tensordot(w, math.pi * radius**2, axes=(0, 0))

    def settling_time(self, fraction: float = 0.9):
        r"""The time (s, from ``times[0]``) after which the stored volume stays within
        ``(1 - fraction)`` of its change to the steady state, :math:`|V(t) - V_\infty| \le
        (1 - f)|V_\infty - V(t_0)|` (linear interpolation between output times); ``inf`` if that
        is not reached by the last output time. The steady state is that of the boundary values at
        the last output time (:meth:`steady`, :meth:`steady_volume`); a pump still running into a
        closed end or a chamber has none: :class:`~tubefsi.NoSteadyStateError`. A batch: an array
        of the scenes' shape.

        The band is never narrower than the run's accuracy, :math:`\epsilon V_s` with
        :math:`\epsilon` the :attr:`error_estimate` (the integrator's tolerance without error
        control) and :math:`V_s` the stored volume's scale (the tube's volume change at the
        problem's pressure scale, plus a chamber's): a volume that close to the steady one is
        settled as far as the run can tell. So a
        run started at its own steady state has settled at 0, and where
        :math:`(1 - f)|V_\infty - V(t_0)|` is narrower than that (a band the run does not resolve,
        for a change above 1 % of its accuracy) the time is that of the accuracy band, with an
        :class:`~tubefsi.AccuracyWarning`."""
        f = as_scalar("fraction", fraction, "(0, 1)", lambda v: (v > 0) & (v < 1))
        v_inf = np.asarray(self.steady_volume())[..., None]
        dev = np.abs(self.stored - v_inf)
        accuracy = self.error_estimate if math.isfinite(self.error_estimate) else self.integrator_rtol
        floor = accuracy * np.reshape(_volume_scale(self._system), np.shape(v_inf))
        change = np.abs(v_inf - self.stored[..., :1])
        # (a change within 1 % of the accuracy: a start at the steady state itself, up to the
        # discretization's gap between the discrete and the quadrature volumes; no warning)
        if np.any(((1.0 - f) * change < floor) & (change > 0.01 * floor)):
            warnings.warn(f"settling_time({f:g}): the band {1.0 - f:.3g} of the volume's change is narrower than "
                          f"the run's accuracy ({accuracy:.2g} of the steady volume); the time to within that "
                          "accuracy is given: lower rtol for a narrower band", AccuracyWarning, stacklevel=2)
        band = np.maximum((1.0 - f) * change, floor)
        outside = dev > band
        count = self.times.size
        # the last output time outside the band, per scene (-1: none)
        last = np.where(np.any(outside, axis=-1), count - 1 - np.argmax(outside[..., ::-1], axis=-1), -1)
        k = np.clip(last, 0, count - 2)[..., None]
        d0, d1 = np.take_along_axis(dev, k, -1)[..., 0], np.take_along_axis(dev, k + 1, -1)[..., 0]
        b = band[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(d0 != d1, (d0 - b) / (d0 - d1), 1.0)
        t0, t1 = self.times[k[..., 0]], self.times[k[..., 0] + 1]
        out = np.where(last == count - 1, math.inf, t0 + w * (t1 - t0) - self.times[0])
        out = np.where((b == 0.0) | (last < 0), 0.0, out)
        return float(out) if self.shape == () else out

    # -------------------------------------------------------------- output
    def to_xarray(self):
        """An :class:`xarray.Dataset` with dimensions ``time`` and ``z`` (the nodes): ``pressure``,
        ``radius``, ``flow_rate`` (interpolated to the nodes) and the histories over ``time``."""
        self._one_scene("to_xarray()")
        try:
            import xarray as xr
        except ImportError:
            raise ImportError("Transient.to_xarray needs xarray: pip install tubefsi[xarray]") from None
        flow = np.stack([np.interp(self.z, self.z_faces, row) for row in self.flow_faces]) \
            if self.times.size else np.zeros((0, self.z.size))
        data = {
            "pressure": (("time", "z"), self.pressure_nodes, {"units": "Pa"}),
            "radius": (("time", "z"), self.radius_nodes, {"units": "m"}),
            "flow_rate": (("time", "z"), flow, {"units": "m^3/s"}),
            "inlet_flow_rate": ("time", self.inlet_flow_rate, {"units": "m^3/s"}),
            "outlet_flow_rate": ("time", self.outlet_flow_rate, {"units": "m^3/s"}),
            "inlet_pressure": ("time", self.inlet_pressure, {"units": "Pa"}),
            "stored_volume": ("time", self.stored, {"units": "m^3"}),
        }
        return xr.Dataset(data, coords={"time": ("time", self.times, {"units": "s"}), "z": ("z", self.z, {"units": "m"})},
                          attrs={"cells": self.cells, "error_estimate": self.error_estimate,
                                 "mass_error": self.mass_error})

    def to_csv(self, path) -> None:
        """Write the histories (time, inlet/outlet flow rate, inlet/outlet pressure, stored volume) as CSV."""
        self._one_scene("to_csv()")
        header = "time_s,inlet_flow_rate_m3_s,outlet_flow_rate_m3_s,inlet_pressure_Pa,outlet_pressure_Pa,stored_volume_m3"
        table = np.column_stack([self.times, self.inlet_flow_rate, self.outlet_flow_rate, self.inlet_pressure,
                                 self.outlet_pressure, self.stored])
        np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.17g")

    def _shown_times(self, times, count=6):
        if times is None:
            return self.times[np.unique(np.linspace(0, self.times.size - 1, min(count, self.times.size)).astype(int))]
        return np.atleast_1d(np.asarray(times, dtype=float))

    def plot(self, times=None, *, fig=None):
        """Pressure and radius along the tube at ``times`` (default: six output times) and the inlet
        and outlet flow rates against time (after the first output time: the flow at the instant
        of a step is singular); returns the figure."""
        self._one_scene("plot()")
        import matplotlib.pyplot as plt

        fig = fig or plt.figure(figsize=(10, 3.2), layout="constrained")
        ax_p, ax_r, ax_q = fig.subplots(1, 3)
        z_mm = 1e3 * self.z
        for t in self._shown_times(times):
            ax_p.plot(z_mm, self.pressure(self.z, t), label=f"t = {t:.3g} s")
            ax_r.plot(z_mm, 1e6 * self.radius(self.z, t))
        ax_p.set(xlabel="z (mm)", ylabel="pressure (Pa)")
        ax_r.set(xlabel="z (mm)", ylabel="radius (µm)")
        ax_p.legend(fontsize="small")
        shown = slice(1, None) if self.times.size > 1 else slice(None)   # (a step's start is singular)
        ax_q.plot(self.times[shown], self.inlet_flow_rate[shown], label="inlet")
        ax_q.plot(self.times[shown], self.outlet_flow_rate[shown], "--", label="outlet")
        ax_q.set(xlabel="t (s)", ylabel="flow rate (m$^3$/s)")
        ax_q.legend(fontsize="small")
        return fig

    def animate(self, *, interval: float = 50.0, fig=None):
        """A :class:`matplotlib.animation.FuncAnimation` of pressure and radius along the tube over
        the output times (returned, not saved: ``anim.save("inflation.gif")``)."""
        self._one_scene("animate()")
        import matplotlib.pyplot as plt
        from matplotlib.animation import FuncAnimation

        fig = fig or plt.figure(figsize=(8, 3.2), layout="constrained")
        ax_p, ax_r = fig.subplots(1, 2)
        z_mm = 1e3 * self.z
        (line_p,) = ax_p.plot(z_mm, self.pressure_nodes[0])
        (line_r,) = ax_r.plot(z_mm, 1e6 * self.radius_nodes[0])
        ax_p.set(xlabel="z (mm)", ylabel="pressure (Pa)", ylim=_limits(self.pressure_nodes))
        ax_r.set(xlabel="z (mm)", ylabel="radius (µm)", ylim=_limits(1e6 * self.radius_nodes))
        title = fig.suptitle("")

        def frame(k):
            line_p.set_ydata(self.pressure_nodes[k])
            line_r.set_ydata(1e6 * self.radius_nodes[k])
            title.set_text(f"t = {self.times[k]:.4g} s")
            return line_p, line_r, title

        return FuncAnimation(fig, frame, frames=self.times.size, interval=interval, blit=False)


def _limits(values):
    lo, hi = float(np.min(values)), float(np.max(values))
    pad = 0.05 * (hi - lo) if hi > lo else 0.05 * max(abs(hi), 1.0)
    return lo - pad, hi + pad


# ----------------------------------------------------------------------------------- the driver
def _run(system: _System, times, y0, rtol, method):
    """One integration: ``(Transient fields dict, rhs evaluations)``."""
    n = system.n
    Y0 = system._states(y0)
    # the tolerances per scene: the cells' area strain, the chamber's pressure, the volume counters
    s_scale = np.maximum(np.max(np.abs(Y0[:, :n]), axis=1), _area_strain_scale(system))
    atol = np.empty(Y0.shape)
    atol[:, :n] = (rtol * s_scale)[:, None]
    # the volume counters: to the tolerance of the stored volume's change
    volume_scale = math.pi * system.radius**2 * system.length * s_scale
    if system.outlet_kind == "chamber":
        atol[:, n] = rtol * system.pressure_scale
        volume_scale = volume_scale + system.outlet.compliance_at(Y0[:, n], system.pressure_scale) * system.pressure_scale
    atol[:, -2:] = (rtol * volume_scale)[:, None]
    atol = atol.reshape(-1)
    span = (float(times[0]), float(times[-1]))
    if span[1] == span[0]:
        ys = y0[:, None]
        nfev = 0
    else:
        res = integrate.solve_ivp(system.rhs, span, y0, method=method, t_eval=times, rtol=rtol, atol=atol,
                                  jac=system.jacobian)
        if res.status != 0 or res.y.shape[1] != times.size:
            reached = float(res.t[-1]) if res.t.size else span[0]
            raise ConvergenceError(f"the time integration stopped after t = {reached:.6g} s: {res.message} (where "
                                   "smaller steps cannot keep the tube within the wall's range, the boundary values "
                                   "drive it beyond its limit pressure or its buckling bound)")
        ys, nfev = res.y, res.nfev
    return _fields(system, times, ys), nfev


def _area_strain_scale(system):
    """The area strain at the pressure scale (at most half the wall's limit pressure: the scale is
    a magnitude, and a suction's may exceed the limit of inflation); per scene for a batch."""
    wall, _, tb = system.section(system._column(np.zeros(system.scenes)) if system.shape else 0.0)
    limit = np.asarray(wall.limit_pressure(tb), dtype=float).reshape(-1)
    p = np.minimum(system.pressure_scale, 0.5 * limit)                 # (the inlet's tube law: a scale)
    lam = 1.0 + np.asarray(wall.strain(system._column(p), tb), dtype=float).reshape(-1)
    out = lam * lam - 1.0
    return float(out[0]) if system.shape == () else out


def _fields(system, times, ys):
    """The fields of the states ``ys`` (``(S size, len(times))``) at the output times: arrays
    ``(len(times), nodes)`` for one scene, ``(S, len(times), nodes)`` for a batch."""
    n, batch = system.n, system.shape != ()
    Y = ys.reshape(system.scenes, system.size, -1)
    if batch:                                     # (time, scene, cell) while computing
        Y = Y.transpose(2, 0, 1)
        tt = np.broadcast_to(times[:, None], (times.size, system.scenes))
    else:
        Y = Y[0].T
        tt = times
    s = Y[..., :n]
    chamber = Y[..., n] if system.outlet_kind == "chamber" else None
    p, lam, q = system.fluxes(tt, s, chamber)
    # the boundary nodes: the pressure the boundary holds (a pump's from the flux of the half cell)
    if system.inlet_kind == "pressure":
        p0 = _elementwise(system.inlet, tt, "inlet_pressure")
    else:
        a0 = np.broadcast_to(system.a_faces, (system.scenes, system.n + 1))[:, 0] if batch \
            else np.broadcast_to(system.a_faces, (system.n + 1,))[0]
        g = system.scene_rheology.pressure_gradient(np.abs(q[..., 0]), a0 * lam[..., 0]) * np.sign(q[..., 0])
        p0 = p[..., 0] + 0.5 * system.dz * g
    if system.outlet_kind == "pressure":
        pl = _elementwise(system.outlet, tt, "outlet_pressure")
    elif system.outlet_kind == "chamber":
        pl = chamber
    else:
        pl = p[..., -1]
    ends = np.stack([p0, pl], axis=-1)
    z_ends = np.stack([np.zeros(system.scenes), system.length], axis=-1) if batch else [0.0, system.length]
    wall_ends, a_ends, tb_ends = system.section(z_ends)                 # (the wall's law at z = 0 and L)
    lam_ends = 1.0 + wall_ends.strain(ends - system._column(system.external), tb_ends)
    pressure = np.concatenate([p0[..., None], p, pl[..., None]], axis=-1)
    radius_ends = a_ends * lam_ends
    radius = np.concatenate([radius_ends[..., :1], system.a_cells * lam, radius_ends[..., 1:]], axis=-1)
    if system.graded:
        stored = np.sum(system.cell_volumes * (1.0 + s), axis=-1)
    else:
        area0 = math.pi * system.radius**2
        stored = area0 * system.dz * np.sum(1.0 + s, axis=-1)
    if chamber is not None:
        held = system.outlet.volume_at(chamber)
        if np.any(held < 0):
            k = tuple(np.argwhere(held < 0)[0])
            raise InvalidParameterError("outlet", "a chamber whose volume V(p) stays >= 0", float(held[k]),
                                        f"the outlet chamber empties: V = {held[k]:.6g} m^3 at p = {chamber[k]:.6g} "
                                        f"Pa (t = {times[k[0]]:.6g} s){_scene_text(system.shape)(k[-1]) if batch else ''}")
        stored = stored + held
    v_in, v_out = Y[..., -2], Y[..., -1]
    change = stored - stored[0]
    # (the chamber is part of the store: what leaves the tube into it stays)
    balance = change - (v_in - (0.0 if chamber is not None else v_out))
    scale = np.maximum(np.maximum(np.max(np.abs(change), axis=0), np.max(np.abs(v_in), axis=0)), np.finfo(float).tiny)
    out = dict(pressure_nodes=pressure, radius_nodes=radius, flow_faces=q, stored=stored,
               volume_in=v_in, volume_out=v_out, chamber_pressure=chamber)
    if batch:                                     # the scene axis first: (scene, time, node)
        out = {k: None if v is None else np.moveaxis(v, 1, 0) for k, v in out.items()}
    out["mass_error"] = float(np.max(np.max(np.abs(balance), axis=0) / scale))
    return out


def _monitored(system, fields, times):
    """The inlet history the error control watches: the flow rate behind a pressure inlet, the
    pressure behind a pump (the initial instant left out: a step's flow is singular there; so are
    the output times where a pressure inlet jumps, its values just before and after differing by
    more than 1e-6 of the pressure scale)."""
    h = fields["flow_faces"][..., 0] if system.inlet_kind == "pressure" else fields["pressure_nodes"][..., 0]
    keep = np.ones(h.shape[-1], dtype=bool)
    keep[0] = h.shape[-1] == 1
    if system.inlet_kind == "pressure":
        delta = 1e-9 * max(float(times[-1] - times[0]), float(np.max(np.abs(times))))
        jump = np.abs(system.boundary(system.inlet, times + delta, "inlet_pressure")
                      - system.boundary(system.inlet, times - delta, "inlet_pressure"))
        steady = jump <= 1e-6 * system.pressure_scale          # (a batch: (times, scenes), each its scale)
        keep &= steady if steady.ndim == 1 else np.all(steady, axis=1)
    return h[..., keep] if np.any(keep) else h[..., -1:]


def _difference(a, b, floor=0.0):
    """The largest :math:`|a - b|` relative to the history's scale: its largest :math:`|b|`, but at
    least ``floor`` (:func:`_history_scale`), not pointwise: a history that decays to ~0 (a
    relaxation) is measured against the flow or pressure the problem drives, not against noise."""
    scale = np.maximum(np.maximum(np.max(np.abs(b), axis=-1), floor), np.finfo(float).tiny)
    return float(np.max(np.max(np.abs(a - b), axis=-1) / scale))     # (a batch: the largest over the scenes)


def _volume_scale(system):
    """The stored volume's scale (m^3, per scene for a batch): the inlet section's area strain at
    the pressure scale (:func:`_area_strain_scale`) times the tube's volume, plus a chamber's volume
    change over the pressure scale."""
    scale = math.pi * np.asarray(system.radius) ** 2 * system.length * np.abs(_area_strain_scale(system))
    if system.outlet_kind == "chamber":
        ps = np.asarray(system.pressure_scale, dtype=float)
        scale = scale + np.abs(np.asarray(system.outlet.volume_at(ps), dtype=float)
                               - np.asarray(system.outlet.volume_at(0.0 * ps), dtype=float))
    return float(scale) if system.shape == () else np.asarray(scale, dtype=float)


def _history_scale(system):
    r"""The scale of the watched inlet history: behind a pressure inlet the flow rate the tube
    carries under the problem's pressure scale over its length, :math:`Q(p_s/L, a)` (rigid
    radius); behind a pump its pressure scale :math:`p_s`."""
    if system.inlet_kind == "flow":
        scale = system.pressure_scale
    else:
        scale = system.scene_rheology.flow_rate(system.radius, system.pressure_scale / system.length)
    return float(scale) if system.shape == () else np.asarray(scale, dtype=float)


@checked_keywords
def evolve(rheology, wall, tube: Tube, times, *, inlet_pressure=None, inlet_flow_rate=None,
           outlet_pressure=None, outlet="open", external_pressure: float = 0.0, initial=None,
           rtol: float = 1e-6, cells: int | None = None, method: str = "BDF", density: float | None = None,
           error_control: bool = True) -> Transient:
    r"""Integrate the transient flow through a soft tube from ``times[0]`` to ``times[-1]``.

    Solves :math:`C(p)\,\partial_t p = \partial_z Q(-\partial_z p, R(p))` (mass conservation,
    the rheology's tube flow function :math:`Q` and the wall's tube law, ``docs/transients.md``).

    Parameters
    ----------
    rheology, wall : model instance, class or registered name
    tube : Tube
        Radius and thickness numbers or functions of z (a graded tube: each cell its own radius
        and tube law, ``docs/transients.md``), or arrays (one per scene); length a number or an
        array (one per scene). A wall's parameters may be functions of z too.
    times : array_like
        At least two increasing output times (s); the integration starts at ``times[0]`` from
        ``initial``.
    inlet_pressure : float, array or callable of t, optional
        Gauge pressure at the inlet :math:`p(0, t)` (Pa); an array: one constant per scene.
    inlet_flow_rate : float, array or callable of t, optional
        Flow rate pumped in :math:`q(0, t)` (m^3/s). Exactly one of the two inlets.
    outlet : {"open", "closed"}, Chamber or callable
        ``"open"``: the outlet pressure ``outlet_pressure`` holds at :math:`z = L`; ``"closed"``: a
        dead end, :math:`q(L) = 0`; a :class:`Chamber` or a callable :math:`V(p)` (m^3): a chamber
        filled by the outlet flow.
    outlet_pressure : float, array or callable of t, optional
        The outlet's gauge pressure (Pa) for ``outlet="open"`` (default 0); refused with a closed
        end or a chamber (they set their own pressure).
    external_pressure : float or array
        :math:`p_e` (Pa): the wall sees :math:`p - p_e`.
    initial : None, float, array or Solution
        ``None``: at rest at the outlet pressure (open) or at 0 (closed, chamber); a number: at rest
        at that pressure (Pa; an array: one per scene); a steady :class:`Solution` of the same
        fluid, wall, tube and external pressure (compared by value, a profile along z by identity,
        else :class:`InvalidParameterError`): its profile. A starting
        or boundary pressure below the wall's buckling bound raises :class:`~tubefsi.BucklingError`.
    rtol : float
        Requested relative accuracy of the inlet history (the flow rate behind a pressure inlet,
        the pressure behind a pump), relative to its scale (its largest value, at least the flow
        the tube carries under the problem's pressure scale; the pressure scale behind a pump).
    cells : int, optional
        The coarsest grid of the refinement (default 16; at most ``MAX_CELLS / 4``: the error
        control runs ``cells``, twice and four times as many); with ``error_control=False``, the
        cells of the one run.
    method : {"BDF", "Radau"}
        The stiff integrator of :func:`scipy.integrate.solve_ivp`.
    density : float, optional
        Fluid density (kg/m^3): warns (:class:`~tubefsi.ModelValidityWarning`) where the
        Womersley number :math:`a\sqrt{\rho/(\mu t_c)}` exceeds :data:`WOMERSLEY` or the reduced
        Reynolds number :math:`Re\,a/L` exceeds :data:`~tubefsi.validity.REDUCED_REYNOLDS`.
    error_control : bool
        ``False``: one run at ``cells`` and the integrator tolerance ``rtol`` (no estimate).

    Returns
    -------
    Transient
        Arrays of scene parameters (the boundary values above as numbers, ``external_pressure``,
        ``initial`` as pressures, the tube's radius, thickness and length, the rheology's and the
        wall's parameters) broadcast together to the scenes' shape ``S`` and run as one batch:
        the result's ``shape`` is ``S``, its fields ``(*S, len(times), nodes)``, its histories
        ``(*S, len(times))``, its nodes ``(*S, nodes)``, the cells, times and error estimates
        (the largest over the scenes) shared; ``r.scene(k)`` is one scene. Callables of t,
        the chamber, ``density`` and a wall's profiles are shared by the scenes; a starting
        Solution with a batch, arrays that do not broadcast, and array parameters of models
        whose hooks do not broadcast (``broadcasts = False``) raise
        :class:`~tubefsi.InvalidParameterError` naming them.
        With error control: the fields inside the tube of the finest run (``cells`` is its
        count), the boundary histories (inlet and outlet flow, pressure and radius, the chamber
        pressure, the stored volume, the volumes in and out) Richardson-extrapolated from the two
        finest runs, :math:`h_{4n} + (h_{4n} - h_{2n})/3`.
    """
    if density is not None:
        density = positive_scalar("density", density)
    rheo = resolve("rheology", rheology)
    wall_model = resolve("wall", wall)
    system, times, y0_of, rtol, method = _setup(rheo, wall_model, tube, times, inlet_pressure, inlet_flow_rate,
                                                outlet_pressure, outlet, external_pressure, initial, rtol, method,
                                                cells)
    n = system.n
    if error_control and 4 * n > MAX_CELLS:
        raise InvalidParameterError("cells", f"[2, {MAX_CELLS // 4}] with error control (its finest run has four "
                                    "times the cells)", cells)
    if not error_control:
        fields, nfev = _run(system, times, y0_of(system), rtol, method)
        return _result(system, times, fields, n, rtol, math.inf, math.inf, nfev, density)
    # (at looser integrator tolerances BDF's error is far from proportional to the tolerance: the
    # time estimate fails there and costs a run; benchmarks/transient.py)
    tol = min(0.1 * rtol, 1e-4)
    runs = {}                      # (cells, integrator tolerance) -> (fields, rhs evaluations), this call's

    def run(cells, tolerance):
        if (cells, tolerance) not in runs:
            sys_n = attrs.evolve(system, n=cells)
            runs[cells, tolerance] = _run(sys_n, times, y0_of(sys_n), tolerance, method)
        return runs[cells, tolerance][0]

    while True:
        # the reported runs: n, 2n, 4n cells at tol/10; the time estimate: n cells at tol and tol/10
        loose, coarse, middle, fine = run(n, tol), run(n, 0.1 * tol), run(2 * n, 0.1 * tol), run(4 * n, 0.1 * tol)
        h1, h2, h4 = (_monitored(system, f, times) for f in (coarse, middle, fine))
        floor = _history_scale(system)
        # space: the Richardson extrapolations of the pairs (n, 2n) and (2n, 4n); their difference d
        # is the coarser pair's error minus the finer pair's: for an order p >= 2 (third order
        # asymptotically) the finer pair's error is at most d / (2^p - 1) <= d / 3
        e_space = _difference(_extrapolated(h1, h2), _extrapolated(h2, h4), floor) / 3.0
        # time: the error of the run at tol, conservative for the reported ones at tol/10; the
        # extrapolation (4 h_4n - h_2n)/3 adds the time errors of two runs with weights 4/3 and 1/3
        e_time = 5.0 / 3.0 * _difference(_monitored(system, loose, times), h1, floor)
        total = sum(nfev for _, nfev in runs.values())
        fine_sys = attrs.evolve(system, n=4 * n)
        if e_space + e_time <= rtol:
            return _result(fine_sys, times, _extrapolated_fields(middle, fine), fine_sys.n, 0.1 * tol, e_space,
                           e_time, total, density)
        grow_space = e_space > 0.5 * rtol and 8 * n <= MAX_CELLS
        grow_time = e_time > 0.5 * rtol and tol > _MIN_RTOL
        if not (grow_space or grow_time):
            warn_user(f"evolve: the estimated relative error of the inlet history, {e_space + e_time:.2g} "
                      f"(space {e_space:.2g} at {fine_sys.n} cells, time {e_time:.2g}), misses rtol = {rtol:g}",
                      AccuracyWarning)
            return _result(fine_sys, times, _extrapolated_fields(middle, fine), fine_sys.n, 0.1 * tol, e_space,
                           e_time, total, density)
        if grow_space:
            # the extrapolated values converge at third order: the cells for the target, as a power of two
            factor = (e_space / (0.4 * rtol)) ** (1.0 / 3.0)
            n = min(n * 2 ** max(1, math.ceil(math.log2(factor))), MAX_CELLS // 4)
        if grow_time:
            tol = max(0.1 * tol, _MIN_RTOL)


def _extrapolated(coarse, fine):
    """The Richardson extrapolation :math:`(4 h_{2n} - h_n)/3` of a second-order quantity."""
    return fine + (fine - coarse) / 3.0


#: The histories at the ends of the tube, the same points on every grid: extrapolated.
_HISTORIES = ("stored", "volume_in", "volume_out", "chamber_pressure")


def _extrapolated_fields(middle, fine):
    """The fields of the run on 4n cells with the boundary histories (the flow rate, pressure and
    radius at the inlet and the outlet, the stored volume, the volumes in and out, the chamber
    pressure) Richardson-extrapolated from the runs on 2n and 4n cells; the mass error is the run's."""
    out = dict(fine)
    for key in _HISTORIES:
        if fine[key] is not None:
            out[key] = _extrapolated(middle[key], fine[key])
    for key in ("pressure_nodes", "radius_nodes", "flow_faces"):
        values = fine[key].copy()
        values[..., [0, -1]] = _extrapolated(middle[key][..., [0, -1]], fine[key][..., [0, -1]])
        out[key] = values
    return out


def _result(system, times, fields, cells, tol, e_space, e_time, total, density):
    shape = system.shape
    final_in = system.boundary(system.inlet, times[-1], "inlet")
    final_out = system.boundary(system.outlet, times[-1], "outlet_pressure") if system.outlet_kind == "pressure" \
        else np.full(np.shape(final_in), math.nan)
    if shape == ():
        final = (float(final_in), float(final_out))
        z = np.concatenate([[0.0], system.z, [system.length]])
        z_faces = np.arange(system.n + 1) * system.dz
    else:
        # a batch: the scene axes first, (*shape, times, nodes)
        final = (final_in.reshape(shape), final_out.reshape(shape))
        z = np.concatenate([np.zeros((system.scenes, 1)), system.z, system.length[:, None]], axis=1)
        z = z.reshape(shape + z.shape[-1:])
        z_faces = (np.arange(system.n + 1) * system._column(system.dz)).reshape(shape + (system.n + 1,))
        fields = {k: v.reshape(shape + v.shape[1:]) if isinstance(v, np.ndarray) else v for k, v in fields.items()}
    out = Transient(times=times, z=z, z_faces=z_faces, cells=cells, integrator_rtol=tol, shape=shape,
                    space_error=e_space, time_error=e_time, evaluations=total, system=system, final=final, **fields)
    if density is not None:
        _check_validity(out, float(density))
    return out


def _setup(rheo, wall, tube, times, inlet_pressure, inlet_flow_rate, outlet_pressure, outlet, external_pressure,
           initial, rtol, method, cells):
    if not isinstance(tube, Tube):
        raise InvalidParameterError("tube", "a tubefsi.Tube", tube)
    if getattr(wall, "is_rigid", False):
        raise InvalidParameterError("wall", "a compliant wall", wall, "a rigid wall stores no volume: a transient "
                                    "needs a compliant wall or a chamber")
    times = real_array("times", times, "an array of at least 2 finite, increasing times (s)")
    if times.ndim != 1 or times.size < 2 or not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise InvalidParameterError("times", "a 1-d array of at least 2 finite, increasing times (s)", times)
    rtol = positive_scalar("rtol", rtol)
    if not (1e-12 <= rtol < 1):
        raise InvalidParameterError("rtol", "[1e-12, 1)", rtol)
    if method not in ("BDF", "Radau"):
        raise InvalidParameterError("method", "{'BDF', 'Radau'}", method)
    if (inlet_pressure is None) == (inlet_flow_rate is None):
        raise InvalidParameterError("inlet_pressure / inlet_flow_rate", "exactly one of the two", None)
    inlet_kind = "pressure" if inlet_pressure is not None else "flow"
    inlet_name = "inlet_pressure" if inlet_kind == "pressure" else "inlet_flow_rate"
    inlet, inlet_shape = _boundary(inlet_name, inlet_pressure if inlet_kind == "pressure" else inlet_flow_rate)
    if outlet_pressure is not None and not (isinstance(outlet, str) and outlet == "open"):
        raise InvalidParameterError("outlet_pressure", "None unless outlet='open'", outlet_pressure,
                                    "a closed end or a chamber sets its own pressure")
    outlet_shape = ()
    if isinstance(outlet, str) and outlet == "open":
        outlet_kind = "pressure"
        outlet_value, outlet_shape = _boundary("outlet_pressure", 0.0 if outlet_pressure is None else outlet_pressure)
    elif isinstance(outlet, str) and outlet == "closed":
        outlet_kind, outlet_value = "closed", None
    elif isinstance(outlet, Chamber):
        outlet_kind, outlet_value = "chamber", outlet
    elif callable(outlet):
        outlet_kind, outlet_value = "chamber", Chamber(volume=outlet)
    else:
        raise InvalidParameterError("outlet", "'open', 'closed', a Chamber or a callable V(p)", outlet)
    p_ext = _finite("external_pressure", external_pressure, "finite numbers (Pa), one or one per scene")
    if cells is not None and (isinstance(cells, (bool, np.bool_)) or not isinstance(cells, (int, np.integer))):
        raise InvalidParameterError("cells", f"an integer in [2, {MAX_CELLS}]", cells)
    n = 16 if cells is None else int(cells)
    if not (2 <= n <= MAX_CELLS):
        raise InvalidParameterError("cells", f"[2, {MAX_CELLS}]", cells)
    if initial is not None and not isinstance(initial, Solution):
        initial = _finite("initial", initial, "None, finite pressures (Pa) or a steady Solution of the same tube")
    shape = _scene_shape(rheo, wall, tube, {inlet_name: inlet_shape, "outlet_pressure": outlet_shape,
                                            "external_pressure": p_ext.shape,
                                            "initial": np.shape(initial) if isinstance(initial, np.ndarray) else ()})
    S = math.prod(shape)
    inlet = _per_scene_function(inlet, shape)
    if outlet_kind == "pressure":
        outlet_value = _per_scene_function(outlet_value, shape)
    if shape != () and isinstance(initial, Solution):
        raise InvalidParameterError("initial", "None or pressures (Pa) for a batch of scenes", initial,
                                    "a steady Solution starts one scene")

    def per_scene(x):         # a number or an array of scenes as (S,)
        return np.broadcast_to(np.asarray(x, dtype=float), shape).reshape(S)

    p_ext_s = per_scene(p_ext)
    length = per_scene(tube.length)
    # the tube's sections: the inlet's radius and t/a for the scales, the walls along z (a graded
    # tube: 257 positions and its profiles' breakpoints) for the pressure bounds; per scene (S, k)
    a = np.broadcast_to(_tube_at(tube, np.zeros((S, 1)), shape or (1,))[0], (S, 1))[:, 0]
    along = _positions(wall, tube) * length[:, None]
    wall_z, _, tb_z = _section(wall, tube, along, shape or (1,))
    t0 = times[0]
    # the boundary values at 33 times, (33, S)
    sample = np.broadcast_to(np.linspace(times[0], times[-1], 33)[:, None], (33, S))
    p_rest = (_elementwise(outlet_value, np.full(S, t0), "outlet_pressure") if outlet_kind == "pressure"
              else np.zeros(S))
    # the pressure scale: the largest boundary pressure met, or a pump's steady inlet pressure
    if inlet_kind == "pressure":
        scale = np.max(np.abs(_elementwise(inlet, sample, "inlet_pressure") - p_ext_s), axis=0)
    else:
        q = np.max(np.abs(_elementwise(inlet, sample, "inlet_flow_rate")), axis=0)
        drop = np.zeros(S)
        moving = q > 0
        if np.any(moving):
            g = _scene_model(rheo, shape or (1,)).pressure_gradient(np.where(moving, q, 1.0), a)
            drop = np.where(moving, np.broadcast_to(g, (S,)) * length, 0.0)
        scale = drop
    if outlet_kind == "pressure":
        scale = np.maximum(scale, np.max(np.abs(_elementwise(outlet_value, sample, "outlet_pressure") - p_ext_s),
                                         axis=0))
    scale = np.maximum(scale, np.abs(p_rest - p_ext_s))
    if isinstance(initial, Solution):
        _check_initial(initial, rheo, wall, tube, float(p_ext))
    elif initial is not None:
        scale = np.maximum(scale, np.abs(per_scene(initial) - p_ext_s))
    if np.any(scale == 0.0):      # nothing drives the tube (at rest at p_e): the pressure of a strain 1e-6
        modulus = np.min(np.broadcast_to(wall_z.small_strain_modulus(tb_z), along.shape), axis=1)
        scale = np.where(scale == 0.0, 1e-6 * modulus, scale)
    # the lowest transmural pressure met at the boundaries and at the start: not below buckling
    # and not at or above the wall's limit pressure (signed: a large suction is buckling, above)
    start = p_rest if initial is None else (per_scene(initial) if not isinstance(initial, Solution)
                                            else np.full(S, float(initial.pressure(float(length[0])))))
    met = [start[None]]
    if inlet_kind == "pressure":
        met.append(_elementwise(inlet, sample, "inlet_pressure"))
    if outlet_kind == "pressure":
        met.append(_elementwise(outlet_value, sample, "outlet_pressure"))
    low = np.min(np.concatenate(met), axis=0) - p_ext_s
    high = np.max(np.concatenate(met), axis=0) - p_ext_s
    bound = np.max(np.broadcast_to(wall_z.min_pressure(tb_z), along.shape), axis=1)
    where = _scene_text(shape)
    if np.any(low < bound):
        k = int(np.argmax(low < bound))
        raise BucklingError(float(bound[k]), float(low[k]), "a boundary or starting pressure minus "
                            f"external_pressure is below it{where(k)}")
    limit = np.min(np.broadcast_to(wall_z.limit_pressure(tb_z), along.shape), axis=1)
    if np.any(high >= limit):
        k = int(np.argmax(high >= limit))
        raise NoSteadyStateError("pressure", float(limit[k]), float(high[k]), f"a boundary or starting transmural "
                                 f"pressure; {type(wall).__name__} cannot sustain it{where(k)}")
    if shape == ():
        p_ext_s, scale, start = float(p_ext_s[0]), float(scale[0]), float(start[0])
    system = _System(rheology=rheo, wall=wall, tube=tube, external=p_ext_s, n=n,
                     inlet_kind=inlet_kind, inlet=inlet, outlet_kind=outlet_kind, outlet=outlet_value,
                     pressure_scale=scale, shape=shape)
    if isinstance(initial, Solution):
        start = initial

    def y0_of(sys_):
        return sys_.initial_state(start, t0)

    return system, times, y0_of, rtol, method


def _scene_text(shape):
    """``where(k)``: the text naming scene ``k`` (flat) of a batch, empty for one scene."""
    def where(k):
        return "" if shape == () else f" (scene {tuple(int(i) for i in np.unravel_index(k, shape))} of shape {shape})"
    return where


def _scene_shape(rheo, wall, tube, boundaries):
    """The scenes' shape: the broadcast shape of the array parameters of the rheology, the wall and
    the tube and of the boundary values, the external and the starting pressure (``()``: one
    scene). Arrays that do not broadcast together, and array parameters of a model whose hooks do
    not broadcast over them, raise :class:`InvalidParameterError` naming them."""
    shapes = {f"tube.{k}": np.shape(v) for k in ("length", "radius", "thickness")
              if isinstance(v := getattr(tube, k), np.ndarray) and v.ndim}
    for kind, model in (("rheology", rheo), ("wall", wall)):
        arrays = {f"{kind}.{k}": v.shape for k in _array_fields(type(model))
                  if isinstance(v := getattr(model, k), np.ndarray) and v.ndim}
        broadcasts = getattr(type(model), "broadcasts", True)
        if kind == "rheology":          # (a law whose flow table is built per fluid: one fluid per call)
            broadcasts = broadcasts and (model.separable or flow_map_kind(model) is not None)
        if arrays and not broadcasts:
            raise InvalidParameterError(kind, "numbers for its parameters (its hooks do not broadcast over "
                                        "arrays of scenes)", model, f"{', '.join(arrays)} are arrays")
        shapes.update(arrays)
    if varies(wall) and not getattr(type(wall), "broadcasts", True):
        raise InvalidParameterError("wall", "a wall whose hooks broadcast over its parameters, to vary along z",
                                    wall, f"{type(wall).__name__} has broadcasts = False")
    shapes.update({k: s for k, s in boundaries.items() if s != ()})
    shape = ()
    for name, s in shapes.items():          # (the first array that does not broadcast with those before it)
        if 0 in s:
            raise InvalidParameterError(name, "an array of at least one scene", None, f"an empty array of shape {s}")
        try:
            shape = np.broadcast_shapes(shape, s)
        except ValueError:
            raise InvalidParameterError(name, f"an array of scenes that broadcasts with the others' shape {shape}",
                                        None, "; ".join(f"{k} has shape {v}" for k, v in shapes.items())) from None
    return shape


def _positions(wall, tube):
    """Fractions of the length where the tube's sections are checked: the inlet for a uniform tube;
    257 positions and the profiles' breakpoints inside the tube for a graded one."""
    profiles = [v for v in (tube.radius, tube.thickness) if isinstance(v, Profile)]
    profiles += [getattr(wall, k) for k in _array_fields(type(wall)) if isinstance(getattr(wall, k), Profile)]
    if not profiles:
        return np.zeros(1)
    length = float(np.max(tube.length))
    breaks = [b / length for p in profiles for b in p.breakpoints if 0.0 < b < length]
    return np.unique(np.concatenate([np.linspace(0.0, 1.0, 257), breaks]))


def _check_initial(initial, rheo, wall, tube, p_ext):
    """A starting Solution must be of the same fluid, wall, tube and external pressure (by value)."""
    other = initial.tube
    differs = []
    if initial.rheology != rheo:
        differs.append(f"its rheology {initial.rheology!r} is not {rheo!r}")
    if initial.wall != wall:
        differs.append(f"its wall {initial.wall!r} is not {wall!r}")
    for field in ("radius", "thickness", "length"):
        mine, theirs = getattr(tube, field), getattr(other, field)
        if isinstance(mine, Profile) or isinstance(theirs, Profile):
            if theirs is not mine:          # (a profile compares by identity: the same tube's)
                differs.append(f"its tube {field} {theirs!r} is not {mine!r}")
        elif np.ndim(theirs) or float(theirs) != float(mine):
            differs.append(f"its tube {field} {theirs!r} is not {float(mine)!r}")
    if np.ndim(initial.external_pressure) or float(initial.external_pressure) != p_ext:
        differs.append(f"its external pressure {initial.external_pressure!r} Pa is not {p_ext!r}")
    if np.ndim(initial.pressure_drop) or not math.isfinite(float(initial.pressure_drop)):
        differs.append("it is not one steady state of finite pressures")
    if differs:
        raise InvalidParameterError("initial", "a steady Solution of the same fluid, wall, tube and external pressure",
                                    None, "; ".join(differs))


def _check_validity(result: Transient, density: float) -> None:
    r"""Warn where the quasi-steady, inertia-free model fails: the Womersley number
    :math:`a\sqrt{\rho/(\mu t_c)}` with the apparent viscosity at the inlet's largest flow and the
    process time :math:`t_c` (the 50 % settling time, else the span), and :math:`Re\,a/L`; a batch:
    per scene, the warning naming the largest and its scene."""
    sy = result._system
    flows = np.abs(result.inlet_flow_rate).reshape(sy.scenes, -1)
    k = np.argmax(flows, axis=-1)[:, None]
    q = np.take_along_axis(flows, k, -1)[:, 0]
    r = np.take_along_axis(result.radius_nodes[..., 0].reshape(sy.scenes, -1), k, -1)[:, 0]
    moving = q > 0.0
    if not np.any(moving):
        return
    q, r = np.where(moving, q, 1.0), r            # (a scene at rest: no flow, nothing to check)
    g = np.broadcast_to(sy.scene_rheology.pressure_gradient(q, r), q.shape)
    tau_w = 0.5 * g * r
    rate = 4.0 * q / (math.pi * r**3)
    mu = tau_w / rate
    try:
        t_c = np.ravel(result.settling_time(0.5)).astype(float)
    except (InvalidParameterError, NoSteadyStateError):
        t_c = np.full(sy.scenes, math.inf)
    t_c = np.where(np.isfinite(t_c) & (t_c > 0), t_c, float(result.times[-1] - result.times[0]))
    womersley = np.where(moving, sy.radius * np.sqrt(density / (mu * t_c)), 0.0)
    velocity = q / (math.pi * r * r)
    reduced_re = np.where(moving, 8.0 * density * velocity**2 / tau_w * r / sy.length, 0.0)
    where = _scene_text(result.shape)
    j = int(np.argmax(womersley))
    if womersley[j] > WOMERSLEY:
        warn_user(f"evolve: the Womersley number a*sqrt(rho/(mu t_c)) = {womersley[j]:.3g} exceeds {WOMERSLEY} "
                  f"(t_c = {t_c[j]:.3g} s){where(j)}: fluid inertia is not negligible on this time scale",
                  ModelValidityWarning)
    j = int(np.argmax(reduced_re))
    if reduced_re[j] > REDUCED_REYNOLDS:
        warn_user(f"evolve: the reduced Reynolds number Re a/L = {reduced_re[j]:.3g} exceeds {REDUCED_REYNOLDS}"
                  f"{where(j)}: inertia is not negligible", ModelValidityWarning)
