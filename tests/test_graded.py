"""Tapered and graded tubes (``docs/graded.md``): tube fields and wall parameters as functions of z.

References, each independent of the code under test:

* a linear taper with constant t/a: the separated identity with the taper's integral, both by
  mpmath at 30 digits (``mp.quad`` of :math:`a(z)^{-k}` and of :math:`P'(s)s^k`, ``mp.findroot``),
  with the thick neo-Hookean tube law written here from its closed form;
* a graded tube (modulus or thickness varying along z): a chain of uniform segments solved one
  after the other with the *uniform* engine (each segment's outlet pressure the next one's
  inlet pressure), whose midpoint-rule error is second order in the segment length (the order
  is measured), extrapolated twice by Richardson.
"""

from __future__ import annotations

import math
import warnings

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi.couplers import Graded
from tubefsi.scene import make_scene
from tubefsi.testing.profiles import scaled

walls = tubefsi.registry.walls
fluids = tubefsi.registry.rheologies
mp.mp.dps = 30

L = 0.05
A0, A1 = 1e-3, 0.6e-3
TB = 0.2
MU = 2e4


def taper(a0=A0, a1=A1, length=L):
    return lambda z: a0 + (a1 - a0) * z / length


def power_law(n, m=0.5):
    return fluids["power-law"](consistency=m, index=n)


# ------------------------------------------------------------------ mpmath reference of the taper
def thick_nh(mu, tb):
    r"""Thick neo-Hookean tube law :math:`P(\lambda) = \mu[\ln(\lambda/\lambda_o) - 1/(2\lambda^2)
    + 1/(2\lambda_o^2)]`, :math:`\lambda_o^2 = 1 + (\lambda^2 - 1)/(1 + \bar t)^2` (the Lamé integral
    of :math:`\mu(s - s^{-3})/(s^2 - 1)`), in mpmath."""
    mu, tb = mp.mpf(mu), mp.mpf(tb)

    def P(lam):
        lo2 = 1 + (lam**2 - 1) / (1 + tb) ** 2
        return mu * (mp.log(lam) - mp.log(lo2) / 2 - 1 / (2 * lam**2) + 1 / (2 * lo2))

    return P


def thick_nh_slope(mu, tb):
    r""":math:`P'(\lambda) = \mu\,d((d + 2)\lambda^2 + d)/(\lambda^3(\lambda^2 + d)^2)`,
    :math:`d = (1 + \bar t)^2 - 1`: the derivative of :func:`thick_nh`, simplified by hand so that
    it decays as :math:`\lambda^{-5}` without cancellation (for the integral to infinity)."""
    mu, d = mp.mpf(mu), (1 + mp.mpf(tb)) ** 2 - 1

    def dP(lam):
        x = lam**2
        return mu * d * ((d + 2) * x + d) / (lam * x * (x + d) ** 2)

    return dP


def taper_reference(n, m, q, z, a0=A0, a1=A1, length=L, mu=MU, tb=TB):
    r"""``(p(z), R(z))`` of a power-law fluid in a linearly tapered thick neo-Hookean tube with
    constant t/a: :math:`\int_1^{\lambda(z)} P'(s) s^k ds = \phi(q)\int_z^L a^{-k} dz'`."""
    n, m, q = mp.mpf(n), mp.mpf(m), mp.mpf(q)
    k = 3 * n + 1
    phi = 2 * m * ((3 * n + 1) * q / (mp.pi * n)) ** n
    a = lambda x: mp.mpf(a0) + (mp.mpf(a1) - mp.mpf(a0)) * x / mp.mpf(length)   # noqa: E731
    P = thick_nh(mu, tb)
    target = phi * mp.quad(lambda x: a(x) ** -k, [mp.mpf(z), mp.mpf(length)])
    dP = thick_nh_slope(mu, tb)
    J = lambda lam: mp.quad(lambda s: dP(s) * s**k, [1, lam]) - target   # noqa: E731
    guess = 1 + target / dP(mp.mpf(1))
    lam = mp.findroot(J, (guess, guess * 1.01), solver="secant")
    return P(lam), a(mp.mpf(z)) * lam


