"""The "inputs" family: what a user may pass where a number is expected, at every parameter.

Every field of every registered model and coupler (from the registries: plugins included), every
``Tube`` field, and the loads, the outlet and external pressures and the density of ``solve`` are
given values that NumPy would convert silently or fail on deep inside: arrays (two entries, empty,
32 dimensions), masked arrays, Python ints beyond the doubles, ``np.longdouble`` values that round
to 0 or to infinity as doubles, arrays of 33 dimensions, ragged lists; a choice field arrays and
ints. The contract: an :class:`~tubefsi.InvalidParameterError` naming the parameter, or finite
results of the broadcast shape (empty for an empty array), computed by a solve.
"""

from __future__ import annotations

import attrs
import numpy as np

from ... import registry
from ...errors import InvalidParameterError
from ...geometry import Tube
from ...solve import solve
from ._core import _TUBE, Probe, _names
from ._models import _KIND

_DEEPEST = (1,) * 32           # the most dimensions an argument may have
_TOO_DEEP = (1,) * 33


def _valid_variants(good):
    """``(label, value, shape of the results)``: admissible forms of the admissible value ``good``."""
    return (("[v, v]", [good, good], (2,)),
            ("[]", [], (0,)),
            ("32 dimensions", np.full(_DEEPEST, good), _DEEPEST),
            ("masked, nothing masked", np.ma.masked_array([good, good], mask=False), (2,)),
            ("np.longdouble(v)", np.longdouble(good), ()),
            ("1-element array", np.array([good]), (1,)))


def _bad_variants(good):
    """``(label, value)``: forms that must be refused whatever the parameter's range."""
    huge = np.longdouble(1e300) * np.longdouble(1e300)       # finite as a long double, inf as a double
    return (("10**400", 10**400), ("-10**400", -(10**400)), ("[v, 10**400]", [good, 10**400]),
            ("np.longdouble 1e-400", np.longdouble(1e-200) * np.longdouble(1e-200)),
            ("np.longdouble 1e600", huge), ("array of np.longdouble 1e600", np.array([huge, huge])),
            ("masked entry", np.ma.masked_array([good, good], mask=[False, True])),
            ("np.ma.masked", np.ma.masked),
            ("33 dimensions", np.full(_TOO_DEEP, good)), ("ragged", [good, [good]]),
            ("[v, 'x']", [good, "x"]), ("[v, None]", [good, None]), ("datetime64", np.datetime64("2020-01-01")))


def _choice_variants(options):
    """``(label, value)``: forms a choice field (one of ``options``) must refuse."""
    return (("array of choices", np.array(options[:2])), ("[]", []), ("empty array", np.array([])),
            ("[choice]", [options[0]]), ("1", 1), ("10**400", 10**400), ("masked", np.ma.masked))


def _shape_check(shape):
    def check(sol):
        got = np.shape(sol.pressure_drop)
        if got != shape or np.shape(sol.flow_rate) != shape:
            return f"results of shape {got}, not {shape}"
        return None

    return check


def _names_it(parameter):
    """A typed error of an admissible value: only an InvalidParameterError naming ``parameter``."""
    def words(error):
        if isinstance(error, InvalidParameterError) and _names(error.parameter, parameter):
            return None
        return f"{type(error).__name__} naming {getattr(error, 'parameter', None)!r}: {error}"[:200]

    return words


def _partners():
    """A wall for a rheology's probes, a fluid for a wall's, and the pair for a coupler's and the
    solve's own arguments: the core models (None where one is not registered)."""
    R, W = registry.rheologies, registry.walls
    wall = W["thick-neo-hookean"](shear_modulus=2e3) if "thick-neo-hookean" in W else None
    fluid = R["newtonian"](viscosity=1e-3) if "newtonian" in R else None
    power = R["power-law"](consistency=0.017, index=0.7) if "power-law" in R else None
    return fluid, wall, power


