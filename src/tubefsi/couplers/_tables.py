r"""Error-controlled tables of the separated identity, for whole curves and repeated scalar calls.

For a power-law fluid, :math:`G(q, R) = \phi(q)R^{-k}`, and a wall whose tube law scales with one
modulus, :math:`P = \mu\hat P(\lambda)`, the separated identity (``docs/theory.md``, section
"Coupling without an ODE") reads :math:`\hat J(v) = L\phi(q)/(\mu a^k)` with

.. math:: \hat J(v) = \int_0^v s^{k+1}\,\hat P'(s)\,du, \qquad s = e^u,

which depends only on the wall's shape, :math:`\bar t` and :math:`n`: not on :math:`q`,
:math:`\mu`, :math:`m`, :math:`a` or :math:`L`. A :class:`SeparatedTable` holds, for one such
key, piecewise-Chebyshev interpolants of

* :math:`x(y) = \ln\hat J(e^y)` (the forward map, :math:`y = \ln v`),
* :math:`y(x)` (its inverse: the inlet log-stretch of a target), and
* :math:`\ln\hat P(e^{e^y})` (the pressure drop), where the wall's pressure needs a quadrature,

each refined panel by panel until its Chebyshev tail is below the tolerance, then checked a
posteriori at points that were not interpolated: the forward map and the pressure against
fresh error-controlled quadratures, the inverse against the forward map's exact value at its
answer. A table whose check fails is not used (its points go to the direct solver), so a table
never makes an answer less accurate than the direct path; the estimate is kept in
:attr:`SeparatedTable.error`.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

__all__ = ["Chebyshev", "ScalarPair", "SeparatedTable", "UniformPolynomial", "fit_chebyshev", "fit_on_breaks",
           "fit_uniform"]

_DEGREE = 10
_NODES = np.cos(np.pi * (np.arange(_DEGREE + 1) + 0.5) / (_DEGREE + 1))[::-1]     # ascending, in (-1, 1)
_FIT = np.polynomial.chebyshev.chebvander(_NODES, _DEGREE)
_FIT_INV = np.linalg.inv(_FIT)
_CHECK = np.array([-0.97, -0.81, -0.55, -0.23, 0.11, 0.43, 0.71, 0.93])              # not nodes
_AT_CHECK = np.polynomial.chebyshev.chebvander(_CHECK, _DEGREE)


def _cheb_to_mono(degree):
    """Row k: the monomial coefficients of T_k (numpy's cheb2poly), to ``degree``."""
    return np.array([np.pad(np.polynomial.chebyshev.cheb2poly(np.eye(degree + 1)[k]), (0, degree - k))
                     for k in range(degree + 1)])


_CHEB_TO_MONO = _cheb_to_mono(_DEGREE)


def _fit_panels(f, a, b):
    """The degree-10 Chebyshev coefficients of ``f`` (vectorized) on the panels ``a[i] .. b[i]``
    and, per panel, the interpolant's miss at the check points and its tail, both relative to
    ``max(1, |f|)``: ``(coef, miss, tail, mid)``."""
    mid, half = 0.5 * (a + b), 0.5 * (b - a)
    x = np.concatenate([mid[:, None] + half[:, None] * _NODES, mid[:, None] + half[:, None] * _CHECK], axis=1)
    values = np.asarray(f(x.ravel()), dtype=float).reshape(x.shape)
    y_nodes, y_check = values[:, :_DEGREE + 1], values[:, _DEGREE + 1:]
    coef = y_nodes @ _FIT_INV.T
    scale = np.maximum(1.0, np.max(np.abs(y_nodes), axis=1))
    miss = np.max(np.abs(coef @ _AT_CHECK.T - y_check), axis=1) / scale
    tail = np.max(np.abs(coef[:, -3:]), axis=1) / scale
    return coef, miss, tail, mid


class Chebyshev:
    """A piecewise Chebyshev interpolant: degree-10 series on the panels ``breaks[j] .. breaks[j+1]``."""

    def __init__(self, breaks, coef):
        self.breaks = np.asarray(breaks, dtype=float)
        self.coef = np.asarray(coef, dtype=float)
        self._breaks = self.breaks.tolist()
        self.lo, self.hi = float(self.breaks[0]), float(self.breaks[-1])
        self._width = np.diff(self.breaks)
        # 2t = 4 (x - a) / width - 2 on the panel [a, a + width], as one multiply and one add
        self._t2_scale = 4.0 / self._width
        self._t2_offset = -2.0 - self.breaks[:-1] * self._t2_scale
        self._t2_scale_list, self._t2_offset_list = self._t2_scale.tolist(), self._t2_offset.tolist()
        self._coef_parts = [(row[-1], tuple(row[-2:0:-1]), row[0]) for row in self.coef.tolist()]
        self._last = len(self._breaks) - 2
        self._coefT = np.ascontiguousarray(self.coef.T)
        # Horner in the monomial basis of t takes three passes per degree where Clenshaw takes
        # four; it is used where the conversion does not amplify rounding: sum |a_j| within twice
        # sum |c_k| on every panel (the two rules' error bounds then agree; for the fast-decaying
        # series of a table the monomial sums are within a few per cent of the Chebyshev ones)
        mono = self.coef @ _CHEB_TO_MONO
        self._horner = bool(np.all(np.abs(mono).sum(axis=1) <= 2.0 * np.abs(self.coef).sum(axis=1)))
        self._monoT = np.ascontiguousarray(mono.T)
        self._mono_parts = [tuple(row[::-1]) for row in mono.tolist()]     # a_D, ..., a_0
        self._scalar_panels = [None] * len(self._mono_parts)
        self._t_scale, self._t_offset = 0.5 * self._t2_scale, 0.5 * self._t2_offset
        self._t_scale_list, self._t_offset_list = self._t_scale.tolist(), self._t_offset.tolist()
        # panel lookup by equal buckets as narrow as the narrowest panel (the panels come from
        # bisection, so a bucket holds at most two of them): one multiply and a gather instead
        # of a binary search; a bucket keeps its first panel and the break inside it
        count = int(max(1, math.ceil((self.hi - self.lo) / self._width.min() - 1e-9)))
        self._search = count > 1 << 16          # panels too uneven for buckets: binary search
        count = min(count, 1 << 16)
        self._bucket_scale = count / (self.hi - self.lo)
        edges = self.lo + np.arange(count) / self._bucket_scale
        first = np.clip(np.searchsorted(self.breaks, edges, side="right") - 1, 0, len(self.breaks) - 2)
        self._bucket_panel = first
        self._bucket_break = self.breaks[np.minimum(first + 1, len(self.breaks) - 1)]
        self._buckets = count

    def _panel(self, x):
        """The panel index of each ``x``, possibly one past the last panel at its upper end: every
        gather by it clips (``mode="clip"``) to the panels."""
        if self._search:
            return np.clip(np.searchsorted(self.breaks, x, side="right") - 1, 0, len(self.breaks) - 2)
        b = np.subtract(x, self.lo)
        b *= self._bucket_scale
        # clipped while still floats (two ufuncs, not np.clip: its Python wrapper costs more than
        # the work at a few points; and the integer ufuncs are not vectorized)
        np.minimum(b, self._buckets - 1, out=b)
        np.maximum(b, 0.0, out=b)
        b = b.astype(np.intp)
        j = self._bucket_panel.take(b, mode="clip")
        j += x >= self._bucket_break.take(b, mode="clip")     # the second panel of a bucket holding two
        return j

    def __call__(self, x, out=None):
        """Values at ``x`` (an array inside ``[lo, hi]``): a panel lookup and one Clenshaw sweep (or
        Horner, below). ``out``: a float array of ``x``'s shape for the values (it may be ``x``
        itself: ``x`` is read only before the first value is written)."""
        x = np.asarray(x, dtype=float)
        if x.ndim != 1:                                        # the lookups work on flat arrays
            return self(x.ravel()).reshape(x.shape)
        j = self._panel(x)
        # (per-panel factors gathered first and scaled in place: no pass allocates what it does not
        # keep; and every gather with mode="clip", the indices being in range: with the default
        # mode, "raise", a gather into ``out`` is buffered and costs twice as much)
        if self._horner:
            t = self._t_scale.take(j, mode="clip")              # t in [-1, 1] on the panel
            t *= x
            ak = self._t_offset.take(j, mode="clip")
            t += ak
            mono = self._monoT
            value = mono[_DEGREE].take(j, out=out, mode="clip")
            for k in range(_DEGREE - 1, -1, -1):               # b = b t + a_k
                value *= t
                mono[k].take(j, out=ak, mode="clip")
                value += ak
            return value
        t2 = self._t2_scale.take(j, mode="clip")               # 2 t, t in [-1, 1] on the panel
        t2 *= x
        t2 += self._t2_offset.take(j, mode="clip")
        # Clenshaw with the coefficients gathered one degree at a time into contiguous vectors (a
        # 2-D gather coef[:, j] has strided rows: every pass over them was three times slower)
        coef = self._coefT
        b2 = coef[_DEGREE].take(j, mode="clip")
        b1 = np.multiply(t2, b2)
        b1 += coef[_DEGREE - 1].take(j, mode="clip")
        ck, tmp = np.empty_like(b1), np.empty_like(b1)
        for k in range(_DEGREE - 2, 0, -1):                    # b_k = 2t b_{k+1} - b_{k+2} + c_k
            coef[k].take(j, out=ck, mode="clip")
            ck -= b2
            np.multiply(t2, b1, out=tmp)
            tmp += ck
            b1, b2, tmp = tmp, b1, b2
        value = np.multiply(t2, b1, out=out)
        value *= 0.5
        value -= b2
        value += coef[0].take(j, out=ck, mode="clip")
        return value

    def scalar(self, x: float) -> float:
        """The value at one float ``x``, in plain Python (the scalar path)."""
        j = bisect.bisect_right(self._breaks, x) - 1
        j = 0 if j < 0 else (self._last if j > self._last else j)
        if self._horner:
            panel = self._scalar_panels[j]
            if panel is None:                          # the panel's Horner rule, made on first use
                panel = self._scalar_panels[j] = _horner_rule(self._mono_parts[j], self._t_scale_list[j],
                                                              self._t_offset_list[j])
            return panel(x)
        t2 = x * self._t2_scale_list[j] + self._t2_offset_list[j]
        top, inner, c0 = self._coef_parts[j]       # c_D; c_{D-1}, ..., c_1; c_0
        b1, b2 = top, 0.0
        for ck in inner:
            b1, b2 = t2 * b1 - b2 + ck, b1
        return 0.5 * t2 * b1 - b2 + c0

    def derivative(self):
        """The interpolant of the derivative (on the same panels)."""
        scale = 2.0 / np.diff(self.breaks)
        d = np.polynomial.chebyshev.chebder(self.coef.T, axis=0).T * scale[:, None]
        return Chebyshev(self.breaks, np.pad(d, ((0, 0), (0, 1))))


def fit_on_breaks(f, breaks, *, tol=5e-14):
    """``(Chebyshev, error)`` of ``f`` (vectorized) on the given panels ``breaks``, each panel's
    tail and check points within ``tol`` (as in :func:`fit_chebyshev`); ``(None, inf)`` if a panel
    misses (no splitting: the panels are another interpolant's, whose scalar path this one joins)."""
    coef, miss, tail, _ = _fit_panels(f, np.asarray(breaks[:-1], dtype=float), np.asarray(breaks[1:], dtype=float))
    if not np.all(np.isfinite(miss) & (miss <= tol) & (tail <= tol)):
        return None, math.inf
    return Chebyshev(breaks, coef), float(np.max(miss))


class ScalarPair:
    """Two interpolants on the same panels evaluated together at one float: one panel search and
    one call of a generated rule that returns both values (the scalar path of a table: the inlet
    log-stretch and the log pressure of a target). Each value is what its own
    :meth:`Chebyshev.scalar` gives, to the bit, where both use Horner's rule."""

    def __init__(self, first: Chebyshev, second: Chebyshev):
        if not np.array_equal(first.breaks, second.breaks) or not (first._horner and second._horner):
            raise ValueError("a ScalarPair needs two Horner-rule interpolants on the same panels")
        self._first, self._second = first, second
        self._breaks, self._last = first._breaks, first._last
        self._rules = [None] * (self._last + 1)

    def __call__(self, x: float):
        """``(first(x), second(x))`` for one float ``x``."""
        j = bisect.bisect_right(self._breaks, x) - 1
        j = 0 if j < 0 else (self._last if j > self._last else j)
        rule = self._rules[j]
        if rule is None:                       # the panel's rule, made on first use
            one, two = self._first, self._second
            rule = self._rules[j] = _horner_rule(one._mono_parts[j], one._t_scale_list[j], one._t_offset_list[j],
                                                 two._mono_parts[j])
        return rule(x)


def _horner_rule(parts, scale, offset, second=None):
    """``x -> sum_k a_k t^k``, ``t = x scale + offset``, for one float: Horner's rule unrolled into
    one expression with the panel's numbers as constants (``parts``: a_D, ..., a_0). The same
    operations in the same order as the loop ``value = value t + a`` from ``a_D``, so the same
    bits, at a third of its cost (the scalar path evaluates two tables per solve). ``second``: the
    coefficients of a second polynomial in the same ``t``; the rule then returns both values."""
    def horner(coefficients):
        expr = repr(coefficients[0])
        for a in coefficients[1:]:
            expr = f"({expr}) * t + {a!r}"
        return expr

    body = horner(parts) if second is None else f"{horner(parts)}, {horner(second)}"
    namespace: dict = {}
    exec(f"def rule(x):\n    t = x * {scale!r} + {offset!r}\n    return {body}\n", namespace)   # noqa: S102
    return namespace["rule"]


def fit_chebyshev(f, lo, hi, *, panels=4, tol=1e-14, max_panels=256):
    """``(Chebyshev, error)``: ``f`` (vectorized) interpolated on ``[lo, hi]``, panels split until
    each one's tail and its check points are within ``tol`` (absolute, relative to ``max(1, |f|)``).

    ``error`` is the largest check-point discrepancy seen on the accepted panels (``inf`` if some
    panel could not be accepted within ``max_panels``).
    """
    pending = list(zip(np.linspace(lo, hi, panels + 1)[:-1], np.linspace(lo, hi, panels + 1)[1:]))
    done, worst = [], 0.0
    while pending:
        if len(done) + len(pending) > max_panels:
            return None, math.inf
        a = np.array([p[0] for p in pending])
        b = np.array([p[1] for p in pending])
        coef, miss, tail, mid = _fit_panels(f, a, b)
        ok = np.isfinite(miss) & (miss <= tol) & (tail <= tol)
        nxt = []
        for i in range(len(a)):
            if ok[i]:
                done.append((a[i], b[i], coef[i]))
                worst = max(worst, float(miss[i]))
            else:
                nxt += [(a[i], mid[i]), (mid[i], b[i])]
        pending = nxt
    done.sort(key=lambda p: p[0])
    breaks = [p[0] for p in done] + [done[-1][1]]
    return Chebyshev(breaks, np.array([p[2] for p in done])), worst


def _shift_to_unit(degree):
    r"""The matrix ``S`` with ``a_u = a_t S``: monomial coefficients in :math:`t \in [-1, 1]` to
    those in :math:`u = (t + 1)/2 \in [0, 1]` (:math:`t^k = (2u - 1)^k`, binomially)."""
    out = np.zeros((degree + 1, degree + 1))
    for k in range(degree + 1):
        for m in range(k + 1):
            out[k, m] = math.comb(k, m) * 2.0**m * (-1.0) ** (k - m)
    return out


class UniformPolynomial:
    r"""A piecewise polynomial of low degree :math:`D` on :math:`P` equal panels of ``[lo, hi]``,
    in the monomial basis of each panel's own coordinate :math:`u \in [0, 1)`: the array path of
    a table where a low degree meets the tolerance (:func:`fit_uniform`).

    Next to :class:`Chebyshev` (degree 10 on bisected panels) it costs per point a multiply-add
    and a truncation for the panel (no bucket gathers) and :math:`D + 1` gathers and :math:`2D`
    passes for Horner's rule: about half, at :math:`D = 6`. Its panel coordinate carries an
    absolute rounding of about :math:`\epsilon P`: ``x`` is in effect rounded to
    :math:`\epsilon\,(hi - lo)` (where the Chebyshev form rounds it to :math:`\epsilon|x|`); the
    check of :func:`fit_uniform` measures the values as evaluated, rounding included. It has no
    scalar path: the scalar path keeps the :class:`Chebyshev` it was fitted to.
    """

    def __init__(self, lo, hi, coef):
        self.lo, self.hi = float(lo), float(hi)
        self.coef = np.asarray(coef, dtype=float)          # (P, D + 1), ascending powers of u
        self.panels, self.degree = self.coef.shape[0], self.coef.shape[1] - 1
        # b = (x - lo) P / (hi - lo), shrunk by 2^-40 so that x = hi, with the rounding of the
        # multiply-add, stays inside the last panel (the panels are fitted on this same map)
        self._scale = self.panels / (self.hi - self.lo) * (1.0 - 2.0**-40)
        self._offset = -self.lo * self._scale
        self._coefT = np.ascontiguousarray(self.coef.T)

    def panel_nodes(self, u):
        """``x`` at the panel coordinates ``u`` (shape ``(m,)``) of every panel: shape ``(P, m)``."""
        return (np.arange(self.panels)[:, None] + np.asarray(u)[None, :] - self._offset) / self._scale

    def __call__(self, x, out=None):
        """Values at ``x`` (an array inside ``[lo, hi]``); ``out`` as in :meth:`Chebyshev.__call__`."""
        x = np.asarray(x, dtype=float)
        if x.ndim != 1:
            return self(x.ravel()).reshape(x.shape)
        u = np.multiply(x, self._scale)
        u += self._offset
        j = u.astype(np.intp)          # truncation = floor: u >= 0 up to a rounding (then j = 0)
        u -= j                         # the panel coordinate, in [0, 1)
        coef = self._coefT
        value = coef[self.degree].take(j, out=out, mode="clip")
        ak = np.empty_like(u)
        for k in range(self.degree - 1, -1, -1):        # b = b u + a_k
            value *= u
            coef[k].take(j, out=ak, mode="clip")
            value += ak
        return value


#: (degree, panels) tried in turn by :func:`fit_uniform`, cheapest first
_UNIFORM_RULES = ((5, 2048), (6, 1024), (6, 2048), (8, 2048))
#: panel coordinates of the check points (the ends, for continuity, and two between nodes)
_UNIFORM_CHECK = np.array([0.0, 0.2887, 0.6931, 1.0])


def fit_uniform(f, lo, hi, *, tol=2e-15, rules=_UNIFORM_RULES):
    """``(UniformPolynomial, error)``: ``f`` (vectorized) interpolated at the Chebyshev nodes of
    equal panels, for the first ``(degree, panels)`` of ``rules`` whose error at check points
    (the panel ends and two points between nodes, per panel) is within ``tol`` relative to
    ``max(1, |f|)``; ``(None, inf)`` if none is. The check is of the polynomial as it is
    evaluated, after the change of basis."""
    for degree, panels in rules:
        nodes = 0.5 * (1.0 + np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))[::-1])   # in (0, 1)
        probe = UniformPolynomial(lo, hi, np.zeros((panels, degree + 1)))
        values = np.asarray(f(probe.panel_nodes(nodes).ravel()), dtype=float).reshape(panels, degree + 1)
        t = 2.0 * nodes - 1.0
        cheb = np.linalg.solve(np.polynomial.chebyshev.chebvander(t, degree), values.T).T
        fitted = UniformPolynomial(lo, hi, cheb @ _cheb_to_mono(degree) @ _shift_to_unit(degree))
        x_check = np.clip(fitted.panel_nodes(_UNIFORM_CHECK).ravel(), lo, hi)
        want = np.asarray(f(x_check), dtype=float)
        miss = float(np.max(np.abs(fitted(x_check) - want) / np.maximum(1.0, np.abs(want))))
        if miss <= tol:
            return fitted, miss
    return None, math.inf


