r"""Yield-stress (viscoplastic) fluids: Bingham, Casson, Herschel–Bulkley.

Each has a field ``yield_stress`` :math:`\tau_y`, which tubefsi's generic path reads: no flow
while the wall stress :math:`\tau_w = GR/2` does not exceed :math:`\tau_y` (so a tube carries
nothing below the yield pressure gradient :math:`2\tau_y/R`), a rigid plug
:math:`r < r_p = 2\tau_y/G` in the velocity profile, and :math:`G(q, R) \to 2\tau_y/R` as
:math:`q \to 0^+`. A pressure-controlled solve returns ``q = 0`` where the pressure drop
cannot yield the fluid all along the tube; a flow-controlled solve at ``q = 0`` returns a
zero pressure drop by convention (the static state is indeterminate), and the *yield
pressure drop* is the limit :math:`q \to 0^+`.

The tube flow functions are elementary and given in closed form, written in the excess
stress :math:`\tau_w - \tau_y` (passed in exactly by tubefsi's flow table as ``excess``) so
that they keep their relative accuracy however close to the yield point; the contract suite
checks them against the generic Rabinowitsch–Mooney quadrature.
"""

from __future__ import annotations

from math import comb

import attrs
import numpy as np
from tubefsi.fields import nonnegative, positive
from tubefsi.rheology import Rheology

__all__ = ["Bingham", "Casson", "HerschelBulkley"]


def _yield(*, doc="yield stress tau_y"):
    return nonnegative(unit="Pa", doc=doc)


def _plug(r, radius, g, tau_y):
    """``max(r, r_p)``: the radius where the yielded region starts (``radius`` if unyielded)."""
    return np.maximum(r, np.minimum(radius, 2.0 * tau_y / g))


def _root_difference(a, b):
    r""":math:`\sqrt a - \sqrt b` for :math:`a \ge b \ge 0` without cancellation (0 at a = b)."""
    den = np.sqrt(a) + np.sqrt(b)
    return np.divide(np.maximum(a - b, 0.0), den, out=np.zeros(np.broadcast_shapes(np.shape(den), np.shape(a))), where=den > 0)


@attrs.frozen(kw_only=True)
class Bingham(Rheology):
    r"""Bingham plastic: :math:`\tau = \tau_y + \mu_p\dot\gamma` once yielded.

    Tube flow (Buckingham–Reiner), with :math:`x = \tau_y/\tau_w`:
    :math:`\Gamma = \frac{\tau_w}{\mu_p}\left(1 - \tfrac43 x + \tfrac13 x^4\right)
    = \frac{(\tau_w - \tau_y)^2 (x^2 + 2x + 3)}{3\mu_p\tau_w}`.
    """

    _examples = ({"yield_stress": 0.005, "plastic_viscosity": 0.0035},
                 {"yield_stress": 20.0, "plastic_viscosity": 0.5})

    yield_stress: float = _yield()
    plastic_viscosity: float = positive(unit="Pa s", doc="plastic viscosity mu_p")

    def _stress(self, shear_rate):
        return self.yield_stress + self.plastic_viscosity * shear_rate

    def _shear_rate(self, stress):
        return np.maximum(stress - self.yield_stress, 0.0) / self.plastic_viscosity

    def _apparent_shear_rate(self, wall_stress, excess=None):
        t = np.asarray(wall_stress, dtype=float)
        excess = np.maximum(t - self.yield_stress, 0.0) if excess is None else excess
        x = self.yield_stress / t
        # excess^2/tau_w as excess (excess/tau_w): no square beyond the doubles
        return excess * (excess / t) * (x * x + 2.0 * x + 3.0) / (3.0 * self.plastic_viscosity)

    def _velocity(self, r, radius, pressure_gradient):
        g = pressure_gradient
        rr = _plug(r, radius, g, self.yield_stress)
        return (radius - rr) * (0.25 * g * (radius + rr) - self.yield_stress) / self.plastic_viscosity


