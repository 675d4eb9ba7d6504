"""The generic (non-separable) rheology path: error-controlled Rabinowitsch–Mooney quadrature, the
flow law's inverse tabulated on fixed panels (``tubefsi.rheology.flow_law``), bounded work at
extreme loads, typed errors, and what the fixed panels promise: an answer independent of the
table's history, a table per parameter set, and threads that share a fluid.

Everything goes through the public API (``flow_rate``, ``pressure_gradient``, ``velocity``,
``tubefsi.solve``, ``tubefsi.cache_clear``); the quadrature's own tests import it from the
numerics layer. References are independent of the library: the Rabinowitsch–Mooney integral
:math:`\\Gamma = (4/\\tau_w^3)\\int_0^{\\tau_w}\\tau^2\\dot\\gamma\\,d\\tau` of a piecewise law is
elementary (``docs/theory.md``, section "The flow law of a generalized Newtonian fluid"), and
mpmath integrates the smooth laws. Work is bounded by counting flow-function evaluations and table
panels (``flow_table(fluid).evaluations``, ``.panel_count``: an internal of the rheology layer,
read only because no public call counts work), not by wall-clock time.

The table's promise (``docs/theory.md``; the ``flow_law`` module docstring) is a relative error
``TOL = 1e-14`` of :math:`G`. A comparison of :math:`\\tau_w = GR/2` against a reference adds the
rounding of the two logarithms the table works in, :math:`\\ln\\Gamma` and
:math:`s = \\ln(\\tau_w - \\tau_y)`: :math:`4\\epsilon(|\\ln\\Gamma| + |s|)`.
"""

from __future__ import annotations

import concurrent.futures
import math
import random
import threading
import tracemalloc
import warnings

import attrs
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mpmath import mp, mpf

import tubefsi
from tubefsi import AccuracyWarning, InvalidParameterError
from tubefsi.errors import TubefsiError
from tubefsi.numerics.quadrature import unit_integral
from tubefsi.testing.profiles import scaled
from tubefsi.rheology import Rheology
from tubefsi.rheology.flow_law import flow_table

EPS = np.finfo(float).eps
#: The table's tolerance: the relative error of G it promises.
TOL = 1e-14
#: Flow-function evaluations of one smooth panel: its two ends, then the degree-16 fit of the
#: forward map on 17 Chebyshev nodes and 4 check points (accepted at the first try).
SMOOTH_PANEL = 2 + 17 + 4
#: The most one panel can cost beyond that: a fit attempt that bisects up to its cap of 64
#: sub-panels evaluates at most 127 of them (a binary tree with 64 leaves), 21 points each.
KINKED_PANEL = 127 * 21 - 21


# ---------------------------------------------------------------- laws written afresh
@attrs.frozen
class NewtonianBelow(Rheology):
    """Rate-natural, kinked: Newtonian (eta0) below tau_c, a power law above, continuous at tau_c."""

    eta0: float = 0.05
    index: float = 0.5
    tau_c: float = 2.0

    @property
    def m(self):
        return self.tau_c / (self.tau_c / self.eta0) ** self.index

    def _shear_rate(self, tau):
        return np.where(tau <= self.tau_c, tau / self.eta0, (np.maximum(tau, self.tau_c) / self.m) ** (1 / self.index))

    def exact_rate(self, tw):
        """4 q / (pi R^3), in closed form."""
        tc, e0, n, m = self.tau_c, self.eta0, self.index, self.m
        k = 3 + 1 / n
        integral = np.where(tw <= tc, tw**4 / (4 * e0),
                            tc**4 / (4 * e0) + m ** (-1 / n) * (np.maximum(tw, tc) ** k - tc**k) / k)
        return 4 * integral / tw**3

    def exact_velocity(self, r, radius, g):
        """(2/G) int_{tau(r)}^{tau_w} rate(tau) dtau, in closed form."""
        tc, e0, n, m = self.tau_c, self.eta0, self.index, self.m

        def primitive(t):       # int_0^t rate
            j = 1 + 1 / n
            return np.where(t <= tc, t * t / (2 * e0),
                            tc * tc / (2 * e0) + m ** (-1 / n) * (np.maximum(t, tc) ** j - tc**j) / j)

        return 2 / g * (primitive(0.5 * g * radius) - primitive(0.5 * g * r))


@attrs.frozen
class KinkedPowerLaw(Rheology):
    """Stress-natural, kinked: tau = m g^n below g_c, Newtonian tau = m g_c^(n-1) g above."""

    m: float = 0.02
    index: float = 0.6
    g_c: float = 50.0

    def _stress(self, g):
        m, n, gc = self.m, self.index, self.g_c
        return np.where(g <= gc, m * np.minimum(g, gc) ** n, m * gc ** (n - 1) * g)

    def exact_rate(self, tw):
        m, n, gc = self.m, self.index, self.g_c
        tc, eta = m * gc**n, m * gc ** (n - 1)
        k = 3 + 1 / n
        below = m ** (-1 / n) * np.minimum(tw, tc) ** k / k
        above = np.where(tw > tc, (tw**4 - tc**4) / (4 * eta), 0.0)
        return 4 * (below + above) / tw**3


def _carreau_stress(law, g):
    log_x = np.log(law.lam * g)
    return g * law.eta0 * np.exp(0.5 * (law.index - 1.0) * np.logaddexp(0.0, 2.0 * log_x))


