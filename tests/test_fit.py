"""Parameter fitting: exact data are recovered exactly, noisy data within the stated uncertainty."""

import importlib.util
import pathlib

import numpy as np
import pytest

import tubefsi
from tubefsi.registry import rheologies, walls

EXAMPLE = pathlib.Path(__file__).parents[1] / "examples" / "fit_synthetic.py"


def _example():
    spec = importlib.util.spec_from_file_location("fit_synthetic", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_noise_free_data_are_recovered_to_solver_precision():
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    true_fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    true_wall = walls["thin-mooney-rivlin"](c1=1.5e3, c2=-0.5e3)
    q = np.geomspace(1e-10, 5e-9, 12)
    dp = tubefsi.solve(true_fluid, true_wall, tube, flow_rate=q).pressure_drop
    start_wall = walls["thin-mooney-rivlin"](c1=3e3, c2=-0.5e3)
    result = tubefsi.fit(q, dp, true_fluid, start_wall, tube, parameters=["wall.c1"])
    assert result.success
    assert result.parameters["wall.c1"] == pytest.approx(1.5e3, rel=1e-9)
    assert result.wall.c2 == -0.5e3            # unfitted parameters stay as given
    assert np.max(np.abs(result.residuals)) < 1e-10


def test_synthetic_noisy_data_recover_known_parameters_within_three_standard_errors():
    module = _example()
    result = module.run(None)
    for name, true in module.TRUE.items():
        se = result.standard_errors[name]
        assert 0 < se < 0.2 * abs(true)
        assert abs(result.parameters[name] - true) < 3 * se
    assert result.wall.shear_modulus == result.parameters["wall.shear_modulus"]


def test_bad_fit_requests_raise():
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q, dp = np.array([1e-10, 2e-10, 3e-10]), np.array([10.0, 20.0, 30.0])
    with pytest.raises(tubefsi.InvalidParameterError, match="parameters"):
        tubefsi.fit(q, dp, fluid, wall, tube, parameters=["wall.youngs_modulus"])
    with pytest.raises(tubefsi.InvalidParameterError, match="parameters"):
        tubefsi.fit(q, dp, fluid, wall, tube, parameters=["shear_modulus"])
    with pytest.raises(tubefsi.InvalidParameterError):
        tubefsi.fit(q, -dp, fluid, wall, tube, parameters=["wall.shear_modulus"])
    with pytest.raises(tubefsi.InvalidParameterError, match="fewer"):
        tubefsi.fit(q, dp, fluid, wall, tube,
                    parameters=["wall.shear_modulus", "rheology.index", "rheology.consistency"])


@pytest.mark.parametrize("wall", [walls["thick-neo-hookean"](shear_modulus=2e3),
                                  walls["thin-fung"](shear_modulus=1e3, stiffening=20.0),
                                  walls["thick-fung"](shear_modulus=1e3, stiffening=20.0)], ids=repr)
def test_a_start_hint_changes_the_start_not_the_answer(wall):
    """``start_hint`` (a fit's previous solution as the start of the next solve) against the
    solve without it: the same answers to 1e-13 from a good hint, a poor one (ten times off, zero,
    NaN) and one for other flow rates (ignored); the error-controlled iteration decides."""
    from tubefsi.couplers.separated import start_hint

    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = rheologies["power-law"](consistency=0.01, index=0.8)
    q_max = tubefsi.max_flow_rate(fluid, wall, tube)
    q = np.geomspace(0.02, 0.7, 20) * (q_max if np.isfinite(q_max) else 5e-9)
    other = rheologies["power-law"](consistency=0.0101, index=0.8003)     # a fit's next trial point
    plain = tubefsi.solve(other, wall, tube, flow_rate=q, on_infeasible="nan")
    near = tubefsi.solve(fluid, wall, tube, flow_rate=q, on_infeasible="nan").state.log_stretch
    poor = near.copy()
    poor[::3], poor[1::3], poor[2::3] = 10.0 * near[::3], 0.0, np.nan
    for hint_q, hint_v in ((q, near), (q, poor), (1.5 * q, near)):
        with start_hint(hint_q, hint_v):
            hinted = tubefsi.solve(other, wall, tube, flow_rate=q, on_infeasible="nan")
        np.testing.assert_allclose(hinted.pressure_drop, plain.pressure_drop, rtol=1e-13, atol=0)
        np.testing.assert_allclose(hinted.inlet_displacement, plain.inlet_displacement, rtol=1e-13, atol=0)


def test_a_fit_with_start_hints_finds_the_optimum_of_one_without():
    """fit passes each solve the previous solution as its start (start_hint); with the hint
    switched off the optimum is the same to 1e-7, a 1e-5 part of its standard error (the solves
    differ in their last bits, the path of the iteration with them, and three correlated
    parameters amplify that)."""
    import tubefsi.couplers.separated as engine
    fit_module = importlib.import_module("tubefsi.fit")
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid, wall = rheologies["power-law"](consistency=0.017, index=0.7), walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.geomspace(0.02, 0.7, 20) * tubefsi.max_flow_rate(fluid, wall, tube)
    dp = tubefsi.solve(fluid, wall, tube, flow_rate=q).pressure_drop * np.exp(
        0.01 * np.random.default_rng(3).standard_normal(q.size))
    names = ["wall.shear_modulus", "rheology.consistency", "rheology.index"]
    start = (rheologies["power-law"](consistency=0.03, index=0.6), walls["thick-neo-hookean"](shear_modulus=3e3))
    hinted = tubefsi.fit(q, dp, *start, tube, parameters=names)
    real = fit_module.start_hint
    try:
        fit_module.start_hint = lambda *args: engine.contextlib.nullcontext()
        unhinted = tubefsi.fit(q, dp, *start, tube, parameters=names)
    finally:
        fit_module.start_hint = real
    for name in names:
        assert hinted.parameters[name] == pytest.approx(unhinted.parameters[name], rel=1e-7)
        assert abs(hinted.parameters[name] - unhinted.parameters[name]) <= 1e-5 * unhinted.standard_errors[name]
