r"""The separated-variables engine shared by the ``closed-form`` and ``quadrature`` couplers.

Lubrication theory gives :math:`dp/dz = -G(q, R(p))` with :math:`p(L) = p_{out}`.
Writing the tube law :math:`p = P(\lambda)` and the log-stretch
:math:`u = \ln(\lambda/\lambda_{out})` separates the variables (``docs/theory.md``, section
"Coupling without an ODE"):

.. math::

    L - z = \int_0^{v(z)} \frac{s\,P'(s)}{G(q, a s)}\,du, \qquad s = \lambda_{out} e^u,

so the inlet log-stretch :math:`v` solves :math:`H(v; q) = L` and the pressure drop is
:math:`\int_0^v s P'(s)\,du`. For a separable rheology, :math:`G = \phi(q)\psi(R)`, this is
:math:`J(v) = L\,\phi(q)` with :math:`J` independent of :math:`q`, so one function serves a
whole flow curve. A concrete coupler gives only ``_J(scene, v, q)`` (closed form or
quadrature) and may override ``_J_infinity``; the engine solves flow- and
pressure-controlled problems, profiles and the maximum flow rate from it.

A wall with a maximum stretch :math:`\lambda_{max}` (a locking material such as Gent, the
first pressure peak of a non-monotone tube law, the representable end of a Fung law) bounds
:math:`v` by :math:`v_{max} = \ln(\lambda_{max}/\lambda_{out})`. :meth:`SeparatedVariables.integrate`
grades its panels geometrically toward :math:`v_{max}` where the pressure is unbounded there
(:math:`P'` singular: a lock), and narrows them where the integrand grows fast.

The rigid wall (:math:`\lambda \equiv 1`) has no log-stretch coordinate: its problems are
Hagen–Poiseuille, :math:`\Delta p = L\,G(q, a)`, handled here once (``_rigid_state``).
"""

from __future__ import annotations

import abc
import functools
import math

import numpy as np
from scipy import interpolate, optimize
from scipy.optimize import elementwise

from .._numerics import EPS, integrate_graded, solve_increasing
from .._quadrature import adaptive_to_pole, quiet, warn_unconverged
from ..errors import NoSteadyStateError
from ..scene import Scene, State
from .base import Coupler

__all__ = ["SeparatedVariables", "MAX_LOG_STRETCH"]

#: Largest inlet stretch (relative to the outlet) a solve may reach: ln(1e15).
MAX_LOG_STRETCH = math.log(1e15)
_PROBE_LOG_STRETCH = math.log(1e8)