@attrs.frozen
class CarreauLike(Rheology):
    """Stress-natural Carreau law, written afresh: eta = eta0 (1 + (lam g)^2)^((n-1)/2)."""

    eta0: float = 0.056
    lam: float = 3.313
    index: float = 0.3568

    def _stress(self, g):
        return _carreau_stress(self, g)


@attrs.define
class MutableCarreau(Rheology):
    """The same law in a class that is not frozen: its parameters may change in place."""

    eta0: float = 0.056
    lam: float = 3.313
    index: float = 0.3568

    def _stress(self, g):
        return _carreau_stress(self, g)


@attrs.frozen
class RateOnlyHerschelBulkley(Rheology):
    """Rate-natural yield-stress law without closed forms: rate = ((tau - tau_y)/K)^(1/n)."""

    yield_stress: float = 2.0
    consistency: float = 0.3
    index: float = 0.45

    def _shear_rate(self, tau):
        return (np.maximum(tau - self.yield_stress, 0.0) / self.consistency) ** (1 / self.index)

    def exact_rate(self, tw, excess):
        m, ty, d = 1 / self.index, self.yield_stress, excess
        bracket = d * d / (m + 3) + 2 * ty * d / (m + 2) + ty * ty / (m + 1)
        return 4 * (d / self.consistency) ** m * d * bracket / tw**3


@attrs.frozen
class StressOnlyHerschelBulkley(Rheology):
    """Stress-natural yield-stress law without closed forms: tau = tau_y + K rate^n."""

    yield_stress: float = 2.0
    consistency: float = 0.3
    index: float = 0.45

    def _stress(self, g):
        return self.yield_stress + self.consistency * g**self.index

    exact_rate = RateOnlyHerschelBulkley.exact_rate          # the same law: the same elementary Gamma


@attrs.frozen
class TwoKinks(Rheology):
    """Rate-natural, increasing, with two kinks: slopes 1, 1/2 and 2 (Pa s)^-1 at 1 and 1.5 Pa."""

    def _shear_rate(self, tau):
        return np.where(tau < 1.0, tau, np.where(tau < 1.5, 1.0 + 0.5 * (tau - 1.0), 1.25 + 2.0 * (tau - 1.5)))


def rel(a, b):
    return np.abs(np.asarray(a) - b) / np.abs(b)


def carreau_reference(law, wall_rates):
    """``(tau_w, Gamma)`` of a Carreau law at the wall shear rates ``wall_rates``: 30-digit mpmath,
    :math:`\\Gamma = \\tfrac43\\dot\\gamma_w\\int_0^1[1 - (\\tau(\\dot\\gamma_w t)/\\tau_w)^3]dt` with
    breakpoints around the transition (where tanh-sinh needs them), rounded to doubles."""
    taus, gammas = [], []
    with mp.workdps(30):
        e0, lam, n = mpf(law.eta0), mpf(law.lam), mpf(law.index)

        def tau(g):
            return g * e0 * (1 + (lam * g) ** 2) ** ((n - 1) / 2)

        for rate in np.ravel(wall_rates):
            g_w = mpf(float(rate))
            t_w = tau(g_w)
            corner = 1 / (lam * g_w)
            points = [0] + sorted(c for c in (corner / 1000, corner / 10, corner, 10 * corner, 1000 * corner)
                                  if c < 1) + [1]
            gamma = 4 * g_w / 3 * mp.quad(lambda t: 1 - (tau(g_w * t) / t_w) ** 3, points)
            taus.append(float(t_w))
            gammas.append(float(gamma))
    return np.array(taus), np.array(gammas)


def wall_stress_error(law, tw, gamma, radius=1e-3):
    """Relative error of tau_w = G R / 2 from ``pressure_gradient`` at the flow rate of the
    reference apparent shear rate ``gamma`` of wall stress ``tw``."""
    q = 0.25 * math.pi * radius**3 * np.asarray(gamma)
    return rel(0.5 * law.pressure_gradient(q, radius) * radius, tw)


def allowed(tw, gamma):
    """TOL plus the rounding of the table's logarithms (module docstring; no yield stress)."""
    return TOL + 4 * EPS * (np.abs(np.log(gamma)) + np.abs(np.log(tw)))


@pytest.fixture(autouse=True)
def _accuracy_warnings_are_errors():
    with warnings.catch_warnings():
        warnings.simplefilter("error", AccuracyWarning)
        yield


@pytest.fixture(autouse=True)
def _fresh_tables():
    """Each test starts from an empty cache (its counts of work are its own)."""
    tubefsi.cache_clear()
    yield
    tubefsi.cache_clear()


# ---------------------------------------------------------------- the Rabinowitsch–Mooney integral
@pytest.mark.parametrize("law", [NewtonianBelow(), NewtonianBelow(eta0=1.0, index=1.8, tau_c=0.3),
                                 KinkedPowerLaw(), KinkedPowerLaw(m=2.0, index=1.4, g_c=0.2)], ids=repr)
def test_kinked_law_is_integrated_to_the_tolerance(law):
    """Dense wall stresses across the kink (wherever it falls in the quadrature's panels): the flow
    rate within ~1e-14 of the elementary closed form, without a warning. (R = 1 and G = 2 tau_w:
    the wall stress reaches the integral exactly; q = pi Gamma / 4 adds two roundings, 2 eps.)
    The fixed graded rule this replaced lost ~1e-4 here, silently."""
    tw = np.geomspace(1e-3, 1e3, 1500)
    q = law.flow_rate(1.0, 2.0 * tw)
    assert np.max(rel(q, 0.25 * math.pi * law.exact_rate(tw))) < 2e-14 + 2 * EPS


