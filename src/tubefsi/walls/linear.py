r"""Linearly elastic walls (small-strain pressure-vessel theory), with a choice of end condition.

The hoop strain of the inner surface is linear in the pressure, :math:`\lambda = 1 + K p/(E\bar t)`.
The Lamé solution (``docs/walls_beyond.md``, section "End conditions of linear walls") gives,
with :math:`b = (1+\bar t)^2`:

=============  ================================================  =======================  ===============================
``end_condition``  axial state                                   thick :math:`K`          thin limit (:math:`\bar t\to0`)
=============  ================================================  =======================  ===============================
``"closed"``   end caps carry :math:`p\pi a^2` (the default)     :math:`[(1+\nu)b + 1-2\nu]/(2+\bar t)`   :math:`1 - \nu/2`
``"open"``     no axial stress, :math:`\sigma_z = 0`              :math:`[(1+\nu)b + 1-\nu]/(2+\bar t)`    :math:`1`
``"clamped"``  no axial strain (plane strain)                    :math:`(1+\nu)(b + 1-2\nu)/(2+\bar t)`   :math:`1 - \nu^2`
=============  ================================================  =======================  ===============================

At :math:`\nu = 1/2` closed and clamped coincide; an incompressible hyperelastic wall (clamped,
:math:`E = 3\mu`) has these as its small-strain limit.
"""

from __future__ import annotations

import attrs
import numpy as np

from ..numerics.kernels import expm1_ratio, log1p_ratio
from ..fields import choice, positive, real
from .base import WallModel

__all__ = ["ThinLinear", "ThickLinear", "END_CONDITIONS"]

#: The end conditions of a linear wall: end caps, free ends, clamped ends.
END_CONDITIONS = ("closed", "open", "clamped")


class _LinearWall(WallModel):
    __slots__ = ()

    closed_form_integral = True
    #: small-strain theory: a linear wall past a few per cent of strain is the wrong model
    calibrated_strain = 0.05

    def _pressure_scale(self):
        return self.youngs_modulus

    def _shape_key(self):
        return tuple((f.name, getattr(self, f.name)) for f in attrs.fields(type(self)) if f.name != "youngs_modulus")

    def _unit_wall(self):
        return attrs.evolve(self, youngs_modulus=1.0)

    def _compliance(self, tb):
        """:math:`d\\lambda/dp` (1/Pa)."""
        return self._factor(tb) / (self.youngs_modulus * tb)

    def _strain(self, pressure, tb):
        return self._compliance(tb) * np.asarray(pressure, dtype=float)

    def _pressure_at_strain(self, strain, tb):
        return np.asarray(strain, dtype=float) / self._compliance(tb)

    def _stiffness(self, stretch, tb):
        return np.ones_like(np.asarray(stretch, dtype=float)) / self._compliance(tb)

    def _stiffness_decay_exponent(self, tb):
        return 0.0

    def _min_pressure(self, tb):
        r"""Minus the buckling pressure of a long ring, :math:`E t^3/(4(1-\nu^2)R^3)`, with the inner
        radius (thin) or, conservatively, the outer radius (thick) for :math:`R`
        (``docs/walls_beyond.md``, section "Buckling")."""
        nu = self.poisson_ratio
        return -self.youngs_modulus * tb**3 / (4.0 * (1.0 - nu) * (1.0 + nu) * self._ring_radius(tb) ** 3)

    def _min_stretch(self, tb):
        return 1.0 + self._strain(self._min_pressure(tb), tb)

    def _power_law_integral(self, log_ratio, outlet_stretch, exponent, tb):
        k = exponent
        return outlet_stretch ** (k + 1) * expm1_ratio(k + 1, log_ratio) / self._compliance(tb)

    def _power_law_integral_inverse(self, integral, outlet_stretch, exponent, tb):
        k = exponent
        return log1p_ratio(k + 1, integral * self._compliance(tb) / outlet_stretch ** (k + 1))


def _young():
    return positive(unit="Pa", doc="Young's modulus E")


def _poisson():
    return real(low=-1.0, high=0.5, high_open=False, doc="Poisson ratio nu")


def _ends():
    return choice(END_CONDITIONS, default="closed",
                  doc="closed (end caps), open (no axial stress) or clamped (no axial strain)")


@attrs.frozen(kw_only=True)
class ThinLinear(_LinearWall):
    r"""Thin linearly elastic tube, :math:`\lambda = 1 + K p/(E\bar t)` with :math:`K = 1-\nu/2`
    (closed ends), :math:`1` (open) or :math:`1-\nu^2` (clamped)."""

    _examples = ({"youngs_modulus": 6e3, "poisson_ratio": 0.5},
                 {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "end_condition": "clamped"})

    youngs_modulus: float = _young()
    poisson_ratio: float = _poisson()
    end_condition: str = _ends()

    @staticmethod
    def _ring_radius(tb):
        return 1.0

    def _factor(self, tb):
        nu = self.poisson_ratio
        if self.end_condition == "closed":
            return 1.0 - 0.5 * nu
        if self.end_condition == "open":
            return 1.0 + 0.0 * nu
        return (1.0 - nu) * (1.0 + nu)


@attrs.frozen(kw_only=True)
class ThickLinear(_LinearWall):
    r"""Thick linearly elastic tube (Lamé), :math:`\lambda = 1 + K p/(E\bar t)`; closed ends:
    :math:`K = [(1+\bar t)^2(1+\nu) + (1-2\nu)]/(2+\bar t)` (other ends: module docstring)."""

    _examples = ({"youngs_modulus": 6e3, "poisson_ratio": 0.5},
                 {"youngs_modulus": 1e6, "poisson_ratio": -0.2, "end_condition": "open"})

    youngs_modulus: float = _young()
    poisson_ratio: float = _poisson()
    end_condition: str = _ends()

    @staticmethod
    def _ring_radius(tb):
        return 1.0 + tb

    def _factor(self, tb):
        nu = self.poisson_ratio
        b = (1.0 + tb) ** 2
        if self.end_condition == "closed":
            return (b * (1.0 + nu) + (1.0 - 2.0 * nu)) / (2.0 + tb)
        if self.end_condition == "open":
            return (b * (1.0 + nu) + (1.0 - nu)) / (2.0 + tb)
        return (1.0 + nu) * (b + (1.0 - 2.0 * nu)) / (2.0 + tb)
