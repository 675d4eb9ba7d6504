r"""The tubes of a :class:`~tubefsi.Network`, stored and evaluated (``docs/network.md``).

Stored: :class:`_Tubes`, the mapping tube name -> :class:`_Tube` of a network, keeps the tubes of
each :meth:`Network.add_tubes` call (and each :meth:`Network.add_tube`) together as one
:class:`_Batch` of columns: their names, nodes, external pressures and the models whose array
parameters hold one entry per tube. A :class:`_Tube` is made when one is asked for by name; the
solver reads the columns (:meth:`_Tubes.columns`), so that 10^5 tubes added from arrays cost no
Python object each.

Evaluated: tubes that share their wall and fluid classes are stacked into one model with array
parameters and solved in one broadcast :func:`tubefsi.solve` per Newton iteration
(:class:`_Groups`, from the columns).
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import MutableMapping

import attrs
import numpy as np

from . import validity
from .errors import NoSteadyStateError
from .fields import _array_fields, varies
from .couplers.graded import _breakpoints
from .geometry import Tube
from .profiles import Profile
from .scene import make_scene
from .solve import max_flow_rate as tubefsi_max_flow
from .solve import solve_unchecked


@attrs.define(eq=False)
class _Tube:
    """One tube. ``row`` is None for a tube whose models have scalar parameters (one of
    :meth:`Network.add_tube`, or of an :meth:`Network.add_tubes` call of scalars); otherwise it is
    the tube's entry in the flat (1-D) array parameters of the models it shares with the other
    tubes of that call."""

    name: object
    u: object
    v: object
    wall: object
    tube: Tube
    rheology: object
    external_pressure: float = 0.0
    row: object = None

    @property
    def graded(self) -> bool:
        """Whether its radius, thickness or a wall parameter varies along it (a graded tube: never
        from :meth:`Network.add_tubes`)."""
        return self.tube.graded or varies(self.wall)

    def models(self):
        """This tube's wall, tube and fluid, each with scalar parameters."""
        if self.row is None:
            return self.wall, self.tube, self.rheology
        return tuple(_entry(m, self.row) for m in (self.wall, self.tube, self.rheology))


def _entry(model, row):
    """``model`` with its flat array parameters taken at ``row`` (validated scalars)."""
    arrays = {f: float(v[row]) for f in _array_fields(type(model)) if isinstance(v := getattr(model, f), np.ndarray)}
    return attrs.evolve(model, **arrays) if arrays else model


@attrs.frozen(eq=False)
class _Batch:
    """Tubes added together: their ``names``, end nodes ``u`` and ``v`` (lists), ``external``
    pressures (an array), one wall, tube and fluid, and ``rows`` (None where the models' parameters
    are scalars, else per tube its entry in their flat array parameters)."""

    names: list
    u: list
    v: list
    wall: object
    tube: Tube
    rheology: object
    external: np.ndarray
    rows: np.ndarray | None

    def member(self, k) -> _Tube:
        """Tube ``k`` of the batch."""
        return _Tube(self.names[k], self.u[k], self.v[k], self.wall, self.tube, self.rheology,
                     float(self.external[k]), None if self.rows is None else int(self.rows[k]))

    @property
    def graded(self) -> bool:
        return self.tube.graded or varies(self.wall)


