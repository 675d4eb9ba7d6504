r"""Neo-Hookean walls, and the closed forms every :math:`\hat W' = \mu(\lambda - \lambda^{-3})` law shares.

Strain energy :math:`W = \tfrac{\mu}{2}(I_1 - 3)`. In plane strain
:math:`I_1 - 3 = (\lambda - 1/\lambda)^2`, so :math:`\hat W'(\lambda) = \mu(\lambda - \lambda^{-3})`.
Mooney–Rivlin reduces to the same law with :math:`\mu = 2(c_1 + c_2)`.

With an axial pre-stretch :math:`\lambda_z` (the tube clamped at the installed length
:math:`\lambda_z L`; ``docs/walls_beyond.md``, section "Axial pre-stretch") the lumen at zero
pressure is :math:`a/\sqrt{\lambda_z}` and the wall thickness :math:`t/\sqrt{\lambda_z}`; in the
stretch :math:`\lambda = R\sqrt{\lambda_z}/a` of that installed tube every law below holds with
:math:`\mu/\lambda_z` for :math:`\mu` (Mooney–Rivlin: :math:`2(c_1/\lambda_z + c_2\lambda_z)`).

Tube laws (:math:`x = \lambda^2 - 1`, :math:`b = (1+\bar t)^2`, :math:`d = b - 1`):

* thin, reference thickness: :math:`P = \mu\bar t(\lambda - \lambda^{-3})`, no limit;
* thin, current thickness: :math:`P = \mu\bar t(1 - \lambda^{-4})`, limit :math:`\mu\bar t`;
* thick: :math:`P = \tfrac{\mu}{2}\left[\ln\left(1 + \tfrac{x d}{b + x}\right) + \tfrac{x d}{\lambda^2 (b + x)}\right]`,
  limit :math:`\mu\ln(1+\bar t)`, slope
  :math:`P' = \mu\lambda d\,\frac{\lambda^2(d+2) + d}{\lambda^4(\lambda^2+d)^2}`.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..numerics.kernels import expm1_ratio, log1p_ratio
from ..numerics.roots import solve_signed
from ..errors import InvalidParameterError
from ..fields import positive, varies
from .hyperelastic import HyperelasticWall, ThickWall, ThinWall, axial_stretch

__all__ = ["NeoHookean", "ThinNeoHookean", "ThickNeoHookean"]


class _NeoHookeanLaw:
    """Closed forms in terms of ``self._installed_modulus()`` (mixed into the concrete classes): the
    shear modulus over the axial stretch, the law of the installed tube (module docstring)."""

    __slots__ = ()

    def _pressure_scale(self):
        return self._installed_modulus()

    def _shape_key(self):
        return (getattr(self, "thickness_convention", "thick"),)

    def _unit_wall(self):
        # the law of the installed tube is the modulus times that of the unit neo-Hookean law
        return attrs.evolve(self, **self._unit_parameters())

    def _dW(self, stretch):
        return self._installed_modulus() * (stretch - stretch**-3)

    def _d2W(self, stretch):
        return self._installed_modulus() * (1.0 + 3.0 * stretch**-4)

    def _thick_integrand(self, s):
        return self._installed_modulus() * (s * s + 1.0) / s**3


def _beyond(out, strain, stretch, direct):
    """``out`` with ``direct(stretch)`` where the strain is past 1e70 (its polynomial form would
    overflow); the rare case only costs its own points."""
    if out.ndim == 0:
        return direct(stretch) if strain > 1e70 else out
    if out.size and not strain.max() <= 1e70:        # (one reduction where nothing is that far)
        far = strain > 1e70
        out[far] = direct(stretch[far])
    return out


def _quartic_rise(e):
    r""":math:`\lambda^4 - 1 = \varepsilon(4 + \varepsilon(6 + \varepsilon(4 + \varepsilon)))` at
    :math:`\lambda = 1 + \varepsilon`, in one array for an array (Horner in place)."""
    if e.ndim == 0:
        return e * (4.0 + e * (6.0 + e * (4.0 + e)))
    out = e + 4.0
    out *= e
    out += 6.0
    out *= e
    out += 4.0
    out *= e
    return out


def _reference_unit(strain):
    r""":math:`\lambda - \lambda^{-3}` at :math:`\lambda = 1 + \varepsilon`: as
    :math:`(\lambda^4 - 1)/\lambda^3` from the strain (no cancellation at small strain), directly
    past :math:`\varepsilon = 10^{70}` (where :math:`\lambda^4` would overflow)."""
    e = np.asarray(strain, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        lam = 1.0 + e
        cube = lam * lam
        cube *= lam
        out = _quartic_rise(e)
        out /= cube
        return _beyond(out, e, lam, lambda big: big - big**-3)


def _current_unit(strain):
    r""":math:`1 - \lambda^{-4}` at :math:`\lambda = 1 + \varepsilon`, as :math:`(\lambda^4 - 1)/\lambda^4`
    (directly past :math:`\varepsilon = 10^{70}`)."""
    e = np.asarray(strain, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        lam = 1.0 + e
        lam2 = lam * lam
        lam2 *= lam2
        out = _quartic_rise(e)
        out /= lam2
        return _beyond(out, e, lam, lambda big: 1.0 - big**-4)


class _ThinForms(_NeoHookeanLaw):
    __slots__ = ()

    closed_form_integral = True

    def _pressure_at_strain(self, strain, tb):
        unit = _reference_unit(strain) if self.thickness_convention == "reference" else _current_unit(strain)
        scale = self._installed_modulus() * tb
        if type(scale) is float and unit.ndim:      # (a curve: scaled in place)
            unit *= scale
            return unit
        return scale * unit

    def _pressure_at_log_stretch(self, log_stretch, strain, tb):
        # reference thickness: lam - lam^-3 = lam (1 - e^{-4v}) = -(1 + strain) expm1(-4v): one
        # exponential of an exact argument (4v is) and a product, to a few ulp at any v (no
        # cancellation at small v; e^{-3v} would round 3v: a relative 3v eps), where the strain
        # form takes ten passes
        v = log_stretch
        if (self.thickness_convention != "reference" or type(v) is not np.ndarray or type(tb) is not float
                or type(self._installed_modulus()) is not float or v.shape != np.shape(strain)
                or not (v.size and v.max() <= 700.0)):
            return self._pressure_at_strain(strain, tb)
        out = np.multiply(v, -4.0)
        np.expm1(out, out=out)
        lam = np.add(strain, 1.0)
        out *= lam
        out *= -self._installed_modulus() * tb
        return out

    def _stiffness(self, stretch, tb):
        if self.thickness_convention == "reference":
            return self._installed_modulus() * tb * (1.0 + 3.0 * stretch**-4)
        return 4.0 * self._installed_modulus() * tb * stretch**-5

    def _strain(self, pressure, tb):
        k = np.asarray(pressure, dtype=float) / (self._installed_modulus() * tb)
        if self.thickness_convention == "current":
            return np.expm1(-0.25 * np.log1p(-k))
        e, _ = solve_signed(
            lambda e, i: _reference_unit(e),
            lambda e, i: 1.0 + 3.0 * (1.0 + e) ** -4,
            k, guess=np.where(k < 1.0, 0.25 * k, k), lower=-1.0)
        return e

    def _limit_pressure(self, tb):
        return math.inf if self.thickness_convention == "reference" else self._installed_modulus() * tb

    def _stiffness_decay_exponent(self, tb):
        return 0.0 if self.thickness_convention == "reference" else 5.0

    def _power_law_integral(self, log_ratio, outlet_stretch, exponent, tb):
        k, s0, mt = exponent, outlet_stretch, self._installed_modulus() * tb
        if self.thickness_convention == "reference":
            return mt * (s0 ** (k + 1) * expm1_ratio(k + 1, log_ratio)
                         + 3.0 * s0 ** (k - 3) * expm1_ratio(k - 3, log_ratio))
        return 4.0 * mt * s0 ** (k - 4) * expm1_ratio(k - 4, log_ratio)

    def _has_power_law_integral_inverse(self) -> bool:
        return self.thickness_convention != "reference"

    def _power_law_integral_inverse(self, integral, outlet_stretch, exponent, tb):
        if self.thickness_convention == "reference":
            return None
        k = exponent
        return log1p_ratio(k - 4, integral / (4.0 * self._installed_modulus() * tb * outlet_stretch ** (k - 4)))


def _far_slope(out, stretch, d, modulus, power):
    r"""``out`` (the thick slope times :math:`\lambda^{1 - power}`, from the polynomial form), with the
    points where that form overflows (:math:`\lambda^4 (\lambda^2 + d)^2` at :math:`\lambda = 10^{77}`, or
    :math:`d^2` at :math:`\bar t = 10^{77}`, as inf/inf) taken from the same quantity written in bounded
    factors, :math:`\mu\,\frac{d}{\lambda^2 + d}\,\frac{d + 2 + d/\lambda^2}{\lambda^2 + d}\,\lambda^{-power}`
    (a double, or an underflow to 0, wherever the slope is). The slope is positive: a 0 (the
    denominator overflowed first, past 1e60) or a NaN marks such a point; the rare case costs its
    own points."""
    if np.ndim(out) == 0:
        if 0.0 < out < math.inf:
            return out
    elif out.size and 0.0 < out.min() and out.max() < math.inf:       # (a NaN fails the first)
        return out
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        lam = np.asarray(stretch, dtype=float)
        lam2 = lam * lam
        bounded = modulus * (d / (lam2 + d)) * ((d + 2.0 + d / lam2) / (lam2 + d)) / lam**power
        return np.where((out > 0) & (out < math.inf), out, bounded)


class _ThickForms(_NeoHookeanLaw):
    __slots__ = ()

    def _pressure_at_strain(self, strain, tb):
        e = np.asarray(strain, dtype=float)
        b = (1.0 + tb) ** 2
        d = tb * (2.0 + tb)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            x = e * (2.0 + e)                                  # lam^2 - 1 (inf past 1e154: fine below)
            if np.ndim(x) and x.size and x.max() <= 1e150:     # (one reduction, NaN failing it: the usual case, one branch)
                ratio = x / (b + x)
                last = x * d / ((1.0 + x) * (b + x))
            else:
                huge = x > 1e150
                ratio = np.where(huge, 1.0 / (1.0 + b / x), x / (b + x))
                last = np.where(huge, ratio * d / (1.0 + x), x * d / ((1.0 + x) * (b + x)))
        return 0.5 * self._installed_modulus() * (np.log1p(ratio * d) + last)

    def _stiffness(self, stretch, tb):
        # mu d lam (lam^2 (d + 2) + d) / (lam^4 (lam^2 + d)^2), d = tb (2 + tb); the per-point factors
        # (mu d, d + 2) first, then in place: the integrand's hot spot, on (nodes x points) arrays
        with np.errstate(over="ignore", invalid="ignore"):     # (the far points: _far_slope)
            lam2 = np.multiply(stretch, stretch)
            d = tb * (2.0 + tb)
            den = lam2 + d
            den *= den
            den *= lam2
            den *= lam2
            num = lam2 * (d + 2.0)
            num += d
            num *= stretch
            num *= self._installed_modulus() * d
            num /= den
        return _far_slope(num, stretch, d, self._installed_modulus(), 1.0)

    def _log_slope(self, stretch, tb):
        # lam P' = mu d (lam^2 (d + 2) + d) / (lam^2 (lam^2 + d)^2): the stiffness's form with the
        # factor lam cancelled, two passes fewer over (nodes x points); a subclass that overrides
        # the stiffness gets its own
        if type(self)._stiffness is not _ThickForms._stiffness:
            return stretch * self._stiffness(stretch, tb)
        with np.errstate(over="ignore", invalid="ignore"):     # (the far points: _far_slope)
            lam2 = np.multiply(stretch, stretch)
            d = tb * (2.0 + tb)
            den = lam2 + d
            den *= den
            den *= lam2
            # (in place where the shapes allow: one array of nodes x points fewer)
            inplace = type(lam2) is np.ndarray and (np.ndim(d) == 0 or np.broadcast_shapes(lam2.shape, np.shape(d)) == lam2.shape)
            num = np.multiply(lam2, d + 2.0, out=lam2) if inplace else lam2 * (d + 2.0)
            num += d
            num *= self._installed_modulus() * d
            num /= den
        return _far_slope(num, stretch, d, self._installed_modulus(), 0.0)

    def _strain(self, pressure, tb):
        # the law per unit modulus: no parameter but t/a, which is gathered for the active points
        shape = np.broadcast_shapes(np.shape(pressure), np.shape(tb), np.shape(self._installed_modulus()))
        k = np.broadcast_to(np.asarray(pressure, dtype=float) / self._installed_modulus(), shape).ravel()
        tb = np.broadcast_to(np.asarray(tb, dtype=float), shape).ravel()
        unit = _UNIT_THICK
        e, _ = solve_signed(lambda e, i: unit._pressure_at_strain(e, tb[i]),
                            lambda e, i: unit._stiffness(1.0 + e, tb[i]),
                            k, guess=k / unit._stiffness(np.ones(k.shape), tb), lower=-1.0)
        return e.reshape(shape)

    def _limit_pressure(self, tb):
        return self._installed_modulus() * np.log1p(tb)

    def _stiffness_decay_exponent(self, tb):
        return 5.0


@attrs.frozen(kw_only=True)
class NeoHookean(HyperelasticWall):
    r"""Neo-Hookean material, :math:`W = \tfrac{\mu}{2}(I_1 - 3)` (abstract: pick a theory)."""

    shear_modulus: float = positive(unit="Pa", doc="small-strain shear modulus mu")
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        mu, lz = self.shear_modulus, self.axial_stretch
        if type(mu) is float and type(lz) is float and math.isfinite(mu / lz):
            return                 # (the commonest wall, made in a Monte Carlo loop: no array work)
        if varies(self):           # a graded wall: its modulus is evaluated along z
            return
        with np.errstate(over="ignore"):
            installed = np.asarray(self.shear_modulus / self.axial_stretch)
        if not np.all(np.isfinite(installed)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(installed))[0]) if installed.ndim else ()
            raise InvalidParameterError("axial_stretch", "values where shear_modulus / axial_stretch is a finite "
                                        "double", float(np.broadcast_to(self.axial_stretch, installed.shape)[bad]),
                                        "the installed tube's shear modulus would overflow")

    def _installed_modulus(self):
        return self.shear_modulus / self.axial_stretch

    def _unit_parameters(self):
        return {"shear_modulus": 1.0, "axial_stretch": 1.0}


@attrs.frozen(kw_only=True)
class ThinNeoHookean(_ThinForms, ThinWall, NeoHookean):
    r"""Thin-walled neo-Hookean tube: :math:`P = \mu\bar t(\lambda - \lambda^{-3})` (reference)
    or :math:`\mu\bar t(1 - \lambda^{-4})` (current thickness)."""

    _examples = ({"shear_modulus": 2e3}, {"shear_modulus": 2e3, "thickness_convention": "current", "axial_stretch": 1.1})


@attrs.frozen(kw_only=True)
class ThickNeoHookean(_ThickForms, ThickWall, NeoHookean):
    r"""Thick-walled neo-Hookean tube (exact plane-strain Lamé solution); limit pressure
    :math:`\mu\ln(1+\bar t)`."""

    _examples = ({"shear_modulus": 2e3},)


#: The thick neo-Hookean law of unit modulus (its inverse iterates on it, gathering only t/a).
_UNIT_THICK = ThickNeoHookean(shear_modulus=1.0)
