"""Batches of scenes in tubefsi.evolve: arrays of scene parameters broadcast to the scenes' shape
and are integrated as one system (shared output times, cells and integrator tolerance, the
Jacobian block-diagonal). Each scene of a batch is checked against the same scene run alone."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi.testing.profiles import scaled

L = 1e-2
TIMES = np.linspace(0.0, 0.02, 6)


def _fluid(index=0.7):
    return tubefsi.registry.rheologies["power-law"](consistency=0.017, index=index)


def _wall(modulus=2e4):
    return tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=modulus)


def _tube(length=L, radius=1e-4):
    return tubefsi.Tube(radius=radius, thickness=0.3 * radius, length=length)


# (batch arguments, the scene k's arguments): fluid, wall, tube, evolve keywords
BATCHES = {
    "inlet-pressures": (
        lambda: (_fluid(), _wall(), _tube(), dict(inlet_pressure=np.array([1e3, 2e3, 4e3]))),
        lambda k: (_fluid(), _wall(), _tube(), dict(inlet_pressure=[1e3, 2e3, 4e3][k]))),
    "lengths-by-index": (
        lambda: (_fluid(np.array([0.6, 0.8, 1.0])), _wall(), _tube(np.array([[0.5 * L], [L]])),
                 dict(inlet_pressure=2e3, outlet="closed")),
        lambda k: (_fluid([0.6, 0.8, 1.0][k % 3]), _wall(), _tube([0.5 * L, L][k // 3]),
                   dict(inlet_pressure=2e3, outlet="closed"))),
    "moduli-external-radii": (
        lambda: (_fluid(), _wall(np.array([1e4, 3e4])), _tube(radius=np.array([1e-4, 1.5e-4])),
                 dict(inlet_pressure=2e3, outlet_pressure=np.array([0.0, 500.0]), external_pressure=np.array([-200.0, 100.0]))),
        lambda k: (_fluid(), _wall([1e4, 3e4][k]), _tube(radius=[1e-4, 1.5e-4][k]),
                   dict(inlet_pressure=2e3, outlet_pressure=[0.0, 500.0][k], external_pressure=[-200.0, 100.0][k]))),
    "pumps-into-chamber-graded": (
        lambda: (_fluid(), tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=lambda z: 2e4 * (1 + z / L)),
                 tubefsi.Tube.tapered(length=L, radius=1.2e-4, outlet_radius=0.8e-4, thickness=3.6e-5),
                 dict(inlet_flow_rate=np.array([1e-11, 3e-11]), initial=np.array([0.0, 300.0]),
                      outlet=tubefsi.Chamber.linear(1e-9, 1e-13))),
        None),
}


def _alone(name, k, batch_args):
    """Scene k alone: the same models and tube objects where they are shared (a graded tube's
    profiles compare by identity), the scene's numbers otherwise."""
    single = BATCHES[name][1]
    if single is not None:
        return single(k)
    fluid, wall, tube, kwargs = batch_args
    return fluid, wall, tube, dict(inlet_flow_rate=[1e-11, 3e-11][k], initial=[0.0, 300.0][k], outlet=kwargs["outlet"])


@pytest.mark.parametrize("name", [pytest.param(b, marks=[pytest.mark.slow] if b == "lengths-by-index" else [])
                                  for b in BATCHES])
