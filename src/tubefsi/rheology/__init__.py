"""Rheologies (generalized Newtonian fluids) and their base class."""

from .base import Rheology
from .newtonian import Newtonian
from .power_law import PowerLaw

__all__ = ["Rheology", "Newtonian", "PowerLaw"]
