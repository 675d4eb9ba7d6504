r"""Error-controlled, vectorized adaptive quadrature: Gauss–Kronrod 10/21 on many intervals at once.

:func:`adaptive` integrates one integrand over an interval per point, for thousands of points
in a few array operations per round. Each panel carries the Kronrod estimate and the QUADPACK
error estimate

.. math::

    E = \rho\,\min\bigl(1, (200\,|K_{21} - G_{10}|/\rho)^{3/2}\bigr), \qquad
    \rho = \int |f - \bar f|,

which is how QUADPACK (``qk21``) and :func:`scipy.integrate.quad` estimate the error of the
21-point rule from its embedded 10-point Gauss rule (with a floor of two units of rounding of
:math:`\int |f|` per panel, instead of QUADPACK's fifty, so that a relative tolerance of 1e-14
can be met). A point is done when the sum of its panels' estimates is within
``max(atol, rtol |I|)``; otherwise the worst panels of that point are bisected, and only the new
halves are evaluated. A point that cannot reach its tolerance keeps its best value and is
reported through ``converged = False`` with its estimate: the caller decides whether that is an
:class:`~tubefsi.AccuracyWarning` (:func:`warn_unconverged`), so that trial points of an
iteration never warn.

``robust=True`` makes the estimate safe for integrands that are not smooth (a kinked
constitutive law), where QUADPACK's estimate presumes a convergence the rule does not have:

* a panel's estimate is at least :math:`|K_{21} - G_{10}|`;
* each half of a bisected panel is charged at least a third of the change of the panel's value
  on bisection (that change is the parent's true error; across a kink the error falls as the
  width squared, so a half keeps a third of it);
* each panel is also evaluated at its two ends, and the mismatch there of the polynomial through
  its 21 nodes, times the width of the strip beyond the outermost node (0.22 % of the panel), is
  added: a Gauss-type rule never samples that strip, and a kink inside it would be integrated as
  the smooth continuation with a tiny estimate.

:func:`adaptive_to_pole` grades the panels toward a singularity beyond the upper end (a locking
stretch), :func:`unit_integral` toward :math:`t = 0` on :math:`(0, 1]` (an algebraic singularity,
a yield point). The fixed composite Gauss–Legendre rules at the end of the module carry no error
estimate: only a coarse coupler uses them, and it is checked against the adaptive rule.

The nodes and weights are QUADPACK's ``qk21`` constants; ``tests/test_quadrature.py`` checks them.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..errors import AccuracyWarning, warn_user
from .kernels import gauss_legendre, rows_dot

__all__ = ["Integral", "adaptive", "adaptive_to_pole", "unit_integral", "warn_unconverged", "KRONROD_NODES",
           "KRONROD_WEIGHTS", "GAUSS_WEIGHTS", "integrate_panels", "integrate_fitted", "integrate_graded"]

_X = np.array([
    0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
    0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
    0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
    0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
    0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0,
])
_WK = np.array([
    0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
    0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
    0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
    0.123491976262065851077958109831074, 0.134709217311473325928054001771707,
    0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
    0.149445554002916905664936468389821,
])
_WG = np.array([
    0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
    0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
    0.295524224714752870173892994651338,
])

#: The 21 Kronrod nodes on [0, 1], ascending, and the Kronrod and embedded Gauss weights there.
KRONROD_NODES = 0.5 * (1.0 + np.concatenate([-_X[:-1], _X[::-1]]))
KRONROD_WEIGHTS = 0.5 * np.concatenate([_WK[:-1], _WK[::-1]])
#: The 10-point Gauss weights on [0, 1], for the nodes ``KRONROD_NODES[1::2]``.
GAUSS_WEIGHTS = 0.5 * np.concatenate([_WG, _WG[::-1]])

_EPS = float(np.finfo(float).eps)


def _lagrange_at(nodes, point):
    """Weights of the polynomial interpolating at ``nodes``, evaluated at ``point``."""
    w = np.ones(nodes.size)
    for k in range(nodes.size):
        others = np.delete(nodes, k)
        w[k] = np.prod((point - others) / (nodes[k] - others))
    return w


def _rules(robust):
    """The rules as columns over a panel's values: Kronrod, Gauss, and (``robust``: the values then
    include the two ends first and last) the nodes' interpolant at each end minus the end value."""
    if not robust:
        rules = np.zeros((21, 2))
        rules[:, 0] = KRONROD_WEIGHTS
        rules[1::2, 1] = GAUSS_WEIGHTS
        return rules
    rules = np.zeros((23, 4))
    rules[1:-1, 0] = KRONROD_WEIGHTS
    rules[2:-1:2, 1] = GAUSS_WEIGHTS
    rules[1:-1, 2] = _lagrange_at(KRONROD_NODES, 0.0)
    rules[1:-1, 3] = _lagrange_at(KRONROD_NODES, 1.0)
    rules[0, 2] = rules[-1, 3] = -1.0
    return rules


