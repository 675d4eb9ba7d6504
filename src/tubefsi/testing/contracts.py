"""Contract suites: subclass one and provide the fixture it names.

Every assertion compares two independently computed quantities (a model's
closed form against the base class's generic derivation, a forward map against
its inverse, a coupler against another one, a profile against the ODE it must
satisfy), so a broken law or a broken override fails here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import differentiate

from ..couplers.quadrature import Quadrature
from ..errors import InvalidParameterError, NoSteadyStateError
from ..geometry import Tube
from ..rheology._flow_table import tanh_sinh
from ..solve import max_flow_rate, solve
from ..walls.hyperelastic import HyperelasticWall, ThickWall, ThinWall
from ..walls.linear import ThickLinear, ThinLinear
from .strategies import flow_rates, reduced_thicknesses, strains

__all__ = ["WallContract", "HyperelasticWallContract", "RheologyContract", "CouplerContract"]

_settings = settings(deadline=None, max_examples=25,
                     suppress_health_check=[HealthCheck.function_scoped_fixture])


def _rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


class WallContract:
    """Contract of every :class:`~tubefsi.walls.WallModel`; needs a ``wall`` fixture."""

    #: relative tolerance of the inverse round trip, before the condition number
    round_trip_rtol = 1e-9

    @pytest.fixture
    def wall(self):  # pragma: no cover - provided by the subclass
        raise NotImplementedError

    @staticmethod
    def _skip_rigid(wall):
        if wall.is_rigid:
            pytest.skip("a rigid wall has no tube-law function")

    @staticmethod
    def _top_strain(wall, tb, strain):
        """Keep strains below a locking stretch."""
        lam_max = wall.max_stretch(tb)
        return min(strain, 0.999 * (lam_max - 1.0)) if math.isfinite(lam_max) else strain

    def test_zero_pressure_at_unit_stretch(self, wall):
        self._skip_rigid(wall)
        assert wall.pressure(1.0, 0.3) == 0.0
        assert wall.strain(0.0, 0.3) == 0.0

    @_settings
    @given(e1=strains(1e-6, 10.0), ratio=st.floats(1.001, 10.0), tb=reduced_thicknesses())
    def test_tube_law_is_increasing(self, wall, e1, ratio, tb):
        self._skip_rigid(wall)
        e1 = self._top_strain(wall, tb, e1)
        e2 = self._top_strain(wall, tb, e1 * ratio)
        if e2 <= e1:
            return
        p1, p2 = wall.pressure(1 + e1, tb), wall.pressure(1 + e2, tb)
        assert 0 < p1 < p2
        assert wall.stiffness(1 + e1, tb) > 0
        assert p2 < wall.limit_pressure(tb)

    @_settings
    @given(e=strains(1e-6, 10.0), tb=reduced_thicknesses())
    def test_inverse_round_trip(self, wall, e, tb):
        self._skip_rigid(wall)
        e = self._top_strain(wall, tb, e)
        lam = 1.0 + e
        e = lam - 1.0  # the strain the float stretch really represents
        p = wall.pressure(lam, tb)
        cond = p / (e * wall.stiffness(lam, tb))  # relative condition number of the inverse
        assert _rel(wall.strain(p, tb), e) <= self.round_trip_rtol * max(1.0, cond)
        assert _rel(wall.stretch(p, tb), lam) <= self.round_trip_rtol * max(1.0, cond)

    @_settings
    @given(e=strains(1e-3, 5.0), tb=reduced_thicknesses())
    def test_stiffness_is_the_slope(self, wall, e, tb):
        self._skip_rigid(wall)
        # (kept clear of a maximum stretch, where a vanishing slope defeats finite differences)
        lam = 1.0 + min(e, 0.99 * (wall.max_stretch(tb) - 1.0))
        res = differentiate.derivative(lambda s: wall.pressure(s, tb), lam, initial_step=1e-3 * (lam - 1))
        assert _rel(wall.stiffness(lam, tb), res.df) < 1e-7

    @_settings
    @given(tb=reduced_thicknesses())
    def test_small_strain_is_linear(self, wall, tb):
        self._skip_rigid(wall)
        lam = 1.0 + 1e-8
        e = lam - 1.0
        assert _rel(wall.pressure(lam, tb) / e, wall.small_strain_modulus(tb)) < 1e-6

    def test_vectorized_like_scalars(self, wall):
        self._skip_rigid(wall)
        tb = 0.4
        lam = np.array([[1.0, 1.001], [1.2, self._top_strain(wall, tb, 2.0) + 1.0]])
        p = wall.pressure(lam, tb)
        assert p.shape == lam.shape
        for idx in np.ndindex(lam.shape):
            assert p[idx] == pytest.approx(wall.pressure(float(lam[idx]), tb), rel=1e-14, abs=0)
        assert isinstance(wall.pressure(1.1, tb), float)
        np.testing.assert_allclose(wall.stretch(p, tb), lam, rtol=1e-9)

    def test_limit_pressure(self, wall):
        self._skip_rigid(wall)
        tb = 0.3
        limit = wall.limit_pressure(tb)
        lam_max = wall.max_stretch(tb)
        if math.isinf(limit):
            assert wall.pressure(1.0 + self._top_strain(wall, tb, 100.0), tb) > 10 * wall.pressure(1.1, tb)
            return
        if math.isfinite(lam_max):
            # the tube law ends at a maximum stretch with a bounded pressure (its first peak, or
            # the end of the representable range): the pressure there is the limit
            lam = 1.0 + (lam_max - 1.0) * (1 - 1e-9)
            top = wall.pressure(lam, tb)
            assert top < limit
            assert limit - top <= 2 * (lam_max - lam) * wall.stiffness(lam, tb) + 1e-12 * limit
            with pytest.raises(InvalidParameterError, match="stretch"):
                wall.pressure(lam_max, tb)
        else:
            assert wall.pressure(100.0, tb) < limit
            big = wall.pressure(1e4, tb)
            assert big <= limit
            assert _rel(big, limit) < 1e-6
        with pytest.raises(NoSteadyStateError) as info:
            wall.stretch(limit, tb)
        assert info.value.limit == pytest.approx(limit)

    def test_bad_input_raises(self, wall):
        self._skip_rigid(wall)
        for bad in (0.5, math.nan, math.inf, [1.1, 0.9]):
            with pytest.raises(InvalidParameterError, match="stretch"):
                wall.pressure(bad, 0.3)
        for bad in (-1.0, math.nan):
            with pytest.raises(InvalidParameterError, match="pressure"):
                wall.stretch(bad, 0.3)
        for tb in (0.0, -1.0, math.nan, math.inf):
            with pytest.raises(InvalidParameterError, match="reduced_thickness"):
                wall.pressure(1.1, tb)


class HyperelasticWallContract(WallContract):
    """Adds the limits of §2.5 for :class:`~tubefsi.walls.HyperelasticWall` walls."""

    def test_small_strain_matches_linear_wall(self, wall):
        """Small-strain limit = linear wall with E = 3 mu, nu = 1/2, same theory."""
        assert isinstance(wall, HyperelasticWall)
        mu = float(HyperelasticWall._d2W(wall, np.asarray(1.0))) / 4.0  # generic d2W: W''(1) = 4 mu
        linear = (ThickLinear if isinstance(wall, ThickWall) else ThinLinear)(
            youngs_modulus=3 * mu, poisson_ratio=0.5)
        for tb in (0.01, 0.3, 2.0):
            assert _rel(wall.small_strain_modulus(tb), linear.small_strain_modulus(tb)) < 1e-8

    def test_closed_forms_match_generic_theory(self, wall):
        """Overrides agree with the base class's derivation from dW alone."""
        theory = ThickWall if isinstance(wall, ThickWall) else ThinWall
        for tb in (0.05, 0.5):
            lam = np.array([1.0 + 1e-3, 1.3, 2.0, 3.0])
            lam = np.minimum(lam, 1 + 0.999 * (wall.max_stretch(tb) - 1))
            generic = theory._pressure_at_strain(wall, lam - 1.0, tb)
            np.testing.assert_allclose(wall.pressure(lam, tb), generic, rtol=1e-9)
            np.testing.assert_allclose(wall.stiffness(lam, tb), theory._stiffness(wall, lam, tb), rtol=1e-7)

    def test_thick_tends_to_thin_current(self, wall):
        """As t/a -> 0 the thick law tends to tb * dW(lam) / lam, with an O(t/a) error."""
        if not isinstance(wall, ThickWall):
            pytest.skip("thin wall")
        tbs = (1e-2, 1e-3, 1e-4)
        lam = min(1.5, 1.0 + 0.5 * (min(wall.max_stretch(tb) for tb in tbs) - 1.0))
        errors = []
        for tb in tbs:
            thin = tb * float(wall.dW(lam)) / lam
            errors.append(_rel(wall.pressure(lam, tb), thin))
        assert errors[0] < 0.05
        assert errors[2] < errors[1] / 5 < errors[0] / 25


