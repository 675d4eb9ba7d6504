"""The family "solutions": a solution's accessors at every shape of argument.

For each pair, a scalar solution and one of three loads; the profiles with ``z`` (and the velocity
with ``r``) of shapes that broadcast with the solution's and of shapes that do not; the maximum
flow rate and ``feasible`` of solutions whose parameters are arrays. The contract: a result of the
broadcast shape, or an :class:`~tubefsi.InvalidParameterError` naming the argument where the shapes
do not broadcast.
"""

from __future__ import annotations

import attrs
import numpy as np

from ...solve import max_flow_rate, solve
from ._core import Probe

_PROFILES = ("pressure", "radius", "displacement", "pressure_gradient", "wall_shear_stress")
#: Shapes of ``z`` (in units of L) tried against solutions of shape () and (3,).
_Z_SHAPES = ((), (1,), (3,), (5,), (5, 1), (2, 3), (0,), (4, 1, 1))


def _shape_check(expected):
    def check(result):
        return None if np.shape(result) == expected else f"shape {np.shape(result)}, not {expected}"
    return check


def _broadcast(a, b):
    try:
        return np.broadcast_shapes(a, b)
    except ValueError:
        return None


def solution_probes(fluid, wall, tube, tag):
    loads = {(): 1e-12, (3,): np.array([1e-12, 2e-12, 3e-12])}
    length = float(np.max(tube.length)) if np.ndim(tube.length) == 0 else None
    if length is None:
        return
    for sol_shape, load in loads.items():
        def sol(load=load):
            return solve(fluid, wall, tube, flow_rate=load)

        for z_shape in _Z_SHAPES:
            z = np.full(z_shape, 0.5 * length) if z_shape else 0.5 * length
            expected = _broadcast(z_shape, sol_shape)
            label = f"{tag} solution {sol_shape}, z {z_shape}"
            for method in _PROFILES:
                if expected is None:
                    yield Probe(f"Solution.{method}", label, lambda m=method, zz=z, s=sol: getattr(s(), m)(zz),
                                bad=True, parameter="z")
                else:
                    yield Probe(f"Solution.{method}", label, lambda m=method, zz=z, s=sol: getattr(s(), m)(zz),
                                check=_shape_check(expected))
            r = np.zeros(z_shape) if z_shape else 0.0
            if expected is not None:                       # r of z's shape at the centreline
                yield Probe("Solution.velocity", label + ", r like z", lambda rr=r, zz=z, s=sol: s().velocity(rr, zz),
                            check=_shape_check(expected))
        yield Probe("Solution.feasible", f"{tag} solution {sol_shape}", lambda s=sol: s().feasible,
                    check=lambda f, e=sol_shape: None if np.shape(f) == e and np.asarray(f).dtype == bool
                    else f"feasible {f!r}")
    # the maximum flow rate of a solution whose wall parameters are arrays: the array of its scenes
    moduli = [name for name, field in attrs.fields_dict(type(wall)).items()
              if field.metadata.get("admissible") == "(0, inf)" and type(getattr(wall, name)) is float]
    if moduli and not wall.is_rigid:
        name = moduli[0]
        value = getattr(wall, name)

        def both():                  # (a joint constraint may refuse the doubled value: a typed error)
            pair = attrs.evolve(wall, **{name: [value, 2.0 * value]})
            return (solve(fluid, pair, tube, flow_rate=1e-12).max_flow_rate,
                    [max_flow_rate(fluid, attrs.evolve(wall, **{name: v}), tube) for v in (value, 2.0 * value)])

        yield Probe("Solution.max_flow_rate", f"{tag} {name} of shape (2,)", both, allow_inf=True,
                    check=lambda r: None if np.shape(r[0]) == (2,) and np.array_equal(r[0], r[1])
                    else f"{r[0]!r} against the scalar scenes' {r[1]!r}")