def test_kinked_law_against_mpmath():
    """The closed form itself against mpmath (kink as a breakpoint), and the library on top."""
    law = NewtonianBelow()
    with mp.workdps(30):
        tc, e0 = mpf(law.tau_c), mpf(law.eta0)
        m, n = tc / (tc / e0) ** mpf(law.index), mpf(law.index)

        def rate(t):
            return t / e0 if t <= tc else (t / m) ** (1 / n)

        for tw in (0.7, 2.0000001, 5.3, 90.0):
            t = mpf(tw)
            pts = [0, tc, t] if t > tc else [0, t]
            ref = 4 * mp.quad(lambda s: s * s * rate(s), pts) / t**3
            assert float(abs(law.exact_rate(np.array(tw))[()] - ref) / ref) < 1e-15
            q = law.flow_rate(1.0, 2.0 * tw)
            assert float(abs(q - mp.pi * ref / 4) / (mp.pi * ref / 4)) < 2e-14 + 2 * EPS


def test_yield_stress_quadrature_runs_over_the_yielded_part_only():
    """A generic rate-natural yield-stress law: to the tolerance away from yield; near it the law
    itself (given tau, not tau - tau_y) resolves the excess only to ~eps tau_y / excess, the
    rounding floor that the quadrature reports (no quadrature does better: the problem's own
    condition number). The reference takes the excess of the wall stress as given, tw - tau_y:
    exact (Sterbenz) for tw < 2 tau_y, and within eps/2 beyond (3.2 eps/2 in Gamma)."""
    law = RateOnlyHerschelBulkley()
    tw = law.yield_stress + np.geomspace(1e-1, 1e4, 100) * law.yield_stress
    q = law.flow_rate(1.0, 2.0 * tw)
    assert np.max(rel(q, 0.25 * math.pi * law.exact_rate(tw, tw - law.yield_stress))) < 2e-14 + 2 * EPS
    tw = law.yield_stress + np.geomspace(1e-12, 1e-3, 20) * law.yield_stress
    excess = tw - law.yield_stress                       # exact: the excess the library sees
    q = law.flow_rate(1.0, 2.0 * tw)
    assert np.all(rel(q, 0.25 * math.pi * law.exact_rate(tw, excess)) < 40 * EPS * tw / excess)
    assert np.all(law.flow_rate(1.0, np.array([1.0, 4.0])) == 0.0)     # tau_w = 0.5, 2.0 <= tau_y


def test_kinked_velocity_profile():
    law = NewtonianBelow()
    radius, g = 1e-3, 2 * 10.0 / 1e-3            # wall stress 10 Pa, kink at 2 Pa (r = R / 5)
    r = np.concatenate([np.linspace(0, radius, 101)[:-1], [0.2 * radius, 0.2 * radius * (1 + 1e-9)]])
    got = law.velocity(r, radius, g)
    assert np.max(rel(got, law.exact_velocity(r, radius, g))) < 1e-13


def test_an_unresolvable_integrand_is_warned_about():
    """The estimate cannot be met (a rapidly oscillating law): an AccuracyWarning with it."""

    @attrs.frozen
    class Rippled(Rheology):
        def _shear_rate(self, tau):
            return tau * (1.0 + 1e-6 * np.sin(1e9 * tau))

    with pytest.warns(AccuracyWarning, match="Rabinowitsch"):
        Rippled().flow_rate(1.0, 6.0)


def test_unit_integral_endpoint_singularity_and_hidden_kink():
    """t^(1/n) at t = 0 costs nothing special; a kink just short of a panel end (invisible to
    Gauss–Kronrod nodes) is still found."""
    res = unit_integral(lambda t, idx: t ** (1 / 0.3), 1)
    assert abs(res.value[0] - 0.3 / 1.3) < 1e-15 and res.converged[0]
    # kink at z = 2 - 1e-4 in z = -ln t: a panel end of the initial grid
    tc = math.exp(-(2.0 - 1e-4))
    res = unit_integral(lambda t, idx: np.abs(t - tc), 1)
    exact = 0.5 * tc**2 + 0.5 * (1 - tc) ** 2
    assert abs(res.value[0] - exact) / exact < 1e-14


@pytest.mark.parametrize("tw", [2.20383715, 2.87801264, 3.86282971])
def test_two_kinks_are_integrated_to_the_tolerance(tw):
    """An increasing law with two kinks, at wall stresses where the quadrature stopped early: the
    flow rate against mpmath (kinks as breakpoints) to 2e-14, without a warning."""
    q = TwoKinks().flow_rate(1.0, 2.0 * tw)
    with mp.workdps(30):
        t_w = mpf(tw)

        def rate(t):
            return t if t < 1 else (1 + (t - 1) / 2 if t < mpf(1.5) else mpf(1.25) + 2 * (t - mpf(1.5)))

        ref = mp.pi * mp.quad(lambda s: s * s * rate(s), [0, 1, mpf(1.5), t_w]) / t_w**3
    assert float(abs(q - ref) / ref) < 2e-14


# ---------------------------------------------------------------- the flow table
@pytest.mark.slow
@pytest.mark.parametrize("law", [CarreauLike(), NewtonianBelow(), KinkedPowerLaw(),
                                 NewtonianBelow(eta0=1.0, index=1.8, tau_c=0.3)], ids=repr)
