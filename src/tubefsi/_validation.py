"""Input checks of the public functions: arrays and scalars that raise InvalidParameterError.

Model parameters are declared with :mod:`tubefsi.fields`; these check the loads and the
other arguments of the entry points.
"""

from __future__ import annotations

import decimal
import math
import numbers

import numpy as np

from ._units import to_si
from .errors import InvalidParameterError


#: The most dimensions an argument may have: NumPy's functions iterate over at most 32 (its arrays
#: may have 64), and broadcasting never adds dimensions, so arguments of at most 32 broadcast too.
MAX_DIMS = 32

#: The common real numbers: Python's ints and floats, NumPy's integer and float scalars.
_NUMBERS = (int, float, np.integer, np.floating)


def real_array(name, value, admissible):
    """``value`` as a float array: a real number or an array of them (any shape up to
    :data:`MAX_DIMS` dimensions, empty too). Booleans, strings, complex numbers, ``None``, dates and
    other objects raise :class:`InvalidParameterError` (NumPy would turn ``"1"`` into 1.0, ``True``
    into 1.0 and drop an imaginary part). A pint Quantity is converted to its SI magnitude first.

    A real number of another type (a Python int, a :class:`~fractions.Fraction`, a
    :class:`~decimal.Decimal`, ``np.longdouble``, or such entries of a list) is rounded to the
    nearest double, but one the doubles cannot hold at all raises: a nonzero number that would
    round to 0 or a finite one that would round to infinity is not silently answered as 0 or inf.
    A masked array is refused where it has masked entries (NumPy would hand over the data hidden
    under the mask); without any, it is its data."""
    value = to_si(name, value)
    if type(value) is float:
        return np.asarray(value)
    if isinstance(value, (bool, np.bool_, str, bytes)) or value is None:
        raise _not_a_number(name, admissible, value)
    if isinstance(value, _NUMBERS):          # (before the abstract classes below: cheaper)
        return np.asarray(_double(name, admissible, value))
    if isinstance(value, np.ma.MaskedArray):
        value = _unmasked(name, admissible, value)
    if isinstance(value, (numbers.Real, decimal.Decimal)):     # a Fraction, a Decimal, another Real
        return np.asarray(_double(name, admissible, value))
    try:
        a = np.asarray(value)
    except Exception:                          # ragged nested lists, objects that fail as arrays
        raise InvalidParameterError(name, admissible, None, f"a {type(value).__name__} that is no array of numbers "
                                    "(ragged nested lists?); give a real number (SI units) or an array of them") from None
    if a.ndim > MAX_DIMS:
        raise InvalidParameterError(name, admissible, None, f"an array of {a.ndim} dimensions; give arrays of at "
                                    f"most {MAX_DIMS} dimensions")
    if a.dtype.kind == "f" and a.dtype.itemsize > 8:         # np.longdouble: entries may leave the doubles
        return _doubles(name, admissible, a)
    if a.dtype.kind in "iuf":
        return a.astype(float, copy=False)
    if a.dtype.kind == "O":                  # a list mixing types, or holding ints beyond the doubles
        entries = [_entry(name, admissible, v, index) for index, v in np.ndenumerate(a)]
        return np.array(entries, dtype=float).reshape(a.shape)
    raise _not_a_number(name, admissible, value if a.ndim == 0 else f"an array of {a.dtype}")


def _not_a_number(name, admissible, value):
    return InvalidParameterError(name, admissible, value, "give a real number (SI units) or an array of them")


def _unmasked(name, admissible, value):
    """The data of a masked array without masked entries."""
    mask = np.ma.getmaskarray(value)
    if mask.any():
        where = f" (the first at index {tuple(int(i) for i in np.argwhere(mask)[0])})" if mask.ndim else ""
        raise InvalidParameterError(name, admissible, None, f"a masked array with masked entries{where}: give only "
                                    "the values to solve for (e.g. array.compressed())")
    return np.ma.getdata(value)


def _entry(name, admissible, value, index):
    """An entry of an object array (a list mixing types) as a float, checked as a scalar is."""
    where = f" at index {index}" if index else ""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, decimal.Decimal)):
        raise InvalidParameterError(name, admissible, None, f"got {type(value).__name__} {_shown(value)}{where}; "
                                    "give a real number (SI units) or an array of them")
    return _double(name, admissible, value, where)


_TO_ZERO = "rounds to 0 in double precision (the smallest nonzero double is 4.9e-324)"
_TO_INF = "is beyond double precision (the largest double is 1.8e308)"


def _double(name, admissible, value, where=""):
    """A real number as the nearest double; refused where the doubles cannot hold it at all."""
    try:
        x = float(value)
    except OverflowError:                    # a Python int or Fraction beyond 1.8e308
        x = math.inf
    except (TypeError, ValueError):          # a signalling Decimal NaN, an odd Real
        raise _not_a_number(name, admissible, value) from None
    if x == 0.0 and value != 0:
        raise _lost(name, admissible, value, where, _TO_ZERO)
    if math.isinf(x) and abs(value) < math.inf:
        raise _lost(name, admissible, value, where, _TO_INF)
    return x


def _doubles(name, admissible, a):
    """A ``np.longdouble`` array as doubles; refused where an entry cannot be held by them at all."""
    with np.errstate(over="ignore"):
        x = a.astype(float)
    lost = ((x == 0) & (a != 0)) | (np.isinf(x) & np.isfinite(a))
    if np.any(lost):
        index = tuple(int(i) for i in np.argwhere(lost)[0]) if a.ndim else ()
        raise _lost(name, admissible, a[index], f" at index {index}" if a.ndim else "",
                    _TO_ZERO if x[index] == 0 else _TO_INF)
    return x


def _lost(name, admissible, value, where, why):
    return InvalidParameterError(name, admissible, None, f"got {_shown(value)}{where}, which {why}: give values "
                                 "within double precision")


def _shown(value):
    """A short text of a number: an int or a Fraction of hundreds of digits as 1.000e+400."""
    if isinstance(value, numbers.Rational) and not isinstance(value, np.integer):
        return format(decimal.Decimal(value.numerator) / value.denominator, ".4g")
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


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


def as_scalar(name, value, admissible, predicate) -> float:
    """:func:`as_array` of one number: a float, or an error naming ``name`` for an array."""
    a = as_array(name, value, admissible, predicate)
    if a.ndim:
        raise InvalidParameterError(name, admissible, value, "a single number")
    return float(a)


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
