r"""Ogden walls, with any number of terms.

:math:`W = \sum_p \frac{2\mu_p}{\alpha_p^2}\left(\lambda_1^{\alpha_p} + \lambda_2^{\alpha_p}
+ \lambda_3^{\alpha_p} - 3\right)`, small-strain shear modulus :math:`\mu = \sum_p \mu_p`
(neo-Hookean: one term, :math:`\alpha = 2`). In plane strain
:math:`\hat W'(\lambda) = \sum_p \frac{2\mu_p}{\alpha_p}(\lambda^{\alpha_p - 1} - \lambda^{-\alpha_p - 1})`,
which depends on :math:`|\alpha_p|` only.

With :math:`A = \max|\alpha_p|`, the tube law grows without bound if :math:`A > 1` (thin,
reference thickness) or :math:`A > 2` (thin current thickness, thick); at equality it
saturates, and below it rises to a peak and falls. Terms of different signs can also make
it non-monotone at moderate stretch (Treloar-type fits do, for thin current-thickness and
thick tubes): the first peak is then the wall's maximum stretch and limit pressure
(see :mod:`tubefsi_hyperelastic._limit_point`).

Installed at an axial stretch :math:`\lambda_z` (``docs/walls_beyond.md``, section "Axial
pre-stretch"), the principal stretches from the stress-free tube are
:math:`(1/(\lambda\sqrt{\lambda_z}), \lambda/\sqrt{\lambda_z}, \lambda_z)` and
:math:`D(\lambda) = \sum_p \frac{2\mu_p\lambda_z^{-\alpha_p/2}}{\alpha_p}(\lambda^{\alpha_p - 1} -
\lambda^{-\alpha_p - 1})`: the plane-strain law with the moduli :math:`\mu_p\lambda_z^{-\alpha_p/2}`
(whose sum, the installed small-strain modulus, must be positive).
"""

from __future__ import annotations

import math

import attrs
import numpy as np
from tubefsi import InvalidParameterError
from tubefsi._validation import real_array
from tubefsi.walls import HyperelasticWall, ThickWall, ThinWall
from tubefsi.walls.hyperelastic import axial_stretch

from ._limit_point import LimitPoint

__all__ = ["Ogden", "ThinOgden", "ThickOgden"]


def _floats(values, field):
    # tubefsi's rule for what is a real number (no masked entries, nothing beyond the doubles, no
    # strings or dates), then a flat sequence
    a = real_array(field.name, values, "a non-empty sequence of finite numbers")
    if a.ndim > 1:
        raise InvalidParameterError(field.name, "a non-empty sequence of finite numbers", values,
                                    f"an array of shape {a.shape}: give a flat sequence")
    return tuple(float(v) for v in np.atleast_1d(a))


def _check_terms(instance, attribute, value):
    if not value or not all(math.isfinite(v) for v in value):
        raise InvalidParameterError(attribute.name, "a non-empty sequence of finite numbers", value)
    if attribute.name == "exponents" and any(v == 0 for v in value):
        raise InvalidParameterError("exponents", "nonzero numbers", value)


def _slope_terms(a, k, s, shift=0.0):
    r""":math:`[(a - k)s^a + (a + k)s^{-a}]\,s^{-shift}`, the bracket of a term's slope (:math:`k = 1`:
    :math:`\hat W''`, :math:`k = 2`: the thin current-thickness law) times the power of the stretch it
    comes with, folded into the exponents (so a double wherever the product is: :math:`s^a` alone
    overflows at :math:`s = 10^{300}`). For :math:`|a| < k/2` as :math:`2a[\cosh(au) - k\sinh(au)/a]`,
    :math:`u = \ln s`, whose two terms do not cancel there (the direct form loses everything as
    :math:`a \to 0`); elsewhere directly (where the hyperbolic form would cancel, :math:`a = k` at
    large stretch)."""
    if abs(a) < 0.5 * k:
        u = np.log(s)
        return 2.0 * a * (np.cosh(a * u) - k * np.sinh(a * u) / a) * s ** (-shift)
    return (a - k) * s ** (a - shift) + (a + k) * s ** (-a - shift)