class _Tubes(MutableMapping):
    """A network's tubes: tube name -> :class:`_Tube`, in the order they were added, stored as
    :class:`_Batch` es. Every tube has a *slot*, a number never reused: a batch holds the slots
    ``start, start + 1, ...`` (``_starts`` lists each batch's first), and the mapping name -> slot
    gives the order and which tubes are still there (a removed one only leaves it; a tube set by
    name anew is a batch of its own in the same place of the order)."""

    def __init__(self):
        self._slot: dict = {}
        self._batches: list = []
        self._starts: list = []
        self._next = 0

    def add(self, names, u, v, wall, tube, rheology, external, rows):
        """Add the tubes ``names`` (new names) as one batch (see :class:`_Batch`)."""
        n = len(names)
        self._batches.append(_Batch(names, u, v, wall, tube, rheology, np.asarray(external, dtype=float), rows))
        self._starts.append(self._next)
        self._slot.update(zip(names, range(self._next, self._next + n)))
        self._next += n

    def _locate(self, slot):
        b = bisect.bisect_right(self._starts, slot) - 1
        return self._batches[b], slot - self._starts[b]

    def __getitem__(self, name) -> _Tube:
        batch, k = self._locate(self._slot[name])
        return batch.member(k)

    def __setitem__(self, name, t: _Tube):
        rows = None if t.row is None else np.array([t.row])
        batch = _Batch([name], [t.u], [t.v], t.wall, t.tube, t.rheology, np.array([float(t.external_pressure)]), rows)
        self._batches.append(batch)
        self._starts.append(self._next)
        self._slot[name] = self._next         # (an existing name keeps its place in the order)
        self._next += 1

    def __delitem__(self, name):
        del self._slot[name]

    def __iter__(self):
        return iter(self._slot)

    def __len__(self):
        return len(self._slot)

    def __contains__(self, name):
        return name in self._slot

    def names(self):
        """The tube names as a (set-like) view."""
        return self._slot.keys()

    def copy(self) -> _Tubes:
        """A copy that later additions and removals do not reach (the batches are shared: they are
        never changed)."""
        new = _Tubes()
        new._slot, new._batches, new._starts, new._next = dict(self._slot), list(self._batches), list(self._starts), \
            self._next
        return new

    def ends(self):
        """``(u, v)``: the end nodes of every tube, as lists in the tubes' order."""
        slots = list(self._slot.values())
        u_all = list(itertools.chain.from_iterable(b.u for b in self._batches))
        v_all = list(itertools.chain.from_iterable(b.v for b in self._batches))
        return list(map(u_all.__getitem__, slots)), list(map(v_all.__getitem__, slots))

    def columns(self, index) -> _Columns:
        """The tubes as :class:`_Columns`, their nodes numbered by ``index`` (node -> position)."""
        n = len(self._slot)
        slots = np.fromiter(self._slot.values(), np.intp, n)
        starts = np.asarray(self._starts, dtype=np.intp)
        which = np.searchsorted(starts, slots, side="right") - 1
        # per slot (every batch in order, so that a slot is its position), then the live ones
        ends = [np.fromiter(map(index.get, itertools.chain.from_iterable(getattr(b, end) for b in self._batches),
                                itertools.repeat(-1)), np.intp, self._next)[slots] for end in ("u", "v")]
        external = np.concatenate([b.external for b in self._batches])[slots]
        return _Columns(list(self._slot), tuple(self._batches), which, slots - starts[which], ends[0], ends[1], external)


@attrs.frozen(eq=False)
class _Columns:
    """The tubes of a network, in its order, as columns: ``names``, the ``batches``, per tube the
    position of its batch (``which``) and its place in it (``place``), the positions of its nodes
    (``U``, ``V``) and its external pressure. ``columns[i]`` is tube ``i`` as a :class:`_Tube`."""

    names: list
    batches: tuple
    which: np.ndarray
    place: np.ndarray
    U: np.ndarray
    V: np.ndarray
    external: np.ndarray

    def __len__(self):
        return len(self.names)

    def __getitem__(self, i) -> _Tube:
        return self.batches[int(self.which[i])].member(int(self.place[i]))

    def __iter__(self):
        return map(self.__getitem__, range(len(self.names)))

    def present(self, index):
        """The positions of the batches that hold some of the tubes ``index``, in increasing order."""
        return np.flatnonzero(np.bincount(self.which[index], minlength=len(self.batches)))

    def by_batch(self):
        """``(batch, index)`` per batch that still has tubes, in the order of their first tubes:
        the positions ``index`` of its tubes."""
        present, first = np.unique(self.which, return_index=True)
        order = np.argsort(self.which, kind="stable")
        bounds = np.searchsorted(self.which[order], present)
        ends = np.append(bounds[1:], order.size)
        for j in np.argsort(first, kind="stable").tolist():
            yield self.batches[int(present[j])], order[bounds[j]:ends[j]]


