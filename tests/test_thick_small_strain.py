r"""The thick (Lamé) law of a material that gives only ``_dW``, from strain 1e-12 up.

A wall written as the wall-law tutorial teaches (``docs/tutorials/wall-law-in-a-script.md``) gives the
reduced strain-energy derivative :math:`D = \hat W'` alone, and :class:`~tubefsi.walls.ThickWall`
integrates :math:`g(s) = D(s)/(s^2 - 1)` from :math:`\lambda_o` to :math:`\lambda`. Near :math:`s = 1`
the ratio cancels: :math:`D(1 + h)` of a law written as :math:`\mu(s - s^{-3})` carries a rounding
of :math:`\epsilon_{mach}/(2h)` relative. The default ``_thick_integrand`` therefore forms :math:`g` there
from the slope, :math:`g(s) = \int_0^1 D'(1 + t(s-1))\,dt/(s+1)` (``_secant_slope`` in
``tubefsi/walls/hyperelastic.py``); before, it switched to the constant :math:`D''(1)/2` below
:math:`|s - 1| = 10^{-7}`, a first-order error: 1.6e-7 relative at strain 1e-7, 1.6e-12 at 1e-12.

The reference is :mod:`tubefsi.testing.reference.tube_laws` at 40 digits: the Lamé integral of the
material's own :math:`\hat W'/(s^2 - 1)` by ``mpmath.quad`` (neo-Hookean type: the simplified
:math:`\mu(s^2+1)/s^3`), the slope by Leibniz's rule.

The bounds, and why:

* **pressure**, ``PRESSURE_RTOL`` = 1e-13: with no ``_d2W`` the slope is ``scipy.differentiate``'s,
  good to 1e-14..1.4e-13 at a point (its floor: rounding against truncation); the secant is the
  integral of its Chebyshev interpolant from 12 fixed points within 1/256 of 1, a weighted mean of
  those errors (the integrand is then good to 5e-14 at worst, measured; the pressure to 6e-14 in
  1500 random cases). Beyond 1/256 the ratio itself is used, good to
  :math:`128\,\epsilon_{mach} = 2.8\times 10^{-14}` times its formula's conditioning (2 for
  Mooney–Rivlin written with :math:`c_2 < 0`; 1.2e-14 measured); the quadrature's tolerance is
  1e-14. With an exact ``_d2W`` the error is rounding (3e-15).
* **stiffness**: Leibniz's rule :math:`g(\lambda) - g(\lambda_o)\lambda/(b\lambda_o)` takes a difference,
  which multiplies the integrand's error by :math:`\kappa = (g(\lambda) + g(\lambda_o)\lambda/(b\lambda_o))/P'`
  (:math:`(b + 1)/(b - 1)` at small strain, whatever the law: 20 at :math:`\bar t = 0.05`):
  ``STIFFNESS_RTOL`` = 1e-13 times :math:`\kappa`, twice the worst single integrand value (not
  averaged as the pressure is). Measured, the slope is better than that: 6e-14 at worst below a
  strain of 0.01 even at :math:`\bar t = 0.01` (the two integrand values share the table's error).
* **strain** at a given pressure: the pressure's bound times the condition number
  :math:`P/(\varepsilon P')` (1 at small strain) plus the pressure's own rounding.

The thick-law tests fail on the code before this file (errors 1.6e-12 at strain 1e-12 to 1.9e-7 at
1e-7, in pressure, slope and strain), and so does the batch test (the plain neo-Hookean's pressure
at strain 1e-12 alone and in a batch differed in its last bit); the thin-law and broadcasting
tests guard the refactoring around them (they pass there too).
"""

from __future__ import annotations

import attrs
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mpmath import mp, mpf

from tubefsi import fields
from tubefsi.testing.profiles import scaled
from tubefsi.testing.reference import tube_laws as ref
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall
from tubefsi.walls import hyperelastic

DPS = 40
PRESSURE_RTOL = 1e-13
STIFFNESS_RTOL = 1e-13
#: the strains checked, 1e-12 ... 3
STRAINS = (1e-12, 1e-10, 1e-8, 1e-7, 1e-6, 1e-4, 1e-2, 0.5, 3.0)
THICKNESSES = (0.05, 0.3, 2.0)


