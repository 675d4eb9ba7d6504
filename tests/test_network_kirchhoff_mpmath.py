"""Cyclic compliant networks against a Kirchhoff solve in mpmath (``docs/network.md``, "Accuracy
and cost"): a ladder (two rails joined by rungs whose flow directions are not known in advance)
and a loop, with mixed walls (thick neo-Hookean of different moduli, rigid) and mixed boundary
conditions (an inflow, a fixed pressure, a resistance outlet).

Reference, independent of the network code: every tube's law written in mpmath at 20 digits —
a power-law fluid, :math:`L\\phi(q) = a^k[\\hat J(\\lambda_{in}) - \\hat J(\\lambda_{out})]` with
the thick neo-Hookean tube law of ``tubefsi.testing.reference`` (a rigid tube:
:math:`L\\phi(q) = a^k\\Delta p`) — and Kirchhoff's law at every free node solved by mpmath's
multidimensional Newton method (``mp.findroot``) from the network's pressures perturbed by 2 %.
"""

from __future__ import annotations

import pytest
from mpmath import mp, mpf

from tubefsi import Network, Tube
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference.power_law import ref_J_direct, ref_phi_inverse
from tubefsi.testing.reference.tube_laws import NeoHookean, RefWall, stretch_at_pressure

N, M = 0.7, 0.01


def _network(tubes, conditions):
    net = Network(rheology=rheologies["power-law"](consistency=M, index=N))
    for (u, v), (mu, a, length) in tubes.items():
        wall = walls["rigid"]() if mu is None else walls["thick-neo-hookean"](shear_modulus=mu)
        net.add_tube(u, v, wall, Tube(radius=a, thickness=0.3 * a, length=length))
    for node, (kind, *values) in conditions.items():
        {"pressure": net.set_pressure, "inflow": net.set_inflow, "resistance": net.set_resistance}[kind](node, *values)
    return net


def _kirchhoff(tubes, conditions, start, dps=20):
    """Node pressures and tube flows of the network in mpmath (module docstring)."""
    with mp.workdps(dps):
        k = 3 * mpf(N) + 1
        walls_ = {e: None if mu is None else RefWall("thick", NeoHookean(mu), mpf("0.3"))
                  for e, (mu, _, _) in tubes.items()}
        memo = {}

        def J(e, p):
            if p <= 0:
                return mpf(0)
            key = (e, p)
            if key not in memo:
                memo[key] = ref_J_direct(walls_[e], stretch_at_pressure(walls_[e], p), k)
            return memo[key]

        def flow(e, pu, pv):
            mu, a, length = tubes[e]
            a, length = mpf(a), mpf(length)
            hi, lo, sign = (pu, pv, 1) if pu >= pv else (pv, pu, -1)
            if hi == lo:
                return mpf(0)
            rise = (hi - lo) if walls_[e] is None else J(e, hi) - J(e, lo)
            return sign * ref_phi_inverse(a**k * rise / length, N, M)

        fixed = {node: mpf(c[1]) for node, c in conditions.items() if c[0] == "pressure"}
        free = [node for node in start if node not in fixed]

        def pressures(x):
            p = dict(fixed)
            p.update(zip(free, x))
            return p

        def balance(*x):
            p = pressures(x)
            out = {node: mpf(0) for node in free}
            for (u, v) in tubes:
                q = flow((u, v), p[u], p[v])
                if u in out:
                    out[u] -= q
                if v in out:
                    out[v] += q
            for node, c in conditions.items():
                if c[0] == "inflow":
                    out[node] += mpf(c[1])
                elif c[0] == "resistance":
                    out[node] -= (p[node] - mpf(c[2])) / mpf(c[1])
            scale = max(abs(mpf(c[1])) for c in conditions.values() if c[0] == "inflow")
            return [out[node] / scale for node in free]

        x = mp.findroot(balance, [mpf(start[node]) * mpf("1.02") for node in free], tol=mpf(10) ** (-2 * dps + 8))
        x = [x] if len(free) == 1 else list(x)
        p = pressures(x)
        return {n: float(v) for n, v in p.items()}, {e: float(flow(e, p[e[0]], p[e[1]])) for e in tubes}


LADDER = {("in", "a1"): (5e3, 1.2e-4, 1e-2), ("a1", "a2"): (8e3, 1e-4, 8e-3), ("a2", "a3"): (None, 9e-5, 6e-3),
          ("b1", "b2"): (6e3, 1e-4, 9e-3), ("b2", "b3"): (4e3, 1.1e-4, 7e-3),
          ("a1", "b1"): (7e3, 8e-5, 5e-3), ("a2", "b2"): (None, 6e-5, 6e-3), ("b3", "a3"): (5e3, 7e-5, 4e-3),
          ("a3", "out"): (9e3, 1.2e-4, 1e-2), ("b3", "side"): (6e3, 8e-5, 8e-3)}
LADDER_BC = {"in": ("inflow", 2e-9), "out": ("pressure", 20.0), "side": ("resistance", 3e12, 40.0)}

LOOP = {("in", "x"): (5e3, 1.2e-4, 1e-2), ("x", "y"): (8e3, 1e-4, 8e-3), ("y", "z"): (None, 9e-5, 6e-3),
        ("z", "x"): (4e3, 1e-4, 9e-3), ("y", "out"): (6e3, 1e-4, 7e-3), ("z", "r"): (7e3, 8e-5, 5e-3)}
LOOP_BC = {"in": ("inflow", 1.5e-9), "out": ("pressure", 60.0), "r": ("resistance", 2e12, 0.0)}


@pytest.mark.parametrize("tubes, conditions", [pytest.param(LADDER, LADDER_BC, marks=pytest.mark.slow), (LOOP, LOOP_BC)],
                         ids=["ladder", "loop"])
def test_cyclic_compliant_network_against_mpmath(tubes, conditions):
    """Every node pressure and tube flow to 1e-10 (relative; flows to 1e-10 of the throughput)."""
    result = _network(tubes, conditions).solve()
    p_ref, q_ref = _kirchhoff(tubes, conditions, result.pressure)
    through = max(c[1] for c in conditions.values() if c[0] == "inflow")
    for node, value in p_ref.items():
        assert rel_err(result.pressure[node], value) <= 1e-10, node
    for e, value in q_ref.items():
        assert abs(result.flow_rate[e] - value) <= 1e-10 * through, e
