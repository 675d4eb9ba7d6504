r"""Fung walls: exponential strain stiffening, as in arteries.

:math:`W = \frac{\mu}{2b}\left(e^{b(I_1 - 3)} - 1\right)`; in plane strain
:math:`\hat W'(\lambda) = \mu(\lambda - \lambda^{-3})\,e^{b(\lambda - 1/\lambda)^2}`.
The tube law increases without bound. Its pressure would overflow double precision beyond
:math:`b(\lambda - 1/\lambda)^2 \approx 709`; the wall declares
:math:`b(\lambda - 1/\lambda)^2 = 600` its maximum stretch and the (astronomical) pressure
there its limit pressure, so that stretches and pressures past them raise tubefsi's typed
errors instead of returning ``inf``.
"""

from __future__ import annotations

import attrs
import numpy as np
from tubefsi.fields import positive
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall

from ._forms import hoop, quartic

__all__ = ["Fung", "ThinFung", "ThickFung"]


@attrs.frozen(kw_only=True)
class Fung(HyperelasticWall):
    """Fung material (abstract: pick a theory, :class:`ThinFung` or :class:`ThickFung`)."""

    shear_modulus: float = positive(unit="Pa", doc="small-strain shear modulus mu")
    stiffening: float = positive(doc="stiffening exponent b")

    def _pressure_scale(self):                  # P = mu * P_hat(b): a curve table serves every mu
        return self.shear_modulus

    def _shape_key(self):
        return (self.stiffening, getattr(self, "thickness_convention", "thick"))

    def _max_stretch(self, tb):
        x = (600.0 / self.stiffening) ** 0.5          # lam - 1/lam where exp(b x^2) = e^600
        return 0.5 * (x + (x * x + 4.0) ** 0.5)

    def _limit_pressure(self, tb):
        return self._pressure_at_strain(np.asarray(self._max_stretch(tb) - 1.0 + 0.0 * np.asarray(tb)), tb)

    def _growth(self, s):
        with np.errstate(over="ignore"):
            return np.exp(self.stiffening * hoop(s) ** 2)

    def _dW(self, s):
        return self.shear_modulus * quartic(s) * self._growth(s)

    def _d2W(self, s):
        with np.errstate(over="ignore"):
            return self.shear_modulus * self._growth(s) * (1.0 + 3.0 * s**-4
                                                          + 2.0 * self.stiffening * quartic(s) ** 2)

    def _thick_integrand(self, s):
        with np.errstate(over="ignore"):
            return self.shear_modulus * (s * s + 1.0) / s**3 * self._growth(s)


@attrs.frozen(kw_only=True)
class ThinFung(ThinWall, Fung):
    r"""Thin-walled Fung tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"shear_modulus": 2e3, "stiffening": 0.5},
                 {"shear_modulus": 1e4, "stiffening": 2.0, "thickness_convention": "current"})


@attrs.frozen(kw_only=True)
class ThickFung(ThickWall, Fung):
    """Thick-walled Fung tube (exact plane-strain Lamé solution)."""

    _examples = ({"shear_modulus": 2e3, "stiffening": 0.5}, {"shear_modulus": 3e4, "stiffening": 3.0})
