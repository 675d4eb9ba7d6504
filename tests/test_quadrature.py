"""The error-controlled adaptive quadrature every default path uses (tubefsi.numerics.quadrature).

References: the Kronrod rule's exactness for polynomials (closed form 1/(d+1)), numpy's
Gauss–Legendre nodes, and mpmath at 30 digits for the integrals.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubefsi.errors import AccuracyWarning
from tubefsi.numerics.quadrature import (GAUSS_WEIGHTS, KRONROD_NODES, KRONROD_WEIGHTS, adaptive, adaptive_to_pole,
                                         unit_integral, warn_unconverged)
from tubefsi.numerics.roots import solve_increasing
from tubefsi.numerics.spectral import LOBATTO_NODES, solve_integral
from tubefsi.testing.profiles import scaled


def test_kronrod_rule_is_exact_to_degree_31_and_embeds_gauss_10():
    t = 2.0 * KRONROD_NODES - 1.0                       # back on [-1, 1]: mean of t^d is (1 + (-1)^d) / (2 (d + 1))
    for degree in range(32):
        assert abs(KRONROD_WEIGHTS @ t**degree - (1 + (-1) ** degree) / (2.0 * (degree + 1))) < 2e-16
    assert abs(KRONROD_WEIGHTS @ t**32 - 1.0 / 33) > 1e-12                # and not beyond
    x, w = np.polynomial.legendre.leggauss(10)
    np.testing.assert_allclose(KRONROD_NODES[1::2], 0.5 * (x + 1.0), rtol=0, atol=2e-16)
    np.testing.assert_allclose(GAUSS_WEIGHTS, 0.5 * w, rtol=0, atol=2e-16)


@pytest.mark.parametrize("b", [0.0, 1.0, 20.0, 100.0, 400.0])
def test_fast_growth_reaches_the_tolerance(b):
    """exp(b x^2) on [0, 1]: growth by e^400 across the interval is still resolved."""
    r = adaptive(lambda x, i: np.exp(b * x * x), 0.0, 1.0)
    with mpmath.workdps(30):
        ref = mpmath.quad(lambda x: mpmath.exp(b * x * x), [0, 0.5, 0.9, 1])
    assert r.converged
    assert abs(r.value / ref - 1) < 1e-14
    assert r.error <= 1e-14 * abs(r.value)


@settings(deadline=None, max_examples=scaled(30))
@given(st.lists(st.tuples(st.floats(0.0, 3.0), st.floats(0.1, 30.0)), min_size=1, max_size=20))
def test_vectorized_equals_one_point_at_a_time(cases):
    k = np.array([c[0] for c in cases])
    upper = np.array([c[1] for c in cases])

    def f(x, i):
        return np.exp(-k[i, None] * x) * np.sqrt(1.0 + np.exp(x))

    together = adaptive(f, 0.0, upper, panels=np.ceil(upper / 2))
    for j in range(k.size):
        alone = adaptive(lambda x, i: np.exp(-k[j] * x) * np.sqrt(1.0 + np.exp(x)), 0.0, upper[j],
                         panels=np.ceil(upper[j] / 2))
        assert together.value[j] == pytest.approx(float(alone.value), rel=1e-14, abs=0)
    assert np.all(together.converged)


@pytest.mark.parametrize("distance", [1e-3, 1e-8, 1e-13])
def test_pole_beyond_the_end_is_graded(distance):
    """1/(pole - x) on [0, 1] with the pole at 1 + distance: the log substitution resolves it, to
    the accuracy the abscissae allow (x near 1 is rounded to eps, the distance to the pole is not
    finer), and the reported estimate covers the true error."""
    pole = 1.0 + distance
    r = adaptive_to_pole(lambda x, i: 1.0 / (pole - x), 0.0, 1.0, pole, gap=pole - 1.0)
    with mpmath.workdps(30):
        exact = mpmath.log(mpmath.mpf(pole) / (mpmath.mpf(pole) - 1))
    assert r.converged
    assert abs(r.value - exact) <= r.error
    assert r.error <= max(1e-14, 100 * np.finfo(float).eps / distance) * abs(r.value)
    assert r.panels < 60


def test_noise_is_reported_not_hidden():
    """An integrand with relative noise 1e-9 cannot be integrated to 1e-14: converged is False,
    the estimate says about 1e-9, and refinement stops instead of running to the panel limit."""
    rng = np.random.default_rng(1)

    def noisy(x, i):
        return np.exp(x) * (1.0 + 1e-9 * rng.standard_normal(x.shape))

    r = adaptive(noisy, 0.0, 1.0)
    assert not r.converged
    assert 1e-11 < r.error / r.value < 1e-7
    assert r.panels < 2048
    assert abs(r.value / (np.e - 1.0) - 1) < 1e-8
    with pytest.warns(AccuracyWarning, match="estimated relative error"):
        warn_unconverged("the test integral", r)
    import warnings

    with warnings.catch_warnings():   # only the points the caller asks about count
        warnings.simplefilter("error")
        warn_unconverged("the test integral", r, where=np.zeros(np.shape(r.converged), dtype=bool))


@pytest.mark.parametrize("f, exact", [
    (lambda t: 1.0 / (1.0 + t * t), mpmath.pi / 4),
    (lambda t: np.sqrt(1.0 + t), (2 * mpmath.sqrt(8) - 2) / 3),
    (lambda t: t ** (1 / 0.3), mpmath.mpf(0.3) / mpmath.mpf(1.3)),
], ids=["1/(1+t^2)", "sqrt(1+t)", "t^(1/0.3)"])
def test_a_smooth_unit_integral_takes_its_initial_panels_only(f, exact):
    """unit_integral's initial panels (z = -ln t from 0 to 40: width 1 next to t = 1, wider toward
    t = 0) meet 1e-15 for a smooth integrand without bisecting one; with an absolute rounding of
    the integrand given as well (its floor taken without evaluating the integrand again)."""
    for rounding in (None, lambda idx: np.full(idx.shape, 2 * np.finfo(float).eps)):
        r = unit_integral(lambda t, i: f(t), 1, rounding=rounding)
        assert r.converged[0] and r.panels[0] == 11
        assert abs(r.value[0] - float(exact)) <= 2e-15 * float(exact)


def test_graded_initial_panels_are_the_equal_ones_where_they_coincide():
    """``adaptive(breaks=)`` at the ends of equal panels gives the bits of ``panels=``."""
    def f(x, i):
        return np.exp(-x) * np.cos(3 * x)

    equal = adaptive(f, np.array([0.0, 1.0]), np.array([40.0, 5.0]), panels=4)
    graded = adaptive(f, np.array([0.0, 1.0]), np.array([40.0, 5.0]), breaks=(0.0, 0.25, 0.5, 0.75, 1.0))
    assert np.array_equal(equal.value, graded.value) and np.array_equal(equal.error, graded.error)


def test_zero_width_and_reversed_intervals():
    r = adaptive(lambda x, i: np.cos(x), np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.0, 2.0]))
    np.testing.assert_allclose(r.value, [0.0, -np.sin(1.0), 0.0], rtol=1e-15, atol=0)
    assert np.all(r.converged)


def test_newton_reports_where_its_answer_was_evaluated():
    """``solve_increasing(evaluated=)`` marks the points whose answer is the last evaluated point
    (so its quadrature error estimate is known): x^3 = t from a start at the root and far from it."""
    target = np.array([8.0, 27.0, 1e-3])
    seen = []

    def F(x, i):
        seen.append(x.copy())
        return x**3

    evaluated = np.zeros(3, dtype=bool)
    x, ok = solve_increasing(F, lambda x, i: 3 * x**2, target, guess=np.array([2.0, 1.0, 0.1]), evaluated=evaluated)
    np.testing.assert_allclose(x, np.cbrt(target), rtol=1e-15)
    assert ok.all()
    # the first point starts on its root: its answer is that evaluation
    assert evaluated[0] and x[0] == 2.0
    for k in np.flatnonzero(evaluated):      # every marked answer was evaluated as it stands
        assert any(np.any(values == x[k]) for values in seen)


# ------------------------------------------------------------------ solve_integral (one-shot Chebyshev)
@pytest.mark.parametrize("degree", [12, 16])
def test_interpolation_maps_against_numpy_chebyshev(degree):
    """The value -> coefficient map is the Chebyshev interpolant at the Lobatto nodes (numpy's
    chebfit through the same n + 1 points), its antiderivative vanishes at -1, and the
    cumulative rows are that antiderivative at the nodes (numpy's chebval)."""
    from tubefsi.numerics.spectral import lobatto_rule as _lobatto_rule
    rule = _lobatto_rule(degree)
    rng = np.random.default_rng(3)
    y = rng.standard_normal((5, degree + 1))
    t = 2.0 * rule.nodes - 1.0
    if degree == 16:
        np.testing.assert_array_equal(rule.nodes, LOBATTO_NODES)
    coef = (rule.matrix[rule.coef] @ y.T).T
    ref = np.array([np.polynomial.chebyshev.chebfit(t, row, degree) for row in y])
    np.testing.assert_allclose(coef, ref, rtol=0, atol=1e-13)
    anti = (rule.matrix[rule.anti] @ y.T).T
    np.testing.assert_allclose(np.polynomial.chebyshev.chebval(-1.0, anti.T), 0.0, atol=1e-14)
    np.testing.assert_allclose(np.polynomial.chebyshev.chebder(anti.T).T, ref, rtol=0, atol=1e-13)
    cumulative = (rule.matrix[rule.cumulative] @ y.T).T
    np.testing.assert_allclose(cumulative, np.polynomial.chebyshev.chebval(t, anti.T), rtol=0, atol=1e-13)


METHODS = ["clenshaw", "barycentric"]


@pytest.mark.parametrize("method", METHODS)
@settings(deadline=None, max_examples=scaled(30))
@given(st.floats(0.0, 4.0), st.floats(0.2, 3.0), st.floats(0.01, 0.6))
def test_solved_points_meet_the_tolerance_against_mpmath(method, k, c, target):
    """int_0^x e^{ku} (c + u) du = T, solved where the estimate says so, against mpmath's root,
    by either way of finding the root on the interpolant."""
    x, solved, short = solve_integral(lambda u, i: np.exp(k * u) * (c + u), np.array([target]),
                                      np.array([1.5 * target / c]), method=method)
    with mpmath.workdps(40):
        f = lambda xx: mpmath.quad(lambda u: mpmath.exp(k * u) * (c + u), [0, xx]) - target
        root = mpmath.findroot(f, target / c)
    if solved[0]:
        assert abs(x[0] / float(root) - 1) < 4e-15
    else:                         # not solved: either the root is beyond 1.5 T / c or the tail said no
        assert short[0] or float(root) < 1.5 * target / c


@pytest.mark.parametrize("method", METHODS)
def test_what_is_not_resolved_is_left_to_the_caller(method):
    """A kink (|u - 0.3|), a steep exponential, a non-positive and a non-finite integrand, and
    a root beyond the interval: none of them is answered."""
    target = np.array([0.3, 0.5, 0.5, 0.5, 5.0])
    upper = np.array([1.0, 1.0, 1.0, 1.0, 1.0])

    def f(u, i):
        out = np.empty(u.shape)                # nodes x points
        out[:, 0] = 0.2 + np.abs(u[:, 0] - 0.3)
        out[:, 1] = 0.01 * np.exp(40.0 * u[:, 1])
        out[:, 2] = u[:, 2] - 0.5
        out[:, 3] = np.where(u[:, 3] > 0.9, np.inf, 1.0)
        out[:, 4] = 1.0
        return out

    x, solved, short = solve_integral(f, target, upper, method=method)
    assert not np.any(solved)
    assert list(short) == [False, False, False, False, True]


@pytest.mark.parametrize("method", METHODS)
def test_vectorized_solve_equals_one_at_a_time(method):
    """A point's answer is the same bits alone and in a batch (and the closed form's)."""
    k = np.array([0.5, 2.0, 3.5])
    target = np.array([0.05, 0.2, 0.3])
    x, solved, _ = solve_integral(lambda u, i: np.exp(k[i] * u), target, 1.5 * target, method=method)
    for j in range(3):
        xj, sj, _ = solve_integral(lambda u, i: np.exp(k[j] * u), target[j:j + 1], 1.5 * target[j:j + 1],
                                   method=method)
        assert sj[0] == solved[j]
        assert xj[0] == x[j]
    # the closed form: (e^{kx} - 1)/k = T
    np.testing.assert_allclose(x[solved], (np.log1p(k * target) / k)[solved], rtol=4e-15)


@pytest.mark.parametrize("degree", [16, 24])
def test_barycentric_rule_against_numpy_chebyshev(degree):
    """The constants of the barycentric root: its matrix's rows are the interpolant's last three
    Chebyshev coefficients, its antiderivative at the nodes and at s_* (numpy's chebfit, chebint
    and chebval through the same points), and the n + 2 weights interpolate a polynomial of
    degree n + 1 exactly (against numpy's polyval off the nodes)."""
    from tubefsi.numerics.spectral import _barycentric_rule, barycentric, lobatto_rule
    matrix, nodes, weights, lobatto = _barycentric_rule(degree)
    rule = lobatto_rule(degree)
    y = np.random.default_rng(5).standard_normal(degree + 1)
    coef = np.polynomial.chebyshev.chebfit(rule.t, y, degree)
    anti = np.polynomial.chebyshev.chebint(coef, lbnd=-1.0)
    rows = matrix @ y
    np.testing.assert_allclose(rows[:3], coef[-3:], rtol=0, atol=1e-13)
    np.testing.assert_allclose(rows[3:], np.polynomial.chebyshev.chebval(nodes, anti), rtol=0, atol=1e-13)
    poly = np.random.default_rng(6).standard_normal(degree + 2)      # degree n + 1, on [-1, 1]
    at = np.array([-0.97, -0.31, 0.013, 0.55, 0.999])
    got = barycentric(weights, at[:, None] - nodes, np.polynomial.polynomial.polyval(nodes, poly))
    np.testing.assert_allclose(got, np.polynomial.polynomial.polyval(at, poly), rtol=0, atol=1e-11)
    got = barycentric(lobatto, at[:, None] - rule.t, np.polynomial.polynomial.polyval(rule.t, poly[:-1]))
    np.testing.assert_allclose(got, np.polynomial.polynomial.polyval(at, poly[:-1]), rtol=0, atol=1e-11)


def test_barycentric_root_with_the_target_on_a_node():
    """The target is a constant integrand's integral at a Lobatto node, to the bit (the rule's own
    cumulative row there): the start's interpolant gives 0/0 and Newton's method starts from the
    interval's end instead; the root is still the node (closed form T / c)."""
    from tubefsi.numerics.spectral import _barycentric_rule, lobatto_rule
    nodes = lobatto_rule(24).nodes
    on = [12, 18, 23]
    target = 0.5 * (_barycentric_rule(24)[0] @ np.full(25, 2.0))[3:][on]      # (X / 2 = 1/2)
    x, solved, _ = solve_integral(lambda u, i: np.full(u.shape, 2.0), target, np.ones(3), degree=24,
                                  method="barycentric")
    assert solved.all()
    np.testing.assert_allclose(x, nodes[on], rtol=1e-15)


def test_hermite_root_of_a_cubic():
    """A cubic is its own Hermite interpolant: the root of s^3 + s (rise 2, slopes 1 and 4) = goal
    against numpy's polynomial roots."""
    from tubefsi.numerics.spectral import hermite_root
    goal = np.array([0.1, 0.7, 1.3, 1.9])
    s = hermite_root(np.full(4, 2.0), goal, np.ones(4), np.full(4, 4.0), iterations=8)
    expected = [np.roots([1.0, 0.0, 1.0, -g])[np.abs(np.roots([1.0, 0.0, 1.0, -g]).imag) < 1e-12].real[0] for g in goal]
    np.testing.assert_allclose(s, expected, rtol=1e-14)
