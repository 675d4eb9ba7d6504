"""The chapter's printed inconsistencies and what they change (docs/verification.md).

Each test backs one claim of the verification page, and would fail if the claim were false.
"As printed" means the chapter's own equations (tubefsi.chapter.printed_*); "consistent"
means tubefsi.solve of the physical scene (tubefsi.dimensionless.scene), whose formulas are
derived from the tube law and the flow law (docs/theory.md) and checked against an independent
high-precision reference and, for the tube laws, against finite elements (test_fem_tube_laws).
"""

import math

import mpmath
import numpy as np
import pytest

import tubefsi
from tubefsi import chapter
from tubefsi import dimensionless as nd
from tubefsi.registry import walls
from tubefsi.walls.hyperelastic import HyperelasticWall

TB = 0.3                                   # the chapter's thick-wall figure
BETAS = (0.5, 1.0, 2.0)                    # the reproduced curves (CHAPTER_PARAMETERS)
INDICES = (1.0, 0.7)
QBAR = np.linspace(0.005, 1.0, 200)


def flow_factor(n, qbar):
    """X = [(3 + 1/n) qbar]^n; a rigid tube has dpbar = 2 X (Hagen–Poiseuille)."""
    return ((3.0 + 1.0 / n) * np.asarray(qbar)) ** n


def consistent(n, qbar, *, tb=None, gamma=None, beta=None, wall=None, **options):
    wall = wall or ("thin-mooney-rivlin" if tb is None else "thick-mooney-rivlin")
    return nd.scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar, gamma=gamma, beta=beta, wall=wall,
                    wall_options=options or None).pressure_drop()


def linear(n, qbar, beta, tb=None):
    return consistent(n, qbar, tb=tb, beta=beta, wall="thin-linear" if tb is None else "thick-linear")


# =============================================================================== 1. gamma = 3 beta
HYPERELASTIC_EXAMPLES = [pytest.param(name, kw, id=f"{name}-{i}") for name in walls
                         if isinstance(walls[name], type) and issubclass(walls[name], HyperelasticWall)
                         for i, kw in enumerate(getattr(walls[name], "_examples", ()))]


@pytest.mark.parametrize(("name", "params"), HYPERELASTIC_EXAMPLES)
def test_gamma_is_three_beta_for_every_incompressible_wall(name, params):
    """gamma = P_c/(2(c1+c2) t/a) = P_c/(mu t/a) and beta = P_c/(E t/a) with E = 3 mu: gamma = 3 beta."""
    g = nd.groups(tubefsi.registry.rheologies["power-law"](consistency=0.02, index=0.7), walls[name](**params),
                  tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2), flow_rate=1e-9)
    assert g.gamma == pytest.approx(3.0 * g.beta, rel=1e-14)
    assert g.gamma != pytest.approx(g.beta / 3.0, rel=0.5)          # the printed relation


def test_gamma_is_three_beta_from_the_chapters_own_definitions():
    """Its eq. (Linear_Hyper) G = 2(c1+c2) and 2G(1+nu) = E at nu = 1/2: E = 6(c1+c2)."""
    c1, c2, pc, tb, nu = 1.7, -0.4, 5.0, 0.3, 0.5
    e = 2 * (2 * (c1 + c2)) * (1 + nu)
    gamma, beta = pc / (2 * (c1 + c2) * tb), pc / (e * tb)
    assert gamma == pytest.approx(3 * beta, rel=1e-15)


@pytest.mark.parametrize("theory", ["thin", "thick"])
def test_printed_labelling_compares_a_nine_times_stiffer_hyperelastic_wall(theory):
    """At "beta = 3 gamma" the hyperelastic wall's small-strain stiffness dP/dlam is 9x the
    linear wall's; at gamma = 3 beta it is equal (thin and thick, nu = 1/2)."""
    tb = 0.3 if theory == "thick" else 0.1
    lin = nd.scene(index=1, reduced_thickness=tb, qbar=0.5, beta=1.0, wall=f"{theory}-linear").wall
    printed = nd.scene(index=1, reduced_thickness=tb, qbar=0.5, gamma=1.0 / 3.0, wall=f"{theory}-mooney-rivlin").wall
    fixed = nd.scene(index=1, reduced_thickness=tb, qbar=0.5, gamma=3.0, wall=f"{theory}-mooney-rivlin").wall
    ratio = printed.small_strain_modulus(tb) / lin.small_strain_modulus(tb)
    assert ratio == pytest.approx(9.0, rel=1e-9)
    assert fixed.small_strain_modulus(tb) == pytest.approx(lin.small_strain_modulus(tb), rel=1e-9)


