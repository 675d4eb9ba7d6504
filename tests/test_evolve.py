"""tubefsi.evolve against independent references.

* the linear limit (Newtonian fluid, thin linear wall at strain 1e-8): the Fourier series of
  p_t = D p_zz for a pressure step with an open (p = 0) and a closed (p_z = 0) end, summed here;
* the long-time limit against tubefsi.solve (a different algorithm: the steady couplers), the
  finite-volume answers of three grids Richardson-extrapolated;
* the observed order of convergence in space (2);
* a dead-end chamber behind a stiff tube against the lumped RC closed form;
* mass: a pump into a closed end stores exactly q t.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import tubefsi

A, T, L, E, MU = 1e-4, 1e-5, 1e-2, 1e6, 1e-3


def _linear_setup():
    tube = tubefsi.Tube(radius=A, thickness=T, length=L)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=MU)
    # thin, open ends: lambda = 1 + p a/(E t) exactly (docs/walls_beyond.md)
    wall = tubefsi.registry.walls["thin-linear"](youngs_modulus=E, poisson_ratio=0.5, end_condition="open")
    conductance = math.pi * A**4 / (8 * MU)              # Poiseuille
    compliance = 2 * math.pi * A**2 / (E * T / A)        # dA/dp at small strain
    return tube, fluid, wall, conductance, conductance / compliance


def _series(kind, t, conductance, diffusivity, p_in):
    """Inlet flow -K p_z(0, t) of the Fourier series solution (4000 terms: e^{-n^2 pi^2 D t/L^2}
    is below 1e-300 long before at the times used)."""
    n = np.arange(1, 4001)[:, None]
    if kind == "open":
        return conductance * p_in / L * (1 + 2 * np.sum(np.exp(-diffusivity * (n * math.pi / L) ** 2 * t), axis=0))
    k = (2 * n - 1) * math.pi / (2 * L)
    return conductance * 2 * p_in / L * np.sum(np.exp(-diffusivity * k**2 * t), axis=0)


@pytest.mark.parametrize("rtol", [1e-4, pytest.param(1e-6, marks=pytest.mark.slow)])
@pytest.mark.parametrize("outlet", ["open", "closed"])
def test_linear_limit_against_fourier_series(outlet, rtol):
    """The error-controlled inlet flow (boundary histories extrapolated from 2n and 4n cells)
    against the series: within rtol and within the estimate (its sharpness:
    tests/test_evolve_estimate.py)."""
    tube, fluid, wall, conductance, diffusivity = _linear_setup()
    p_in = 1e-3                                          # strain 1e-8: the nonlinearity is ~4e-8
    times = np.linspace(0.0, 4e-3, 41)
    result = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=p_in, outlet=outlet, rtol=rtol)
    reference = _series(outlet, times[1:], conductance, diffusivity, p_in)
    error = np.max(np.abs(result.inlet_flow_rate[1:] - reference)) / np.max(reference)
    assert error <= rtol
    assert error <= result.error_estimate            # the estimate is honest
    assert result.mass_error < 1e-6


@pytest.mark.slow
def test_long_time_limit_matches_solve():
    """A power-law fluid in a thick neo-Hookean tube: the steady flow rate of the transient (at
    t = 40 diffusion times, on 16, 32, 64 cells, extrapolated with h^2 and h^3 terms) against
    ``solve`` (quadrature of the steady ODE)."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    p_in = 2e3
    steady = tubefsi.solve(fluid, wall, tube, pressure_drop=p_in)
    values = []
    for n in (16, 32, 64):
        r = tubefsi.evolve(fluid, wall, tube, [0.0, 5.0], inlet_pressure=p_in, cells=n, rtol=1e-11,
                           error_control=False)
        values.append(r.inlet_flow_rate[-1])
        assert r.outlet_flow_rate[-1] == pytest.approx(r.inlet_flow_rate[-1], rel=1e-9)
    q16, q32, q64 = values
    # q_n = q + c2 h^2 + c3 h^3 through the three grids
    h = np.array([1.0, 0.5, 0.25])
    coefficients = np.linalg.solve(np.column_stack([np.ones(3), h**2, h**3]), np.array(values))
    assert abs(q64 - steady.flow_rate) / steady.flow_rate < 1e-3
    assert abs(coefficients[0] - steady.flow_rate) / steady.flow_rate < 1e-7


