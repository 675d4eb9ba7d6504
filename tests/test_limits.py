"""Limiting cases through the whole solver, and agreement of the ODE path.

The limits are derived in ``docs/theory.md``, section "Limits".

Every reference here is independent of the code path under test: Hagen–Poiseuille in
closed form, the Newtonian class against the power law, the linear wall against the
hyperelastic one at small strain, the ODE integrator against the quadrature.
"""

import math

import attrs
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi.couplers import ODE, Quadrature
from tubefsi.registry import rheologies, walls
from tubefsi.testing.profiles import scaled

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
HYPERELASTIC = [("thin-neo-hookean", {"thickness_convention": "reference"}, "thin-linear"),
                ("thin-neo-hookean", {"thickness_convention": "current"}, "thin-linear"),
                ("thick-neo-hookean", {}, "thick-linear")]


@settings(deadline=None, max_examples=scaled(20))
@given(n=st.floats(0.3, 2.0), q=st.floats(-12, -6).map(lambda x: 10.0**x))
def test_rigid_is_hagen_poiseuille(n, q):
    fluid = rheologies["power-law"](consistency=0.02, index=n)
    a, L = TUBE.radius, TUBE.length
    expected = L * 2 * 0.02 * ((3 * n + 1) * q / (math.pi * n)) ** n * a ** -(3 * n + 1)
    sol = tubefsi.solve(fluid, "rigid", TUBE, flow_rate=q)
    assert sol.pressure_drop == pytest.approx(expected, rel=1e-13)
    back = tubefsi.solve(fluid, "rigid", TUBE, pressure_drop=expected)
    assert back.flow_rate == pytest.approx(q, rel=1e-13)


@pytest.mark.parametrize("name", ["thin-linear", "thick-neo-hookean", "thin-mooney-rivlin"])
def test_stiff_wall_tends_to_rigid(name):
    fluid = rheologies["power-law"](consistency=0.02, index=0.7)
    q = 1e-9
    rigid = tubefsi.solve(fluid, "rigid", TUBE, flow_rate=q).pressure_drop
    errors = []
    for modulus in (1e8, 1e10, 1e12):
        kw = {"youngs_modulus": modulus, "poisson_ratio": 0.5} if "linear" in name else (
            {"shear_modulus": modulus} if "neo" in name else {"c1": modulus / 2, "c2": 0.0})
        errors.append(abs(tubefsi.solve(fluid, walls[name](**kw), TUBE, flow_rate=q).pressure_drop / rigid - 1))
    # first order in the compliance: error falls 100x per 100x stiffer wall
    assert errors[0] < 1e-2 and errors[1] == pytest.approx(errors[0] / 100, rel=0.05)
    assert errors[2] == pytest.approx(errors[1] / 100, rel=0.05)


@settings(deadline=None, max_examples=scaled(15))
@given(q=st.floats(-12, -8).map(lambda x: 10.0**x), wall_index=st.integers(0, 6))
def test_power_law_index_one_is_newtonian(q, wall_index):
    examples = [walls[n](**kw) for n in walls for kw in walls[n]._examples]
    wall = examples[wall_index % len(examples)]
    newt = tubefsi.solve(rheologies["newtonian"](viscosity=3e-3), wall, TUBE, flow_rate=q)
    power = tubefsi.solve(rheologies["power-law"](consistency=3e-3, index=1.0), wall, TUBE, flow_rate=q)
    assert power.pressure_drop == pytest.approx(newt.pressure_drop, rel=1e-13)
    assert power.coupler_name == newt.coupler_name


@pytest.mark.parametrize(("name", "kw", "linear"), HYPERELASTIC)
def test_small_strain_hyperelastic_is_linear_with_E_3mu(name, kw, linear):
    mu = 2e3
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    hyper = walls[name](shear_modulus=mu, **kw)
    lin = walls[linear](youngs_modulus=3 * mu, poisson_ratio=0.5)
    diffs = []
    for q in (1e-13, 1e-14, 1e-15):
        h = tubefsi.solve(fluid, hyper, TUBE, flow_rate=q)
        ln = tubefsi.solve(fluid, lin, TUBE, flow_rate=q)
        strain = h.inlet_displacement / TUBE.radius
        diffs.append((abs(h.pressure_drop / ln.pressure_drop - 1), strain))
    for diff, strain in diffs:
        assert diff < 5 * strain**2 + 1e-13  # the pressure drops differ at second order in strain
    assert diffs[2][0] < diffs[0][0]


def test_thick_tends_to_thin_current_in_the_solver():
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    thick, thin = walls["thick-neo-hookean"](shear_modulus=2e3), walls["thin-neo-hookean"](
        shear_modulus=2e3, thickness_convention="current")
    errors = []
    for t in (1e-6, 1e-7, 1e-8):
        tube = tubefsi.Tube(radius=1e-4, thickness=t, length=1e-2)
        q = 0.5 * tubefsi.max_flow_rate(fluid, thin, tube)
        errors.append(abs(tubefsi.solve(fluid, thick, tube, flow_rate=q).pressure_drop
                          / tubefsi.solve(fluid, thin, tube, flow_rate=q).pressure_drop - 1))
    assert errors[0] < 0.05
    assert errors[1] == pytest.approx(errors[0] / 10, rel=0.1)
    assert errors[2] == pytest.approx(errors[1] / 10, rel=0.1)


@pytest.mark.parametrize("wall", [walls[n](**kw) for n in walls for kw in walls[n]._examples], ids=repr)
def test_ode_integrator_agrees_with_quadrature(wall):
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    q = 0.5e-9
    ode = ODE(method="DOP853", rtol=1e-12, atol=1e-14)
    a = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, coupler=ode)
    b = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, coupler="quadrature")
    assert a.pressure_drop == pytest.approx(b.pressure_drop, rel=1e-9)
    back = tubefsi.solve(fluid, wall, TUBE, pressure_drop=b.pressure_drop, coupler=ode)
    assert back.flow_rate == pytest.approx(q, rel=1e-9)


