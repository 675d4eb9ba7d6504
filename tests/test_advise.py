"""The advisor and the diagnostics, on scenes where the right answer is known."""

import math
import warnings

import pytest

import tubefsi
from tubefsi import ModelValidityWarning
from tubefsi.registry import rheologies, walls

BLOOD = rheologies["power-law"](consistency=0.017, index=0.7)


def _labels(advice):
    return [c.label for c in advice.candidates if c.relative_difference <= advice.tolerance]


def test_stiff_tube_rigid_suffices():
    tube = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
    stiff = walls["thick-neo-hookean"](shear_modulus=1e8)  # strain ~ 1e-5
    advice = tubefsi.advise(BLOOD, stiff, tube, flow_rate=1e-9)
    assert advice.recommended.label == "rigid wall"
    assert advice.recommended.relative_difference < 1e-3
    # the rigid answer is Hagen–Poiseuille for the power law, independently
    n, m, a, L = 0.7, 0.017, 1e-4, 1e-2
    hp = L * 2 * m * ((3 * n + 1) * 1e-9 / (math.pi * n)) ** n * a ** -(3 * n + 1)
    assert advice.recommended.pressure_drop == pytest.approx(hp, rel=1e-12)
    assert "recommended" in str(advice)


def test_soft_thick_tube_at_large_strain_needs_the_thick_hyperelastic_model():
    tube = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
    soft = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = 0.6 * tubefsi.max_flow_rate(BLOOD, soft, tube)
    advice = tubefsi.advise(BLOOD, soft, tube, flow_rate=q)
    assert advice.requested.wall is soft
    assert advice.recommended is advice.requested
    assert _labels(advice) == [advice.requested.label]   # only the thick hyperelastic model within 1 %
    by_label = {c.label.split(",")[0].split(" ")[0]: c for c in advice.candidates}
    assert by_label["rigid"].relative_difference > 1.0
    assert by_label["thick-linear"].relative_difference > 0.1
    assert advice.requested.pressure_drop == pytest.approx(
        tubefsi.solve(BLOOD, soft, tube, flow_rate=q).pressure_drop, rel=1e-14)


def test_small_strain_linear_suffices_and_newtonian_replaces_n_near_one():
    tube = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
    wall = walls["thick-neo-hookean"](shear_modulus=2e5)
    near_newtonian = rheologies["power-law"](consistency=3.5e-3, index=0.999)
    advice = tubefsi.advise(near_newtonian, wall, tube, flow_rate=2e-9, tolerance=0.01)
    assert advice.recommended.label.startswith("thick-linear")
    labels = [c.label for c in advice.candidates]
    assert any("newtonian" in lab for lab in labels)


def test_pressure_controlled_advice_matches_flow_controlled():
    tube = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    dp = tubefsi.solve(BLOOD, wall, tube, flow_rate=2e-9).pressure_drop
    a = tubefsi.advise(BLOOD, wall, tube, pressure_drop=dp)
    b = tubefsi.advise(BLOOD, wall, tube, flow_rate=2e-9)
    assert [c.label for c in a.candidates] == [c.label for c in b.candidates]
    assert a.requested.pressure_drop == pytest.approx(dp, rel=1e-12)


def test_diagnostics_flag_what_fails():
    soft = walls["thick-neo-hookean"](shear_modulus=2e3)
    tube = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
    q_max = tubefsi.max_flow_rate(BLOOD, soft, tube)
    sol = tubefsi.solve(BLOOD, soft, tube, flow_rate=0.95 * q_max)
    with pytest.warns(ModelValidityWarning, match="maximum flow rate"):
        diag = sol.diagnostics(density=1060.0)
    assert diag.flow_rate_fraction == pytest.approx(0.95, rel=1e-12)
    assert diag.inlet_pressure_fraction > 0.9
    assert diag.slenderness == pytest.approx(0.01)
    # Metzner–Reed Reynolds number, independently: Re = rho V^(2-n) D^n / (m 8^(n-1) ((3n+1)/4n)^n)
    n, m, a = 0.7, 0.017, 1e-4
    v = 0.95 * q_max / (math.pi * a**2)
    re = 1060.0 * v ** (2 - n) * (2 * a) ** n / (m * 8 ** (n - 1) * ((3 * n + 1) / (4 * n)) ** n)
    assert diag.reynolds_number == pytest.approx(re, rel=1e-12)


def test_diagnostics_quiet_when_assumptions_hold():
    tube = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
    sol = tubefsi.solve(BLOOD, walls["thick-neo-hookean"](shear_modulus=2e5), tube, flow_rate=1e-10)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        diag = sol.diagnostics(density=1060.0)
    assert diag.warnings == ()
    stubby = tubefsi.Tube(radius=1e-3, thickness=1e-3, length=2e-3)
    wide = tubefsi.solve(BLOOD, walls["thin-linear"](youngs_modulus=1e3, poisson_ratio=0.5), stubby, flow_rate=1e-4)
    msgs = " ".join(wide.diagnostics(warn=False).warnings)
    assert "slender" in msgs and "linear wall" in msgs


def test_diagnostics_quote_the_validity_maps_end_effect_error():
    """The expected modelling error of the pressure drop is the validity map's end-layer estimate
    (3n+1) eps_in (0.3 a + 0.2 t)/L, and it is within 25 % of what the finite-element reference
    measured (docs/validity_map.csv, written by examples/validity_map.py) for the map's thick-wall
    scenes at small strain and a/L <= 0.05."""
    import csv
    from pathlib import Path

    fluid = tubefsi.registry.rheologies["power-law"](consistency=1e-2, index=0.5)
    tube = tubefsi.Tube(radius=1e-3, thickness=3e-4, length=4e-2)
    sol = tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=1e4), tube, flow_rate=1e-7)
    diag = sol.diagnostics(warn=False)
    eps = sol.inlet_displacement / 1e-3
    assert diag.expected_model_error == pytest.approx((3 * 0.5 + 1) * eps * (0.3e-3 + 0.2 * 3e-4) / 4e-2, rel=1e-9)
    assert "expected model error" in str(diag)
    path = Path(__file__).resolve().parents[1] / "docs" / "validity_map.csv"
    rows = [r for r in csv.DictReader(path.open()) if "thick" in r["scene"] and float(r["strain"]) <= 0.05
            and float(r["a_over_L"]) <= 0.05]
    assert len(rows) >= 12
    for r in rows:
        a_over_l, tb, n, strain = (float(r[k]) for k in ("a_over_L", "t_over_a", "n", "strain"))
        estimate = tubefsi.validity.end_effect_error(n, strain, 1.0, tb, 1.0 / a_over_l)
        assert estimate == pytest.approx(abs(float(r["error"])), rel=0.25), r["scene"]


def test_advice_quotes_the_validity_map():
    """advise reports the requested model's own end-effect error (docs/validity.md), the same
    number as the solution's diagnostics, and prints it."""
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    advice = tubefsi.advise(fluid, wall, tube, flow_rate=1e-9)
    expected = tubefsi.solve(fluid, wall, tube, flow_rate=1e-9).diagnostics(warn=False).expected_model_error
    assert 0 < advice.expected_model_error == pytest.approx(expected, rel=1e-12)
    assert "validity map" in str(advice)
