"""Small vectorized kernels shared by models, couplers and the rest of the numerics layer.

Everything here works on whole arrays at once: no Python loop runs per point.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["EPS", "gauss_legendre", "expm1_ratio", "log1p_ratio", "as_output", "rows_dot", "blocked_matmul"]

EPS = float(np.finfo(float).eps)


@functools.lru_cache(maxsize=32)
def gauss_legendre(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [0, 1] (read-only arrays)."""
    x, w = np.polynomial.legendre.leggauss(order)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


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


def as_output(value, scalar: bool):
    """A Python float for a scalar result, else an ndarray."""
    if type(value) is float:
        return value if scalar else np.asarray(value)
    a = np.asarray(value, dtype=float)
    if scalar and a.size == 1:
        return float(a.reshape(()))
    return a


def rows_dot(y, w):
    """``y @ w`` for ``y`` of shape ``(P, m)`` and ``w`` of shape ``(m,)`` or ``(m, r)``, by
    :func:`numpy.einsum` (its own loops, not BLAS: a row's sum is taken in the same order
    whatever the number of rows, and small products pay no BLAS threading)."""
    return np.einsum("pm,m->p" if np.ndim(w) == 1 else "pm,mr->pr", y, w)


#: Columns per BLAS call in :func:`blocked_matmul`: fixed (a point's bits must not depend on its
#: batch), and narrow, because a single point pays for a whole padded block (64 columns: a one-point
#: product of the flow map ~3x cheaper than with 256, and large batches no slower).
_BLOCK = 64


def blocked_matmul(a, b):
    """``a @ b`` (``a`` of shape ``(r, m)``, ``b`` of shape ``(m, P)``) by BLAS on blocks of exactly
    ``_BLOCK`` (64) columns (the last one padded with zeros). Why: OpenBLAS picks its kernel by the problem's
    shape and the CPU, so a column's sum could be taken in another order in a batch of another size
    (a point solved in a batch of three differed in its last bit from the same point alone, on an
    AVX-512 machine); one problem shape for every column makes a point's result independent of its
    batch. Small blocks also stay below OpenBLAS's threading threshold."""
    rows, size = a.shape[0], b.shape[1]
    block = np.zeros((b.shape[0], _BLOCK))
    if size <= _BLOCK:                        # (one block: its product's first columns)
        block[:, :size] = b
        return (a @ block)[:, :size]
    out = np.empty((rows, size))
    for start in range(0, size, _BLOCK):
        count = min(_BLOCK, size - start)
        block[:, :count] = b[:, start:start + count]
        if count < _BLOCK:
            block[:, count:] = 0.0
        out[:, start:start + count] = (a @ block)[:, :count]
    return out
