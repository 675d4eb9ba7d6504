r"""``ode``: integrate the lubrication ODE along the tube, as the chapter does.

The state is the hoop strain and the pressure rise, :math:`y = (\lambda - 1, p - p_{out})`,
each divided by its rigid-tube scale (:math:`\Delta p_0 = L\,G(q, a)` and
:math:`\Delta p_0/P'(1)`) so that the tolerances act on O(1) numbers, integrated from
:math:`z = L` (outlet strain, :math:`p = p_{out}`) to :math:`z = 0`:

.. math::

    \frac{d\lambda}{dz} = -\frac{G(q, a\lambda)}{P'(\lambda)}, \qquad
    \frac{dp}{dz} = -G(q, a\lambda).

``method`` is any :func:`scipy.integrate.solve_ivp` method (default tolerances
rtol = 1e-8, atol = 1e-10), or ``"odeint"`` for :func:`scipy.integrate.odeint` (LSODA)
with its own defaults — the chapter's method, kept as the speed baseline. Pressure-controlled problems are solved by
shooting on the flow rate (Brent's method inside the rigid-tube bracket). One ODE
runs per point; this coupler is a reference, not a default. With ``check_error`` (the
default) :func:`tubefsi.solve` re-integrates at 1/100 of the tolerances
(:meth:`ODE.refined`, through :class:`~tubefsi.couplers.Checked`) and warns where the two
results differ by more than ten times the tolerance. The maximum flow rate, the profiles
and the rigid tube come from the separated-variables engine (``quadrature``): they are
properties of the problem, not of the integrator.
"""

from __future__ import annotations

import math
from typing import ClassVar, final

import attrs
import numpy as np

from .._lazy import lazy_module
from ..errors import ConvergenceError, NoSteadyStateError
from ..fields import choice
from ..scene import State
from ._options import flag, tolerance
from .base import Coupler
from .quadrature import Quadrature

# SciPy on first use (tubefsi._lazy): listing the models must not import it
integrate = lazy_module("scipy.integrate", globals(), "integrate")
optimize = lazy_module("scipy.optimize", globals(), "optimize")

__all__ = ["ODE"]

#: Right-hand-side evaluations allowed per integration before giving up.
_MAX_EVALUATIONS = 20_000

_METHODS = ("odeint", "RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")


#: The engine behind the maximum flow rate, the profiles and the rigid tube.
_ENGINE = Quadrature()


