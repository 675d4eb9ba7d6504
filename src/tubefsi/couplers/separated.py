r"""The separated-variables engine shared by the ``closed-form`` and ``quadrature`` couplers.

Lubrication theory gives :math:`dp/dz = -G(q, R(p))` with :math:`p(L) = p_{out}`.
Writing the tube law :math:`p = P(\lambda)` and the log-stretch
:math:`u = \ln(\lambda/\lambda_{out})` separates the variables (``docs/theory.md``, section
"Coupling without an ODE"):

.. math::

    L - z = \int_0^{v(z)} \frac{s\,P'(s)}{G(q, a s)}\,du, \qquad s = \lambda_{out} e^u,

so the inlet log-stretch :math:`v` solves :math:`H(v; q) = L` and the pressure drop is
:math:`\int_0^v s P'(s)\,du`. For a separable rheology, :math:`G = \phi(q)\psi(R)`, this is
:math:`J(v) = L\,\phi(q)` with :math:`J` independent of :math:`q`, so one function serves a
whole flow curve. A concrete coupler gives only ``_J(scene, v, index, q)`` (closed form or
quadrature) and may override ``_J_infinity``; the engine solves flow- and pressure-controlled
problems, profiles and the maximum flow rate from it.

The engine works on a *flat* scene (:meth:`tubefsi.scene.Scene.flat`): one entry per point,
every per-point quantity a scalar (shared) or a 1-D array aligned with the points; ``index``
arguments select points, and :meth:`~tubefsi.scene.Scene.at` gathers their quantities.

A wall with a maximum stretch :math:`\lambda_{max}` (a locking material such as Gent, the
first pressure peak of a non-monotone tube law, the representable end of a Fung law) bounds
:math:`v` by :math:`v_{max} = \ln(\lambda_{max}/\lambda_{out})`. :meth:`SeparatedVariables.integrate`
grades its quadrature toward :math:`v_{max}` where the pressure is unbounded there
(:math:`P'` singular: a lock).

The rigid wall (:math:`\lambda \equiv 1`) has no log-stretch coordinate: its problems are
Hagen–Poiseuille, :math:`\Delta p = L\,G(q, a)`, handled here once (``_rigid_state``).
"""

from __future__ import annotations

import abc
import contextlib
import contextvars
import functools
import math
import time

import numpy as np

from .._lazy import lazy_module
from .._numerics import EPS, integrate_graded, solve_increasing
from .._products import rows_dot, scratch
from .._quadrature import (CHEBYSHEV_DEGREE, Integral, adaptive_to_pole, quiet, recording, solve_integral,
                           warn_unconverged)
from ..errors import ConvergenceError, InvalidParameterError, NoSteadyStateError, StretchRangeError
from ..scene import Points, Scene, State
from ._tables import ScalarPair, SeparatedTable, fit_chebyshev, fit_on_breaks, fit_uniform
from .base import Coupler

#: Half the exponent range of doubles: a product of two factors within it stays a normal double.
_LOG_RANGE = 0.5 * math.log(np.finfo(float).tiny) * -1.0

# SciPy on first use (tubefsi._lazy): listing the models must not import it
interpolate = lazy_module("scipy.interpolate", globals(), "interpolate")
optimize = lazy_module("scipy.optimize", globals(), "optimize")
elementwise = lazy_module("scipy.optimize.elementwise", globals(), "elementwise")

__all__ = ["SeparatedVariables", "MAX_LOG_STRETCH"]

#: Largest inlet stretch (relative to the outlet) a solve may reach: ln(1e15). Not a physical
#: limit (``max_flow_rate`` is the one limit): beyond it ``StretchRangeError``.
MAX_LOG_STRETCH = math.log(1e15)
_PROBE_LOG_STRETCH = math.log(1e8)
#: A runaway solve within this relative distance of the maximum flow rate is at the limit (to
#: the accuracy of q_max): NoSteadyStateError, not StretchRangeError.
_AT_THE_LIMIT = 1e-11


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


def _pick(value, index):
    """A per-point quantity (scalar or flat array) at ``index``."""
    return value if np.ndim(value) == 0 else value[index]


