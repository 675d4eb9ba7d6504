"""The steps of the transient model (docs/theory.md, section "Transients"), checked numerically,
and the long-time limit of tubefsi.evolve against tubefsi.solve for every kind of wall and fluid."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi.testing.profiles import scaled

TB = 0.3


@pytest.mark.parametrize("name", ["thin-linear", "thick-neo-hookean", "thick-mooney-rivlin", "thin-ogden"])
def test_compliance_identity(name):
    """C = dA/dp = 2 pi a^2 lambda / P'(lambda): a central difference of A(p) = pi a^2 lambda(p)^2
    from wall.strain against the tube law's slope wall.stiffness."""
    cls = tubefsi.registry.walls[name]
    wall = cls(**cls._examples[0])
    a = 1e-4
    lam = np.array([1.01, 1.1, 1.3])
    p = wall.pressure(lam, TB)
    h = 1e-5 * p

    def area(q):
        return math.pi * a**2 * (1.0 + wall.strain(q, TB)) ** 2

    difference = (area(p + h) - area(p - h)) / (2 * h)
    closed = 2 * math.pi * a**2 * lam / wall.stiffness(lam, TB)
    np.testing.assert_allclose(difference, closed, rtol=1e-6)


def test_signed_flow_function():
    """Q(-G, R) = -Q(G, R): a reversed gradient gives the reversed flow (the relaxation of an
    inflated tube empties it through the inlet)."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    r = tubefsi.evolve(fluid, wall, tube, np.linspace(0, 0.05, 6), inlet_pressure=0.0, initial=2e3,
                       outlet="closed", cells=16, error_control=False, rtol=1e-8)
    assert np.all(r.inlet_flow_rate[1:] < 0)                 # it empties through the inlet
    assert np.all(np.diff(r.stored_volume()) < 0)
    # the released volume: pi a^2 L (lambda(2 kPa)^2 - 1), lambda from the wall's tube law
    lam = 1.0 + wall.strain(2e3, tube.reduced_thickness)
    released = math.pi * tube.radius**2 * tube.length * (lam**2 - 1.0)
    assert -(r.volume_in[-1] - r.volume_in[0]) == pytest.approx(released, rel=2e-2)   # nearly empty at 0.05 s


WALLS = {
    "thin": ("thin-neo-hookean", {"shear_modulus": 2e4}),
    "thick": ("thick-neo-hookean", {"shear_modulus": 2e4}),
    "mooney-rivlin": ("thick-mooney-rivlin", None),
    "linear": ("thin-linear", {"youngs_modulus": 6e4, "poisson_ratio": 0.5}),
    "plugin": ("thick-gent", None),
}
FLUIDS = {
    "power-law": ("power-law", {"consistency": 0.017, "index": 0.7}),
    "newtonian": ("newtonian", {"viscosity": 3.5e-3}),
    "carreau": ("carreau", None),
}


def _model(registry, name, kwargs):
    cls = registry[name]
    return cls(**(kwargs if kwargs is not None else cls._examples[0]))


def _cases():
    for w in WALLS:
        for f in FLUIDS:
            slow = (w, f) != ("thick", "power-law")
            yield pytest.param(w, f, marks=[pytest.mark.slow] if slow else [], id=f"{w}-{f}")


@pytest.mark.parametrize("wall_kind, fluid_kind", list(_cases()))
def test_long_time_limit_against_solve(wall_kind, fluid_kind):
    """The steady flow rate of the transient on 16, 32, 64, 128 cells converges to tubefsi.solve's
    (the steady couplers: a different algorithm) at second order, and its extrapolation through
    q_n = q + c2 h^2 + c3 h^3 + c4 h^4 (the scheme's expansion: the half cells at the ends add odd
    powers) agrees with solve to 1e-10 (measured: 2e-12 to 7e-12; three grids and two terms
    leave the h^4 term, 4e-11 to 2e-9 from 16, 32, 64 cells)."""
    wall = _model(tubefsi.registry.walls, *WALLS[wall_kind])
    fluid = _model(tubefsi.registry.rheologies, *FLUIDS[fluid_kind])
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    p_in = 0.1 * float(wall.small_strain_modulus(tube.reduced_thickness))     # ~10 % strain
    steady = tubefsi.solve(fluid, wall, tube, pressure_drop=p_in)
    # the slowest mode decays as exp(-pi^2 D t / L^2), D ~ dQ/dG / C: end at 60 of its time scales
    g = p_in / tube.length
    conductance = float(fluid.flow_rate(tube.radius, g)) / g
    compliance = 2 * math.pi * tube.radius**2 / float(wall.small_strain_modulus(tube.reduced_thickness))
    t_end = 60 * tube.length**2 * compliance / (math.pi**2 * conductance)
    cells = np.array([16, 32, 64, 128])
    values = np.array([tubefsi.evolve(fluid, wall, tube, [0.0, t_end], inlet_pressure=p_in, cells=n, rtol=1e-12,
                                      error_control=False).inlet_flow_rate[-1] for n in cells])
    errors = np.abs(values - steady.flow_rate) / steady.flow_rate
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((1.8 < orders) & (orders < 2.1)), orders
    h = cells[0] / cells
    q = np.linalg.solve(np.column_stack([np.ones(4), h**2, h**3, h**4]), values)[0]
    assert abs(q - steady.flow_rate) / steady.flow_rate < 1e-10


def test_accuracy_warning_states_the_estimate(monkeypatch):
    """Where the refinement reaches its limits (here the cells, capped at 64 for the test) the
    finest run comes back with an AccuracyWarning stating the estimate, which the result reports."""
    import importlib

    monkeypatch.setattr(importlib.import_module("tubefsi.evolve"), "MAX_CELLS", 64)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    with pytest.warns(tubefsi.AccuracyWarning, match="estimated relative error") as caught:
        r = tubefsi.evolve(fluid, wall, tube, np.linspace(0, 0.01, 6), inlet_pressure=1e3, rtol=1e-7)
    assert r.cells == 64
    assert r.error_estimate > 1e-7
    assert f"{r.error_estimate:.2g}" in str(caught[0].message)


@settings(deadline=None, max_examples=scaled(6))
@given(modulus=st.floats(5e3, 1e5), index=st.floats(0.5, 1.2), rate=st.floats(1e-12, 1e-10),
       closed=st.booleans())
def test_pump_conserves_mass(modulus, index, rate, closed):
    """Contract: a pump's stored volume grows by exactly what it delivered minus what left
    (the unknowns are the cells' areas: to the integrator's Newton tolerance), for any fluid
    index, wall modulus, flow rate and outlet."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=index)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=modulus)
    times = np.linspace(0.0, 0.01, 6)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_flow_rate=rate, outlet="closed" if closed else "open",
                       cells=16, rtol=1e-6, error_control=False)
    np.testing.assert_allclose(r.inlet_flow_rate, rate, rtol=0, atol=0)
    delivered = rate * times - (r.volume_out - r.volume_out[0])
    stored = r.stored_volume() - r.stored_volume()[0]
    assert np.max(np.abs(stored - delivered)) <= 1e-6 * rate * times[-1]
    assert r.mass_error <= 1e-6


