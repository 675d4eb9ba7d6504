"""Results at the edge of validity are reported (``tubefsi.validity``), and solve and
max_flow_rate agree on the one limit. The thresholds are crossed from both sides on scenes
whose deformed state is known in closed form, independently of the solver."""

import math
import warnings

import numpy as np
import pytest

import tubefsi
from tubefsi import ModelValidityWarning, StretchRangeError
from tubefsi.cli import parse_model_spec
from tubefsi.registry import rheologies, walls

WATER = rheologies["newtonian"](viscosity=1e-3)
BLOOD = rheologies["power-law"](consistency=0.017, index=0.7)


def _validity_messages(call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = call()
    return result, [str(w.message) for w in caught if issubclass(w.category, ModelValidityWarning)]


def _thin_current_inlet_pressure(mu, tb, stretch):
    """Thin current-thickness neo-Hookean law, p = mu tb (1 - lam^-4) (docs/theory.md)."""
    return mu * tb * -math.expm1(-4.0 * math.log(stretch))


@pytest.mark.parametrize("ratio, warns", [(0.12, True), (0.08, False)])
def test_deformed_slenderness_from_both_sides(ratio, warns):
    a, L, mu = 5e-4, 1e-2, 1e3
    tube = tubefsi.Tube(radius=a, thickness=2e-5, length=L)
    wall = walls["thin-neo-hookean"](shear_modulus=mu, thickness_convention="current")
    dp = _thin_current_inlet_pressure(mu, tube.reduced_thickness, ratio * L / a)
    sol, msgs = _validity_messages(lambda: tubefsi.solve(WATER, wall, tube, pressure_drop=dp))
    assert sol.inlet_radius / L == pytest.approx(ratio, rel=1e-10)
    assert any("not slender" in m for m in msgs) == warns
    diag = sol.diagnostics(warn=False)
    assert diag.slenderness == pytest.approx(0.05)         # undeformed a/L: fine either way
    assert diag.deformed_slenderness == pytest.approx(ratio, rel=1e-10)
    assert any("not slender" in m for m in diag.warnings) == warns


@pytest.mark.parametrize("strain, warns", [(0.06, True), (0.04, False)])
def test_linear_wall_at_large_strain(strain, warns):
    tube = tubefsi.Tube(radius=1e-4, thickness=1e-5, length=1e-2)
    E, nu = 1e5, 0.4
    wall = walls["thin-linear"](youngs_modulus=E, poisson_ratio=nu)
    dp = strain * E * tube.reduced_thickness / (1.0 - nu / 2.0)      # lam = 1 + (1 - nu/2) p / (E tb)
    _, msgs = _validity_messages(lambda: tubefsi.solve(WATER, wall, tube, pressure_drop=dp))
    assert any("linear wall" in m for m in msgs) == warns


def test_calibrated_strain_of_a_user_law():
    class Calibrated(walls["thick-neo-hookean"]):
        calibrated_strain = 0.3

    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    dp = np.array([10.0, 500.0])               # the limit pressure is 2e3 ln(1.3) = 525 Pa
    sol, msgs = _validity_messages(lambda: tubefsi.solve(BLOOD, Calibrated(shear_modulus=2e3), tube, pressure_drop=dp))
    assert sol.inlet_displacement[0] / 1e-4 < 0.3 < sol.inlet_displacement[1] / 1e-4
    assert [m for m in msgs if "calibrated" in m] and "1 of 2 points" in msgs[0]


@pytest.mark.parametrize("q, warns", [(1.7e-9, True), (1.4e-9, False)])
def test_reduced_reynolds_number_with_a_density(q, warns):
    # rigid tube, Newtonian: Re a/L = rho V D / mu * a / L = 2 rho q / (pi mu L); 0.1 at q = 1.571e-9
    tube = tubefsi.Tube(radius=1e-4, thickness=1e-5, length=1e-2)
    expected = 2 * 1000.0 * q / (math.pi * 1e-3 * 1e-2)
    sol, msgs = _validity_messages(lambda: tubefsi.solve(WATER, "rigid", tube, flow_rate=q, density=1000.0))
    assert any("Reynolds" in m for m in msgs) == warns
    assert sol.diagnostics(warn=False).reduced_reynolds_number == pytest.approx(expected, rel=1e-12)
    _, quiet = _validity_messages(lambda: tubefsi.solve(WATER, "rigid", tube, flow_rate=q))
    assert quiet == []                         # no density, no Reynolds check


def test_the_documented_filter_silences_them():
    tube = tubefsi.Tube(radius=5e-4, thickness=1e-5, length=0.05)
    wall = walls["thin-neo-hookean"](shear_modulus=1e3, thickness_convention="current")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.filterwarnings("ignore", category=tubefsi.ModelValidityWarning)
        tubefsi.solve(WATER, wall, tube, flow_rate=1e-6)
    assert caught == []


def test_issue_scene_warns_then_refuses_beyond_the_solvers_range():
    """The issue's scene: Newtonian, thin current-thickness neo-Hookean, a = 0.5 mm, L = 5 cm."""
    tube = tubefsi.Tube(radius=5e-4, thickness=1e-5, length=0.05)
    wall = walls["thin-neo-hookean"](shear_modulus=1e3, thickness_convention="current")
    sol, msgs = _validity_messages(lambda: tubefsi.solve(WATER, wall, tube, flow_rate=1e-6))
    assert sol.inlet_radius > 1.0 and any("not slender" in m for m in msgs)
    assert tubefsi.max_flow_rate(WATER, wall, tube) == math.inf      # the one limit: none here
    with pytest.raises(StretchRangeError) as info:
        tubefsi.solve(WATER, wall, tube, flow_rate=1e-5)
    err = info.value
    assert isinstance(err, tubefsi.InvalidParameterError) and not isinstance(err, tubefsi.NoSteadyStateError)
    assert "not a physical limit" in str(err) and "max_flow_rate is inf" in str(err)
    # the range it states is the solver's: just inside it the inlet stretch approaches 1e15
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        near = tubefsi.solve(WATER, wall, tube, flow_rate=0.999 * err.limit)
    assert 1e13 < near.inlet_radius / 5e-4 <= 1e15


def test_advise_takes_an_array_of_loads():
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.array([0.0, 1e-10, 5e-10])
    advice = tubefsi.advise(BLOOD, wall, tube, flow_rate=q)
    for c in advice.candidates:
        if not c.note:
            dp = tubefsi.solve(c.rheology, c.wall, tube, flow_rate=q).pressure_drop
            np.testing.assert_allclose(c.pressure_drop, dp, rtol=1e-14)
            ref = tubefsi.solve(BLOOD, wall, tube, flow_rate=q[1:]).pressure_drop
            # (abs: the reference model as a candidate differs by rounding only, which depends on
            # the path each call shape takes; every solve is accurate to ~1e-14)
            assert c.relative_difference == pytest.approx(np.max(np.abs(dp[1:] / ref - 1)), rel=1e-12, abs=1e-13)
    single = tubefsi.advise(BLOOD, wall, tube, flow_rate=5e-10)
    # (abs: a candidate that is the reference model differs by the two solves' rounding only,
    # ~1e-15 on one path and 0 on another; each solve is accurate to ~1e-14)
    assert [c.relative_difference for c in single.candidates] == pytest.approx(
        [c.relative_difference for c in advice.candidates], rel=1e-12, abs=1e-13)
    assert "max rel. diff" in str(advice)
    with pytest.raises(tubefsi.InvalidParameterError, match="one scene"):
        tubefsi.advise(BLOOD, walls["thick-neo-hookean"](shear_modulus=[2e3, 3e3]), tube, flow_rate=1e-10)


def test_advise_labels_the_thin_convention_it_compares():
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    advice = tubefsi.advise(BLOOD, walls["thick-neo-hookean"](shear_modulus=2e3), tube, flow_rate=1e-10)
    thin = [c for c in advice.candidates if c.label.startswith("thin-")]
    assert {c.wall.thickness_convention for c in thin} == {"current", "reference"}
    for c in thin:        # the label is the spec of the very wall compared
        name, params = parse_model_spec(c.label.split(" ")[0])
        assert walls[name](shear_modulus=2e3, **params) == c.wall


def test_a_network_warns_once_for_its_result_not_per_newton_iteration():
    short = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=2e-3)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    net = tubefsi.Network(rheology=BLOOD)
    net.add_tube("a", "b", wall, short, name="ab")
    net.add_tube("b", "c", wall, short, name="bc")
    net.add_tube("b", "c", "rigid", short, name="bc2")
    net.set_pressure("a", 520.0)               # near the limit pressure 2e3 ln(1.3) = 525 Pa
    net.set_pressure("c", 0.0)
    result, msgs = _validity_messages(net.solve)
    assert len(msgs) == 1 and "tube 'ab'" in msgs[0] and "not slender" in msgs[0]
    # the tube it names is the one past R/L = 0.1, from the network's own radii
    assert result.flow_rate["ab"] > 0
