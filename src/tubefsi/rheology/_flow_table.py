r"""A fast, accurate tube-flow function for any rheology (the non-separable path).

In a tube the flow depends on the wall stress :math:`\tau_w = GR/2` only through the
apparent wall shear rate

.. math::

    \Gamma(\tau_w) = \frac{4q}{\pi R^3} = \frac{4}{\tau_w^3}\int_0^{\tau_w}\tau^2\dot\gamma(\tau)\,d\tau ,

so :math:`G(q, R) = 2\,\tau_w(\Gamma = 4q/\pi R^3)/R`. One monotone function of one
variable serves every radius and flow rate. :class:`FlowTable` samples
:math:`\ln\Gamma` as a function of :math:`s = \ln(\tau_w - \tau_y)` (``tau_y`` the
yield stress, 0 for most fluids) on unit panels with degree-28 Chebyshev
interpolants, extended on demand, and inverts it by Newton's method on the
interpolant: after a one-off set-up of a few thousand flow-function evaluations,
:math:`G(q, R)` costs a handful of polynomial evaluations per point.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

__all__ = ["FlowTable", "flow_table", "tanh_sinh"]

_DEGREE = 28
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


def graded_rule(panels: int = 30, order: int = 12, levels: int = 6):
    """Nodes/weights on [0, 1] graded geometrically toward 0: Gauss–Legendre on the panels
    [2^-(k+1), 2^-k] (k < ``panels``) and the tanh-sinh rule on [0, 2^-panels].

    A constitutive law with a transition at a small fraction of the interval (a Carreau fluid
    whose wall shear rate is far above 1/lambda has complex singularities close to t = 0) is
    integrated to ~1e-16: every panel is half as wide as its distance to 0, so a singularity
    near 0 is at least three half-widths from it; the innermost panel carries the algebraic
    endpoint behaviour (t**(1/n), the yield point) and a negligible share of the integral.
    """
    x, w = np.polynomial.legendre.leggauss(order)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    lo = 2.0 ** -np.arange(1, panels + 1, dtype=float)           # panel k: [lo_k, 2 lo_k]
    t = (lo[:, None] * (1.0 + x[None, :])).ravel()
    wt = (lo[:, None] * w[None, :]).ravel()
    ts, ws = tanh_sinh(levels)
    t = np.concatenate([ts * lo[-1], t])
    wt = np.concatenate([ws * lo[-1], wt])
    order_ = np.argsort(t)
    return t[order_], wt[order_]


_T, _W = graded_rule()


class FlowTable:
    """Piecewise-Chebyshev :math:`\\ln\\Gamma(s)` and its inverse for one rheology."""

    def __init__(self, rheology):
        self.rheology = rheology
        self.yield_stress = float(rheology.yield_stress)
        self.panels: dict[int, np.ndarray] = {}   # panel index -> Chebyshev coefficients
        self._slopes: dict[int, np.ndarray] = {}  # panel index -> coefficients of the derivative

    # ------------------------------------------------------------ exact flow function
    def apparent_shear_rate(self, excess):
        r""":math:`\Gamma` at the wall stress :math:`\tau_y +` ``excess``, by the rheology's hook (a
        closed form, or quadrature), given the excess itself: exact however close to yield."""
        excess = np.asarray(excess, dtype=float)
        if self.yield_stress == 0.0:
            return self.rheology._apparent_shear_rate(excess)
        return self.rheology._apparent_shear_rate(self.yield_stress + excess, excess=excess)

    # ------------------------------------------------------------ table
    def _panel(self, j: int) -> np.ndarray:
        coef = self.panels.get(j)
        if coef is None:
            s = j + 0.5 * (_CHEB + 1.0)
            y = np.log(self.apparent_shear_rate(np.exp(s)))
            coef = np.polynomial.chebyshev.chebfit(_CHEB, y, _DEGREE)
            self.panels[j] = coef
            self._slopes[j] = np.append(2.0 * np.polynomial.chebyshev.chebder(coef), 0.0)  # d/ds
        return coef

    def _ensure(self, j_lo: int, j_hi: int):
        for j in range(j_lo, j_hi + 1):
            self._panel(j)

    def log_rate(self, s):
        """Interpolated :math:`\\ln\\Gamma` and its derivative at ``s`` (arrays)."""
        s = np.asarray(s, dtype=float)
        j = np.floor(s).astype(int)
        self._ensure(int(j.min()), int(j.max()))
        panels, where = np.unique(j.ravel(), return_inverse=True)
        coef = np.stack([self.panels[int(jj)] for jj in panels])[where]      # one row per point
        slope = np.stack([self._slopes[int(jj)] for jj in panels])[where]
        x = 2.0 * (s.ravel() - j.ravel()) - 1.0
        return _clenshaw(x, coef).reshape(s.shape), _clenshaw(x, slope).reshape(s.shape)

    def wall_stress(self, apparent_rate):
        r""":math:`\tau_w` with :math:`\Gamma(\tau_w) =` ``apparent_rate``, by Newton on the table;
        the yield stress (0 for most fluids) where ``apparent_rate`` is 0."""
        rate = np.asarray(apparent_rate, dtype=float)
        if np.any(rate <= 0):
            out = np.full(rate.shape, self.yield_stress)
            if np.any(rate > 0):
                out[rate > 0] = self.wall_stress(rate[rate > 0])
            return out
        target = np.log(rate)
        # start from a coarse lookup on the panel ends, widening the table as needed
        lo, hi = self._bracket(float(target.min()), float(target.max()))
        grid = np.arange(lo, hi + 1, dtype=float)
        ends = self.log_rate(np.minimum(grid, hi + 1 - 1e-12))[0]
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


def _clenshaw(x, coef):
    """Chebyshev series with one row of coefficients per point, vectorized over the points."""
    b1 = np.zeros_like(x)
    b2 = np.zeros_like(x)
    for k in range(coef.shape[1] - 1, 0, -1):
        b1, b2 = 2.0 * x * b1 - b2 + coef[:, k], b1
    return x * b1 - b2 + coef[:, 0]


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
