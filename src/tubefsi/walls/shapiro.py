r"""The Shapiro collapsible tube law (Shapiro 1977, *J. Biomech. Eng.* 99, 126–147).

A thin tube under external pressure collapses: past its buckling pressure the cross-section
flattens, and the area falls steeply with the transmural pressure. Shapiro's algebraic law
relates the transmural pressure to the area ratio :math:`\alpha = A/A_0 = (R/a)^2 = \lambda^2`
(:math:`R` the radius of the circle of the same area, the hydraulic picture lubrication uses):

.. math::

    p = K_p\,(\alpha^{n_1} - \alpha^{-n_2}), \qquad \alpha = \lambda^2,

with the tube-law stiffness :math:`K_p` (Pa) and the exponents :math:`n_1` (inflation; 10 for
veins) and :math:`n_2` (collapse; 3/2 fits the collapse of thin elastic tubes). It holds for
every transmural pressure: :math:`p \to -\infty` as :math:`\alpha \to 0`. In
:math:`x = \ln\lambda`, :math:`p/K_p = \mathrm{expm1}(2n_1x) - \mathrm{expm1}(-2n_2x)` (no
cancellation at small strain) and :math:`P'(\lambda) = K_p(2n_1\lambda^{2n_1-1} + 2n_2\lambda^{-2n_2-1})`.
The law does not depend on :math:`\bar t`. With :math:`s P'(s) = K_p(2n_1 s^{2n_1} + 2n_2 s^{-2n_2})`
the separated integral of a power-law fluid is a sum of two exponentials in the log-stretch
(``docs/walls_beyond.md``, section "The Shapiro tube law").
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..numerics.kernels import expm1_ratio
from ..numerics.roots import solve_signed
from ..fields import positive
from .base import WallModel

__all__ = ["Shapiro"]


@attrs.frozen(kw_only=True)
class Shapiro(WallModel):
    r"""Collapsible tube, :math:`p = K_p(\alpha^{n_1} - \alpha^{-n_2})`, :math:`\alpha = \lambda^2`
    (see the module docstring); usable at negative and positive transmural pressure.

    The stiffness :math:`K_p` is the parameter ``tube_stiffness`` (``stiffness`` is the tube-law
    slope :meth:`~tubefsi.walls.WallModel.stiffness` of every wall)."""

    closed_form_integral = True
    _examples = ({"tube_stiffness": 50.0}, {"tube_stiffness": 2e3, "n1": 4.0, "n2": 0.75})

    tube_stiffness: float = positive(unit="Pa", doc="tube-law stiffness K_p")
    n1: float = positive(default=10.0, doc="inflation exponent n1 (of the area ratio)")
    n2: float = positive(default=1.5, doc="collapse exponent n2 (of the area ratio)")

    def _pressure_scale(self):
        return self.tube_stiffness

    def _shape_key(self):
        return (self.n1, self.n2)

    def _unit_wall(self):
        return attrs.evolve(self, tube_stiffness=1.0)

    def _pressure_at_strain(self, strain, tb):
        x = np.log1p(np.asarray(strain, dtype=float))
        return self.tube_stiffness * (np.expm1(2.0 * self.n1 * x) - np.expm1(-2.0 * self.n2 * x))

    def _stiffness(self, stretch, tb):
        s = np.asarray(stretch, dtype=float)
        return self.tube_stiffness * (2.0 * self.n1 * s ** (2.0 * self.n1 - 1.0) + 2.0 * self.n2 * s ** (-2.0 * self.n2 - 1.0))

    def _strain(self, pressure, tb):
        # Newton on ln|p/K_p| in x = ln(lambda) (exponential on either branch), per unit stiffness
        shape = np.broadcast_shapes(np.shape(pressure), np.shape(self.tube_stiffness), np.shape(self.n1),
                                    np.shape(self.n2))
        k = np.broadcast_to(np.asarray(pressure, dtype=float) / self.tube_stiffness, shape).ravel()
        a = np.broadcast_to(2.0 * np.asarray(self.n1, dtype=float), shape).ravel()
        b = np.broadcast_to(2.0 * np.asarray(self.n2, dtype=float), shape).ravel()
        guess = np.log1p(np.abs(k)) / np.where(k > 0, a, b)      # the dominant term alone
        x, _ = solve_signed(lambda x, i: np.expm1(a[i] * x) - np.expm1(-b[i] * x),
                            lambda x, i: a[i] * np.exp(a[i] * x) + b[i] * np.exp(-b[i] * x),
                            k, guess=guess, log=True, max_step=2.0)
        return np.expm1(x).reshape(shape)

    def _min_pressure(self, tb):
        return -math.inf

    def _min_stretch(self, tb):
        return 0.0

    def _stiffness_decay_exponent(self, tb):
        return 1.0 - 2.0 * self.n1

    def _power_law_integral(self, log_ratio, outlet_stretch, exponent, tb):
        k, s0, a, b = exponent, outlet_stretch, 2.0 * self.n1, 2.0 * self.n2
        return self.tube_stiffness * (a * s0 ** (k + a) * expm1_ratio(k + a, log_ratio)
                                 + b * s0 ** (k - b) * expm1_ratio(k - b, log_ratio))