class SeparatedTable:
    r"""The tables of one (wall shape, t/a, n) key; see the module docstring.

    ``forward(y)`` is :math:`\ln\hat J(e^y)`, ``inverse(x)`` its inverse (``inverse_fast``: the
    same, of low degree on equal panels, for arrays, where it was accepted; ``scalar_pair(x)``: the
    inverse and the log pressure of a target together, for one float), ``pressure(y)`` the log of
    the pressure per unit modulus (None where the wall's pressure is cheap to evaluate directly).
    ``x_lo .. x_hi`` is the range of targets served; ``j_inf`` is :math:`\hat J(\infty)` (or ``inf``);
    ``error`` the a-posteriori estimate of the error of :math:`\ln v` (and of the log pressure).
    """

    def __init__(self, forward, inverse, pressure, *, x_lo, x_hi, y_lo, y_hi, j_inf, error, k, wall_type,
                 tabulate_pressure, pressure_inverse=None, inverse_fast=None, scalar_pair=None):
        self.forward, self.inverse, self.pressure = forward, inverse, pressure
        self.inverse_fast, self.scalar_pair = inverse_fast, scalar_pair
        self.pressure_inverse = pressure_inverse
        self.x_lo, self.x_hi, self.y_lo, self.y_hi = x_lo, x_hi, y_lo, y_hi
        self.j_inf, self.error, self.k, self.wall_type = j_inf, error, k, wall_type
        self.tabulate_pressure = tabulate_pressure
        self.log_stretch_max = None        # ln of the wall's maximum stretch, set by the scalar path

    def for_scene(self, scene):
        """The table bound to a scene of its key: the target normalization and the pressure (None
        where the normalization a^k P_scale leaves the normal doubles: a power law of a large index)."""
        bound = _Bound(self, scene)
        return bound if 2.2250738585072014e-308 <= bound.norm < math.inf else None


class _Bound:
    __slots__ = ("table", "norm", "scale", "wall", "tb", "x_lo", "x_hi", "inverse")

    def __init__(self, table, scene):
        self.table = table
        self.wall, self.tb = scene.wall, scene.tb
        self.scale = float(scene.wall._pressure_scale())
        self.norm = float(scene.tube.radius) ** table.k * self.scale
        # the array path: the low-degree uniform inverse where it was accepted
        self.x_lo, self.x_hi = table.x_lo, table.x_hi
        self.inverse = table.inverse if table.inverse_fast is None else table.inverse_fast

    def rise(self, y, v, strain=None):
        """The pressure rise (Pa) at ``y = ln v`` (arrays; ``strain``: :math:`e^v - 1` if the caller has it)."""
        if self.table.tabulate_pressure:
            out = self.table.pressure(y)
            np.exp(out, out=out)
            out *= self.scale
            return out
        return self.wall._pressure_at_log_stretch(v, np.expm1(v) if strain is None else strain, self.tb)
