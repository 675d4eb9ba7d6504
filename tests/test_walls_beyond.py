"""Walls beyond the uniform clamped tube (``docs/walls_beyond.md``): end conditions of linear
walls, the Shapiro collapsible tube, external pressure, axial pre-stretch.

Every reference is computed here independently of the code under test (mpmath at 30 digits).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import tubefsi
import tubefsi.testing
from tubefsi.testing.profiles import scaled

walls = tubefsi.registry.walls
mp.mp.dps = 30


# ------------------------------------------------------------------ 1. linear end conditions
def lame_strain(p, E, nu, tb, ends):
    r"""Hoop strain of the inner surface from the generalized-plane-strain Lamé problem, in
    displacements: :math:`u_r = A r + B/r`, :math:`\varepsilon_z = e`, 3-D Hooke's law with the Lamé
    constants, :math:`\sigma_r(a) = -p`, :math:`\sigma_r(b) = 0` and the axial condition of
    ``ends`` (closed: axial force :math:`p\pi a^2`; open: none; clamped: :math:`e = 0`), solved as
    a 3x3 linear system in mpmath (none of the closed forms of ``linear.py``)."""
    E, nu, p = mp.mpf(E), mp.mpf(nu), mp.mpf(p)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu)) if nu != 0.5 else None
    mu = E / (2 * (1 + nu))
    a, b = mp.mpf(1), 1 + mp.mpf(tb)

    # stresses are linear in (A, B, e); rows: sigma_r(a) + p = 0, sigma_r(b) = 0, axial condition
    def sig_r(r):   # coefficients of A, B, e
        return [2 * (lam + mu), -2 * mu / r**2, lam]

    sig_z = [2 * lam, mp.mpf(0), lam + 2 * mu]
    rows = [sig_r(a), sig_r(b)]
    rhs = [-p, mp.mpf(0)]
    if ends == "clamped":
        rows.append([0, 0, 1])
        rhs.append(0)
    else:       # uniform sigma_z over the annulus pi (b^2 - a^2): force p pi a^2 (closed) or 0 (open)
        rows.append(sig_z)
        rhs.append(p * a**2 / (b**2 - a**2) if ends == "closed" else 0)
    A, B, _ = mp.lu_solve(mp.matrix(rows), mp.matrix(rhs))
    return A + B / a**2


@pytest.mark.parametrize("ends", ["closed", "open", "clamped"])
@pytest.mark.parametrize("kind", ["thick-linear", "thin-linear"])
@pytest.mark.parametrize("nu", [-0.3, 0.0, 0.3, 0.45])
def test_linear_end_conditions_match_lame(kind, ends, nu):
    E, p = 2.5e5, 7.0
    wall = walls[kind](youngs_modulus=E, poisson_ratio=nu, end_condition=ends)
    for tb in (1e-3, 0.2, 1.5):
        if kind == "thick-linear":
            ref = lame_strain(p, E, nu, tb, ends)
        else:   # the thin wall is the t/a -> 0 limit: K(tb) extrapolated from tiny tb
            h = mp.mpf("1e-12")
            ref = lame_strain(p, E, nu, h, ends) * h / tb
        assert wall.strain(p, tb) == pytest.approx(float(ref), rel=1e-13)


def test_linear_end_conditions_thin_limits_and_incompressible_coincide():
    for ends, k in (("closed", 1 - 0.3 / 2), ("open", 1.0), ("clamped", 1 - 0.3**2)):
        thin = walls["thin-linear"](youngs_modulus=1.0, poisson_ratio=0.3, end_condition=ends)
        assert thin.strain(1.0, 1.0) == pytest.approx(k, rel=1e-15)
    # nu = 1/2: closed ends carry no axial strain, so closed = clamped (the hyperelastic limit)
    closed, clamped = (walls["thick-linear"](youngs_modulus=3.0, poisson_ratio=0.5, end_condition=e)
                       for e in ("closed", "clamped"))
    neo = walls["thick-neo-hookean"](shear_modulus=1.0)
    for tb in (0.1, 1.0):
        assert clamped.small_strain_modulus(tb) == pytest.approx(closed.small_strain_modulus(tb), rel=1e-15)
        assert clamped.small_strain_modulus(tb) == pytest.approx(neo.small_strain_modulus(tb), rel=1e-12)


def test_end_condition_validates_and_enters_the_table_key():
    with pytest.raises(tubefsi.InvalidParameterError, match="end_condition"):
        walls["thin-linear"](youngs_modulus=1.0, poisson_ratio=0.3, end_condition="capped")
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
    drops = {}
    for ends in ("closed", "open", "clamped"):
        wall = walls["thick-linear"](youngs_modulus=1e4, poisson_ratio=0.3, end_condition=ends)
        for _ in range(3):          # the third call is served by the cached table / scalar path
            drops.setdefault(ends, []).append(tubefsi.solve(fluid, wall, tube, flow_rate=1e-9).pressure_drop)
    for ends, values in drops.items():
        assert max(values) - min(values) <= 1e-13 * values[0]
    assert len({v[-1] for v in drops.values()}) == 3


# ------------------------------------------------------------------ 2-3. Shapiro, external pressure
TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
NEWTONIAN = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
POWER_LAW = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)


def mp_gradient(fluid, q, R):
    """G(q, R) of a power law (Newtonian: n = 1, m = mu), from the flow law in mpmath."""
    n = mp.mpf(getattr(fluid, "index", 1.0))
    m = mp.mpf(getattr(fluid, "consistency", getattr(fluid, "viscosity", None)))
    return 2 * m * ((3 * n + 1) * mp.mpf(q) / (mp.pi * n)) ** n * R ** -(3 * n + 1)


def mp_root(f, lo, hi):
    """The root of an increasing ``f`` in ``[lo, hi]``: bisection to 1e-12 of the bracket, then
    the secant method from the two ends (mpmath's default)."""
    for _ in range(25):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return mp.findroot(f, (lo, hi))


def mp_reference(law, slope, fluid, tube, q, p_transmural_out, z=(), antiderivative=None):
    """``(dp, inlet strain, [R(z)])`` of the separated problem in mpmath: the outlet stretch from
    the tube law ``law`` (a root), the inlet stretch from
    :math:`\\int_{\\lambda_{out}}^{\\lambda_{in}} P'(s)/G(q, as)\\,ds = L` (a root of mpmath's
    quadrature, or of ``antiderivative(s)`` of :math:`s^k P'(s)` for a power law, :math:`k = 3n+1`)."""
    a, L = mp.mpf(tube.radius), mp.mpf(tube.length)
    lam_out = mp_root(lambda s: law(s) - p_transmural_out, mp.mpf("0.01"), mp.mpf(10))

    def H(lam):
        if antiderivative is not None:       # G = phi(q) R^-k: the integral is a^k/phi [F(lam) - F(lam_out)]
            return (antiderivative(lam) - antiderivative(lam_out)) / mp_gradient(fluid, q, a)
        return mp.quad(lambda s: slope(s) / mp_gradient(fluid, q, a * s), [lam_out, lam])

    def stretch_at(length):      # bracketed: the rise above the outlet doubled until H passes length
        hi = lam_out * mp.mpf("1.001")
        while H(hi) < length:
            hi = lam_out + 2 * (hi - lam_out)
        return mp_root(lambda lam: H(lam) - length, lam_out, hi)

    lam_in = stretch_at(L)
    radii = [a * stretch_at(L - mp.mpf(zz)) for zz in z]
    return law(lam_in) - law(lam_out), lam_in - 1, radii


def shapiro_law(K, fluid, n1=10, n2=1.5):
    """Shapiro's law, its slope and the antiderivative of :math:`s^k P'(s)`,
    :math:`K[2n_1 s^{k+2n_1}/(k+2n_1) + 2n_2 s^{k-2n_2}/(k-2n_2)]`, in mpmath."""
    K, n1, n2 = mp.mpf(K), mp.mpf(n1), mp.mpf(n2)
    k = 3 * mp.mpf(getattr(fluid, "index", 1.0)) + 1
    return (lambda s: K * (s ** (2 * n1) - s ** (-2 * n2)),
            lambda s: K * (2 * n1 * s ** (2 * n1 - 1) + 2 * n2 * s ** (-2 * n2 - 1)),
            lambda s: K * (2 * n1 * s ** (k + 2 * n1) / (k + 2 * n1) + 2 * n2 * s ** (k - 2 * n2) / (k - 2 * n2)))


@pytest.mark.parametrize("fluid", [NEWTONIAN, POWER_LAW], ids=["newtonian", "power-law"])
@pytest.mark.parametrize("p_e, q", [(0.0, 2e-10),        # inflated
                                    (60.0, 1e-10),       # outlet collapsed, inlet inflated
                                    (900.0, 1e-11),      # both ends collapsed
                                    (5e3, 2e-12)])       # deep collapse (area ratio ~ 0.1)
def test_shapiro_under_external_pressure_matches_mpmath(fluid, p_e, q):
    K, p_out = 50.0, 10.0
    wall = walls["shapiro"](tube_stiffness=K)
    z = np.array([0.2, 0.7]) * TUBE.length
    law, slope, antiderivative = shapiro_law(K, fluid)
    dp, e_in, radii = mp_reference(law, slope, fluid, TUBE, q, mp.mpf(p_out) - p_e, z, antiderivative)
    for coupler in ("auto", "quadrature"):          # the closed form, and the engine's quadrature
        sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, outlet_pressure=p_out, external_pressure=p_e,
                            coupler=coupler)
        assert sol.pressure_drop == pytest.approx(float(dp), rel=1e-11)
        assert sol.inlet_displacement == pytest.approx(float(e_in * TUBE.radius), rel=1e-11)
        np.testing.assert_allclose(sol.radius(z), [float(r) for r in radii], rtol=1e-11)
    assert sol.inlet_pressure == pytest.approx(p_out + float(dp), rel=1e-14)
    assert sol.outlet_pressure == p_out and sol.external_pressure == p_e
    if p_e >= 900:
        assert sol.inlet_pressure < p_e          # both ends collapsed
    back = tubefsi.solve(fluid, wall, TUBE, pressure_drop=sol.pressure_drop, outlet_pressure=p_out,
                         external_pressure=p_e)
    assert back.flow_rate == pytest.approx(q, rel=1e-11)


