r"""The tube-flow function of any rheology (the non-separable path): error-controlled quadrature,
and an error-checked table of its inverse.

In a tube the flow depends on the wall stress :math:`\tau_w = GR/2` only through the
apparent wall shear rate

.. math::

    \Gamma(\tau_w) = \frac{4q}{\pi R^3} = \frac{4}{\tau_w^3}\int_0^{\tau_w}\tau^2\dot\gamma(\tau)\,d\tau ,

so :math:`G(q, R) = 2\,\tau_w(\Gamma = 4q/\pi R^3)/R`: one monotone function of one variable
serves every radius and flow rate (``docs/theory.md``, section "The flow law of a generalized
Newtonian fluid").

**Quadrature** (:func:`unit_integral`). The Rabinowitsch–Mooney integral and the velocity
profile are integrals over :math:`t \in (0, 1]` whose integrands may be singular at
:math:`t = 0` (:math:`t^{1/n}`, the yield point) and not smooth anywhere (a kinked
constitutive law). They are taken in :math:`t = e^{-z}`, :math:`z \in [0, 40]` (panels graded
geometrically toward :math:`t = 0`, where an algebraic singularity becomes a smooth, decaying
integrand) by the vectorized Gauss–Kronrod rule of :func:`tubefsi._quadrature.adaptive`, with
error estimates made safe for kinks (see :func:`unit_integral`), to an internal relative
tolerance of 1e-15; a point whose estimate stays above the promised 1e-14 (and above the
rounding of its integrand) is an ``AccuracyWarning`` stating the estimate. A kinked law is
integrated to ~1e-14 wherever its kink falls.

**The table** (:class:`FlowTable`) gives :math:`s = \ln(\tau_w - \tau_y)` (:math:`\tau_y` the
yield stress, 0 for most fluids) as a function of :math:`y = \ln\Gamma`, built only where
calls need it:

* *forward panels* in a parameter :math:`p` in which the flow function needs no root solve
  (:math:`p = s` for a rate-natural law or a closed-form flow function;
  :math:`p = \ln\dot\gamma_w` for a stress-natural law, where :math:`\tau_w = \tau(\dot\gamma_w)`
  and :math:`\Gamma` follow directly): degree-24 Chebyshev interpolants of :math:`y(p)` (and
  :math:`s(p)`) on Chebyshev–Lobatto points, each an error-controlled flow-function value,
  evaluated for all pending panels in one vectorized round (for a stress-natural law, a panel's
  nodes from one cumulative integral, :func:`stress_natural_rate_panels`, where its error
  estimate allows);
* *the inverse* of each forward panel: a degree-64 Chebyshev series of :math:`s(y)` over its
  image, its nodes by Newton's method on the forward interpolant (a convergence check on every
  node; the interpolants evaluated by the barycentric formula), split into *lookup panels* of
  degree 7 (16 equal ones, then bisection) until their tails meet the tolerance;
* *the a-posteriori check*: a forward panel is accepted when the Chebyshev tails of its
  interpolants and its inverse are below the tolerance **and** the lookup agrees with the flow
  function evaluated directly at four check points between the nodes; otherwise it is bisected.
  Both tests are in :math:`G`: an error :math:`\delta s` is an error
  :math:`\delta s\,(\tau_w - \tau_y)/\tau_w` of :math:`G`, and a panel cannot be more accurate
  than its nodes' own quadrature estimates. At a kink of the law (where the parametrisation is
  not smooth) the bisection stops at panels of relative width 1e-9, accepted on their check
  points; a panel failing even those at width 1e-13 is kept, and a lookup in it (or in a panel
  whose nodes missed their tolerance) is an ``AccuracyWarning`` stating the error.

The tolerance the table meets is :data:`TOL` = 1e-14 in the relative error of :math:`G` (an
error :math:`10^{-14}\,\tau_w/(\tau_w - \tau_y)` of :math:`s`: 1e-14 itself without a yield
stress), plus the rounding of the logarithms, :math:`\approx 4\epsilon(|\ln\Gamma| + |s|)`;
``tests/test_rheology_generic.py`` checks it against direct integrals over 40 decades.

*Coverage.* The table is a set of disjoint *segments* (runs of panels). A load within
:math:`|\Delta\ln\Gamma| \le 8` of a segment extends it, by panels as wide as the slope at its
end suggests (up to 64 in :math:`p`, bisected as needed: an asymptote such as a Newtonian
:math:`\eta_0` at small stress or a power law at large costs a logarithmic number of panels);
a farther load starts a new segment from the asymptote of the nearest one (or, for the first,
from :math:`\ln\dot\gamma_w \approx \ln\Gamma`, or secant steps on direct evaluations); a call
spanning several segments fills the gaps between them. So a scalar solve builds a panel or two
(~30 flow-function evaluations each), a load of 1e-300 a few more, never the range in between.
A yield-stress fluid's table ends where :math:`\tau_w - \tau_y` falls below
:math:`\epsilon\tau_y/8` (closed forms, given the excess exactly) or :math:`\sqrt\epsilon\,\tau_y`
(a law that takes or gives only :math:`\tau`, and so cannot resolve the excess more finely):
below it :math:`G` is the yield gradient to ~1e-16, continued by the power-law asymptote of the
end. The flow function is tabulated within :math:`|p|, |s| \le 700`, and where it is finite: a
load beyond that is extrapolated by the end's power-law asymptote (tiny loads, with an
``AccuracyWarning``) or an ``InvalidParameterError`` (huge ones).

*Lookups* cost a logarithm, a bucket lookup of the panel (equal-width buckets in :math:`y`, each
holding its first panel and the breakpoint inside it; a search only in the rare buckets with
several), eight multiply-adds with coefficients gathered one degree at a time, and an
exponential per point: a working set of a few arrays of the points' size, no per-point
coefficient rows.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from ..numerics.kernels import rows_dot
from ..numerics.quadrature import GAUSS_WEIGHTS, KRONROD_NODES, KRONROD_WEIGHTS, Integral, warn_unconverged
from ..errors import ConvergenceError, InvalidParameterError

__all__ = ["FlowTable", "flow_table", "tanh_sinh", "unit_integral", "TOL"]

_EPS = np.finfo(float).eps
_TINY = np.finfo(float).tiny

#: Tolerance of the table: the relative error of G (of tau_w - tau_y times (tau_w - tau_y) / tau_w).
TOL = 1e-14
#: Relative tolerance of every flow-function quadrature (the table's nodes included): a tenth of
#: the 1e-14 promised, for the estimates of panels across a kink are erratic (measured up to ten
#: times too small once the bisection has localised it).
RTOL = 1e-15


# =============================================================== quadrature over (0, 1]
_Z_END = 40.0          # t = e^-z >= e^-40 ~ 4e-18: the rest of (0, 1] is below the tolerance
_Z_PANELS = 20


def _lagrange_at(nodes, point):
    """Weights of the polynomial interpolating at ``nodes``, evaluated at ``point``."""
    w = np.ones(nodes.size)
    for k in range(nodes.size):
        others = np.delete(nodes, k)
        w[k] = np.prod((point - others) / (nodes[k] - others))
    return w


# extrapolation of the 21 Kronrod nodes' interpolant to the panel ends (sum |w| = 4.19)
_END_WEIGHTS = np.stack([_lagrange_at(KRONROD_NODES, 0.0), _lagrange_at(KRONROD_NODES, 1.0)], axis=1)
_END_GAP = KRONROD_NODES[0]          # 0.0022: the part of a panel beyond its outermost nodes
_NODES_23 = np.concatenate([[0.0], KRONROD_NODES, [1.0]])
# the initial panels' abscissae in z and t = e^-z: the same for every point, so computed once
_Z_FIRST = np.arange(_Z_PANELS)[:, None] * (_Z_END / _Z_PANELS) + (_Z_END / _Z_PANELS) * _NODES_23
_Z_FIRST[:, 0] = np.arange(_Z_PANELS) * (_Z_END / _Z_PANELS)
_Z_FIRST[:, -1] = np.append(np.arange(1, _Z_PANELS) * (_Z_END / _Z_PANELS), _Z_END)
_T_FIRST = np.exp(-_Z_FIRST)


# the rules as columns over the 23 values of a panel (its two ends, then the 21 Kronrod nodes):
# Kronrod, Gauss, and the nodes' interpolant at the two ends minus the end values; one product
_RULES = np.zeros((23, 4))
_RULES[1:-1, 0] = KRONROD_WEIGHTS
_RULES[2:-1:2, 1] = GAUSS_WEIGHTS
_RULES[1:-1, 2:] = _END_WEIGHTS
_RULES[0, 2] = _RULES[-1, 3] = -1.0
_KRONROD_23 = np.ascontiguousarray(_RULES[:, 0])


def _panels(g, lo, hi, idx, noise, x=None):
    """Kronrod values, error estimates and rounding floors of the panels [lo, hi] (see
    :func:`unit_integral`); ``x``, if given, are the panels' 23 abscissae."""
    h = hi - lo
    if x is None:
        x = lo[:, None] + h[:, None] * _NODES_23
        x[:, 0], x[:, -1] = lo, hi
    y = np.asarray(g(x, idx), dtype=float)
    rules = rows_dot(y, _RULES)              # (row by row, whatever the batch: tubefsi._products)
    kron = rules[:, 0]
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        ay = np.abs(y)
        magnitude = rows_dot(ay, _KRONROD_23)
        y -= kron[:, None]                      # y is g's fresh array: reused for the spread
        np.abs(y, out=y)
        spread = rows_dot(y, _KRONROD_23)
        raw = np.abs(kron - rules[:, 1])
        scaled = np.where((spread > 0) & (raw > 0), spread * np.minimum(1.0, (200.0 * raw / spread) ** 1.5), raw)
        # the nodes' interpolant against the integrand at the panel's ends: a kink (or any
        # feature) between the outermost node and an end, which no Gauss-type rule sees
        ends = np.abs(rules[:, 2]) + np.abs(rules[:, 3])
        ends *= _END_GAP
        floor = 2.0 * _EPS * magnitude
        if noise is not None:
            floor = np.maximum(floor, rows_dot(ay[:, 1:-1] * noise(x[:, 1:-1], idx), KRONROD_WEIGHTS))
        # QUADPACK's scaled estimate presumes a smooth integrand: never below |K21 - G10| itself
        error = np.maximum(np.maximum(scaled, raw) + ends, floor)
    return kron * h, error * h, floor * h


