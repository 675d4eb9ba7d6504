"""Transients of graded tubes (radius, thickness or wall modulus varying along z): the long-time
limit against tubefsi.solve (the Graded coupler: a different algorithm), mass conservation, and
the transient of a linear taper against an independent spectral solution of the linear PDE."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi.testing.profiles import scaled

L = 1e-2


def _fluid(kind="power-law"):
    if kind == "power-law":
        return tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    return tubefsi.registry.rheologies["newtonian"](viscosity=3.5e-3)


def _taper():
    return tubefsi.Tube.tapered(length=L, radius=1.2e-4, outlet_radius=0.8e-4, thickness=3.6e-5)


def _graded_wall():
    """A thick neo-Hookean wall twice as stiff at the outlet as at the inlet."""
    return tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=lambda z: 2e4 * (1.0 + z / L))


def _extrapolated(values, cells):
    """The limit of q_n = q + c2 h^2 + c3 h^3 + c4 h^4 through four grids (the scheme's expansion:
    the half cells at the ends add odd powers)."""
    h = cells[0] / cells
    return np.linalg.solve(np.column_stack([np.ones(cells.size), h**2, h**3, h**4]), values)[0]


def _settled(fluid, wall, tube, p):
    """A time of 60 of the slowest mode's decay times, exp(-pi^2 D t / L^2), D ~ (dQ/dG) / C at the
    narrowest, softest section."""
    a = 0.8e-4
    g = p / tube.length
    conductance = float(fluid.flow_rate(a, g)) / g
    compliance = 2 * math.pi * 1.2e-4**2 / float(tubefsi.registry.walls["thick-neo-hookean"](
        shear_modulus=2e4).small_strain_modulus(0.3))
    return 60 * tube.length**2 * compliance / (math.pi**2 * conductance)


CASES = {
    "taper-pressure": (_taper, "neo-hookean", "pressure"),
    "taper-pump": (_taper, "neo-hookean", "pump"),
    "graded-wall-pressure": (lambda: tubefsi.Tube(radius=1e-4, thickness=3e-5, length=L), "graded", "pressure"),
}


@pytest.mark.parametrize("case", [pytest.param(c, marks=[pytest.mark.slow] if c.startswith("graded") else [])
                                  for c in CASES])
def test_long_time_limit_against_solve(case):
    """The steady inlet flow (a pressure inlet) or inlet pressure (a pump) of the transient of a
    graded tube on 16, 32, 64, 128 cells converges to tubefsi.solve's for the same graded tube (the
    Graded coupler: an error-controlled integration of the steady ODE along z, a different
    algorithm) at second order (observed 2.0 to 2.5), and its extrapolation agrees with solve to
    1e-10 (measured 2.5e-12 to 2.3e-11)."""
    make_tube, wall_kind, inlet = CASES[case]
    tube = make_tube()
    wall = _graded_wall() if wall_kind == "graded" else tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    fluid = _fluid()
    p_in = 1.6e3                                                     # ~10 % strain at the inlet
    steady = tubefsi.solve(fluid, wall, tube, pressure_drop=p_in, outlet_pressure=200.0)
    t_end = _settled(fluid, wall, tube, p_in)
    cells = np.array([16, 32, 64, 128])
    if inlet == "pressure":
        runs = [tubefsi.evolve(fluid, wall, tube, [0.0, t_end], inlet_pressure=p_in + 200.0, outlet_pressure=200.0,
                               cells=n, rtol=1e-12, error_control=False) for n in cells]
        values, expected = np.array([r.inlet_flow_rate[-1] for r in runs]), steady.flow_rate
    else:
        runs = [tubefsi.evolve(fluid, wall, tube, [0.0, t_end], inlet_flow_rate=steady.flow_rate,
                               outlet_pressure=200.0, initial=200.0, cells=n, rtol=1e-12, error_control=False)
                for n in cells]
        values, expected = np.array([r.inlet_pressure[-1] for r in runs]) - 200.0, steady.pressure_drop
    errors = np.abs(values - expected) / expected
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((1.8 < orders) & (orders < 2.6)), orders
    assert abs(_extrapolated(values, cells) - expected) / expected < 1e-10
    # the steady state the result reports is solve's for the graded tube, and its stored volume
    assert runs[-1].steady().flow_rate == pytest.approx(steady.flow_rate, rel=1e-12)
    assert runs[-1].stored_volume()[-1] == pytest.approx(runs[-1].steady_volume(), rel=1e-4)


@settings(deadline=None, max_examples=scaled(5))
@given(outlet_radius=st.floats(0.5e-4, 2e-4), rate=st.floats(1e-11, 1e-10), closed=st.booleans())
def test_graded_pump_conserves_mass(outlet_radius, rate, closed):
    """Contract: behind a pump the stored volume of a tapered tube grows by exactly what was pumped
    in minus what left (the unknowns are the cells' areas, each relative to its own radius: to
    the integrator's Newton tolerance), for any taper and outlet."""
    tube = tubefsi.Tube.tapered(length=L, radius=1e-4, outlet_radius=outlet_radius, thickness=3e-5)
    times = np.linspace(0.0, 0.01, 6)
    r = tubefsi.evolve(_fluid(), _graded_wall(), tube, times, inlet_flow_rate=rate,
                       outlet="closed" if closed else "open", cells=16, rtol=1e-6, error_control=False)
    delivered = rate * times - (r.volume_out - r.volume_out[0])
    stored = r.stored_volume() - r.stored_volume()[0]
    assert np.max(np.abs(stored - delivered)) <= 1e-6 * rate * times[-1]
    assert r.mass_error <= 1e-6


def test_closed_graded_tube_fills_to_its_steady_volume():
    """A pressure inlet into a closed taper of graded modulus: the stored volume tends to the
    integral of pi a(z)^2 lambda(p_in; z)^2 (steady_volume, by Gauss-Legendre quadrature of the
    local tube laws), and the radius at the nodes to a(z) lambda(p_in; z)."""
    tube = _taper()
    wall = _graded_wall()
    p_in = 1e3
    r = tubefsi.evolve(_fluid("newtonian"), wall, tube, np.linspace(0.0, 2.0, 5), inlet_pressure=p_in,
                       outlet="closed", rtol=1e-6)
    assert r.stored_volume()[-1] == pytest.approx(r.steady_volume(), rel=1e-6)
    z = r.z                                           # (the nodes: 0, the cell centres, L)
    a = 1.2e-4 + (0.8e-4 - 1.2e-4) * z / L
    expected = a * (1.0 + tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4 * (1 + z / L)).strain(p_in, 0.3))
    np.testing.assert_allclose(r.radius_nodes[-1], expected, rtol=1e-6)


