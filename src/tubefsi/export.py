r"""A :class:`~tubefsi.Solution` as a table: the data behind ``Solution.to_dataframe()``,
``Solution.to_xarray()`` and the command line's CSV, JSON and NetCDF output (``docs/export.md``).

A solution has the broadcast shape of its inputs: the load and every array parameter of the
models, the tube and the outlet pressure. Each axis of that shape gets a **named dimension**:
the name of the input that varies along that axis alone (the load first, then the
parameters in the order rheology, wall, tube, outlet pressure), else ``dim_<i>``; each input
that varies becomes a **coordinate** over the dimensions it varies along. The results
(:data:`RESULTS`) are the data. pandas and xarray are optional extras
(``pip install tubefsi[pandas]``, ``tubefsi[xarray]``).
"""

from __future__ import annotations

import attrs
import numpy as np

from .errors import InvalidParameterError
from .fields import _array_fields, parameters

__all__ = ["RESULTS", "Table", "table", "to_dataframe", "to_xarray", "to_quantities"]

#: The results of every solution, with their units (the columns of the command line's tables).
RESULTS = {
    "pressure_drop": "Pa",
    "flow_rate": "m^3/s",
    "inlet_pressure": "Pa",
    "inlet_displacement": "m",
    "inlet_radius": "m",
}


@attrs.frozen
class Table:
    """A solution's named dimensions, coordinates ``name -> (dims, values)``, data
    ``name -> values`` (the full shape) and ``units``."""

    dims: tuple
    coords: dict
    data: dict
    units: dict
    attrs: dict

    def columns(self) -> dict:
        """One flat column per coordinate (broadcast to the full shape) and per result."""
        shape = tuple(np.shape(next(iter(self.data.values()))))
        out = {}
        for name, (dims, values) in self.coords.items():
            index = tuple(slice(None) if d in dims else None for d in self.dims)
            out[name] = np.broadcast_to(np.asarray(values)[index], shape).ravel()
        out.update({name: np.ravel(values) for name, values in self.data.items()})
        return out


def _varying_axes(value, ndim):
    """The axes (of an ``ndim``-d result, NumPy's right alignment) along which ``value`` varies."""
    a = np.asarray(value)
    offset = ndim - a.ndim
    axes = []
    for j in range(a.ndim):
        if a.shape[j] > 1 and not np.all(a == a.take([0], axis=j)):
            axes.append(offset + j)
    return tuple(axes)


def _inputs(solution, controlled):
    """``[(name, value, unit), ...]``: the load and every array parameter, in order."""
    scene = solution.scene
    state = solution.state
    out = []
    if controlled:
        out.append((controlled, np.asarray(getattr(state, controlled)), RESULTS[controlled]))
    seen = {controlled}
    for owner, model in (("rheology", scene.rheology), ("wall", scene.wall), ("tube", scene.tube)):
        units = {p.name: p.unit for p in parameters(model)}
        for name in _array_fields(type(model)):
            value = getattr(model, name)
            if np.ndim(value) == 0:
                continue
            label = name if name not in seen else f"{owner}_{name}"
            seen.add(label)
            out.append((label, np.asarray(value, dtype=float), units.get(name, "")))
    if np.ndim(scene.outlet_pressure):
        out.append(("outlet_pressure", np.asarray(scene.outlet_pressure, dtype=float), "Pa"))
    return out


def table(solution, dims=None) -> Table:
    """The :class:`Table` of ``solution``; ``dims`` overrides the names of its dimensions."""
    shape = np.shape(solution.state.flow_rate)
    ndim = len(shape)
    inputs = [(name, value, unit, _varying_axes(value, ndim))
              for name, value, unit in _inputs(solution, solution.controlled)]
    names = []
    for j in range(ndim):
        alone = [name for name, _, _, axes in inputs if axes == (j,) and name not in names]
        names.append(alone[0] if alone else f"dim_{j}")
    if dims is not None:
        dims = tuple(dims)
        if len(dims) != ndim or len(set(dims)) != ndim or not all(isinstance(d, str) for d in dims):
            raise InvalidParameterError("dims", f"{ndim} distinct names, one per axis of the shape {shape}", dims)
        names = list(dims)
    coords, units = {}, {}
    for name, value, unit, axes in inputs:
        if not axes:
            continue
        full = np.broadcast_to(value, shape)
        index = tuple(slice(None) if j in axes else 0 for j in range(ndim))
        coords[name] = (tuple(names[j] for j in axes), np.array(full[index]))
        units[name] = unit
    data = {}
    for name, unit in RESULTS.items():
        if name in coords:
            continue
        data[name] = np.asarray(getattr(solution, name), dtype=float).reshape(shape)
        units[name] = unit
    if not np.all(solution.feasible):
        data["feasible"] = solution.feasible.reshape(shape)
        units["feasible"] = ""
    info = {"coupler": solution.coupler_name, "rheology": repr(solution.rheology), "wall": repr(solution.wall),
            "tube": repr(solution.tube)}
    return Table(dims=tuple(names), coords=coords, data=data, units=units, attrs=info)


def _require(module, extra):
    try:
        return __import__(module)
    except ImportError:
        raise ImportError(f"this needs {module}: pip install 'tubefsi[{extra}]'") from None


def to_dataframe(solution, dims=None):
    """A :class:`pandas.DataFrame`, one row per point: the varying inputs, then the results
    (units in ``DataFrame.attrs["units"]``)."""
    pd = _require("pandas", "pandas")
    t = table(solution, dims)
    frame = pd.DataFrame(t.columns())
    frame.attrs.update(t.attrs, units=dict(t.units))
    return frame


def to_xarray(solution, dims=None):
    """An :class:`xarray.Dataset`: a named dimension per axis, the varying inputs as
    coordinates, the results as data variables, each with its ``units`` attribute."""
    xr = _require("xarray", "xarray")
    t = table(solution, dims)
    coords = {name: (d, values, {"units": t.units[name]}) for name, (d, values) in t.coords.items()}
    data = {name: (t.dims, values, {"units": t.units[name]}) for name, values in t.data.items()}
    return xr.Dataset(data, coords=coords, attrs=t.attrs)


def to_quantities(solution, registry=None) -> dict:
    """The results as :class:`pint.Quantity` objects (``registry``: a :class:`pint.UnitRegistry`,
    default pint's application registry), keyed as :data:`RESULTS`."""
    pint = _require("pint", "units")
    registry = registry or pint.get_application_registry()
    return {name: registry.Quantity(getattr(solution, name), unit.replace("^", "**"))
            for name, unit in RESULTS.items()}
