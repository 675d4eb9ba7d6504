"""Contract suites: subclass one and provide the fixture it names.

Every assertion compares two independently computed quantities (a model's
closed form against the base class's generic derivation, a forward map against
its inverse, a coupler against another one, a profile against the ODE it must
satisfy), so a broken law or a broken override fails here.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import differentiate
from scipy.integrate import tanhsinh
from scipy.optimize import elementwise

from ..couplers.quadrature import Quadrature
from ..errors import AccuracyWarning, BucklingError, InvalidParameterError, NoSteadyStateError
from ..geometry import Tube
from ..numerics.cache import plain
from ..solve import max_flow_rate, solve
from .reference.quadrature import tanh_sinh
from ..walls.hyperelastic import HyperelasticWall, ThickWall, ThinWall
from ..walls.linear import ThickLinear, ThinLinear
from .profiles import scaled
from .strategies import examples, flow_rates, reduced_thicknesses, strains

__all__ = ["WallContract", "HyperelasticWallContract", "RheologyContract", "CouplerContract", "AccuracyContract",
           "BruteForce", "brute_force", "accuracy_cases"]

# max_examples through scaled(): as written under the ci profile, ten times it under explore
_settings = settings(deadline=None, max_examples=scaled(25),
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
        low = wall.min_stretch(0.3)                 # 1 for a wall that only inflates
        below = 0.5 * low if low > 0 else -0.5
        for bad in (below, math.nan, math.inf, [1.1, below]):
            with pytest.raises(InvalidParameterError, match="stretch"):
                wall.pressure(bad, 0.3)
        for bad in ((-1.0, math.nan) if wall.min_pressure(0.3) == 0 else (math.nan,)):
            with pytest.raises(InvalidParameterError, match="pressure"):
                wall.stretch(bad, 0.3)
        for tb in (0.0, -1.0, math.nan, math.inf):
            with pytest.raises(InvalidParameterError, match="reduced_thickness"):
                wall.pressure(1.1, tb)


    def test_shape_scale_split(self, wall):
        r"""A wall that declares its shape/scale split, so that one table serves every scale
        (``docs/theory.md``): :math:`P = s\,\hat P` with :math:`\hat P` its unit wall's law, the
        unit wall of scale 1 and of the wall's shape, the shape plain values, the maximum stretch
        the unit wall's. Reference: the wall's own tube law."""
        self._skip_rigid(wall)
        shape = wall._shape_key()
        if shape is None:
            pytest.skip("no shape/scale split declared: no table is shared between instances")
        assert plain(shape), f"the shape {shape!r} is not plain values (numbers, strings, tuples)"
        unit = wall._unit_wall()
        assert type(unit) is type(wall)
        assert unit._shape_key() == shape
        assert _rel(unit._pressure_scale(), 1.0) <= 1e-15
        scale = wall._pressure_scale()
        for tb in (0.05, 0.3, 1.0):
            assert _rel(unit.max_stretch(tb), wall.max_stretch(tb)) <= 1e-13 or unit.max_stretch(tb) == math.inf
            for e in (1e-6, 0.1, 1.0, 5.0):
                lam = 1.0 + self._top_strain(wall, tb, e)
                assert _rel(scale * unit.pressure(lam, tb), wall.pressure(lam, tb)) <= 1e-12, (tb, lam)

    @_settings
    @given(fraction=st.floats(1e-6, 1.0), tb=reduced_thicknesses())
    def test_negative_branch(self, wall, fraction, tb):
        """A wall that holds negative transmural pressures: increasing down to its minimum
        pressure, the inverse round trip, and a BucklingError (naming the bound) beyond."""
        self._skip_rigid(wall)
        low = wall.min_pressure(tb)
        if low == 0:
            return
        p = fraction * (low if math.isfinite(low) else -1e3 * wall.small_strain_modulus(tb))
        e = wall.strain(p, tb)
        assert -1.0 < e < 0.0
        assert wall.min_stretch(tb) <= (1.0 + e) * (1 + 1e-12)     # (the inverse at min_pressure, rounded)
        assert wall.strain(0.5 * p, tb) > e
        assert wall.stiffness(1.0 + e, tb) > 0
        back = wall.pressure(1.0 + e, tb)
        cond = abs(back / ((1.0 + e - 1.0) * wall.stiffness(1.0 + e, tb)))
        assert _rel(back, p) <= self.round_trip_rtol * max(1.0, cond) + 4 * abs(e - (1.0 + e - 1.0)) / abs(e) * cond
        if math.isfinite(low):
            with pytest.raises(BucklingError) as info:
                wall.strain(1.01 * low, tb)
            assert info.value.limit == pytest.approx(low)


class HyperelasticWallContract(WallContract):
    """Adds the limits of §2.5 for :class:`~tubefsi.walls.HyperelasticWall` walls."""

    def test_small_strain_matches_linear_wall(self, wall):
        """Small-strain limit = linear wall with E = 3 mu, nu = 1/2, same theory (isotropic materials)."""
        assert isinstance(wall, HyperelasticWall)
        if not getattr(wall, "isotropic", True):
            pytest.skip("an anisotropic material")
        mu = float(HyperelasticWall._d2W(wall, np.asarray(1.0))) / 4.0  # generic d2W: W''(1) = 4 mu
        linear = (ThickLinear if isinstance(wall, ThickWall) else ThinLinear)(
            youngs_modulus=3 * mu, poisson_ratio=0.5)
        for tb in (0.01, 0.3, 2.0):
            assert _rel(wall.small_strain_modulus(tb), linear.small_strain_modulus(tb)) < 1e-8

    def test_closed_forms_match_generic_theory(self, wall):
        """Overrides agree with the base class's derivation from dW alone (where the installed
        tube's rest state is homogeneous: a pre-stretched fibre wall's is not, and its thick law
        is not the Lamé integral of its membrane law)."""
        theory = ThickWall if isinstance(wall, ThickWall) else ThinWall
        if theory is ThickWall and not wall._homogeneous_rest():
            pytest.skip("a rest state that is not homogeneous")
        for tb in (0.05, 0.5):
            lam = np.array([1.0 + 1e-3, 1.3, 2.0, 3.0])
            lam = np.minimum(lam, 1 + 0.999 * (wall.max_stretch(tb) - 1))
            generic = theory._pressure_at_strain(wall, lam - 1.0, tb)
            np.testing.assert_allclose(wall.pressure(lam, tb), generic, rtol=1e-9)
            np.testing.assert_allclose(wall.stiffness(lam, tb), theory._stiffness(wall, lam, tb), rtol=1e-7)

    def test_thick_tends_to_thin_current(self, wall):
        """As t/a -> 0 the thick law tends to tb * dW(lam) / lam, with an O(t/a) error: the
        difference falls at least fivefold per decade of t/a. Its coefficient is the law's own
        (about 0.77 t/a for neo-Hookean, 43–61 t/a for a stiff fibre law, at stretch 1.5), so at
        t/a = 0.01 only a difference below 1 (the thin law is the leading term) is asked."""
        if not isinstance(wall, ThickWall):
            pytest.skip("thin wall")
        tbs = (1e-2, 1e-3, 1e-4)
        lam = min(1.5, 1.0 + 0.5 * (min(wall.max_stretch(tb) for tb in tbs) - 1.0))
        errors = []
        for tb in tbs:
            thin = tb * float(wall.dW(lam)) / lam
            errors.append(_rel(wall.pressure(lam, tb), thin))
        assert errors[0] < 1.0
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

    @settings(deadline=None, max_examples=scaled(10), suppress_health_check=[HealthCheck.function_scoped_fixture])
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
        # the tube the flow sees (an axially pre-stretched wall installs it longer and narrower)
        L, a, tb = sol.tube.length, sol.tube.radius, sol.tube.reduced_thickness
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



# ---------------------------------------------------------------------------- brute force
_EPS = float(np.finfo(float).eps)
#: the strain rise of the first panel (above the outlet), where the tube law is nearly linear
_FIRST_RISE = 1e-3


@dataclasses.dataclass(frozen=True)
class _Settings:
    """One discretization of the brute force: tolerances, rules and break-point ratios."""

    quad_rtol: float        # tanh-sinh relative tolerance on each panel
    gauss_nodes: int        # Gauss-Legendre nodes on the first panel
    root_xrtol: float       # relative tolerance of every root (stretch, pressure rise, flow rate)
    strain_ratio: float     # break points geometric in the strain rise, this ratio apart ...
    pressure_ratio: float   # ... and, between those, in the pressure rise, at most this ratio apart


#: The brute force runs twice, at two tolerances on two sets of break points; the relative
#: difference of the two answers is its error estimate, and the tighter run is the answer.
_LOOSE = _Settings(quad_rtol=1e-13, gauss_nodes=10, root_xrtol=1e-14, strain_ratio=3.0, pressure_ratio=30.0)
_TIGHT = _Settings(quad_rtol=1e-14, gauss_nodes=16, root_xrtol=4 * _EPS, strain_ratio=2.0, pressure_ratio=16.0)


class _Separated:
    r"""One run of the brute force on one scene (see :func:`brute_force`).

    With :math:`d = p - p_{out}` the pressure rise above the outlet, lubrication
    (``docs/theory.md``, section "Lubrication") separates in the pressure itself:

    .. math:: F(d; q) \equiv \int_0^{d} \frac{dx}{G\big(q,\, a\lambda(p_{out} + x)\big)} = L - z .

    ``F`` is summed over panels whose break points are geometric in the strain rise (down to a
    rise of 1e-3) and in the gap to a maximum stretch, and, between those, in the pressure rise:
    Gauss–Legendre on the first panel (where the law is nearly linear), tanh–sinh
    (:func:`scipy.integrate.tanhsinh`) on the others. The stretch :math:`\lambda(p)` at every
    node is a bracketing root (Chandrupatla, :func:`scipy.optimize.elementwise.find_root`) of the
    forward law ``wall.pressure``. Flow-controlled, the panels are laid from the outlet up until
    ``F`` reaches ``L``; the inlet and profile pressures are then found inside their panels by
    Newton's method with the exact slope ``1/G``. Pressure-controlled, the panels end at the
    given drop and the flow rate is a bracketing root of ``F(dp; q) = L``.
    """

    def __init__(self, rheology, wall, tube, outlet_pressure, settings):
        self.rheology, self.wall = rheology, wall
        self.a, self.length, self.tb = tube.radius, tube.length, tube.reduced_thickness
        self.p_out = float(outlet_pressure)
        self.s = settings
        self._memo: dict = {}
        lam_max = wall.max_stretch(self.tb)
        #: the largest stretch the law is evaluated at (the last double below a maximum stretch)
        self.top = float(np.nextafter(lam_max, 1.0)) if math.isfinite(lam_max) else 1e15
        self.limit = wall.limit_pressure(self.tb)
        #: stretches where the law's slope kinks (fibres engaging): panel break points
        kinks = [float(k) for k in wall._slope_kinks(self.tb)]
        self.kinks = np.array(sorted(k for k in kinks if math.isfinite(k) and 0 < k < self.top))
        found = (1.0, 0.0) if self.p_out == 0 else self._stretch_search(self.p_out)
        if found is None:
            raise AssertionError(f"brute force: the outlet pressure {self.p_out!r} reaches the limit pressure")
        self.lam_out, self.e_out = found

    # ------------------------------------------------------------------ the inverse tube law
    def _law(self, s, p):
        """``wall.pressure(s) - p`` (``P(1) = 0``, the contract of every tube law, is not evaluated)."""
        s, p = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(p, dtype=float))
        value = np.zeros(s.shape)
        inside = s != 1.0
        if np.any(inside):
            with np.errstate(over="ignore", invalid="ignore"):
                value[inside] = self.wall.pressure(s[inside], self.tb)
        return value - p

    def _roots(self, p, lo, hi):
        """``(stretch, strain)`` with ``wall.pressure(stretch) = p``, bracketed by ``[lo, hi]``.

        The strain is interpolated linearly inside the final bracket (a few doubles wide), so that
        it keeps its relative accuracy at small strain, where ``stretch - 1`` is rounded to the
        spacing of the doubles near 1.
        """
        p, lo, hi = np.broadcast_arrays(p, lo, hi)
        shape = p.shape
        p, lo, hi = (np.array(x, dtype=float).ravel() for x in (p, lo, hi))
        lo = np.maximum(1.0, lo * (1.0 - 1e-12))
        hi = np.minimum(self.top, hi * (1.0 + 1e-12))
        tol = dict(xatol=0.0, xrtol=self.s.root_xrtol, fatol=0.0, frtol=0.0)
        res = elementwise.find_root(self._law, (lo, hi), args=(p,), tolerances=tol)
        for _ in range(60):                         # a bracket broken by rounding: widen it
            bad = res.status == -1
            if not np.any(bad):
                break
            lo = np.where(bad, 1.0 + 0.5 * (lo - 1.0), lo)
            hi = np.where(bad, np.minimum(self.top, 1.0 + 2.0 * (hi - 1.0)), hi)
            again = elementwise.find_root(self._law, (lo[bad], hi[bad]), args=(p[bad],), tolerances=tol)
            for name in ("x", "status", "success"):
                getattr(res, name)[bad] = getattr(again, name)
            for pair, new in ((res.bracket, again.bracket), (res.f_bracket, again.f_bracket)):
                pair[0][bad], pair[1][bad] = new
        if not np.all(res.success):
            raise AssertionError(f"brute force: no stretch found for the pressures {p[~res.success][:3]}")
        (xl, xr), (fl, fr) = res.bracket, res.f_bracket
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.clip(-fl / (fr - fl), 0.0, 1.0)
        strain = np.where((fl < 0) & (fr > 0), (xl - 1.0) + t * (xr - xl), res.x - 1.0)
        strain = np.where(fl == 0, xl - 1.0, np.where(fr == 0, xr - 1.0, strain))
        return (1.0 + strain).reshape(shape), strain.reshape(shape)

    def _stretches(self, p, lo, hi):
        """:meth:`_roots` at quadrature nodes, remembered by pressure (the flow-rate root of a
        pressure-controlled problem integrates on the same nodes at every iterate)."""
        p, lo, hi = np.broadcast_arrays(p, lo, hi)
        flat = p.ravel()
        out = np.empty(flat.size)
        miss = []
        for i, x in enumerate(flat.tolist()):
            hit = self._memo.get(x)
            if hit is None:
                miss.append(i)
            else:
                out[i] = hit
        if miss:
            miss = np.asarray(miss)
            lam, _ = self._roots(flat[miss], lo.ravel()[miss], hi.ravel()[miss])
            out[miss] = lam
            self._memo.update(zip(flat[miss].tolist(), lam.tolist()))
        return out.reshape(p.shape)

    def _stretch_search(self, p):
        """``(stretch, strain)`` at the pressure ``p``, bracketed by doubling the strain; None at or
        beyond the limit pressure or the largest admissible stretch. Its trial stretches may
        overflow a law: their warnings are not the answer's."""
        if not p < self.limit:
            return None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lo, hi = 1.0, 1.0 + _FIRST_RISE
            while self._law(hi, p) < 0:
                if hi >= self.top:
                    return None
                lo, hi = hi, min(self.top, 1.0 + 2.0 * (hi - 1.0))
        lam, strain = self._roots(p, lo, hi)
        return float(lam), float(strain)

    # ------------------------------------------------------------------ the separated integral
    def _integrand(self, x, q, lo, hi):
        x, q, lo, hi = np.broadcast_arrays(x, q, lo, hi)
        lam = self._stretches(self.p_out + x, lo, hi)
        g = self.rheology.pressure_gradient(q.ravel(), self.a * lam.ravel())
        return (1.0 / np.asarray(g, dtype=float)).reshape(x.shape)

    def _integrate(self, lower, upper, q, lam_lo, lam_hi, first, strict=True):
        """Integrals of ``1/G`` over ``[lower, upper]`` (inside panels bracketed by the stretches
        ``[lam_lo, lam_hi]``): Gauss–Legendre where ``first`` (and on slivers), else tanh–sinh.
        Not ``strict``: ``(integrals, converged)`` instead of raising."""
        lower, upper, lam_lo, lam_hi, first = (np.array(v).ravel() for v in
                                               np.broadcast_arrays(lower, upper, lam_lo, lam_hi, first))
        # Gauss-Legendre also on slivers (a root a few doubles above a break point), where the
        # nodes of tanh-sinh coincide and its error estimate is noise
        first = first.astype(bool) | (np.abs(upper - lower) <= 1e-8 * np.maximum(np.abs(lower), np.abs(upper)))
        out, ok = np.zeros(lower.size), np.ones(lower.size, dtype=bool)
        if np.any(first):
            t, w = np.polynomial.legendre.leggauss(self.s.gauss_nodes)
            a, b = lower[first, None], upper[first, None]
            f = self._integrand(a + (b - a) * (0.5 + 0.5 * t), q, lam_lo[first, None], lam_hi[first, None])
            out[first] = 0.5 * (b - a)[:, 0] * (f @ w)
        rest = ~first
        if np.any(rest):
            # every integral is a piece of F <= L (a length): an absolute tolerance of 1e-2 rtol L
            # keeps the answer's relative accuracy, and spares the slivers whose integrand, flat
            # to within the rounding of the radius, would keep tanh-sinh refining
            atol = 1e-2 * self.s.quad_rtol * self.length
            res = tanhsinh(self._integrand, lower[rest], upper[rest], args=(q, lam_lo[rest], lam_hi[rest]),
                           rtol=self.s.quad_rtol, atol=atol)
            # tanh-sinh stops at its finest level where the noise of the integrand (the rounding
            # of the stretch by the pressure) is above rtol; its estimate is then checked instead
            good = res.success | (res.error <= 1e-12 * np.abs(res.integral) + 1e2 * atol)
            if strict and not np.all(good):
                raise AssertionError(f"brute force: tanh-sinh did not converge (status {np.unique(res.status)}, "
                                     f"estimated relative error {np.max(res.error / res.integral):.2g})")
            out[rest], ok[rest] = res.integral, good
        return out if strict else (out, ok)

    def _panels(self, lam_top, d_top):
        """Break points ``(d, stretch)`` of ``[0, d_top]`` (``lam_top`` the stretch at ``d_top``):
        geometric in the strain rise below the top, down to a rise of 1e-3, and in the gap to a
        maximum stretch (where a peaking law's inverse has a square-root branch point), then
        refined in the pressure."""
        rs = self.s.strain_ratio
        rise = lam_top - self.lam_out
        n = max(0, math.ceil(math.log(rise / _FIRST_RISE) / math.log(rs)))
        s = self.lam_out + rise * rs ** -np.arange(n, 0, -1.0)
        if self.top < 1e15:             # and geometric in the gap to a maximum stretch
            gap = self.top - lam_top
            n = max(0, math.ceil(math.log((self.top - self.lam_out) / gap) / math.log(rs)))
            s = np.union1d(s, self.top - gap * rs ** np.arange(1.0, n + 1))
            s = s[s > self.lam_out + _FIRST_RISE]
        s = np.union1d(s, self.kinks[(self.kinks > self.lam_out) & (self.kinks < lam_top)])
        d = self._law(s, self.p_out)
        keep = (d > 0) & (d < d_top)
        return self._refine(np.concatenate([[0.0], d[keep], [d_top]]),
                            np.concatenate([[self.lam_out], s[keep], [lam_top]]))

    def _refine(self, d, lam):
        """Break points ``(d, lam)`` with points geometric in the pressure rise (at most
        ``pressure_ratio`` apart) inserted between those above the first."""
        keep = np.concatenate([[True], np.diff(d) > 0])
        d, lam = d[keep], lam[keep]
        rp = self.s.pressure_ratio
        extra, lo, hi = [], [], []
        for j in range(1, d.size - 1):
            if d[j + 1] > rp * d[j]:
                for i in range(1, math.floor(math.log(d[j + 1] / d[j]) / math.log(rp)) + 1):
                    if d[j + 1] * rp**-i > d[j] * (1 + 1e-9):
                        extra.append(d[j + 1] * rp**-i)
                        lo.append(lam[j])
                        hi.append(lam[j + 1])
        if extra:
            lam_x, _ = self._roots(self.p_out + np.asarray(extra), np.asarray(lo), np.asarray(hi))
            order = np.argsort(np.concatenate([d, extra]), kind="stable")
            d, lam = np.concatenate([d, extra])[order], np.concatenate([lam, lam_x])[order]
        return d, lam

    def _panels_upward(self, q, target):
        """Break points and the cumulative integral from the outlet up, geometric in the strain
        rise and in the gap to a maximum stretch (a batch at a time) until it reaches
        ``target``: ``(d, stretch, F)``. Nothing beyond the answer is integrated (near a limit
        pressure the pressure no longer resolves the stretch)."""
        rs = self.s.strain_ratio
        d, lam, cumulative = np.zeros(1), np.array([self.lam_out]), np.zeros(1)
        s = self.lam_out
        for _ in range(40):
            batch = []
            # a batch of rises from 1e-3 to 0.5, then one at a time: the law is evaluated little
            # beyond the answer (a stiff law is slow to evaluate, or overflows, far above it)
            while len(batch) < (60 if d.size == 1 else 1):
                rise = (s - self.lam_out) * rs if s > self.lam_out else _FIRST_RISE
                s = min(self.lam_out + rise, self.top - (self.top - s) / rs)
                batch.append(s)
                if d.size == 1 and s - self.lam_out >= 0.5:
                    break
            batch = np.union1d(batch, self.kinks[(self.kinks > lam[-1]) & (self.kinks < batch[-1])])
            with warnings.catch_warnings():      # probes, possibly far above the answer (or the
                warnings.simplefilter("ignore")  # range of the law): break points only, whose
                p = self._law(batch, self.p_out)  # accuracy does not enter the integral
            fine = np.isfinite(p) & (p > d[-1])
            if not np.any(fine) or batch[0] > 1e8 * self.lam_out:
                break
            d_new, lam_new = self._refine(np.concatenate([d[-1:], p[fine]]), np.concatenate([lam[-1:], batch[fine]]))
            first = (np.arange(d_new.size - 1) == 0) & (d.size == 1)
            parts, ok = self._integrate(d_new[:-1], d_new[1:], q, lam_new[:-1], lam_new[1:], first, strict=False)
            sums = cumulative[-1] + np.cumsum(parts)
            # keep the panels up to the one that reaches the target (those above are not needed,
            # and close to a peak of the law the pressure no longer resolves their stretches)
            n = int(np.searchsorted(sums, target)) + 1 if sums[-1] >= target else sums.size
            if not np.all(ok[:n]):
                raise AssertionError("brute force: tanh-sinh did not converge on a panel below the inlet")
            d, lam = np.concatenate([d, d_new[1:n + 1]]), np.concatenate([lam, lam_new[1:n + 1]])
            cumulative = np.concatenate([cumulative, sums[:n]])
            if cumulative[-1] >= target:
                return d, lam, cumulative
            s = float(lam[-1])
        raise AssertionError(f"brute force: no steady state found at q = {q!r} (inlet stretch beyond "
                             f"{float(lam[-1]):.3g})")

    def _cumulative(self, panels, q):
        d, lam = panels
        first = np.arange(d.size - 1) == 0
        return np.concatenate([[0.0], np.cumsum(self._integrate(d[:-1], d[1:], q, lam[:-1], lam[1:], first))])

    def _positions(self, panels, cumulative, q, targets):
        """``(pressure rise, strain)`` where ``F = targets``: each a root inside its panel, by
        Newton's method with the exact slope ``dF/dd = 1/G`` kept inside the panel (bisection
        when a step leaves it). ``F`` at each iterate is ``F`` at the previous one plus the
        integral between the two, so that after the first step only short intervals are
        integrated."""
        d, lam = panels
        targets = np.asarray(targets, dtype=float)
        if np.any(targets > cumulative[-1] * (1 + 1e-12)):
            raise AssertionError("brute force: a target lies beyond the last panel")
        m = np.clip(np.searchsorted(cumulative, targets, side="right") - 1, 0, d.size - 2)
        lam_lo, lam_hi = lam[m], lam[m + 1]
        lo, hi = d[m].copy(), d[m + 1].copy()
        x, fx = d[m].copy(), cumulative[m] - targets          # F(x) - target, <= 0 at the start
        first = (m == 0).astype(float)
        todo = fx != 0
        for _ in range(100):
            if not np.any(todo):
                break
            i = np.flatnonzero(todo)
            lam_x, _ = self._roots(self.p_out + x[i], lam_lo[i], lam_hi[i])
            slope = 1.0 / np.asarray(self.rheology.pressure_gradient(np.full(i.size, q), self.a * lam_x), dtype=float)
            lo[i] = np.where(fx[i] < 0, x[i], lo[i])
            hi[i] = np.where(fx[i] > 0, x[i], hi[i])
            new = x[i] - fx[i] / slope
            new = np.where((new > lo[i]) & (new < hi[i]), new, 0.5 * (lo[i] + hi[i]))
            fx[i] = fx[i] + self._integrate(x[i], new, q, lam_lo[i], lam_hi[i], first[i])
            # done when the step, or the residual, is at the rounding of the sum of F's pieces
            done = ((np.abs(new - x[i]) <= self.s.root_xrtol * np.abs(new))
                    | (np.abs(fx[i]) <= 4 * _EPS * targets[i]))
            x[i] = new
            todo[i] = ~done & (fx[i] != 0)
        else:
            raise AssertionError("brute force: the root of the separated integral failed")
        _, strain = self._roots(self.p_out + x, lam_lo, lam_hi)
        return x, strain

    # ------------------------------------------------------------------ the two problems
    def flow_controlled(self, q, z):
        """``(pressure drop, inlet strain, pressure rises at z, strains at z)`` at the flow rate q."""
        L = self.length
        d, lam, cumulative = self._panels_upward(q, L)
        rise, strain = self._positions((d, lam), cumulative, q, np.concatenate([[L], L - z]))
        return rise[0], strain[0], rise[1:], strain[1:]

    def pressure_controlled(self, dp, z):
        """``(flow rate, inlet strain, pressure rises at z, strains at z)`` at the pressure drop dp."""
        L, a = self.length, self.a
        found = self._stretch_search(self.p_out + dp)
        if found is None:
            raise AssertionError(f"brute force: the pressure drop {dp!r} reaches the limit pressure")
        lam_in, strain_in = found
        panels = self._panels(lam_in, dp)
        # the flow lies between the rigid-tube flows at the outlet and the inlet radii
        lo = float(self.rheology.flow_rate(a * self.lam_out, dp / L)) * (1 - 1e-9)
        hi = float(self.rheology.flow_rate(a * lam_in, dp / L)) * (1 + 1e-9)

        def excess(q):
            return np.asarray([self._cumulative(panels, qi)[-1] for qi in np.ravel(q)]).reshape(np.shape(q)) - L

        nothing = np.full(z.shape, math.nan)
        lo = max(lo, 1e-12 * hi)
        if not hi > 0 or excess(np.asarray(lo)) < 0:        # a yield stress holds the fluid: no flow
            return 0.0, strain_in, nothing, nothing
        res = elementwise.find_root(excess, (lo, hi),
                                    tolerances=dict(xatol=0.0, xrtol=self.s.root_xrtol, fatol=0.0, frtol=0.0))
        if not res.success:
            raise AssertionError(f"brute force: no flow rate found for the pressure drop {dp!r}")
        q = float(res.x)
        rise, strain = nothing, nothing
        if z.size:
            rise, strain = self._positions(panels, self._cumulative(panels, q), q, L - z)
        return q, strain_in, rise, strain


