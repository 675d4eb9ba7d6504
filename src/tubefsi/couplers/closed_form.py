r"""``closed-form``: power-law fluids in walls whose separated integral is elementary.

For :math:`G = \phi(q)(as)^{-k}`, :math:`k = 3n+1`,
:math:`J(v) = a^k\int_0^v s^{k+1}P'(s)\,du`, which the wall gives in closed form
(``WallModel._power_law_integral``) for linear walls and both thin Mooney–Rivlin /
neo-Hookean conventions, e.g. thin reference thickness with :math:`\lambda_{out} = 1`:

.. math::

    J/(a^k\mu\bar t) = \frac{\lambda^{3n+2} - 1}{3n+2} + 3\,\frac{\lambda^{3n-2} - 1}{3n-2},

evaluated as ``expm1(c v)/c``, exact through the removable singularities at
:math:`n = 2/3` and (thin current thickness) :math:`n = 1`.
"""

from __future__ import annotations

from typing import ClassVar, final

import attrs
import numpy as np

from ..scene import State
from .separated import MAX_LOG_STRETCH, SeparatedVariables

__all__ = ["ClosedForm"]


@final
@attrs.frozen(kw_only=True)
class ClosedForm(SeparatedVariables):
    """Closed-form separated integral (power-law fluid; rigid, linear or thin hyperelastic wall)."""

    cost_rank: ClassVar[int] = 0

    def supports(self, rheology, wall) -> bool:
        return rheology.separable and rheology.radius_exponent is not None and wall.closed_form_integral

    def _J(self, scene, v, index, q=None):
        pts = scene.at(np.asarray(index))
        k = pts.rheology.radius_exponent
        return pts.radius**k * pts.wall._power_law_integral(np.asarray(v, dtype=float), pts.outlet_stretch, k,
                                                            pts.tb)

    def _J_infinity(self, scene, index, q=None):
        index = np.asarray(index)
        return self._J(scene, np.full(index.shape, np.inf), index) + np.zeros(index.shape)

    def curve_from_table(self, scene, q):
        # a wall with an explicit inverse is served by it, not by a table (flow_controlled)
        return None if scene.wall._has_power_law_integral_inverse() else super().curve_from_table(scene, q)

    def flow_controlled(self, scene, flow_rate):
        """Explicit inverse where the wall has one (linear, thin current thickness), else Newton."""
        q = np.asarray(flow_rate, dtype=float)
        if scene.wall.is_rigid:
            return super().flow_controlled(scene, q)
        if not scene.wall._has_power_law_integral_inverse():   # (a property of the wall's class and options)
            return super().flow_controlled(scene, q)    # no explicit inverse: the tables or Newton (in logs)
        index = np.arange(q.size)
        pts = scene.at(index)
        k = pts.rheology.radius_exponent
        target = self.target(pts, q)
        v = pts.wall._power_law_integral_inverse(target / pts.radius**k, pts.outlet_stretch, k, pts.tb)
        v = np.where(q == 0, 0.0, v)
        if not np.all(v <= MAX_LOG_STRETCH):
            self._raise_runaway(scene, q, v <= MAX_LOG_STRETCH)
        return State(q, self.pressure_rise(scene, v, index), self.strain_at(pts, v) + 0.0 * v, v)
