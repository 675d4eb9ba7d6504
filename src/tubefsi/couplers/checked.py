r"""``Checked``: re-solve with a coupler's refined version and warn where the two disagree.

A coupler whose answer may fall short of the accuracy contract (a coarse quadrature rule,
an ODE integrator with local error control) returns a finer version of itself from
:meth:`~tubefsi.couplers.Coupler.refined`. :func:`tubefsi.solve` wraps it in
:class:`Checked`, which solves with both, takes the largest relative difference of the
results as the error estimate and issues an :class:`~tubefsi.AccuracyWarning` stating it
when it exceeds the coupler's :meth:`~tubefsi.couplers.Coupler.error_threshold`. Every
self-checking coupler gets the same check from this one wrapper, instead of re-coding it.
"""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from ..errors import AccuracyWarning, warn_user
from .base import Coupler

__all__ = ["Checked", "checked"]


def _relative_difference(a, b) -> float:
    """``max |a/b - 1|`` over the entries where ``b != 0``."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    nonzero = b != 0
    return float(np.max(np.abs(a[nonzero] / b[nonzero] - 1.0), initial=0.0))


@final
@attrs.frozen(kw_only=True)
class Checked(Coupler):
    """``inner``'s answers, with an a-posteriori error estimate against ``reference``."""

    inner: Coupler
    reference: Coupler

    def supports(self, rheology, wall) -> bool:
        return self.inner.supports(rheology, wall)

    def flow_controlled(self, scene, flow_rate):
        state = self.inner.flow_controlled(scene, flow_rate)
        fine = self.reference.flow_controlled(scene, flow_rate)
        self._judge(max(_relative_difference(state.pressure_drop, fine.pressure_drop),
                        _relative_difference(state.inlet_strain, fine.inlet_strain)))
        return state

    def pressure_controlled(self, scene, pressure_drop):
        state = self.inner.pressure_controlled(scene, pressure_drop)
        fine = self.reference.pressure_controlled(scene, pressure_drop)
        self._judge(_relative_difference(state.flow_rate, fine.flow_rate))
        return state

    def max_flow_rate(self, scene) -> float:
        return self.inner.max_flow_rate(scene)

    def limit_pressure(self, scene):
        return self.inner.limit_pressure(scene)

    def profile(self, scene, state, z):
        return self.inner.profile(scene, state, z)

    def describe(self) -> str:
        return self.inner.describe()

    def _judge(self, error: float) -> None:
        threshold = self.inner.error_threshold()
        if error > threshold:
            warn_user(f"{self.inner.describe()}: estimated relative error {error:.2g} (against "
                      f"{self.reference.describe()}) exceeds {threshold:.2g}; refine it or use "
                      "coupler='auto' for the default, error-controlled path", AccuracyWarning)


def checked(coupler: Coupler) -> Coupler:
    """``coupler`` wrapped in :class:`Checked` if it offers a refined version, else itself."""
    reference = coupler.refined()
    return coupler if reference is None else Checked(inner=coupler, reference=reference)
