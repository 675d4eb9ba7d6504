"""The rigid wall: the tube never deforms, :math:`\\lambda = 1` (Hagen–Poiseuille)."""

from __future__ import annotations

import math

import attrs
import numpy as np

from ..errors import InvalidParameterError
from .base import WallModel

__all__ = ["Rigid"]


@attrs.frozen(kw_only=True)
class Rigid(WallModel):
    """A wall that does not deform under any pressure; its tube law is the line ``stretch = 1``."""

    is_rigid = True
    closed_form_integral = True     # Hagen–Poiseuille
    _examples = ({},)

    def _strain(self, pressure, tb):
        return np.zeros_like(np.asarray(pressure, dtype=float))

    def _stiffness(self, stretch, tb):
        return np.full_like(np.asarray(stretch, dtype=float), math.inf)

    def _stiffness_decay_exponent(self, tb):
        return 0.0

    def _min_pressure(self, tb):
        return -math.inf        # no pressure deforms it

    def _min_stretch(self, tb):
        return 1.0

    def pressure(self, stretch, reduced_thickness):
        """Not a function: any pressure keeps a rigid tube at ``stretch = 1``."""
        self._check_thickness(reduced_thickness)
        raise InvalidParameterError("stretch", "{} (a rigid wall's pressure is not a function of stretch)",
                                    stretch)
