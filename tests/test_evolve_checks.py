"""tubefsi.evolve: the steady state of a stopped pump, and the checks of its inputs.

* a pump that stops into a chamber: the volume is pumped in linearly, V(t) = V(t0) + q t (mass,
  a closed form), then held; the settling time and the steady volume follow from that line;
* bad inputs get InvalidParameterError naming the parameter (or BucklingError), never a raw
  Python or NumPy error.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import tubefsi

FLUID = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
WALL = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=1e5)
TUBE = tubefsi.Tube(radius=2.5e-4, thickness=1e-4, length=0.05)
TIMES = np.linspace(0.0, 0.1, 3)


def test_stopped_pump_into_chamber_settles_when_the_pumping_does():
    q, stop = 1e-9, 0.51
    times = np.linspace(0.0, 1.0, 41)
    r = tubefsi.evolve(FLUID, WALL, TUBE, times, inlet_flow_rate=lambda t: q if t < stop else 0.0,
                       outlet=tubefsi.Chamber.linear(1e-7, 1e-11), rtol=1e-3)
    # mass: the final volume is the start plus what was pumped in, q * stop (closed form)
    v0 = r.stored_volume()[0]
    assert r.steady_volume() == pytest.approx(v0 + q * stop, rel=1e-9)
    assert r.steady() is None
    # V(t) = v0 + q t until stop: within 13 % of the change from 0.87 stop on (linear in t, so
    # the linear interpolation between output times is exact)
    assert r.settling_time(0.87) == pytest.approx(0.87 * stop, rel=1e-4)


def test_running_pump_into_closed_end_has_no_settling_time():
    r = tubefsi.evolve(FLUID, WALL, TUBE, TIMES, inlet_flow_rate=1e-10, outlet="closed", rtol=1e-3)
    with pytest.raises(tubefsi.NoSteadyStateError, match="fills it without bound"):
        r.settling_time(0.9)


def test_initial_solution_of_another_problem_is_refused():
    other_tube = tubefsi.Tube(radius=1e-4, thickness=1e-4, length=0.05)
    other_wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e5)
    for sol, what in [(tubefsi.solve(FLUID, WALL, other_tube, flow_rate=1e-9), "radius"),
                      (tubefsi.solve(FLUID, other_wall, TUBE, flow_rate=1e-9), "wall"),
                      (tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9, external_pressure=100.0), "external")]:
        with pytest.raises(tubefsi.InvalidParameterError, match=what) as info:
            tubefsi.evolve(FLUID, WALL, TUBE, TIMES, inlet_pressure=1e3, initial=sol, rtol=1e-2)
        assert info.value.parameter == "initial"


@pytest.mark.parametrize("kwargs", [dict(inlet_pressure=-1e6), dict(inlet_pressure=0.0, initial=-1e6),
                                    dict(inlet_pressure=0.0, outlet_pressure=-1e4)])
def test_pressure_below_buckling_is_buckling_error(kwargs):
    # the buckling bound of the wall, from the wall itself (min_pressure)
    bound = float(WALL.min_pressure(TUBE.thickness / TUBE.radius))
    with pytest.raises(tubefsi.BucklingError) as info:
        tubefsi.evolve(FLUID, WALL, TUBE, TIMES, rtol=1e-2, **kwargs)
    assert info.value.limit == pytest.approx(bound)


def test_rigid_wall_is_refused():
    with pytest.raises(tubefsi.InvalidParameterError, match="rigid wall stores no volume") as info:
        tubefsi.evolve(FLUID, "rigid", TUBE, TIMES, inlet_pressure=1e3)
    assert info.value.parameter == "wall"


def test_chamber_emptying_is_refused():
    with pytest.raises(tubefsi.InvalidParameterError, match="chamber empties") as info:
        tubefsi.evolve(FLUID, WALL, TUBE, np.linspace(0, 0.5, 11), inlet_pressure=-1000.0,
                       outlet=tubefsi.Chamber.linear(0.0, 1e-12), rtol=1e-3)
    assert info.value.parameter == "outlet"


def test_inconsistent_chamber_compliance_is_refused():
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        tubefsi.Chamber(volume=lambda p: 1e-9 + 1e-12 * p, compliance=lambda p: 2e-12 + 0.0 * p)
    assert info.value.parameter == "compliance"
    # the consistent pair is accepted
    tubefsi.Chamber(volume=lambda p: 1e-9 * np.exp(p / 1e3), compliance=lambda p: 1e-12 * np.exp(p / 1e3))


def _raises(p):
    raise RuntimeError("no curve there")


@pytest.mark.parametrize("kwargs, name", [
    (dict(times="abc"), "times"),
    (dict(times=[0.0]), "times"),
    (dict(times=0.1), "times"),
    (dict(initial="x"), "initial"),
    (dict(density=-1.0), "density"),
    (dict(external_pressure=np.array([1.0, 2.0]), inlet_pressure=np.array([1e3, 2e3, 3e3])), "external_pressure"),
    (dict(inlet_pressure="1e4"), "inlet_pressure"),
    (dict(cells=16.5), "cells"),
    (dict(outlet="closed", outlet_pressure=0.0), "outlet_pressure"),
    (dict(inlet_pressure=lambda t: np.array([1.0, 2.0])), "inlet_pressure"),
    (dict(inlet_pressure=None, inlet_flow_rate=lambda t: math.nan), "inlet_flow_rate"),
    (dict(outlet=_raises), "outlet"),
])
def test_bad_input_names_the_parameter(kwargs, name):
    args = dict(times=TIMES, inlet_pressure=1e3, rtol=1e-2) | kwargs
    times = args.pop("times")
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        tubefsi.evolve(FLUID, WALL, TUBE, times, **args)
    assert info.value.parameter == name


def test_non_finite_inlet_message_gives_the_value():
    with pytest.raises(tubefsi.InvalidParameterError, match=r"got nan.*at t = ") as info:
        tubefsi.evolve(FLUID, WALL, TUBE, TIMES, inlet_pressure=lambda t: math.nan if t > 0.05 else 1e3)
    assert info.value.parameter == "inlet_pressure"


@pytest.mark.parametrize("volume", ["a", np.array([1e-9, 2e-9])])
def test_bad_linear_chamber(volume):
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        tubefsi.Chamber.linear(volume, 1e-12)
    assert info.value.parameter == "volume"


def test_repr_shows_plain_floats():
    # (at rest: no volume change, the mass balance 0 / a tiny scale)
    r = tubefsi.evolve(FLUID, WALL, TUBE, TIMES, inlet_pressure=0.0, error_control=False, cells=8)
    assert "np.float64" not in repr(r)
    assert isinstance(r.mass_error, float)


def test_relaxation_error_is_measured_against_the_problem_scale():
    # released at both ends from 1e4 Pa: the tube empties to its rest volume pi a^2 L (closed form)
    # within milliseconds; the flow history then decays to ~0 and must not drive the refinement
    times = np.linspace(0.0, 0.5, 26)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.AccuracyWarning)
        r = tubefsi.evolve(FLUID, WALL, TUBE, times, inlet_pressure=0.0, initial=1e4, rtol=1e-3)
    a, length = TUBE.radius, TUBE.length
    lam0 = 1.0 + float(WALL.strain(1e4, TUBE.thickness / a))       # the wall's tube law
    assert r.stored_volume()[0] == pytest.approx(math.pi * (a * lam0) ** 2 * length, rel=1e-3)
    assert r.stored_volume()[-1] == pytest.approx(math.pi * a**2 * length, rel=1e-6)


def test_pressure_step_at_an_output_time():
    # the flow at the instant of a step is singular: left out of the estimate, the run settles to
    # the steady flow of tubefsi.solve (a different algorithm)
    times = np.linspace(0.0, 0.5, 26)                  # 0.1 is an output time
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.AccuracyWarning)
        r = tubefsi.evolve(FLUID, WALL, TUBE, times, inlet_pressure=lambda t: 1e4 if t >= 0.1 else 0.0, rtol=1e-3)
    steady = tubefsi.solve(FLUID, WALL, TUBE, pressure_drop=1e4).flow_rate
    assert r.inlet_flow_rate[-1] == pytest.approx(steady, rel=1e-3)
    assert r.error_estimate <= 1e-3


@pytest.mark.parametrize("fraction", ["0.9", np.array([0.5, 0.9]), 1.0])
def test_bad_settling_fraction(fraction):
    r = tubefsi.evolve(FLUID, WALL, TUBE, TIMES, inlet_pressure=1e3, error_control=False, cells=8)
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        r.settling_time(fraction)
    assert info.value.parameter == "fraction"


def test_pressure_above_the_limit_is_no_steady_state():
    limit = float(WALL.limit_pressure(TUBE.thickness / TUBE.radius))    # from the wall itself
    with pytest.raises(tubefsi.NoSteadyStateError) as info:
        tubefsi.evolve(FLUID, WALL, TUBE, TIMES, inlet_pressure=1.2 * limit, rtol=1e-2)
    assert not isinstance(info.value, tubefsi.BucklingError)
    assert info.value.limit == pytest.approx(limit)


def test_a_run_started_at_its_steady_state_has_settled_at_once():
    """Started from ``solve``'s steady profile of the same boundary values, nothing changes (the
    exact answer: settled at 0); the discrete volume differs from the steady profile's quadrature
    by far less than the run's accuracy, which once made the band of a zero change unreachable."""
    steady = tubefsi.solve(FLUID, WALL, TUBE, pressure_drop=2e4)
    r = tubefsi.evolve(FLUID, WALL, TUBE, np.linspace(0.0, 0.05, 11), inlet_pressure=2e4, initial=steady, rtol=1e-4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.AccuracyWarning)
        assert [r.settling_time(f) for f in (0.5, 0.9, 0.99)] == [0.0, 0.0, 0.0]


