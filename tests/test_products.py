"""tubefsi._products: matrix products whose rows (columns) do not depend on their batch.

References: the same row (column) computed alone; and NumPy's BLAS product, which they must
equal to rounding (a relative 1e-14 of the sum of magnitudes)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tubefsi._products import fixed_width_product, rows_dot
from tubefsi.testing.profiles import scaled


@settings(deadline=None, max_examples=scaled(60))
@given(size=st.integers(1, 300), start=st.integers(0, 299), m=st.sampled_from([4, 17, 21, 23]),
       r=st.sampled_from([None, 2, 4]), seed=st.integers(0, 2**32 - 1))
def test_rows_dot_is_batch_independent_and_correct(size, start, m, r, seed):
    rng = np.random.default_rng(seed)
    y = rng.standard_normal((300, m)) * 10.0 ** rng.uniform(-3, 3, (300, 1))
    w = rng.standard_normal(m if r is None else (m, r))
    start = min(start, 300 - size)
    whole = rows_dot(y, w)
    part = rows_dot(y[start:start + size], w)
    assert np.array_equal(part, whole[start:start + size])
    alone = rows_dot(y[start:start + 1], w)
    assert np.array_equal(alone[0], whole[start])
    bound = 1e-14 * (np.abs(y) @ np.abs(w))
    assert np.all(np.abs(whole - y @ w) <= bound)


@settings(deadline=None, max_examples=scaled(60))
@given(size=st.integers(1, 700), start=st.integers(0, 699), width=st.sampled_from([16, 256]),
       seed=st.integers(0, 2**32 - 1))
def test_fixed_width_product_is_batch_independent_and_correct(size, start, width, seed):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((52, 17))
    b = rng.standard_normal((700, 17)).T                   # a transposed view (any strides are accepted)
    start = min(start, 700 - size)
    whole = fixed_width_product(a, b, width=width)
    part = fixed_width_product(a, b[:, start:start + size], width=width)
    assert np.array_equal(part, whole[:, start:start + size])
    assert np.array_equal(fixed_width_product(a, b[:, start:start + 1], width=width)[:, 0], whole[:, start])
    out = np.empty((52, size))
    assert fixed_width_product(a, b[:, start:start + size], out=out, width=width) is out
    assert np.all(np.abs(whole - a @ b) <= 1e-14 * (np.abs(a) @ np.abs(b)))
