"""Named fluids with literature parameters, each with its source.

>>> from tubefsi_rheologies import preset
>>> blood = preset("blood-carreau-yasuda")
>>> blood.zero_shear_viscosity
0.056

Parameters are in SI units, as the cited works give them (1 P = 0.1 Pa s). Blood
rheology depends on haematocrit, temperature and the donor; these fits are the ones
the computational-haemodynamics literature commonly uses, not universal constants.
"""

from __future__ import annotations

from types import MappingProxyType

import attrs

__all__ = ["Preset", "PRESETS", "preset"]


@attrs.frozen
class Preset:
    """A named fluid: a registered rheology, its parameters, and where they come from."""

    name: str
    rheology: str                 # registered name in tubefsi.registry.rheologies
    parameters: MappingProxyType = attrs.field(converter=lambda d: MappingProxyType(dict(d)))
    citation: str
    note: str = ""

    def build(self):
        """The rheology instance (looked up in :data:`tubefsi.registry.rheologies`)."""
        from tubefsi.registry import rheologies

        return rheologies[self.rheology](**self.parameters)


_CHO_KENSEY = ("Y. I. Cho and K. R. Kensey, 'Effects of the non-Newtonian viscosity of blood on flows in a "
               "diseased arterial vessel. Part 1: Steady flows', Biorheology 28(3-4), 241-262 (1991)")

_ALL = [
    Preset("blood-carreau", "carreau",
           dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=3.313, index=0.3568),
           _CHO_KENSEY,
           "human whole blood; fit to viscometric data over shear rates of about 0.1-1000 1/s"),
    Preset("blood-carreau-yasuda", "carreau-yasuda",
           dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=3.313, index=0.3568,
                transition=2.0),
           "J. Boyd, J. M. Buick and S. Green, 'Analysis of the Casson and Carreau-Yasuda non-Newtonian blood "
           "models in steady and oscillatory flows using the lattice Boltzmann method', Phys. Fluids 19, "
           "093103 (2007); constants of " + _CHO_KENSEY,
           "the Cho-Kensey Carreau fit written as Carreau-Yasuda with a = 2"),
    Preset("blood-cross", "cross",
           dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=1.007,
                exponent=1.028),
           _CHO_KENSEY, "human whole blood"),
    Preset("blood-herschel-bulkley", "herschel-bulkley",
           dict(yield_stress=0.0175, consistency=8.9721e-3, index=0.8601),
           "A. Valencia, A. Zarate, M. Galvez and L. Badilla, 'Non-Newtonian blood flow dynamics in a right "
           "internal carotid artery with a saccular aneurysm', Int. J. Numer. Methods Fluids 50(6), 751-764 "
           "(2006)",
           "human whole blood"),
    Preset("blood-analogue-gijsen", "carreau-yasuda",
           dict(zero_shear_viscosity=0.022, infinite_shear_viscosity=0.0022, relaxation_time=0.110, index=0.392,
                transition=0.644),
           "F. J. H. Gijsen, F. N. van de Vosse and J. D. Janssen, 'The influence of the non-Newtonian "
           "properties of blood on the flow in large arteries: steady flow in a carotid bifurcation model', "
           "J. Biomech. 32(6), 601-608 (1999)",
           "laboratory blood-analogue fluid (aqueous polymer solution) matched to blood's shear thinning"),
]

#: name -> :class:`Preset` (read-only)
PRESETS = MappingProxyType({p.name: p for p in _ALL})


def preset(name: str):
    """The rheology instance of preset ``name`` (see :data:`PRESETS`)."""
    try:
        return PRESETS[name].build()
    except KeyError:
        raise KeyError(f"{name!r} is not a preset; known: {', '.join(sorted(PRESETS))}") from None