@attrs.frozen(eq=False)
class _Part:
    """Tubes evaluated together: ``index`` (into the network's tubes), one fluid, wall and tube
    whose array parameters are aligned with ``index``, and their external pressure(s). The tubes
    of a graded part share one wall, tube and fluid (the same objects); ``reverse`` then holds
    that wall and tube read from the other end (a flow from ``v`` to ``u`` enters at ``z = L``),
    None for a uniform part."""

    index: np.ndarray
    fluid: object
    wall: object
    tube: Tube
    external: object
    reverse: tuple | None = None

    def models(self, forward=True):
        """``(wall, tube)`` of the tubes with the flow from u to v (``forward``) or from v to u."""
        return (self.wall, self.tube) if forward or self.reverse is None else self.reverse

    def split(self, forward):
        """``(positions, wall, tube, external)`` per direction of flow present: the positions in
        ``index`` of the tubes whose flow enters at u (``forward``, a mask over every tube) and
        then at v (a uniform part: all of them, one direction)."""
        if self.reverse is None:
            yield slice(None), self.wall, self.tube, self.external
            return
        ahead = np.asarray(forward[self.index], dtype=bool)
        p_e = np.broadcast_to(np.asarray(self.external, dtype=float), self.index.shape)
        for mask, models in ((ahead, (self.wall, self.tube)), (~ahead, self.reverse)):
            if np.any(mask):
                where = np.flatnonzero(mask)
                yield where, models[0], models[1], _column(p_e[where])

    def ends(self, forward=True):
        """The undeformed radii (m) at the inlet and the outlet of the flow."""
        tube = self.models(forward)[1]
        return _radius_at(tube, 0.0), _radius_at(tube, tube.length)


