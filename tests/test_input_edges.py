"""What users pass in where a number is expected (issue 25): the contract is a typed error naming
the parameter, or finite results of the broadcast shape (empty for an empty array) — never a
silent 0, a value read from under a mask, or a NumPy/Python exception.

The rule (``tubefsi._validation.real_array``, shared by the model fields, the ``Tube`` fields and
the arguments of the entry points): a real number of any type is rounded to the nearest double,
and refused where the doubles cannot hold it at all (nonzero rounding to 0, finite rounding to
inf); masked entries, arrays of more than 32 dimensions, strings, dates and ragged lists are
refused; a choice field takes one of its strings, nothing else."""

from __future__ import annotations

import datetime
import warnings
from decimal import Decimal
from fractions import Fraction

import attrs
import numpy as np
import pytest
import tubefsi
from tubefsi import InvalidParameterError, Tube, registry, solve
from tubefsi.couplers import ODE, Quadrature

R, W = registry.rheologies, registry.walls
NEWTONIAN = R["newtonian"](viscosity=1e-3)
POWER = R["power-law"](consistency=0.017, index=0.7)
NEO = W["thick-neo-hookean"](shear_modulus=2e3)
TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
TUBE_FIELDS = {"radius": 1e-4, "thickness": 3e-5, "length": 1e-2}

#: A long double the doubles cannot hold: below the smallest subnormal, and beyond the largest double.
UNDER = np.longdouble(1e-200) * np.longdouble(1e-200)
OVER = np.longdouble(1e300) * np.longdouble(1e300)


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        yield


def _refused(call, parameter, *words):
    with pytest.raises(InvalidParameterError) as info:
        call()
    assert info.value.parameter == parameter, str(info.value)
    for word in words:
        assert word in str(info.value), str(info.value)
    return info.value


# one call per place a number enters: the loads, the outlet state, the density, a model field, a Tube field
PLACES = {
    "flow_rate": lambda v: solve(NEWTONIAN, NEO, TUBE, flow_rate=v),
    "pressure_drop": lambda v: solve(NEWTONIAN, NEO, TUBE, pressure_drop=v),
    "outlet_pressure": lambda v: solve(NEWTONIAN, NEO, TUBE, flow_rate=1e-12, outlet_pressure=v),
    "external_pressure": lambda v: solve(NEWTONIAN, NEO, TUBE, flow_rate=1e-12, external_pressure=v),
    "density": lambda v: solve(NEWTONIAN, NEO, TUBE, flow_rate=1e-12, density=v),
    "shear_modulus": lambda v: W["thick-neo-hookean"](shear_modulus=v),
    "viscosity": lambda v: R["newtonian"](viscosity=v),
    "radius": lambda v: Tube(**{**TUBE_FIELDS, "radius": v}),
}


# ------------------------------------------------------------------ numbers beyond the doubles
def test_a_long_double_flow_rate_below_the_doubles_is_refused_not_answered_zero():
    # was: cast to 0.0 and answered dp = 0; the true drop, 8 mu L q / (pi a^4) ~ 1e-271 Pa, is a double
    _refused(lambda: solve(NEWTONIAN, NEO, TUBE, flow_rate=np.longdouble("1e-400")), "flow_rate",
             "double precision")


def test_a_long_double_within_the_doubles_takes_the_float_route():
    # the contract of solve: a NumPy scalar gives the same bits as the Python float
    reference = solve(NEWTONIAN, NEO, TUBE, flow_rate=1e-12).pressure_drop
    assert solve(NEWTONIAN, NEO, TUBE, flow_rate=np.longdouble(1e-12)).pressure_drop == reference


@pytest.mark.parametrize("place", sorted(PLACES))
@pytest.mark.parametrize("value", [10**400, -(10**400), UNDER, OVER, [1.0, 10**400], np.array([1.0, OVER]),
                                   Fraction(1, 10**400), Decimal("1e-400"), Decimal("1e400")],
                         ids=["10**400", "-10**400", "longdouble 1e-400", "longdouble 1e600", "list with 10**400",
                              "array of long doubles", "Fraction 1e-400", "Decimal 1e-400", "Decimal 1e400"])