def test_self_similar_nonlinear_wall():
    r"""A Newtonian fluid in a thick neo-Hookean tube (strain up to 15 %) behind a pressure step,
    on a tube long enough to be semi-infinite at the times used: :math:`\lambda = \Lambda(\eta)`,
    :math:`\eta = z/\sqrt t`, with

    .. math:: g' = -\pi a^2\eta\Lambda\Lambda', \qquad \Lambda' = g/(K(\Lambda)P'(\Lambda)),

    :math:`K = \pi a^4\Lambda^4/(8\mu)`, :math:`\Lambda(0) = \lambda(p_{in})`, :math:`\Lambda(\infty) = 1`:
    shooting on :math:`g(0)` (bisection on whether the DOP853 solution, rtol 1e-12, crosses
    :math:`\Lambda = 1`). Then :math:`q(0, t)\sqrt t = -g(0)` and :math:`p(z, t) = P(\Lambda(z/\sqrt t))`."""
    from scipy.integrate import solve_ivp

    a, tb, mu = 1e-4, 0.3, 1e-3
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=mu)
    p_in = 3e3
    lam_in = 1.0 + float(wall.strain(p_in, tb))

    def rhs(eta, y):
        lam, g = y
        dlam = g / (math.pi * (a * lam) ** 4 / (8 * mu) * float(wall.stiffness(max(lam, 1.0), tb)))
        return [dlam, -math.pi * a * a * eta * lam * dlam]

    def crossed(eta, y):
        return y[0] - 1.0

    crossed.terminal = True

    def shoot(g0):
        return solve_ivp(rhs, (0.0, 1.0), [lam_in, g0], method="DOP853", rtol=1e-12, atol=1e-16,
                         events=crossed, dense_output=True)

    steep, shallow = -1e-8, -1e-14
    for _ in range(45):
        mid = -math.sqrt(steep * shallow)
        steep, shallow = (mid, shallow) if shoot(mid).status == 1 else (steep, mid)
    g0 = 0.5 * (steep + shallow)
    profile = shoot(shallow)

    tube = tubefsi.Tube(radius=a, thickness=tb * a, length=0.1)     # eta(L) >= 1 at t <= 0.01 s
    times = np.linspace(0.0, 0.01, 11)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=p_in, outlet="closed", rtol=1e-4)
    error = np.max(np.abs(r.inlet_flow_rate[1:] * np.sqrt(times[1:]) / -g0 - 1.0))
    assert error < 1e-4
    assert error < 3 * r.error_estimate
    z = np.array([0.005, 0.01, 0.02, 0.04])
    expected = wall.pressure(profile.sol(z / math.sqrt(times[-1]))[0], tb)
    np.testing.assert_allclose(r.pressure(z, times[-1]), expected, rtol=0, atol=1e-4 * p_in)


