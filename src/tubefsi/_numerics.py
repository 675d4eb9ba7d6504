"""Vectorized numerical kernels shared by models and couplers.

Everything here works on whole arrays at once: no Python loop runs per point.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ._products import rows_dot
from .errors import ConvergenceError

EPS = np.finfo(float).eps


@functools.cache
def gauss_legendre(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(order)
    return 0.5 * (x + 1.0), 0.5 * w


def expm1_ratio(k, x):
    r"""Stable :math:`(e^{k x} - 1)/k`, equal to ``x`` at ``k = 0`` (``k`` a float or an array).

    This is :math:`\int_0^x e^{k u}\,du`; the removable singularity at ``k = 0``
    (n = 2/3 for thin reference walls, n = 1 for thin current walls) is taken
    exactly, and ``expm1`` keeps full relative accuracy for small ``k x``.
    """
    x = np.asarray(x, dtype=float)
    if np.ndim(k) == 0:
        with np.errstate(over="ignore"):    # beyond double range: inf, refused by the callers' checks
            return x * 1.0 if k == 0.0 else np.expm1(k * x) / k
    k = np.asarray(k, dtype=float)
    zero = k == 0.0
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(zero, x, np.expm1(k * x) / np.where(zero, 1.0, k))


def log1p_ratio(k, y):
    r"""Inverse of :func:`expm1_ratio` in ``x``: :math:`\ln(1 + k y)/k`, ``y`` at ``k = 0``.

    Returns ``inf`` where :math:`1 + k y \le 0` (the integral never reaches ``y``).
    """
    y = np.asarray(y, dtype=float)
    k = np.asarray(k, dtype=float)
    if k.ndim == 0 and k == 0.0:
        return y * 1.0
    arg = k * y
    zero = k == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(arg > -1.0, np.log1p(np.maximum(arg, -1.0)) / np.where(zero, 1.0, k), np.inf)
        return np.where(zero, y, out)


def integrate_panels(f, upper, *, order=16, panel_width=2.0):
    r"""``∫_0^upper f(u) du`` for each entry of ``upper`` (>= 0), by composite Gauss–Legendre.

    ``f(u)`` receives an array of shape ``(k, m)`` for ``k`` of the points and must
    broadcast per-point parameters along the last axis; a point's panels have width
    at most ``panel_width``. Points are grouped by panel count so each group is one
    array operation; intervals shorter than a quarter panel use half the order
    (their integrands are analytic in a strip four times wider, relatively).
    """
    upper = np.asarray(upper, dtype=float)
    flat = upper.ravel()
    out = np.zeros(flat.shape)
    if flat.size == 0:
        return out.reshape(upper.shape)
    panels = np.maximum(1, np.ceil(flat / panel_width)).astype(int)
    short = flat <= 0.25 * panel_width
    groups = np.where(short, 0, panels)
    for g in np.unique(groups):
        idx = np.flatnonzero(groups == g)
        count, m = (1, max(order // 2, 4)) if g == 0 else (int(g), order)
        x, w = gauss_legendre(m)
        t = ((np.arange(count)[:, None] + x[None, :]) / count).ravel()
        wt = np.tile(w, count) / count
        u = flat[idx, None] * t
        out[idx] = flat[idx] * rows_dot(f(u, idx), wt)
    return out.reshape(upper.shape)


def _panels_and_slope(f, upper, width, idx, order):
    """Composite Gauss–Legendre of ``f`` on [0, upper_i] with panels of width <= width_i (as in
    :func:`integrate_panels`), and, per point, ``kappa h / m``: the largest |d ln|f|/du| across a
    panel times the panel width, over what ``m`` nodes resolve."""
    out = np.zeros(upper.shape)
    load = np.zeros(upper.shape)
    panels = np.maximum(1, np.ceil(upper / width)).astype(int)
    groups = np.where(upper <= 0.25 * width, 0, panels)
    for g in np.unique(groups):
        sel = np.flatnonzero(groups == g)
        count, m = (1, max(order // 2, 4)) if g == 0 else (int(g), order)
        x, w = gauss_legendre(m)
        t = ((np.arange(count)[:, None] + x[None, :]) / count).ravel()
        wt = np.tile(w, count) / count
        u = upper[sel, None] * t
        values = f(u, idx[sel])
        out[sel] = upper[sel] * rows_dot(values, wt)
        # log-slope across each panel from its first and last nodes (exact for an exponential):
        # e^(kappa u) on a panel of width h is integrated to full precision for kappa h <= m
        # (m >= 12; 0.6 m below), i.e. for |ln(last / first)| <= c = (x_m - x_1) m
        panel = values.reshape(len(sel), count, m)
        first, last = np.abs(panel[..., 0]), np.abs(panel[..., -1])
        c = (x[-1] - x[0]) * (m if m >= 12 else 0.6 * m)
        # only where the integrand matters: not across a zero, nor where it is < 1e-3 of its peak
        small = np.minimum(first, last)
        big = small >= 1e-3 * np.maximum(first.max(axis=-1), last.max(axis=-1))[:, None]
        steep = big & (np.maximum(first, last) > math.exp(c) * small)
        rows = np.flatnonzero(steep.any(axis=-1))
        if rows.size:
            with np.errstate(all="ignore"):
                ratio = np.abs(np.log(last[rows] / first[rows])) / c
            load[sel[rows]] = np.max(np.where(steep[rows] & np.isfinite(ratio), ratio, 0.0), axis=-1)
    return out, load


def integrate_fitted(f, upper, *, order=16, panel_width=2.0):
    r""":func:`integrate_panels`, with each point's panels narrowed until :math:`\kappa h \le m`,
    :math:`\kappa` the largest :math:`|d\ln f/du|` across a panel (from its end nodes).

    Gauss–Legendre with ``m`` nodes integrates :math:`e^{\kappa u}` to full precision on panels
    with :math:`\kappa h \le m`; this keeps an integrand that grows exponentially or faster
    (a strain-stiffening wall, e.g. Fung) as accurate as a slowly varying one. Where the first
    pass already satisfies it (every built-in pair) the result is exactly that of
    :func:`integrate_panels`, at no extra cost.
    """
    upper = np.asarray(upper, dtype=float)
    flat = upper.ravel()
    width = np.full(flat.shape, float(panel_width))
    out = np.zeros(flat.shape)
    todo = np.arange(flat.size)
    for _ in range(12):
        value, load = _panels_and_slope(f, flat[todo], width[todo], todo, order)
        out[todo] = value
        count = np.maximum(1, np.ceil(flat[todo] / width[todo]))
        h = flat[todo] / count                                                  # the panel width used
        coarse = (load > 1.0) & (count < 1e4)                                   # at most 1e4 panels
        if not np.any(coarse):
            break
        width[todo[coarse]] = 0.9 * h[coarse] / load[coarse]
        todo = todo[coarse]
    return out.reshape(upper.shape)


def integrate_graded(f, upper, pole, *, gap=None, reach=1.0, order=16, panel_width=2.0):
    r"""``∫_0^upper f(u) du`` like :func:`integrate_fitted`, for an integrand that may be
    singular at ``u = pole`` (``> upper``; scalar or one per point, ``inf`` for none).

    The part within ``reach`` of the pole is integrated in :math:`t = \ln(\text{pole} - u)` on
    panels of unit width, i.e. on panels in ``u`` graded geometrically toward the pole, each
    about as wide as its distance to the pole: a pole or a logarithmic singularity there costs
    one panel per factor e of approach, at full accuracy. ``gap`` (default ``pole - upper``)
    lets the caller pass the distance to the pole without cancellation.
    """
    upper = np.asarray(upper, dtype=float)
    flat = upper.ravel()
    pole = np.broadcast_to(np.asarray(pole, dtype=float), upper.shape).ravel()
    if not np.any(np.isfinite(pole)):
        return integrate_fitted(f, upper, order=order, panel_width=panel_width)
    split = np.where(np.isfinite(pole), np.maximum(pole - reach, 0.0), np.inf)
    out = integrate_fitted(f, np.minimum(flat, split), order=order, panel_width=panel_width).ravel()
    near = np.flatnonzero(flat > split)
    if near.size:
        pn = pole[near]
        d = pn - flat[near] if gap is None else np.broadcast_to(np.asarray(gap, dtype=float),
                                                                 upper.shape).ravel()[near]
        d = np.maximum(d, pn * 4 * EPS)                        # distance of the upper end to the pole
        top = pn - split[near]

        def g(y, sub):                                         # u = pole - d e^y, du = -d e^y dy
            e = d[sub, None] * np.exp(y)
            return f(pn[sub, None] - e, near[sub]) * e

        out[near] += integrate_panels(g, np.log(top / d), order=order, panel_width=1.0)
    return out.reshape(upper.shape)


_SUBNORMAL_ULPS = 8 * float(np.finfo(float).smallest_subnormal)


def solve_increasing(F, dF, target, *, guess, upper=None, xmax=np.inf, maxiter=200,
                     rtol=4 * EPS, max_step=np.inf, log=False, evaluated=None, quadratic=None, pole=None):
    r"""Solve ``F(x) = target`` for increasing ``F`` with ``F(0) = 0``, elementwise.

    Safeguarded Newton: a bracket ``[lo, hi]`` is kept, Newton steps that leave
    it are replaced by bisection (or by doubling while no upper end is known).
    ``F`` and ``dF`` take ``(x, index)`` where ``index`` selects the entries still
    iterating, so converged points cost nothing. No step grows ``x`` by more than
    ``max_step``. With ``log=True`` Newton runs on ``ln F(x) = ln target``, which
    is close to linear both where ``F`` is linear and where it grows exponentially.

    Returns ``(x, ok)``; ``ok`` is False where no root exists below ``xmax``. ``evaluated`` (a
    boolean array of the target's size, optional) is set True where the returned ``x`` is the
    last point ``F`` was evaluated at (its residual met the tolerance there), or, with
    ``quadratic`` (a relative step, e.g. 1e-8), where the last Newton step from that point was
    below ``quadratic`` times ``x`` and times the distance to ``pole`` (optional, per entry: a
    singularity of ``F`` above the root, e.g. a locking stretch): Newton's error after a step
    ``d`` is ``|F''/2F'| d^2``, and ``F''/F'`` is of order ``1/x`` for ``ln J ~ ln x`` and
    ``1/(pole - x)`` near a pole, so the error is then ~1e-16 relative to both; the step is
    taken as the last one, and the evaluation it came from (that close) stands for the answer's.
    """
    target = np.asarray(target, dtype=float)
    shape = target.shape
    target = target.ravel()
    n = target.size
    x = np.broadcast_to(np.asarray(guess, dtype=float), shape).ravel().copy()
    lo = np.zeros(n)
    hi = np.full(n, np.inf) if upper is None else np.broadcast_to(
        np.asarray(upper, dtype=float), shape).ravel().copy()
    x = np.clip(x, lo, np.where(np.isfinite(hi), hi, np.inf))
    ok = np.ones(n, dtype=bool)
    pole_flat = None if pole is None else np.broadcast_to(np.asarray(pole, dtype=float), shape).ravel()
    active = np.flatnonzero(target > 0)
    x[target == 0] = 0.0
    for _ in range(maxiter):
        if active.size == 0:
            break
        xa = x[active]
        fa = F(xa, active)
        r = fa - target[active]
        d = dF(xa, active)
        lo_a = np.where(r <= 0, xa, lo[active])
        hi_a = np.where(r >= 0, xa, hi[active])
        with np.errstate(divide="ignore", invalid="ignore"):
            if log:
                xn = xa - np.log(fa / target[active]) * fa / d
            else:
                xn = xa - r / d
        # Newton cannot move x (its step rounds away: a residual of a few ulps, e.g. at a root
        # below the normal doubles): x is the root as far as doubles resolve it, not a bad step
        stay = np.isfinite(xn) & (np.abs(xn - xa) <= _SUBNORMAL_ULPS)
        bad = ~np.isfinite(xn) | (xn <= lo_a) | (xn >= hi_a)
        bisect = np.where(np.isfinite(hi_a), 0.5 * (lo_a + hi_a),
                          np.minimum(np.maximum(2.0 * xa, xa + 1.0), xa + max_step))
        xn = np.minimum(xn, xa + max_step)
        xn = np.where(bad, bisect, xn)
        runaway = xn > xmax
        xn = np.where(runaway, xmax, xn)
        lo[active], hi[active] = lo_a, hi_a
        step = np.abs(xn - xa)
        # (a few ulps of the subnormals: a root below the normal doubles, e.g. the strain at a
        # subnormal pressure, is resolved only that far)
        done = ((np.abs(r) <= 8 * EPS * target[active]) | (step <= rtol * np.abs(xn) + _SUBNORMAL_ULPS)
                | (hi_a - lo_a <= rtol * np.abs(xn) + _SUBNORMAL_ULPS) | stay)
        stuck = runaway & (xa >= xmax)
        ok[active[stuck]] = False
        met = (np.abs(r) <= 8 * EPS * target[active]) | stay
        x[active] = np.where(met, xa, xn)
        last = met
        if quadratic is not None:
            scale = np.abs(xn) if pole is None else np.minimum(np.abs(xn), pole_flat[active] - xn)
            near = ~bad & ~runaway & (step <= quadratic * scale)
            done |= near
            last = met | near
        if evaluated is not None:
            evaluated.ravel()[active] = last
        active = active[~(done | stuck)]
    else:
        if active.size:
            raise ConvergenceError(f"Newton iteration did not converge for {active.size} points")
    return x.reshape(shape), ok.reshape(shape)


def as_output(value, scalar: bool):
    """Return a Python float for scalar input, else an ndarray."""
    if type(value) is float:
        return value if scalar else np.asarray(value)
    a = np.asarray(value, dtype=float)
    if scalar and a.ndim == 0:
        return float(a)
    if scalar and a.size == 1:
        return float(a.reshape(()))
    return a


def solve_signed(F, dF, target, *, guess, lower=None, upper=None, **kw):
    r""":func:`solve_increasing` for targets of either sign (``F`` increasing, ``F(0) = 0``).

    Positive targets are solved as they are; negative ones on the reflected problem
    :math:`-F(-x) = -\text{target}`, which is increasing with a root :math:`-x > 0`, below
    ``-lower`` (``lower``: the bound of the negative roots, e.g. a strain of -1). ``F`` and ``dF``
    take ``(x, index)`` as for :func:`solve_increasing`. Returns ``(x, ok)``.
    """
    target = np.asarray(target, dtype=float)
    shape = target.shape
    t = target.ravel()
    g = np.broadcast_to(np.asarray(guess, dtype=float), shape).ravel()
    neg = np.flatnonzero(t < 0)
    if neg.size == 0:
        return solve_increasing(F, dF, target, guess=guess, upper=upper, **kw)
    x, ok = np.zeros(t.size), np.ones(t.size, dtype=bool)
    pos = np.flatnonzero(t >= 0)
    if pos.size:
        up = None if upper is None else np.broadcast_to(np.asarray(upper, dtype=float), shape).ravel()[pos]
        x[pos], ok[pos] = solve_increasing(lambda y, i: F(y, pos[i]), lambda y, i: dF(y, pos[i]), t[pos],
                                           guess=g[pos], upper=up, **kw)
    low = None if lower is None else -np.broadcast_to(np.asarray(lower, dtype=float), shape).ravel()[neg]
    y, ok[neg] = solve_increasing(lambda y, i: -F(-y, neg[i]), lambda y, i: dF(-y, neg[i]), -t[neg],
                                  guess=np.abs(g[neg]) if low is None else np.minimum(np.abs(g[neg]), 0.5 * low),
                                  upper=low, **kw)
    x[neg] = -y
    return x.reshape(shape), ok.reshape(shape)