def test_order_of_convergence_in_space():
    """A smooth ramp of the inlet pressure (no singular start): differences of the inlet-flow
    history halve twice per halving of the cells."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    times = np.linspace(0.0, 0.02, 21)
    ramp = lambda t: 2e3 * -np.expm1(-np.asarray(t) / 2e-3)  # noqa: E731
    runs = [tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=ramp, cells=n, rtol=1e-10,
                           error_control=False).inlet_flow_rate for n in (16, 32, 64)]
    ratio = np.max(np.abs(runs[0] - runs[1])) / np.max(np.abs(runs[1] - runs[2]))
    assert 2.0 - 0.2 < math.log2(ratio) < 2.0 + 0.3


def test_dead_end_chamber_rc_limit():
    """A stiff tube (strain ~1e-12, compliance 6e-6 of the chamber's) into a linear chamber
    V = V0 + C p: p_ch = P (1 - exp(-t/tau)), tau = R C, R = 8 mu L/(pi a^4)."""
    tube = tubefsi.Tube(radius=A, thickness=T, length=L)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=MU)
    wall = tubefsi.registry.walls["thin-linear"](youngs_modulus=1e12, poisson_ratio=0.5, end_condition="open")
    resistance = 8 * MU * L / (math.pi * A**4)
    c_chamber = 1e-15 / 1.0                              # m^3/Pa
    tau = resistance * c_chamber
    p_in = 1.0
    times = np.linspace(0.0, 5 * tau, 26)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=p_in, outlet=tubefsi.Chamber.linear(1e-9, c_chamber),
                       rtol=1e-6)
    expected = p_in * -np.expm1(-times / tau)
    assert np.max(np.abs(r.chamber_pressure - expected)) / p_in < 3e-5
    q_expected = p_in / resistance * np.exp(-times[1:] / tau)
    assert np.max(np.abs(r.inlet_flow_rate[1:] - q_expected)) / np.max(q_expected) < 3e-5
    assert r.mass_error < 1e-6


def test_pump_into_closed_end_stores_q_t():
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    q = 1e-11
    times = np.linspace(0.0, 0.02, 11)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_flow_rate=q, outlet="closed", rtol=1e-4)
    stored = r.stored_volume() - r.stored_volume()[0]
    assert np.max(np.abs(stored - q * (times - times[0]))) <= 1e-9 * q * times[-1]
    assert np.all(r.outlet_flow_rate == 0.0)
    with pytest.raises(tubefsi.NoSteadyStateError):
        r.settling_time(0.9)


def test_settling_and_fields():
    tube, fluid, wall, conductance, diffusivity = _linear_setup()
    times = np.linspace(0.0, 8e-3, 81)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=1e-3, outlet="closed", rtol=1e-4)
    # closed end, linear limit: V(t) - V_inf ~ (8/pi^2) sum exp(-D k^2 t)/(2m-1)^2 (the series'
    # volume); 50 % is reached where that sum is half its initial value (solved by bisection here)
    m = np.arange(1, 2001)

    def remaining(t):
        k = (2 * m - 1) * math.pi / (2 * L)
        return 8 / math.pi**2 * np.sum(np.exp(-diffusivity * k**2 * t) / (2 * m - 1) ** 2)

    lo, hi = 0.0, 8e-3
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if remaining(mid) > 0.5 else (lo, mid)
    assert r.settling_time(0.5) == pytest.approx(lo, rel=2e-2)        # linear interpolation between outputs
    assert r.settling_time(0.5) < r.settling_time(0.9) < r.settling_time(0.99)
    # fields: interpolation reproduces the nodes and broadcasts
    assert r.pressure(0.0, times[5]) == pytest.approx(1e-3)
    assert np.shape(r.pressure(np.linspace(0, L, 7)[:, None], times[None, :])) == (7, times.size)
    assert r.flow_rate(L, times[3]) == 0.0
    assert np.all(np.diff(r.radius(0.5 * L, times)) >= -1e-18)       # the closed tube inflates
    with pytest.raises(tubefsi.InvalidParameterError):
        r.pressure(2 * L, times[1])


def test_initial_steady_solution_relaxes():
    """Starting from the steady state of the same pressure, nothing moves."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e4)
    steady = tubefsi.solve(fluid, wall, tube, pressure_drop=1e3)
    r = tubefsi.evolve(fluid, wall, tube, np.linspace(0, 0.01, 5), inlet_pressure=1e3, initial=steady,
                       cells=64, error_control=False, rtol=1e-9)
    # at t = 0 the profile of solve is not yet the 64-cell scheme's own: a discretization step
    assert abs(r.inlet_flow_rate[0] - steady.flow_rate) / steady.flow_rate < 3e-3
    assert np.max(np.abs(r.inlet_flow_rate[1:] - steady.flow_rate)) / steady.flow_rate < 1e-5


def test_validity_warning_with_density():
    tube, water, wall, _, _ = _linear_setup()
    # water: the pressure step settles in ~0.2 ms, faster than viscous diffusion across the bore
    # (a^2 rho/mu = 10 ms): Womersley ~ 7
    with pytest.warns(tubefsi.ModelValidityWarning, match="Womersley"):
        tubefsi.evolve(water, wall, tube, np.linspace(0.0, 4e-3, 11), inlet_pressure=1e-3, rtol=1e-2, density=1e3,
                       cells=16, error_control=False)
    # glycerol (mu = 1 Pa s): a thousand times slower, a^2 rho/mu = 10 us: quasi-steady
    glycerol = tubefsi.registry.rheologies["newtonian"](viscosity=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.ModelValidityWarning)
        tubefsi.evolve(glycerol, wall, tube, np.linspace(0.0, 4.0, 11), inlet_pressure=1e-3, rtol=1e-2,
                       density=1.26e3, cells=16, error_control=False)


@pytest.mark.parametrize("kwargs, name", [
    (dict(inlet_pressure=1.0, inlet_flow_rate=1e-9), "inlet_pressure / inlet_flow_rate"),
    (dict(), "inlet_pressure / inlet_flow_rate"),
    (dict(inlet_pressure=1.0, outlet="nowhere"), "outlet"),
    (dict(inlet_pressure=1.0, rtol=0.0), "rtol"),
    (dict(inlet_pressure=1.0, method="RK45"), "method"),
    (dict(inlet_pressure=1.0, cells=1), "cells"),
    (dict(inlet_pressure=math.nan), "inlet_pressure"),
])
def test_bad_input_names_the_parameter(kwargs, name):
    tube, fluid, wall, _, _ = _linear_setup()
    with pytest.raises(tubefsi.InvalidParameterError, match=name.split(" ")[0]):
        tubefsi.evolve(fluid, wall, tube, [0.0, 1e-3], **kwargs)


def test_array_parameters_that_do_not_broadcast_are_refused():
    """Arrays of scene parameters broadcast together (tests/test_evolve_batch.py); two that do not
    are refused, the second named."""
    tube, fluid, _, _, _ = _linear_setup()
    wall = tubefsi.registry.walls["thin-linear"](youngs_modulus=[1e6, 2e6], poisson_ratio=0.5)
    with pytest.raises(tubefsi.InvalidParameterError, match="wall.youngs_modulus has shape") as info:
        tubefsi.evolve(fluid, wall, tube, [0.0, 1e-3], inlet_pressure=[1.0, 2.0, 3.0])
    assert info.value.parameter == "inlet_pressure"


def test_bad_times():
    tube, fluid, wall, _, _ = _linear_setup()
    with pytest.raises(tubefsi.InvalidParameterError, match="times"):
        tubefsi.evolve(fluid, wall, tube, [0.0, 1e-3, 1e-3], inlet_pressure=1.0)


def test_outputs(tmp_path):
    tube, fluid, wall, _, _ = _linear_setup()
    times = np.linspace(0.0, 4e-3, 9)
    r = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=1e-3, outlet="closed", cells=8, error_control=False)
    r.to_csv(tmp_path / "h.csv")
    table = np.loadtxt(tmp_path / "h.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 1], r.inlet_flow_rate)
    fig = r.plot()
    assert len(fig.axes) == 3
    anim = r.animate()
    assert anim is not None
    xr = pytest.importorskip("xarray")
    ds = r.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert ds["pressure"].dims == ("time", "z")
    np.testing.assert_array_equal(ds["inlet_pressure"].values, r.inlet_pressure)


def test_cli_evolve(tmp_path, capsys):
    """``tubefsi evolve`` writes the histories of the same call as CSV, and a figure."""
    from tubefsi.cli import main

    status = main(["evolve", "--rheology", "newtonian:viscosity=1e-3", "--wall",
                   "thin-linear:youngs_modulus=1e6,poisson_ratio=0.5,end_condition=open",
                   "--tube", "radius=1e-4,thickness=1e-5,length=1e-2", "--inlet-pressure", "1e-3",
                   "--outlet", "closed", "--t-end", "4e-3", "--steps", "5", "--rtol", "1e-2",
                   "--output", str(tmp_path / "h.csv"), "--plot", str(tmp_path / "h.png")])
    assert status == 0
    table = np.loadtxt(tmp_path / "h.csv", delimiter=",", skiprows=1)
    tube, fluid, wall, _, _ = _linear_setup()
    r = tubefsi.evolve(fluid, wall, tube, np.linspace(0.0, 4e-3, 5), inlet_pressure=1e-3, outlet="closed", rtol=1e-2)
    np.testing.assert_array_equal(table[:, 1], r.inlet_flow_rate)
    assert (tmp_path / "h.png").stat().st_size > 0


def test_cli_evolve_refuses_an_outlet_pressure_at_a_closed_end(tmp_path, capsys):
    """``--outlet-pressure`` with ``--outlet closed`` has no meaning: it was silently ignored;
    now the command fails naming it (as ``evolve`` refuses ``outlet_pressure``)."""
    from tubefsi.cli import main

    status = main(["evolve", "--rheology", "newtonian:viscosity=1e-3", "--wall",
                   "thin-linear:youngs_modulus=1e6,poisson_ratio=0.5,end_condition=open",
                   "--tube", "radius=1e-4,thickness=1e-5,length=1e-2", "--inlet-pressure", "1e-3",
                   "--outlet", "closed", "--outlet-pressure", "5", "--t-end", "4e-3", "--steps", "5",
                   "--output", str(tmp_path / "h.csv")])
    assert status != 0
    assert "outlet_pressure" in capsys.readouterr().err
    assert not (tmp_path / "h.csv").exists()