# ---------------------------------------------------------------------------- the materials: _dW only
@attrs.frozen(kw_only=True)
class PlainNeoHookean(HyperelasticWall):
    """mu (s - s^-3), written as the difference (the cancellation the integrand must survive)."""

    shear_modulus: float = fields.positive(unit="Pa")

    def _dW(self, s):
        return self.shear_modulus * (s - s**-3)


@attrs.frozen(kw_only=True)
class PlainMooneyRivlin(HyperelasticWall):
    """2 c1 (s - s^-3) + 2 c2 (s - s^-3) (I1 = I2 in plane strain), each term a difference."""

    c1: float = fields.real(unit="Pa")
    c2: float = fields.real(unit="Pa")

    def _dW(self, s):
        return 2.0 * self.c1 * (s - s**-3) + 2.0 * self.c2 * (s - s**-3)


@attrs.frozen(kw_only=True)
class PlainGent(HyperelasticWall):
    """Gent, as in the module docstring of ``tubefsi.walls.hyperelastic``: stiffens, locks."""

    shear_modulus: float = fields.positive(unit="Pa")
    locking_parameter: float = fields.positive()

    def _dW(self, s):
        i1 = (s - 1 / s) ** 2
        return self.shear_modulus * (s - s**-3) / (1 - i1 / self.locking_parameter)

    def _locking_stretch(self):
        jm = self.locking_parameter
        return 0.5 * (jm**0.5 + (jm + 4) ** 0.5)


_C = (1 / 2, 1 / 20, 11 / 1050, 19 / 7000, 519 / 673750)


@attrs.frozen(kw_only=True)
class ArrudaBoyce(HyperelasticWall):
    """The tutorial's material, verbatim (section 1)."""

    shear_modulus: float = fields.positive(unit="Pa", doc="small-strain shear modulus mu")
    chain_stretch: float = fields.positive(doc="chain locking stretch lambda_m")

    def _dW(self, s):
        i1 = s * s + s**-2 + 1.0
        dW_dI1 = self.shear_modulus * sum(c * i * i1 ** (i - 1) / self.chain_stretch ** (2 * i - 2)
                                          for i, c in enumerate(_C, start=1))
        # 2 (s - s^-3), written so that it keeps its accuracy at s = 1 + 1e-9
        return 2.0 * dW_dI1 * (s - 1.0) * (s + 1.0) * (s * s + 1.0) / s**3


@attrs.frozen(kw_only=True)
class Fibre(HyperelasticWall):
    """The tutorial's guarded fibre law (section 6.2): an exact ``_d2W``, no ``_thick_integrand``."""

    shear_modulus: float = fields.positive(unit="Pa")
    k1: float = fields.positive(unit="Pa")
    k2: float = fields.positive()

    def _growth(self, s):
        x = (s - 1.0) * (s + 1.0)
        with np.errstate(over="ignore"):
            return np.exp(self.k2 * x * x)

    def _dW(self, s):
        x = (s - 1.0) * (s + 1.0)
        return self.shear_modulus * x * (s * s + 1.0) / s**3 + 2.0 * self.k1 * s * x * self._growth(s)

    def _d2W(self, s):
        x = (s - 1.0) * (s + 1.0)
        with np.errstate(over="ignore", invalid="ignore"):
            return (self.shear_modulus * (1.0 + 3.0 / s**4)
                    + 2.0 * self.k1 * self._growth(s) * (x + 2.0 * s * s + 4.0 * self.k2 * s * s * x * x))

    def _max_stretch(self, tb):
        return float(np.sqrt(1.0 + np.sqrt(600.0 / self.k2)))


def _theories(material):
    thick = attrs.frozen(kw_only=True)(type(f"Thick{material.__name__}", (ThickWall, material), {}))
    thin = attrs.frozen(kw_only=True)(type(f"Thin{material.__name__}", (ThinWall, material), {}))
    return thick, thin


THICK, THIN = {}, {}
for _m in (PlainNeoHookean, PlainMooneyRivlin, PlainGent, ArrudaBoyce, Fibre):
    THICK[_m], THIN[_m] = _theories(_m)

