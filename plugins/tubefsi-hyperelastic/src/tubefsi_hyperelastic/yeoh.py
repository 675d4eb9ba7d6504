r"""Yeoh walls: :math:`W = c_1(I_1 - 3) + c_2(I_1 - 3)^2 + c_3(I_1 - 3)^3`.

In plane strain, with :math:`y = I_1 - 3 = (\lambda - 1/\lambda)^2`,
:math:`\hat W'(\lambda) = 2(c_1 + 2c_2 y + 3c_3 y^2)(\lambda - \lambda^{-3})`; the small-strain
shear modulus is :math:`2c_1`. With :math:`c_2, c_3 \ge 0` the tube law increases without bound
(or saturates, when :math:`c_2 = c_3 = 0`: neo-Hookean). A negative :math:`c_2` (common in
fits to rubber) can make it rise to a peak first: the peak is then the wall's maximum stretch
and limit pressure (see :mod:`tubefsi_hyperelastic._limit_point`).
"""

from __future__ import annotations

import math

import attrs
import numpy as np
from tubefsi.fields import nonnegative, positive, real
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall

from ._forms import hoop, quartic
from ._limit_point import LimitPoint

__all__ = ["Yeoh", "ThinYeoh", "ThickYeoh"]


@attrs.frozen(kw_only=True)
class Yeoh(LimitPoint, HyperelasticWall):
    """Yeoh material (abstract: pick a theory, :class:`ThinYeoh` or :class:`ThickYeoh`)."""

    c1: float = positive(unit="Pa", doc="c1 = half the small-strain shear modulus")
    c2: float = real(unit="Pa", doc="c2 (may be negative)")
    c3: float = nonnegative(unit="Pa", doc="c3 >= 0")

    def _pressure_scale(self):                  # P is linear in (c1, c2, c3): c1 * P_hat(c2/c1, c3/c1)
        return self.c1

    def _shape_key(self):
        return (self.c2 / self.c1, self.c3 / self.c1, getattr(self, "thickness_convention", "thick"))

    def _f(self, y):  # dW/d lam = f(y) (lam - lam^-3), f = 2 dW/dI1
        return 2.0 * (self.c1 + y * (2.0 * self.c2 + 3.0 * self.c3 * y))

    def _df(self, y):
        return 4.0 * self.c2 + 12.0 * self.c3 * y

    def _dW(self, s):
        return self._f(hoop(s) ** 2) * quartic(s)

    def _d2W(self, s):
        g = quartic(s)
        return self._f(hoop(s) ** 2) * (1.0 + 3.0 * s**-4) + 2.0 * self._df(hoop(s) ** 2) * g * g

    def _thick_integrand(self, s):
        return self._f(hoop(s) ** 2) * (s * s + 1.0) / s**3

    def _max_stretch(self, tb):
        return math.inf if self.c2 >= 0 else super()._max_stretch(tb)   # c2, c3 >= 0: increasing

    def _limit_pressure(self, tb):
        return self._asymptote(tb, self._theory()) if self.c2 >= 0 else super()._limit_pressure(tb)

    def _asymptote(self, tb, theory):
        if self.c2 != 0 or self.c3 != 0 or theory == "reference":
            return math.inf
        return 2.0 * self.c1 * (tb if theory == "current" else np.log1p(tb))

    def _asymptotic_decay(self, tb, theory):
        return 5.0


@attrs.frozen(kw_only=True)
class ThinYeoh(ThinWall, Yeoh):
    r"""Thin-walled Yeoh tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"c1": 1e3, "c2": 50.0, "c3": 2.0},
                 {"c1": 1e3, "c2": -120.0, "c3": 8.0, "thickness_convention": "current"},
                 {"c1": 1e3, "c2": 0.0, "c3": 0.0, "thickness_convention": "current"})

    def _stiffness(self, stretch, tb):
        if self.thickness_convention == "reference":
            return tb * self._d2W(stretch)
        # d/dlam (dW/lam) = [4 f s^-4 + 2 f'(y) (s - s^-3)^2] / s: no cancellation at large stretch
        s = stretch
        y, g = hoop(s) ** 2, quartic(s)
        return tb * (4.0 * self._f(y) * s**-4 + 2.0 * self._df(y) * g * g) / s


@attrs.frozen(kw_only=True)
class ThickYeoh(ThickWall, Yeoh):
    """Thick-walled Yeoh tube (exact plane-strain Lamé solution)."""

    _examples = ({"c1": 1e3, "c2": 50.0, "c3": 2.0}, {"c1": 1e3, "c2": -120.0, "c3": 8.0})
