r"""Holzapfel–Gasser–Ogden (HGO) arterial walls: a neo-Hookean matrix reinforced by two
symmetric helical families of collagen fibres.

Holzapfel, Gasser & Ogden, "A new constitutive framework for arterial wall mechanics and a
comparative study of material models", *J. Elasticity* 61 (2000) 1–48:

.. math::

    W = \frac{\mu}{2}(I_1 - 3) + \sum_{i = 4, 6}\frac{k_1}{2k_2}\left(e^{k_2(I_i - 1)^2} - 1\right),
    \qquad I_4 = I_6 = \lambda_\theta^2\cos^2\beta + \lambda_z^2\sin^2\beta,

the fibres at :math:`\pm\beta` to the circumferential direction, bearing load only in tension
(:math:`I_i > 1`; a fibre term is 0 otherwise). Clamped at its stress-free length
(``axial_stretch`` :math:`\lambda_z = 1`, plane strain), with :math:`x = (s^2 - 1)\cos^2\beta`
(the fibre strain :math:`I_4 - 1`, positive only in inflation)

.. math::

    \hat W'(s) = \mu(s - s^{-3}) + 4k_1\cos^2\beta\;s\,x\,e^{k_2x^2}\,[x > 0], \qquad
    \frac{\hat W'(s)}{s^2 - 1} = \mu\frac{s^2+1}{s^3} + 4k_1\cos^4\beta\;s\,e^{k_2x^2}\,[s > 1].

:math:`\hat W''` jumps at :math:`s = 1` (the fibres engage): the small-strain modulus of
inflation is :math:`\mu + 2k_1\cos^4\beta`, that of collapse :math:`\mu` (which sets the buckling
bound). Like the Demiray walls, :math:`k_2x^2 = 600` is the maximum stretch (beyond it
:math:`e^{k_2x^2}` overflows) and the pressure there the limit pressure. Presets:
:data:`PRESETS` (``docs/walls_beyond.md``, section "Arterial walls").

Installed at :math:`\lambda_z \neq 1` the fibres are stretched (or slack) at rest, the rest state is
not homogeneous and is solved for: the thick law is an integral over the stress-free radius, the
thin law its membrane limit, both in the stretch of the installed lumen (so :math:`P(1) = 0`;
:mod:`tubefsi.walls._hgo_insitu`, ``docs/walls_beyond.md``, section "Arterial walls in situ").
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..errors import InvalidParameterError
from ..fields import flat_points, positive, real
from ..numerics.quadrature import Integral
from . import _hgo_insitu as insitu
from .hyperelastic import HyperelasticWall, ThickWall, ThinWall, axial_stretch

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
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        x0 = np.asarray(insitu.Law.of(self).x0)
        bad = ~(self.fibre_exponent * x0 * x0 < insitu.OVERFLOW)
        if np.any(bad):
            i = tuple(np.argwhere(bad)[0]) if bad.ndim else ()
            raise InvalidParameterError("axial_stretch", "values with k2 x0^2 < 600 (x0 the fibre strain at rest)",
                                        float(np.broadcast_to(self.axial_stretch, bad.shape)[i]),
                                        "the fibres at rest would be beyond the maximum stretch")

    def _in_situ(self) -> bool:
        """Whether the tube is pre-stretched (then the rest state is solved for; module docstring)."""
        lz = self.axial_stretch
        return not (lz == 1.0 if type(lz) is float else bool(np.all(np.asarray(lz) == 1.0)))

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
        if self._in_situ():
            return insitu.membrane(self, np.asarray(s, dtype=float) - 1.0)
        x = self._fibre_strain(s)
        matrix = self.shear_modulus * (s - 1.0) * (s + 1.0) * (s * s + 1.0) / s**3
        return matrix + 4.0 * self.fibre_stiffness * self._cos2() * s * x * self._growth(x)

    def _d2W(self, s):
        """The inflation-side (right) value at s = 1, where the fibres engage."""
        if self._in_situ():
            return insitu.membrane(self, np.asarray(s, dtype=float) - 1.0, slope=True)
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
        # the matrix modulus of the installed tube, mu / lz: the fibres are slack in collapse (lz = 1) and
        # only stiffen a pre-stretched wall, so this bounds the buckling pressure from the safe side
        return self.shear_modulus / self.axial_stretch + 0.0 * np.asarray(tb, dtype=float)

    def _max_stretch(self, tb):
        if self._in_situ():
            shape, wall, (t,) = flat_points(self, tb)
            return insitu.max_stretch(wall, t, self._rest_kind()).reshape(shape)
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

    def _rest_kind(self):
        return "installed"

    def _slope_kinks(self, tb):
        r"""Where the fibres engage: :math:`\lambda = 1` clamped at the stress-free length; in situ the
        stretches where the lumen fibre (and, thick, the outer one) crosses :math:`I_4 = 1`."""
        if not self._in_situ():
            return (1.0 + 0.0 * np.asarray(tb, dtype=float),)
        shape, wall, (t,) = flat_points(self, tb)
        t = np.broadcast_to(t, (max(1, math.prod(shape)),))
        law = insitu.Law.of(wall)
        e0 = insitu.rest(wall, t, self._rest_kind())
        thin = self._rest_kind() == "membrane"
        w_outer = 1.0 if thin else 1.0 / (1.0 + (1.0 + e0) * t * (2.0 + t))
        out = []
        for w in ((1.0,) if thin else (1.0, w_outer)):
            with np.errstate(divide="ignore", invalid="ignore"):
                e = -law.x0 * law.lz / (law.c2 * w)
                lam = np.sqrt((1.0 + e) / (1.0 + e0))
            out.append(np.where(np.isfinite(lam) & (lam > 0), lam, np.nan).reshape(shape) if shape else
                       float(np.where(np.isfinite(lam) & (lam > 0), lam, np.nan)[0]))
        return tuple(out)

    def _homogeneous_rest(self) -> bool:
        return not self._in_situ()

    def _installed_cross_section(self, tube):
        r"""The installed tube at rest (``docs/walls_beyond.md``, section "Arterial walls in situ"):
        lumen :math:`a\sqrt{(1+e_0)/\lambda_z}`, outer radius :math:`a\sqrt{(1+e_0+\bar t(2+\bar t))/\lambda_z}`
        (thick) or thickness :math:`t/(s_0\lambda_z)` (membrane), :math:`e_0` the rest state."""
        a, t = np.asarray(tube.radius, dtype=float), np.asarray(tube.thickness, dtype=float)
        shape, wall, (tb,) = flat_points(self, t / a)
        e0 = insitu.rest(wall, tb, "membrane" if isinstance(self, ThinWall) else "stress-free").reshape(shape)
        lz = self.axial_stretch
        inner = np.sqrt((1.0 + e0) / lz)
        radius = a * inner
        if isinstance(self, ThinWall):
            thickness = t / (inner * lz)
        else:
            d = (t / a) * (2.0 + t / a)
            thickness = a * d / (np.sqrt(lz) * (np.sqrt(1.0 + e0 + d) + np.sqrt(1.0 + e0)))
        as_float = shape == () and np.ndim(tube.radius) == 0 and np.ndim(tube.thickness) == 0
        return (float(radius), float(thickness)) if as_float else (radius, thickness)


@attrs.frozen(kw_only=True)
class ThinHGO(ThinWall, HolzapfelGasserOgden):
    r"""Thin-walled HGO tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current);
    in situ the membrane law :math:`D` of the installed tube for :math:`\hat W'`."""

    def _dW_at_strain(self, strain):
        if self._in_situ():                        # the membrane law is formed from the strain itself
            shape, wall, (e,) = flat_points(self, strain)
            return Integral.exact(insitu.membrane(wall, e).reshape(shape))
        return super()._dW_at_strain(strain)

    def _rest_kind(self):
        return "membrane"

    _examples = ({**PRESETS["rabbit-carotid-media"]},
                 {"shear_modulus": 1e3, "fibre_stiffness": 5e3, "fibre_exponent": 2.0, "fibre_angle": 0.7,
                  "thickness_convention": "current"},
                 {"shear_modulus": 1e3, "fibre_stiffness": 5e3, "fibre_exponent": 2.0, "fibre_angle": 0.7,
                  "thickness_convention": "current", "axial_stretch": 1.1})


@attrs.frozen(kw_only=True)
class ThickHGO(ThickWall, HolzapfelGasserOgden):
    """Thick-walled HGO tube (the exact Lamé integral; pre-stretched, its rest state solved for).

    In situ (``axial_stretch`` not 1) the law is the integral over the stress-free radius of
    ``docs/walls_beyond.md``, section "Arterial walls in situ"."""

    def _pressure_at_strain(self, strain, tb):
        if not self._in_situ():
            return super()._pressure_at_strain(strain, tb)
        shape, wall, (e, t) = flat_points(self, strain, tb)
        e = np.broadcast_to(e, (max(1, math.prod(shape)),))   # with the parameters: a scalar strain too
        return insitu.thick_pressure(wall, e, t).reshape(shape)

    def _pressure_estimate(self, strain, tb):
        return Integral.exact(self._pressure_at_strain(strain, tb)) if self._in_situ() else self._lame(strain, tb)

    def _stiffness(self, stretch, tb):
        if not self._in_situ():
            return super()._stiffness(stretch, tb)
        shape, wall, (lam, t) = flat_points(self, stretch, tb)
        lam = np.broadcast_to(lam, (max(1, math.prod(shape)),))
        return insitu.thick_pressure(wall, lam - 1.0, t, slope=True).reshape(shape)

    _examples = ({**PRESETS["rabbit-carotid-adventitia"]},)     # in situ: tests/test_walls_beyond.py
