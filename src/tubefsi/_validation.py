"""Input checks of the public functions: arrays and scalars that raise InvalidParameterError.

Model parameters are declared with :mod:`tubefsi.fields`; these check the loads and the
other arguments of the entry points.
"""

from __future__ import annotations

import math

import numpy as np

from ._units import to_si
from .errors import InvalidParameterError


def as_load(name, value, *, allow_zero=True):
    """Convert a flow rate / pressure to a float array; reject negative, NaN, inf."""
    value = to_si(name, value)
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, "[0, inf)", value) from None
    bad = ~np.isfinite(a) | (a < 0) | ((a == 0) if not allow_zero else False)
    if np.any(bad):
        first = a[bad].flat[0] if a.ndim else a.item()
        where = "" if a.ndim == 0 else f" at index {tuple(int(i) for i in np.argwhere(bad)[0])}"
        raise InvalidParameterError(name, "[0, inf)" if allow_zero else "(0, inf)", first,
                                    f"invalid entry{where}" if where else "")
    return a


def as_array(name, value, admissible, predicate):
    """Convert to a float array and check ``predicate`` elementwise."""
    value = to_si(name, value)
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, admissible, value) from None
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(a) & predicate(a)
    if not np.all(ok):
        bad = a[~ok].flat[0] if a.ndim else a.item()
        raise InvalidParameterError(name, admissible, bad)
    return a


def positive_scalar(name, value) -> float:
    """A finite float ``> 0``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, "(0, inf)", value) from None
    if not (math.isfinite(v) and v > 0):
        raise InvalidParameterError(name, "(0, inf)", v)
    return v


def nonnegative_array(name, value):
    """A float array of finite entries ``>= 0``."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, "[0, inf)", value) from None
    if not np.all(np.isfinite(a) & (a >= 0)):
        raise InvalidParameterError(name, "[0, inf)", a[~(np.isfinite(a) & (a >= 0))].flat[0]
                                    if a.ndim else a.item())
    return a