def _spectral_inlet_flow(a_of, compliance_of, mu, length, p_in, times, nodes):
    r"""The inlet flow of the linear PDE :math:`C(z)\,p_t = (K(z)\,p_z)_z`, :math:`K = \pi a^4/(8\mu)`,
    :math:`p(0) = p_{in}`, :math:`p(L) = 0`, :math:`p(z, 0) = 0`, by vertex-centred finite
    differences on ``nodes`` intervals (K at the midpoints) and the exact solution in time of the
    semi-discrete system by its generalized eigen-decomposition (no time stepping: a different
    algorithm from evolve's finite volumes and BDF). The inlet flow is the half-cell balance
    :math:`q(0) = -K_{1/2}(p_1 - p_0)/h + (h/2)\,C_{1/4}\,\bar p_t` (second order)."""
    from scipy.linalg import eigh_tridiagonal

    h = length / nodes
    z = np.arange(nodes + 1) * h
    k = math.pi * a_of(z[:-1] + 0.5 * h) ** 4 / (8.0 * mu)           # K at the midpoints
    c = compliance_of(z[1:-1])                                        # C at the inner nodes
    # steady state: (K p_z)_z = 0, p = p_in (1 - int_0^z 1/K / int_0^L 1/K)
    resistance = np.concatenate([[0.0], np.cumsum(h / k)])
    steady = p_in * (1.0 - resistance / resistance[-1])
    # C u_t = D u for the departure u = p - steady (u = 0 at both ends): symmetric with w = sqrt(C) u
    diag = -(k[:-1] + k[1:]) / h**2 / c
    off = k[1:-1] / h**2 / np.sqrt(c[:-1] * c[1:])
    omega, vectors = eigh_tridiagonal(diag, off)
    w0 = np.sqrt(c) * -steady[1:-1]
    amplitudes = vectors.T @ w0
    decay = np.exp(np.outer(times, omega))                          # (times, modes)
    u1 = (decay * amplitudes) @ vectors[0] / math.sqrt(c[0])        # u at the first inner node
    du1 = (decay * (omega * amplitudes)) @ vectors[0] / math.sqrt(c[0])
    q_half = -k[0] * (steady[1] + u1 - p_in) / h
    c_quarter = compliance_of(np.array([0.25 * h]))[0]
    return q_half + 0.5 * h * c_quarter * 0.25 * du1     # p_t ~ du1 z/h near the inlet: its mean over [0, h/2]