def test_table_against_direct_integrals_over_many_decades(law):
    """tau_w = G R / 2 from ``pressure_gradient`` (the flow map where it serves the law) and from the
    table itself at the reference flow rate of 40 decades of wall stress, within TOL plus the
    rounding of the logarithms: the piecewise laws against their elementary
    Gamma (801 wall stresses), the Carreau law against mpmath (101 wall shear rates).

    Work, once 801 wall stresses across the 40 decades have been served: the table holds fixed
    unit panels of the natural parameter p (ln tau_w for a rate-natural law, ln of the wall shear
    rate, from the public ``shear_rate``, for a stress-natural one), so it builds the panels those
    loads span, plus at most one past each end where the first jump toward the far end overshoots
    it (1 measured: a slope taken where the law is Newtonian, used where it is twice as steep).
    Each costs SMOOTH_PANEL evaluations, a few more where a fit needs bisecting (25 on average
    allowed, 23.2 measured for the Carreau law), and at most KINKED_PANEL more at a kink."""
    radius = 1e-3
    dense = np.geomspace(1e-20, 1e20, 801)
    if isinstance(law, CarreauLike):
        tw, gamma = carreau_reference(law, np.geomspace(law.shear_rate(1e-20), law.shear_rate(1e20), 101))
        kinks = 0
    else:
        tw, gamma = dense, law.exact_rate(dense)
        kinks = 1
    err = wall_stress_error(law, tw, gamma, radius)           # (the flow map, for a law it serves)
    bound = allowed(tw, gamma)
    assert np.all(err <= bound), float(np.max(err / bound))
    q = 0.25 * math.pi * radius**3 * np.asarray(gamma)
    err = rel(0.5 * _tabulated_gradient(law, q, radius) * radius, tw)     # the table itself
    assert np.all(err <= bound), float(np.max(err / bound))
    _tabulated_gradient(law, law.flow_rate(radius, 2.0 * dense / radius), radius)
    p = np.log(law.shear_rate(dense)) if isinstance(law, (CarreauLike, KinkedPowerLaw)) else np.log(dense)
    spanned = math.floor(p.max()) - math.floor(p.min()) + 1
    table = flow_table(law)
    assert spanned <= table.panel_count <= spanned + 2
    assert table.evaluations <= 25 * table.panel_count + kinks * KINKED_PANEL


def test_table_of_a_yield_stress_fluid_near_and_far_from_yield():
    """Against the elementary Gamma from 1e-9 to 1e6 Pa above yield. Below the lowest panel the
    law resolves (tau_w - tau_y < sqrt(eps) tau_y for a law that gets only tau) the table follows
    that panel's power-law asymptote: G stays within TOL (it carries tau_y), the excess within
    TOL tau_w / excess (its condition number near yield)."""
    law = RateOnlyHerschelBulkley()
    excess = np.geomspace(1e-9, 1e6, 301)
    tw = law.yield_stress + excess
    radius = 1e-3
    q = 0.25 * math.pi * radius**3 * law.exact_rate(tw, excess)
    g = law.pressure_gradient(q, radius)
    got_excess = 0.5 * g * radius - law.yield_stress
    # G itself to TOL; the excess (ill-conditioned near yield: G carries tau_y) to TOL tau_w / excess
    assert np.all(rel(0.5 * g * radius, tw) < TOL + 4 * EPS * np.abs(np.log(excess)))
    assert np.all(rel(got_excess, excess) < (TOL + 8 * EPS * np.abs(np.log(excess))) * tw / excess + 1e-15)
    # q -> 0+: the yield gradient, exactly
    assert law.pressure_gradient(1e-300, radius) == 2 * law.yield_stress / radius


@pytest.mark.parametrize("law", [RateOnlyHerschelBulkley(consistency=0.32), StressOnlyHerschelBulkley()], ids=repr)
def test_generic_yield_stress_laws_from_tiny_to_large_loads(law):
    """No closed forms, only the law: G(q -> 0+) is the yield gradient, and G inverts the flow
    rate over 30 decades of it, with a bounded table: fewer than 40 panels (22 and 33 measured),
    each interpolated, near yield too (the next test): SMOOTH_PANEL evaluations, a few more where
    a fit bisects (25 allowed)."""
    radius = 1e-3
    g_yield = 2 * law.yield_stress / radius
    assert law.pressure_gradient(1e-300, radius) == g_yield
    q = np.geomspace(1e-30, 1e-3, 28)
    g = law.pressure_gradient(q, radius)
    assert np.all(g > g_yield) and np.all(np.diff(g) > 0)
    # q(G) is ill-conditioned near yield (tau_w / (tau_w - tau_y)): compare G, well-conditioned
    g_back = law.pressure_gradient(law.flow_rate(radius, g), radius)
    assert np.all(rel(g_back, g) < 1e-14)
    table = flow_table(law)
    assert table.panel_count < 40
    assert table.evaluations <= 2 + 25 * table.panel_count


@pytest.mark.parametrize("law", [RateOnlyHerschelBulkley(), StressOnlyHerschelBulkley()], ids=repr)
def test_near_yield_panels_of_a_generic_law_are_interpolated(law):
    """From 1e-8 to 1e-1 of tau_y above yield (down to the table's floor, sqrt(eps) tau_y): G
    against the elementary Gamma within TOL plus the rounding of the logarithms, and every panel
    those loads span interpolated (25 evaluations each allowed, 23 measured). The law gets tau,
    not tau - tau_y: its flow function there is rounded to ~eps tau_y / (tau_w - tau_y), far above
    the fits' tolerance in ln Gamma, but G carries tau_y and moves only (tau_w - tau_y) / tau_w of
    that; the fits are held to TOL in G. (They were held to it in ln Gamma: each such panel gave up
    after ~2700 evaluations and bisected ~55 quadratures per lookup, 0.8 and 2.1 s here.)"""
    radius = 1e-3
    excess = law.yield_stress * np.geomspace(1e-8, 1e-1, 71)
    tw = law.yield_stress + excess
    g = law.pressure_gradient(0.25 * math.pi * radius**3 * law.exact_rate(tw, excess), radius)
    assert np.all(rel(0.5 * g * radius, tw) < TOL + 4 * EPS * np.abs(np.log(excess)))
    table = flow_table(law)
    assert table.evaluations <= 2 + 25 * table.panel_count


