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

``import tubefsi`` is light: the public names below are loaded on first use (PEP 562), so a
script that only needs the errors or the registry does not pay for SciPy.
"""

# imported under private names: ``tubefsi.sys`` and the like are not part of the package
import importlib as _importlib
import sys as _sys
import types as _types
import typing as _typing

from .errors import (AccuracyWarning, BucklingError, ConvergenceError, FitWarning, InvalidParameterError, KeywordError,
                     ModelValidityWarning, NoSteadyStateError, StretchRangeError, TubefsiError)

__all__ = [
    "dimensionless", "fields", "Tube", "solve", "max_flow_rate", "select_coupler", "Solution", "registry",
    "advise", "Advice", "Diagnostics", "ModelValidityWarning", "fit", "FitResult", "Network", "NetworkSolution",
    "NetworkFitResult",
    "TubefsiError", "InvalidParameterError", "KeywordError", "NoSteadyStateError", "ConvergenceError", "AccuracyWarning",
    "StretchRangeError", "BucklingError", "FitWarning", "Profile", "sampled", "Problem", "cache_clear", "cache_info",
    "read_network_table", "write_network_table", "datasets",
    "evolve", "Transient", "Chamber",
]

__version__ = "0.1.0"

#: public name -> the module that defines it (``None``: the name is a submodule)
_LAZY = {
    "dimensionless": None, "fields": None, "registry": None,
    "Tube": "geometry", "Solution": "solution", "Profile": "profiles", "sampled": "profiles",
    "solve": "solve", "max_flow_rate": "solve", "select_coupler": "solve", "Problem": "solve",
    "cache_clear": "couplers.tables", "cache_info": "couplers.tables",
    "advise": "advise", "Advice": "advise", "Diagnostics": "advise",
    "fit": "fit", "FitResult": "fit",
    "Network": "network", "NetworkSolution": "network", "NetworkFitResult": "network_fit",
    "read_network_table": "network_io", "write_network_table": "network_io", "datasets": None,
    "evolve": "evolve", "Transient": "evolve", "Chamber": "evolve",
}


if _typing.TYPE_CHECKING:      # never run: tells type checkers what the lazy names below are
    from . import dimensionless, fields, registry
    from .advise import Advice, Diagnostics, advise
    from .couplers.tables import cache_clear, cache_info
    from .evolve import Chamber, Transient, evolve
    from .fit import FitResult, fit
    from .geometry import Tube
    from .network import Network, NetworkSolution
    from .network_io import read_network_table, write_network_table
    from . import datasets
    from .network_fit import NetworkFitResult
    from .profiles import Profile, sampled
    from .solution import Solution
    from .solve import Problem, max_flow_rate, select_coupler, solve


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'tubefsi' has no attribute {name!r}")
    where = _LAZY[name]
    if where is None:
        value = _importlib.import_module(f".{name}", __name__)
    else:
        value = getattr(_importlib.import_module(f".{where}", __name__), name)
    globals()[name] = value          # the next access is a plain attribute
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


#: submodules that share their name with the function they define: the package attribute is the function
_FUNCTIONS = ("solve", "advise", "fit", "evolve")


class _Package(_types.ModuleType):
    def __reduce__(self):
        # pickled by name, as a plain module is (cloudpickle, dask and multiprocessing send
        # functions that refer to ``tubefsi`` to other processes)
        return _importlib.import_module, (self.__name__,)

    def __setattr__(self, name, value):
        # importing the submodule ``tubefsi.solve`` sets the package attribute ``solve`` to that
        # module; keep the public function there instead, as an eager import would
        if name in _FUNCTIONS and isinstance(value, _types.ModuleType):
            value = getattr(value, name)
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package