@pytest.mark.parametrize("n", [0.6, 1.0, 1.3])
def test_linear_taper_matches_one_quadrature(n):
    """Pressure drop, inlet radius and the profiles of a linear taper with constant t/a (the exact,
    separable path), flow- and pressure-controlled, against mpmath: 1e-11."""
    q = 1e-7 if n < 1.2 else 2e-8
    tube = tubefsi.Tube(radius=taper(), thickness=lambda z: TB * taper()(z), length=L)
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    fluid = power_law(n)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    dp_ref, r_in = taper_reference(n, 0.5, q, 0.0)
    assert sol.pressure_drop == pytest.approx(float(dp_ref), rel=1e-11)
    assert sol.inlet_radius == pytest.approx(float(r_in), rel=1e-11)
    assert sol.inlet_displacement == pytest.approx(float(r_in - A0), rel=1e-11)
    for z in (0.3 * L, 0.8 * L):
        p_ref, r_ref = taper_reference(n, 0.5, q, z)
        assert sol.pressure(z) == pytest.approx(float(p_ref), rel=1e-11)
        assert sol.radius(z) == pytest.approx(float(r_ref), rel=1e-11)
    back = tubefsi.solve(fluid, wall, tube, pressure_drop=float(dp_ref))
    assert back.flow_rate == pytest.approx(q, rel=1e-11)


def test_taper_max_flow_rate_matches_one_quadrature():
    r"""A shear-thinning fluid in a thick neo-Hookean taper: :math:`\phi(q_{max})\int_0^L a^{-k}dz =
    \int_1^\infty P'(s)s^k ds` (mpmath), and a flow rate above it has no steady state."""
    n, m = 0.5, 0.5
    tube = tubefsi.Tube(radius=taper(), thickness=lambda z: TB * taper()(z), length=L)
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    k = 3 * mp.mpf(n) + 1
    a = lambda x: A0 + (A1 - A0) * x / L   # noqa: E731
    dP = thick_nh_slope(MU, TB)
    j_inf = mp.quad(lambda s: dP(s) * s**k, [1, 2, 10, mp.inf])
    phi = j_inf / mp.quad(lambda x: mp.mpf(a(x)) ** -k, [0, L])
    q_ref = mp.pi * n / (3 * n + 1) * (phi / (2 * m)) ** (1 / mp.mpf(n))
    q_max = tubefsi.max_flow_rate(power_law(n, m), wall, tube)
    assert q_max == pytest.approx(float(q_ref), rel=1e-10)
    with pytest.raises(tubefsi.NoSteadyStateError):
        tubefsi.solve(power_law(n, m), wall, tube, flow_rate=1.01 * q_max)


# ------------------------------------------------------------------ graded tubes: a segment chain
def chain(fluid, wall_at, radius_at, thickness_at, q, segments, upto=0.0):
    """The inlet pressure of a chain of ``segments`` uniform segments (midpoint values) from the
    outlet to ``upto``, each solved by the uniform engine with the previous one's inlet pressure."""
    p = 0.0
    h = L / segments
    mids = (np.arange(segments)[::-1] + 0.5) * h
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)   # short segments are not slender
        for zm in mids[mids > upto]:
            seg = tubefsi.Tube(radius=radius_at(zm), thickness=thickness_at(zm), length=h)
            p = tubefsi.solve(fluid, wall_at(zm), seg, flow_rate=q, outlet_pressure=p).inlet_pressure
    return p


def richardson(values):
    """Two Richardson steps of a second-order sequence at h, h/2, h/4; the observed order."""
    c1, c2, c3 = values
    order = math.log2((c2 - c1) / (c3 - c2))
    r1, r2 = (4 * c2 - c1) / 3, (4 * c3 - c2) / 3
    return (16 * r2 - r1) / 15, order


def _nh(mu):
    return walls["thick-neo-hookean"](shear_modulus=mu)


def _linear(e):
    return walls["thin-linear"](youngs_modulus=e, poisson_ratio=0.5)


