"""The edges of a solution's accessors, ``select_coupler`` and ``fit`` (issue 25): shapes a profile
takes, the maximum flow rate and feasibility of broadcast solutions, sweeps through the maximum
flow rate, and the checks and warnings of a fit.

References: each broadcast answer against the scalar solves of its points (the broadcasting
contract, DESIGN §1.3); the fit's warnings against fits whose outcome is known by construction
(synthetic data from known parameters).
"""

from __future__ import annotations

import pathlib
import re
import warnings

import numpy as np
import pytest

import tubefsi
from tubefsi.registry import rheologies, walls

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
WALL = walls["thick-neo-hookean"](shear_modulus=2e3)
LOADS = np.array([1e-10, 2e-10, 3e-10])


@pytest.fixture(scope="module")
def curve():
    return tubefsi.solve(FLUID, WALL, TUBE, flow_rate=LOADS)


# ----------------------------------------------------------------------------- profile shapes
@pytest.mark.parametrize("method", ["pressure", "radius", "displacement", "pressure_gradient", "wall_shear_stress"])
def test_a_z_that_does_not_broadcast_names_z_and_the_shapes(curve, method):
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        getattr(curve, method)(np.linspace(0.0, TUBE.length, 5))
    assert info.value.parameter == "z"
    assert "(3,)" in str(info.value) and "z[:, None]" in str(info.value)


def test_a_column_of_positions_gives_every_point_at_every_position(curve):
    z = np.linspace(0.0, TUBE.length, 5)
    table = curve.pressure(z[:, None])
    assert table.shape == (5, 3)
    for j, q in enumerate(LOADS):           # reference: the scalar solve of each load
        np.testing.assert_allclose(table[:, j], tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q).pressure(z),
                                   rtol=1e-13, atol=0)


def test_a_radius_that_does_not_broadcast_names_r(curve):
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        curve.velocity(np.linspace(0.0, 5e-5, 4), 0.0)
    assert info.value.parameter == "r"
    assert curve.velocity(np.linspace(0.0, 5e-5, 4)[:, None], 0.0).shape == (4, 3)


# ----------------------------------------------------------------------------- max flow rate, feasible
@pytest.mark.parametrize("kind", ["modulus", "outlet", "radius"])
def test_max_flow_rate_of_a_broadcast_solution_is_the_array_of_its_scenes(kind):
    moduli, outlets, radii = [2e3, 3e3], [0.0, 40.0], [1e-4, 1.2e-4]
    if kind == "modulus":
        sol = tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=moduli), TUBE, flow_rate=1e-10)
        scalars = [tubefsi.max_flow_rate(FLUID, walls["thick-neo-hookean"](shear_modulus=m), TUBE) for m in moduli]
    elif kind == "outlet":
        sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-10, outlet_pressure=outlets)
        scalars = [tubefsi.max_flow_rate(FLUID, WALL, TUBE, outlet_pressure=p) for p in outlets]
    else:
        tubes = [tubefsi.Tube(radius=a, thickness=3e-5, length=1e-2) for a in radii]
        sol = tubefsi.solve(FLUID, WALL, tubefsi.Tube(radius=radii, thickness=3e-5, length=1e-2), flow_rate=1e-10)
        scalars = [tubefsi.max_flow_rate(FLUID, WALL, t) for t in tubes]
    assert np.shape(sol.max_flow_rate) == (2,)
    np.testing.assert_array_equal(sol.max_flow_rate, scalars)


def test_max_flow_rate_without_a_limit_is_inf_for_every_outlet_pressure():
    wall = walls["thin-linear"](**walls["thin-linear"]._examples[0])
    got = tubefsi.max_flow_rate(FLUID, wall, TUBE, outlet_pressure=[0.0, 10.0])
    scalars = [tubefsi.max_flow_rate(FLUID, wall, TUBE, outlet_pressure=p) for p in (0.0, 10.0)]
    assert scalars == [np.inf, np.inf]            # the documented answer: every flow rate has a steady state
    np.testing.assert_array_equal(got, scalars)


def test_feasible_is_always_a_boolean_array_of_the_results_shape(curve):
    scalar = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-10)
    assert isinstance(scalar.feasible, np.ndarray) and scalar.feasible.shape == () and scalar.feasible
    assert curve.feasible.dtype == bool and curve.feasible.shape == (3,) and curve.feasible.all()
    grid = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=LOADS[:, None] * [1.0, 2.0])
    assert grid.feasible.shape == (3, 2)