class SeparatedVariables(Coupler):
    """Abstract engine: solves every problem from the separated integral ``_J`` of a subclass.

    Hooks: ``_J(scene, v, q)`` (required: :math:`\\int_0^v` of the separated integrand,
    ``q`` only for a non-separable rheology) and ``_J_infinity(scene, q)`` (optional:
    :math:`J(\\infty)`, for the maximum flow rate).
    """

    __slots__ = ()

    # --------------------------------------------------------------- the tube law along u
    @staticmethod
    def stretch_at(scene: Scene, u):
        """Hoop stretch at log-stretch ``u``."""
        return scene.outlet_stretch * np.exp(u)

    @staticmethod
    def strain_at(scene: Scene, u):
        """Hoop strain at log-stretch ``u``, without cancellation."""
        return scene.outlet_strain + scene.outlet_stretch * np.expm1(u)

    #: Relative tolerance of every quadrature of the separated integrand (error-controlled).
    _RTOL: float = 1e-14

    def integrate(self, scene: Scene, f, upper, *, order=None, panel_width=2.0):
        r"""``∫_0^upper f(u, idx) du`` over log-stretch, per point.

        By default adaptive Gauss–Kronrod quadrature with an a-posteriori error estimate per
        point, refined to ``_RTOL`` (:func:`tubefsi._quadrature.adaptive_to_pole`), graded in
        :math:`\ln(v_{max} - u)` toward a locking stretch; an estimate that stays above the
        tolerance is an ``AccuracyWarning``. With ``order`` a fixed composite Gauss–Legendre
        rule of that order on panels of ``panel_width`` (a coarse rule, for the work-precision
        chart; its coupler checks it against the adaptive one).
        """
        # a maximum stretch with an unbounded pressure (a locking wall) is a singularity of P'
        singular = math.isfinite(scene.log_stretch_max) and not math.isfinite(scene.wall._limit_pressure(scene.tb))
        pole = scene.log_stretch_max if singular else math.inf
        if order is not None:
            return integrate_graded(f, upper, pole, order=order, panel_width=panel_width)
        result = adaptive_to_pole(f, 0.0, upper, pole, rtol=self._RTOL, panel_width=panel_width)
        if not np.all(result.converged):
            warn_unconverged("the separated-variables integral", result)
        return result.value

    def pressure_rise(self, scene: Scene, v):
        r""":math:`P(\lambda_{out}e^v) - p_{out}`, computed without cancellation."""
        v = np.asarray(v, dtype=float)
        if scene.outlet_pressure == 0.0:
            return scene.wall._pressure_at_strain(np.expm1(v), scene.tb)
        return self.integrate(scene, lambda u, idx: self._slope(scene, u), v)

    def _slope(self, scene: Scene, u):
        s = self.stretch_at(scene, u)
        return s * scene.wall._stiffness(s, scene.tb)

    def integrand(self, scene: Scene, u, q=None):
        r""":math:`s P'(s)/\psi(a s)` (separable) or :math:`s P'(s)/G(q, a s)`."""
        s = self.stretch_at(scene, u)
        a = scene.tube.radius
        slope = s * scene.wall._stiffness(s, scene.tb)
        if scene.rheology.separable:
            return slope / scene.rheology._radius_factor(a * s)
        qq = np.broadcast_to(q, np.shape(u))
        return slope / scene.rheology._pressure_gradient(qq, a * s)

    @staticmethod
    def target(scene: Scene, q):
        """Right-hand side of the separated identity for flow rate ``q``."""
        if scene.rheology.separable:
            return scene.tube.length * scene.rheology._flow_factor(q)
        return np.full(np.shape(q), scene.tube.length)

    # --------------------------------------------------------------- J hooks
    @abc.abstractmethod
    def _J(self, scene: Scene, v, q):
        r""":math:`\int_0^v` of the separated integrand (``q`` only if non-separable)."""

    def _J_infinity(self, scene: Scene, q=None) -> float:
        r""":math:`J(\infty)`: finite only for a wall with a limit pressure and a fast
        enough decay of :math:`s P'(s)/\psi(as)`; used for the maximum flow rate."""
        tb = scene.tb
        if not math.isfinite(scene.wall._limit_pressure(tb)):
            return math.inf
        qq = None if q is None else np.asarray(q, dtype=float)
        if math.isfinite(scene.log_stretch_max):
            # the tube law ends at its pressure peak: J stays finite up to it
            return float(self._J(scene, np.asarray(scene.log_stretch_max * (1 - 8 * EPS)), qq))
        rheo = scene.rheology
        mu = rheo.radius_exponent
        if mu is None:
            # local exponent of G in R far out, where the probe of J(inf) ends
            r = scene.tube.radius * np.exp(_PROBE_LOG_STRETCH) * np.array([1.0, 10.0])
            g = rheo._radius_factor(r) if rheo.separable else rheo._pressure_gradient(np.full(2, q), r)
            mu = float(-np.log(g[1] / g[0]) / np.log(10.0))
        alpha = scene.wall._stiffness_decay_exponent(tb) - 1.0 - mu
        if not alpha > 1e-12:
            return math.inf
        v1 = np.asarray(_PROBE_LOG_STRETCH)
        head = self._J(scene, v1, qq)
        tail = self.integrand(scene, v1, qq) / alpha
        return float(head + tail)

    # --------------------------------------------------------------- problems
    def flow_controlled(self, scene: Scene, flow_rate) -> State:
        """Solve for the pressure drop at each flow rate (array)."""
        q = np.asarray(flow_rate, dtype=float)
        if scene.wall.is_rigid:
            return _rigid_state(scene, flow_rate=q)
        v, ok = self.solve_log_stretch(scene, np.where(q == 0, 0.0, self.target(scene, q)), q)
        if not np.all(ok):
            self._raise_runaway(scene, q, ok)
        dp = self.pressure_rise(scene, v)
        return State(q, dp, self.strain_at(scene, v), v)

    def solve_log_stretch(self, scene: Scene, target, q=None, upper=None, *, check=True):
        r"""Log-stretch :math:`v` with :math:`J(v; q) = ` ``target``, elementwise; returns ``(v, ok)``.

        Safeguarded Newton on :math:`\ln J`. For a separable rheology a whole curve
        shares :math:`J`, so a coarse solve on a few quantiles of the targets gives
        every point a starting value within a few Newton steps of its root. Trial points do
        not warn (:func:`~tubefsi._quadrature.quiet`); with ``check`` the integral at the answer
        is evaluated once more, with its error estimate (``AccuracyWarning`` beyond tolerance).
        """
        sep = scene.rheology.separable
        target = np.asarray(target, dtype=float)
        qflat = None if sep else np.broadcast_to(q, target.shape).ravel()

        def F(v, i):
            return self._J(scene, v, None if sep else qflat[i])

        def dF(v, i):
            return self.integrand(scene, v, None if sep else qflat[i])

        positive = target[target > 0]
        if sep and positive.size > 256:
            anchors = np.geomspace(positive.min(), positive.max(), 129)
            v_anchor, ok = self.solve_log_stretch(scene, anchors, check=False)
            keep = ok & (v_anchor < MAX_LOG_STRETCH)
            if np.count_nonzero(keep) >= 2:
                shape = interpolate.PchipInterpolator(np.log(anchors[keep]), v_anchor[keep], extrapolate=True)
                guess = np.maximum(shape(np.log(np.where(target > 0, target, anchors[0]))), 0.0)
            else:
                guess = np.ones(target.shape)
        else:
            with np.errstate(divide="ignore", invalid="ignore"):   # G(0, R) = 0: only where target = 0
                slope0 = self.integrand(scene, np.zeros(target.shape), None if sep else np.broadcast_to(q, target.shape))
                guess = np.where(target > 0, np.minimum(target / slope0, 1.0), 0.0)
        if upper is not None:
            guess = np.minimum(guess, upper)
        cap = self._log_stretch_cap(scene)
        if math.isfinite(scene.log_stretch_max):
            upper = cap if upper is None else np.minimum(upper, cap)
            guess = np.minimum(guess, 0.5 * cap)
        with quiet():
            v, ok = solve_increasing(F, dF, target, guess=guess, upper=upper, xmax=MAX_LOG_STRETCH, max_step=2.0,
                                     log=True)
        answered = np.flatnonzero(ok.ravel() & (target.ravel() > 0))
        if check and answered.size:
            F(v.ravel()[answered], answered)                            # the answer's own error estimate
        if math.isfinite(scene.log_stretch_max):
            # converged onto the maximum stretch without reaching the target: out of reach
            at_cap = np.flatnonzero((v.ravel() >= cap * (1 - 1e-12)) & (target.ravel() > 0))
            if at_cap.size:
                short = F(v.ravel()[at_cap], at_cap) < target.ravel()[at_cap] * (1 - 1e-9)
                ok = ok.copy()
                ok.ravel()[at_cap[short]] = False
        return v, ok

    @staticmethod
    def _log_stretch_cap(scene):
        """The largest log-stretch a solve may reach: below a maximum stretch, and ln(1e15)."""
        v_max = scene.log_stretch_max
        return min(MAX_LOG_STRETCH, v_max * (1 - 8 * EPS)) if math.isfinite(v_max) else MAX_LOG_STRETCH

    def pressure_controlled(self, scene: Scene, pressure_drop) -> State:
        """Solve for the flow rate at each pressure drop (array)."""
        dp = np.asarray(pressure_drop, dtype=float)
        tb, wall, a, L = scene.tb, scene.wall, scene.tube.radius, scene.tube.length
        rheo = scene.rheology
        if wall.is_rigid:
            return _rigid_state(scene, pressure_drop=dp)
        wall._check_pressure(scene.outlet_pressure + dp, tb)
        e_in = wall._strain(scene.outlet_pressure + dp, tb)
        v = np.log1p((e_in - scene.outlet_strain) / scene.outlet_stretch)
        if rheo.separable:
            q = rheo._flow_factor_inverse(self._J(scene, v, None) / L)
        else:
            q = self._solve_flow_rate(scene, v, dp)
        q = np.where(dp == 0, 0.0, q)
        return State(q, dp, e_in, v)

    def _solve_flow_rate(self, scene, v, dp):
        r"""Non-separable rheology: find q with H(v; q) = L (H decreases with q).

        Rigid tubes of the outlet and inlet radii under the mean gradient dp/L bracket q.
        A yield-stress fluid has a finite :math:`H(v; 0^+)`, with :math:`G = 2\tau_y/R`:
        where it does not exceed L the pressure drop cannot yield the fluid all along
        the tube, and q = 0.
        """
        a, L, rheo = scene.tube.radius, scene.tube.length, scene.rheology
        shape = np.shape(v)
        v = np.asarray(v, dtype=float).ravel()
        dp = np.broadcast_to(np.asarray(dp, dtype=float), shape).ravel()
        g = np.where(dp == 0, 1.0, dp) / L
        q_lo = rheo._flow_rate(np.full_like(g, a * scene.outlet_stretch), g)
        q_hi = rheo._flow_rate(a * self.stretch_at(scene, v), g)
        flowing = (q_hi > 0) & (dp > 0)
        if rheo.yield_stress > 0 and np.any(flowing):
            flowing[flowing] = self._J(scene, v[flowing], np.zeros(np.count_nonzero(flowing))) > L
        q = np.zeros(v.shape)
        if not np.any(flowing):
            return q.reshape(shape)
        v, q_lo, q_hi = v[flowing], q_lo[flowing], q_hi[flowing]

        def f(log_q, v):
            return np.log(self._J(scene, v, np.exp(log_q))) - math.log(L)

        hi = np.log(q_hi) * (1 + 1e-15) + 1e-15
        with np.errstate(divide="ignore"):
            lo = np.log(q_lo)
        lo = lo - 1e-12 * np.abs(lo)
        found = np.ones(v.shape, dtype=bool)
        unyielded = q_lo <= 0          # the outlet section alone would not yield: search down
        if np.any(unyielded):
            top = hi[unyielded]
            br = elementwise.bracket_root(f, top - 2.0, top, xmin=top - 700.0, xmax=top, args=(v[unyielded],))
            lo[unyielded] = br.bracket[0]
            hi[unyielded] = np.where(br.success, br.bracket[1], hi[unyielded])
            found[unyielded] = br.success   # else q < 1e-304 q_hi: zero in double precision
        res = elementwise.find_root(f, (lo, hi), args=(v,),
                                    tolerances=dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300))
        q[flowing] = np.where(found, np.exp(res.x), 0.0)
        return q.reshape(shape)

    def profile(self, scene: Scene, state: State, z):
        r"""``(strain, pressure_rise)`` at ``z`` (already validated to lie in [0, L]), broadcast
        against the state: the log-stretch :math:`v(z)` solves :math:`J(v) = (1 - z/L)\,J(v_{in})`
        (separable) or :math:`H(v; q) = L - z`."""
        L = scene.tube.length
        z, q, v_in = np.broadcast_arrays(np.asarray(z, dtype=float), state.flow_rate, state.log_stretch)
        if scene.wall.is_rigid:
            gradient = np.where(q == 0, 0.0, scene.rheology._pressure_gradient(q, scene.tube.radius))
            return np.zeros(z.shape) + scene.outlet_strain, (L - z) * gradient
        frac = (L - z) / L
        v, _ = self.solve_log_stretch(scene, np.where(q == 0, 0.0, frac * self.target(scene, q)), q,
                                      upper=v_in * (1 + 1e-12) + 1e-300)
        v = np.where(frac == 1.0, v_in, v)
        return self.strain_at(scene, v), self.pressure_rise(scene, v)

    def max_flow_rate(self, scene: Scene) -> float:
        """Largest flow rate with a steady state (``inf`` if none)."""
        if not math.isfinite(scene.wall._limit_pressure(scene.tb)):   # the rigid wall's included
            return math.inf
        if not scene.rheology.separable:
            return self._max_flow_rate_general(scene)
        j_inf = self._J_infinity(scene)
        if not math.isfinite(j_inf):
            return math.inf
        try:
            with np.errstate(over="ignore"):
                return float(scene.rheology._flow_factor_inverse(j_inf / scene.tube.length))
        except OverflowError:  # beyond double precision (e.g. the representable end of a Fung wall)
            return math.inf

    def _max_flow_rate_general(self, scene: Scene) -> float:
        """Non-separable rheology: the q with H(inf; q) = L (H decreases with q), by Brent's method;
        cached per (coupler, scene), since every flow-controlled solve asks for it."""
        try:
            return _cached_max_flow_rate(self, scene)
        except TypeError:  # an unhashable model
            return self._max_flow_rate_search(scene)

    def _max_flow_rate_search(self, scene: Scene) -> float:
        L = scene.tube.length
        tau_y = float(scene.rheology.yield_stress)
        if tau_y > 0 and not self._J_infinity(scene, 0.0) > L:
            return 0.0  # even the limit pressure cannot yield the fluid all along the tube

        def excess(log_q):
            return math.log(self._J_infinity(scene, math.exp(log_q))) - math.log(L)

        a = scene.tube.radius
        g0 = max(scene.wall._limit_pressure(scene.tb) / L, 4.0 * tau_y / a)
        log_q = math.log(float(scene.rheology._flow_rate(np.asarray([a]), np.asarray([g0]))[0]))
        if not math.isfinite(excess(log_q)):
            return math.inf  # G(q, R) falls off too fast in R: every flow rate has a steady state
        lo, hi = log_q, log_q
        while excess(lo) < 0:
            lo -= 2.0
        while excess(hi) > 0:
            hi += 2.0
            if hi - log_q > 200:
                return math.inf
        return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps))

    def _raise_runaway(self, scene, q, ok):
        q_max = self.max_flow_rate(scene)
        bad = q[~ok].flat[0]
        if math.isfinite(q_max) and bad >= q_max:
            raise NoSteadyStateError("flow_rate", q_max, bad, "the tube inflates without bound")
        cap = self._log_stretch_cap(scene)
        v = np.asarray(cap)
        sep = scene.rheology.separable
        if sep:
            reach = float(scene.rheology._flow_factor_inverse(self._J(scene, v, None) / scene.tube.length))
        else:
            v1 = np.array([cap])
            reach = float(self._solve_flow_rate(scene, v1, self.pressure_rise(scene, v1))[0])
        if cap < MAX_LOG_STRETCH:
            raise NoSteadyStateError("flow_rate", reach, bad,
                                     "the inlet stretch would reach the wall's maximum stretch")
        raise NoSteadyStateError("flow_rate", reach, bad,
                                 "the inlet stretch would exceed 1e15 (the tube inflates without practical bound)")




@functools.lru_cache(maxsize=256)
def _cached_max_flow_rate(coupler, scene) -> float:
    return coupler._max_flow_rate_search(scene)


def _rigid_state(scene: Scene, *, flow_rate=None, pressure_drop=None) -> State:
    r"""Hagen–Poiseuille in the rigid tube: :math:`\Delta p = L\,G(q, a)`, either way round."""
    a, L, rheo = scene.tube.radius, scene.tube.length, scene.rheology
    if flow_rate is not None:
        q = flow_rate
        dp = np.where(q == 0, 0.0, L * rheo._pressure_gradient(q, a))
    else:
        dp = pressure_drop
        q = np.where(dp == 0, 0.0, rheo._flow_rate(np.full_like(dp, a), np.where(dp == 0, 1.0, dp) / L))
    zero = np.zeros_like(q)
    return State(q, dp, zero + scene.outlet_strain, zero)
