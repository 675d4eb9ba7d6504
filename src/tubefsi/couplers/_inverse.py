r"""The direct solution of the separated identity, point by point (vectorized over points).

Where no table serves a point (:mod:`tubefsi.couplers.tables`), its inlet log-stretch :math:`v`
solves :math:`J(v) = T` directly:

* :func:`one_batch` (the ``quadrature`` coupler's first try): one batch of integrand values per
  point, a Chebyshev interpolant on :math:`[0, 1.5 v_0]` integrated exactly
  (:func:`~tubefsi.numerics.spectral.solve_integral`), accepted only where the tail of its
  coefficients meets the tolerance;
* :func:`newton`: safeguarded Newton on :math:`\ln J` with the coupler's error-controlled
  :math:`J`, from a start that an eight-point Gauss estimate of :math:`J` brings within ~1e-10.

Every point takes the same steps whatever batch it comes in. The rest of the module: the
inlet log-stretch of a pressure drop (:func:`inlet_log_stretch`), the flow rate of a
non-separable fluid at a given inlet (:func:`solve_flow_rate`), :math:`J(\infty)` and the maximum
flow rate, whether a target is beyond :math:`J(\infty)` (:func:`beyond_limit`: a cheap screening
estimate first; :func:`clearly_beyond`: that screen alone, before any solve), and what a point
whose solve ran away is: beyond the maximum flow rate (``NoSteadyStateError``) or beyond the
solver's range (``StretchRangeError``).
"""

from __future__ import annotations

import math

import numpy as np

from .._lazy import lazy_module
from ..errors import ConvergenceError, InvalidParameterError, NoSteadyStateError, StretchRangeError
from ..fields import _array_fields, _replace
from ..numerics.kernels import EPS, blocked_matmul, rows_dot
from ..numerics.quadrature import Integral, warn_unconverged
from ..numerics.roots import solve_increasing
from ..numerics.spectral import CHEBYSHEV_DEGREE, lobatto_rule, solve_integral
from ..rheology import flow_map

optimize = lazy_module("scipy.optimize", globals(), "optimize")
elementwise = lazy_module("scipy.optimize.elementwise", globals(), "elementwise")

__all__ = ["MAX_LOG_STRETCH", "newton", "one_batch", "inlet_log_stretch", "solve_flow_rate", "j_infinity",
           "beyond_limit", "clearly_beyond", "max_flow_rate", "classify_runaway", "log_stretch_cap",
           "one_batch_mapped", "solve_flow_rate_mapped"]

#: Largest inlet stretch (relative to the outlet) a solve may reach: ln(1e15). Not a physical
#: limit (``max_flow_rate`` is the one limit): beyond it ``StretchRangeError``.
MAX_LOG_STRETCH = math.log(1e15)
#: Where :func:`j_infinity` ends its quadrature and adds the power-law tail: ln(1e8).
_PROBE_LOG_STRETCH = math.log(1e8)
#: A runaway solve within this relative distance of the maximum flow rate is at the limit (to the
#: accuracy of q_max): beyond it, not beyond the solver's range.
AT_THE_LIMIT = 1e-11
#: :func:`beyond_limit` screens with J(inf) to this relative tolerance, from initial panels this
#: wide (two Gauss-Kronrod panels on [0, ln 1e8], about 45 integrand values a point, where J(inf)
#: to 1e-14 takes about 220; their estimate is typically 1e-4), and lets it decide where the target
#: is farther from it than this many times its error estimate. (Measured over every registered
#: wall's examples with a limit, n 0.3-0.99, t/a 0.02-3: the estimate exceeds the error 20-fold.)
_SCREEN_RTOL, _SCREEN_PANEL_WIDTH, _SCREEN_SAFETY = 1e-2, 10.0, 10.0
#: Newton on ln J stops after a step below this, relative to v and to the distance to a maximum
#: stretch: its error is then ~(step)^2 / 2 relative to both, and the evaluation it came from,
#: that close, is the answer's error estimate (:func:`tubefsi.numerics.roots.solve_increasing`).
_QUADRATIC_STEP = 1e-8
#: A pressure drop below this fraction of the outlet pressure starts its Newton iteration from the
#: linearized rise (:func:`inlet_log_stretch`): the strain difference then holds few digits.
_SMALL_DROP = 1e-3
#: The Gauss start: eight Gauss–Legendre nodes on [0, 1] and the end, at most eight steps.
_START_NODES, _START_WEIGHTS = np.polynomial.legendre.leggauss(8)
_START_NODES, _START_WEIGHTS = 0.5 * (_START_NODES + 1.0), 0.5 * _START_WEIGHTS
_START_NODES_AND_END = np.append(_START_NODES, 1.0)
_START_STEPS = 8
#: A one-batch interval shorter than this (in v) tries degree 12 before degree 16: measured over
#: the random scenes of benchmarks/speed.py, its tail met 1e-14 at every point below 0.19.
_LOW_DEGREE, _LOW_DEGREE_REACH = 12, 0.15
#: The degrees :func:`one_batch` tries in turn after that (or first, on a longer interval): a
#: point whose interpolant's tail misses at one is tried at the next on the same interval.
_HIGHER_DEGREES = (CHEBYSHEV_DEGREE, 24, 32)


def _pick(value, index):
    """A per-point quantity (scalar or flat array) at ``index``."""
    return value if np.ndim(value) == 0 else value[index]


def log_stretch_cap(scene, index):
    """The largest log-stretch a solve may reach: below a maximum stretch, and ln(1e15)."""
    v_max = np.asarray(_pick(scene.log_stretch_max, index), dtype=float)
    # (fmin drops a NaN, and an infinite maximum is above the cap)
    return np.fmin(MAX_LOG_STRETCH, v_max * (1 - 8 * EPS)) + np.zeros(np.shape(index))


def _linear_guess(engine, scene, target, index, q):
    """:math:`T/f(0)`, capped at 1: the root of the linearized identity."""
    with np.errstate(divide="ignore", invalid="ignore"):
        slope0 = engine.integrand(scene.at(index), np.zeros(target.shape), q)
        return np.where(target > 0, np.minimum(target / slope0, 1.0), 0.0)


