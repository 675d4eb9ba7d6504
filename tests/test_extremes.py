"""The core models at the edges of their valid range (issue 25, "the models' numerics at extreme
values"): each call gives the finite value an independent reference (a closed form in mpmath, 40
digits, or an asymptote) says, or, where the true value leaves the doubles, an
InvalidParameterError naming the argument; never a NaN, an inf or a Python/NumPy exception.
The plugins' models have their own files (``plugins/*/tests/test_extremes_*.py``); the fuzz family
"extremes" (:mod:`tubefsi.testing.fuzz._extremes`) runs the same contract over every registered model.
"""

import numpy as np
import pytest
from mpmath import mp, mpf

from tubefsi import InvalidParameterError, Tube, registry, solve
from tubefsi.rheology import Rheology
from tubefsi.testing.fuzz import bad_input_probes, run_probe
from tubefsi.walls.hyperelastic import AXIAL_STRETCH_RANGE
from tubefsi.testing.reference import rel_err as rel

W, R = registry.walls, registry.rheologies
MAX = float(np.finfo(float).max)


@pytest.fixture(autouse=True, scope="module")
def _digits():
    with mp.workdps(40):
        yield



# ------------------------------------------------------------------ walls: stiffness at stretch 1e300
@pytest.mark.parametrize("name, kwargs", [("thick-neo-hookean", {"shear_modulus": 2e3}),
                                          ("thick-mooney-rivlin", {"c1": 1.5e3, "c2": -0.5e3})])
def test_thick_stiffness_far_out_is_its_closed_form(name, kwargs):
    r"""Thick neo-Hookean (and Mooney–Rivlin, the same law) slope
    :math:`\mu d(\lambda^2(d+2)+d)/(\lambda^3(\lambda^2+d)^2)` (``neo_hookean`` module docstring) in
    mpmath: 3.7e-297 at 1e60 (the polynomial form was inf/inf = NaN past 1e77), an underflow to 0
    at 1e300 (was NaN); and the small-strain modulus at t/a = 1e100, 2 mu d/(1 + d) -> 2 mu
    (was NaN: d^2 overflowed)."""
    wall = W[name](**kwargs)
    mu, tb = mpf(2e3), mpf(0.3)
    d = tb * (2 + tb)
    for lam in (1e40, 1e60):
        lam_m = mpf(lam)
        reference = mu * d * (lam_m**2 * (d + 2) + d) / (lam_m**3 * (lam_m**2 + d) ** 2)
        assert rel(wall.stiffness(lam, 0.3), reference) < 1e-14
    assert wall.stiffness(1e100, 0.3) == wall.stiffness(1e300, 0.3) == 0.0      # 3.7e-497: below the doubles
    d = mpf(1e100) * (2 + mpf(1e100))
    assert rel(wall.small_strain_modulus(1e100), mu * d * (2 * d + 2) / (1 + d) ** 2) < 1e-14


def test_thick_small_strain_modulus_at_the_thinnest_wall():
    r"""At t/a = 1e-100 the thick neo-Hookean small-strain modulus is :math:`4\mu\,t/a` to first
    order, 8e-97 for mu = 2e3: the closed form the plugins' thick walls are checked against at the
    same thickness (``test_extremes_hyperelastic.py``, where the generic thick slope gave 0)."""
    wall = W["thick-neo-hookean"](shear_modulus=2e3)
    assert rel(wall.small_strain_modulus(1e-100), 4 * mpf(2e3) * mpf(1e-100)) < 1e-14


def test_stiffness_beyond_the_doubles_is_a_typed_error():
    """A stiffness that truly overflows (Shapiro's n1 = 10 slope ~ s^19 at 1e300) names the stretch;
    the public methods neither return inf nor warn."""
    with pytest.raises(InvalidParameterError, match="stretch.*finite double"):
        W["shapiro"](tube_stiffness=50.0).stiffness(1e300, 0.3)


