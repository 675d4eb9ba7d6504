"""The generic (non-separable) rheology path: error-controlled Rabinowitsch–Mooney quadrature,
the error-checked flow table and its inverse, bounded work at extreme loads, typed errors.

References are independent of the library: the Rabinowitsch–Mooney integral
:math:`\\Gamma = (4/\\tau_w^3)\\int_0^{\\tau_w}\\tau^2\\dot\\gamma\\,d\\tau` of a piecewise law is
elementary (``docs/theory.md``, section "The flow law of a generalized Newtonian fluid"), and
mpmath integrates the smooth laws. Work is bounded by counting flow-function evaluations and
table panels, not by wall-clock time.
"""

from __future__ import annotations

import math
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
from tubefsi.rheology import Rheology
from tubefsi.rheology._flow_table import TOL, flow_table, unit_integral
from tubefsi.testing.profiles import scaled

EPS = np.finfo(float).eps


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


@attrs.frozen
class CarreauLike(Rheology):
    """Stress-natural Carreau law, written afresh: eta = eta0 (1 + (lam g)^2)^((n-1)/2)."""

    eta0: float = 0.056
    lam: float = 3.313
    index: float = 0.3568

    def _stress(self, g):
        log_x = np.log(self.lam * g)
        return g * self.eta0 * np.exp(0.5 * (self.index - 1.0) * np.logaddexp(0.0, 2.0 * log_x))


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


def rel(a, b):
    return np.abs(np.asarray(a) - b) / np.abs(b)


@pytest.fixture(autouse=True)
def _accuracy_warnings_are_errors():
    with warnings.catch_warnings():
        warnings.simplefilter("error", AccuracyWarning)
        yield


# ---------------------------------------------------------------- the Rabinowitsch–Mooney integral
@pytest.mark.parametrize("law", [NewtonianBelow(), NewtonianBelow(eta0=1.0, index=1.8, tau_c=0.3),
                                 KinkedPowerLaw(), KinkedPowerLaw(m=2.0, index=1.4, g_c=0.2)], ids=repr)
def test_kinked_law_is_integrated_to_the_tolerance(law):
    """Dense wall stresses across the kink (wherever it falls in the quadrature's panels):
    within ~1e-14 of the elementary closed form, without a warning. The fixed graded rule this
    replaced lost ~1e-4 here, silently."""
    tw = np.geomspace(1e-3, 1e3, 1500)
    got = law._apparent_shear_rate(tw)
    assert np.max(rel(got, law.exact_rate(tw))) < 2e-14


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
            assert float(abs(law._apparent_shear_rate(np.array([tw]))[0] - ref) / ref) < 2e-14


def test_yield_stress_quadrature_runs_over_the_yielded_part_only():
    """A generic rate-natural yield-stress law, ``excess`` exact: to the tolerance away from yield;
    near it the law itself (given tau, not tau - tau_y) resolves the excess only to
    ~eps tau_y / excess, the rounding floor that the quadrature reports (no quadrature does
    better: the problem's own condition number)."""
    law = RateOnlyHerschelBulkley()
    excess = np.geomspace(1e-1, 1e4, 100) * law.yield_stress
    tw = law.yield_stress + excess
    got = law._apparent_shear_rate(tw, excess=excess)
    assert np.max(rel(got, law.exact_rate(tw, excess))) < 2e-14
    excess = np.geomspace(1e-12, 1e-3, 20) * law.yield_stress
    tw = law.yield_stress + excess
    got = law._apparent_shear_rate(tw, excess=excess)
    assert np.all(rel(got, law.exact_rate(tw, excess)) < 40 * EPS * tw / excess)
    assert np.all(law._apparent_shear_rate(np.array([0.5, 2.0])) == 0.0)


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
        Rippled()._apparent_shear_rate(np.array([3.0]))


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


# ---------------------------------------------------------------- the flow table
def _table_error(law, tw, excess=None):
    """Relative error of pressure_gradient at the exact flow rate of wall stress tw."""
    radius = 1e-3
    rate = law._apparent_shear_rate(tw) if excess is None else law._apparent_shear_rate(tw, excess=excess)
    q = 0.25 * math.pi * radius**3 * rate
    g = law.pressure_gradient(q, radius)
    return rel(0.5 * g * radius, tw), rate


@pytest.mark.parametrize("law", [CarreauLike(), NewtonianBelow(), KinkedPowerLaw(),
                                 NewtonianBelow(eta0=1.0, index=1.8, tau_c=0.3)], ids=repr)