def test_a_band_below_the_runs_accuracy_warns():
    """A step of 1 % with a band of 1e-7 of it: narrower than a run at rtol 1e-3 resolves."""
    steady = tubefsi.solve(FLUID, WALL, TUBE, pressure_drop=2e4)
    r = tubefsi.evolve(FLUID, WALL, TUBE, np.linspace(0.0, 0.05, 11), inlet_pressure=2.02e4, initial=steady, rtol=1e-3)
    with pytest.warns(tubefsi.AccuracyWarning, match="narrower than the run's accuracy"):
        assert math.isfinite(r.settling_time(1.0 - 1e-7))


def test_a_shear_thinning_run_survives_a_lowered_inlet_pressure():
    """Lowering the inlet pressure of a shear-thinning run mid-way once stopped it with an
    InvalidParameterError from inside the integrator (a Newton iterate beyond the wall's range).
    The run completes, and its long-time limit is ``solve``'s at the lowered pressure."""
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    r = tubefsi.evolve(fluid, WALL, TUBE, np.linspace(0.0, 3.0, 7), inlet_pressure=lambda t: 2e4 if t < 0.1 else 1e4,
                       rtol=1e-4)
    steady = tubefsi.solve(fluid, WALL, TUBE, pressure_drop=1e4).flow_rate
    assert r.inlet_flow_rate[-1] == pytest.approx(steady, rel=1e-5)