#: name -> (fluid, wall, tube, and per position z: the segment's wall, radius and thickness)
CASES = {
    # a modulus graded along a uniform tube: not separable, integrated along z
    "graded-modulus": (power_law(0.6), _nh(lambda z: MU * (1.0 + 1.5 * z / L)),
                       tubefsi.Tube(radius=A0, thickness=TB * A0, length=L),
                       lambda z: _nh(MU * (1.0 + 1.5 * z / L)), lambda z: A0, lambda z: TB * A0),
    # a taper of constant wall thickness: t/a varies, not separable
    "taper-constant-thickness": (power_law(0.6), _nh(MU), tubefsi.Tube(radius=taper(), thickness=2e-4, length=L),
                                 lambda z: _nh(MU), lambda z: taper()(z), lambda z: 2e-4),
    # a linear wall stiffening toward the outlet, a Newtonian fluid
    "linear-graded": (fluids["newtonian"](viscosity=0.05), _linear(lambda z: 3 * MU * np.exp(z / L)),
                      tubefsi.Tube(radius=A0, thickness=TB * A0, length=L),
                      lambda z: _linear(3 * MU * math.exp(z / L)), lambda z: A0, lambda z: TB * A0),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_graded_tube_matches_segment_chain(case):
    """The error-controlled integration along z against the uniform-segment chain at 32, 64 and
    128 segments: the chain converges at second order (observed 2 +- 0.05) and its twice
    Richardson-extrapolated value agrees to 1e-11, for the pressure drop, a mid-tube pressure and
    the flow rate of the pressure-controlled problem."""
    fluid, wall, tube, wall_at, r_at, t_at = CASES[case]
    q = 1e-7
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    assert sol.coupler_name == "Graded"
    ref, order = richardson([chain(fluid, wall_at, r_at, t_at, q, s) for s in (32, 64, 128)])
    assert abs(order - 2.0) < 0.05
    assert sol.pressure_drop == pytest.approx(ref, rel=1e-11)
    mid, _ = richardson([chain(fluid, wall_at, r_at, t_at, q, s, upto=L / 2) for s in (32, 64, 128)])
    assert sol.pressure(L / 2) == pytest.approx(mid, rel=1e-11)
    back = tubefsi.solve(fluid, wall, tube, pressure_drop=ref)
    assert back.flow_rate == pytest.approx(q, rel=1e-11)


# ------------------------------------------------------------------ limits (property tests)
@settings(max_examples=scaled(12), deadline=None)
@given(n=st.floats(0.4, 1.5), eps=st.floats(1e-9, 1e-3), separable=st.booleans())
def test_vanishing_taper_gives_the_uniform_tube(n, eps, separable):
    """a(z) = a0 (1 - eps z/L): the pressure drop differs from the uniform tube's by O(eps) (below
    (3n + 2) eps), on the separable path (t/a constant) and the integrated one (t constant)."""
    a = taper(A0, A0 * (1 - eps))
    thickness = (lambda z: TB * a(z)) if separable else TB * A0
    tube = tubefsi.Tube(radius=a, thickness=thickness, length=L)
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    dp = tubefsi.solve(power_law(n), wall, tube, flow_rate=1e-7).pressure_drop
    uniform = tubefsi.solve(power_law(n), wall, tubefsi.Tube(radius=A0, thickness=TB * A0, length=L),
                            flow_rate=1e-7).pressure_drop
    change = dp / uniform - 1.0
    assert 0.0 < change < (3 * n + 2) * eps


@settings(max_examples=scaled(6), deadline=None)
@given(n=st.floats(0.4, 1.5), q=st.floats(1e-9, 1e-7), tb=st.floats(0.05, 1.0))
def test_constant_callables_equal_the_scalar_tube(n, q, tb):
    """Constant functions of z give the scalar tube's answers: to 1e-13 where the scene separates
    (a power-law fluid: constant radius, thickness and modulus are recognised as such, and the
    equivalent length is L), to 1e-11 through the integration along z (a Carreau fluid, which never
    separates, with a constant modulus function)."""
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    scalar_tube = tubefsi.Tube(radius=A0, thickness=tb * A0, length=L)
    scalar = tubefsi.solve(power_law(n), wall, scalar_tube, flow_rate=q)
    tube = tubefsi.Tube(radius=lambda z: A0 + 0 * z, thickness=lambda z: np.full_like(z, tb * A0), length=L)
    graded = walls["thick-neo-hookean"](shear_modulus=lambda z: MU)        # a scalar return: a constant
    for sol in (tubefsi.solve(power_law(n), wall, tube, flow_rate=q),
                tubefsi.solve(power_law(n), graded, scalar_tube, flow_rate=q)):
        assert sol.pressure_drop == pytest.approx(scalar.pressure_drop, rel=1e-13)
        assert sol.inlet_radius == pytest.approx(scalar.inlet_radius, rel=1e-13)
        assert sol.pressure(L / 3) == pytest.approx(scalar.pressure(L / 3), rel=1e-13)
    carreau = fluids["carreau"](zero_shear_viscosity=0.05, infinite_shear_viscosity=0.0035, relaxation_time=3.3,
                                index=n)
    scalar = tubefsi.solve(carreau, wall, scalar_tube, flow_rate=q)
    gen = tubefsi.solve(carreau, graded, scalar_tube, flow_rate=q)
    assert gen.pressure_drop == pytest.approx(scalar.pressure_drop, rel=1e-11)
    assert gen.radius(L / 3) == pytest.approx(scalar.radius(L / 3), rel=1e-11)


# ------------------------------------------------------------------ arrays, tables, plots
def test_arrays_broadcast_along_a_graded_tube():
    """A curve of flow rates and an array modulus through one graded tube equal the scalar solves."""
    wall = walls["thick-neo-hookean"](shear_modulus=np.array([1e4, 4e4]))
    tube = tubefsi.Tube(radius=taper(), thickness=2e-4, length=L)
    q = np.array([[1e-8], [1e-7]])
    sol = tubefsi.solve(power_law(0.7), wall, tube, flow_rate=q)
    assert sol.pressure_drop.shape == (2, 2)
    for i, qi in enumerate(q.ravel()):
        for j, mu in enumerate((1e4, 4e4)):
            one = tubefsi.solve(power_law(0.7), walls["thick-neo-hookean"](shear_modulus=mu), tube, flow_rate=float(qi))
            assert sol.pressure_drop[i, j] == pytest.approx(one.pressure_drop, rel=1e-12)
    z = np.linspace(0, L, 4)[:, None, None]
    assert sol.radius(z).shape == (4, 2, 2)


def test_sampled_stenosis_and_its_breakpoints():
    """A stenosis given as a table (pchip) with t/a constant is separable; the same radius with a
    constant thickness is integrated, stopping at every knot; both agree with a fine chain."""
    zs = np.linspace(0, L, 21)
    a_tab = A0 * (1 - 0.4 * np.exp(-((zs - L / 2) / (L / 8)) ** 2))
    radius = tubefsi.sampled(zs, a_tab)
    assert radius.breakpoints == tuple(zs[1:-1])
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    sep = tubefsi.solve(power_law(0.7), wall, tubefsi.Tube(radius=radius, thickness=lambda z: TB * radius(z),
                                                           length=L), flow_rate=1e-8)
    gen = tubefsi.solve(power_law(0.7), wall, tubefsi.Tube(radius=radius, thickness=TB * A0, length=L), flow_rate=1e-8)
    lin = tubefsi.sampled(zs, a_tab, kind="linear")
    assert float(lin(np.array(L / 2))) == pytest.approx(a_tab[10])
    # the chain's segments straddle no knot; the bump is flat at both ends, so the chain's h^2 term
    # vanishes: one Richardson step with the observed order (about 4)
    c1, c2, c3 = [chain(power_law(0.7), lambda z: wall, lambda z: float(radius(np.array(z))),
                        lambda z: TB * A0, 1e-8, s) for s in (80, 160, 320)]
    order = math.log2((c2 - c1) / (c3 - c2))
    assert 3.8 < order < 4.3
    assert gen.pressure_drop == pytest.approx(c3 + (c3 - c2) / (2**order - 1), rel=1e-9)
    assert sep.pressure_drop > 0 and sep.radius(L / 2) < sep.radius(0.0)


def test_tapered_profile_plot_shows_the_taper():
    """The radius panel of a tapered tube draws R(z) and the undeformed a(z) in a length unit."""
    import matplotlib

    matplotlib.use("Agg")
    tube = tubefsi.Tube(radius=taper(), thickness=lambda z: TB * taper()(z), length=L)
    sol = tubefsi.solve(power_law(0.7), walls["thick-neo-hookean"](shear_modulus=MU), tube, flow_rate=1e-7)
    fig = sol.plot()
    ax_r = fig.axes[1]
    undeformed = [line for line in ax_r.get_lines() if line.get_label() == "undeformed"]
    assert len(undeformed) == 1
    y = np.asarray(undeformed[0].get_ydata(), dtype=float)
    assert y[-1] / y[0] == pytest.approx(A1 / A0)
    assert "radius $R$" in ax_r.get_ylabel()


# ------------------------------------------------------------------ typed errors
@pytest.mark.parametrize("bad, match", [
    (lambda z: -1e-3 + 0 * z, "radius"),
    (lambda z: np.where(z > L / 2, np.nan, 1e-3), "radius"),
    (lambda z: np.ones(3) * 1e-3, "shape"),
    (lambda z: 1 / 0, "ZeroDivisionError"),
])
def test_bad_profiles_raise_typed_errors(bad, match):
    with pytest.raises(tubefsi.InvalidParameterError, match=match):
        tubefsi.solve(power_law(0.7), walls["thick-neo-hookean"](shear_modulus=MU),
                      tubefsi.Tube(radius=bad, thickness=2e-4, length=L), flow_rate=1e-7)


def test_other_typed_errors():
    with pytest.raises(tubefsi.InvalidParameterError, match="shear_modulus"):
        tubefsi.solve(power_law(0.7), walls["thick-neo-hookean"](shear_modulus=lambda z: MU * (1 - 2 * z / L)),
                      tubefsi.Tube(radius=A0, thickness=2e-4, length=L), flow_rate=1e-7)
    with pytest.raises(tubefsi.InvalidParameterError, match="length"):
        tubefsi.Tube(radius=A0, thickness=2e-4, length=lambda z: L)
    with pytest.raises(tubefsi.InvalidParameterError, match="consistency"):
        tubefsi.solve(fluids["power-law"](consistency=lambda z: 0.5, index=0.7),
                      walls["thick-neo-hookean"](shear_modulus=MU), tubefsi.Tube(radius=A0, thickness=2e-4, length=L),
                      flow_rate=1e-7)
    with pytest.raises(tubefsi.InvalidParameterError, match="radius"):     # a table shorter than the tube
        tubefsi.Tube(radius=tubefsi.sampled([0, L / 2], [A0, A1]), thickness=2e-4, length=L)
    with pytest.raises(tubefsi.InvalidParameterError, match="z"):
        tubefsi.sampled([0, L, L / 2], [A0, A1, A0])
    with pytest.raises(tubefsi.InvalidParameterError, match="kind"):
        tubefsi.sampled([0, L], [A0, A1], kind="cubic")


@pytest.mark.slow
def test_graded_beyond_the_limit_is_no_steady_state():
    """A graded shear-thinning flow above what the tube carries: the integration along z fails, and
    the NoSteadyStateError gives the maximum flow rate (that of
    ``test_graded_max_flow_rate_at_the_inlet``, 9.0909716e-6 m^3/s)."""
    wall = walls["thick-neo-hookean"](shear_modulus=lambda z: MU * (1 + z / L))
    tube = tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)
    with pytest.raises(tubefsi.NoSteadyStateError, match="maximum flow rate 9.09097"):
        tubefsi.solve(power_law(0.5), wall, tube, flow_rate=1e-5, coupler=Graded(rtol=1e-10, check_threshold=1e-6))