# =============================================================================== 2. factor 3 (thin)
@pytest.mark.parametrize("lam", [1.0, 1.3, 2.0, 5.0])
def test_thin_tube_law_derivative_has_the_factor_3(lam):
    d = mpmath.diff(lambda s: s - s**-3, mpmath.mpf(lam))
    assert float(d) == pytest.approx(1 + 3 * lam**-4, rel=1e-14)
    assert float(d) != pytest.approx(1 + lam**-4, rel=1e-3)


@pytest.mark.parametrize("n", [0.7, 1.0, 1.4])
@pytest.mark.parametrize("lam", [1.2, 2.0, 3.5])
def test_printed_closed_form_integrates_an_ode_without_the_factor_3(n, lam):
    """d/dlam of the printed right side is lam^(3n+1) + lam^(3n-3) (the printed ODE); the tube
    law times the flow law needs lam^(3n+1) d(lam - lam^-3)/dlam = lam^(3n+1) + 3 lam^(3n-3)."""
    mp = mpmath.mpf
    n_ = mp(n)

    def printed(s):
        return s ** (3 * n_ + 2) / (3 * n_ + 2) + s ** (3 * n_ - 2) / (3 * n_ - 2)

    derived = mpmath.diff(lambda s: s - s**-3, mp(lam)) * mp(lam) ** (3 * n_ + 1)
    assert float(mpmath.diff(printed, mp(lam))) == pytest.approx(lam ** (3 * n + 1) + lam ** (3 * n - 3), rel=1e-13)
    assert float(derived) == pytest.approx(lam ** (3 * n + 1) + 3 * lam ** (3 * n - 3), rel=1e-13)


@pytest.mark.parametrize("n", INDICES + (2 / 3, 1.5))
@pytest.mark.parametrize("gamma", [0.2, 1.0, 3.0])
def test_corrected_thin_closed_form_agrees_with_tubefsi(n, gamma):
    q = QBAR[::20]
    np.testing.assert_allclose(chapter.thin_reference_pressure_drop(n, gamma, q), consistent(n, q, gamma=gamma),
                               rtol=1e-12)


def test_printed_thin_closed_form_overestimates_the_pressure_drop():
    """By 43 % at n = 1, gamma = 1, qbar = 0.1; 36 % at n = 0.7; 3 % at n = 1, gamma = 3, qbar = 1."""
    for n, g, q, excess in [(1.0, 1.0, 0.1, 0.435), (0.7, 1.0, 0.1, 0.365), (1.0, 3.0, 1.0, 0.031)]:
        assert chapter.printed_thin_pressure_drop(n, g, q) / consistent(n, q, gamma=g) - 1 == pytest.approx(excess, abs=1e-3)
    for n in INDICES:
        for g in (1 / 6, 1 / 3, 2 / 3, 1.5, 3.0, 6.0):
            assert np.all(chapter.printed_thin_pressure_drop(n, g, QBAR) > consistent(n, QBAR, gamma=g))


@pytest.mark.parametrize("n", INDICES)
def test_printed_thin_closed_form_misses_hagen_poiseuille_by_2(n):
    """As qbar -> 0 the tube is rigid: dpbar -> 2X. The printed closed form gives 4X."""
    q = 1e-12
    assert chapter.printed_thin_pressure_drop(n, 1.0, q) / (2 * flow_factor(n, q)) == pytest.approx(2.0, rel=1e-5)
    assert consistent(n, q, gamma=1.0) / (2 * flow_factor(n, q)) == pytest.approx(1.0, rel=1e-5)


