r"""The rheology contract: a generalized Newtonian fluid in simple shear.

A subclass implements ``_stress(shear_rate)`` *or* ``_shear_rate(stress)`` (for
positive arguments). The base class derives the inverse, the apparent viscosity
and, from the Rabinowitsch–Mooney integral with :math:`\tau = G r/2`,

.. math::

    q(R, G) = \frac{\pi R^3}{\tau_w^3}\int_0^{\tau_w} \tau^2\,\dot\gamma(\tau)\,d\tau,
    \qquad \tau_w = \frac{G R}{2},

the tube flow function, its inverse ``pressure_gradient(q, R)`` and the velocity
profile :math:`v(r) = \int_r^R \dot\gamma(G\rho/2)\,d\rho`.

A *separable* rheology (Newtonian, power law) has
:math:`G(q, R) = \phi(q)\,\psi(R)`; it sets ``separable = True`` and implements
``_flow_factor`` (:math:`\phi`), ``_flow_factor_inverse`` and ``_radius_factor``
(:math:`\psi`). Couplers then reuse one integral for a whole flow curve.

A *yield-stress* fluid (Bingham, Herschel–Bulkley, Casson, ...) has a field
``yield_stress`` :math:`\tau_y > 0`: ``_shear_rate`` is 0 for :math:`\tau \le \tau_y`
and ``_stress(shear_rate)`` tends to :math:`\tau_y` as the shear rate tends to 0. The
generic paths integrate only over the yielded region: no flow while the wall stress
:math:`GR/2 \le \tau_y`, a plug :math:`r < 2\tau_y/G` in the velocity profile, and
:math:`G(q, R) \to 2\tau_y/R` (the yield gradient) as :math:`q \to 0^+`.
"""

from __future__ import annotations

import abc
import math
from typing import ClassVar

import numpy as np
from scipy.optimize import elementwise

from .._numerics import as_output
from .._validation import as_array
from ..errors import InvalidParameterError
from ._flow_table import _T, _W, flow_table

__all__ = ["Rheology"]

_TOL = dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300)


def _overrides(obj, name) -> bool:
    return getattr(type(obj), name) is not getattr(Rheology, name)