def test_thick_neo_hookean_under_external_pressure_matches_mpmath():
    mu, tb = 2e3, TUBE.reduced_thickness
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    b = (1 + mp.mpf(tb)) ** 2

    def law(lam):       # the Lamé integral of dW/(s^2 - 1) = mu (s^2 + 1)/s^3, by quadrature
        lam_o = mp.sqrt(1 + (lam**2 - 1) / b)
        return mp.quad(lambda s: mu * (s**2 + 1) / s**3, [lam_o, lam])

    def slope(lam):     # Leibniz: g(lam) - g(lam_o) dlam_o/dlam, dlam_o/dlam = lam/(b lam_o)
        lam_o = mp.sqrt(1 + (lam**2 - 1) / b)
        return mu * ((lam**2 + 1) / lam**3 - (lam_o**2 + 1) / lam_o**3 * lam / (b * lam_o))

    p_e = 0.9 * -wall.min_pressure(tb)      # just above the buckling bound
    for q, fluid in ((3e-11, NEWTONIAN), (1e-9, POWER_LAW)):
        sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, external_pressure=p_e)
        with mp.workdps(20):                # nested quadratures: 20 digits are plenty for 1e-11
            dp, e_in, _ = mp_reference(law, slope, fluid, TUBE, q, -mp.mpf(p_e))
        assert sol.pressure_drop == pytest.approx(float(dp), rel=1e-11)
        assert sol.inlet_displacement == pytest.approx(float(e_in * TUBE.radius), rel=1e-11)


@settings(deadline=None, max_examples=scaled(15))
@given(p_out=st.floats(0.0, 50.0), p_e=st.floats(-30.0, 200.0), q=st.floats(1e-12, 1e-9),
       name=st.sampled_from(["shapiro", "thin-neo-hookean", "thick-linear"]))
# a subnormal outlet pressure: Newton's step on the outlet strain rounds to zero (it bisected away)
@example(p_out=2.2250738585e-313, p_e=0.0, q=9.912712503594836e-10, name="thin-neo-hookean")
def test_external_pressure_is_a_shift_of_the_outlet_pressure(p_out, p_e, q, name):
    """External pressure p_e with outlet pressure p_out + p_e is the tube under outlet pressure
    p_out (the transmural pressures agree; the gauge pressures differ by p_e)."""
    wall = examples_of(name)
    if p_out - (-p_e if p_e < 0 else 0) < 0 or p_out + max(p_e, 0) < 0:
        return
    try:
        ref = tubefsi.solve(NEWTONIAN, wall, TUBE, flow_rate=q, outlet_pressure=p_out)
    except tubefsi.NoSteadyStateError:
        return
    if p_out + p_e < 0:
        return
    sol = tubefsi.solve(NEWTONIAN, wall, TUBE, flow_rate=q, outlet_pressure=p_out + p_e, external_pressure=p_e)
    rel = 4e-16 * abs(p_e) / max(sol.pressure_drop, 1e-300)      # the rounding of p_out + p_e - p_e
    cond = max(1.0, abs(p_out + p_e) / max(p_out, 1e-300))
    assert sol.pressure_drop == pytest.approx(ref.pressure_drop, rel=1e-12 * cond + rel * 10)
    assert sol.inlet_pressure == pytest.approx(ref.inlet_pressure + p_e, rel=1e-12, abs=1e-12 * abs(p_e))


def examples_of(name):
    return tubefsi.testing.examples("walls", name)[0]


