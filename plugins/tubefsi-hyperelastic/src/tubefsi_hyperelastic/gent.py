r"""Gent walls: a strain-stiffening material with limited chain extensibility.

:math:`W = -\frac{\mu J_m}{2}\ln\left(1 - \frac{I_1 - 3}{J_m}\right)`; in plane strain
:math:`I_1 - 3 = (\lambda - 1/\lambda)^2`, so
:math:`\hat W'(\lambda) = \mu(\lambda - \lambda^{-3}) / (1 - (\lambda - 1/\lambda)^2/J_m)`.
The material locks at :math:`\lambda_{lock} = (\sqrt{J_m} + \sqrt{J_m + 4})/2`: every
pressure has a solution and the stretch stays below :math:`\lambda_{lock}` (no limit pressure,
a maximum stretch instead). :math:`J_m \to \infty` is neo-Hookean.
"""

from __future__ import annotations

import attrs
from tubefsi.fields import positive
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall

from ._forms import hoop, quartic

__all__ = ["Gent", "ThinGent", "ThickGent"]


@attrs.frozen(kw_only=True)
class Gent(HyperelasticWall):
    """Gent material (abstract: pick a theory, :class:`ThinGent` or :class:`ThickGent`)."""

    shear_modulus: float = positive(unit="Pa", doc="small-strain shear modulus mu")
    locking_parameter: float = positive(doc="J_m, the largest I1 - 3")

    def _pressure_scale(self):                  # P = mu * P_hat(J_m): a curve table serves every mu
        return self.shear_modulus

    def _shape_key(self):
        return (self.locking_parameter, getattr(self, "thickness_convention", "thick"))

    def _locking_stretch(self):
        jm = self.locking_parameter
        return 0.5 * (jm**0.5 + (jm + 4.0) ** 0.5)

    def _room(self, s):
        """:math:`1 - (s - 1/s)^2/J_m`, factored so that it keeps its accuracy near the lock."""
        lock, root = self._locking_stretch(), self.locking_parameter**0.5
        return (lock - s) * (1.0 + 1.0 / (s * lock)) * (root + hoop(s)) / self.locking_parameter

    def _dW(self, s):
        return self.shear_modulus * quartic(s) / self._room(s)

    def _d2W(self, s):
        room = self._room(s)
        return self.shear_modulus * ((1.0 + 3.0 * s**-4) / room
                                     + 2.0 * quartic(s) ** 2 / (self.locking_parameter * room * room))

    def _thick_integrand(self, s):
        return self.shear_modulus * (s * s + 1.0) / (s**3 * self._room(s))


@attrs.frozen(kw_only=True)
class ThinGent(ThinWall, Gent):
    r"""Thin-walled Gent tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"shear_modulus": 2e3, "locking_parameter": 10.0},
                 {"shear_modulus": 2e3, "locking_parameter": 2.0, "thickness_convention": "current"})


@attrs.frozen(kw_only=True)
class ThickGent(ThickWall, Gent):
    """Thick-walled Gent tube (exact plane-strain Lamé solution)."""

    _examples = ({"shear_modulus": 2e3, "locking_parameter": 10.0}, {"shear_modulus": 5e4, "locking_parameter": 1.0})
