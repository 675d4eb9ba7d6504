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
  bottom of the range of each fluid from unit panels below it and a bound on the rest
  (:func:`_k_below`; the error-controlled quadrature from 0 where that bound is too loose), then
  *upward* on unit panels in :math:`x` from Chebyshev–Lobatto values and the integration matrix
  (no difference of nearly equal integrals), and inverts :math:`y(x)` from the rational
  interpolant of its nodes, then Newton's method on each panel's interpolant (both by the
  barycentric formula); :math:`\tau_w = \tau(e^x)` is then evaluated exactly. The panels below
  also check the law: a stress that is not finite, negative or falling there is refused.

Every answer carries its own check: a panel's Chebyshev tails (of :math:`\tau^3\dot\gamma` and of
:math:`y`) and the quadrature's estimate, a Newton iteration's convergence. A point that misses
its tolerance is marked (``ok`` False) and left to the caller's other route: nothing is accepted
unchecked. Nothing is kept between calls.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import InvalidParameterError
from ..fields import _array_fields, _replace
from ..numerics.cache import keep_on_class
from ..numerics.kernels import blocked_matmul
from ..numerics.quadrature import unit_integral
from ..numerics.spectral import at_nodes, barycentric, lobatto_rule, lobatto_weights

__all__ = ["kind", "ClosedMap", "PanelMap", "flow_map", "wall_stress", "log_rate_bracket"]

_EPS = float(np.finfo(float).eps)
_TINY = float(np.finfo(float).tiny)
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
    """Values at the Chebyshev-Lobatto nodes -> the last three Chebyshev coefficients of their
    interpolant (its tail: rows 0..2) and the interpolant's derivative at the nodes (the next
    ``degree + 1``), in one matrix (constants of the degree, read-only)."""
    rule = lobatto_rule(degree)
    to_coef = rule.matrix[rule.coef]
    to_derivative = np.polynomial.chebyshev.chebder(to_coef, axis=0)
    at_nodes = np.polynomial.chebyshev.chebvander(rule.t, degree - 1) @ to_derivative
    maps = np.vstack([to_coef[-3:], at_nodes])
    maps.setflags(write=False)
    return maps


@functools.lru_cache(maxsize=2)
def _k_maps(degree):
    r"""Values at the Chebyshev-Lobatto nodes -> the last three Chebyshev coefficients of their
    interpolant (its tail: rows 0..2), the cumulative integrals at the nodes (the next
    ``degree + 1``) and those rows' absolute values (the last ``degree + 1``): applied to
    positive values, those give the sums of the terms each cumulative integral adds up, the
    scale of its rounding (constants of the degree, read-only). All on a panel of the map's width
    (:math:`dx = (W/2)\,dt`: the factor exact, a power of two)."""
    rule = lobatto_rule(degree)
    cumulative = rule.matrix[rule.cumulative]
    maps = (0.5 * WIDTH) * np.vstack([rule.matrix[rule.coef][-3:], cumulative, np.abs(cumulative)])
    maps.setflags(write=False)
    return maps


#: Unit panels below a map's start on which :func:`_k_below` takes :math:`K` there, in one batch.
_BELOW = 16
#: The relative tolerance of that :math:`K` (the map's values need it to a few eps).
_K_RTOL = 1e-15


@functools.lru_cache(maxsize=64)
def _panel_nodes(j0, count):
    """The nodes of panels ``j0 .. j0 + count - 1`` from a map's start, ``(nodes, count, 1)`` (in
    units of the panel width; constants, read-only)."""
    nodes = WIDTH * (np.arange(j0, j0 + count)[:, None] + lobatto_rule(DEGREE).nodes[:, None, None])
    nodes.setflags(write=False)
    return nodes


