"""Safeguarded Newton iterations on many points at once (increasing functions, either sign).

Each point iterates on its own: converged points drop out, and a point's iterations do not
depend on its neighbours'. ``F(x, index)`` and ``dF(x, index)`` take the positions ``index`` of the
points still iterating, so a caller gathers per-point parameters with them.
"""

from __future__ import annotations

import numpy as np

from ..errors import ConvergenceError
from .kernels import EPS

__all__ = ["solve_increasing", "solve_signed"]

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
