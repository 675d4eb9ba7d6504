r"""The separated-variables engine shared by the ``closed-form`` and ``quadrature`` couplers.

Lubrication theory gives :math:`dp/dz = -G(q, R(p))` with :math:`p(L) = p_{out}`. Writing the
tube law :math:`p = P(\lambda)` and the log-stretch :math:`u = \ln(\lambda/\lambda_{out})`
separates the variables (``docs/theory.md``, section "Coupling without an ODE"):

.. math::

    L - z = \int_0^{v(z)} \frac{s\,P'(s)}{G(q, a s)}\,du, \qquad s = \lambda_{out} e^u,

so the inlet log-stretch :math:`v` solves :math:`H(v; q) = L` and the pressure drop is
:math:`P(\lambda_{out}e^v) - p_{out}`. For a separable rheology, :math:`G = \phi(q)\psi(R)`, this
is :math:`J(v) = L\,\phi(q)` with :math:`J` independent of :math:`q`. This module writes that
identity once: the integrand, the target :math:`L\phi(q)`, the pressure, the profile
(:math:`J(v(z)) = (1 - z/L)\,J(v_{in})`), the maximum flow rate (:math:`J(\infty)`) and the
pressure-controlled problem. A concrete coupler gives ``_J`` (closed form or quadrature) and may
override ``_J_infinity`` and ``_solve_J`` (how :math:`J(v) = T` is solved for :math:`v`).

Each problem takes one route per point, decided by the call's inputs alone:

* a *table* (:mod:`tubefsi.couplers.tables`) where the scene has one: a power-law fluid, a wall
  that declares its shape/scale split, an unloaded outlet, one shape for every point; the table
  serves every target in its range, from the one bounded cache behind :func:`tubefsi.solve`;
* otherwise, and beyond the table's range, the *direct* solution (:mod:`tubefsi.couplers._inverse`).

A single point of a scene of scalars (a Python float, a NumPy scalar, a 0-d or 1-element array:
:func:`tubefsi.solve` passes each as one float) is served by the same table in plain Python
(:meth:`SeparatedVariables._table_point`): the same operations as the array path.

The engine works on a *flat* scene (:meth:`tubefsi.scene.Scene.flat`): one entry per point,
every per-point quantity a scalar (shared) or a 1-D array aligned with the points; ``index``
arguments select points, and :meth:`~tubefsi.scene.Scene.at` gathers their quantities.
"""

from __future__ import annotations

import abc
import math
from typing import NamedTuple

import numpy as np

from ..numerics.chebyshev import fit_piecewise
from ..numerics.kernels import EPS
from ..numerics.quadrature import Integral, adaptive_to_pole, integrate_graded, warn_unconverged
from ..scene import Points, Scene, State
from . import _inverse
from .base import Coupler
from ..numerics.cache import TABLES
from .tables import SeparatedTable, table_key

__all__ = ["SeparatedVariables", "MAX_LOG_STRETCH", "exact"]

#: Half the exponent range of doubles: a product of two factors within it stays a normal double.
_LOG_RANGE = 0.5 * -math.log(np.finfo(float).tiny)
#: Largest inlet stretch (relative to the outlet) a solve may reach: ln(1e15). Not a physical
#: limit (``max_flow_rate`` is the one limit): beyond it ``StretchRangeError``.
MAX_LOG_STRETCH = _inverse.MAX_LOG_STRETCH


#: The accuracy contract (relative), beyond which an estimate is an AccuracyWarning.
_CONTRACT = 1e-12
#: A call of at least this many points (or of one) is served by the scene's table, if it has one.
_TABLE_MIN_POINTS = 64
#: A curve of at least this many flow rates through one scene of a non-separable fluid is
#: interpolated between direct solves (:meth:`SeparatedVariables._curve`).
_CURVE_MIN_POINTS = 64
#: Tolerance of such a curve, in ln v: the direct solves' own accuracy, not tighter.
_CURVE_TOL = 1e-13

#: An :class:`~tubefsi.numerics.quadrature.Integral` of values known exactly (a closed form).
exact = Integral.exact


