"""The hyperelastic walls at the edges of their valid range (issue 25, "the models' numerics at
extreme values"): a finite value that an independent reference (the law in mpmath, 40 digits)
gives, or, where the true value leaves the doubles, an InvalidParameterError naming the argument —
never NaN, inf, OverflowError, ZeroDivisionError, TypeError or SciPy's ValueError."""

import attrs
import numpy as np
import pytest
from mpmath import mp, mpf, sqrt

from tubefsi import InvalidParameterError, Tube, solve
from tubefsi.registry import walls
from tubefsi.rheology import Rheology
from tubefsi.testing.fuzz import bad_input_probes, run_probe
from tubefsi.testing.reference import rel_err as rel

MAX = float(np.finfo(float).max)
PLUGIN_WALLS = [n for n in walls if walls[n].__module__.startswith("tubefsi_hyperelastic")]


@pytest.fixture(autouse=True, scope="module")
def _digits():
    with mp.workdps(40):
        yield



def ogden_term_slope(c, a, s):
    """d/ds of c (s^(a-1) - s^(-a-1)), in mpmath."""
    return c * ((a - 1) * s ** (a - 2) + (a + 1) * s ** (-a - 2))


def test_ogden_stiffness_at_stretch_1e300():
    r"""Ogden (mu = 2e3, alpha = 3) at stretch 1e300: thin (reference thickness) :math:`\bar t D'(s)`,
    8e302; thick :math:`g(\lambda) - g(\lambda_o)\lambda/(b\lambda_o)`, :math:`g = D/(s^2 - 1)`,
    :math:`\lambda_o^2 = 1 + (\lambda^2 - 1)/b`, both in mpmath (both were NaN: s^a times s^-a-1)."""
    c, a, tb, lam = mpf(2) * 2000 / 3, mpf(3), mpf(0.3), mpf(1e300)
    thin = walls["thin-ogden"](moduli=(2e3,), exponents=(3.0,))
    assert rel(thin.stiffness(1e300, 0.3), tb * ogden_term_slope(c, a, lam)) < 1e-14
    b = (1 + tb) ** 2
    lam_o = sqrt(1 + (lam**2 - 1) / b)

    def g(s):
        return c * (s ** (a - 1) - s ** (-a - 1)) / (s**2 - 1)

    thick = walls["thick-ogden"](moduli=(2e3,), exponents=(3.0,))
    assert rel(thick.stiffness(1e300, 0.3), g(lam) - g(lam_o) * lam / (b * lam_o)) < 1e-13


def test_yeoh_stiffness_at_stretch_1e300():
    """A Yeoh wall with c3 > 0 has a slope ~ s^5 at 1e300: an InvalidParameterError naming the
    stretch (it was NaN). With c2 = c3 = 0 (thin, current thickness) it is the neo-Hookean
    4 mu t/a s^-5, mu = 2 c1: 2.4e-247 at 1e50 and an underflow to 0 at 1e300 (it was NaN: 0 * inf
    in the absent terms)."""
    with pytest.raises(InvalidParameterError, match="stretch"):
        walls["thin-yeoh"](c1=1e3, c2=50.0, c3=2.0).stiffness(1e300, 0.3)
    wall = walls["thin-yeoh"](c1=1e3, c2=0.0, c3=0.0, thickness_convention="current")
    assert rel(wall.stiffness(1e50, 0.3), 4 * mpf(2e3) * mpf(0.3) * mpf(1e50) ** -5) < 1e-14
    assert wall.stiffness(1e300, 0.3) == 0.0


@pytest.mark.parametrize("name", ["thick-demiray", "thin-gent", "thick-yeoh", "thin-ogden"])
@pytest.mark.parametrize("value", [1e300, 1e-300, 5e-324])
def test_extreme_axial_stretch_is_an_invalid_parameter(name, value):
    """axial_stretch = 1e300, 1e-300, 5e-324: an InvalidParameterError naming it with its range
    [1e-100, 1e100] (OverflowError and ZeroDivisionError from the invariants, before)."""
    example = dict(walls[name]._examples[0])
    with pytest.raises(InvalidParameterError, match=r"axial_stretch.*\[1e-100, 1e\+100\]"):
        walls[name](**{**example, "axial_stretch": value})


def test_ogden_axial_stretch_broadcasts():
    """An array of axial stretches (a TypeError before) gives, entry by entry, the walls of each
    value: pressure, stiffness and limits, and a solve of the three tubes at once."""
    values = [0.8, 1.0, 1.2]
    arrayed = walls["thick-ogden"](moduli=(2e3,), exponents=(3.0,), axial_stretch=values)
    each = [walls["thick-ogden"](moduli=(2e3,), exponents=(3.0,), axial_stretch=v) for v in values]
    np.testing.assert_array_equal(arrayed.pressure(1.2, 0.3), [w.pressure(1.2, 0.3) for w in each])
    np.testing.assert_array_equal(arrayed.stiffness(1.2, 0.3), [w.stiffness(1.2, 0.3) for w in each])
    fluid = SimpleThinning()
    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    drops = solve(fluid, arrayed, tube, flow_rate=1e-10).pressure_drop
    np.testing.assert_allclose(drops, [solve(fluid, w, tube, flow_rate=1e-10).pressure_drop for w in each],
                               rtol=1e-12)
    with pytest.raises(InvalidParameterError, match=r"axial_stretch.*entry \(1,\)"):
        walls["thin-ogden"](moduli=(2e3,), exponents=(700.0,), axial_stretch=[1.0, 1e-100])


