r"""Mooney–Rivlin walls.

Strain energy :math:`W = c_1(I_1 - 3) + c_2(I_2 - 3)`. Under plane strain
:math:`I_1 = I_2 = \lambda^2 + \lambda^{-2} + 1`, so
:math:`\hat W'(\lambda) = 2(c_1 + c_2)(\lambda - \lambda^{-3})`: only :math:`c_1 + c_2`
matters, and it must be positive (:math:`c_2 < 0` is common). Under an axial pre-stretch
:math:`\lambda_z` the law is the neo-Hookean one of the installed tube with
:math:`\mu = 2(c_1/\lambda_z + c_2\lambda_z)`, which must be positive too. The tube laws are
the neo-Hookean ones with shear modulus :math:`\mu = 2(c_1 + c_2)`
(see :mod:`tubefsi.walls.neo_hookean`).
"""

from __future__ import annotations

import attrs
import numpy as np

from ..fields import real, varies
from ..errors import InvalidParameterError
from .hyperelastic import HyperelasticWall, ThickWall, ThinWall, axial_stretch
from .neo_hookean import _ThickForms, _ThinForms

__all__ = ["MooneyRivlin", "ThinMooneyRivlin", "ThickMooneyRivlin"]


@attrs.frozen(kw_only=True)
class MooneyRivlin(HyperelasticWall):
    """Mooney–Rivlin material (abstract: pick a theory). Requires ``c1 + c2 > 0``."""

    c1: float = real(unit="Pa", doc="first Mooney–Rivlin constant (c1 + c2 > 0)")
    c2: float = real(unit="Pa", doc="second Mooney–Rivlin constant, often negative (c1 + c2 > 0)")
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        if varies(self):           # a graded wall: checked where the scene evaluates it along z
            return
        total = np.asarray(self.c1 + self.c2)
        if not np.all(total > 0):
            bad = np.argwhere(~(total > 0))[0] if total.ndim else ()
            raise InvalidParameterError("c1 + c2", "(0, inf)", float(total[tuple(bad)]),
                                        "the small-strain shear modulus 2 (c1 + c2) must be positive"
                                        + (f" (entry {tuple(int(i) for i in bad)})" if total.ndim else ""))
        with np.errstate(over="ignore", invalid="ignore"):
            installed = np.asarray(2.0 * (self.c1 / self.axial_stretch + self.c2 * self.axial_stretch))
        if not np.all((installed > 0) & np.isfinite(installed)):
            bad = np.argwhere(~((installed > 0) & np.isfinite(installed)))[0] if installed.ndim else ()
            raise InvalidParameterError("c1/axial_stretch + c2*axial_stretch", "(0, inf), twice it a finite double",
                                        float(installed[tuple(bad)]) / 2.0,
                                        "the installed tube's shear modulus 2 (c1/lz + c2 lz) must be positive "
                                        "and finite")

    @property
    def shear_modulus(self) -> float:
        """Small-strain shear modulus :math:`\\mu = 2(c_1 + c_2)` (Pa)."""
        return 2.0 * (self.c1 + self.c2)

    def _installed_modulus(self):
        r""":math:`2(c_1/\lambda_z + c_2\lambda_z)`: the neo-Hookean modulus of the installed tube."""
        lz = self.axial_stretch
        return 2.0 * (self.c1 / lz + self.c2 * lz)

    def _unit_parameters(self):
        return {"c1": 0.5, "c2": 0.0, "axial_stretch": 1.0}


@attrs.frozen(kw_only=True)
class ThinMooneyRivlin(_ThinForms, ThinWall, MooneyRivlin):
    r"""Thin-walled Mooney–Rivlin tube: :math:`P = 2(c_1+c_2)\bar t(\lambda - \lambda^{-3})`
    (reference thickness, the chapter's eq.) or :math:`2(c_1+c_2)\bar t(1 - \lambda^{-4})` (current)."""

    _examples = ({"c1": 1.5e3, "c2": -0.5e3}, {"c1": 1e3, "c2": 0.2e3, "thickness_convention": "current"})


@attrs.frozen(kw_only=True)
class ThickMooneyRivlin(_ThickForms, ThickWall, MooneyRivlin):
    r"""Thick-walled Mooney–Rivlin tube: :math:`P = (c_1+c_2)[f(x_o) - f(x_i)]`, :math:`f(x) = x + \ln x`."""

    _examples = ({"c1": 1.5e3, "c2": -0.5e3}, {"c1": 1e3, "c2": 1e3, "axial_stretch": 1.2})