class RheologyContract:
    """Contract of every :class:`~tubefsi.rheology.Rheology`; needs a ``rheology`` fixture.

    Yield-stress fluids (a ``yield_stress`` field > 0) are held to the same tests, with
    tolerances scaled by the condition number where the yield point makes a quantity
    ill-conditioned, plus :meth:`test_yield_stress`.
    """

    @_settings
    @given(rate=st.floats(-6, 6).map(lambda x: 10.0**x))
    def test_stress_and_shear_rate_invert(self, rheology, rate):
        tau = rheology.stress(rate)
        assert tau > 0
        above = rheology.stress(rate * 1.01)
        assert above > tau
        # relative condition number of the inverse, tau / (rate dtau/drate): large near a yield stress
        cond = max(1.0, tau / (rate * (above - tau) / (0.01 * rate)))
        assert _rel(rheology.shear_rate(tau), rate) < 1e-10 * cond
        assert rheology.apparent_viscosity(rate) == pytest.approx(tau / rate, rel=1e-14)

    @_settings
    @given(radius=st.floats(-6, -2).map(lambda x: 10.0**x), gradient=st.floats(0, 8).map(lambda x: 10.0**x))
    def test_flow_function_inverts_and_matches_rabinowitsch_mooney(self, rheology, radius, gradient):
        q = rheology.flow_rate(radius, gradient)
        tau_w, tau_y = 0.5 * gradient * radius, float(rheology.yield_stress)
        if tau_w <= tau_y:
            assert q == 0.0
            return
        assert q > 0
        assert _rel(rheology.pressure_gradient(q, radius), gradient) < 1e-10
        generic = float(rheology._rabinowitsch_mooney(np.asarray([radius]), np.asarray([gradient]))[0])
        # near the yield point q depends on tau_w - tau_y: condition number tau_w / (tau_w - tau_y)
        assert _rel(q, generic) < 1e-10 * max(1.0, tau_w / (tau_w - tau_y))

    def test_velocity_profile_carries_the_flow_rate(self, rheology):
        radius = 1e-4
        gradient = max(1e5, 8.0 * float(rheology.yield_stress) / radius)   # wall stress >= 4 tau_y
        q = rheology.flow_rate(radius, gradient)
        # flux by the tanh-sinh rule (endpoint singularities such as r^(1 + 1/n) cost nothing),
        # split at the plug radius of a yield-stress fluid; one vectorized velocity call
        t, w = tanh_sinh(7)
        r_plug = min(radius, 2.0 * float(rheology.yield_stress) / gradient)
        r = np.concatenate([r_plug * t, r_plug + (radius - r_plug) * t])
        weights = np.concatenate([r_plug * w, (radius - r_plug) * w])
        flux = float(np.sum(weights * 2 * math.pi * r * rheology.velocity(r, radius, gradient)))
        assert _rel(flux, q) < 1e-10
        assert rheology.velocity(radius, radius, gradient) == 0.0
        r = np.linspace(0, radius, 9)
        v = rheology.velocity(r, radius, gradient)
        assert np.all(np.diff(v) <= 0)
        generic = rheology._velocity_generic(r[:-1], np.full(8, radius), np.full(8, gradient))
        np.testing.assert_allclose(v[:-1], generic, rtol=1e-9)

    def test_yield_stress(self, rheology):
        """No flow below the yield gradient 2 tau_y / R, G(q -> 0+) -> 2 tau_y / R, a rigid plug."""
        tau_y = float(rheology.yield_stress)
        if not tau_y > 0:
            pytest.skip("no yield stress")
        radius = 1e-3
        g_yield = 2.0 * tau_y / radius
        assert rheology.flow_rate(radius, g_yield) == 0.0
        assert rheology.flow_rate(radius, 0.5 * g_yield) == 0.0
        assert rheology.shear_rate(0.5 * tau_y) == 0.0
        assert np.all(rheology.velocity(np.linspace(0, radius, 5), radius, 0.9 * g_yield) == 0.0)
        q_small = rheology.flow_rate(radius, g_yield * (1 + 1e-3))
        assert 0 < q_small
        assert _rel(rheology.pressure_gradient(q_small, radius), g_yield * (1 + 1e-3)) < 1e-9
        assert _rel(rheology.pressure_gradient(1e-12 * q_small, radius), g_yield) < 1e-6
        # plug: constant velocity inside r_p = 2 tau_y / G, decreasing outside
        g = 4.0 * g_yield
        r_plug = 2.0 * tau_y / g
        inside = rheology.velocity(np.linspace(0, r_plug, 7), radius, g)
        np.testing.assert_allclose(inside, inside[0], rtol=1e-12)
        assert rheology.velocity(0.5 * (r_plug + radius), radius, g) < inside[0]

    def test_bad_input_raises(self, rheology):
        with pytest.raises(InvalidParameterError, match="shear_rate"):
            rheology.stress(-1.0)
        with pytest.raises(InvalidParameterError, match="radius"):
            rheology.flow_rate(0.0, 1.0)
        with pytest.raises(InvalidParameterError, match="flow_rate"):
            rheology.pressure_gradient(math.nan, 1e-3)