class Rheology(abc.ABC):
    r"""Abstract base of every rheology (see the module docstring for the contract).

    Hooks (arrays of positive arguments; implement one of the first two, override the
    others for speed or accuracy):

    ===============================  ======================================================================
    hook (arguments)                 default
    ===============================  ======================================================================
    ``_stress(shear_rate)``          natural hook, or the inverse of ``_shear_rate`` (a root solve)
    ``_shear_rate(stress)``          natural hook, or the inverse of ``_stress``
    ``_apparent_shear_rate``         ``(wall_stress, excess=None)``: :math:`\Gamma = 4q/(\pi R^3)` by the
                                     Rabinowitsch–Mooney integral (a fixed rule graded toward zero stress)
    ``_flow_rate``                   ``(radius, pressure_gradient)``: :math:`\pi R^3\Gamma(GR/2)/4`
    ``_pressure_gradient``           ``(flow_rate, radius)``: the inverse, from a cached Chebyshev table of
                                     :math:`\ln\Gamma`
    ``_velocity``                    ``(r, radius, pressure_gradient)``:
                                     :math:`\int_r^R \dot\gamma(G\rho/2)\,d\rho` by quadrature
    ``_flow_factor``                 separable rheologies only: :math:`\phi(q)` in :math:`G = \phi(q)\psi(R)`,
    ``_flow_factor_inverse``         its inverse,
    ``_radius_factor``               and :math:`\psi(R)`
    ===============================  ======================================================================

    Class attributes: ``separable``, ``radius_exponent`` (:math:`k` with
    :math:`\psi(R) = R^{-k}`, for power-law-like fluids: enables the ``closed-form``
    coupler; None otherwise), ``yield_stress`` (0 unless the fluid declares a
    ``yield_stress`` field) and ``_examples`` (parameter sets for the contract suites).
    """

    __slots__ = ()

    #: True when ``pressure_gradient(q, R) = phi(q) * psi(R)``.
    separable: ClassVar[bool] = False
    #: :math:`k` with :math:`G(q, R) = \phi(q) R^{-k}` (power law: :math:`3n+1`); None if not of that form.
    radius_exponent = None
    #: The yield stress (Pa); a yield-stress fluid declares it as a field.
    yield_stress = 0.0
    #: Example parameter sets (keyword dicts) run through the contract suites of :mod:`tubefsi.testing`.
    _examples: ClassVar[tuple] = ()

    # ------------------------------------------------------------------ public API
    def stress(self, shear_rate):
        """Shear stress (Pa) at shear rate ``shear_rate`` (1/s, >= 0)."""
        g = as_array("shear_rate", shear_rate, "[0, inf)", lambda a: a >= 0)
        return as_output(np.where(g == 0, 0.0, self._stress(np.where(g == 0, 1.0, g))), np.ndim(shear_rate) == 0)

    def shear_rate(self, stress):
        """Shear rate (1/s) at shear stress ``stress`` (Pa, >= 0)."""
        t = as_array("stress", stress, "[0, inf)", lambda a: a >= 0)
        return as_output(np.where(t == 0, 0.0, self._shear_rate(np.where(t == 0, 1.0, t))), np.ndim(stress) == 0)

    def apparent_viscosity(self, shear_rate):
        r"""Apparent viscosity :math:`\eta = \tau/\dot\gamma` (Pa s), shear rate > 0."""
        g = as_array("shear_rate", shear_rate, "(0, inf)", lambda a: a > 0)
        return as_output(self._stress(g) / g, np.ndim(shear_rate) == 0)

    def flow_rate(self, radius, pressure_gradient):
        r"""Flow rate :math:`q(R, G)` (m^3/s) in a rigid tube of radius ``radius`` (m)
        under pressure gradient :math:`G = -dp/dz` (Pa/m)."""
        r = as_array("radius", radius, "(0, inf)", lambda a: a > 0)
        g = as_array("pressure_gradient", pressure_gradient, "[0, inf)", lambda a: a >= 0)
        r, g = np.broadcast_arrays(r, g)
        out = np.zeros(r.shape)
        pos = g > 0
        out[pos] = self._flow_rate(r[pos], g[pos])
        return as_output(out, np.ndim(radius) == 0 and np.ndim(pressure_gradient) == 0)

    def pressure_gradient(self, flow_rate, radius):
        r"""Pressure gradient :math:`G(q, R) = -dp/dz` (Pa/m) that drives ``flow_rate`` (m^3/s)."""
        q = as_array("flow_rate", flow_rate, "[0, inf)", lambda a: a >= 0)
        r = as_array("radius", radius, "(0, inf)", lambda a: a > 0)
        q, r = np.broadcast_arrays(q, r)
        out = np.zeros(q.shape)
        pos = q > 0
        out[pos] = self._pressure_gradient(q[pos], r[pos])
        return as_output(out, np.ndim(flow_rate) == 0 and np.ndim(radius) == 0)

    def velocity(self, r, radius, pressure_gradient):
        r"""Axial velocity (m/s) at radial position ``r`` (0 <= r <= radius)."""
        rr = as_array("r", r, "[0, radius]", lambda a: a >= 0)
        big_r = as_array("radius", radius, "(0, inf)", lambda a: a > 0)
        g = as_array("pressure_gradient", pressure_gradient, "[0, inf)", lambda a: a >= 0)
        rr, big_r, g = np.broadcast_arrays(rr, big_r, g)
        if np.any(rr > big_r * (1 + 1e-12)):
            raise _invalid("r", "[0, radius]", rr[rr > big_r].flat[0])
        out = np.zeros(rr.shape)
        pos = g > 0
        out[pos] = self._velocity(np.minimum(rr[pos], big_r[pos]), big_r[pos], g[pos])
        return as_output(out, all(np.ndim(v) == 0 for v in (r, radius, pressure_gradient)))

    # ------------------------------------------------------------------ hooks
    def _stress(self, shear_rate):
        if not _overrides(self, "_shear_rate"):
            raise TypeError(f"{type(self).__name__} must implement _stress or _shear_rate")
        g = np.asarray(shear_rate, dtype=float)

        def f(t, g):
            return self._shear_rate(t) - g

        lo = np.full_like(g, 1e-300)
        b = elementwise.bracket_root(f, lo, np.maximum(g, 1.0), xmin=0.0, args=(g,))
        return elementwise.find_root(f, b.bracket, args=(g,), tolerances=_TOL).x

    def _shear_rate(self, stress):
        if not _overrides(self, "_stress"):
            raise TypeError(f"{type(self).__name__} must implement _stress or _shear_rate")
        t = np.asarray(stress, dtype=float)
        tau_y = float(self.yield_stress)
        flowing = t > tau_y
        tt = np.where(flowing, t, tau_y + 1.0)

        def f(g, t):
            return self._stress(g) - t

        b = elementwise.bracket_root(f, np.full_like(tt, 1e-300), np.maximum(tt, 1.0), xmin=0.0, args=(tt,))
        return np.where(flowing, elementwise.find_root(f, b.bracket, args=(tt,), tolerances=_TOL).x, 0.0)

    def _flow_rate(self, radius, pressure_gradient):
        if self.separable:
            return self._flow_factor_inverse(pressure_gradient / self._radius_factor(radius))
        return 0.25 * math.pi * radius**3 * self._apparent_shear_rate(0.5 * pressure_gradient * radius)

    def _rabinowitsch_mooney(self, radius, pressure_gradient):
        """The generic flow function (quadrature), whatever the subclass overrides."""
        return 0.25 * math.pi * radius**3 * Rheology._apparent_shear_rate(self, 0.5 * pressure_gradient * radius)

    def _apparent_shear_rate(self, wall_stress, excess=None):
        r"""Apparent wall shear rate :math:`\Gamma = 4q/(\pi R^3)` at wall stress :math:`\tau_w`.

        ``excess``, if given, is :math:`\tau_w - \tau_y` computed by the caller without
        cancellation (the flow table passes it): near the yield point the flow depends on it,
        not on :math:`\tau_w`. Overrides must accept it.

        :math:`\Gamma = 4\int_0^1 t^2\dot\gamma(\tau_w t)\,dt` (a fixed rule graded toward t = 0,
        ``_flow_table.graded_rule``) when the shear rate is natural; else, integrating by parts
        in the shear rate,
        :math:`\Gamma = \tfrac43\dot\gamma_w\left[1 - \int_0^1 (\tau(\dot\gamma_w t)/\tau_w)^3 dt\right]`.
        With a yield stress the first rule runs over the yielded part
        :math:`\tau_y/\tau_w < t < 1` only (0 when :math:`\tau_w \le \tau_y`). Closed forms
        (Buckingham–Reiner for Bingham, ...) may override it.
        """
        tau_w = np.asarray(wall_stress, dtype=float)
        tau_y = float(self.yield_stress)
        if _overrides(self, "_shear_rate"):
            if tau_y == 0.0:
                return 4.0 * (self._shear_rate(tau_w[..., None] * _T) * _T * _T) @ _W
            excess = np.maximum(tau_w - tau_y, 0.0) if excess is None else np.asarray(excess, dtype=float)
            tau = tau_y + excess[..., None] * _T           # the yielded stresses, tau_y .. tau_w
            safe_w = np.where(excess > 0, tau_w, 1.0)
            mean = (self._shear_rate(np.where(excess[..., None] > 0, tau, 2.0 * tau_y + 1.0)) * tau * tau) @ _W
            return np.where(excess > 0, 4.0 * excess * mean / safe_w**3, 0.0)
        rate_w = self._shear_rate(tau_w)
        ratio = self._stress(rate_w[..., None] * _T) / tau_w[..., None]
        return (4.0 / 3.0) * rate_w * (1.0 - (ratio**3) @ _W)

    def _pressure_gradient(self, flow_rate, radius):
        r""":math:`G(q, R)`; at ``q = 0`` the limit :math:`q \to 0^+`: 0, or the yield gradient
        :math:`2\tau_y/R` of a yield-stress fluid (non-separable rheologies)."""
        if self.separable:
            return self._flow_factor(flow_rate) * self._radius_factor(radius)
        return 2.0 * flow_table(self).wall_stress(4.0 * flow_rate / (math.pi * radius**3)) / radius

    def _velocity(self, r, radius, pressure_gradient):
        return self._velocity_generic(r, radius, pressure_gradient)

    def _velocity_generic(self, r, radius, pressure_gradient):
        r""":math:`v(r) = \int_r^R \dot\gamma(G\rho/2)\,d\rho` by the same graded rule; for a
        stress-natural law, by parts: :math:`\frac{2}{G}\big([\tau\dot\gamma] - \int \tau\,d\dot\gamma\big)`."""
        r, radius, g = (np.asarray(x, dtype=float) for x in (r, radius, pressure_gradient))
        if _overrides(self, "_shear_rate"):
            tau_y = float(self.yield_stress)
            if tau_y > 0.0:  # integrate over the yielded annulus only: the plug moves rigidly
                r = np.maximum(r, np.minimum(radius, 2.0 * tau_y / g))
            rho = r[..., None] + (radius - r)[..., None] * _T
            return (radius - r) * (self._shear_rate(0.5 * g[..., None] * rho) @ _W)
        tau_r, tau_w = 0.5 * g * r, 0.5 * g * radius
        rate_r = np.where(tau_r > 0, self._shear_rate(np.where(tau_r > 0, tau_r, 1.0)), 0.0)
        rate_w = self._shear_rate(tau_w)
        nodes = rate_r[..., None] + (rate_w - rate_r)[..., None] * _T
        mean_stress = self._stress(np.maximum(nodes, 1e-300)) @ _W
        return (2.0 / g) * (tau_w * rate_w - tau_r * rate_r - (rate_w - rate_r) * mean_stress)

    # separable rheologies implement these three
    def _flow_factor(self, flow_rate):
        raise NotImplementedError

    def _flow_factor_inverse(self, factor):
        raise NotImplementedError

    def _radius_factor(self, radius):
        raise NotImplementedError


def _invalid(name, admissible, value):
    return InvalidParameterError(name, admissible, value)