def test_outlet_and_external_pressure_reach_solve():
    """Gauge outlet pressure 1 kPa, 0.5 kPa outside, 3 kPa at the inlet: the long-time flow of 64
    cells is solve's (same outlet and external pressures) to the discretization, and ``steady()``
    is that solve."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    reference = tubefsi.solve(fluid, wall, tube, pressure_drop=2e3, outlet_pressure=1e3, external_pressure=500.0)
    r = tubefsi.evolve(fluid, wall, tube, [0.0, 1.0], inlet_pressure=3e3, outlet_pressure=1e3, external_pressure=500.0,
                       cells=64, rtol=1e-9, error_control=False)
    assert r.inlet_flow_rate[-1] == pytest.approx(reference.flow_rate, rel=1e-3)
    assert r.steady().flow_rate == reference.flow_rate
    assert r.radius(0.0, 1.0) == pytest.approx(reference.inlet_radius, rel=1e-9)


@pytest.mark.parametrize("fluid_kind", ["power-law", "carreau"])
@pytest.mark.parametrize("boundary", ["open", "pump-closed", "chamber"])
def test_jacobian_against_central_differences(fluid_kind, boundary):
    """The semi-discrete system's analytic Jacobian (the face flows' slopes from the
    Rabinowitsch–Mooney form, the wall's stiffness) against central differences of its right-hand
    side at a non-uniform state (steps 1e-6 of each unknown: truncation and rounding ~1e-9)."""
    import importlib

    evolve_module = importlib.import_module("tubefsi.evolve")
    fluid = _model(tubefsi.registry.rheologies, *FLUIDS[fluid_kind])
    wall = _model(tubefsi.registry.walls, *WALLS["plugin"])
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    inlet = dict(inlet_flow_rate=1e-10) if boundary == "pump-closed" else dict(inlet_pressure=2e3)
    outlet = {"open": "open", "pump-closed": "closed",
              "chamber": tubefsi.Chamber(volume=lambda p: 1e-9 + 1e-13 * p + 1e-17 * p**2)}[boundary]
    system, _, y0_of, _, _ = evolve_module._setup(fluid, wall, tube, [0.0, 1.0], inlet.get("inlet_pressure"),
                                                  inlet.get("inlet_flow_rate"), 0.0 if outlet == "open" else None,
                                                  outlet, 0.0, None, 1e-6, "BDF", 12)
    n = system.n
    y = y0_of(system)
    y[:n] = 0.01 + 0.03 * (1.0 + np.sin(np.arange(n)))
    if boundary == "chamber":
        y[n] = 700.0
    exact = system.jacobian(0.3, y).toarray()
    differences = np.zeros_like(exact)
    for k in range(system.size - 2):                 # (the counters' columns are zero)
        step = 1e-6 * max(abs(y[k]), 1e-2 if k < n else 1e3)
        e = np.zeros(system.size)
        e[k] = step
        differences[:, k] = (system.rhs(0.3, y + e) - system.rhs(0.3, y - e)) / (2 * step)
    assert np.max(np.abs(exact - differences)) <= 1e-6 * np.max(np.abs(differences))


@pytest.mark.parametrize("index", [0.7, 1.0, 1.3])
def test_jacobian_slope_at_rest(index):
    """At rest (G = 0) the face flow's slope dq/dG steers Newton's iteration: a power law's
    closed form dQ/dG = Q/(nG), Q = pi n/(3n+1) R^3 (GR/2m)^(1/n), taken at 1e-5 of the scale's
    gradient p_s/L for a shear-thinning law (its slope vanishes at rest), at 1e-8 of it otherwise
    (Newtonian: the same; shear-thickening: the larger slope nearer rest, kept); above 1e-5 p_s/L
    the exact slope."""
    import importlib

    evolve_module = importlib.import_module("tubefsi.evolve")
    m = 0.017
    fluid = tubefsi.registry.rheologies["power-law"](consistency=m, index=index)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    system, _, _, _, _ = evolve_module._setup(fluid, wall, tube, [0.0, 1.0], 2e3, None, None, "open", 0.0, None,
                                              1e-6, "BDF", 8)
    scale = 2e3 / tube.length
    radius = np.full(3, 1.1e-4)
    gradient = np.array([0.0, 3e-6 * scale, 0.3 * scale])

    def slope(g):                                    # the closed form
        q = math.pi * index / (3 * index + 1) * radius[0] ** 3 * (g * radius[0] / (2 * m)) ** (1 / index)
        return q / (index * g)

    at_rest = slope(1e-5 * scale) if index < 1 else slope(1e-8 * scale)
    expected = [at_rest, max(slope(3e-6 * scale), slope(1e-5 * scale)), slope(0.3 * scale)]
    d_gradient, _ = system.face_slopes(radius, gradient)
    np.testing.assert_allclose(d_gradient, expected, rtol=1e-12)
