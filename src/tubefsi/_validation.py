"""Input checks of the public functions: arrays and scalars that raise InvalidParameterError.

Model parameters are declared with :mod:`tubefsi.fields`; these check the loads and the
other arguments of the entry points.
"""

from __future__ import annotations

import math

import numpy as np

from ._units import to_si
from .errors import InvalidParameterError


def real_array(name, value, admissible):
    """``value`` as a float array: a real number or an array of them. Booleans, strings, complex
    numbers, ``None`` and other objects raise :class:`InvalidParameterError` (NumPy would turn
    ``"1"`` into 1.0, ``True`` into 1.0 and drop an imaginary part). A pint Quantity is converted
    to its SI magnitude first."""
    value = to_si(name, value)
    if isinstance(value, (bool, np.bool_, str, bytes)) or value is None:
        raise InvalidParameterError(name, admissible, value, "give a real number (SI units) or an array of them")
    if type(value) is float or type(value) is int:
        return np.asarray(float(value))
    try:
        a = np.asarray(value)
    except Exception:
        raise InvalidParameterError(name, admissible, value) from None
    if a.dtype.kind not in "iuf":
        raise InvalidParameterError(name, admissible, value if a.ndim == 0 else f"an array of {a.dtype}",
                                    "give a real number (SI units) or an array of them")
    return a.astype(float, copy=False)


def as_load(name, value, *, allow_zero=True):
    """Convert a flow rate / pressure to a float array; reject negative, NaN, inf."""
    a = real_array(name, value, "[0, inf)")
    low = a.min() if a.size else None
    if a.size and (low > 0 or (allow_zero and low == 0)) and a.max() < math.inf:
        return a                             # two reductions (a NaN fails both) instead of four passes
    bad = ~np.isfinite(a) | (a < 0) | ((a == 0) if not allow_zero else False)
    if np.any(bad):
        first = a[bad].flat[0] if a.ndim else a.item()
        where = "" if a.ndim == 0 else f" at index {tuple(int(i) for i in np.argwhere(bad)[0])}"
        raise InvalidParameterError(name, "[0, inf)" if allow_zero else "(0, inf)", first,
                                    f"invalid entry{where}" if where else "")
    return a


def as_array(name, value, admissible, predicate):
    """Convert to a float array and check ``predicate`` elementwise."""
    a = real_array(name, value, admissible)
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(a) & predicate(a)
    if not np.all(ok):
        bad = a[~ok].flat[0] if a.ndim else a.item()
        raise InvalidParameterError(name, admissible, bad)
    return a


def positive_scalar(name, value) -> float:
    """A finite float ``> 0``."""
    a = real_array(name, value, "(0, inf)")
    if a.ndim:
        raise InvalidParameterError(name, "(0, inf)", value, "a single number")
    v = float(a)
    if not (math.isfinite(v) and v > 0):
        raise InvalidParameterError(name, "(0, inf)", v)
    return v


def nonnegative_array(name, value):
    """A float array of finite entries ``>= 0``."""
    a = real_array(name, value, "[0, inf)")
    if not np.all(np.isfinite(a) & (a >= 0)):
        raise InvalidParameterError(name, "[0, inf)", a[~(np.isfinite(a) & (a >= 0))].flat[0]
                                    if a.ndim else a.item())
    return a
