"""Every bad input raises the named error; no valid input returns NaN."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi import InvalidParameterError, NoSteadyStateError
from tubefsi.registry import rheologies, walls
from tubefsi.testing.profiles import scaled

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
WALL = walls["thick-neo-hookean"](shear_modulus=2e3)
BAD_POSITIVE = [0.0, -1.0, math.nan, math.inf, -math.inf, "abc", None]


@pytest.mark.parametrize("field", ["radius", "thickness", "length"])
@pytest.mark.parametrize("bad", BAD_POSITIVE)
def test_tube_geometry(field, bad):
    kw = dict(radius=1e-4, thickness=3e-5, length=1e-2)
    kw[field] = bad
    with pytest.raises(InvalidParameterError, match=field) as info:
        tubefsi.Tube(**kw)
    assert info.value.parameter == field
    assert "(0, inf)" in str(info.value) or "real numbers" in str(info.value)


@pytest.mark.parametrize(("name", "field", "others"), [
    ("newtonian", "viscosity", {}),
    ("power-law", "consistency", {"index": 0.7}),
    ("power-law", "index", {"consistency": 1.0}),
    ("thin-linear", "youngs_modulus", {"poisson_ratio": 0.3}),
    ("thick-linear", "youngs_modulus", {"poisson_ratio": 0.3}),
    ("thin-neo-hookean", "shear_modulus", {}),
    ("thick-neo-hookean", "shear_modulus", {}),
])
@pytest.mark.parametrize("bad", BAD_POSITIVE)
def test_model_parameters_must_be_positive(name, field, others, bad):
    cls = rheologies[name] if name in rheologies else walls[name]
    with pytest.raises(InvalidParameterError, match=field) as info:
        cls(**{field: bad}, **others)
    assert info.value.parameter == field


@pytest.mark.parametrize("name", ["thin-linear", "thick-linear"])
@pytest.mark.parametrize("nu", [-1.0, -1.5, 0.5000001, 0.7, math.nan])
def test_poisson_ratio_range(name, nu):
    with pytest.raises(InvalidParameterError, match=r"poisson_ratio must be in \(-1, 0.5\]"):
        walls[name](youngs_modulus=1e3, poisson_ratio=nu)
    walls[name](youngs_modulus=1e3, poisson_ratio=0.5)  # the incompressible bound is admissible


@pytest.mark.parametrize("name", ["thin-mooney-rivlin", "thick-mooney-rivlin"])
@pytest.mark.parametrize(("c1", "c2"), [(1.0, -1.0), (1.0, -2.0), (-1.0, 0.5), (0.0, 0.0)])
def test_mooney_rivlin_needs_positive_sum(name, c1, c2):
    with pytest.raises(InvalidParameterError, match=r"c1 \+ c2") as info:
        walls[name](c1=c1, c2=c2)
    assert info.value.admissible == "(0, inf)"
    walls[name](c1=c1, c2=abs(c1) + 1.0)


@pytest.mark.parametrize("name", ["thin-mooney-rivlin", "thin-neo-hookean"])
def test_unknown_thickness_convention(name):
    kw = {"c1": 1.0, "c2": 0.0} if "mooney" in name else {"shear_modulus": 1.0}
    with pytest.raises(InvalidParameterError, match="thickness_convention.*'reference', 'current'"):
        walls[name](**kw, thickness_convention="deformed")


@pytest.mark.parametrize("load", ["flow_rate", "pressure_drop"])
@pytest.mark.parametrize("bad", [-1e-9, math.nan, math.inf, [1e-10, -1e-10], np.array([1e-10, np.nan])])
def test_loads_must_be_finite_and_non_negative(load, bad):
    with pytest.raises(InvalidParameterError, match=load):
        tubefsi.solve(FLUID, WALL, TUBE, **{load: bad})


def test_exactly_one_load():
    with pytest.raises(InvalidParameterError, match="exactly one"):
        tubefsi.solve(FLUID, WALL, TUBE)
    with pytest.raises(InvalidParameterError, match="exactly one"):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9, pressure_drop=1.0)


@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf])
def test_outlet_pressure(bad):
    with pytest.raises(InvalidParameterError, match="outlet_pressure"):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9, outlet_pressure=bad)


def test_unknown_names_and_wrong_types():
    with pytest.raises(InvalidParameterError, match="wall"):
        tubefsi.solve(FLUID, "no-such-wall", TUBE, flow_rate=1e-9)
    with pytest.raises(InvalidParameterError, match="rheology"):
        tubefsi.solve(WALL, WALL, TUBE, flow_rate=1e-9)
    with pytest.raises(InvalidParameterError, match="coupler"):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9, coupler="magic")
    with pytest.raises(InvalidParameterError, match="coupler"):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9, coupler="closed-form")  # thick: no closed form
    with pytest.raises(InvalidParameterError, match="tube"):
        tubefsi.solve(FLUID, WALL, (1e-4, 3e-5, 1e-2), flow_rate=1e-9)
    with pytest.raises(InvalidParameterError, match="rheology"):
        tubefsi.solve("power-law", WALL, TUBE, flow_rate=1e-9)  # needs parameters


def test_registered_name_without_parameters_is_accepted():
    sol = tubefsi.solve(FLUID, "rigid", TUBE, flow_rate=1e-9)
    assert sol.pressure_drop > 0


def test_zero_flow_rate_gives_zero_pressure_drop():
    sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=[0.0, 1e-9])
    assert sol.pressure_drop[0] == 0.0 and sol.pressure_drop[1] > 0
    assert tubefsi.solve(FLUID, WALL, TUBE, flow_rate=0.0).pressure_drop == 0.0


def test_pressure_beyond_limit_is_no_steady_state():
    limit = WALL.limit_pressure(TUBE.reduced_thickness)
    assert limit == pytest.approx(2e3 * math.log(1.3), rel=1e-15)
    for dp in (limit, 2 * limit, [0.5 * limit, 1.5 * limit]):
        with pytest.raises(NoSteadyStateError, match="limit") as info:
            tubefsi.solve(FLUID, WALL, TUBE, pressure_drop=dp)
        assert info.value.limit == limit and info.value.quantity == "pressure"
    with pytest.raises(NoSteadyStateError):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-10, outlet_pressure=limit)


def test_flow_rate_beyond_maximum_is_no_steady_state():
    q_max = tubefsi.max_flow_rate(FLUID, WALL, TUBE)
    assert 0 < q_max < math.inf
    with pytest.raises(NoSteadyStateError, match="flow_rate") as info:
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=[0.5 * q_max, 1.0001 * q_max])
    assert info.value.limit == q_max and info.value.quantity == "flow_rate"
    sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=0.999 * q_max)
    assert np.isfinite(sol.pressure_drop) and sol.pressure_drop < WALL.limit_pressure(0.3)


def test_profiles_reject_positions_outside_the_tube():
    sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9)
    for z in (-1e-3, 2e-2, math.nan):
        with pytest.raises(InvalidParameterError, match="z"):
            sol.pressure(z)
    with pytest.raises(InvalidParameterError, match="r"):
        sol.velocity(2 * sol.inlet_radius, 0.0)


@pytest.mark.parametrize("wall", [walls[n](**kw) for n in walls for kw in getattr(walls[n], "_examples", ())],
                         ids=repr)
def test_no_nan_over_a_wide_load_range(wall):
    q_max = tubefsi.max_flow_rate(FLUID, wall, TUBE)
    top = 0.999 * q_max if math.isfinite(q_max) else 1e-6
    q = np.geomspace(1e-18, top, 50)
    sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)
    for value in (sol.pressure_drop, sol.inlet_displacement, sol.pressure(0.5 * TUBE.length)):
        assert np.all(np.isfinite(value))
        assert np.all(value > 0) or (wall.is_rigid and np.all(value >= 0))
    back = tubefsi.solve(FLUID, wall, TUBE, pressure_drop=sol.pressure_drop)
    assert np.all(np.isfinite(back.flow_rate))


@settings(deadline=None, max_examples=scaled(300))
@given(low=st.sampled_from([-math.inf, -1.0, 0.0, 1.0]), width=st.sampled_from([0.0, 1.0, math.inf]),
       low_open=st.booleans(), high_open=st.booleans(),
       value=st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                       st.sampled_from([-math.inf, -1.0, -0.0, 0.0, 1.0, 2.0, math.inf, math.nan])))
def test_interval_validator_against_its_definition(low, width, low_open, high_open, value):
    """A float parameter passes exactly when it is a finite number (or +inf under a closed infinite
    upper end) within the interval, open or closed at each end, as an array entry does."""
    from tubefsi.fields import _interval_validator
    high = low + width

    class Field:
        name = "x"

    inside = ((value > low) if low_open else (value >= low)) and ((value < high) if high_open else (value <= high))
    admitted = inside and (math.isfinite(value) or (value == math.inf and high == math.inf and not high_open))
    check = _interval_validator(low, high, low_open, high_open, "the interval")
    for given_value in (value, np.array([value])):
        try:
            check(None, Field, given_value)
            passed = True
        except InvalidParameterError:
            passed = False
        assert passed == admitted, (low, high, low_open, high_open, value)