def test_chapter_odeint_defaults_are_accurate_to_about_1e_4():
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall = walls["thick-mooney-rivlin"](c1=1.5e3, c2=-0.5e3)
    a = tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-9, coupler=ODE(method="odeint"))
    b = tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-9)
    assert 0 < abs(a.pressure_drop / b.pressure_drop - 1) < 1e-3


@pytest.mark.parametrize("wall", [walls[n](**kw) for n in walls for kw in walls[n]._examples], ids=repr)
def test_outlet_pressure_is_a_shorter_tube(wall):
    """A tube cut at z1 with outlet pressure p(z1) carries the same flow with drop p(0) - p(z1)."""
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    q = 0.5e-9
    full = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    z1 = 0.6 * TUBE.length
    p1 = full.pressure(z1)
    cut = attrs.evolve(full.tube, length=z1)       # z is along the installed tube (axial pre-stretch)
    short = tubefsi.solve(fluid, wall, cut, flow_rate=q, outlet_pressure=p1)
    assert short.inlet_pressure == pytest.approx(full.inlet_pressure, rel=1e-12)
    assert short.pressure_drop == pytest.approx(full.inlet_pressure - p1, rel=1e-11)
    assert short.inlet_displacement == pytest.approx(full.inlet_displacement, rel=1e-11)
    back = tubefsi.solve(fluid, wall, cut, pressure_drop=short.pressure_drop,
                         outlet_pressure=p1)
    assert back.flow_rate == pytest.approx(q, rel=1e-9)


def test_auto_picks_closed_form_where_it_exists():
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    picks = {n: tubefsi.select_coupler(fluid, walls[n](**walls[n]._examples[0])) for n in walls}
    names = {n: tubefsi.registry.couplers.name_of(c) for n, c in picks.items()}
    assert names["thick-neo-hookean"] == names["thick-mooney-rivlin"] == "quadrature"
    for n in ("rigid", "thin-linear", "thick-linear", "thin-neo-hookean", "thin-mooney-rivlin"):
        assert names[n] == "closed-form"
    assert isinstance(tubefsi.select_coupler(fluid, walls["rigid"](), Quadrature()), Quadrature)


def test_velocity_profile_matches_power_law_formula():
    n, m = 0.7, 0.017
    fluid = rheologies["power-law"](consistency=m, index=n)
    sol = tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, flow_rate=1e-9)
    z = 0.3 * TUBE.length
    big_r = sol.radius(z)
    g = sol.pressure_gradient(z)
    r = np.linspace(0, big_r, 5)
    expected = n / (n + 1) * (g / (2 * m)) ** (1 / n) * (big_r ** (1 + 1 / n) - r ** (1 + 1 / n))
    np.testing.assert_allclose(sol.velocity(r, z), expected, rtol=1e-13, atol=0)
    mean = 1e-9 / (math.pi * big_r**2)
    assert sol.velocity(0.0, z) == pytest.approx(mean * (3 * n + 1) / (n + 1), rel=1e-12)


def test_chunked_sweep_equals_one_call(monkeypatch):
    import sys

    solve_module = sys.modules["tubefsi.solve"]  # the module, shadowed by the function on the package

    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.linspace(0, 1e-8, 301).reshape(7, 43)
    whole = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    monkeypatch.setattr(solve_module, "CHUNK", 50)
    parts = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    assert parts.pressure_drop.shape == q.shape
    np.testing.assert_allclose(parts.pressure_drop, whole.pressure_drop, rtol=1e-14, atol=0)
    back = tubefsi.solve(fluid, wall, TUBE, pressure_drop=whole.pressure_drop)
    np.testing.assert_allclose(back.flow_rate, q, rtol=1e-12, atol=0)


def test_loose_ode_near_the_maximum_flow_rate_warns_instead_of_silently_erring():
    """LSODA at SciPy's default rtol = 1e-3 is 30 % off in displacement at 99 % of q_max: it must say so."""
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = 0.99 * tubefsi.max_flow_rate(fluid, wall, TUBE)
    exact = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    with pytest.warns(tubefsi.AccuracyWarning, match="estimated relative error"):
        loose = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, coupler=ODE(rtol=1e-3, atol=1e-6))
    assert abs(loose.inlet_displacement / exact.inlet_displacement - 1) > 1e-2   # the warning was deserved
    with pytest.raises(tubefsi.NoSteadyStateError):
        tubefsi.solve(fluid, wall, TUBE, flow_rate=1.01 * q / 0.99, coupler=ODE())


def test_stiffening_wall_max_flow_rate_is_inf_without_a_spurious_warning():
    """Exponential fibres (thin HGO, reference thickness) have no limit pressure: the law's
    representable end (pressure 1.3e266 Pa at stretch 6) is not one, and the flow rate that would
    reach it is beyond double range. ``inf`` comes back, and no AccuracyWarning about the
    integral up to that end (its estimate cannot matter for a q_max that overflows)."""
    import warnings

    wall = walls["thin-hgo"](shear_modulus=3000.0, fibre_stiffness=2363.2, fibre_exponent=0.8393,
                             fibre_angle=math.radians(29.0), thickness_convention="reference")
    assert wall.limit_pressure(TUBE.reduced_thickness) > 1e250
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.AccuracyWarning)
        assert tubefsi.max_flow_rate(rheologies["power-law"](consistency=0.017, index=0.7), wall, TUBE) == math.inf
