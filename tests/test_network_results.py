"""A network's results as arrays aligned with its tubes and nodes, O(1) per read, and its per-tube
table (issue 28, item 5).

References: rigid tubes carrying a Newtonian fluid in series and in parallel, whose flows,
pressure drops, wall shear stresses (4 mu q / (pi a^3)) and Reynolds numbers (rho V D / mu) are
Hagen–Poiseuille's in closed form; and for compliant tubes the single-tube solve of each tube
(its strains and wall shear stresses at both ends, ``Solution.radius`` and
``Solution.wall_shear_stress`` at z = 0 and z = L).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tubefsi import InvalidParameterError, Network, Tube
from tubefsi.registry import rheologies, walls

MU = 1.2e-3
NEWTONIAN = rheologies["newtonian"](viscosity=MU)
RIGID = walls["rigid"]()


def _resistance(tube):
    return 8 * MU * tube.length / (math.pi * tube.radius**4)


def _rigid_network():
    """in -> j (series), then j -> out through two parallel tubes of different radii."""
    t1 = Tube(radius=2e-4, thickness=5e-5, length=1e-2)
    t2 = Tube(radius=1e-4, thickness=5e-5, length=2e-2)
    t3 = Tube(radius=1.5e-4, thickness=5e-5, length=1.5e-2)
    net = Network(rheology=NEWTONIAN)
    net.add_tube("in", "j", RIGID, t1)
    net.add_tube("j", "out", RIGID, t2, name="thin")
    net.add_tube("j", "out", RIGID, t3, name="wide")
    net.set_pressure("in", 200.0).set_pressure("out", 20.0)
    return net, (t1, t2, t3)


def test_rigid_newtonian_table_against_hagen_poiseuille():
    net, (t1, t2, t3) = _rigid_network()
    result = net.solve()
    r1, r2, r3 = (_resistance(t) for t in (t1, t2, t3))
    r_total = r1 + 1 / (1 / r2 + 1 / r3)
    q = 180.0 / r_total
    p_j = 200.0 - q * r1
    expected_q = {("in", "j"): q, "thin": (p_j - 20.0) / r2, "wide": (p_j - 20.0) / r3}
    radii = {("in", "j"): t1.radius, "thin": t2.radius, "wide": t3.radius}
    drops = {("in", "j"): 200.0 - p_j, "thin": p_j - 20.0, "wide": p_j - 20.0}
    rho = 1050.0
    re = result.reynolds_numbers(rho)
    for name, qe in expected_q.items():
        i = result.tube_index[name]
        assert result.flow_rates[i] == pytest.approx(qe, rel=1e-12)
        assert result.pressure_drops[i] == pytest.approx(drops[name], rel=1e-12)
        a = radii[name]
        tau = 4 * MU * qe / (math.pi * a**3)
        assert result.wall_shear_stress_u[i] == pytest.approx(tau, rel=1e-12)
        assert result.wall_shear_stress_v[i] == pytest.approx(tau, rel=1e-12)
        assert result.strain_u[i] == 0.0 and result.strain_v[i] == 0.0
        velocity = qe / (math.pi * a**2)
        assert re[i] == pytest.approx(rho * velocity * 2 * a / MU, rel=1e-12)
    table = result.tube_table(density=rho)
    for column in ("pressure_drop", "strain_u", "strain_v", "wall_shear_stress_u", "wall_shear_stress_v",
                   "reynolds_number"):
        assert len(table[column]) == 3
    assert table["reynolds_number"] == re.tolist()
    assert "reynolds_number" not in result.tube_table()


def test_compliant_tubes_table_against_the_single_tube_solve():
    fluid = rheologies["power-law"](consistency=0.01, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    net = Network(rheology=fluid)
    net.add_tube("in", "j", wall, tube)
    net.add_tube("a", "j", wall, tube)              # its flow runs v -> u: both ends matter
    net.add_tube("j", "out", wall, Tube(radius=1.2e-4, thickness=3e-5, length=1e-2))
    net.set_pressure("in", 600.0).set_pressure("a", 500.0).set_pressure("out", 100.0)
    result = net.solve()
    for name in result.tube_names:
        i = result.tube_index[name]
        t = net._tubes[name]
        single = result.solution(name)            # oriented from the higher-pressure end
        forward = result.flow_rates[i] >= 0
        inlet, outlet = (result.strain_u[i], result.strain_v[i]) if forward else (result.strain_v[i],
                                                                                   result.strain_u[i])
        a, length = t.tube.radius, t.tube.length
        assert inlet == pytest.approx(float(single.radius(0.0)) / a - 1, rel=1e-9)
        assert outlet == pytest.approx(float(single.radius(length)) / a - 1, rel=1e-9)
        tau_in, tau_out = ((result.wall_shear_stress_u[i], result.wall_shear_stress_v[i]) if forward
                           else (result.wall_shear_stress_v[i], result.wall_shear_stress_u[i]))
        assert tau_in == pytest.approx(float(single.wall_shear_stress(0.0)), rel=1e-9)
        assert tau_out == pytest.approx(float(single.wall_shear_stress(length)), rel=1e-9)
        assert inlet > outlet > 0


def test_reading_is_o1_and_the_arrays_are_aligned_and_read_only():
    net, _ = _rigid_network()
    result = net.solve()
    # the mappings are built once per solution (they were rebuilt on every access: O(n) per read)
    assert result.flow_rate is result.flow_rate and result.pressure is result.pressure
    assert result.flow_rates is result.flow_rates and result.pressures is result.pressures
    for name, q in result.flow_rate.items():
        assert result.flow_rates[result.tube_index[name]] == q
    for node, p in result.pressure.items():
        assert result.pressures[result.node_index[node]] == p
    assert list(result.tube_index) == result.tube_names
    with pytest.raises(ValueError):
        result.flow_rates[0] = 0.0
    with pytest.raises(ValueError):
        result.pressures[0] = 0.0


def test_to_dataframe_tubes_and_nodes():
    pd = pytest.importorskip("pandas")
    net, _ = _rigid_network()
    result = net.solve()
    tubes = result.to_dataframe(density=1000.0)
    assert isinstance(tubes, pd.DataFrame) and len(tubes) == 3
    np.testing.assert_array_equal(tubes["flow_rate"].to_numpy(), result.flow_rates)
    np.testing.assert_array_equal(tubes["reynolds_number"].to_numpy(), result.reynolds_numbers(1000.0))
    assert tubes.attrs["units"]["wall_shear_stress_u"] == "Pa"
    nodes = result.to_dataframe("nodes")
    assert list(nodes["node"]) == result.nodes
    np.testing.assert_array_equal(nodes["pressure"].to_numpy(), result.pressures)
    assert nodes.attrs["units"]["pressure"] == "Pa"
    with pytest.raises(InvalidParameterError, match="table"):
        result.to_dataframe("edges")
    with pytest.raises(InvalidParameterError, match="density"):
        result.to_dataframe("nodes", density=1000.0)
    for bad in (0.0, -1.0, float("nan"), "water"):
        with pytest.raises(InvalidParameterError, match="density"):
            result.reynolds_numbers(bad)


def test_a_tube_without_flow_has_no_shear_and_no_reynolds_number():
    net = Network(rheology=NEWTONIAN)
    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    net.add_tube("in", "j", RIGID, tube)
    net.add_tube("j", "out", RIGID, tube)
    net.add_tube("j", "dead", RIGID, tube)
    net.set_pressure("in", 100.0).set_pressure("out", 0.0)
    result = net.solve()
    i = result.tube_index[("j", "dead")]
    main = result.tube_index[("in", "j")]
    assert result.wall_shear_stress_u[i] <= 1e-10 * result.wall_shear_stress_u[main]
    re = result.reynolds_numbers(1000.0)
    assert np.all(np.isfinite(re)) and re[i] <= 1e-10 * re[main]