def test_table_against_direct_integrals_over_many_decades(law):
    """The table's inverse against the error-controlled direct integral over 40 decades of wall
    stress: within TOL plus the rounding of the logarithms (4 eps (|ln Gamma| + |ln tau_w|))."""
    tw = np.geomspace(1e-20, 1e20, 801)
    err, rate = _table_error(law, tw)
    allowed = TOL + 4 * EPS * (np.abs(np.log(rate)) + np.abs(np.log(tw)))
    assert np.all(err <= allowed), float(np.max(err / allowed))
    table = flow_table(law)
    assert table.evaluations < 6000 and table.panel_count < 120


def test_table_of_a_yield_stress_fluid_near_and_far_from_yield():
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


# (equal rheologies share one cached table: each test below uses a fluid of its own)
@pytest.mark.parametrize("law", [RateOnlyHerschelBulkley(consistency=0.32), StressOnlyHerschelBulkley()], ids=repr)
def test_generic_yield_stress_laws_from_tiny_to_large_loads(law):
    """No closed forms, only the law: G(q -> 0+) is the yield gradient, and G inverts the
    flow rate over 30 decades of it, with a bounded table."""
    radius = 1e-3
    g_yield = 2 * law.yield_stress / radius
    assert law.pressure_gradient(1e-300, radius) == g_yield
    q = np.geomspace(1e-30, 1e-3, 28)
    g = law.pressure_gradient(q, radius)
    assert np.all(g > g_yield) and np.all(np.diff(g) > 0)
    # q(G) is ill-conditioned near yield (tau_w / (tau_w - tau_y)): compare G, well-conditioned
    g_back = law.pressure_gradient(law.flow_rate(radius, g), radius)
    assert np.all(rel(g_back, g) < 1e-14)
    assert flow_table(law).panel_count < 40


@pytest.mark.parametrize("law", [CarreauLike(eta0=0.057), NewtonianBelow(eta0=0.051)], ids=repr)
def test_tiny_loads_take_a_bounded_number_of_evaluations(law):
    """G(q, R) down to q = 1e-300 (the old table was extended panel by panel: 25 s at 1e-100,
    > 590 s at 1e-300): a few panels per load, and the Newtonian asymptote 8 eta0 q / (pi R^4)."""
    radius = 1e-4
    table = flow_table(law)
    for q in (1e-20, 1e-100, 1e-300):
        before = table.evaluations, table.panel_count
        g = law.pressure_gradient(q, radius)
        assert rel(g, 8 * law.eta0 * q / (math.pi * radius**4)) < 1e-13 + 8 * EPS * abs(math.log(q))
        assert table.evaluations - before[0] <= 120 and table.panel_count - before[1] <= 3


@pytest.mark.parametrize("law", [CarreauLike(eta0=0.058), KinkedPowerLaw(m=0.021)], ids=repr)
def test_huge_loads_take_a_bounded_number_of_evaluations(law):
    radius = 1e-4
    table = flow_table(law)
    for q in (1e3, 1e60, 1e120):
        before = table.evaluations, table.panel_count
        g = law.pressure_gradient(q, radius)
        assert table.evaluations - before[0] <= 120 and table.panel_count - before[1] <= 3
        back = law.flow_rate(radius, g)
        assert rel(back, q) < 2e-14 + 8 * EPS * math.log(q)


def test_loads_beyond_the_flow_functions_range_cost_little():
    """Where the law overflows (((tau - tau_y)/K)^(1/n) beyond ~1e139 Pa) the table ends there: a
    huge load is an InvalidParameterError after a bounded number of evaluations."""
    law = RateOnlyHerschelBulkley(consistency=0.31)
    with pytest.raises(InvalidParameterError, match="flow_rate"):
        law.pressure_gradient(1e200, 1e-4)
    assert flow_table(law).evaluations < 3000


def test_far_apart_loads_do_not_tabulate_the_gap():
    """Two loads 90 units of ln Gamma apart: two short segments; a call spanning both merges them."""
    law = CarreauLike(lam=1.0)
    radius = 1e-3
    law.pressure_gradient(1e-40, radius)
    law.pressure_gradient(1e-1, radius)
    table = flow_table(law)
    assert len(table.segments) == 2 and table.panel_count <= 4
    q = np.array([1e-40, 1e-20, 1e-1])
    g = law.pressure_gradient(q, radius)
    assert len(table.segments) == 1
    assert np.all(rel(law.flow_rate(radius, g), q) < 1e-13)


def test_lookups_do_not_gather_coefficient_rows():
    """The lookup's working set is a few arrays of the points' size (the old table gathered an
    (M x 29) coefficient array twice: ~60 arrays)."""
    law = CarreauLike(eta0=0.059)
    q = np.geomspace(1e-12, 1e-8, 16384)[:, None]
    r = 1e-4 * np.exp(np.linspace(0.0, 0.6, 21))[None, :] * np.ones((16384, 1))
    law._pressure_gradient(np.broadcast_to(q, r.shape), r)            # build the table first
    tracemalloc.start()
    try:
        law._pressure_gradient(np.broadcast_to(q, r.shape), r)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 10 * r.nbytes


