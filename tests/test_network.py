"""Networks of soft tubes (``docs/network.md``): exact identities, an mpmath reference, errors.

References: the identities are exact properties of Kirchhoff's law with the single-tube law (a
tube cut in series is the tube, identical parallel tubes share the flow, a symmetric tree splits
evenly, mass balances at every node), checked against :func:`tubefsi.solve` of the single tube
and against the network's own symmetry. The Y bifurcation is checked against an independent
mpmath computation: single-tube laws of thick neo-Hookean tubes and a power-law fluid written in
``tubefsi.testing.reference`` (``L phi(q) = a^k [J(lam_in) - J(lam_out)]``, ``docs/theory.md``),
with the junction pressure found by a bracketed root finder at 30 digits.
"""

from __future__ import annotations

import json
import warnings
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import tubefsi
from tubefsi import ConvergenceError, InvalidParameterError, Network, NoSteadyStateError, Tube
from tubefsi.registry import rheologies, walls
from tubefsi.testing.profiles import scaled

FLUID = rheologies["power-law"](consistency=0.01, index=0.8)
WALL = walls["thick-neo-hookean"](shear_modulus=4e3)
TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
LIMIT = 4e3 * math.log1p(0.3)              # thick neo-Hookean limit pressure mu ln(1 + t/a)

fluids = st.builds(lambda m, n: rheologies["power-law"](consistency=m, index=n),
                   st.floats(0.002, 0.05), st.floats(0.5, 1.3))
moduli = st.floats(2e3, 2e4)


def _throughput(result):
    table = result.node_table()
    return sum(max(x, 0.0) for x in table["inflow"])


def _worst_balance(result):
    """The largest mass imbalance of a free node over the throughput, from the flows alone."""
    net = result.net
    bal = {node: net._inflow.get(node, 0.0) for node in result.nodes}
    for name, t in net._tubes.items():
        bal[t.u] -= result.flow_rate[name]
        bal[t.v] += result.flow_rate[name]
    return max(abs(bal[n]) for n in result.nodes if n not in net._pressure) / _throughput(result)


# ---------------------------------------------------------------------------- identities
@settings(max_examples=scaled(12), deadline=None)
@given(fluid=fluids, mu=moduli, k=st.integers(2, 4), f_in=st.floats(0.1, 0.8), f_out=st.floats(0.0, 0.5))
def test_a_tube_cut_in_series_is_the_tube(fluid, mu, k, f_in, f_out):
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    limit = mu * math.log1p(0.3)
    p_out = f_out * f_in * limit
    p_in = f_in * limit
    net = Network(rheology=fluid)
    piece = Tube(radius=TUBE.radius, thickness=TUBE.thickness, length=TUBE.length / k)
    for j in range(k):
        net.add_tube(j, j + 1, wall, piece)
    net.set_pressure(0, p_in).set_pressure(k, p_out)
    result = net.solve()
    whole = tubefsi.solve(fluid, wall, TUBE, pressure_drop=p_in - p_out, outlet_pressure=p_out)
    for j in range(k):
        assert result.flow_rate[(j, j + 1)] == pytest.approx(whole.flow_rate, rel=1e-11)
    # the cut points sit on the single tube's pressure profile
    z = np.arange(1, k) * TUBE.length / k
    np.testing.assert_allclose([result.pressure[j] for j in range(1, k)], whole.pressure(z), rtol=1e-11)
    assert _worst_balance(result) <= 1e-12


@settings(max_examples=scaled(10), deadline=None)
@given(fluid=fluids, mu=moduli, k=st.integers(2, 5), f=st.floats(0.01, 0.2))
def test_identical_parallel_tubes_share_the_flow(fluid, mu, k, f):
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    # k q through one tube drops f of the limit pressure: the network stays well below it
    q = tubefsi.solve(fluid, wall, TUBE, pressure_drop=f * mu * math.log1p(0.3)).flow_rate / k
    net = Network(rheology=fluid)
    net.add_tube("in", "a", wall, TUBE)
    for j in range(k):
        net.add_tube("a", "b", wall, TUBE, name=f"parallel {j}")
    net.add_tube("b", "out", wall, TUBE)
    net.set_inflow("in", q * k).set_pressure("out", 0.0)
    result = net.solve()
    for j in range(k):
        assert result.flow_rate[f"parallel {j}"] == pytest.approx(q, rel=1e-13)
    assert result.flow_rate[("in", "a")] == pytest.approx(k * q, rel=1e-13)
    # the parallel bundle carries k q at its pressure drop, as one tube carries q
    one = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, outlet_pressure=result.pressure["b"])
    assert result.pressure["a"] == pytest.approx(one.inlet_pressure, rel=1e-11)


