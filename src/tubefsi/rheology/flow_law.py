r"""The tube-flow function of any rheology: the Rabinowitsch–Mooney integral, and a table of its
inverse built on fixed panels (the non-separable path of :meth:`Rheology._pressure_gradient`).

In a tube the flow depends on the wall stress :math:`\tau_w = GR/2` only through the apparent wall
shear rate

.. math::

    \Gamma(\tau_w) = \frac{4q}{\pi R^3} = \frac{4}{\tau_w^3}\int_0^{\tau_w}\tau^2\dot\gamma(\tau)\,d\tau ,

so :math:`G(q, R) = 2\,\tau_w(\Gamma = 4q/\pi R^3)/R`: one increasing function of one variable
serves every radius and flow rate (``docs/theory.md``, section "The flow law of a generalized
Newtonian fluid").

**The integral** (:func:`rate_natural_rate`, :func:`stress_natural_rate`) is taken by the robust
adaptive Gauss–Kronrod rule graded toward zero stress (:func:`tubefsi.numerics.quadrature.unit_integral`)
to a relative estimate of 1e-15, in the law's natural variable: the stress for a rate-natural law
(a yield-stress fluid over its yielded part only), the shear rate for a stress-natural one (by
parts: a positive integrand). A closed form (``_apparent_shear_rate``) replaces it where the law
has one.

**The table** (:class:`FlowTable`) tabulates the inverse, :math:`s = \ln(\tau_w - \tau_y)` as a
function of :math:`y = \ln\Gamma`, on *fixed* panels of the law's natural parameter :math:`p`
(:math:`p = s` for a rate-natural law or a closed form, :math:`p = \ln\dot\gamma_w` for a
stress-natural one, where :math:`\tau_w = \tau(e^p)` needs no root): panel :math:`j` covers
:math:`j \le p \le j + 1`. A panel is built from exact evaluations only — the forward map
:math:`y(p)` interpolated to 5e-15 (:func:`~tubefsi.numerics.chebyshev.fit_piecewise`), its inverse
:math:`s(y)` interpolated to 1e-14 over the panel's image from Newton's method on it, both checked
at points between their nodes — so what a panel holds depends on the fluid and :math:`j` alone.
Both tolerances are in :math:`G`: near yield, where :math:`G` carries :math:`\tau_y` and an error
of :math:`s` or :math:`y` moves it only :math:`(\tau_w - \tau_y)/\tau_w` as much, they are divided
by that share (the law's rounding there, ~eps :math:`\tau_y/(\tau_w - \tau_y)` in :math:`\Gamma`
where it gets :math:`\tau`, would otherwise defeat every fit). Panels are built where loads need
them and kept (the table only grows, under a lock); which ones exist changes the time, never an
answer. A law whose flow function cannot be interpolated on a panel (a kink) keeps that panel
*direct*: its lookups solve :math:`y(p) = y` exactly there.

Below the lowest panel the law resolves (a yield-stress fluid near yield, where the law can no longer
tell :math:`\tau_w - \tau_y`), :math:`s` follows the power-law asymptote of that panel's end: there
:math:`G` is the yield gradient to ~1e-16 (without a yield stress, an ``AccuracyWarning``).

Tables live in the one cache behind :func:`tubefsi.solve` (:mod:`tubefsi.numerics.cache`), keyed by
the fluid's class and parameter values: two equal fluids share one, a fluid whose parameters
change gets another, and a fluid that cannot say its values as plain numbers gets a table of its
own for each call.
"""

from __future__ import annotations

import math
import threading
import weakref

import numpy as np

from ..errors import ConvergenceError, InvalidParameterError
from ..numerics.cache import TABLES, instance_values
from ..numerics.chebyshev import fit_piecewise
from ..numerics.quadrature import Integral, unit_integral, warn_unconverged

__all__ = ["FlowTable", "flow_table", "rate_natural_rate", "stress_natural_rate", "check", "TOL", "RTOL"]

