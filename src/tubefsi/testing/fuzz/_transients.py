"""The family "transients": :func:`tubefsi.evolve` for every registered model, and its arguments.

For each pair (each registered rheology with a few walls, each wall with a few fluids), one short
run without error control (8 cells, three output times) from rest, driven by the inlet pressure
of a steady solve of the same tube at a small flow rate (so it lies below any limit pressure):
finite fields and histories, or a typed error (a rigid wall stores no volume: an
:class:`~tubefsi.InvalidParameterError` naming ``wall``). Then ``evolve``'s own arguments —
the loads, the pressures, ``rtol``, ``density``, ``cells`` and ``times`` — given the values
that any real parameter must refuse: an :class:`~tubefsi.InvalidParameterError` naming the
argument.
"""

from __future__ import annotations

import math

import numpy as np

from ...evolve import evolve
from ...solve import solve
from ._core import _ALWAYS_BAD, Probe

#: Three output times (s) and a coarse grid: a probe costs a fraction of a second.
_TIMES = (0.0, 1e-3, 1e-2)
_RUN = {"cells": 8, "error_control": False, "rtol": 1e-4}


def _drive(fluid, wall, tube):
    """The inlet pressure (Pa) of a steady solve at a small flow rate: feasible for the pair."""
    return float(solve(fluid, wall, tube, flow_rate=1e-12).inlet_pressure)


def _fields(result):
    """The numbers a user reads of a transient: its histories and its fields mid-tube."""
    z = 0.5 * float(result.z[-1])
    return (result.inlet_flow_rate, result.outlet_flow_rate, result.inlet_pressure, result.stored_volume(),
            result.pressure(z, result.times), result.radius(z, result.times))


def transient_probes(fluid, wall, tube, tag):
    if wall.is_rigid:
        yield Probe("evolve", f"{tag} rigid wall", lambda: evolve(fluid, wall, tube, _TIMES, inlet_pressure=1.0, **_RUN),
                    bad=True, parameter="wall")
        return

    def run(**changes):
        kwargs = {"inlet_pressure": _drive(fluid, wall, tube), **_RUN, **changes}
        times = kwargs.pop("times", _TIMES)
        return _fields(evolve(fluid, wall, tube, times, **kwargs))

    yield Probe("evolve", f"{tag} open end", run)
    yield Probe("evolve", f"{tag} closed end", lambda: run(outlet="closed"))


def argument_probes(fluid, wall, tube):
    """``evolve``'s own arguments at values every real parameter must refuse."""
    drive = 1e2

    def call(name, value):
        kwargs = {"inlet_pressure": drive, **_RUN}
        times = _TIMES
        if name == "times":
            times = value
        elif name == "inlet_flow_rate":
            kwargs.pop("inlet_pressure")
            kwargs[name] = value
        else:
            kwargs[name] = value
        return evolve(fluid, wall, tube, times, **kwargs)

    for name in ("inlet_pressure", "inlet_flow_rate", "external_pressure", "rtol", "density"):
        for value in _ALWAYS_BAD:
            if value is None and name == "density":         # its default: no validity check
                continue
            yield Probe("evolve", f"{name}={value!r}"[:60], lambda n=name, v=value: call(n, v), bad=True, parameter=name)
    for value in (0, -3, 2.5, "8", 10**400, np.array([8, 16])):
        yield Probe("evolve", f"cells={value!r}"[:60], lambda v=value: call("cells", v), bad=True, parameter="cells")
    for value in ([0.0], [1.0, 0.0], [0.0, math.nan], "x", [], np.zeros((2, 2)), [0.0, 1.0, 1.0]):
        yield Probe("evolve", f"times={value!r}"[:60], lambda v=value: call("times", v), bad=True, parameter="times")