_PLAIN, _ROBUST = _rules(False), _rules(True)
_ROBUST_NODES = np.concatenate([[0.0], KRONROD_NODES, [1.0]])
_END_GAP = float(KRONROD_NODES[0])          # the part of a panel beyond its outermost node


@attrs.frozen
class Integral:
    """What the adaptive rules return: arrays of one shape (the intervals')."""

    value: np.ndarray       #: the integral
    error: np.ndarray       #: the a-posteriori error estimate
    converged: np.ndarray   #: whether ``error <= max(atol, rtol |value|)`` (or within the rounding)
    panels: np.ndarray      #: the number of panels used

    @classmethod
    def exact(cls, value) -> Integral:
        """Values known exactly (a closed form): no error, converged."""
        value = np.asarray(value, dtype=float)
        return cls(value=value, error=np.zeros(value.shape), converged=np.ones(value.shape, dtype=bool),
                   panels=np.zeros(value.shape, dtype=int))

    def replaced(self, positions, other: Integral) -> Integral:
        """This integral with the (flat) entries ``positions`` taken from ``other``."""
        fields = {}
        for name in ("value", "error", "converged", "panels"):
            mine = np.array(getattr(self, name)).ravel()
            mine[positions] = np.ravel(getattr(other, name))
            fields[name] = mine.reshape(np.shape(getattr(self, name)))
        return Integral(**fields)

    def __add__(self, other: Integral) -> Integral:
        """The integral over the union of two adjacent intervals (same points)."""
        return Integral(value=self.value + other.value, error=self.error + other.error,
                        converged=self.converged & other.converged, panels=self.panels + other.panels)


def _panel_rule(f, lo, hi, idx, noise, robust, noise_absolute=False):
    """Kronrod values, error estimates and rounding floors of the panels ``[lo, hi]``."""
    h = hi - lo
    if robust:
        x = lo[:, None] + h[:, None] * _ROBUST_NODES
        x[:, 0], x[:, -1] = lo, hi
        inner = slice(1, -1)
    else:
        x = lo[:, None] + h[:, None] * KRONROD_NODES
        inner = slice(None)
    y = np.asarray(f(x, idx), dtype=float)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        rules = rows_dot(y, _ROBUST if robust else _PLAIN)
        kron = rules[:, 0]                     # mean values of f on the panel (the weights sum to 1)
        ay = np.abs(y[:, inner])
        magnitude = rows_dot(ay, KRONROD_WEIGHTS)
        spread = rows_dot(np.abs(y[:, inner] - kron[:, None]), KRONROD_WEIGHTS)
        raw = np.abs(kron - rules[:, 1])
        scaled = np.where((spread > 0) & (raw > 0), spread * np.minimum(1.0, (200.0 * raw / spread) ** 1.5), raw)
        if robust:
            # never below |K21 - G10| itself, plus the nodes' interpolant against the end values
            scaled = np.maximum(scaled, raw) + _END_GAP * (np.abs(rules[:, 2]) + np.abs(rules[:, 3]))
        floor = 2.0 * _EPS * magnitude                        # the rule's own rounding
        if noise is not None:                                 # and the integrand's, where known
            rounded = noise(x[:, inner], idx)
            floor = np.maximum(floor, rows_dot(rounded if noise_absolute else ay * rounded, KRONROD_WEIGHTS))
        error = np.maximum(scaled, floor)
    return kron * h, error * np.abs(h), floor * np.abs(h)