def _interpolated_log_stretch(log_x, solve):
    r""":math:`v` at the points ``log_x`` from the interpolant of :math:`\ln v` over their range
    (:func:`~tubefsi.numerics.chebyshev.fit_piecewise`, degree 16 on panels bisected to
    ``_CURVE_TOL``), its nodes and check points answered by ``solve(x)`` (``(v, ok, final)`` of
    direct solves at ``x = exp(log_x)``); None where the range is a point or the fit is not
    accepted. Which route a point takes depends on the call's values alone."""
    lo, hi = float(log_x.min()), float(log_x.max())
    if not hi > lo:
        return None

    def log_v(x):
        v, ok, final = solve(np.exp(x))
        good = ok & np.asarray(final.converged) & (v > 0)
        return np.where(good, np.log(np.where(v > 0, v, 1.0)), np.nan)

    with np.errstate(all="ignore"):
        interpolant, error = fit_piecewise(log_v, lo, hi, degree=16, tol=_CURVE_TOL, panels=2, max_panels=64)
    if interpolant is None:
        return None
    return np.exp(interpolant(np.clip(log_x, lo, hi)))


def _at_rest(pts, state, z, strain, rise):
    r"""A fluid at rest below its yield stress (``q = 0`` under a pressure drop) carries any gradient
    below the yield gradient: the profile is taken linear, :math:`p = p_{out} + \Delta p\,(1 - z/L)`,
    with the tube law's strain, so that it starts at the inlet pressure."""
    dp = np.asarray(state.pressure_drop, dtype=float)
    rest = (np.asarray(state.flow_rate) == 0) & (dp > 0)
    if not np.any(rest):
        return strain, rise
    rise = np.where(rest, dp * (1.0 - z / pts.length), rise)
    if not pts.wall.is_rigid:
        p = np.asarray(pts.outlet_pressure) + rise + 0.0 * dp
        strain = np.where(rest, pts.wall._strain(p, pts.tb), strain)
    return strain, rise


def _split_at_kinks(pts, upper):
    """``[0, k..., upper]`` per point: the log-stretches in ``(0, upper)`` where the wall's slope
    kinks (``WallModel._slope_kinks``, e.g. where a fibre wall's fibres engage), ``upper`` where
    there is none; just ``[0, upper]`` when no point has one."""
    upper = np.asarray(upper, dtype=float)
    kinks = pts.wall._slope_kinks(pts.tb)
    if not kinks:
        return [np.zeros(upper.shape), upper]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = [np.log(np.asarray(k, dtype=float) / pts.outlet_stretch) + 0.0 * upper for k in kinks]
    inside = [np.where((x > 0) & (x < upper), x, upper) for x in u]
    if not any(np.any(x < upper) for x in inside):
        return [np.zeros(upper.shape), upper]
    return [np.zeros(upper.shape), *np.sort(np.stack(inside), axis=0), upper]


def _rigid_state(scene: Scene, *, flow_rate=None, pressure_drop=None) -> State:
    r"""Hagen–Poiseuille in the rigid tube: :math:`\Delta p = L\,G(q, a)`, either way round."""
    load = flow_rate if flow_rate is not None else pressure_drop
    pts = scene.at(np.arange(np.size(load)))
    a, L, rheo = pts.radius, pts.length, pts.rheology
    if flow_rate is not None:
        q = flow_rate
        dp = np.where(q == 0, 0.0, L * rheo._pressure_gradient(q, a + 0.0 * q))
    else:
        dp = pressure_drop
        q = np.where(dp == 0, 0.0, rheo._flow_rate(a + 0.0 * dp, np.where(dp == 0, 1.0, dp) / L))
    zero = np.zeros_like(q)
    return State(q, dp, zero + scene.outlet_strain, zero)


class _Direct(NamedTuple):
    """What :meth:`SeparatedVariables._flow_direct` solved: the points it answered and whether each
    point has a root (False: none below the solver's range)."""

    points: np.ndarray
    ok: np.ndarray


