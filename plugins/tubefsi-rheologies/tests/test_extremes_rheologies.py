"""The plugin's fluids at the edges of their valid range (issue 25, "the models' numerics at
extreme values"): a finite value that an independent reference (the closed form in mpmath, 40
digits) gives, or, where the true value leaves the doubles, an InvalidParameterError naming the
argument — never NaN, inf or a Python exception."""

import numpy as np
import pytest
from mpmath import mp, mpf, sqrt

from tubefsi import InvalidParameterError, Tube, solve
from tubefsi.registry import rheologies, walls
from tubefsi.testing.fuzz import bad_input_probes, run_probe
from tubefsi.testing.reference import rel_err as rel

MAX = float(np.finfo(float).max)
PLUGIN_FLUIDS = [n for n in rheologies if rheologies[n].__module__.startswith("tubefsi_rheologies")]


@pytest.fixture(autouse=True, scope="module")
def _digits():
    with mp.workdps(40):
        yield



def casson_velocity(r, radius, g, ty, mu):
    """The Casson profile, (2/(k mu)) [z^4/4 + c z^3/3] from z(max(r, r_p)) to z(R), z = sqrt(k rho) - c."""
    k, c = mpf(g) / 2, sqrt(mpf(ty))
    rr = max(mpf(r), min(mpf(radius), mpf(ty) / k))

    def prim(rho):
        z = sqrt(k * rho) - c
        return z**4 / 4 + c * z**3 / 3

    return 2 * (prim(mpf(radius)) - prim(rr)) / (k * mpf(mu))


def test_casson_without_yield_stress_is_newtonian():
    """The issue's scene: Casson with yield_stress = 0 (allowed) gave a NaN centreline velocity at
    every drop (0/0 in the square root's excess). It is the Newtonian fluid of the plastic
    viscosity: the same flow rate and profile (the Newtonian solve), and directly
    Hagen–Poiseuille, G (R^2 - r^2)/(4 mu)."""
    fluid = rheologies["casson"](yield_stress=0.0, plastic_viscosity=0.004)
    newtonian = rheologies["newtonian"](viscosity=0.004)
    wall = walls["thin-linear"](youngs_modulus=6e5, poisson_ratio=0.3)
    tube = Tube(radius=6.5e-5, thickness=2.4e-6, length=0.026)
    sol, ref = solve(fluid, wall, tube, pressure_drop=100), solve(newtonian, wall, tube, pressure_drop=100)
    np.testing.assert_allclose(sol.velocity([0, 3e-5], 0.01), ref.velocity([0, 3e-5], 0.01), rtol=1e-12)
    v = fluid.velocity(np.array([0.0, 3e-5]), 6e-5, 1e6)
    for r, got in zip((0, 3e-5), v):
        assert rel(got, mpf(1e6) * (mpf(6e-5) ** 2 - mpf(r) ** 2) / (4 * mpf(0.004))) < 1e-14


def test_casson_at_a_huge_gradient():
    """Casson (0.005 Pa, 0.0035 Pa s) at G = 1e300: the velocity (7e293 on the axis; z^4 overflowed,
    it was inf) and the flow rate (the Rabinowitsch–Mooney sum over tau_w^3 was inf/inf) against the
    closed forms in mpmath; at plastic viscosity 1e300 the velocity is 7e-10 (it was NaN)."""
    fluid = rheologies["casson"](yield_stress=0.005, plastic_viscosity=0.0035)
    for r in (0.0, 5e-5):
        assert rel(fluid.velocity(r, 1e-4, 1e300), casson_velocity(r, 1e-4, 1e300, 0.005, 0.0035)) < 1e-13
    tau_w, ty, mu = mpf(1e300) * mpf(1e-4) / 2, mpf(0.005), mpf(0.0035)
    x = ty / tau_w
    gamma = tau_w / mu * (1 - 16 * sqrt(x) / 7 + 4 * x / 3 - x**4 / 21)
    assert rel(fluid.flow_rate(1e-4, 1e300), mp.pi * mpf(1e-4) ** 3 * gamma / 4) < 1e-13
    stiff = rheologies["casson"](yield_stress=0.005, plastic_viscosity=1e300)
    assert rel(stiff.velocity(0.0, 1e-4, 1e300), casson_velocity(0, 1e-4, 1e300, 0.005, 1e300)) < 1e-13


def test_herschel_bulkley_and_bingham_at_a_huge_wall_stress():
    r"""The closed flow functions at a wall stress of 1e200 Pa (their d^2 bracket over tau_w^3 was
    inf/inf or 0), and the Herschel–Bulkley velocity at index 1 (the Bingham profile,
    :math:`(R - r_p)(G(R + r_p)/4 - \tau_y)/K` on the axis), against mpmath."""
    tau_w, ty, k = mpf(1e200), mpf(2), mpf(0.5)
    x = ty / tau_w
    bingham = tau_w / k * (1 - 4 * x / 3 + x**4 / 3)
    g = 2e200 / 1e-4
    for fluid in (rheologies["bingham"](yield_stress=2.0, plastic_viscosity=0.5),
                  rheologies["herschel-bulkley"](yield_stress=2.0, consistency=0.5, index=1.0)):
        assert rel(fluid.flow_rate(1e-4, g), mp.pi * mpf(1e-4) ** 3 * bingham / 4) < 1e-13
    hb = rheologies["herschel-bulkley"](yield_stress=2.0, consistency=0.5, index=1.0)
    r_p = 2 * ty / mpf(g)
    axis = (mpf(1e-4) - r_p) * (mpf(g) * (mpf(1e-4) + r_p) / 4 - ty) / k
    assert rel(hb.velocity(0.0, 1e-4, g), axis) < 1e-13


