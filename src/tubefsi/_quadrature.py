r"""Error-controlled, vectorized adaptive quadrature: Gauss–Kronrod 10/21 on many intervals at once.

:func:`adaptive` integrates one integrand over an interval per point, for thousands of points
in a few array operations per round. Each panel carries the Kronrod estimate and the QUADPACK
error estimate

.. math::

    E = \rho\,\min\bigl(1, (200\,|K_{21} - G_{10}|/\rho)^{3/2}\bigr), \qquad
    \rho = \int |f - \bar f|,

which is how QUADPACK (``qk21``) and :func:`scipy.integrate.quad` estimate the error of the
21-point rule from its embedded 10-point Gauss rule (with a floor of two units of rounding of
:math:`\int |f|` per panel, instead of QUADPACK's fifty, so that a relative tolerance of 1e-14
can be met). A point is done when the sum of its panels'
estimates is within ``max(atol, rtol |I|)``; otherwise the worst panels of that point are
bisected, and only the new halves are evaluated. A point that
cannot reach its tolerance within ``max_rounds`` or ``max_panels`` keeps its best value and is
reported through ``converged = False`` with its estimate, for the caller to warn or raise.

The nodes and weights are QUADPACK's ``qk21`` constants; ``tests/test_quadrature.py`` checks them
(the Gauss part against :func:`numpy.polynomial.legendre.leggauss`, the Kronrod rule by its
exactness for polynomials of degree 31).
"""

from __future__ import annotations

import contextlib
import contextvars
import functools

import attrs
import numpy as np

from ._products import fixed_width_product, rows_dot, scratch
from .errors import AccuracyWarning, warn_user

__all__ = ["Integral", "adaptive", "adaptive_to_pole", "solve_integral", "warn_unconverged", "quiet", "KRONROD_NODES",
           "KRONROD_WEIGHTS", "GAUSS_WEIGHTS", "LOBATTO_NODES"]

_X = np.array([
    0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
    0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
    0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
    0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
    0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0,
])
_WK = np.array([
    0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
    0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
    0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
    0.123491976262065851077958109831074, 0.134709217311473325928054001771707,
    0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
    0.149445554002916905664936468389821,
])
_WG = np.array([
    0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
    0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
    0.295524224714752870173892994651338,
])

#: The 21 Kronrod nodes on [0, 1], ascending, and the Kronrod and embedded Gauss weights there.
KRONROD_NODES = 0.5 * (1.0 + np.concatenate([-_X[:-1], _X[::-1]]))
KRONROD_WEIGHTS = 0.5 * np.concatenate([_WK[:-1], _WK[::-1]])
#: The 10-point Gauss weights on [0, 1], for the nodes ``KRONROD_NODES[1::2]``.
GAUSS_WEIGHTS = 0.5 * np.concatenate([_WG, _WG[::-1]])

#: The Kronrod weights and the embedded Gauss weights (zero at the Kronrod-only nodes), as columns.
_KRONROD_AND_GAUSS = np.stack([KRONROD_WEIGHTS, np.zeros(21)], axis=1)
_KRONROD_AND_GAUSS[1::2, 1] = GAUSS_WEIGHTS

_EPS = np.finfo(float).eps


@attrs.frozen
class Integral:
    """What :func:`adaptive` returns: arrays of one shape (the intervals')."""

    value: np.ndarray       #: the integral
    error: np.ndarray       #: the a-posteriori error estimate
    converged: np.ndarray   #: whether ``error <= max(atol, rtol |value|)``
    panels: np.ndarray      #: the number of panels used


def _rule(f, lo, hi, idx, noise=None):
    """Kronrod values, QUADPACK error estimates and rounding floors of the panels ``[lo, hi]``."""
    h = hi - lo
    x = lo[:, None] + h[:, None] * KRONROD_NODES
    y = np.asarray(f(x, idx), dtype=float)
    # (every product row by row, whatever the batch: tubefsi._products)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        rules = rows_dot(y, _KRONROD_AND_GAUSS)
        kron, gauss = rules[:, 0], rules[:, 1]          # mean values of f on the panel (weights sum to 1)
        spread = rows_dot(np.abs(y - kron[:, None]), KRONROD_WEIGHTS)
        raw = np.abs(kron - gauss)
        scaled = np.where((spread > 0) & (raw > 0), spread * np.minimum(1.0, (200.0 * raw / spread) ** 1.5), raw)
        magnitude = rows_dot(np.abs(y), KRONROD_WEIGHTS)
        floor = 2.0 * _EPS * magnitude                            # the rule's own rounding
        if noise is not None:                                     # and the integrand's, if known
            floor = np.maximum(floor, rows_dot(np.abs(y) * noise(x, idx), KRONROD_WEIGHTS))
        error = np.maximum(scaled, floor)
    return kron * h, error * np.abs(h), floor * np.abs(h)