def test_each_scene_is_the_scene_alone(name):
    """Every scene of a batch against the same scene run alone (one run each, 16 cells, integrator
    tolerance 1e-12). The batch's time steps are shared (chosen for all scenes at once), so the
    two runs are not the same arithmetic: they differ by the integrator's error, not bit for bit
    (test_one_scene_in_an_array_keeps_the_bits). Measured, relative to the scene's largest value:
    the pressures 8e-13 to 2e-11, radii and stored volumes 2e-16 to 4e-12, the flows 5e-15 to 3e-12
    (3e-10 inside a pumped tube, where the flow is the difference of two cells' pressures);
    asserted 1e-9. The batch's arrays have the scenes' axes first."""
    fluid, wall, tube, kwargs = BATCHES[name][0]()
    run = dict(cells=16, rtol=1e-12, error_control=False)
    batch = tubefsi.evolve(fluid, wall, tube, TIMES, **kwargs, **run)
    assert batch.flow_faces.shape == batch.shape + (TIMES.size, 17)
    assert batch.pressure_nodes.shape == batch.radius_nodes.shape == batch.shape + (TIMES.size, 18)
    assert batch.inlet_flow_rate.shape == batch.stored_volume().shape == batch.shape + (TIMES.size,)
    assert batch.z.shape == batch.shape + (18,)
    for k in range(int(np.prod(batch.shape))):
        f, w, t, kw = _alone(name, k, (fluid, wall, tube, kwargs))
        alone = tubefsi.evolve(f, w, t, TIMES, **kw, **run)
        scene = batch.scene(int(k))
        assert scene.shape == ()
        np.testing.assert_array_equal(scene.z, alone.z)
        for field in ("flow_faces", "pressure_nodes", "radius_nodes", "stored"):
            mine, theirs = getattr(scene, field), getattr(alone, field)
            assert np.max(np.abs(mine - theirs)) <= 1e-9 * np.max(np.abs(theirs)), (field, k)


def test_one_scene_in_an_array_keeps_the_bits():
    """A batch of one scene (arrays of one entry) is the scalar run bit for bit (the same
    arithmetic with a scene axis of length 1, the same steps)."""
    run = dict(outlet="closed", cells=16, rtol=1e-8, error_control=False)
    alone = tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=2e3, **run)
    batch = tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=[2e3], **run)
    assert batch.shape == (1,)
    for field in ("flow_faces", "pressure_nodes", "radius_nodes", "stored", "volume_in"):
        np.testing.assert_array_equal(getattr(batch, field)[0], getattr(alone, field))


def test_error_controlled_batch_agrees_with_each_scene():
    """With error control the batch refines for its worst scene (its estimate is the largest over
    the scenes); each scene's inlet flow agrees with the error-controlled run alone within the two
    estimates, and each scene conserves mass."""
    p = np.array([1e3, 3e3])
    batch = tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=p, rtol=1e-4)
    assert batch.error_estimate <= 1e-4
    assert batch.mass_error <= 1e-8
    for k, pk in enumerate(p):
        alone = tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=pk, rtol=1e-4)
        scale = np.max(np.abs(alone.inlet_flow_rate[1:]))
        gap = np.max(np.abs(batch.inlet_flow_rate[k, 1:] - alone.inlet_flow_rate[1:])) / scale
        assert gap <= batch.error_estimate + alone.error_estimate


def test_pump_batch_stores_what_it_delivers():
    """Pumps of three flow rates into closed tubes: each scene's stored volume grows by exactly its
    rate times t (mass conservation per scene, to the Newton tolerance)."""
    rates = np.array([1e-11, 5e-11, 1e-10])
    r = tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_flow_rate=rates, outlet="closed", cells=16,
                       rtol=1e-6, error_control=False)
    stored = r.stored_volume() - r.stored_volume()[:, :1]
    np.testing.assert_allclose(stored, rates[:, None] * TIMES, rtol=0, atol=1e-6 * rates[-1] * TIMES[-1])


def test_batch_refusals():
    """What a batch does not do is refused with the parameter named: a starting Solution, the
    methods of one scene on a batch (fields at (z, t), export, plots), a scene index outside it,
    and arrays of parameters of a wall whose hooks do not broadcast."""
    tube = _tube()
    steady = tubefsi.solve(_fluid(), _wall(), tube, pressure_drop=1e3)
    with pytest.raises(tubefsi.InvalidParameterError) as info:
        tubefsi.evolve(_fluid(), _wall(), tube, TIMES, inlet_pressure=[1e3, 2e3], initial=steady)
    assert info.value.parameter == "initial"
    r = tubefsi.evolve(_fluid(), _wall(), tube, TIMES, inlet_pressure=[1e3, 2e3], cells=8, error_control=False)
    for call in (lambda: r.pressure(0.0, 0.01), lambda: r.to_csv("x.csv"), r.plot, lambda: r.stored_volume(0.01)):
        with pytest.raises(tubefsi.InvalidParameterError) as info:
            call()
        assert info.value.parameter == "scene"
    for bad in (2, -1, (0, 1), True):
        with pytest.raises(tubefsi.InvalidParameterError):
            r.scene(bad)
    yeoh = tubefsi.registry.walls["thick-yeoh"](c1=[1e3, 2e3], c2=50.0, c3=2.0)
    with pytest.raises(tubefsi.InvalidParameterError, match="c1") as info:
        tubefsi.evolve(_fluid(), yeoh, tube, TIMES, inlet_pressure=1e3)
    assert info.value.parameter == "wall"


