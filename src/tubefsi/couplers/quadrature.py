r"""``quadrature``: any rheology with any wall, by the separated-variables identity.

:math:`J(v) = \int_0^v s P'(s)/G(q, as)\,du` is evaluated by composite
Gauss–Legendre quadrature in the log-stretch :math:`u`, where the integrand of every
built-in pair is analytic in a strip of half-width :math:`\pi/2` about the real axis
(16 nodes per panel of width 2 give full double precision), and the inlet
log-stretch is found by safeguarded Newton iteration. No ODE is integrated.
"""

from __future__ import annotations

from typing import ClassVar

import attrs
import numpy as np

from .._numerics import integrate_panels
from .base import Coupler

__all__ = ["Quadrature"]


@attrs.frozen(kw_only=True)
class Quadrature(Coupler):
    """Gauss–Legendre quadrature of the separated identity (any pair)."""

    order: int = attrs.field(default=16, converter=int)
    panel_width: float = attrs.field(default=2.0, converter=float)

    cost_rank: ClassVar[int] = 10

    def supports(self, rheology, wall) -> bool:
        return True

    def _J(self, scene, v, q):
        v = np.asarray(v, dtype=float)
        if q is None:
            return integrate_panels(lambda u, idx: scene.integrand(u), v, order=self.order,
                                    panel_width=self.panel_width)
        qflat = np.broadcast_to(np.asarray(q, dtype=float), v.shape).ravel()
        return integrate_panels(lambda u, idx: scene.integrand(u, qflat[idx, None]), v, order=self.order,
                                panel_width=self.panel_width)