def gauss_start(engine, scene, index, target, guess, q, top):
    r"""A start within ~1e-10 of the root: Newton on an eight-point Gauss–Legendre estimate of
    :math:`J(v)` over :math:`[0, v]` (its slope the exact integrand at :math:`v`), from the linear
    guess until a step moves less than 1e-5 of :math:`v` (at most eight steps). Only a start: the
    error-controlled iteration that follows decides the answer."""
    live = np.flatnonzero((target > 0) & (guess > 0))
    if live.size == 0:
        return guess
    ids, t, v = index[live], target[live], guess[live].copy()
    hi = top[live] + np.zeros(live.size)
    q_live = None if q is None else q[live]
    act = np.arange(live.size)
    with np.errstate(all="ignore"):
        for _ in range(_START_STEPS):
            va = v[act]
            values = engine.integrand(scene.at(ids[act], column=True), va[:, None] * _START_NODES_AND_END,
                                      None if q is None else q_live[act][:, None])
            estimate = va * rows_dot(values[:, :-1], _START_WEIGHTS)
            nxt = np.clip(va - np.log(estimate / t[act]) * estimate / values[:, -1], 0.5 * va,
                          np.minimum(2.0 * va, hi[act]))
            nxt = np.where(np.isfinite(nxt) & (nxt > 0), nxt, va)
            v[act] = nxt
            act = act[np.abs(nxt - va) > 1e-5 * va]
            if act.size == 0:
                break
    out = guess.copy()
    out[live] = v
    return out


def newton(engine, scene, target, index, q=None, upper=None):
    r"""``(v, ok, final)``: safeguarded Newton on :math:`\ln J(v) = \ln T` at the points ``index``
    (``q`` per point for a non-separable rheology), below ``upper`` and the largest log-stretch a
    solve may reach. ``final`` is the :class:`~tubefsi.numerics.quadrature.Integral` of :math:`J`
    at the answer (the iteration's last evaluation where it stands for it, else evaluated once
    more). ``ok`` is False where no root exists there: ``v = inf`` where the target is at or beyond
    :math:`J(\infty)` (without ``upper``, a wall with a limit pressure: checked before iterating by
    :func:`beyond_limit`, ``final`` holding the :math:`J(\infty)` that told it), else the
    log-stretch the iteration ran to."""
    target = np.asarray(target, dtype=float).ravel()
    index = np.asarray(index).ravel()
    n = target.size
    qflat = None if scene.rheology.separable else np.broadcast_to(np.asarray(q, dtype=float), target.shape)
    v, ok = np.zeros(n), np.ones(n, dtype=bool)
    value, error, converged = np.array(target), np.zeros(n), np.ones(n, dtype=bool)
    todo = np.flatnonzero(target > 0)
    # (a non-separable fluid's J(inf) depends on q and costs the flow law far from the tube: asked
    # for only where an iteration runs away, classify_runaway)
    if upper is None and todo.size and qflat is None:
        pts = scene.at(index[todo])
        limited = np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb)) + np.zeros(todo.size))
        if np.any(limited):
            sub = todo[limited]
            over, j_inf = beyond_limit(engine, scene, target[sub], index[sub])
            where = sub[over]
            v[where], ok[where] = np.inf, False
            value[where], error[where], converged[where] = j_inf.value[over], j_inf.error[over], j_inf.converged[over]
            todo = np.setdiff1d(todo, where, assume_unique=True)
    if todo.size:
        up = None if upper is None else np.broadcast_to(np.asarray(upper, dtype=float), target.shape)[todo]
        v[todo], ok[todo], part = _iterate(engine, scene, target[todo], index[todo],
                                           None if qflat is None else qflat[todo], up)
        value[todo], error[todo], converged[todo] = part.value, part.error, part.converged
    return v, ok, Integral(value=value, error=error, converged=converged, panels=np.zeros(n, dtype=int))


class _Remembered:
    """``F(x, i)`` of an integral (``integral(x, i)`` returns an :class:`Integral` at the points
    ``i``), keeping each point's last evaluation: for Newton's method, where the evaluation its last,
    quadratically small step came from stands for the answer's (``solve_increasing``'s
    ``evaluated``), so the answer's error estimate needs no evaluation of its own."""

    def __init__(self, integral, start):
        self.integral = integral
        self.value = np.array(start, dtype=float)
        self.error = np.zeros(self.value.size)
        self.converged = np.ones(self.value.size, dtype=bool)   # whether the last evaluation met its tolerance

    def __call__(self, x, i):
        result = self.integral(x, i)
        self.converged[i], self.error[i] = result.converged, result.error
        self.value[i] = result.value
        return np.asarray(result.value, dtype=float)

    def last(self, converged=None) -> Integral:
        """The last evaluations as an :class:`Integral` (``converged``: instead of their own flags)."""
        return Integral(value=self.value, error=self.error,
                        converged=self.converged if converged is None else converged,
                        panels=np.zeros(self.value.size, dtype=int))


def _iterate(engine, scene, target, index, qflat, upper):
    """:func:`newton`'s iteration proper, on points with a positive target."""
    n = target.size
    F = _Remembered(lambda v, i: engine._J(scene, v, index[i], None if qflat is None else qflat[i]), target)

    def dF(v, i):
        return engine.integrand(scene.at(index[i]), v, None if qflat is None else qflat[i])

    cap = log_stretch_cap(scene, index)
    guess = _linear_guess(engine, scene, target, index, qflat)
    if upper is not None:
        guess = np.minimum(guess, upper)
    guess = gauss_start(engine, scene, index, target, guess, qflat,
                        np.minimum(0.5 * cap, np.inf if upper is None else upper))
    capped = np.isfinite(np.asarray(_pick(scene.log_stretch_max, index), dtype=float) + np.zeros(n))
    limit = np.where(capped, cap, np.inf)
    upper = limit if upper is None else np.minimum(upper, limit)
    guess = np.where(capped, np.minimum(guess, 0.5 * cap), guess)
    evaluated = np.zeros(n, dtype=bool)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        v, ok = solve_increasing(F, dF, target, guess=guess, upper=upper, xmax=MAX_LOG_STRETCH, max_step=2.0,
                                 log=True, evaluated=evaluated, quadratic=_QUADRATIC_STEP,
                                 pole=np.where(capped, cap, np.inf))
    again = np.flatnonzero(ok & ~evaluated)
    if again.size:                 # the answer's own error estimate where the iteration ended elsewhere
        F(v[again], again)
    if np.any(capped):
        # converged onto the maximum stretch without reaching the target: out of reach
        at_cap = np.flatnonzero(capped & (v >= cap * (1 - 1e-12)))
        if at_cap.size:
            with np.errstate(all="ignore"):
                short = F(v[at_cap], at_cap) < target[at_cap] * (1 - 1e-9)
            ok = ok.copy()
            ok[at_cap[short]] = False
    return v, ok, F.last(F.converged | ~ok)