def adaptive(f, lower, upper, *, rtol=1e-14, atol=0.0, panels=None, max_rounds=60, max_panels=2048,
             noise=None) -> Integral:
    r""":math:`\int_{lower}^{upper} f(x)\,dx` for each entry of ``lower``/``upper``, error-controlled.

    Parameters
    ----------
    f : callable
        ``f(x, index)`` with ``x`` of shape ``(P, 21)`` (the nodes of ``P`` panels) and ``index``
        of shape ``(P,)`` (the flat position of each panel's point); returns values of ``x``'s
        shape. Per-point parameters are gathered with ``index`` (e.g. ``a[index, None]``).
    lower, upper : array_like
        The limits (broadcast together); ``upper < lower`` gives minus the integral.
    rtol, atol : float
        The tolerance ``max(atol, rtol |I|)`` on each point's error estimate.
    panels : array_like of int, optional
        Initial number of equal panels per point (default 1).
    max_rounds, max_panels : int
        Limits of the refinement (rounds of bisection; panels per point).
    noise : callable, optional
        ``noise(x, index)``: the relative rounding error of ``f`` at the nodes, where the caller
        knows it (e.g. a pole approached closer than the abscissae resolve). A point whose
        estimate is within twice its rounding floor is done: no refinement can do better, and
        the estimate, floor included, is reported.

    Returns
    -------
    Integral
        ``value``, ``error``, ``converged`` and ``panels``, shaped like the broadcast limits.
    """
    lower, upper = np.broadcast_arrays(np.asarray(lower, dtype=float), np.asarray(upper, dtype=float))
    shape = lower.shape
    lo_pt, hi_pt = lower.ravel(), upper.ravel()
    n = lo_pt.size
    count = np.ones(n, dtype=int) if panels is None else np.maximum(
        1, np.broadcast_to(np.asarray(panels, dtype=int), shape).ravel())
    # the initial panels
    idx = np.repeat(np.arange(n), count)
    first = np.cumsum(count) - count
    j = np.arange(idx.size) - first[idx]
    width = (hi_pt - lo_pt)[idx] / count[idx]
    lo = lo_pt[idx] + j * width
    hi = np.where(j == count[idx] - 1, hi_pt[idx], lo + width)
    value, error, rounding = _rule(f, lo, hi, idx, noise)
    total = np.bincount(idx, value, minlength=n)
    err = np.bincount(idx, error, minlength=n)
    floor = np.bincount(idx, rounding, minlength=n)
    used = count.copy()
    done_value = np.zeros(n)      # contributions of the retired panels (of finished points)
    done_error = np.zeros(n)
    done_floor = np.zeros(n)
    finished = np.zeros(n, dtype=bool)
    best = err.copy()                 # the smallest estimate so far, and rounds without halving it
    stalled = np.zeros(n, dtype=int)
    for _ in range(max_rounds):
        tol = np.maximum(atol, rtol * np.abs(total))
        # done: within tolerance (or the rounding floor); hopeless: not finite, or a noisy
        # integrand whose estimate has not halved in eight rounds of refinement
        stalled = np.where(err < 0.5 * best, 0, stalled + 1)
        best = np.minimum(best, err)
        finished |= ((err <= np.maximum(tol, 2.0 * floor)) | ~np.isfinite(total) | ~np.isfinite(err)
                     | (stalled >= 8))
        live = ~finished[idx]
        if not np.any(live):
            break
        if not np.all(live):      # retire the panels of finished points: they are not needed again
            dead = ~live
            done_value += np.bincount(idx[dead], value[dead], minlength=n)
            done_error += np.bincount(idx[dead], error[dead], minlength=n)
            done_floor += np.bincount(idx[dead], rounding[dead], minlength=n)
            idx, lo, hi = idx[live], lo[live], hi[live]
            value, error, rounding = value[live], error[live], rounding[live]
        # bisect each unfinished point's worst panels (within a factor 4 of its largest estimate),
        # as QUADPACK bisects its worst one, but many per round; never one already within
        # 1/100 of its share of the tolerance
        worst = np.zeros(n)
        np.maximum.at(worst, idx, error)
        split = (error >= 0.25 * worst[idx]) & (error > 0.01 * tol[idx] / used[idx]) & (used[idx] < max_panels)
        if not np.any(split):
            break
        mid = 0.5 * (lo[split] + hi[split])
        s_idx = np.concatenate([idx[split], idx[split]])
        s_lo = np.concatenate([lo[split], mid])
        s_hi = np.concatenate([mid, hi[split]])
        s_val, s_err, s_rnd = _rule(f, s_lo, s_hi, s_idx, noise)
        used += np.bincount(idx[split], minlength=n)
        keep = ~split
        idx = np.concatenate([idx[keep], s_idx])
        lo = np.concatenate([lo[keep], s_lo])
        hi = np.concatenate([hi[keep], s_hi])
        value = np.concatenate([value[keep], s_val])
        error = np.concatenate([error[keep], s_err])
        rounding = np.concatenate([rounding[keep], s_rnd])
        total = done_value + np.bincount(idx, value, minlength=n)
        err = done_error + np.bincount(idx, error, minlength=n)
        floor = done_floor + np.bincount(idx, rounding, minlength=n)
    tol = np.maximum(atol, rtol * np.abs(total))
    converged = (err <= np.maximum(tol, 2.0 * floor)) & np.isfinite(total)
    return Integral(value=total.reshape(shape), error=err.reshape(shape), converged=converged.reshape(shape),
                    panels=used.reshape(shape))