def _field_probes(kind, name, tube):
    cls = getattr(registry, kind)[name]
    example = dict(cls._examples[0]) if getattr(cls, "_examples", ()) else {}
    fluid, wall, power = _partners()
    entry = f"{_KIND[kind]}:{name}"

    def solved(model):
        if kind == "rheologies":
            return solve(model, wall, tube, flow_rate=1e-12)
        if kind == "walls":
            return solve(fluid, model, tube, flow_rate=1e-12)
        return solve(power, wall, tube, flow_rate=1e-12, coupler=model)

    if None in (fluid, wall, power):
        return
    for field in attrs.fields(cls):
        if not field.init:
            continue
        meta = field.metadata
        if "options" in meta:
            for label, value in _choice_variants(meta["options"]):
                yield Probe(entry, f"inputs {field.name}={label}", lambda kw={**example, field.name: value}: cls(**kw),
                            bad=True, parameter=field.name)
            continue
        good = example.get(field.name, field.default)
        if not isinstance(good, float):        # an integer or boolean option, a tuple of terms
            good = 1.0
        for label, value in _bad_variants(good):
            yield Probe(entry, f"inputs {field.name}={label}", lambda kw={**example, field.name: value}: cls(**kw),
                        bad=True, parameter=field.name)
        if not meta.get("array"):               # a field that holds no array of numbers
            if "low" in meta:                   # a real option that is one setting: a single number
                for label, value, _ in _valid_variants(good)[:2] + _valid_variants(good)[-1:]:
                    yield Probe(entry, f"inputs {field.name}={label}",
                                lambda kw={**example, field.name: value}: cls(**kw), bad=True, parameter=field.name)
            continue
        for label, value, shape in _valid_variants(good):
            yield Probe(entry, f"inputs {field.name}={label}",
                        lambda kw={**example, field.name: value}: solved(cls(**kw)), check=_shape_check(shape),
                        words=_names_it(field.name))


def _tube_probes(fluid, wall):
    for field in attrs.fields(Tube):
        good = _TUBE[field.name]
        for label, value in _bad_variants(good):
            yield Probe("Tube", f"inputs {field.name}={label}", lambda kw={**_TUBE, field.name: value}: Tube(**kw),
                        bad=True, parameter=field.name)
        for label, value, shape in _valid_variants(good):
            yield Probe("Tube", f"inputs {field.name}={label}",
                        lambda kw={**_TUBE, field.name: value}: solve(fluid, wall, Tube(**kw), flow_rate=1e-12),
                        check=_shape_check(shape), words=_names_it(field.name))


#: The arguments of ``solve`` that take numbers, each with an admissible value and the load it goes with.
_SOLVE_ARGUMENTS = {"flow_rate": (1e-12, {}), "pressure_drop": (10.0, {}),
                    "outlet_pressure": (10.0, {"flow_rate": 1e-12}), "external_pressure": (-5.0, {"flow_rate": 1e-12}),
                    "density": (1e3, {"flow_rate": 1e-12})}


def _solve_probes(fluid, wall, tube):
    for parameter, (good, load) in _SOLVE_ARGUMENTS.items():
        for label, value in _bad_variants(good):
            yield Probe("solve", f"inputs {parameter}={label}",
                        lambda kw={**load, parameter: value}: solve(fluid, wall, tube, **kw), bad=True,
                        parameter=parameter)
        for label, value, shape in _valid_variants(good):
            if parameter == "density" and shape != ():
                # a density is broadcast to the loads' shape, never widens it: with an array load
                kw = {"flow_rate": np.full(shape, 1e-12), parameter: value}
            else:
                kw = {**load, parameter: value}
            yield Probe("solve", f"inputs {parameter}={label}", lambda kw=kw: solve(fluid, wall, tube, **kw),
                        check=_shape_check(shape), words=_names_it(parameter))
    for label, value in (("array", np.array(["raise", "nan"])), ("[]", []), ("1", 1)):
        yield Probe("solve", f"inputs on_infeasible={label}",
                    lambda v=value: solve(fluid, wall, tube, flow_rate=1e-12, on_infeasible=v), bad=True,
                    parameter="on_infeasible")


def _inputs_family(chosen):
    """Arrays, masked arrays, numbers beyond the doubles and too many dimensions at every parameter."""
    tube = Tube(**_TUBE)
    for kind in ("rheologies", "walls", "couplers"):
        for name in getattr(chosen, kind):
            yield from _field_probes(kind, name, tube)
    fluid, wall, power = _partners()
    if chosen.core and None not in (fluid, wall, power):
        yield from _tube_probes(fluid, wall)
        yield from _solve_probes(power, wall, tube)
