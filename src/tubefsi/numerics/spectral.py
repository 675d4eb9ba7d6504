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

__all__ = ["solve_integral", "CHEBYSHEV_DEGREE", "LOBATTO_NODES", "lobatto_rule", "clenshaw", "hermite_root",
           "lobatto_weights", "barycentric", "at_nodes"]

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


@functools.lru_cache(maxsize=4)
def _barycentric_rule(n):
    """What :func:`solve_integral`'s ``method="barycentric"`` needs of degree ``n`` (constants,
    read-only): one matrix from the values at the nodes to the last three Chebyshev coefficients
    (the tail), the antiderivative at the nodes and at :math:`s_*` (midway between the two middle
    nodes); the ``n + 2`` nodes of the antiderivative (the Lobatto nodes, then :math:`s_*`) with
    their barycentric weights; and the Lobatto nodes' own weights :math:`(-1)^i`, halved at the
    ends."""
    rule = lobatto_rule(n)
    star = 0.5 * (rule.t[n // 2] + rule.t[n // 2 + 1])
    at_star = np.polynomial.chebyshev.chebvander(np.array([star]), n + 1) @ rule.matrix[rule.anti]
    matrix = np.vstack([rule.matrix[rule.coef][-3:], rule.matrix[rule.cumulative], at_star])
    nodes = np.append(rule.t, star)
    gaps = nodes[:, None] - nodes[None, :]
    np.fill_diagonal(gaps, 1.0)
    weights = 1.0 / np.prod(gaps, axis=1)
    weights /= np.abs(weights).max()
    for constant in (matrix, nodes, weights):
        constant.setflags(write=False)
    return matrix, nodes, weights, lobatto_weights(n)


@functools.lru_cache(maxsize=4)
def lobatto_weights(n):
    """The barycentric weights of the ``n + 1`` Chebyshev–Lobatto nodes: :math:`(-1)^i`, halved
    at the ends (Berrut & Trefethen, *SIAM Review* 46, 2004; a common factor cancels; a
    constant, read-only)."""
    w = (-1.0) ** np.arange(n + 1)
    w[[0, -1]] *= 0.5
    w.setflags(write=False)
    return w


def barycentric(weights, offsets, values):
    """The barycentric formula (second form) along the last axis: the interpolant of ``values``
    at the points whose offsets from the nodes are ``offsets`` (NaN where a point is on a node,
    an offset exactly 0: :func:`at_nodes` takes the node's value there). With the Lobatto weights
    at mapped nodes, the linear rational interpolant of Baltensperger, Berrut & Noël (*Math.
    Comp.* 68, 1999). Sums along the last axis: in one order whatever the leading dimensions."""
    ratio = weights / offsets
    return (ratio * values).sum(axis=-1) / ratio.sum(axis=-1)


def at_nodes(on_node, value, node_values):
    """``value`` where no node is hit, else the value at the node hit: the barycentric formula's
    0/0 there. ``on_node`` ``(..., nodes)``, at most one True per row; ``node_values`` of its
    shape, or the nodes' own values ``(nodes,)``."""
    if not on_node.any():
        return value
    first = on_node.argmax(axis=-1)
    at = node_values[first] if node_values.ndim == 1 else np.take_along_axis(node_values, first[..., None], axis=-1)[..., 0]
    return np.where(on_node.any(axis=-1), at, value)


def solve_integral(f, target, upper, *, rtol=1e-14, values=None, degree=CHEBYSHEV_DEGREE, method="clenshaw"):
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

    ``method`` says how the root is found on the interpolant (the same root, to rounding; the
    caller picks one, so a point's bits never depend on its batch):

    * ``"clenshaw"``: from the cubic Hermite interpolant between the nodes that bracket it,
      then Newton's method with the interpolant evaluated by Clenshaw's recurrence: three
      array operations per coefficient, each over the batch (the fewest operations per point,
      for large batches);
    * ``"barycentric"``: from the interpolant of the inverse, :math:`t(J)` through the nodes'
      :math:`(J_i, t_i)`, then Newton's method with the antiderivative (degree :math:`n + 1`,
      through the nodes and one point more) and the integrand evaluated by the barycentric
      formula (Berrut & Trefethen, *SIAM Review* 46, 2004): a handful of array operations
      over ``(points, nodes)`` and ``(points, nodes, nodes)`` (the fewest operations, for
      one point or a few).

    Returns ``(x, solved, short)``, flat arrays of the targets' size: ``x`` is meaningful only
    where ``solved``; ``short`` marks the points whose integral over ``[0, X]`` falls short of
    the target (the caller may try a longer interval).
    """
    rule = lobatto_rule(degree)
    barycentric = method == "barycentric"
    matrix = _barycentric_rule(degree)[0] if barycentric else rule.matrix
    target = np.asarray(target, dtype=float).ravel()
    upper = np.asarray(upper, dtype=float)
    if upper.shape != target.shape:
        upper = np.broadcast_to(upper, target.shape)
    if values is None:
        nodes = rule.nodes[:, None] * upper
        values = f(nodes, np.arange(target.size))
    y = np.asarray(values, dtype=float)
    half = 0.5 * upper
    with np.errstate(invalid="ignore", over="ignore"):
        maps = blocked_matmul(matrix, y)                 # rows contiguous, for the recurrences
        if barycentric:          # (the tail, then the antiderivative at the nodes and at s_*)
            tail_rows, known = maps[:3], maps[3:]
            known *= half                                # dx = (X/2) dt
            cumulative = known[:-1]
        else:
            coef, anti, cumulative = maps[rule.coef], maps[rule.anti], maps[rule.cumulative]
            tail_rows = coef[-3:]
            anti *= half
            cumulative *= half
        tail = np.abs(tail_rows).sum(axis=0) * upper
        # every value positive: one reduction over the whole batch (NaN fails it), the per-point
        # minimum (a strided reduction, ten times dearer) only where that fails
        positive = True if y.min() > 0 else np.min(y, axis=0) > 0
        usable = positive & np.isfinite(tail) & (target > 0)   # a nan or inf in y reaches the tail
        short = usable & (cumulative[-1] < target)
        good = usable & ~short & (tail <= rtol * target)
    x = np.zeros(target.size)
    live = np.nonzero(good)[0]
    if live.size == 0:
        return x, good, short
    h, t_goal = half, target
    if live.size < target.size:
        h, t_goal, y = half[live], target[live], y[:, live]
        if barycentric:
            known = known[:, live]
        else:
            coef, anti, cumulative = coef[:, live], anti[:, live], cumulative[:, live]
    if barycentric:
        t, moving = _root_barycentric(degree, known, y, h, t_goal)
        good[live[moving]] = False
        x[live] = h * (1.0 + t)
        return x, good, short
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


def _root_barycentric(degree, known, y, h, goal):
    r"""``(t, unconverged)``: the root :math:`t \in [-1, 1]` of :math:`J(t) =` ``goal``, where
    :math:`J` is the antiderivative of the interpolant of ``y`` (``(nodes, P)``), ``known`` at the
    nodes and at :math:`s_*` (``(nodes + 1, P)``), with :math:`J' = h\,p`
    (:func:`solve_integral`, ``method="barycentric"``). The points along the first axis and
    the nodes along the last, contiguous one: a sum over the nodes is taken in the same order
    whatever the number of points."""
    _, nodes, weights, lobatto = _barycentric_rule(degree)
    rule = lobatto_rule(degree)
    values_j = np.ascontiguousarray(known.T)                                        # (P, n + 2)
    values_f = np.ascontiguousarray(y.T)                                            # (P, n + 1)
    j_nodes = values_j[:, :-1]
    # the start: t(J) through (J_i, t_i), by the linear rational interpolant with the Lobatto
    # nodes' weights at the J_i, their image under a smooth increasing map (f > 0); its error
    # falls exponentially with the degree (Baltensperger, Berrut & Noël, Math. Comp. 68, 1999):
    # a start, which Newton's method checks
    with np.errstate(all="ignore"):
        t = np.fmin(np.fmax(barycentric(lobatto, goal[:, None] - j_nodes, rule.t), -1.0), 1.0)   # (a NaN: -1)
        # Newton on the interpolant: quadratic, so a step below 1e-9 leaves an error of order
        # (f'/f) 1e-18 after it, and is the last one
        moving = np.ones(goal.size, dtype=bool)
        for _ in range(8):
            offsets = t[:, None] - nodes
            integral = barycentric(weights, offsets, values_j)
            integrand = barycentric(lobatto, offsets[:, :-1], values_f)
            on_node = offsets[:, :-1] == 0.0
            if on_node.any():               # (the formula's 0/0: the node's own values)
                integral = at_nodes(on_node, integral, j_nodes)
                integrand = at_nodes(on_node, integrand, values_f)
            step = np.where(moving, (integral - goal) / (integrand * h), 0.0)
            t = np.fmin(np.fmax(t - step, -1.0), 1.0)
            moving &= ~(np.abs(step) <= 1e-9)
            if not moving.any():
                break
    return t, moving
