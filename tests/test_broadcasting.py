"""Every parameter an array: models, tube fields, outlet pressure and load broadcast together.

The reference for every broadcast result is the loop of scalar solves it replaces (an
independent call per entry): a broadcast solve must equal them entry by entry.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.profiles import scaled

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)


def _pl(m, n):
    return rheologies["power-law"](consistency=m, index=n)


@settings(deadline=None, max_examples=scaled(15))
@given(st.lists(st.tuples(st.floats(1e3, 1e4), st.floats(0.01, 0.05), st.floats(0.5, 1.5),
                          st.floats(5e-5, 3e-4), st.floats(0.05, 1.0), st.floats(5e-3, 5e-2), st.floats(0.05, 0.9)),
                min_size=1, max_size=6),
       st.sampled_from(["thick-neo-hookean", "thin-neo-hookean", "thick-linear"]))
def test_broadcast_solve_equals_the_loop_of_scalar_solves(rows, wall_name):
    mu, m, n, a, tb, L, frac = (np.array(c) for c in zip(*rows))
    cls = walls[wall_name]
    wall = cls(shear_modulus=mu) if "linear" not in wall_name else cls(youngs_modulus=3 * mu, poisson_ratio=0.5)
    tube = tubefsi.Tube(radius=a, thickness=tb * a, length=L)
    fluid = _pl(m, n)
    # a flow rate below any maximum flow rate: a fraction of the rigid-tube flow at 0.3 mu t/a
    q = frac * fluid.flow_rate(a, 0.3 * mu * tb / L)
    together = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    assert together.pressure_drop.shape == (len(rows),)
    for i in range(len(rows)):
        w = cls(shear_modulus=mu[i]) if "linear" not in wall_name else cls(youngs_modulus=3 * mu[i], poisson_ratio=0.5)
        one = tubefsi.solve(_pl(m[i], n[i]), w, tubefsi.Tube(radius=a[i], thickness=tb[i] * a[i], length=L[i]),
                            flow_rate=q[i])
        assert isinstance(one.pressure_drop, float)
        assert together.pressure_drop[i] == pytest.approx(one.pressure_drop, rel=1e-13, abs=0)
        assert together.inlet_displacement[i] == pytest.approx(one.inlet_displacement, rel=1e-13, abs=0)
    back = tubefsi.solve(fluid, wall, tube, pressure_drop=together.pressure_drop)
    np.testing.assert_allclose(back.flow_rate, q, rtol=1e-12, atol=0)


def test_shapes_broadcast_like_numpy():
    wall = walls["thick-neo-hookean"](shear_modulus=np.array([1e3, 2e3, 4e3]))          # (3,)
    tube = tubefsi.Tube(radius=np.array([[1e-4], [2e-4]]), thickness=3e-5, length=1e-2)  # (2, 1)
    sol = tubefsi.solve(_pl(0.017, 0.7), wall, tube, flow_rate=1e-10)
    assert sol.pressure_drop.shape == (2, 3)
    for i, a in enumerate([1e-4, 2e-4]):
        for j, mu in enumerate([1e3, 2e3, 4e3]):
            ref = tubefsi.solve(_pl(0.017, 0.7), walls["thick-neo-hookean"](shear_modulus=mu),
                                tubefsi.Tube(radius=a, thickness=3e-5, length=1e-2), flow_rate=1e-10)
            assert sol.pressure_drop[i, j] == pytest.approx(ref.pressure_drop, rel=1e-13)
    # profiles broadcast z against the solution's shape
    p = sol.pressure(np.array([0.0, 5e-3, 1e-2])[:, None, None])
    assert p.shape == (3, 2, 3)
    np.testing.assert_allclose(p[0], sol.inlet_pressure, rtol=1e-12)
    np.testing.assert_array_equal(p[2], 0.0)


def test_outlet_pressure_array():
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    p_out = np.array([0.0, 50.0, 200.0])
    sol = tubefsi.solve(_pl(0.017, 0.7), wall, TUBE, flow_rate=1e-10, outlet_pressure=p_out)
    for i, p in enumerate(p_out):
        ref = tubefsi.solve(_pl(0.017, 0.7), wall, TUBE, flow_rate=1e-10, outlet_pressure=float(p))
        assert sol.pressure_drop[i] == pytest.approx(ref.pressure_drop, rel=1e-13)


def test_scalars_in_give_floats_out():
    sol = tubefsi.solve(_pl(0.017, 0.7), walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, flow_rate=1e-9)
    for name in ("pressure_drop", "flow_rate", "inlet_pressure", "inlet_displacement", "inlet_radius"):
        assert isinstance(getattr(sol, name), float), name
    assert isinstance(sol.pressure(1e-3), float)
    assert isinstance(walls["thick-neo-hookean"](shear_modulus=2e3).limit_pressure(0.3), float)


def test_bad_entries_are_named_with_their_index():
    with pytest.raises(tubefsi.InvalidParameterError, match=r"shear_modulus.*entry \(1,\)"):
        walls["thick-neo-hookean"](shear_modulus=np.array([1e3, -1.0, 2e3]))
    with pytest.raises(tubefsi.InvalidParameterError, match=r"radius.*entry \(0, 1\)"):
        tubefsi.Tube(radius=np.array([[1e-4, np.nan]]), thickness=3e-5, length=1e-2)
    with pytest.raises(tubefsi.InvalidParameterError, match="index"):
        rheologies["power-law"](consistency=0.01, index=np.array([0.5, 0.0]))
    with pytest.raises(tubefsi.InvalidParameterError, match="shear_modulus"):
        walls["thick-neo-hookean"](shear_modulus=np.array([1e3 + 1j]))
    with pytest.raises(tubefsi.InvalidParameterError, match="outlet_pressure"):
        tubefsi.solve(_pl(0.01, 0.7), "rigid", TUBE, flow_rate=1e-9, outlet_pressure=np.array([0.0, -1.0]))


def test_infeasible_points_are_nan_on_request():
    wall = walls["thick-neo-hookean"](shear_modulus=np.array([2e3, 4e3, 8e3]))
    fluid = _pl(0.017, 0.7)
    q_max = tubefsi.max_flow_rate(fluid, wall, TUBE)
    assert q_max.shape == (3,)
    q = 1.2 * q_max[0]                              # beyond the softest tube's maximum only
    with pytest.raises(tubefsi.NoSteadyStateError) as info:
        tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    assert info.value.limit == pytest.approx(q_max[0])
    sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, on_infeasible="nan")
    np.testing.assert_array_equal(sol.feasible, [False, True, True])
    assert np.isnan(sol.pressure_drop[0]) and np.all(np.isfinite(sol.pressure_drop[1:]))
    for i in (1, 2):
        ref = tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=float(wall.shear_modulus[i])), TUBE,
                            flow_rate=q)
        assert sol.pressure_drop[i] == pytest.approx(ref.pressure_drop, rel=1e-13)
    assert np.isnan(sol.pressure(0.0)[0])
    with pytest.raises(tubefsi.InvalidParameterError, match="on_infeasible"):
        tubefsi.solve(fluid, wall, TUBE, flow_rate=q, on_infeasible="ignore")


def test_walls_that_do_not_broadcast_are_solved_per_parameter_set():
    """A plugin wall whose hooks are scalar (a first-peak scan per parameter set) still takes arrays."""
    wall = walls["thick-yeoh"](c1=1e3, c2=np.array([-120.0, 50.0, -120.0]), c3=8.0)
    fluid = _pl(0.017, 0.7)
    sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-10)
    for i, c2 in enumerate([-120.0, 50.0, -120.0]):
        ref = tubefsi.solve(fluid, walls["thick-yeoh"](c1=1e3, c2=c2, c3=8.0), TUBE, flow_rate=1e-10)
        assert sol.pressure_drop[i] == pytest.approx(ref.pressure_drop, rel=1e-13)


def _rheology_cases():
    for name in sorted(rheologies):
        cls = rheologies[name]
        examples = [e for e in cls._examples if e]
        if len(examples) >= 2:
            yield pytest.param(cls, examples[0], examples[1], id=name)


@pytest.mark.parametrize("cls, first, second", list(_rheology_cases()))
def test_rheology_methods_broadcast_over_parameters(cls, first, second):
    """Every registered rheology: parameters given as arrays (two example sets stacked) give, entry
    by entry, what each parameter set gives alone, for every public method, zeros included."""
    keys = [k for k in first if k in second and isinstance(first[k], float) and isinstance(second[k], float)]
    if not keys:
        pytest.skip("no numeric parameters shared by two examples")
    stacked = {k: np.array([first[k], second[k]]) if k in keys else first[k] for k in first}
    try:
        both = cls(**stacked)
        alone = [cls(**first), cls(**{**first, **{k: second[k] for k in keys}})]
    except tubefsi.InvalidParameterError:
        pytest.skip("the mixed parameter set is not admissible")
    rate = np.array([[0.0], [3.0], [40.0]])
    radius, q = 1e-4, np.array([[0.0], [1e-10], [1e-9]])
    got = {"stress": both.stress(rate), "pressure_gradient": both.pressure_gradient(q, radius),
           "apparent_viscosity": both.apparent_viscosity(rate[1:])}
    for j, model in enumerate(alone):
        np.testing.assert_allclose(got["stress"][:, j], model.stress(rate[:, 0]), rtol=1e-14)
        np.testing.assert_allclose(got["pressure_gradient"][:, j], model.pressure_gradient(q[:, 0], radius),
                                   rtol=1e-13)
        np.testing.assert_allclose(got["apparent_viscosity"][:, j], model.apparent_viscosity(rate[1:, 0]),
                                   rtol=1e-14)
    g = both.pressure_gradient(1e-9, radius)
    assert g.shape == (2,)
    flow = both.flow_rate(radius, g)
    np.testing.assert_allclose(flow, 1e-9, rtol=1e-12)


def test_a_scalar_argument_with_array_parameters_in_the_generic_wall_paths():
    """The generic thick-wall integral, the thin law at small strain and the generic inverse take
    a scalar stretch or pressure with array parameters (they used to index one point only)."""
    from tubefsi.registry import walls
    moduli = np.array([1.0e3, 1.5e3, 2.0e3])
    for name, extra in (("thick-demiray", {"stiffening": 20.0}), ("thin-demiray", {"stiffening": 2.0})):
        wall = walls[name](shear_modulus=moduli, **extra)
        got = wall.pressure(1.05, 0.3)
        strain = wall.strain(50.0, 0.3)
        for i, mu in enumerate(moduli):
            one = walls[name](shear_modulus=float(mu), **extra)
            assert got[i] == one.pressure(1.05, 0.3)
            assert abs(strain[i] / one.strain(50.0, 0.3) - 1) <= 1e-15     # a root: to its last bits
        limit = wall.limit_pressure(0.3)
        assert np.shape(limit) == (3,)


def test_points_of_every_point_are_read_only_views_with_the_gathered_values():
    """Scene.at of all the points of a flat scene in order takes read-only views (no gather); any
    other index of the same size gathers; both give each point its own values."""
    from tubefsi.scene import make_scene
    mu = np.array([1e3, 2e3, 3e3, 4e3])
    scene = make_scene(rheologies["power-law"](consistency=np.array([0.01, 0.02, 0.03, 0.04]), index=0.7),
                       walls["thick-neo-hookean"](shear_modulus=mu),
                       tubefsi.Tube(radius=1e-4, thickness=np.array([1e-5, 2e-5, 3e-5, 4e-5]), length=1e-2))
    for column in (False, True):
        every = scene.at(np.arange(4), column=column)
        backwards = scene.at(np.arange(4)[::-1].copy(), column=column)
        shape = (4, 1) if column else (4,)
        for got, flipped, ref in ((every.wall.shear_modulus, backwards.wall.shear_modulus, mu),
                                  (every.tb, backwards.tb, np.array([0.1, 0.2, 0.3, 0.4])),
                                  (every.rheology.consistency, backwards.rheology.consistency,
                                   np.array([0.01, 0.02, 0.03, 0.04]))):
            assert got.shape == shape and not got.flags.writeable
            np.testing.assert_array_equal(got.ravel(), ref)
            np.testing.assert_array_equal(flipped.ravel(), ref[::-1])
    assert not np.shares_memory(backwards.wall.shear_modulus, scene.wall.shear_modulus)


def test_thick_neo_hookean_pressure_of_a_batch_is_its_entries():
    """The thick neo-Hookean law decides its far-strain branch by one reduction over the batch:
    an entry's value does not depend on what else is in the batch (strains past 1e154, where
    lam^2 - 1 overflows, and a NaN among them included)."""
    from tubefsi.registry import walls
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    strain = np.concatenate([np.geomspace(1e-12, 1e200, 300), [np.nan]])
    batch = wall._pressure_at_strain(strain, 0.3)
    alone = np.array([wall._pressure_at_strain(np.array([e]), 0.3)[0] for e in strain])
    np.testing.assert_array_equal(batch, alone)
    assert np.all(np.isfinite(batch[:-1])) and batch[-2] == pytest.approx(2e3 * np.log1p(0.3), rel=1e-12)
