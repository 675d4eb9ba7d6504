r"""Shear-thinning fluids without a yield stress: Carreau, Carreau–Yasuda, Cross, Ellis.

None of them is separable, so tubefsi's generic path serves them: the Rabinowitsch–Mooney
flow function (a fixed quadrature graded toward zero stress), tabulated once per fluid as
:math:`\ln\Gamma(\ln\tau_w)` on Chebyshev panels and inverted by Newton's method; a whole
flow curve stays vectorized. Each class gives only its natural law — the viscosity function
:math:`\eta(\dot\gamma)` (``_stress``), or for Ellis the shear rate :math:`\dot\gamma(\tau)`
(``_shear_rate``), whose flow function and velocity profile are elementary and given in
closed form.
"""

from __future__ import annotations

import attrs
import numpy as np
from tubefsi import InvalidParameterError
from tubefsi.fields import nonnegative, positive
from tubefsi.rheology import Rheology

__all__ = ["Carreau", "CarreauYasuda", "Cross", "Ellis"]


def _log1p_power(x, a):
    r""":math:`\ln(1 + x^a)` for :math:`x > 0` without overflow: :math:`a\ln x + \ln(1 + x^{-a})` where
    :math:`x^a > 1` (so the stress keeps increasing up to the largest representable shear rate)."""
    with np.errstate(divide="ignore"):
        la = a * np.log(x)
    # max(la, 0) + ln(1 + e^-|la|): one exponential and one log1p per point, either branch
    return np.log1p(np.exp(-np.abs(la))) + np.maximum(la, 0.0)


def _log1p_power_per_exponent(x, a):
    r""":math:`\ln(1 + x^a)/a` for :math:`x > 0`: :math:`\max(\ln x, 0) + \ln(1 + e^{-a|\ln x|})/a`,
    finite for any exponent (the product :math:`a\ln x` alone overflows at :math:`a = 10^{308}`)."""
    with np.errstate(divide="ignore", over="ignore"):
        la = np.log(x)
        return np.log1p(np.exp(-np.abs(a * la))) / a + np.maximum(la, 0.0)


def _require(ok, name, admissible, value, detail=None):
    """An ``InvalidParameterError`` naming the first entry where ``ok`` fails (arrays broadcast)."""
    ok = np.asarray(ok)
    if np.all(ok):
        return
    bad = tuple(int(i) for i in np.argwhere(~ok)[0]) if ok.ndim else ()
    value = np.broadcast_to(np.asarray(value, dtype=float), ok.shape)[bad]
    where = f"entry {bad}" if bad else ""
    raise InvalidParameterError(name, admissible, float(value), "; ".join(p for p in (detail, where) if p))


class _ViscosityRange(Rheology):
    """Shared check: ``0 <= infinite_shear_viscosity <= zero_shear_viscosity``."""

    __slots__ = ()

    def __attrs_post_init__(self):
        _require(self.infinite_shear_viscosity <= self.zero_shear_viscosity, "infinite_shear_viscosity",
                 "[0, zero_shear_viscosity]", self.infinite_shear_viscosity)


@attrs.frozen(kw_only=True)
class CarreauYasuda(_ViscosityRange):
    r"""Carreau–Yasuda fluid:
    :math:`\eta = \eta_\infty + (\eta_0 - \eta_\infty)\,[1 + (\lambda\dot\gamma)^a]^{(n-1)/a}`.

    The stress :math:`\eta\dot\gamma` increases for every ``index`` :math:`n > 0`
    (:math:`d\tau/d\dot\gamma \ge \eta_\infty + (\eta_0-\eta_\infty)\,n\,[\dots]^{(n-1)/a - 1}`);
    :math:`a = 2` is the Carreau fluid.
    """

    _examples = ({"zero_shear_viscosity": 0.056, "infinite_shear_viscosity": 0.00345, "relaxation_time": 3.313,
                  "index": 0.3568, "transition": 2.0},
                 {"zero_shear_viscosity": 0.022, "infinite_shear_viscosity": 0.0022, "relaxation_time": 0.110,
                  "index": 0.392, "transition": 0.644},
                 {"zero_shear_viscosity": 1.0, "infinite_shear_viscosity": 0.0, "relaxation_time": 0.1,
                  "index": 1.6, "transition": 1.0})

    zero_shear_viscosity: float = positive(unit="Pa s", doc="zero-shear viscosity eta_0")
    infinite_shear_viscosity: float = nonnegative(unit="Pa s", doc="infinite-shear viscosity eta_inf")
    relaxation_time: float = positive(unit="s", doc="relaxation time lambda")
    index: float = positive(doc="power-law index n")
    transition: float = positive(doc="Yasuda transition parameter a")

    def _stress(self, shear_rate):
        a = self.transition
        x = self.relaxation_time * shear_rate
        shape = np.exp((self.index - 1.0) * _log1p_power_per_exponent(x, a))
        return shear_rate * (self.infinite_shear_viscosity
                             + (self.zero_shear_viscosity - self.infinite_shear_viscosity) * shape)


@attrs.frozen(kw_only=True)
class Carreau(_ViscosityRange):
    r"""Carreau fluid: :math:`\eta = \eta_\infty + (\eta_0 - \eta_\infty)\,[1 + (\lambda\dot\gamma)^2]^{(n-1)/2}`."""

    _examples = ({"zero_shear_viscosity": 0.056, "infinite_shear_viscosity": 0.00345, "relaxation_time": 3.313,
                  "index": 0.3568},
                 {"zero_shear_viscosity": 2.0, "infinite_shear_viscosity": 0.0, "relaxation_time": 10.0,
                  "index": 0.5})

    zero_shear_viscosity: float = positive(unit="Pa s", doc="zero-shear viscosity eta_0")
    infinite_shear_viscosity: float = nonnegative(unit="Pa s", doc="infinite-shear viscosity eta_inf")
    relaxation_time: float = positive(unit="s", doc="relaxation time lambda")
    index: float = positive(doc="power-law index n")

    def _stress(self, shear_rate):
        x = self.relaxation_time * shear_rate
        shape = np.exp(0.5 * (self.index - 1.0) * _log1p_power(x, 2.0))
        return shear_rate * (self.infinite_shear_viscosity
                             + (self.zero_shear_viscosity - self.infinite_shear_viscosity) * shape)


