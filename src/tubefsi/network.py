r"""Steady flow through a network of soft tubes (``docs/network.md``): the :class:`Network` a user
builds (tubes, boundary conditions, networkx). Its Newton solver is in :mod:`tubefsi.network_solver`, the
evaluation of its tubes by groups in :mod:`tubefsi.network_groups`, its results in
:mod:`tubefsi.network_solution`.
"""

from __future__ import annotations

import copy
import itertools
import operator
from collections.abc import Hashable

import numpy as np

from ._keywords import checked_keywords
from ._progress import bar
from ._validation import as_array, as_scalar
from .errors import InvalidParameterError
from .fields import broadcast_model, varies, parameter_shape
from .geometry import Tube
from .network_fit import fit_network
from .network_groups import _Tubes
from .network_solution import NetworkSolution, _hashable
from .network_solver import _Solver
from .rheology.base import Rheology
from .scene import resolve
from .walls.base import WallModel

__all__ = ["Network", "NetworkSolution"]


class Network:
    """A graph of soft tubes between named nodes.

    Parameters
    ----------
    rheology : model instance, class or registered name, optional
        The fluid of every tube that does not name its own.

    Examples
    --------
    ::

        net = tubefsi.Network(rheology=fluid)
        net.add_tube("in", "j", wall, tube)
        net.add_tube("j", "a", wall, tube)
        net.add_tube("j", "b", wall, tube)
        net.set_inflow("in", 1e-9)
        net.set_pressure("a", 0.0)
        net.set_pressure("b", 50.0)
        result = net.solve()
        result.pressure["j"], result.flow_rate[("j", "a")]
    """

    @checked_keywords
    def __init__(self, rheology: Rheology | type[Rheology] | str | None = None):
        self.rheology = None if rheology is None else resolve("rheology", rheology)
        self._tubes = _Tubes()
        self._nodes: dict = {}
        self._pressure: dict = {}
        self._inflow: dict = {}
        #: node -> (resistance, distal pressure) of a resistance outlet
        self._resistance: dict = {}
        #: node -> (x, y), for :meth:`NetworkSolution.plot`
        self.positions: dict = {}

    # ------------------------------------------------------------------ building
    @checked_keywords
    def add_tube(self, u: Hashable, v: Hashable, wall: WallModel | type[WallModel] | str, tube: Tube, *,
                 name: Hashable | None = None, rheology: Rheology | type[Rheology] | str | None = None,
                 external_pressure: float = 0.0) -> Network:
        """Add a tube from node ``u`` to node ``v`` (positive flow runs from ``u`` to ``v``).

        ``name`` (any hashable) defaults to ``(u, v)``; two tubes between the same nodes need
        names. ``rheology`` overrides the network's fluid for this tube. ``external_pressure``
        (Pa, any sign) is the pressure outside this tube: its wall sees the node pressures minus
        it (``docs/walls_beyond.md``, "External pressure and collapse"); a node pressure whose
        transmural pressure falls below the wall's buckling bound raises ``BucklingError``.
        Parameters are scalars or, for a graded (e.g. tapered) tube, functions of the position
        along it (``docs/graded.md``; :meth:`tubefsi.Tube.tapered`), ``z = 0`` at ``u``: its flow
        from ``v`` to ``u`` is that of the tube read from ``v`` (``docs/network.md``, "Graded
        tubes").
        """
        for label, node in (("u", u), ("v", v)):
            if not _hashable(node):
                raise InvalidParameterError(label, "a hashable node name (a number, text, a tuple...)", node)
        if name is not None and not _hashable(name):
            raise InvalidParameterError("name", "a hashable name (a number, text, a tuple...)", name)
        name = (u, v) if name is None else name
        if u == v:
            raise InvalidParameterError("v", "a node other than u", v, "a tube joins two distinct nodes")
        if name in self._tubes:
            raise InvalidParameterError("name", "a name no other tube has", name,
                                        "tubes between the same two nodes need distinct names")
        wall, tube, fluid = self._models(wall, tube, rheology)
        for label, model in (("wall", wall), ("rheology", fluid), ("tube", tube)):
            if parameter_shape(model) != ():
                raise InvalidParameterError(label, "scalar parameters (one tube per add_tube)", model)
        p_e = as_array("external_pressure", external_pressure, "the real numbers", np.isfinite)
        if p_e.ndim:
            raise InvalidParameterError("external_pressure", "a number (one tube per add_tube)", external_pressure)
        for node in (u, v):
            self._nodes.setdefault(node, len(self._nodes))
        self._tubes.add([name], [u], [v], wall, tube, fluid, [float(p_e)], None)
        return self

    def _models(self, wall, tube, rheology):
        """``(wall, tube, fluid)`` of a tube to add: the models resolved (the network's fluid
        by default), the tube a :class:`~tubefsi.Tube`."""
        wall = resolve("wall", wall)
        fluid = self.rheology if rheology is None else resolve("rheology", rheology)
        if fluid is None:
            raise InvalidParameterError("rheology", "a fluid, here or in Network(rheology=...)", None)
        if not isinstance(tube, Tube):
            raise InvalidParameterError("tube", "a tubefsi.Tube", tube)
        return wall, tube, fluid

    @checked_keywords
    def add_tubes(self, u, v, wall, tube, *, names=None, rheology=None, external_pressure=0.0):
        """Add ``n`` tubes at once, from node ``u[k]`` to node ``v[k]`` (sequences or arrays of
        node names of length ``n``), as :meth:`add_tube` does for one.

        ``wall``, ``tube`` and ``rheology`` are one model each whose parameters are scalars
        (shared by every tube) or arrays of length ``n`` (one entry per tube), e.g.
        ``Tube(radius=radii, thickness=0.3 * radii, length=lengths)``; ``external_pressure`` is a
        number or an array of length ``n``; ``names`` (default ``(u[k], v[k])``) a sequence of
        ``n`` distinct names. Everything is checked before any tube is added. Building from
        arrays costs a fraction of calling :meth:`add_tube` per tube (``docs/network.md``).
        """
        u, v = _names_of("u", u), _names_of("v", v)
        n = len(u)
        if n == 0:
            raise InvalidParameterError("u", "a sequence of at least one node name", u)
        if len(v) != n:
            raise InvalidParameterError("v", f"a sequence of {n} node names, as long as u", None, f"it has {len(v)}")
        names = list(zip(u, v)) if names is None else _names_of("names", names)
        if len(names) != n:
            raise InvalidParameterError("names", f"{n} names, one per tube", len(names))
        if any(map(operator.eq, u, v)):                   # (a loop: found in C, then named)
            k = next(k for k, (a, b) in enumerate(zip(u, v)) if a == b)
            raise InvalidParameterError(f"v[{k}]", "a node other than u[k]", v[k], "a tube joins two distinct nodes")
        taken = self._tubes.names()
        if len(set(names)) != n or not taken.isdisjoint(names):       # (set operations: one pass in C)
            seen = set()
            for k, name in enumerate(names):
                if name in taken or name in seen:
                    raise InvalidParameterError(f"names[{k}]", "a name no other tube has", name,
                                                "tubes between the same two nodes need distinct names")
                seen.add(name)
        wall, tube, fluid = self._models(wall, tube, rheology)
        models = []
        for label, model in (("wall", wall), ("tube", tube), ("rheology", fluid)):
            if parameter_shape(model) not in ((), (n,)):
                raise InvalidParameterError(label, f"scalar parameters or arrays of length {n} (one entry per "
                                            f"tube)", model, f"its parameters have the shape {parameter_shape(model)}")
            if varies(model):
                raise InvalidParameterError(label, "a uniform tube and wall (add a tube that varies along z, a "
                                            "graded tube, by add_tube)", model)
            models.append(broadcast_model(model, (n,)))
        wall, tube, fluid = models
        p_e = as_array("external_pressure", external_pressure, "the real numbers", np.isfinite)
        if p_e.shape not in ((), (n,)):
            raise InvalidParameterError("external_pressure", f"a number or an array of length {n}", p_e)
        p_e = np.broadcast_to(p_e.astype(float), (n,))
        shared = parameter_shape(wall) == parameter_shape(tube) == parameter_shape(fluid) == ()
        nodes = self._nodes
        # new nodes in order of first appearance, u[0], v[0], u[1], ... as add_tube adds them
        fresh = [node for node in dict.fromkeys(itertools.chain.from_iterable(zip(u, v))) if node not in nodes]
        nodes.update(zip(fresh, range(len(nodes), len(nodes) + len(fresh))))
        # one batch of columns: no Python object per tube (a tube is made when asked for by name)
        self._tubes.add(names, u, v, wall, tube, fluid, p_e, None if shared else np.arange(n))
        return self

    @checked_keywords
    def remove_tube(self, name):
        """Remove tube ``name``. A node left without a tube leaves the network with its
        boundary condition and position."""
        t = self._tubes.pop(name, None) if _hashable(name) else None
        if t is None:
            raise InvalidParameterError("name", "a name of one of the network's tubes", name)
        u, v = self._tubes.ends()
        used = set(u).union(v)
        gone = [node for node in (t.u, t.v) if node not in used]
        if gone:
            for node in gone:
                for store in (self._pressure, self._inflow, self._resistance, self.positions):
                    store.pop(node, None)
            self._nodes = {node: i for i, node in enumerate(k for k in self._nodes if k not in gone)}
        return self

    @checked_keywords
    def set_pressure(self, node: Hashable, pressure: float) -> Network:
        """Fix the (transmural, gauge) pressure of ``node`` (Pa, >= 0)."""
        self._free_of(node, "pressure")
        self._pressure[node] = as_scalar("pressure", pressure, "[0, inf)", lambda a: a >= 0)
        return self

    @checked_keywords
    def set_inflow(self, node: Hashable, flow_rate: float) -> Network:
        """Inject ``flow_rate`` (m^3/s; negative: withdraw) at ``node``."""
        self._free_of(node, "inflow")
        self._inflow[node] = as_scalar("flow_rate", flow_rate, "(-inf, inf)", np.isfinite)
        return self

    @checked_keywords
    def set_resistance(self, node, resistance, distal_pressure=0.0):
        """Make ``node`` a resistance outlet: a terminal resistance ``resistance`` (Pa s/m^3, > 0)
        to a ``distal_pressure`` (Pa) takes the flow ``(p - distal_pressure) / resistance`` out of
        the network at ``node`` (the steady state of a Windkessel, whose resistance is R1 + R2).
        A component with a resistance outlet needs no fixed pressure."""
        self._free_of(node, "resistance")
        r = as_scalar("resistance", resistance, "(0, inf) Pa s/m^3", lambda a: np.isfinite(a) & (a > 0))
        p_d = as_scalar("distal_pressure", distal_pressure, "the real numbers (Pa)", np.isfinite)
        self._resistance[node] = (r, p_d)
        return self

    @checked_keywords
    def set_pressures(self, nodes, pressures) -> Network:
        """Fix the pressures of many nodes at once, as :meth:`set_pressure` for each: ``nodes`` a
        sequence or 1-D array of node names, ``pressures`` (Pa, >= 0) a number or an array as
        long. Everything is checked before any is set."""
        nodes, values = self._many(nodes, pressures, "pressures", "[0, inf)", lambda a: a >= 0)
        self._free_of_all(nodes, "pressure")
        self._pressure.update(zip(nodes, values))
        return self

    @checked_keywords
    def set_inflows(self, nodes, flow_rates) -> Network:
        """Inject flow rates at many nodes at once, as :meth:`set_inflow` for each (m^3/s, a
        number or an array as long as ``nodes``)."""
        nodes, values = self._many(nodes, flow_rates, "flow_rates", "(-inf, inf)", np.isfinite)
        self._free_of_all(nodes, "inflow")
        self._inflow.update(zip(nodes, values))
        return self

    @checked_keywords
    def set_resistances(self, nodes, resistances, distal_pressures=0.0) -> Network:
        """Make many nodes resistance outlets at once, as :meth:`set_resistance` for each, each
        with its own terminal resistance (Pa s/m^3, > 0) and distal pressure (Pa): numbers or
        arrays as long as ``nodes``."""
        nodes, r = self._many(nodes, resistances, "resistances", "(0, inf) Pa s/m^3",
                              lambda a: np.isfinite(a) & (a > 0))
        _, p_d = self._many(nodes, distal_pressures, "distal_pressures", "the real numbers (Pa)", np.isfinite)
        self._free_of_all(nodes, "resistance")
        self._resistance.update(zip(nodes, zip(r, p_d)))
        return self

    def _many(self, nodes, values, label, admissible, check):
        """``(nodes, values)`` of a bulk setter as lists, the values checked and broadcast."""
        nodes = _names_of("nodes", nodes)
        if len(set(nodes)) != len(nodes):      # two values for one node: which one is meant?
            seen = set()
            k = next(k for k, node in enumerate(nodes) if node in seen or seen.add(node))
            raise InvalidParameterError(f"nodes[{k}]", "a node not named earlier in the same call", nodes[k])
        array = as_array(label, values, admissible, check)
        if array.shape not in ((), (len(nodes),)):
            raise InvalidParameterError(label, f"a number or an array of length {len(nodes)} (one per node)",
                                        array)
        return nodes, np.broadcast_to(array.astype(float), (len(nodes),)).tolist()

    def _free_of_all(self, nodes, kind):
        """:meth:`_free_of` for many nodes (one set intersection per other kind)."""
        for other, store in (("pressure", self._pressure), ("inflow", self._inflow),
                             ("resistance", self._resistance)):
            if other != kind and store:
                clash = store.keys() & set(nodes)
                if clash:
                    self._free_of(next(iter(clash)), kind)

    def _free_of(self, node, kind):
        """Raise unless ``node`` has no boundary condition but one of ``kind`` (which it replaces)."""
        for other, store in (("pressure", self._pressure), ("inflow", self._inflow),
                             ("resistance", self._resistance)):
            if other != kind and _hashable(node) and node in store:
                raise InvalidParameterError("node", "a node with one boundary condition: a pressure, an inflow or "
                                            "a resistance", node, f"it has {'a fixed' if other == 'pressure' else 'an'}"
                                            f" {other} already")

    @checked_keywords
    def set_position(self, node: Hashable, xy: tuple[float, float]) -> Network:
        """Place ``node`` at ``xy = (x, y)`` or ``(x, y, z)`` (m, finite) for the plot (which draws
        x and y) and the ``.vtp`` file. A node may be placed before its tubes are added; the
        position of a node that is in no tube is not used."""
        if not _hashable(node):
            raise InvalidParameterError("node", "a hashable node name", node)
        try:
            point = np.asarray(xy, dtype=float)
        except (TypeError, ValueError):
            point = None
        if point is None or point.shape not in ((2,), (3,)) or not np.all(np.isfinite(point)):
            raise InvalidParameterError("xy", "a point (x, y) or (x, y, z) of finite numbers (m)", xy)
        self.positions[node] = tuple(point.tolist())
        return self

    @property
    def nodes(self) -> list:
        return list(self._nodes)

    @property
    def tube_names(self) -> list:
        return list(self._tubes)

    # ------------------------------------------------------------------ networkx
    @classmethod
    @checked_keywords
    def from_networkx(cls, graph, *, rheology=None, wall="wall", tube="tube", fluid="rheology",
                      pressure="pressure", inflow="inflow", pos="pos"):
        """A network from a networkx graph whose edges hold a ``wall`` and a ``tube`` attribute
        (and optionally a ``rheology`` attribute, the fluid of that tube); nodes may hold
        ``pressure``, ``inflow``, ``pos`` and ``resistance`` (with ``distal_pressure``, default 0: a
        resistance outlet, :meth:`set_resistance`). Each keyword names the attribute to read (``fluid``:
        the edge attribute holding a tube's rheology, ``"rheology"`` by default).

        Edges run from the first node to the second as networkx lists them; a tube is named by
        the edge attribute ``name`` where there is one (as :meth:`to_networkx` writes it), else
        ``(u, v, key)`` in a multigraph and ``(u, v)`` in a graph.
        """
        net = cls(rheology=rheology)
        multi = graph.is_multigraph()
        edges = graph.edges(keys=True, data=True) if multi else ((u, v, None, d) for u, v, d in graph.edges(data=True))
        for u, v, key, data in edges:
            for attr in (wall, tube):
                if attr not in data:
                    raise InvalidParameterError(f"edge ({u!r}, {v!r})", f"an edge with a {attr!r} attribute", data)
            name = data["name"] if "name" in data else (u, v, key) if multi else None
            net.add_tube(u, v, data[wall], data[tube], name=name,
                         rheology=data.get(fluid), external_pressure=data.get("external_pressure", 0.0))
        for node, data in graph.nodes(data=True):
            if pressure in data:
                net.set_pressure(node, data[pressure])
            if inflow in data:
                net.set_inflow(node, data[inflow])
            if "resistance" in data:
                net.set_resistance(node, data["resistance"], data.get("distal_pressure", 0.0))
            if pos in data:
                net.set_position(node, data[pos])
        return net

    def to_networkx(self):
        """A ``networkx.MultiDiGraph`` (keys and the edge attribute ``name``: the tube names) with
        the same attributes that :meth:`from_networkx` reads (which gives the same names back)."""
        import networkx as nx

        graph = nx.MultiDiGraph()
        for node in self._nodes:
            data = {}
            if node in self._pressure:
                data["pressure"] = self._pressure[node]
            if node in self._inflow:
                data["inflow"] = self._inflow[node]
            if node in self._resistance:
                data["resistance"], data["distal_pressure"] = self._resistance[node]
            if node in self.positions:
                data["pos"] = self.positions[node]
            graph.add_node(node, **data)
        for t in self._tubes.values():
            wall, tube, fluid = t.models()
            graph.add_edge(t.u, t.v, key=t.name, name=t.name, wall=wall, tube=tube, rheology=fluid,
                           external_pressure=t.external_pressure)
        return graph

    # ------------------------------------------------------------------ solving
    @checked_keywords
    def solve(self, *, rtol: float = 1e-13, max_iterations: int = 100, progress: bool | str = False,
              initial: NetworkSolution | dict | None = None) -> NetworkSolution:
        """The steady state: node pressures and tube flow rates (a :class:`NetworkSolution`).

        ``initial`` (a :class:`NetworkSolution`, e.g. the previous point of a sweep, or a mapping
        node -> pressure in Pa) starts Newton's method from those pressures at the nodes it
        names (the rigid start elsewhere): a warm start, which changes the iterations taken,
        not the answer.

        ``progress`` (bool or ``"auto"``) shows a progress bar over the Newton iterations (tqdm,
        ``pip install 'tubefsi[progress]'``; ``"auto"``: only if tqdm is installed and standard
        error is a terminal); it ends at convergence, usually well before ``max_iterations``.

        Raises
        ------
        InvalidParameterError
            An empty network, a fixed node that is in no tube, a part of the network without a
            fixed pressure, or inflows that would need a negative pressure somewhere.
        NoSteadyStateError
            A tube reaches its limit pressure (no steady state carries the inflows), naming it.
        ConvergenceError
            Newton's method did not bring the mass balance below ``rtol`` times the throughput.

        Warns
        -----
        AccuracyWarning
            When rounding alone (pressures close to a limit pressure) keeps the mass balance above
            ``rtol`` times the throughput; the warning gives the balance reached.
        """
        rtol = as_scalar("rtol", rtol, "[1e-15, 1)", lambda a: (a >= 1e-15) & (a < 1))
        if isinstance(max_iterations, (bool, np.bool_)) or not isinstance(max_iterations, (int, np.integer)) \
                or max_iterations < 1:
            raise InvalidParameterError("max_iterations", "an integer >= 1", max_iterations)
        max_iterations = int(max_iterations)
        start = _initial_pressures(initial)
        solver = _Solver(self._snapshot())
        shown = bar(max_iterations, progress, "tubefsi.Network.solve", unit="Newton step")
        try:
            return solver.run(rtol, max_iterations, shown, start)
        finally:
            shown.close()

    @checked_keywords
    def fit(self, *, pressure=None, flow_rate=None, moduli=None, resistances=None, pressure_sigma=None,
            flow_sigma=None, rtol: float = 1e-13):
        r"""Calibrate per-group wall moduli and terminal resistances to measured node pressures and
        tube flow rates by least squares (``docs/network.md``, "Calibration").

        Parameters
        ----------
        pressure : mapping node -> Pa, optional
            Measured node pressures.
        flow_rate : mapping tube name -> m^3/s, optional
            Measured flow rates (positive from the tube's ``u`` to its ``v``).
        moduli : mapping group name -> sequence of tube names, optional
            Each group's tubes share one value of the modulus that scales their walls' tube law
            (:math:`P = \mu\hat P(\lambda)`: a neo-Hookean wall's shear modulus, a linear wall's
            Young's modulus), fitted as ``"modulus[<group>]"``; they start from one value of it.
        resistances : sequence of nodes, optional
            Resistance outlets (:meth:`set_resistance`) whose resistance is fitted, as
            ``"resistance[<node>]"``.
        pressure_sigma, flow_sigma : float, optional
            The scales of the pressure and flow residuals (default: the root mean square of the
            measured values of each kind).
        rtol : float, optional
            The relative tolerance of each network solve (as :meth:`solve`).

        Returns
        -------
        NetworkFitResult
            ``network`` (a copy with the fitted values), ``solution``, ``parameters``,
            ``standard_errors`` (Gauss–Newton, by the delta method), ``covariance``,
            ``residuals`` (weighted), ``success``, ``message``.

        Warns
        -----
        FitWarning
            Where the data do not support the fit (as :func:`tubefsi.fit`).

        Notes
        -----
        Every parameter is fitted through its logarithm, within a factor 1e4 of its start, with
        the analytic Jacobian of the implicit function theorem on the Kirchhoff system; each
        evaluation is one :meth:`solve`, warm-started from the previous one.
        """
        return fit_network(self, pressure=pressure, flow_rate=flow_rate, moduli=moduli, resistances=resistances,
                           pressure_sigma=pressure_sigma, flow_sigma=flow_sigma,
                           rtol=as_scalar("rtol", rtol, "[1e-15, 1)", lambda a: (a >= 1e-15) & (a < 1)))

    def _snapshot(self):
        """A copy that later changes to this network do not reach (the solution keeps it)."""
        new = copy.copy(self)
        for name in ("_nodes", "_pressure", "_inflow", "_resistance", "positions"):
            setattr(new, name, dict(getattr(self, name)))
        new._tubes = self._tubes.copy()
        return new


def _initial_pressures(initial):
    """A warm start as a dict node -> pressure (None: the rigid start)."""
    if initial is None:
        return None
    if isinstance(initial, NetworkSolution):
        return initial.pressure
    if not hasattr(initial, "items"):
        raise InvalidParameterError("initial", "a NetworkSolution or a mapping node -> pressure (Pa)", initial)
    start = {}
    for node, value in initial.items():
        start[node] = as_scalar(f"initial[{node!r}]", value, "[0, inf) Pa", lambda a: np.isfinite(a) & (a >= 0))
    return start


def _names_of(label, values) -> list:
    """Node or tube names given as a sequence or an array, as a list of plain Python objects."""
    if isinstance(values, np.ndarray):
        if values.ndim != 1:
            raise InvalidParameterError(label, "a 1-D sequence of names", values)
        return values.tolist()
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
        raise InvalidParameterError(label, "a sequence of names (a list or a 1-D array)", values)
    values = list(values)
    for k, x in enumerate(values):
        if not _hashable(x):
            raise InvalidParameterError(f"{label}[{k}]", "a hashable name", x)
    return values