def test_numbers_the_doubles_cannot_hold_are_refused_naming_the_parameter(place, value):
    # was: OverflowError from float(int), or a silent 0 / inf from the cast
    error = _refused(lambda: PLACES[place](value), place, "double precision")
    if np.ndim(value) == 1:
        assert "index (1,)" in str(error)


def test_a_python_int_beyond_the_doubles_is_shown_short():
    error = _refused(lambda: solve(NEWTONIAN, NEO, TUBE, pressure_drop=10**400), "pressure_drop")
    assert "1.000e+400" in str(error) and len(str(error)) < 300


@pytest.mark.parametrize("value, expected", [(Fraction(1, 1000), 0.001), (Decimal("0.001"), 0.001),
                                             (np.float32(0.5), 0.5), (2**70, 2.0**70), (np.uint64(7), 7.0)])
def test_real_numbers_of_other_types_are_the_nearest_double(value, expected):
    assert R["newtonian"](viscosity=value).viscosity == expected
    assert Tube(**{**TUBE_FIELDS, "length": value}).length == expected


# ------------------------------------------------------------------ masked arrays
@pytest.mark.parametrize("place", sorted(PLACES))
def test_a_masked_entry_is_refused_not_solved_from_the_data_under_it(place):
    good = {"external_pressure": -5.0, "flow_rate": 1e-12}.get(place, 10.0)
    masked = np.ma.masked_array([good, -1.0], mask=[False, True])      # the hidden -1 would be refused too
    _refused(lambda: PLACES[place](masked), place, "masked", "(1,)")
    _refused(lambda: PLACES[place](np.ma.masked), place, "masked")


def test_a_masked_array_without_masked_entries_is_its_data():
    masked = np.ma.masked_array([1e-12, 2e-12], mask=False)
    reference = solve(POWER, NEO, TUBE, flow_rate=[1e-12, 2e-12]).pressure_drop
    np.testing.assert_array_equal(solve(POWER, NEO, TUBE, flow_rate=masked).pressure_drop, reference)
    wall = W["thick-neo-hookean"](shear_modulus=np.ma.masked_array([2e3, 3e3]))
    assert type(wall.shear_modulus) is np.ndarray


# ------------------------------------------------------------------ choice fields
def _choice_fields():
    out = []
    for kind in (R, W, registry.couplers):
        for name in kind:
            cls = kind[name]
            for field in attrs.fields(cls):
                if "options" in field.metadata:
                    out.append(pytest.param(cls, field, id=f"{name}.{field.name}"))
    return out


@pytest.mark.parametrize("cls, field", _choice_fields())
@pytest.mark.parametrize("value", [np.array(["a", "b"]), np.array([]), [], 1, None, ["x", ["y"]]],
                         ids=["array", "empty array", "[]", "1", "None", "ragged"])
def test_a_choice_field_refuses_anything_but_one_of_its_strings(cls, field, value):
    # was: "The truth value of an array ... is ambiguous" (ValueError) for an array
    example = dict(cls._examples[0]) if getattr(cls, "_examples", ()) else {}
    options = field.metadata["options"]
    given = np.array(options[:2]) if value.__class__ is np.ndarray and value.size else value
    error = _refused(lambda: cls(**{**example, field.name: given}), field.name)
    assert all(repr(o) in str(error) for o in options)


def test_the_ode_method_is_a_choice_field():
    assert "options" in attrs.fields_dict(ODE)["method"].metadata
    _refused(lambda: ODE(method=np.array(["RK45", "BDF"])), "method", "'LSODA'")
    assert ODE(method="BDF").method == "BDF"


def test_on_infeasible_given_an_array_is_refused():
    _refused(lambda: solve(NEWTONIAN, NEO, TUBE, flow_rate=1e-12, on_infeasible=np.array(["raise", "nan"])),
             "on_infeasible", "'raise'")


