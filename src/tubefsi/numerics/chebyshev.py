r"""Piecewise polynomial interpolants with a-posteriori error control: the one table stack.

:func:`fit_piecewise` interpolates a vectorized function (one or several outputs) by polynomials
of a fixed degree at the Chebyshev points of each panel, bisecting a panel until, for every
output, its Chebyshev tail and its misfit at four check points between the nodes are within the
tolerance. The misfit is measured on the polynomial *as it is evaluated* (the monomial form of
:class:`PiecewisePolynomial`), so the rounding of that form is part of the check.

:class:`PiecewisePolynomial` evaluates every output of a panel set at once: a panel lookup (equal
buckets as narrow as the narrowest panel hold at most two panels each, so a lookup is one multiply
and two gathers; a bucket that would hold more falls back to a binary search), then Horner's rule
in the panel's own coordinate :math:`t \in [-1, 1]` with the coefficients gathered one degree at a
time. :meth:`PiecewisePolynomial.scalar` does the same operations on one Python float, for a single
point, without NumPy.

It serves the separated-variables tables (:mod:`tubefsi.couplers.tables`) and the per-call curve
interpolants of the engine; immutable once built (its arrays are read-only), so threads share it.
"""

from __future__ import annotations

import bisect
import functools
import math

import numpy as np

__all__ = ["PiecewisePolynomial", "fit_piecewise", "chebyshev_nodes"]

#: Check points (in a panel's coordinate t) between the nodes of every degree used here.
_CHECK = np.array([-0.97, -0.55, 0.11, 0.71])
#: At most this many lookup buckets (beyond, the crowded ones use a binary search).
_MAX_BUCKETS = 1 << 16


def _read_only(array):
    array = np.ascontiguousarray(array)
    array.setflags(write=False)
    return array


def chebyshev_nodes(degree: int) -> np.ndarray:
    """The ``degree + 1`` Chebyshev points of the first kind on [-1, 1], ascending."""
    return np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))[::-1].copy()


@functools.lru_cache(maxsize=16)
def _fit_matrix(degree):
    """Values at :func:`chebyshev_nodes` -> Chebyshev coefficients (rows: coefficients); a constant
    per degree, computed once."""
    return _read_only(np.linalg.inv(np.polynomial.chebyshev.chebvander(chebyshev_nodes(degree), degree)))


@functools.lru_cache(maxsize=16)
def _to_monomial(degree):
    """Row k: the monomial coefficients of T_k; a constant per degree, computed once."""
    return _read_only(np.array([np.pad(np.polynomial.chebyshev.cheb2poly(np.eye(degree + 1)[k]), (0, degree - k))
                                for k in range(degree + 1)]))


