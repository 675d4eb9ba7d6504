r"""Yeoh walls: :math:`W = c_1(I_1 - 3) + c_2(I_1 - 3)^2 + c_3(I_1 - 3)^3`.

In plane strain, with :math:`y = I_1 - 3 = (\lambda - 1/\lambda)^2`,
:math:`\hat W'(\lambda) = 2(c_1 + 2c_2 y + 3c_3 y^2)(\lambda - \lambda^{-3})`; the small-strain
shear modulus is :math:`2c_1`. With :math:`c_2, c_3 \ge 0` the tube law increases without bound
(or saturates, when :math:`c_2 = c_3 = 0`: neo-Hookean). A negative :math:`c_2` (common in
fits to rubber) can make it rise to a peak first: the peak is then the wall's maximum stretch
and limit pressure (see :mod:`tubefsi_hyperelastic._limit_point`).

The material gives only :math:`W_1 = c_1 + 2c_2 y + 3c_3 y^2` and :math:`W_{11}` (the invariant
hooks of :class:`~tubefsi.walls.HyperelasticWall`), which serve every axial stretch
:math:`\lambda_z`: installed at :math:`\lambda_z`, :math:`y = (\lambda - 1/\lambda)^2/\lambda_z + c`,
:math:`c = (\lambda_z-1)^2(\lambda_z+2)/\lambda_z` (``docs/walls_beyond.md``, section "Axial
pre-stretch"); the installed tube's small-strain modulus :math:`2W_1(c)/\lambda_z` must be
positive (``InvalidParameterError`` otherwise).
"""

from __future__ import annotations

import math

import attrs
import numpy as np
from tubefsi import InvalidParameterError
from tubefsi.fields import nonnegative, positive, real
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall
from tubefsi.walls.hyperelastic import _times, axial_stretch

from ._limit_point import LimitPoint

__all__ = ["Yeoh", "ThinYeoh", "ThickYeoh"]


@attrs.frozen(kw_only=True)
class Yeoh(LimitPoint, HyperelasticWall):
    """Yeoh material (abstract: pick a theory, :class:`ThinYeoh` or :class:`ThickYeoh`)."""

    c1: float = positive(unit="Pa", doc="c1 = half the small-strain shear modulus")
    c2: float = real(unit="Pa", doc="c2 (may be negative)")
    c3: float = nonnegative(unit="Pa", doc="c3 >= 0")
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        with np.errstate(over="ignore", invalid="ignore"):
            rest = self._W1(self._installed_invariants(1.0)[0], None)
        if not np.all((rest > 0) & np.isfinite(rest)):
            raise InvalidParameterError("axial_stretch", "values where c1 + 2 c2 y + 3 c3 y^2 is positive and finite "
                                        "at rest, y = (lz - 1)^2 (lz + 2)/lz", self.axial_stretch,
                                        "the installed tube's small-strain modulus must be positive and finite")

    def _pressure_scale(self):                  # P is linear in (c1, c2, c3): c1 * P_hat(c2/c1, c3/c1, lz)
        return self.c1

    def _shape_key(self):
        return (self.c2 / self.c1, self.c3 / self.c1, self.axial_stretch, getattr(self, "thickness_convention", "thick"))

    def _unit_wall(self):               # from the shape alone: equal shapes give the same unit wall
        c2, c3, _, _ = self._shape_key()
        return attrs.evolve(self, c1=1.0, c2=c2, c3=c3)

    # a term whose coefficient is 0 contributes nothing at any y (_times: not 0 * inf = NaN where y
    # leaves the doubles, at a stretch of 1e300)
    def _W1(self, i1, i2):       # dW/dI1 at y = I1 - 3
        return self.c1 + _times(2.0 * self.c2, i1) + _times(3.0 * self.c3, i1 * i1)

    def _W_second(self, i1, i2):
        return 2.0 * self.c2 + _times(6.0 * self.c3, i1), 0.0, 0.0

    def _max_stretch(self, tb):
        return math.inf if self.c2 >= 0 else super()._max_stretch(tb)   # c2, c3 >= 0: increasing

    def _limit_pressure(self, tb):
        return self._asymptote(tb, self._theory()) if self.c2 >= 0 else super()._limit_pressure(tb)

    def _asymptote(self, tb, theory):
        if self.c2 != 0 or self.c3 != 0 or theory == "reference":
            return math.inf
        return 2.0 * self.c1 / self.axial_stretch * (tb if theory == "current" else np.log1p(tb))

    def _asymptotic_decay(self, tb, theory):
        return 5.0


@attrs.frozen(kw_only=True)
class ThinYeoh(ThinWall, Yeoh):
    r"""Thin-walled Yeoh tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"c1": 1e3, "c2": 50.0, "c3": 2.0},
                 {"c1": 1e3, "c2": -120.0, "c3": 8.0, "thickness_convention": "current"},
                 {"c1": 1e3, "c2": 0.0, "c3": 0.0, "thickness_convention": "current"},
                 {"c1": 1e3, "c2": 50.0, "c3": 2.0, "axial_stretch": 1.25})


@attrs.frozen(kw_only=True)
class ThickYeoh(ThickWall, Yeoh):
    """Thick-walled Yeoh tube (exact plane-strain Lamé solution)."""

    _examples = ({"c1": 1e3, "c2": 50.0, "c3": 2.0}, {"c1": 1e3, "c2": -120.0, "c3": 8.0})