def one_batch(engine, scene, target, index, bound):
    r"""``(v, solved)``: :func:`~tubefsi.numerics.spectral.solve_integral` at the points with a
    positive target (separable rheology), on :math:`[0, 1.5 v_0]` (:math:`v_0` the linear guess:
    the root is within a few tens of per cent of it for a moderate strain), and on three times that
    where the integral fell short; never beyond ``bound``. An interval shorter than
    ``_LOW_DEGREE_REACH`` is tried at degree 12 first, then (or first, a longer one) at degrees
    16, 24 and 32 in turn where the interpolant's tail misses (a wall whose slope varies over the
    interval: a few tens of per cent of strain in a stiffening one): which degree answers depends
    on the point alone."""
    target = np.asarray(target, dtype=float).ravel()
    index = np.asarray(index).ravel()
    v = np.zeros(target.size)
    solved = np.zeros(target.size, dtype=bool)
    bound = np.broadcast_to(bound, target.shape)
    top = np.minimum(1.5 * _linear_guess(engine, scene, target, index, None), bound)

    def attempt(points, degree):
        """Solve ``points`` (positions) at ``degree``; returns their (good, short) masks."""
        ids = index[points]

        def f(u, i):            # u: nodes x points, so per-point quantities broadcast as rows
            return engine.integrand(scene.at(ids[i]), u)

        with np.errstate(all="ignore"):
            x, good, short = solve_integral(f, target[points], top[points], rtol=engine._RTOL, degree=degree)
        v[points[good]] = x[good]
        solved[points[good]] = True
        return good, short

    live = np.flatnonzero((target > 0) & (top > 0))
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
        shorter = [short_low]
        for degree in _HIGHER_DEGREES:                             # the tail missed again: higher
            if high.size == 0:
                break
            good, short = attempt(high, degree)
            shorter.append(high[short])
            high = high[~good & ~short]
        shorter = np.concatenate(shorter)
        wider = np.minimum(3.0 * top[shorter], bound[shorter])
        keep = wider > top[shorter]
        top[shorter] = wider
        live = np.sort(shorter[keep])
    return v, solved


def _head(engine, scene, v, index, q, rtol) -> Integral:
    """J(v) by the coupler's own rule, or (``rtol``) a screening estimate: the adaptive rule to
    that looser tolerance from panels ``_SCREEN_PANEL_WIDTH`` wide (a fixed rule is its own)."""
    if rtol is None or engine._coarse:
        return engine._J(scene, v, index, q)

    def f(u, i):
        return engine.integrand(scene.at(index[i], column=True), u, None if q is None else q[i, None])

    return engine.integrate(scene, f, v, index, panel_width=_SCREEN_PANEL_WIDTH, rtol=max(rtol, engine._RTOL))


def j_infinity(engine, scene, index, q=None, rtol=None) -> Integral:
    r""":math:`J(\infty)` at the points ``index``: up to a maximum stretch where the tube law peaks
    there, else the quadrature to ln(1e8) plus the power-law tail of the integrand beyond it
    (:math:`sP' \sim s^{1-\kappa}`, :math:`\psi \sim R^{-\mu}`: a tail :math:`f(v_1)/\alpha`,
    :math:`\alpha = \kappa - 1 - \mu > 0`); ``inf`` where the wall has no limit pressure or the
    integrand does not decay. With ``rtol``, a screening estimate (:func:`_head`): the same tail,
    its quadrature to that looser tolerance (the error estimate says how loose)."""
    pts = scene.at(index)
    n = index.size
    value, error = np.full(n, np.inf), np.zeros(n)
    converged = np.ones(n, dtype=bool)
    limited = np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb)) + np.zeros(n))
    qq = None if q is None else np.broadcast_to(np.asarray(q, dtype=float), index.shape)
    v_max = np.asarray(pts.log_stretch_max, dtype=float) + np.zeros(n)
    peak = limited & np.isfinite(v_max)
    if np.any(peak):      # the tube law ends at its pressure peak: J stays finite up to it
        part = _head(engine, scene, v_max[peak] * (1 - 8 * EPS), index[peak], None if qq is None else qq[peak], rtol)
        value[peak], error[peak], converged[peak] = part.value, part.error, part.converged
    far = np.flatnonzero(limited & ~peak)
    if far.size:
        sub = index[far]
        sp = scene.at(sub)
        rheo = sp.rheology
        mu = rheo.radius_exponent
        if mu is None:            # the local exponent of G in R far out, where the probe ends
            r = np.asarray(sp.radius * np.exp(_PROBE_LOG_STRETCH)) + np.zeros(sub.shape)
            if rheo.separable:
                g0, g1 = rheo._radius_factor(r), rheo._radius_factor(10 * r)
            else:
                g0, g1 = rheo._pressure_gradient(qq[far], r), rheo._pressure_gradient(qq[far], 10 * r)
            mu = -np.log(g1 / g0) / np.log(10.0)
        alpha = np.asarray(sp.wall._stiffness_decay_exponent(sp.tb)) - 1.0 - mu + np.zeros(sub.shape)
        decays = alpha > 1e-12
        if np.any(decays):
            ids = sub[decays]
            v1 = np.full(ids.size, _PROBE_LOG_STRETCH)
            qd = None if qq is None else qq[far][decays]
            head = _head(engine, scene, v1, ids, qd, rtol)
            tail = engine.integrand(scene.at(ids), v1, qd) / alpha[decays]
            where = far[decays]
            value[where], error[where], converged[where] = head.value + tail, head.error, head.converged
    return Integral(value=value, error=error, converged=converged, panels=np.zeros(n, dtype=int))


