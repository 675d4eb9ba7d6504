"""Boundary conditions of a network (issue 28, item 2): fixed pressures and inflows at any number
of nodes, and resistance outlets, q = (p - p_d) / R at a node.

References: a resistance outlet after a rigid Newtonian tube is a series circuit
(Hagen–Poiseuille in closed form); after a compliant tube it is Kirchhoff's law at the outlet
node, p_out - p_d = R Q(p_in - p_out; p_out) with the single-tube law, solved here by Brent's
method; and a rigid Newtonian diamond with a cross edge under mixed boundary conditions (an
inflow, a fixed pressure, two resistance outlets to different distal pressures) is a linear
Kirchhoff system solved here in mpmath at 30 digits.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import tubefsi
from tubefsi import InvalidParameterError, Network, Tube
from tubefsi.registry import rheologies, walls

MU = 1e-3
NEWTONIAN = rheologies["newtonian"](viscosity=MU)
RIGID = walls["rigid"]()
TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
R_TUBE = 8 * MU * TUBE.length / (math.pi * TUBE.radius**4)


@pytest.mark.parametrize("distal", [0.0, 30.0])
def test_a_resistance_outlet_is_a_series_rigid_tube(distal):
    r = 0.7 * R_TUBE
    # pressure-driven
    net = Network(rheology=NEWTONIAN).add_tube("in", "out", RIGID, TUBE)
    net.set_pressure("in", 200.0).set_resistance("out", r, distal_pressure=distal)
    result = net.solve()
    q = (200.0 - distal) / (R_TUBE + r)
    assert result.flow_rate[("in", "out")] == pytest.approx(q, rel=1e-12)
    assert result.pressure["out"] == pytest.approx(distal + q * r, rel=1e-12)
    assert result.node_table()["inflow"][1] == pytest.approx(-q, rel=1e-12)   # what the outlet takes
    # inflow-driven: no fixed pressure anywhere, the resistance anchors the network
    net = Network(rheology=NEWTONIAN).add_tube("in", "out", RIGID, TUBE)
    net.set_inflow("in", 1e-9).set_resistance("out", r, distal_pressure=distal)
    result = net.solve()
    assert result.pressure["out"] == pytest.approx(distal + 1e-9 * r, rel=1e-12)
    assert result.pressure["in"] == pytest.approx(distal + 1e-9 * (r + R_TUBE), rel=1e-12)


@pytest.mark.parametrize("driven", ["pressure", "inflow"])
def test_a_resistance_outlet_after_a_compliant_tube_against_brent(driven):
    fluid = rheologies["power-law"](consistency=0.01, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    r, p_d = 2e12, 50.0
    net = Network(rheology=fluid).add_tube("in", "j", wall, TUBE).add_tube("j", "out", wall, TUBE)
    net.set_resistance("out", r, distal_pressure=p_d)
    if driven == "pressure":
        p_in = 600.0
        net.set_pressure("in", p_in)
        result = net.solve()

        def mismatch(p_out):            # Kirchhoff at "out": the tubes' flow is the resistance's
            q = tubefsi.solve(fluid, wall, Tube(radius=TUBE.radius, thickness=TUBE.thickness, length=2 * TUBE.length),
                              pressure_drop=p_in - p_out, outlet_pressure=p_out).flow_rate
            return q - (p_out - p_d) / r

        p_out = brentq(mismatch, p_d, p_in, xtol=1e-14, rtol=1e-15)
        assert result.pressure["out"] == pytest.approx(p_out, rel=1e-11)
    else:
        q = 2e-10
        net.set_inflow("in", q)
        result = net.solve()
        p_out = p_d + q * r
        single = tubefsi.solve(fluid, wall, Tube(radius=TUBE.radius, thickness=TUBE.thickness, length=2 * TUBE.length),
                               flow_rate=q, outlet_pressure=p_out)
        assert result.pressure["out"] == pytest.approx(p_out, rel=1e-12)
        assert result.pressure["in"] == pytest.approx(single.inlet_pressure, rel=1e-11)


def test_mixed_boundary_conditions_on_a_diamond_with_a_cross_edge_against_mpmath():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 30
    radii = {("s", "a"): 1.2e-4, ("s", "b"): 0.8e-4, ("a", "b"): 0.6e-4, ("a", "t"): 1e-4, ("b", "t"): 1.1e-4,
             ("t", "o1"): 1e-4, ("b", "o2"): 0.9e-4}
    inflow, p_fixed = 3e-10, 20.0
    outlets = {"o1": (3e11, 10.0), "o2": (5e11, 40.0)}
    net = Network(rheology=NEWTONIAN)
    for (u, v), a in radii.items():
        net.add_tube(u, v, RIGID, Tube(radius=a, thickness=3e-5, length=1e-2))
    net.add_tube("t", "fix", RIGID, TUBE)
    net.set_inflow("s", inflow).set_pressure("fix", p_fixed)
    for node, (r, p_d) in outlets.items():
        net.set_resistance(node, r, distal_pressure=p_d)
    result = net.solve()
    # the independent Kirchhoff solve: conductances in mpmath, G p = b over the unknown nodes
    edges = {e: mp.pi * mp.mpf(a) ** 4 / (8 * mp.mpf(MU) * mp.mpf("1e-2")) for e, a in radii.items()}
    edges[("t", "fix")] = mp.pi * mp.mpf(TUBE.radius) ** 4 / (8 * mp.mpf(MU) * mp.mpf(TUBE.length))
    unknown = ["s", "a", "b", "t", "o1", "o2"]
    at = {n: i for i, n in enumerate(unknown)}
    G = mp.zeros(6, 6)
    b = mp.zeros(6, 1)
    b[at["s"]] = mp.mpf(inflow)
    for (u, v), g in edges.items():
        for x, y in ((u, v), (v, u)):
            if x in at:
                G[at[x], at[x]] += g
                if y in at:
                    G[at[x], at[y]] -= g
                else:
                    b[at[x]] += g * mp.mpf(p_fixed)
    for node, (r, p_d) in outlets.items():
        G[at[node], at[node]] += 1 / mp.mpf(r)
        b[at[node]] += mp.mpf(p_d) / mp.mpf(r)
    p = mp.lu_solve(G, b)
    for node in unknown:
        assert result.pressure[node] == pytest.approx(float(p[at[node]]), rel=1e-11)
    cross = edges[("a", "b")] * (p[at["a"]] - p[at["b"]])
    assert result.flow_rate[("a", "b")] == pytest.approx(float(cross), rel=1e-9, abs=1e-22)
    # every outlet takes what its resistance says
    table = result.node_table()
    for node, (r, p_d) in outlets.items():
        i = result.nodes.index(node)
        assert table["inflow"][i] == pytest.approx(-(result.pressure[node] - p_d) / r, rel=1e-12)


def test_resistance_input_and_conflicts():
    net = Network(rheology=NEWTONIAN).add_tube("in", "out", RIGID, TUBE)
    for bad in (0.0, -1.0, float("nan"), float("inf"), "big"):
        with pytest.raises(InvalidParameterError, match="resistance"):
            net.set_resistance("out", bad)
    with pytest.raises(InvalidParameterError, match="distal_pressure"):
        net.set_resistance("out", 1e10, distal_pressure=float("nan"))
    net.set_resistance("out", 1e10).set_resistance("out", 2e10)        # replaces
    with pytest.raises(InvalidParameterError, match="one boundary condition"):
        net.set_pressure("out", 1.0)
    with pytest.raises(InvalidParameterError, match="one boundary condition"):
        net.set_inflow("out", 1e-9)
    net.set_pressure("in", 5.0)
    with pytest.raises(InvalidParameterError, match="one boundary condition"):
        net.set_resistance("in", 1e10)
    with pytest.raises(InvalidParameterError, match="no tube"):
        Network(rheology=NEWTONIAN).add_tube("in", "out", RIGID, TUBE).set_pressure("in", 1.0) \
            .set_resistance("elsewhere", 1e10).solve()


def test_resistances_round_trip_through_networkx():
    pytest.importorskip("networkx")
    net = Network(rheology=NEWTONIAN).add_tube("in", "out", RIGID, TUBE)
    net.set_pressure("in", 100.0).set_resistance("out", 3e11, distal_pressure=5.0)
    again = Network.from_networkx(net.to_networkx(), rheology=NEWTONIAN)
    np.testing.assert_array_equal(again.solve().pressures, net.solve().pressures)


def test_resistance_outlets_are_equivalent_series_tubes():
    """Two inlets (a fixed pressure, an inflow) and three resistance outlets, each with its own R
    and distal pressure, on a compliant power-law network with a cycle, against the same network
    with each resistance replaced by a rigid Newtonian tube of Poiseuille resistance
    8 mu L / (pi a^4) = R ending at a node fixed at the distal pressure (the edge law instead of
    the outlet term): the same pressures and flows to 1e-11."""
    fluid = rheologies["power-law"](consistency=0.01, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    edges = [("p", "a"), ("q", "a"), ("a", "b"), ("a", "c"), ("b", "c"), ("b", "o1"), ("c", "o2"), ("c", "o3")]
    outlets = {"o1": (3e12, 0.0), "o2": (5e12, 40.0), "o3": (8e12, 10.0)}
    length = 1e-2

    def build(with_tubes):
        net = Network(rheology=fluid)
        for k, (u, v) in enumerate(edges):
            net.add_tube(u, v, wall, Tube(radius=1e-4 * (1 + 0.1 * k), thickness=3e-5, length=length))
        net.set_pressure("p", 400.0).set_inflow("q", 2e-9)
        for node, (r, p_d) in outlets.items():
            if with_tubes:         # a rigid tube of resistance r: a = (8 mu L / (pi r))^(1/4)
                a = (8 * MU * length / (math.pi * r)) ** 0.25
                net.add_tube(node, node + "'", RIGID, Tube(radius=a, thickness=0.3 * a, length=length),
                             rheology=NEWTONIAN)
                net.set_pressure(node + "'", p_d)
            else:
                net.set_resistance(node, r, distal_pressure=p_d)
        return net.solve()

    plain, series = build(False), build(True)
    for node in plain.nodes:
        assert series.pressure[node] == pytest.approx(plain.pressure[node], rel=1e-11, abs=1e-9)
    for name in plain.tube_names:
        assert series.flow_rate[name] == pytest.approx(plain.flow_rate[name], rel=1e-11, abs=1e-11 * 2e-9)
    for node, (r, p_d) in outlets.items():
        assert series.flow_rate[(node, node + "'")] == pytest.approx((plain.pressure[node] - p_d) / r, rel=1e-11)


def test_inflow_beyond_what_the_resistance_outlets_take_is_no_steady_state():
    """Without a fixed pressure all the inflow leaves by the resistance outlets, each taking at most
    (p_lim - p_d)/R (p_lim = mu ln(1 + t/a), the thick neo-Hookean limit pressure in closed form):
    an inflow beyond the sum raises NoSteadyStateError at once with that capacity; below it, a
    steady state."""
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    limit = 4e3 * math.log1p(0.3)
    outlets = {"a": (2e12, 10.0), "b": (5e12, 0.0)}
    capacity = sum((limit - p_d) / r for r, p_d in outlets.values())

    def network(q):
        net = Network(rheology=rheologies["power-law"](consistency=0.01, index=0.7))
        net.add_tube("in", "j", wall, TUBE).add_tube("j", "a", wall, TUBE).add_tube("j", "b", wall, TUBE)
        for node, (r, p_d) in outlets.items():
            net.set_resistance(node, r, distal_pressure=p_d)
        return net.set_inflow("in", q)

    with pytest.raises(tubefsi.NoSteadyStateError, match="resistance outlets") as info:
        network(1.01 * capacity).solve()
    assert info.value.limit == pytest.approx(capacity, rel=1e-14)
    result = network(0.3 * capacity).solve()
    assert sum((result.pressure[n] - p_d) / r for n, (r, p_d) in outlets.items()) == pytest.approx(0.3 * capacity,
                                                                                                  rel=1e-12)


def test_bulk_boundary_conditions_are_the_single_ones():
    """set_pressures, set_inflows and set_resistances give the network that the single setters
    give (the same solution, bit for bit), and check their input before setting any."""
    fluid = rheologies["power-law"](consistency=0.01, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)

    def tree():
        net = Network(rheology=fluid)
        for u, v in (("r", "j"), ("j", "a"), ("j", "b"), ("r", "k"), ("k", "c"), ("k", "d"), ("s", "r")):
            net.add_tube(u, v, wall, TUBE)
        return net

    single = tree().set_pressure("a", 10.0).set_pressure("b", 20.0).set_inflow("s", 1e-10).set_inflow("k", 2e-11)
    single.set_resistance("c", 1e12, 5.0).set_resistance("d", 2e12, 0.0)
    bulk = tree().set_pressures(["a", "b"], np.array([10.0, 20.0])).set_inflows(["s", "k"], [1e-10, 2e-11])
    bulk.set_resistances(np.array(["c", "d"]), [1e12, 2e12], distal_pressures=[5.0, 0.0])
    one, many = single.solve(), bulk.solve()
    assert np.array_equal(one.pressures, many.pressures)
    assert np.array_equal(one.flow_rates, many.flow_rates)
    net = tree()
    with pytest.raises(InvalidParameterError, match="pressures"):
        net.set_pressures(["a", "b"], [1.0, -2.0])
    with pytest.raises(InvalidParameterError, match="length 2"):
        net.set_pressures(["a", "b"], [1.0, 2.0, 3.0])
    with pytest.raises(InvalidParameterError, match=r"nodes\[2\].*not named earlier"):
        net.set_pressures(["a", "b", "a"], [0.0, 1.0, 5.0])    # the last value once won silently
    net.set_inflows(["a"], 1e-12)
    with pytest.raises(InvalidParameterError, match="inflow already"):
        net.set_pressures(["b", "a"], 1.0)
    assert "b" not in net._pressure                   # nothing set