class CouplerContract:
    """Contract of a coupler on a pair; needs a ``case`` fixture: ``(rheology, wall, coupler)``.

    ``reference`` is compared against (the quadrature coupler by default) with
    relative tolerance ``agreement_rtol``.
    """

    agreement_rtol = 1e-11
    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)

    @pytest.fixture
    def case(self):  # pragma: no cover - provided by the subclass
        raise NotImplementedError

    def _reference(self):
        return Quadrature()

    def _load_scale(self, rheology, wall):
        """A flow rate that strains the tube by O(1) but stays below any maximum flow rate."""
        tb, a, L = self.tube.reduced_thickness, self.tube.radius, self.tube.length
        dp = 0.5 * (1.0 if wall.is_rigid else wall.small_strain_modulus(tb))
        if wall.is_rigid:
            dp = 1e3
        q = float(rheology.flow_rate(a, dp / L))
        return min(q, 0.9 * max_flow_rate(rheology, wall, self.tube))

    def _solve(self, case, **kw):
        rheology, wall, coupler = case
        return solve(rheology, wall, self.tube, coupler=coupler, **kw)

    @settings(deadline=None, max_examples=10, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(fraction=flow_rates(1e-3, 1.0))
    def test_agrees_with_reference_and_inverts(self, case, fraction):
        rheology, wall, coupler = case
        q = fraction * self._load_scale(rheology, wall)
        sol = self._solve(case, flow_rate=q)
        ref = solve(rheology, wall, self.tube, flow_rate=q, coupler=self._reference())
        assert _rel(sol.pressure_drop, ref.pressure_drop) < self.agreement_rtol
        assert _rel(sol.inlet_displacement, ref.inlet_displacement) < self.agreement_rtol or wall.is_rigid
        back = self._solve(case, pressure_drop=sol.pressure_drop)
        assert _rel(back.flow_rate, q) < max(self.agreement_rtol, 1e-11) * 10

    def test_zero_flow_gives_zero_drop(self, case):
        sol = self._solve(case, flow_rate=0.0)
        assert sol.pressure_drop == 0.0 and sol.inlet_displacement == 0.0
        assert self._solve(case, pressure_drop=0.0).flow_rate == 0.0

    def test_array_load_matches_scalar_loads(self, case):
        q = self._load_scale(*case[:2]) * np.array([0.1, 0.5, 0.9])
        sol = self._solve(case, flow_rate=q)
        assert sol.pressure_drop.shape == (3,)
        for i in range(3):
            assert _rel(sol.pressure_drop[i], self._solve(case, flow_rate=float(q[i])).pressure_drop) < 1e-12

    def test_profile_satisfies_tube_law_and_lubrication(self, case):
        rheology, wall, _ = case
        q = 0.7 * self._load_scale(rheology, wall)
        sol = self._solve(case, flow_rate=q)
        L, a, tb = self.tube.length, self.tube.radius, self.tube.reduced_thickness
        z = np.linspace(0, L, 7)
        p = sol.pressure(z)
        assert p[0] == pytest.approx(sol.inlet_pressure, rel=1e-12)
        assert p[-1] == sol.outlet_pressure
        assert np.all(np.diff(p) < 0)
        radius = sol.radius(z)
        if not wall.is_rigid:
            np.testing.assert_allclose(radius, a * wall.stretch(p, tb), rtol=1e-10)
        zi = z[1:-1]
        slope = differentiate.derivative(lambda zz: sol.pressure(zz), zi, initial_step=L * 1e-3).df
        np.testing.assert_allclose(-slope, rheology.pressure_gradient(q, sol.radius(zi)), rtol=1e-7)
        np.testing.assert_allclose(sol.wall_shear_stress(zi), 0.5 * (-slope) * sol.radius(zi), rtol=1e-7)