def _limit(engine, scene, index, rtol=None) -> Integral:
    """``engine._J_infinity`` at the points ``index``: computed once for a scene of scalars (its
    points share every quantity, so their J(inf) are the same to the bit)."""
    if scene.size > 1 or index.size < 2:
        return engine._J_infinity(scene, index, rtol=rtol)
    one = engine._J_infinity(scene, index[:1], rtol=rtol)
    n = index.size
    return Integral(value=np.repeat(np.ravel(one.value), n), error=np.repeat(np.ravel(one.error), n),
                    converged=np.repeat(np.ravel(one.converged), n), panels=np.repeat(np.ravel(one.panels), n))


def _screen(engine, scene, target, index):
    """``(over, close, screen)``: the screening estimate of J(inf) at the points ``index``
    (``_SCREEN_RTOL``), the targets it puts at or beyond J(inf) for certain, and those too close to
    it to tell (NaN among them)."""
    screen = _limit(engine, scene, index, _SCREEN_RTOL)
    value = np.asarray(screen.value, dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        margin = _SCREEN_SAFETY * (np.asarray(screen.error, dtype=float) + engine._RTOL * value)
        margin = np.where(np.isfinite(value), margin, 0.0)        # (inf: no finite limit, exactly)
        over = target >= value + margin
        close = ~over & ~(target < (value - margin) * (1.0 - AT_THE_LIMIT))
    return over, close, screen


def beyond_limit(engine, scene, target, index):
    r"""``(over, j_inf)`` at the points ``index`` (a separable fluid): whether each positive target
    is at or beyond :math:`J(\infty)` (to :data:`AT_THE_LIMIT`), and the :math:`J(\infty)` that
    told it. A screening estimate (``engine._J_infinity(..., rtol=_SCREEN_RTOL)``, a fraction of
    the cost) tells every target farther from it than ``_SCREEN_SAFETY`` times its error estimate
    (and the coupler's own tolerance); :math:`J(\infty)` to the coupler's own tolerance tells the
    others. So the answer is the one :math:`J(\infty)` itself gives; only the time changes."""
    over, close, screen = _screen(engine, scene, target, index)
    if not np.any(close):
        return over, screen
    sub = np.flatnonzero(close)
    own = _limit(engine, scene, index[sub])
    over[sub] = target[sub] >= own.value * (1.0 - AT_THE_LIMIT)
    return over, screen.replaced(sub, own)


def clearly_beyond(engine, scene, target, index):
    r"""``(positions, j_inf)``: the targets (a separable fluid) that the screening estimate of
    :math:`J(\infty)` puts beyond it for certain (:func:`beyond_limit` without its second look,
    which the solve's own check gives the others), and those estimates; asked before any solve.
    Only a target the rigid tube (of the outlet's radius) would carry at or above the wall's limit
    pressure is asked: :math:`\psi` falls as the radius grows, so
    :math:`J(\infty) \ge (p_{lim} - p_{out})/\psi(a\lambda_{out})` and no other target is beyond
    it; the others (in a sweep below the limit, all) cost one comparison."""
    pts = scene.at(index)
    with np.errstate(all="ignore"):
        rise = np.asarray(pts.wall._limit_pressure(pts.tb), dtype=float) - pts.outlet_pressure + np.zeros(index.size)
        rigid = target * pts.rheology._radius_factor(pts.radius * pts.outlet_stretch)
        asked = np.flatnonzero(np.isfinite(rise) & (target > 0) & (rigid >= rise))
    if asked.size == 0:
        return asked, None
    over, _, screen = _screen(engine, scene, target[asked], index[asked])
    return asked[over], Integral(value=screen.value[over], error=screen.error[over],
                                 converged=screen.converged[over], panels=screen.panels[over])


def max_flow_rate(engine, scene, index):
    """The largest flow rate with a steady state at the points ``index`` of a flat scene (``inf``
    where none): :math:`\\phi^{-1}(J(\\infty)/L)` for a separable fluid, a bracketed search in
    :math:`\\ln q` of :math:`H(\\infty; q) = L` for any other."""
    pts = scene.at(index)
    limited = np.isfinite(np.asarray(pts.wall._limit_pressure(pts.tb), dtype=float) + np.zeros(index.shape))
    out = np.full(index.shape, np.inf)
    if not np.any(limited):
        return out
    ids = index[limited]
    if not scene.rheology.separable:
        # one search per point, on that point as a scene of scalars (its fluid's parameters may vary)
        out[limited] = [_max_flow_rate_point(engine, scene.point(int(i)), 0) for i in ids]
        return out
    j_inf = engine._J_infinity(scene, ids)
    finite = np.isfinite(j_inf.value)
    if np.any(finite):
        sp = scene.at(ids[finite])
        with np.errstate(over="ignore"):
            q = sp.rheology._flow_factor_inverse(j_inf.value[finite] / sp.length) + 0.0 * j_inf.value[finite]
        q_all = np.full(ids.size, np.inf)
        q_all[finite] = np.where(np.isfinite(q), q, np.inf)
        out[limited] = q_all
        # a stiffening law whose "limit" is where its pressure leaves double range has a maximum flow
        # rate beyond it too (inf, exactly): an estimate matters only for a representable q_max
        warn_unconverged("the integral to the maximum flow rate", j_inf, where=np.isfinite(q_all))
    return out


def _max_flow_rate_point(engine, scene, i):
    """Non-separable rheology, point ``i``: the q with H(inf; q) = L (H decreases with q), by a
    bracketed root search in ln q."""
    ids = np.array([i])
    pts = scene.at(ids)
    L = float(np.asarray(pts.length).ravel()[0])
    tau_y = float(scene.rheology.yield_stress)
    if tau_y > 0 and not engine._J_infinity(scene, ids, 0.0).value[0] > L:
        return 0.0  # even the limit pressure cannot yield the fluid all along the tube

    def excess(log_q):
        return math.log(engine._J_infinity(scene, ids, math.exp(log_q)).value[0]) - math.log(L)

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


def classify_runaway(engine, scene, q, bad, v, *, raise_):
    r"""What the points ``bad`` (positions) whose solve found no root are. Where the solve found the
    target at or beyond :math:`J(\infty)` (``v = inf``) the point is beyond its maximum flow rate;
    elsewhere (the iteration ran away) the maximum flow rate decides (to its accuracy,
    :data:`AT_THE_LIMIT`). Points beyond it are returned (with ``raise_``, the first is a
    ``NoSteadyStateError``, its limit computed for the message); any other is beyond the solver's
    range: a ``StretchRangeError`` or, below a maximum stretch, a ``NoSteadyStateError`` giving the
    flow rate that reaches it."""
    bad = np.asarray(bad)
    q_bad = q[bad]
    q_max = np.full(bad.size, np.nan)
    known = np.isinf(v[bad])          # (a root beyond J(inf): v = inf)
    if not np.all(known):
        rest = bad[~known]
        q_max[~known] = np.broadcast_to(np.asarray(engine.max_flow_rate(scene.take(rest) if scene.size > 1 else scene),
                                                   dtype=float), rest.shape)
    beyond = known | (np.isfinite(q_max) & (q_bad >= q_max * (1.0 - AT_THE_LIMIT)))
    if raise_ and np.any(beyond):
        i = int(np.argmax(beyond))
        if np.isnan(q_max[i]):          # known beyond J(inf): its limit, for the message
            q_max[i] = float(engine.max_flow_rate(scene.point(int(bad[i]))))
        detail = "the tube inflates without bound" + ("" if q_bad[i] >= q_max[i] else (
            f" (this flow rate is the maximum one to within {AT_THE_LIMIT:.0e}, its accuracy)"))
        raise NoSteadyStateError("flow_rate", float(q_max[i]), float(q_bad[i]), detail)
    if np.all(beyond):
        return bad
    i = int(np.argmax(~beyond))
    one = scene.point(int(bad[i]))
    ids = np.array([0])
    cap = np.atleast_1d(log_stretch_cap(one, ids))
    pts = one.at(ids)
    if one.rheology.separable:
        reach = float(np.ravel(pts.rheology._flow_factor_inverse(engine._J(one, cap, ids).value / pts.length))[0])
    else:
        reach = float(solve_flow_rate(engine, one, cap, engine.pressure_rise(one, cap, ids, warn=False), ids)[0])
    if float(cap[0]) < MAX_LOG_STRETCH:
        if q_bad[i] >= reach:
            raise NoSteadyStateError("flow_rate", reach, float(q_bad[i]),
                                     "the inlet stretch would reach the wall's maximum stretch")
        raise InvalidParameterError("flow_rate", "flow rates whose inlet stretch can be told from the wall's "
                                    "locking stretch in double precision", float(q_bad[i]),
                                    f"below the limit {reach:.6g} m^3/s the inlet stretch is the locking stretch to "
                                    "the last digit: the pressure drop there cannot be resolved")
    limit = "max_flow_rate is inf" if not math.isfinite(q_max[i]) else f"below max_flow_rate = {q_max[i]:.6g} m^3/s"
    raise StretchRangeError(reach, float(q_bad[i]), f"a steady state exists ({limit}) but its inlet stretch exceeds "
                            "1e15, and R/L far exceeds 0.1 there: the model no longer applies")


def inlet_log_stretch(engine, scene, dp, index):
    r"""The inlet log-stretch under the pressure drop ``dp`` at the points ``index``.

    With an unloaded outlet, :math:`v = \mathrm{log1p}(\varepsilon(\Delta p))` from the tube law's
    inverse. With an outlet pressure, differencing the strains at :math:`p_{out}` and
    :math:`p_{out} + \Delta p` would lose :math:`\varepsilon_{mach}\,p_{out}/\Delta p`; so the strain
    difference only starts a Newton iteration on the pressure rise itself,
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
    F = _Remembered(lambda x, i: engine.rise_from_outlet(scene, x, sub[i]), np.zeros(sub.size))

    def dF(x, i):
        return engine._slope(scene.at(sub[i]), x)

    # a drop far below the outlet pressure: the strain difference is rounding noise, and Newton on
    # ln F from far above a tiny root only bisects; the linearized rise is within O(v) of the root
    guess = np.maximum(v[polish], 0.0)
    small = dp[polish] <= _SMALL_DROP * np.abs(np.asarray(pts.outlet_pressure) + np.zeros(dp.shape))[polish]
    if np.any(small):
        guess[small] = dp[polish][small] / dF(np.zeros(int(np.count_nonzero(small))), np.flatnonzero(small))
    evaluated = np.zeros(sub.size, dtype=bool)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        w, _ = solve_increasing(F, dF, dp[polish], guess=guess, max_step=2.0, log=True, evaluated=evaluated,
                                quadratic=_QUADRATIC_STEP)
    again = np.flatnonzero(~evaluated)
    if again.size:                               # the answer's own error estimate where Newton ended elsewhere
        F(w[again], again)
    warn_unconverged("the pressure rise from the outlet", F.last())
    v = v.copy()
    v[polish] = w
    return v


def solve_flow_rate(engine, scene, v, dp, index):
    r"""Non-separable rheology: find q with H(v; q) = L (H decreases with q), per point.

    Rigid tubes of the outlet and inlet radii under the mean gradient dp/L bracket q. A
    yield-stress fluid has a finite :math:`H(v; 0^+)`, with :math:`G = 2\tau_y/R`: where it does
    not exceed L the pressure drop cannot yield the fluid all along the tube, and q = 0.
    """
    pts = scene.at(index)
    a, L, rheo = pts.radius, pts.length, pts.rheology
    v = np.asarray(v, dtype=float)
    dp = np.asarray(dp, dtype=float)
    g = np.where(dp == 0, 1.0, dp) / L
    if flow_map.kind(rheo) == "stress" and any(np.ndim(getattr(rheo, f)) for f in _array_fields(type(rheo))):
        # fluids given by their stress, one per point: the inlet's rigid tube bounds q from above
        # through its wall shear rate (Gamma <= 4 gamma_w / 3, the rate bracketed by bisection of
        # the law), and the search runs down from there (the law's generic inverse takes one fluid)
        r_in = a * engine.stretch_at(pts, v) + 0.0 * g
        _, x_in = flow_map.log_rate_bracket(rheo, 0.5 * g * r_in)
        with np.errstate(over="ignore"):
            q_hi = (math.pi / 3.0) * r_in**3 * np.exp(x_in)
        q_lo = np.zeros(q_hi.shape)
    else:
        q_lo = rheo._flow_rate(a * pts.outlet_stretch + 0.0 * g, g)
        q_hi = rheo._flow_rate(a * engine.stretch_at(pts, v), g)
    flowing = (q_hi > 0) & (dp > 0)
    if np.any(np.asarray(scene.rheology.yield_stress) > 0) and np.any(flowing):
        sel = np.flatnonzero(flowing)
        flowing[sel] = engine._J(scene, v[sel], index[sel], np.zeros(sel.size)).value > _pick(L + 0.0 * v, sel)
    q = np.zeros(v.shape)
    if not np.any(flowing):
        return q
    sel = np.flatnonzero(flowing)
    v_s, q_lo, q_hi = v[sel], q_lo[sel], q_hi[sel]
    ids = index[sel]
    log_length = np.log(np.asarray(L, dtype=float) + np.zeros(v.shape))[sel]

    def f(log_q, v, i, log_l):
        return np.log(engine._J(scene, v, i, np.exp(log_q)).value) - log_l

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


#: The degrees :func:`one_batch_mapped` tries, in turn (a short interval: three times wider instead).
_MAPPED_DEGREES = (24, 32, 32)
#: Its tolerance on the tail: the flow map's own values carry ~1e-15 of rounding (ln Gamma to a few
#: eps of itself, inverted), which the tail of an interpolant of them shows as ~1e-14.
_MAPPED_RTOL = 5e-14


def one_batch_mapped(engine, scene, target, index, q, bound):
    r"""``(v, solved)``: :func:`one_batch` for a non-separable fluid whose flow law a
    :mod:`~tubefsi.rheology.flow_map` serves. At the flow rate ``q`` of a point, the node
    :math:`u` has :math:`\ln\Gamma = \ln(4q/\pi) - 3\ln(a\lambda_{out}) - 3u`, so the map built over
    that range per point gives :math:`\tau_w` and :math:`G = 2\tau_w/(a s)` at every node without a
    table; the identity :math:`\int_0^v sP'(s)/G\,du = T` is then solved on the Chebyshev
    interpolant in :math:`u` as for a separable fluid. A point is solved only where the map vouches
    for every node and the interpolant's tail for the integral (else left to :func:`newton`)."""
    target = np.asarray(target, dtype=float).ravel()
    index = np.asarray(index).ravel()
    q = np.asarray(q, dtype=float)
    if q.shape != target.shape:
        q = np.broadcast_to(q, target.shape)
    v = np.zeros(target.size)
    solved = np.zeros(target.size, dtype=bool)
    bound = np.asarray(bound, dtype=float)
    if bound.shape != target.shape:
        bound = np.broadcast_to(bound, target.shape)
    live = np.nonzero((target > 0) & (q > 0))[0]
    which = flow_map.kind(scene.rheology)
    if live.size == 0 or which is None:
        return v, solved
    with np.errstate(all="ignore"):
        return _one_batch_mapped(engine, scene, target, index, q, bound, v, solved, live, which)


def _one_batch_mapped(engine, scene, target, index, q, bound, v, solved, live, which):
    """:func:`one_batch_mapped` once its arguments are arrays and some point is live."""
    pts = scene.at(index)
    zeros = np.zeros(target.size)
    y_out = (np.log(4.0 / math.pi * q) - 3.0 * np.log(pts.radius * pts.outlet_stretch)) + zeros
    # the linear guess from the law at the outlet's apparent rate (a start: within a factor ~2)
    if which == "closed":      # (exact there, and cheap)
        rough, _, _ = flow_map.flow_map(pts.rheology, y_out, y_out, which=which).wall_stress(y_out[None])
        rough = rough[0]
    else:
        rough = np.asarray(pts.rheology._stress(np.exp(y_out)), dtype=float) + zeros
    slope0 = np.asarray(engine._slope(pts, 0.0), dtype=float) + zeros           # (at the outlet, u = 0)
    # (bound is finite: a NaN guess stays NaN, and fails the test below)
    top = np.minimum(1.5 * target * 2.0 * rough / ((pts.radius * pts.outlet_stretch) * slope0), bound)
    live = live[top[live] > 0]
    rtol = max(engine._RTOL, _MAPPED_RTOL)
    split = np.zeros(0, dtype=int)              # (tail missed at the top degree: solved in pieces)
    for degree in _MAPPED_DEGREES:
        if live.size == 0:
            break
        every = live.size == target.size
        sel = slice(None) if every else live       # (every point: views, no gathers)
        f, vouched = _mapped_integrand(engine, pts if every else scene.at(index[live]), y_out[sel], top[sel], which)
        x, good, short = solve_integral(f, target[sel], top[sel], rtol=rtol, degree=degree, method="barycentric")
        good &= vouched
        v[live[good]] = x[good]
        solved[live[good]] = True
        if good.all():
            live = live[:0]
            break
        # short: three times the interval; a tail that missed: the next degree on the same one, or
        # (at the top degree already) the interval in pieces
        again = short & vouched
        wider = np.minimum(3.0 * top[live[again]], bound[live[again]])
        keep = wider > top[live[again]]
        top[live[again]] = wider
        missed = live[~good & ~short & vouched]
        if degree == _MAPPED_DEGREES[-1]:
            split = np.concatenate([split, missed])
            missed = missed[:0]
        live = np.sort(np.concatenate([live[again][keep], missed]))
    for pieces in _MAPPED_PIECES:
        if split.size == 0:
            break
        f, vouched = _mapped_integrand(engine, scene.at(index[split]), y_out[split], top[split], which)
        x, good = _solve_in_pieces(f, target[split], top[split], pieces, _MAPPED_DEGREES[-1], rtol)
        good &= vouched
        v[split[good]] = x[good]
        solved[split[good]] = True
        split = split[~good & vouched]
    return v, solved


#: A point whose interpolant's tail misses at the top degree is solved on its interval cut into this
#: many equal pieces, in turn (:func:`_solve_in_pieces`).
_MAPPED_PIECES = (2, 4)


def _mapped_integrand(engine, sub, y_out, top, which):
    """``(f, vouched)``: the separated integrand of the points ``sub`` (:class:`~tubefsi.scene.Points`
    of a non-separable fluid, at their flow rates: ``y_out`` is ln Gamma at the outlet) from a flow
    map built over ``[0, top]`` of each, and whether the map vouched for every value ``f`` gave
    (updated by each call); ``which``: the fluid's :func:`~tubefsi.rheology.flow_map.kind`."""
    fmap = flow_map.flow_map(sub.rheology, y_out - 3.0 * top - 1e-9, y_out + 1e-9, which=which)
    vouched = np.ones(y_out.size, dtype=bool)
    a_out = sub.radius * sub.outlet_stretch

    def f(u, i):
        tau, ok, _ = fmap.wall_stress(y_out - 3.0 * u)
        vouched[:] &= ok.all(axis=0)
        return engine._slope(sub, u) * (a_out * np.exp(u)) / (2.0 * tau)

    return f, vouched


def _solve_in_pieces(f, target, upper, pieces, degree, rtol):
    r"""``(x, solved)``: :math:`\int_0^x f = T` on ``[0, X]`` cut into ``pieces`` equal pieces, each
    interpolated on its own Chebyshev–Lobatto nodes (``f`` is asked for every point of the batch on
    each piece). The integral of each piece is its interpolant's (Clenshaw–Curtis); the root lies in
    the first piece where their running sum reaches :math:`T`, and is solved there
    (:func:`~tubefsi.numerics.spectral.solve_integral` on that piece's values, with the target less
    the pieces below). Accepted where the tails of the pieces up to it sum to at most
    ``rtol`` :math:`T` and every value is positive and finite."""
    rule = lobatto_rule(degree)
    n = target.size
    width = upper / pieces
    weights = rule.matrix[rule.cumulative][-1]                   # the integral over [-1, 1]
    below = np.zeros(n)                                           # the pieces' integrals below the root's
    tails = np.zeros(n)
    x, solved = np.zeros(n), np.zeros(n, dtype=bool)
    pending = np.ones(n, dtype=bool)
    for k in range(pieces):
        start = k * width
        values = f(start + rule.nodes[:, None] * width, np.arange(n))
        coef = blocked_matmul(rule.matrix[rule.coef], values)
        tails += np.abs(coef[-3:]).sum(axis=0) * width
        whole = 0.5 * width * (weights @ values)
        positive = np.all(np.isfinite(values) & (values > 0), axis=0)
        here = pending & positive & ((below + whole >= target) | (k == pieces - 1))
        pending &= positive
        if np.any(here):
            sel = np.flatnonzero(here)
            local, good, _ = solve_integral(None, target[sel] - below[sel], width[sel], rtol=np.inf,
                                            values=values[:, sel], degree=degree)
            ok = good & (tails[sel] <= rtol * target[sel])
            x[sel[ok]] = start[sel[ok]] + local[ok]
            solved[sel[ok]] = True
            pending[sel] = False
        below += whole
    return x, solved


#: The degrees :func:`solve_flow_rate_mapped` tries, in turn, on the interval [0, v].
_FLOW_DEGREES = (24, 48)
#: Its Newton iteration in ln q: at most this many steps, the last one below ``_FLOW_STEP``.
_FLOW_ITERATIONS, _FLOW_STEP = 40, 1e-9
#: The width (in ln of the wall shear rate) of the bisection that bounds the rigid tubes' rates.
_BRACKET_WIDTH = 0.05


def _twice(model, n):
    """``model`` with its array parameters (one per point, ``n``) repeated for two sets of points."""
    arrays = {f: np.broadcast_to(v, (n,)) for f in _array_fields(type(model)) if np.ndim(v := getattr(model, f))}
    return _replace(model, {f: np.concatenate([v, v]) for f, v in arrays.items()}) if arrays else model


#: Where the outlet alone would not yield a yield-stress fluid, the search starts this far below the
#: inlet's bound in ln q (a flow rate e^-60 of it: below that, the adaptive route decides).
_UNYIELDED_REACH = 60.0


def solve_flow_rate_mapped(engine, scene, v, dp, index):
    r"""``(q, solved)``: the flow rate of a non-separable fluid at a given inlet log-stretch ``v``
    (the pressure-controlled problem), from the flow map of its law, for every point at once.

    With :math:`v` known the separated identity is :math:`H(q) = \int_0^v c(u)/\tau_w(\Gamma(q, u))\,du
    = L`, :math:`c = sP'(s)\,a s/2` (the wall's part, fixed) and
    :math:`\ln\Gamma = \ln(4q/\pi) - 3\ln(a\lambda_{out}) - 3u`. On the Chebyshev–Lobatto nodes of
    :math:`[0, v]` the map (:mod:`~tubefsi.rheology.flow_map`, built once over the range of
    :math:`\ln\Gamma` that the bracket of :func:`solve_flow_rate` spans) gives :math:`\tau_w`, and
    Newton's method on :math:`\ln H(\ln q) = \ln L` uses
    :math:`dH/d\ln q = -\int_0^v (c/\tau_w)\,k\,du`, :math:`k = d\ln\tau_w/d\ln\Gamma =
    \Gamma/(4\dot\gamma_w - 3\Gamma)` (the Rabinowitsch–Mooney identity), kept inside the
    bracket (bisection where a step leaves it); a step below 1e-9 is the last (quadratic: the
    answer is 1e-18 from the root after it). A point is solved only where the map vouches for
    every node and the tail of the interpolant of the integrand at that last evaluation (1e-9 from
    the answer) meets the tolerance, :math:`v\sum_{k=n-2}^n|c_k| \le 5\cdot10^{-14} L`; the others are left to
    :func:`solve_flow_rate`. A yield-stress fluid that the pressure drop cannot yield all along
    the tube (:math:`H(0^+) \le L`, :math:`\tau_w = \tau_y` at every node) has ``q = 0``."""
    v = np.asarray(v, dtype=float).ravel()
    dp = np.asarray(dp, dtype=float).ravel()
    index = np.asarray(index).ravel()
    n = v.size
    q = np.zeros(n)
    solved = np.zeros(n, dtype=bool)
    if flow_map.kind(scene.rheology) is None or engine._coarse or n == 0:
        return q, solved
    pts = scene.at(index)
    if pts.wall._slope_kinks(pts.tb):          # (a kinked tube law: the adaptive route splits it)
        return q, solved
    a, L, rheo = pts.radius, pts.length, pts.rheology
    a_out = a * pts.outlet_stretch + np.zeros(n)
    length = np.asarray(L, dtype=float) + np.zeros(n)
    tau_y = np.asarray(rheo.yield_stress, dtype=float) + np.zeros(n)
    log_shift = math.log(4.0 / math.pi) - 3.0 * np.log(a_out)       # ln Gamma at u = 0 is ln q + this
    a_in = a * engine.stretch_at(pts, v) + np.zeros(n)
    g = np.where(dp > 0, dp, 1.0) / length
    stress_law = flow_map.kind(scene.rheology) == "stress"
    # the bracket in ln q: rigid tubes of the outlet's and the inlet's radii under the mean gradient
    with np.errstate(all="ignore"):
        if stress_law:
            # (in the law's own variable: x_out below the outlet's wall shear rate starts the map,
            # Gamma <= 4 gamma_w / 3 bounds the inlet's from above; the map's bottom gives lo)
            lower, upper = flow_map.log_rate_bracket(_twice(rheo, n), np.concatenate([0.5 * g * a_out, 0.5 * g * a_in]),
                                                     width=_BRACKET_WIDTH)
            x_out, x_in = lower[:n], upper[n:]
            hi = x_in + math.log(4.0 / 3.0) - log_shift + 3.0 * v          # (ln Gamma_in = ln q + shift - 3 v)
            lo = np.full(n, -np.inf)
        else:
            lo = np.log(np.asarray(rheo._flow_rate(a_out, g), dtype=float) + np.zeros(n))
            hi = np.log(np.asarray(rheo._flow_rate(a_in, g), dtype=float) + np.zeros(n))
            unyielded = np.isfinite(hi) & ~np.isfinite(lo) & (tau_y > 0)
            lo = np.where(unyielded, hi - _UNYIELDED_REACH, lo)     # (the outlet alone would not yield)
        lo, hi = lo - 1e-12 * (1.0 + np.abs(lo)), hi + 1e-12 * (1.0 + np.abs(hi))
    live = np.flatnonzero((dp > 0) & (v > 0) & np.isfinite(hi) & (hi > lo) & (np.isfinite(lo) | stress_law))
    for degree in _FLOW_DEGREES:
        if live.size == 0:
            break
        rule = lobatto_rule(degree)
        weights = rule.matrix[rule.cumulative][-1] * 0.5              # Clenshaw-Curtis on [0, 1]
        if np.any(tau_y[live] > 0):
            # a yield-stress fluid: H(0+), tau_w = tau_y at every node; q = 0 where it does not exceed L
            u = rule.nodes[:, None] * v[live]
            with np.errstate(all="ignore"):
                wall = engine._slope(scene.at(index[live]), u) * (a_out[live] * np.exp(u)) * 0.5
                h0 = v[live] * (weights @ (wall / tau_y[live]))
            rest = (tau_y[live] > 0) & ~(h0 > length[live])
            solved[live[rest]] = True
            live = live[~rest]
            if live.size == 0:
                break
        sub = scene.at(index[live])
        vv = v[live]
        u = rule.nodes[:, None] * vv                                  # (nodes, P)
        with np.errstate(all="ignore"):
            wall = engine._slope(sub, u) * (a_out[live] * np.exp(u)) * 0.5
        s_lo, s_hi, shift, log_l = lo[live], hi[live], log_shift[live], np.log(length[live])
        if stress_law:
            fmap = flow_map.flow_map(sub.rheology, None, s_hi + shift, x_lo=x_out[live] - 3.0 * vv - 1.0)
            s_lo = fmap.bottom + 3.0 * vv - shift + 1e-12 * (1.0 + np.abs(s_hi))
        else:
            fmap = flow_map.flow_map(sub.rheology, s_lo + shift - 3.0 * vv - 1e-9, s_hi + shift + 1e-9)
        s = 0.5 * (s_lo + s_hi)
        moving = np.ones(live.size, dtype=bool)
        # the integrand values of each point's last evaluation, 1e-9 from its answer at most: its
        # interpolant's tail is the answer's check (no evaluation more)
        last = np.full(u.shape, np.nan)
        with np.errstate(all="ignore"):
            for _ in range(_FLOW_ITERATIONS):
                y = s + shift - 3.0 * u
                tau, ok, x = fmap.wall_stress(y)
                vouched = np.all(ok, axis=0)
                f = wall / tau
                h = vv * (weights @ f)
                k = 1.0 / (4.0 * fmap.wall_rate(tau, x) / np.exp(y) - 3.0)
                dh = -vv * (weights @ (f * k))
                residual = np.log(h) - log_l
                # the bracket: H decreases with q
                s_lo = np.where(moving & (residual > 0), s, s_lo)
                s_hi = np.where(moving & (residual < 0), s, s_hi)
                step = residual / (dh / h)
                nxt = s - step
                # a step below _FLOW_STEP is the last (quadratic: its error is ~1e-18 after it)
                done = np.abs(step) <= _FLOW_STEP
                outside = ~done & (~np.isfinite(nxt) | (nxt <= s_lo) | (nxt >= s_hi))
                nxt = np.where(outside, 0.5 * (s_lo + s_hi), np.clip(nxt, s_lo, s_hi))
                last[:, moving] = np.where(vouched, f, np.nan)[:, moving]
                s = np.where(moving & vouched, nxt, s)
                moving &= vouched & ~done
                if not np.any(moving):
                    break
            coef = blocked_matmul(rule.matrix[rule.coef], np.where(np.isfinite(last), last, 0.0))
            tail = vv * np.abs(coef[-3:]).sum(axis=0)
            good = ~moving & np.all(np.isfinite(last) & (last > 0), axis=0) & (tail <= _MAPPED_RTOL * length[live])
        q[live[good]] = np.exp(s[good])
        solved[live[good]] = True
        live = live[~good]
    return q, solved
