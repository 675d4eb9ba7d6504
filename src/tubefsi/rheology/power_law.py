r"""Power-law (Ostwald–de Waele) fluid: :math:`\tau = m\,|\dot\gamma|^{n-1}\dot\gamma`.

Tube flow: :math:`q = \frac{\pi n}{3n+1}\left(\frac{G}{2m}\right)^{1/n} R^{3+1/n}`, hence
:math:`G(q, R) = 2m\left[\frac{(3n+1)q}{\pi n}\right]^n R^{-(3n+1)}` (separable).
Velocity: :math:`v(r) = \frac{n}{n+1}\left(\frac{G}{2m}\right)^{1/n}(R^{1+1/n} - r^{1+1/n})`.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..errors import InvalidParameterError
from ..fields import positive
from .base import Rheology

__all__ = ["PowerLaw", "FactorRangeError"]


_TINY = float(np.finfo(float).tiny)
_HUGE = 1.0 / _TINY


class FactorRangeError(InvalidParameterError):
    r"""A factor of the separated form :math:`G = \phi(q)\,\psi(R)` leaves the normal doubles
    (a large index: :math:`R^{-(3n+1)}` overflows at R = 1e-4 m for n >= 26) where :math:`G` itself
    may not: :func:`tubefsi.solve` then solves the problem again in units of the tube's radius
    (``docs/verification.md``, "Fuzzing")."""


def _representable(value, load, name, index):
    """Raise unless ``value`` (a factor of G) is a normal double wherever ``load > 0``: a factor that
    underflows or overflows would make the pressure drop 0, NaN or inf (``docs/verification.md``,
    "Fuzzing")."""
    if type(value) is float and type(load) is float and (_TINY <= value < math.inf or not load > 0.0):
        return                                   # the scalar path: no NumPy round trip
    with np.errstate(invalid="ignore"):
        bad = (np.asarray(load) > 0) & ~((np.asarray(value) >= _TINY) & (np.asarray(value) < math.inf))
    if np.any(bad):
        q = float(np.ravel(np.broadcast_to(load, np.shape(bad)))[np.argmax(np.ravel(bad))])
        what = f"2 m [(3n+1) q / (pi n)]^n, n = {index!r}"
        raise FactorRangeError(name, f"values for which {what} is within double precision "
                                    f"[{_TINY:.3g}, {_HUGE:.3g}]", q, "the pressure gradient would underflow "
                                    "or overflow")


class _PowerLawForms(Rheology):
    """Closed forms in terms of ``self.consistency`` and ``self.index``."""

    __slots__ = ()
    separable = True
    _gradient_scales = ("consistency", "viscosity")      # G = 2m [...]^n R^-(3n+1): proportional to m

    def _stress(self, shear_rate):
        return self.consistency * shear_rate**self.index

    def _shear_rate(self, stress):
        return (stress / self.consistency) ** (1.0 / self.index)

    def _flow_factor(self, flow_rate):
        n = self.index
        try:
            out = 2.0 * self.consistency * ((3.0 * n + 1.0) * flow_rate / (math.pi * n)) ** n
        except OverflowError:
            out = math.inf
        _representable(out, flow_rate, "flow_rate", n)
        return out

    def _log_flow_factor(self, flow_rate):
        # ln 2m + n ln((3n+1)/(pi n)) + n ln q: a log and a multiply-add, no power; finite wherever
        # q > 0, even where phi itself would leave double range
        n = self.index
        if type(flow_rate) is float and type(n) is float and type(self.consistency) is float and flow_rate > 0.0:
            return math.log(2.0 * self.consistency) + n * math.log((3.0 * n + 1.0) / (math.pi * n)) \
                + n * math.log(flow_rate)                    # (one point: the same operations in floats)
        with np.errstate(divide="ignore"):
            shift = np.log(2.0 * self.consistency) + n * np.log((3.0 * n + 1.0) / (math.pi * n))
            out = np.log(flow_rate)
            if type(n) is float and type(out) is np.ndarray:     # a curve: in place, one array
                out *= n
                out += shift
                return out
            return out * n + shift

    def _flow_factor_inverse(self, factor):
        n = self.index
        # a factor below the normal doubles (a tiny drop, a J that underflows) has lost its digits
        if (0.0 < factor < _TINY) if type(factor) is float else np.any((factor > 0) & (factor < _TINY)):
            low = float(np.min(np.where(np.asarray(factor) > 0, factor, math.inf)))
            raise FactorRangeError("pressure_drop", f"drops whose flow factor J/L = 2 m [(3n+1) q / (pi n)]^n "
                                   f"is a normal double (>= {_TINY:.3g})", None,
                                   f"J/L = {low:.3g} underflows (n = {_text(n)}): the flow rate would lose its digits")
        return math.pi * n / (3.0 * n + 1.0) * (factor / (2.0 * self.consistency)) ** (1.0 / n)

    def _radius_factor(self, radius):
        try:
            out = radius ** -(3.0 * self.index + 1.0)
        except OverflowError:
            out = math.inf
        with np.errstate(invalid="ignore"):
            big = out > _HUGE                    # its reciprocal (the engine divides by it) underflows
        if np.any(big):
            r = float(np.ravel(np.broadcast_to(radius, np.shape(out)))[np.argmax(np.ravel(big))])
            raise FactorRangeError(
                "index", f"(0, {(-math.log(_TINY) / abs(math.log(r)) - 1.0) / 3.0:.6g}) at radius {r:g} m",
                self.index, "R^-(3n+1) leaves the range of double precision")
        return out

    def _pressure_gradient(self, flow_rate, radius):
        # G = (2m/R) [(3n+1) q / (pi n R^3)]^n: the apparent shear rate first, so that G is a
        # double wherever it is one, whatever phi(q) and R^-(3n+1) are alone (n >= 26)
        n = self.index
        try:
            return 2.0 * self.consistency / radius * ((3.0 * n + 1.0) * flow_rate / (math.pi * n * radius**3)) ** n
        except OverflowError:
            return math.inf

    def _flow_rate(self, radius, pressure_gradient):
        n = self.index
        return math.pi * n / (3.0 * n + 1.0) * radius**3 * (pressure_gradient * radius / (2.0 * self.consistency)) ** (
            1.0 / n)

    @property
    def radius_exponent(self) -> float:
        """:math:`3n+1`: :math:`G \\propto R^{-(3n+1)}` at fixed flow rate."""
        return 3.0 * self.index + 1.0

    def _flow_index(self, flow_rate, radius):
        return np.zeros(np.broadcast_shapes(np.shape(flow_rate), np.shape(radius))) + self.index

    def _log_gradient_derivative(self, parameter, flow_rate, radius):
        # ln G = ln 2m + n ln(Gamma (3n+1)/(4n)) - ln R... with Gamma = 4q/(pi R^3):
        # d/dm = 1/m; d/dn = ln(Gamma (3n+1)/(4n)) - 1/(3n+1)
        shape = np.broadcast_shapes(np.shape(flow_rate), np.shape(radius))
        if parameter in ("consistency", "viscosity"):
            return np.zeros(shape) + 1.0 / self.consistency
        if parameter == "index":
            n = self.index
            rate = 4.0 * np.asarray(flow_rate) / (math.pi * np.asarray(radius) ** 3)
            return np.log(rate * (3.0 * n + 1.0) / (4.0 * n)) - 1.0 / (3.0 * n + 1.0) + np.zeros(shape)
        return super()._log_gradient_derivative(parameter, flow_rate, radius)

    def _velocity(self, r, radius, pressure_gradient):
        # v = n/(n+1) R (tau_w/m)^(1/n) (1 - (r/R)^k), tau_w = G R/2, k = 1 + 1/n: the powers of the
        # wall stress and of r/R (<= 1) only, so a double wherever v is (R^k alone overflows at
        # R = 1e300, (G/2m)^(1/n) at G = 1e300 and n < 1)
        n = self.index
        k = 1.0 + 1.0 / n
        with np.errstate(divide="ignore"):
            shell = -np.expm1(k * np.log(r / radius))
        return n / (n + 1.0) * radius * (0.5 * pressure_gradient * radius / self.consistency) ** (1.0 / n) * shell


@attrs.frozen(kw_only=True)
class PowerLaw(_PowerLawForms):
    r"""Power-law fluid, :math:`\tau = m\dot\gamma^n`: shear-thinning for :math:`n<1`."""

    _examples = ({"consistency": 0.017, "index": 0.7}, {"consistency": 1.0, "index": 2 / 3},
                 {"consistency": 0.5, "index": 1.5}, {"consistency": 1e-3, "index": 1.0})

    consistency: float = positive(unit="Pa s^n", doc="consistency m")
    index: float = positive(doc="power-law index n")


def _text(value) -> str:
    """A number or an array in a message, as plain numbers (``0.7``, not ``np.float64(0.7)``)."""
    return f"{float(value):.6g}" if np.ndim(value) == 0 else np.array2string(np.asarray(value, dtype=float), precision=6)