def adaptive_to_pole(f, lower, upper, pole, *, gap=None, reach=1.0, rtol=1e-14, atol=0.0, panel_width=2.0,
                     max_rounds=60) -> Integral:
    r""":func:`adaptive` for an integrand that may be singular at ``x = pole`` (> ``upper``; ``inf``
    for none), as a locking material's stiffness is at its locking stretch.

    Within ``reach`` of the pole the integral is taken in :math:`y = \ln(\text{pole} - x)`,
    :math:`\int f\,dx = \int f(\text{pole} - e^y)\,e^y\,dy`, where a pole or a logarithmic
    singularity of ``f`` becomes a smooth, slowly varying integrand. ``gap`` is
    ``pole - upper``, computed by the caller without cancellation (default: the difference).
    ``f(x, index)`` is called as for :func:`adaptive`; the initial panels are at most
    ``panel_width`` wide. ``lower >= 0`` and ``upper >= lower`` elementwise.
    """
    lower, upper, pole = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (lower, upper, pole)))
    shape = lower.shape
    lo, up, po = lower.ravel(), upper.ravel(), pole.ravel()
    # the substitution pays where the pole is closer to the upper end than the interval is long
    d_gap = (po - up) if gap is None else np.broadcast_to(np.asarray(gap, dtype=float), shape).ravel()
    finite = np.isfinite(po) & (d_gap < up - lo)
    split = np.where(finite, np.clip(po - reach, lo, up), up)
    count = np.maximum(1, np.ceil((split - lo) / panel_width)).astype(int)
    head = adaptive(f, lo, split, rtol=rtol, atol=atol, panels=count, max_rounds=max_rounds)
    value, error, converged, panels = (head.value.copy(), head.error.copy(), head.converged.copy(),
                                       head.panels.copy())
    near = np.flatnonzero(finite & (up > split))
    if near.size:
        pn = po[near]
        d_end = np.maximum(d_gap[near], np.abs(pn) * 4 * _EPS)        # distance of the upper end to the pole

        def g(y, sub):
            e = np.exp(y)
            return f(pn[sub, None] - e, near[sub]) * e

        # y from ln(pole - upper) to ln(pole - split), their difference without cancellation
        y_lo = np.log(d_end)
        y_hi = y_lo + np.log1p((up[near] - split[near]) / d_end)
        def rounding(y, sub):       # pole - e^y is rounded to eps |pole|: the distance e^y to it is not finer
            return 4.0 * _EPS * (1.0 + np.abs(pn[sub, None])) / np.exp(y)

        tail = adaptive(g, y_lo, y_hi, rtol=rtol, atol=atol,
                        panels=np.maximum(1, np.ceil((y_hi - y_lo) / panel_width)).astype(int),
                        max_rounds=max_rounds, noise=rounding)
        value[near] += tail.value
        error[near] += tail.error
        panels[near] += tail.panels
        converged[near] &= tail.converged
    return Integral(value=value.reshape(shape), error=error.reshape(shape), converged=converged.reshape(shape),
                    panels=panels.reshape(shape))