@final
@attrs.frozen(kw_only=True)
class ODE(Coupler):
    """Integrate dp/dz = -G(q, R(p)) with SciPy (reference path, one ODE per point)."""

    method: str = choice(_METHODS, default="LSODA", doc="SciPy's integrator (odeint or a solve_ivp method)")
    rtol: float | None = tolerance(0.0, 0.1, default=None, optional=True, doc="relative tolerance (None: the default)")
    atol: float | None = tolerance(0.0, 1e300, default=None, optional=True,
                                   doc="absolute tolerance (None: the default)")
    #: Re-integrate at 1/100 of the tolerances and warn (AccuracyWarning) where the two
    #: results differ by more than ten times the tolerance: the global error of a
    #: local-error-controlled integrator can exceed its tolerance, e.g. near a limit.
    check_error: bool = flag(default=True, doc="re-integrate at 1/100 of the tolerances and compare")

    cost_rank: ClassVar[int] = 1000
    meets_accuracy_contract: ClassVar[bool] = False

    def supports(self, rheology, wall) -> bool:
        return True

    def max_flow_rate(self, scene):
        return _ENGINE.max_flow_rate(scene)

    def profile(self, scene, state, z):
        return _ENGINE.profile(scene, state, z)

    def refined(self):
        """The same integrator at 1/100 of the tolerances (when ``check_error``)."""
        if not self.check_error:
            return None
        rtol, atol = self._tolerances()
        return attrs.evolve(self, rtol=0.01 * rtol, atol=0.01 * atol, check_error=False)

    def error_threshold(self) -> float:
        return min(10 * self._tolerances()[0], 1e-3)

    def describe(self) -> str:
        return f"ODE({self.method}, rtol={self._tolerances()[0]:g})"

    def _tolerances(self):
        """The tolerances in force: odeint's own defaults, or 1e-8 / 1e-10 for solve_ivp."""
        if self.method == "odeint":
            return (self.rtol or 1.49012e-8), (self.atol or 1.49012e-8)
        return (self.rtol or 1e-8), (self.atol or 1e-10)

    def _integrate(self, scene, q):
        """Return (inlet strain, pressure rise) for one flow rate."""
        tb, a, L = scene.tb, scene.tube.radius, scene.tube.length
        wall, rheo = scene.wall, scene.rheology
        lam_max = wall._max_stretch(tb)
        rtol, atol = self._tolerances()
        drop0 = L * float(rheo._pressure_gradient(np.asarray([q]), np.asarray([a * scene.outlet_stretch]))[0])
        strain0 = drop0 / float(wall._stiffness(np.asarray(scene.outlet_stretch), tb))

        calls = [0]

        def rhs(z, y):
            calls[0] += 1
            if calls[0] > _MAX_EVALUATIONS:
                raise ConvergenceError(f"{self.method} needed more than {_MAX_EVALUATIONS} steps at q = {float(q):.6g} "
                                       "(a stiff or nearly unbounded inflation)")
            lam = 1.0 + y[0] * strain0
            lam = min(max(lam, 1.0), lam_max * (1 - 1e-15)) if math.isfinite(lam_max) else max(lam, 1.0)
            with np.errstate(all="ignore"):
                g = float(rheo._pressure_gradient(np.asarray([q]), np.asarray([a * lam]))[0])
                stiff = float(wall._stiffness(np.asarray(lam), tb))
            if not (math.isfinite(g) and stiff > 0):
                raise ConvergenceError(f"the ODE left the tube law's range (stretch {lam:.3g}) at q = {float(q):.6g}")
            return [-g / stiff / strain0, -g / drop0]

        y0 = [scene.outlet_strain / strain0, 0.0]
        try:
            if self.method == "odeint":
                y, info = integrate.odeint(rhs, y0, [L, 0.0], tfirst=True, full_output=True,
                                           rtol=rtol, atol=atol)
                if info["message"] != "Integration successful.":
                    raise ConvergenceError(f"odeint failed at q = {float(q):.6g}: {info['message']}")
                strain, rise = y[-1]
            else:
                sol = integrate.solve_ivp(rhs, (L, 0.0), y0, method=self.method, rtol=rtol, atol=atol)
                if not sol.success:
                    raise ConvergenceError(f"solve_ivp({self.method}) failed at q = {float(q):.6g}: {sol.message}")
                strain, rise = sol.y[:, -1]
        except (ArithmeticError, FloatingPointError) as exc:
            if isinstance(exc, ConvergenceError):
                raise
            raise ConvergenceError(f"{self.method} failed at q = {float(q):.6g}: {type(exc).__name__}: {exc}") from exc
        strain, rise = strain * strain0, rise * drop0
        if not (np.isfinite(strain) and np.isfinite(rise)):
            raise ConvergenceError(f"the ODE solution is not finite at q = {float(q):.6g}")
        return strain, rise

    def _shoot(self, scene, drop, lo, hi):
        """The flow rate whose integrated pressure rise is ``drop``, by Brent's method in [lo, hi]."""

        def miss(qq):
            return self._integrate(scene, qq)[1] - drop

        q_max = self.max_flow_rate(scene)
        f_lo, f_hi = miss(lo), miss(hi)
        for _ in range(20):  # integration error may shift the root just outside the exact bracket
            if f_lo <= 0 <= f_hi:
                break
            if f_lo > 0:
                lo *= 0.999
                f_lo = miss(lo)
            if f_hi < 0:
                hi = hi * 1.001 if not math.isfinite(q_max) else 0.5 * (hi + q_max)
                f_hi = miss(hi)
        else:
            raise ConvergenceError(f"{self.method}: shooting could not bracket the flow rate for Δp = {float(drop):.6g}")
        return optimize.brentq(miss, lo, hi, xtol=1e-300, rtol=8 * np.finfo(float).eps)

    def flow_controlled(self, scene, flow_rate) -> State:
        q = np.asarray(flow_rate, dtype=float)
        if scene.wall.is_rigid:
            return _ENGINE.flow_controlled(scene, q)
        q_max = np.broadcast_to(np.asarray(self.max_flow_rate(scene), dtype=float), q.shape)
        if np.any(q >= q_max):
            i = int(np.argmax(q >= q_max))
            raise NoSteadyStateError("flow_rate", float(q_max[i]), float(q[i]))
        strain = np.empty(q.size)
        rise = np.empty(q.size)
        for i, qi in enumerate(q.ravel()):          # one ODE per point, on that point's scene
            one = scene.point(i)
            strain[i], rise[i] = (one.outlet_strain, 0.0) if qi == 0 else self._integrate(one, qi)
        out_strain = np.broadcast_to(np.asarray(scene.outlet_strain), q.shape)
        out_stretch = np.broadcast_to(np.asarray(scene.outlet_stretch), q.shape)
        v = np.log1p((strain - out_strain) / out_stretch)
        return State(q, rise, strain, v)

    def pressure_controlled(self, scene, pressure_drop) -> State:
        dp = np.asarray(pressure_drop, dtype=float)
        if scene.wall.is_rigid:
            return _ENGINE.pressure_controlled(scene, dp)
        q = np.zeros(dp.size)
        e_in = np.zeros(dp.size)
        q_max = np.broadcast_to(np.asarray(self.max_flow_rate(scene), dtype=float), dp.shape)
        for i, d in enumerate(dp.ravel()):
            one = scene.point(i)
            tb, a, L, rheo = one.tb, one.tube.radius, one.tube.length, one.rheology
            one.wall._check_pressure(one.outlet_pressure + d, tb)
            e = float(one.wall._strain(np.asarray(one.outlet_pressure + d), tb))
            e_in[i] = e
            if d == 0:
                continue
            # the flow lies between the rigid-tube flows at the outlet and inlet radii (and below q_max)
            lo = float(rheo._flow_rate(np.asarray([a * one.outlet_stretch]), np.asarray([d / L]))[0])
            hi = min(float(rheo._flow_rate(np.asarray([a * (1.0 + e)]), np.asarray([d / L]))[0]),
                     float(q_max[i]) * (1 - 1e-12))
            if hi <= lo * (1 + 1e-14):
                q[i] = lo
                continue
            q[i] = self._shoot(one, d, lo, hi)
        out_strain = np.broadcast_to(np.asarray(scene.outlet_strain), dp.shape)
        out_stretch = np.broadcast_to(np.asarray(scene.outlet_stretch), dp.shape)
        v = np.log1p((e_in - out_strain) / out_stretch)
        return State(q.reshape(dp.shape), dp, e_in, v)
