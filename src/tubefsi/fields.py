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
the parameter and its admissible range. What counts as a number is one rule, shared with the
loads of :func:`~tubefsi.solve` (:func:`tubefsi._validation.real_array`): a real number of any type
is rounded to the nearest double but refused where the doubles cannot hold it (``10**400``,
``np.longdouble("1e-400")``); masked entries and arrays of more than 32 dimensions are refused;
an empty array is an empty set of points. The unit, the range and the description go into
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

import copy
import math

import attrs
import numpy as np

from ._units import is_quantity, to_si
from ._validation import real_array
from .errors import InvalidParameterError
from .numerics.cache import keep_on_class
from .profiles import Profile, as_profile

__all__ = ["real", "positive", "nonnegative", "choice", "Parameter", "parameters", "parameter_shape",
           "broadcast_model", "model_at", "parameter_sets", "evaluate", "flat_points", "take", "varies",
           "at_position"]


def _convert_real(value, field, instance=None):
    """A float for a scalar, a read-only float ndarray for an array (any shape), a
    :class:`~tubefsi.Profile` for a function of z; a pint Quantity is converted to SI first. What
    is a real number is :func:`~tubefsi._validation.real_array`'s rule, shared with the arguments
    of the entry points (the loads, the outlet pressure...)."""
    if type(value) is float:                 # the common case (a Monte Carlo loop builds models)
        return value
    if isinstance(value, float):             # a NumPy float64: a double already
        return float(value)
    value = to_si(field.name, value, field.metadata.get("unit", ""))
    if callable(value) and field.metadata.get("along") and not is_quantity(value):   # a function of z
        if instance is not None and not getattr(type(instance), "varies_along_z", True):
            raise InvalidParameterError(field.name, f"a number or an array ({type(instance).__name__}'s parameters "
                                        "do not vary along the tube)", value)
        return as_profile(value, field)
    a = real_array(field.name, value, field.metadata.get("admissible", "the real numbers"))
    if a.ndim == 0:
        return float(a)
    if not field.metadata.get("array", True):
        raise InvalidParameterError(field.name, field.metadata["admissible"], value, "a single number")
    a = np.array(a, dtype=float)            # a private copy: the model is immutable
    a.setflags(write=False)
    return a


def _convert_real_field(value, instance, field):
    """:func:`_convert_real` in the argument order of an attrs converter that takes the instance."""
    if type(value) is float:                 # the common case, without a second call
        return value
    return _convert_real(value, field, instance)


_real_converter = attrs.Converter(_convert_real_field, takes_self=True, takes_field=True)


def _fmt(x) -> str:
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return f"{x:g}"


def _interval_validator(low, high, low_open, high_open, admissible):
    # a float (the common case) is tested by one chained comparison, without numpy: a NaN fails
    # every comparison, inf passes only a closed infinite upper end, and -inf never passes (an
    # infinite lower end is open)
    low_open = low_open or low == -math.inf

    def general(attribute, value):
        if type(value) is float:
            raise InvalidParameterError(attribute.name, admissible, value)
        if isinstance(value, Profile):            # checked where it is evaluated
            return
        v = np.asarray(value)
        if v.size and v.dtype.kind == "f":
            # the extremes decide (two reductions; a NaN makes both fail): the elementwise test
            # below only to name the offending entry
            lo_v, hi_v = v.min(), v.max()
            if (low < lo_v if low_open else low <= lo_v) and (hi_v < high if high_open else hi_v <= high):
                return
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(v) | ((v == math.inf) & (high == math.inf) & (not high_open))
            ok &= (v > low) if low_open else (v >= low)
            ok &= (v < high) if high_open else (v <= high)
        if not np.all(ok):
            if v.ndim == 0:
                raise InvalidParameterError(attribute.name, admissible, float(v))
            where = tuple(int(i) for i in np.argwhere(~ok)[0])
            raise InvalidParameterError(attribute.name, admissible, float(v[where]),
                                        f"entry {where} of an array of shape {v.shape}")

    if low_open and high_open:
        def check(instance, attribute, value):
            if not (type(value) is float and low < value < high):
                general(attribute, value)
    elif low_open:
        def check(instance, attribute, value):
            if not (type(value) is float and low < value <= high):
                general(attribute, value)
    elif high_open:
        def check(instance, attribute, value):
            if not (type(value) is float and low <= value < high):
                general(attribute, value)
    else:
        def check(instance, attribute, value):
            if not (type(value) is float and low <= value <= high):
                general(attribute, value)
    return check


