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