class SeparatedVariables(Coupler):
    """Abstract engine: solves every problem from the separated integral ``_J`` of a subclass.

    Hooks: ``_J(scene, v, index, q)`` (required: :math:`\\int_0^v` of the separated integrand
    at the points ``index`` of a flat scene, ``q`` only for a non-separable rheology) and
    ``_J_infinity(scene, index, q)`` (optional: :math:`J(\\infty)`, for the maximum flow rate).
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
        if type(s_out) is float and s_out == 1.0:       # an unloaded outlet: no pass to multiply by 1
            return np.exp(u)
        return s_out * np.exp(u)

    @staticmethod
    def strain_at(points: Points, u):
        """Hoop strain at log-stretch ``u``, without cancellation."""
        return points.outlet_strain + points.outlet_stretch * np.expm1(u)

    def integrate(self, scene: Scene, f, upper, index, *, order=None, panel_width=2.0, rtol=None):
        r"""``∫_0^upper f(u, i) du`` for the points ``index`` (``upper`` one per point; ``f`` gets
        positions ``i`` into ``index``).

        By default adaptive Gauss–Kronrod quadrature with an a-posteriori error estimate per
        point, refined to ``_RTOL`` (:func:`tubefsi._quadrature.adaptive_to_pole`), graded in
        :math:`\ln(v_{max} - u)` toward a locking stretch; an estimate that stays above the
        tolerance is an ``AccuracyWarning``. With ``order`` a fixed composite Gauss–Legendre
        rule of that order on panels of ``panel_width`` (a coarse rule, for the work-precision
        chart; its coupler checks it against the adaptive one).
        """
        upper = np.asarray(upper, dtype=float)
        pts = scene.at(index)
        # a maximum stretch with an unbounded pressure (a locking wall) is a singularity of P'
        v_max = np.asarray(pts.log_stretch_max, dtype=float) + 0.0 * upper
        locks = np.isfinite(v_max) & ~np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb)) + 0.0 * upper)
        pole = np.where(locks, v_max, np.inf)
        if order is not None:
            return integrate_graded(f, upper, pole, order=order, panel_width=panel_width)
        rtol = self._RTOL if rtol is None else rtol
        edges = _split_at_kinks(pts, upper)
        result = adaptive_to_pole(f, edges[0], edges[1], pole, rtol=rtol, panel_width=panel_width)
        for lo, hi in zip(edges[1:-1], edges[2:]):     # a tube law whose slope kinks: each piece on its own
            more = adaptive_to_pole(f, lo, hi, pole, rtol=rtol, panel_width=panel_width)
            value, error = result.value + more.value, result.error + more.error
            result = Integral(value=value, error=error, panels=result.panels + more.panels,
                              converged=(result.converged & more.converged) | (error <= rtol * np.abs(value)))
        if not np.all(result.converged):
            warn_unconverged("the separated-variables integral", result)
        return result.value

    def pressure_rise(self, scene: Scene, v, index, *, points=None, strain=None):
        r""":math:`P(\lambda_{out}e^v) - p_{out}` at the points ``index``, without cancellation
        (``points``: ``scene.at(index)`` and ``strain``: ``expm1(v)``, if the caller has them)."""
        v = np.asarray(v, dtype=float)
        pts = scene.at(index) if points is None else points
        if np.ndim(scene.outlet_pressure) == 0 and scene.outlet_pressure == 0.0:
            return pts.wall._pressure_at_strain(np.expm1(v) if strain is None else strain, pts.tb)
        rise = self.integrate(scene, lambda u, i: self._slope(scene.at(index[i], column=True), u), v, index)
        zero_out = np.asarray(pts.outlet_pressure) == 0.0
        if np.any(zero_out):                  # the tube law itself, where the outlet is unloaded
            direct = pts.wall._pressure_at_strain(np.expm1(v), pts.tb)
            rise = np.where(zero_out, direct, rise)
        return rise

    @staticmethod
    def _slope(points: Points, u):
        s = SeparatedVariables.stretch_at(points, u)
        return points.wall._log_slope(s, points.tb)

    def integrand(self, points: Points, u, q=None):
        r""":math:`s P'(s)/\psi(a s)` (separable) or :math:`s P'(s)/G(q, a s)`."""
        if type(u) is np.ndarray and u.size >= _SCRATCH_SIZE and type(points.outlet_stretch) is float \
                and points.outlet_stretch == 1.0:
            # a large batch: the stretches in a scratch buffer (a fresh array of megabytes costs a
            # page fault per 4 KiB); the wall reads them, and nothing returned refers to them
            s = np.exp(u, out=scratch("stretch", u.shape))
        else:
            s = self.stretch_at(points, u)
        a = points.radius
        slope = points.wall._log_slope(s, points.tb)
        rheo = points.rheology
        if rheo.separable:
            k = rheo.radius_exponent
            if k is not None:
                # psi = R^-k: (a s)^k = (a s_out)^k e^{ku}, an exp per node instead of a power with
                # a per-point exponent (several times dearer); the power of the per-point factor
                # keeps its one rounding, and where it leaves double range psi itself says so
                with np.errstate(over="ignore", under="ignore"):
                    scale = (a * points.outlet_stretch) ** k
                reach = np.max(np.abs(k)) * max(np.max(u), -np.min(u)) if np.size(u) else 0.0
                near = np.abs(np.log(scale)) < _LOG_RANGE
                within = reach < _LOG_RANGE and np.all(near)
                ku = k * u
                if within and type(ku) is np.ndarray and ku.shape == np.shape(slope):
                    np.exp(ku, out=ku)               # in place: one array for the product
                    ku *= scale
                    return np.multiply(slope, ku, out=ku)
                with np.errstate(over="ignore", under="ignore", invalid="ignore"):
                    fast = slope * (scale * np.exp(ku))
                if within:
                    return fast
                # some factor beyond half the exponent range: the power where the exponential
                # form could leave the doubles, decided node by node (a point's answer must not
                # depend on the batch it came in); the power raises where psi itself leaves them
                return np.where(near & (np.abs(ku) < _LOG_RANGE), fast, slope / rheo._radius_factor(a * s))
            return slope / rheo._radius_factor(a * s)
        qq = np.broadcast_to(q, np.shape(u))
        return slope / rheo._pressure_gradient(qq, a * s)

    def _integrand_at_outlet(self, points: Points, shape, q=None):
        """``integrand(points, zeros(shape), q)`` (the linear guess's slope), with the exponentials
        of u = 0 left out where the fluid is a separable power law and the outlet unloaded: the
        same values (e^0 = 1 and 1 * scale = scale exactly), a third of the passes."""
        rheo = points.rheology
        k = rheo.radius_exponent if q is None and rheo.separable else None
        if k is None or not (type(points.outlet_stretch) is float and points.outlet_stretch == 1.0):
            return self.integrand(points, np.zeros(shape), q)
        slope = points.wall._log_slope(np.ones(shape), points.tb)
        with np.errstate(over="ignore", under="ignore"):
            scale = (points.radius * points.outlet_stretch) ** k
        if not (np.all(np.abs(np.log(scale)) < _LOG_RANGE)
                and np.broadcast_shapes(np.shape(slope), np.shape(scale)) == tuple(shape)):
            return self.integrand(points, np.zeros(shape), q)
        return slope * scale

    @staticmethod
    def target(points: Points, q):
        """Right-hand side of the separated identity for flow rate ``q``."""
        if points.rheology.separable:
            return points.length * points.rheology._flow_factor(q)
        return np.zeros(np.shape(q)) + points.length

    # --------------------------------------------------------------- J hooks
    @abc.abstractmethod
    def _J(self, scene: Scene, v, index, q=None):
        r""":math:`\int_0^v` of the separated integrand at the points ``index`` (``q`` only if
        non-separable)."""

    def _J_infinity(self, scene: Scene, index, q=None):
        r""":math:`J(\infty)` at the points ``index``: finite only for a wall with a limit pressure
        and a fast enough decay of :math:`s P'(s)/\psi(as)`; for the maximum flow rate."""
        index = np.asarray(index)
        pts = scene.at(index)
        out = np.full(index.shape, np.inf)
        limited = np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb)) + np.zeros(index.shape))
        if not np.any(limited):
            return out
        qq = None if q is None else np.broadcast_to(np.asarray(q, dtype=float), index.shape)
        v_max = np.asarray(pts.log_stretch_max, dtype=float) + np.zeros(index.shape)
        peak = limited & np.isfinite(v_max)
        if np.any(peak):      # the tube law ends at its pressure peak: J stays finite up to it
            out[peak] = self._J(scene, v_max[peak] * (1 - 8 * EPS), index[peak], None if qq is None else qq[peak])
        far = limited & ~peak
        if np.any(far):
            sub = index[far]
            sp = scene.at(sub)
            rheo = sp.rheology
            mu = rheo.radius_exponent
            if mu is None:
                # local exponent of G in R far out, where the probe of J(inf) ends
                r = np.asarray(sp.radius * np.exp(_PROBE_LOG_STRETCH)) + np.zeros(sub.shape)
                if rheo.separable:
                    g0, g1 = rheo._radius_factor(r), rheo._radius_factor(10 * r)
                else:
                    g0 = rheo._pressure_gradient(qq[far], r)
                    g1 = rheo._pressure_gradient(qq[far], 10 * r)
                mu = -np.log(g1 / g0) / np.log(10.0)
            alpha = np.asarray(sp.wall._stiffness_decay_exponent(sp.tb)) - 1.0 - mu + np.zeros(sub.shape)
            decays = alpha > 1e-12
            if np.any(decays):
                v1 = np.full(int(np.count_nonzero(decays)), _PROBE_LOG_STRETCH)
                ids = sub[decays]
                qd = None if qq is None else qq[far][decays]
                head = self._J(scene, v1, ids, qd)
                tail = self.integrand(scene.at(ids), v1, qd) / alpha[decays]
                part = out[far]
                part[decays] = head + tail
                out[far] = part
        return out

    # --------------------------------------------------------------- problems
    def flow_controlled(self, scene: Scene, flow_rate, *, target=None) -> State:
        """Solve for the pressure drop at each flow rate (flat array, one per point); ``target``:
        the right-hand side of the separated identity if the caller has it already."""
        q = np.asarray(flow_rate, dtype=float)
        if scene.wall.is_rigid:
            return _rigid_state(scene, flow_rate=q)
        table = self._table(scene, build=q.size >= _TABLE_MIN_POINTS or _worth_building(scene))
        if table is not None and target is None:
            state = _curve_from_table(scene, table, q)
            if state is not None:
                return state
        index = np.arange(q.size)
        pts = scene.at(index)
        target = np.where(q == 0, 0.0, self.target(pts, q) if target is None else target)
        v = np.zeros(q.shape)
        dp = np.full(q.shape, np.nan)
        direct = target > 0
        if table is not None:                # the points whose target the table serves
            with np.errstate(divide="ignore"):
                x = np.log(target / table.norm)
            served = direct & (x >= table.x_lo) & (x <= table.x_hi)
            if np.any(served):
                y = table.inverse(x[served])
                v[served] = np.exp(y)
                dp[served] = table.rise(y, v[served])
                direct &= ~served
        if scene.size == 1 and not self._coarse and np.count_nonzero(direct) >= _TABLE_MIN_POINTS:
            sub = np.flatnonzero(direct)
            v_c = self._curve_by_interpolation(scene, q[sub])
            if v_c is not None:
                v[sub] = v_c
                dp[sub] = self.pressure_rise(scene, v_c, sub)
                direct[sub] = False
        strain = None
        if np.any(direct):
            start = time.perf_counter()
            sub = np.flatnonzero(direct)
            v_d, ok = self.solve_log_stretch(scene, target[sub], sub, q[sub])
            if not np.all(ok):
                self._raise_runaway(scene, q[sub], ok, sub)
            v[sub] = v_d
            if sub.size == q.size and type(scene.outlet_strain) is float and scene.outlet_strain == 0.0:
                # every point solved here at an unloaded outlet (a broadcast solve): the strain is
                # expm1(v) itself (strain_at's 0 + 1 * expm1(v)), computed once for both uses
                strain = np.expm1(v)
                dp[sub] = self.pressure_rise(scene, v_d, sub, points=pts, strain=strain)
            else:
                dp[sub] = self.pressure_rise(scene, v_d, sub)
            if table is None:
                _charge(scene, time.perf_counter() - start)
        dp[target == 0] = 0.0
        return State(q, dp, self.strain_at(pts, v) + 0.0 * v if strain is None else strain, v)

    def curve_from_table(self, scene: Scene, q) -> State | None:
        """The state of every flow rate ``q`` (a flat array of positive ones) of a scene of
        scalars from its table if the table is built and serves every point, else None (what
        :meth:`flow_controlled` does first; the lean curve path of :func:`tubefsi.solve`)."""
        table = self._table(scene, build=False)
        return None if table is None else _curve_from_table(scene, table, q)

    def _curve_by_interpolation(self, scene: Scene, q):
        r"""The inlet log-stretches of a long curve through one scene that has no table (a
        non-separable fluid, a loaded outlet): :math:`\ln v` as a function of :math:`\ln q` is
        smooth, so it is interpolated by piecewise Chebyshev series whose nodes are direct
        solves, refined until each panel's tail and its check points (direct solves between the
        nodes) agree to 1e-13 in :math:`\ln v` (:func:`~tubefsi.couplers._tables.fit_chebyshev`). A few hundred
        direct solves then serve any number of points. None where it cannot be accepted (the
        direct path then serves every point)."""
        log_q = np.log(q)
        lo, hi = float(log_q.min()), float(log_q.max())
        if not hi > lo:
            return None
        span = _CURVE_SPAN.get()
        if span is not None and span.scene is scene and span.lo <= lo and hi <= span.hi:
            # one call solved in chunks: the interpolant of the call's whole range, built once
            if span.interpolant is None:
                span.interpolant = self._fit_log_stretch(scene, span.lo, span.hi) or False
            if span.interpolant is False:
                return None
            return np.exp(span.interpolant(np.clip(log_q, span.lo, span.hi)))
        interpolant = self._fit_log_stretch(scene, lo, hi)
        return None if interpolant is None else np.exp(interpolant(np.clip(log_q, lo, hi)))

    def _fit_log_stretch(self, scene: Scene, lo, hi):
        r"""The accepted interpolant of :math:`\ln v` on ``[lo, hi]`` in :math:`\ln q`, or None."""
        length = float(scene.tube.length)
        separable = scene.rheology.separable
        pts = scene.at(np.zeros(1, dtype=int))

        def log_v(x):
            flow = np.exp(x)
            ids = np.zeros(flow.size, dtype=int)
            target = self.target(pts, flow) if separable else np.full(flow.size, length)
            with quiet():
                v, ok = self.solve_log_stretch(scene, np.broadcast_to(target, flow.shape), ids,
                                               None if separable else flow, check=False)
            return np.where(ok & (v > 0), np.log(np.where(v > 0, v, 1.0)), np.nan)

        interpolant, error = fit_chebyshev(log_v, lo, hi, panels=2, max_panels=64, tol=_CURVE_TOL)
        if interpolant is None or not math.isfinite(error):
            return None
        return interpolant

    # --------------------------------------------------------------- tables
    def _table(self, scene: Scene, build=True):
        """The :class:`~tubefsi.couplers._tables.SeparatedTable` of a scene of shared quantities, a
        power-law fluid and an unloaded outlet (cached per wall shape, t/a and n), or None
        (``build=False``: only if already cached)."""
        key = _table_key(scene)
        if key is None or self._coarse:         # a fixed rule is timed and charted as itself
            return None
        cached = _TABLES.get(key)
        if cached is None and not build:
            return None
        if cached is None:
            start = time.perf_counter()
            with quiet():
                cached = _TABLES[key] = _build_table(self, scene)
            _BUILD_SECONDS[0] = 0.5 * (_BUILD_SECONDS[0] + time.perf_counter() - start)
            _SPENT.pop(key, None)
            while len(_TABLES) > 128:
                _TABLES.pop(next(iter(_TABLES)))
        if cached is False:
            return None
        return cached.for_scene(scene)

    def solve_log_stretch(self, scene: Scene, target, index, q=None, upper=None, *, check=True, one_batch=True):
        r"""Log-stretch :math:`v` with :math:`J(v; q) = ` ``target`` at the points ``index``;
        returns ``(v, ok)``.

        First, with ``one_batch``, the points of a separable fluid's broadcast solve (at least
        ``_ONE_BATCH_MIN_POINTS``, not one long curve) are solved from one batch of 17 integrand
        values each: a Chebyshev interpolant of the integrand on :math:`[0, 1.5v_0]`
        (:math:`v_0` the linear guess), integrated exactly, with an
        a-posteriori estimate from the tail of its coefficients
        (:func:`~tubefsi._quadrature.solve_integral`); a point is answered there only where that
        estimate meets ``_RTOL``.

        The others: safeguarded Newton on :math:`\ln J`. For a separable rheology in a scene whose
        quantities are shared by all points (a curve), a coarse solve on a few quantiles of the
        targets gives every point a starting value within a few Newton steps of its root. Trial
        points do not warn (:func:`~tubefsi._quadrature.quiet`); with ``check`` the integral at
        the answer is evaluated once more, with its error estimate (``AccuracyWarning`` beyond
        tolerance).
        """
        target = np.asarray(target, dtype=float)
        index = np.asarray(index)
        sep = scene.rheology.separable
        qflat = None if sep else np.broadcast_to(np.asarray(q, dtype=float), target.shape)

        unchecked = np.ones(target.size, dtype=bool)    # the last evaluation missed its tolerance here

        def F(v, i):
            with recording() as missed:
                value = self._J(scene, v, index[i], None if sep else qflat[i])
            good = np.ones(np.size(i), dtype=bool)
            for _, result in missed:
                converged = np.asarray(result.converged)
                if converged.shape == good.shape:
                    good &= converged
                else:                                   # not one entry per point: check them all again
                    good[:] = False
            unchecked[i] = ~good
            return value

        def dF(v, i):
            return self.integrand(scene.at(index[i]), v, None if sep else qflat[i])

        positive = target[target > 0]
        shared = scene.size == 1
        if sep and shared and positive.size > 256:
            anchors = np.geomspace(positive.min(), positive.max(), 129)
            v_anchor, ok = self.solve_log_stretch(scene, anchors, np.zeros(anchors.size, dtype=int), check=False)
            keep = ok & (v_anchor < MAX_LOG_STRETCH)
            if np.count_nonzero(keep) >= 2:
                shape = interpolate.PchipInterpolator(np.log(anchors[keep]), v_anchor[keep], extrapolate=True)
                guess = np.maximum(shape(np.log(np.where(target > 0, target, anchors[0]))), 0.0)
            else:
                guess = np.ones(target.shape)
        else:
            with np.errstate(divide="ignore", invalid="ignore"):   # G(0, R) = 0: only where target = 0
                slope0 = self._integrand_at_outlet(scene.at(index), target.shape, qflat)
                guess = np.where(target > 0, np.minimum(target / slope0, 1.0), 0.0)
        hint = _START_HINT.get()
        if hint is not None and shared and q is not None and hint[0].shape == np.shape(q) and np.array_equal(hint[0], q):
            ok_hint = (target > 0) & np.isfinite(hint[1]) & (hint[1] > 0)
            guess = np.where(ok_hint, hint[1], guess)
        if upper is not None:
            guess = np.minimum(guess, upper)
        cap = self._log_stretch_cap(scene, index) + np.zeros(target.shape)
        if (one_batch and sep and not self._coarse and positive.size >= _ONE_BATCH_MIN_POINTS
                and not (shared and positive.size > 256)):
            bound = 0.5 * cap if upper is None else np.minimum(0.5 * cap, upper)
            v, solved = self._solve_by_interpolation(scene, index, target, guess, bound, qflat)
            if np.any(solved):
                ok = np.ones(target.shape, dtype=bool)
                rest = np.flatnonzero(~solved.ravel())
                if rest.size:
                    v, ok = v.ravel(), ok.ravel()
                    v[rest], ok[rest] = self.solve_log_stretch(
                        scene, target.ravel()[rest], index.ravel()[rest], None if sep else qflat.ravel()[rest],
                        None if upper is None else (np.asarray(upper, dtype=float) + np.zeros(target.shape)).ravel()[rest],
                        check=check, one_batch=False)
                return v.reshape(target.shape), ok.reshape(target.shape)
        if _GAUSS_START and not (sep and shared and positive.size > 256):
            guess = self._gauss_start(scene, index, target, guess, qflat, np.minimum(
                0.5 * cap, np.inf if upper is None else upper))
        capped = np.isfinite(np.asarray(_pick(scene.log_stretch_max, index), dtype=float) + np.zeros(target.shape))
        if np.any(capped):
            limit = np.where(capped, cap, np.inf)
            upper = limit if upper is None else np.minimum(upper, limit)
            guess = np.where(capped, np.minimum(guess, 0.5 * cap), guess)
        evaluated = np.zeros(target.size, dtype=bool)
        with quiet():
            v, ok = solve_increasing(F, dF, target, guess=guess, upper=upper, xmax=MAX_LOG_STRETCH, max_step=2.0,
                                     log=True, evaluated=evaluated, quadratic=_QUADRATIC_STEP,
                                     pole=np.where(capped, cap, np.inf))
        # the answer's own error estimate: where the iteration ended on an evaluation that met its
        # tolerance, that evaluation is the estimate; elsewhere the integral is evaluated once more
        answered = np.flatnonzero(ok.ravel() & (target.ravel() > 0) & ~(evaluated & ~unchecked))
        if check and answered.size:
            self._J(scene, v.ravel()[answered], index.ravel()[answered], None if sep else qflat.ravel()[answered])
        if np.any(capped):
            # converged onto the maximum stretch without reaching the target: out of reach
            at_cap = np.flatnonzero(capped.ravel() & (v.ravel() >= cap.ravel() * (1 - 1e-12))
                                    & (target.ravel() > 0))
            if at_cap.size:
                with quiet():
                    short = F(v.ravel()[at_cap], at_cap) < target.ravel()[at_cap] * (1 - 1e-9)
                ok = ok.copy()
                ok.ravel()[at_cap[short]] = False
        return v, ok

    def _solve_by_interpolation(self, scene, index, target, guess, bound, q):
        """:func:`~tubefsi._quadrature.solve_integral` at the points with a positive target, on
        :math:`[0, 1.5 v_0]` (:math:`v_0` the linear ``guess``: the root is within a few tens of
        per cent of it for a moderate strain, and a short interval keeps the interpolant's
        degree low), and on three times that where the integral fell short; never beyond
        ``bound``. A point whose interval is shorter than ``_LOW_DEGREE_REACH`` is tried at degree
        ``_LOW_DEGREE`` first (13 integrand values instead of 17), and at degree 16 where that
        interpolant's tail misses the tolerance: which degree answers depends on the point alone.
        Returns ``(v, solved)`` shaped like ``target``."""
        v = np.zeros(target.shape)
        solved = np.zeros(target.shape, dtype=bool)
        bound = np.broadcast_to(bound, target.shape).ravel()
        top = (np.minimum(1.5 * guess, bound.reshape(target.shape)) + np.zeros(target.shape)).ravel()
        flat_target, flat_index = target.ravel(), index.ravel()
        flat_q = None if q is None else q.ravel()

        def attempt(points, degree):
            """Solve ``points`` (flat positions) at ``degree``; returns their (good, short) masks."""
            ids = flat_index[points]
            if flat_q is None:         # (u: nodes x points, so per-point quantities as rows)
                def f(u, i):
                    return self.integrand(scene.at(ids[i]), u)
            else:
                q_live = flat_q[points]

                def f(u, i):
                    return self.integrand(scene.at(ids[i]), u, q_live[i])
            with np.errstate(all="ignore"):
                x, good, short = solve_integral(f, flat_target[points], top[points], rtol=self._RTOL, degree=degree)
            v.ravel()[points[good]] = x[good]
            solved.ravel()[points[good]] = True
            return good, short

        live = np.flatnonzero((flat_target > 0) & (top > 0))
        for _ in range(2):
            if live.size == 0:
                break
            near = top[live] < _LOW_DEGREE_REACH
            low, high = live[near], live[~near]
            short_low = np.zeros(0, dtype=int)
            if low.size:
                good, short = attempt(low, _LOW_DEGREE)
                short_low = low[short]
                high = np.concatenate([high, low[~good & ~short]])     # the tail missed: degree 16
            short_high = high[attempt(high, CHEBYSHEV_DEGREE)[1]] if high.size else high
            shorter = np.concatenate([short_low, short_high])
            wider = np.minimum(3.0 * top[shorter], bound[shorter])
            keep = wider > top[shorter]
            top[shorter] = wider
            live = np.sort(shorter[keep])
        return v, solved

    def _gauss_start(self, scene, index, target, guess, q, top):
        r"""A starting value near the root for the Newton iteration on :math:`\ln J`: Newton on a
        eight-point Gauss–Legendre estimate of :math:`J(v)` over :math:`[0, v]` (eight integrand
        values per point and step, no error estimate; ~1e-10 for smooth integrands over moderate
        strains), its slope the exact :math:`J'(v)`, from the linear guess until a step moves less
        than 1e-5 (then, Newton being quadratic, the start is within ~1e-10, the rule's own error;
        at most ``_START_STEPS``; each step only for the points still moving). Eight
        nodes, not six: at large strain six leave half the points two adaptive passes from the
        root, eight one. Only a start: the error-controlled iteration that follows decides the answer."""
        live = np.flatnonzero((target > 0) & (guess > 0))
        if live.size == 0:
            return guess
        ids, t, v = index[live], target[live], guess[live].copy()
        hi = top[live] + np.zeros(live.size)
        q_live = None if q is None else q[live]
        act = np.arange(live.size)                    # the points still moving
        with np.errstate(all="ignore"):
            for _ in range(_START_STEPS):
                pts = scene.at(ids[act], column=True)
                va = v[act]
                # the eight nodes and the end v (the slope) in one evaluation: an integrand with
                # a fixed cost per call (an interpolated flow law) pays it once per step
                values = self.integrand(pts, va[:, None] * _START_NODES_AND_END,
                                        None if q is None else q_live[act][:, None])
                estimate = va * rows_dot(values[:, :-1], _START_WEIGHTS)
                slope = values[:, -1]
                nxt = np.clip(va - np.log(estimate / t[act]) * estimate / slope, 0.5 * va, np.minimum(2.0 * va, hi[act]))
                nxt = np.where(np.isfinite(nxt) & (nxt > 0), nxt, va)
                v[act] = nxt
                # Newton converges quadratically: after a step below 1e-5 the error is ~1e-10, the
                # rule's own; from there Newton on the exact J takes over
                act = act[np.abs(nxt - va) > 1e-5 * va]
                if act.size == 0:
                    break
        out = guess.copy()
        out[live] = v
        return out

    @staticmethod
    def _log_stretch_cap(scene, index):
        """The largest log-stretch a solve may reach: below a maximum stretch, and ln(1e15)."""
        v_max = np.asarray(_pick(scene.log_stretch_max, index), dtype=float)
        return np.where(np.isfinite(v_max), np.minimum(MAX_LOG_STRETCH, v_max * (1 - 8 * EPS)), MAX_LOG_STRETCH)

    def pressure_controlled(self, scene: Scene, pressure_drop) -> State:
        """Solve for the flow rate at each pressure drop (flat array, one per point)."""
        dp = np.asarray(pressure_drop, dtype=float)
        if scene.wall.is_rigid:
            return _rigid_state(scene, pressure_drop=dp)
        index = np.arange(dp.size)
        pts = scene.at(index)
        p_in = pts.outlet_pressure + dp
        pts.wall._check_pressure(p_in, pts.tb)
        v = np.zeros(dp.shape)
        q = np.zeros(dp.shape)
        direct = dp > 0
        table = self._table(scene, build=dp.size >= _TABLE_MIN_POINTS or _worth_building(scene))
        start = time.perf_counter()
        if table is not None and table.table.pressure_inverse is not None:
            with np.errstate(divide="ignore"):
                w = np.log(dp / table.scale)
            inv = table.table.pressure_inverse
            served = direct & (w >= inv.lo) & (w <= inv.hi)
            if np.any(served):
                y = inv(w[served])
                x = table.table.forward(y)
                v[served] = np.exp(y)
                q[served] = scene.rheology._flow_factor_inverse(np.exp(x) * table.norm / pts.length)
                direct &= ~served
        if np.any(direct):
            sub = np.flatnonzero(direct)
            v[sub] = self._inlet_log_stretch(scene, dp[sub], sub)
            sp = scene.at(sub)
            if scene.rheology.separable:
                j = np.full(sub.size, np.nan)
                if table is not None:          # the forward table gives J at the inlet stretch
                    with np.errstate(divide="ignore"):
                        y = np.log(v[sub])
                    inside = (y >= table.table.y_lo) & (y <= table.table.y_hi)
                    j[inside] = np.exp(table.table.forward(y[inside])) * table.norm
                rest = np.isnan(j)
                if np.any(rest):
                    j[rest] = self._J(scene, v[sub][rest], sub[rest])
                q[sub] = sp.rheology._flow_factor_inverse(j / sp.length)
            else:
                q[sub] = self._solve_flow_rate(scene, v[sub], dp[sub], sub)
            if table is None:
                _charge(scene, time.perf_counter() - start)
        e_in = self.strain_at(pts, v) + 0.0 * v
        return State(q, dp, e_in, v)

    def _inlet_log_stretch(self, scene, dp, index):
        r"""The inlet log-stretch under the pressure drop ``dp`` at the points ``index``.

        With an unloaded outlet, :math:`v = \mathrm{log1p}(\varepsilon(\Delta p))` from the tube
        law's inverse. With an outlet pressure, differencing the strains at :math:`p_{out}` and
        :math:`p_{out} + \Delta p` would lose :math:`\varepsilon_{mach}\,p_{out}/\Delta p`; so the
        strain difference only starts a Newton iteration on the pressure rise itself,
        :math:`\int_0^v sP'(s)\,du = \Delta p`.
        """
        pts = scene.at(index)
        e_in = pts.wall._strain(pts.outlet_pressure + dp, pts.tb)
        v = np.log1p((e_in - pts.outlet_strain) / pts.outlet_stretch)
        loaded = (np.asarray(pts.outlet_pressure) + np.zeros(dp.shape)) != 0      # transmural: may be < 0
        polish = np.flatnonzero(loaded & (dp > 0))
        if polish.size == 0:
            return v
        sub = index[polish]

        def F(x, i):
            return self.pressure_rise(scene, x, sub[i])

        def dF(x, i):
            return self._slope(scene.at(sub[i]), x)

        # a drop far below the outlet pressure: the strain difference is rounding noise (it may
        # be 0), and Newton on ln F from far above a tiny root only bisects; the linearized rise,
        # dp / (s P'(s)) at the outlet, is within O(v) of the root
        guess = np.maximum(v[polish], 0.0)
        small = dp[polish] <= _SMALL_DROP * np.abs(np.asarray(pts.outlet_pressure) + np.zeros(dp.shape))[polish]
        if np.any(small):
            guess[small] = dp[polish][small] / dF(np.zeros(int(np.count_nonzero(small))), np.flatnonzero(small))
        with quiet():
            w, _ = solve_increasing(F, dF, dp[polish], guess=guess, max_step=2.0, log=True)
        v = v.copy()
        v[polish] = w
        return v

    def _solve_flow_rate(self, scene, v, dp, index):
        r"""Non-separable rheology: find q with H(v; q) = L (H decreases with q), per point.

        Rigid tubes of the outlet and inlet radii under the mean gradient dp/L bracket q.
        A yield-stress fluid has a finite :math:`H(v; 0^+)`, with :math:`G = 2\tau_y/R`:
        where it does not exceed L the pressure drop cannot yield the fluid all along
        the tube, and q = 0.
        """
        pts = scene.at(index)
        a, L, rheo = pts.radius, pts.length, pts.rheology
        v = np.asarray(v, dtype=float)
        dp = np.asarray(dp, dtype=float)
        g = np.where(dp == 0, 1.0, dp) / L
        q_lo = rheo._flow_rate(a * pts.outlet_stretch + 0.0 * g, g)
        q_hi = rheo._flow_rate(a * self.stretch_at(pts, v), g)
        flowing = (q_hi > 0) & (dp > 0)
        if scene.rheology.yield_stress > 0 and np.any(flowing):
            sel = np.flatnonzero(flowing)
            flowing[sel] = self._J(scene, v[sel], index[sel], np.zeros(sel.size)) > _pick(L + 0.0 * v, sel)
        q = np.zeros(v.shape)
        if not np.any(flowing):
            return q
        sel = np.flatnonzero(flowing)
        v_s, q_lo, q_hi = v[sel], q_lo[sel], q_hi[sel]
        ids = index[sel]
        log_length = np.log(np.asarray(L, dtype=float) + np.zeros(v.shape))[sel]

        def f(log_q, v, i, log_l):
            return np.log(self._J(scene, v, i, np.exp(log_q))) - log_l

        hi = np.log(q_hi)
        hi = hi + 1e-15 * np.abs(hi) + 1e-15        # above q_hi whatever the sign of ln q_hi
        with np.errstate(divide="ignore"):
            lo = np.log(q_lo)
        lo = lo - 1e-12 * np.abs(lo)
        found = np.ones(v_s.shape, dtype=bool)
        unyielded = q_lo <= 0          # the outlet section alone would not yield: search down
        if np.any(unyielded):
            top = hi[unyielded]
            br = elementwise.bracket_root(f, top - 2.0, top, xmin=top - 700.0, xmax=top,
                                          args=(v_s[unyielded], ids[unyielded], log_length[unyielded]))
            lo[unyielded] = br.bracket[0]
            hi[unyielded] = np.where(br.success, br.bracket[1], hi[unyielded])
            found[unyielded] = br.success   # else q < 1e-304 q_hi: zero in double precision
        res = elementwise.find_root(f, (lo, hi), args=(v_s, ids, log_length),
                                    tolerances=dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300))
        q[sel] = np.where(found, np.exp(res.x), 0.0)
        return q

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
        v = np.where(frac == 1.0, v_in, 0.0)
        rise = np.full(q.shape, np.nan)
        direct = (target > 0) & (frac < 1.0)
        table = self._table(scene, build=q.size >= _TABLE_MIN_POINTS)
        if table is not None:
            with np.errstate(divide="ignore"):
                x = np.log(target / table.norm)
            served = direct & (x >= table.x_lo) & (x <= table.x_hi)
            if np.any(served):
                y = table.inverse(x[served])
                v[served] = np.minimum(np.exp(y), v_in[served] if np.ndim(v_in) else v_in)
                rise[served] = table.rise(y, v[served])
                direct &= ~served
        if np.any(direct):
            sub = np.flatnonzero(direct)
            upper = (v_in[sub] if np.ndim(v_in) else v_in) * (1 + 1e-12) + 1e-300
            v[sub], _ = self.solve_log_stretch(scene, target[sub], sub, _pick(q, sub) if np.ndim(q) else q,
                                               upper=upper)
            rise[sub] = self.pressure_rise(scene, v[sub], sub)
        rest = np.isnan(rise)
        if np.any(rest):                     # the inlet itself and zero flow
            sub = np.flatnonzero(rest)
            rise[sub] = self.pressure_rise(scene, v[sub], sub)
        return _at_rest(pts, state, z, self.strain_at(pts, v) + 0.0 * v, rise)

    def length_integral(self, scene: Scene, state: State, weight, *, uniform=False):
        r""":math:`\int_0^L w(q, R(z))\,dz`: :math:`L\,w` where ``w`` does not depend on R (or the wall
        is rigid); otherwise, with :math:`dz = -sP'(s)/G\,du`, the separated integral weighted by
        :math:`w(q, as)`: :math:`\int_0^{v_{in}} w\,sP'(s)/G(q, as)\,du` (the adaptive,
        error-controlled quadrature of :math:`J`, to 1e-12)."""
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
        value = self.integrate(scene, f, v_in, index, rtol=1e-12)
        # a separable integrand omits phi(q): dz = -sP'/(phi psi) du
        return value / rheo._flow_factor(q) if rheo.separable else value

    def max_flow_rate(self, scene: Scene):
        """Largest flow rate with a steady state at each point of a flat scene (a float for a
        scene of shared quantities; ``inf`` where there is none)."""
        n = scene.size
        table = self._table(scene, build=False)
        if table is not None:                    # J(inf) per unit modulus is in the table
            with np.errstate(over="ignore"):
                q = scene.rheology._flow_factor_inverse(np.float64(table.table.j_inf) * table.norm / scene.tube.length)
            return float(q) if np.isfinite(q) else math.inf
        index = np.arange(n)
        pts = scene.at(index)
        limited = np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb), dtype=float) + np.zeros(n))
        out = np.full(n, np.inf)
        if np.any(limited):
            ids = index[limited]
            if scene.rheology.separable:
                with recording() as missed:     # an estimate matters only for a representable q_max
                    j_inf = self._J_infinity(scene, ids)
                finite = np.isfinite(j_inf)
                if np.any(finite):
                    sp = scene.at(ids[finite])
                    with np.errstate(over="ignore"):
                        q = sp.rheology._flow_factor_inverse(j_inf[finite] / sp.length) + 0.0 * j_inf[finite]
                    sub = out[ids]
                    sub[finite] = np.where(np.isfinite(q), q, np.inf)
                    out[ids] = sub
                    # a stiffening law whose "limit" is where its pressure leaves double range
                    # (exponential fibres) has a maximum flow rate beyond it too: inf, exactly
                    if np.any(np.isfinite(q)):
                        for what, result in missed:
                            warn_unconverged(what, result)
            else:
                out[ids] = self._max_flow_rate_search(scene, ids)
        return float(out[0]) if n == 1 else out

    def _max_flow_rate_search(self, scene: Scene, index):
        """Non-separable rheology: the q with H(inf; q) = L (H decreases with q), per point, by a
        bracketed root search in ln q (cached for a scene of shared quantities: every
        flow-controlled solve asks for it)."""
        if scene.size == 1:
            try:
                return np.full(index.shape, _cached_max_flow_rate(self, scene))
            except TypeError:          # an unhashable model
                pass
        out = np.full(index.shape, np.inf)
        for k, i in enumerate(index):           # one bracketed search per point
            out[k] = self._max_flow_rate_point(scene, int(i))
        return out

    def _max_flow_rate_point(self, scene, i):
        ids = np.array([i])
        pts = scene.at(ids)
        L = float(np.asarray(pts.length).ravel()[0])
        tau_y = float(scene.rheology.yield_stress)
        if tau_y > 0 and not self._J_infinity(scene, ids, 0.0)[0] > L:
            return 0.0  # even the limit pressure cannot yield the fluid all along the tube

        def excess(log_q):
            return math.log(self._J_infinity(scene, ids, math.exp(log_q))[0]) - math.log(L)

        a = float(np.asarray(pts.radius).ravel()[0])
        g0 = max(float(np.asarray(pts.wall._limit_pressure(pts.tb)).ravel()[0]) / L, 4.0 * tau_y / a)
        with np.errstate(all="ignore"):       # a start within the fluid's representable flow
            for _ in range(40):
                q0 = float(pts.rheology._flow_rate(np.asarray([a]), np.asarray([g0]))[0])
                if math.isfinite(q0) and q0 > 0 or g0 <= 4.0 * tau_y / a:
                    break
                g0 = max(1e-10 * g0, 4.0 * tau_y / a)
        if not (math.isfinite(q0) and q0 > 0):
            raise ConvergenceError(f"the maximum flow rate search finds no finite flow rate of {scene.rheology!r} "
                                   f"below the limit pressure gradient {g0:.6g} Pa/m")
        log_q = math.log(q0)
        if not math.isfinite(excess(log_q)):
            return math.inf  # G(q, R) falls off too fast in R: every flow rate has a steady state
        lo, hi = log_q, log_q
        while excess(lo) < 0:              # steps of e^2: the doubles' range is crossed in ~700
            lo -= 2.0
            if log_q - lo > 1500:
                raise ConvergenceError(f"the maximum flow rate search of {scene.rheology!r} does not bracket it")
        try:
            while excess(hi) > 0:
                hi += 2.0
                if hi - log_q > 200:
                    return math.inf
        except InvalidParameterError:      # beyond the flow the fluid's law represents: none bigger
            return math.inf
        return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps))

    def _raise_runaway(self, scene, q, ok, index=None):
        """The NoSteadyStateError of the first point whose solve ran away (``index``: the points
        ``q`` and ``ok`` refer to)."""
        bad = int(np.flatnonzero(~np.asarray(ok).ravel())[0])
        one = scene.point(bad if index is None else int(np.asarray(index)[bad]))
        q_max = float(self.max_flow_rate(one))
        q_bad = float(q.ravel()[bad])
        if math.isfinite(q_max) and q_bad >= q_max:
            raise NoSteadyStateError("flow_rate", q_max, q_bad, "the tube inflates without bound")
        if math.isfinite(q_max) and q_bad >= q_max * (1.0 - _AT_THE_LIMIT):
            raise NoSteadyStateError("flow_rate", q_max, q_bad, "the tube inflates without bound (this flow "
                                     f"rate is the maximum one to within {_AT_THE_LIMIT:.0e}, its accuracy)")
        ids = np.array([0])
        cap = np.atleast_1d(self._log_stretch_cap(one, ids))
        pts = one.at(ids)
        if one.rheology.separable:
            reach = float(np.ravel(pts.rheology._flow_factor_inverse(self._J(one, cap, ids) / pts.length))[0])
        else:
            reach = float(self._solve_flow_rate(one, cap, self.pressure_rise(one, cap, ids), ids)[0])
        if float(cap[0]) < MAX_LOG_STRETCH:
            raise NoSteadyStateError("flow_rate", reach, q_bad,
                                     "the inlet stretch would reach the wall's maximum stretch")
        limit = "max_flow_rate is inf" if not math.isfinite(q_max) else f"below max_flow_rate = {q_max:.6g} m^3/s"
        raise StretchRangeError(reach, q_bad, f"a steady state exists ({limit}) but its inlet stretch exceeds "
                                "1e15, and R/L far exceeds 0.1 there: the model no longer applies")


@functools.lru_cache(maxsize=256)
def _cached_max_flow_rate(coupler, scene) -> float:
    return coupler._max_flow_rate_point(scene, 0)


def _curve_from_table(scene: Scene, table, q):
    """The state of every flow rate ``q`` (a flat array) of a scene with a table, or None where some
    target is outside it. Each pass over the points writes into an array it keeps (at 10^4 points
    the allocations, not the arithmetic, were most of the cost)."""
    # x = ln(L phi(q) / norm) straight from ln phi (no power, no division)
    x = scene.rheology._log_flow_factor(q) + math.log(float(scene.tube.length) / table.norm)
    if x.size and not (x.min() >= table.x_lo and x.max() <= table.x_hi):   # (NaN fails both)
        return None
    y = table.inverse(x, out=x)
    tabulated = table.table.tabulate_pressure
    rise = table.rise(y, None) if tabulated else None       # (from ln v, before y becomes v)
    v = np.exp(y, out=y)
    strain = np.expm1(v)                         # the outlet is unloaded wherever there is a table
    return State(q, rise if tabulated else table.rise(None, v, strain), strain, v)


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


class _Span:
    """The range of ln q of one call that a caller solves in chunks through one scene."""

    __slots__ = ("scene", "lo", "hi", "interpolant")

    def __init__(self, scene, lo, hi):
        self.scene, self.lo, self.hi, self.interpolant = scene, lo, hi, None


_CURVE_SPAN = contextvars.ContextVar("tubefsi_curve_span", default=None)
#: (flow rates, inlet log-stretches) of a nearby solve of the same flow rates (see start_hint).
_START_HINT = contextvars.ContextVar("tubefsi_start_hint", default=None)


@contextlib.contextmanager
def start_hint(flow_rate, log_stretch):
    """Within the block, a direct solve of exactly these flow rates through a scene of shared
    quantities starts its Gauss iteration from ``log_stretch`` (a nearby solution: the same
    data at the previous parameters of a fit) instead of the linear guess. Only a start: the
    error-controlled iteration that follows decides the answer."""
    token = _START_HINT.set((np.asarray(flow_rate, dtype=float), np.asarray(log_stretch, dtype=float)))
    try:
        yield
    finally:
        _START_HINT.reset(token)


@contextlib.contextmanager
def curve_span(scene: Scene, flow_rate):
    """Within the block, the chunks of a long curve through ``scene`` (the same object each
    chunk) share one interpolant of the inlet log-stretch over all of ``flow_rate`` (the
    positive, finite ones) instead of each building its own."""
    q = np.asarray(flow_rate, dtype=float)
    q = q[(q > 0) & np.isfinite(q)]
    if q.size < 2:
        yield
        return
    with np.errstate(divide="ignore"):
        token = _CURVE_SPAN.set(_Span(scene, float(np.log(q.min())), float(np.log(q.max()))))
    try:
        yield
    finally:
        _CURVE_SPAN.reset(token)


#: Curves at least this long build a table at once; shorter calls build one once the time spent
#: solving their key directly has reached the time a build takes (a ski-rental rule: never more
#: than twice the cost of the better choice in hindsight, whatever the sequence of calls).
_TABLE_MIN_POINTS = 64
#: The one-batch solve (:func:`~tubefsi._quadrature.solve_integral`) for a separable fluid's
#: broadcast solves of at least this many points: below, its fixed cost (a few dozen array
#: operations) outweighs the integrand values it saves, and a point it cannot accept (a large
#: strain) costs its 17 values on top of the adaptive path. A non-separable fluid's integrand
#: (an interpolated flow law) is left to the adaptive path, whose panels follow its smoothness.
_ONE_BATCH_MIN_POINTS = 64
#: A one-batch solve on an interval shorter than this (in ln v) tries a degree-12 interpolant
#: first: measured over the random scenes of benchmarks/speed.py, its tail met 1e-14 at every
#: point with an interval below 0.19 (and at 75 % of all); a miss costs its 13 values on top
_LOW_DEGREE, _LOW_DEGREE_REACH = 12, 0.15
#: Integrand batches of at least this many values put their stretches in a scratch buffer.
_SCRATCH_SIZE = 1 << 14
#: Start the direct Newton iteration from a Gauss estimate (SeparatedVariables._gauss_start).
_GAUSS_START = True
_START_NODES, _START_WEIGHTS = np.polynomial.legendre.leggauss(8)
#: at most this many Newton steps on the Gauss estimate (a start far out needs 6-8, most 3)
_START_STEPS = 8
_START_NODES, _START_WEIGHTS = 0.5 * (_START_NODES + 1.0), 0.5 * _START_WEIGHTS      # on [0, 1]
_START_NODES_AND_END = np.append(_START_NODES, 1.0)
#: Newton on ln J stops after a step below this, relative to v and to the distance to a
#: maximum stretch: its error is then ~(step)^2 / 2 relative to both (ln J ~ ln v, or
#: -ln(v_max - v) near a locking stretch), and the evaluation it came from, that close, is the
#: answer's error estimate (:func:`tubefsi._numerics.solve_increasing`)
_QUADRATIC_STEP = 1e-8
#: Tolerance of a curve interpolated between direct solves, in ln v: the direct solves' own
#: accuracy (the quadrature's 1e-14, a little more near a yield point), not tighter.
_CURVE_TOL = 1e-13
#: A pressure drop below this fraction of the outlet pressure starts its inlet-stretch Newton
#: iteration from the linearized rise (SeparatedVariables._inlet_log_stretch): the strain
#: difference then holds fewer than ~3 significant digits.
_SMALL_DROP = 1e-3
_SPENT: dict = {}
_BUILD_SECONDS = [0.1]          # running estimate of a build's cost, updated by every build


def _table_key(scene):
    """The cache key of a scene's table (wall class, shape key, t/a, radius exponent), or None
    where no table applies (parameters per point, a fluid not of power-law form, a loaded
    outlet, an unhashable shape)."""
    rheo, wall = scene.rheology, scene.wall
    if (scene.size != 1 or rheo.radius_exponent is None or not rheo.separable
            or np.ndim(scene.outlet_pressure) or scene.outlet_pressure != 0.0):
        return None
    try:
        key = (type(wall), wall._shape_key(), float(scene.tb), float(rheo.radius_exponent))
        hash(key)
    except (TypeError, ValueError):
        return None
    return key


def _worth_building(scene) -> bool:
    """Whether the direct solves of this key have cost as much as building its table."""
    key = _table_key(scene)
    return key is not None and _SPENT.get(key, 0.0) >= _BUILD_SECONDS[0]


def _charge(scene, seconds) -> None:
    """Account ``seconds`` of direct solving to the scene's table key."""
    key = _table_key(scene)
    if key is None or key in _TABLES:
        return
    _SPENT[key] = _SPENT.get(key, 0.0) + seconds
    if len(_SPENT) > 4096:
        _SPENT.clear()