def _law_panels(rheology, x0, j0, count):
    r"""The law on the nodes of panels ``j0 .. j0 + count - 1`` (panel j spans
    ``[x0 + j W, x0 + (j + 1) W]``; ``j0 < 0`` below the map), each point's (its array parameters
    and ``x0`` one per point), in one batch: ``(g, tau, cube, values, maps)``, the wall shear
    rates, the stresses, :math:`\tau^3`, the integrand :math:`\tau^3\dot\gamma` of :math:`K` in :math:`x`
    (``(nodes, count, P)``) and :func:`_k_maps` applied to it (``(rows, count, P)``)."""
    g = np.exp(x0 + _panel_nodes(j0, count))
    tau = PanelMap._tau(rheology, g)
    cube = tau * tau * tau
    values = cube * g
    maps = blocked_matmul(_k_maps(DEGREE), values.reshape(DEGREE + 1, count * x0.size)).reshape(-1, count, x0.size)
    return g, tau, cube, values, maps


def _check_increasing(rheology, g, tau):
    """Raise :class:`~tubefsi.errors.InvalidParameterError` where the law's stress ``tau`` (at the
    shear rates ``g``, ``(nodes, panels, P)``, panels in order along the rate) is not finite,
    negative, or falls from one node to the next: the panels below a map are
    used for :math:`K` alone, and no other check looks at them (a decreasing band there would
    give a flow rate without a word)."""
    # (a panel's last node is the next one's first, to the bit: rising within each panel, from a
    # non-negative first value to a finite last, is rising all along; a NaN fails a comparison)
    fine = (tau[0, 0] >= 0.0) & (tau[1:] >= tau[:-1]).all(axis=(0, 1)) & np.isfinite(tau[-1, -1])
    if fine.all():
        return
    along = np.ascontiguousarray(tau.transpose(1, 0, 2)).reshape(-1, tau.shape[-1])   # in x order
    p = int(np.flatnonzero(~fine)[0])
    column = along[:, p]
    wrong = ~(np.isfinite(column) & (column >= 0.0))                  # the first bad node: a stress
    wrong[1:] |= ~(column[1:] >= column[:-1]) & ~wrong[:-1]          # not finite or negative, or a fall
    at = int(np.flatnonzero(wrong)[0])
    rate = float(np.ascontiguousarray(g.transpose(1, 0, 2)).reshape(-1, g.shape[-1])[at, p])
    stress = float(column[at])
    why = ("not a finite stress" if not math.isfinite(stress) else "negative" if stress < 0.0 else
           f"below the {float(column[at - 1]):.6g} Pa at a lower rate")
    raise InvalidParameterError("rheology", "a finite, positive shear stress increasing with the shear rate",
                                rheology, f"its stress at the shear rate {rate:.6g} 1/s is {stress:.6g} Pa: {why}"
                                + (f" (point {p} of the call)" if tau.shape[-1] > 1 else ""))


def _k_below(rheology, x0, values, maps):
    r"""``(K, error)``: :math:`K = \int_0^{\dot\gamma_0}\tau^3\,d\dot\gamma =
    \int_{-\infty}^{x_0}\tau(e^x)^3 e^x\,dx` at each point's ``x0`` (its array parameters one
    per point) and an estimate of its error, from the ``values`` and ``maps`` of
    :func:`_law_panels` on the ``_BELOW`` unit panels below :math:`x_0`.

    Clenshaw–Curtis on each panel, its Chebyshev tail its error; below them the rest lies in
    :math:`[0, \tau_b^3\dot\gamma_b]` for an increasing law (:math:`\tau \le \tau_b` there),
    taken as half of it, with half of it as its error. Where that misses ``_K_RTOL`` (a law
    still thinning steeply far below :math:`x_0`: :math:`\tau^3\dot\gamma` falls by less than
    1e-16 over the panels) the adaptive quadrature from zero
    (:func:`~tubefsi.numerics.quadrature.unit_integral`) answers."""
    # (the top node's value is the largest of an increasing law's; else smaller: a floor on the
    # safe side)
    tails = np.abs(maps[:3]).sum(axis=0)
    tails = np.where(tails <= (0.5 * WIDTH) * 32.0 * _EPS * values[-1], 0.0, tails)      # (the values' rounding)
    rest = 0.5 * values[0, 0]                                  # the bottom node: x0 - _BELOW W
    # the sums over the panels (each one's integral: the cumulative's last row) along a contiguous
    # last axis: the same order whatever the number of points
    K = rest + np.ascontiguousarray(maps[DEGREE + 3].T).sum(axis=1)
    error = rest + np.ascontiguousarray(tails.T).sum(axis=1) + 4.0 * _EPS * K
    fine = (error <= _K_RTOL * K) & (values[0, 0] >= 0.0)
    if not fine.all():
        missed = np.flatnonzero(~fine)
        g0 = np.exp(x0[missed])
        base = unit_integral(lambda t, idx: PanelMap._tau(_at(rheology, missed[idx], column=True), g0[idx, None] * t) ** 3,
                             missed.size, rtol=_K_RTOL)
        K[missed] = g0 * base.value
        error[missed] = g0 * base.error + 4.0 * _EPS * np.abs(K[missed])
    return K, error