def test_an_ogden_exponent_of_1e300_is_a_typed_error():
    """alpha = 1e300: the law leaves the doubles at any stretch above 1 (SciPy's root finder raised
    ValueError on the NaN slopes of the peak scan). The scan ends where the slope is not finite;
    the pressure there names the stretch; the small-strain modulus is still mu's (the Ogden law's,
    whatever alpha: the thick neo-Hookean's 1633.1)."""
    for name in ("thick-ogden", "thin-ogden"):
        wall = walls[name](moduli=(2e3,), exponents=(1e300,))
        with pytest.raises(InvalidParameterError, match="stretch"):
            wall.pressure(1.05, 0.3)
    thick = walls["thick-ogden"](moduli=(2e3,), exponents=(1e300,))
    reference = walls["thick-neo-hookean"](shear_modulus=2e3).small_strain_modulus(0.3)
    assert abs(thick.small_strain_modulus(0.3) - reference) <= 1e-12 * reference


def test_fung_maximum_stretch_at_the_smallest_stiffening():
    r"""b = 5e-324: the maximum stretch :math:`(x + \sqrt{x^2 + 4})/2`, :math:`x^2 = 600/b`, is 1.1e163,
    a double (600/b overflowed: it was inf, and the limit pressure NaN)."""
    wall = walls["thin-demiray"](shear_modulus=2e3, stiffening=5e-324)
    x = sqrt(600 / mpf(5e-324))
    assert rel(wall.max_stretch(0.3), (x + sqrt(x**2 + 4)) / 2) < 1e-14


def test_thick_fung_rises_past_stretch_1e149():
    """Thick Demiray with b = 1e-300 is neo-Hookean until b (I1 - 3) ~ 1, near stretch 1e150: its
    pressure must go on rising there (it fell to 0: (s^2 + 1)/s^3 had s^3 overflow)."""
    wall = walls["thick-demiray"](shear_modulus=2e3, stiffening=1e-300)
    p = [wall.pressure(lam, 0.3) for lam in (1e100, 1e149, 1e150)]
    assert 0 < p[0] <= p[1] < p[2]


@pytest.mark.parametrize("name", ["thick-demiray", "thick-gent", "thick-yeoh", "thick-ogden"])
def test_thick_small_strain_modulus_at_the_thinnest_wall(name):
    """At t/a = 1e-100 every isotropic thick wall has the small-strain modulus of the thick
    neo-Hookean wall of its shear modulus, 4 mu t/a to first order (it was 0: b - 1 rounded to 0)."""
    wall = walls[name](**walls[name]._examples[0])
    mu = wall._ring_modulus(np.ones(1))[0]           # D'(1)/4: the material's small-strain shear modulus
    assert rel(wall.small_strain_modulus(1e-100), 4 * mpf(mu) * mpf(1e-100)) < 1e-13


def test_a_pressure_past_the_law_is_a_typed_error_without_an_infinite_limit():
    """Thin Gent with mu = 1e308 (valid): its pressure overflows before the lock. stretch(1e300)
    names the pressure (it was a NoSteadyStateError with an infinite limit)."""
    wall = walls["thin-gent"](shear_modulus=MAX, locking_parameter=10.0)
    with pytest.raises(InvalidParameterError, match="pressure"):
        wall.strain(1e300, 0.3)


@attrs.frozen
class SimpleThinning(Rheology):
    """A shear-thinning, stress-natural fluid (no closed form: the generic paths), Newtonian with
    eta_inf at high shear; written here so that this suite needs no rheology plugin."""

    eta0: float = 0.056
    eta_inf: float = 0.00345

    def _stress(self, rate):
        return rate * (self.eta_inf + (self.eta0 - self.eta_inf) / (1.0 + np.sqrt(rate)))


@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # (the couplers' intermediate overflows)
@pytest.mark.parametrize("name", ["thick-demiray", "thin-demiray", "thick-hgo", "thin-hgo"])
def test_stiffening_walls_at_a_drop_of_1e260(name):
    r"""Demiray and HGO tubes at a drop of 1e260 Pa with a shear-thinning fluid: the centreline velocity
    was inf. At wall stresses of ~1e257 Pa the fluid is Newtonian with eta_inf, so
    :math:`v(0, z) = G(z)R(z)^2/(4\eta_\infty)` with the solution's own G and R (to 1e-9)."""
    wall = walls[name](**walls[name]._examples[0])
    sol = solve(SimpleThinning(), wall, Tube(radius=1e-4, thickness=3e-5, length=1e-2), pressure_drop=1e260)
    z = np.array([0.0, 0.5e-2, 1e-2])
    v = sol.velocity(0.0, z)
    g, radius = sol.pressure_gradient(z), sol.radius(z)
    reference = g * radius**2 / (4 * 0.00345)
    assert np.all(np.isfinite(v)) and np.all(np.diff(sol.pressure(z)) < 0)
    np.testing.assert_allclose(v, reference, rtol=1e-9)


def test_the_extremes_family_of_the_plugin_walls_has_no_breach():
    """The fuzz family "extremes" over this plugin's walls: every outcome typed or a checked value."""
    probes = bad_input_probes([], PLUGIN_WALLS, [], core=False, families=["extremes"])
    assert len(probes) > 300
    breaches = [o for o in (run_probe(p) for p in probes) if o.breach]
    assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)