@dataclasses.dataclass(frozen=True)
class BruteForce:
    """An independent brute-force answer for one load (see :func:`brute_force`).

    ``error`` maps each answer (``flow_rate``, ``pressure_drop``, ``inlet_displacement``,
    ``pressure``, ``radius``, ``displacement``) to its estimated relative error, the relative
    difference between the two runs (arrays for the profiles); ``warnings`` holds the messages
    of warnings the models issued while the brute force evaluated them.
    """

    flow_rate: float
    pressure_drop: float
    inlet_displacement: float
    z: np.ndarray
    pressure: np.ndarray
    radius: np.ndarray
    displacement: np.ndarray
    error: dict
    warnings: tuple = ()


def brute_force(rheology, wall, tube, *, flow_rate=None, pressure_drop=None, z=(), outlet_pressure=0.0):
    r"""The steady state at one load by brute force, independently of tubefsi's couplers.

    Exactly one of ``flow_rate`` and ``pressure_drop`` (floats) is given; ``z`` lists positions
    (m) for the profiles. Lubrication, :math:`dp/dz = -G(q, a\lambda(p))`,
    :math:`p(L) = p_{out}` (``docs/theory.md``, section "Lubrication"), is separated *in the
    pressure*: :math:`L - z = \int_{p_{out}}^{p(z)} dp\,/\,G(q, a\lambda(p))` (the identity of
    section "Coupling without an ODE" with :math:`dp = P'\,d\lambda` undone). The integral is
    summed over panels geometric in strain and pressure (Gauss–Legendre on the first, nearly
    linear one, tanh–sinh on the others); :math:`\lambda(p)` at every node is a bracketing root
    of ``wall.pressure``; the inlet and profile pressures solve the integral by Newton's method
    with its exact slope :math:`1/G` (safeguarded), the flow rate by a bracketing root. That is
    a different variable, integrand, rule and root finder from tubefsi's default path
    (adaptive Gauss–Kronrod in the log-stretch with the stiffness :math:`P'`, Newton on
    :math:`\ln J`), and it calls only the models' public methods ``wall.pressure``,
    ``wall.max_stretch``, ``wall.limit_pressure``, ``rheology.pressure_gradient`` and
    ``rheology.flow_rate`` — never ``wall.stiffness`` nor the wall's own inverse. A rigid wall is
    Hagen–Poiseuille, :math:`\Delta p = L\,G(q, a)`.

    It runs twice, at two tolerances (tanh–sinh ``rtol`` 1e-13 and 1e-14, roots to 1e-14 and
    4 eps) on two sets of break points, and returns the tighter run with the relative
    difference of the two as its error estimate (:class:`BruteForce`); it measures the
    discretization, not the rounding of the models' own evaluations. Cost per load: about
    0.1 s for closed-form walls, up to a few seconds for a thick wall of a strongly stiffening
    general material (whose every pressure is a quadrature). Raises ``AssertionError`` if it
    cannot reach its tolerance (a brute force that fails must fail a test, not return).
    """
    if (flow_rate is None) == (pressure_drop is None):
        raise TypeError("give exactly one of flow_rate= and pressure_drop=")
    z = np.atleast_1d(np.asarray(z, dtype=float))
    a, L = tube.radius, tube.length
    runs = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for settings in (_LOOSE, _TIGHT):
            if wall.is_rigid:
                if flow_rate is not None:
                    q, dp = float(flow_rate), L * float(rheology.pressure_gradient(flow_rate, a))
                else:
                    q, dp = float(rheology.flow_rate(a, pressure_drop / L)), float(pressure_drop)
                e_in, rise, strain = 0.0, dp * (L - z) / L, np.zeros(z.shape)
            else:
                engine = _Separated(rheology, wall, tube, outlet_pressure, settings)
                if flow_rate is not None:
                    q = float(flow_rate)
                    dp, e_in, rise, strain = (engine.flow_controlled(q, z) if q > 0
                                              else (0.0, engine.e_out, 0 * z, engine.e_out + 0 * z))
                else:
                    dp = float(pressure_drop)
                    q, e_in, rise, strain = (engine.pressure_controlled(dp, z) if dp > 0
                                             else (0.0, engine.e_out, 0 * z, engine.e_out + 0 * z))
            runs.append(dict(flow_rate=q, pressure_drop=float(dp), inlet_displacement=float(a * e_in),
                             pressure=outlet_pressure + np.asarray(rise, dtype=float),
                             radius=a * (1.0 + np.asarray(strain, dtype=float)),
                             displacement=a * np.asarray(strain, dtype=float)))
    loose, tight = runs
    error = {}
    for key, value in tight.items():
        v, w = np.asarray(value, dtype=float), np.asarray(loose[key], dtype=float)
        with np.errstate(invalid="ignore", divide="ignore"):
            err = np.where(v == w, 0.0, np.abs(w - v) / np.abs(v))
        error[key] = float(err) if err.ndim == 0 else err
    messages = tuple(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))
    return BruteForce(z=z, error=error, warnings=messages, **tight)