# ------------------------------------------------------------------ axial stretch
@pytest.mark.parametrize("name", ["thick-neo-hookean", "thin-mooney-rivlin", "thick-hgo"])
@pytest.mark.parametrize("value", [1e300, 1e-300, 5e-324, 1e101, 1e-101])
def test_axial_stretch_outside_its_range_names_it(name, value):
    """axial_stretch lies in [1e-100, 1e100] (AXIAL_STRETCH_RANGE: the invariants of the installed
    rest state, ~lz^2 and ~2/lz^2, stay doubles there); beyond, an InvalidParameterError naming it
    and its range (Demiray, Gent, Yeoh and Ogden raised OverflowError or ZeroDivisionError)."""
    example = dict(W[name]._examples[0])
    with pytest.raises(InvalidParameterError, match=r"axial_stretch.*1e-100, 1e\+100"):
        W[name](**{**example, "axial_stretch": value})


def test_axial_stretch_range_ends_are_admissible():
    """At the ends of the range the neo-Hookean law of the installed tube is mu/lz's (a closed form)."""
    low, high = AXIAL_STRETCH_RANGE
    for lz in (low, high):
        wall = W["thin-neo-hookean"](shear_modulus=2e3, axial_stretch=lz)
        reference = mpf(2e3) / mpf(lz) * mpf(0.3) * (mpf(1.5) - mpf(1.5) ** -3)
        assert rel(wall.pressure(1.5, 0.3), reference) < 1e-14


def test_an_installed_modulus_beyond_the_doubles_names_the_axial_stretch():
    """mu = 1e308 at lz = 1e-100: the installed modulus mu/lz overflows (its pressures would all be inf)."""
    with pytest.raises(InvalidParameterError, match="axial_stretch"):
        W["thick-neo-hookean"](shear_modulus=1e308, axial_stretch=1e-100)


# ------------------------------------------------------------------ rheologies
def test_newtonian_velocity_of_a_huge_tube_is_hagen_poiseuille():
    r""":math:`v = G(R^2 - r^2)/(4\mu)` at R = 1e300, G = 1e-300 (2.5e302 on the axis): finite
    although R^2 is not (it was [inf, nan, nan])."""
    fluid = R["newtonian"](viscosity=1e-3)
    big_r, g = mpf(1e300), mpf(1e-300)
    v = fluid.velocity(np.array([0.0, 0.5e300, 1e300]), 1e300, 1e-300)
    for r, got in zip((0, big_r / 2, big_r), v):
        reference = g * (big_r**2 - r**2) / (4 * mpf(1e-3))
        assert (got == 0.0 == reference) or rel(got, reference) < 1e-14


def test_power_law_velocity_is_its_closed_form_far_out():
    r""":math:`v = \frac{n}{n+1}(G/2m)^{1/n}(R^{1+1/n} - r^{1+1/n})` in mpmath, at a wall stress of
    5e-297 Pa and a radius of 1e300 m (R^k overflowed)."""
    fluid = R["power-law"](consistency=0.017, index=0.7)
    n, m, big_r, g = mpf(0.7), mpf(0.017), mpf(1e300), mpf(1e-300)
    k = 1 + 1 / n
    v = fluid.velocity(np.array([0.0, 0.5e300]), 1e300, 1e-300)
    for r, got in zip((0, big_r / 2), v):
        reference = n / (n + 1) * (g / (2 * m)) ** (1 / n) * (big_r**k - mpf(r) ** k)
        assert rel(got, reference) < 1e-13


def test_a_law_beyond_the_doubles_names_its_argument():
    """A power law of index 0.7 at a stress of 1e300 Pa has a shear rate of ~1e430/s: an
    InvalidParameterError naming the stress (it returned inf); the velocity at G = 1e300 likewise
    names the pressure gradient, and a Newtonian stress of 10 Pa s times the largest double its
    shear rate."""
    fluid = R["power-law"](consistency=0.017, index=0.7)
    with pytest.raises(InvalidParameterError, match="stress"):
        fluid.shear_rate(1e300)
    with pytest.raises(InvalidParameterError, match="pressure_gradient"):
        fluid.velocity(0.0, 1e-4, 1e300)
    with pytest.raises(InvalidParameterError, match="shear_rate"):
        R["newtonian"](viscosity=10.0).stress(MAX)