# =============================================================================== 3. factor 4 (thick)
def test_printed_thick_ode_numbers():
    """n = 0.7, gamma = 1, qbar = 0.5, t/a = 0.3: printed ODE 0.558, consistent 0.870.

    docs/verification.md, section "The chapter's printed inconsistencies", item 3.
    """
    printed = chapter.printed_thick_pressure_drop(0.7, 1.0, 0.5, TB)
    fixed = chapter.printed_thick_pressure_drop(0.7, 1.0, 0.5, TB, factor=4.0)
    assert round(printed, 3) == 0.558
    assert round(consistent(0.7, 0.5, tb=TB, gamma=1.0), 3) == 0.870
    assert fixed == pytest.approx(consistent(0.7, 0.5, tb=TB, gamma=1.0), rel=1e-10)


@pytest.mark.parametrize("n", INDICES + (1.5,))
@pytest.mark.parametrize(("gamma", "tb"), [(0.2, 0.3), (1.0, 0.3), (3.0, 0.3), (1.0, 1.0), (1.0, 0.05)])
def test_thick_ode_with_factor_4_agrees_with_tubefsi(n, gamma, tb):
    sc = nd.scene(index=n, reduced_thickness=tb, qbar=0.1, gamma=gamma)
    q = QBAR[::10][QBAR[::10] < sc.max_qbar()]
    np.testing.assert_allclose(chapter.printed_thick_pressure_drop(n, gamma, q, tb, factor=4.0),
                               consistent(n, q, tb=tb, gamma=gamma), rtol=1e-9)


