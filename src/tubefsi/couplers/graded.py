r"""``Graded``: tubes whose radius, thickness or wall parameters vary along z (``docs/graded.md``).

The lubrication problem is :math:`dp/dz = -G(q, a(z)\,\lambda(p; \bar t(z), \theta(z)))`,
:math:`p(L) = p_{out}`, with :math:`\lambda` the local tube law's inverse.

*Separable case.* Where the tube law does not depend on z — :math:`\bar t = t/a` and every wall
parameter constant, only the radius varies — and the fluid is a power law,
:math:`G = \phi(q) R^{-k}`, the variables still separate:
:math:`\lambda^k\,dp = -\phi(q)\,a(z)^{-k}\,dz`, so the tube is the uniform tube of radius
:math:`a_{ref} = a(L)` and the *equivalent length*

.. math::

    L_{eq} = \int_0^L \Bigl(\frac{a_{ref}}{a(z)}\Bigr)^k dz,

the position z mapping to :math:`z_{eq}` with :math:`L_{eq} - z_{eq} = \int_z^L (a_{ref}/a)^k dz'`.
That uniform tube is solved by the separated-variables engine (exact, fast, tables), and
:math:`L_{eq}` by adaptive Gauss–Kronrod quadrature (relative 1e-15, split at the profiles'
breakpoints). The case is detected at the quadrature's own nodes: :math:`\bar t(z)` and the wall
parameters must equal their outlet values there to 1e-14.

*General case.* The ODE is integrated from the outlet to each requested position by an
embedded Dormand–Prince 8(5,3) pair with *per-point* step-size control, vectorized over all
points (each has its own position, step and error), never stepping across a breakpoint;
the tube law is inverted at every stage. The answer (local tolerance ``rtol``) is checked a
posteriori against a second integration at 100 ``rtol``: where the two differ by more than
``check_threshold`` an :class:`~tubefsi.AccuracyWarning` states the difference. Pressure-
controlled problems find the flow rate by bracketed root finding (Chandrupatla) on
:math:`\ln\Delta p(\ln q)`. A trial step beyond the local limit pressure is rejected and
halved; a point that cannot advance is beyond its steady state (:class:`~tubefsi.NoSteadyStateError`).
"""

from __future__ import annotations

import math
from typing import ClassVar, final

import attrs
import numpy as np

from .._lazy import lazy_module
from ..numerics.quadrature import adaptive
from ..errors import (AccuracyWarning, ConvergenceError, InvalidParameterError, NoSteadyStateError,
                      StretchRangeError, warn_user)
from ..fields import _array_fields, model_at
from ..geometry import Tube
from ..profiles import Profile
from ..scene import Scene, State
from ._options import tolerance
from .base import Coupler
from .checked import checked
from .closed_form import ClosedForm
from .quadrature import Quadrature

__all__ = ["Graded"]

# SciPy on first use (tubefsi._lazy): listing the models must not import it
elementwise = lazy_module("scipy.optimize.elementwise", globals(), "elementwise")
_dop = lazy_module("scipy.integrate._ivp.dop853_coefficients", globals(), "_dop")   # the DOP853 tableau
#: Relative deviation of t/a or a wall parameter from its outlet value still taken as constant.
_CONSTANT = 1e-14
#: The largest hoop stretch the integration along a graded tube follows (R/L is far beyond the
#: model's reach long before); a point that would exceed it is beyond its steady state.
STRETCH_CAP = 1e3
#: Steps (rounds over all points) before the integration gives up.
_MAX_ROUNDS = 20_000
#: A pressure this close (relative) to the local limit pressure short of the end of an integration
#: stops it as beyond the steady state (the tube law's stretch there is near 1e2.5 for a limit
#: approached as lambda^-4; the maximum flow rate extrapolates from there).
_NEAR_LIMIT = 1e-10
#: Newton steps (each one integration) of the maximum flow rate per candidate touch position.
_TOUCH_ROUNDS = 60
#: The estimated relative error of the maximum flow rate at which its Newton iteration stops.
_TOUCH_TOL = 1e-13


def _profiles(model):
    return {n: v for n in _array_fields(type(model)) if isinstance(v := getattr(model, n), Profile)}


def _breakpoints(scene) -> np.ndarray:
    """All breakpoints of the scene's profiles, sorted (m)."""
    found = set()
    for model in (scene.tube, scene.wall):
        for p in _profiles(model).values():
            found.update(p.breakpoints)
    return np.array(sorted(found), dtype=float)


def _split(lower, upper, breaks):
    """``(lo, hi, owner)``: the intervals ``[lower_i, upper_i]`` (lower < upper) split at ``breaks``."""
    n = lower.size
    if breaks.size == 0:
        return lower, upper, np.arange(n)
    edges = np.sort(np.clip(np.concatenate([lower[:, None], np.broadcast_to(breaks, (n, breaks.size)),
                                            upper[:, None]], axis=1), lower[:, None], upper[:, None]), axis=1)
    lo, hi = edges[:, :-1], edges[:, 1:]
    keep = hi > lo
    owner = np.broadcast_to(np.arange(n)[:, None], lo.shape)
    return lo[keep], hi[keep], owner[keep]