#: (wall class, shape key, t/a, radius exponent) -> SeparatedTable, or False where none can be built.
_TABLES: dict = {}


def _newton_inverse(function, slope, grid_values, grid_points, lo, hi):
    """The inverse of an increasing interpolant on [lo, hi]: linear interpolation on a grid of
    its values, then Newton steps on the interpolant itself to ~1e-15."""
    def inverse(value):
        y = np.interp(value, grid_values, grid_points)
        for _ in range(8):
            step = (function(y) - value) / slope(y)
            y = np.clip(y - step, lo, hi)
            if np.all(np.abs(step) <= 1e-15 * np.maximum(1.0, np.abs(y))):
                break
        return y

    return inverse


def _build_table(engine, scene):
    """Build the table of ``scene`` (shared quantities, power law, unloaded outlet); False if the
    a-posteriori checks fail (the direct path then serves every point)."""
    rheo, wall = scene.rheology, scene.wall
    k = float(rheo.radius_exponent)
    scale = float(wall._pressure_scale())
    norm = float(scene.tube.radius) ** k * scale
    zero = np.zeros(1, dtype=int)

    def j_hat(v):
        v = np.asarray(v, dtype=float)
        return engine._J(scene, v, np.zeros(v.size, dtype=int)) / norm

    cap = float(engine._log_stretch_cap(scene, zero))
    v_lo, v_hi = 1e-9, min(math.log(1e4), 0.999 * cap)
    y_lo, y_hi = math.log(v_lo), math.log(v_hi)
    forward, err_f = fit_chebyshev(lambda y: np.log(j_hat(np.exp(y))), y_lo, y_hi, panels=4)
    if forward is None:
        return False
    x_lo, x_hi = float(forward(np.array([y_lo]))[0]), float(forward(np.array([y_hi]))[0])
    slope = forward.derivative()
    grid_y = np.linspace(y_lo, y_hi, 2049)
    grid_x = forward(grid_y)

    inverse_of_forward = _newton_inverse(forward, slope, grid_x, grid_y, y_lo, y_hi)

    inverse, err_i = fit_chebyshev(inverse_of_forward, x_lo, x_hi, panels=4)
    if inverse is None:
        return False
    # for arrays, the same inverse of low degree on equal panels where that meets 2e-15 (about
    # half the work per point); fitted to the accepted interpolant, so its error adds to err_i
    inverse_fast, err_u = fit_uniform(inverse, x_lo, x_hi)
    # a-posteriori check of the whole chain against fresh quadratures at points not tabulated,
    # through each inverse that is served
    x_check = x_lo + (x_hi - x_lo) * (np.arange(64) + 0.37) / 64
    miss_y = 0.0
    for served in (inverse, inverse_fast) if inverse_fast is not None else (inverse,):
        y_check = served(x_check)
        miss_x = np.abs(np.log(j_hat(np.exp(y_check))) - x_check)
        miss_y = max(miss_y, float(np.max(miss_x / np.abs(slope(y_check)))))   # the error of ln v
    error = float(max(err_f, err_i + (err_u if inverse_fast is not None else 0.0), miss_y))
    # the pressure per unit modulus (for the scalar path, and for curves where the wall needs a
    # quadrature for it; a cheap closed form is evaluated directly on arrays)
    def log_rise(y):
        return np.log(wall._pressure_at_strain(np.expm1(np.exp(y)), scene.tb) / scale)

    pressure, err_p = fit_chebyshev(log_rise, y_lo, y_hi, panels=4, tol=5e-14)
    if pressure is None:
        return False
    error = max(error, err_p)
    # the scalar path's pair: the log pressure as a function of the target on the inverse's own
    # panels, so that one panel search and one generated rule give both (None where it misses)
    scalar_pair = None
    if inverse._horner:
        of_target, err_t = fit_on_breaks(lambda x: pressure(inverse(x)), inverse.breaks, tol=5e-14)
        if of_target is not None and of_target._horner:
            scalar_pair = ScalarPair(inverse, of_target)
            error = max(error, err_p + err_t)
    # its inverse (the inlet log-stretch of a pressure drop), by Newton on the pressure table
    p_slope = pressure.derivative()
    grid_w = pressure(grid_y)
    # where the pressure saturates (a limit pressure) its inverse is ill-conditioned: serve only
    # the part where it still rises by more than 1e-3 per unit of ln v (the direct path does the rest)
    rising = np.flatnonzero((np.diff(grid_w) <= 0) | (p_slope(grid_y[1:]) < 1e-3))
    top = grid_y[rising[0]] if rising.size else y_hi
    keep = grid_y <= top
    grid_y_p, grid_w = grid_y[keep], grid_w[keep]
    w_lo, w_hi = float(grid_w[0]), float(grid_w[-1])

    inverse_of_pressure = _newton_inverse(pressure, p_slope, grid_w, grid_y_p, y_lo, top)

    pressure_inverse = None
    if grid_w.size > 16 and np.all(np.diff(grid_w) > 0):
        pressure_inverse, err_pi = fit_chebyshev(inverse_of_pressure, w_lo, w_hi, panels=4)
        if pressure_inverse is not None:
            w_check = w_lo + (w_hi - w_lo) * (np.arange(64) + 0.41) / 64
            y_check = pressure_inverse(w_check)
            # the backward error: the answers are exact for pressure drops this close (relative)
            backward = float(np.max(np.abs(log_rise(y_check) - w_check)))
            if not (backward <= 1e-13 and err_pi <= 1e-13):
                pressure_inverse = None
    if not error <= 1e-13:
        return False
    j_inf = float(engine._J_infinity(scene, zero)[0]) / norm
    return SeparatedTable(forward, inverse, pressure, x_lo=x_lo, x_hi=x_hi, y_lo=y_lo, y_hi=y_hi,
                          j_inf=j_inf, error=error, k=k, wall_type=type(wall),
                          tabulate_pressure=wall._pressure_needs_quadrature(), pressure_inverse=pressure_inverse,
                          inverse_fast=inverse_fast, scalar_pair=scalar_pair)
