r"""Demiray walls: exponential strain stiffening, as in arteries.

The isotropic exponential law of Demiray (1972), sometimes called "Fung-type"; it is not Fung's
anisotropic arterial law (an exponential of a quadratic form in the circumferential and axial
Green strains), whose anisotropy :mod:`tubefsi.walls.hgo` models with fibres.

:math:`W = \frac{\mu}{2b}\left(e^{b(I_1 - 3)} - 1\right)`, a 3-D isotropic energy of :math:`I_1`
alone (:math:`W_1 = \tfrac{\mu}{2}e^{b(I_1-3)}`, the natural hook ``_W1`` of
:class:`~tubefsi.walls.HyperelasticWall`, which derives the tube laws at every axial stretch
:math:`\lambda_z`). In plane strain :math:`\hat W'(\lambda) = \mu(\lambda - \lambda^{-3})\,e^{b(\lambda -
1/\lambda)^2}`; installed at :math:`\lambda_z`, :math:`D(\lambda) = (\mu/\lambda_z)(\lambda -
\lambda^{-3})e^{b(I_1 - 3)}` with :math:`I_1 - 3 = (\lambda - 1/\lambda)^2/\lambda_z + c`,
:math:`c = (\lambda_z - 1)^2(\lambda_z + 2)/\lambda_z` (``docs/walls_beyond.md``, section "Axial
pre-stretch"). The tube law increases without bound. Its pressure would overflow double
precision beyond :math:`b(I_1 - 3) \approx 709`; the wall declares :math:`b(I_1 - 3) = 600` its
maximum stretch and the (astronomical) pressure there its limit pressure, so that stretches
and pressures past them raise tubefsi's typed errors instead of returning ``inf``; an axial
stretch with :math:`bc \ge 600` is an ``InvalidParameterError``.
"""

from __future__ import annotations

import attrs
import numpy as np
from tubefsi import InvalidParameterError
from tubefsi.fields import positive
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall
from tubefsi.walls.hyperelastic import axial_stretch

from ._forms import quartic

__all__ = ["Demiray", "ThinDemiray", "ThickDemiray"]


@attrs.frozen(kw_only=True)
class Demiray(HyperelasticWall):
    """Demiray material (abstract: pick a theory, :class:`ThinDemiray` or :class:`ThickDemiray`)."""

    shear_modulus: float = positive(unit="Pa", doc="small-strain shear modulus mu")
    stiffening: float = positive(doc="stiffening exponent b")
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        rest = self.stiffening * self._installed_invariants(1.0)[0]     # b (I1 - 3) at rest
        if not np.all(rest < 600.0):
            bad = np.argwhere(~(np.asarray(rest) < 600.0))[0] if np.ndim(rest) else ()
            raise InvalidParameterError("axial_stretch", "b (lz - 1)^2 (lz + 2)/lz < 600",
                                        float(np.broadcast_to(self.axial_stretch, np.shape(rest))[tuple(bad)]),
                                        "the installed tube at rest is already beyond the maximum stretch")

    def _pressure_scale(self):                  # P = mu * P_hat(b, lz): a curve table serves every mu
        return self.shear_modulus

    def _shape_key(self):
        return (self.stiffening, self.axial_stretch, getattr(self, "thickness_convention", "thick"))

    def _unit_wall(self):
        return attrs.evolve(self, shear_modulus=1.0)

    def _max_stretch(self, tb):
        # b (I1 - 3) = 600: (lam - 1/lam)^2 = x^2 = lz (600 - b c)/b, lam = (x + sqrt(x^2 + 4))/2; as
        # sqrt(lz (600 - b c)) / sqrt(b) and by hypot, a double for every b (600/b overflows at 5e-324)
        lz, b = self.axial_stretch, self.stiffening
        x = np.sqrt(lz * (600.0 - b * self._installed_invariants(1.0)[0])) / np.sqrt(b)
        return 0.5 * (x + np.hypot(x, 2.0))

    def _limit_pressure(self, tb):
        return self._pressure_at_strain(np.asarray(self._max_stretch(tb) - 1.0 + 0.0 * np.asarray(tb)), tb)

    def _W1(self, i1, i2):
        with np.errstate(over="ignore"):
            return 0.5 * self.shear_modulus * np.exp(self.stiffening * i1)

    def _W_second(self, i1, i2):
        return self.stiffening * self._W1(i1, i2), 0.0, 0.0

    # the installed law from the invariants, written out in the plane-strain forms' order of
    # operations: at lz = 1 they are those forms bit for bit (D = F (s - s^-3), F = (mu/lz) e^{b y})
    def _growth(self, s):
        with np.errstate(over="ignore"):
            return np.exp(self.stiffening * self._installed_invariants(s)[0])

    def _dW(self, s):
        return self.shear_modulus / self.axial_stretch * quartic(s) * self._growth(s)

    def _d2W(self, s):
        lz = self.axial_stretch
        with np.errstate(over="ignore", invalid="ignore"):
            return self.shear_modulus / lz * self._growth(s) * (1.0 + 3.0 * s**-4
                                                               + 2.0 * (self.stiffening / lz) * quartic(s) ** 2)

    def _thick_integrand(self, s):
        with np.errstate(over="ignore"):
            # (s^2 + 1)/s^3 as (1 + s^-2)/s, the core's form: no s^3 beyond the doubles at s = 1e150
            return self.shear_modulus / self.axial_stretch * ((1.0 + 1.0 / (s * s)) / s) * self._growth(s)


@attrs.frozen(kw_only=True)
class ThinDemiray(ThinWall, Demiray):
    r"""Thin-walled Demiray tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"shear_modulus": 2e3, "stiffening": 0.5},
                 {"shear_modulus": 1e4, "stiffening": 2.0, "thickness_convention": "current"},
                 {"shear_modulus": 2e3, "stiffening": 0.5, "axial_stretch": 0.85})


@attrs.frozen(kw_only=True)
class ThickDemiray(ThickWall, Demiray):
    """Thick-walled Demiray tube (exact plane-strain Lamé solution)."""

    _examples = ({"shear_modulus": 2e3, "stiffening": 0.5}, {"shear_modulus": 3e4, "stiffening": 3.0})
