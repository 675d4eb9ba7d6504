"""Validated coupler options: a bad option raises :class:`~tubefsi.InvalidParameterError` when the
coupler is made (``docs/verification.md``, "Fuzzing"), never a NaN tolerance taken at its word
or a ``MemoryError`` from a quadrature order of a million."""

from __future__ import annotations

import numbers

import attrs

from ..errors import InvalidParameterError
from ..fields import _convert_real, _interval_validator, real


def integer(low, high, *, default, optional=False, doc=""):
    """An integer option in ``[low, high]`` (``None`` too if ``optional``)."""
    admissible = f"the integers in [{low}, {high}]" + (" or None" if optional else "")

    def convert(value, field):
        if value is None and optional:
            return None
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            else:
                raise InvalidParameterError(field.name, admissible, value)
        value = int(value)
        if not low <= value <= high:
            raise InvalidParameterError(field.name, admissible, value)
        return value

    return attrs.field(default=default, converter=attrs.Converter(convert, takes_field=True),
                       metadata={"unit": "", "doc": doc, "admissible": admissible})


def flag(*, default, doc=""):
    """A boolean option (``True`` or ``False``, nothing else)."""
    def check(instance, attribute, value):
        if not isinstance(value, bool):
            raise InvalidParameterError(attribute.name, "True or False", value)

    return attrs.field(default=default, validator=check, metadata={"unit": "", "doc": doc, "admissible": "{True, False}"})


def tolerance(low, high, *, default, optional=False, doc=""):
    """A tolerance in ``(low, high]`` (``None`` too if ``optional``: the method's own default)."""
    if not optional:
        return real(low=low, high=high, high_open=False, doc=doc, default=default, along=False, array=False)
    admissible = f"({low:g}, {high:g}] or None"
    check = _interval_validator(low, high, True, False, admissible)

    def convert(value, field):
        return None if value is None else _convert_real(value, field)

    def optional_check(instance, attribute, value):
        if value is not None:
            if not isinstance(value, float):
                raise InvalidParameterError(attribute.name, admissible, value, "a single number")
            check(instance, attribute, value)

    return attrs.field(default=default, converter=attrs.Converter(convert, takes_field=True),
                       validator=optional_check, metadata={"unit": "", "doc": doc, "admissible": admissible})


__all__ = ["integer", "flag", "tolerance"]