class PiecewisePolynomial:
    r"""Polynomials of one degree on the panels ``breaks[j] .. breaks[j+1]``, for several outputs.

    ``coef`` has shape ``(outputs, panels, degree + 1)``: each panel's Chebyshev coefficients in
    its coordinate :math:`t = (2x - b_j - b_{j+1})/(b_{j+1} - b_j)`. Evaluation is Horner's rule on
    the equivalent monomial coefficients in :math:`t` (the fit checks that form's accuracy).
    """

    def __init__(self, breaks, coef, *, monomial=None):
        breaks = np.asarray(breaks, dtype=float)
        coef = np.asarray(coef, dtype=float)
        if coef.ndim == 2:
            coef = coef[None]
        self.outputs, panels, size = coef.shape
        self.degree = size - 1
        if breaks.shape != (panels + 1,) or not np.all(np.diff(breaks) > 0):
            raise ValueError("breaks must increase and number one more than the panels")
        self.breaks = _read_only(breaks)
        self.chebyshev = _read_only(coef)
        self.lo, self.hi = float(breaks[0]), float(breaks[-1])
        width = np.diff(breaks)
        self._scale = _read_only(2.0 / width)                             # t = x scale + offset
        self._offset = _read_only(-(breaks[:-1] + breaks[1:]) / width)
        # (outputs, panels, degree + 1); given by join(), which keeps its pieces' to the bit
        mono = coef @ _to_monomial(self.degree) if monomial is None else np.asarray(monomial, dtype=float)
        self._mono = _read_only(np.moveaxis(mono, 2, 1))                  # (outputs, degree + 1, panels)
        # the lookup: buckets as narrow as the narrowest panel (so that a bucket holds at most two)
        count = int(min(_MAX_BUCKETS, max(1, math.ceil((self.hi - self.lo) / width.min() - 1e-9))))
        self._bucket_scale = count / (self.hi - self.lo)
        edges = self.lo + np.arange(count + 1) / self._bucket_scale
        first = np.clip(np.searchsorted(breaks, edges[:-1], side="right") - 1, 0, panels - 1)
        last = np.clip(np.searchsorted(breaks, edges[1:], side="left") - 1, 0, panels - 1)
        self._first = _read_only(first.astype(np.intp))
        self._next_break = _read_only(breaks[np.minimum(first + 1, panels)])
        self._crowded = _read_only(last > first + 1)
        self._any_crowded = bool(self._crowded.any())
        self._buckets = count
        self._last_panel = panels - 1
        # the scalar path's plain lists
        self._first_list, self._next_list = self._first.tolist(), self._next_break.tolist()
        self._crowded_list, self._breaks_list = self._crowded.tolist(), self.breaks.tolist()
        self._scale_list, self._offset_list = self._scale.tolist(), self._offset.tolist()
        self._panel_coefficients = [[tuple(mono[o, j, ::-1].tolist()) for o in range(self.outputs)]
                                    for j in range(panels)]               # per panel: per output a_D..a_0

    @classmethod
    def join(cls, pieces) -> PiecewisePolynomial:
        """One piecewise polynomial of ``pieces`` that follow each other (each one's ``hi`` the next
        one's ``lo``), with their coefficients: the same values, to the bit, with one lookup."""
        breaks = np.concatenate([pieces[0].breaks[:1]] + [piece.breaks[1:] for piece in pieces])
        coef = np.concatenate([piece.chebyshev for piece in pieces], axis=1)
        mono = np.concatenate([np.moveaxis(piece._mono, 1, 2) for piece in pieces], axis=1)
        return cls(breaks, coef, monomial=mono)

    @property
    def panels(self) -> int:
        return self.breaks.size - 1

    def panel(self, x):
        """The panel of each ``x`` (a 1-D array within ``[lo, hi]``; clipped to the panels)."""
        b = np.subtract(x, self.lo)
        b *= self._bucket_scale
        np.minimum(b, self._buckets - 1, out=b)
        np.maximum(b, 0.0, out=b)
        b = b.astype(np.intp)
        j = self._first.take(b, mode="clip")
        j += x >= self._next_break.take(b, mode="clip")
        if self._any_crowded:
            crowded = np.flatnonzero(self._crowded.take(b, mode="clip"))
            if crowded.size:
                j[crowded] = np.searchsorted(self.breaks, x[crowded], side="right") - 1
        np.clip(j, 0, self.panels - 1, out=j)
        return j

    def __call__(self, x, output: int = 0):
        """The values of ``output`` at ``x`` (an array within ``[lo, hi]``), of ``x``'s shape."""
        x = np.asarray(x, dtype=float)
        flat = x.ravel()
        return self._horner(flat, self.panel(flat), output).reshape(x.shape)

    def evaluate(self, x):
        """Every output at ``x`` (a 1-D array within ``[lo, hi]``): shape ``(outputs, x.size)``,
        with one panel lookup."""
        x = np.asarray(x, dtype=float)
        j = self.panel(x)
        return np.stack([self._horner(x, j, o) for o in range(self.outputs)])

    def _horner(self, x, j, output):
        t = self._scale.take(j, mode="clip")
        t *= x
        t += self._offset.take(j, mode="clip")
        mono = self._mono[output]
        value = mono[self.degree].take(j, mode="clip")
        term = np.empty_like(value)
        for k in range(self.degree - 1, -1, -1):               # value = value t + a_k
            value *= t
            mono[k].take(j, out=term, mode="clip")
            value += term
        return value

    def scalar(self, x: float) -> list:
        """Every output at one float ``x`` within ``[lo, hi]``, in plain Python: the operations of
        :meth:`evaluate` in the same order."""
        b = int((x - self.lo) * self._bucket_scale)        # (truncation: -1 < b < 0 gives 0)
        if not 0 <= b < self._buckets:
            b = 0 if b < 0 else self._buckets - 1
        j = self._first_list[b]
        if x >= self._next_list[b]:
            j += 1
        if self._any_crowded and self._crowded_list[b]:
            j = bisect.bisect_right(self._breaks_list, x) - 1
        j = 0 if j < 0 else (self._last_panel if j > self._last_panel else j)
        t = x * self._scale_list[j] + self._offset_list[j]
        if self.degree == 8:                     # the tables' degree: the loop below, written out
            return [((((((((a8 * t + a7) * t + a6) * t + a5) * t + a4) * t + a3) * t + a2) * t + a1) * t + a0)
                    for a8, a7, a6, a5, a4, a3, a2, a1, a0 in self._panel_coefficients[j]]
        out = []
        for coefficients in self._panel_coefficients[j]:
            value = coefficients[0]
            for a in coefficients[1:]:
                value = value * t + a
            out.append(value)
        return out

    def derivative(self, output: int = 0) -> PiecewisePolynomial:
        """The derivative of ``output`` (on the same panels, one degree lower)."""
        scale = 2.0 / np.diff(self.breaks)
        d = np.polynomial.chebyshev.chebder(self.chebyshev[output].T, axis=0).T * scale[:, None]
        return PiecewisePolynomial(self.breaks, d)


