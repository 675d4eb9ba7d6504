r"""The wall stress of a non-separable fluid at given apparent wall shear rates, for many fluids at
once and without a table kept per fluid (``docs/theory.md``, section "Non-separable fluids without
a table").

In a tube the flow depends on the wall stress only through the apparent wall shear rate
:math:`\Gamma = 4q/(\pi R^3)`, and the separated identity needs :math:`\tau_w` at the
:math:`\Gamma` of each of its nodes. In the law's *natural variable* :math:`x`, :math:`\Gamma(x)`
needs no inner inverse:

* a law with a closed form of :math:`\Gamma` (``_apparent_shear_rate``; Ellis, Bingham, Casson,
  Herschel–Bulkley): :math:`x = \ln(\tau_w - \tau_y)`, :math:`y = \ln\Gamma(x)` exact, and
  :math:`dy/dx = (4\dot\gamma_w/\Gamma - 3)(\tau_w - \tau_y)/\tau_w`; each node is solved by
  Newton's method on the exact :math:`y(x)` (:class:`ClosedMap`). The plug's kink never enters: the
  excess :math:`\tau_w - \tau_y = e^x` is exact.
* a law given by its stress (Carreau, Carreau–Yasuda, Cross; no yield stress): :math:`x = \ln\dot\gamma_w`,
  :math:`\tau_w = \tau(e^x)` explicit and, integrating the Rabinowitsch–Mooney integral by parts,
  :math:`\Gamma = \tfrac43\bigl(\dot\gamma_w - K(\dot\gamma_w)/\tau_w^3\bigr)` with the cumulative
  :math:`K(\dot\gamma) = \int_0^{\dot\gamma}\tau^3\,dg`. :class:`PanelMap` takes :math:`K` at the
  bottom of the range of each fluid once (error-controlled quadrature from 0), then *upward* on
  unit panels in :math:`x` from Chebyshev–Lobatto values and the integration matrix (no
  difference of nearly equal integrals), and inverts :math:`y(x)` by Newton's method on each
  panel's interpolant; :math:`\tau_w = \tau(e^x)` is then evaluated exactly.

Every answer carries its own check: a panel's Chebyshev tails (of :math:`\tau^3\dot\gamma` and of
:math:`y`) and the quadrature's estimate, a Newton iteration's convergence. A point that misses
its tolerance is marked (``ok`` False) and left to the caller's other route: nothing is accepted
unchecked. Nothing is kept between calls.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..fields import _array_fields, _replace
from ..numerics.kernels import blocked_matmul
from ..numerics.quadrature import unit_integral
from ..numerics.spectral import clenshaw, hermite_root, lobatto_rule

__all__ = ["kind", "ClosedMap", "PanelMap", "flow_map", "wall_stress", "log_rate_bracket"]

_EPS = float(np.finfo(float).eps)
#: Degree and width (in ln of the wall shear rate) of a panel of :class:`PanelMap`.
DEGREE, WIDTH = 24, 1.0
#: At most this many panels per fluid (a range of e^24 in the wall shear rate).
MAX_PANELS = 24
#: Tolerance of a map, in ln Gamma (so in ln tau_w: the flow index, <= 1 for these fluids, times it),
#: above the rounding of ln Gamma's own values.
TOL = 1e-14
#: :meth:`PanelMap.wall_stress` answers at most this many values at once (its gathers hold ~75
#: arrays of their size: memory bounded whatever the call).
_CHUNK = 4096
#: Newton iterations of :class:`ClosedMap` (steps clipped to 3 in ln(tau_w - tau_y)).
_NEWTON = 60


@functools.lru_cache(maxsize=2)
def _y_maps(degree):
    """Values at the Chebyshev-Lobatto nodes -> the Chebyshev coefficients of their interpolant (rows
    ``0..degree``), of its derivative (the next ``degree``) and that derivative at the nodes (the
    last ``degree + 1``), in one matrix: one product per panel gives all (constants of the degree,
    read-only)."""
    rule = lobatto_rule(degree)
    to_coef = rule.matrix[rule.coef]
    to_derivative = np.polynomial.chebyshev.chebder(to_coef, axis=0)
    at_nodes = np.polynomial.chebyshev.chebvander(rule.t, degree - 1) @ to_derivative
    maps = np.vstack([to_coef, to_derivative, at_nodes])
    maps.setflags(write=False)
    return maps


@functools.lru_cache(maxsize=2)
def _k_maps(degree):
    """The maps of :func:`~tubefsi.numerics.spectral.lobatto_rule` (values -> coefficients,
    antiderivative, cumulative integrals at the nodes), then the cumulative rows' absolute values:
    applied to positive values, those give the sums of the terms each cumulative integral adds up,
    the scale of its rounding (constants of the degree, read-only)."""
    rule = lobatto_rule(degree)
    maps = np.vstack([rule.matrix, np.abs(rule.matrix[rule.cumulative])])
    maps.setflags(write=False)
    return maps


def _overridden(cls, name) -> bool:
    owners = [c for c in cls.__mro__ if name in vars(c)]
    return len(owners) > 1 and owners[0] is not owners[-1]


def kind(rheology):
    """``"closed"`` (a closed form of the apparent wall shear rate), ``"stress"`` (a law given by its
    stress, without a yield stress), or None (a law the maps do not serve)."""
    cls = type(rheology)
    if rheology.separable:
        return None
    if _overridden(cls, "_apparent_shear_rate"):
        return "closed"
    if _overridden(cls, "_stress") and not _overridden(cls, "_shear_rate") and \
            not np.any(np.asarray(rheology.yield_stress) != 0):
        return "stress"
    return None


def _at(model, index, column=False):
    """``model`` with its array parameters (one per point, 1-D) taken at ``index`` (as columns, to
    broadcast against ``(points, nodes)``, if ``column``)."""
    arrays = {n: v for n in _array_fields(type(model)) if isinstance(v := getattr(model, n), np.ndarray) and v.ndim}
    if not arrays:
        return model
    return _replace(model, {n: v[index][:, None] if column else v[index] for n, v in arrays.items()})


def _points(model, count):
    """``model`` with every array parameter broadcast to ``(count,)``."""
    arrays = {n: v for n in _array_fields(type(model)) if isinstance(v := getattr(model, n), np.ndarray)}
    if not arrays:
        return model
    return _replace(model, {n: np.broadcast_to(v, (count,)).copy() if v.size != count else v.reshape(count)
                            for n, v in arrays.items()})


class ClosedMap:
    """Newton's method on the exact :math:`y(x) = \\ln\\Gamma(\\tau_y + e^x)` (module docstring)."""

    def __init__(self, rheology, y_lo, y_hi):
        self.rheology = rheology
        self.y_lo, self.y_hi = y_lo, y_hi

    def _y(self, rheo, x):
        e = np.exp(x)
        tau_w = rheo.yield_stress + e
        gamma = np.asarray(rheo._apparent_shear_rate(tau_w, excess=e), dtype=float)
        rate = np.asarray(rheo._shear_rate(tau_w), dtype=float)
        return np.log(gamma), (4.0 * rate / gamma - 3.0) * e / tau_w, tau_w

    def wall_stress(self, y, x=None):
        """``(tau_w, ok, x)`` at ``y = ln Gamma`` (shape ``(..., P)``, points along the last axis);
        ``x`` a start (default 0, i.e. tau_w - tau_y = 1 Pa)."""
        y = np.asarray(y, dtype=float)
        rheo = self.rheology
        x = np.zeros(y.shape) if x is None else np.array(np.broadcast_to(x, y.shape), dtype=float)
        p = y.shape[-1] if y.ndim else 1
        flat_y, flat_x = y.reshape(-1, p), x.reshape(-1, p)
        rows, cols = np.nonzero(np.isfinite(flat_y))
        live = np.arange(rows.size)
        xs = flat_x[rows, cols]
        ys = flat_y[rows, cols]
        out_tau = np.full(rows.size, np.nan)
        done = np.zeros(rows.size, dtype=bool)
        with np.errstate(all="ignore"):
            for _ in range(_NEWTON):
                if live.size == 0:
                    break
                r = _at(rheo, cols[live])
                value, slope, tau_w = self._y(r, xs[live])
                step = (value - ys[live]) / slope
                bad = ~np.isfinite(step) | ~(slope > 0)
                step = np.clip(np.where(bad, 0.0, step), -3.0, 3.0)
                converged = ~bad & (np.abs(value - ys[live]) <= 4.0 * _EPS * np.maximum(1.0, np.abs(ys[live])))
                out_tau[live[converged]] = tau_w[converged]
                done[live[converged]] = True
                xs[live] -= step
                live = live[~converged & ~bad]
        tau_flat = np.full(flat_y.shape, np.nan)
        ok_flat = np.zeros(flat_y.shape, dtype=bool)
        x_flat = np.full(flat_y.shape, np.nan)
        tau_flat[rows, cols], ok_flat[rows, cols], x_flat[rows, cols] = out_tau, done, xs
        tau, ok = tau_flat.reshape(y.shape), ok_flat.reshape(y.shape)
        return tau, ok, x_flat.reshape(y.shape)

    def wall_rate(self, tau, x):
        """The wall shear rate at the wall stresses ``tau`` that :meth:`wall_stress` gave (shape
        ``(..., P)``): the law's own shear rate there."""
        tau = np.asarray(tau, dtype=float)
        with np.errstate(all="ignore"):       # (the law's parameters: one per point, the last axis)
            return np.asarray(self.rheology._shear_rate(np.maximum(tau, np.finfo(float).tiny)), dtype=float) + 0.0 * tau


