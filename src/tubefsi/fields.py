r"""Parameters of model classes: attrs fields with a unit, an admissible range and a description.

Every model in tubefsi — a wall law, a rheology, a coupler's options — is an
``attrs`` frozen, keyword-only class whose parameters are declared with these factories.
A model author writes, for a new material::

    import attrs
    from tubefsi import fields
    from tubefsi.walls import HyperelasticWall, ThickWall

    @attrs.frozen(kw_only=True)
    class Gent(HyperelasticWall):
        shear_modulus: float = fields.positive(unit="Pa", doc="small-strain shear modulus mu")
        locking_parameter: float = fields.positive(doc="J_m, the largest I1 - 3")

Each factory converts the value to a float and validates it: NaN, infinities, booleans,
strings and values outside the range raise :class:`~tubefsi.InvalidParameterError` naming
the parameter and its admissible range. The unit, the range and the description go into
the field's metadata, where ``tubefsi list`` and :func:`parameters` read them, so a plugin's
parameters are documented the same way as the built-ins'. A variant of a model is made with
:func:`attrs.evolve`, which validates again.

===================  ==============================================================
factory              admissible values
===================  ==============================================================
:func:`real`         an interval ``(low, high)``, open or closed at either end
:func:`positive`     ``(0, inf)``
:func:`nonnegative`  ``[0, inf)``
:func:`choice`       one of a fixed set of strings
===================  ==============================================================
"""

from __future__ import annotations

import math

import attrs

from .errors import InvalidParameterError

__all__ = ["real", "positive", "nonnegative", "choice", "Parameter", "parameters"]


def _convert_float(value, field):
    if isinstance(value, (bool, str)):
        raise InvalidParameterError(field.name, "the real numbers", value,
                                    "give a plain number in SI units")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(field.name, "the real numbers", value,
                                    "give a plain number in SI units") from None


_float_converter = attrs.Converter(_convert_float, takes_field=True)


def _fmt(x) -> str:
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return f"{x:g}"


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
    """A float parameter in the interval from ``low`` to ``high`` (open ends by default).

    NaN is always rejected, and an infinite value unless the interval is closed at infinity.
    ``unit`` is the SI unit as text (``"Pa"``, ``"Pa s^n"``, ``""`` for a number), ``doc`` a
    few words for ``tubefsi list``.
    """
    lo = "(" if low_open else "["
    hi = ")" if high_open else "]"
    admissible = f"{lo}{_fmt(low)}, {_fmt(high)}{hi}"
    return attrs.field(
        converter=_float_converter,
        validator=_interval_validator(low, high, low_open, high_open, admissible),
        metadata={"unit": unit, "doc": doc, "admissible": admissible,
                  "low": low, "high": high, "low_open": low_open, "high_open": high_open},
        default=default,
    )


def positive(*, unit="", doc="", default=attrs.NOTHING):
    """A finite float parameter that must be ``> 0``."""
    return real(low=0.0, unit=unit, doc=doc, default=default)


def nonnegative(*, unit="", doc="", default=attrs.NOTHING):
    """A finite float parameter that must be ``>= 0``."""
    return real(low=0.0, low_open=False, unit=unit, doc=doc, default=default)


def choice(options, *, doc="", default=attrs.NOTHING):
    """A string parameter restricted to ``options`` (a sequence of strings)."""
    options = tuple(options)
    admissible = "{" + ", ".join(repr(o) for o in options) + "}"

    def check(instance, attribute, value):
        if value not in options:
            raise InvalidParameterError(attribute.name, admissible, value)

    return attrs.field(validator=check, default=default,
                       metadata={"unit": "", "doc": doc, "admissible": admissible, "options": options})


@attrs.frozen
class Parameter:
    """One parameter of a model class, as :func:`parameters` reports it."""

    name: str
    unit: str           #: SI unit as text, ``""`` for a pure number
    admissible: str     #: the admissible range, e.g. ``"(0, inf)"``
    doc: str            #: a short description
    default: object     #: the default value, or ``attrs.NOTHING`` when the parameter is required

    @property
    def required(self) -> bool:
        """Whether the parameter has no default."""
        return self.default is attrs.NOTHING

    @property
    def positive(self) -> bool:
        """Whether the admissible range is ``(0, inf)`` (e.g. a modulus or a viscosity)."""
        return self.admissible == "(0, inf)"


def parameters(model) -> tuple[Parameter, ...]:
    """The parameters of a model class or instance, in declaration order.

    Fields declared without these factories are reported with the metadata they have
    (empty unit, range and description).
    """
    cls = model if isinstance(model, type) else type(model)
    if not attrs.has(cls):
        return ()
    return tuple(Parameter(name=f.name, unit=f.metadata.get("unit", ""),
                           admissible=f.metadata.get("admissible", ""), doc=f.metadata.get("doc", ""),
                           default=f.default)
                 for f in attrs.fields(cls) if f.init)
