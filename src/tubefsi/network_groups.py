r"""The tubes of a :class:`~tubefsi.Network` evaluated by groups (``docs/network.md``): tubes that share
their wall and fluid classes are stacked into one model with array parameters and solved in one broadcast
:func:`tubefsi.solve` per Newton iteration. :func:`_gather` and :func:`_stack` build those arrays from
the tubes of :meth:`Network.add_tube` and :meth:`Network.add_tubes` alike.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from . import validity
from .errors import NoSteadyStateError
from .fields import _array_fields
from .geometry import Tube
from .scene import make_scene
from .solve import max_flow_rate as tubefsi_max_flow
from .solve import solve_unchecked


class _Groups:
    """The tubes grouped by (wall class, fluid class, non-array parameters), each group's
    parameters stacked into arrays, and one broadcast solve per group."""

    def __init__(self, tubes, subset):
        groups: dict = {}
        keys: dict = {}               # id(model) -> its class and non-array parameters
        self.external = []            # per part: the external pressure of its tubes (float or array)
        for i, t in enumerate(tubes):
            if not subset[i]:
                continue
            wall, fluid = t.wall, t.rheology
            if id(wall) not in keys:
                keys[id(wall)] = (type(wall), _fixed(wall))
            if id(fluid) not in keys:
                keys[id(fluid)] = (type(fluid), _fixed(fluid))
            groups.setdefault((keys[id(wall)], keys[id(fluid)]), []).append(i)
        self.parts = []
        for index in groups.values():
            members = [tubes[i] for i in index]
            wall = _stack(members, "wall")
            fluid = _stack(members, "rheology")
            tube = Tube(**_gather(members, "tube", ("radius", "thickness", "length")))
            self.parts.append((np.asarray(index), fluid, wall, tube))
            self.external.append(_column([m.external_pressure for m in members]))
        n = len(tubes)
        self.limit = np.zeros(n)
        self.radius = np.zeros(n)
        self.length = np.zeros(n)
        for (index, fluid, wall, tube), p_e in zip(self.parts, self.external):
            # the node (gauge) pressure at which the transmural one reaches the limit pressure
            self.limit[index] = np.broadcast_to(wall.limit_pressure(tube.reduced_thickness) + np.asarray(p_e),
                                                index.shape)
            self.radius[index] = np.broadcast_to(tube.radius, index.shape)
            self.length[index] = np.broadcast_to(tube.length, index.shape)

    def evaluate(self, drop, outlet):
        """Flow rates and the derivatives by the inlet and outlet pressures of the tubes (pressure-
        controlled; zeros for the tubes of no group)."""
        q, d_in, d_out, radius_in, radius_out = (np.zeros(drop.size) for _ in range(5))
        for (index, fluid, wall, tube), p_e in zip(self.parts, self.external):
            # Newton's trial pressures: unchecked (the result is checked once; no process-wide
            # warning filter, which would silence other threads too)
            sol = solve_unchecked(fluid, wall, tube, pressure_drop=drop[index], outlet_pressure=outlet[index],
                                  external_pressure=p_e)
            q[index] = sol.flow_rate
            _, d_in[index], d_out[index] = sol._sensitivities()
            radius_in[index] = sol.inlet_radius
            radius_out[index] = np.broadcast_to(tube.radius * sol.scene.outlet_stretch, index.shape)
        return q, d_in, d_out, radius_in, radius_out

    def check(self, q, radius_u, radius_v, tubes):
        """The converged tubes against the model's assumptions (:mod:`tubefsi.validity`): one
        ModelValidityWarning per failed assumption of a group, naming its first offending tube."""
        for index, fluid, wall, tube in self.parts:
            scene = make_scene(fluid, wall, tube)
            scene = scene.flat(index.shape) if scene.shape != () else scene
            big = np.maximum(radius_u[index], radius_v[index])
            found = validity.check(scene, np.abs(q[index]), big / np.broadcast_to(tube.radius, index.shape) - 1.0)
            if found.messages:
                slender = big / np.broadcast_to(tube.length, index.shape)
                name = tubes[index[int(np.argmax(slender))]].name
                validity.warn(attrs.evolve(found, messages=tuple(
                    f"network (e.g. tube {name!r}): {m.replace(' points', ' tubes')}" for m in found.messages)))

    def inlet(self, q, outlet, tubes):
        """Flow-controlled: the inlet pressure and the inlet and outlet radii of the tubes carrying
        ``q > 0`` with ``outlet`` pressure; a flow rate beyond a tube's maximum raises, naming it."""
        p_in, radius_in, radius_out = (np.zeros(q.size) for _ in range(3))
        for (index, fluid, wall, tube), p_e in zip(self.parts, self.external):
            # checked with the rest of the result
            sol = solve_unchecked(fluid, wall, tube, flow_rate=q[index], outlet_pressure=outlet[index],
                                  external_pressure=p_e, on_infeasible="nan")
            if not np.all(sol.feasible):
                j = int(np.flatnonzero(~sol.feasible)[0])
                limit = np.broadcast_to(tubefsi_max_flow(fluid, wall, tube, outlet_pressure=outlet[index],
                                                         external_pressure=p_e), index.shape)[j]
                raise NoSteadyStateError("flow_rate", float(limit), float(q[index][j]),
                                         f"the inflow into tube {tubes[index[j]].name!r} reaches its maximum flow rate "
                                         f"at the outlet pressure {outlet[index][j]:.10g} Pa")
            p_in[index] = sol.inlet_pressure
            radius_in[index] = sol.inlet_radius
            radius_out[index] = np.broadcast_to(tube.radius * sol.scene.outlet_stretch, index.shape)
        return p_in, radius_in, radius_out

    def apparent_viscosity(self, q, mu):
        """Per tube, the Newtonian viscosity with the fluid's pressure gradient at ``|q|`` in the
        undeformed tube (``mu`` where q = 0)."""
        out = mu.copy()
        for index, fluid, wall, tube in self.parts:
            qi = np.abs(q[index])
            ok = qi > 0
            if np.any(ok):
                a = np.broadcast_to(tube.radius, index.shape)
                g = np.asarray(fluid.pressure_gradient(np.where(ok, qi, 1.0), tube.radius), dtype=float)
                g = np.broadcast_to(g, index.shape)
                value = g * math.pi * a**4 / (8 * np.where(ok, qi, 1.0))
                out[index] = np.where(ok & np.isfinite(value) & (value > 0), value, mu[index])
        return out

    def nominal_viscosity(self, n):
        mu = np.empty(n)
        for index, fluid, wall, tube in self.parts:
            mu[index] = np.broadcast_to(np.asarray(fluid.apparent_viscosity(1.0), dtype=float), index.shape)
        return mu