# ---------------------------------------------------------------- zero loads and typed errors
def test_zero_flow_rate():
    """G(0, R) = 0 through the public API (a convention for yield-stress fluids too); the hook
    gives the limit q -> 0+: 0, or the yield gradient 2 tau_y / R."""
    radius = 1e-3
    for law in (CarreauLike(), RateOnlyHerschelBulkley(), KinkedPowerLaw()):
        assert law.pressure_gradient(0.0, radius) == 0.0
        np.testing.assert_array_equal(law.pressure_gradient(np.zeros(3), radius), 0.0)
        g = law._pressure_gradient(np.array([0.0, 0.0]), np.array([radius, 2 * radius]))
        np.testing.assert_array_equal(g, 2 * law.yield_stress / np.array([radius, 2 * radius]))
        mixed = law.pressure_gradient(np.array([0.0, 1e-9]), radius)
        assert mixed[0] == 0.0 < mixed[1]


def test_plugin_rheologies_at_zero_flow_rate():
    pytest.importorskip("tubefsi_rheologies")
    from tubefsi.registry import rheologies

    for name in ("carreau", "carreau-yasuda", "cross", "ellis", "bingham", "casson", "herschel-bulkley"):
        law = rheologies[name](**rheologies[name]._examples[0])
        assert law.pressure_gradient(0.0, 1e-4) == 0.0
        assert law._pressure_gradient(np.zeros(1), np.full(1, 1e-4))[0] == 2 * law.yield_stress / 1e-4


def test_loads_beyond_the_representable_range_are_typed_errors():
    law = NewtonianBelow(eta0=1.0, index=1.8, tau_c=0.3)     # shear-thickening: tau_w ~ Gamma^1.8
    with pytest.raises(InvalidParameterError, match="flow_rate"):
        law.pressure_gradient(1e250, 1e-4)
    with pytest.raises(InvalidParameterError, match="flow_rate"):
        law.pressure_gradient(np.inf, 1e-4)


def test_a_decreasing_law_is_rejected():
    @attrs.frozen
    class NotAFluid(Rheology):
        def _shear_rate(self, tau):                   # continuous, decreasing between 1 and 1.5 Pa
            return np.where(tau < 1.0, tau, np.where(tau < 1.5, 2.0 - tau, tau - 1.0))

    with pytest.raises(InvalidParameterError, match="rheology"):
        NotAFluid().pressure_gradient(np.geomspace(1e-12, 1e-6, 50), 1e-3)


def test_no_bare_arithmetic_errors_across_loads():
    """Every outcome over a wide range of loads is a value or a tubefsi error."""
    for law in (CarreauLike(), RateOnlyHerschelBulkley(), KinkedPowerLaw(), NewtonianBelow()):
        for q in (0.0, 5e-324, 1e-200, 1e-30, 1e-6, 1.0, 1e30, 1e200):
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


# ---------------------------------------------------------------- a panel's nodes from one cumulative integral
def _panel_nodes(a, b):
    """The 29 parameters of the table panel on [a, b] (its Lobatto nodes and check points), (1, 29)."""
    from tubefsi.rheology._flow_table import _panel_nodes as nodes
    return nodes(np.array([a]), np.array([b]))


@pytest.mark.parametrize("a, b", [(-6.0, -4.0), (-1.0, 1.0), (3.0, 5.0), (-4.0, 4.0), (12.0, 20.0)])
def test_cumulative_panel_rate_against_mpmath(a, b):
    """Gamma at a panel's nodes from the cumulative integral K (one rule for the whole panel)
    against 30-digit mpmath quadrature of 4/3 rate int_0^1 (1 - (tau(rate t)/tau_w)^3) dt for
    the Carreau law written afresh: every accepted node within 3e-15 and within its estimate
    plus 1e-15; at least 80 % of the nodes accepted on a smooth law."""
    from tubefsi.rheology._flow_table import stress_natural_rate_panels
    law = CarreauLike()
    p = _panel_nodes(a, b)
    rate = np.exp(p)
    tw = law._stress(rate)     # the reference takes these as given: their rounding, amplified 3q/(1-q), is the law's
    gamma, estimate, ok = stress_natural_rate_panels(law, p, tw)
    assert ok.mean() >= 0.8
    with mp.workdps(30):
        e0, lam, n = mpf(law.eta0), mpf(law.lam), mpf(law.index)

        def tau(g):
            return g * e0 * (1 + (lam * g) ** 2) ** ((n - 1) / 2)

        for j in range(0, p.shape[1], 4):
            g_w = mpf(float(rate[0, j]))
            t_w = mpf(float(tw[0, j]))           # the given wall stress (see above)
            corner = 1 / (lam * g_w)             # the transition, where tanh-sinh needs a breakpoint
            points = [0] + sorted(c for c in (corner / 1000, corner / 10, corner, 10 * corner, 1000 * corner) if c < 1) + [1]
            ref = 4 * g_w / 3 * mp.quad(lambda t: 1 - (tau(g_w * t) / t_w) ** 3, points)
            err = float(abs(gamma[0, j] - ref) / ref)
            if ok[0, j]:
                assert err < 3e-15 and err < estimate[0, j] + 1e-15, (j, err, estimate[0, j])