@pytest.mark.parametrize("law", [CarreauLike(), NewtonianBelow()], ids=repr)
def test_tiny_loads_take_a_bounded_number_of_evaluations(law):
    """G(q, R) down to q = 1e-300 (the first table was extended panel by panel: 25 s at 1e-100,
    > 590 s at 1e-300): each load builds at most 3 panels (the one its secant step lands on, and
    a neighbour or two), SMOOTH_PANEL evaluations each, plus 2 for the first secant; and G is the
    Newtonian asymptote 8 eta0 q / (pi R^4)."""
    radius = 1e-4
    table = flow_table(law)
    for q in (1e-20, 1e-100, 1e-300):
        before = table.evaluations, table.panel_count
        g = law.pressure_gradient(q, radius)
        assert rel(g, 8 * law.eta0 * q / (math.pi * radius**4)) < 1e-13 + 8 * EPS * abs(math.log(q))
        built = table.panel_count - before[1]
        assert built <= 3 and table.evaluations - before[0] <= 2 + SMOOTH_PANEL * built


@pytest.mark.parametrize("law", [CarreauLike(), KinkedPowerLaw()], ids=repr)
def test_huge_loads_take_a_bounded_number_of_evaluations(law):
    """Up to q = 1e120, as the tiny loads above; the flow rate of the answer gives q back."""
    radius = 1e-4
    table = flow_table(law)
    for q in (1e3, 1e60, 1e120):
        before = table.evaluations, table.panel_count
        g = law.pressure_gradient(q, radius)
        built = table.panel_count - before[1]
        assert built <= 3 and table.evaluations - before[0] <= 2 + SMOOTH_PANEL * built
        back = law.flow_rate(radius, g)
        assert rel(back, q) < 2e-14 + 8 * EPS * math.log(q)


def test_loads_beyond_the_flow_functions_range_cost_little():
    """Where the law's flow function overflows (a shear-thickening law, index 2: its shear rate
    beyond ~1e154 Pa) the table ends: a huge load is an InvalidParameterError after a bounded number
    of evaluations. The first panel's secant lands beyond the range; the table steps back by
    doubling steps and bisects for the range's last panel: at most ~21 panels tried (2 evaluations
    each where the flow function is not finite, up to 25 where it is), 324 measured. (A thinning law
    no longer ends before its apparent shear rate does: the integrand is scaled by the wall stress.)"""
    law = RateOnlyHerschelBulkley(consistency=0.31, index=2.0)
    with pytest.raises(InvalidParameterError, match="flow_rate"):
        law.pressure_gradient(1e200, 1e-4)
    assert flow_table(law).evaluations <= 2 + 21 * 25


def test_a_valid_load_beyond_the_first_secant_step():
    """A law that steepens 10-fold at tau_c = 1e13 Pa (the secant from p = 0, 1 sees its Newtonian
    part) and overflows beyond ~1e42 Pa: a load of a fresh table whose secant start lands past
    that end is found, to TOL against the elementary Gamma (it was an IndexError), after the
    probes of the test above and the 3 panels of the load (114 to 162 evaluations measured)."""
    law = NewtonianBelow(eta0=1.0, index=0.1, tau_c=1e13)
    tw = np.array([1e18, 1e20, 1e22])
    gamma = law.exact_rate(tw)
    for i in range(tw.size):
        tubefsi.cache_clear()
        err = wall_stress_error(law, tw[i], gamma[i])
        assert err <= allowed(tw[i], gamma[i]), err
        assert flow_table(law).evaluations <= 2 + 21 * 25 + 3 * 25


def test_far_apart_loads_do_not_tabulate_the_gap():
    """Two loads 90 units of ln Gamma apart build panels near each (at most 3 each, 6 measured),
    never the ~90 between; a call spanning both adds only the panels of its middle load (1
    measured): the fixed panels need no contiguous run."""
    law = CarreauLike(lam=1.0)
    radius = 1e-3
    law.pressure_gradient(1e-40, radius)
    law.pressure_gradient(1e-1, radius)
    table = flow_table(law)
    assert table.panel_count <= 6
    q = np.array([1e-40, 1e-20, 1e-1])
    g = law.pressure_gradient(q, radius)
    assert table.panel_count <= 9
    assert table.evaluations <= 2 + 25 * table.panel_count
    assert np.all(rel(law.flow_rate(radius, g), q) < 1e-13)


def test_lookups_stay_a_few_arrays_of_the_points_size():
    """The working set of pressure_gradient over 344064 built points: ~16 arrays of their size
    (measured 16.3: the public call's validation, broadcasting and masking ~9 copies, the table's
    lookup itself 7.1), below 20. A lookup that gathered each point's 9 coefficient rows of the
    degree-8 inverse would add 9 arrays on its own."""
    law = CarreauLike()
    q = np.geomspace(1e-12, 1e-8, 16384)[:, None]
    r = 1e-4 * np.exp(np.linspace(0.0, 0.6, 21))[None, :] * np.ones((16384, 1))
    law.pressure_gradient(np.broadcast_to(q, r.shape), r)            # build the table first
    tracemalloc.start()
    try:
        law.pressure_gradient(np.broadcast_to(q, r.shape), r)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * r.nbytes


