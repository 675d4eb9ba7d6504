r"""``closed-form``: power-law fluids in walls whose separated integral is elementary.

For :math:`G = \phi(q)(as)^{-k}`, :math:`k = 3n+1`,
:math:`J(v) = a^k\int_0^v s^{k+1}P'(s)\,du`, which the wall gives in closed form
(``WallModel._power_law_integral``) for linear walls and both thin Mooney–Rivlin /
neo-Hookean conventions, e.g. thin reference thickness with :math:`\lambda_{out} = 1`:

.. math::

    J/(a^k\mu\bar t) = \frac{\lambda^{3n+2} - 1}{3n+2} + 3\,\frac{\lambda^{3n-2} - 1}{3n-2},

evaluated as ``expm1(c v)/c``, exact through the removable singularities at
:math:`n = 2/3` and (thin current thickness) :math:`n = 1`. Where the wall also gives the
explicit inverse (linear walls, thin current thickness) it answers every flow rate; otherwise
Newton's method on the closed form, or the wall's table where it declares a shape/scale split.
"""

from __future__ import annotations

from typing import ClassVar, final

import attrs
import numpy as np

from . import _inverse
from .separated import SeparatedVariables, exact

__all__ = ["ClosedForm"]


@final
@attrs.frozen(kw_only=True)
class ClosedForm(SeparatedVariables):
    """Closed-form separated integral (power-law fluid; rigid, linear or thin hyperelastic wall)."""

    cost_rank: ClassVar[int] = 0

    def supports(self, rheology, wall) -> bool:
        return wall.closed_form_integral and rheology.separable and rheology.radius_exponent is not None

    def _J(self, scene, v, index, q=None):
        pts = scene.at(np.asarray(index))
        k = pts.rheology.radius_exponent
        return exact(pts.radius**k * pts.wall._power_law_integral(np.asarray(v, dtype=float), pts.outlet_stretch, k,
                                                                  pts.tb))

    def _J_infinity(self, scene, index, q=None, rtol=None):      # exact: no screening estimate
        index = np.asarray(index)
        return exact(self._J(scene, np.full(index.shape, np.inf), index).value + np.zeros(index.shape))

    def _table(self, scene, points):
        # a wall with an explicit inverse needs no table: the closed form answers every point
        return None if scene.wall._has_power_law_integral_inverse() else super()._table(scene, points)

    def _solve_J(self, scene, target, index, q=None, upper=None):
        """The wall's explicit inverse where it has one, else Newton's method on the closed form."""
        if not scene.wall._has_power_law_integral_inverse():
            return super()._solve_J(scene, target, index, q, upper)
        target = np.asarray(target, dtype=float).ravel()
        index = np.asarray(index).ravel()
        pts = scene.at(index)
        k = pts.rheology.radius_exponent
        v = pts.wall._power_law_integral_inverse(target / pts.radius**k, pts.outlet_stretch, k, pts.tb)
        v = np.where(target == 0, 0.0, v) + np.zeros(target.shape)
        if upper is not None:
            v = np.minimum(v, upper)
        ok = v <= _inverse.MAX_LOG_STRETCH
        if np.all(ok):
            return v, ok, exact(target)
        # no root below the solver's range: beyond J(inf) (v = inf, J(inf) its integral), or a
        # steady state beyond the range (the largest log-stretch, for the error to say)
        j_inf = self._J_infinity(scene, index).value
        beyond = ~ok & (target >= j_inf * (1.0 - _inverse.AT_THE_LIMIT))
        v = np.where(beyond, np.inf, np.where(ok, v, _inverse.MAX_LOG_STRETCH))
        return v, ok, exact(np.where(beyond, j_inf, target))