def _difference(a, s, u):
    r""":math:`s^{a-1} - s^{-a-1}` at :math:`u = \ln s`, without cancellation near 1 and without an
    overflowing factor: :math:`s^{-a-1}\,\mathrm{expm1}(2au)` where :math:`au \le 0`, else
    :math:`-s^{a-1}\,\mathrm{expm1}(-2au)` (the product form is :math:`0\cdot\infty` at :math:`s = 10^{300}`)."""
    with np.errstate(over="ignore", invalid="ignore"):
        grows = a * u > 0
        return np.where(grows, -(s ** (a - 1.0)) * np.expm1(-2.0 * a * u), s ** (-a - 1.0) * np.expm1(2.0 * a * u))


def _difference_ratio(a, s, u):
    r""":math:`(s^{a-1} - s^{-a-1})/(s^2 - 1)` (:math:`a` at :math:`s = 1`): odd in :math:`a`; above 1 as
    :math:`\mathrm{sign}(a)\,s^{|a|-3}\,\mathrm{expm1}(-2|a|u)/\mathrm{expm1}(-2u)` (bounded factors), below
    as :math:`s^{-a-1}\,\mathrm{expm1}(2au)/\mathrm{expm1}(2u)`."""
    big = abs(a)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        above = np.sign(a) * s ** (big - 3.0) * (np.expm1(-2.0 * big * u) / np.expm1(-2.0 * u))
        below = s ** (-a - 1.0) * (np.expm1(2.0 * a * u) / np.expm1(2.0 * u))
        return np.where(u == 0, a, np.where(u > 0, above, below))


