r"""One-batch solution of an integral equation from Chebyshev interpolation (the spectral solver).

:func:`solve_integral` solves :math:`\int_0^x f(u)\,du = T` for many points at once from one batch
of integrand values per point: the Chebyshev interpolant on Chebyshev–Lobatto nodes of
:math:`[0, X]`, integrated in closed form, bracketed at the nodes and solved by Newton's method on
the polynomial. Its error is estimated from the tail of the interpolant's coefficients; a point
whose estimate misses the tolerance is left to the caller (an adaptive method).
"""

from __future__ import annotations

import functools

import attrs
import numpy as np

from .kernels import blocked_matmul

__all__ = ["solve_integral", "CHEBYSHEV_DEGREE", "LOBATTO_NODES", "lobatto_rule", "clenshaw", "hermite_root"]

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


@functools.lru_cache(maxsize=8)
def lobatto_rule(n):
    """The :class:`_LobattoRule` of degree ``n`` (constants, read-only, computed once per degree)."""
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
    for constant in (t, nodes, matrix):     # (shared by every call: a write into one would change later answers)
        constant.setflags(write=False)
    return _LobattoRule(n, t, nodes, matrix, slice(0, n + 1), slice(n + 1, 2 * n + 3), slice(2 * n + 3, 3 * n + 4))


#: The Chebyshev–Lobatto nodes of :func:`solve_integral` on [0, 1] (an end node is exactly 0, the other 1).
LOBATTO_NODES = lobatto_rule(CHEBYSHEV_DEGREE).nodes


def clenshaw(coef, t):
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


def hermite_root(rise, goal, d0, d1, iterations=3):
    r"""The root :math:`s \in [0, 1]` of :math:`H(s) =` ``goal`` for the cubic Hermite
    interpolant :math:`H` of a function rising by ``rise`` over :math:`[0, 1]` from 0, with
    slopes ``d0`` and ``d1`` at the ends: Newton's method from the linear interpolant's root,
    ``iterations`` steps, clipped to [0, 1]. A start for Newton's method on a better interpolant
    (its rounding is moot). :math:`H(s) = ((a_3 s + a_2) s + d_0) s` with
    :math:`a_3 = d_0 + d_1 - 2r`, :math:`a_2 = 3r - 2d_0 - d_1`, by Horner's rule."""
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.minimum(np.maximum(goal / rise, 0.0), 1.0)    # (ufuncs: np.clip's wrapper costs more)
        a3 = d0 + d1 - 2.0 * rise
        a2 = 3.0 * rise - 2.0 * d0 - d1
        a3_3, a2_2 = 3.0 * a3, 2.0 * a2
        for _ in range(iterations):
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
            np.minimum(np.maximum(s, 0.0, out=s), 1.0, out=s)
    return s


#: Batches of at most this many points evaluate an interpolant and its derivative in one pass
#: (the same bits either way; only the time differs).
_PAIRED_BELOW = 2048


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
    rule = lobatto_rule(degree)
    target = np.asarray(target, dtype=float).ravel()
    upper = np.broadcast_to(np.asarray(upper, dtype=float), target.shape)
    if values is None:
        nodes = rule.nodes[:, None] * upper
        values = f(nodes, np.arange(target.size))
    y = np.asarray(values, dtype=float)
    half = 0.5 * upper
    with np.errstate(invalid="ignore", over="ignore"):
        maps = blocked_matmul(rule.matrix, y)            # (3n + 4, P): rows contiguous, for the recurrences
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
    # the integrand values (nodes x points) and the bracket's ends are no longer needed: freed
    # before the Newton iterations allocate theirs, the call's peak memory is lower, and with it
    # the heap that glibc trims after the call and the next call faults back in
    del values, y, flat_y, flat_cumulative, c0, c1, scale, j, lower
    s = hermite_root(rise, goal, d0, d1)
    t = t0 + (t1 - t0) * s
    # Newton on the interpolant: quadratic, so a step below 1e-9 leaves an error of order
    # (f'/f) 1e-18 after it, and is the last one
    moving = np.ones(live.size, dtype=bool)
    # a small batch pays per array operation: the integral and the integrand in one Clenshaw pass
    # halve them (the integrand's top coefficient is zero, so its values are the same bits); a
    # large batch is faster in two passes over contiguous rows
    paired = live.size <= _PAIRED_BELOW
    if paired:
        pair = np.zeros((anti.shape[0], 2, live.size))
        pair[:, 0] = anti
        pair[:-1, 1] = coef
    for _ in range(8):
        if paired:
            integral, integrand = clenshaw(pair, np.broadcast_to(t, (2, live.size)))
        else:
            integral, integrand = clenshaw(anti, t), clenshaw(coef, t)
        step = (integral - t_goal) / (integrand * h)
        step[~moving] = 0.0                  # a point's iterations do not depend on its neighbours'
        t = np.minimum(np.maximum(t - step, t0), t1)
        moving &= ~(np.abs(step) <= 1e-9)
        if not moving.any():
            break
    else:
        good[live[moving]] = False
    x[live] = h * (1.0 + t)
    return x, good, short