def _panel_coordinates(lo, hi, t):
    """``x`` at the panel coordinates ``t`` of the panels ``lo .. hi``: shape (panels, t.size)."""
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    return mid[:, None] + half[:, None] * t


def fit_piecewise(f, lo, hi, *, degree=8, tol=1e-14, panels=4, max_panels=4096, relative=False):
    r"""``(PiecewisePolynomial, error)``: ``f`` interpolated on ``[lo, hi]``, or ``(None, inf)``.

    ``f(x)`` takes a 1-D array and returns values of its shape, or an array ``(outputs, x.size)``
    for several outputs. Panels (starting from ``panels`` equal ones) are bisected until each
    output's last two Chebyshev coefficients and its misfit at four check points (between the
    nodes, evaluated by the monomial form of the result) are within ``tol`` — absolute, or with
    ``relative`` relative to ``max(1, |f|)`` on the panel. ``error`` is the largest check-point
    misfit of the accepted panels. More than ``max_panels`` panels, or a non-finite value, fails.
    """
    nodes = chebyshev_nodes(degree)
    fit = _fit_matrix(degree).T                       # values @ fit -> coefficients
    edges = np.linspace(lo, hi, panels + 1)
    pending_lo, pending_hi = edges[:-1], edges[1:]
    done = []
    worst = 0.0
    while pending_lo.size:
        if len(done) + pending_lo.size > max_panels:
            return None, math.inf
        x = np.concatenate([_panel_coordinates(pending_lo, pending_hi, nodes),
                            _panel_coordinates(pending_lo, pending_hi, _CHECK)], axis=1)
        with np.errstate(all="ignore"):
            values = np.asarray(f(x.ravel()), dtype=float)
        values = values.reshape((-1,) + x.shape)          # (outputs, panels, nodes + checks)
        if not np.all(np.isfinite(values)):
            return None, math.inf
        at_nodes, at_checks = values[..., :degree + 1], values[..., degree + 1:]
        coef = at_nodes @ fit                             # (outputs, panels, degree + 1)
        mono = coef @ _to_monomial(degree)
        predicted = mono[..., degree, None] + 0.0 * _CHECK   # Horner's rule, as evaluated, at the checks
        for k in range(degree - 1, -1, -1):
            predicted = predicted * _CHECK + mono[..., k, None]
        miss = np.abs(predicted - at_checks).max(axis=2)
        tail = np.abs(coef[..., -2:]).max(axis=2)
        scale = np.maximum(1.0, np.abs(at_nodes).max(axis=2)) if relative else 1.0
        ok = np.all((miss <= tol * scale) & (tail <= tol * scale), axis=0)
        for i in np.flatnonzero(ok):
            done.append((pending_lo[i], pending_hi[i], coef[:, i]))
            worst = max(worst, float(np.max(miss[:, i] / (scale if np.ndim(scale) == 0 else scale[:, i]))))
        bad = ~ok
        mid = 0.5 * (pending_lo[bad] + pending_hi[bad])
        pending_lo, pending_hi = np.concatenate([pending_lo[bad], mid]), np.concatenate([mid, pending_hi[bad]])
    done.sort(key=lambda item: item[0])
    breaks = np.array([item[0] for item in done] + [done[-1][1]])
    coef = np.stack([item[2] for item in done], axis=1)
    return PiecewisePolynomial(breaks, coef), worst