class SeparatedVariables(Coupler):
    """Abstract engine: solves every problem from the separated integral ``_J`` of a subclass.

    Hooks: ``_J(scene, v, index, q)`` (required: :math:`\\int_0^v` of the separated integrand at
    the points ``index`` of a flat scene, ``q`` only for a non-separable rheology, as an
    :class:`~tubefsi.numerics.quadrature.Integral` with its error estimate), ``_J_infinity(scene,
    index, q, rtol)`` (optional: :math:`J(\\infty)`, for the maximum flow rate; ``rtol`` asks for a
    cheaper screening estimate), ``_solve_J(scene, target, index, q, upper)`` (optional: :math:`v`
    with :math:`J(v) = T`; default safeguarded Newton) and ``_table_options()`` (the plain values
    that tell its tables apart; None: no tables).
    """

    __slots__ = ()

    #: Relative tolerance of every quadrature of the separated integrand (error-controlled).
    _RTOL: float = 1e-14
    #: A fixed (unchecked) rule: no tables or interpolated curves, so that it is what it says.
    _coarse: bool = False

    # --------------------------------------------------------------- the tube law along u
    @staticmethod
    def stretch_at(points: Points, u):
        """Hoop stretch at log-stretch ``u``."""
        s_out = points.outlet_stretch
        if type(s_out) is float and s_out == 1.0:
            return np.exp(u)
        return s_out * np.exp(u)

    @staticmethod
    def strain_at(points: Points, u):
        """Hoop strain at log-stretch ``u``, without cancellation."""
        return points.outlet_strain + points.outlet_stretch * np.expm1(u)

    def integrate(self, scene: Scene, f, upper, index, *, order=None, panel_width=2.0, rtol=None) -> Integral:
        r"""``∫_0^upper f(u, i) du`` for the points ``index`` (``upper`` one per point; ``f`` gets
        positions ``i`` into ``index``), split where the wall's slope kinks.

        By default adaptive Gauss–Kronrod quadrature with an a-posteriori error estimate per point,
        refined to ``_RTOL`` (:func:`~tubefsi.numerics.quadrature.adaptive_to_pole`), graded in
        :math:`\ln(v_{max} - u)` toward a locking stretch. With ``order`` a fixed composite
        Gauss–Legendre rule (a coarse rule; its coupler checks it against the adaptive one): its
        result claims no error estimate.
        """
        upper = np.asarray(upper, dtype=float)
        pts = scene.at(index)
        # a maximum stretch with an unbounded pressure (a locking wall) is a singularity of P'
        v_max = np.asarray(pts.log_stretch_max, dtype=float) + 0.0 * upper
        locks = np.isfinite(v_max) & ~np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb)) + 0.0 * upper)
        pole = np.where(locks, v_max, np.inf)
        if order is not None:
            return exact(integrate_graded(f, upper, pole, order=order, panel_width=panel_width))
        rtol = self._RTOL if rtol is None else rtol
        edges = _split_at_kinks(pts, upper)
        result = adaptive_to_pole(f, edges[0], edges[1], pole, rtol=rtol, panel_width=panel_width)
        for lo, hi in zip(edges[1:-1], edges[2:]):     # a tube law whose slope kinks: each piece on its own
            result = result + adaptive_to_pole(f, lo, hi, pole, rtol=rtol, panel_width=panel_width)
        return result

    def pressure_rise(self, scene: Scene, v, index, *, warn=True):
        r""":math:`P(\lambda_{out}e^v) - p_{out}` at the points ``index``, without cancellation (the
        tube law where the outlet is unloaded, else the integral of :math:`sP'(s)` from the
        outlet); ``warn``: an estimate beyond tolerance is an ``AccuracyWarning``."""
        v = np.asarray(v, dtype=float)
        pts = scene.at(index)
        if np.ndim(scene.outlet_pressure) == 0 and scene.outlet_pressure == 0.0:
            return pts.wall._pressure_at_log_stretch(v, np.expm1(v), pts.tb)
        rise = self.rise_from_outlet(scene, v, index)
        if warn:
            warn_unconverged("the pressure rise from the outlet", rise)
        zero_out = np.asarray(pts.outlet_pressure) == 0.0
        if np.any(zero_out):                  # the tube law itself, where the outlet is unloaded
            direct = pts.wall._pressure_at_log_stretch(v, np.expm1(v), pts.tb)
            return np.where(zero_out, direct, rise.value)
        return rise.value

    def rise_from_outlet(self, scene: Scene, v, index) -> Integral:
        r""":math:`\int_0^v sP'(s)\,du` at the points ``index``, with its error estimate: the
        pressure rise from a loaded outlet (:meth:`pressure_rise`)."""
        return self.integrate(scene, lambda u, i: self._slope(scene.at(index[i], column=True), u), v, index)

    def _warn_near_a_lock(self, scene: Scene, v, index, rise):
        r"""An ``AccuracyWarning`` where the pressure drop cannot be known to the contract from the
        inlet stretch as a double: near a wall's locking stretch the tube law is so steep that the
        rounding of :math:`\lambda` alone moves the pressure by :math:`|\lambda P'/\Delta p|\,\epsilon`
        relative (the problem itself may be well conditioned in the flow rate; the stretch is not)."""
        pts = scene.at(index)
        if not np.isfinite(np.asarray(pts.log_stretch_max, dtype=float)).any():
            return
        with np.errstate(all="ignore"):       # (lambda P' = dP / d ln lambda)
            estimate = 2.0 * EPS * np.abs(pts.wall._log_slope(self.stretch_at(pts, v), pts.tb) / rise)
        bad = np.isfinite(estimate) & (estimate > _CONTRACT)
        if np.any(bad):
            warn_unconverged("the pressure drop this close to the wall's locking stretch (the tube law's slope "
                             "magnifies the rounding of the inlet stretch)",
                             Integral(value=np.ones(int(np.count_nonzero(bad))), error=estimate[bad],
                                      converged=np.zeros(int(np.count_nonzero(bad)), dtype=bool),
                                      panels=np.zeros(int(np.count_nonzero(bad)), dtype=int)))

    @staticmethod
    def _slope(points: Points, u):
        return points.wall._log_slope(SeparatedVariables.stretch_at(points, u), points.tb)

    def integrand(self, points: Points, u, q=None):
        r""":math:`s P'(s)/\psi(a s)` (separable) or :math:`s P'(s)/G(q, a s)`."""
        s = self.stretch_at(points, u)
        a = points.radius
        slope = points.wall._log_slope(s, points.tb)
        rheo = points.rheology
        if not rheo.separable:
            return slope / rheo._pressure_gradient(np.broadcast_to(q, np.shape(u)), a * s)
        k = rheo.radius_exponent
        if k is None:
            return slope / rheo._radius_factor(a * s)
        # psi = R^-k: (a s)^k = (a s_out)^k e^{ku}, an exponential per node instead of a power with a
        # per-point exponent; where a factor could leave the doubles, the power (which says so)
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            scale = (a * points.outlet_stretch) ** k
            ku = k * u
            reach = np.max(np.abs(ku)) if np.size(ku) else 0.0
            if reach < _LOG_RANGE and np.all(np.abs(np.log(scale)) < _LOG_RANGE):
                return slope * (scale * np.exp(ku))
            fast = slope * (scale * np.exp(ku))
            near = (np.abs(np.log(scale)) < _LOG_RANGE) & (np.abs(ku) < _LOG_RANGE)
        if np.all(near):
            return fast
        return np.where(near, fast, slope / rheo._radius_factor(a * s))

    @staticmethod
    def target(points: Points, q):
        """Right-hand side of the separated identity for flow rate ``q``."""
        if points.rheology.separable:
            return points.length * points.rheology._flow_factor(q)
        return np.zeros(np.shape(q)) + points.length

    # --------------------------------------------------------------- hooks
    @abc.abstractmethod
    def _J(self, scene: Scene, v, index, q=None) -> Integral:
        r""":math:`\int_0^v` of the separated integrand at the points ``index`` (``q`` only if
        non-separable), with its error estimate."""

    def _J_infinity(self, scene: Scene, index, q=None, rtol=None) -> Integral:
        r""":math:`J(\infty)` at the points ``index``: finite only for a wall with a limit pressure
        and a fast enough decay of :math:`s P'(s)/\psi(as)`; for the maximum flow rate. ``rtol``: a
        cheaper screening estimate to that looser tolerance, its error estimate saying how loose
        (an exact :math:`J(\infty)` may ignore it)."""
        return _inverse.j_infinity(self, scene, np.asarray(index), q, rtol)

    def _solve_J(self, scene: Scene, target, index, q=None, upper=None):
        """``(v, ok, final)``: the log-stretches with ``J(v) = target`` at the points ``index`` below
        ``upper``; ``ok`` is False where none exists below the largest log-stretch a solve may reach
        (``v = inf`` where the target is beyond :math:`J(\\infty)`), and ``final`` is the
        :class:`~tubefsi.numerics.quadrature.Integral` of :math:`J` at the answer (its error
        estimate). Default: :func:`tubefsi.couplers._inverse.newton`."""
        return _inverse.newton(self, scene, target, index, q, upper)

    def _table_options(self):
        """The plain values that tell this coupler's tables apart (None: it takes no tables)."""
        return None if self._coarse else ()

    @staticmethod
    def _log_stretch_cap(scene, index):
        """The largest log-stretch a solve may reach: below a maximum stretch, and ln(1e15)."""
        return _inverse.log_stretch_cap(scene, index)

    # --------------------------------------------------------------- the table
    def _table(self, scene: Scene, points: int):
        """The table of ``scene`` (from the one cache, :data:`~tubefsi.numerics.cache.TABLES`), or
        None where the scene has none or the call is not one it serves: one point, or at least
        ``_TABLE_MIN_POINTS`` (a panel costs about what 50 direct solves do: a short array is
        answered directly, whatever the cache holds)."""
        if 1 < points < _TABLE_MIN_POINTS:
            return None
        key = table_key(self, scene)
        if key is None:
            return None
        return TABLES.get(key, SeparatedTable)

    @staticmethod
    def _log_norm(points: Points):
        r""":math:`\ln(a^k\mu)`: the target per unit of the table's (per point)."""
        k = points.rheology.radius_exponent
        return k * np.log(points.radius) + np.log(points.wall._pressure_scale())

    def _table_point(self, scene: Scene, q: float):
        """The :class:`State` of one positive flow rate through a scene of scalars from its table,
        in plain Python (floats), or None where it has none or the table leaves it to the direct
        path."""
        table = self._table(scene, 1)
        if table is None:
            return None
        rheology, tube = scene.rheology, scene.tube
        scale = scene.wall._pressure_scale()
        x = (rheology._log_flow_factor(q) + math.log(tube.length) - rheology.radius_exponent * math.log(tube.radius)
             - math.log(scale))
        found = table.scalar(x, self, scene)
        if found is None:
            return None
        v = math.exp(found[0])
        return State(q, scale * math.exp(found[1]), math.expm1(v), v)

    def _from_table(self, table, scene, pts: Points, log_target):
        """``(v, rise, served)`` of the targets ``exp(log_target)`` the table's panels serve (arrays);
        the table's variable is ``log_target - ln(a^k mu)``."""
        y, w, served = table.evaluate(log_target - self._log_norm(pts), self, scene)
        v = np.where(served, np.exp(y), 0.0)
        scale = pts.wall._pressure_scale()
        rise = np.where(served, np.exp(w) * scale, np.nan)
        return v, rise, served

    # --------------------------------------------------------------- problems
    def flow_controlled(self, scene: Scene, flow_rate) -> State:
        """Solve for the pressure drop at each flow rate (a flat array, one per point)."""
        state, feasible = self._flow(scene, np.asarray(flow_rate, dtype=float), raise_=True)
        return state

    def flow_controlled_point(self, scene: Scene, flow_rate: float) -> State:
        """One flow rate through a scene of scalars: from its table in plain Python where it has one
        (the operations of :meth:`flow_controlled` on a one-point array), else as that array."""
        if flow_rate > 0.0 and not scene.wall.is_rigid:
            answer = self._table_point(scene, flow_rate)
            if answer is not None:
                return answer
        return super().flow_controlled_point(scene, flow_rate)

    def solve_feasible(self, scene: Scene, load, controlled: str):
        if controlled == "flow_rate":
            return self._flow(scene, np.asarray(load, dtype=float), raise_=False)
        return super().solve_feasible(scene, load, controlled)

    def _flow(self, scene: Scene, q, *, raise_):
        """``(State, feasible)`` of the flow rates ``q``: NaN and False where a point is beyond its
        maximum flow rate (or, with ``raise_``, a NoSteadyStateError). Each point's route: the
        scene's table where it serves the call, else a curve interpolated between direct solves
        (a long curve of a non-separable fluid), else the direct solution."""
        if scene.wall.is_rigid:
            return _rigid_state(scene, flow_rate=q), None
        if q.size == 1 and scene.size == 1 and q.reshape(-1)[0] > 0.0:     # (flow_controlled_point's route)
            answer = self._table_point(scene, float(q.reshape(-1)[0]))
            if answer is not None:
                return answer, None
        table = self._table(scene, q.size)
        pts = scene.at(np.arange(q.size))
        v, rise = np.zeros(q.shape), np.zeros(q.shape)
        todo = q > 0                           # (the points no route has answered yet)
        if table is not None:
            # ln(L phi(q)) formed as _table_point forms it, in logarithms (no power of q)
            log_target = pts.rheology._log_flow_factor(np.where(todo, q, 1.0)) + np.log(pts.length)
            v_t, rise_t, served = self._from_table(table, scene, pts, log_target)
            served &= todo
            if served.all():                   # (every point: no gathers)
                v, rise = v_t, rise_t
            else:
                v[served], rise[served] = v_t[served], rise_t[served]
            todo &= ~served
        target = np.where(todo, self.target(pts, np.where(todo, q, 1.0)), 0.0) if todo.any() else todo * 0.0
        solved = self._flow_direct(scene, q, target, todo, v)
        feasible = None
        if not solved.ok.all():
            beyond = _inverse.classify_runaway(self, scene, q, np.flatnonzero(~solved.ok), v, raise_=raise_)
            feasible = np.ones(q.shape, dtype=bool)
            feasible[beyond] = False
            v[~solved.ok] = 0.0
        if solved.points.size:
            rise[solved.points] = self.pressure_rise(scene, v[solved.points], solved.points)
            self._warn_near_a_lock(scene, v[solved.points], solved.points, rise[solved.points])
        rise[q == 0] = 0.0
        strain = self.strain_at(pts, v) + 0.0 * v
        if feasible is not None:
            for values in (rise, strain, v):
                values[~feasible] = np.nan
        return State(q, rise, strain, v), feasible

    def _flow_direct(self, scene: Scene, q, target, todo, v) -> _Direct:
        """Solve the points ``todo`` without a table (into ``v``): a long curve of a non-separable
        fluid by interpolation between direct solves, the others directly."""
        ok = np.ones(q.shape, dtype=bool)
        answered = np.zeros(q.shape, dtype=bool)
        if np.count_nonzero(todo) >= _CURVE_MIN_POINTS and scene.size == 1 and not scene.rheology.separable:
            sub = np.flatnonzero(todo)
            curve = self._curve(scene, q[sub])
            if curve is not None:
                v[sub] = curve
                todo = todo.copy()
                todo[sub] = False
                answered[sub] = True
        if todo.any():
            sub = np.nonzero(todo)[0]
            v[sub], ok[sub], final = self._solve_J(scene, target[sub], sub, None if scene.rheology.separable else q[sub])
            warn_unconverged("the separated-variables integral", final, where=ok[sub])
            answered[sub] = ok[sub]
        return _Direct(points=np.nonzero(answered)[0], ok=ok)

    def _curve(self, scene: Scene, q):
        r"""The inlet log-stretches of a long curve through one scene without a table (a non-separable
        fluid): :math:`\ln v` as a function of :math:`\ln q` is smooth, so it is interpolated
        (:func:`~tubefsi.numerics.chebyshev.fit_piecewise`) from direct solves at the nodes, each
        panel accepted where its tail and its check points (direct solves between the nodes) agree
        to 1e-13 in :math:`\ln v`: a few hundred direct solves serve the whole curve. None where it
        cannot be accepted (the direct path then serves every point). Which route a point takes
        depends on the call's flow rates alone."""
        length = np.full(1, float(scene.tube.length))

        def solve(flow):
            return self._solve_J(scene, np.broadcast_to(length, flow.shape), np.zeros(flow.size, dtype=int), flow)

        return _interpolated_log_stretch(np.log(q), solve)

    def _profile_curve(self, scene: Scene, q, target, upper):
        r"""The log-stretches of many sections of one scene without a table (a non-separable fluid
        at the flow rate ``q``): :math:`\ln v` as a function of :math:`\ln(L - z)`, the target of
        :math:`H(v; q) = L - z`, is smooth, and is interpolated as :meth:`_curve` interpolates a
        flow curve. None where it cannot be accepted (each section is then solved directly)."""
        def solve(t):
            return self._solve_J(scene, t, np.zeros(t.size, dtype=int), np.full(t.size, q), upper=np.full(t.size, upper))

        return _interpolated_log_stretch(np.log(target), solve)

    def pressure_controlled(self, scene: Scene, pressure_drop) -> State:
        """Solve for the flow rate at each pressure drop (flat array, one per point)."""
        dp = np.asarray(pressure_drop, dtype=float)
        if scene.wall.is_rigid:
            return _rigid_state(scene, pressure_drop=dp)
        index = np.arange(dp.size)
        pts = scene.at(index)
        pts.wall._check_pressure(pts.outlet_pressure + dp, pts.tb)
        v = np.zeros(dp.shape)
        q = np.zeros(dp.shape)
        flowing = dp > 0
        if np.any(flowing):
            sub = np.flatnonzero(flowing)
            v[sub] = _inverse.inlet_log_stretch(self, scene, dp[sub], sub)
            if scene.rheology.separable:
                q[sub] = self._flow_from_log_stretch(scene, v[sub], sub)
            else:
                q[sub] = self._flow_rate_at(scene, v[sub], dp[sub], sub)
        return State(q, dp, self.strain_at(pts, v) + 0.0 * v, v)

    def _flow_rate_at(self, scene, v, dp, index):
        r"""The flow rates of a non-separable fluid whose inlet log-stretch is ``v`` (the pressure drop
        ``dp``): :func:`tubefsi.couplers._inverse.solve_flow_rate` (a bracketed root search in
        :math:`\ln q` on the coupler's error-controlled :math:`J`)."""
        return _inverse.solve_flow_rate(self, scene, v, dp, index)

    def _flow_from_log_stretch(self, scene, v, index):
        """The flow rates whose inlet log-stretch is ``v`` (separable): :math:`\\phi^{-1}(J(v)/L)`."""
        sp = scene.at(index)
        result = self._J(scene, v, index)
        warn_unconverged("the separated-variables integral", result)
        return sp.rheology._flow_factor_inverse(result.value / sp.length)

    def profile(self, scene: Scene, state: State, z):
        r"""``(strain, pressure_rise)`` at ``z`` (validated to lie in [0, L]) for a flat scene and a
        flat state of one entry per point: the log-stretch :math:`v(z)` solves
        :math:`J(v) = (1 - z/L)\,J(v_{in})` (separable) or :math:`H(v; q) = L - z`."""
        z = np.asarray(z, dtype=float)
        q, v_in = np.asarray(state.flow_rate), np.asarray(state.log_stretch)
        index = np.arange(q.size)
        pts = scene.at(index)
        L = pts.length
        if scene.wall.is_rigid:
            gradient = np.where(q == 0, 0.0, pts.rheology._pressure_gradient(q, pts.radius))
            return _at_rest(pts, state, z, np.zeros(q.shape) + pts.outlet_strain, (L - z) * gradient)
        frac = (L - z) / L
        target = np.where(q == 0, 0.0, frac * self.target(pts, q))
        v = np.where(frac == 1.0, v_in, 0.0) + np.zeros(q.shape)
        rise = np.where(target > 0, np.nan, 0.0)
        direct = (target > 0) & (frac < 1.0)
        table = self._table(scene, q.size)
        if table is not None:
            with np.errstate(divide="ignore"):
                log_target = np.log(np.where(direct, target, 1.0))
            v_t, rise_t, served = self._from_table(table, scene, pts, log_target)
            served &= direct
            v[served] = np.minimum(v_t[served], v_in[served] if np.ndim(v_in) else v_in)
            rise[served] = rise_t[served]
            direct &= ~served
        if np.any(direct):
            sub = np.flatnonzero(direct)
            upper = (v_in[sub] if np.ndim(v_in) else v_in) * (1 + 1e-12) + 1e-300
            curve = None
            flows = np.broadcast_to(q, target.shape)[sub]
            if sub.size >= _CURVE_MIN_POINTS and scene.size == 1 and not scene.rheology.separable \
                    and np.all(flows == flows[0]):       # (one tube, one flow rate: many sections)
                curve = self._profile_curve(scene, float(flows[0]), target[sub], float(np.max(upper)))
            if curve is not None:
                v[sub] = curve
            else:
                v[sub], ok, final = self._solve_J(scene, target[sub], sub, q[sub] if np.ndim(q) else q, upper=upper)
                warn_unconverged("the separated-variables integral", final, where=ok)
        rest = np.isnan(rise)
        if np.any(rest):                     # the directly solved points, the inlet itself
            sub = np.flatnonzero(rest)
            rise[sub] = self.pressure_rise(scene, v[sub], sub)
        return _at_rest(pts, state, z, self.strain_at(pts, v) + 0.0 * v, rise)

    def length_integral(self, scene: Scene, state: State, weight, *, uniform=False):
        r""":math:`\int_0^L w(q, R(z))\,dz`: :math:`L\,w` where ``w`` does not depend on R (or the wall
        is rigid); otherwise, with :math:`dz = -sP'(s)/G\,du`, the separated integral weighted by
        :math:`w(q, as)`: :math:`\int_0^{v_{in}} w\,sP'(s)/G(q, as)\,du` (to 1e-12)."""
        q = np.asarray(state.flow_rate, dtype=float)
        index = np.arange(q.size)
        pts = scene.at(index)
        rheo = pts.rheology
        if uniform or scene.wall.is_rigid:
            return pts.length * weight(rheo, q, pts.radius * pts.outlet_stretch) + 0.0 * q
        v_in = np.asarray(state.log_stretch, dtype=float) + 0.0 * q

        def f(u, i):
            points = scene.at(index[i], column=True)
            qq = np.broadcast_to(q[i, None], np.shape(u))
            return self.integrand(points, u, None if rheo.separable else qq) * weight(
                points.rheology, qq, points.radius * self.stretch_at(points, u))

        # a derivative needs no more than 1e-12 (and a differenced weight has no more)
        result = self.integrate(scene, f, v_in, index, rtol=1e-12)
        warn_unconverged("a length integral of the sensitivities", result)
        # a separable integrand omits phi(q): dz = -sP'/(phi psi) du
        return result.value / rheo._flow_factor(q) if rheo.separable else result.value

    def max_flow_rate(self, scene: Scene):
        """Largest flow rate with a steady state at each point of a flat scene (a float for a
        scene of shared quantities; ``inf`` where there is none)."""
        out = _inverse.max_flow_rate(self, scene, np.arange(scene.size))
        return float(out[0]) if scene.size == 1 else out