_EPS = float(np.finfo(float).eps)
_TINY = float(np.finfo(float).tiny)

#: Tolerance of the table: the relative error of G.
TOL = 1e-14
#: Relative tolerance of every flow-function quadrature (a tenth of TOL: the estimates of panels
#: across a kink are erratic).
RTOL = 1e-15
#: The natural parameter stays within ln(1e304).
_P_LIMIT = 700


def _positive(x):
    """Keep hook arguments positive where a tiny product underflows."""
    return np.maximum(x, _TINY)


def rate_natural_rate(rheology, wall_stress, excess=None, *, rtol: float = RTOL):
    r""":math:`\Gamma` and its quadrature (``(Integral, indices of the integrated points)``, or None
    when nothing was integrated) from a rate-natural law: :math:`4\int_0^1 t^2\dot\gamma(\tau_w t)\,dt`,
    or with a yield stress :math:`\tau_y`, over the yielded part only,
    :math:`\frac{4\Delta}{\tau_w^3}\int_0^1 (\tau_y + \Delta u)^2\dot\gamma(\tau_y + \Delta u)\,du`
    with :math:`\Delta = \tau_w - \tau_y` (``excess``, exact when given)."""
    tau_w = np.asarray(wall_stress, dtype=float)
    tau_y = float(rheology.yield_stress)
    shape = tau_w.shape
    tw = tau_w.ravel()
    out = np.zeros(tw.size)
    if tau_y == 0.0:
        live = np.flatnonzero(tw > 0)
        if not live.size:
            return out.reshape(shape), None
        tl = tw[live]

        def f(t, idx):
            return t * t * rheology._shear_rate(_positive(tl[idx, None] * t))

        res = unit_integral(f, live.size, rtol=rtol)
        out[live] = 4.0 * res.value
        return out.reshape(shape), (res, live)
    ex = (np.maximum(tau_w - tau_y, 0.0) if excess is None
          else np.broadcast_to(np.asarray(excess, dtype=float), shape)).ravel()
    live = np.flatnonzero(ex > 0)
    if not live.size:
        return out.reshape(shape), None
    el, tl = ex[live], tw[live]

    def f(u, idx):
        # tau^2 over tau_w^2 (the integral is over the unit interval): no square of a stress
        # beyond the doubles however large tau_w
        tau = tau_y + el[idx, None] * u
        ratio = tau / tl[idx, None]
        return ratio * ratio * rheology._shear_rate(tau)

    def rounding(u, idx):
        # the law gets tau, not tau - tau_y: its shear rate carries the rounding of tau_y + excess u,
        # relatively ~ eps tau_y / (excess u) times its exponent (taken as up to 4)
        return 4.0 * _EPS * tau_y / np.maximum(el[idx, None] * u, _TINY)

    res = unit_integral(f, live.size, rtol=rtol, relative_rounding=rounding)
    out[live] = 4.0 * res.value * (el / tl)
    return out.reshape(shape), (res, live)


#: How far above the wall stress :func:`stress_natural_rate` lets the stress at a lower rate be
#: (the wall rate is a root of tau(rate) = tau_w to a few eps): beyond it, a law that does not increase.
_RATIO_SLACK = 1e-9