def _symmetric_tree(depth, fluid, wall, tube_of_generation):
    net = Network(rheology=fluid)
    net.add_tube("root", 1, wall, tube_of_generation(0))
    for node in range(1, 2 ** (depth - 1)):
        for child in (2 * node, 2 * node + 1):
            net.add_tube(node, child, wall, tube_of_generation(int(math.log2(child))))
    leaves = range(2 ** (depth - 1), 2**depth)
    return net, leaves


@settings(max_examples=scaled(8), deadline=None)
@given(fluid=fluids, mu=moduli, depth=st.integers(2, 5), f=st.floats(0.05, 0.9))
def test_a_symmetric_tree_splits_evenly(fluid, mu, depth, f):
    wall = walls["thick-neo-hookean"](shear_modulus=mu)

    def gen(g):
        a = 1e-4 * 2 ** (-g / 3)
        return Tube(radius=a, thickness=0.3 * a, length=100 * a)

    net, leaves = _symmetric_tree(depth, fluid, wall, gen)
    net.set_pressure("root", f * mu * math.log1p(0.3))
    for leaf in leaves:
        net.set_pressure(leaf, 0.0)
    result = net.solve()
    q_root = result.flow_rate[("root", 1)]
    for name, q in result.flow_rate.items():
        if name[0] != "root":
            generation = int(math.log2(name[1]))
            assert q == pytest.approx(q_root / 2**generation, rel=1e-12), name
    assert _worst_balance(result) <= 1e-12


@settings(max_examples=scaled(10), deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_nodes=st.integers(4, 14), loops=st.integers(0, 4))
def test_mass_balances_at_every_node(seed, n_nodes, loops):
    """A random tree with extra loop tubes, mixed fluids and walls, inflows and fixed pressures."""
    rng = np.random.default_rng(seed)
    thinning = rheologies["power-law"](consistency=0.01, index=0.7)
    newtonian = rheologies["newtonian"](viscosity=3e-3)
    net = Network(rheology=thinning)
    pairs = [(int(rng.integers(0, i)), i) for i in range(1, n_nodes)]
    for _ in range(loops):
        u, v = rng.choice(n_nodes, 2, replace=False)
        pairs.append((int(u), int(v)))
    for j, (u, v) in enumerate(pairs):
        a = 1e-4 * rng.uniform(0.5, 1.5)
        wall = walls["thick-neo-hookean"](shear_modulus=rng.uniform(3e3, 2e4)) if j % 3 else walls["rigid"]()
        net.add_tube(u, v, wall, Tube(radius=a, thickness=0.3 * a, length=a * rng.uniform(50, 150)),
                     name=j, rheology=newtonian if j % 4 == 1 else None)
    net.set_pressure(0, 300.0)
    net.set_pressure(n_nodes - 1, 20.0)
    net.set_inflow(1, 1e-10)
    result = net.solve()
    assert result.residual <= 1e-13
    assert _worst_balance(result) <= 1e-12