# ------------------------------------------------------------------ dimensions
@pytest.mark.parametrize("place", sorted(PLACES))
def test_an_array_of_33_dimensions_is_refused(place):
    # was: NumPy's RuntimeError "only supports up to 32 dimensions" for a load or the outlet pressure
    good = {"external_pressure": -5.0, "flow_rate": 1e-12}.get(place, 10.0)
    _refused(lambda: PLACES[place](np.full((1,) * 33, good)), place, "32 dimensions")


@pytest.mark.parametrize("where", ["flow_rate", "viscosity", "length", "outlet_pressure"])
@pytest.mark.parametrize("shape", [(1,), (1, 1), (1,) * 32], ids=["(1,)", "(1, 1)", "32 dimensions"])
def test_arrays_of_one_entry_give_the_bits_of_the_scalar_solve(where, shape):
    # was: TypeError "only 0-dimensional arrays can be converted" (a model or tube parameter of one
    # entry took the route of one point, which takes floats); contract: same route, same bits
    fluid, tube, kw = NEWTONIAN, TUBE, {"flow_rate": 1e-12}
    if where == "flow_rate":
        kw = {"flow_rate": np.full(shape, 1e-12)}
    elif where == "viscosity":
        fluid = R["newtonian"](viscosity=np.full(shape, 1e-3))
    elif where == "length":
        tube = Tube(radius=1e-4, thickness=3e-5, length=np.full(shape, 1e-2))
    else:
        kw["outlet_pressure"] = np.full(shape, 0.0)
    sol = solve(fluid, NEO, tube, **kw)
    assert np.shape(sol.pressure_drop) == shape
    assert np.ravel(sol.pressure_drop)[0] == solve(NEWTONIAN, NEO, TUBE, flow_rate=1e-12).pressure_drop


def test_twenty_dimensions_against_twenty_broadcast():
    fluid = R["newtonian"](viscosity=np.full((1,) * 20, 1e-3))
    sol = solve(fluid, NEO, TUBE, flow_rate=np.full((1,) * 20, 1e-12))
    assert np.shape(sol.pressure_drop) == (1,) * 20


# ------------------------------------------------------------------ empty arrays
EMPTY_SCENES = {
    "flow_rate": lambda: solve(POWER, NEO, TUBE, flow_rate=[]),
    "Tube radius": lambda: solve(POWER, NEO, Tube(radius=[], thickness=3e-5, length=1e-2), flow_rate=1e-12),
    "viscosity": lambda: solve(R["newtonian"](viscosity=[]), NEO, TUBE, flow_rate=1e-12),
    "outlet pressure, Carreau and Gent": lambda: solve(R["carreau"](**R["carreau"]._examples[0]),
                                                       W["thick-gent"](**W["thick-gent"]._examples[0]), TUBE,
                                                       flow_rate=1e-12, outlet_pressure=[]),
    "external pressure": lambda: solve(POWER, NEO, TUBE, flow_rate=1e-12, external_pressure=[]),
    "axial stretch of HGO": lambda: solve(POWER, W["thick-hgo"](**{**W["thick-hgo"]._examples[0], "axial_stretch": []}),
                                          TUBE, flow_rate=1e-12),
    "axial stretch of Gent": lambda: solve(POWER, W["thick-gent"](shear_modulus=2e3, locking_parameter=10.0,
                                                                  axial_stretch=[]), TUBE, pressure_drop=10.0),
    "density with an empty load": lambda: solve(POWER, NEO, TUBE, flow_rate=[], density=[]),
}


@pytest.mark.parametrize("case", sorted(EMPTY_SCENES))
def test_an_empty_array_gives_empty_results(case):
    # NumPy's convention, as solve(flow_rate=[]) already had it; was: "zero-size array to reduction
    # operation" (Tube), a broadcast error (Carreau and Gent), an IndexError (a fluid's table)
    sol = EMPTY_SCENES[case]()
    assert np.shape(sol.pressure_drop) == (0,) and np.shape(sol.flow_rate) == (0,)