def test_a_sweep_through_the_maximum_flow_rate_never_aborts():
    q_max = tubefsi.max_flow_rate(FLUID, WALL, TUBE)
    ulps = q_max * (1.0 + np.arange(-64, 65) * 2.0**-52)          # within its accuracy of q_max
    for q in (np.linspace(0.1, 1.5, 15) * q_max, ulps):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
            sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q, on_infeasible="nan")
        below, above = q < q_max * (1 - 1e-9), q > q_max * (1 + 1e-9)
        assert sol.feasible[below].all() and not sol.feasible[above].any()
        assert np.isfinite(sol.pressure_drop[sol.feasible]).all() and np.isnan(sol.pressure_drop[~sol.feasible]).all()
    for q in ulps[::16]:                                            # one point at a time, as a loop does
        sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=float(q), on_infeasible="nan")
        assert bool(sol.feasible) == bool(np.isfinite(sol.pressure_drop))


# ----------------------------------------------------------------------------- select_coupler
def test_select_coupler_takes_models_as_solve_does():
    expected = tubefsi.solve(FLUID, "rigid", TUBE, flow_rate=1e-10).coupler_name
    assert tubefsi.registry.couplers.name_of(tubefsi.select_coupler(FLUID, "rigid")) == expected
    assert tubefsi.select_coupler(FLUID, walls["rigid"]) is not None                  # a class with defaults
    for rheology, wall, named in ((None, WALL, "rheology"), (FLUID, None, "wall"), ("no-such-fluid", WALL, "rheology"),
                                  ("power-law", WALL, "rheology")):                  # (needs parameters)
        with pytest.raises(tubefsi.InvalidParameterError) as info:
            tubefsi.select_coupler(rheology, wall)
        assert info.value.parameter == named


# ----------------------------------------------------------------------------- fit
Q = np.linspace(1e-10, 5e-10, 20)
NAMES = ["rheology.consistency", "rheology.index", "wall.shear_modulus"]


@pytest.fixture(scope="module")
def data():
    drop = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=Q).pressure_drop
    return Q, drop * (1 + 0.01 * np.random.default_rng(0).standard_normal(Q.size))


@pytest.mark.parametrize("parameters", [None, [1], [], 5, ["wall.shear_modulus", "wall.shear_modulus"],
                                        ["wall"], ["wall.no_such_field"]])
def test_fit_names_a_bad_parameter_list(data, parameters):
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        tubefsi.fit(*data, FLUID, WALL, TUBE, parameters=parameters)
    assert info.value.parameter == "parameters"


def test_fit_from_a_good_start_does_not_warn_and_a_single_name_is_one_parameter(data):
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.FitWarning)
        result = tubefsi.fit(*data, rheologies["power-law"](consistency=0.03, index=0.6),
                             walls["thick-neo-hookean"](shear_modulus=3e3), TUBE, parameters=NAMES)
        one = tubefsi.fit(*data, FLUID, walls["thick-neo-hookean"](shear_modulus=3e3), TUBE,
                          parameters="wall.shear_modulus")
    assert result.success and abs(result.parameters["rheology.index"] - 0.7) < 0.1     # synthetic: n = 0.7
    assert list(one.parameters) == ["wall.shear_modulus"]


@pytest.mark.parametrize("start, words", [((1e4, 0.2, 2e3), "not determined by the data"),
                                          ((1e-6, 0.95, 1e5), "edge of its search range")])
def test_fit_from_a_poor_start_warns_and_says_what_to_try(data, start, words):
    with pytest.warns(tubefsi.FitWarning, match=words) as record:
        tubefsi.fit(*data, rheologies["power-law"](consistency=start[0], index=start[1]),
                    walls["thick-neo-hookean"](shear_modulus=start[2]), TUBE, parameters=NAMES)
    assert "Try starting values closer to the data" in str(record[0].message)


# ----------------------------------------------------------------------------- the results page
def test_the_results_pages_snippets_run(tmp_path, monkeypatch):
    """docs/results.md: its Python blocks, in order, in one namespace (the profile snippet once
    passed 5 positions to a solution of 3 points)."""
    pytest.importorskip("xarray")
    pytest.importorskip("pandas")
    text = (pathlib.Path(__file__).parents[1] / "docs" / "results.md").read_text()
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        for block in re.findall(r"```python\n(.*?)```", text, flags=re.S):
            exec(compile(block, "docs/results.md", "exec"), namespace)
    assert namespace["sol"].velocity(namespace["r"], namespace["z"]).shape == (4, 5)
