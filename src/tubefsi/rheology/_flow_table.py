r"""A fast, accurate tube-flow function for any rheology (the non-separable path).

In a tube the flow depends on the wall stress :math:`\tau_w = GR/2` only through the
apparent wall shear rate

.. math::

    \Gamma(\tau_w) = \frac{4q}{\pi R^3} = \frac{4}{\tau_w^3}\int_0^{\tau_w}\tau^2\dot\gamma(\tau)\,d\tau ,

so :math:`G(q, R) = 2\,\tau_w(\Gamma = 4q/\pi R^3)/R`. One monotone function of one
variable serves every radius and flow rate. :class:`FlowTable` samples
:math:`\ln\Gamma` as a function of :math:`s = \ln(\tau_w - \tau_y)` (``tau_y`` the
yield stress, 0 for most fluids) on unit panels with degree-20 Chebyshev
interpolants, extended on demand, and inverts it by Newton's method on the
interpolant: after a one-off set-up of a few thousand flow-function evaluations,
:math:`G(q, R)` costs a handful of polynomial evaluations per point.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

__all__ = ["FlowTable", "flow_table", "tanh_sinh"]

_DEGREE = 20
_CHEB = np.cos(np.pi * (np.arange(_DEGREE + 1) + 0.5) / (_DEGREE + 1))  # Chebyshev points on [-1, 1]


def tanh_sinh(levels: int = 6):
    """Fixed tanh-sinh (double-exponential) nodes/weights on [0, 1]: exact to ~1e-15 even
    with algebraic endpoint singularities such as t**(1/n)."""
    h = 2.0**-levels * 8
    k = np.arange(-int(3.2 / h) - 1, int(3.2 / h) + 2)
    x = 0.5 * np.pi * np.sinh(k * h)
    t = 0.5 * (1.0 + np.tanh(x))
    w = h * 0.5 * np.pi * np.cosh(k * h) / (2.0 * np.cosh(x) ** 2)
    keep = (t > 0) & (t < 1) & (w > 1e-300)
    return t[keep], w[keep]


_T, _W = tanh_sinh(6)


class FlowTable:
    """Piecewise-Chebyshev :math:`\\ln\\Gamma(s)` and its inverse for one rheology."""

    def __init__(self, rheology):
        self.rheology = rheology
        self.yield_stress = float(getattr(rheology, "yield_stress", 0.0))
        self.panels: dict[int, np.ndarray] = {}   # panel index -> Chebyshev coefficients

    # ------------------------------------------------------------ exact flow function
    def apparent_shear_rate(self, wall_stress):
        r""":math:`\Gamma(\tau_w)` by the rheology's hook (a closed form, or quadrature)."""
        return self.rheology._apparent_shear_rate(np.asarray(wall_stress, dtype=float))

    # ------------------------------------------------------------ table
    def _panel(self, j: int) -> np.ndarray:
        coef = self.panels.get(j)
        if coef is None:
            s = j + 0.5 * (_CHEB + 1.0)
            y = np.log(self.apparent_shear_rate(self.yield_stress + np.exp(s)))
            coef = np.polynomial.chebyshev.chebfit(_CHEB, y, _DEGREE)
            self.panels[j] = coef
        return coef

    def _ensure(self, j_lo: int, j_hi: int):
        for j in range(j_lo, j_hi + 1):
            self._panel(j)

    def log_rate(self, s):
        """Interpolated :math:`\\ln\\Gamma` and its derivative at ``s`` (arrays)."""
        s = np.asarray(s, dtype=float)
        j = np.floor(s).astype(int)
        self._ensure(int(j.min()), int(j.max()))
        y = np.empty_like(s)
        dy = np.empty_like(s)
        for jj in np.unique(j):
            m = j == jj
            x = 2.0 * (s[m] - jj) - 1.0
            c = self.panels[int(jj)]
            y[m] = np.polynomial.chebyshev.chebval(x, c)
            dy[m] = 2.0 * np.polynomial.chebyshev.chebval(x, np.polynomial.chebyshev.chebder(c))
        return y, dy

    def wall_stress(self, apparent_rate):
        r""":math:`\tau_w` with :math:`\Gamma(\tau_w) =` ``apparent_rate`` (> 0), by Newton on the table."""
        target = np.log(np.asarray(apparent_rate, dtype=float))
        # start from a coarse lookup on the panel ends, widening the table as needed
        lo, hi = self._bracket(float(target.min()), float(target.max()))
        grid = np.arange(lo, hi + 1, dtype=float)
        ends = np.array([self.log_rate(np.array([g]))[0][0] for g in grid])
        s = np.interp(target, ends, grid)
        for _ in range(60):
            y, dy = self.log_rate(s)
            step = (y - target) / dy
            s_new = np.clip(s - step, lo, hi + 1 - 1e-12)
            if np.all(np.abs(s_new - s) <= 1e-15 * np.maximum(1.0, np.abs(s))):
                s = s_new
                break
            s = s_new
        return self.yield_stress + np.exp(s)

    def _bracket(self, y_min: float, y_max: float):
        lo, hi = -2, 2
        while self.log_rate(np.array([float(lo)]))[0][0] > y_min:
            lo -= 4
            if lo < -690:
                raise ArithmeticError("the flow function does not reach so small a shear rate")
        while self.log_rate(np.array([float(hi) + 1 - 1e-9]))[0][0] < y_max:
            hi += 4
            if hi > 690:
                raise ArithmeticError("the flow function does not reach so large a shear rate")
        return lo, hi


_TABLES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def flow_table(rheology) -> FlowTable:
    """The cached :class:`FlowTable` of ``rheology``."""
    try:
        return _TABLES[rheology]
    except KeyError:
        table = _TABLES[rheology] = FlowTable(rheology)
        return table
    except TypeError:  # not weak-referenceable: no cache
        return FlowTable(rheology)
