r"""The steady state of a :class:`~tubefsi.Network`: its results as arrays aligned with the tubes
and the nodes, tables (dict columns, pandas, xarray, CSV, JSON) and each tube's full single-tube solution
(``docs/network.md``, "Results").

Everything here is read from the arrays the solver hands over; the mappings by name are built
once per solution, on first use, so that every read after it is O(1).
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Hashable

import attrs
import numpy as np

from . import _html
from ._keywords import checked_keywords
from ._validation import as_array
from .export import _require
from .fields import _array_fields
from .network_groups import _reversed
from .errors import InvalidParameterError
from .solution import Solution
from .solve import solve

__all__ = ["NetworkSolution"]

#: The units of the columns of the node and tube tables.
UNITS = {"pressure": "Pa", "inflow": "m^3/s", "flow_rate": "m^3/s", "pressure_u": "Pa", "pressure_v": "Pa",
         "pressure_drop": "Pa", "radius_u": "m", "radius_v": "m", "length": "m", "strain_u": "1", "strain_v": "1",
         "wall_shear_stress_u": "Pa", "wall_shear_stress_v": "Pa", "reynolds_number": "1"}


def _frozen(a) -> np.ndarray:
    """``a`` as a float array that cannot be written (handed out without a copy)."""
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@attrs.frozen(kw_only=True, repr=False, eq=False)
class NetworkSolution:
    r"""The steady state of a :class:`~tubefsi.Network`.

    Arrays (read-only, handed out without a copy, so a read is O(1)) follow the order of
    :attr:`nodes` (node arrays) or of :attr:`tube_names` (tube arrays):

    ==========================  =====================================================================
    ``pressures``               node pressures (Pa)
    ``flow_rates``              tube flow rates (m^3/s), positive from the tube's ``u`` to its ``v``
    ``pressure_drops``          ``p_u - p_v`` per tube (Pa)
    ``radius_u``, ``radius_v``  deformed inner radii at the tube's two ends (m)
    ``strain_u``, ``strain_v``  hoop strains ``R/a - 1`` at the two ends
    ``wall_shear_stress_u``,    wall shear stress magnitudes :math:`\tau_w = G R/2` at the two ends
    ``wall_shear_stress_v``     (Pa), with the fluid's pressure gradient G at the end's radius
    ==========================  =====================================================================

    :meth:`reynolds_numbers` gives the Metzner–Reed Reynolds number per tube for a density.

    Attributes
    ----------
    pressure : dict
        node -> pressure (Pa) (built once, on first use).
    flow_rate : dict
        tube name -> flow rate (m^3/s), positive from the tube's ``u`` to its ``v``.
    iterations : int
        Newton iterations taken.
    residual : float
        The largest mass imbalance of a free node over the throughput.
    """

    net: object
    nodes: list
    #: the tubes as columns (``network_groups._Columns``: ``tubes[i]`` is tube ``i``)
    tubes: object
    p: np.ndarray = attrs.field(converter=_frozen)
    q: np.ndarray = attrs.field(converter=_frozen)
    radius_u: np.ndarray = attrs.field(converter=_frozen)
    radius_v: np.ndarray = attrs.field(converter=_frozen)
    iterations: int
    residual: float
    #: per tube: the indices of its two nodes into ``nodes``, its undeformed radius (at its ``u``
    #: end; ``radius0_v`` at its ``v`` end where it differs: a graded tube) and its length
    U: np.ndarray
    V: np.ndarray
    radius0: np.ndarray = attrs.field(converter=_frozen)
    length: np.ndarray = attrs.field(converter=_frozen)
    radius0_v: np.ndarray | None = attrs.field(default=None, converter=attrs.converters.optional(_frozen))
    #: (tube indices, their fluid with parameters stacked in that order) per group of tubes
    fluids: tuple = ()
    _memo: dict = attrs.field(init=False, factory=dict)

    def _once(self, key, build):
        """``build()`` the first time ``key`` is asked for, the same object afterwards."""
        if key not in self._memo:
            self._memo[key] = build()
        return self._memo[key]

    # ------------------------------------------------------------------ by name
    @property
    def pressure(self) -> dict:
        return self._once("pressure", lambda: dict(zip(self.nodes, self.p.tolist())))

    @property
    def flow_rate(self) -> dict:
        return self._once("flow_rate", lambda: dict(zip(self.tube_names, self.q.tolist())))

    @property
    def tube_names(self) -> list:
        return self._once("tube_names", lambda: list(self.tubes.names))

    @property
    def tube_index(self) -> dict:
        """tube name -> its position in the tube arrays."""
        return self._once("tube_index", lambda: {name: i for i, name in enumerate(self.tube_names)})

    @property
    def node_index(self) -> dict:
        """node -> its position in the node arrays."""
        return self._once("node_index", lambda: {node: i for i, node in enumerate(self.nodes)})

    # ------------------------------------------------------------------ arrays
    @property
    def pressures(self) -> np.ndarray:
        """Node pressures (Pa) in the order of :attr:`nodes` (read-only)."""
        return self.p

    @property
    def flow_rates(self) -> np.ndarray:
        """Tube flow rates (m^3/s) in the order of :attr:`tube_names` (read-only)."""
        return self.q

    @property
    def pressure_drops(self) -> np.ndarray:
        """``p_u - p_v`` per tube (Pa, read-only)."""
        return self._once("pressure_drops", lambda: _frozen(self.p[self.U] - self.p[self.V]))

    @property
    def strain_u(self) -> np.ndarray:
        """Hoop strain ``R/a - 1`` at each tube's ``u`` end (read-only)."""
        return self._once("strain_u", lambda: _frozen(self.radius_u / self.radius0 - 1.0))

    @property
    def strain_v(self) -> np.ndarray:
        """Hoop strain ``R/a - 1`` at each tube's ``v`` end (read-only)."""
        a = self.radius0 if self.radius0_v is None else self.radius0_v
        return self._once("strain_v", lambda: _frozen(self.radius_v / a - 1.0))

    @property
    def wall_shear_stress_u(self) -> np.ndarray:
        """Wall shear stress magnitude ``G R / 2`` at each tube's ``u`` end (Pa, read-only)."""
        return self._once("tau_u", lambda: self._wall_shear(self.radius_u))

    @property
    def wall_shear_stress_v(self) -> np.ndarray:
        """Wall shear stress magnitude ``G R / 2`` at each tube's ``v`` end (Pa, read-only)."""
        return self._once("tau_v", lambda: self._wall_shear(self.radius_v))

    def _wall_shear(self, radius):
        """``G(|q|, R) R / 2`` per tube, with each group's fluid (0 where no flow)."""
        tau = np.zeros(self.q.size)
        q = np.abs(self.q)
        for index, fluid in self.fluids:
            flowing = index[q[index] > 0]
            if flowing.size:
                mine = np.isin(index, flowing)
                fluid = _rows(fluid, mine) if not np.all(mine) else fluid
                g = np.broadcast_to(np.asarray(fluid.pressure_gradient(q[flowing], radius[flowing]), dtype=float),
                                    flowing.shape)
                tau[flowing] = 0.5 * g * radius[flowing]
        return _frozen(tau)

    @checked_keywords
    def reynolds_numbers(self, density) -> np.ndarray:
        r"""The Metzner–Reed Reynolds number :math:`8\rho V^2/\tau_w` per tube (the larger of its two
        ends; 0 without flow), for the fluid ``density`` (kg/m^3): the mean velocity
        :math:`V = |q|/(\pi R^2)` and the wall shear stress at the same end."""
        rho = float(as_array("density", density, "(0, inf) kg/m^3", lambda a: np.isfinite(a) & (a > 0)))
        out = np.zeros(self.q.size)
        for radius, tau in ((self.radius_u, self.wall_shear_stress_u), (self.radius_v, self.wall_shear_stress_v)):
            velocity = np.abs(self.q) / (math.pi * radius**2)
            with np.errstate(divide="ignore", invalid="ignore"):
                re = np.where(tau > 0, 8.0 * rho * velocity**2 / np.where(tau > 0, tau, 1.0), 0.0)
            out = np.maximum(out, re)
        return out

    # ------------------------------------------------------------------ single tubes
    @checked_keywords
    def solution(self, name: Hashable) -> Solution:
        """The full single-tube :class:`~tubefsi.Solution` of tube ``name`` (profiles included): its
        flow rate at its outlet pressure, oriented from its higher-pressure end (``z = 0`` is ``u``
        if the flow runs u -> v, else ``v``)."""
        i = self.tube_index.get(name) if _hashable(name) else None
        if i is None:
            raise InvalidParameterError("name", "the name of a tube of the network", name)
        t = self.tubes[i]
        wall, tube, fluid = t.models()
        pu, pv = self.p[self.U[i]], self.p[self.V[i]]
        if t.graded and pv > pu:           # the flow enters at v: the tube read from there
            wall, tube = _reversed(wall, tube)
        return solve(fluid, wall, tube, flow_rate=abs(float(self.q[i])), outlet_pressure=float(min(pu, pv)),
                     external_pressure=t.external_pressure)

    # ------------------------------------------------------------------ tables
    def node_table(self) -> dict:
        """Columns ``node``, ``pressure`` (Pa), ``inflow`` (m^3/s, net flow injected; at a fixed
        node or a resistance outlet, what the boundary supplies) and ``fixed``."""
        n = len(self.nodes)
        injected = np.bincount(self.U, self.q, n) - np.bincount(self.V, self.q, n)
        fixed = self.net._pressure
        return {"node": list(self.nodes), "pressure": self.p.tolist(), "inflow": injected.tolist(),
                "fixed": [node in fixed for node in self.nodes]}

    @checked_keywords
    def tube_table(self, *, density=None) -> dict:
        """Columns ``name``, ``u``, ``v``, ``flow_rate`` (m^3/s), ``pressure_u``, ``pressure_v``
        (Pa), ``radius_u``, ``radius_v`` (deformed inner radii at the two ends, m), ``length`` (m),
        ``pressure_drop`` (Pa), ``strain_u``, ``strain_v``, ``wall_shear_stress_u``,
        ``wall_shear_stress_v`` (Pa) and, given ``density`` (kg/m^3), ``reynolds_number``."""
        nodes = self.nodes
        table = {"name": self.tube_names, "u": list(map(nodes.__getitem__, self.U.tolist())),
                 "v": list(map(nodes.__getitem__, self.V.tolist())),
                 "flow_rate": self.q.tolist(), "pressure_u": self.p[self.U].tolist(),
                 "pressure_v": self.p[self.V].tolist(), "radius_u": self.radius_u.tolist(),
                 "radius_v": self.radius_v.tolist(), "length": self.length.tolist(),
                 "pressure_drop": self.pressure_drops.tolist(), "strain_u": self.strain_u.tolist(),
                 "strain_v": self.strain_v.tolist(), "wall_shear_stress_u": self.wall_shear_stress_u.tolist(),
                 "wall_shear_stress_v": self.wall_shear_stress_v.tolist()}
        if density is not None:
            table["reynolds_number"] = self.reynolds_numbers(density).tolist()
        return table

    @checked_keywords
    def to_dataframe(self, table="tubes", *, density=None):
        """The tube table (``table="tubes"``, :meth:`tube_table`, one row per tube) or the node
        table (``"nodes"``, :meth:`node_table`) as a :class:`pandas.DataFrame`, units in
        ``frame.attrs["units"]``. Needs pandas (``pip install 'tubefsi[pandas]'``)."""
        if table not in ("tubes", "nodes"):
            raise InvalidParameterError("table", "'tubes' or 'nodes'", table)
        if table == "nodes" and density is not None:
            raise InvalidParameterError("density", "None for the node table (a tube's Reynolds number)", density)
        pd = _require("pandas", "pandas")
        columns = self.tube_table(density=density) if table == "tubes" else self.node_table()
        frame = pd.DataFrame(columns)
        frame.attrs["units"] = {k: UNITS[k] for k in columns if k in UNITS}
        return frame

    @checked_keywords
    def to_xarray(self, *, density=None):
        """The results as an :class:`xarray.Dataset` with the dimensions ``tube`` (coordinates: the
        tube names, their nodes ``u`` and ``v``) and ``node`` (the node names): the columns of
        :meth:`tube_table` (with the undeformed ``radius``) and of :meth:`node_table` as data
        variables, each with its ``units`` attribute; names that are neither text nor integers
        become text. Needs xarray (``pip install 'tubefsi[xarray]'``)."""
        xr = _require("xarray", "xarray")
        tubes, nodes = self.tube_table(density=density), self.node_table()
        tube_vars = {key: ("tube", np.asarray(values), {"units": UNITS[key]})
                     for key, values in tubes.items() if key in UNITS}
        tube_vars["radius"] = ("tube", np.asarray(self.radius0), {"units": "m"})
        node_vars = {"pressure": ("node", np.asarray(nodes["pressure"]), {"units": "Pa"}),
                     "inflow": ("node", np.asarray(nodes["inflow"]), {"units": "m^3/s"}),
                     "fixed": ("node", np.asarray(nodes["fixed"], dtype=bool), {})}
        coords = {"tube": _labels(tubes["name"]), "u": ("tube", _labels(tubes["u"])),
                  "v": ("tube", _labels(tubes["v"])), "node": _labels(nodes["node"])}
        return xr.Dataset({**tube_vars, **node_vars}, coords=coords,
                          attrs={"iterations": self.iterations, "residual": self.residual})

    @checked_keywords
    def to_csv(self, prefix: str | os.PathLike) -> tuple:
        """Write ``<prefix>_nodes.csv`` and ``<prefix>_tubes.csv``; returns the two paths."""
        paths = (f"{prefix}_nodes.csv", f"{prefix}_tubes.csv")
        for path, table in zip(paths, (self.node_table(), self.tube_table())):
            with open(path, "w", newline="", encoding="utf-8") as fh:
                writer = csv.writer(fh)
                writer.writerow(list(table))
                for row in zip(*table.values()):
                    writer.writerow([_text(x) if not isinstance(x, float) else repr(x) for x in row])
        return paths

    @checked_keywords
    def to_json(self, path: str | os.PathLike | None = None) -> str:
        """The node and tube tables as JSON (node and tube names as text); written to ``path`` if given."""
        data = {"nodes": _records(self.node_table()), "tubes": _records(self.tube_table()),
                "iterations": self.iterations, "residual": self.residual}
        text = json.dumps(data, indent=1)
        if path is not None:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
        return text

    def plot(self, **kwargs):
        """The network coloured by pressure, tubes as wide as their deformed radius; see
        :func:`tubefsi.plotting.plot_network`."""
        from .plotting import plot_network

        return plot_network(self, **kwargs)

    def _repr_html_(self) -> str:
        """The notebook summary: the size and convergence, then the first rows of the node and tube
        tables with units."""
        return "\n".join([
            _html.table("NetworkSolution", [("nodes", len(self.nodes)), ("tubes", len(self.tubes)),
                                            ("Newton iterations", self.iterations),
                                            ("residual", f"{self.residual:.2e}")]),
            _html.columns_html("nodes", self.node_table(), UNITS),
            _html.columns_html("tubes", self.tube_table(), UNITS)])

    def __repr__(self) -> str:
        return (f"NetworkSolution({len(self.nodes)} nodes, {len(self.tubes)} tubes, "
                f"{self.iterations} iterations, residual {self.residual:.2e})")


def _rows(model, mask):
    """``model`` with each array parameter cut to the entries of ``mask``."""
    cut = {f: np.asarray(getattr(model, f))[mask] for f in _array_fields(type(model))
           if np.ndim(getattr(model, f)) == 1}
    return attrs.evolve(model, **cut) if cut else model


def _hashable(x) -> bool:
    try:
        hash(x)
    except TypeError:
        return False
    return True


def _labels(names) -> np.ndarray:
    """Names as a 1-D array of coordinate labels: as they are if all are text or all integers
    (NumPy's too), else as text."""
    if all(isinstance(x, str) for x in names):
        return np.array(names)
    if all(isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_)) for x in names):
        return np.array([int(x) for x in names], dtype=np.int64)
    return np.array([str(x) for x in names])


def _text(x):
    if isinstance(x, np.integer):
        return int(x)
    return x if isinstance(x, (str, int, bool)) else str(x)


def _records(table):
    return [{k: (v if isinstance(v, (float, int, bool, str)) else int(v) if isinstance(v, np.integer) else str(v))
             for k, v in zip(table, row)}
            for row in zip(*table.values())]