def _eq_key(value):
    """What a parameter compares and hashes by: a float itself, an array its shape and bytes (so
    that equal models hash alike and different ones, as a rule, do not: a model is a key of the
    flow-table cache), anything else (a profile along z) itself."""
    if type(value) is float:
        return value
    if isinstance(value, np.ndarray):
        return ("array", value.shape, value.tobytes())
    return value


def real(*, low=-math.inf, high=math.inf, low_open=True, high_open=True, unit="", doc="",
         default=attrs.NOTHING, along=True, array=True):
    """A real parameter in the interval from ``low`` to ``high`` (open ends by default).

    The value is a float, or an array of any shape (read-only, broadcast against the other
    parameters and the load by NumPy's rules, as :mod:`scipy.stats` broadcasts its shape
    parameters). NaN is always rejected, and an infinite value unless the interval is closed
    at infinity; an offending array entry is named by its index. ``unit`` is the SI unit as
    text (``"Pa"``, ``"Pa s^n"``, ``""`` for a number), ``doc`` a few words for
    ``tubefsi list``. With ``along`` (the default) the value may also be a function of the axial
    position z, a :class:`~tubefsi.Profile` (a graded tube, ``docs/graded.md``); options that are
    not properties of the tube pass ``along=False``, and options that are one setting, not a
    parameter of each point (a coupler's tolerance), ``array=False``: a single number.
    """
    lo = "(" if low_open else "["
    hi = ")" if high_open else "]"
    admissible = f"{lo}{_fmt(low)}, {_fmt(high)}{hi}"
    return attrs.field(
        converter=_real_converter,
        validator=_interval_validator(low, high, low_open, high_open, admissible),
        eq=_eq_key,
        metadata={"unit": unit, "doc": doc, "admissible": admissible, "array": array, "along": along,
                  "low": low, "high": high, "low_open": low_open, "high_open": high_open},
        default=default,
    )


def positive(*, unit="", doc="", default=attrs.NOTHING, along=True, array=True):
    """A finite float parameter that must be ``> 0``."""
    return real(low=0.0, unit=unit, doc=doc, default=default, along=along, array=array)


def nonnegative(*, unit="", doc="", default=attrs.NOTHING, along=True, array=True):
    """A finite float parameter that must be ``>= 0``."""
    return real(low=0.0, low_open=False, unit=unit, doc=doc, default=default, along=along, array=array)


def choice(options, *, doc="", default=attrs.NOTHING):
    """A string parameter restricted to ``options`` (a sequence of strings)."""
    options = tuple(options)
    admissible = "{" + ", ".join(repr(o) for o in options) + "}"

    def check(instance, attribute, value):
        # a string first: ``in`` would compare an array elementwise ("truth value ... ambiguous")
        if not (isinstance(value, str) and value in options):
            raise InvalidParameterError(attribute.name, admissible, value,
                                        "" if isinstance(value, str) else "give one of these strings")

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


# ------------------------------------------------------------------------- arrays of parameters
def _array_fields(cls) -> tuple[str, ...]:
    """The names of the fields of ``cls`` that may hold arrays (declared with :func:`real`), read
    off attrs' field list once and kept on the class
    (:func:`~tubefsi.numerics.cache.keep_on_class`)."""
    found = cls.__dict__.get("_tubefsi_array_fields")
    if found is not None:
        return found
    fields = getattr(cls, "__attrs_attrs__", None)
    return keep_on_class(cls, "_tubefsi_array_fields",
                         () if fields is None else tuple(f.name for f in fields if f.metadata.get("array")))


def parameter_shape(model) -> tuple[int, ...]:
    """The broadcast shape of a model's array parameters (``()`` when all are scalars)."""
    shapes = None
    for name in _array_fields(type(model)):
        value = getattr(model, name)
        if type(value) is not float:        # (a float, the common case, broadcasts with anything)
            shape = np.shape(value)
            if shape != ():
                shapes = [shape] if shapes is None else shapes + [shape]
    return () if shapes is None else np.broadcast_shapes(*shapes)


def _replace(model, values: dict):
    """A copy of ``model`` with some parameters replaced, bypassing validation (already done)."""
    new = copy.copy(model)
    for name, value in values.items():
        object.__setattr__(new, name, value)
    return new


def broadcast_model(model, shape):
    """``model`` with every array parameter broadcast to ``shape`` and flattened (1-D, aligned
    with the flat points of ``shape``); the model itself if all its parameters are scalars."""
    arrays = {name: v for name in _array_fields(type(model)) if isinstance(v := getattr(model, name), np.ndarray)}
    if not arrays:
        return model
    return _replace(model, {name: np.broadcast_to(v, shape).ravel() for name, v in arrays.items()})