def test_printed_thick_brace_is_the_tube_law_slope():
    """The printed left side is right: the brace is -P'(lam)/(c1+c2); only the right side's factor is off."""
    wall = walls["thick-mooney-rivlin"](c1=0.7, c2=-0.2)
    u = np.linspace(0.0, 4.0, 41)
    np.testing.assert_allclose(chapter._thick_brace(u, TB), -wall.stiffness(1 + u, TB) / (wall.c1 + wall.c2),
                               rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize(("n", "gamma", "qbar"), [(0.7, 1.0, 0.5), (1.0, 3.0, 0.8), (1.3, 0.5, 0.3)])
def test_tubefsi_profiles_satisfy_the_thick_ode_with_factor_4(n, gamma, qbar):
    """Along the solved tube, B(u) du/dz / (t/a gamma X (1+u)^-(1+3n)) = 4 at every z (not 1)."""
    sc = nd.scene(index=n, reduced_thickness=TB, qbar=qbar, gamma=gamma)
    sol = sc.solve()
    L, a = sc.tube.length, sc.tube.radius
    z = np.linspace(0.1, 0.9, 9) * L
    h = 1e-4 * L
    u = sol.displacement(z) / a
    dudz = (sol.displacement(z + h) - sol.displacement(z - h)) / (2 * h) * L / a     # d ubar / d zbar
    ratio = chapter._thick_brace(u, TB) * dudz / (TB * gamma * flow_factor(n, qbar) * (1 + u) ** -(1 + 3 * n))
    np.testing.assert_allclose(ratio, 4.0, rtol=1e-6)


@pytest.mark.parametrize(("n", "gamma", "qbar"), [(0.7, 1.0, 0.5), (1.0, 3.0, 0.8)])
def test_printed_thick_pressure_gradient_relation_lacks_2_tb(n, gamma, qbar):
    """Its eq. (deflection_pressure_gradient_thick_nondim) reads gamma dp/dz = -B du/dz; the thick
    law 2 t/a gamma p = f(x_o) - f(x_i) gives 2 t/a gamma dp/dz = -B du/dz (checked along a solution)."""
    sc = nd.scene(index=n, reduced_thickness=TB, qbar=qbar, gamma=gamma)
    sol = sc.solve()
    L, a, pc = sc.tube.length, sc.tube.radius, sc.pressure_scale
    z = np.linspace(0.1, 0.9, 9) * L
    h = 1e-4 * L
    u = sol.displacement(z) / a
    dudz = (sol.displacement(z + h) - sol.displacement(z - h)) / (2 * h) * L / a
    dpdz = (sol.pressure(z + h) - sol.pressure(z - h)) / (2 * h) * L / pc
    np.testing.assert_allclose(-chapter._thick_brace(u, TB) * dudz / (gamma * dpdz), 2 * TB, rtol=1e-6)


@pytest.mark.parametrize("n", INDICES)
@pytest.mark.parametrize("tb", [0.1, TB, 1.0])
def test_printed_thick_ode_misses_hagen_poiseuille_by_4(n, tb):
    """As qbar -> 0: dpbar -> 2X consistently, X/2 from the printed ODE (any gamma, t/a)."""
    q = 1e-12
    assert chapter.printed_thick_pressure_drop(n, 0.7, q, tb) / (2 * flow_factor(n, q)) == pytest.approx(0.25, rel=1e-5)
    assert consistent(n, q, tb=tb, gamma=0.7) / (2 * flow_factor(n, q)) == pytest.approx(1.0, rel=1e-5)


def _conclusion_thin_relation(n, q, m, length, c, t, a, u, *, pi=False, three=False):
    """Both sides of the chapter's dimensional thin relation (eq. flowrate_deflection_dim) at z = 0,
    optionally with the 1/pi^n and the factor 3 restored."""
    left = m * ((3 + 1 / n) * q / (math.pi if pi else 1.0)) ** n / (c * t) * length
    k = 3.0 if three else 1.0
    right = ((a + u) ** (3 * n + 2) / (a**2 * (3 * n + 2)) + k * a**2 * (a + u) ** (3 * n - 2) / (3 * n - 2)
             - a ** (3 * n) * (1 / (3 * n + 2) + k / (3 * n - 2)))
    return left, right


@pytest.mark.parametrize("n", [1.0, 0.7, 1.5])
def test_dimensional_restatement_in_the_conclusion_lacks_pi_and_the_factor_3(n):
    """The conclusion's eq. (flowrate_deflection_dim) (and its Newtonian case) drops 1/pi^n from the
    flow law as well as the factor 3; with both restored it holds at tubefsi's inlet displacement."""
    c1, c2, a, t, length, m, q = 1.2e3, -0.2e3, 1e-4, 1e-5, 1e-2, 0.02, 2e-10
    wall = walls["thin-mooney-rivlin"](c1=c1, c2=c2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=m, index=n)
    u = tubefsi.solve(fluid, wall, tubefsi.Tube(radius=a, thickness=t, length=length), flow_rate=q).inlet_displacement
    assert u / a > 0.05                                          # a finite deformation
    args = (n, q, m, length, c1 + c2, t, a, u)
    left, right = _conclusion_thin_relation(*args, pi=True, three=True)
    assert left == pytest.approx(right, rel=1e-11)
    for pi, three in [(False, False), (True, False), (False, True)]:
        left, right = _conclusion_thin_relation(*args, pi=pi, three=three)
        assert abs(left / right - 1) > 0.05


# =============================================================================== 4. thin vs thick laws
@pytest.mark.parametrize("tb", [1e-2, 1e-3, 1e-4])
def test_thick_law_tends_to_the_thin_current_thickness_law(tb):
    """max over 1 < lam <= 3 of |P_thick / P_thin,current - 1| is 1.5 t/a to first order."""
    mu = 2e3
    lam = np.linspace(1.001, 3.0, 500)
    thick = walls["thick-neo-hookean"](shear_modulus=mu).pressure(lam, tb)
    thin = walls["thin-neo-hookean"](shear_modulus=mu, thickness_convention="current").pressure(lam, tb)
    worst = np.max(np.abs(thick / thin - 1))
    assert worst == pytest.approx(1.5 * tb, rel=0.02)


@pytest.mark.parametrize("wall", ["thin-neo-hookean", "thin-mooney-rivlin"])
def test_thin_reference_law_is_the_current_law_times_the_stretch(wall):
    """The two thin laws agree to first order in strain only: P_ref / P_cur = lambda."""
    kw = {"shear_modulus": 2e3} if "neo" in wall else {"c1": 1.5e3, "c2": -0.5e3}
    lam = np.linspace(1.0001, 3.0, 50)
    ref = walls[wall](**kw, thickness_convention="reference").pressure(lam, 0.05)
    cur = walls[wall](**kw, thickness_convention="current").pressure(lam, 0.05)
    np.testing.assert_allclose(ref / cur, lam, rtol=1e-13)


def test_thin_current_thickness_changes_the_thin_figure():
    """With the consistent (current) thickness, the thin tube saturates at 1/gamma and a
    shear-thinning flow has a maximum flow rate (0.147 at gamma = 3, n = 0.7); the chapter's
    reference-thickness law has neither."""
    cur = dict(thickness_convention="current")
    assert consistent(1.0, 1.0, gamma=3.0, **cur) == pytest.approx(1 / 3, rel=1e-6)
    assert consistent(1.0, 1.0, gamma=3.0) == pytest.approx(0.8134, abs=1e-4)
    assert nd.scene(index=0.7, reduced_thickness=0.1, qbar=0.1, gamma=3.0, wall="thin-mooney-rivlin",
                    wall_options=cur).max_qbar() == pytest.approx(0.147, abs=1e-3)
    reference = nd.scene(index=0.7, reduced_thickness=0.1, qbar=0.1, gamma=3.0, wall="thin-mooney-rivlin")
    assert reference.max_qbar() == math.inf


# =============================================================================== 5. softening
@pytest.mark.parametrize("lam", [1.0, 1.5, 3.0, 10.0])
def test_plane_strain_invariants_are_equal(lam):
    """Stretches (1/lam, lam, 1): I1 = I2, so W = c1 (I1 - 3) + c2 (I2 - 3) depends on c1 + c2 only
    (the FEM check with felupe's 3-D Mooney–Rivlin model confirms it for c2 of either sign)."""
    l1, l2, l3 = 1 / lam, lam, 1.0
    i1 = l1**2 + l2**2 + l3**2
    i2 = (l1 * l2) ** 2 + (l2 * l3) ** 2 + (l3 * l1) ** 2
    assert i1 == pytest.approx(i2, rel=1e-15)


MR = [{"c1": 1.5e3, "c2": -0.5e3}, {"c1": 1e3, "c2": 1e3}, {"c1": 3e3, "c2": -2.5e3}]
THEORIES = [("thin-mooney-rivlin", {"thickness_convention": "reference"}, "thin-linear"),
            ("thin-mooney-rivlin", {"thickness_convention": "current"}, "thin-linear"),
            ("thick-mooney-rivlin", {}, "thick-linear")]


@pytest.mark.parametrize("params", MR, ids=["c2<0", "c2>0", "c2<<0"])
@pytest.mark.parametrize(("name", "options", "_"), THEORIES, ids=["thin-ref", "thin-cur", "thick"])
def test_plane_strain_mooney_rivlin_tube_laws_soften(name, options, _, params):
    """dP/dlam falls monotonically from lambda = 1, for every c2 (negative included)."""
    wall = walls[name](**params, **options)
    lam = np.linspace(1.0, 10.0, 2000)
    slope = wall.stiffness(lam, TB)
    assert np.all(np.diff(slope) < 0)
    assert slope[-1] < 0.3 * slope[0]


@pytest.mark.parametrize("params", MR, ids=["c2<0", "c2>0", "c2<<0"])
def test_thick_and_thin_current_laws_saturate(params):
    mu = 2 * (params["c1"] + params["c2"])
    thick = walls["thick-mooney-rivlin"](**params)
    cur = walls["thin-mooney-rivlin"](**params, thickness_convention="current")
    assert thick.limit_pressure(TB) == pytest.approx(mu * math.log1p(TB), rel=1e-14)
    assert cur.limit_pressure(TB) == pytest.approx(mu * TB, rel=1e-14)
    assert thick.pressure(1e3, TB) == pytest.approx(thick.limit_pressure(TB), rel=1e-5)
    assert cur.pressure(1e3, TB) == pytest.approx(cur.limit_pressure(TB), rel=1e-5)


@pytest.mark.parametrize(("name", "options", "linear_name"), THEORIES, ids=["thin-ref", "thin-cur", "thick"])
def test_hyperelastic_wall_deforms_more_than_the_linear_one_at_equal_stiffness(name, options, linear_name):
    """At E = 3 mu (equal small-strain stiffness): P_hyper(lam) < P_linear(lam) for every
    lam > 1, so at equal pressure the hyperelastic tube is the *more* inflated one."""
    mu = 2e3
    hyper = walls[name](c1=mu / 2, c2=0.0, **options)
    lin = walls[linear_name](youngs_modulus=3 * mu, poisson_ratio=0.5)
    lam = np.linspace(1.001, 3.0, 300)
    assert np.all(hyper.pressure(lam, TB) < lin.pressure(lam, TB))
    p = hyper.pressure(lam, TB)
    assert np.all(hyper.stretch(p, TB) > lin.stretch(p, TB))


def test_the_material_stiffens_but_the_tube_softens():
    """The hoop-minus-radial Cauchy stress lam dW(lam) = mu (lam^2 - lam^-2) has the slope
    2 mu (lam + lam^-3), which grows without bound beyond lam = 3^(1/4) (the material stiffens,
    as the chapter's d sigma/d lambda argument says); the pressure a thin tube holds is that
    stress times the current thickness t/lam over the current radius lam a, and the 1/lam^2
    wins: the tube law softens, and the softening is geometric."""
    mu, tb = 2e3, 1e-3
    wall = walls["thin-neo-hookean"](shear_modulus=mu, thickness_convention="current")
    lam = np.linspace(1.0, 4.0, 400)
    stress = lam * wall.dW(lam)
    np.testing.assert_allclose(stress, mu * (lam**2 - lam**-2), rtol=1e-12, atol=1e-9)
    slope = np.gradient(stress, lam)
    beyond = lam > 3**0.25 + 0.02
    assert np.all(np.diff(slope[beyond]) > 0) and slope[-1] > 2 * slope[0]
    np.testing.assert_allclose(wall.pressure(lam, tb), tb * stress / lam**2, rtol=1e-12, atol=1e-12)


# =============================================================================== conclusions
@pytest.mark.parametrize("n", INDICES)
@pytest.mark.parametrize("beta", BETAS)
def test_thin_conclusion_reverses(n, beta):
    """Chapter: at the same FSI parameter the (stiffer) hyperelastic tube needs the higher pressure
    drop. True only as printed; at equal E it needs a lower one, at every qbar."""
    lin = linear(n, QBAR, beta)
    assert np.all(chapter.printed_thin_pressure_drop(n, beta / 3, QBAR) > lin)                    # as printed
    assert np.all(chapter.thin_reference_pressure_drop(n, beta / 3, QBAR) > lin)    # factor 3 fixed, gamma = beta/3
    assert np.all(consistent(n, QBAR, gamma=3 * beta) < lin)                                   # consistent


@pytest.mark.parametrize("n", INDICES)
def test_thick_crossing_is_an_artifact(n):
    """Chapter: linear above hyperelastic at small qbar, below at large qbar and beta ("strain-
    stiffening"). The printed equations reproduce that crossing; consistently there is none:
    the hyperelastic tube needs the lower pressure drop at every qbar and beta. The crossing
    needs both errors: with the factor 4 alone restored the (9x stiffer) hyperelastic curve lies
    above the linear one everywhere, with the labelling alone fixed below it everywhere."""
    printed_hyper = chapter.printed_thick_pressure_drop(n, 2.0 / 3, QBAR, TB)
    lin = linear(n, QBAR, 2.0, tb=TB)
    assert np.any(printed_hyper < lin) and np.any(printed_hyper > lin)
    assert printed_hyper[0] < lin[0] and printed_hyper[-1] > lin[-1]
    for beta in BETAS:
        lin = linear(n, QBAR, beta, tb=TB)
        assert np.all(chapter.printed_thick_pressure_drop(n, beta / 3, QBAR, TB, factor=4.0) > lin)
        label_only = chapter.printed_thick_pressure_drop(n, 3 * beta, QBAR, TB)
        ok = np.isfinite(label_only)
        assert ok.sum() > 50 and np.all(label_only[ok] < lin[ok])
        sc = nd.scene(index=n, reduced_thickness=TB, qbar=0.1, gamma=3 * beta)
        q = QBAR[QBAR < sc.max_qbar()]
        assert np.all(consistent(n, q, tb=TB, gamma=3 * beta) < linear(n, q, beta, tb=TB))


@pytest.mark.parametrize("beta", BETAS)
def test_thick_hyperelastic_pressure_drop_saturates(beta):
    """Consistent: Newtonian dpbar rises to p_max/P_c = ln(1 + t/a)/(gamma t/a) and stays below it
    (within 2e-4 of it at qbar = 1 for every beta of the figure)."""
    gamma = 3 * beta
    top = math.log1p(TB) / (gamma * TB)
    dp = consistent(1.0, QBAR, tb=TB, gamma=gamma)
    assert np.all(dp <= top * (1 + 1e-13)) and np.all(np.diff(dp) >= 0)
    assert dp[-1] == pytest.approx(top, rel=2e-4)


def test_shear_thinning_thick_tubes_have_a_maximum_flow_rate_within_the_figure():
    """Consistent, n = 0.7, t/a = 0.3: qbar_max = 0.512, 0.190, 0.071 for beta = 0.5, 1, 2; as
    printed, every thick curve (n = 1 and 0.7) rises over the whole range qbar in [0, 1]."""
    for beta, expected in zip(BETAS, (0.512, 0.190, 0.071)):
        assert nd.scene(index=0.7, reduced_thickness=TB, qbar=0.1, gamma=3 * beta).max_qbar() == pytest.approx(
            expected, abs=1e-3)
        for n in INDICES:
            printed = chapter.printed_thick_pressure_drop(n, beta / 3, QBAR, TB)
            assert np.all(np.isfinite(printed)) and np.all(np.diff(printed) > 0)


@pytest.mark.parametrize("beta", BETAS)
def test_maximum_flow_rate_is_where_the_consistent_ode_runs_out(beta):
    """Independently: qbar_max solves int_0^inf (-B) lam^(1+3n) du = 4 t/a gamma [(3+1/n) qbar]^n
    (mpmath quadrature of the thick ODE with the factor 4), for n = 0.7."""
    n, gamma = 0.7, 3 * beta
    d = TB * (2 + TB)

    def integrand(v):                       # v = ln(lam), du = lam dv
        lam = mpmath.e**v
        l2 = lam * lam
        return 2 * lam * d * (l2 * (d + 2) + d) / (l2 * l2 * (l2 + d) ** 2) * lam ** (2 + 3 * n)

    total = float(mpmath.quad(integrand, [0, 1, 5, 20, mpmath.inf]))
    expected = (total / (4 * TB * gamma)) ** (1 / n) / (3 + 1 / n)
    got = nd.scene(index=n, reduced_thickness=TB, qbar=0.1, gamma=gamma).max_qbar()
    assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("theory", ["thin", "thick"])
def test_pressure_drop_falls_with_beta_unchanged(theory):
    """Chapter: dpbar decreases as beta grows. Holds both as printed and consistently."""
    tb = TB if theory == "thick" else None
    q = np.array([0.02, 0.05])
    printed = [chapter.printed_thin_pressure_drop(1.0, b / 3, q) if tb is None
               else chapter.printed_thick_pressure_drop(1.0, b / 3, q, tb) for b in BETAS]
    fixed = [consistent(1.0, q, tb=tb, gamma=3 * b) for b in BETAS]
    lin = [linear(1.0, q, b, tb=tb) for b in BETAS]
    for curves in (printed, fixed, lin):
        assert np.all(np.diff(np.array(curves), axis=0) < 0)


def test_thickness_effect_holds_at_fixed_gamma_and_reverses_at_fixed_modulus():
    """Chapter: dpbar decreases with t/a. Consistently true at fixed gamma (a modulus
    proportional to a/t); at a fixed shear modulus a thicker wall is stiffer and dpbar grows."""
    tbs = (0.1, 0.3, 1.0)
    at_gamma = [consistent(0.7, 0.3, tb=tb, gamma=1.0) for tb in tbs]
    at_mu = [consistent(0.7, 0.3, tb=tb, gamma=0.1 / tb) for tb in tbs]
    assert np.all(np.diff(at_gamma) < 0) and np.all(np.diff(at_mu) > 0)


# =============================================================================== the reproduction
def test_reproduction_writes_both_figures_both_ways(tmp_path):
    paths = chapter.reproduce_chapter(tmp_path, points=21)
    names = sorted(p.name for p in paths)
    assert names == sorted(f"{f}_{v}.{e}" for f in ("thin", "thick") for v in ("printed", "consistent")
                           for e in ("png", "csv"))
    rows = (tmp_path / "thick_consistent.csv").read_text().splitlines()
    assert rows[0] == "figure,variant,n,beta_label,gamma_used,wall,qbar,dpbar"
    assert len(rows) == 1 + 2 * 3 * 2 * 21
    assert any(r.endswith(",") for r in rows)        # beyond the maximum flow rate: no steady state


def test_chapter_curves_match_the_functions_they_plot():
    (hyper, lin, *_), = [chapter.chapter_curves("thick", "printed", points=11)]
    assert hyper["gamma"] == pytest.approx(BETAS[0] / 3) and lin["wall"] == "linear"
    np.testing.assert_allclose(hyper["dpbar"], chapter.printed_thick_pressure_drop(1.0, BETAS[0] / 3, hyper["qbar"], TB))
    hyper, lin, *_ = chapter.chapter_curves("thin", "consistent", points=11)
    assert hyper["gamma"] == pytest.approx(3 * BETAS[0])
    np.testing.assert_allclose(hyper["dpbar"], consistent(1.0, hyper["qbar"], gamma=3 * BETAS[0]), rtol=1e-14)
    np.testing.assert_allclose(lin["dpbar"], chapter.linear_pressure_drop(1.0, BETAS[0], lin["qbar"]), rtol=1e-12)


@pytest.mark.parametrize("n", INDICES + (2 / 3,))
@pytest.mark.parametrize("tb", [None, TB])
def test_chapter_linear_closed_forms_agree_with_tubefsi(n, tb):
    """Its linear formulas (eq. q-dp-linear-elastic, q-dp-linear-elastic-thick) are right."""
    for beta in BETAS:
        np.testing.assert_allclose(chapter.linear_pressure_drop(n, beta, QBAR, reduced_thickness=tb),
                                   linear(n, QBAR, beta, tb=tb), rtol=1e-12)


def test_reproduced_figures_put_the_flow_rate_up_and_define_their_symbols():
    """As the demo's flow curves: pressure drop across, flow rate up; the figure itself says what
    the bars, beta and gamma are (under the legend, which the layout keeps inside the figure)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = chapter.chapter_curves("thick", "consistent", points=11)
    par = dict(chapter.CHAPTER_PARAMETERS)
    fig = chapter._figure("thick", "consistent", curves, par, plt.get_cmap("viridis")([0.0, 0.4, 0.8]))
    try:
        for ax in fig.axes:
            assert "pressure drop" in ax.get_xlabel() and "flow rate" in ax.get_ylabel()
        first = fig.axes[0].get_lines()[0]
        np.testing.assert_array_equal(first.get_ydata(), curves[0]["qbar"])
        np.testing.assert_array_equal(first.get_xdata(), curves[0]["dpbar"])
        (legend,) = fig.legends
        title = legend.get_title().get_text()
        for symbol in (r"\Delta\bar p =", r"\bar q =", r"\beta =", r"\gamma =", r"\mathcal{P}_c", r"\bar t = t/a"):
            assert symbol in title, symbol
        assert len(legend.get_texts()) == 2 * len(par["betas"])
    finally:
        plt.close(fig)
