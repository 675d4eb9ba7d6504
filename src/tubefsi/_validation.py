"""attrs field factories and array checks that raise InvalidParameterError."""

from __future__ import annotations

import math

import attrs
import numpy as np

from .errors import InvalidParameterError


def _convert_float(value, field):
    if isinstance(value, (bool, str)):
        raise InvalidParameterError(field.name, "the real numbers", value)
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(field.name, "the real numbers", value) from None


_float_converter = attrs.Converter(_convert_float, takes_field=True)


def _interval_validator(low, high, low_open, high_open, admissible):
    def check(instance, attribute, value):
        ok = math.isfinite(value) or (value == math.inf and high == math.inf and not high_open)
        ok = ok and (value > low if low_open else value >= low)
        ok = ok and (value < high if high_open else value <= high)
        if not ok:
            raise InvalidParameterError(attribute.name, admissible, value)

    return check


def real(*, low=-math.inf, high=math.inf, low_open=True, high_open=True, unit="", doc="",
         default=attrs.NOTHING):
    """A float field validated to lie in an interval; NaN and infinities are rejected."""
    lo = "(" if low_open else "["
    hi = ")" if high_open else "]"
    admissible = f"{lo}{_fmt(low)}, {_fmt(high)}{hi}"
    return attrs.field(
        converter=_float_converter,
        validator=_interval_validator(low, high, low_open, high_open, admissible),
        metadata={"unit": unit, "doc": doc, "admissible": admissible},
        default=default,
    )


def positive(*, unit="", doc="", default=attrs.NOTHING):
    """A finite float field that must be > 0."""
    return real(low=0.0, unit=unit, doc=doc, default=default)


def choice(options, *, doc="", default=attrs.NOTHING):
    """A string field restricted to ``options``."""
    admissible = "{" + ", ".join(repr(o) for o in options) + "}"

    def check(instance, attribute, value):
        if value not in options:
            raise InvalidParameterError(attribute.name, admissible, value)

    return attrs.field(validator=check, default=default,
                       metadata={"unit": "", "doc": doc, "admissible": admissible})


def _fmt(x):
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return f"{x:g}"


def as_load(name, value, *, allow_zero=True):
    """Convert a flow rate / pressure to a float array; reject negative, NaN, inf."""
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