def test_separable_taper_derivatives_and_unsupported_ones():
    """The derivatives of a separable taper are the equivalent uniform tube's (against central
    differences of solves, 1e-7); the parameter derivatives and the diagnostics of a graded tube
    say they have none."""
    tube = tubefsi.Tube(radius=taper(), thickness=lambda z: TB * taper()(z), length=L)
    wall = walls["thick-neo-hookean"](shear_modulus=MU)
    q, h = 1e-7, 1e-5
    sol = tubefsi.solve(power_law(0.6), wall, tube, flow_rate=q)
    plus, minus = (tubefsi.solve(power_law(0.6), wall, tube, flow_rate=q * (1 + s * h)).pressure_drop for s in (1, -1))
    assert sol.dpressure_drop_dflow_rate == pytest.approx((plus - minus) / (2 * q * h), rel=1e-7)
    with pytest.raises(tubefsi.InvalidParameterError, match="difference two solves"):
        sol.dpressure_drop_dparameter("rheology.consistency")
    with pytest.raises(tubefsi.InvalidParameterError, match="graded"):
        sol.diagnostics()


# ------------------------------------------------------------------ derivatives of a graded solve
def _central(f, x, h):
    """Richardson-extrapolated central difference of ``f`` at ``x`` with steps ``h``, ``h/2`` (error
    O(h^4) plus rounding ~ 1e-13 |f| / h), and the same at ``2h``, ``h``: their difference bounds
    the truncation error of the first. ``f`` is called once, with the six abscissae as an array."""
    steps = np.array([h / 2, h, 2 * h])
    values = f(np.concatenate([x + steps, x - steps]))
    c = (values[:3] - values[3:]) / (2 * steps)
    return (4 * c[0] - c[1]) / 3, (4 * c[1] - c[2]) / 3