def model_at(model, index, *, column=False):
    """``model`` with its flat (1-D) array parameters taken at ``index``, as a column (``(n, 1)``,
    to broadcast against ``(n, nodes)`` arguments) if ``column``; the model itself if scalar."""
    arrays = {name: v for name in _array_fields(type(model)) if isinstance(v := getattr(model, name), np.ndarray)}
    if not arrays:
        return model
    return _replace(model, {name: (v[index][:, None] if column else v[index]) for name, v in arrays.items()})


def parameter_sets(model, shape):
    """``[(index, model_with_scalar_parameters), ...]``: the distinct parameter sets of ``model``
    broadcast to ``shape``, with the flat indices of the points that have each one. For models
    whose hooks are not vectorized over their parameters (``broadcasts = False``), and for
    tables built per parameter set."""
    arrays = {name: v for name in _array_fields(type(model)) if isinstance(v := getattr(model, name), np.ndarray)}
    n = int(np.prod(shape, dtype=int))
    if not arrays:
        return [(np.arange(n), model)]
    if n == 0:                              # no point, no parameter set
        return []
    names = list(arrays)
    stack = np.stack([np.broadcast_to(arrays[k], shape).ravel() for k in names], axis=1)
    rows, inverse = np.unique(stack, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(rows.shape[0] + 1))
    return [(order[bounds[j]:bounds[j + 1]], _replace(model, {k: float(rows[j, c]) for c, k in enumerate(names)}))
            for j in range(rows.shape[0])]


def evaluate(model, fn, *args, per_set=False):
    """``fn(model', *args')`` with the arguments and the model's parameters broadcast together.

    The arguments (floats or arrays) and the model's array parameters are broadcast to one
    shape and flattened; ``fn`` gets the model with aligned 1-D parameters (or, for a model
    with ``broadcasts = False``, one call per distinct parameter set) and returns values of the
    flat shape. Returns a float when everything is scalar, else an array of the broadcast shape.
    ``per_set`` forces one call per parameter set (a model whose derived quantities are cached per
    parameter set, such as the flow table of a non-separable rheology).
    """
    arrays = [np.asarray(a, dtype=float) for a in args]
    shape = np.broadcast_shapes(*(a.shape for a in arrays), parameter_shape(model))
    if shape == ():
        return float(np.asarray(fn(model, *arrays), dtype=float))
    if 0 in shape:                          # no point (an empty array, NumPy's convention): nothing to ask fn
        return np.zeros(shape)
    flat = [np.broadcast_to(a, shape).ravel() if a.ndim else a for a in arrays]
    n = int(np.prod(shape, dtype=int))
    if getattr(type(model), "broadcasts", True) and not per_set:
        out = np.asarray(fn(broadcast_model(model, shape), *flat), dtype=float)
        return np.array(np.broadcast_to(out.reshape(-1) if out.ndim else out, (n,)).reshape(shape))
    out = np.empty(n)
    for index, scalar_model in parameter_sets(model, shape):
        out[index] = fn(scalar_model, *(a[index] if a.ndim else a for a in flat))
    return out.reshape(shape)


def flat_points(model, *values):
    """``(shape, model', [values'])``: the values and the model's array parameters broadcast
    together and flattened to aligned 1-D arrays (scalar values and a model's scalar parameters
    stay scalars; :func:`take` reads either at some points).

    Generic hooks that iterate with only some points active (root finders, differentiation) use
    it, then take the model at the active indices with :func:`model_at`.
    """
    arrays = [np.asarray(v, dtype=float) for v in values]
    shape = np.broadcast_shapes(*(a.shape for a in arrays), parameter_shape(model))
    n = (int(np.prod(shape, dtype=int)),)
    return shape, broadcast_model(model, shape), [np.broadcast_to(a, shape).reshape(n).copy() if a.ndim else a
                                                  for a in arrays]


def varies(model) -> bool:
    """Whether some parameter of ``model`` is a function of z (a :class:`~tubefsi.Profile`)."""
    for name in _array_fields(type(model)):
        value = getattr(model, name)
        if type(value) is not float and isinstance(value, Profile):
            return True
    return False


def at_position(model, z, index=None):
    """``model`` with each :class:`~tubefsi.Profile` parameter evaluated at the positions ``z`` (and
    its flat array parameters taken at ``index``, if given, to align with ``z``); bypasses the
    validators (each profile validates its own values)."""
    values = {}
    for name in _array_fields(type(model)):
        v = getattr(model, name)
        if isinstance(v, Profile):
            values[name] = v(z)
        elif index is not None and isinstance(v, np.ndarray):
            values[name] = v[index]
    return _replace(model, values) if values else model


def take(value, index):
    """A per-point value (a scalar, shared by all points, or a 1-D array) at ``index``."""
    return value if np.ndim(value) == 0 else value[index]