#: name -> (material class, parameters, reference material)
CASES = {
    "neo-hookean": (PlainNeoHookean, dict(shear_modulus=1e3), ref.NeoHookean(1e3)),
    "mooney-rivlin": (PlainMooneyRivlin, dict(c1=3e3, c2=-1e3), ref.MooneyRivlin(3e3, -1e3)),
    "gent-20": (PlainGent, dict(shear_modulus=1e3, locking_parameter=20.0), ref.Gent(1e3, 20.0)),
    "gent-2": (PlainGent, dict(shear_modulus=1e3, locking_parameter=2.0), ref.Gent(1e3, 2.0)),
    "arruda-boyce": (ArrudaBoyce, dict(shear_modulus=1e3, chain_stretch=2.5), ref.ArrudaBoyce(1e3, 2.5)),
    "fibre": (Fibre, dict(shear_modulus=1e3, k1=1e4, k2=20.0), ref.HoopFibre(1e3, 1e4, 20.0)),
}


def thick_wall(name):
    material, params, _ = CASES[name]
    return THICK[material](**params)


def reference(name, tb, kind="thick"):
    return ref.RefWall(kind, CASES[name][2], tb, closed_form=False)


def admissible(name, strain, wall, tb):
    return 1.0 + strain < 0.99 * float(wall.max_stretch(tb))


def leibniz_condition(wall_ref, lam):
    """kappa = (g(lam) + g(lam_o) lam/(b lam_o)) / P': how much the slope's difference amplifies."""
    lo = wall_ref.outer(lam)
    g = wall_ref.material.lame_integrand
    return float((g(lam) + g(lo) * lam / (wall_ref.b * lo)) / wall_ref.dP(lam))


def rel(got, want):
    return float(abs(mpf(float(got)) / want - 1))


def lame(law, x):
    """The thick law at the stretch ``x``, collapsing too: ``RefWall.P`` integrates from the smaller
    of ``lam_o``, ``lam`` up, which is the law only for ``lam >= 1``."""
    if x >= 1:
        return law.P(x)
    return -mp.quad(law.material.lame_integrand, [x, law.outer(x)])


def cases_at(name, tb):
    """The strains of ``STRAINS`` the wall admits at ``tb`` (gent-2 locks at stretch 1.93)."""
    wall = thick_wall(name)
    return wall, [e for e in STRAINS if admissible(name, e, wall, tb)]


# ---------------------------------------------------------------------------- the reference itself
def test_reference_arruda_boyce_matches_its_strain_energy():
    """The reference's hand-written plane-strain dW of the tutorial's material is d/ds W(1/s, s, 1)."""
    mat = ref.ArrudaBoyce(1e3, 2.5)
    with mp.workdps(DPS):
        for s in (mpf("1.001"), mpf("1.3"), mpf("2.5")):
            assert abs(mat.dW(s) / mp.diff(mat.W_hat, s) - 1) < mpf(10) ** -30


# ---------------------------------------------------------------------------- the thick law
@pytest.mark.parametrize("tb", THICKNESSES)
@pytest.mark.parametrize("name", list(CASES))
def test_thick_law_of_a_dW_only_material_matches_mpmath(name, tb):
    """Pressure and slope at strains 1e-12 ... 3 (one call each, a vector of stretches): within
    ``PRESSURE_RTOL`` and ``STIFFNESS_RTOL * kappa`` of the 40-digit Lamé integral."""
    wall, strains = cases_at(name, tb)
    lam = 1.0 + np.array(strains)                  # the exact strains are lam - 1 (Sterbenz)
    pressure, stiffness = wall.pressure(lam, tb), wall.stiffness(lam, tb)
    with mp.workdps(DPS):
        law = reference(name, tb)
        for i, e in enumerate(strains):
            x = mpf(float(lam[i]))
            assert rel(pressure[i], law.P(x)) <= PRESSURE_RTOL, (e, rel(pressure[i], law.P(x)))
            kappa = leibniz_condition(law, x)
            assert rel(stiffness[i], law.dP(x)) <= STIFFNESS_RTOL * kappa, (e, rel(stiffness[i], law.dP(x)), kappa)
            # a scalar call is the same law (the vector above is one batch)
            assert rel(wall.pressure(float(lam[i]), tb), law.P(x)) <= PRESSURE_RTOL