def _initial_panels(lo_pt, hi_pt, count, breaks=None):
    """``(idx, lo, hi)`` of ``count[i]`` equal panels per point, or of the panels between the
    ``breaks`` (fractions of each point's interval, 0 first and 1 last)."""
    if breaks is not None:
        edges = lo_pt[:, None] + (hi_pt - lo_pt)[:, None] * breaks          # (points, panels + 1)
        edges[:, -1] = hi_pt
        return np.repeat(np.arange(lo_pt.size), breaks.size - 1), edges[:, :-1].ravel(), edges[:, 1:].ravel()
    idx = np.repeat(np.arange(lo_pt.size), count)
    first = np.cumsum(count) - count
    j = np.arange(idx.size) - first[idx]
    width = (hi_pt - lo_pt)[idx] / count[idx]
    lo = lo_pt[idx] + j * width
    hi = np.where(j == count[idx] - 1, hi_pt[idx], lo + width)
    return idx, lo, hi


def adaptive(f, lower, upper, *, rtol=1e-14, atol=0.0, panels=None, breaks=None, max_rounds=60, max_panels=2048,
             noise=None, noise_absolute=False, robust=False) -> Integral:
    r""":math:`\int_{lower}^{upper} f(x)\,dx` for each entry of ``lower``/``upper``, error-controlled.

    Parameters
    ----------
    f : callable
        ``f(x, index)`` with ``x`` of shape ``(P, m)`` (the nodes of ``P`` panels) and ``index``
        of shape ``(P,)`` (the flat position of each panel's point); returns values of ``x``'s
        shape. Per-point parameters are gathered with ``index`` (e.g. ``a[index, None]``).
    lower, upper : array_like
        The limits (broadcast together); ``upper < lower`` gives minus the integral.
    rtol, atol : float
        The tolerance ``max(atol, rtol |I|)`` on each point's error estimate.
    panels : array_like of int, optional
        Initial number of equal panels per point (default 1).
    breaks : array_like, optional
        Instead, the initial panels' ends as fractions of every point's interval (from 0 to 1):
        panels graded to where the integrand needs them.
    max_rounds, max_panels : int
        Limits of the refinement (rounds of bisection; panels per point).
    noise : callable, optional
        ``noise(x, index)``: the relative rounding error of ``f`` at the nodes, where the caller
        knows it (a difference of nearly equal terms, a pole approached closer than the abscissae
        resolve). A point whose estimate is within twice its rounding floor is done.
    noise_absolute : bool
        ``noise`` gives the absolute rounding error of ``f``'s values instead (a difference of
        nearly equal terms rounded to a fixed amount: no need to evaluate ``f`` again to scale it).
    robust : bool
        Estimates safe for integrands with kinks (module docstring).

    Returns
    -------
    Integral
        ``value``, ``error``, ``converged`` and ``panels``, shaped like the broadcast limits. A
        point stops when its estimate meets the tolerance (or twice its rounding floor), when it
        has not fallen four-fold in 24 rounds (a noisy integrand; a shorter window stops points
        whose bisection is still uncovering a second kink's hidden error), or at ``max_rounds`` or
        ``max_panels``; ``converged`` says which.
    """
    lower, upper = np.broadcast_arrays(np.asarray(lower, dtype=float), np.asarray(upper, dtype=float))
    shape = lower.shape
    lo_pt, hi_pt = lower.ravel(), upper.ravel()
    n = lo_pt.size
    if breaks is not None:
        breaks = np.asarray(breaks, dtype=float)
        count = np.full(n, breaks.size - 1)
    else:
        count = np.ones(n, dtype=int) if panels is None else np.maximum(
            1, np.broadcast_to(np.asarray(panels, dtype=int), shape).ravel())
    idx, lo, hi = _initial_panels(lo_pt, hi_pt, count, breaks)
    value, error, rounding = _panel_rule(f, lo, hi, idx, noise, robust, noise_absolute)
    total = np.bincount(idx, value, minlength=n)
    err = np.bincount(idx, error, minlength=n)
    floor = np.bincount(idx, rounding, minlength=n)
    used = count.copy()
    done_value, done_error, done_floor = np.zeros(n), np.zeros(n), np.zeros(n)   # retired panels
    finished = np.zeros(n, dtype=bool)
    snapshots = []
    for round_ in range(max_rounds):
        tol = np.maximum(atol, rtol * np.abs(total))
        if round_ % 12 == 0:                   # hopeless: not fallen four-fold in 24 rounds
            if len(snapshots) == 2:
                finished |= err > 0.25 * snapshots.pop(0)
            snapshots.append(err.copy())
        finished |= (err <= np.maximum(tol, 2.0 * floor)) | ~np.isfinite(total) | ~np.isfinite(err)
        live = ~finished[idx]
        if not np.any(live):
            break
        if not np.all(live):                   # retire the panels of finished points
            dead = ~live
            done_value += np.bincount(idx[dead], value[dead], minlength=n)
            done_error += np.bincount(idx[dead], error[dead], minlength=n)
            done_floor += np.bincount(idx[dead], rounding[dead], minlength=n)
            idx, lo, hi = idx[live], lo[live], hi[live]
            value, error, rounding = value[live], error[live], rounding[live]
        # bisect each unfinished point's worst panels (within a factor 4 of its largest estimate),
        # as QUADPACK bisects its worst one, but many per round; never one already within 1/100 of
        # its share of the tolerance
        worst = np.zeros(n)
        np.maximum.at(worst, idx, error)
        split = (error >= 0.25 * worst[idx]) & (error > 0.01 * tol[idx] / used[idx]) & (used[idx] < max_panels)
        if not np.any(split):
            break
        mid = 0.5 * (lo[split] + hi[split])
        s_idx = np.concatenate([idx[split], idx[split]])
        s_lo = np.concatenate([lo[split], mid])
        s_hi = np.concatenate([mid, hi[split]])
        s_val, s_err, s_rnd = _panel_rule(f, s_lo, s_hi, s_idx, noise, robust, noise_absolute)
        if robust:                             # a half keeps a third of its parent's true error
            parent = value[split]
            change = np.abs(parent - (s_val[:parent.size] + s_val[parent.size:])) / 3.0
            s_err = np.maximum(s_err, np.concatenate([change, change]))
        used += np.bincount(idx[split], minlength=n)
        keep = ~split
        idx = np.concatenate([idx[keep], s_idx])
        lo = np.concatenate([lo[keep], s_lo])
        hi = np.concatenate([hi[keep], s_hi])
        value = np.concatenate([value[keep], s_val])
        error = np.concatenate([error[keep], s_err])
        rounding = np.concatenate([rounding[keep], s_rnd])
        total = done_value + np.bincount(idx, value, minlength=n)
        err = done_error + np.bincount(idx, error, minlength=n)
        floor = done_floor + np.bincount(idx, rounding, minlength=n)
    tol = np.maximum(atol, rtol * np.abs(total))
    converged = (err <= np.maximum(tol, 2.0 * floor)) & np.isfinite(total)
    return Integral(value=total.reshape(shape), error=err.reshape(shape), converged=converged.reshape(shape),
                    panels=used.reshape(shape))