DERIVATIVE_CASES = {
    "graded-modulus": (power_law(0.6), _nh(lambda z: MU * (1.0 + 1.5 * z / L)),
                       tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)),
    "taper-constant-thickness-carreau": (
        fluids["carreau"](zero_shear_viscosity=0.05, infinite_shear_viscosity=0.0035, relaxation_time=3.3, index=0.5),
        _nh(MU), tubefsi.Tube(radius=taper(), thickness=2e-4, length=L)),
    "linear-graded": (fluids["newtonian"](viscosity=0.05), _linear(lambda z: 3 * MU * np.exp(z / L)),
                      tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)),
}


@pytest.mark.parametrize("case", sorted(DERIVATIVE_CASES))
def test_graded_derivatives_match_finite_differences(case):
    r"""The derivatives of a graded solve that does not separate (the variational equations
    integrated along z with the pressure) against central differences of flow-controlled solves,
    Richardson-extrapolated: :math:`d\Delta p/dq` and :math:`\partial\Delta p/\partial p_{out}|_q`,
    whence :math:`\partial q/\partial p_{in} = 1/(d\Delta p/dq)` and :math:`\partial q/\partial
    p_{out} = -(1 + \partial\Delta p/\partial p_{out})/(d\Delta p/dq)`; agreement within ten times
    the difference's own truncation estimate plus 1e-9 (its rounding), at an outlet pressure of
    200 Pa, and the pressure-controlled solve's derivatives equal the flow-controlled ones."""
    fluid, wall, tube = DERIVATIVE_CASES[case]
    q, p_out = 1e-7, 200.0
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q, outlet_pressure=p_out)
    assert sol.coupler_name == "Graded"
    drop = lambda x, po: tubefsi.solve(fluid, wall, tube, flow_rate=x, outlet_pressure=po).pressure_drop  # noqa: E731
    dq, dq2 = _central(lambda x: drop(x, p_out), q, 1e-3 * q)
    assert abs(sol.dpressure_drop_dflow_rate - dq) <= 10 * abs(dq - dq2) + 1e-9 * abs(dq)
    dpo, dpo2 = _central(lambda x: drop(q, x), p_out, 1e-2 * p_out)
    expected = -(1 + dpo) / dq
    bound = 10 * (abs(dpo - dpo2) / abs(1 + dpo) + abs(dq - dq2) / abs(dq)) + 1e-9
    assert sol.dflow_rate_dinlet_pressure == pytest.approx(1 / dq, rel=10 * abs(dq - dq2) / abs(dq) + 1e-9)
    assert sol.dflow_rate_doutlet_pressure == pytest.approx(expected, rel=bound)
    assert sol.dflow_rate_doutlet_pressure < 0 < sol.dflow_rate_dinlet_pressure
    if case == "linear-graded":        # a pressure-controlled state (the cheapest case)
        back = tubefsi.solve(fluid, wall, tube, pressure_drop=sol.pressure_drop, outlet_pressure=p_out)
        assert back.dflow_rate_doutlet_pressure == pytest.approx(sol.dflow_rate_doutlet_pressure, rel=1e-10)