@attrs.frozen(kw_only=True)
class Cross(_ViscosityRange):
    r"""Cross fluid: :math:`\eta = \eta_\infty + (\eta_0 - \eta_\infty)/[1 + (\lambda\dot\gamma)^m]`.

    Its stress increases with the shear rate, as a fluid's must, when :math:`m < 1`, or when
    :math:`\eta_\infty > (\eta_0 - \eta_\infty)(m-1)^2/(4m)` for :math:`m \ge 1` (the minimum of
    :math:`d\tau/d\dot\gamma` is :math:`\eta_\infty - (\eta_0-\eta_\infty)(m-1)^2/(4m)`); other
    parameters are rejected.
    """

    _examples = ({"zero_shear_viscosity": 0.056, "infinite_shear_viscosity": 0.00345, "relaxation_time": 1.007,
                  "exponent": 1.028},
                 {"zero_shear_viscosity": 1.0, "infinite_shear_viscosity": 0.0, "relaxation_time": 0.5,
                  "exponent": 0.6})

    zero_shear_viscosity: float = positive(unit="Pa s", doc="zero-shear viscosity eta_0")
    infinite_shear_viscosity: float = nonnegative(unit="Pa s", doc="infinite-shear viscosity eta_inf")
    relaxation_time: float = positive(unit="s", doc="relaxation time lambda")
    exponent: float = positive(doc="Cross exponent m")

    def __attrs_post_init__(self):
        super().__attrs_post_init__()
        m, e0, einf = self.exponent, self.zero_shear_viscosity, self.infinite_shear_viscosity
        # (m - 1)^2 / (4m) as (m - 1) ((m - 1)/(4m)): no square that overflows at m = 1e300
        _require((m < 1.0) | (einf > (e0 - einf) * (m - 1.0) * (0.25 * ((m - 1.0) / m))), "exponent",
                 "(0, 1), or [1, inf) with infinite_shear_viscosity > "
                 "(zero_shear_viscosity - infinite_shear_viscosity) (m - 1)^2 / (4 m)", m,
                 "the shear stress would not increase with the shear rate")

    def _stress(self, shear_rate):
        x = self.relaxation_time * shear_rate
        return shear_rate * (self.infinite_shear_viscosity + (self.zero_shear_viscosity - self.infinite_shear_viscosity)
                             * np.exp(-_log1p_power(x, self.exponent)))


@attrs.frozen(kw_only=True)
class Ellis(Rheology):
    r"""Ellis fluid: :math:`\dot\gamma = \frac{\tau}{\eta_0}\left[1 + (\tau/\tau_{1/2})^{\alpha-1}\right]`.

    :math:`\tau_{1/2}` is the stress at which the apparent viscosity is :math:`\eta_0/2`;
    :math:`\alpha > 1` thins. Closed forms: apparent wall shear rate
    :math:`\Gamma = \frac{\tau_w}{\eta_0}\left[1 + \frac{4}{\alpha+3}(\tau_w/\tau_{1/2})^{\alpha-1}\right]`,
    velocity :math:`v = \frac{G}{4\eta_0}(R^2 - r^2) + \frac{(G/2)^\alpha}{(\alpha+1)\eta_0\tau_{1/2}^{\alpha-1}}
    (R^{\alpha+1} - r^{\alpha+1})`.
    """

    _examples = ({"zero_shear_viscosity": 0.1, "half_stress": 1.0, "exponent": 2.5},
                 {"zero_shear_viscosity": 0.056, "half_stress": 0.05, "exponent": 1.7})

    zero_shear_viscosity: float = positive(unit="Pa s", doc="zero-shear viscosity eta_0")
    half_stress: float = positive(unit="Pa", doc="stress tau_1/2 at which the viscosity halves")
    exponent: float = positive(doc="Ellis exponent alpha (> 1 thins)")

    def _shear_rate(self, stress):
        a = self.exponent
        return stress / self.zero_shear_viscosity * (1.0 + (stress / self.half_stress) ** (a - 1.0))

    def _apparent_shear_rate(self, wall_stress, excess=None):
        a = self.exponent
        t = np.asarray(wall_stress, dtype=float)
        return t / self.zero_shear_viscosity * (1.0 + 4.0 / (a + 3.0) * (t / self.half_stress) ** (a - 1.0))

    def _velocity(self, r, radius, pressure_gradient):
        # in the wall stress tau_w = G R/2 and r/R <= 1 only: v = (tau_w/eta_0)(R - r)(1 + r/R)/2
        # + R tau_1/2/((a+1) eta_0) (tau_w/tau_1/2)^a (1 - (r/R)^(a+1)), the latter without
        # cancellation near the wall; no power of R, G or tau_1/2 alone (each leaves the doubles
        # long before v does)
        a, eta0, half = self.exponent, self.zero_shear_viscosity, self.half_stress
        tau_w = 0.5 * pressure_gradient * radius
        newtonian = 0.5 * (tau_w / eta0) * (radius - r) * (1.0 + r / radius)
        with np.errstate(divide="ignore"):
            shell = -np.expm1((a + 1.0) * np.log(r / radius))
        return newtonian + radius * (half / ((a + 1.0) * eta0)) * (tau_w / half) ** a * shell
