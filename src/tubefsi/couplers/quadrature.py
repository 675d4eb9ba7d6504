r"""``quadrature``: any rheology with any wall, by the separated-variables identity.

:math:`J(v) = \int_0^v s P'(s)/G(q, as)\,du` is evaluated by adaptive Gauss–Kronrod quadrature
in the log-stretch :math:`u` with an a-posteriori error estimate per point (``docs/theory.md``,
section "Coupling without an ODE"). The inlet log-stretch is found from one batch of integrand
values per point where a Chebyshev interpolant's tail vouches for it, else by safeguarded Newton
iteration (:mod:`tubefsi.couplers._inverse`); a target that a cheap estimate of :math:`J(\infty)`
puts beyond it is told so before either. No ODE is integrated. Toward a wall's locking
stretch the integral is graded in :math:`\ln(v_{max} - u)`.
"""

from __future__ import annotations

from typing import ClassVar, final

import attrs
import numpy as np

from ..fields import real
from ..numerics.quadrature import Integral
from . import _inverse
from ._options import flag, integer, tolerance
from .separated import SeparatedVariables

__all__ = ["Quadrature"]


@final
@attrs.frozen(kw_only=True)
class Quadrature(SeparatedVariables):
    """Quadrature of the separated identity (any pair): adaptive and error-controlled by default.

    ``order=None`` (the default): adaptive Gauss–Kronrod quadrature with an a-posteriori error
    estimate per point, refined until it is below ``rtol`` relative. An integer ``order`` selects
    a fixed composite Gauss–Legendre rule of that order on panels of ``panel_width`` (coarse,
    cheaper, unchecked by itself); with ``check_error`` (the default) :func:`tubefsi.solve`
    compares it with the adaptive rule and warns (``AccuracyWarning``) above 1e-8.
    """

    order: int | None = integer(1, 200, default=None, optional=True, doc="fixed Gauss-Legendre order, or None")
    panel_width: float = real(low=0.01, high=100.0, low_open=False, high_open=False, default=2.0,
                              doc="panel width of a fixed rule (log-stretch)", along=False, array=False)
    rtol: float = tolerance(1e-15, 0.1, default=1e-14, doc="relative tolerance of the adaptive rule")
    check_error: bool = flag(default=True, doc="check a fixed rule against the adaptive one")

    cost_rank: ClassVar[int] = 10

    @property
    def _RTOL(self) -> float:                      # the engine's tolerance: this coupler's option
        return self.rtol

    @property
    def _coarse(self) -> bool:
        return self.order is not None

    def _table_options(self):
        return (self.rtol,) if self.order is None else None

    def max_flow_rate(self, scene):
        # a property of the problem, not of the rule: a coarse rule must not move it
        return (Quadrature() if self._coarse else super()).max_flow_rate(scene)

    def refined(self):
        """The adaptive rule, against which a fixed rule is checked (``check_error``)."""
        return None if self.order is None or not self.check_error else Quadrature()

    def describe(self) -> str:
        if self._coarse:
            return f"Quadrature(order={self.order}, panel_width={self.panel_width:g})"
        return f"Quadrature(rtol={self.rtol:g})"

    def supports(self, rheology, wall) -> bool:
        return True

    def _J(self, scene, v, index, q=None):
        v = np.asarray(v, dtype=float)
        index = np.asarray(index)
        if q is None:
            def f(u, i):
                return self.integrand(scene.at(index[i], column=True), u)
        else:
            qq = np.broadcast_to(np.asarray(q, dtype=float), v.shape).ravel()

            def f(u, i):
                return self.integrand(scene.at(index[i], column=True), u, qq[i, None])
        return self.integrate(scene, f, v, index, order=self.order, panel_width=self.panel_width)

    def _solve_J(self, scene, target, index, q=None, upper=None):
        """The targets a screen of J(inf) puts beyond it first, before any solve (a separable fluid,
        the adaptive rule, no upper bound); one batch of integrand values per point for the
        others, safeguarded Newton for the points it cannot vouch for."""
        target = np.asarray(target, dtype=float).ravel()
        index = np.asarray(index).ravel()
        if self._coarse or not np.any(target > 0):
            return super()._solve_J(scene, target, index, q, upper)
        if not scene.rheology.separable:
            return self._solve_mapped(scene, target, index, q, upper)
        ok = np.ones(target.size, dtype=bool)
        final = Integral.exact(target)              # (where solved: the interpolant's tail met the tolerance)
        beyond = np.zeros(0, dtype=int)
        if upper is None:
            beyond, limit = _inverse.clearly_beyond(self, scene, target, index)
            if beyond.size:
                ok[beyond] = False
                final = final.replaced(beyond, limit)
        live = np.where(ok, target, 0.0)            # (a zero target: no solve)
        bound = 0.5 * _inverse.log_stretch_cap(scene, index)
        if upper is not None:
            bound = np.minimum(bound, upper)
        v, solved = _inverse.one_batch(self, scene, live, index, bound)
        v[beyond] = np.inf
        rest = np.flatnonzero(~solved & (live > 0))
        if rest.size:
            up = None if upper is None else np.broadcast_to(np.asarray(upper, dtype=float), target.shape)[rest]
            v[rest], ok[rest], part = super()._solve_J(scene, target[rest], index[rest], None, up)
            final = final.replaced(rest, part)
        return v, ok, final

    def _solve_mapped(self, scene, target, index, q, upper):
        """A non-separable fluid: one batch of integrand values per point from the flow map of its
        law (:func:`tubefsi.couplers._inverse.one_batch_mapped`), safeguarded Newton for the points
        it cannot vouch for."""
        bound = 0.5 * _inverse.log_stretch_cap(scene, index)
        if upper is not None:
            bound = np.minimum(bound, upper)
        v, solved = _inverse.one_batch_mapped(self, scene, target, index, q, bound)
        ok = np.ones(target.size, dtype=bool)
        final = Integral.exact(target)
        rest = np.nonzero(~solved & (target > 0))[0]
        if rest.size:
            up = None if upper is None else np.broadcast_to(np.asarray(upper, dtype=float), target.shape)[rest]
            qq = np.broadcast_to(np.asarray(q, dtype=float), target.shape)[rest]
            v[rest], ok[rest], part = super()._solve_J(scene, target[rest], index[rest], qq, up)
            final = final.replaced(rest, part)
        return v, ok, final

    def _flow_rate_at(self, scene, v, dp, index):
        """The flow rates of a non-separable fluid at the inlet log-stretches ``v``: from the flow map
        of its law (:func:`tubefsi.couplers._inverse.solve_flow_rate_mapped`, every point at once),
        the bracketed search of the engine for the points it cannot vouch for."""
        q, solved = _inverse.solve_flow_rate_mapped(self, scene, v, dp, index)
        rest = np.flatnonzero(~solved)
        if rest.size:
            q[rest] = super()._flow_rate_at(scene, np.asarray(v)[rest], np.asarray(dp)[rest], np.asarray(index)[rest])
        return q