def test_graded_derivatives_limits():
    r"""Two independent references: a constant modulus *function* with a Carreau fluid (never
    separable: the integration along z) gives the uniform tube's derivatives (the separated
    engine's :math:`K = \int k\,dz`) to 1e-10; and at q = 0 a Newtonian fluid in a linear taper of
    constant thickness has :math:`d\Delta p/dq = (8\mu/\pi)\int_0^L a^{-4}dz
    = 8\mu L(a_0^{-3} - a_1^{-3})/(3\pi(a_1 - a_0))` (the rigid-tube law of the unloaded tube)."""
    carreau = fluids["carreau"](zero_shear_viscosity=0.05, infinite_shear_viscosity=0.0035, relaxation_time=3.3,
                                index=0.6)
    tube = tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)
    q = np.array([1e-8, 1e-7])
    uniform = tubefsi.solve(carreau, _nh(MU), tube, flow_rate=q, outlet_pressure=100.0)
    graded = tubefsi.solve(carreau, _nh(lambda z: MU), tube, flow_rate=q, outlet_pressure=100.0)
    assert graded.coupler_name == "Graded"
    for name in ("dpressure_drop_dflow_rate", "dflow_rate_dinlet_pressure", "dflow_rate_doutlet_pressure"):
        np.testing.assert_allclose(getattr(graded, name), getattr(uniform, name), rtol=1e-10)
    mu = 0.05
    rest = tubefsi.solve(fluids["newtonian"](viscosity=mu), _nh(MU), tubefsi.Tube(radius=taper(), thickness=2e-4,
                                                                                  length=L), flow_rate=0.0)
    exact = 8 * mu * L * (A0**-3 - A1**-3) / (3 * math.pi * (A1 - A0))
    assert rest.dpressure_drop_dflow_rate == pytest.approx(exact, rel=1e-11)


