r"""Gent walls: a strain-stiffening material with limited chain extensibility.

:math:`W = -\frac{\mu J_m}{2}\ln\left(1 - \frac{I_1 - 3}{J_m}\right)`; in plane strain
:math:`I_1 - 3 = (\lambda - 1/\lambda)^2`, so
:math:`\hat W'(\lambda) = \mu(\lambda - \lambda^{-3}) / (1 - (\lambda - 1/\lambda)^2/J_m)`.
The material locks at :math:`\lambda_{lock} = (\sqrt{J_m} + \sqrt{J_m + 4})/2`: every
pressure has a solution and the stretch stays below :math:`\lambda_{lock}` (no limit pressure,
a maximum stretch instead). :math:`J_m \to \infty` is neo-Hookean.

Installed at an axial stretch :math:`\lambda_z` (``docs/walls_beyond.md``, section "Axial
pre-stretch"), :math:`I_1 - 3 = (\lambda - 1/\lambda)^2/\lambda_z + c`,
:math:`c = (\lambda_z-1)^2(\lambda_z+2)/\lambda_z`, in the stretch :math:`\lambda` of the installed
tube, so :math:`D(\lambda) = (\mu/\lambda_z)(\lambda - \lambda^{-3})/(1 - (I_1 - 3)/J_m)` and the
lock moves to :math:`\lambda_{lock} = (r + \sqrt{r^2 + 4})/2`, :math:`r = \sqrt{\lambda_z(J_m - c)}`;
:math:`c \ge J_m` (the installed tube locked at rest) is an ``InvalidParameterError``.
"""

from __future__ import annotations

import attrs
import numpy as np
from tubefsi import InvalidParameterError
from tubefsi.fields import positive
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall
from tubefsi.walls.hyperelastic import axial_stretch

from ._forms import hoop, quartic

__all__ = ["Gent", "ThinGent", "ThickGent"]


@attrs.frozen(kw_only=True)
class Gent(HyperelasticWall):
    """Gent material (abstract: pick a theory, :class:`ThinGent` or :class:`ThickGent`)."""

    shear_modulus: float = positive(unit="Pa", doc="small-strain shear modulus mu")
    locking_parameter: float = positive(doc="J_m, the largest I1 - 3")
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        room = np.asarray(self._reach())
        if not np.all(room > 0):
            bad = np.argwhere(~(room > 0))[0] if room.ndim else ()
            raise InvalidParameterError("axial_stretch", "(lz - 1)^2 (lz + 2)/lz < locking_parameter",
                                        float(np.broadcast_to(self.axial_stretch, room.shape)[tuple(bad)]),
                                        "the installed tube at rest is already locked")

    def _pressure_scale(self):                  # P = mu * P_hat(J_m, lz): a curve table serves every mu
        return self.shear_modulus

    def _shape_key(self):
        return (self.locking_parameter, self.axial_stretch, getattr(self, "thickness_convention", "thick"))

    def _unit_wall(self):
        return attrs.evolve(self, shear_modulus=1.0)

    def _reach(self):
        r""":math:`\lambda_z(J_m - c)`: the largest :math:`(\lambda - 1/\lambda)^2` of the installed tube."""
        return self.axial_stretch * (self.locking_parameter - self._installed_invariants(1.0)[0])

    def _locking_stretch(self):
        jm = self._reach()
        return 0.5 * (jm**0.5 + (jm + 4.0) ** 0.5)

    def _room(self, s):
        """:math:`1 - (I_1 - 3)/J_m`, factored so that it keeps its accuracy near the lock."""
        lz = self.axial_stretch
        lock, root = self._locking_stretch(), self._reach() ** 0.5
        return (lock - s) * (1.0 + 1.0 / (s * lock)) * (root + hoop(s)) / (lz * self.locking_parameter)

    def _dW(self, s):
        return self.shear_modulus / self.axial_stretch * quartic(s) / self._room(s)

    def _d2W(self, s):
        room, lz = self._room(s), self.axial_stretch
        return self.shear_modulus / lz * ((1.0 + 3.0 * s**-4) / room
                                          + 2.0 * quartic(s) ** 2 / (lz * self.locking_parameter * room * room))

    def _thick_integrand(self, s):
        return self.shear_modulus / self.axial_stretch * (s * s + 1.0) / (s**3 * self._room(s))


@attrs.frozen(kw_only=True)
class ThinGent(ThinWall, Gent):
    r"""Thin-walled Gent tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"shear_modulus": 2e3, "locking_parameter": 10.0},
                 {"shear_modulus": 2e3, "locking_parameter": 2.0, "thickness_convention": "current"},
                 {"shear_modulus": 2e3, "locking_parameter": 2.0, "thickness_convention": "current", "axial_stretch": 1.4})


@attrs.frozen(kw_only=True)
class ThickGent(ThickWall, Gent):
    """Thick-walled Gent tube (exact plane-strain Lamé solution)."""

    _examples = ({"shear_modulus": 2e3, "locking_parameter": 10.0}, {"shear_modulus": 5e4, "locking_parameter": 1.0})
