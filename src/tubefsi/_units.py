"""pint.Quantity arguments, converted to SI at the boundary (the optional extra ``tubefsi[units]``).

tubefsi computes in SI numbers. A :class:`pint.Quantity` given where a number is expected — a
model parameter declared with :mod:`tubefsi.fields`, a ``Tube`` field, a load, the outlet
pressure, a density — is converted to its SI magnitude (``to_base_units``) after its dimension
is checked against the parameter's unit; pint is never imported unless such a value arrives.
"""

from __future__ import annotations

from .errors import InvalidParameterError

__all__ = ["is_quantity", "to_si", "LOAD_UNITS"]

#: Units of the arguments of the entry points that are not model fields.
LOAD_UNITS = {"flow_rate": "m^3/s", "pressure_drop": "Pa", "outlet_pressure": "Pa", "density": "kg/m^3",
              "z": "m", "r": "m"}


def is_quantity(value) -> bool:
    """True for a pint Quantity (by its type's module: no import of pint)."""
    return type(value).__module__.partition(".")[0] == "pint" and hasattr(value, "to_base_units")


def to_si(name: str, value, unit: str = ""):
    """``value`` unchanged unless it is a pint Quantity: then its SI magnitude, after checking
    its dimension against ``unit`` (a unit pint cannot parse, such as ``Pa s^n``, is not checked)."""
    if not is_quantity(value):
        return value
    unit = unit or LOAD_UNITS.get(name, "")
    expected = None
    if unit:
        try:
            expected = value._REGISTRY.parse_expression("dimensionless" if unit == "-" else unit)
        except Exception:          # a unit that depends on another parameter: no check
            expected = None
    if expected is not None and value.dimensionality != expected.dimensionality:
        raise InvalidParameterError(name, f"a quantity in {unit}", f"{value:~}")
    return value.to_base_units().magnitude
