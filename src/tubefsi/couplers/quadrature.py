r"""``quadrature``: any rheology with any wall, by the separated-variables identity.

:math:`J(v) = \int_0^v s P'(s)/G(q, as)\,du` is evaluated by composite
Gauss–Legendre quadrature in the log-stretch :math:`u`, where the integrand of every
built-in pair is analytic in a strip of half-width :math:`\pi/2` about the real axis
(16 nodes per panel of width 2 give full double precision), and the inlet
log-stretch is found by safeguarded Newton iteration. No ODE is integrated. Toward a
wall's maximum stretch the panels are graded geometrically (:meth:`Scene.integrate`).
"""

from __future__ import annotations

import warnings
from typing import ClassVar

import attrs
import numpy as np

from ..errors import AccuracyWarning
from .base import Coupler


def _rel(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    nonzero = b != 0
    return float(np.max(np.abs(a[nonzero] / b[nonzero] - 1.0), initial=0.0))

__all__ = ["Quadrature"]


@attrs.frozen(kw_only=True)
class Quadrature(Coupler):
    """Gauss–Legendre quadrature of the separated identity (any pair)."""

    order: int = attrs.field(default=16, converter=int)
    panel_width: float = attrs.field(default=2.0, converter=float)
    #: A coarser rule than the default (order < 16 or panels wider than 2) is checked
    #: against the default rule, with an AccuracyWarning above 1e-8 relative difference.
    check_error: bool = attrs.field(default=True, converter=bool)

    cost_rank: ClassVar[int] = 10

    @property
    def _coarse(self) -> bool:
        return self.order < 16 or self.panel_width > 2.0

    def max_flow_rate(self, scene):
        # a property of the problem, not of the rule: a coarse rule must not move it
        return (Quadrature() if self._coarse else super()).max_flow_rate(scene)

    def flow_controlled(self, scene, flow_rate):
        state = super().flow_controlled(scene, flow_rate)
        if self._coarse and self.check_error:
            ref = Quadrature().flow_controlled(scene, flow_rate)
            self._warn(max(_rel(state.pressure_drop, ref.pressure_drop), _rel(state.inlet_strain, ref.inlet_strain)))
        return state

    def pressure_controlled(self, scene, pressure_drop):
        state = super().pressure_controlled(scene, pressure_drop)
        if self._coarse and self.check_error:
            self._warn(_rel(state.flow_rate, Quadrature().pressure_controlled(scene, pressure_drop).flow_rate))
        return state

    def _warn(self, error):
        if error > 1e-8:
            warnings.warn(f"Quadrature(order={self.order}, panel_width={self.panel_width:g}): relative "
                          f"difference {error:.2g} from the default rule; use coupler='auto' for full accuracy",
                          AccuracyWarning, stacklevel=4)

    def supports(self, rheology, wall) -> bool:
        return True

    def _J(self, scene, v, q):
        v = np.asarray(v, dtype=float)
        if q is None:
            return scene.integrate(lambda u, idx: scene.integrand(u), v, order=self.order,
                                   panel_width=self.panel_width)
        qflat = np.broadcast_to(np.asarray(q, dtype=float), v.shape).ravel()
        return scene.integrate(lambda u, idx: scene.integrand(u, qflat[idx, None]), v, order=self.order,
                               panel_width=self.panel_width)