class PanelMap:
    r""":math:`y(x)` on unit panels in :math:`x = \ln\dot\gamma_w` covering :math:`[y_{lo}, y_{hi}]`
    per point (module docstring); :meth:`wall_stress` inverts it."""

    def __init__(self, rheology, y_lo, y_hi, x_lo=None):
        self.rheology = rheology
        y_lo, y_hi = np.asarray(y_lo, dtype=float), np.asarray(y_hi, dtype=float)
        n = y_hi.size
        rule = lobatto_rule(DEGREE)
        self.rule = rule
        # gamma_w >= 3 Gamma / 4 for an increasing law (K >= 0): x(y_lo) >= y_lo + ln(3/4); or the
        # caller's start in x (the map then covers what lies above it)
        self.x0 = y_lo + math.log(0.75) - 0.01 if x_lo is None else np.asarray(x_lo, dtype=float) + np.zeros(n)
        if x_lo is not None:
            y_lo = np.full(n, -np.inf)
        # Chebyshev coefficients of y per panel ([:, 0]) and of its derivative ([:, 1], the top one zero),
        # stacked for one Clenshaw pass of both
        self.pair = np.full((DEGREE + 1, 2, MAX_PANELS, n), np.nan)
        self.pair[-1, 1] = 0.0
        # each panel's y at its middle node apart: the interpolant holds y's variation over the panel
        self.offset = np.full((MAX_PANELS, n), np.nan)
        self.y_nodes = np.full((DEGREE + 1, MAX_PANELS, n), np.nan)
        self.node_slopes = np.full((DEGREE + 1, MAX_PANELS, n), np.nan)     # dy/dt at the nodes
        self.ok = np.isfinite(self.x0) & np.isfinite(y_hi)
        self.panels = np.zeros(n, dtype=int)
        with np.errstate(all="ignore"):
            g0 = np.exp(self.x0)
            base = unit_integral(lambda t, idx: self._tau(_at(rheology, idx, column=True), g0[idx, None] * t) ** 3, n, rtol=1e-15)
            K = g0 * base.value
            err_k = g0 * base.error + 4.0 * _EPS * np.abs(K)
            self.ok &= np.isfinite(K) & (K > 0)
            live = np.flatnonzero(self.ok)
            j = 0
            while live.size and j < MAX_PANELS:
                # the panels of this step, built in one batch: at least those that y <= x + ln(4/3)
                # (Gamma <= 4 gamma_w / 3) says most live points need to reach y_hi
                need = np.ceil((y_hi[live] - math.log(4.0 / 3.0) - self.x0[live]) / WIDTH - j + 1e-9)
                batch = int(min(MAX_PANELS - j, max(1.0, float(np.sort(need)[(9 * (need.size - 1)) // 10]))))
                live = self._panels(rheology, live, j, batch, K, err_k, y_lo, y_hi, x_lo is None)
                j += batch
            self.ok[live] = False                                   # (beyond MAX_PANELS)

    def _panels(self, rheology, live, j0, batch, K, err_k, y_lo, y_hi, check_bottom):
        """Panels ``j0 .. j0 + batch - 1`` of the points ``live``, their law values in one batch (a
        point's bits are those of building them one by one); ``K`` and ``err_k`` carried up panel
        by panel. Returns the points still live after them (every panel good, y_hi not reached)."""
        rule = self.rule
        y_maps, k_maps = _y_maps(DEGREE), _k_maps(DEGREE)
        terms = slice(rule.matrix.shape[0], None)                 # the rows of k_maps beyond rule.matrix
        p = live.size
        r = _at(rheology, live)
        x = self.x0[live] + WIDTH * ((j0 + np.arange(batch))[:, None] + rule.nodes[:, None, None])  # (nodes, batch, P)
        g = np.exp(x)
        tau = self._tau(r, g)
        cube = tau * tau * tau
        values = cube * g
        maps = blocked_matmul(k_maps, values.reshape(DEGREE + 1, batch * p)).reshape(-1, batch, p)
        cumulative = (0.5 * WIDTH) * maps[rule.cumulative]
        # K's error at each node: the panel's start's, the tail of the integrand's interpolant
        # (a tail at the rounding of the values, 32 eps of their largest, is noise), and the
        # rounding of the node's own sum, a few eps of the terms it adds up (at the panel's
        # low nodes far below its top: a Newtonian plateau's integrand grows e^4-fold over a
        # panel, and the top's rounding charged to the bottom node failed such fluids)
        w_tail = np.abs(maps[rule.coef][-3:]).sum(axis=0)
        noise = w_tail <= 32.0 * _EPS * np.max(values, axis=0)
        own = np.where(noise, 0.0, (0.5 * WIDTH) * w_tail) + 2.0 * _EPS * ((0.5 * WIDTH) * maps[terms])
        # K and its error at each panel's start, carried up from the last (the same sums, in the
        # same order, as panel by panel)
        k_nodes = np.empty(cumulative.shape)
        err_nodes = np.empty(cumulative.shape)
        k_start, e_start = K[live], err_k[live]
        for b in range(batch):
            k_nodes[:, b] = k_start + cumulative[:, b]
            err_nodes[:, b] = e_start + own[:, b] + 2.0 * _EPS * k_nodes[:, b]
            k_start, e_start = k_nodes[-1, b], err_nodes[-1, b]
        gamma = (4.0 / 3.0) * (g - k_nodes / cube)
        y = np.log(gamma)
        # the interpolant of y's variation from its middle node (the coefficients of y itself,
        # ~35 where Gamma ~ 1e15, would carry rounding of eps |y| each: 1e-13 at a point)
        ref = y[DEGREE // 2]
        c_and_slope = blocked_matmul(y_maps, (y - ref).reshape(DEGREE + 1, batch * p)).reshape(-1, batch, p)
        c = c_and_slope[:DEGREE + 1]
        err_y = np.max((4.0 / 3.0) * err_nodes / (cube * gamma), axis=0)
        tail = np.abs(c[-3:]).sum(axis=0)
        good = np.isfinite(y).all(axis=0) & (np.diff(y, axis=0) > 0).all(axis=0) & \
            (cube > 0).all(axis=0) & (err_y + tail <= TOL + 32.0 * _EPS * np.abs(y).max(axis=0))
        # each point takes its panels in order until one fails or reaches y_hi (as one by one):
        # panel b where every panel before it was good and below y_hi
        goes_on = good & (y[-1] < y_hi[live])                      # (batch, P): the next one is built
        taken = np.ones((batch, p), dtype=bool)
        taken[1:] = np.logical_and.accumulate(goes_on[:-1], axis=0)
        b, at = np.nonzero(taken)
        j, pts = j0 + b, live[at]
        self.pair[:, 0, j, pts], self.pair[:-1, 1, j, pts] = c[:, b, at], c_and_slope[DEGREE + 1:2 * DEGREE + 1, b, at]
        self.offset[j, pts] = ref[b, at]
        self.y_nodes[:, j, pts] = y[:, b, at]
        self.node_slopes[:, j, pts] = c_and_slope[2 * DEGREE + 1:, b, at]
        self.ok[pts[~good[b, at]]] = False
        last = taken.sum(axis=0) - 1                                # each point's last panel taken
        K[live], err_k[live] = k_nodes[-1, last, np.arange(p)], err_nodes[-1, last, np.arange(p)]
        self.panels[live] = j0 + last + 1
        if j0 == 0 and check_bottom:
            self.ok[live[y[0, 0] > y_lo[live]]] = False             # (cannot happen for an increasing law)
        return live[goes_on.all(axis=0)]

    def wall_rate(self, tau, x):
        """The wall shear rate at the answers of :meth:`wall_stress`: :math:`e^x` (its natural
        variable)."""
        return np.exp(x)

    @staticmethod
    def _tau(rheo, g):
        return np.asarray(rheo._stress(np.maximum(g, np.finfo(float).tiny)), dtype=float)

    def wall_stress(self, y, x=None):
        """``(tau_w, ok, x)`` at ``y = ln Gamma`` (shape ``(..., P)``, points along the last axis), in
        chunks of at most ``_CHUNK`` values (each value's answer is its own: the same bits)."""
        y = np.asarray(y, dtype=float)
        n = self.x0.size
        y2 = y.reshape(-1, n)
        rows = max(1, _CHUNK // n)
        if y2.shape[0] <= rows:
            return self._wall_stress(y2, y.shape)
        parts = [self._wall_stress(y2[i:i + rows], y2[i:i + rows].shape) for i in range(0, y2.shape[0], rows)]
        return tuple(np.concatenate([p[k] for p in parts]).reshape(y.shape) for k in range(3))

    def _wall_stress(self, y2, shape):
        n = self.x0.size
        cols = np.broadcast_to(np.arange(n), y2.shape)
        # the panel of each target: the count of panels whose top is below it
        tops = self.y_nodes[-1]                                     # (MAX_PANELS, P)
        with np.errstate(invalid="ignore"):
            j = np.minimum(np.sum(tops[:, None, :] < y2[None], axis=0), np.maximum(self.panels - 1, 0))
            nodes = self.y_nodes[:, j, cols]                       # (DEGREE + 1, rows, P)
            inside = (y2 >= self.y_nodes[0, 0]) & (y2 <= nodes[-1]) & self.ok
            # the start: the cubic Hermite interpolant between the panel's nodes that bracket y,
            # from their values and slopes (within ~1e-6: one Newton step fewer than a line)
            k = np.minimum(np.maximum((nodes < y2[None]).sum(axis=0), 1), DEGREE)
            t_nodes = self.rule.t
            ya, yb = self.y_nodes[k - 1, j, cols], self.y_nodes[k, j, cols]
            ta, tb = t_nodes[k - 1], t_nodes[k]
            sa, sb = self.node_slopes[k - 1, j, cols], self.node_slopes[k, j, cols]
            s = hermite_root(yb - ya, y2 - ya, sa * (tb - ta), sb * (tb - ta))
            t = np.where(np.isfinite(s), ta + (tb - ta) * s, ta)
            pair = self.pair[:, :, j, cols]                          # (DEGREE + 1, 2, rows, P)
            y2 = y2 - self.offset[j, cols]                           # (exact within a factor 2: Sterbenz)
            # Newton on the interpolant, quadratic: after a step below 1e-9 the error is ~1e-18 and
            # that point stops (its iterations do not depend on its neighbours')
            moving = inside.copy()
            for _ in range(10):
                value, slope = clenshaw(pair, np.broadcast_to(t, pair.shape[1:]))
                step = (value - y2) / slope
                step = np.where(moving & np.isfinite(step), step, 0.0)
                t = np.minimum(np.maximum(t - step, -1.0), 1.0)
                moving &= ~(np.abs(step) <= 1e-9)
                if not moving.any():
                    break
            inside &= ~moving
            x = self.x0[cols] + WIDTH * (j + 0.5 * (t + 1.0))
            tau = self._tau(self.rheology, np.exp(x))            # (the law's parameters: one per point, the last axis)
        return tau.reshape(shape), inside.reshape(shape), x.reshape(shape)


def flow_map(rheology, y_lo, y_hi, x_lo=None, which=None):
    r"""The map of ``rheology`` (its array parameters one per point, along the last axis) over
    ``[y_lo, y_hi]`` per point (``y = ln Gamma``), or None where :func:`kind` is None. ``x_lo``
    (a law given by its stress): start the map's panels there in :math:`\ln\dot\gamma_w` instead
    (``y_lo`` is then ignored; :class:`ClosedMap` needs no range). ``which``: :func:`kind` of
    ``rheology``, where the caller has it."""
    which = kind(rheology) if which is None else which
    if which is None:
        return None
    y_hi = np.atleast_1d(np.asarray(y_hi, dtype=float))
    y_lo = np.broadcast_to(np.asarray(np.nan if y_lo is None else y_lo, dtype=float), y_hi.shape)
    model = _points(rheology, y_hi.size)
    return ClosedMap(model, y_lo, y_hi) if which == "closed" else PanelMap(model, y_lo, y_hi, x_lo)


def log_rate_bracket(rheology, stress, width=1e-3):
    r"""``(x_lo, x_hi)`` with :math:`\tau(e^{x_{lo}}) \le` ``stress`` :math:`\le \tau(e^{x_{hi}})`,
    :math:`x_{hi} - x_{lo} \le` ``width``, per point (a law given by its stress, increasing; its
    array parameters one per point): bisection in :math:`x = \ln\dot\gamma` over the doubles'
    range. A bracket, not a root: for the start of a map."""
    t = np.atleast_1d(np.asarray(stress, dtype=float))
    rheology = _points(rheology, t.size)
    lo, hi = np.full(t.shape, math.log(np.finfo(float).tiny)), np.full(t.shape, math.log(np.finfo(float).max) - 1.0)
    with np.errstate(all="ignore"):
        while np.any(hi - lo > width):
            mid = 0.5 * (lo + hi)
            below = np.asarray(rheology._stress(np.exp(mid)), dtype=float) + 0.0 * t <= t
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return lo, hi


#: A fluid of scalar parameters is served by one map over the range of the apparent rates asked
#: for where that range spans at most this much of ln Gamma (a map covers e^24 of the wall shear rate).
_ONE_MAP_RANGE = 16.0


def wall_stress(rheology, apparent_rate):
    r""":math:`\tau_w` at each apparent wall shear rate (any shape; the fluid's array parameters
    broadcast against it), each point on its own; ``(tau_w, ok)``. At a zero rate, the limit
    :math:`\Gamma \to 0^+`: :math:`\tau_w = \tau_y` (0 without a yield stress).

    A fluid of scalar parameters (one fluid, many rates) is served by *one* map spanning the
    rates' range (where it spans at most ``_ONE_MAP_RANGE`` in :math:`\ln\Gamma`); a fluid with
    array parameters by a map per point. Either way each value is the map's inverse at that rate,
    checked as the map checks it; the one map's panels start at the lowest rate asked, so a value's
    last bits (not its accuracy) depend on the range of the call."""
    rate = np.asarray(apparent_rate, dtype=float)
    arrays = [getattr(rheology, n) for n in _array_fields(type(rheology))]
    shape = np.broadcast_shapes(rate.shape, *(np.shape(a) for a in arrays))
    flat_rate = np.broadcast_to(rate, shape).ravel()
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.log(flat_rate)
    one = not any(np.ndim(a) for a in arrays)
    finite = np.isfinite(y)
    if one and np.any(finite) and float(np.ptp(y[finite])) <= _ONE_MAP_RANGE:
        m = flow_map(rheology, [float(np.min(y[finite]))], [float(np.max(y[finite]))])
        tau, ok, _ = m.wall_stress(y[:, None])
        tau, ok = tau[:, 0], ok[:, 0]
    else:
        model = _replace(rheology, {n: np.broadcast_to(getattr(rheology, n), shape).ravel()
                                    for n in _array_fields(type(rheology)) if isinstance(getattr(rheology, n), np.ndarray)})
        m = flow_map(model, y, y)
        tau, ok, _ = m.wall_stress(y[None])
        tau, ok = tau[0], ok[0]
    zero = flat_rate == 0.0
    if np.any(zero):
        tau_y = np.broadcast_to(np.asarray(rheology.yield_stress, dtype=float), shape).ravel()
        tau, ok = np.where(zero, tau_y, tau), ok | zero
    return tau.reshape(shape), ok.reshape(shape)