_QUIET = contextvars.ContextVar("tubefsi_quiet_quadrature", default=False)


@contextlib.contextmanager
def quiet():
    """Within an iteration, quadratures at trial points do not warn (nor do their integrands'
    overflows at far-out trial stretches): the iteration checks its final answer itself."""
    token = _QUIET.set(True)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            yield
    finally:
        _QUIET.reset(token)


_RECORD = contextvars.ContextVar("tubefsi_record_unconverged", default=None)


@contextlib.contextmanager
def recording():
    """Collect, instead of warning, the ``(what, result)`` of every quadrature in the block that
    missed its tolerance: an iteration learns whether the evaluation it ends on was converged,
    and need not evaluate its answer once more only to find out."""
    found = []
    token = _RECORD.set(found)
    try:
        yield found
    finally:
        _RECORD.reset(token)


def warn_unconverged(what: str, result: Integral) -> None:
    """The ``AccuracyWarning`` of a quadrature that could not meet its tolerance somewhere
    (silent within :func:`quiet`, collected within :func:`recording`)."""
    found = _RECORD.get()
    if found is not None:
        found.append((what, result))
        return
    if _QUIET.get():
        return
    bad = ~np.asarray(result.converged)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(result.value != 0, result.error / np.abs(result.value), np.inf)
    worst = float(np.max(rel[bad]))
    warn_user(f"{what} did not reach its tolerance at {int(np.count_nonzero(bad))} point(s); estimated "
              f"relative error up to {worst:.2g}", AccuracyWarning)


# ------------------------------------------------------------ one-shot solve of an integral equation
#: Degree of the Chebyshev interpolant of :func:`solve_integral` (17 Chebyshev–Lobatto nodes).
CHEBYSHEV_DEGREE = 16


@attrs.frozen
class _LobattoRule:
    """What :func:`solve_integral` needs of one degree ``n``: the ``n + 1`` Chebyshev–Lobatto nodes
    on [-1, 1] and [0, 1], and one matrix for every linear map, applied in one product (one
    BLAS call): values at the nodes -> the Chebyshev coefficients of the interpolant on [-1, 1]
    (rows ``coef``: the discrete cosine transform of type I), of its antiderivative that vanishes
    at -1 (rows ``anti``, :func:`numpy.polynomial.chebyshev.chebint`), and that antiderivative at
    the nodes (rows ``cumulative``: the integrals over [-1, t_j], to bracket the root)."""

    degree: int
    t: np.ndarray
    nodes: np.ndarray
    matrix: np.ndarray
    coef: slice
    anti: slice
    cumulative: slice


@functools.lru_cache(maxsize=None)
def _lobatto_rule(n):
    t = -np.cos(np.pi * np.arange(n + 1) / n)                       # on [-1, 1], ascending
    nodes = 0.5 * (1.0 + t)
    nodes[0], nodes[-1] = 0.0, 1.0                                 # (an end node exactly 0, the other 1)
    k = np.arange(n + 1)
    theta = np.pi * np.arange(n + 1) / n                 # t_j = -cos(theta_j)
    to_coef = np.cos(np.outer(k, theta)) * (-1.0) ** k[:, None] * (2.0 / n)
    to_coef[:, [0, -1]] *= 0.5                           # the end nodes count half (trapezoid on theta)
    to_coef[[0, -1], :] *= 0.5                           # and so do the first and last coefficients
    to_antiderivative = np.polynomial.chebyshev.chebint(to_coef, lbnd=-1.0, axis=0)
    cumulative = np.polynomial.chebyshev.chebvander(t, n + 1) @ to_antiderivative
    matrix = np.vstack([to_coef, to_antiderivative, cumulative])
    return _LobattoRule(n, t, nodes, matrix, slice(0, n + 1), slice(n + 1, 2 * n + 3), slice(2 * n + 3, 3 * n + 4))