def test_buckling_bounds_and_errors():
    tb = 0.2
    thin = walls["thin-linear"](youngs_modulus=1e4, poisson_ratio=0.3)
    assert thin.min_pressure(tb) == pytest.approx(-1e4 * tb**3 / (4 * (1 - 0.09)), rel=1e-15)
    thick = walls["thick-linear"](youngs_modulus=1e4, poisson_ratio=0.3)
    assert thick.min_pressure(tb) == pytest.approx(-1e4 * (tb / 1.2) ** 3 / (4 * (1 - 0.09)), rel=1e-15)
    for name in ("thin-neo-hookean", "thin-mooney-rivlin"):           # mu t^3/a^3, mu = 2 (c1 + c2)
        w = examples_of(name)
        mu = w.shear_modulus
        assert w.min_pressure(tb) == pytest.approx(-mu * tb**3, rel=1e-14)
    assert walls["shapiro"](tube_stiffness=1.0).min_pressure(tb) == -math.inf
    with pytest.raises(tubefsi.BucklingError) as info:
        tubefsi.solve(NEWTONIAN, thin, TUBE, flow_rate=1e-10, external_pressure=-1.01 * thin.min_pressure(0.3))
    assert info.value.limit == pytest.approx(thin.min_pressure(0.3))
    assert isinstance(info.value, tubefsi.NoSteadyStateError)
    for bad in (math.nan, math.inf, "x"):
        with pytest.raises(tubefsi.InvalidParameterError, match="external_pressure"):
            tubefsi.solve(NEWTONIAN, thin, TUBE, flow_rate=1e-10, external_pressure=bad)
    # arrays broadcast like the outlet pressure, entry by entry
    p_e = np.array([[0.0], [1.0], [5.0]])
    q = np.array([1e-10, 3e-10])
    sol = tubefsi.solve(NEWTONIAN, thin, TUBE, flow_rate=q, external_pressure=p_e)
    assert sol.pressure_drop.shape == (3, 2)
    for i, j in np.ndindex(3, 2):
        one = tubefsi.solve(NEWTONIAN, thin, TUBE, flow_rate=float(q[j]), external_pressure=float(p_e[i, 0]))
        assert sol.pressure_drop[i, j] == pytest.approx(one.pressure_drop, rel=1e-13)
    assert tubefsi.max_flow_rate(POWER_LAW, "thick-neo-hookean" if False else examples_of("thick-neo-hookean"),
                                 TUBE, external_pressure=5.0) > tubefsi.max_flow_rate(
        POWER_LAW, examples_of("thick-neo-hookean"), TUBE)


# ------------------------------------------------------------------ 4. axial pre-stretch
def physical_dW(name, lz):
    r""":math:`\hat W'(s; \lambda_z) = d/ds\,W(1/(s\lambda_z), s, \lambda_z)` of the 3-D energies, by
    mpmath differentiation (neo-Hookean: :math:`\mu/2(I_1 - 3)`; Mooney–Rivlin with c2)."""
    lz = mp.mpf(lz)

    def energy(s):
        l1, l2, l3 = 1 / (s * lz), s, lz
        i1 = l1**2 + l2**2 + l3**2
        i2 = (l1 * l2) ** 2 + (l2 * l3) ** 2 + (l1 * l3) ** 2
        if name == "neo-hookean":
            return mp.mpf(2e3) / 2 * (i1 - 3)
        return mp.mpf(1e3) * (i1 - 3) + mp.mpf(-300) * (i2 - 3)

    c1, c2 = (mp.mpf(1e3), mp.mpf(0)) if name == "neo-hookean" else (mp.mpf(1e3), mp.mpf(-300))

    def dW(s):      # by hand: 2 c1 (s - s^-3 lz^-2) + 2 c2 (lz^2 s - s^-3) (mu = 2 c1 for neo-Hookean)
        return 2 * c1 * (s - s**-3 / lz**2) + 2 * c2 * (lz**2 * s - s**-3)

    for s in (mp.mpf("0.7"), mp.mpf("1.9")):   # ... checked against the energy once
        assert abs(dW(s) - mp.diff(energy, s)) < mp.mpf(10) ** (5 - mp.mp.dps)
    return dW


def make(name, theory, lz, convention="reference"):
    kw = dict(shear_modulus=2e3) if name == "neo-hookean" else dict(c1=1e3, c2=-300.0)
    if theory == "thin":
        kw["thickness_convention"] = convention
    return walls[f"{theory}-{name}"](axial_stretch=lz, **kw)


@pytest.mark.parametrize("name", ["neo-hookean", "mooney-rivlin"])
@pytest.mark.parametrize("lz", [0.8, 1.0, 1.25, 1.6])
def test_axial_stretch_tube_laws_match_mpmath(name, lz):
    r"""The installed tube's law (stretch :math:`\lambda = R\sqrt{\lambda_z}/a`) against the thick
    integral :math:`\int_{s_o}^{s_i}\hat W'(s)/(\lambda_z s^2 - 1)\,ds` of the 3-D energy
    (mpmath), :math:`s_i = \lambda/\sqrt{\lambda_z}`, and against the generic thick integral; the
    thin laws against :math:`\bar t\hat W'(s_i)/\sqrt{\lambda_z}` (reference) and
    :math:`\bar t\hat W'(s_i)/(\lambda_z s_i)` (current)."""
    from tubefsi.walls.hyperelastic import ThickWall

    dW = physical_dW(name, lz)
    thick = make(name, "thick", lz)
    thin = {c: make(name, "thin", lz, c) for c in ("reference", "current")}
    for tb in (0.05, 0.3, 1.2):
        B = (1 + mp.mpf(tb)) ** 2
        for lam in (1.0 + 0.5 * (thick.min_stretch(tb) - 1.0), 1.01, 1.5, 3.0):     # a collapsing one too
            s_i = mp.mpf(lam) / mp.sqrt(lz)
            s_o = mp.sqrt((1 + (lz * s_i**2 - 1) / B) / lz)
            ref = mp.quad(lambda s: dW(s) / (lz * s**2 - 1), [s_o, s_i])
            assert thick.pressure(lam, tb) == pytest.approx(float(ref), rel=1e-13)
            generic = float(ThickWall._pressure_at_strain(thick, np.array([lam - 1.0]), tb)[0])
            assert generic == pytest.approx(float(ref), rel=1e-13)
            assert thin["reference"].pressure(lam, tb) == pytest.approx(float(tb * dW(s_i) / mp.sqrt(lz)), rel=1e-13)
            assert thin["current"].pressure(lam, tb) == pytest.approx(float(tb * dW(s_i) / (lz * s_i)), rel=1e-13)