def adaptive_to_pole(f, lower, upper, pole, *, gap=None, reach=1.0, rtol=1e-14, atol=0.0, panel_width=2.0,
                     max_rounds=60) -> Integral:
    r""":func:`adaptive` for an integrand that may be singular at ``x = pole`` (> ``upper``; ``inf``
    for none), as a locking material's stiffness is at its locking stretch.

    Within ``reach`` of the pole the integral is taken in :math:`y = \ln(\text{pole} - x)`,
    :math:`\int f\,dx = \int f(\text{pole} - e^y)\,e^y\,dy`, where a pole or a logarithmic
    singularity of ``f`` becomes a smooth, slowly varying integrand. ``gap`` is
    ``pole - upper``, computed by the caller without cancellation (default: the difference).
    ``f(x, index)`` is called as for :func:`adaptive`; the initial panels are at most
    ``panel_width`` wide. ``lower >= 0`` and ``upper >= lower`` elementwise.
    """
    lower, upper, pole = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (lower, upper, pole)))
    shape = lower.shape
    lo, up, po = lower.ravel(), upper.ravel(), pole.ravel()
    # the substitution pays where the pole is closer to the upper end than the interval is long
    d_gap = (po - up) if gap is None else np.broadcast_to(np.asarray(gap, dtype=float), shape).ravel()
    finite = np.isfinite(po) & (d_gap < up - lo)
    split = np.where(finite, np.clip(po - reach, lo, up), up)
    count = np.maximum(1, np.ceil((split - lo) / panel_width)).astype(int)
    head = adaptive(f, lo, split, rtol=rtol, atol=atol, panels=count, max_rounds=max_rounds)
    value, error, converged, panels = (head.value.copy(), head.error.copy(), head.converged.copy(),
                                       head.panels.copy())
    near = np.flatnonzero(finite & (up > split))
    if near.size:
        pn = po[near]
        d_end = np.maximum(d_gap[near], np.abs(pn) * 4 * _EPS)        # distance of the upper end to the pole

        def g(y, sub):
            e = np.exp(y)
            return f(pn[sub, None] - e, near[sub]) * e

        def rounding(y, sub):     # pole - e^y is rounded to eps |pole|: the distance e^y is no finer
            return 4.0 * _EPS * (1.0 + np.abs(pn[sub, None])) / np.exp(y)

        # y from ln(pole - upper) to ln(pole - split), their difference without cancellation
        y_lo = np.log(d_end)
        y_hi = y_lo + np.log1p((up[near] - split[near]) / d_end)
        tail = adaptive(g, y_lo, y_hi, rtol=rtol, atol=atol,
                        panels=np.maximum(1, np.ceil((y_hi - y_lo) / panel_width)).astype(int),
                        max_rounds=max_rounds, noise=rounding)
        value[near] += tail.value
        error[near] += tail.error
        panels[near] += tail.panels
        converged[near] &= tail.converged
    return Integral(value=value.reshape(shape), error=error.reshape(shape), converged=converged.reshape(shape),
                    panels=panels.reshape(shape))