def unit_integral(f, n: int, *, rtol: float = RTOL, rounding=None, relative_rounding=None,
                  max_rounds: int = 60, max_panels: int = 2048) -> Integral:
    r""":math:`\int_0^1 f(t)\,dt` for ``n`` points at once, error-controlled.

    ``f(t, index)`` gets ``t`` of shape ``(P, m)`` and the points' indices (gather per-point
    parameters with ``a[index, None]``). The integral is taken in :math:`t = e^{-z}` over
    :math:`z \in [0, 40]` with 20 initial panels: geometric grading toward :math:`t = 0`, where an
    algebraic singularity (:math:`t^{1/n}`, a yield point) becomes a smooth, exponentially
    decaying integrand. The omitted :math:`(0, e^{-40})` is below 4e-18 of the integral for the
    bounded, monotone integrands of this module. ``rounding(index)``, if given, is the absolute
    rounding error of ``f``'s values per point (a difference of nearly equal terms), or
    ``relative_rounding(t, index)`` their relative rounding at the nodes: a point whose estimate is
    within it is done.

    The rule is :func:`tubefsi._quadrature.adaptive`'s (Gauss–Kronrod 10/21, QUADPACK estimates,
    bisection of each point's worst panels) with three additions for
    integrands that are not smooth (a kinked constitutive law), where QUADPACK's estimate
    :math:`\rho\,(200|K_{21} - G_{10}|/\rho)^{3/2}` assumes a convergence the rule does not
    have and was measured 100 times too small at 1e-14:

    * a panel's estimate is at least :math:`|K_{21} - G_{10}|` (the 3/2 power presumes K21 far
      more accurate than G10, which a kink denies);
    * the estimate of each half of a bisected panel is at least a third of the change of the
      panel's value on bisection (that change is the parent's true error; across a kink the
      error falls as the width squared, so a half keeps a third of it);
    * each panel is also evaluated at its two ends, and the mismatch there of the polynomial
      through its 21 nodes, times the width of the strip beyond the outermost node (0.22 % of the
      panel), is added to its estimate. A Gauss-type rule never samples that strip: a kink
      inside it (for bisected panels: whenever the kink lies just short of a panel end) would
      be integrated as the smooth continuation with a tiny estimate, silently wrong by ~1e-8.

    A point stops refining when its estimate is within its tolerance (or twice its rounding
    floor), when it has not fallen four-fold in 12 rounds (a noisy integrand), or after
    ``max_rounds`` rounds or ``max_panels`` panels; ``converged`` reports which.
    """
    last = {}
    first = {"z": np.tile(_Z_FIRST, (n, 1))}      # the first round's abscissae, the same for all points
    first["t"] = np.tile(_T_FIRST, (n, 1))

    def g(z, idx):
        t = first.pop("t") if z is first.get("z") else np.exp(-z)
        v = np.asarray(f(t, idx), dtype=float)
        last["x"], last["v"] = z, v
        return v * t

    noise = None
    if relative_rounding is not None:
        def noise(z, idx):
            return relative_rounding(np.exp(-z), idx)
    elif rounding is not None:
        def noise(z, idx):
            v = last["v"][:, 1:-1] if last.get("v") is not None and last["v"].shape[0] == z.shape[0] else \
                np.asarray(f(np.exp(-z), idx), dtype=float)
            with np.errstate(divide="ignore"):
                return rounding(idx)[:, None] / np.maximum(np.abs(v), _TINY)

    count = _Z_PANELS
    idx = np.repeat(np.arange(n), count)
    lo = np.tile(np.arange(count) * (_Z_END / count), n)
    hi = np.tile(np.append(np.arange(1, count) * (_Z_END / count), _Z_END), n)
    value, error, rounding_ = _panels(g, lo, hi, idx, noise, x=first["z"])
    total = np.bincount(idx, value, minlength=n)
    err = np.bincount(idx, error, minlength=n)
    floor = np.bincount(idx, rounding_, minlength=n)
    used = np.full(n, count)
    done_value, done_error, done_floor = np.zeros(n), np.zeros(n), np.zeros(n)
    finished = np.zeros(n, dtype=bool)
    snapshots = []                    # the estimates every 6 rounds: a point is hopeless (a noisy
    for round_ in range(max_rounds):  # integrand) when it has not fallen 4-fold in 12 rounds
        tol = rtol * np.abs(total)
        if round_ % 6 == 0:
            if len(snapshots) == 2:
                finished |= err > 0.25 * snapshots.pop(0)
            snapshots.append(err.copy())
        finished |= (err <= np.maximum(tol, 2.0 * floor)) | ~np.isfinite(total) | ~np.isfinite(err)
        live = ~finished[idx]
        if not np.any(live):
            break
        if not np.all(live):
            dead = ~live
            done_value += np.bincount(idx[dead], value[dead], minlength=n)
            done_error += np.bincount(idx[dead], error[dead], minlength=n)
            done_floor += np.bincount(idx[dead], rounding_[dead], minlength=n)
            idx, lo, hi = idx[live], lo[live], hi[live]
            value, error, rounding_ = value[live], error[live], rounding_[live]
        worst = np.zeros(n)
        np.maximum.at(worst, idx, error)
        split = (error >= 0.25 * worst[idx]) & (error > 0.01 * tol[idx] / used[idx]) & (used[idx] < max_panels)
        if not np.any(split):
            break
        mid = 0.5 * (lo[split] + hi[split])
        s_idx = np.concatenate([idx[split], idx[split]])
        s_lo = np.concatenate([lo[split], mid])
        s_hi = np.concatenate([mid, hi[split]])
        s_val, s_err, s_rnd = _panels(g, s_lo, s_hi, s_idx, noise)
        # the parent against its halves: its true error. Across a kink (error ~ width^2) a half
        # keeps a third of it, however small the halves' own estimates
        parent = value[split]
        change = np.abs(parent - (s_val[: parent.size] + s_val[parent.size:])) / 3.0
        s_err = np.maximum(s_err, np.concatenate([change, change]))
        used += np.bincount(idx[split], minlength=n)
        keep = ~split
        idx = np.concatenate([idx[keep], s_idx])
        lo = np.concatenate([lo[keep], s_lo])
        hi = np.concatenate([hi[keep], s_hi])
        value = np.concatenate([value[keep], s_val])
        error = np.concatenate([error[keep], s_err])
        rounding_ = np.concatenate([rounding_[keep], s_rnd])
        total = done_value + np.bincount(idx, value, minlength=n)
        err = done_error + np.bincount(idx, error, minlength=n)
        floor = done_floor + np.bincount(idx, rounding_, minlength=n)
    tol = rtol * np.abs(total)
    converged = (err <= np.maximum(tol, 2.0 * floor)) & np.isfinite(total)
    return Integral(value=total, error=err, converged=converged, panels=used)