class _Groups:
    """The tubes grouped by (wall class, fluid class, non-array parameters), each group's
    parameters stacked into arrays, and one broadcast solve per group; each graded tube (a
    radius, thickness or wall parameter that varies along it) is a part of its own, solved by the
    graded-tube engine (:class:`tubefsi.couplers.Graded`) from whichever end its flow enters."""

    def __init__(self, tubes, subset):
        # the batches' groups (a graded batch: its very models; a uniform one: its wall and fluid
        # classes and fixed parameters), then each tube of the subset in its batch's group
        # (one key per distinct triple of models: batches of add_tube calls often share them)
        keys: dict = {}
        by_models: dict = {}
        chosen = np.flatnonzero(subset)
        group_of = np.zeros(len(tubes.batches), dtype=np.intp)
        graded = []
        for b in tubes.present(chosen).tolist():        # (the batches of the subset only)
            batch = tubes.batches[b]
            ids = (id(batch.wall), id(batch.tube), id(batch.rheology))
            g = by_models.get(ids)
            if g is None:
                key = ("graded", ids) if batch.graded else \
                    ((type(batch.wall), _fixed(batch.wall)), (type(batch.rheology), _fixed(batch.rheology)))
                if key not in keys:
                    keys[key] = len(keys)
                    graded.append(batch.graded)
                g = by_models[ids] = keys[key]
            group_of[b] = g
        group = group_of[tubes.which[chosen]]
        order = np.argsort(group, kind="stable")
        bounds = np.searchsorted(group[order], np.arange(len(keys) + 1))
        members = [chosen[order[bounds[g]:bounds[g + 1]]] for g in range(len(keys))]
        self.parts = []
        for index in (index for index, g in zip(members, graded) if index.size and not g):
            wall = _stack(tubes, index, "wall")
            fluid = _stack(tubes, index, "rheology")
            tube = Tube(**_gather(tubes, index, "tube", ("radius", "thickness", "length")))
            self.parts.append(_Part(index, fluid, wall, tube, _column(tubes.external[index])))
        for index in (index for index, g in zip(members, graded) if index.size and g):
            t = tubes[index[0]]
            self.parts.append(_Part(index, t.rheology, t.wall, t.tube, _column(tubes.external[index]),
                                    _reversed(t.wall, t.tube)))
        n = len(tubes)
        self.names = tubes.names               # (to name a tube in an error)
        # the node (gauge) pressures at which the transmural one reaches the limit pressure: the
        # smallest along each tube (``limit``) and at its ends u (z = 0) and v (z = L), which bound
        # the pressures of its nodes (a uniform tube: all three the same)
        self.limit = np.zeros(n)
        self.limit_u = np.zeros(n)
        self.limit_v = np.zeros(n)
        self.radius = np.zeros(n)            # a uniform tube's radius; a graded tube's Poiseuille mean
        self.radius_u = np.zeros(n)          # the undeformed radii at the two ends
        self.radius_v = np.zeros(n)
        self.length = np.zeros(n)
        for part in self.parts:
            index, wall, tube = part.index, part.wall, part.tube
            if part.reverse is None:
                limit = limit_u = limit_v = wall.limit_pressure(tube.reduced_thickness)
                self.radius[index] = np.broadcast_to(tube.radius, index.shape)
            else:
                limit, limit_u, limit_v, self.radius[index] = _along(part)
            for out, value in ((self.limit, limit), (self.limit_u, limit_u), (self.limit_v, limit_v)):
                out[index] = np.broadcast_to(value + np.asarray(part.external), index.shape)
            self.radius_u[index], self.radius_v[index] = (np.broadcast_to(a, index.shape) for a in part.ends())
            self.length[index] = np.broadcast_to(tube.length, index.shape)

    def evaluate(self, drop, outlet, forward, named=False):
        """Flow rates and the derivatives by the inlet and outlet pressures of the tubes (pressure-
        controlled, the flow entering at u where ``forward``, else at v; zeros for the tubes of no
        group). A tube without a steady state raises NoSteadyStateError: with ``named``, one that
        names it (found by solving the tubes of its group one by one: for the error shown only)."""
        q, d_in, d_out, radius_in, radius_out = (np.zeros(drop.size) for _ in range(5))
        for part, index, wall, tube, p_e in self._pieces(forward):
            # Newton's trial pressures: unchecked (the result is checked once; no process-wide
            # warning filter, which would silence other threads too)
            try:
                sol = solve_unchecked(part.fluid, wall, tube, pressure_drop=drop[index],
                                      outlet_pressure=outlet[index], external_pressure=p_e)
            except NoSteadyStateError as exc:
                if not named:
                    raise
                raise self._named(exc, part.fluid, wall, tube, p_e, index, drop, outlet) from None
            q[index] = sol.flow_rate
            _, d_in[index], d_out[index] = sol._sensitivities()
            radius_in[index] = sol.inlet_radius
            radius_out[index] = np.broadcast_to(_radius_at(tube, tube.length) * sol.scene.outlet_stretch, index.shape)
        return q, d_in, d_out, radius_in, radius_out

    def _named(self, exc, fluid, wall, tube, p_e, index, drop, outlet):
        """``exc`` (a pressure-controlled solve of the tubes ``index`` without a steady state) as a
        NoSteadyStateError naming the first of them that has none (each solved alone: the error
        path only), with its inlet and outlet pressures."""
        j = 0
        if index.size > 1:
            p_e = np.broadcast_to(np.asarray(p_e, dtype=float), index.shape)
            for j in range(index.size):
                k = index[j]
                try:
                    solve_unchecked(_entry_of(fluid, index.size, j), _entry_of(wall, index.size, j),
                                    _entry_of(tube, index.size, j),
                                    pressure_drop=drop[k], outlet_pressure=outlet[k], external_pressure=p_e[j])
                except NoSteadyStateError as found:
                    exc = found
                    break
        k = int(index[j])
        inlet = float(drop[k] + outlet[k])
        where = f"tube {self.names[k]!r} at the outlet pressure {float(outlet[k]):.10g} Pa"
        if exc.quantity == "pressure":
            return NoSteadyStateError("pressure", exc.limit, inlet, name="the inlet pressure of " + where)
        return NoSteadyStateError(exc.quantity, exc.limit, None, f"{where} and the inlet pressure {inlet:.10g} Pa "
                                  f"({exc})")

    def _pieces(self, forward):
        """``(part, index, wall, tube, external)``: the tubes of each part, split by the direction
        of their flow where they are graded, each with the models read from where it enters."""
        for part in self.parts:
            for where, wall, tube, p_e in part.split(forward):
                yield part, part.index[where], wall, tube, p_e

    def modulus_derivative(self, drop, outlet, forward):
        r"""Per tube, :math:`\mu\,\partial q/\partial\mu` at fixed end pressures, :math:`\mu` the
        modulus that scales its wall's tube law (:math:`P = \mu\hat P(\lambda)`), oriented as
        :meth:`evaluate`'s flows (from the inlet), with its flows and their derivatives by the end
        pressures: ``(q, d_in, d_out, scale)``.

        The separated identity :math:`F = \int_{p_{out}}^{p_{in}} dp/G(q, R(p)) - L = 0` with
        :math:`R = a\hat\lambda(p/\mu)` makes :math:`F + L` homogeneous of degree one in
        :math:`(p_{in}, p_{out}, \mu)` (transmural pressures), so Euler's identity and
        :math:`\partial_q F = -K/q` give
        :math:`\mu\,\partial q/\partial\mu = (L G_{in} - p_{in})\,\partial q/\partial p_{in}
        - p_{out}\,\partial q/\partial p_{out}` (:math:`L` the installed length, :math:`G_{in}`
        the pressure gradient at the inlet). Uniform tubes only (a graded tube: NaN)."""
        q, d_in, d_out, scale = (np.full(drop.size, np.nan) for _ in range(4))
        for part, index, wall, tube, p_e in self._pieces(forward):
            sol = solve_unchecked(part.fluid, wall, tube, pressure_drop=drop[index], outlet_pressure=outlet[index],
                                  external_pressure=p_e)
            qi = np.broadcast_to(np.asarray(sol.flow_rate, dtype=float), index.shape)
            _, di, do = (np.broadcast_to(np.asarray(x, dtype=float), index.shape) for x in sol._sensitivities())
            q[index], d_in[index], d_out[index] = qi, di, do
            if part.reverse is not None:
                continue
            p_out = outlet[index] - np.asarray(p_e, dtype=float)
            g_in = np.broadcast_to(np.asarray(part.fluid._pressure_gradient(
                qi, np.broadcast_to(np.asarray(sol.inlet_radius, dtype=float), index.shape)), dtype=float), index.shape)
            length = np.broadcast_to(np.asarray(sol.tube.length, dtype=float), index.shape)
            scale[index] = (length * g_in - (p_out + drop[index])) * di - p_out * do
        return q, d_in, d_out, scale

    def check(self, q, radius_u, radius_v, tubes, forward):
        """The converged tubes against the model's assumptions (:mod:`tubefsi.validity`): one
        ModelValidityWarning per failed assumption of a group, naming its first offending tube (a
        graded tube: the section where its flow enters, as for a single graded tube)."""
        for part, index, wall, tube, _ in self._pieces(forward):
            if part.reverse is None:
                scene = make_scene(part.fluid, part.wall, part.tube)
                scene = scene.flat(index.shape) if scene.shape != () else scene
                a_u = a_v = np.broadcast_to(part.tube.radius, index.shape)
            else:
                scene = make_scene(part.fluid, wall, tube).uniform_at(0.0)
                a_u, a_v = self.radius_u[index], self.radius_v[index]
            strain = np.maximum(radius_u[index] / a_u, radius_v[index] / a_v) - 1.0
            found = validity.check(scene, np.abs(q[index]), strain)
            if found.messages:
                slender = np.maximum(radius_u[index], radius_v[index]) / np.broadcast_to(part.tube.length, index.shape)
                name = tubes[index[int(np.argmax(slender))]].name
                validity.warn(attrs.evolve(found, messages=tuple(
                    f"network (e.g. tube {name!r}): {m.replace(' points', ' tubes')}" for m in found.messages)))

    def inlet(self, q, outlet, tubes, forward):
        """Flow-controlled: the inlet pressure and the inlet and outlet radii of the tubes carrying
        ``q > 0`` with ``outlet`` pressure (entering at u where ``forward``, else at v); a flow
        rate beyond a tube's maximum raises, naming it."""
        p_in, radius_in, radius_out = (np.zeros(q.size) for _ in range(3))
        for part, index, wall, tube, p_e in self._pieces(forward):
            fluid = part.fluid
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
            radius_out[index] = np.broadcast_to(_radius_at(tube, tube.length) * sol.scene.outlet_stretch, index.shape)
        return p_in, radius_in, radius_out

    def max_flow(self, outlet, forward):
        """Per tube, :func:`tubefsi.max_flow_rate` at the ``outlet`` pressure with its flow entering
        at u where ``forward``, else at v (0 for the tubes of no group; ``inf`` where it has none)."""
        out = np.zeros(outlet.size)
        for part, index, wall, tube, p_e in self._pieces(forward):
            out[index] = np.broadcast_to(tubefsi_max_flow(part.fluid, wall, tube, outlet_pressure=outlet[index],
                                                          external_pressure=p_e), index.shape)
        return out

    def apparent_viscosity(self, q, mu, stretch):
        """Per tube, the Newtonian viscosity with the fluid's pressure gradient at ``|q|`` in the tube
        of its radius times ``stretch`` (one per tube; ``mu`` where q = 0; a graded tube: the
        uniform tube of its Poiseuille mean radius), :math:`\\mu = \\pi R^4 G(|q|, R)/(8|q|)`."""
        out = mu.copy()
        for part in self.parts:
            index, fluid = part.index, part.fluid
            qi = np.abs(q[index])
            ok = qi > 0
            if np.any(ok):
                a = self.radius[index] * stretch[index]
                g = np.broadcast_to(np.asarray(fluid.pressure_gradient(np.where(ok, qi, 1.0), a), dtype=float),
                                    index.shape)
                value = g * math.pi * a**4 / (8 * np.where(ok, qi, 1.0))
                out[index] = np.where(ok & np.isfinite(value) & (value > 0), value, mu[index])
        return out

    def strain(self, pressure):
        """Per tube, the hoop strain of its wall under the node (gauge) ``pressure`` (one per tube)
        held below 90 % of its limit pressure and above its external pressure (0 for the tubes of
        no part and for a graded tube): the rigid start's estimate of the inflated radii."""
        out = np.zeros(pressure.size)
        for part in self.parts:
            if part.reverse is not None:
                continue
            index, p_e = part.index, np.asarray(part.external, dtype=float)
            transmural = np.clip(pressure[index] - p_e, 0.0, 0.9 * (self.limit[index] - p_e))
            out[index] = np.broadcast_to(part.wall.strain(transmural, part.tube.reduced_thickness), index.shape)
        return out

    def nominal_viscosity(self, n):
        mu = np.empty(n)
        for part in self.parts:
            mu[part.index] = np.broadcast_to(np.asarray(part.fluid.apparent_viscosity(1.0), dtype=float),
                                             part.index.shape)
        return mu

    def fluids(self):
        """``(index, fluid)`` per part (the results' wall shear stresses)."""
        return tuple((part.index, part.fluid) for part in self.parts)