#: :func:`unit_integral` integrates over z in [0, 40], t = e^-z (the rest of (0, 1] is below e^-40),
#: on initial panels of width 1 near the upper end t = 1, where the integrand carries most of the
#: integral (a Kronrod panel of width 2 there misses 1e-15 for a smooth law, and was bisected at
#: every point), widening toward z = 40, where a panel carries at most e^-z of it
_Z_END = 40.0
_Z_BREAKS = tuple(z / _Z_END for z in (0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 22.0, 30.0, 40.0))


def unit_integral(f, n: int, *, rtol: float = 1e-15, rounding=None, relative_rounding=None,
                  max_rounds: int = 60, max_panels: int = 2048) -> Integral:
    r""":math:`\int_0^1 f(t)\,dt` for ``n`` points at once, error-controlled and safe for kinks.

    ``f(t, index)`` gets ``t`` of shape ``(P, m)`` and the points' indices. The integral is taken
    in :math:`t = e^{-z}` over :math:`z \in [0, 40]` with 11 initial panels (ends 0, 1, 2, 3, 4,
    6, 8, 12, 16, 22, 30, 40): geometric grading toward :math:`t = 0`, where an algebraic
    singularity (:math:`t^{1/n}`, a yield point) becomes a smooth, exponentially decaying
    integrand. The omitted :math:`(0, e^{-40})` is below 4e-18 of the integral for the bounded,
    monotone integrands it serves (the Rabinowitsch–Mooney integral, velocity profiles).
    ``rounding(index)``, if given, is the absolute rounding error of ``f``'s values per point (a
    difference of nearly equal terms), or ``relative_rounding(t, index)`` their relative rounding
    at the nodes. The rule is :func:`adaptive` with ``robust=True``.
    """
    def g(z, idx):
        t = np.exp(-z)
        return np.asarray(f(t, idx), dtype=float) * t

    noise = None
    if relative_rounding is not None:
        def noise(z, idx):
            return relative_rounding(np.exp(-z), idx)
    elif rounding is not None:
        def noise(z, idx):              # g = f t: f's absolute rounding, times t
            return rounding(idx)[:, None] * np.exp(-z)

    return adaptive(g, np.zeros(n), np.full(n, _Z_END), rtol=rtol, breaks=_Z_BREAKS,
                    max_rounds=max_rounds, max_panels=max_panels, noise=noise,
                    noise_absolute=relative_rounding is None, robust=True)