def _positive(x):
    """Keep hook arguments positive where a tiny product underflows."""
    return np.maximum(x, _TINY)


def rate_natural_rate(rheology, wall_stress, excess=None, *, rtol: float = RTOL):
    r""":math:`\Gamma` and its quadrature (``(Integral, indices of the integrated points)``, or
    None when nothing was integrated) from a rate-natural law: :math:`4\int_0^1 t^2\dot\gamma(\tau_w t)\,dt`,
    or with a yield stress :math:`\tau_y`, over the yielded part only,
    :math:`\frac{4\Delta}{\tau_w^3}\int_0^1 (\tau_y + \Delta u)^2\dot\gamma(\tau_y + \Delta u)\,du`
    with :math:`\Delta = \tau_w - \tau_y` (``excess``, exact when given)."""
    tau_w = np.asarray(wall_stress, dtype=float)
    tau_y = float(rheology.yield_stress)
    shape = tau_w.shape
    tw = tau_w.ravel()
    out = np.zeros(tw.size)
    if tau_y == 0.0:
        live = np.flatnonzero(tw > 0)
        if not live.size:
            return out.reshape(shape), None
        tl = tw[live]

        def f(t, idx):
            return t * t * rheology._shear_rate(_positive(tl[idx, None] * t))

        res = unit_integral(f, live.size, rtol=rtol)
        out[live] = 4.0 * res.value
        return out.reshape(shape), (res, live)
    ex = (np.maximum(tau_w - tau_y, 0.0) if excess is None
          else np.broadcast_to(np.asarray(excess, dtype=float), shape)).ravel()
    live = np.flatnonzero(ex > 0)
    if not live.size:
        return out.reshape(shape), None
    el, tl = ex[live], tw[live]

    def f(u, idx):
        tau = tau_y + el[idx, None] * u
        return tau * tau * rheology._shear_rate(tau)

    def rounding(u, idx):
        # the law gets tau, not tau - tau_y: its shear rate carries the rounding of tau_y + excess u,
        # relatively ~ eps tau_y / (excess u) times its exponent (taken as up to 4)
        return 4.0 * _EPS * tau_y / np.maximum(el[idx, None] * u, _TINY)

    res = unit_integral(f, live.size, rtol=rtol, relative_rounding=rounding)
    out[live] = 4.0 * el * res.value / tl**3
    return out.reshape(shape), (res, live)


def stress_natural_rate(rheology, wall_rate, wall_stress, *, rtol: float = RTOL):
    r""":math:`\Gamma` from a stress-natural law, by parts in the shear rate:
    :math:`\Gamma = \tfrac43\dot\gamma_w\int_0^1\bigl[1 - (\tau(\dot\gamma_w t)/\tau_w)^3\bigr]dt`
    (a positive integrand: no cancellation), with its quadrature."""
    rate_w = np.asarray(wall_rate, dtype=float)
    tau_w = np.broadcast_to(np.asarray(wall_stress, dtype=float), rate_w.shape)
    shape = rate_w.shape
    rw, tw = rate_w.ravel(), tau_w.ravel()
    out = np.zeros(rw.size)
    live = np.flatnonzero((rw > 0) & (tw > 0))
    if not live.size:
        return out.reshape(shape), None
    rl, tl = rw[live], tw[live]

    def f(t, idx):
        ratio = rheology._stress(_positive(rl[idx, None] * t)) / tl[idx, None]
        return 1.0 - ratio * ratio * ratio

    # 1 - ratio^3 is rounded to a few eps absolute where ratio ~ 1: near yield it is small
    # everywhere, and this floor is all the accuracy there is
    res = unit_integral(f, live.size, rtol=rtol, rounding=lambda idx: np.full(idx.shape, 2.0 * _EPS))
    out[live] = (4.0 / 3.0) * rl * res.value
    return out.reshape(shape), (res, live)


def stress_natural_rate_panels(rheology, p, wall_stress, *, rtol: float = RTOL):
    r""":math:`\Gamma` at the shear rates :math:`e^p` of table panels (``p`` of shape (panels,
    nodes), ``wall_stress`` :math:`\tau(e^p)`), from one cumulative integral per panel instead of
    one integral per point: ``(Gamma, relative error estimate, accepted)``.

    With :math:`K(p) = \int_{-\infty}^{p}\tau(e^u)^3e^u\,du = \int_0^{e^p}\tau(\dot\gamma)^3\,d\dot\gamma`,
    :math:`\Gamma = \tfrac43\,\dot\gamma_w\,(1 - q)`, :math:`q = K/(\tau_w^3\dot\gamma_w)`. K is summed
    over steps in :math:`u`: 20 of width 2 below the panel's lowest node (as :func:`unit_integral`'s
    initial panels; the rest, below :math:`e^{-40}` of the lowest rate, is bounded by the integrand
    at the first step's start, for :math:`\tau` increases), then node to node (in parts of at most 2).
    Each step is taken by the Kronrod rule on the step and on its two halves: the halves'
    estimates, at least the change on bisection (which bounds the error where the law has a kink,
    as in :func:`unit_integral`). A point is accepted when the summed truncation estimates are
    within ``rtol`` of :math:`\Gamma` (or twice the rounding, which they cannot fall below), and
    they and the rounding together (the rules' floors, and :math:`6\epsilon q` for the sum, the
    scale factors and :math:`1 - q`, all amplified by :math:`q/(1-q)`: large where the stress is
    nearly constant, as near a yield stress or for a power-law index below ~0.3) within a quarter
    of :data:`TOL`; the caller integrates the others one by one (:func:`stress_natural_rate`). One
    vectorized rule for the whole panel: a fourth of the law evaluations of the point-wise
    integrals of a 29-node panel, and none of their refinement rounds."""
    p = np.asarray(p, dtype=float)
    rows, m = p.shape
    order = np.argsort(p, axis=1)
    ps = np.take_along_axis(p, order, axis=1)
    tau = np.take_along_axis(np.asarray(wall_stress, dtype=float), order, axis=1)
    rate = np.exp(ps)
    # the scale: values below 1 on the panel; ratios of rates, never exponentials of differences
    # of large parameters (which would carry their rounding, |p| eps)
    rate_top, tau_top = rate[:, -1], tau[:, -1]

    def step(u, idx):
        rate_u = np.exp(u)
        ratio = np.asarray(rheology._stress(rate_u), dtype=float) / tau_top[idx, None]
        rate_u /= rate_top[idx, None]
        return ratio * ratio * ratio * rate_u

    width = _Z_END / _Z_PANELS
    below = ps[:, :1] - width * np.arange(_Z_PANELS, 0, -1)          # the steps' starts below the panel
    starts = np.concatenate([below, ps[:, :-1]], axis=1)
    ends = np.concatenate([below[:, 1:], ps], axis=1)
    steps = starts.shape[1]
    # an interval wider than 2 (a wide panel's, across an asymptote) in parts of at most 2
    a, b = starts.ravel(), ends.ravel()
    parts = np.maximum(np.ceil((b - a) / width), 1.0).astype(np.intp)
    which = np.repeat(np.arange(a.size), parts)
    k = np.arange(which.size) - np.repeat(np.cumsum(parts) - parts, parts)
    share = (b - a)[which] / parts[which]
    lo = a[which] + k * share
    hi = np.where(k == parts[which] - 1, b[which], lo + share)
    mid = 0.5 * (lo + hi)
    idx = which // steps
    value, error, floor = _panels(step, np.concatenate([lo, lo, mid]), np.concatenate([hi, mid, hi]),
                                  np.concatenate([idx, idx, idx]), None)
    n = lo.size
    halves = value[n: 2 * n] + value[2 * n:]
    part_err = np.maximum(error[n: 2 * n] + error[2 * n:], np.abs(value[:n] - halves))
    halves = np.bincount(which, halves, minlength=a.size).reshape(rows, steps)
    step_err = np.bincount(which, part_err, minlength=a.size).reshape(rows, steps)
    step_floor = np.bincount(which, floor[n: 2 * n] + floor[2 * n:], minlength=a.size).reshape(rows, steps)
    tail = step(below[:, :1], np.arange(rows))[:, 0]                 # bounds the integral below
    with np.errstate(all="ignore"):
        # K below the panel, then the node-to-node growth summed on its own and added once: a
        # running sum of small steps on a large K would round at every step
        k0 = halves[:, :_Z_PANELS].sum(axis=1)
        growth = np.concatenate([np.zeros((rows, 1)), np.cumsum(halves[:, _Z_PANELS:], axis=1)], axis=1)
        k = k0[:, None] + growth
        k_err = np.cumsum(step_err, axis=1)[:, _Z_PANELS - 1:] + tail[:, None]
        k_floor = np.cumsum(step_floor, axis=1)[:, _Z_PANELS - 1:]
        back = (rate_top[:, None] / rate) * (tau_top[:, None] / tau) ** 3
        q = k * back
        rest = 1.0 - q
        gamma = (4.0 / 3.0) * rate * rest
        # the truncation estimate within rtol, and the rounding (the rules' floors; the sum, the
        # scale factors and 1 - q, 6 eps q: all amplified by q / (1 - q)) within a quarter of the
        # table's promise
        truncation = np.maximum(k_err - k_floor, 0.0) * back / rest
        rounding = (k_floor * back + 6.0 * _EPS * q) / rest
        rel = truncation + rounding
        # (the truncation estimate of a step is at least its rounding noise: as unit_integral's
        # points, a node is also done when that estimate is within twice the rounding)
        good = (rest > 0) & (truncation <= np.maximum(rtol, 2.0 * rounding)) & (rel <= 0.25 * TOL) \
            & np.isfinite(gamma) & np.isfinite(rel)
    out = np.empty_like(gamma), np.empty_like(rel), np.empty(good.shape, dtype=bool)
    for dest, src in zip(out, (gamma, rel, good)):
        np.put_along_axis(dest, order, src, axis=1)
    return out