@pytest.mark.parametrize("case", ["batch-chamber", "graded-pump"])
def test_jacobian_of_batches_and_graded_tubes(case):
    """The analytic Jacobian (block-diagonal for a batch; per-cell tube laws and face radii for a
    graded tube) against central differences of the right-hand side at a non-uniform state."""
    import importlib

    evolve_module = importlib.import_module("tubefsi.evolve")
    if case == "batch-chamber":
        args = (_fluid(np.array([0.6, 1.0])), _wall(np.array([2e4, 5e4])), _tube(np.array([L, 2 * L])), [0.0, 1.0],
                np.array([2e3, 1e3]), None, None, tubefsi.Chamber(volume=lambda p: 1e-9 + 1e-13 * p + 1e-17 * p**2),
                np.array([0.0, 100.0]), None, 1e-6, "BDF", 6)
    else:
        wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=lambda z: 2e4 * (1 + z / L))
        args = (_fluid(), wall, tubefsi.Tube.tapered(length=L, radius=1.2e-4, outlet_radius=0.6e-4, thickness=4e-5),
                [0.0, 1.0], None, 1e-10, None, "closed", 0.0, None, 1e-6, "BDF", 12)
    system, _, y0_of, _, _ = evolve_module._setup(*args)
    n, m = system.n, system.size
    y = y0_of(system).reshape(system.scenes, m)
    y[:, :n] = 0.01 + 0.03 * (1.0 + np.sin(np.arange(n) + np.arange(system.scenes)[:, None]))
    if case == "batch-chamber":
        y[:, n] = [700.0, 300.0]
    y = y.reshape(-1)
    exact = system.jacobian(0.3, y).toarray()
    differences = np.zeros_like(exact)
    for k in range(y.size):
        if k % m >= m - 2:                         # (the counters' columns are zero)
            continue
        step = 1e-6 * max(abs(y[k]), 1e-2 if k % m < n else 1e3)
        e = np.zeros(y.size)
        e[k] = step
        differences[:, k] = (system.rhs(0.3, y + e) - system.rhs(0.3, y - e)) / (2 * step)
    assert np.max(np.abs(exact - differences)) <= 1e-6 * np.max(np.abs(differences))


@settings(deadline=None, max_examples=scaled(8))
@given(p_shape=st.sampled_from([(), (2,), (3, 1)]), length_shape=st.sampled_from([(), (1,), (2,), (1, 2)]),
       pump=st.booleans())
def test_shapes_broadcast(p_shape, length_shape, pump):
    """Contract: the scenes' shape is the broadcast of the parameters' shapes (NumPy's rules), the
    fields and histories carry it first, and scene(k) of every flat k is one scene with that
    scene's length (a shared callable of t at the outlet)."""
    shape = np.broadcast_shapes(p_shape, length_shape)
    value = np.full(p_shape, 1e-11 if pump else 1e3)
    lengths = np.full(length_shape, L) * (1.0 + np.arange(int(np.prod(length_shape))).reshape(length_shape))
    inlet = dict(inlet_flow_rate=value) if pump else dict(inlet_pressure=value)
    r = tubefsi.evolve(_fluid(), _wall(), _tube(lengths if length_shape else L), TIMES[:3], cells=4, rtol=1e-4,
                       error_control=False, outlet_pressure=lambda t: 10.0 * t, **inlet)
    assert r.shape == shape
    assert r.pressure_nodes.shape == shape + (3, 6) and r.flow_faces.shape == shape + (3, 5)
    assert r.inlet_pressure.shape == r.stored_volume().shape == shape + (3,)
    for k in range(int(np.prod(shape))) if shape else ():
        one = r.scene(k)
        assert one.z[-1] == np.broadcast_to(lengths if length_shape else L, shape).ravel()[k]
        np.testing.assert_array_equal(one.inlet_flow_rate, r.inlet_flow_rate.reshape(-1, 3)[k])


