r"""Tube laws that may stop increasing: the first pressure peak (a limit point).

A plane-strain tube of a material that softens in the hoop direction (an Ogden material with
small exponents, a Yeoh material with :math:`c_2 < 0`, ...) can have a tube law
:math:`P(\lambda)` that rises to a maximum and falls, as a balloon does. Uniform inflation
is stable only up to that first peak: there the tube bulges. tubefsi then treats the peak
stretch as the wall's maximum stretch and the peak pressure as its limit pressure, so
``stretch(p)`` raises ``NoSteadyStateError`` above it and a shear-thinning flow has a
maximum flow rate. Laws that keep increasing get the limit pressure of their asymptote.
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from tubefsi.numerics.cache import TABLES, instance_values

__all__ = ["LimitPoint"]

#: hoop strains scanned for the first peak (the stiffness is evaluated in closed form)
_SCAN = np.geomspace(1e-4, 1e4, 1601)


def first_peak(wall, tb: float) -> tuple[float, float]:
    """``(stretch, pressure)`` at the first zero of ``dP/dlam``, or ``(inf, nan)`` if there is none:
    kept in tubefsi's one cache, keyed by the wall's class (weakly) and values (never the wall)."""
    values = instance_values(wall)
    if values is None:
        return _first_peak(wall, tb)
    return TABLES.get(("first peak", weakref.ref(type(wall)), values, tb), lambda: _first_peak(wall, tb))


def _first_peak(wall, tb: float) -> tuple[float, float]:
    lam = 1.0 + _SCAN
    with np.errstate(over="ignore", invalid="ignore"):
        slope = wall._stiffness(lam, tb)
    # the scan ends where the law leaves the doubles (a slope of inf or NaN: a huge exponent): a
    # peak beyond it is beyond double precision too, and the root finder needs finite ends
    end = np.flatnonzero(~np.isfinite(slope))
    bad = np.flatnonzero(slope[:end[0] if end.size else lam.size] <= 0)
    if bad.size == 0:
        return math.inf, math.nan
    from scipy import optimize   # here, not at import: listing the models must not load SciPy

    i = bad[0]
    lo = 1.0 if i == 0 else lam[i - 1]
    peak = optimize.brentq(lambda s: float(wall._stiffness(np.asarray(s), tb)), lo, lam[i],
                           xtol=1e-15, rtol=4 * np.finfo(float).eps)
    # a hair above the computed peak pressure, so that no rounded P(lam) reaches it
    return peak, float(wall._pressure_at_strain(np.asarray(peak - 1.0), tb)) * (1.0 + 1e-14)


class LimitPoint:
    """Mixin for a material class: maximum stretch and limit pressure from the first peak.

    The material gives ``_asymptote(tb, theory)`` (the pressure as the stretch tends to
    infinity: ``inf`` for a law that grows without bound) and ``_asymptotic_decay(tb, theory)``
    (``kappa`` with :math:`P' \\sim \\lambda^{-\\kappa}`, where the asymptote is finite).
    ``theory`` is ``"reference"``, ``"current"`` (thin walls) or ``"thick"``.

    The peak is found per parameter set and thickness (a scan), so these walls do not broadcast
    their parameters (``broadcasts = False``: tubefsi solves each distinct set separately); an
    array of thicknesses is scanned once per distinct value.
    """

    __slots__ = ()

    broadcasts = False

    def _theory(self) -> str:
        return getattr(self, "thickness_convention", "thick")

    def _peaks(self, tb):
        """``(stretch, pressure)`` of the first peak per thickness (arrays for an array ``tb``)."""
        tb = np.asarray(tb, dtype=float)
        if tb.ndim == 0:
            return first_peak(self, float(tb))
        values, inverse = np.unique(tb.ravel(), return_inverse=True)
        peaks = np.array([first_peak(self, float(t)) for t in values])
        return peaks[inverse, 0].reshape(tb.shape), peaks[inverse, 1].reshape(tb.shape)

    def _max_stretch(self, tb):
        return self._peaks(tb)[0]

    def _limit_pressure(self, tb):
        peak, pressure = self._peaks(tb)
        return np.where(np.isfinite(peak), pressure, self._asymptote(tb, self._theory()))

    def _stiffness_decay_exponent(self, tb):
        return self._asymptotic_decay(tb, self._theory())