# ------------------------------------------------------------------ the maximum flow rate of a graded tube
def _thick_nh_float(mu, tb, lam):
    """The thick neo-Hookean tube law (as :func:`thick_nh`) in floats."""
    lo2 = 1 + (lam**2 - 1) / (1 + tb) ** 2
    return mu * (math.log(lam) - 0.5 * math.log(lo2) - 1 / (2 * lam**2) + 1 / (2 * lo2))


def _touch_reference(mu_of, n, m, q0, q1, a=A0, tb=TB, length=L):
    r"""The flow rate at which the pressure of a power-law fluid in a uniform thick neo-Hookean tube
    with a modulus :math:`\mu(z)` reaches the inlet's limit pressure :math:`\mu(0)\ln(1 + \bar t)`:
    SciPy's DOP853 (``solve_ivp``, rtol 1e-13) of :math:`dp/dz = -\phi(q)(a\lambda)^{-k}`, the
    stretch by ``brentq`` on the closed-form law, and secant steps on the inlet's margin
    :math:`p_{lim}(0) - p(0; q)` from below (it is linear in q there: the limit pressure rises
    along z), extrapolated to zero from a margin below 2e-7 Pa."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    def stretch(p, mu):
        if p <= 0:
            return 1.0
        hi = 1.0
        while _thick_nh_float(mu, tb, math.exp(hi)) < p:
            hi *= 2
        return math.exp(brentq(lambda x: _thick_nh_float(mu, tb, math.exp(x)) - p, 0.0, hi, xtol=1e-16, rtol=1e-15))

    def margin(q):
        k, phi = 3 * n + 1, 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n
        sol = solve_ivp(lambda z, y: [-phi * (a * stretch(y[0], mu_of(z))) ** -k], (length, 0.0), [0.0],
                        method="DOP853", rtol=1e-13, atol=1e-10)
        return mu_of(0.0) * math.log(1 + tb) - sol.y[0, -1]

    f0, f1 = margin(q0), margin(q1)
    for _ in range(40):
        q2 = q1 - f1 * (q1 - q0) / (f1 - f0)
        if abs(f1) < 2e-7:
            return q2
        q2 = q1 + 0.9 * (q2 - q1)          # stay below the limit
        q0, f0, q1, f1 = q1, f1, q2, margin(q2)
    raise AssertionError("the reference did not converge")


@pytest.mark.slow
def test_graded_max_flow_rate_at_the_inlet():
    r"""A modulus rising along the tube, :math:`\mu = \mu_0(1 + z/L)`, with a shear-thinning fluid
    (n = 0.5): the pressure first reaches the local limit at the inlet; the maximum flow rate
    against the independent DOP853/brentq reference (1e-11; measured 4e-13); below it a solve
    works and ``on_infeasible="nan"`` masks only the point beyond."""
    mu_of = lambda z: MU * (1 + z / L)   # noqa: E731
    fluid, wall = power_law(0.5), _nh(mu_of)
    tube = tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.AccuracyWarning)
        q_max = tubefsi.max_flow_rate(fluid, wall, tube)
    ref = _touch_reference(mu_of, 0.5, 0.5, 0.99 * q_max, 0.995 * q_max)
    assert q_max == pytest.approx(ref, rel=1e-11)
    loose = Graded(rtol=1e-10, check_threshold=1e-6)     # the masking only (cheaper)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)     # R_in/L > 0.1 near the limit
        sol = tubefsi.solve(fluid, wall, tube, flow_rate=np.array([0.999 * q_max, 1.001 * q_max]),
                            on_infeasible="nan", coupler=loose)
    assert list(sol.feasible) == [True, False]
    assert math.isfinite(sol.pressure_drop[0]) and math.isnan(sol.pressure_drop[1])
    assert sol.pressure_drop[0] < MU * math.log(1 + TB)


@pytest.mark.slow
def test_graded_pressure_beyond_a_soft_section_is_no_steady_state():
    r"""A sampled modulus dipping to half at mid-tube (a breakpoint): the pressure first touches the
    local limit there, so the largest inlet pressure with a steady state is that of the maximum
    flow rate, below the inlet section's limit :math:`\mu_0\ln(1 + \bar t)`; a pressure drop beyond
    it is a ``NoSteadyStateError`` giving that pressure (not the flow rate at the edge, which the
    bracketing alone would return), bounded by the inlet pressures of the flows just below and at
    the maximum."""
    wall = _nh(tubefsi.sampled([0, L / 2, L], [MU, 0.5 * MU, MU], kind="linear"))
    tube = tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)
    loose = Graded(rtol=1e-10, check_threshold=1e-6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        with pytest.raises(tubefsi.NoSteadyStateError) as info:
            tubefsi.solve(power_law(0.5), wall, tube, pressure_drop=1.1 * MU * math.log(1 + TB) * 0.8, coupler=loose)
        below = tubefsi.solve(power_law(0.5), wall, tube, flow_rate=0.99 * 9.0909715833e-6, coupler=loose)
    limit = info.value.limit
    assert below.inlet_pressure < limit < 0.8 * MU * math.log(1 + TB)


def test_touch_candidates_of_a_soft_section():
    r"""Where the pressure can first reach the local limit (no integration): the inlet when the limit
    pressure rises along z there; the minimum of a smooth dip (golden sections, to 1e-8 of the
    length: the limit pressure is flat there); nowhere when it falls along the whole tube."""
    tube = tubefsi.Tube(radius=A0, thickness=TB * A0, length=L)
    scene = lambda mu: make_scene(power_law(0.5), _nh(mu), tube)   # noqa: E731
    cases = [(lambda z: MU * (1 + z / L), [0.0]),
             (lambda z: MU * (1 - 0.5 * np.exp(-((z - 0.37 * L) / (L / 10)) ** 2)), [0.37 * L]),
             (lambda z: MU * (1 + (z / L - 0.3) ** 2), [0.3 * L]),
             (lambda z: MU * (2 - z / L), [])]
    for mu, expected in cases:
        zc, pts = Graded()._touch_candidates(scene(mu), np.array([L]))
        np.testing.assert_allclose(zc, expected, atol=1e-8 * L)
        assert list(pts) == [0] * len(expected)
    assert tubefsi.max_flow_rate(power_law(0.5), _nh(cases[-1][0]), tube) == math.inf