def _entry_of(model, n, j):
    """``model`` (whose array parameters have length ``n`` or are scalars) at entry ``j``."""
    arrays = {f: np.asarray(v)[j] for f in _array_fields(type(model))
              if isinstance(v := getattr(model, f), np.ndarray) and v.shape == (n,)}
    return attrs.evolve(model, **arrays) if arrays else model


def _radius_at(tube, z):
    """The undeformed radius at the position ``z`` (m): a(z) of a graded tube, else its radius."""
    if isinstance(tube.radius, Profile):
        return float(tube.radius(np.asarray(float(z))))
    return tube.radius


#: Positions (besides the breakpoints) where a graded tube's limit pressure and mean radius are sampled.
_SAMPLES = 65


def _along(part):
    r"""A graded tube's limit pressures and its radius for the rigid start: the smallest local limit
    pressure of its sections (sampled at 65 positions and its breakpoints), the local ones at its
    ends ``z = 0`` and ``z = L`` (the bounds of its nodes' pressures: the pressure at an end is its
    node's; the interior is checked by the graded-tube solve itself, which raises where the
    profile would pass a section's own limit), and the Poiseuille mean
    :math:`(\frac1L\int_0^L a^{-4}\,dz)^{-1/4}` (trapezoidal rule)."""
    scene = make_scene(part.fluid, part.wall, part.tube)
    L = float(part.tube.length)
    z = np.union1d(np.linspace(0.0, L, _SAMPLES), [b for b in _breakpoints(scene) if 0.0 < b < L])
    wall, a, tb = scene.at_position(z)
    limit = np.broadcast_to(np.asarray(wall._limit_pressure(tb), dtype=float), z.shape)
    a = np.broadcast_to(a, z.shape)
    mean = float((np.trapezoid(a**-4.0, z) / L) ** -0.25)
    return float(np.min(limit)), float(limit[0]), float(limit[-1]), mean


