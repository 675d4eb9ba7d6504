"""tubefsi: steady fluid–structure interaction of generalized Newtonian flow in soft tubes.

Quick start::

    import tubefsi
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e3)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=1e-9)
    sol.pressure_drop, sol.inlet_displacement

The package is layered, lowest first (``docs/architecture.md``):
``errors``, ``fields`` and ``registry``; the models (``geometry``, ``rheology``, ``walls``);
``scene``; ``couplers``; ``solution``; ``solve``; then ``advise``, ``fit``, ``dimensionless``,
``chapter``, ``plotting``, ``cli`` and ``testing``. A module imports only from its own layer
or below (``tests/test_architecture.py``).
"""

from . import dimensionless, fields, registry
from .advise import Advice, Diagnostics, ModelValidityWarning, advise
from .errors import AccuracyWarning, ConvergenceError, InvalidParameterError, NoSteadyStateError, TubefsiError
from .fit import FitResult, fit
from .geometry import Tube
from .solution import Solution
from .solve import max_flow_rate, select_coupler, solve

__all__ = [
    "dimensionless", "fields", "Tube", "solve", "max_flow_rate", "select_coupler", "Solution", "registry",
    "advise", "Advice", "Diagnostics", "ModelValidityWarning", "fit", "FitResult",
    "TubefsiError", "InvalidParameterError", "NoSteadyStateError", "ConvergenceError", "AccuracyWarning",
]

__version__ = "0.1.0"