def test_ellis_profiles_far_out():
    r"""Ellis, :math:`v = \frac{G}{4\eta_0}(R^2 - r^2) + \frac{(G/2)^\alpha}{(\alpha+1)\eta_0\tau_{1/2}^{\alpha-1}}
    (R^{\alpha+1} - r^{\alpha+1})` in mpmath: at R = 1e300, G = 1e-300 (R^(a+1) overflowed: NaN) and
    with a half stress of 1e300 Pa (its power raised OverflowError)."""
    def reference(r, radius, g, eta0, half, a):
        r, radius, g, eta0, half, a = map(mpf, (r, radius, g, eta0, half, a))
        return g / (4 * eta0) * (radius**2 - r**2) + (g / 2) ** a / ((a + 1) * eta0 * half ** (a - 1)) * (
            radius ** (a + 1) - r ** (a + 1))

    for params, radius, g in (((0.1, 1.0, 2.5), 1e300, 1e-300), ((0.1, 1e300, 2.5), 1e-4, 1e3)):
        fluid = rheologies["ellis"](zero_shear_viscosity=params[0], half_stress=params[1], exponent=params[2])
        for r in (0.0, 0.5 * radius):
            assert rel(fluid.velocity(r, radius, g), reference(r, radius, g, *params)) < 1e-13
        assert fluid.velocity(radius, radius, g) == 0.0


def test_carreau_yasuda_with_a_huge_transition_parameter():
    r"""a = 1.8e308: :math:`[1 + x^a]^{(n-1)/a} \to \max(x, 1)^{n-1}`; the stress is that limit's (the
    exponent (n-1)/a times ln(1 + x^a) = inf gave exp(-inf): the infinite-shear law alone)."""
    fluid = rheologies["carreau-yasuda"](zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345,
                                         relaxation_time=3.313, index=0.3568, transition=MAX)
    x = mpf(3.313)
    reference = mpf(0.00345) + (mpf(0.056) - mpf(0.00345)) * x ** (mpf(0.3568) - 1)
    assert rel(fluid.stress(1.0), reference) < 1e-14
    assert abs(fluid.shear_rate(fluid.stress(1.0)) - 1.0) < 1e-12


@pytest.mark.parametrize("exponent", [1e300, MAX])
def test_cross_with_a_huge_exponent_is_rejected(exponent):
    """Cross with exponent m >= 1 needs eta_inf > (eta_0 - eta_inf)(m - 1)^2/(4m) (an increasing
    stress); at m = 1e300 that square raised OverflowError, at m = 1.8e308 4m overflowed and the
    check passed a law whose stress drops 16-fold at the shear rate 1/lambda."""
    with pytest.raises(InvalidParameterError, match="exponent"):
        rheologies["cross"](zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=1.007,
                            exponent=exponent)


def test_a_fluid_of_the_largest_viscosity_does_not_flow_backwards():
    """Carreau with eta_0 = 1.8e308: its flow under 1e3 Pa/m is a subnormal 0 or more and its
    velocity never negative (the by-parts integrand 1 - (tau/tau_w)^3 went a rounding below 0:
    -1.5e-316 m^3/s)."""
    fluid = rheologies["carreau"](zero_shear_viscosity=MAX, infinite_shear_viscosity=0.00345, relaxation_time=3.313,
                                  index=0.3568)
    assert fluid.flow_rate(1e-4, 1e3) >= 0.0
    assert np.all(fluid.velocity(np.array([0.0, 5e-5, 1e-4]), 1e-4, 1e3) >= 0.0)


def test_a_subnormal_yield_stress_builds_its_flow_table():
    """Bingham with yield stress 5e-324 (valid): its flow table's floor ln(tau_y eps/8) underflowed
    to ln 0 (ValueError: math domain error); the pressure gradient inverts the flow rate."""
    fluid = rheologies["bingham"](yield_stress=5e-324, plastic_viscosity=0.0035)
    q = fluid.flow_rate(1e-4, 1e3)
    assert abs(fluid.pressure_gradient(q, 1e-4) - 1e3) <= 1e-12 * 1e3


@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # (the couplers' intermediate overflows)
def test_yield_stress_fluids_beyond_the_doubles_are_an_error_not_zero_flow():
    """Bingham, Casson and Herschel–Bulkley through a thin linear tube at a drop of 1e260 Pa (the
    tube's radius grows to 4e252 m): the flow leaves the doubles, a typed error (it returned
    q = 0, 'no flow')."""
    wall = walls["thin-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    for name in ("bingham", "casson", "herschel-bulkley"):
        fluid = rheologies[name](**rheologies[name]._examples[0])
        with pytest.raises(InvalidParameterError):
            solve(fluid, wall, tube, pressure_drop=1e260)


def test_the_extremes_family_of_the_plugin_fluids_has_no_breach():
    """The fuzz family "extremes" over this plugin's fluids (their methods at extreme arguments and
    each field at extreme valid values, and their solves at a drop of 1e260 Pa)."""
    probes = bad_input_probes(PLUGIN_FLUIDS, [], [], core=False, families=["extremes"])
    assert len(probes) > 300
    breaches = [o for o in (run_probe(p) for p in probes) if o.breach]
    assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)