def test_generic_velocity_at_a_huge_gradient_is_the_newtonian_limit():
    r"""A stress-natural law without a closed velocity (a Carreau-type fluid written here) at
    G = 1e300, R = 1e-4: the wall stress 5e295 Pa is all in the infinite-shear viscosity, so
    :math:`v = G(R^2 - r^2)/(4\eta_\infty)` to 1e-12 (the quadrature's product of a shear rate and a
    stress overflowed: it was inf)."""
    import attrs

    @attrs.frozen
    class Thinning(Rheology):
        eta0: float = 0.056
        eta_inf: float = 0.00345

        def _stress(self, rate):
            return rate * (self.eta_inf + (self.eta0 - self.eta_inf) / (1.0 + np.sqrt(rate)))

    fluid = Thinning()
    v = fluid.velocity(np.array([0.0, 5e-5]), 1e-4, 1e300)
    for r, got in zip((0.0, 5e-5), v):
        reference = mpf(1e300) * (mpf(1e-4) ** 2 - mpf(r) ** 2) / (4 * mpf(0.00345))
        assert rel(got, reference) < 1e-12


def test_a_generic_flow_function_at_a_huge_wall_stress():
    r"""The rate-natural Rabinowitsch–Mooney integral of a yield-stress law (Bingham written as a
    shear rate only) at a wall stress of 1e200 Pa: the Buckingham–Reiner closed form, about
    :math:`\tau_w/\mu_p` (the integrand's tau^2 over tau_w^3 overflowed: the flow rate was 0)."""
    import attrs

    @attrs.frozen
    class RateBingham(Rheology):
        yield_stress: float = 2.0
        mu: float = 0.5

        def _shear_rate(self, tau):
            return np.maximum(tau - self.yield_stress, 0.0) / self.mu

    fluid = RateBingham()
    tau_w, ty, mu = mpf(1e200), mpf(2), mpf(0.5)
    x = ty / tau_w
    gamma = tau_w / mu * (1 - 4 * x / 3 + x**4 / 3)
    q = fluid.flow_rate(1e-4, 2e204)            # tau_w = G R / 2
    assert rel(q, mp.pi * mpf(1e-4) ** 3 * gamma / 4) < 1e-12


# ------------------------------------------------------------------ solves at a huge pressure drop
@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # (the couplers' intermediate overflows)
def test_a_flow_beyond_the_doubles_is_an_error_not_zero_flow():
    """A yield-stress fluid through a thin linear tube at a drop of 1e200 Pa: the tube's radius
    grows to 4e188 m and the flow beyond the doubles: a typed error (it returned q = 0, 'no flow',
    because the rigid bound's flow rate was inf/inf = NaN). The fluid is the rate-natural Bingham
    law above (a core test needs no plugin)."""
    import attrs

    @attrs.frozen
    class RateBingham(Rheology):
        yield_stress: float = 0.005
        mu: float = 0.0035

        def _shear_rate(self, tau):
            return np.maximum(tau - self.yield_stress, 0.0) / self.mu

    wall = W["thin-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
    with pytest.raises(InvalidParameterError):
        solve(RateBingham(), wall, Tube(radius=1e-4, thickness=3e-5, length=1e-2), pressure_drop=1e200)


# ------------------------------------------------------------------ the fuzz family
def test_the_extremes_family_of_the_core_models_has_no_breach():
    """The fuzz family "extremes" over the built-in walls and fluids (the plugins' run in their own
    suites and in ``make fuzz``): every outcome typed or a checked value."""
    walls = [n for n in W if W[n].__module__.startswith("tubefsi.")]
    fluids = [n for n in R if R[n].__module__.startswith("tubefsi.")]
    probes = bad_input_probes(fluids, walls, [], core=False, families=["extremes"])
    assert len(probes) > 300
    breaches = [o for o in (run_probe(p) for p in probes) if o.breach]
    assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)