@pytest.mark.parametrize("name", list(CASES))
def test_strain_at_tiny_pressures_round_trips(name):
    """``wall.strain`` of the reference pressure at strains 1e-12 ... 3 (rounded to a double, 1.1e-16)
    gives the strain back within ``PRESSURE_RTOL`` times the condition number P/(e P') (1 at small
    strain; 2.6 for neo-Hookean at strain 3, whose law saturates) plus that rounding."""
    tb = 0.3
    _, strains = cases_at(name, tb)
    wall = thick_wall(name)
    lam = 1.0 + np.array(strains)
    with mp.workdps(DPS):
        law = reference(name, tb)
        exact = [mpf(float(x)) for x in lam]
        p = np.array([float(law.P(x)) for x in exact])
        back = wall.strain(p, tb)                       # one call: tiny and large pressures together
        for i, x in enumerate(exact):
            cond = float(law.P(x) / ((x - 1) * law.dP(x)))
            bound = (PRESSURE_RTOL + 2.3e-16) * cond
            assert rel(back[i], x - 1) <= bound, (strains[i], rel(back[i], x - 1), cond)
            assert rel(wall.strain(float(p[i]), tb), x - 1) <= bound


# ---------------------------------------------------------------------------- no cliff at a switch
@pytest.mark.parametrize("name", list(CASES))
def test_integrand_has_no_cliff_at_its_switches(name):
    """The integrand on both sides of each switch (the slope's reach, exact and numerical, and the
    old one at 1e-7) and at 1 itself: within 1e-13 of D(s)/(s^2 - 1) (5e-16 with an exact slope),
    so the two sides meet to that (measured: 5e-14 at worst, the numerical slope's own error)."""
    wall = thick_wall(name)
    exact = type(wall)._d2W is not HyperelasticWall._d2W      # the material's own slope
    bound = 5e-16 if exact else 1e-13
    points = [1.0]
    switches = (getattr(hyperelastic, "_SECANT_REACH", 0.125), getattr(hyperelastic, "_SECANT_REACH_NUMERICAL", 2**-8))
    for reach in (*switches, 1e-7, 1e-12):
        for sign in (1.0, -1.0):
            points += [1.0 + sign * reach * (1.0 - 2.0**-30), 1.0 + sign * reach * (1.0 + 2.0**-30)]
    s = np.array(points)
    g = wall._thick_integrand(s)
    with mp.workdps(DPS):
        g_ref = CASES[name][2].lame_integrand
        for si, gi in zip(s, g):
            x = mpf(float(si))
            want = g_ref(x) if x != 1 else g_ref(x + mpf(10) ** -35)      # the limit at s = 1
            assert rel(gi, want) <= bound, (si, rel(gi, want))


# ---------------------------------------------------------------------------- thin walls (the shared rule)
@pytest.mark.parametrize("convention", ["reference", "current"])
@pytest.mark.parametrize("name", list(CASES))
def test_thin_law_of_a_dW_only_material_matches_mpmath(name, convention):
    """The thin laws integrate the slope below a strain of 0.1 (by the shared ``_secant_slope`` with an
    exact one, ``fibre``; adaptively with a numerical one): within ``PRESSURE_RTOL`` of tb D(lam)
    (over lam) at every strain of ``STRAINS`` (a regression test: the code before passes it too)."""
    tb = 0.1
    material, params, mat = CASES[name]
    wall = THIN[material](**params, thickness_convention=convention)
    strains = [e for e in STRAINS if 1.0 + e < 0.99 * float(wall.max_stretch(tb))]
    lam = 1.0 + np.array(strains)
    pressure = wall.pressure(lam, tb)
    with mp.workdps(DPS):
        law = ref.RefWall("thin-" + convention, mat, tb, closed_form=False)
        for i, e in enumerate(strains):
            assert rel(pressure[i], law.P(mpf(float(lam[i])))) <= PRESSURE_RTOL, e


