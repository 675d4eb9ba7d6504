"""Networks built from arrays (``Network.add_tubes``) and tubes removed (issue 28, item 5).

References: rigid tubes carrying a Newtonian fluid in parallel and in series, whose flows are
Hagen–Poiseuille's in closed form; and the same network built one tube at a time by
``add_tube`` (compliant walls, per-tube moduli, radii and external pressures), which must give
the same pressures and flows to rounding.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tubefsi import InvalidParameterError, Network, Tube
from tubefsi.registry import rheologies, walls

MU = 1e-3
NEWTONIAN = rheologies["newtonian"](viscosity=MU)
RIGID = walls["rigid"]()


def _conductance(a, length):
    return math.pi * np.asarray(a) ** 4 / (8 * MU * np.asarray(length))


def test_parallel_rigid_tubes_from_arrays_against_hagen_poiseuille():
    radii = np.array([1e-4, 1.5e-4, 2e-4, 0.7e-4])
    lengths = np.array([1e-2, 2e-2, 1.5e-2, 0.5e-2])
    net = Network(rheology=NEWTONIAN)
    net.add_tubes(["in"] * 4, ["out"] * 4, RIGID, Tube(radius=radii, thickness=3e-5, length=lengths),
                  names=["a", "b", "c", "d"])
    net.set_pressure("in", 150.0).set_pressure("out", 30.0)
    result = net.solve()
    np.testing.assert_allclose(result.flow_rates, 120.0 * _conductance(radii, lengths), rtol=1e-12)
    assert result.tube_names == ["a", "b", "c", "d"]
    # each tube's own single-tube solution is its entry of the arrays
    assert result.solution("c").flow_rate == pytest.approx(result.flow_rate["c"], rel=1e-12)
    assert result.solution("c").tube.radius == radii[2]


def test_remove_tube_against_hagen_poiseuille():
    radii = np.array([1e-4, 1.5e-4, 2e-4])
    net = Network(rheology=NEWTONIAN)
    net.add_tubes(["in"] * 3, ["out"] * 3, RIGID, Tube(radius=radii, thickness=3e-5, length=1e-2),
                  names=["a", "b", "c"])
    net.add_tube("out", "sink", RIGID, Tube(radius=3e-4, thickness=3e-5, length=1e-2))
    net.set_pressure("in", 100.0).set_pressure("sink", 0.0)
    net.remove_tube("b")
    result = net.solve()
    g = _conductance(radii[[0, 2]], 1e-2).sum()
    g_sink = float(_conductance(3e-4, 1e-2))
    q = 100.0 / (1 / g + 1 / g_sink)
    assert result.tube_names == ["a", "c", ("out", "sink")]
    assert result.flow_rate[("out", "sink")] == pytest.approx(q, rel=1e-12)
    assert result.flow_rate["a"] + result.flow_rate["c"] == pytest.approx(q, rel=1e-12)
    with pytest.raises(InvalidParameterError, match="name"):
        net.remove_tube("b")
    with pytest.raises(InvalidParameterError, match="name"):
        net.remove_tube(["not", "hashable"])


def test_a_node_left_without_tubes_leaves_with_its_boundary_condition():
    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    net = Network(rheology=NEWTONIAN)
    net.add_tube("in", "j", RIGID, tube).add_tube("j", "out", RIGID, tube).add_tube("j", "spur", RIGID, tube)
    net.set_pressure("in", 100.0).set_pressure("out", 0.0).set_pressure("spur", 10.0).set_position("spur", (1, 2))
    net.remove_tube(("j", "spur"))
    assert net.nodes == ["in", "j", "out"] and "spur" not in net.positions
    result = net.solve()                     # the two equal tubes in series split the drop evenly
    assert result.pressure["j"] == pytest.approx(50.0, rel=1e-12)


def test_bulk_equals_one_by_one_for_compliant_tubes():
    rng = np.random.default_rng(3)
    n = 14                                   # a binary tree: tube k from node (k - 1) // 2 to node k
    child = np.arange(1, n + 1)
    parent = (child - 1) // 2
    moduli = rng.uniform(3e3, 6e3, n)
    radii = rng.uniform(0.8e-4, 1.2e-4, n)
    p_e = rng.uniform(-20.0, 20.0, n)
    fluid = rheologies["power-law"](consistency=0.01, index=0.8)
    leaves = sorted(set(child.tolist()) - set(parent.tolist()))

    def finish(net):
        net.set_pressure(0, 400.0)
        for leaf in leaves:
            net.set_pressure(leaf, 50.0 + leaf)
        return net.solve()

    one = Network(rheology=fluid)
    for k in range(n):
        one.add_tube(int(parent[k]), int(child[k]), walls["thick-neo-hookean"](shear_modulus=moduli[k]),
                     Tube(radius=radii[k], thickness=3e-5, length=1e-2), external_pressure=p_e[k])
    bulk = Network(rheology=fluid)
    bulk.add_tubes(parent, child, walls["thick-neo-hookean"](shear_modulus=moduli),
                   Tube(radius=radii, thickness=3e-5, length=1e-2), external_pressure=p_e)
    a, b = finish(one), finish(bulk)
    assert a.tube_names == b.tube_names and a.nodes == b.nodes
    np.testing.assert_allclose(b.flow_rates, a.flow_rates, rtol=1e-13)
    np.testing.assert_allclose(b.pressures, a.pressures, rtol=1e-13)
    np.testing.assert_allclose(b.radius_u, a.radius_u, rtol=1e-13)
    # each bulk tube's models are its entries (networkx and single-tube solutions read them)
    pytest.importorskip("networkx")
    graph = bulk.to_networkx()
    edge = graph.edges[0, 1, (0, 1)]
    assert edge["wall"].shear_modulus == moduli[0] and edge["tube"].radius == radii[0]
    assert edge["external_pressure"] == p_e[0]


def test_batches_tubes_between_them_and_a_removal_inside_one_equal_one_by_one():
    # the tubes are stored per add_tubes / add_tube call: a network built from three calls, with a
    # tube removed from inside the first, must be the network built one tube at a time
    rng = np.random.default_rng(5)
    n = 14
    child = np.arange(1, n + 1)
    parent = (child - 1) // 2
    moduli = rng.uniform(3e3, 6e3, n)
    radii = rng.uniform(0.8e-4, 1.2e-4, n)
    fluid = rheologies["power-law"](consistency=0.01, index=0.8)
    leaves = sorted(set(child.tolist()) - set(parent.tolist()))

    def wall(mu):
        return walls["thick-neo-hookean"](shear_modulus=mu)

    def finish(net):
        net.set_pressure(0, 400.0)
        for leaf in leaves:
            net.set_pressure(leaf, 0.0)
        return net.solve()

    one = Network(rheology=fluid)
    for k in range(n):
        one.add_tube(int(parent[k]), int(child[k]), wall(moduli[k]), Tube(radius=radii[k], thickness=3e-5, length=1e-2))
    mixed = Network(rheology=fluid)
    first = list(range(7))
    mixed.add_tubes(parent[first].tolist() + [0], child[first].tolist() + [1], wall(np.append(moduli[first], 5e3)),
                    Tube(radius=np.append(radii[first], 1e-4), thickness=3e-5, length=1e-2),
                    names=[(int(parent[k]), int(child[k])) for k in first] + ["extra"])
    mixed.add_tube(int(parent[7]), int(child[7]), wall(moduli[7]), Tube(radius=radii[7], thickness=3e-5, length=1e-2))
    rest = list(range(8, n))
    mixed.add_tubes(parent[rest], child[rest], wall(moduli[rest]), Tube(radius=radii[rest], thickness=3e-5, length=1e-2))
    mixed.remove_tube("extra")
    a, b = finish(one), finish(mixed)
    assert a.tube_names == b.tube_names == mixed.tube_names and a.nodes == b.nodes
    np.testing.assert_allclose(b.flow_rates, a.flow_rates, rtol=1e-13)
    np.testing.assert_allclose(b.pressures, a.pressures, rtol=1e-13)
    # a tube asked for by name carries its own entries (the last batch's fourth tube: tube 11)
    name = (int(parent[11]), int(child[11]))
    assert mixed._tubes[name].models()[0].shear_modulus == moduli[11]
    assert b.solution(name).tube.radius == radii[11]
    assert b.solution(name).flow_rate == pytest.approx(a.flow_rate[name], rel=1e-12)


@pytest.mark.parametrize("call, parameter", [
    (lambda net, t: net.add_tubes(["a", "b"], ["b"], RIGID, t), "v"),
    (lambda net, t: net.add_tubes([], [], RIGID, t), "u"),
    (lambda net, t: net.add_tubes("ab", "bc", RIGID, t), "u"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "b"], RIGID, t), r"v\[1\]"),
    (lambda net, t: net.add_tubes(["a", "a"], ["b", "b"], RIGID, t), r"names\[1\]"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "c"], RIGID, t, names=["x"]), "names"),
    (lambda net, t: net.add_tubes([["a"], "b"], ["b", "c"], RIGID, t), r"u\[0\]"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "c"], RIGID,
                                  Tube(radius=np.full(3, 1e-4), thickness=3e-5, length=1e-2)), "tube"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "c"], walls["thick-neo-hookean"](shear_modulus=np.ones(3) * 4e3), t),
     "wall"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "c"], RIGID, t, external_pressure=[1.0, 2.0, 3.0]),
     "external_pressure"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "c"], RIGID, t, external_pressure=[1.0, np.nan]),
     "external_pressure"),
    (lambda net, t: net.add_tubes(["a", "b"], ["b", "c"], RIGID, "tube"), "tube"),
])
def test_bad_bulk_input_names_the_parameter_and_adds_nothing(call, parameter):
    net = Network(rheology=NEWTONIAN)
    net.add_tube("a", "b", RIGID, Tube(radius=1e-4, thickness=3e-5, length=1e-2), name="x")
    with pytest.raises(InvalidParameterError, match=parameter):
        call(net, Tube(radius=1e-4, thickness=3e-5, length=1e-2))
    assert net.tube_names == ["x"] and net.nodes == ["a", "b"]