def accuracy_cases(walls, fluids=None) -> list:
    """``pytest.param((fluid, wall))`` for every pair, for an :class:`AccuracyContract` fixture.

    ``fluids`` defaults to the first example of ``power-law`` and of ``newtonian`` (as
    :func:`~tubefsi.testing.coupler_cases`).
    """
    if fluids is None:
        fluids = [examples("rheologies", "power-law")[0], examples("rheologies", "newtonian")[0]]
    return [pytest.param((fluid, wall), id=f"{wall!r}-{fluid!r}") for wall in walls for fluid in fluids]


@dataclasses.dataclass
class _Row:
    """One compared quantity of :class:`AccuracyContract`."""

    load: str
    quantity: str
    default: float
    brute: float
    error: float
    kappa: float
    brute_error: float
    warned: bool
    notes: tuple = ()       # warnings the models issued while the brute force evaluated them
    verdict: str = ""


def _solve_recording(*args, **kwargs):
    """``(solution, warned)``: ``solve`` with its AccuracyWarnings recorded (and re-issued)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = solve(*args, **kwargs)
    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return sol, any(issubclass(w.category, AccuracyWarning) for w in caught)


class AccuracyContract:
    r"""The default answers against an independent brute force; needs a ``case`` fixture
    ``(rheology, wall)`` (:func:`accuracy_cases`; a longer tuple such as a
    :class:`CouplerContract` case is accepted, its coupler ignored: the default path is checked).

    The promise of ``docs/verification.md``, section "Contracts": the default ``solve`` is
    accurate to :math:`10^{-12}\max(1, \kappa)` relative for any correctly written model, or
    it warns (``AccuracyWarning``) or raises. The other suites compare a model's paths with
    each other; this one compares ``solve(...)`` with :func:`brute_force`, a different
    algorithm that calls only the models' public methods (``docs/theory.md``, sections
    "Lubrication" and "Coupling without an ODE"), so a law the default path gets wrong fails
    here.

    Loads: the inlet strains ``accuracy_strains``, small to large (each capped at 90 % of a
    maximum stretch; a rigid wall takes the pressure drops ``rigid_pressure_drops``). For each,
    the flow rate ``q`` of the pressure drop ``P(1 + strain)`` is picked with the default path
    (it is only a load) and solved flow-controlled by both: the pressure drop, the inlet
    displacement and, at ``z = accuracy_positions * L``, the pressure, the radius and the
    displacement are compared. Then the default path solves the pressure-controlled problem
    at the brute force's pressure drop (rounded to a double), and its flow rate and inlet
    displacement are compared with the brute force's ``q`` and inlet displacement (the
    rounding moves them by :math:`\kappa\varepsilon`, far below the tolerance). A load of no
    flow (a yield stress) must be no flow for the brute force too.

    A comparison passes if ``|default / brute - 1| <= accuracy_rtol * max(1, kappa)``, or if
    the default solve warned (``AccuracyWarning``) for that load. :math:`\kappa`, the relative
    condition number of the quantity with respect to the load, is the central finite
    difference of the default answers at ``load * (1 +- kappa_step)``. The brute force's own
    estimated error (the difference of its two runs) must be below
    ``brute_force_rtol * max(1, kappa)``, or the comparison is inconclusive, which fails too
    (unless the default path warned). A ``ConvergenceError`` of the default path fails the
    test: the loads are ordinary ones. The failure message lists every failed comparison, and
    the warnings the models issued while the brute force evaluated them.

    Cost: one brute force per load (about 0.1 s for closed-form walls, 1–2 s for a thick wall of
    a general material) and five default solves; 1–8 s per pair for the registered models.
    """

    tube = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    #: inlet strains of the loads, small to large (capped at 90 % of a maximum stretch)
    accuracy_strains = (1e-6, 1e-3, 0.1, 1.0)
    #: the loads of a rigid wall (Pa)
    rigid_pressure_drops = (1.0, 1e3, 1e6)
    #: positions of the profile checks, as fractions of the tube length
    accuracy_positions = (0.1, 0.5, 0.9)
    #: the tolerance, times max(1, kappa)
    accuracy_rtol = 1e-11
    #: the largest estimated error of the brute force itself, times max(1, kappa)
    brute_force_rtol = 1e-12
    #: relative step of the finite differences that estimate kappa
    kappa_step = 1e-6
    outlet_pressure = 0.0

    @pytest.fixture
    def case(self):  # pragma: no cover - provided by the subclass
        raise NotImplementedError

    def _accuracy_pressure_drops(self, wall):
        """The pressure drops of the loads."""
        if wall.is_rigid:
            return list(self.rigid_pressure_drops)
        tb = self.tube.reduced_thickness
        lam_max = wall.max_stretch(tb)
        drops = []
        for strain in self.accuracy_strains:
            if math.isfinite(lam_max):
                strain = min(strain, 0.9 * (lam_max - 1.0))
            drop = wall.pressure(1.0 + strain, tb) - self.outlet_pressure
            if drop > 0 and drop not in drops:
                drops.append(drop)
        return drops

    def accuracy_rows(self, rheology, wall):
        """Every comparison of :meth:`test_default_answers_match_brute_force`, as rows."""
        kw = dict(outlet_pressure=self.outlet_pressure)
        tube, h = self.tube, self.kappa_step
        # the brute force works on the tube the flow sees (``Solution.tube``: the installed tube
        # of an axially pre-stretched wall), and the positions are along it
        installed = solve(rheology, wall, tube, flow_rate=0.0, **kw).tube
        z = np.asarray(self.accuracy_positions, dtype=float) * installed.length
        rows = []

        def kappa(minus, plus, value):
            return float(np.max(np.abs(np.asarray(plus) - np.asarray(minus)) / (2 * h * np.abs(value))))

        def row(load, name, default, brute, brute_error, k, warned, notes=()):
            default, brute = np.atleast_1d(default), np.atleast_1d(brute)
            for i in range(default.size):
                d, b = float(default[i]), float(brute[i])
                err = 0.0 if d == b else abs(d - b) / abs(b)
                where = f"{name}(z={z[i]:.3g})" if default.size > 1 else name
                kk = k[i] if np.ndim(k) else k
                be = np.atleast_1d(brute_error)[i if np.ndim(brute_error) else 0]
                rows.append(_Row(load, where, d, b, err, max(1.0, float(kk)), float(be), warned, notes))

        for drop in self._accuracy_pressure_drops(wall):
            picked = solve(rheology, wall, tube, pressure_drop=drop, **kw)
            q = float(picked.flow_rate)
            load = f"q={q:.6g} (the flow of dp={drop:.6g})"
            if not q > 0:           # no flow (a yield stress): the brute force must agree
                bf = brute_force(rheology, wall, installed, pressure_drop=drop, **kw)
                rows.append(_Row(load, "flow_rate", q, bf.flow_rate, 0.0 if bf.flow_rate == q else math.inf,
                                 1.0, 0.0, False))
                continue
            bf = brute_force(rheology, wall, installed, flow_rate=q, z=z, **kw)
            notes = bf.warnings
            # flow-controlled, and the profiles
            sol, warned = _solve_recording(rheology, wall, tube, flow_rate=q, **kw)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                profile = (sol.pressure(z), sol.radius(z), sol.displacement(z))
            warned_profile = warned or any(issubclass(w.category, AccuracyWarning) for w in caught)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                near = solve(rheology, wall, tube, flow_rate=q * np.array([1 - h, 1 + h]), **kw)
                zz = z[:, None]
                near_profile = (near.pressure(zz), near.radius(zz), near.displacement(zz))
            row(load, "pressure_drop", sol.pressure_drop, bf.pressure_drop, bf.error["pressure_drop"],
                kappa(*near.pressure_drop, sol.pressure_drop), warned, notes)
            if not wall.is_rigid:
                row(load, "inlet_displacement", sol.inlet_displacement, bf.inlet_displacement,
                    bf.error["inlet_displacement"],
                    kappa(*near.inlet_displacement, sol.inlet_displacement), warned, notes)
            for name, value, pair in zip(("pressure", "radius", "displacement"), profile, near_profile):
                if wall.is_rigid and name == "displacement":
                    continue
                ks = [kappa(pair[i, 0], pair[i, 1], value[i]) for i in range(z.size)]
                row(load, name, value, getattr(bf, name), bf.error[name], ks, warned_profile, notes)
            # pressure-controlled, at the brute force's pressure drop rounded to a double
            dp = float(bf.pressure_drop)
            back, warned = _solve_recording(rheology, wall, tube, pressure_drop=dp, **kw)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                near = solve(rheology, wall, tube, pressure_drop=dp * np.array([1 - h, 1 + h]), **kw)
            load = f"dp={dp:.6g}"
            k_q = kappa(*near.flow_rate, back.flow_rate)
            # the brute force's flow rate at its own pressure drop: that drop's error, times kappa
            row(load, "flow_rate", back.flow_rate, bf.flow_rate, bf.error["pressure_drop"] * max(1.0, k_q),
                k_q, warned, notes)
            if not wall.is_rigid:
                row(load, "inlet_displacement", back.inlet_displacement, bf.inlet_displacement,
                    bf.error["inlet_displacement"],
                    kappa(*near.inlet_displacement, back.inlet_displacement), warned, notes)
        for r in rows:
            if r.verdict:
                continue
            if r.brute_error > self.brute_force_rtol * r.kappa:
                r.verdict = "warned" if r.warned else "INCONCLUSIVE: the brute force did not reach its tolerance"
            elif r.error <= self.accuracy_rtol * r.kappa:
                r.verdict = "ok"
            elif r.warned:
                r.verdict = "warned"
            else:
                r.verdict = "FAIL"
        return rows

    def test_default_answers_match_brute_force(self, case):
        rheology, wall = case[0], case[1]
        rows = self.accuracy_rows(rheology, wall)
        bad = [r for r in rows if r.verdict not in ("ok", "warned")]
        if bad:
            lines = [f"{r.load:>36s} {r.quantity:>24s} default {r.default!r:>24s} brute force {r.brute!r:>24s} "
                     f"rel. error {r.error:.2g} (tolerance {self.accuracy_rtol * r.kappa:.2g}, kappa {r.kappa:.3g}, "
                     f"brute-force error {r.brute_error:.2g}) {r.verdict}" for r in bad]
            seen = "".join(f"\n  {m}" for m in dict.fromkeys(m for r in bad for m in r.notes))
            if seen:
                seen = "\nwarnings the models issued while the brute force evaluated them:" + seen
            raise AssertionError(f"{wall!r} with {rheology!r}: the default answers disagree with the brute "
                                 f"force:\n" + "\n".join(lines) + seen)