def stress_natural_rate(rheology, wall_rate, wall_stress, *, rtol: float = RTOL):
    r""":math:`\Gamma` from a stress-natural law, by parts in the shear rate:
    :math:`\Gamma = \tfrac43\dot\gamma_w\int_0^1\bigl[1 - (\tau(\dot\gamma_w t)/\tau_w)^3\bigr]dt`
    (a positive integrand: no cancellation), with its quadrature."""
    rate_w = np.asarray(wall_rate, dtype=float)
    tau_w = np.broadcast_to(np.asarray(wall_stress, dtype=float), rate_w.shape)
    shape = rate_w.shape
    rw, tw = rate_w.ravel(), tau_w.ravel()
    out = np.zeros(rw.size)
    live = np.flatnonzero((rw > 0) & (tw > 0))
    if not live.size:
        return out.reshape(shape), None
    rl, tl = rw[live], tw[live]

    def f(t, idx):
        exact = rl[idx, None] * t
        rate = _positive(exact)
        ratio = np.asarray(rheology._stress(rate), dtype=float) / tl[idx, None]
        # tau(rate_w t) <= tau_w in the tube: a ratio a rounding above 1 (the wall rate is a root
        # of tau(rate) = tau_w to a few eps) counts nothing, not a negative flow; a ratio well above
        # 1, not finite or negative is a law that does not increase, or has no finite stress there:
        # refused, not clipped into a wrong flow rate (except where the rate was raised to the
        # smallest normal double, above the wall's own: a law steep enough there clips to 0)
        bad = ~((ratio >= 0.0) & (ratio <= 1.0 + _RATIO_SLACK)) & (rate == exact)
        if bad.any():
            row, col = (int(k[0]) for k in np.nonzero(bad))
            point = int(idx[row])
            raise InvalidParameterError(
                "rheology", "a finite, positive shear stress increasing with the shear rate", rheology,
                f"at the shear rate {float(np.broadcast_to(rate, ratio.shape)[row, col]):.6g} 1/s its stress is "
                f"{float(ratio[row, col] * tl[point]):.6g} Pa, not between 0 and the {float(tl[point]):.6g} Pa "
                f"of the higher rate {float(rl[point]):.6g} 1/s")
        return np.maximum(1.0 - ratio * ratio * ratio, 0.0)

    # 1 - ratio^3 is rounded to a few eps absolute where ratio ~ 1: near yield it is small
    # everywhere, and this floor is all the accuracy there is
    res = unit_integral(f, live.size, rtol=rtol, rounding=lambda idx: np.full(idx.shape, 2.0 * _EPS))
    out[live] = (4.0 / 3.0) * rl * res.value
    return out.reshape(shape), (res, live)


def relative_error(result, shape):
    """Per-point relative error estimates of an integrator's result (inf where not finite)."""
    res, live = result
    err = np.zeros(int(np.prod(shape)))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(res.error / res.value)
    err[live] = np.where(np.isfinite(rel) & np.isfinite(res.value), rel, np.inf)
    return err.reshape(shape)


