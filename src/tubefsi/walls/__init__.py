"""Wall laws (tube laws) and their base classes."""

from .base import WallModel
from .hyperelastic import HyperelasticWall, InstalledTube, ThickWall, ThinWall
from .linear import ThickLinear, ThinLinear
from .mooney_rivlin import MooneyRivlin, ThickMooneyRivlin, ThinMooneyRivlin
from .neo_hookean import NeoHookean, ThickNeoHookean, ThinNeoHookean
from .rigid import Rigid
from .shapiro import Shapiro
from .hgo import HolzapfelGasserOgden, ThickHGO, ThinHGO

__all__ = [
    "WallModel", "HyperelasticWall", "ThinWall", "ThickWall", "InstalledTube",
    "Rigid", "ThinLinear", "ThickLinear",
    "MooneyRivlin", "ThinMooneyRivlin", "ThickMooneyRivlin",
    "NeoHookean", "ThinNeoHookean", "ThickNeoHookean",
    "Shapiro", "HolzapfelGasserOgden", "ThinHGO", "ThickHGO",
]