@settings(max_examples=scaled(25), deadline=None)
@given(eta0=st.floats(1e-3, 10.0), lam=st.floats(1e-3, 1e3), index=st.floats(0.05, 1.8),
       centre=st.floats(-25.0, 25.0), width=st.floats(0.05, 12.0))
def test_table_inverts_the_direct_integral_of_any_carreau_law(eta0, lam, index, centre, width):
    """Property (it replaces the cumulative panel rule's, removed with it): for a Carreau law and a
    window of wall shear rates e^(centre +- width/2), the table's G at the flow rate of the
    error-controlled direct integral (``flow_rate``) gives back the wall stress, within TOL, the
    rounding of the logarithms, and the direct integral's own error (its estimate 1e-15, else an
    AccuracyWarning, amplified by d ln tau_w / d ln Gamma <= max(1, n)) plus its roundings."""
    tubefsi.cache_clear()
    law = CarreauLike(eta0=eta0, lam=lam, index=index)
    radius = 1.0
    tw = law.stress(np.exp(np.linspace(centre - width / 2, centre + width / 2, 9)))
    q = law.flow_rate(radius, 2.0 * tw)
    gamma = q / (0.25 * math.pi)
    err = wall_stress_error(law, tw, gamma, radius)
    assert np.all(err <= allowed(tw, gamma) + max(1.0, index) * (1e-15 + 4 * EPS))


# ---------------------------------------------------------------- what the fixed panels promise
def _neighbours(x, k):
    """``x`` and the ``k`` doubles on either side of it."""
    below, above, out = x, x, [x]
    for _ in range(k):
        below, above = np.nextafter(below, 0.0), np.nextafter(above, np.inf)
        out += [below, above]
    return sorted(out)


def _panel_ends(law, natural, js, radius=1.0):
    """Flow rates within a few ulps of where the table's panels meet: panel j ends at natural
    parameter p = j + 1, i.e. tau_w - tau_y = e^p (rate-natural) or the wall shear rate e^p
    (stress-natural). Through the public API the end is reached within a few roundings; 16
    doubles either side of it make sure that one load lies exactly on it."""
    loads = []
    for j in js:
        tw = float(law.stress(math.exp(j))) if natural == "stress" else law.yield_stress + math.exp(j)
        loads += _neighbours(float(law.flow_rate(radius, 2.0 * tw / radius)), 16)
    return loads


@pytest.mark.parametrize("law, natural, js, span", [
    (CarreauLike(), "stress", range(-4, 6), (1e-5, 1e2)),
    (NewtonianBelow(), "rate", range(-3, 5), (1e-4, 1e4)),
    (RateOnlyHerschelBulkley(), "rate", (-15, -11, -5, 0, 3), (1e-10, 1e2)),
], ids=["stress-natural", "rate-natural-kinked", "yield-stress"])
def test_an_answer_does_not_depend_on_the_tables_history(law, natural, js, span):
    """The same load gives the same bits whatever loads the table served before: loads across the
    law's range, loads on (and around) the ends where panels meet, and (a yield-stress fluid) loads
    below its lowest panel, served one at a time in increasing order, one at a time in a shuffled
    order, and in one call in decreasing order after a sweep of other loads."""
    radius = 1.0
    common = np.array(sorted(set(np.geomspace(*span, 24).tolist() + _panel_ends(law, natural, js, radius)
                                 + [1e-300, 1e-30])))

    def one_at_a_time(order):
        tubefsi.cache_clear()
        out = np.empty(common.size)
        for i in order:
            out[i] = law.pressure_gradient(common[i], radius)
        return out

    increasing = one_at_a_time(range(common.size))
    shuffled = list(range(common.size))
    random.Random(7).shuffle(shuffled)
    scattered = one_at_a_time(shuffled)
    tubefsi.cache_clear()
    law.pressure_gradient(np.geomspace(span[0] * 1e-3, span[1] * 1e3, 57), radius)
    swept = law.pressure_gradient(common[::-1], radius)[::-1]
    assert np.array_equal(increasing, scattered)
    assert np.array_equal(increasing, swept)


def _tabulated_gradient(law, q, radius):
    """G(q, R) from the law's flow table itself (a fluid the flow maps serve reaches its table only
    where its map fails: the table is exercised directly)."""
    rate = 4.0 * np.asarray(q, dtype=float) / (math.pi * radius**3)
    return 2.0 * flow_table(law).wall_stress(law, rate) / radius


def test_a_fluid_whose_parameters_differ_gets_its_own_table():
    """Two fluids of one class with different parameters, in either order: each its own G from its
    flow table, to TOL against its mpmath reference, the same bits in both orders; an equal fluid
    shares a table."""
    radius = 1e-3
    rates = np.geomspace(1e-3, 1e5, 9)
    laws = [CarreauLike(), CarreauLike(eta0=0.56, lam=0.5, index=0.7)]
    refs = [carreau_reference(law, rates) for law in laws]
    answers = {}
    for order in ((0, 1), (1, 0)):
        tubefsi.cache_clear()
        for i in order:
            tw, gamma = refs[i]
            g = _tabulated_gradient(laws[i], 0.25 * math.pi * radius**3 * gamma, radius)
            assert np.all(rel(0.5 * g * radius, tw) <= allowed(tw, gamma))
            if i in answers:
                assert np.array_equal(g, answers[i])
            answers[i] = g
        assert tubefsi.cache_info().size == 2
    assert not np.array_equal(answers[0], answers[1])
    _tabulated_gradient(CarreauLike(), 1e-9, radius)            # equal to laws[0]: its table
    assert tubefsi.cache_info().size == 2


