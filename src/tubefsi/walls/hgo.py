r"""Holzapfel–Gasser–Ogden (HGO) arterial walls: a neo-Hookean matrix reinforced by two
symmetric helical families of collagen fibres.

Holzapfel, Gasser & Ogden, "A new constitutive framework for arterial wall mechanics and a
comparative study of material models", *J. Elasticity* 61 (2000) 1–48:

.. math::

    W = \frac{\mu}{2}(I_1 - 3) + \sum_{i = 4, 6}\frac{k_1}{2k_2}\left(e^{k_2(I_i - 1)^2} - 1\right),
    \qquad I_4 = I_6 = \lambda_\theta^2\cos^2\beta + \lambda_z^2\sin^2\beta,

the fibres at :math:`\pm\beta` to the circumferential direction, bearing load only in tension
(:math:`I_i > 1`; a fibre term is 0 otherwise). The tube is clamped at its stress-free length
(:math:`\lambda_z = 1`, plane strain), so with :math:`x = (s^2 - 1)\cos^2\beta`
(the fibre strain :math:`I_4 - 1`, positive only in inflation)

.. math::

    \hat W'(s) = \mu(s - s^{-3}) + 4k_1\cos^2\beta\;s\,x\,e^{k_2x^2}\,[x > 0], \qquad
    \frac{\hat W'(s)}{s^2 - 1} = \mu\frac{s^2+1}{s^3} + 4k_1\cos^4\beta\;s\,e^{k_2x^2}\,[s > 1].

:math:`\hat W''` jumps at :math:`s = 1` (the fibres engage): the small-strain modulus of
inflation is :math:`\mu + 2k_1\cos^4\beta`, that of collapse :math:`\mu` (which sets the buckling
bound). Like the Fung walls, :math:`k_2x^2 = 600` is the maximum stretch (beyond it
:math:`e^{k_2x^2}` overflows) and the pressure there the limit pressure. Presets:
:data:`PRESETS` (``docs/walls_beyond.md``, section "Arterial walls").
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..errors import InvalidParameterError
from ..fields import positive, real
from .hyperelastic import HyperelasticWall, ThickWall, ThinWall

__all__ = ["HolzapfelGasserOgden", "ThinHGO", "ThickHGO", "PRESETS"]

#: Published parameter sets (Pa, rad): the rabbit carotid artery of Holzapfel, Gasser & Ogden
#: (2000), Table 1 (media and adventitia fitted separately; their matrix constant c is mu).
PRESETS = {
    "rabbit-carotid-media": dict(shear_modulus=3.0e3, fibre_stiffness=2.3632e3, fibre_exponent=0.8393,
                                 fibre_angle=math.radians(29.0)),
    "rabbit-carotid-adventitia": dict(shear_modulus=0.3e3, fibre_stiffness=0.5620e3, fibre_exponent=0.7112,
                                      fibre_angle=math.radians(62.0)),
}


@attrs.frozen(kw_only=True)
class HolzapfelGasserOgden(HyperelasticWall):
    """HGO material (abstract: pick a theory, :class:`ThinHGO` or :class:`ThickHGO`)."""

    #: anisotropic: its small-strain limit is not the isotropic linear wall
    isotropic = False

    shear_modulus: float = positive(unit="Pa", doc="matrix shear modulus mu")
    fibre_stiffness: float = positive(unit="Pa", doc="fibre stiffness k1")
    fibre_exponent: float = positive(doc="fibre stiffening exponent k2")
    fibre_angle: float = real(low=0.0, high=math.pi / 2, low_open=False, high_open=False, unit="rad",
                              doc="fibre angle beta to the circumferential direction")

    @classmethod
    def preset(cls, name: str, **overrides):
        """A wall of a published parameter set of :data:`PRESETS` (e.g. ``"rabbit-carotid-media"``)."""
        if name not in PRESETS:
            raise InvalidParameterError("preset", "{" + ", ".join(PRESETS) + "}", name)
        return cls(**{**PRESETS[name], **overrides})

    def _cos2(self):
        return np.cos(self.fibre_angle) ** 2

    def _fibre_strain(self, s):
        """:math:`x = I_4 - 1` where the fibres are in tension, else 0."""
        return np.maximum((s - 1.0) * (s + 1.0) * self._cos2(), 0.0)

    def _growth(self, x):
        with np.errstate(over="ignore"):
            return np.exp(self.fibre_exponent * x * x)

    def _dW(self, s):
        x = self._fibre_strain(s)
        matrix = self.shear_modulus * (s - 1.0) * (s + 1.0) * (s * s + 1.0) / s**3
        return matrix + 4.0 * self.fibre_stiffness * self._cos2() * s * x * self._growth(x)

    def _d2W(self, s):
        """The inflation-side (right) value at s = 1, where the fibres engage."""
        x = self._fibre_strain(s)
        c2 = self._cos2()
        fibres = 4.0 * self.fibre_stiffness * c2 * self._growth(x) * (x + 2.0 * s * s * c2
                                                                      * (1.0 + 2.0 * self.fibre_exponent * x * x))
        return self.shear_modulus * (1.0 + 3.0 * s**-4) + np.where(s >= 1.0, fibres, 0.0)

    def _thick_integrand(self, s):
        x = self._fibre_strain(s)
        fibres = 4.0 * self.fibre_stiffness * self._cos2() ** 2 * s * self._growth(x)
        return self.shear_modulus * (s * s + 1.0) / s**3 + np.where(s >= 1.0, fibres, 0.0)

    def _ring_modulus(self, tb):
        return self.shear_modulus + 0.0 * np.asarray(tb, dtype=float)     # collapse: the fibres are slack

    def _max_stretch(self, tb):
        c2 = self._cos2()
        with np.errstate(divide="ignore"):
            return np.where(c2 > 1e-300, np.sqrt(1.0 + np.sqrt(600.0 / self.fibre_exponent) / np.maximum(c2, 1e-300)),
                            np.inf) + 0.0 * np.asarray(tb, dtype=float)

    def _limit_pressure(self, tb):
        top = np.asarray(self._max_stretch(tb), dtype=float)
        finite = np.isfinite(top)
        if not np.any(finite):
            return top
        return np.where(finite, self._pressure_at_strain(np.where(finite, top, 2.0) - 1.0, tb), np.inf)

    def _collapse_stretch(self, tb):
        return 0.0


@attrs.frozen(kw_only=True)
class ThinHGO(ThinWall, HolzapfelGasserOgden):
    r"""Thin-walled HGO tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({**PRESETS["rabbit-carotid-media"]},
                 {"shear_modulus": 1e3, "fibre_stiffness": 5e3, "fibre_exponent": 2.0, "fibre_angle": 0.7,
                  "thickness_convention": "current"})


@attrs.frozen(kw_only=True)
class ThickHGO(ThickWall, HolzapfelGasserOgden):
    """Thick-walled HGO tube (the exact plane-strain Lamé integral)."""

    _examples = ({**PRESETS["rabbit-carotid-adventitia"]},)