@pytest.mark.slow
def test_a_plain_class_wall_given_by_its_stretch_evolves():
    """A WallModel subclass with the one method ``_stretch`` (its domain: stretches >= 1): the
    resting cells' trial states undershoot to strains of -1e-25, which stopped the run; its
    long-time limit is ``solve``'s."""
    from tubefsi.walls.base import WallModel

    class LinearWall(WallModel):
        def _stretch(self, pressure, tb):
            return 1.0 + np.asarray(pressure) / (2e5 * tb)

    r = tubefsi.evolve(FLUID, LinearWall(), TUBE, np.linspace(0.0, 0.5, 3), inlet_pressure=1e3, rtol=1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.AccuracyWarning)
        steady = tubefsi.solve(FLUID, LinearWall(), TUBE, pressure_drop=1e3).flow_rate
    assert r.inlet_flow_rate[-1] == pytest.approx(steady, rel=1e-5)


@pytest.mark.parametrize("kwargs, name", [
    (dict(inlet_pressure=np.array([])), "inlet_pressure"),
    (dict(inlet_pressure=np.zeros((2, 0))), "inlet_pressure"),
    (dict(inlet_pressure=1e3, external_pressure=np.zeros(0)), "external_pressure"),
])
def test_an_empty_array_of_scenes_is_refused(kwargs, name):
    with pytest.raises(tubefsi.InvalidParameterError, match=name):
        tubefsi.evolve(FLUID, WALL, TUBE, TIMES, rtol=1e-3, **kwargs)


def test_a_change_below_the_runs_accuracy_warns():
    """A 0.5 % step run at a loose tolerance without error control: its change lies below what the
    run resolves, so its settling time is 0 as far as the run can tell, and it says so (it once
    returned 0 silently where the stored history gives 1.8 s)."""
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    r = tubefsi.evolve(fluid, WALL, TUBE, np.linspace(0.0, 5.0, 51), inlet_pressure=2e4 + 100, initial=2e4,
                       outlet=tubefsi.Chamber.linear(1e-7, 1e-11), error_control=False, cells=32, rtol=1e-2)
    with pytest.warns(tubefsi.AccuracyWarning, match="narrower than the run's accuracy"):
        r.settling_time(0.9)
