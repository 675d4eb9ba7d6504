r"""A coupler on the scene measured in another unit of length (``docs/verification.md``, "Fuzzing").

Lubrication and the tube law are invariant under a change of the unit of length :math:`u`: with
:math:`a' = a/u`, :math:`t' = t/u`, :math:`L' = L/u`, :math:`z' = z/u` and :math:`q' = q/u^3`, the
pressures, strains and log-stretches are unchanged (:math:`G(q, R)\,dz` is, for every rheology:
:math:`G` is a stress over a length and :math:`q/R^3` a shear rate). :func:`tubefsi.solve`
solves a power law of a large index (:math:`R^{-(3n+1)}` beyond the doubles at :math:`R` = 1e-4 m
for :math:`n \ge 26`) in units of the tube's radius, where :math:`\psi(a s) = s^{-(3n+1)}`, and
hands the :class:`~tubefsi.Solution` this coupler, which maps its questions (profiles, the
maximum flow rate) to the rescaled scene and the answers back.
"""

from __future__ import annotations

from typing import final

import attrs
import numpy as np

from ..geometry import Tube
from ..scene import State
from .base import Coupler

__all__ = ["Rescaled"]


def in_units(tube: Tube, unit) -> Tube:
    """``tube`` with its lengths measured in units of ``unit`` metres."""
    return Tube(radius=np.divide(tube.radius, unit), thickness=np.divide(tube.thickness, unit),
                length=np.divide(tube.length, unit))


@final
@attrs.frozen(kw_only=True)
class Rescaled(Coupler):
    """``inner`` applied to the scene measured in units of ``unit`` metres."""

    inner: Coupler
    unit: float

    def supports(self, rheology, wall) -> bool:
        return self.inner.supports(rheology, wall)

    def _scene(self, scene):
        return attrs.evolve(scene, tube=in_units(scene.tube, self.unit))

    def _state(self, state, factor):
        return State(np.asarray(state.flow_rate) * factor, state.pressure_drop, state.inlet_strain, state.log_stretch)

    def flow_controlled(self, scene, flow_rate):
        state = self.inner.flow_controlled(self._scene(scene), np.asarray(flow_rate) / self.unit**3)
        return self._state(state, self.unit**3)

    def pressure_controlled(self, scene, pressure_drop):
        return self._state(self.inner.pressure_controlled(self._scene(scene), pressure_drop), self.unit**3)

    def max_flow_rate(self, scene) -> float:
        return np.asarray(self.inner.max_flow_rate(self._scene(scene))) * self.unit**3

    def profile(self, scene, state, z):
        return self.inner.profile(self._scene(scene), self._state(state, self.unit**-3), np.asarray(z) / self.unit)

    def describe(self) -> str:
        return self.inner.describe()