def warn_unconverged(what: str, result: Integral, where=None) -> None:
    """The ``AccuracyWarning`` of an integral that missed its tolerance somewhere (``where``: a
    boolean mask of the points that count, default all); silent where every point converged."""
    bad = ~np.asarray(result.converged, dtype=bool)
    if where is not None:
        bad &= np.asarray(where, dtype=bool)
    if not bad.any():
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(result.value != 0, np.abs(result.error / result.value), np.inf)
    worst = float(np.max(np.where(bad, rel, -np.inf)))
    estimate = f"estimated relative error up to {worst:.2g}" if math.isfinite(worst) else \
        "its error could not be estimated (a non-finite or zero value)"
    warn_user(f"{what} did not reach its tolerance at {int(np.count_nonzero(bad))} point(s); {estimate}",
              AccuracyWarning)


# ------------------------------------------------------------------ fixed rules (no error estimate)
def integrate_panels(f, upper, *, order=16, panel_width=2.0):
    r"""``∫_0^upper f(u) du`` for each entry of ``upper`` (>= 0), by composite Gauss–Legendre.

    ``f(u, index)`` receives an array of shape ``(k, m)`` for ``k`` of the points; a point's
    panels have width at most ``panel_width``. Points are grouped by panel count so each group is
    one array operation; intervals shorter than a quarter panel use half the order.
    """
    return _composite(f, np.asarray(upper, dtype=float), np.full(np.shape(upper), float(panel_width)),
                      order)[0]