def test_reversing_a_tube_negates_its_flow():
    """The edge law is odd in p_u - p_v: a tube added backwards carries minus the flow."""
    def build(backwards):
        net = Network(rheology=FLUID)
        net.add_tube("in", "j", WALL, TUBE)
        net.add_tube("j", "a", WALL, TUBE)
        if backwards:
            net.add_tube("b", "j", WALL, TUBE, name="branch")
        else:
            net.add_tube("j", "b", WALL, TUBE, name="branch")
        return net.set_inflow("in", 1e-9).set_pressure("a", 0.0).set_pressure("b", 30.0).solve()

    forward, backward = build(False), build(True)
    assert forward.flow_rate["branch"] > 0
    # to rounding, not bit for bit: the node balances and the Jacobian's diagonal sum the same
    # terms in another order when an edge is reversed
    assert abs(backward.flow_rate["branch"] + forward.flow_rate["branch"]) <= 2e-15 * forward.flow_rate["branch"]
    assert abs(backward.pressure["j"] - forward.pressure["j"]) <= 2e-15 * forward.pressure["j"]


def test_flow_reverses_in_a_loop():
    """A tube whose flow runs from v to u: negative flow, and its single-tube solution agrees."""
    net = Network(rheology=FLUID)
    net.add_tube("a", "c", WALL, TUBE)
    net.add_tube("c", "b", WALL, TUBE)
    net.add_tube("d", "c", WALL, TUBE)   # flow from c to d: reversed
    net.set_pressure("a", 400.0).set_pressure("b", 0.0).set_pressure("d", 10.0)
    result = net.solve()
    q = result.flow_rate[("d", "c")]
    assert q < 0
    sol = result.solution(("d", "c"))
    assert sol.flow_rate == pytest.approx(-q, rel=1e-13)
    assert sol.inlet_pressure == pytest.approx(result.pressure["c"], rel=1e-15)


@pytest.mark.parametrize("index", [0.5, 1.0, 1.6])
def test_a_dead_end_carries_no_flow(index):
    """A branch that ends at a free node: zero flow, the dead end at its junction's pressure (the
    degenerate Jacobian of a no-flow tube, dq/dp = 0 or inf, is clipped)."""
    fluid = rheologies["power-law"](consistency=0.01, index=index)
    net = Network(rheology=fluid)
    net.add_tube("in", "j", WALL, TUBE)
    net.add_tube("j", "out", WALL, TUBE)
    net.add_tube("j", "dead", WALL, TUBE)
    net.add_tube("dead", "deader", WALL, TUBE)
    net.set_pressure("in", 500.0).set_pressure("out", 0.0)
    result = net.solve()
    assert abs(result.flow_rate[("j", "dead")]) <= 1e-15 * result.flow_rate[("in", "j")]
    assert result.pressure["deader"] == pytest.approx(result.pressure["j"], rel=1e-15)
    whole = tubefsi.solve(fluid, WALL, Tube(radius=1e-4, thickness=3e-5, length=2e-2), pressure_drop=500.0)
    assert result.flow_rate[("in", "j")] == pytest.approx(whole.flow_rate, rel=1e-11)


# ---------------------------------------------------------------------------- mpmath reference
def _reference_y(wall_params, tubes, n, m, p_fixed, inflow=None, dps=30):
    """Junction (and inlet) pressure and flows of a Y: tube 0 from node 0 to J, tubes 1 and 2 from
    J to nodes 1 and 2 at fixed pressures; node 0 at a fixed pressure or fed by ``inflow``."""
    from mpmath import mp, mpf

    from tubefsi.testing.reference.power_law import ref_J_direct, ref_phi_inverse
    from tubefsi.testing.reference.tube_laws import NeoHookean, RefWall, stretch_at_pressure

    with mp.workdps(dps):
        k = 3 * mpf(n) + 1
        refs = [RefWall("thick", NeoHookean(mu), mpf(t) / mpf(a)) for mu, (a, t, _) in zip(wall_params, tubes)]

        def J(i, p):
            return mpf(0) if p == 0 else ref_J_direct(refs[i], stretch_at_pressure(refs[i], p), k)

        def q(i, p_in, p_out):
            a, _, length = (mpf(x) for x in tubes[i])
            return ref_phi_inverse(a**k * (J(i, p_in) - J(i, p_out)) / length, n, m)

        p1, p2 = mpf(p_fixed[1]), mpf(p_fixed[2])
        limit = min(r.limit_pressure() for r in refs)
        lo = max(p1, p2) * (1 + mpf(10) ** -20) + mpf(10) ** -20
        if inflow is None:
            p0 = mpf(p_fixed[0])
            hi = min(p0, min(refs[1].limit_pressure(), refs[2].limit_pressure()) * (1 - mpf(10) ** -12))
            pj = mp.findroot(lambda x: q(0, p0, x) - q(1, x, p1) - q(2, x, p2), (lo, hi), solver="anderson")
        else:
            target = mpf(inflow)
            pj = mp.findroot(lambda x: q(1, x, p1) + q(2, x, p2) - target, (lo, limit * (1 - mpf(10) ** -6)),
                             solver="anderson")
            p0 = mp.findroot(lambda x: q(0, x, pj) - target, (pj * (1 + mpf(10) ** -20), limit * (1 - mpf(10) ** -6)),
                             solver="anderson")
        return p0, pj, [q(0, p0, pj), q(1, pj, p1), q(2, pj, p2)]


