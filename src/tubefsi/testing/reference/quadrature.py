"""Quadrature helpers of the references: geometric break points and a fixed Gauss–Legendre rule.

Written with mpmath alone, at the caller's ``mp.dps``.
"""

from __future__ import annotations

import functools

from mpmath import mp, mpf

__all__ = ["geometric_breaks", "gauss_legendre_rule", "gauss_legendre"]


def geometric_breaks(lo, hi, ratio=2):
    """``lo = x_0 < x_1 < ... = hi`` with ``x_{k+1} <= ratio * x_k`` (``lo > 0``): sub-intervals
    for ``mpmath.quad`` over a range spanning decades (e.g. ``[1, lam]`` at a large stretch)."""
    pts = [lo]
    while pts[-1] * ratio < hi:
        pts.append(pts[-1] * ratio)
    pts.append(hi)
    return pts


@functools.lru_cache(maxsize=None)
def _gl(m: int, dps: int):
    with mp.workdps(dps + 10):
        nodes, weights = [], []
        for k in range(1, m + 1):
            x = mp.cos(mp.pi * (k - mpf(1) / 4) / (m + mpf(1) / 2))
            for _ in range(100):                     # Newton on P_m
                p0, p1 = mpf(1), x
                for j in range(2, m + 1):
                    p0, p1 = p1, ((2 * j - 1) * x * p1 - (j - 1) * p0) / j
                dp = m * (x * p1 - p0) / (x * x - 1)
                dx = p1 / dp
                x -= dx
                if abs(dx) < mpf(10) ** (-(dps + 8)):
                    break
            nodes.append(x)
            weights.append(2 / ((1 - x * x) * dp * dp))
    return tuple(nodes), tuple(weights)


def gauss_legendre_rule(m: int = 24):
    """(nodes, weights) of the ``m``-point Gauss–Legendre rule on [-1, 1], at the current
    precision (computed once per ``(m, mp.dps)``, 10 guard digits)."""
    return _gl(m, mp.dps)


def gauss_legendre(f, a, b, m=24):
    """``∫_a^b f`` by the ``m``-point Gauss–Legendre rule (nodes at the current precision)."""
    nodes, weights = _gl(m, mp.dps)
    c, h = (a + b) / 2, (b - a) / 2
    return h * mp.fsum(w * f(c + h * x) for x, w in zip(nodes, weights))


def tanh_sinh(levels: int = 6):
    """Fixed tanh-sinh (double-exponential) nodes and weights on [0, 1] in double precision: exact to
    ~1e-15 even with algebraic endpoint singularities such as t**(1/n) (a reference rule for the
    contract suites, independent of the library's adaptive quadrature)."""
    import numpy as np

    h = 2.0**-levels * 8
    k = np.arange(-int(3.2 / h) - 1, int(3.2 / h) + 2)
    x = 0.5 * np.pi * np.sinh(k * h)
    t = 0.5 * (1.0 + np.tanh(x))
    w = h * 0.5 * np.pi * np.cosh(k * h) / (2.0 * np.cosh(x) ** 2)
    keep = (t > 0) & (t < 1) & (w > 1e-300)
    return t[keep], w[keep]