@pytest.mark.parametrize("lz", [1.3])
def test_pre_stretched_tube_in_situ_matches_mpmath(lz):
    """solve() with axial_stretch: the installed tube (lumen a/sqrt(lz) at zero pressure, length
    lz L) with the thick neo-Hookean law of the 3-D energy, against mpmath."""
    wall = make("neo-hookean", "thick", lz)
    sol0 = tubefsi.solve(NEWTONIAN, wall, TUBE, flow_rate=0.0)
    assert sol0.radius(0.0) == pytest.approx(TUBE.radius / math.sqrt(lz), rel=1e-15)
    assert sol0.tube.length == pytest.approx(lz * TUBE.length, rel=1e-15)
    again = tubefsi.solve(NEWTONIAN, wall, sol0.tube, flow_rate=1e-9)         # not installed twice
    assert again.pressure_drop == tubefsi.solve(NEWTONIAN, wall, TUBE, flow_rate=1e-9).pressure_drop
    with pytest.raises(tubefsi.InvalidParameterError, match="tube"):
        tubefsi.solve(NEWTONIAN, make("neo-hookean", "thick", 1.1), sol0.tube, flow_rate=1e-9)
    dW = physical_dW("neo-hookean", lz)
    tb = TUBE.reduced_thickness
    B = (1 + mp.mpf(tb)) ** 2

    def law(lam):
        s_i = lam / mp.sqrt(lz)
        s_o = mp.sqrt((1 + (lz * s_i**2 - 1) / B) / lz)
        return mp.quad(lambda s: dW(s) / (lz * s**2 - 1), [s_o, s_i])

    def slope(lam):         # d/dlam of the integral (Leibniz), ds_o/dlam = lam/(B lz s_o) ... in s_i units
        s_i = lam / mp.sqrt(lz)
        s_o = mp.sqrt((1 + (lz * s_i**2 - 1) / B) / lz)
        return (dW(s_i) / (lz * s_i**2 - 1) - dW(s_o) / (lz * s_o**2 - 1) * s_i / (B * s_o)) / mp.sqrt(lz)

    installed = tubefsi.Tube(radius=TUBE.radius / math.sqrt(lz), thickness=TUBE.thickness / math.sqrt(lz),
                             length=TUBE.length * lz)
    q = 1e-9
    sol = tubefsi.solve(NEWTONIAN, wall, TUBE, flow_rate=q, outlet_pressure=20.0)
    with mp.workdps(20):
        dp, e_in, _ = mp_reference(law, slope, NEWTONIAN, installed, q, mp.mpf(20))
    assert sol.pressure_drop == pytest.approx(float(dp), rel=1e-11)
    assert sol.radius(0.0) == pytest.approx(float((1 + e_in) * installed.radius), rel=1e-11)


@settings(deadline=None, max_examples=scaled(10))
@given(delta=st.floats(-1e-6, 1e-6), name=st.sampled_from(["thick-neo-hookean", "thin-mooney-rivlin"]),
       q=st.floats(1e-11, 1e-8))
def test_axial_stretch_tends_to_todays_walls(delta, name, q):
    """lambda_z -> 1 gives the plane-strain wall: the pressure drop moves by O(delta)."""
    base = examples_of(name)
    near = attrs_evolve(base, axial_stretch=1.0 + delta)
    ref = tubefsi.solve(NEWTONIAN, base, TUBE, flow_rate=q).pressure_drop
    got = tubefsi.solve(NEWTONIAN, near, TUBE, flow_rate=q).pressure_drop
    assert abs(got / ref - 1) <= 10 * abs(delta) + 1e-13


def attrs_evolve(model, **changes):
    import attrs

    return attrs.evolve(model, **changes)


def test_axial_stretch_validates():
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(tubefsi.InvalidParameterError, match="axial_stretch"):
            walls["thick-neo-hookean"](shear_modulus=1.0, axial_stretch=bad)
    with pytest.raises(tubefsi.InvalidParameterError, match="axial_stretch"):   # 2 (c1/lz + c2 lz) <= 0
        walls["thick-mooney-rivlin"](c1=1.0, c2=-0.3, axial_stretch=2.0)
    names = [p.name for p in tubefsi.fields.parameters(walls["thin-neo-hookean"])]
    assert "axial_stretch" in names


# ------------------------------------------------------------------ 5. HGO arterial walls
def hgo_dW(mu, k1, k2, beta):
    r""":math:`\hat W'(s)` of the 3-D HGO energy on the plane-strain path (stretches
    :math:`1/s, s, 1`), by mpmath differentiation; a fibre term only where :math:`I_4 > 1`."""
    mu, k1, k2, c = mp.mpf(mu), mp.mpf(k1), mp.mpf(k2), mp.cos(mp.mpf(beta))

    def energy(s):
        i1 = s**-2 + s**2 + 1
        i4 = s**2 * c**2 + (1 - c**2)
        fibre = k1 / (2 * k2) * (mp.exp(k2 * (i4 - 1) ** 2) - 1) if i4 > 1 else 0
        return mu / 2 * (i1 - 3) + 2 * fibre

    return lambda s: mp.diff(energy, s)


@pytest.mark.parametrize("preset", ["rabbit-carotid-media", "rabbit-carotid-adventitia"])
def test_hgo_tube_laws_match_mpmath(preset):
    from tubefsi.walls.hgo import PRESETS

    p = PRESETS[preset]
    dW = hgo_dW(p["shear_modulus"], p["fibre_stiffness"], p["fibre_exponent"], p["fibre_angle"])
    thick = walls["thick-hgo"].preset(preset)
    thin = walls["thin-hgo"].preset(preset, thickness_convention="current")
    for tb in (0.1, 0.5):
        B = (1 + mp.mpf(tb)) ** 2
        for lam in (1.0 + 0.5 * (thick.min_stretch(tb) - 1.0), 1.02, 1.4, 2.0):
            lam_o = mp.sqrt(1 + (mp.mpf(lam) ** 2 - 1) / B)
            ref = mp.quad(lambda s: dW(s) / (s**2 - 1), [lam_o, lam])
            assert thick.pressure(lam, tb) == pytest.approx(float(ref), rel=1e-12)
            assert thin.pressure(lam, tb) == pytest.approx(float(tb * dW(mp.mpf(lam)) / lam), rel=1e-12)
    with pytest.raises(tubefsi.InvalidParameterError, match="preset"):
        walls["thick-hgo"].preset("bovine")
    with pytest.raises(tubefsi.InvalidParameterError, match="fibre_angle"):
        walls["thick-hgo"](shear_modulus=1.0, fibre_stiffness=1.0, fibre_exponent=1.0, fibre_angle=2.0)


class TestStiffHGO(tubefsi.testing.AccuracyContract):
    """A stiff fibre law (k2 = 20, fibres near the hoop) against the brute force."""

    @pytest.fixture(params=tubefsi.testing.accuracy_cases(
        [walls["thin-hgo"](shear_modulus=1e3, fibre_stiffness=1e4, fibre_exponent=20.0, fibre_angle=0.3)],
        [POWER_LAW]))
    def case(self, request):
        return request.param


