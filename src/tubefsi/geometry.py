"""The undeformed tube."""

from __future__ import annotations

import attrs
import numpy as np

from .errors import InvalidParameterError
from .fields import positive

__all__ = ["Tube"]


@attrs.frozen(kw_only=True)
class Tube:
    r"""An undeformed straight tube, clamped at both ends.

    Parameters
    ----------
    radius : float
        Undeformed inner radius :math:`a` (m).
    thickness : float
        Wall thickness :math:`t` (m).
    length : float
        Length :math:`L` (m). Lubrication theory assumes :math:`a/L \ll 1`.
    """

    radius: float = positive(unit="m", doc="undeformed inner radius a")
    thickness: float = positive(unit="m", doc="wall thickness t")
    length: float = positive(unit="m", doc="tube length L")

    def __attrs_post_init__(self):
        tb = np.asarray(self.thickness) / np.asarray(self.radius)
        if not np.all((tb > 0) & np.isfinite(tb)):        # t/a beyond double range
            raise InvalidParameterError("thickness", "values with a finite, nonzero t/a", self.thickness,
                                        f"t/a = {np.ravel(tb)[np.argmin(np.isfinite(tb) & (tb > 0))]!r} with radius "
                                        f"{self.radius!r}")

    @property
    def reduced_thickness(self) -> float:
        r"""Thickness ratio :math:`\bar t = t/a` (dimensionless)."""
        return self.thickness / self.radius

    @property
    def slenderness(self) -> float:
        r""":math:`\epsilon = a/L`; lubrication theory needs it small."""
        return self.radius / self.length