def test_a_bad_entry_is_named():
    """A non-finite entry of an array of scene values is refused naming the parameter and the entry."""
    with pytest.raises(tubefsi.InvalidParameterError, match=r"entry \(1,\)") as info:
        tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=[1e3, np.nan, 2e3])
    assert info.value.parameter == "inlet_pressure"
    with pytest.raises(tubefsi.InvalidParameterError, match=r"entry \(0, 1\)") as info:
        tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=1e3, external_pressure=[[0.0, np.inf]])
    assert info.value.parameter == "external_pressure"


@pytest.mark.parametrize("outlet", ["open", "chamber", "pump-closed"])
def test_steady_state_and_settling_of_a_batch(outlet):
    """The steady state, its stored volume and the settling times of a batch (one solve of the
    scenes' shape, the volumes and times as arrays) are each scene's own: against scene(k)'s
    (the one-scene methods: a solve and a quadrature per scene) to rounding."""
    fluid = _fluid(np.array([0.6, 1.0]))
    tube = _tube(np.array([[L], [2 * L]]))
    if outlet == "pump-closed":
        kwargs = dict(inlet_flow_rate=lambda t: 1e-10 * (t < 0.01), outlet="closed")
    else:
        kwargs = dict(inlet_pressure=2e3, outlet=tubefsi.Chamber.linear(1e-9, 1e-13) if outlet == "chamber" else "open")
    r = tubefsi.evolve(fluid, _wall(), tube, np.linspace(0.0, 0.2, 21), cells=16, rtol=1e-6, error_control=False,
                       **kwargs)
    assert r.shape == (2, 2)
    volume, times = r.steady_volume(), r.settling_time(0.9)
    assert volume.shape == times.shape == (2, 2)
    steady = r.steady()
    for k in range(4):
        one = r.scene(k)
        assert volume.ravel()[k] == pytest.approx(one.steady_volume(), rel=1e-13)
        assert times.ravel()[k] == pytest.approx(one.settling_time(0.9), rel=1e-12)
        if outlet == "open":
            assert steady.flow_rate.ravel()[k] == pytest.approx(one.steady().flow_rate, rel=1e-13)
        else:
            assert steady is None


def test_validity_of_a_batch_names_the_scene():
    """With density, the validity check runs per scene: water (Womersley ~ 7 on this time scale)
    beside glycerol (quasi-steady) warns naming the water's scene."""
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=np.array([1.0, 1e-3]))
    wall = tubefsi.registry.walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5, end_condition="open")
    tube = tubefsi.Tube(radius=1e-4, thickness=1e-5, length=1e-2)
    with pytest.warns(tubefsi.ModelValidityWarning, match=r"Womersley.*scene \(1,\)"):
        tubefsi.evolve(fluid, wall, tube, np.linspace(0.0, 4e-3, 11), inlet_pressure=1e-3, density=1e3, cells=16,
                       rtol=1e-2, error_control=False)


def test_a_scene_beyond_the_wall_is_named():
    """The pressure bounds are checked per scene (the thick neo-Hookean wall at t/a = 0.3: buckling
    below -246 Pa, a limit pressure 5.2 kPa from its tube law): the error names the scene."""
    with pytest.raises(tubefsi.BucklingError, match=r"scene \(1,\) of shape \(2,\)"):
        tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=[1e3, -1e9])
    with pytest.raises(tubefsi.NoSteadyStateError, match=r"scene \(0, 1\) of shape \(1, 2\)"):
        tubefsi.evolve(_fluid(), _wall(), _tube(), TIMES, inlet_pressure=[[1e3, 1e9]])