Y_CASES = [
    # (shear moduli, tubes (a, t, L), n, m, fixed pressures (p0, p1, p2), inflow)
    ((4e3, 6e3, 3e3), ((1e-4, 3e-5, 1e-2), (8e-5, 3e-5, 8e-3), (7e-5, 2e-5, 1.2e-2)), 0.7, 0.01,
     (700.0, 0.0, 120.0), None),
    ((1e4, 5e3, 8e3), ((1.2e-4, 2e-5, 6e-3), (1e-4, 4e-5, 1e-2), (6e-5, 2e-5, 5e-3)), 0.55, 0.03,
     (None, 40.0, 10.0), 1e-9),
]


@pytest.mark.parametrize("case", Y_CASES, ids=["pressure-driven", "inflow-driven"])
def test_y_bifurcation_against_mpmath(case):
    from tubefsi.testing.reference import rel_err

    moduli, tubes, n, m, p_fixed, inflow = case
    fluid = rheologies["power-law"](consistency=m, index=n)
    net = Network(rheology=fluid)
    ends = [(0, "J"), ("J", 1), ("J", 2)]
    for (u, v), mu, (a, t, length) in zip(ends, moduli, tubes):
        net.add_tube(u, v, walls["thick-neo-hookean"](shear_modulus=mu), Tube(radius=a, thickness=t, length=length))
    if inflow is None:
        net.set_pressure(0, p_fixed[0])
    else:
        net.set_inflow(0, inflow)
    net.set_pressure(1, p_fixed[1]).set_pressure(2, p_fixed[2])
    result = net.solve()
    p0, pj, flows = _reference_y(moduli, tubes, n, m, p_fixed, inflow)
    errors = [rel_err(result.pressure["J"], pj), rel_err(result.pressure[0], p0)]
    errors += [rel_err(result.flow_rate[e], f) for e, f in zip(ends, flows)]
    assert max(errors) <= 1e-10, errors


# ---------------------------------------------------------------------------- errors
def _y(**kw):
    net = Network(rheology=FLUID)
    net.add_tube("in", "j", WALL, TUBE).add_tube("j", "a", WALL, TUBE).add_tube("j", "b", WALL, TUBE)
    return net


def test_a_node_with_both_a_pressure_and_an_inflow():
    net = _y().set_pressure("in", 10.0)
    with pytest.raises(InvalidParameterError, match="one boundary condition"):
        net.set_inflow("in", 1e-9)
    net = _y().set_inflow("a", 1e-9)
    with pytest.raises(InvalidParameterError, match="one boundary condition"):
        net.set_pressure("a", 1.0)


def test_no_fixed_pressure():
    with pytest.raises(InvalidParameterError, match="fixed pressure"):
        _y().set_inflow("in", 1e-9).solve()


def test_a_component_without_a_fixed_pressure():
    net = _y().set_pressure("a", 0.0).set_pressure("b", 0.0).set_pressure("in", 100.0)
    net.add_tube("x", "y", WALL, TUBE)
    with pytest.raises(InvalidParameterError, match="disconnected") as info:
        net.solve()
    assert "'x'" in str(info.value)


