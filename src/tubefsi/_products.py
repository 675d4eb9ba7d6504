r"""Matrix products whose rows (or columns) do not depend on the batch they came in.

tubefsi promises that a broadcast solve equals its scalar solves entry by entry, to the last bit
(``docs/contracts.md``). A BLAS product does not keep that promise on every machine: OpenBLAS
picks its kernels by the problem's shape and the CPU, and on some CPUs (seen on an AVX-512
Sapphire Rapids) the rows of ``y @ w`` for a ``(P, m)`` matrix, and the columns of ``A @ B`` for
an ``(m, P)`` one, are summed in an order that depends on ``P``: a point solved in a batch of
three then differed in its last bit from the same point alone. So every product over a batch of
points on a solver's path goes through these two functions:

* :func:`rows_dot`: ``y @ w`` by :func:`numpy.einsum` (its own loops, no BLAS): the order of a
  row's sum depends on ``m`` only. About twice the time of a BLAS matrix-vector product;
* :func:`fixed_width_product`: ``a @ b`` for a fixed matrix ``a`` and ``b`` of ``P`` columns, by
  BLAS on blocks of exactly ``width`` columns (the last one padded with zeros), so that every
  column goes through one problem shape, at the speed of BLAS.

:func:`scratch` hands out the reused buffers these products and the one-batch solve write into.
"""

from __future__ import annotations

import math
import threading

import numpy as np

__all__ = ["fixed_width_product", "rows_dot", "scratch"]

_SCRATCH = threading.local()


def scratch(name, shape):
    """An uninitialized float array of ``shape`` from this thread's scratch buffer ``name``, reused
    by every call (valid until the next call asks for the same name). Why: the arrays of a batch
    of 10^4 points are megabytes, which glibc allocates with mmap and unmaps on free, so that a
    fresh one costs a page fault per 4 KiB written (~1000 per batch, a quarter of a broadcast
    solve's time). A buffer grows to the largest batch seen (at most ``CHUNK`` points of a solve:
    7 MB)."""
    size = math.prod(shape)
    buffer = getattr(_SCRATCH, name, None)
    if buffer is None or buffer.size < size:
        buffer = np.empty(size)
        setattr(_SCRATCH, name, buffer)
    return buffer[:size].reshape(shape)


def rows_dot(y, w):
    """``y @ w`` for ``y`` of shape ``(P, m)`` and ``w`` of shape ``(m,)`` or ``(m, r)``, each row
    summed in an order that does not depend on ``P``."""
    return np.einsum("pm,m->p" if np.ndim(w) == 1 else "pm,mr->pr", y, w)


def fixed_width_product(a, b, *, out=None, width=256):
    """``a @ b`` (``a`` of shape ``(r, m)``, ``b`` of shape ``(m, P)``, any strides), computed on
    blocks of exactly ``width`` columns copied into one contiguous buffer (the last block padded
    with zeros): each column's result depends on that column alone. ``out``: an ``(r, P)`` array
    for the result. ``r m width`` should stay below OpenBLAS's threading threshold (~2.6e5)."""
    rows, size = a.shape[0], b.shape[1]
    out = np.empty((rows, size)) if out is None else out
    buffer = scratch("padded", (b.shape[0], width))
    for start in range(0, size, width):
        count = min(width, size - start)
        buffer[:, :count] = b[:, start:start + count]
        if count < width:
            buffer[:, count:] = 0.0
            out[:, start:start + count] = (a @ buffer)[:, :count]
        else:                           # a whole block: written in place (the same product, no copy)
            np.matmul(a, buffer, out=out[:, start:start + width])
    return out