# ---------------------------------------------------------------------------- broadcasting
def test_array_parameters_broadcast_like_a_loop():
    """Moduli and locking parameters as arrays (3, 1) against strains (4,) and thicknesses: one
    call per quantity equals the scalar walls (the table is per parameter set, the rule per point)."""
    mu = np.array([[1e3], [2.5e3], [4e4]])
    jm = np.array([[20.0], [2.0], [5.0]])
    strains = np.array([1e-12, 3e-8, 2e-3, 0.4])
    tb = np.array([0.05, 0.3, 2.0, 0.7])
    wall = THICK[PlainGent](shear_modulus=mu, locking_parameter=jm)
    p, k = wall.pressure(1.0 + strains, tb), wall.stiffness(1.0 + strains, tb)
    e = wall.strain(p, tb)
    assert p.shape == k.shape == e.shape == (3, 4)
    for i in range(3):
        one = THICK[PlainGent](shear_modulus=float(mu[i, 0]), locking_parameter=float(jm[i, 0]))
        for j in range(4):
            assert p[i, j] == pytest.approx(one.pressure(1.0 + strains[j], tb[j]), rel=1e-14, abs=0)
            assert k[i, j] == pytest.approx(one.stiffness(1.0 + strains[j], tb[j]), rel=1e-14, abs=0)
            assert e[i, j] == pytest.approx((1.0 + strains[j]) - 1.0, rel=2e-13, abs=0)


@pytest.mark.parametrize("name", ["neo-hookean", "gent-2", "fibre"])
def test_a_points_bits_do_not_depend_on_its_batch(name):
    """The slope's rule (numerical: ``gent-2``, ``neo-hookean``; exact: ``fibre``) sums without BLAS,
    so a stretch gives the same bits alone, in a batch and in a reversed batch
    (``docs/verification.md``, "A point's answer does not depend on the batch it comes in")."""
    wall = thick_wall(name)
    tb = 0.3
    lam = 1.0 + np.array([1e-12, -3e-9, 2e-7, 1e-3, -2e-3, 0.004, 0.05, 0.2, 0.5])
    for quantity in (wall.pressure, wall.stiffness):
        batch = quantity(lam, tb)
        np.testing.assert_array_equal(quantity(lam[::-1], tb)[::-1], batch)
        np.testing.assert_array_equal([quantity(x, tb) for x in lam], batch)


# ---------------------------------------------------------------------------- properties
@settings(deadline=None, max_examples=scaled(40))
@given(name=st.sampled_from(sorted(CASES)), log_strain=st.floats(-12.0, -0.5), log_tb=st.floats(-2.0, 1.0),
       compress=st.booleans())
def test_thick_law_matches_mpmath_at_random_strains(name, log_strain, log_tb, compress):
    """Any strain in [1e-12, 0.3] (inflating) or [-0.3, -1e-12] (collapsing, down to the buckling
    stretch), any t/a in [0.01, 10]: pressure within ``PRESSURE_RTOL``, slope within
    ``STIFFNESS_RTOL * kappa``, strain back within ``PRESSURE_RTOL`` times its condition number."""
    tb = 10.0**log_tb
    wall = thick_wall(name)
    e = 10.0**log_strain
    lam = 1.0 + e
    if compress:
        lam = max(1.0 - e, float(wall.min_stretch(tb)) * (1 + 1e-9))
    lam = min(lam, 1.0 + 0.9 * (float(wall.max_stretch(tb)) - 1.0))
    if lam == 1.0:
        return
    with mp.workdps(DPS):
        law = reference(name, tb)
        x = mpf(lam)
        p = lame(law, x)
        assert rel(wall.pressure(lam, tb), p) <= PRESSURE_RTOL
        assert rel(wall.stiffness(lam, tb), law.dP(x)) <= STIFFNESS_RTOL * abs(leibniz_condition(law, x))
        cond = abs(float(p / ((x - 1) * law.dP(x))))
        assert rel(wall.strain(float(p), tb), x - 1) <= (PRESSURE_RTOL + 2.3e-16) * cond