def test_a_fluid_changed_in_place_answers_for_its_new_values():
    """A fluid that is not frozen, changed between calls: each call answers for the values it has
    then (to TOL against mpmath, and the same bits as a fresh fluid of those values), and changed
    back it answers as before, to the bit."""
    radius = 1e-3
    rates = np.geomspace(1e-2, 1e4, 7)
    fluid = MutableCarreau()
    tw, gamma = carreau_reference(fluid, rates)
    q = 0.25 * math.pi * radius**3 * gamma
    first = fluid.pressure_gradient(q, radius)
    assert np.all(rel(0.5 * first * radius, tw) <= allowed(tw, gamma))
    fluid.eta0, fluid.lam, fluid.index = 0.3, 0.2, 0.5
    tw2, gamma2 = carreau_reference(fluid, rates)
    q2 = 0.25 * math.pi * radius**3 * gamma2
    second = fluid.pressure_gradient(q2, radius)
    assert np.all(rel(0.5 * second * radius, tw2) <= allowed(tw2, gamma2))
    assert np.array_equal(second, MutableCarreau(eta0=0.3, lam=0.2, index=0.5).pressure_gradient(q2, radius))
    assert np.array_equal(fluid.pressure_gradient(q, radius), MutableCarreau(eta0=0.3, lam=0.2, index=0.5)
                          .pressure_gradient(q, radius))
    fluid.eta0, fluid.lam, fluid.index = 0.056, 3.313, 0.3568
    assert np.array_equal(fluid.pressure_gradient(q, radius), first)


def test_threads_sharing_one_fluid_get_the_sequential_answers():
    """8 threads share one Carreau fluid on a cold cache, released together: each computes G at
    its own 40 loads one at a time (interleaved with the others') and a flow-controlled solve.
    Every answer is the sequential one, to the bit, and none raises."""
    law = CarreauLike()
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=5e3)
    tube = tubefsi.Tube(radius=5e-4, thickness=1.5e-4, length=2e-2)
    radius, threads = 1e-3, 8
    loads = np.geomspace(1e-16, 1e-4, threads * 40)
    curves = [np.geomspace(1e-10, 1e-7, 5) * (1.0 + 0.01 * i) for i in range(threads)]

    def work(i, barrier=None):
        if barrier is not None:
            barrier.wait()
        g = np.array([law.pressure_gradient(q, radius) for q in loads[i::threads]])
        return g, np.asarray(tubefsi.solve(law, wall, tube, flow_rate=curves[i]).pressure_drop)

    sequential = [work(i) for i in range(threads)]
    tubefsi.cache_clear()
    barrier = threading.Barrier(threads)
    with concurrent.futures.ThreadPoolExecutor(max_workers=threads) as pool:
        futures = [pool.submit(work, i, barrier) for i in range(threads)]
        parallel = [future.result(timeout=120) for future in futures]
    for (g, drop), (g_par, drop_par) in zip(sequential, parallel):
        assert np.array_equal(g, g_par)
        assert np.array_equal(drop, drop_par)


# ---------------------------------------------------------------- zero loads and typed errors
def test_zero_flow_rate():
    """G(0, R) = 0 through the public API (a convention for yield-stress fluids too), while the
    limit q -> 0+ is 0, or the yield gradient 2 tau_y / R."""
    radius = 1e-3
    for law in (CarreauLike(), RateOnlyHerschelBulkley(), KinkedPowerLaw()):
        assert law.pressure_gradient(0.0, radius) == 0.0
        np.testing.assert_array_equal(law.pressure_gradient(np.zeros(3), radius), 0.0)
        mixed = law.pressure_gradient(np.array([0.0, 1e-9]), radius)
        assert mixed[0] == 0.0 < mixed[1]
        tiny = law.pressure_gradient(np.array([1e-300, 1e-300]), np.array([radius, 2 * radius]))
        if law.yield_stress > 0:
            np.testing.assert_array_equal(tiny, 2 * law.yield_stress / np.array([radius, 2 * radius]))
        else:                                  # 1e-289 (Newtonian), 1e-173 (power law tau ~ rate^0.6)
            assert np.all((tiny > 0) & (tiny < 1e-100))


def test_plugin_rheologies_at_zero_flow_rate():
    pytest.importorskip("tubefsi_rheologies")
    from tubefsi.registry import rheologies

    for name in ("carreau", "carreau-yasuda", "cross", "ellis", "bingham", "casson", "herschel-bulkley"):
        law = rheologies[name](**rheologies[name]._examples[0])
        assert law.pressure_gradient(0.0, 1e-4) == 0.0
        tiny = law.pressure_gradient(1e-300, 1e-4)
        if law.yield_stress > 0:
            assert tiny == 2 * law.yield_stress / 1e-4
        else:
            assert 0.0 < tiny < 1e-100


def test_loads_beyond_the_representable_range_are_typed_errors():
    law = NewtonianBelow(eta0=1.0, index=1.8, tau_c=0.3)     # shear-thickening: tau_w ~ Gamma^1.8
    with pytest.raises(InvalidParameterError, match="flow_rate"):
        law.pressure_gradient(1e250, 1e-4)
    with pytest.raises(InvalidParameterError, match="flow_rate"):
        law.pressure_gradient(np.inf, 1e-4)


