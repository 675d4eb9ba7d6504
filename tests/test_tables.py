"""The tables of the separated identity (tubefsi.couplers.tables) and the table stack they are
built on (tubefsi.numerics.chebyshev, whose internals its tests read).

References: the direct, error-controlled path of the same engine, reached through the public API
by the same law written without a declared shape/scale split (the tables must reproduce it to its
own accuracy); closed forms and NumPy's Chebyshev module for the interpolants; mpmath for the
thin reference-thickness law.
"""

from __future__ import annotations

import math

import attrs
import numpy as np
import pytest

import tubefsi
from tubefsi.numerics.chebyshev import PiecewisePolynomial, fit_piecewise
from tubefsi.registry import rheologies, walls

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)

WALLS = [
    walls["thick-neo-hookean"](shear_modulus=2e3),
    walls["thin-neo-hookean"](shear_modulus=2e3),
    walls["thick-mooney-rivlin"](c1=1.5e3, c2=-0.5e3),
    walls["thick-demiray"](shear_modulus=2e3, stiffening=2.0),
    walls["thin-demiray"](shear_modulus=1e3, stiffening=20.0),
    walls["thick-gent"](shear_modulus=2e3, locking_parameter=3.0),
    walls["thick-yeoh"](c1=1e3, c2=50.0, c3=2.0),
]


def undeclared(wall):
    """The same law and parameters, in a subclass that declares no shape/scale split (no table)."""
    cls = type(wall)
    plain = type(f"Undeclared{cls.__name__}", (cls,), {"_shape_key": lambda self: None, "__module__": __name__})
    return plain(**{f.name: getattr(wall, f.name) for f in attrs.fields(cls) if f.init})


def _curve(wall):
    q_max = tubefsi.max_flow_rate(FLUID, wall, TUBE)
    top = 0.9 * q_max if np.isfinite(q_max) else 5e-9
    return np.concatenate([[0.0], np.geomspace(1e-6 * top, top, 400)])


@pytest.mark.parametrize("wall", WALLS, ids=repr)
def test_table_reproduces_the_direct_path(wall):
    """Curve and single points from the table against the direct path (the same law declaring no
    split), to 1e-13 relative (up to 0.9 of the maximum flow rate; nearer to it the problem's
    condition number grows); the maximum flow rate and a pressure-controlled solve too."""
    q = _curve(wall)
    plain = undeclared(wall)
    fast = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q, on_infeasible="nan")
    slow = tubefsi.solve(FLUID, plain, TUBE, flow_rate=q, on_infeasible="nan")
    np.testing.assert_allclose(fast.pressure_drop, slow.pressure_drop, rtol=1e-13, atol=0)
    np.testing.assert_allclose(fast.inlet_displacement, slow.inlet_displacement, rtol=1e-13, atol=0)
    for qi in q[[1, 200, -1]]:
        one = tubefsi.solve(FLUID, wall, TUBE, flow_rate=float(qi))
        assert one.pressure_drop == pytest.approx(float(slow.pressure_drop[np.searchsorted(q, qi)]), rel=1e-13)
    assert tubefsi.max_flow_rate(FLUID, wall, TUBE) == pytest.approx(tubefsi.max_flow_rate(FLUID, plain, TUBE),
                                                                   rel=1e-13)
    dp = slow.pressure_drop[1::100]
    np.testing.assert_allclose(tubefsi.solve(FLUID, wall, TUBE, pressure_drop=dp).flow_rate,
                               tubefsi.solve(FLUID, plain, TUBE, pressure_drop=dp).flow_rate, rtol=1e-12)


@pytest.mark.parametrize("wall", [w for w in WALLS if type(w).__name__ in ("ThickNeoHookean", "ThickMooneyRivlin")],
                         ids=repr)
def test_table_reproduces_the_direct_path_up_to_the_maximum_flow_rate(wall):
    """Where the inlet stretch runs away (the table's panels in the runaway variable, up to
    q_max (1 - 1e-9)), curve and single points against the direct path (the same law declaring
    no split): the pressure drop to 1e-13, the inlet displacement to 1e-13 times the problem's
    condition number, which grows as 1 / (1 - q/q_max)."""
    q_max = tubefsi.max_flow_rate(FLUID, wall, TUBE)
    gap = np.geomspace(1e-9, 0.5, 120)
    q = q_max * (1.0 - gap)
    plain = undeclared(wall)
    fast = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)
    slow = tubefsi.solve(FLUID, plain, TUBE, flow_rate=q)
    np.testing.assert_allclose(fast.pressure_drop, slow.pressure_drop, rtol=1e-13, atol=0)
    bound = 1e-13 / gap
    assert np.all(np.abs(fast.inlet_displacement / slow.inlet_displacement - 1) <= bound)
    for i in (0, 30, 60, 119):
        one = tubefsi.solve(FLUID, wall, TUBE, flow_rate=float(q[i]))
        assert abs(one.inlet_displacement / slow.inlet_displacement[i] - 1) <= bound[i]
        assert one.pressure_drop == pytest.approx(float(slow.pressure_drop[i]), rel=1e-13)


def test_one_table_serves_every_modulus_and_the_cache_is_bounded_and_clearable():
    """Walls of one shape share a table (a hit), another shape or t/a builds its own (a miss);
    clearing changes nothing but the time."""
    tubefsi.cache_clear()
    base = tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, flow_rate=1e-9).pressure_drop
    info = tubefsi.cache_info()
    assert (info.misses, info.size) == (1, 1)
    tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=3e3), TUBE, flow_rate=1e-9)
    assert tubefsi.cache_info().hits >= 1 and tubefsi.cache_info().size == 1
    tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=3e3), tubefsi.Tube(radius=1e-4, thickness=2e-5,
                                                                                     length=1e-2), flow_rate=1e-9)
    assert tubefsi.cache_info().size == 2
    assert tubefsi.cache_info().maxsize >= 2
    tubefsi.cache_clear()
    assert tubefsi.cache_info().size == 0
    again = tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, flow_rate=1e-9).pressure_drop
    assert again == base