def _overridden(cls, name) -> bool:
    owners = [c for c in cls.__mro__ if name in vars(c)]
    return len(owners) > 1 and owners[0] is not owners[-1]


def _class_kind(cls):
    """What :func:`kind` finds from the class alone: ``"closed"``, ``"stress"`` (before the yield
    stress is looked at) or ``""``, kept on the class."""
    found = cls.__dict__.get("_tubefsi_map_kind")
    if found is None:
        if _overridden(cls, "_apparent_shear_rate"):
            found = "closed"
        elif _overridden(cls, "_stress") and not _overridden(cls, "_shear_rate"):
            found = "stress"
        else:
            found = ""
        found = keep_on_class(cls, "_tubefsi_map_kind", found)
    return found


def kind(rheology):
    """``"closed"`` (a closed form of the apparent wall shear rate), ``"stress"`` (a law given by its
    stress, without a yield stress), or None (a law the maps do not serve)."""
    if rheology.separable:
        return None
    found = _class_kind(type(rheology))
    if found == "closed":
        return found
    if found == "stress":
        tau_y = rheology.yield_stress
        if (tau_y == 0.0) if type(tau_y) is float else not np.any(np.asarray(tau_y) != 0):
            return found
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
        # per panel: y at its middle node (``offset``) and at its top node, and at its nodes (the
        # last, contiguous axis: a sum over them is taken in the same order whatever the number of
        # points) y's variation from the middle node, z = y - offset, which the interpolant holds,
        # and the interpolant's slope dz/dt (``nodes[..., 0, :]`` and ``nodes[..., 1, :]``)
        self.offset = np.empty((MAX_PANELS, n))
        self.tops = np.empty((MAX_PANELS, n))
        self.nodes = np.empty((MAX_PANELS, n, 2, DEGREE + 1))
        for unset in (self.offset, self.tops, self.nodes):    # (a panel never built: NaN)
            unset.fill(np.nan)
        #: :math:`y` at the bottom of each point's map (its first panel's first node).
        self.bottom = np.full(n, np.nan)
        self.ok = np.isfinite(self.x0) & np.isfinite(y_hi)
        self.panels = np.zeros(n, dtype=int)
        live = np.nonzero(self.ok)[0]
        if live.size == 0:
            return
        with np.errstate(all="ignore"):
            batch = self._batch(live, 0, y_hi)
            # the panels below the map (for K at its start) and its first batch: one law call
            law = _law_panels(rheology, self.x0, -_BELOW, _BELOW + batch)
            _check_increasing(rheology, law[0], law[1])
            K, err_k = _k_below(rheology, self.x0, law[3][:, :_BELOW], law[4][:, :_BELOW])
            self.ok &= np.isfinite(K) & (K > 0)
            live = np.nonzero(self.ok)[0]
            sel = slice(None) if live.size == n else live          # (every point: views, no gathers)
            law = tuple(a[:, _BELOW:, sel] for a in law)
            j = 0
            while live.size and j < MAX_PANELS:
                live = self._panels(rheology, live, j, batch, K, err_k, y_lo, y_hi, x_lo is None, law)
                j += batch
                law = None
                if live.size and j < MAX_PANELS:
                    batch = self._batch(live, j, y_hi)
            self.ok[live] = False                                   # (beyond MAX_PANELS)

    def _batch(self, live, j, y_hi):
        """How many panels the next step builds from panel ``j`` on, in one batch: at least those that
        y <= x + ln(4/3) (Gamma <= 4 gamma_w / 3) says most of the points ``live`` need to reach y_hi."""
        need = np.ceil((y_hi[live] - math.log(4.0 / 3.0) - self.x0[live]) / WIDTH - j + 1e-9)
        return int(min(MAX_PANELS - j, max(1.0, float(np.sort(need)[(9 * (need.size - 1)) // 10]))))

    def _panels(self, rheology, live, j0, batch, K, err_k, y_lo, y_hi, check_bottom, law=None):
        """Panels ``j0 .. j0 + batch - 1`` of the points ``live``, their law values in one batch (a
        point's bits are those of building them one by one; :func:`_law_panels`, or ``law``, its
        result where the caller has it); ``K`` and ``err_k`` carried up panel by panel. Returns
        the points still live after them (every panel good, y_hi not reached)."""
        y_maps = _y_maps(DEGREE)
        p = live.size
        g, _, cube, values, maps = _law_panels(_at(rheology, live), self.x0[live], j0, batch) if law is None else law
        cumulative = maps[3:DEGREE + 4]
        # K's error at each node: the panel's start's, the tail of the integrand's interpolant
        # (a tail at the rounding of the values, 32 eps of their largest, is noise), and the
        # rounding of the node's own sum, a few eps of the terms it adds up (at the panel's
        # low nodes far below its top: a Newtonian plateau's integrand grows e^4-fold over a
        # panel, and the top's rounding charged to the bottom node failed such fluids)
        # (the top node's value is the largest of an increasing law's; else smaller: a floor on the
        # safe side)
        w_tail = np.abs(maps[:3]).sum(axis=0)
        own = np.where(w_tail <= (0.5 * WIDTH) * 32.0 * _EPS * values[-1], 0.0, w_tail) + 2.0 * _EPS * maps[DEGREE + 4:]
        # K and its error at each panel's start, carried up from the last: running sums along
        # the panels (in order, as panel by panel)
        sel = slice(None) if p == K.size else live                  # (every point: views, no gathers)
        k_start, e_start = K[sel], err_k[sel]
        k_nodes = np.concatenate([k_start[None], cumulative[-1, :-1]]).cumsum(axis=0) + cumulative
        own += 2.0 * _EPS * k_nodes
        err_nodes = np.concatenate([e_start[None], own[-1, :-1]]).cumsum(axis=0) + own
        # Gamma tau^3 = (4/3) (tau^3 gamma_w - K): the flow function's integral by parts
        gamma_cube = (4.0 / 3.0) * (values - k_nodes)
        y = np.log(gamma_cube / cube)
        # the interpolant of y's variation from its middle node (the coefficients of y itself,
        # ~35 where Gamma ~ 1e15, would carry rounding of eps |y| each: 1e-13 at a point)
        ref = y[DEGREE // 2]
        z = y - ref
        tail_and_slope = blocked_matmul(y_maps, z.reshape(DEGREE + 1, batch * p)).reshape(-1, batch, p)
        err_y = ((4.0 / 3.0) * err_nodes / gamma_cube).max(axis=0)
        tail = np.abs(tail_and_slope[:3]).sum(axis=0)
        # (a NaN in y fails the first test, an infinite one the tail's)
        good = (y[1:] > y[:-1]).all(axis=0) & (cube > 0).all(axis=0) & \
            (err_y + tail <= TOL + 32.0 * _EPS * np.abs(y).max(axis=0))
        # each point takes its panels in order until one fails or reaches y_hi (as one by one):
        # panel b where every panel before it was good and below y_hi
        goes_on = good & (y[-1] < y_hi[sel])                       # (batch, P): the next one is built
        taken = np.ones((batch, p), dtype=bool)
        if batch > 1 and not goes_on[:-1].all():
            taken[1:] = np.logical_and.accumulate(goes_on[:-1], axis=0)
        # every panel of the batch is stored: one a point did not take lies beyond its count of
        # panels, which the inverse never reads (and a later batch builds only for points that
        # took all of theirs)
        stored = slice(j0, j0 + batch)
        self.offset[stored, live] = ref
        self.tops[stored, live] = y[-1]
        self.nodes[stored, live, 0] = z.transpose(1, 2, 0)
        self.nodes[stored, live, 1] = tail_and_slope[3:].transpose(1, 2, 0)
        if j0 == 0:
            self.bottom[live] = y[0, 0]
        self.ok[live[(taken & ~good).any(axis=0)]] = False
        if taken.all():                                             # (each point's last panel: the batch's)
            K[live], err_k[live] = k_nodes[-1, -1], err_nodes[-1, -1]
            self.panels[live] = j0 + batch
        else:
            last = taken.sum(axis=0) - 1                            # each point's last panel taken
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
        return np.asarray(rheo._stress(np.maximum(g, _TINY)), dtype=float)

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
        cols = np.arange(self.x0.size)                              # (broadcast against j's rows)
        # the panel of each target: the count of panels whose top is below it
        t_nodes = self.rule.t
        with np.errstate(invalid="ignore", divide="ignore"):
            j = np.minimum((self.tops[:, None, :] < y2[None]).sum(axis=0), np.maximum(self.panels - 1, 0))
            inside = (y2 >= self.bottom) & (y2 <= self.tops[j, cols]) & self.ok
            nodes = self.nodes[j, cols]                             # (rows, P, 2, DEGREE + 1)
            z_nodes, slopes = nodes[..., 0, :], nodes[..., 1, :]    # the values the panel interpolated
            z = y2 - self.offset[j, cols]                           # (exact within a factor 2: Sterbenz)
            weights = lobatto_weights(DEGREE)
            # the start: t as a function of z through the nodes (z_i, t_i), by the linear rational
            # interpolant with the Lobatto nodes' weights at the z_i, their image under the smooth
            # increasing y; its error falls exponentially with the degree (Baltensperger, Berrut &
            # Noël, Math. Comp. 68, 1999): a start, which Newton's method below checks
            # (a target on a node exactly gives 0/0: the panel's bottom instead, Newton's start;
            # fmax and fmin drop a NaN)
            t = np.fmin(np.fmax(barycentric(weights, z[..., None] - z_nodes, t_nodes), -1.0), 1.0)
            # Newton on the interpolant, quadratic: after a step below 1e-9 the error is ~1e-18 and
            # that point stops (its iterations do not depend on its neighbours'). The interpolant
            # and its derivative (degree n - 1: exact from its values at the nodes) by the
            # barycentric formula, stable at Chebyshev points (Higham, IMA J. Numer. Anal. 24, 2004)
            moving = inside.copy()
            for _ in range(10):
                offset_t = t[..., None] - t_nodes
                ratio = weights / offset_t
                total = ratio.sum(axis=-1)
                value = (ratio * z_nodes).sum(axis=-1) / total
                slope = (ratio * slopes).sum(axis=-1) / total
                on_node = offset_t == 0.0
                if on_node.any():
                    value = at_nodes(on_node, value, z_nodes)
                    slope = at_nodes(on_node, slope, slopes)
                # (a point that has converged keeps its t: its bits do not depend on its neighbours';
                # a NaN step leaves it moving, and unvouched after the last iteration)
                step = np.where(moving, (value - z) / slope, 0.0)
                t = np.fmin(np.fmax(t - step, -1.0), 1.0)
                moving &= ~(np.abs(step) <= 1e-9)
                if not moving.any():
                    break
            inside &= ~moving
            x = self.x0 + WIDTH * (j + 0.5 * (t + 1.0))   # (t = -1: the panel's start)
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
    y_lo = np.asarray(np.nan if y_lo is None else y_lo, dtype=float)
    if y_lo.shape != y_hi.shape:
        y_lo = np.broadcast_to(y_lo, y_hi.shape)
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