def _composite(f, upper, width, order):
    """Composite Gauss–Legendre of ``f`` on [0, upper_i] with panels of width <= width_i, and, per
    point, ``kappa h / m``: the largest |d ln|f|/du| across a panel times the panel width, over
    what ``m`` nodes resolve."""
    flat, widths = upper.ravel(), np.broadcast_to(width, upper.shape).ravel()
    out, load = np.zeros(flat.shape), np.zeros(flat.shape)
    panels = np.maximum(1, np.ceil(flat / widths)).astype(int)
    groups = np.where(flat <= 0.25 * widths, 0, panels)
    for g in np.unique(groups):
        sel = np.flatnonzero(groups == g)
        count, m = (1, max(order // 2, 4)) if g == 0 else (int(g), order)
        x, w = gauss_legendre(m)
        t = ((np.arange(count)[:, None] + x[None, :]) / count).ravel()
        wt = np.tile(w, count) / count
        values = f(flat[sel, None] * t, sel)
        out[sel] = flat[sel] * rows_dot(values, wt)
        # e^(kappa u) on a panel of width h is integrated to full precision for kappa h <= m
        # (m >= 12; 0.6 m below), i.e. for |ln(last / first)| <= c = (x_m - x_1) m
        panel = values.reshape(len(sel), count, m)
        first, last = np.abs(panel[..., 0]), np.abs(panel[..., -1])
        c = (x[-1] - x[0]) * (m if m >= 12 else 0.6 * m)
        small = np.minimum(first, last)
        big = small >= 1e-3 * np.maximum(first.max(axis=-1), last.max(axis=-1))[:, None]
        steep = big & (np.maximum(first, last) > math.exp(c) * small)
        rows = np.flatnonzero(steep.any(axis=-1))
        if rows.size:
            with np.errstate(all="ignore"):
                ratio = np.abs(np.log(last[rows] / first[rows])) / c
            load[sel[rows]] = np.max(np.where(steep[rows] & np.isfinite(ratio), ratio, 0.0), axis=-1)
    return out.reshape(upper.shape), load.reshape(upper.shape)


def integrate_fitted(f, upper, *, order=16, panel_width=2.0):
    r""":func:`integrate_panels`, with each point's panels narrowed until :math:`\kappa h \le m`,
    :math:`\kappa` the largest :math:`|d\ln f/du|` across a panel (from its end nodes): an
    integrand that grows exponentially or faster (a strain-stiffening wall) stays as accurate as a
    slowly varying one. Where the first pass satisfies it the result is that of
    :func:`integrate_panels`."""
    flat = np.asarray(upper, dtype=float).ravel()
    width = np.full(flat.shape, float(panel_width))
    out = np.zeros(flat.shape)
    todo = np.arange(flat.size)
    for _ in range(12):
        value, load = _composite(lambda u, i: f(u, todo[i]), flat[todo], width[todo], order)
        out[todo] = value
        count = np.maximum(1, np.ceil(flat[todo] / width[todo]))
        h = flat[todo] / count                                                  # the panel width used
        coarse = (load > 1.0) & (count < 1e4)                                   # at most 1e4 panels
        if not np.any(coarse):
            break
        width[todo[coarse]] = 0.9 * h[coarse] / load[coarse]
        todo = todo[coarse]
    return out.reshape(np.shape(upper))


def integrate_graded(f, upper, pole, *, gap=None, reach=1.0, order=16, panel_width=2.0):
    r"""``∫_0^upper f(u) du`` like :func:`integrate_fitted`, for an integrand that may be singular at
    ``u = pole`` (``> upper``; scalar or one per point, ``inf`` for none): the part within ``reach``
    of the pole is integrated in :math:`t = \ln(\text{pole} - u)` on panels of unit width (panels
    in ``u`` graded geometrically toward the pole). ``gap`` (default ``pole - upper``) lets the
    caller pass the distance to the pole without cancellation."""
    upper = np.asarray(upper, dtype=float)
    flat = upper.ravel()
    pole = np.broadcast_to(np.asarray(pole, dtype=float), upper.shape).ravel()
    if not np.any(np.isfinite(pole)):
        return integrate_fitted(f, upper, order=order, panel_width=panel_width)
    split = np.where(np.isfinite(pole), np.maximum(pole - reach, 0.0), np.inf)
    out = integrate_fitted(f, np.minimum(flat, split), order=order, panel_width=panel_width).ravel()
    near = np.flatnonzero(flat > split)
    if near.size:
        pn = pole[near]
        d = pn - flat[near] if gap is None else np.broadcast_to(np.asarray(gap, dtype=float),
                                                                 upper.shape).ravel()[near]
        d = np.maximum(d, pn * 4 * _EPS)                       # distance of the upper end to the pole
        top = pn - split[near]

        def g(y, sub):                                         # u = pole - d e^y, du = -d e^y dy
            e = d[sub, None] * np.exp(y)
            return f(pn[sub, None] - e, near[sub]) * e

        out[near] += integrate_panels(g, np.log(top / d), order=order, panel_width=1.0)
    return out.reshape(upper.shape)
