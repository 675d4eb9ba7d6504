"""Generalized Newtonian rheologies for tubefsi, registered in ``tubefsi.rheologies``.

=====================  =====================================================================
registered name        parameters
=====================  =====================================================================
``carreau``            zero_shear_viscosity, infinite_shear_viscosity, relaxation_time, index
``carreau-yasuda``     ... and transition (the Yasuda parameter a)
``cross``              zero_shear_viscosity, infinite_shear_viscosity, relaxation_time, exponent
``ellis``              zero_shear_viscosity, half_stress, exponent
``bingham``            yield_stress, plastic_viscosity
``casson``             yield_stress, plastic_viscosity
``herschel-bulkley``   yield_stress, consistency, index
=====================  =====================================================================

tubefsi finds them through the entry points of this distribution and never imports it;
use them by name (``tubefsi.registry.rheologies["carreau"]``) or import the classes.
Named literature fluids: :func:`preset`, :data:`PRESETS`.
"""

from .generalized import Carreau, CarreauYasuda, Cross, Ellis
from .presets import PRESETS, Preset, preset
from .yield_stress import Bingham, Casson, HerschelBulkley

__all__ = ["Carreau", "CarreauYasuda", "Cross", "Ellis", "Bingham", "Casson", "HerschelBulkley",
           "PRESETS", "Preset", "preset"]
__version__ = "0.1.0"