def test_a_decreasing_law_is_rejected():
    """A shear rate that decreases between 1 and 1.5 Pa: Gamma rises, falls and rises again
    inside one panel of the table (its ends alone do not show it)."""

    @attrs.frozen
    class NotAFluid(Rheology):
        def _shear_rate(self, tau):                   # continuous, decreasing between 1 and 1.5 Pa
            return np.where(tau < 1.0, tau, np.where(tau < 1.5, 2.0 - tau, tau - 1.0))

    with pytest.raises(InvalidParameterError, match="rheology"):
        NotAFluid().pressure_gradient(np.geomspace(1e-12, 1e-6, 50), 1e-3)


def test_no_bare_arithmetic_errors_across_loads():
    """Every outcome over a wide range of loads is a value or a tubefsi error."""
    for law in (CarreauLike(), RateOnlyHerschelBulkley(), KinkedPowerLaw(), NewtonianBelow(),
                NewtonianBelow(eta0=1.0, index=0.1, tau_c=1e13)):
        for q in (0.0, 5e-324, 1e-200, 1e-30, 1e-6, 1.0, 1e30, 1e200):
            tubefsi.cache_clear()                  # each load the first of its table
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", AccuracyWarning)
                    g = law.pressure_gradient(q, 1e-4)
            except TubefsiError:
                continue
            assert math.isfinite(g) and g >= 0.0


def test_solve_with_a_kinked_law():
    """A whole solve in a thick neo-Hookean tube: flow-controlled and back."""
    law = NewtonianBelow(eta0=0.01, index=0.5, tau_c=1.0)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=5e3)
    tube = tubefsi.Tube(radius=5e-4, thickness=1.5e-4, length=2e-2)
    q = np.geomspace(1e-10, 1e-7, 12)
    a = tubefsi.solve(law, wall, tube, flow_rate=q)
    back = tubefsi.solve(law, wall, tube, pressure_drop=a.pressure_drop)
    np.testing.assert_allclose(back.flow_rate, q, rtol=1e-11)


# ---------------------------------------------------------------- laws that break their contract
@attrs.frozen(kw_only=True)
class _InfBand(Rheology):
    """Newtonian, but an infinite stress for 0.5 < rate < 0.6 1/s (a user's law gone wrong)."""
    eta: float = 0.01

    def _stress(self, g):
        return np.where((g > 0.5) & (g < 0.6), np.inf, self.eta * g)


@attrs.frozen(kw_only=True)
class _NanBelow(Rheology):
    """Newtonian, but NaN below 1e-3 1/s."""
    eta: float = 0.01

    def _stress(self, g):
        return np.where(g < 1e-3, np.nan, self.eta * g)


@attrs.frozen(kw_only=True)
class _FallingCross(Rheology):
    """Cross with exponent 2 and eta_inf = 0.05 eta_0: its stress falls for rates of about 1-3 1/s
    (it increases only where eta_inf > (eta_0 - eta_inf)/8)."""
    eta0: float = 1.0
    eta_inf: float = 0.05

    def _stress(self, g):
        return g * (self.eta_inf + (self.eta0 - self.eta_inf) / (1.0 + g * g))


@attrs.frozen(kw_only=True)
class _NegativeBand(Rheology):
    """Newtonian, but a negative stress for 0.8 < rate < 1.2 1/s (a band narrower than the
    quadratures' nodes can be missed by any sampling: this one spans several)."""
    eta: float = 0.01

    def _stress(self, g):
        return np.where(np.abs(g - 1.0) < 0.2, -self.eta * g, self.eta * g)


_BROKEN_WALL_TUBE = (dict(shear_modulus=5e3), dict(radius=5e-4, thickness=1.5e-4, length=2e-2))


@pytest.mark.parametrize("law, load", [
    (_InfBand(), dict(flow_rate=1e-8)), (_InfBand(), dict(pressure_drop=10.0)),
    (_NanBelow(), dict(flow_rate=1e-8)), (_NanBelow(), dict(pressure_drop=10.0)),
    (_FallingCross(), dict(flow_rate=1e-8)), (_FallingCross(), dict(flow_rate=1e-9)),
    (_NegativeBand(), dict(flow_rate=1e-8)),
], ids=["inf-flow", "inf-pressure", "nan-flow", "nan-pressure", "falling-1e-8", "falling-1e-9", "negative"])
def test_a_law_that_is_not_a_rising_finite_stress_is_refused(law, load):
    """A law written as a plain class whose stress is infinite, NaN, negative or falling over a band
    of rates well below the wall's: an InvalidParameterError naming the rheology and the shear
    rate, whether the band lies in the panels of the flow map below its start (used for K alone)
    or in the generic flow function's quadrature. The flow map's K came from the panels and the
    bound below them, the generic quadrature clipped 1 - (tau/tau_w)^3 at 0: a pressure drop 0.13 %
    off (the infinite band), a flow rate of 0 at a feasible drop (NaN), a number at 1e-8 where
    1e-9 was refused (falling), each without a word."""
    from tubefsi.registry import walls
    wall_kw, tube_kw = _BROKEN_WALL_TUBE
    with pytest.raises(InvalidParameterError) as info:
        tubefsi.solve(law, walls["thick-neo-hookean"](**wall_kw), tubefsi.Tube(**tube_kw), **load)
    assert info.value.parameter == "rheology" and "shear rate" in str(info.value)