def _flipped(profile, length):
    r"""The profile read from the other end of a tube of ``length``: :math:`z \mapsto f(L - z)`
    (it validates its values as the original does)."""
    lo, hi = profile.span
    return Profile(lambda z: profile(length - np.asarray(z, dtype=float)),
                   breakpoints=[length - b for b in profile.breakpoints], span=(length - hi, length - lo))


def _reversed(wall, tube):
    """``(wall, tube)`` of a graded tube read from its outlet: every profile flipped along the
    (stress-free) length, the numbers kept."""
    L = float(tube.length)
    flip = {f: _flipped(v, L) for f in _array_fields(type(wall)) if isinstance(v := getattr(wall, f), Profile)}
    tube_flip = {f: _flipped(v, L) for f in ("radius", "thickness") if isinstance(v := getattr(tube, f), Profile)}
    return (attrs.evolve(wall, **flip) if flip else wall), attrs.evolve(tube, **tube_flip)


def _fixed(model):
    """The values of a model's parameters that cannot be arrays (they split groups)."""
    return tuple(getattr(model, name) for name in _scalar_fields(type(model)))


def _scalar_fields(cls):
    arrays = set(_array_fields(cls))
    return tuple(f.name for f in attrs.fields(cls) if f.init and f.name not in arrays) if attrs.has(cls) else ()