def _fixed(model):
    """The values of a model's parameters that cannot be arrays (they split groups)."""
    return tuple(getattr(model, name) for name in _scalar_fields(type(model)))


def _scalar_fields(cls):
    arrays = set(_array_fields(cls))
    return tuple(f.name for f in attrs.fields(cls) if f.init and f.name not in arrays) if attrs.has(cls) else ()


def _column(values):
    a = np.asarray(values, dtype=float)
    return float(a[0]) if np.all(a == a[0]) else a


def _gather(members, which, fields) -> dict:
    """field -> the members' values of that parameter of their ``which`` model (a float where all
    agree, else an array aligned with ``members``). Tubes added together by
    :meth:`Network.add_tubes` share one model: their entries are taken at their rows, in one
    indexing per model rather than one lookup per tube."""
    by_model: dict = {}
    for j, m in enumerate(members):
        model = getattr(m, which)
        entry = by_model.get(id(model))
        if entry is None:
            entry = by_model[id(model)] = (model, [], [])
        entry[1].append(j)
        entry[2].append(m.row)
    out = {f: np.empty(len(members)) for f in fields}
    for model, positions, rows in by_model.values():
        for f in fields:
            value = getattr(model, f)
            out[f][positions] = value[rows] if isinstance(value, np.ndarray) and value.ndim else value
    return {f: _column(column) for f, column in out.items()}


def _stack(members, which):
    """One model whose array parameters hold the members' values (a scalar where all agree)."""
    first = getattr(members[0], which)
    if all(getattr(m, which) is first and m.row is None for m in members):
        return first
    return attrs.evolve(first, **_gather(members, which, _array_fields(type(first))))