def relative_error(result, shape):
    """Per-point relative error estimates of an integrator's result (inf where not finite). A
    point may stop short of the internal tolerance (1e-15) on a law's own rounding: its estimate,
    not that flag, is what counts."""
    res, live = result
    err = np.zeros(int(np.prod(shape)))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(res.error / res.value)
    err[live] = np.where(np.isfinite(rel) & np.isfinite(res.value), rel, np.inf)
    return err.reshape(shape)


def check(what: str, result) -> None:
    """Warn (``AccuracyWarning``) where a quadrature (``(Integral, points)`` or None) missed the
    promised relative accuracy, :data:`TOL` (its internal tolerance is a tenth of that), unless it
    is within the rounding of its integrand (``converged``: no quadrature can do better)."""
    if result is None:
        return
    res = result[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        good = (res.converged | (res.error <= TOL * np.abs(res.value))) & np.isfinite(res.value)
    if not np.all(good):
        warn_unconverged(what, Integral(value=res.value, error=res.error, converged=good, panels=res.panels))


# =============================================================== fixed rules (kept for callers)
def tanh_sinh(levels: int = 6):
    """Fixed tanh-sinh (double-exponential) nodes/weights on [0, 1]: exact to ~1e-15 even
    with algebraic endpoint singularities such as t**(1/n)."""
    h = 2.0**-levels * 8
    k = np.arange(-int(3.2 / h) - 1, int(3.2 / h) + 2)
    x = 0.5 * np.pi * np.sinh(k * h)
    t = 0.5 * (1.0 + np.tanh(x))
    w = h * 0.5 * np.pi * np.cosh(k * h) / (2.0 * np.cosh(x) ** 2)
    keep = (t > 0) & (t < 1) & (w > 1e-300)
    return t[keep], w[keep]


def graded_rule(panels: int = 30, order: int = 12, levels: int = 6):
    """Nodes/weights on [0, 1] graded geometrically toward 0: Gauss–Legendre on the panels
    [2^-(k+1), 2^-k] (k < ``panels``) and the tanh-sinh rule on [0, 2^-panels]. A fixed rule,
    without an error estimate: the default paths use :func:`unit_integral` instead."""
    x, w = np.polynomial.legendre.leggauss(order)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    lo = 2.0 ** -np.arange(1, panels + 1, dtype=float)           # panel k: [lo_k, 2 lo_k]
    t = (lo[:, None] * (1.0 + x[None, :])).ravel()
    wt = (lo[:, None] * w[None, :]).ravel()
    ts, ws = tanh_sinh(levels)
    t = np.concatenate([ts * lo[-1], t])
    wt = np.concatenate([ws * lo[-1], wt])
    order_ = np.argsort(t)
    return t[order_], wt[order_]


# =============================================================== Chebyshev machinery
def _cheb_and_slope(x, degree):
    """T_k(x) and T_k'(x) = k U_{k-1}(x) (points, degree + 1), x within [-1, 1]."""
    theta = np.arccos(np.clip(x, -1.0, 1.0))
    k = np.arange(degree + 1)
    kt = theta[..., None] * k
    s = np.sin(theta)[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(np.abs(s) > 1e-8, np.sin(kt) / s, k * np.where(theta[..., None] < 1.0, 1.0, (-1.0) ** (k + 1)))
    return np.cos(kt), k * u


_N = 24                                                       # forward degree
_XF = -np.cos(np.pi * np.arange(_N + 1) / _N)                 # Chebyshev–Lobatto points, ascending
_XF[0], _XF[-1], _XF[_N // 2] = -1.0, 1.0, 0.0
_XC = np.sort(-np.cos(np.pi * (np.array([2, 8, 15, 21]) + 0.5) / _N))   # check points, between nodes
_FIT_F = np.linalg.inv(np.polynomial.chebyshev.chebvander(_XF, _N)).T  # values @ _FIT_F -> coefficients

_SLOPE_F = _FIT_F @ _cheb_and_slope(_XF, _N)[1].T              # values at nodes -> d/dx at nodes
_SLOPE_F[:, 0] = _FIT_F @ np.array([(-1.0) ** (k + 1) * k * k for k in range(_N + 1)])
_SLOPE_F[:, -1] = _FIT_F @ np.array([k * k for k in range(_N + 1)], dtype=float)

_XS = np.concatenate([_XF, _XC])                              # a panel's nodes, then its check points


def _panel_nodes(pa, pb):
    """The parameters of the panels ``[pa, pb]`` (1-D arrays): their Lobatto nodes (exact at the
    ends), then their check points; shape (panels, 29)."""
    p = (0.5 * (pa + pb))[:, None] + (0.5 * (pb - pa))[:, None] * _XS
    p[:, 0], p[:, _N] = pa, pb
    return p


_P = 7                                                        # lookup degree
_XL = -np.cos(np.pi * (np.arange(_P + 1) + 0.5) / (_P + 1))   # Chebyshev points (first kind)
_FIT_L = np.linalg.inv(np.polynomial.chebyshev.chebvander(_XL, _P)).T
_TO_MONO = np.array([np.pad(np.polynomial.chebyshev.cheb2poly(np.eye(_P + 1)[k]), (0, _P + 1))[: _P + 1]
                     for k in range(_P + 1)])                 # Chebyshev -> monomial coefficients

_M = 64                                                       # degree of a forward panel's inverse
_XI = -np.cos(np.pi * (np.arange(_M + 1) + 0.5) / (_M + 1))
_FIT_I = np.linalg.inv(np.polynomial.chebyshev.chebvander(_XI, _M)).T

# barycentric weights of the two node sets (Berrut & Trefethen 2004, eqs. 5.4 and 5.3): the
# interpolants are evaluated by the barycentric formula, an outer difference and two products,
# instead of a matrix of cosines (8x faster at these sizes; forward stable on [-1, 1], Higham 2004)
_WF = (-1.0) ** np.arange(_N + 1)
_WF[0] *= 0.5
_WF[-1] *= 0.5
_WI = (-1.0) ** np.arange(_M + 1) * np.sin(np.pi * (np.arange(_M + 1) + 0.5) / (_M + 1))

_START_SUBS = 16      # lookup panels a forward panel's inverse is first split into
_W_KINK = 1e-9        # relative forward-panel width below which the check points alone decide
_W_MIN = 1e-13        # ... and below which a panel is kept, flagged with its check error
_MAX_PANELS = 1024
_P_LIMIT = 700.0      # |p| and |s| stay within ln(1e304)
_SEED_SINGLE = (2.0, 0.25)   # a first load alone spans this far below and above it (in p): see _seed_panels
_NEAR = 8.0           # a load this close (in ln Gamma) to a segment extends it; farther, a new one


# =============================================================== the table
class FlowTable:
    """The error-controlled inverse :math:`s(y)` of the flow function of one rheology
    (see the module docstring). ``evaluations`` counts flow-function evaluations,
    ``rounds`` the vectorized rounds of them, ``panel_count`` the accepted forward panels."""

    def __init__(self, rheology):
        self.rheology = rheology
        self.yield_stress = float(rheology.yield_stress)
        self.closed_form = _overridden(rheology, "_apparent_shear_rate")
        rate_natural = _overridden(rheology, "_shear_rate")
        #: "rate": p = s = ln(tau_w - tau_y); "stress": p = ln(wall shear rate)
        self.mode = "rate" if (self.closed_form or rate_natural) else "stress"
        self.evaluations = 0
        self.rounds = 0
        self._segments = []        # disjoint runs of accepted forward panels, ascending in p
        # a yield-stress fluid's table ends where tau_w - tau_y is below eps tau_y / 8 (closed forms,
        # given the excess) or sqrt(eps) tau_y (a law that gets only tau, or gives only tau, which
        # does not resolve tau - tau_y more finely): below, G is the yield gradient to ~1e-16 and
        # the power-law asymptote of the table's end continues it
        floor = _EPS / 8.0 if self.closed_form else math.sqrt(_EPS)
        self._floor = math.log(self.yield_stress * floor) if self.yield_stress > 0 else -_P_LIMIT
        self._p_floor = None

    # ------------------------------------------------------------ exact flow function
    def apparent_shear_rate(self, excess):
        r""":math:`\Gamma` at the wall stress :math:`\tau_y +` ``excess``, by the rheology's hook (a
        closed form, or quadrature), given the excess itself: exact however close to yield."""
        excess = np.asarray(excess, dtype=float)
        if self.yield_stress == 0.0:
            return self.rheology._apparent_shear_rate(excess)
        return self.rheology._apparent_shear_rate(self.yield_stress + excess, excess=excess)

    def _exact(self, p):
        """``(s, y, err)`` at parameters ``p`` (1-D points, or 2-D: rows of a panel's nodes): s = ln(tau_w - tau_y), y = ln Gamma, err the
        relative error estimate of Gamma (0 for a closed form); NaN where not finite."""
        p = np.asarray(p, dtype=float)
        self.evaluations += p.size
        self.rounds += 1
        rheo, tau_y = self.rheology, self.yield_stress
        err = np.zeros(p.shape)
        res = None
        with np.errstate(all="ignore"):
            if self.mode == "rate":
                excess = np.exp(p)
                s = p.copy()
                tau_w = tau_y + excess
                if self.closed_form:
                    gamma = self.apparent_shear_rate(excess)
                else:
                    gamma, res = rate_natural_rate(rheo, tau_w, excess if tau_y > 0 else None)
            else:
                rate = np.exp(p)
                tau_w = np.asarray(rheo._stress(rate), dtype=float)
                s = np.log(tau_w - tau_y) if tau_y > 0 else np.log(tau_w)
                rest = np.ones(p.shape, dtype=bool)
                if p.ndim == 2 and np.all(np.isfinite(tau_w)) and np.all(tau_w > 0):
                    # whole panels: one cumulative integral each; the points it cannot give to
                    # the tolerance are integrated one by one
                    gamma, err, ok = stress_natural_rate_panels(rheo, p, tau_w)
                    rest = ~ok
                else:
                    gamma = np.empty(p.shape)
                if np.any(rest):
                    gamma[rest], res = stress_natural_rate(rheo, rate[rest], tau_w[rest])
                    if res is not None:
                        err[rest] = relative_error(res, (int(np.count_nonzero(rest)),))
                    res = None
            gamma = np.asarray(gamma, dtype=float)
            y = np.log(gamma)
            if res is not None:
                err = relative_error(res, p.shape)
        bad = ~(np.isfinite(s) & np.isfinite(y))
        s[bad], y[bad] = np.nan, np.nan
        return s, y, err

    # ------------------------------------------------------------ building
    def _build(self, intervals):
        """Forward panels covering ``intervals`` [(pa, pb)], bisected until accepted, in vectorized
        rounds of flow-function evaluations: ``(accepted panels, ascending; [(pa, pb)] of the panels
        with non-finite values)``."""
        pending = list(intervals)
        done, bad = [], []
        while pending:
            if self.panel_count + len(done) + len(pending) > _MAX_PANELS:
                raise ConvergenceError(f"the flow table of {self.rheology!r} needs more than {_MAX_PANELS} "
                                       "panels: is the constitutive law continuous and increasing?")
            pa = np.array([a for a, _ in pending])
            pb = np.array([b for _, b in pending])
            mid = 0.5 * (pa + pb)
            s, y, err = self._exact(_panel_nodes(pa, pb))   # whole panels: see stress_natural_rate_panels
            nxt = []
            for i in range(len(pending)):
                verdict = self._accept(pa[i], pb[i], s[i], y[i], err[i])
                if verdict == "nonfinite":
                    bad.append((pa[i], pb[i]))
                elif isinstance(verdict, dict):
                    done.append(verdict)
                else:
                    m = mid[i]
                    nxt += [(pa[i], m), (m, pb[i])]
            pending = nxt
        done.sort(key=lambda d: d["pa"])
        return done, bad

    def _accept(self, pa, pb, s, y, err):
        """The accepted panel (a dict), "split", or "nonfinite"."""
        if not (np.all(np.isfinite(s)) and np.all(np.isfinite(y))):
            return "nonfinite"
        sn, yn = s[: _N + 1], y[: _N + 1]
        sc, yc = s[_N + 1:], y[_N + 1:]
        if np.any(np.diff(yn) <= 0) or np.any(np.diff(sn) <= 0):
            slack = 2.0 * float(np.max(err)) + 8.0 * _EPS * float(np.max(np.abs(yn)) + np.max(np.abs(sn)))
            clear = min(np.min(np.diff(yn)), np.min(np.diff(sn))) < -slack   # beyond the nodes' noise
            if clear:   # the exact flow function decreases: not a fluid (no need to look closer)
                raise InvalidParameterError(
                    "rheology", "a shear stress increasing with the shear rate", self.rheology,
                    f"its tube-flow function decreases near ln(tau_w - tau_y) = {float(np.median(sn)):.6g}")
            return "split"
        # interpolants of the offsets from the panel's centre: their rounding is the panel's own
        y0, s0 = 0.5 * (yn[0] + yn[-1]), 0.5 * (sn[0] + sn[-1])
        cy = (yn - y0) @ _FIT_F
        cs = (sn - s0) @ _FIT_F if self.mode == "stress" else None
        dy = yn @ _SLOPE_F                                    # d/dx at the nodes
        if np.any(dy <= 0):
            return "split"
        ds = sn @ _SLOPE_F if cs is not None else np.full(_N + 1, 0.5 * (pb - pa))
        sigma = float(np.max(ds / dy))                       # ds/dy on the panel
        scale = float(np.max(np.abs(yn))) * sigma + float(np.max(np.abs(sn)))
        # what the lookup delivers is G = 2 tau_w / R: an error d s of s = ln(tau_w - tau_y) is an
        # error d s (tau_w - tau_y) / tau_w of G (small near yield, where G is the yield gradient)
        share = np.exp(s) / (self.yield_stress + np.exp(s))             # at nodes and check points
        top = float(np.max(share[: _N + 1]))
        # the nodes' own quadrature estimates (a panel cannot be more accurate than its nodes) and
        # the rounding of the logarithms, in G
        node_error = float(np.max((ds / dy) * err[: _N + 1] * share[: _N + 1]))
        if not math.isfinite(node_error):
            return "nonfinite"
        rounding = 4.0 * _EPS * scale
        noise = rounding * top + node_error
        tail = sigma * float(np.max(np.abs(cy[-4:])))
        if cs is not None:
            tail += float(np.max(np.abs(cs[-4:])))
        width = (pb - pa) / max(1.0, abs(pa), abs(pb))
        smooth = tail * top <= 0.25 * TOL + noise
        if not smooth and width > _W_KINK:
            return "split"
        panel = dict(pa=pa, pb=pb, cy=cy, cs=cs, yn=yn - y0, sn=sn - s0, y0=y0, s0=s0, ya=float(yn[0]), yb=float(yn[-1]),
                     sa=float(sn[0]),
                     sb=float(sn[-1]), slope_a=float(ds[0] / dy[0]), slope_b=float(ds[-1] / dy[-1]),
                     dya=float(dy[0] / (0.5 * (pb - pa))), dyb=float(dy[-1] / (0.5 * (pb - pa))))
        subs = self._invert(panel, rounding + node_error / top, TOL / top)
        if subs is None:
            return "split" if width > _W_MIN else self._flag(panel, None)
        panel["subs"] = subs
        # the a-posteriori check: the lookup against the flow function at the check points
        got = _eval_subs(subs, yc, s0)
        miss = float(np.max(np.abs(got - sc) * share[_N + 1:]))
        if miss <= 0.5 * TOL + noise:
            # within the tolerance (and the rounding of the logarithms), unless a node's own
            # quadrature missed its tolerance: then a lookup here warns with that estimate
            g_error = max(node_error, miss)
            panel["error"] = g_error if g_error > TOL + rounding * top else 0.0
            panel["check"] = miss
            return panel
        if width > _W_MIN:
            return "split"
        return self._flag(panel, miss)

    def _flag(self, panel, miss):
        """Keep a panel that cannot meet the tolerance (a discontinuity of the law), with its error."""
        if "subs" not in panel:
            panel["subs"] = _linear_subs(panel)
        panel["error"] = np.inf if miss is None else miss
        return panel

    def _invert(self, panel, rounding, tol):
        """Lookup panels of s(y) - s0 over the image of a forward panel, or None if the inverse does
        not converge. The inverse is first a degree-64 Chebyshev series over the whole image (its
        nodes by Newton's method on the forward interpolant, from the Lobatto data), then split into
        degree-7 lookup panels (16 equal ones first, then bisection) until their tails are below
        the tolerance."""
        ya, yb, y0 = panel["ya"], panel["yb"], panel["y0"]
        hw = 0.5 * (yb - ya)
        yt = hw * _XI + (0.5 * (ya + yb) - y0)                # targets, as offsets from y0
        guess = np.interp(yt, panel["yn"], _XF)
        x = _solve_forward(panel["yn"], yt, guess, hw)
        if x is None:
            return None
        if panel["cs"] is None:     # s = p: its offset from s0 is linear in x
            st = (0.5 * (panel["pa"] + panel["pb"]) - panel["s0"]) + 0.5 * (panel["pb"] - panel["pa"]) * x
        else:
            st = _barycentric(x, _XF, _WF, panel["sn"])[0]
        big = st @ _FIT_I
        local = float(np.max(np.abs(st)))
        allowed = 0.0625 * tol + 8.0 * _EPS * local + rounding    # the logarithms' rounding too
        if np.max(np.abs(big[-3:])) > allowed:
            return None
        # start from 16 equal parts (a panel of a smooth law needs 10-30), bisect those that fail
        edges = ya + (yb - ya) * np.arange(_START_SUBS + 1) / _START_SUBS
        edges[-1] = yb
        pending = np.stack([edges[:-1], edges[1:]], 1)
        out = []
        for _ in range(30):
            lo, hi = pending[:, 0], pending[:, 1]
            sm, sh = 0.5 * (lo + hi), 0.5 * (hi - lo)
            u = ((sm - 0.5 * (ya + yb))[:, None] + sh[:, None] * _XL) / hw
            vals = _barycentric(u.ravel(), _XI, _WI, st)[0].reshape(u.shape)
            b = rows_dot(vals, _FIT_L)
            ok = np.max(np.abs(b[:, -2:]), axis=1) <= allowed
            out += [(lo[k], hi[k], b[k]) for k in np.flatnonzero(ok)]
            if np.all(ok):
                out.sort(key=lambda item: item[0])
                return out
            m = sm[~ok]
            pending = np.concatenate([np.stack([lo[~ok], m], 1), np.stack([m, hi[~ok]], 1)])
        return None

    # ------------------------------------------------------------ coverage
    def _cover(self, y_min: float, y_max: float) -> "_Segment":
        """The segment whose image covers [y_min, y_max] (or reaches a closed end of the table):
        extended, merged with its neighbours, or seeded afresh where no segment is near."""
        seeding = True
        for _ in range(400):
            segs = self._segments
            # a closed end of the table covers everything beyond it
            low = [-math.inf if (i == 0 and g.lo_end) else g.ya for i, g in enumerate(segs)]
            high = [math.inf if (i == len(segs) - 1 and g.hi_end) else g.yb for i, g in enumerate(segs)]
            near = [i for i in range(len(segs)) if high[i] >= y_min - _NEAR and low[i] <= y_max + _NEAR]
            if not near:
                seed = self._seed(y_min, y_max) if seeding else None
                if seed is not None:
                    self._add(seed)
                    if not (seed.yb >= y_min - _NEAR and seed.ya <= y_max + _NEAR):
                        # the guess was poor (the slope changed on the way): locate instead
                        seed = self._seed(y_min, y_max, locate=True)
                        if seed is not None and seed.pa not in [g.pa for g in self._segments]:
                            self._add(seed)
                        seeding = False
                    continue
                seeding = False       # no finite seed there: grow the nearest segment toward it
                if not segs:
                    self._add(self._seed_at_unit())
                    continue
                gaps = [max(low[i] - y_max, y_min - high[i]) for i in range(len(segs))]
                near = [int(np.argmin(gaps))]
            if len(near) > 1:                      # the range spans a gap: fill it
                self._bridge(near[0])
                continue
            i = near[0]
            g = segs[i]
            if y_min < g.ya and g.lo_end is None:
                self._extend(i, y_min, below=True)
                continue
            if y_max > g.yb and g.hi_end is None:
                self._extend(i, y_max, below=False)
                continue
            return g
        raise ConvergenceError(f"the flow table of {self.rheology!r} does not reach ln Gamma in "
                               f"[{y_min:.6g}, {y_max:.6g}]")

    def _add(self, segment):
        self._segments = sorted(self._segments + [segment], key=lambda g: g.pa)

    def _limit(self) -> float:
        """The lowest parameter of the table (the yield floor, or the representable range)."""
        if self.mode == "rate" or self.yield_stress == 0.0:
            return self._floor if self.mode == "rate" else -_P_LIMIT
        if self._p_floor is None:      # ln of the shear rate where tau - tau_y = sqrt(eps) tau_y
            rate = float(np.asarray(self.rheology._shear_rate(np.array([self.yield_stress + math.exp(self._floor)])))[0])
            self._p_floor = max(math.log(rate), -_P_LIMIT) if rate > 0 else -_P_LIMIT
        return self._p_floor

    def _seed(self, y_min, y_max, locate=False) -> "_Segment":
        """A new segment near the targets: p located by a few direct evaluations (secant steps),
        starting from the power-law asymptote of the nearest segment's end if there is one."""
        targets = np.array([y_min, y_max])
        lim = self._limit()
        slope = np.ones(2)
        trusted = True              # a guess good to ~1: build around it at once
        if self._segments:          # the power-law asymptote of the nearest segment's end
            below = [g for g in self._segments if g.yb < y_min]
            above = [g for g in self._segments if g.ya > y_max]
            if below and (not above or y_min - below[-1].yb <= above[0].ya - y_max):
                end = below[-1].panels[-1]
                slope[:] = end["dyb"]
                p = end["pb"] + (targets - end["yb"]) / slope
            else:
                end = above[0].panels[0]
                slope[:] = end["dya"]
                p = end["pa"] + (targets - end["ya"]) / slope
            p = np.clip(p, lim, _P_LIMIT)
        elif self.mode == "stress":
            p = np.clip(targets, lim, _P_LIMIT)      # Gamma is within a factor ~2 of the wall shear rate
        else:
            p = np.full(2, math.log(max(self.yield_stress, 1.0)))
            trusted = False
        if locate or not trusted:
            p = self._locate(p, targets, slope, lim)
        done, bad = self._seed_panels(p, lim)
        if not done and trusted:       # the guess was beyond the representable range: search
            p = self._locate(p, targets, slope, lim)
            done, bad = self._seed_panels(p, lim)
        if not done:
            return None                # the caller grows a segment toward the load instead
        return self._segment_from(done, bad, lim)

    def _seed_at_unit(self) -> "_Segment":
        """A first segment at unit stress (or rate): the law must be finite there."""
        lim = self._limit()
        p = np.zeros(2) if self.mode == "stress" else np.full(2, math.log(max(self.yield_stress, 1.0)))
        done, bad = self._seed_panels(p, lim)
        if not done:
            raise ConvergenceError(f"the flow function of {self.rheology!r} is not finite at unit stress")
        return self._segment_from(done, bad, lim)

    def _segment_from(self, done, bad, lim) -> "_Segment":
        run = [done[0]]            # the contiguous run of accepted panels
        for d in done[1:]:
            if d["pa"] != run[-1]["pb"]:
                break
            run.append(d)
        segment = _Segment(run)
        if any(b <= run[0]["pa"] for _, b in bad):
            segment.lo_end = "limit"
        if any(a >= run[-1]["pb"] for a, _ in bad):
            segment.hi_end = "limit"
        if run[0]["pa"] <= lim:
            segment.lo_end = "yield" if self.yield_stress > 0 else "limit"
        return segment

    def _seed_panels(self, p, lim):
        """The panels of a new segment around the parameters ``p``, clear of the existing ones:
        within 1 of them, or around a single load from 2 below to 0.25 above it (a solve's first
        load is its outlet, where the lumen is narrowest: the rest of the tube, and the steps
        that bracket its inlet, have lower Gamma; measured over Carreau fluids whose transition
        falls anywhere in the range, 11 % fewer evaluations than +-1)."""
        below, above = _SEED_SINGLE if float(p.max()) - float(p.min()) <= 1e-9 else (1.0, 1.0)
        lo, hi = max(float(p.min()) - below, lim), min(float(p.max()) + above, _P_LIMIT)
        for g in self._segments:        # stay clear of the existing segments
            if g.pb <= float(p.min()):
                lo = max(lo, g.pb)
            if g.pa >= float(p.max()):
                hi = min(hi, g.pa)
        if not hi > lo:
            lo, hi = min(lo, hi - 1.0), hi
        count = max(1, int(math.ceil((hi - lo) / 8.0)))
        edges = np.linspace(lo, hi, count + 1)
        edges[0], edges[-1] = lo, hi
        return self._build(list(zip(edges[:-1], edges[1:])))

    def _locate(self, p, targets, slope, lim):
        """p with y(p) within 0.5 of ``targets``, by secant steps on direct evaluations."""
        s, y, _ = self._exact(p)
        for _ in range(60):
            fine = np.isfinite(y)
            if np.all(fine):
                break
            p = np.where(fine, p, 0.5 * p)                 # toward unit stress or rate
            s, y, _ = self._exact(p)
        else:
            return p
        for _ in range(60):
            miss = targets - y
            if np.all(np.abs(miss) <= 0.5):
                break
            step = np.where(np.abs(miss) <= 0.5, 0.0, np.clip(miss / slope, -64.0, 64.0))
            p_new = np.clip(p + step, lim, _P_LIMIT)
            for _ in range(60):
                s_new, y_new, _ = self._exact(p_new)
                fine = np.isfinite(y_new)
                if np.all(fine):
                    break
                p_new = np.where(fine, p_new, 0.5 * (p + p_new))
            else:
                return p
            moved = np.abs(p_new - p) > 1e-12
            if not np.any(moved):
                break                      # at a limit of the range: the extension handles the rest
            with np.errstate(divide="ignore", invalid="ignore"):
                sec = (y_new - y) / (p_new - p)
            slope = np.where(moved & (sec > 0), np.clip(sec, 1e-3, 1e3), slope)
            p, y = p_new, y_new
        return p

    def _bridge(self, i):
        """Merge segment ``i`` with the next one, tabulating the gap between them."""
        a, b = self._segments[i], self._segments[i + 1]
        fill = []
        if b.pa > a.pb:
            fill, bad = self._build([(a.pb, b.pa)])
            if bad:
                raise ConvergenceError(f"the flow function of {self.rheology!r} is not finite between "
                                       "finite values")
        merged = _Segment(a.panels + fill + b.panels)
        merged.lo_end, merged.hi_end = a.lo_end, b.hi_end
        self._segments[i: i + 2] = [merged]

    def _extend(self, i, target, below):
        """Grow segment ``i`` toward ``target`` (a value of y), by the slope at its end."""
        segs = self._segments
        g = segs[i]
        lim = self._limit()
        if below:
            first = g.panels[0]
            if self.yield_stress > 0 and first["sa"] <= self._floor * (1 - 1e-12):
                g.lo_end = "yield"
                return
            if first["pa"] <= lim:
                g.lo_end = "yield" if self.yield_stress > 0 else "limit"
                return
            dp = (first["ya"] - target) / max(first["dya"], 1e-6)
            lo = max(lim, first["pa"] - (1.25 * dp + 0.5))
            if i > 0 and lo <= segs[i - 1].pb:
                self._bridge(i - 1)
                return
            self._grow(g, (lo, first["pa"]), below=True)
        else:
            last = g.panels[-1]
            if last["pb"] >= _P_LIMIT or last["sb"] >= _P_LIMIT:
                g.hi_end = "limit"
                return
            dp = (target - last["yb"]) / max(last["dyb"], 1e-6)
            hi = min(_P_LIMIT, last["pb"] + (1.25 * dp + 0.5))
            if i + 1 < len(segs) and hi >= segs[i + 1].pa:
                self._bridge(i)
                return
            self._grow(g, (last["pb"], hi), below=False)

    def _grow(self, segment, interval, below):
        """Add the panels of ``interval`` at the lower (``below``) or upper end of ``segment``. Where
        the flow function is not finite (beyond the representable range), keep the finite part next
        to the segment and close that end."""
        a, b = interval
        for _ in range(80):
            count = max(1, int(math.ceil((b - a) / 64.0)))  # at most 64 wide: the bisection starts there
            edges = np.linspace(a, b, count + 1)
            edges[0], edges[-1] = a, b
            done, bad = self._build(list(zip(edges[:-1], edges[1:])))
            if below:
                edge = max((hi for _, hi in bad), default=a)
                keep = [d for d in done if d["pa"] >= edge]
                if keep:
                    segment.install(keep + segment.panels)
                if not bad:
                    return
                lo_bad = max(lo for lo, hi in bad if hi == edge)
                a, b = edge - 0.5 * (edge - lo_bad), edge
            else:
                edge = min((lo for lo, _ in bad), default=b)
                keep = [d for d in done if d["pb"] <= edge]
                if keep:
                    segment.install(segment.panels + keep)
                if not bad:
                    return
                hi_bad = min(hi for lo, hi in bad if lo == edge)
                a, b = edge, edge + 0.5 * (hi_bad - edge)
            if b - a <= 0.25:         # the end of the representable range, to a quarter in ln
                break
        if below:
            segment.lo_end = "limit"
        else:
            segment.hi_end = "limit"

    # ------------------------------------------------------------ lookups
    def wall_stress(self, apparent_rate):
        r""":math:`\tau_w` with :math:`\Gamma(\tau_w) =` ``apparent_rate``, from the table; the yield
        stress (0 for most fluids) where ``apparent_rate`` is 0."""
        rate = np.asarray(apparent_rate, dtype=float)
        shape = rate.shape
        flat = rate.ravel()
        if flat.size == 0:
            return np.zeros(shape)
        if not np.all(flat > 0):
            out = np.full(flat.shape, self.yield_stress)
            pos = flat > 0
            if np.any(pos):
                out[pos] = self.wall_stress(flat[pos])
            return out.reshape(shape)
        y = np.log(flat)
        y_min, y_max = float(y.min()), float(y.max())
        if not (math.isfinite(y_max) and math.isfinite(y_min)):
            raise InvalidParameterError("flow_rate", "[0, inf)", float(flat[~np.isfinite(y)][0]),
                                        "the apparent wall shear rate 4 q / (pi R^3) must be finite")
        g = self._cover(y_min, y_max)
        if y_max > g.yb:
            last = g.panels[-1]
            raise InvalidParameterError(
                "flow_rate", "a range the fluid can carry", None,
                f"4 q / (pi R^3) = {math.exp(min(y_max, 709.0)):.6g} 1/s needs a wall shear stress beyond "
                f"{self.yield_stress + math.exp(last['sb']):.6g} Pa, where its flow function ends")
        s = g.s(np.maximum(y, g.ya) if y_min < g.ya else y)
        if y_min < g.ya:   # below the table: the power-law asymptote of its end
            first = g.panels[0]
            low = y < g.ya
            s[low] = first["sa"] + first["slope_a"] * (y[low] - first["ya"])
            if g.lo_end != "yield":
                warn_unconverged("the tube-flow function below its representable range (power-law extrapolation)",
                                 Integral(value=np.ones(1), error=np.array([np.inf]), converged=np.array([False]),
                                          panels=np.ones(1, dtype=int)))
        np.exp(s, out=s)
        if self.yield_stress:
            s += self.yield_stress
        return s.reshape(shape)

    @property
    def panel_count(self) -> int:
        """The number of accepted forward panels."""
        return sum(len(g.panels) for g in self._segments)

    @property
    def segments(self):
        """The tabulated ranges of ln Gamma, [(low, high)], ascending."""
        return [(g.ya, g.yb) for g in self._segments]


class _Segment:
    """Contiguous forward panels and their lookup: breakpoints in y, a bucket index of them, and
    the monomial coefficients of each lookup panel in its own coordinate (one array per degree)."""

    __slots__ = ("panels", "lo_end", "hi_end", "flagged", "brk", "center", "inv", "coef", "error", "cell0",
                 "cell_inv", "ncell", "first", "threshold", "multi", "any_multi", "k")

    def __init__(self, panels):
        self.lo_end = None        # why the table ends below: None (open), "yield", "limit"
        self.hi_end = None
        self.install(panels)

    pa = property(lambda self: self.panels[0]["pa"])
    pb = property(lambda self: self.panels[-1]["pb"])
    ya = property(lambda self: self.panels[0]["ya"])
    yb = property(lambda self: self.panels[-1]["yb"])

    def install(self, panels):
        self.panels = panels
        subs = [(sub, p["error"], p["s0"]) for p in panels for sub in p["subs"]]
        lo = np.array([t[0] for t, _, _ in subs])
        hi = np.array([t[1] for t, _, _ in subs])
        # breakpoints (adjacent forward panels share their end's exact value; guard the rounding)
        self.brk = np.maximum.accumulate(np.concatenate([lo, hi[-1:]]))
        mono = rows_dot(np.array([t[2] for t, _, _ in subs]), _TO_MONO)
        mono[:, 0] += np.array([s0 for _, _, s0 in subs])        # the panels' centres, added last
        self.coef = np.ascontiguousarray(mono.T)
        self.error = np.array([e for _, e, _ in subs])
        self.flagged = bool(np.any(self.error > TOL))
        half = 0.5 * (hi - lo)
        with np.errstate(divide="ignore"):
            self.inv = np.where(half > 0, 1.0 / half, 0.0)
        self.center = 0.5 * (lo + hi)
        self.k = k = lo.size
        # buckets of equal width in y: each gives its first panel and the breakpoint inside it
        # (+inf if none); the few buckets that hold several breakpoints fall back to a search
        brk = self.brk
        span = float(brk[-1] - brk[0])
        widths = np.diff(brk)
        finest = float(np.min(widths[widths > 0])) if np.any(widths > 0) else span
        self.ncell = ncell = int(min(max(2.0 * span / finest if finest > 0 else 1.0, 4 * k, 64), 1 << 16))
        self.cell0 = float(brk[0])
        self.cell_inv = ncell / span if span > 0 else 0.0
        edges = brk[0] + np.arange(ncell + 1) * (span / ncell) if span > 0 else np.full(ncell + 1, brk[0])
        first = np.clip(np.searchsorted(brk, edges[:-1], side="right") - 1, 0, k - 1)
        last = np.clip(np.searchsorted(brk, edges[1:], side="left") - 1, 0, k - 1)
        self.first = first.astype(np.intp)
        self.threshold = np.where(last > first, brk[np.minimum(first + 1, k)], np.inf)
        self.multi = last > first + 1
        self.any_multi = bool(np.any(self.multi))

    def s(self, y):
        """s = ln(tau_w - tau_y) at y = ln Gamma (1-D, within the segment's range): the bucket of
        each point gives its panel (a search only where a bucket holds several breakpoints), then
        Horner's rule with the coefficients gathered one degree at a time (no per-point rows)."""
        work = y - self.cell0
        work *= self.cell_inv
        np.clip(work, 0.0, self.ncell - 1, out=work)
        cell = work.astype(np.intp)
        j = self.first.take(cell)
        np.take(self.threshold, cell, out=work, mode="clip")   # in range: clip skips the buffering
        np.add(j, y >= work, out=j, casting="unsafe")
        if self.any_multi:
            sub = np.flatnonzero(self.multi.take(cell))
            if sub.size:
                j[sub] = np.minimum(np.searchsorted(self.brk, y[sub], side="right") - 1, self.k - 1)
        del cell
        np.minimum(j, self.k - 1, out=j)
        x = np.subtract(y, self.center.take(j))
        np.take(self.inv, j, out=work, mode="clip")
        x *= work
        coef = self.coef
        acc = coef[_P].take(j)
        for d in range(_P - 1, -1, -1):
            acc *= x
            np.take(coef[d], j, out=work, mode="clip")
            acc += work
        if self.flagged:
            worst = float(np.max(self.error.take(j)))
            if worst > TOL:
                warn_unconverged("the tube-flow table (a non-smooth constitutive law)",
                                 Integral(value=np.ones(1), error=np.array([worst]), converged=np.array([False]),
                                          panels=np.ones(1, dtype=int)))
        return acc


def _overridden(obj, name) -> bool:
    """Whether ``type(obj)`` overrides the hook ``name`` of the root class that defines it."""
    owners = [c for c in type(obj).__mro__ if name in vars(c)]
    return len(owners) > 1 and owners[0] is not owners[-1]


def _barycentric(x, nodes, weights, values, slope=False):
    """The polynomial through ``values`` at ``nodes`` (barycentric ``weights``) at the points ``x``
    (1-D, within the nodes' interval), and with ``slope`` its derivative; a point on a node gets
    the node's value (and its slope from :data:`_SLOPE_F`, for the Lobatto nodes only)."""
    d = x[:, None] - nodes
    hit = d == 0.0
    any_hit = bool(hit.any())
    if any_hit:
        d[hit] = 1.0
    c = weights / d
    if any_hit:
        rows, cols = np.nonzero(hit)
        c[rows] = 0.0
        c[rows, cols] = 1.0
    den = c.sum(axis=1)
    p = rows_dot(c, values) / den
    if not slope:
        return p, None
    # p'(x) = sum_j c_j (p - v_j) / (x - x_j) / sum_j c_j (Schneider & Werner 1986)
    dp = ((p[:, None] - values) * c / d).sum(axis=1) / den
    if any_hit:
        dp[rows] = (values @ _SLOPE_F)[cols]
    return p, dp


def _solve_forward(values, yt, guess, scale):
    """x in [-1, 1] with ỹ(x) = yt (1-D targets) on one forward interpolant (its ``values`` at the
    Lobatto nodes, of the order of ``scale``): Newton's method with a bisection safeguard; None
    if it does not converge."""
    lo = np.full(yt.shape, -1.0)
    hi = np.full(yt.shape, 1.0)
    x = np.clip(guess, -1.0, 1.0)
    tiny = 8.0 * _EPS * max(float(scale), 1e-300)
    for _ in range(60):
        y, d = _barycentric(x, _XF, _WF, values, slope=True)
        r = y - yt
        if np.all(np.abs(r) <= tiny):
            return x
        lo = np.where(r < 0, x, lo)
        hi = np.where(r > 0, x, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_new = x - r / d
        out = ~((x_new > lo) & (x_new < hi)) | ~np.isfinite(x_new)
        x_new = np.where(out, 0.5 * (lo + hi), x_new)
        if np.all((np.abs(x_new - x) <= 2 * _EPS) | (np.abs(r) <= tiny) | (hi - lo <= 4 * _EPS)):
            return x_new
        x = x_new
    return None


def _eval_subs(subs, y, s0=0.0):
    """Evaluate the lookup panels ``subs`` [(lo, hi, cheb)] (offsets from ``s0``) at ``y`` (1-D)."""
    lo = np.array([t[0] for t in subs])
    j = np.clip(np.searchsorted(lo, y, side="right") - 1, 0, len(subs) - 1)
    a = lo[j]
    b = np.array([subs[k][1] for k in j])
    x = (y - 0.5 * (a + b)) / (0.5 * (b - a))
    coef = np.array([subs[k][2] for k in j]).T              # one column per point
    return np.polynomial.chebyshev.chebval(x, coef, tensor=False) + s0


def _linear_subs(panel):
    """A straight line through the ends: the lookup of a panel whose inversion failed."""
    ya, yb, sa, sb = panel["ya"], panel["yb"], panel["sa"], panel["sb"]
    c = np.zeros(_P + 1)
    c[0], c[1] = 0.5 * (sa + sb) - panel["s0"], 0.5 * (sb - sa)
    return [(ya, yb, c)]


_TABLES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def flow_table(rheology) -> FlowTable:
    """The cached :class:`FlowTable` of ``rheology``."""
    try:
        return _TABLES[rheology]
    except KeyError:
        table = _TABLES[rheology] = FlowTable(rheology)
        return table
    except TypeError:  # not weak-referenceable: no cache
        return FlowTable(rheology)