#: The Chebyshev–Lobatto nodes of :func:`solve_integral` on [0, 1] (an end node is exactly 0, the other 1).
LOBATTO_NODES = _lobatto_rule(CHEBYSHEV_DEGREE).nodes
#: Points per matrix product: OpenBLAS runs a product above ~2.6e5 multiply-adds on several
#: threads, which on a busy machine costs ten times the arithmetic; blocks stay below that.
_BLOCK = 256


def _apply_map(y, matrix):
    """``matrix @ y`` (``y`` of shape (n + 1, P); the result (52, P) at degree 16, rows
    contiguous), in blocks of ``_BLOCK`` points of one shape
    (:func:`~tubefsi._products.fixed_width_product`: a point's answer must not depend on the
    batch it came in: a broadcast solve equals its scalar solves), into this thread's scratch
    buffer (valid until the next call)."""
    return fixed_width_product(matrix, y, out=scratch("maps", (matrix.shape[0], y.shape[1])), width=_BLOCK)


def _clenshaw(coef, t):
    """:math:`\\sum_k c_{kp} T_k(t_p)` for each column ``p`` of ``coef`` (degree along axis 0)
    at its own ``t_p``: three arrays rotated through the recurrence, none allocated in it."""
    b1 = np.zeros(t.shape)
    b2 = np.zeros(t.shape)
    b0 = np.empty(t.shape)
    two_t = 2.0 * t
    for k in range(coef.shape[0] - 1, 0, -1):
        np.multiply(two_t, b1, out=b0)         # b_k = 2 t b_{k+1} - b_{k+2} + c_k
        b0 -= b2
        b0 += coef[k]
        b0, b1, b2 = b2, b0, b1
    b1 *= t
    b1 += coef[0]
    b1 -= b2
    return b1