# ------------------------------------------------------------------ the table stack (numerics)
@pytest.mark.parametrize("fn, lo, hi", [(np.sin, 0.0, 10.0), (np.exp, -5.0, 5.0), (np.log1p, 0.0, 100.0)])
@pytest.mark.parametrize("degree", [8, 16])
def test_piecewise_fit_meets_its_tolerance(fn, lo, hi, degree):
    poly, err = fit_piecewise(fn, lo, hi, degree=degree, tol=1e-14, relative=True)
    x = np.linspace(lo, hi, 10001)
    scale = np.maximum(1.0, np.abs(fn(x)))
    assert np.max(np.abs(poly(x) - fn(x)) / scale) < 4e-14
    assert err < 1e-14
    if fn is np.sin:
        np.testing.assert_allclose(poly.derivative()(x), np.cos(x), atol=1e-11)


def test_piecewise_fit_of_several_outputs_shares_the_panels():
    poly, _ = fit_piecewise(lambda x: np.stack([np.sin(x), np.cos(3 * x)]), 0.0, 5.0, degree=8, tol=1e-14)
    x = np.linspace(0.0, 5.0, 777)
    values = poly.evaluate(x)
    np.testing.assert_allclose(values[0], np.sin(x), atol=2e-14)
    np.testing.assert_allclose(values[1], np.cos(3 * x), atol=2e-14)
    np.testing.assert_array_equal(poly(x, output=1), values[1])


def test_piecewise_fit_gives_up_honestly():
    """A function it cannot resolve (an infinite slope inside, a NaN) gives no interpolant."""
    poly, err = fit_piecewise(lambda x: np.sqrt(np.abs(x - 0.3)), 0.0, 1.0, max_panels=64)
    assert poly is None and err == math.inf
    assert fit_piecewise(lambda x: np.where(x > 0.5, np.nan, x), 0.0, 1.0)[0] is None


def test_the_scalar_evaluation_is_the_array_evaluation_bit_for_bit():
    """One float (plain Python) and arrays (NumPy) run the same operations: the same bits, at
    random points, at the ends and at every break."""
    poly, _ = fit_piecewise(lambda x: np.stack([np.log1p(np.exp(x)), np.sin(x)]), -20.0, 10.0, degree=8, tol=1e-14)
    x = np.concatenate([np.random.default_rng(0).uniform(-20, 10, 500), poly.breaks])
    values = poly.evaluate(x)
    for i, xi in enumerate(x):
        assert poly.scalar(float(xi)) == values[:, i].tolist()


@pytest.mark.parametrize("decay", [0.3, 0.5])
def test_lookup_against_numpy_chebval(decay):
    """Random panels and coefficients decaying as a table's do: the values are NumPy's chebval in
    each panel's coordinate (the monomial form's rounding stays within 1e-13 of the coefficients'
    size; a table checks its own at its check points)."""
    rng = np.random.default_rng(5)
    breaks = np.cumsum(np.concatenate([[0.0], rng.uniform(0.01, 1.0, 40)]))
    breaks[20:] += 0.0                                # uneven panels
    coef = rng.standard_normal((40, 9)) * decay ** np.arange(9)
    poly = PiecewisePolynomial(breaks, coef)
    x = rng.uniform(breaks[0], breaks[-1], 3000)
    j = np.clip(np.searchsorted(breaks, x, side="right") - 1, 0, 39)
    t = (2 * x - breaks[j] - breaks[j + 1]) / (breaks[j + 1] - breaks[j])
    want = np.array([np.polynomial.chebyshev.chebval(ti, coef[k]) for ti, k in zip(t, j)])
    np.testing.assert_allclose(poly(x), want, rtol=0, atol=1e-13 * np.abs(coef).sum(axis=1).max())


def test_thin_reference_pressure_from_the_log_stretch_against_mpmath():
    r"""The thin reference-thickness law from :math:`v = \ln\lambda` (:math:`-\lambda\,\mathrm{expm1}(-4v)`
    with :math:`\lambda = 1 + \mathrm{expm1}(v)`, the curve path) against :math:`\lambda - \lambda^{-3}` in
    40-digit mpmath, from :math:`v = 10^{-12}` to 650, within 4 ulp; the current-thickness law and
    other arguments fall back to the strain form exactly."""
    import mpmath
    with mpmath.workdps(40):
        wall = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="reference")
        v = np.concatenate([np.geomspace(1e-12, 650.0, 400), [3e-9, 0.5, 2.0]])
        got = wall._pressure_at_log_stretch(v, np.expm1(v), 0.3)
        lam = [mpmath.exp(mpmath.mpf(float(x))) for x in v]
        want = np.array([float(2e3 * mpmath.mpf(0.3) * (s - s**-3)) for s in lam])
    assert np.max(np.abs(got / want - 1)) <= 4 * 2.2e-16
    current = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="current")
    assert np.array_equal(current._pressure_at_log_stretch(v[:50], np.expm1(v[:50]), 0.3),
                          current._pressure_at_strain(np.expm1(v[:50]), 0.3))
    far = np.array([1.0, 701.0])                         # past v = 700: the strain form
    assert np.array_equal(wall._pressure_at_log_stretch(far, np.expm1(far), 0.3),
                          wall._pressure_at_strain(np.expm1(far), 0.3))