def _a_ref(scene):
    """The outlet radius a(L) of each point of a flat scene (the equivalent uniform tube's radius)."""
    L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (scene.size,))
    return np.broadcast_to(np.asarray(scene.tube.at(L)[0], dtype=float), (scene.size,))


def _points(scene, n):
    """The flat point of each of ``n`` entries: one each, or all the single point of a scalar scene."""
    return np.zeros(n, dtype=int) if scene.size == 1 else np.arange(n)



@final
@attrs.frozen(kw_only=True)
class Graded(Coupler):
    """Tubes and walls that vary along z: exact where separable, else an error-controlled ODE."""

    rtol: float = tolerance(1e-15, 1e-6, default=1e-13, doc="local relative tolerance of the integration along z")
    check_threshold: float = tolerance(1e-15, 1.0, default=1e-10,
                                       doc="largest difference from the 100 rtol integration without a warning")
    #: The coupler of the separable case's equivalent uniform tube (``"auto"`` or a coupler).
    uniform: object = "auto"

    cost_rank: ClassVar[int] = 5000
    meets_accuracy_contract: ClassVar[bool] = False     # never picked by "auto" for a uniform tube

    def supports(self, rheology, wall) -> bool:
        return True

    def describe(self) -> str:
        return f"Graded(rtol={self.rtol:g})"

    # ------------------------------------------------------------------ separable case
    def equivalent(self, scene: Scene):
        r"""The uniform scene equivalent to a separable graded scene (radius :math:`a(L)`, length
        :math:`L_{eq}`, the wall at z = L) and its coupler; None if the scene is not separable."""
        rheo = scene.rheology
        k = rheo.radius_exponent
        if not rheo.separable or k is None:
            return None
        n = scene.size
        index = np.arange(n)
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (n,))
        wall_out, tb_out = scene.at_outlet()
        a_ref = _a_ref(scene)
        value, ok = self._length_integral(scene, np.zeros(n), L, index, a_ref, wall_out, tb_out)
        if not ok:
            return None
        shared = scene.size == 1 or scene.shape == ()
        if shared:
            a_s, l_s, tb_s = float(a_ref[0]), float(value[0]), float(np.ravel(tb_out)[0])
        else:
            a_s, l_s, tb_s = a_ref, value, np.broadcast_to(tb_out, (n,))
        tube = Tube(radius=a_s, thickness=a_s * tb_s, length=l_s)
        uniform = Scene(rheology=rheo, wall=wall_out, tube=tube, outlet_pressure=scene.outlet_pressure,
                        external_pressure=scene.external_pressure, gauge_outlet_pressure=scene.gauge_outlet_pressure)
        return uniform

    def _length_integral(self, scene, lower, upper, index, a_ref, wall_out, tb_out):
        r""":math:`\int (a_{ref}/a)^k dz` over ``[lower, upper]`` per entry (points ``index``), and whether
        t/a and the wall parameters stayed at their outlet values on every node."""
        k = np.broadcast_to(np.asarray(scene.rheology.radius_exponent, dtype=float), (scene.size,))
        walls = _profiles(scene.wall)
        ref = {name: np.broadcast_to(np.asarray(getattr(wall_out, name), dtype=float), (scene.size,))
               for name in walls}
        tb_ref = np.broadcast_to(np.asarray(tb_out, dtype=float), (scene.size,))
        constant = [True]
        lo, hi, owner = _split(np.asarray(lower, dtype=float), np.asarray(upper, dtype=float), _breakpoints(scene))
        pts = np.asarray(index)[owner]

        def f(z, i):
            p = pts[i][:, None]
            a, t = scene.tube.at(z)
            if isinstance(scene.tube.thickness, Profile) or isinstance(scene.tube.radius, Profile):
                dev = np.abs(t / a / tb_ref[p] - 1.0)
                if np.any(dev > _CONSTANT):
                    constant[0] = False
            for name, prof in walls.items():
                if np.any(np.abs(prof(z) - ref[name][p]) > _CONSTANT * np.abs(ref[name][p])):
                    constant[0] = False
            return (a_ref[p] / a) ** k[p] + 0.0 * z

        result = adaptive(f, lo, hi, rtol=1e-15)
        if not constant[0]:
            return None, False
        if not np.all(result.converged) and np.any(result.error > 1e-13 * np.abs(result.value)):
            warn_user(f"the equivalent length of a tapered tube: estimated relative error "
                      f"{float(np.max(result.error / np.abs(result.value))):.2g}", AccuracyWarning)
        out = np.bincount(owner, result.value, minlength=np.size(lower))
        return out, True

    def _uniform(self, scene):
        """``(uniform scene, its coupler)`` for a separable scene, else None."""
        uniform = self.equivalent(scene)
        if uniform is None:
            return None
        return uniform, checked(_uniform_coupler(self.uniform, uniform))

    def _on_uniform(self, scene, method, *args):
        """``method`` of the equivalent uniform tube's coupler on it, or None if not separable."""
        found = self._uniform(scene)
        return None if found is None else getattr(found[1], method)(found[0], *args)

    # ------------------------------------------------------------------ problems
    def flow_controlled(self, scene, flow_rate):
        q = np.asarray(flow_rate, dtype=float)
        state = self._on_uniform(scene, "flow_controlled", q)
        if state is not None:
            return state
        try:
            rise = self._checked_rise(scene, q, np.zeros(q.shape))
        except (NoSteadyStateError, StretchRangeError) as error:
            # an integration that cannot advance: the maximum flow rate (a dozen integrations, only
            # now) says whether the point is beyond it, and the error gives it
            limit = np.broadcast_to(np.asarray(self.max_flow_rate(scene), dtype=float), q.shape)
            beyond = (q > 0) & (q >= limit)
            if not np.any(beyond):
                raise
            i = int(np.argmax(beyond))
            raise NoSteadyStateError("flow_rate", float(limit[i]), float(q[i]), "the tube inflates without bound") \
                from error
        return self._state(scene, q, rise)

    def _state(self, scene, q, rise):
        index = _points(scene, q.size)
        wall0, a0, tb0 = scene.at_position(np.zeros(q.size), index)
        p = np.asarray(scene.outlet_pressure) + rise
        strain = wall0._strain(p + 0.0 * rise, tb0)
        out_stretch = np.asarray(scene.outlet_stretch)
        v = np.log1p((strain - np.asarray(scene.outlet_strain)) / out_stretch)  # relative to the outlet's law
        return State(q, rise, strain + 0.0 * q, v + 0.0 * q)

    def pressure_controlled(self, scene, pressure_drop):
        dp = np.asarray(pressure_drop, dtype=float)
        state = self._on_uniform(scene, "pressure_controlled", dp)
        if state is not None:
            return state
        q, error = self._flow_rate(scene, dp)
        self._judge_error(error, "flow rate")
        return self._state(scene, q, dp)

    def max_flow_rate(self, scene, *, strict=True):
        r"""The maximum flow rate (m^3/s): the equivalent uniform tube's where separable; otherwise
        the flow rate at which the pressure first touches the local limit pressure somewhere
        (:meth:`touch`; ``inf`` where no section has one, or where the limit pressure never falls
        toward the inlet). ``strict`` is accepted for the solve's call and changes nothing."""
        q_max = self._on_uniform(scene, "max_flow_rate")
        if q_max is not None:
            return q_max
        q, _ = self.touch(scene)
        return float(q[0]) if scene.size == 1 else q

    def touch(self, scene):
        r"""``(q_max, z_touch)`` per point of a flat scene: the largest flow rate with a steady
        state and where its pressure reaches the local limit pressure :math:`p_{lim}(z)`
        (``docs/graded.md``, "The maximum flow rate").

        At the touch :math:`\lambda \to \infty`, so :math:`G = 0` there and the margin
        :math:`\varepsilon = p_{lim} - p` (:math:`\varepsilon' = p_{lim}' + G`) has a minimum 0:
        the touch is at the inlet if :math:`p_{lim}' \ge 0` there, or at an interior local minimum
        of :math:`p_{lim}` (a breakpoint, or a smooth minimum located by golden sections to 1e-10
        of the length). For each candidate :math:`z_c` the flow rate with
        :math:`p(z_c) = p_{lim}(z_c)` is found by safeguarded Newton steps on
        :math:`\ln(p(z_c) - p_{out})` against :math:`\ln q`, the slope :math:`W/(p - p_{out})` from
        the variational equations, from the feasible side (a bracket where a trial is beyond a
        limit); :math:`q_{max}` is the smallest. The answer is the Newton extrapolation from the last
        feasible iterate; its error, estimated from the step and the change of the slope, is stated
        by an :class:`~tubefsi.AccuracyWarning` above ``check_threshold`` (a touch where
        :math:`p_{lim}' = 0` — a smooth minimum, a uniform inlet section — makes the margin vanish
        faster than linearly in :math:`q`: ill-conditioned)."""
        n = scene.size
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (n,))
        p_out = np.broadcast_to(np.asarray(scene.outlet_pressure, dtype=float), (n,))
        zc, pts = self._touch_candidates(scene, L)
        q_max, z_touch = np.full(n, np.inf), np.full(n, np.nan)
        if zc.size == 0:
            return q_max, z_touch
        wall, _, tb = scene.at_position(zc, pts)
        target = np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * zc - p_out[pts]
        q_c, err = np.zeros(zc.size), np.zeros(zc.size)
        room = target > 0
        if np.any(room):
            q_c[room], err[room] = self._touch_flow_rate(scene, zc[room], pts[room], target[room], L[pts[room]])
        np.minimum.at(q_max, pts, q_c)            # the smallest per point
        chosen = q_c == q_max[pts]
        z_touch[pts[chosen]] = zc[chosen]
        self._judge_error(float(np.max(err[chosen], initial=0.0)), "maximum flow rate")
        return q_max, z_touch

    def _touch_candidates(self, scene, L):
        """``(z, point)`` of the candidate touch positions: the inlet where the limit pressure does
        not fall along z there, and the interior local minima of the limit pressure (on 257
        positions and the breakpoints; smooth minima refined by golden sections)."""
        n = scene.size
        breaks = _breakpoints(scene)
        grid = np.linspace(0.0, 1.0, 257)[:, None] * L
        inner = np.broadcast_to(breaks[:, None], (breaks.size, n))
        inner = np.where((inner > 0) & (inner < L), inner, L)          # outside: a duplicate of L
        z = np.concatenate([grid, inner])
        kink = np.concatenate([np.isin(grid, breaks), np.ones(inner.shape, bool)])
        order = np.argsort(z, axis=0, kind="stable")
        z, kink = np.take_along_axis(z, order, 0), np.take_along_axis(kink, order, 0)
        lim = self._limit_along(scene, z)
        if not np.any(np.isfinite(lim)):
            return np.zeros(0), np.zeros(0, dtype=int)
        with np.errstate(invalid="ignore"):
            first = np.isfinite(lim[0]) & (lim[0] <= lim[1])
            local = np.isfinite(lim[1:-1]) & (lim[1:-1] < lim[:-2]) & (lim[1:-1] <= lim[2:])
        rows, cols = np.nonzero(local)
        rows = rows + 1
        smooth = ~kink[rows, cols]
        zc = z[rows, cols].copy()
        if np.any(smooth):
            lo, hi = z[rows[smooth] - 1, cols[smooth]], z[rows[smooth] + 1, cols[smooth]]
            zc[smooth] = self._golden(scene, lo, hi, cols[smooth])
        zc = np.concatenate([np.zeros(int(np.sum(first))), zc])
        pts = np.concatenate([np.flatnonzero(first), cols])
        return zc, pts

    def _limit_along(self, scene, z):
        """The local limit pressure at the positions ``z`` (shape (m, n): n points)."""
        m, n = z.shape
        wall, _, tb = scene.at_position(z.ravel(), np.tile(np.arange(n), m))
        return (np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * z.ravel()).reshape(m, n)

    def _golden(self, scene, lo, hi, pts):
        """The minimum of the limit pressure in ``[lo, hi]`` by golden sections, to 1e-10 of the span."""
        r = (math.sqrt(5.0) - 1.0) / 2.0
        a, b = lo.copy(), hi.copy()
        c, d = b - r * (b - a), a + r * (b - a)

        def lim(z):
            wall, _, tb = scene.at_position(z, pts)
            return np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * z

        fc, fd = lim(c), lim(d)
        for _ in range(math.ceil(math.log(1e-10) / math.log(r))):
            left = fc <= fd                        # the minimum is in [a, d]: drop (d, b], else [a, c)
            a, b = np.where(left, a, c), np.where(left, d, b)
            keep, f_keep = np.where(left, c, d), np.where(left, fc, fd)
            new = np.where(left, b - r * (b - a), a + r * (b - a))
            f_new = lim(new)
            c, fc = np.where(left, new, keep), np.where(left, f_new, f_keep)
            d, fd = np.where(left, keep, new), np.where(left, f_keep, f_new)
        return 0.5 * (a + b)

    def _touch_flow_rate(self, scene, zc, pts, target, L):
        r"""The flow rates with :math:`p(z_c) - p_{out} =` ``target`` (the local limit) and the
        estimated relative errors: safeguarded Newton on :math:`f(x) = \ln(p(z_c) - p_{out}) -
        \ln(\text{target})`, :math:`x = \ln q`, :math:`f' = W/(p - p_{out})`, integrated at
        ``rtol``/10; the integration's share of the error from the difference of :math:`f` at
        10 ``rtol``."""
        rheo = scene.rheology
        _, a, _ = scene.at_position(zc, pts)
        # start: the rigid tube of the section's radius under the mean gradient
        x = np.log(model_at(rheo, pts)._flow_rate(a, target / (L - zc)))
        x_hi = np.full(zc.size, np.inf)
        rtol = max(1e-15, 0.1 * self.rtol)     # the slope d ln p/d ln q < 1 amplifies the pressure's error
        x, x_hi, f, d, err = self._touch_newton(scene, zc, pts, target, x, x_hi, rtol)
        root = x - f / d
        rise = self._integrate(scene, np.exp(x), zc, 100 * rtol, index=pts, strict=False)[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            err = err + np.abs((np.log(rise) - np.log(target) - f) / d)
        return np.exp(root), np.where(np.isfinite(err), err, np.inf)

    def _touch_newton(self, scene, zc, pts, target, x, x_hi, rtol):
        """Safeguarded Newton steps (see :meth:`_touch_flow_rate`) at the integration tolerance
        ``rtol``: ``(x_lo, x_hi, f, f', error)``, ``x_lo`` the last feasible iterate."""
        m = zc.size
        x = x.copy()
        x_lo, f_lo, d_lo = np.full(m, -np.inf), np.zeros(m), np.ones(m)
        d_prev, x_prev = np.full(m, np.nan), np.full(m, np.nan)
        err = np.full(m, np.inf)
        active = np.ones(m, dtype=bool)
        for _ in range(_TOUCH_ROUNDS):
            sel = np.flatnonzero(active)
            if sel.size == 0:
                break
            rise, w, _ = self._integrate(scene, np.exp(x[sel]), zc[sel], rtol, index=pts[sel], strict=False,
                                         variational=True, control=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                ok = np.isfinite(rise) & (rise < target[sel]) & (w > 0)
                f = np.log(rise) - np.log(target[sel])
                d = w / rise
            good, bad = sel[ok], sel[~ok]
            x_hi[bad] = np.minimum(x_hi[bad], x[bad])
            x_prev[good], d_prev[good] = x_lo[good], d_lo[good]
            x_lo[good], f_lo[good], d_lo[good] = x[good], f[ok], d[ok]
            step = -f_lo[sel] / d_lo[sel]
            known = np.isfinite(x_lo[sel])
            # the error of the Newton extrapolation: |step| times the relative change of the slope
            with np.errstate(divide="ignore", invalid="ignore"):
                curvature = np.abs((d_lo[sel] - d_prev[sel]) / (x_lo[sel] - x_prev[sel])) / d_lo[sel]
                e = np.where(np.isfinite(curvature) & np.isfinite(x_prev[sel]), 0.5 * curvature * step**2,
                             np.abs(step))
            err[sel] = np.where(known, e, np.inf)
            trial = np.where(known, x_lo[sel] + step, x[sel] - 2.0)
            beyond = trial >= x_hi[sel]
            trial = np.where(beyond & known, 0.5 * (x_lo[sel] + x_hi[sel]), trial)
            done = known & ((err[sel] <= _TOUCH_TOL) | (x_hi[sel] - x_lo[sel] <= 1e-15))
            x[sel] = trial
            active[sel[done]] = False
        if not np.all(np.isfinite(x_lo)):
            raise ConvergenceError("the maximum flow rate of a graded tube: no flow rate below the limit was found")
        step = -f_lo / d_lo
        err = np.where(active, np.maximum(err, np.minimum(np.abs(step), x_hi - x_lo)), err)
        return x_lo, x_hi, f_lo, d_lo, err

    def sensitivities(self, scene, state):
        r"""The derivatives of a solve: those of the equivalent uniform tube where the scene
        separates (its pressure drop is the same function of the flow rate and the end pressures);
        otherwise from the variational equations integrated along z with the pressure
        (:meth:`_integrate`): :math:`d\Delta p/dq = W(0)/q`, :math:`\partial q/\partial p_{in} =
        q/W(0)`, :math:`\partial q/\partial p_{out} = -V(0)\,q/W(0)`, checked at 100 ``rtol``
        like the pressure. At ``q = 0`` the limit :math:`q \to 0^+` (an apparent shear rate of
        1e-30/s at the outlet, as for uniform tubes)."""
        found = self._uniform(scene)
        if found is not None:
            return found[1].sensitivities(found[0], state)
        q = np.asarray(state.flow_rate, dtype=float).ravel()
        index = _points(scene, q.size)
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (scene.size,))[index]
        wall_l, a_l, tb_l = scene.at_position(L, index)
        p_out = np.broadcast_to(np.asarray(scene.outlet_pressure, dtype=float), (scene.size,))[index]
        r_out = a_l * (1.0 + wall_l._strain(p_out, tb_l))
        q_use = np.where(q > 0, q, 0.25e-30 * math.pi * r_out**3)
        _, w, v = self._integrate(scene, q_use, np.zeros(q.size), self.rtol, variational=True)
        _, w_c, v_c = self._integrate(scene, q_use, np.zeros(q.size), 100 * self.rtol, variational=True)
        self._judge(w, w_c, "sensitivity q dp/dq")
        self._judge(v, v_c, "sensitivity dp_in/dp_out")
        return w / q_use, q_use / w, -v * q_use / w

    def length_integral(self, scene, state, weight, *, uniform=False):
        """Not implemented along a graded tube (the separated identity behind the weighted length
        integrals does not hold): ``InvalidParameterError``."""
        raise InvalidParameterError("tube", "a uniform tube for the parameter derivatives of a solve", scene.tube,
                                    "a graded tube: difference two solves")

    def limit_pressure(self, scene):
        """The largest inlet pressure with a steady state: the inlet section's limit pressure where
        the pressure can only touch its local limit at the inlet (or nowhere); where it can touch
        it downstream first (a softer section: :meth:`touch`), the inlet pressure just below the
        maximum flow rate (1e-9 below it)."""
        n = scene.size
        wall, _, tb = scene.at_position(np.zeros(n), np.arange(n))
        inlet = wall._limit_pressure(tb)
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (n,))
        if self._uniform(scene) is not None or not np.any(self._touch_candidates(scene, L)[0] > 0):
            return inlet
        out = np.asarray(inlet, dtype=float) + np.zeros(n)
        q_max, z_touch = self.touch(scene)
        inside = np.flatnonzero(np.isfinite(q_max) & (z_touch > 0))
        if inside.size:
            p_out = np.broadcast_to(np.asarray(scene.outlet_pressure, dtype=float), (n,))[inside]
            rise = self.rise(scene, q_max[inside] * (1.0 - 1e-9), np.zeros(inside.size), self.rtol, index=inside,
                             strict=False)
            out[inside] = np.minimum(out[inside], np.where(np.isfinite(rise), p_out + rise, out[inside]))
        return out

    def profile(self, scene, state, z):
        z = np.asarray(z, dtype=float)
        q = np.asarray(state.flow_rate, dtype=float)
        n = q.size
        index = _points(scene, n)
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (scene.size,))[index]
        zz = np.broadcast_to(z, (n,))
        found = self._uniform(scene)
        if found is not None:
            uniform, inner = found
            wall_out, tb_out = scene.at_outlet()
            a_ref = _a_ref(scene)
            tail, _ = self._length_integral(scene, zz.copy(), L.copy(), index, a_ref, wall_out, tb_out)
            l_eq = np.broadcast_to(np.asarray(uniform.tube.length, dtype=float), (scene.size,))[index]
            z_eq = np.clip(l_eq - tail, 0.0, l_eq)
            return inner.profile(uniform, state, z_eq)
        rise = self._checked_rise(scene, q, zz)
        wall, _, tb = scene.at_position(zz, index)
        strain = wall._strain(np.asarray(scene.outlet_pressure) + rise, tb)
        return strain, rise

    # ------------------------------------------------------------------ the integration
    def _judge(self, fine, coarse, what):
        fine, coarse = np.asarray(fine, dtype=float), np.asarray(coarse, dtype=float)
        nz = fine != 0
        self._judge_error(float(np.max(np.abs(coarse[nz] / fine[nz] - 1.0), initial=0.0)), what)

    def _judge_error(self, err, what):
        if err > self.check_threshold:
            warn_user(f"{self.describe()}: the {what} at rtol {self.rtol:g} and {100 * self.rtol:g} differ by "
                      f"{err:.2g} (relative), more than {self.check_threshold:.2g}: the estimate of its error",
                      AccuracyWarning)

    def _checked_rise(self, scene, q, z_end):
        fine = self.rise(scene, q, z_end, self.rtol)
        coarse = self.rise(scene, q, z_end, 100 * self.rtol)
        self._judge(fine, coarse, "pressure rise")
        return fine

    def rise(self, scene, q, z_end, rtol, index=None, *, strict=True):
        r"""The pressure rise :math:`p(z_{end}) - p_{out}` (Pa) for the flow rates ``q`` at the points
        ``index`` of a flat scene (default: one per point), integrating from the outlet. Where the
        pressure reaches a local limit pressure on the way: ``NoSteadyStateError`` (``strict``) or
        ``inf``."""
        return self._integrate(scene, q, z_end, rtol, index, strict=strict)[0]

    def _integrate(self, scene, q, z_end, rtol, index=None, *, strict=True, variational=False, control=None):
        r"""The integration along z from the outlet to ``z_end``: the pressure rise (Pa) and, with
        ``variational``, its sensitivities :math:`W = q\,\partial p/\partial q` (Pa) and
        :math:`V = \partial p/\partial p_{out}` integrated with it (one error control for the three):

        .. math::

            \frac{dW}{dz} = -kG - cW,\qquad \frac{dV}{dz} = -cV,\qquad W(L) = 0,\ V(L) = 1,

        :math:`k = \partial\ln G/\partial\ln q`, :math:`c = \partial G/\partial p|_z
        = -(1 + 3k)\,G/(\lambda P_\lambda)` (:math:`\partial\ln G/\partial\ln R = -(1 + 3k)` for every
        generalized Newtonian fluid: :math:`q = R^3 f(GR/2)`). Returns ``(rise, W, V)`` in the
        shape of ``q`` (``W, V`` None without ``variational``). ``control``: the rows whose error
        the step control bounds (default all; ``1``: the pressure only, for a Newton slope)."""
        shape = np.shape(q)
        q = np.asarray(q, dtype=float).ravel()
        n = q.size
        m = 3 if variational else 1
        index = _points(scene, n) if index is None else np.asarray(index, dtype=int).ravel()
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (scene.size,))[index] if np.ndim(
            scene.tube.length) else np.full(n, float(scene.tube.length))
        z_end = np.broadcast_to(np.asarray(z_end, dtype=float), shape).ravel().copy()
        rheo = scene.rheology
        p_out = np.broadcast_to(np.asarray(scene.outlet_pressure, dtype=float), (scene.size,))[index] if np.ndim(
            scene.outlet_pressure) else np.full(n, float(scene.outlet_pressure))
        out = np.zeros((m, n))
        if variational:
            out[2] = 1.0
        live = np.flatnonzero((q > 0) & (z_end < L))
        if live.size == 0:
            return _unpack(out, shape, variational)
        idx = index[live]
        # the scale of the pressure: the rigid-tube drop at the outlet radius
        wall_l, a_l, tb_l = scene.at_position(L[live], idx)
        r_out = a_l * (1.0 + wall_l._strain(p_out[live], tb_l))
        scale = L[live] * model_at(rheo, idx)._pressure_gradient(q[live], r_out)
        breaks = _breakpoints(scene)
        stopped = np.zeros(live.size, dtype=bool)

        def rhs(zs, ys, sel):
            """dy/dz at (zs, ys) for the live entries ``sel`` (NaN beyond the local tube law)."""
            pts = idx[sel]
            wall, a, tb = scene.at_position(zs, pts)
            p = p_out[live][sel] + ys[0] * scale[sel]
            lim = np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * p
            low = np.asarray(wall._min_pressure(tb), dtype=float) + 0.0 * p
            bad = ~((p < lim) & (p >= low)) | ~np.isfinite(p)
            fluid = model_at(rheo, pts)
            with np.errstate(all="ignore"):
                e = wall._strain(np.where(bad, p_out[live][sel], p), tb)
                g = fluid._pressure_gradient(q[live][sel], a * (1.0 + e))
                bad = bad | ~np.isfinite(g) | (e > STRETCH_CAP - 1.0)
                dy = np.empty((m, sel.size))
                dy[0] = -g / scale[sel]
                if variational:
                    k = fluid._flow_index(q[live][sel], a * (1.0 + e))
                    c = -(1.0 + 3.0 * k) * g / ((1.0 + e) * wall._stiffness(1.0 + e, tb))
                    dy[1] = -k * g / scale[sel] - c * ys[1]
                    dy[2] = -c * ys[2]
            return np.where(bad, np.nan, dy)

        stages = _dop.N_STAGES
        A, B, C, E3, E5 = _dop.A[:stages, :stages], _dop.B, _dop.C[:stages], _dop.E3, _dop.E5
        z = L[live].copy()
        y = np.zeros((m, live.size))
        if variational:
            y[2] = 1.0
        span = z - z_end[live]
        h = -np.minimum(span, span * rtol ** 0.125 * 4)
        f = rhs(z, y, np.arange(live.size))
        active = np.ones(live.size, dtype=bool)
        atol = rtol
        for _ in range(_MAX_ROUNDS):
            sel = np.flatnonzero(active)
            if sel.size == 0:
                break
            zs, ys, hs = z[sel], y[:, sel], h[sel]
            target = z_end[live][sel]
            if breaks.size:          # the next breakpoint below z (strictly), else the end
                j = np.searchsorted(breaks, zs, side="left") - 1
                nxt = np.where(j >= 0, breaks[np.maximum(j, 0)], -np.inf)
                target = np.maximum(target, nxt)
            hs = np.maximum(hs, target - zs)              # h < 0: not beyond the stop
            K = np.empty((stages + 1, m, sel.size))
            K[0] = f[:, sel]
            for s in range(1, stages):
                K[s] = rhs(zs + C[s] * hs, ys + np.einsum("s,smn->mn", A[s, :s], K[:s]) * hs, sel)
            y_new = ys + hs * np.einsum("s,smn->mn", B, K[:-1])
            land = np.abs(target - (zs + hs)) <= 1e-15 * np.abs(zs) + 1e-300
            z_new = np.where(land, target, zs + hs)
            K[-1] = rhs(z_new, y_new, sel)
            sc = atol + rtol * np.maximum(np.abs(ys), np.abs(y_new))
            with np.errstate(all="ignore"):
                e5 = np.einsum("s,smn->mn", E5, K) / sc
                e3 = np.einsum("s,smn->mn", E3, K) / sc
                denom = np.sqrt(e5**2 + 0.01 * e3**2)
                err = np.abs(hs) * np.max(np.where(denom > 0, e5**2 / denom, 0.0)[:control], axis=0)
            broken = ~(np.isfinite(err) & np.all(np.isfinite(y_new), axis=0)
                       & np.all(np.isfinite(K), axis=(0, 1)))   # beyond the law
            good = ~broken & (err <= 1.0)
            with np.errstate(all="ignore", divide="ignore"):
                factor = np.where(np.isfinite(err) & (err > 0), 0.9 * err ** -0.125, 10.0)
            factor = np.where(good, np.clip(factor, 1.0, 10.0), np.where(broken, 0.1, np.clip(factor, 0.2, 0.9)))
            acc = sel[good]
            z[acc], y[:, acc], f[:, acc] = z_new[good], y_new[:, good], K[-1][:, good]
            if acc.size:              # within 1e-10 of a local limit pressure short of the end: stop
                wall, _, tb = scene.at_position(z[acc], idx[acc])
                lim = np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * z[acc]
                p = p_out[live][acc] + y[0, acc] * scale[acc]
                with np.errstate(invalid="ignore"):
                    near = np.isfinite(lim) & (p >= lim - _NEAR_LIMIT * np.abs(lim)) & (z[acc] > z_end[live][acc])
                stopped[acc[near]] = True
                active[acc[near]] = False
            h[sel] = hs * factor
            done = good & (z_new <= z_end[live][sel])
            active[sel[done]] = False
            # an overshoot that no longer shrinks: the stretch cap or the local limit is within |h|
            tiny = ~good & (np.abs(h[sel]) < 1e-6 * L[live][sel]) & (z_new - z_end[live][sel] > 10 * np.abs(h[sel]))
            if np.any(tiny):
                stopped[sel[tiny]] = True
                active[sel[tiny]] = False
        else:
            raise ConvergenceError(f"the integration along the graded tube took more than {_MAX_ROUNDS} steps")
        if np.any(stopped) and strict:
            i = int(np.flatnonzero(stopped)[0])
            wall, _, tb = scene.at_position(z[i:i + 1], idx[i:i + 1])
            limit = float(np.ravel(wall._limit_pressure(tb))[0])
            where = (f"at z = {z[i]:.6g} m the pressure reaches the local limit of the tube law (a hoop stretch "
                     f"{STRETCH_CAP:g}): the flow rate {q[live][i]:.6g} m^3/s is beyond the tube's maximum one")
            if not math.isfinite(limit):
                raise StretchRangeError(math.nan, float(q[live][i]), where.replace("the pressure reaches the local "
                                        "limit of the tube law", "the tube inflates beyond").split(":")[0])
            raise NoSteadyStateError("pressure", limit, float(p_out[live][i] + y[0, i] * scale[i]), where,
                                     name="the (transmural) pressure")
        y = np.where(stopped, np.inf, y)
        out[:, live] = y
        out[:2, live] *= scale
        return _unpack(out, shape, variational)

    def _flow_rate(self, scene, dp):
        r"""The flow rates with pressure drop ``dp`` (per point): bracketed root finding on
        :math:`\ln\Delta p(\ln q)` with a loose integration (1e-9), then Newton steps with the
        integration at ``rtol`` (the slope from the variational equations); the flow rate's error
        is estimated from the pressure drop at 100 ``rtol`` over that slope. A drop whose residual
        stays above 1e-9 there is beyond every steady state (``NoSteadyStateError``)."""
        n = dp.size
        q = np.zeros(n)
        live = np.flatnonzero(dp > 0)
        if live.size == 0:
            return q
        ids = _points(scene, n)[live]
        L = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (scene.size,))[ids]
        p_out = np.broadcast_to(np.asarray(scene.outlet_pressure, dtype=float), (scene.size,))[ids]
        # rigid tubes bracket the flow: the narrowest section under the outlet pressure, and the
        # widest under the inlet pressure (or near its local limit), at the mean gradient
        nodes = np.linspace(0.0, 1.0, 33)
        zz = (nodes[:, None] * L).ravel()
        rows = np.tile(np.arange(live.size), nodes.size)
        wall, a, tb = scene.at_position(zz, ids[rows])
        lim = np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * zz
        low = np.asarray(wall._min_pressure(tb), dtype=float) + 0.0 * zz
        with np.errstate(invalid="ignore"):
            near = np.where(np.isfinite(lim), lim - 1e-3 * np.abs(lim), np.inf)
        p_hi = np.clip(np.minimum((p_out + dp[live])[rows], near), low, None)
        r_lo = (a * (1.0 + wall._strain(np.maximum(p_out[rows], low), tb))).reshape(nodes.size, -1).min(axis=0)
        r_hi = (a * (1.0 + wall._strain(p_hi, tb))).reshape(nodes.size, -1).max(axis=0)
        rheo = model_at(scene.rheology, ids)
        x_lo = np.log(rheo._flow_rate(0.98 * r_lo, dp[live] / L))
        x_hi = np.log(rheo._flow_rate(1.02 * r_hi, dp[live] / L))
        log_dp = np.log(dp[live])
        loose = max(1e-9, self.rtol)

        def f(log_q, which, target, rtol=loose):
            rise = self.rise(scene, np.exp(log_q), np.zeros(which.size), rtol, index=which, strict=False)
            return np.where(np.isfinite(rise), np.log(rise) - target, 50.0)   # beyond the limit: too much

        br = elementwise.bracket_root(f, x_lo, x_hi, xmin=x_lo - 700.0, xmax=x_hi + 60.0, args=(ids, log_dp))
        if not np.all(br.success):
            raise ConvergenceError("the flow rate of a graded tube under a pressure drop could not be bracketed")
        res = elementwise.find_root(f, br.bracket, args=(ids, log_dp), tolerances=dict(xrtol=1e-11, xatol=1e-11))
        if not np.all(res.success):
            raise ConvergenceError("the flow rate of a graded tube under a pressure drop did not converge")
        # the root, or the end of the bracket below the limit (a drop beyond every steady state
        # brackets the edge of the feasible flow rates instead: its residual stays large below)
        x = np.where(res.f_x < 50.0, res.x, res.bracket[0])
        rise, w, _ = self._integrate(scene, np.exp(x), np.zeros(x.size), loose, index=ids, strict=False,
                                     variational=True, control=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = w / rise                                     # d ln dp / d ln q, exact
        slope = np.where(np.isfinite(slope) & (slope > 0), slope, 1.0)
        for _ in range(4):
            miss = f(x, ids, log_dp, self.rtol)
            x = x - np.where(miss < 50.0, miss, 0.0) / slope
            if np.all(np.abs(miss / slope) <= 1e-15 * np.maximum(1.0, np.abs(x))):
                break
        miss = f(x, ids, log_dp, self.rtol)
        beyond = ~(np.abs(miss) <= 1e-9)
        if np.any(beyond):
            i = int(np.flatnonzero(beyond)[0])
            reached = float(p_out[i] + dp[live][i] * math.exp(min(float(miss[i]), 0.0)))
            raise NoSteadyStateError("pressure", reached, float(p_out[i] + dp[live][i]),
                                     "the largest inlet pressure with a steady state, that of the maximum flow rate "
                                     "(the pressure touches the local limit pressure of a section downstream); "
                                     "the limit given is the inlet pressure reached below it",
                                     name="the inlet pressure")
        miss_coarse = f(x, ids, log_dp, 100 * self.rtol) - f(x, ids, log_dp, self.rtol)
        q[live] = np.exp(x)
        return q, np.max(np.abs(miss_coarse / slope), initial=0.0)


def _unpack(out, shape, variational):
    """``(rise, W, V)`` from the integration's rows, in ``shape`` (``W, V`` None unless variational)."""
    if not variational:
        return out[0].reshape(shape), None, None
    return tuple(row.reshape(shape) for row in out)


def _uniform_coupler(choice, scene):
    """The separated-variables coupler for the equivalent uniform tube (``"auto"``: closed form where
    the pair has one, else quadrature), or ``choice`` itself."""
    if isinstance(choice, Coupler):
        return choice
    closed = ClosedForm()
    return closed if closed.supports(scene.rheology, scene.wall) else Quadrature()
