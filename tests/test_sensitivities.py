"""Sensitivities of a solve (``docs/theory.md``, section "Sensitivities") against finite differences.

Reference: Richardson-extrapolated central differences of independent solves (step h and h/2,
truncation O(h^4)); the bound allows the rounding of the solves, ~1e-14 / h relative.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import tubefsi
from tubefsi import Tube
from tubefsi.registry import rheologies, walls
from tubefsi.testing.profiles import scaled

TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
H = 1e-3
TOL = 1e-8     # 1e-14 / H (rounding of the solves), with a margin; truncation ~H^4 is far below


def _richardson(f, x, h):
    d1 = (f(x * (1 + h)) - f(x * (1 - h))) / (2 * h * x)
    d2 = (f(x * (1 + h / 2)) - f(x * (1 - h / 2))) / (h * x)
    return (4 * d2 - d1) / 3


PAIRS = [
    ("power-law", {"consistency": 0.01, "index": 0.8}, "thick-neo-hookean", {"shear_modulus": 2e3}),
    ("newtonian", {"viscosity": 1e-3}, "thin-neo-hookean", {"shear_modulus": 5e3}),
    ("carreau", rheologies["carreau"]._examples[0], "thick-neo-hookean", {"shear_modulus": 2e3}),
    ("bingham", rheologies["bingham"]._examples[0], "thick-mooney-rivlin", None),
    ("power-law", {"consistency": 0.01, "index": 1.4}, "rigid", {}),
]


def _models(pair):
    rname, rpar, wname, wpar = pair
    wall_cls = walls[wname]
    if wpar is None:
        wpar = wall_cls._examples[0]
    return rheologies[rname](**rpar), wall_cls(**wpar)


@pytest.mark.parametrize("pair", PAIRS, ids=lambda p: f"{p[0]}-{p[2]}")
@pytest.mark.parametrize("outlet_pressure", [0.0, 150.0])
def test_flow_controlled_slope(pair, outlet_pressure):
    rheo, wall = _models(pair)
    q = np.array([2e-10, 1e-9, 3e-9])
    sol = tubefsi.solve(rheo, wall, TUBE, flow_rate=q, outlet_pressure=outlet_pressure)

    def drop(x):
        return tubefsi.solve(rheo, wall, TUBE, flow_rate=x, outlet_pressure=outlet_pressure).pressure_drop

    reference = _richardson(drop, q, H)
    np.testing.assert_allclose(sol.dpressure_drop_dflow_rate, reference, rtol=TOL)
    # at a fixed outlet, dq/dp_in is the reciprocal
    np.testing.assert_allclose(sol.dflow_rate_dinlet_pressure * sol.dpressure_drop_dflow_rate, 1.0, rtol=1e-14)


@pytest.mark.parametrize("pair", PAIRS, ids=lambda p: f"{p[0]}-{p[2]}")
def test_pressure_controlled_sensitivities(pair):
    rheo, wall = _models(pair)
    p_out = 150.0
    dp = np.array([40.0, 120.0, 300.0])
    sol = tubefsi.solve(rheo, wall, TUBE, pressure_drop=dp, outlet_pressure=p_out)
    p_in = p_out + dp

    def q_of_inlet(x):
        return tubefsi.solve(rheo, wall, TUBE, pressure_drop=x - p_out, outlet_pressure=p_out).flow_rate

    def q_of_outlet(x):
        return tubefsi.solve(rheo, wall, TUBE, pressure_drop=p_in - x, outlet_pressure=x).flow_rate

    scale = np.abs(sol.dflow_rate_dinlet_pressure)
    np.testing.assert_allclose(sol.dflow_rate_dinlet_pressure, _richardson(q_of_inlet, p_in, H * 0.1),
                               rtol=TOL * 10)
    ref_out = _richardson(q_of_outlet, np.full(dp.shape, p_out), H * 0.1)
    assert np.all(np.abs(sol.dflow_rate_doutlet_pressure - ref_out) <= TOL * 10 * scale)
    assert np.all(sol.dflow_rate_doutlet_pressure < 0)


def test_outlet_and_inlet_sensitivities_differ_by_inflation():
    """A stiffer wall brings dq/dp_out toward -dq/dp_in (a rigid tube: exactly)."""
    rheo = rheologies["power-law"](consistency=0.01, index=0.8)
    gaps = []
    for mu in (2e3, 2e4, 2e5):
        sol = tubefsi.solve(rheo, walls["thick-neo-hookean"](shear_modulus=mu), TUBE, pressure_drop=100.0,
                            outlet_pressure=100.0)
        gaps.append(abs(sol.dflow_rate_doutlet_pressure / sol.dflow_rate_dinlet_pressure + 1))
    rigid = tubefsi.solve(rheo, walls["rigid"](), TUBE, pressure_drop=100.0, outlet_pressure=100.0)
    assert gaps[0] > gaps[1] > gaps[2] > 0
    assert rigid.dflow_rate_doutlet_pressure == pytest.approx(-rigid.dflow_rate_dinlet_pressure, rel=1e-14)


def test_separable_closed_form():
    """Power law in a rigid tube: dp/dq = n dp/q exactly."""
    n = 0.6
    rheo = rheologies["power-law"](consistency=0.02, index=n)
    sol = tubefsi.solve(rheo, walls["rigid"](), TUBE, flow_rate=np.geomspace(1e-12, 1e-8, 7))
    np.testing.assert_allclose(sol.dpressure_drop_dflow_rate, n * sol.pressure_drop / sol.flow_rate, rtol=1e-14)


def test_zero_flow_newtonian_limit():
    """q = 0: the uniform tube at the outlet radius, Hagen–Poiseuille 8 mu L / (pi R^4)."""
    mu, p_out = 1e-3, 200.0
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    sol = tubefsi.solve(rheologies["newtonian"](viscosity=mu), wall, TUBE, flow_rate=0.0, outlet_pressure=p_out)
    r_out = TUBE.radius * wall.stretch(p_out, TUBE.reduced_thickness)
    assert sol.dpressure_drop_dflow_rate == pytest.approx(8 * mu * TUBE.length / (math.pi * r_out**4), rel=1e-12)


def test_ode_coupler_uses_its_profile():
    """The interface's default (the flow index integrated over the coupler's own profile)."""
    rheo = rheologies["carreau"](**rheologies["carreau"]._examples[0])
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.array([1e-10, 1e-9])
    by_ode = tubefsi.solve(rheo, wall, TUBE, flow_rate=q, coupler="ode").dpressure_drop_dflow_rate
    by_default = tubefsi.solve(rheo, wall, TUBE, flow_rate=q).dpressure_drop_dflow_rate
    np.testing.assert_allclose(by_ode, by_default, rtol=1e-6)     # the ODE's own tolerance


@settings(deadline=None, max_examples=scaled(20))
@given(n=st.floats(0.4, 1.6), mu=st.floats(5e2, 5e4), q=st.floats(1e-11, 2e-9), p_out=st.floats(0.0, 500.0))
def test_slope_matches_differences_property(n, mu, q, p_out):
    rheo = rheologies["power-law"](consistency=0.01, index=n)
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    try:
        sol = tubefsi.solve(rheo, wall, TUBE, flow_rate=q * (1 + H), outlet_pressure=p_out)
    except tubefsi.NoSteadyStateError:
        return
    sol = tubefsi.solve(rheo, wall, TUBE, flow_rate=q, outlet_pressure=p_out)

    def drop(x):
        return tubefsi.solve(rheo, wall, TUBE, flow_rate=x, outlet_pressure=p_out).pressure_drop

    slope = sol.dpressure_drop_dflow_rate
    # the differences round at ~eps dp / (h q): relative eps / (h kappa), kappa = dln dp / dln q
    kappa = slope * q / sol.pressure_drop
    assert slope == pytest.approx(_richardson(drop, q, H), rel=TOL + 50 * np.finfo(float).eps / (H * kappa))


def test_broadcast_equals_scalars():
    rheo = rheologies["power-law"](consistency=0.01, index=np.array([0.7, 1.0, 1.3]))
    wall = walls["thick-neo-hookean"](shear_modulus=np.array([[1e3], [1e4]]))
    sol = tubefsi.solve(rheo, wall, TUBE, flow_rate=1e-9)
    d = sol.dpressure_drop_dflow_rate
    assert d.shape == (2, 3)
    for i, m in enumerate((1e3, 1e4)):
        for j, n in enumerate((0.7, 1.0, 1.3)):
            one = tubefsi.solve(rheologies["power-law"](consistency=0.01, index=n),
                                walls["thick-neo-hookean"](shear_modulus=m), TUBE, flow_rate=1e-9)
            assert d[i, j] == pytest.approx(one.dpressure_drop_dflow_rate, rel=1e-13)


PARAMETER_CASES = [
    ("power-law", {"consistency": 0.02, "index": 0.75}, "thick-neo-hookean", {"shear_modulus": 5e3},
     ["rheology.consistency", "rheology.index", "wall.shear_modulus"]),
    ("carreau", rheologies["carreau"]._examples[0], "thin-neo-hookean", {"shear_modulus": 5e3},
     ["rheology.zero_shear_viscosity", "rheology.relaxation_time", "rheology.index", "wall.shear_modulus"]),
    ("newtonian", {"viscosity": 1e-3}, "thin-linear", {"youngs_modulus": 5e4, "poisson_ratio": 0.45},
     ["rheology.viscosity", "wall.youngs_modulus"]),
]


@pytest.mark.parametrize("case", PARAMETER_CASES, ids=lambda c: f"{c[0]}-{c[2]}")
def test_parameter_derivatives_match_differences(case):
    """dDp/dtheta at fixed q (the fit's Jacobian) against Richardson differences of solves with
    the parameter perturbed (an independent computation: the solver run twice per step)."""
    import attrs

    rname, rpar, wname, wpar, names = case
    rheo, wall = rheologies[rname](**rpar), walls[wname](**wpar)
    q = np.array([1e-10, 1e-9])
    sol = tubefsi.solve(rheo, wall, TUBE, flow_rate=q)
    for name in names:
        owner, field = name.split(".")
        model = rheo if owner == "rheology" else wall

        def drop(x, owner=owner, field=field, model=model):
            changed = attrs.evolve(model, **{field: float(x)})
            return tubefsi.solve(changed if owner == "rheology" else rheo, changed if owner == "wall" else wall,
                                 TUBE, flow_rate=q).pressure_drop

        value = float(getattr(model, field))
        reference = _richardson(drop, value, H)
        np.testing.assert_allclose(sol.dpressure_drop_dparameter(name), reference, rtol=1e-8, err_msg=name)
    # all of them in one pass (the fit's Jacobian): each one's own call, to the bit
    together = sol._dpressure_drop_dparameters(names)
    for name, value in zip(names, together):
        assert np.array_equal(value, sol.dpressure_drop_dparameter(name)), name
    scalar = tubefsi.solve(rheo, wall, TUBE, flow_rate=1e-9)
    assert scalar._dpressure_drop_dparameters(names) == [scalar.dpressure_drop_dparameter(n) for n in names]


def test_parameter_derivative_rejects_what_it_cannot_do():
    rheo = rheologies["power-law"](consistency=0.02, index=0.75)
    sol = tubefsi.solve(rheo, walls["thin-linear"](youngs_modulus=5e4, poisson_ratio=0.45), TUBE, flow_rate=1e-9)
    with pytest.raises(tubefsi.InvalidParameterError, match="poisson_ratio"):
        sol.dpressure_drop_dparameter("wall.poisson_ratio")
    with pytest.raises(tubefsi.InvalidParameterError, match="rheology.nothing"):
        sol.dpressure_drop_dparameter("rheology.nothing")
    loaded = tubefsi.solve(rheo, walls["thick-neo-hookean"](shear_modulus=5e3), TUBE, flow_rate=1e-9,
                           outlet_pressure=100.0)
    with pytest.raises(tubefsi.InvalidParameterError, match="shear_modulus"):
        loaded.dpressure_drop_dparameter("wall.shear_modulus")
    assert loaded.dpressure_drop_dparameter("rheology.index") > 0