def solve_integral(f, target, upper, *, rtol=1e-14, values=None, degree=CHEBYSHEV_DEGREE):
    r"""Solve :math:`\int_0^{x} f(u)\,du = T` for :math:`x \in (0, X]`, per point, from one
    batch of integrand values: a Chebyshev interpolant on ``[0, X]``, integrated exactly.

    ``f(u, index)`` takes ``u`` of shape ``(n + 1, P)`` (column ``p``: the Chebyshev–Lobatto
    nodes of point ``p``'s interval, ``n = degree``, 16 by default) and the positions ``index``
    of those points, and returns values of that shape; ``f > 0``. (Points along the last,
    contiguous axis: a per-point parameter of shape ``(P,)`` then broadcasts along it, which
    NumPy's loops run at full speed, where a ``(P, 1)`` column against ``(P, n + 1)`` took
    twice the time.) The interpolant
    of degree ``n`` is integrated in closed form, bracketed at the nodes and solved by Newton's
    method on the polynomial (no further integrand values). Its error is estimated a
    posteriori from the tail of its Chebyshev coefficients (for a function analytic near the
    interval they decay geometrically, and the last ones bound what was left off,
    L. N. Trefethen, *Approximation Theory and Approximation Practice*, ch. 8 and 19):
    :math:`E = X\sum_{k=n-2}^{n}|c_k|`, and a point is solved only where
    :math:`E \le` ``rtol`` :math:`T`, its root lies in ``(0, X]`` and every value is positive
    and finite. The others are left to the caller (an adaptive method): nothing here is
    accepted unchecked.

    Returns ``(x, solved, short)``, flat arrays of the targets' size: ``x`` is meaningful only
    where ``solved``; ``short`` marks the points whose integral over ``[0, X]`` falls short of
    the target (the caller may try a longer interval).
    """
    rule = _lobatto_rule(degree)
    target = np.asarray(target, dtype=float).ravel()
    upper = np.broadcast_to(np.asarray(upper, dtype=float), target.shape)
    if values is None:          # (the nodes in a scratch buffer: f's temporaries are its own)
        nodes = np.multiply(rule.nodes[:, None], upper, out=scratch("nodes", (rule.nodes.size, target.size)))
        values = f(nodes, np.arange(target.size))
    y = np.asarray(values, dtype=float)
    half = 0.5 * upper
    with np.errstate(invalid="ignore", over="ignore"):
        maps = _apply_map(y, rule.matrix)                # (3n + 4, P): rows contiguous, for the recurrences
        coef, anti, cumulative = maps[rule.coef], maps[rule.anti], maps[rule.cumulative]
        anti *= half                                     # dx = (X/2) dt
        cumulative *= half
        tail = np.abs(coef[-3:]).sum(axis=0) * upper
        # every value positive: one reduction over the whole batch (NaN fails it), the per-point
        # minimum (a strided reduction, ten times dearer) only where that fails
        positive = True if y.min() > 0 else np.min(y, axis=0) > 0
        usable = positive & np.isfinite(tail) & (target > 0)   # a nan or inf in y reaches the tail
        short = usable & (cumulative[-1] < target)
        good = usable & ~short & (tail <= rtol * target)
    x = np.zeros(target.size)
    live = np.flatnonzero(good)
    if live.size == 0:
        return x, good, short
    h, t_goal = half, target
    if live.size < target.size:
        coef, anti, cumulative, y = coef[:, live], anti[:, live], cumulative[:, live], y[:, live]
        h, t_goal = half[live], target[live]
    # the bracketing nodes, and the cubic Hermite interpolant of the integral between them (its
    # slopes are the integrand values themselves) as Newton's start: within ~1e-5 of the root
    j = np.maximum(np.minimum(np.count_nonzero(cumulative < t_goal, axis=0), rule.degree), 1)
    # the bracket's ends as flat positions in the (nodes x points) arrays: a 1-D take each,
    # a quarter of the time of a 2-D fancy index
    lower = (j - 1) * live.size              # each point's lower bracket node, as a flat position
    lower += np.arange(live.size)
    flat_cumulative, flat_y = cumulative.ravel(), y.ravel()
    c0, c1 = flat_cumulative.take(lower), flat_cumulative.take(lower + live.size)
    t0, t1 = rule.t.take(j - 1), rule.t.take(j)
    scale = h * (t1 - t0)
    d0 = flat_y.take(lower)
    d0 *= scale
    d1 = flat_y.take(lower + live.size)
    d1 *= scale                                              # dJ/ds at the ends, s in [0, 1]
    rise, goal = c1 - c0, t_goal - c0
    s = np.clip(goal / rise, 0.0, 1.0)
    # the Hermite cubic in monomial form, H(s) = ((a3 s + a2) s + d0) s: Horner for it and for its
    # slope (a third of the passes of the Bernstein-like form; a start, so its rounding is moot)
    a3 = d0 + d1 - 2.0 * rise
    a2 = 3.0 * rise - 2.0 * d0 - d1
    a3_3, a2_2 = 3.0 * a3, 2.0 * a2
    # the integrand values (nodes x points) and the bracket's ends are no longer needed: freed
    # before the Newton iterations allocate theirs, the call's peak memory is lower, and with it
    # the heap that glibc trims after the call and the next call faults back in
    del values, y, flat_y, flat_cumulative, c0, c1, d1, rise, scale, j, lower
    for _ in range(3):
        value = a3 * s
        value += a2
        value *= s
        value += d0
        value *= s
        value -= goal
        slope = a3_3 * s
        slope += a2_2
        slope *= s
        slope += d0
        value /= slope
        s -= value
        np.clip(s, 0.0, 1.0, out=s)
    t = t0 + (t1 - t0) * s
    # Newton on the interpolant: quadratic, so a step below 1e-9 leaves an error of order
    # (f'/f) 1e-18 after it, and is the last one
    moving = np.ones(live.size, dtype=bool)
    for _ in range(8):
        step = (_clenshaw(anti, t) - t_goal) / (_clenshaw(coef, t) * h)
        step[~moving] = 0.0                  # a point's iterations do not depend on its neighbours'
        t = np.clip(t - step, t0, t1)
        moving &= ~(np.abs(step) <= 1e-9)
        if not np.any(moving):
            break
    else:
        good[live[moving]] = False
    x[live] = h * (1.0 + t)
    return x, good, short