def test_an_inflow_beyond_the_maximum_flow_rate_names_the_tube():
    q_max = tubefsi.max_flow_rate(FLUID, WALL, TUBE)
    net = Network(rheology=FLUID)
    net.add_tube("in", "out", WALL, TUBE, name="feeder")
    net.set_inflow("in", 1.5 * q_max).set_pressure("out", 0.0)
    with pytest.raises(NoSteadyStateError, match="feeder") as info:
        net.solve()
    assert info.value.quantity == "flow_rate" and info.value.limit == pytest.approx(q_max, rel=1e-12)
    # just below the maximum: a steady state, the inlet within 1e-13 of the limit pressure (a
    # feeding tube is solved flow-controlled, so its inlet pressure is no Newton unknown)
    net = Network(rheology=FLUID).add_tube("in", "out", WALL, TUBE)
    result = net.set_inflow("in", 0.99 * q_max).set_pressure("out", 0.0).solve()
    assert result.flow_rate[("in", "out")] == 0.99 * q_max
    single = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=0.99 * q_max)
    assert result.pressure["in"] == pytest.approx(single.inlet_pressure, rel=1e-14)


def test_an_inflow_into_a_junction_beyond_what_its_tubes_carry():
    """The inflow node has two tubes: its pressure is a Newton unknown and reaches the limit. The
    capacity is 2 q_max (both tubes at their maximum flow rate, :func:`tubefsi.max_flow_rate`, with
    the outlets fixed at 0): the message's upper bound is it (to the 6 digits shown); the error's
    ``limit``, the flow with 'in' held 1e-12 below its limit pressure, is below it and within 3 %
    (the approach to q_max is slow: a power of the gap)."""
    q_max = tubefsi.max_flow_rate(FLUID, WALL, TUBE)
    net = Network(rheology=FLUID).add_tube("in", "a", WALL, TUBE).add_tube("in", "b", WALL, TUBE, name="second")
    net.set_inflow("in", 2.5 * q_max).set_pressure("a", 0.0).set_pressure("b", 0.0)
    with pytest.raises(NoSteadyStateError, match=f"node 'in' held at the limit pressure {LIMIT:.10g} Pa") as info:
        net.solve()
    assert info.value.quantity == "flow_rate" and 0.97 * 2 * q_max < info.value.limit < 2 * q_max
    assert float(str(info.value).split("at most ")[1].split(" ")[0]) == pytest.approx(2 * q_max, rel=1e-5)
    net = Network(rheology=FLUID).add_tube("in", "a", WALL, TUBE).add_tube("in", "b", WALL, TUBE, name="second")
    result = net.set_inflow("in", 1.2 * q_max).set_pressure("a", 0.0).set_pressure("b", 0.0).solve()
    assert result.flow_rate["second"] == pytest.approx(0.6 * q_max, rel=1e-12)


def test_non_convergence_reports_the_residual():
    net = _y().set_inflow("in", 2e-9).set_pressure("a", 0.0).set_pressure("b", 0.0)
    with pytest.raises(ConvergenceError, match="imbalance"):
        net.solve(max_iterations=1)


def test_a_withdrawal_that_needs_a_negative_pressure():
    net = _y().set_pressure("in", 0.0).set_pressure("a", 0.0).set_inflow("b", -1e-9)
    with pytest.raises(InvalidParameterError, match="negative"):
        net.solve()


def test_bad_tubes():
    net = Network(rheology=FLUID)
    with pytest.raises(InvalidParameterError, match="distinct"):
        net.add_tube("a", "a", WALL, TUBE)
    net.add_tube("a", "b", WALL, TUBE)
    with pytest.raises(InvalidParameterError, match="name"):
        net.add_tube("a", "b", WALL, TUBE)
    with pytest.raises(InvalidParameterError, match="rheology"):
        Network().add_tube("a", "b", WALL, TUBE)
    with pytest.raises(InvalidParameterError, match="scalar"):
        net.add_tube("a", "c", walls["thick-neo-hookean"](shear_modulus=[1e3, 2e3]), TUBE)
    with pytest.raises(InvalidParameterError, match="pressure"):
        net.set_pressure("a", -1.0)
    with pytest.raises(NoSteadyStateError):
        net.set_pressure("a", 2 * LIMIT).set_pressure("b", 0.0).solve()


