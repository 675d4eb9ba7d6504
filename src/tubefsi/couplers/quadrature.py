r"""``quadrature``: any rheology with any wall, by the separated-variables identity.

:math:`J(v) = \int_0^v s P'(s)/G(q, as)\,du` is evaluated by composite
Gauss–Legendre quadrature in the log-stretch :math:`u`, where the integrand of every
built-in pair is analytic in a strip of half-width :math:`\pi/2` about the real axis
(16 nodes per panel of width 2 give full double precision), and the inlet
log-stretch is found by safeguarded Newton iteration. No ODE is integrated. Toward a
wall's maximum stretch the panels are graded geometrically (:meth:`Scene.integrate`).
"""

from __future__ import annotations

from typing import ClassVar, final

import attrs
import numpy as np

from .separated import SeparatedVariables

__all__ = ["Quadrature"]


@final
@attrs.frozen(kw_only=True)
class Quadrature(SeparatedVariables):
    """Gauss–Legendre quadrature of the separated identity (any pair)."""

    order: int = attrs.field(default=16, converter=int)
    panel_width: float = attrs.field(default=2.0, converter=float)
    #: A coarser rule than the default (order < 16 or panels wider than 2) is checked
    #: against the default rule (:meth:`refined`), with an AccuracyWarning above 1e-8
    #: relative difference.
    check_error: bool = attrs.field(default=True, converter=bool)

    cost_rank: ClassVar[int] = 10

    @property
    def _coarse(self) -> bool:
        return self.order < 16 or self.panel_width > 2.0

    def max_flow_rate(self, scene):
        # a property of the problem, not of the rule: a coarse rule must not move it
        return (Quadrature() if self._coarse else super()).max_flow_rate(scene)

    def refined(self):
        """The default rule, against which a coarser rule is checked (``check_error``)."""
        return Quadrature() if self._coarse and self.check_error else None

    def describe(self) -> str:
        return f"Quadrature(order={self.order}, panel_width={self.panel_width:g})"

    def supports(self, rheology, wall) -> bool:
        return True

    def _J(self, scene, v, q):
        v = np.asarray(v, dtype=float)
        if q is None:
            return self.integrate(scene, lambda u, idx: self.integrand(scene, u), v, order=self.order,
                                  panel_width=self.panel_width)
        qflat = np.broadcast_to(np.asarray(q, dtype=float), v.shape).ravel()
        return self.integrate(scene, lambda u, idx: self.integrand(scene, u, qflat[idx, None]), v,
                              order=self.order, panel_width=self.panel_width)