def test_linear_taper_transient_against_spectral_solution():
    """A linear taper (radius 1.2e-4 to 0.6e-4 m, thickness t/a = 0.3), Newtonian fluid, thin
    linear wall at strain ~1e-8 (the linear limit): evolve's inlet flow history (rtol 1e-5) against
    the independent spectral solution of C(z) p_t = (K(z) p_z)_z (_spectral_inlet_flow) on 500
    and 1000 intervals, Richardson-extrapolated (within 3e-10 of the extrapolation from 250 and
    500; measured: evolve's error 1.1e-6, its estimate 4.8e-6).
    C(z) = 2 pi a(z)^2 / P'(1; t/a) is the linear wall's small-strain compliance, K = pi a^4/(8 mu)."""
    a0, a1, mu = 1.2e-4, 0.6e-4, 1e-3
    tube = tubefsi.Tube.tapered(length=L, radius=a0, outlet_radius=a1, thickness=0.3 * a0)
    wall = tubefsi.registry.walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=mu)
    stiffness = float(wall.stiffness(1.0, 0.3))                     # P'(1): the same t/a all along

    def a_of(z):
        return a0 + (a1 - a0) * z / L

    def compliance_of(z):
        return 2.0 * math.pi * a_of(z) ** 2 / stiffness

    p_in = 1e-8 * stiffness
    t_scale = L**2 * compliance_of(0.0) / (math.pi * a1**4 / (8 * mu))
    times = np.linspace(0.0, 0.5 * t_scale, 11)
    flows = [_spectral_inlet_flow(a_of, compliance_of, mu, L, p_in, times[1:], n) for n in (250, 500, 1000)]
    coarse, reference = (fine + (fine - coarse) / 3.0 for coarse, fine in zip(flows[:-1], flows[1:]))
    scale = float(np.max(np.abs(reference)))
    assert np.max(np.abs(reference - coarse)) < 1e-8 * scale          # the reference's own convergence (3e-10)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=p_in, rtol=1e-5)
    error = np.max(np.abs(r.inlet_flow_rate[1:] - reference)) / scale
    assert error < 1e-5
    assert error < r.error_estimate


def test_uniform_profile_is_the_uniform_tube():
    """A tube whose radius is a constant profile (the graded path: per-cell radii, tube laws per
    cell) gives the uniform tube's transient to rounding."""
    fluid, wall = _fluid(), tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    uniform = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=L)
    graded = tubefsi.Tube(radius=lambda z: 1e-4 + 0.0 * z, thickness=3e-5, length=L)
    assert graded.graded
    kwargs = dict(inlet_pressure=2e3, outlet="closed", cells=16, rtol=1e-8, error_control=False)
    times = np.linspace(0.0, 0.02, 5)
    r_u, r_g = (tubefsi.evolve(fluid, wall, t, times, **kwargs) for t in (uniform, graded))
    np.testing.assert_allclose(r_g.flow_faces, r_u.flow_faces, rtol=1e-9, atol=1e-9 * np.max(r_u.flow_faces))
    np.testing.assert_allclose(r_g.radius_nodes, r_u.radius_nodes, rtol=1e-12)


def test_graded_steady_start_stays_steady():
    """Started from solve's steady Solution of the same graded tube (the same tube object: a
    profile compares by identity), the transient stays there: its inlet flow after the start is
    solve's to the discretization (the error-controlled, extrapolated histories), and another
    taper object with the same numbers is refused by name."""
    fluid, wall, tube = _fluid(), _graded_wall(), _taper()
    steady = tubefsi.solve(fluid, wall, tube, pressure_drop=1e3)
    r = tubefsi.evolve(fluid, wall, tube, np.linspace(0.0, 0.01, 5), inlet_pressure=1e3, initial=steady, rtol=1e-6)
    np.testing.assert_allclose(r.inlet_flow_rate[1:], steady.flow_rate, rtol=1e-5)
    with pytest.raises(tubefsi.InvalidParameterError, match="its tube radius") as info:
        tubefsi.evolve(fluid, wall, _taper(), [0.0, 0.01], inlet_pressure=1e3, initial=steady)
    assert info.value.parameter == "initial"


def test_cli_evolve_of_a_taper(tmp_path):
    """``tubefsi evolve --tube ...,outlet_radius=..,outlet_thickness=..`` (the command line's
    linear taper) writes the histories of the same graded call."""
    from tubefsi.cli import main

    status = main(["evolve", "--rheology", "power-law:consistency=0.017,index=0.7", "--wall",
                   "thick-neo-hookean:shear_modulus=2e4", "--tube",
                   "radius=1.2e-4,thickness=3.6e-5,length=1e-2,outlet_radius=0.8e-4,outlet_thickness=2.4e-5",
                   "--inlet-pressure", "1e3",
                   "--t-end", "0.01", "--steps", "5", "--rtol", "1e-3", "--output", str(tmp_path / "h.csv")])
    assert status == 0
    table = np.loadtxt(tmp_path / "h.csv", delimiter=",", skiprows=1)
    r = tubefsi.evolve(_fluid(), tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4), _taper(),
                       np.linspace(0.0, 0.01, 5), inlet_pressure=1e3, rtol=1e-3)
    # (the same taper but for the rounding of the outlet thickness: Tube.tapered's t0 aL/a0)
    np.testing.assert_allclose(table[:, 1], r.inlet_flow_rate, rtol=1e-9)