# ---------------------------------------------------------------------------- output
def _solved():
    net = _y().set_inflow("in", 1e-9).set_pressure("a", 0.0).set_pressure("b", 25.0)
    for node, xy in {"in": (0, 0), "j": (1, 0), "a": (2, 1), "b": (2, -1)}.items():
        net.set_position(node, xy)
    return net, net.solve()


def test_tables_exports_and_solutions(tmp_path):
    net, result = _solved()
    tubes = result.tube_table()
    assert tubes["name"] == [("in", "j"), ("j", "a"), ("j", "b")]
    assert np.all(np.array(tubes["radius_u"]) > TUBE.radius)          # inflated
    nodes = result.node_table()
    assert nodes["inflow"][nodes["node"].index("in")] == pytest.approx(1e-9, rel=1e-13)
    nodes_csv, tubes_csv = result.to_csv(tmp_path / "y")
    assert open(tubes_csv).read().splitlines()[0].startswith("name,u,v,flow_rate")
    data = json.loads(result.to_json(tmp_path / "y.json"))
    assert len(data["nodes"]) == 4 and len(data["tubes"]) == 3
    assert data["tubes"][1]["flow_rate"] == result.flow_rate[("j", "a")]
    sol = result.solution(("j", "a"))
    assert sol.flow_rate == pytest.approx(result.flow_rate[("j", "a")], rel=1e-13)
    assert sol.pressure(TUBE.length) == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_array_equal(result.pressures, [result.pressure[n] for n in result.nodes])
    with pytest.raises(InvalidParameterError):
        result.solution("nope")