def _column(values):
    a = np.asarray(values, dtype=float)
    return float(a[0]) if np.all(a == a[0]) else a


def _gather(tubes, index, which, fields) -> dict:
    """field -> the values of that parameter of the ``which`` model of the tubes ``index`` (of
    :class:`_Columns` ``tubes``): a float where all agree, else an array aligned with ``index``.
    One read per distinct model of scalars (the batches of add_tube calls often share one), one
    indexing per batch of arrays (an add_tubes call)."""
    present = tubes.present(index)
    position = np.zeros(len(tubes.batches), dtype=np.intp)
    position[present] = np.arange(present.size)
    inverse = position[tubes.which[index]]          # per tube, its batch's position in present
    scalars: dict = {}                 # id(model) -> (model, positions in present)
    arrays = []
    for j, b in enumerate(present.tolist()):
        batch = tubes.batches[b]
        model = getattr(batch, which)
        if batch.rows is None:
            scalars.setdefault(id(model), (model, []))[1].append(j)
        else:
            arrays.append((j, model, batch.rows))
    out = {}
    for f in fields:
        column = np.zeros(present.size)
        for model, at in scalars.values():
            column[at] = getattr(model, f)
        column = column[inverse]
        for j, model, rows in arrays:
            at = np.flatnonzero(inverse == j)
            value = getattr(model, f)
            column[at] = value[rows[tubes.place[index[at]]]] if isinstance(value, np.ndarray) and value.ndim \
                else value
        out[f] = _column(column)
    return out


def _stack(tubes, index, which):
    """One model whose array parameters hold the values of the tubes ``index`` (a scalar where all
    agree): their batches' model itself where they all share it, with scalar parameters."""
    batches = [tubes.batches[b] for b in tubes.present(index).tolist()]
    model = getattr(batches[0], which)
    if all(getattr(b, which) is model and b.rows is None for b in batches):
        return model
    return attrs.evolve(model, **_gather(tubes, index, which, _array_fields(type(model))))