@attrs.frozen(kw_only=True)
class Casson(Rheology):
    r"""Casson fluid: :math:`\sqrt\tau = \sqrt{\tau_y} + \sqrt{\mu_p\dot\gamma}` once yielded.

    With :math:`c = \sqrt{\tau_y}`, :math:`w = \sqrt{\tau_w}` and :math:`e = w - c`, the
    Rabinowitsch–Mooney integral is the positive sum
    :math:`\Gamma = \frac{8}{\mu_p w^6}\sum_{k=0}^{5}\binom5k \frac{c^{5-k} e^{k+3}}{k+3}`
    (:math:`= \frac{\tau_w}{\mu_p}[1 - \tfrac{16}{7}\sqrt x + \tfrac43 x - \tfrac1{21}x^4]`,
    :math:`x = \tau_y/\tau_w`).
    """

    _examples = ({"yield_stress": 0.005, "plastic_viscosity": 0.0035},
                 {"yield_stress": 10.0, "plastic_viscosity": 0.2})

    yield_stress: float = _yield()
    plastic_viscosity: float = positive(unit="Pa s", doc="Casson viscosity mu_p")

    def _stress(self, shear_rate):
        return (np.sqrt(self.yield_stress) + np.sqrt(self.plastic_viscosity * shear_rate)) ** 2

    def _root_excess(self, stress, excess=None):
        """:math:`\\sqrt\\tau - \\sqrt{\\tau_y}` (>= 0), without cancellation (0 at
        :math:`\\tau = \\tau_y = 0`, the Newtonian limit's centreline, where the ratio is 0/0)."""
        excess = np.maximum(stress - self.yield_stress, 0.0) if excess is None else excess
        root_sum = np.sqrt(stress) + np.sqrt(self.yield_stress)
        return np.divide(excess, root_sum, out=np.zeros(np.broadcast_shapes(np.shape(root_sum), np.shape(excess))), where=root_sum > 0)

    def _shear_rate(self, stress):
        return self._root_excess(stress) ** 2 / self.plastic_viscosity

    def _apparent_shear_rate(self, wall_stress, excess=None):
        t = np.asarray(wall_stress, dtype=float)
        # in units of w = sqrt(tau_w) (the sum is homogeneous of degree 8 in c and e): no power of
        # the stress beyond the first, so a double wherever Gamma is one
        w = np.sqrt(t)
        c, e = np.sqrt(self.yield_stress) / w, self._root_excess(t, excess) / w
        total = sum(comb(5, k) * c ** (5 - k) * e ** (k + 3) / (k + 3) for k in range(6))
        return 8.0 * total * t / self.plastic_viscosity

    def _velocity(self, r, radius, pressure_gradient):
        # v = (2/(k mu_p)) [z^4/4 + c z^3/3] between z(r) and z(R), z = sqrt(k rho) - c, k = G/2;
        # in units of sqrt(k) (z = sqrt(k) y, y = sqrt(rho) - c/sqrt(k)), so that no power of the
        # stress is formed: v = (2 gap/mu_p) [k (e + y)(e^2 + y^2)/4 + c sqrt(k) (e^2 + e y + y^2)/3]
        # is a double wherever the velocity is (a wall stress of 1e295 Pa has e^4 beyond the doubles)
        k, c = 0.5 * pressure_gradient, np.sqrt(self.yield_stress)
        rr = _plug(r, radius, pressure_gradient, self.yield_stress)
        with np.errstate(divide="ignore"):
            plug = self.yield_stress / k                                    # the plug radius
        e = _root_difference(radius, plug)                                   # sqrt(R) - c/sqrt(k)
        y = _root_difference(rr, plug)
        gap = (radius - rr) / (np.sqrt(radius) + np.sqrt(rr))               # e - y
        gap = np.where(radius > rr, gap, 0.0)
        quartic = k * ((e + y) * (e * e + y * y)) / 4.0
        cubic = c * np.sqrt(k) * (e * e + e * y + y * y) / 3.0
        return 2.0 * gap * (quartic + cubic) / self.plastic_viscosity


@attrs.frozen(kw_only=True)
class HerschelBulkley(Rheology):
    r"""Herschel–Bulkley fluid: :math:`\tau = \tau_y + K\dot\gamma^n` once yielded.

    With :math:`m = 1/n` and :math:`\Delta = \tau_w - \tau_y`:
    :math:`\Gamma = \frac{4\Delta^{m+1}}{K^m\tau_w^3}\left[\frac{\Delta^2}{m+3}
    + \frac{2\tau_y\Delta}{m+2} + \frac{\tau_y^2}{m+1}\right]`; velocity
    :math:`v = \frac{2}{(m+1)GK^m}\left[\Delta^{m+1} - (\tau(r) - \tau_y)_+^{m+1}\right]`.
    ``yield_stress = 0`` is the power law, ``index = 1`` the Bingham plastic.
    """

    _examples = ({"yield_stress": 0.0175, "consistency": 8.9721e-3, "index": 0.8601},
                 {"yield_stress": 30.0, "consistency": 5.0, "index": 0.4},
                 {"yield_stress": 1.0, "consistency": 0.1, "index": 1.5})

    yield_stress: float = _yield()
    consistency: float = positive(unit="Pa s^n", doc="consistency K")
    index: float = positive(doc="flow index n")

    def _stress(self, shear_rate):
        return self.yield_stress + self.consistency * shear_rate**self.index

    def _shear_rate(self, stress):
        return (np.maximum(stress - self.yield_stress, 0.0) / self.consistency) ** (1.0 / self.index)

    def _apparent_shear_rate(self, wall_stress, excess=None):
        t = np.asarray(wall_stress, dtype=float)
        m, ty = 1.0 / self.index, self.yield_stress
        d = np.maximum(t - ty, 0.0) if excess is None else excess
        # the bracket over tau_w^2, in the shares d/tau_w and tau_y/tau_w: no power of a stress
        # beyond (d/K)^m, so a double wherever Gamma is one
        dt, yt = d / t, ty / t
        bracket = dt * dt / (m + 3.0) + 2.0 * yt * dt / (m + 2.0) + yt * yt / (m + 1.0)
        return 4.0 * (d / self.consistency) ** m * dt * bracket

    def _velocity(self, r, radius, pressure_gradient):
        m, g, ty = 1.0 / self.index, pressure_gradient, self.yield_stress
        rr = _plug(r, radius, g, ty)
        d_wall = 0.5 * g * radius - ty
        # d_wall^(m+1) - d(r)^(m+1) = -d_wall^(m+1) expm1((m+1) ln(d(r)/d_wall)), ln by log1p
        yielded = rr < radius
        frac = np.where(yielded, -0.5 * g * (radius - rr) / np.where(yielded, d_wall, 1.0), 0.0)
        with np.errstate(divide="ignore"):
            log_ratio = np.log1p(np.maximum(frac, -1.0))
        shell = -np.expm1((m + 1.0) * log_ratio)
        # (d_wall/K)^m d_wall / G with d_wall/G <= R/2 divided first: no product beyond the doubles
        d_pos = np.maximum(d_wall, 0.0)
        scale = np.where(yielded, (d_pos / self.consistency) ** m * (d_pos / g), 0.0)
        return 2.0 * scale * shell / (m + 1.0)