@attrs.frozen(kw_only=True)
class Ogden(LimitPoint, HyperelasticWall):
    """Ogden material (abstract: pick a theory, :class:`ThinOgden` or :class:`ThickOgden`)."""

    moduli: tuple = attrs.field(converter=attrs.Converter(_floats, takes_field=True), validator=_check_terms,
                                metadata={"unit": "Pa", "doc": "moduli mu_p (sum = shear modulus)"})
    exponents: tuple = attrs.field(converter=attrs.Converter(_floats, takes_field=True), validator=_check_terms,
                                   metadata={"unit": "", "doc": "exponents alpha_p (nonzero)"})
    axial_stretch: float = axial_stretch()

    def __attrs_post_init__(self):
        if len(self.moduli) != len(self.exponents):
            raise InvalidParameterError("exponents", f"{len(self.moduli)} values, one per modulus",
                                        self.exponents)
        if not sum(self.moduli) > 0:
            raise InvalidParameterError("moduli", "sum(moduli) > 0", self.moduli,
                                        "the small-strain shear modulus must be positive")
        # the installed small-strain modulus at each axial stretch (an array broadcasts: the wall is
        # then solved per value, LimitPoint); a power that leaves the doubles is rejected too
        lz = np.asarray(self.axial_stretch, dtype=float)
        with np.errstate(over="ignore", invalid="ignore"):
            terms = [m * lz ** (-0.5 * a) for m, a in zip(self.moduli, self.exponents)]
            total = sum(terms)
            ok = np.isfinite(total) & (total > 0) & np.all([np.isfinite(t) for t in terms], axis=0)
        if not np.all(ok):
            i = tuple(int(k) for k in np.argwhere(~ok)[0]) if ok.ndim else ()
            raise InvalidParameterError("axial_stretch", "values where sum(moduli_p lz^(-exponents_p/2)) is positive "
                                        "and each term a finite double", float(lz[i]),
                                        "the installed tube's small-strain modulus must be positive and finite"
                                        + (f" (entry {i})" if i else ""))

    def _installed_moduli(self):
        r""":math:`\mu_p\lambda_z^{-\alpha_p/2}` (the moduli themselves at :math:`\lambda_z = 1`)."""
        lz = float(self.axial_stretch)
        return self.moduli if lz == 1.0 else tuple(m * lz ** (-0.5 * a) for m, a in zip(self.moduli, self.exponents))

    def _pressure_scale(self):                  # P is linear in the moduli
        return sum(self.moduli)

    def _shape_key(self):
        total = sum(self.moduli)
        return (tuple(m / total for m in self.moduli), self.exponents, self.axial_stretch,
                getattr(self, "thickness_convention", "thick"))

    def _unit_wall(self):               # from the shape alone (its scale is 1 to rounding)
        return attrs.evolve(self, moduli=self._shape_key()[0])

    def _terms(self):
        return zip((2.0 * m / a for m, a in zip(self._installed_moduli(), self.exponents)), self.exponents)

    def _dW(self, s):
        # s^(a-1) - s^(-a-1) = s^(-a-1) expm1(2 a ln s): no cancellation near s = 1 (_difference)
        u = np.log(s)
        return sum(c * _difference(a, s, u) for c, a in self._terms())

    def _d2W(self, s):
        return sum(c * _slope_terms(a, 1.0, s, shift=2.0) for c, a in self._terms())

    def _thick_integrand(self, s):
        # (s^(a-1) - s^(-a-1)) / (s^2 - 1)  ->  a at s = 1 (_difference_ratio)
        u = np.log(s)
        return sum(c * _difference_ratio(a, s, u) for c, a in self._terms())

    # -- asymptotics (for the limit pressure when the law has no peak)
    def _critical(self, theory):
        return 1.0 if theory == "reference" else 2.0

    def _asymptote(self, tb, theory):
        crit, top = self._critical(theory), max(abs(a) for a in self.exponents)
        if top > crit:
            return math.inf
        lead = sum(m for m, a in zip(self._installed_moduli(), self.exponents) if abs(a) == crit) * 2.0 / crit
        if top < crit or not lead > 0:
            return 0.0  # the law falls back to zero: its peak is the limit (found by the scan)
        return tb * lead if theory != "thick" else np.log1p(tb) * lead

    def _asymptotic_decay(self, tb, theory):
        crit = self._critical(theory)
        below = [abs(a) for a in self.exponents if abs(a) < crit]
        return crit + 1.0 - max(below) if below else 2.0 * crit + 1.0


@attrs.frozen(kw_only=True)
class ThinOgden(ThinWall, Ogden):
    r"""Thin-walled Ogden tube: :math:`P = \bar t\,\hat W'(\lambda)` (reference) or :math:`/\lambda` (current)."""

    _examples = ({"moduli": (2e3,), "exponents": (3.0,)},
                 {"moduli": (2008.5, 14.75, 49.05), "exponents": (1.3, 5.0, -2.0)},
                 {"moduli": (2008.5, 14.75, 49.05), "exponents": (1.3, 5.0, -2.0), "thickness_convention": "current"})

    def _stiffness(self, stretch, tb):
        if self.thickness_convention == "reference":
            return tb * self._d2W(stretch)
        # d/dlam (dW/lam) = sum c [(a-2) s^(a-3) + (a+2) s^(-a-3)]: no cancellation at large stretch
        s = stretch
        return tb * sum(c * _slope_terms(a, 2.0, s, shift=3.0) for c, a in self._terms())


@attrs.frozen(kw_only=True)
class ThickOgden(ThickWall, Ogden):
    """Thick-walled Ogden tube (exact plane-strain Lamé solution)."""

    _examples = ({"moduli": (2e3,), "exponents": (3.0,)},
                 {"moduli": (2008.5, 14.75, 49.05), "exponents": (1.3, 5.0, -2.0)},
                 {"moduli": (1e3, 1e3), "exponents": (2.0, -1.0)},
                 {"moduli": (2e3,), "exponents": (3.0,), "axial_stretch": 0.8})