def test_an_empty_density_does_not_widen_the_results():
    # the density is broadcast to the loads' shape (it adds a check, not points): refused against one load
    _refused(lambda: solve(POWER, NEO, TUBE, flow_rate=1e-12, density=[]), "density")


def test_an_empty_wall_gives_an_empty_maximum_flow_rate():
    assert np.shape(tubefsi.max_flow_rate(POWER, W["thick-neo-hookean"](shear_modulus=[]), TUBE)) == (0,)


# ------------------------------------------------------------------ other objects
@pytest.mark.parametrize("place", sorted(PLACES))
@pytest.mark.parametrize("value", [[1.0, [1.0]], [1.0, None], [1.0, "x"], np.datetime64("2020-01-01"),
                                   datetime.datetime(2020, 1, 1), 1 + 0j, np.array([1.0, 2.0], dtype=complex)],
                         ids=["ragged", "None entry", "string entry", "datetime64", "datetime", "complex",
                              "complex array"])
def test_other_objects_are_refused_naming_the_parameter(place, value):
    _refused(lambda: PLACES[place](value), place)


def test_a_huge_radius_gives_a_typed_error():
    # was: OverflowError from the change to units of the radius (a^3 beyond the doubles); the drop
    # 8 mu L q / (pi a^4) at a = 1e300 m is below the smallest double
    for kw in ({"flow_rate": 1e-12}, {"pressure_drop": 1.0}):
        with pytest.raises(InvalidParameterError):
            solve(NEWTONIAN, NEO, Tube(radius=1e300, thickness=3e299, length=1e301), **kw)


# ------------------------------------------------------------------ options that are one setting
@pytest.mark.parametrize("field", ["rtol", "panel_width"])
@pytest.mark.parametrize("value", [[1e-3, 1e-3], [], [1e-3]], ids=["two", "empty", "one"])
def test_a_coupler_option_is_a_single_number(field, value):
    # was: accepted, then an unhashable-array TypeError (rtol) or a scalar answer (panel_width)
    _refused(lambda: Quadrature(**{field: value}), field, "a single number")


@pytest.mark.skipif("thick-ogden" not in W, reason="the hyperelastic plugin is not installed")
@pytest.mark.parametrize("value", [10**400, np.ma.masked_array([2e3, 1e3], mask=[False, True]),
                                   np.datetime64("2020-01-01"), [2e3, [1e3]], [[2e3]]],
                         ids=["10**400", "masked", "datetime64", "ragged", "2-d"])
def test_ogden_terms_follow_the_same_rule(value):
    _refused(lambda: W["thick-ogden"](moduli=value, exponents=(3.0,)), "moduli")


@pytest.mark.skipif("thick-ogden" not in W, reason="the hyperelastic plugin is not installed")
def test_an_ogden_axial_stretch_broadcasts_like_every_parameter():
    # was: TypeError from float(array) when the wall was made; reference: the scalar walls' solves
    both = W["thick-ogden"](moduli=(2e3,), exponents=(3.0,), axial_stretch=[1.0, 1.1])
    got = solve(POWER, both, TUBE, flow_rate=1e-12).pressure_drop
    want = [solve(POWER, W["thick-ogden"](moduli=(2e3,), exponents=(3.0,), axial_stretch=lz), TUBE,
                  flow_rate=1e-12).pressure_drop for lz in (1.0, 1.1)]
    np.testing.assert_allclose(got, want, rtol=1e-13)


def test_profile_positions_of_another_shape_are_refused():
    # was: NumPy's broadcast ValueError
    sol = solve(POWER, W["thick-neo-hookean"](shear_modulus=[2e3, 3e3, 4e3]), TUBE, flow_rate=1e-12)
    _refused(lambda: sol.pressure([0.0, 1e-3]), "z", "(3,)")
    _refused(lambda: sol.velocity([0.0, 1e-5], 0.0), "r")