@pytest.mark.parametrize("a, b", [(3.0, 5.0), (3.9, 4.0), (3.0, 3.912)])
def test_cumulative_panel_rate_across_a_kink(a, b):
    """A stress-natural law with a kink inside the panel (ln g_c = 3.912): the accepted nodes
    against the elementary closed form within 2e-14, and the table's exact values (accepted or
    integrated one by one) too."""
    from tubefsi.rheology._flow_table import FlowTable, stress_natural_rate_panels
    law = KinkedPowerLaw()
    p = _panel_nodes(a, b)
    rate = np.exp(p)
    tw = law._stress(rate)
    gamma, _, ok = stress_natural_rate_panels(law, p, tw)
    exact = law.exact_rate(tw)
    assert np.all(rel(gamma[ok], exact[ok]) < 2e-14)
    s, y, _ = FlowTable(law)._exact(p)
    assert np.all(rel(np.exp(y), exact) < 2e-14)


def test_cumulative_panel_rate_refuses_a_stress_plateau():
    """Near a yield stress 1 - q cancels (q -> 1): those nodes are refused, and the table's
    exact values there are the point-wise integrals."""
    from tubefsi.rheology._flow_table import FlowTable, stress_natural_rate, stress_natural_rate_panels
    law, twin = StressOnlyHerschelBulkley(), RateOnlyHerschelBulkley()
    p = _panel_nodes(-20.0, -14.0)            # tau - tau_y ~ 1e-5 .. 1e-3 tau_y
    rate = np.exp(p)
    tw = law._stress(rate)
    _, _, ok = stress_natural_rate_panels(law, p, tw)
    assert not np.any(ok)
    _, y, _ = FlowTable(law)._exact(p)
    assert np.array_equal(np.exp(y), np.exp(np.log(stress_natural_rate(law, rate, tw)[0])))
    # (their own accuracy there is the law's: 1 - (tau / tau_w)^3 carries eps tau_y / (tau - tau_y))
    excess = law.consistency * rate**law.index
    assert np.all(rel(np.exp(y), twin.exact_rate(tw, excess)) < 4 * EPS * law.yield_stress / excess)


@settings(max_examples=scaled(25), deadline=None)
@given(eta0=st.floats(1e-3, 10.0), lam=st.floats(1e-3, 1e3), index=st.floats(0.05, 1.8),
       centre=st.floats(-25.0, 25.0), width=st.floats(0.05, 12.0))
def test_cumulative_panel_rate_equals_the_pointwise_integrals(eta0, lam, index, centre, width):
    """Property: wherever the cumulative rule accepts a node, it agrees with the point-wise
    error-controlled integral of the other formulation (1 - ratio^3 over t in (0, 1]) within its
    own estimate plus the other's rounding, and the estimates stay within a quarter of the
    table's 1e-14."""
    from tubefsi.rheology._flow_table import stress_natural_rate, stress_natural_rate_panels
    law = CarreauLike(eta0=eta0, lam=lam, index=index)
    p = _panel_nodes(centre - width / 2, centre + width / 2)
    rate = np.exp(p)
    tw = law._stress(rate)
    gamma, estimate, ok = stress_natural_rate_panels(law, p, tw)
    if not np.any(ok):                     # every node left to the point-wise rule
        return
    pointwise, (result, live) = stress_natural_rate(law, rate[ok], tw[ok])
    assert live.size == np.count_nonzero(ok)
    # each within its own estimate (the point-wise one, with its rounding floor, from its
    # quadrature), plus the two roundings of the comparison
    own = np.abs(result.error) / np.abs(result.value)
    assert np.all(rel(gamma[ok], pointwise) < estimate[ok] + own + 4 * EPS)
    assert np.all(estimate[ok] <= 0.25 * TOL)