# ------------------------------------------------------------------ the command line
@pytest.mark.parametrize("p_e", [-5.0, 20.0])
def test_cli_external_pressure_and_axial_stretch(capsys, p_e):
    """``tubefsi solve --external-pressure`` (with an axial stretch in the wall spec) gives the
    in-process solve's numbers; ``advise`` refuses an external pressure it would ignore."""
    import json

    from tubefsi import cli

    scene = ["--rheology", "newtonian:viscosity=1e-3", "--wall", "thick-neo-hookean:shear_modulus=1e4,axial_stretch=1.2",
             "--tube", "radius=1e-3,thickness=2e-4,length=0.05"]
    assert cli.main(["solve", *scene, "--flow-rate", "1e-7", "--external-pressure", str(p_e), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = tubefsi.solve(tubefsi.registry.rheologies["newtonian"](viscosity=1e-3),
                        walls["thick-neo-hookean"](shear_modulus=1e4, axial_stretch=1.2),
                        tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05), flow_rate=1e-7, external_pressure=p_e)
    assert out["pressure_drop"] == pytest.approx(ref.pressure_drop, rel=1e-13)
    assert out["inlet_radius"] == pytest.approx(ref.inlet_radius, rel=1e-13)
    assert cli.main(["advise", *scene, "--flow-rate", "1e-7", "--external-pressure", str(p_e)]) == 2
    assert "--external-pressure" in capsys.readouterr().err


# ------------------------------------------------------------------ networks
def test_network_external_pressure_per_tube():
    """A Y of thick neo-Hookean tubes, each under its own external pressure (one daughter's outlet
    slightly collapsed, transmural -10 Pa): the network's junction pressure and flows against
    Kirchhoff's law solved here by Brent's method on single-tube pressure-controlled solves."""
    from scipy.optimize import brentq

    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.02, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    tube = tubefsi.Tube(radius=2e-4, thickness=6e-5, length=2e-2)
    p_e = {"parent": -20.0, "a": 10.0, "b": 40.0}
    ends = {"in": 300.0, "a": 0.0, "b": 60.0}
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("in", "j", wall, tube, name="parent", external_pressure=p_e["parent"])
    net.add_tube("j", "a", wall, tube, name="a", external_pressure=p_e["a"])
    net.add_tube("j", "b", wall, tube, name="b", external_pressure=p_e["b"])
    for node, p in ends.items():
        net.set_pressure(node, p)
    res = net.solve()

    def flow(p_hi, p_lo, name):
        return tubefsi.solve(fluid, wall, tube, pressure_drop=p_hi - p_lo, outlet_pressure=p_lo,
                             external_pressure=p_e[name]).flow_rate

    def balance(pj):
        return flow(ends["in"], pj, "parent") - flow(pj, ends["a"], "a") - flow(pj, ends["b"], "b")

    pj = brentq(balance, ends["b"] + 1e-9, ends["in"] - 1e-9, xtol=1e-13, rtol=1e-15)
    assert res.pressure["j"] == pytest.approx(pj, rel=1e-11)
    assert res.flow_rate["a"] == pytest.approx(flow(pj, ends["a"], "a"), rel=1e-10)
    sol = res.solution("b")
    assert sol.external_pressure == p_e["b"]
    with pytest.raises(tubefsi.InvalidParameterError, match="external_pressure"):
        tubefsi.Network(rheology=fluid).add_tube("x", "y", wall, tube, external_pressure=float("nan"))


# ------------------------------------------------------------------ 6. axial pre-stretch of every material
def axial_dW_of(name, params, lz):
    r""":math:`\hat W'(s; \lambda_z)` of a 3-D energy, written by hand (the reference materials'
    ``dW_axial``, or the HGO one below) and checked against ``mpmath.diff`` of the energy
    :math:`W(1/(s\lambda_z), s, \lambda_z)` at two stretches."""
    from tubefsi.testing.reference import tube_laws as ref

    if name == "hgo":
        dW, energy = hgo_axial(**params, lz=lz)
    else:
        mat = {"gent": lambda: ref.Gent(params["shear_modulus"], params["locking_parameter"]),
               "demiray": lambda: ref.Demiray(params["shear_modulus"], params["stiffening"]),
               "yeoh": lambda: ref.Yeoh(params["c1"], params["c2"], params["c3"]),
               "ogden": lambda: ref.Ogden(params["moduli"], params["exponents"])}[name]()
        L = mp.mpf(lz)
        dW = lambda s: mat.dW_axial(s, L)     # noqa: E731
        energy = lambda s: mat.W(1 / (s * L), s, L)     # noqa: E731
    for s in (mp.mpf("0.83"), mp.mpf("1.37")):
        assert abs(dW(s) / mp.diff(energy, s) - 1) < mp.mpf(10) ** (8 - mp.mp.dps)
    return dW


def hgo_axial(shear_modulus, fibre_stiffness, fibre_exponent, fibre_angle, lz):
    r"""The HGO energy under the axial stretch ``lz`` (stretches :math:`1/(s\lambda_z), s, \lambda_z`) and
    :math:`\hat W'` by hand: :math:`\mu(s - s^{-3}\lambda_z^{-2}) + 4k_1\cos^2\beta\,s\,x\,e^{k_2x^2}[x > 0]`,
    :math:`x = s^2\cos^2\beta + \lambda_z^2\sin^2\beta - 1`."""
    mu, k1, k2, L = (mp.mpf(v) for v in (shear_modulus, fibre_stiffness, fibre_exponent, lz))
    c2, s2 = mp.cos(mp.mpf(fibre_angle)) ** 2, mp.sin(mp.mpf(fibre_angle)) ** 2

    def energy(s):
        i1 = (s * L) ** -2 + s**2 + L**2
        x = s**2 * c2 + L**2 * s2 - 1
        return mu / 2 * (i1 - 3) + (k1 / k2 * (mp.exp(k2 * x**2) - 1) if x > 0 else 0)

    def dW(s):
        x = s**2 * c2 + L**2 * s2 - 1
        return mu * (s - s**-3 / L**2) + (4 * k1 * c2 * s * x * mp.exp(k2 * x**2) if x > 0 else 0)

    dW.kink = mp.sqrt((1 - L**2 * s2) / c2) if 1 - L**2 * s2 > 0 else None     # where the fibres engage
    return dW, energy


def s_integral(dW, lz, tb):
    r"""The thick law in the lumen stretch :math:`s_i` from the stress-free tube,
    :math:`\int_{s_o}^{s_i}\hat W'(s)/(\lambda_z s^2 - 1)\,ds` (mpmath; split where the fibres engage),
    and its derivative in :math:`s_i` (Leibniz, :math:`ds_o/ds_i = s_i/(b s_o)`)."""
    L, b = mp.mpf(lz), (1 + mp.mpf(tb)) ** 2

    def outer(si):
        return mp.sqrt((1 + (L * si**2 - 1) / b) / L)

    def law(si):
        so = outer(si)
        pts = sorted([so, si] + [k for k in [getattr(dW, "kink", None)] if k is not None and min(so, si) < k < max(so, si)])
        return mp.quad(lambda s: dW(s) / (L * s**2 - 1), pts) * (1 if si >= so else -1)

    def slope(si):
        so = outer(si)
        return dW(si) / (L * si**2 - 1) - dW(so) / (L * so**2 - 1) * si / (b * so)

    return law, slope


ISOTROPIC = {"gent": dict(shear_modulus=2e3, locking_parameter=3.0), "demiray": dict(shear_modulus=2e3, stiffening=0.7),
             "yeoh": dict(c1=1e3, c2=-120.0, c3=8.0), "ogden": dict(moduli=(2008.5, 14.75, 49.05), exponents=(1.3, 5.0, -2.0))}


@pytest.mark.parametrize("name", sorted(ISOTROPIC))
@pytest.mark.parametrize("lz", [0.8, 1.6])
def test_axial_stretch_of_plugin_materials_matches_mpmath(name, lz):
    """Gent, Demiray, Yeoh, Ogden installed at lz: the thick law against the s-integral of the 3-D
    energy (mpmath), including a collapsing stretch; the thin laws against the membrane forms
    tb W'(s_i)/sqrt(lz) and tb W'(s_i)/(lz s_i), s_i = lam/sqrt(lz) (the installed rest lumen
    a/sqrt(lz), as for every isotropic material)."""
    pytest.importorskip("tubefsi_hyperelastic")
    dW = axial_dW_of(name, ISOTROPIC[name], lz)
    thick = walls[f"thick-{name}"](axial_stretch=lz, **ISOTROPIC[name])
    thin = {c: walls[f"thin-{name}"](axial_stretch=lz, thickness_convention=c, **ISOTROPIC[name])
            for c in ("reference", "current")}
    with mp.workdps(20):
        for tb in (0.05, 1.2):
            law, _ = s_integral(dW, lz, tb)
            top = min(thick.max_stretch(tb), thin["current"].max_stretch(tb))
            for lam in (1.0 + 0.5 * (thick.min_stretch(tb) - 1.0), 1.01, min(2.0, 1 + 0.9 * (top - 1))):
                s_i = mp.mpf(lam) / mp.sqrt(lz)
                assert thick.pressure(lam, tb) == pytest.approx(float(law(s_i)), rel=1e-12)
                assert thin["reference"].pressure(lam, tb) == pytest.approx(float(tb * dW(s_i) / mp.sqrt(lz)), rel=1e-12)
                assert thin["current"].pressure(lam, tb) == pytest.approx(float(tb * dW(s_i) / (lz * s_i)), rel=1e-12)


def test_axial_stretch_of_plugin_materials_validates_and_locks():
    """Gent's lock and Demiray's maximum stretch in the installed variables (where I1 - 3 = J_m and
    b (I1 - 3) = 600, solved in mpmath from the stretches); typed errors where the installed tube
    at rest is beyond them, or has no positive small-strain modulus (Yeoh, Ogden)."""
    pytest.importorskip("tubefsi_hyperelastic")
    lz = mp.mpf(1.5)

    def installed_i1(sig):          # I1 - 3 at the installed stretch sigma = s sqrt(lz)
        s = sig / mp.sqrt(lz)
        return (s * lz) ** -2 + s**2 + lz**2 - 3

    gent = walls["thick-gent"](shear_modulus=1.0, locking_parameter=3.0, axial_stretch=1.5)
    assert gent.max_stretch(0.3) == pytest.approx(float(mp.findroot(lambda x: installed_i1(x) - 3, 2)), rel=1e-14)
    fung = walls["thin-demiray"](shear_modulus=1.0, stiffening=20.0, axial_stretch=1.5)
    assert fung.max_stretch(0.3) == pytest.approx(float(mp.findroot(lambda x: 20 * installed_i1(x) - 600, 2)), rel=1e-14)
    for name, kw in [("thick-gent", dict(shear_modulus=1.0, locking_parameter=0.5, axial_stretch=2.0)),
                     ("thin-demiray", dict(shear_modulus=1.0, stiffening=300.0, axial_stretch=2.5)),
                     ("thick-yeoh", dict(c1=1.0, c2=-2.0, c3=0.0, axial_stretch=2.0)),
                     ("thick-ogden", dict(moduli=(1.0, -0.9), exponents=(8.0, -2.0), axial_stretch=2.0)),
                     ("thick-gent", dict(shear_modulus=1.0, locking_parameter=3.0, axial_stretch=0.0))]:
        with pytest.raises(tubefsi.InvalidParameterError, match="axial_stretch"):
            walls[name](**kw)
    names = [p.name for p in tubefsi.fields.parameters(walls["thin-ogden"])]
    assert "axial_stretch" in names


@settings(deadline=None, max_examples=scaled(6))
@given(delta=st.floats(-1e-6, 1e-6), name=st.sampled_from(["thick-gent", "thin-demiray", "thick-ogden", "thin-yeoh",
                                                           "thick-hgo", "thin-hgo"]),
       lam=st.floats(1.001, 1.5))
@example(delta=-1e-6, name="thick-hgo", lam=1.001)    # the fibre walls at the low end of lam, on the side
@example(delta=1e-6, name="thin-hgo", lam=1.001)      # of delta where their fibres are slack at rest
def test_axial_stretch_near_one_gives_todays_walls(delta, name, lam):
    r"""lz -> 1: the tube law moves by O(delta) from the plane-strain wall (the fibre walls too).

    The change is measured against a pressure scale that does not vanish at lam = 1,
    |P(lam; 1)| + K0 (K0 = P'(1), the small-strain modulus), not against P(lam; 1) alone. An
    isotropic wall's law is smooth in (lam, lz) with P(1; lz) = 0, so the change
    delta dP/dlz = O(delta (lam - 1)) and the relative change is O(delta) (at most 1.5 |delta| for
    the four isotropic walls here). A fibre wall's plane law has a kink at lam = 1, where the
    fibres engage (slope K- = matrix only below, K+ = K0 above). At lz = 1 + delta the fibre strain
    at rest is x0 = delta (2 sin^2 b - cos^2 b) + O(delta^2); on the side where x0 < 0 (delta < 0
    for thick-hgo, b = 62 deg; delta > 0 for thin-hgo, b = 29 deg) the fibres are slack at rest and
    engage at lam* = 1 + k delta, k = -(2 sin^2 b - cos^2 b)/(2 cos^2 b) (thin wall), so for
    lam > lam*: P(lam; 1 + delta) - P(lam; 1) = -(K+ - K-) k delta + O(delta (lam - 1)), which does
    not vanish as lam -> 1. Against P(lam; 1) ~ K+ (lam - 1) that is c |delta| / (lam - 1),
    c = |k| (K+ - K-)/K+: 0.092 for thin-hgo (measured 0.094), 0.47 for thick-hgo from the thin-wall
    estimate (measured 0.60: the engagement spreads through the thick wall). At the strategy's
    lam = 1.001 that is 94 |delta| and 600 |delta|, so the former bound 50 |delta| on the relative
    change failed there (7.6e-5). Against the scale the measured coefficient is at most 2.04
    (thin-hgo at lam = 1.5, where its fibres stiffen) over lam in [1.001, 1.5] and both signs; the
    bound is 10. A wall whose lz -> 1 limit is wrong by a fraction e of P misses it as soon as
    e (lam - 1) > 10 |delta| (e = 1e-4 fails under the ci profile), by an offset e K0 as soon as
    e > 10 |delta| (e = 1e-5 fails). 1e-13: rounding in P near lam = 1 and for delta -> 0."""
    pytest.importorskip("tubefsi_hyperelastic")
    base = examples_of(name)
    near = attrs_evolve(base, axial_stretch=1.0 + delta)
    tb = 0.3
    p = base.pressure(lam, tb)
    scale = abs(p) + base.small_strain_modulus(tb)
    assert abs(near.pressure(lam, tb) - p) <= (10 * abs(delta) + 1e-13) * scale


@settings(deadline=None, max_examples=scaled(4))
@given(lz=st.lists(st.floats(0.85, 1.8), min_size=2, max_size=3), name=st.sampled_from(["thick-hgo", "thin-hgo",
                                                                                        "thick-demiray", "thin-gent"]))
def test_axial_stretch_broadcasts_like_a_loop(lz, name):
    """An array of axial stretches gives the scalar walls' values, entry by entry."""
    pytest.importorskip("tubefsi_hyperelastic")
    base = examples_of(name)
    lam, tb = np.array([1.02, 1.3])[:, None], np.array([0.1, 0.4])[:, None]
    wall = attrs_evolve(base, axial_stretch=np.array(lz))
    got = wall.pressure(lam, tb)
    assert got.shape == (2, len(lz))
    for j, value in enumerate(lz):
        one = attrs_evolve(base, axial_stretch=value)
        np.testing.assert_allclose(got[:, j], one.pressure(lam[:, 0], tb[:, 0]), rtol=1e-13)
        np.testing.assert_allclose(wall.stiffness(lam, tb)[:, j], one.stiffness(lam[:, 0], tb[:, 0]), rtol=1e-12)


# ------------------------------------------------------------------ 7. HGO in situ
HGO_CASES = [("rabbit-carotid-media", 1.7), ("rabbit-carotid-media", 1.3), ("rabbit-carotid-adventitia", 0.8),
             ("stiff", 1.3)]
STIFF_HGO = dict(shear_modulus=1e3, fibre_stiffness=1e4, fibre_exponent=20.0, fibre_angle=0.7)


def hgo_params(preset):
    from tubefsi.walls.hgo import PRESETS

    return STIFF_HGO if preset == "stiff" else PRESETS[preset]


@pytest.mark.parametrize("preset, lz", HGO_CASES)
def test_hgo_in_situ_matches_mpmath(preset, lz):
    r"""The pre-stretched HGO tube against the s-integral of its 3-D energy (mpmath): the rest
    lumen (the root of the law at zero pressure, stress-free geometry), the installed thickness
    (incompressibility), the thick law and its slope in the installed stretch
    :math:`\lambda = s_i/s_{i0}` (a collapsing stretch, a tiny strain, inflation past the point where
    slack fibres engage inside the wall at lz = 1.3), and the membrane (thin) laws with the
    membrane rest lumen :math:`\hat W'(s_0) = 0`."""
    params = hgo_params(preset)
    dW = axial_dW_of("hgo", params, lz)
    thick = walls["thick-hgo"](axial_stretch=lz, **params)
    thin = {c: walls["thin-hgo"](axial_stretch=lz, thickness_convention=c, **params) for c in ("reference", "current")}
    L = mp.mpf(lz)
    with mp.workdps(20):
        s0 = mp_root(dW, mp.mpf("0.2"), mp.mpf(3)) if dW(1 / mp.sqrt(L)) > 0 else 1 / mp.sqrt(L)   # membrane rest
        for tb in (0.1, 0.5):
            tube = tubefsi.Tube(radius=1.0, thickness=tb, length=1.0)
            law, slope = s_integral(dW, lz, tb)
            rest = mp_root(law, mp.mpf("0.3") * s0, s0 * (1 + mp.mpf(10) ** -25)) if law(s0) > 0 else s0
            installed = thick._installed_tube(tube)
            assert installed.radius == pytest.approx(float(rest), rel=1e-13)
            outer = mp.sqrt(rest**2 + (2 * tb + tb**2) / L)                  # R_o^2 = R_i^2 + (B^2 - A^2)/lz
            assert installed.thickness == pytest.approx(float(outer - rest), rel=1e-13)
            assert installed.length == lz
            tbi = installed.reduced_thickness
            top = thick.max_stretch(tbi)
            for lam in (1.0 + 0.5 * (thick.min_stretch(tbi) - 1.0), 1.0 + 1e-6, 1.05, min(1.5, 1 + 0.9 * (top - 1))):
                s_i = rest * lam
                assert thick.pressure(lam, tbi) == pytest.approx(float(law(s_i)), rel=1e-12), lam
                assert thick.stiffness(lam, tbi) == pytest.approx(float(slope(s_i) * rest), rel=1e-11), lam
            membrane = thin["current"]._installed_tube(tube)
            assert membrane.radius == pytest.approx(float(s0), rel=1e-13)
            assert membrane.thickness == pytest.approx(float(tb / (s0 * L)), rel=1e-13)
            tbm = membrane.reduced_thickness
            for lam in (1.0 + 0.5 * (thin["current"].min_stretch(tbm) - 1.0), 1.0 + 1e-6, 1.3):
                w = dW(s0 * lam)
                assert thin["reference"].pressure(lam, tbm) == pytest.approx(float(tbm * s0 * w), rel=1e-12)
                assert thin["current"].pressure(lam, tbm) == pytest.approx(float(tbm * s0 * w / lam), rel=1e-12)


def test_hgo_rest_state_against_an_ode_in_the_deformed_tube():
    r"""An independent check of the in-situ rest lumen: :math:`d\sigma_r/dR = (\sigma_\theta - \sigma_r)/R`
    integrated over the deformed wall by DOP853 (SciPy, rtol 1e-13), with the stresses from the
    3-D energy's principal stretches at each R (:math:`\rho^2 = A^2 + \lambda_z(R^2 - R_i^2)`); from
    :math:`\sigma_r(R_i) = 0` at the library's rest lumen it ends at :math:`\sigma_r(R_o) = 0`."""
    from scipy.integrate import solve_ivp

    params, lz, tb = hgo_params("rabbit-carotid-media"), 1.7, 0.4
    wall = walls["thick-hgo"](axial_stretch=lz, **params)
    installed = wall._installed_tube(tubefsi.Tube(radius=1.0, thickness=tb, length=1.0))
    mu, k1, k2 = params["shear_modulus"], params["fibre_stiffness"], params["fibre_exponent"]
    c2, s2 = math.cos(params["fibre_angle"]) ** 2, math.sin(params["fibre_angle"]) ** 2
    r_i = installed.radius
    r_o = r_i + installed.thickness

    def radial_stress_at_outer(lumen, p):
        """sigma_r at the outer surface from sigma_r(lumen) = -p; the material point of R has
        rho^2 = 1 + lz (R^2 - lumen^2) in the stress-free tube (its lumen at rho = 1)."""
        def difference(R):      # sigma_theta - sigma_r = lam_t W_t - lam_r W_r at the stretches of R
            lt = R / math.sqrt(1.0 + lz * (R * R - lumen * lumen))
            lr = 1.0 / (lt * lz)
            x = lt * lt * c2 + lz * lz * s2 - 1.0
            fibre = 4.0 * k1 * x * math.exp(k2 * x * x) * lt * lt * c2 if x > 0 else 0.0
            return mu * (lt * lt - lr * lr) + fibre

        outer = math.sqrt(lumen * lumen + (r_o * r_o - r_i * r_i))
        end = solve_ivp(lambda R, y: [difference(R) / R], (lumen, outer), [-p], method="DOP853", rtol=1e-13,
                        atol=1e-16).y[0, -1]
        scale = solve_ivp(lambda R, y: [abs(difference(R)) / R], (lumen, outer), [0.0], method="DOP853",
                          rtol=1e-10).y[0, -1]
        return end, scale

    end, scale = radial_stress_at_outer(r_i, 0.0)
    assert abs(end) < 1e-12 * scale
    # and the lumen 5 % wider: the same ODE from sigma_r = -P(1.05) ends at 0
    end, scale = radial_stress_at_outer(1.05 * r_i, wall.pressure(1.05, installed.reduced_thickness))
    assert abs(end) < 1e-12 * scale


@pytest.mark.parametrize("lz", [1.7, 1.3])
def test_artery_in_situ_solve_matches_mpmath(lz):
    """solve() through the pre-stretched HGO media (thick), Newtonian, under an external pressure
    that puts the outlet below rest: pressure drop and inlet radius against the mpmath solution
    of the installed tube (rest lumen from the s-integral, length lz L) to 1e-11."""
    params = hgo_params("rabbit-carotid-media")
    wall = walls["thick-hgo"](axial_stretch=lz, **params)
    tube = tubefsi.Tube(radius=1e-3, thickness=3e-4, length=2e-2)
    dW = axial_dW_of("hgo", params, lz)
    q, p_out, p_e = 2e-7, 20.0, 25.0
    sol = tubefsi.solve(NEWTONIAN, wall, tube, flow_rate=q, outlet_pressure=p_out, external_pressure=p_e)
    with mp.workdps(20):
        law_s, slope_s = s_integral(dW, lz, tube.reduced_thickness)
        s0 = mp_root(dW, mp.mpf("0.2"), mp.mpf(3))
        rest = mp_root(law_s, mp.mpf("0.3") * s0, s0 * (1 + mp.mpf(10) ** -25))
        installed = tubefsi.Tube(radius=float(rest) * tube.radius, thickness=1.0, length=tube.length * lz)
        dp, e_in, _ = mp_reference(lambda lam: law_s(rest * lam), lambda lam: slope_s(rest * lam) * rest, NEWTONIAN,
                                   installed, q, mp.mpf(p_out - p_e))
    assert sol.tube.radius == pytest.approx(float(rest) * tube.radius, rel=1e-13)
    assert sol.pressure_drop == pytest.approx(float(dp), rel=1e-11)
    assert sol.radius(0.0) == pytest.approx(float((1 + e_in) * rest) * tube.radius, rel=1e-11)


def test_hgo_in_situ_validates():
    params = hgo_params("rabbit-carotid-media")
    with pytest.raises(tubefsi.InvalidParameterError, match="axial_stretch"):     # k2 x0^2 >= 600 at rest
        walls["thick-hgo"](**{**params, "fibre_exponent": 500.0}, axial_stretch=3.0)
    with pytest.raises(tubefsi.InvalidParameterError, match="axial_stretch"):
        walls["thin-hgo"](**params, axial_stretch=-1.0)
    names = [p.name for p in tubefsi.fields.parameters(walls["thick-hgo"])]
    assert "axial_stretch" in names
    wall = walls["thick-hgo"].preset("rabbit-carotid-media", axial_stretch=1.7)
    top = wall.max_stretch(0.3)
    with pytest.raises(tubefsi.InvalidParameterError, match="stretch"):
        wall.pressure(top * 1.0001, 0.3)
    assert wall.min_pressure(0.3) == pytest.approx(-params["shear_modulus"] / 1.7 * (0.3 / 1.3) ** 3)


class TestStiffHGOInSitu(tubefsi.testing.AccuracyContract):
    """A stiff thin fibre law (k2 = 20) at lz = 1.3, whose fibres are slack at rest and engage at
    the stretch 1.10, inside the flow (the quadratures split there), and a stiff thick Demiray
    (b = 20) at lz = 1.3, against the brute force."""

    @pytest.fixture(params=tubefsi.testing.accuracy_cases(
        [walls["thin-hgo"](shear_modulus=1e3, fibre_stiffness=1e4, fibre_exponent=20.0, fibre_angle=0.3,
                           thickness_convention="current", axial_stretch=1.3)]
        + ([walls["thick-demiray"](shear_modulus=1e3, stiffening=20.0, axial_stretch=1.3)] if "thick-demiray" in walls else []),
        [POWER_LAW]))
    def case(self, request):
        return request.param


def test_docs_artery_in_situ_example():
    """The numbers docs/walls_beyond.md quotes for its artery in situ (section "Examples")."""
    blood = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    artery = walls["thick-hgo"].preset("rabbit-carotid-media", axial_stretch=1.7)
    tube = tubefsi.Tube(radius=1.5e-3, thickness=4e-4, length=5e-2)
    rest = tubefsi.solve(blood, artery, tube, flow_rate=0.0).tube
    assert (round(rest.radius, 7), round(rest.thickness, 7), rest.length) == (1.0821e-3, 3.218e-4, 0.085)
    assert round(artery.min_pressure(rest.reduced_thickness), 2) == -21.25
    sol = tubefsi.solve(blood, artery, tube, flow_rate=2e-6, outlet_pressure=1e3, external_pressure=1.01e3)
    assert round(sol.pressure_drop, 1) == 427.4
    ratios = sol.radius(np.linspace(0, sol.tube.length, 5)) / rest.radius
    np.testing.assert_array_equal(np.round(ratios, 3), [1.226, 1.176, 1.120, 1.060, 0.996])