def test_plot(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    _, result = _solved()
    ax = result.plot()
    ax.figure.savefig(tmp_path / "net.png")
    assert (tmp_path / "net.png").stat().st_size > 5000


def test_networkx_round_trip():
    nx = pytest.importorskip("networkx")
    net, result = _solved()
    graph = net.to_networkx()
    assert isinstance(graph, nx.MultiDiGraph) and graph.number_of_edges() == 3
    again = Network.from_networkx(graph, rheology=FLUID).solve()
    assert [again.pressure[n] for n in ("in", "j")] == [result.pressure[n] for n in ("in", "j")]
    simple = nx.DiGraph()
    simple.add_edge("s", "t", wall=WALL, tube=TUBE)
    simple.nodes["s"]["pressure"], simple.nodes["t"]["pressure"] = 100.0, 0.0
    q = Network.from_networkx(simple, rheology=FLUID).solve().flow_rate[("s", "t")]
    assert q == pytest.approx(tubefsi.solve(FLUID, WALL, TUBE, pressure_drop=100.0).flow_rate, rel=1e-13)
    # a networkx layout when no node has coordinates
    bare = Network.from_networkx(simple, rheology=FLUID).solve()
    assert bare.plot() is not None


def test_a_generic_fluid_with_mixed_walls_and_a_dead_end():
    """Carreau–Yasuda blood (the generic, non-separable path) through three wall groups; the dead
    end's tiny pressure drops are where the single-tube solve gives no flow rate (the network
    takes the secant of a probe drop there, ``docs/network.md``)."""
    blood = rheologies["carreau-yasuda"](**rheologies["carreau-yasuda"]._examples[0])
    net = Network(rheology=blood)
    net.add_tube("in", "j", walls["thick-linear"](youngs_modulus=6e3, poisson_ratio=0.5), TUBE)
    net.add_tube("j", "a", WALL, TUBE)
    net.add_tube("j", "b", walls["thin-neo-hookean"](shear_modulus=2e4), TUBE)
    net.add_tube("j", "dead", WALL, TUBE)
    net.set_pressure("in", 300.0).set_pressure("a", 0.0).set_pressure("b", 40.0)
    result = net.solve()
    assert _worst_balance(result) <= 1e-12
    assert abs(result.flow_rate[("j", "dead")]) <= 1e-12 * result.flow_rate[("in", "j")]
    for name in (("in", "j"), ("j", "a"), ("j", "b")):    # each tube obeys its own law
        t = net._tubes[name]
        pu, pv = result.pressure[t.u], result.pressure[t.v]
        single = tubefsi.solve(blood, t.wall, t.tube, pressure_drop=pu - pv, outlet_pressure=pv)
        assert result.flow_rate[name] == pytest.approx(single.flow_rate, rel=1e-12)


def test_the_package_pickles_by_name():
    """dask and multiprocessing send functions that refer to ``tubefsi`` to other processes."""
    import pickle

    assert pickle.loads(pickle.dumps(tubefsi)) is tubefsi


def _carreau_yasuda_diamond(scale, held=None):
    """A diamond with a cross edge (thick neo-Hookean walls, the plugin's Carreau–Yasuda blood
    model) fed at 'in' and 'b'. Tube in-a's limit pressure (931.2 Pa) bounds p_in and p_a. At
    ``scale`` = 1 no steady state exists, by hand: below it, tube a-out carries at most
    5.46e-9 m^3/s and b-out (at p_b <= 931.2 Pa) 1.22e-9 (single-tube solves). If p_b <= p_in,
    that is all the network can take out, short of the 1.73e-8 fed; if p_b > p_in, all that 'in'
    receives (>= 8.72e-9) must leave through in-a and then a-out. With ``held``, 'in' is held at
    that pressure instead of fed."""
    fluid = rheologies["carreau-yasuda"](**rheologies["carreau-yasuda"]._examples[1])
    net = Network(rheology=fluid)
    for u, v, mu, a, t, length in [("in", "a", 4595.0, 1.923e-4, 4.32e-5, 1.135e-2),
                                   ("in", "b", 16899.0, 1.114e-4, 3.56e-5, 5.41e-3),
                                   ("a", "b", 15563.0, 1.307e-4, 3.03e-5, 1.683e-2),
                                   ("a", "out", 7458.0, 1.180e-4, 1.81e-5, 1.105e-2),
                                   ("b", "out", 5662.0, 8.93e-5, 3.58e-5, 9.21e-3)]:
        net.add_tube(u, v, walls["thick-neo-hookean"](shear_modulus=mu), Tube(radius=a, thickness=t, length=length))
    net.set_inflow("b", scale * 8.56e-9).set_pressure("out", 0.0)
    return net.set_inflow("in", scale * 8.72e-9) if held is None else net.set_pressure("in", held)


def test_a_non_separable_network_beyond_its_capacity_says_so_at_once():
    """Issue 28: a Carreau–Yasuda network fed beyond what it carries crept toward the limit
    pressure for 100 Newton iterations (~10 s) and raised ConvergenceError. Now the node pushed into
    its bound is held there and the rest solved: the excess it keeps proves that no steady state
    exists (contract: NoSteadyStateError naming the node, the tube and its limit pressure
    mu ln(1 + t/a), the thick neo-Hookean limit, within 30 iterations; its ``limit`` the capacity as
    a flow rate: what the network carries with 'in' held 1e-12 below that limit pressure, here
    against the pressure-driven solve of the network with 'in' fixed there, 1e-4: rounding so
    close to the limit leaves both balances at ~1e-6)."""
    limit = 4595.0 * math.log1p(4.32e-5 / 1.923e-4)
    with pytest.raises(NoSteadyStateError, match=r"node 'in' held at the limit pressure 931.19632\d* Pa of tube "
                       r"\('in', 'a'\)") as info:
        _carreau_yasuda_diamond(1.0).solve(max_iterations=30)
    assert info.value.quantity == "flow_rate"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.AccuracyWarning)
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        held = _carreau_yasuda_diamond(1.0, held=(1 - 1e-12) * limit).solve()
    assert info.value.limit == pytest.approx(held.flow_rate[("a", "out")] + held.flow_rate[("b", "out")], rel=1e-4)
    # below the capacity: a steady state whose mass balances at every free node (from the flows)
    result = _carreau_yasuda_diamond(0.2).solve()
    assert _worst_balance(result) < 1e-12
