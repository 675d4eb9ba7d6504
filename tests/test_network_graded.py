"""Graded (tapered) tubes as network edges (``docs/network.md``, "Graded tubes").

References, each independent of the network code:

* one graded edge between two fixed pressures: the single graded tube of :func:`tubefsi.solve`,
  read from the end its flow enters — the reversed tube built here by hand, not by the network;
* a linear taper (constant t/a) in series with a uniform tube: a shooting of the two in mpmath
  (30 digits) with the separated identity of each tube, :math:`\\int_{\\lambda_{out}}^{\\lambda_{in}}
  P'(s)s^k ds = \\phi(q)\\int a^{-k} dz`, and the thick neo-Hookean tube law written in closed form
  (``tests/test_graded.py``'s ``thick_nh``), the flow found by ``mp.findroot``;
* a cyclic network with graded edges: Kirchhoff's law at each free node, with every tube's flow
  recomputed by single-tube solves at the network's node pressures.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

import tubefsi
from tubefsi.testing.reference import rel_err

walls = tubefsi.registry.walls
fluids = tubefsi.registry.rheologies

L = 2e-2
MU = 3e4


def _thick_nh(mu, tb):
    r"""Thick neo-Hookean :math:`P(\lambda)` and :math:`P'(\lambda)` in closed form (mpmath)."""
    mu, tb = mp.mpf(mu), mp.mpf(tb)
    d = (1 + tb) ** 2 - 1

    def P(lam):
        lo2 = 1 + (lam**2 - 1) / (1 + tb) ** 2
        return mu * (mp.log(lam) - mp.log(lo2) / 2 - 1 / (2 * lam**2) + 1 / (2 * lo2))

    def dP(lam):
        x = lam**2
        return mu * d * ((d + 2) * x + d) / (lam * x * (x + d) ** 2)

    return P, dP


def _inlet_pressure(q, p_out, a0, a1, length, n, m, tb, mu=MU):
    r"""Inlet pressure of a power-law flow ``q`` through a linear taper ``a0 -> a1`` (constant t/a)
    whose outlet is at ``p_out``: :math:`\int_{\lambda_{out}}^{\lambda_{in}} P'(s)s^k ds =
    \phi(q)\int_0^L a^{-k}dz` (the same for either direction of the taper)."""
    n, m, q = mp.mpf(n), mp.mpf(m), mp.mpf(q)
    k = 3 * n + 1
    phi = 2 * m * ((3 * n + 1) * q / (mp.pi * n)) ** n
    a0, a1, length = mp.mpf(a0), mp.mpf(a1), mp.mpf(length)
    integral = length if a0 == a1 else length * (a1 ** (1 - k) - a0 ** (1 - k)) / ((1 - k) * (a1 - a0))
    integral = integral * (a0 ** -k if a0 == a1 else 1)
    P, dP = _thick_nh(mu, tb)
    lam_out = mp.findroot(lambda lam: P(lam) - p_out, mp.mpf(1) + p_out / dP(mp.mpf(1)) if p_out else mp.mpf(1)) \
        if p_out else mp.mpf(1)
    target = phi * integral
    J = lambda lam: mp.quad(lambda s: dP(s) * s**k, [lam_out, lam]) - target   # noqa: E731
    guess = lam_out + target / (dP(lam_out) * lam_out**k)
    lam_in = mp.findroot(J, (guess, guess * (1 + mp.mpf("1e-3"))), solver="secant")
    return P(lam_in)


def _tapered_wall_tube(a0, a1, tb=0.2):
    return walls["thick-neo-hookean"](shear_modulus=MU), tubefsi.Tube.tapered(
        length=L, radius=a0, outlet_radius=a1, thickness=tb * a0)


def test_tapered_helper_is_the_linear_table():
    """``Tube.tapered`` is the linear interpolation of its ends (t/a kept by default); equal ends
    give a uniform tube."""
    tube = tubefsi.Tube.tapered(length=L, radius=1e-3, outlet_radius=0.5e-3, thickness=2e-4)
    z = np.linspace(0, L, 7)
    a, t = tube.at(z)
    assert np.allclose(a, 1e-3 - 0.5e-3 * z / L, rtol=1e-15, atol=0)
    assert np.allclose(t, 0.2 * a, rtol=1e-15, atol=0)
    assert not tubefsi.Tube.tapered(length=L, radius=1e-3, outlet_radius=1e-3, thickness=2e-4).graded
    with pytest.raises(tubefsi.InvalidParameterError, match="outlet_radius"):
        tubefsi.Tube.tapered(length=L, radius=1e-3, outlet_radius=-1.0, thickness=2e-4)


@pytest.mark.parametrize("forward", [True, False])
def test_one_graded_edge_is_the_single_graded_tube(forward):
    """A taper whose t/a varies (not separable: its flow depends on its direction) between two
    fixed pressures carries the flow of the single graded tube read from the end the flow
    enters; the two directions differ (by ~4 %), so the edge law is not odd. 1e-12."""
    fluid = fluids["newtonian"](viscosity=3.5e-3)
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    ahead = tubefsi.Tube.tapered(length=L, radius=1e-3, outlet_radius=0.6e-3, thickness=2e-4, outlet_thickness=2e-4)
    back = tubefsi.Tube.tapered(length=L, radius=0.6e-3, outlet_radius=1e-3, thickness=2e-4, outlet_thickness=2e-4)
    high, low = 3000.0, 1000.0
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("a", "b", wall, ahead)
    net.set_pressure("a", high if forward else low)
    net.set_pressure("b", low if forward else high)
    result = net.solve()
    single = tubefsi.solve(fluid, wall, ahead if forward else back, pressure_drop=high - low, outlet_pressure=low)
    q = result.flow_rates[0]
    assert np.sign(q) == (1 if forward else -1)
    assert rel_err(abs(q), single.flow_rate) < 1e-12
    # the two ends' deformed radii are those of the single tube's inlet and outlet
    inlet, outlet = (result.radius_u[0], result.radius_v[0]) if forward else (result.radius_v[0], result.radius_u[0])
    assert rel_err(inlet, single.inlet_radius) < 1e-12
    assert rel_err(outlet, float(single.radius(L))) < 1e-10
    other = tubefsi.solve(fluid, wall, back if forward else ahead, pressure_drop=high - low, outlet_pressure=low)
    assert rel_err(other.flow_rate, single.flow_rate) > 1e-2
    assert rel_err(result.solution(("a", "b")).flow_rate, single.flow_rate) < 1e-12


@pytest.mark.parametrize("reverse", [False, True])
def test_taper_in_series_with_a_uniform_tube_against_mpmath(reverse):
    """Inflow into a linear taper (1 -> 0.6 mm, t/a = 0.2) followed by a uniform tube of 0.6 mm to
    a fixed pressure; ``reverse``: the taper's narrow end upstream. The inlet pressure against an
    mpmath shooting of the two tubes (the uniform one first, from the fixed outlet): 1e-10."""
    n, m = 0.7, 0.017
    q, p_end = 4e-6, 200.0
    a0, a1 = (1e-3, 0.6e-3)
    wall, taper = _tapered_wall_tube(a0, a1)
    uniform = tubefsi.Tube(radius=0.6e-3, thickness=0.12e-3, length=L / 2)
    net = tubefsi.Network(rheology=fluids["power-law"](consistency=m, index=n))
    if reverse:                      # the taper's z = L end receives the inflow
        net.add_tube("b", "a", wall, taper)
    else:
        net.add_tube("a", "b", wall, taper)
    net.add_tube("b", "c", wall, uniform)
    net.add_tube("c", "d", wall, uniform, name="tail")   # "a" and "c" are no feeders
    net.set_inflow("a", q)
    net.set_pressure("d", p_end)
    result = net.solve()
    mp.mp.dps = 30
    p_c = _inlet_pressure(q, p_end, 0.6e-3, 0.6e-3, L / 2, n, m, 0.2)
    p_b = _inlet_pressure(q, p_c, 0.6e-3, 0.6e-3, L / 2, n, m, 0.2)
    p_a = _inlet_pressure(q, p_b, a0, a1, L, n, m, 0.2)
    assert rel_err(result.pressure["b"], float(p_b)) < 1e-10
    assert rel_err(result.pressure["a"], float(p_a)) < 1e-10
    assert rel_err(abs(result.flow_rate[("b", "a") if reverse else ("a", "b")]), q) < 1e-12


def _independent_flow(fluid, wall, tube, reverse_tube, pu, pv):
    """The flow u -> v of a tube between node pressures ``pu``, ``pv`` by one single-tube solve."""
    if pu == pv:
        return 0.0
    inlet_first = pu > pv
    sol = tubefsi.solve(fluid, wall, tube if inlet_first else reverse_tube, pressure_drop=abs(pu - pv),
                        outlet_pressure=min(pu, pv))
    return sol.flow_rate if inlet_first else -sol.flow_rate


def test_cyclic_network_with_graded_edges_balances():
    """A diamond with a cross edge, a tapered edge on each side of it and the cross edge tapered
    too (its direction is not known in advance), an inflow and a resistance outlet: Kirchhoff's
    law at every free node with the flows recomputed by single-tube solves (the reversed tubes built
    by hand), to 1e-11 of the throughput."""
    fluid = fluids["power-law"](consistency=0.017, index=0.8)
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    t = lambda a0, a1: tubefsi.Tube.tapered(length=L, radius=a0, outlet_radius=a1, thickness=0.2 * a0)   # noqa: E731
    tubes = {("s", "l"): (t(1e-3, 0.7e-3), t(0.7e-3, 1e-3)), ("s", "r"): (t(0.8e-3, 0.8e-3),) * 2,
             ("l", "r"): (t(0.5e-3, 0.9e-3), t(0.9e-3, 0.5e-3)), ("l", "o"): (t(0.6e-3, 0.6e-3),) * 2,
             ("r", "o"): (t(0.9e-3, 0.5e-3), t(0.5e-3, 0.9e-3)), ("i", "s"): (t(1e-3, 1e-3),) * 2}
    net = tubefsi.Network(rheology=fluid)
    for (u, v), (tube, _) in tubes.items():
        net.add_tube(u, v, wall, tube)
    net.set_inflow("i", 5e-6)
    net.set_resistance("o", 4e7, 100.0)
    result = net.solve()
    p = result.pressure
    flows = {e: _independent_flow(fluid, wall, tube, back, p[e[0]], p[e[1]]) for e, (tube, back) in tubes.items()}
    for e, q in flows.items():
        assert abs(result.flow_rate[e] - q) <= 1e-11 * 5e-6
    balance = {node: 0.0 for node in p}
    for (u, v), q in flows.items():
        balance[u] -= q
        balance[v] += q
    balance["o"] -= (p["o"] - 100.0) / 4e7
    for node in ("s", "l", "r", "o"):
        assert abs(balance[node]) <= 1e-11 * 5e-6, node
    assert abs(flows[("i", "s")] - 5e-6) <= 1e-12 * 5e-6


def test_graded_wall_parameter_edge():
    """A uniform tube whose wall modulus varies along it is a graded edge too: between two fixed
    pressures it carries the single graded tube's flow, in both directions (the wall read from
    the other end built by hand). 1e-12."""
    fluid = fluids["newtonian"](viscosity=3.5e-3)
    tube = tubefsi.Tube(radius=8e-4, thickness=1.6e-4, length=L)
    ahead = walls["thick-neo-hookean"](shear_modulus=lambda z: MU * (1 + 40 * z))
    back = walls["thick-neo-hookean"](shear_modulus=lambda z: MU * (1 + 40 * (L - z)))
    for pu, pv, wall in ((2500.0, 500.0, ahead), (500.0, 2500.0, back)):
        net = tubefsi.Network(rheology=fluid)
        net.add_tube("u", "v", ahead, tube)
        net.set_pressure("u", pu)
        net.set_pressure("v", pv)
        q = net.solve().flow_rates[0]
        single = tubefsi.solve(fluid, wall, tube, pressure_drop=abs(pu - pv), outlet_pressure=min(pu, pv))
        assert rel_err(abs(q), single.flow_rate) < 1e-12
        assert np.sign(q) == np.sign(pu - pv)


def test_add_tubes_refuses_graded_tubes():
    net = tubefsi.Network(rheology=fluids["newtonian"](viscosity=1e-3))
    wall, tube = _tapered_wall_tube(1e-3, 0.5e-3)
    with pytest.raises(tubefsi.InvalidParameterError, match="by add_tube"):
        net.add_tubes(["a"], ["b"], wall, tube)



def test_graded_edge_node_bounded_by_its_own_end_limit():
    """A wall softening along the tube (modulus 2 mu -> mu, limit pressures mu ln 1.2 x 2 -> 1):
    an inlet pressure above the smallest limit along the tube (5.47 kPa at the outlet) but below
    the inlet's own (10.9 kPa), with the pressure below the local limit everywhere, has a steady
    state; the one-edge network carries the single graded tube's flow (:func:`tubefsi.solve`,
    1e-12), where it used to refuse it by the smallest limit. The node pressure beyond the inlet's
    own limit is refused, naming it."""
    fluid = fluids["newtonian"](viscosity=3.5e-3)
    tube = tubefsi.Tube(radius=8e-4, thickness=1.6e-4, length=L)
    wall = walls["thick-neo-hookean"](shear_modulus=lambda z: MU * (2 - z / L))
    single = tubefsi.solve(fluid, wall, tube, pressure_drop=5000.0, outlet_pressure=1000.0)
    assert float(single.pressure(0.0)) > MU * np.log(1.2)
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("u", "v", wall, tube)
    net.set_pressure("u", 6000.0).set_pressure("v", 1000.0)
    assert rel_err(net.solve().flow_rates[0], single.flow_rate) < 1e-12
    net.set_pressure("u", 11000.0)
    with pytest.raises(tubefsi.NoSteadyStateError, match="limit pressure 10939.29") as info:
        net.solve()
    assert info.value.limit == pytest.approx(2 * MU * np.log(1.2), rel=1e-9)


_REVIEW = {   # the reviewer's reproducers: a modulus 8 -> 4 kPa along the tube, a taper entered narrow
    "graded-modulus": (lambda L: (walls["thick-neo-hookean"](shear_modulus=tubefsi.sampled([0, L], [8e3, 4e3],
                                                                                           kind="linear")),
                                  tubefsi.Tube(radius=1e-4, thickness=3e-5, length=L)), 1500.0),
    "taper": (lambda L: (walls["thick-neo-hookean"](shear_modulus=4e3),
                         tubefsi.Tube.tapered(length=L, radius=0.6e-4, outlet_radius=1.2e-4, thickness=3e-5,
                                              outlet_thickness=3e-5)), 1000.0),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(_REVIEW))
def test_graded_edge_reviewer_cases_are_the_single_tube(case):
    """The two cases of the new-user review (inlet pressure above the smallest limit along the
    tube, below the inlet's own): the one-edge network and the same edge fed by a short uniform
    tube from a fixed pressure equal the single graded tube (:func:`tubefsi.solve`; the feeder's
    outlet pressure, the network's free node, is the single tube's inlet pressure), 1e-12."""
    length = 1e-2
    fluid = fluids["newtonian"](viscosity=3.5e-3)
    make, p_in = _REVIEW[case]
    wall, tube = make(length)
    single = tubefsi.solve(fluid, wall, tube, pressure_drop=p_in - 100.0, outlet_pressure=100.0)
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("u", "v", wall, tube)
    net.set_pressure("u", p_in).set_pressure("v", 100.0)
    assert rel_err(net.solve().flow_rates[0], single.flow_rate) < 1e-12
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("s", "u", walls["thick-neo-hookean"](shear_modulus=4e3),
                 tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-3))
    net.add_tube("u", "v", wall, tube)
    net.set_inflow("s", single.flow_rate).set_pressure("v", 100.0)
    assert rel_err(net.solve().pressure["u"], p_in) < 1e-12


def test_graded_edge_softer_inside_is_refused_naming_it():
    """A wall four times softer in the middle than at its ends: node pressures below both ends'
    limit pressures (21.9 kPa) but a profile that would pass the middle's (5.47 kPa) has no steady
    state. The single graded tube (:func:`tubefsi.solve`) refuses it with its largest inlet
    pressure; the network raises the same limit at once, naming the tube."""
    fluid = fluids["newtonian"](viscosity=3.5e-3)
    tube = tubefsi.Tube(radius=8e-4, thickness=1.6e-4, length=L)
    wall = walls["thick-neo-hookean"](shear_modulus=lambda z: MU * (1 + 3 * (2 * z / L - 1) ** 2))
    with pytest.raises(tubefsi.NoSteadyStateError) as single:
        tubefsi.solve(fluid, wall, tube, pressure_drop=10000.0, outlet_pressure=5000.0)
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("u", "v", wall, tube, name="soft middle")
    net.set_pressure("u", 15000.0).set_pressure("v", 5000.0)
    with pytest.raises(tubefsi.NoSteadyStateError, match="tube 'soft middle'") as info:
        net.solve()
    assert info.value.limit == single.value.limit
