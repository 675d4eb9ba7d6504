"""Hyperelastic wall laws for tubefsi, registered in ``tubefsi.walls``.

===========================================  ==================================================
registered names                             parameters
===========================================  ==================================================
``thin-gent``, ``thick-gent``                shear_modulus, locking_parameter (J_m)
``thin-demiray``, ``thick-demiray``                shear_modulus, stiffening (b)
``thin-ogden``, ``thick-ogden``              moduli, exponents (any number of terms)
``thin-yeoh``, ``thick-yeoh``                c1, c2, c3
===========================================  ==================================================

Thin variants also take ``thickness_convention`` ("reference" or "current"), like the core's.
tubefsi finds them through the entry points of this distribution and never imports it.
"""

from .demiray import Demiray, ThickDemiray, ThinDemiray
from .gent import Gent, ThickGent, ThinGent
from .ogden import Ogden, ThickOgden, ThinOgden
from .yeoh import ThickYeoh, ThinYeoh, Yeoh

__all__ = ["Gent", "ThinGent", "ThickGent", "Demiray", "ThinDemiray", "ThickDemiray",
           "Ogden", "ThinOgden", "ThickOgden", "Yeoh", "ThinYeoh", "ThickYeoh"]
__version__ = "0.1.0"