def check(what: str, result) -> None:
    """Warn (``AccuracyWarning``) where a quadrature (``(Integral, points)`` or None) missed the
    promised relative accuracy, :data:`TOL`, unless it is within the rounding of its integrand."""
    if result is None:
        return
    res = result[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        good = (res.converged | (res.error <= TOL * np.abs(res.value))) & np.isfinite(res.value)
    warn_unconverged(what, Integral(value=res.value, error=res.error, converged=good, panels=res.panels))


def _overridden(obj, name) -> bool:
    """Whether ``type(obj)`` overrides the hook ``name`` of the root class that defines it."""
    owners = [c for c in type(obj).__mro__ if name in vars(c)]
    return len(owners) > 1 and owners[0] is not owners[-1]


def _lower_slope(fit, output: int) -> float:
    """The derivative of ``output`` of a fit at its lower end, from its first panel's Chebyshev
    coefficients (T_k'(-1) = (-1)^(k+1) k^2): no derivative interpolant built for one number."""
    c = fit.chebyshev[output, 0]
    k = np.arange(c.size)
    return float(np.dot(c, (-1.0) ** (k + 1) * k * k)) * 2.0 / float(fit.breaks[1] - fit.breaks[0])


class _Panel:
    """One built panel ``j <= p <= j + 1``: its image ``[y_lo, y_hi]``, the inverse ``s(y)`` (None: a
    direct panel, solved exactly at each lookup) and the slopes ``dy/dp``, ``ds/dp`` at its lower end;
    ``finite = False`` beyond the law's range. Immutable once built."""

    __slots__ = ("j", "y_lo", "y_hi", "inverse", "finite", "error", "slope_y", "slope_s")

    def __init__(self, j, y_lo, y_hi, inverse, finite=True, error=0.0, slope_y=1.0, slope_s=1.0):
        self.j, self.y_lo, self.y_hi, self.inverse = j, y_lo, y_hi, inverse
        self.finite, self.error, self.slope_y, self.slope_s = finite, error, slope_y, slope_s


class FlowTable:
    """The inverse :math:`s(y)` of the flow function of the rheologies of one key (see the module
    docstring). It holds no model: each lookup passes the fluid (any of the key's, equal to the
    bit), whose law builds the panels it needs. ``evaluations`` counts flow-function evaluations
    and ``panel_count`` the built panels."""

    def __init__(self, rheology):
        self.yield_stress = float(rheology.yield_stress)
        self.closed_form = _overridden(rheology, "_apparent_shear_rate")
        rate_natural = _overridden(rheology, "_shear_rate")
        #: "rate": p = s = ln(tau_w - tau_y); "stress": p = ln(wall shear rate)
        self.mode = "rate" if (self.closed_form or rate_natural) else "stress"
        self.evaluations = 0
        self._panels = {}                       # j -> _Panel, built on demand, never changed
        self._lock = threading.Lock()
        self.rheology = None                    # the fluid of the lookup under way (under the lock)
        # a yield-stress fluid's table ends where tau_w - tau_y is below eps tau_y / 8 (a closed
        # form, given the excess) or sqrt(eps) tau_y (a law that gets or gives only tau)
        floor = _EPS / 8.0 if self.closed_form else math.sqrt(_EPS)
        # (a sum of logs: the product underflows for a subnormal yield stress)
        self._s_floor = math.log(self.yield_stress) + math.log(floor) if self.yield_stress > 0 else -float(_P_LIMIT)

    # ------------------------------------------------------------ exact flow function
    def _exact(self, p):
        """``(s, y, err)`` at parameters ``p``: s = ln(tau_w - tau_y), y = ln Gamma, err the relative
        error estimate of Gamma (0 for a closed form); NaN where not finite."""
        p = np.asarray(p, dtype=float)
        self.evaluations += p.size
        rheo, tau_y = self.rheology, self.yield_stress
        err = np.zeros(p.shape)
        with np.errstate(all="ignore"):
            if self.mode == "rate":
                excess = np.exp(p)
                s = p.copy()
                tau_w = tau_y + excess
                if self.closed_form:
                    gamma = rheo._apparent_shear_rate(excess) if tau_y == 0.0 else \
                        rheo._apparent_shear_rate(tau_w, excess=excess)
                    res = None
                else:
                    gamma, res = rate_natural_rate(rheo, tau_w, excess if tau_y > 0 else None)
            else:
                rate = np.exp(p)
                tau_w = np.asarray(rheo._stress(rate), dtype=float)
                s = np.log(tau_w - tau_y) if tau_y > 0 else np.log(tau_w)
                gamma, res = stress_natural_rate(rheo, rate, tau_w)
            y = np.log(np.asarray(gamma, dtype=float))
            if res is not None:
                err = relative_error(res, p.shape)
        bad = ~(np.isfinite(s) & np.isfinite(y))
        s, y = np.where(bad, np.nan, s), np.where(bad, np.nan, y)
        return s, y, err

    def _exact_s(self, p):
        """s = ln(tau(e^p) - tau_y) of a stress-natural law (no quadrature)."""
        with np.errstate(all="ignore"):
            tau = np.asarray(self.rheology._stress(np.exp(p)), dtype=float)
            return np.log(tau - self.yield_stress) if self.yield_stress > 0 else np.log(tau)

    def _share(self, s):
        """(tau_w - tau_y) / tau_w at s = ln(tau_w - tau_y): an error d of s is one of d times this
        in G (1 without a yield stress)."""
        with np.errstate(all="ignore"):
            return 1.0 / (1.0 + self.yield_stress * np.exp(-s)) if self.yield_stress > 0 else np.ones(np.shape(s))

    # ------------------------------------------------------------ panels
    def _build(self, j: int) -> _Panel:
        """Panel ``j`` from exact evaluations alone (module docstring)."""
        lo, hi = float(j), float(j + 1)
        if self.mode == "rate" and self.yield_stress > 0 and lo < self._s_floor:
            return _Panel(j, math.nan, math.nan, None, finite=False)     # below the floor: nothing to evaluate
        # TOL is a relative error of G. Near yield G carries tau_y: an error d of s = ln(tau_w - tau_y)
        # is one of d (tau_w - tau_y) / tau_w in G (_share), and an error of y = ln Gamma one of that
        # times ds/dy (below 1 near yield). So the fits' tolerances in y and s are divided by that share
        # at the panel's top, where it is largest: the law's rounding near yield, large in y and s
        # (~eps tau_y / (tau_w - tau_y) where the law gets tau, not the excess), is small in G. At most
        # 1/sqrt(eps)-fold: a law that gets only tau is tabulated no closer to yield than that.
        s_top = hi if self.mode == "rate" else float(self._exact_s(np.array([hi]))[0])
        share = float(self._share(s_top))
        relax = 1.0 / max(share if math.isfinite(share) else 1.0, math.sqrt(_EPS))
        samples = []                           # (p, s, y, err) of every exact evaluation, the ends first

        def forward(p):
            # the panel's two ends ride along with the first batch of nodes: one quadrature call fewer,
            # and the same values as alone (each point's quadrature is independent of its batch)
            x = np.concatenate([[lo, hi], p]) if not samples else p
            s, y, err = self._exact(x)
            samples.append((x, s, y, err))
            if len(samples) > 1:
                return np.stack([y, s])
            if not (np.all(np.isfinite(y[:2])) and y[1] > y[0]):
                return np.full((2, np.size(p)), np.nan)    # no panel to fit (told apart below): the fit stops
            return np.stack([y[2:], s[2:]])

        fit, _ = fit_piecewise(forward, lo, hi, degree=16, tol=5e-15 * relax, panels=1, max_panels=64,
                               relative=True)
        (s_lo, s_hi), (y_lo, y_hi) = samples[0][1][:2].tolist(), samples[0][2][:2].tolist()
        if not (math.isfinite(y_lo) and math.isfinite(y_hi)):
            return _Panel(j, y_lo, y_hi, None, finite=False)
        if not y_hi > y_lo:
            raise InvalidParameterError("rheology", "a shear stress increasing with the shear rate", self.rheology,
                                        f"its tube-flow function does not increase near ln(tau_w - tau_y) = "
                                        f"{s_lo:.6g}")
        # a relative error e of Gamma (a node's estimate) is one of e (ds/dy) (tau_w - tau_y) / tau_w in G,
        # ds/dy taken as the ends' secant (near yield the quadrature's rounding floor, large in Gamma,
        # is small in G)
        _, s, _, err = (np.concatenate(column) for column in zip(*samples))
        with np.errstate(all="ignore"):
            node_error = (s_hi - s_lo) / (y_hi - y_lo) * float(np.max(np.where(np.isfinite(s), err * self._share(s),
                                                                                 err)))
        # a direct panel's slopes (for the asymptote below the lowest panel, and the steps toward
        # a load) are its ends' secant: its fit, if any, cannot be trusted
        secant = {"slope_y": y_hi - y_lo, "slope_s": s_hi - s_lo}
        if fit is None:                        # a kink (or noise): solved exactly at each lookup
            self._increasing(samples)
            return _Panel(j, y_lo, y_hi, None, error=node_error, **secant)
        slope = fit.derivative(0)
        grid = np.linspace(lo, hi, 257)
        grid_y = fit(grid, output=0)
        if not np.all(slope(grid) > 0):
            self._increasing(samples)
            return _Panel(j, y_lo, y_hi, None, error=node_error, **secant)

        def inverse_values(y):
            p = np.interp(y, grid_y, grid)
            for _ in range(30):
                step = (fit(p, output=0) - y) / slope(p)
                p = np.clip(p - step, lo, hi)
                if np.all(np.abs(step) <= 4 * _EPS * max(1.0, abs(hi))):
                    break
            return p if self.mode == "rate" else self._exact_s(p)

        inverse, _ = fit_piecewise(inverse_values, y_lo, y_hi, degree=8, tol=TOL * relax, panels=4, max_panels=512,
                                   relative=True)
        slopes = {"slope_y": _lower_slope(fit, 0), "slope_s": 1.0 if self.mode == "rate" else _lower_slope(fit, 1)}
        return _Panel(j, y_lo, y_hi, inverse, error=node_error, **slopes)

    def _increasing(self, samples) -> None:
        """Raise :class:`InvalidParameterError` where the exact values ``(p, s, y, err)`` of a direct
        panel show y(p) decreasing beyond their error estimates: a lookup solves y(p) = y by
        bisection there, which assumes one root (the ends alone cannot show a dip between them)."""
        if not samples:
            return
        p, s, y, err = (np.concatenate(column) for column in zip(*samples))
        order = np.argsort(p, kind="stable")
        s, y, err = s[order], y[order], err[order]
        allowed = 2.0 * (err[:-1] + err[1:]) + 8.0 * _EPS * np.maximum(1.0, np.abs(y[1:]))
        with np.errstate(invalid="ignore"):
            drop = np.flatnonzero(y[:-1] - y[1:] > allowed)
        if drop.size:
            raise InvalidParameterError("rheology", "a shear stress increasing with the shear rate", self.rheology,
                                        f"its tube-flow function decreases near ln(tau_w - tau_y) = "
                                        f"{float(s[drop[0]]):.6g}")

    def _panel(self, j: int) -> _Panel:
        found = self._panels.get(j)
        if found is None:
            found = self._panels[j] = self._build(j)
        return found

    def _lowest(self) -> int:
        """The lowest panel the law resolves (its floor, or the representable range)."""
        if self.mode == "rate" or self.yield_stress == 0.0:
            return max(math.floor(self._s_floor), -_P_LIMIT) if self.mode == "rate" else -_P_LIMIT
        rate = float(np.asarray(self.rheology._shear_rate(np.array([self.yield_stress + math.exp(self._s_floor)])))[0])
        return max(math.floor(math.log(rate)), -_P_LIMIT) if rate > 0 else -_P_LIMIT

    def _start(self, y: float) -> int:
        """A first panel near the load ``y``: a secant step on exact evaluations at p = 0 and 1."""
        _, y01, _ = self._exact(np.array([0.0, 1.0]))
        slope = float(y01[1] - y01[0]) if np.all(np.isfinite(y01)) else 1.0
        p = float(y01[0]) if not np.isfinite(y01[0]) else (y - float(y01[0])) / max(slope, 1e-3)
        return int(min(max(math.floor(p if math.isfinite(p) else 0.0), self._lowest()), _P_LIMIT - 1))

    def _locate(self, y):
        """The built panels (sorted by j) that hold the loads ``y``, building the missing ones: a
        load outside every built panel's image gets the panel its neighbours' slopes point at, until
        each is held, or lies below the lowest panel the law resolves (the asymptote serves it)."""
        lowest = self._lowest()
        if not any(panel.finite for panel in self._panels.values()):
            self._first_finite(self._start(float(np.median(y))), lowest)
        for _ in range(4 * _P_LIMIT):
            run = sorted((panel for panel in self._panels.values() if panel.finite), key=lambda panel: panel.j)
            k, held, below = self._held(run, y, lowest)
            wanted = self._wanted(run, y, k, ~held & ~below, lowest)
            if not wanted:
                return run, k, below
            for j in wanted:
                self._panel(j)
        raise ConvergenceError(f"the flow table of {self.rheology!r} does not reach ln Gamma in "
                               f"[{float(y.min()):.6g}, {float(y.max()):.6g}]")

    def _first_finite(self, j, lowest):
        """Build a first finite panel from the secant's guess ``j``: where the guess landed outside
        the law's range (the finite panels are one run), past its end (the flow function overflows)
        back into it by steps doubling downward, then the run's last panel by bisection; below its
        floor, upward."""
        if self._panel(j).finite:
            return
        beyond, step = j, 1
        while j > lowest and not self._panel(j).finite:
            beyond, j, step = j, max(j - step, lowest), 2 * step
        if not self._panel(j).finite:
            j, beyond = lowest, None
            while j < _P_LIMIT - 1 and not self._panel(j).finite:
                j += 1
        while beyond is not None and beyond - j > 1 and self._panel(j).finite:
            mid = (j + beyond) // 2
            j, beyond = (mid, beyond) if self._panel(mid).finite else (j, mid)
        if not self._panel(j).finite:
            raise InvalidParameterError(
                "rheology", "a law whose tube-flow function is finite somewhere", self.rheology,
                f"its tube-flow function is not finite for any natural parameter in [{lowest}, {_P_LIMIT}]")

    def _held(self, run, y, lowest):
        """``(k, held, below)``: the panel of ``run`` each load falls in, whether it holds it, and
        whether it is below the lowest panel the law resolves; a load above the last one is an error."""
        lo = np.array([panel.y_lo for panel in run])
        hi = np.array([panel.y_hi for panel in run])
        k = np.clip(np.searchsorted(lo, y, side="right") - 1, 0, len(run) - 1)
        # a panel holds lo <= y < hi (its upper end too where no panel can follow it): a load on
        # the common end of two panels gets the upper one, whether or not it was built before
        last = np.array([panel.j + 1 >= _P_LIMIT or not self._panels.get(panel.j + 1, panel).finite
                         for panel in run])
        held = (y >= lo[k]) & ((y < hi[k]) | ((y == hi[k]) & last[k]))
        # below the first panel, and nothing resolvable below it: the asymptote's (the panel
        # below is built only when a load needs it)
        below = y < lo[0]
        if np.any(below) and not (run[0].j <= lowest or not self._panel(run[0].j - 1).finite):
            below[:] = False
        above = y > hi[-1]
        if np.any(above) and (run[-1].j >= _P_LIMIT - 1 or not self._panel(run[-1].j + 1).finite):
            raise InvalidParameterError(
                "flow_rate", "a range the fluid can carry", None,
                f"4 q / (pi R^3) = {math.exp(min(float(y[above][0]), 709.0)):.6g} 1/s needs a wall shear stress "
                "beyond where its flow function ends")
        return k, held, below

    @staticmethod
    def _wanted(run, y, k, missing, lowest) -> set:
        """The panels to build next for the loads ``missing``: per panel of ``run`` that misses
        some, the one its slope points at above it (not past the next built panel: the secant
        between the two) or below the first panel."""
        wanted = set()
        for i in np.unique(k[missing]):
            targets = y[(k == i) & missing]
            panel = run[i]
            if targets.max() >= panel.y_hi:            # above panel i: toward run[i + 1] (or beyond the last)
                step = (float(targets.max()) - panel.y_hi) / max(panel.slope_y, 1e-3)
                j = panel.j + 1 + int(step)
                if i + 1 < len(run):
                    upper = run[i + 1]
                    gap = upper.y_lo - panel.y_hi
                    share = (float(targets.max()) - panel.y_hi) / gap if gap > 0 else 0.0
                    j = min(j, panel.j + 1 + int(share * (upper.j - panel.j - 1)))
                wanted.add(min(max(j, panel.j + 1), _P_LIMIT - 1))
            if targets.min() < panel.y_lo:             # below the first panel
                step = (panel.y_lo - float(targets.min())) / max(panel.slope_y, 1e-3)
                wanted.add(max(panel.j - 1 - int(step), lowest))
        return wanted

    # ------------------------------------------------------------ lookups
    def wall_stress(self, rheology, apparent_rate):
        r""":math:`\tau_w` with :math:`\Gamma(\tau_w) =` ``apparent_rate`` for ``rheology`` (one of
        this table's key); the yield stress (0 for most fluids) where ``apparent_rate`` is 0."""
        rate = np.asarray(apparent_rate, dtype=float)
        shape, flat = rate.shape, rate.ravel()
        out = np.full(flat.shape, self.yield_stress)
        pos = np.flatnonzero(flat > 0)
        if pos.size == 0:
            return out.reshape(shape)
        y = np.log(flat[pos])
        if not np.all(np.isfinite(y)):
            raise InvalidParameterError("flow_rate", "[0, inf)", float(flat[pos][~np.isfinite(y)][0]),
                                        "the apparent wall shear rate 4 q / (pi R^3) must be finite")
        with self._lock:                    # (panels are built under it; each is immutable after)
            self.rheology = rheology
            try:
                s = self._lookup(*self._locate(y), y)
            finally:
                self.rheology = None
        out[pos] = self.yield_stress + np.exp(s)
        return out.reshape(shape)

    def _lookup(self, run, which, below, y):
        """s at the loads ``y`` from the panels ``run[which]`` (the asymptote of the first ``below`` it)."""
        s = np.empty(y.shape)
        worst = 0.0
        for k in np.unique(which):
            sel = np.flatnonzero((which == k) & ~below)
            if sel.size == 0:
                continue
            panel = run[k]
            worst = max(worst, panel.error)
            ys = np.clip(y[sel], panel.y_lo, panel.y_hi)
            s[sel] = panel.inverse(ys) if panel.inverse is not None else self._solve_exact(panel, ys)
        if np.any(below):                  # below the lowest panel: the power-law asymptote of its end
            first = run[0]
            s_lo = first.inverse(np.array([first.y_lo]))[0] if first.inverse is not None else \
                self._solve_exact(first, np.array([first.y_lo]))[0]
            s[below] = s_lo + first.slope_s / first.slope_y * (y[below] - first.y_lo)
            if self.yield_stress == 0.0:
                warn_unconverged("the tube-flow function below its representable range (power-law extrapolation)",
                                 Integral(value=np.ones(1), error=np.array([np.inf]), converged=np.array([False]),
                                          panels=np.ones(1, dtype=int)))
        if worst > TOL:
            warn_unconverged("the tube-flow table (a flow function whose quadrature missed its tolerance)",
                             Integral(value=np.ones(1), error=np.array([worst]), converged=np.array([False]),
                                      panels=np.ones(1, dtype=int)))
        return s

    def _solve_exact(self, panel, y):
        """s at ``y`` in a direct panel: bisection and secant steps on exact evaluations of y(p)."""
        lo, hi = np.full(y.shape, float(panel.j)), np.full(y.shape, float(panel.j + 1))
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            _, ym, _ = self._exact(mid)
            below = ym < y
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
            if np.all(hi - lo <= 4 * _EPS * np.maximum(1.0, np.abs(hi))):
                break
        p = 0.5 * (lo + hi)
        return p if self.mode == "rate" else self._exact_s(p)

    @property
    def panel_count(self) -> int:
        """The number of built panels (within the law's range)."""
        return sum(1 for panel in self._panels.values() if panel.finite)


def _key(rheology):
    """The cache key of a fluid's table: its class (weakly) and every value it holds, or None where
    one is not a plain number (such a fluid gets a fresh table each call)."""
    values = instance_values(rheology)
    if values is None:
        return None
    return ("flow law", weakref.ref(type(rheology)), values)


def flow_table(rheology) -> FlowTable:
    """The :class:`FlowTable` of ``rheology``'s key, from the one cache (keyed by its values):
    ``flow_table(fluid).wall_stress(fluid, rate)``."""
    key = _key(rheology)
    if key is None:
        return FlowTable(rheology)
    return TABLES.get(key, lambda: FlowTable(rheology))
