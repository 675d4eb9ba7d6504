r"""Newtonian fluid, :math:`\tau = \mu\dot\gamma`: the power law with :math:`n = 1`, :math:`m = \mu`.

Hagen–Poiseuille: :math:`q = \pi R^4 G/(8\mu)`.
"""

from __future__ import annotations

import attrs

from ..fields import positive
from .power_law import _PowerLawForms

__all__ = ["Newtonian"]


@attrs.frozen(kw_only=True)
class Newtonian(_PowerLawForms):
    r"""Newtonian fluid of dynamic viscosity :math:`\mu`."""

    _examples = ({"viscosity": 1e-3}, {"viscosity": 3.5e-3})

    viscosity: float = positive(unit="Pa s", doc="dynamic viscosity mu")

    @property
    def consistency(self) -> float:
        """Equal to the viscosity."""
        return self.viscosity

    @property
    def index(self) -> float:
        """Always 1."""
        return 1.0
