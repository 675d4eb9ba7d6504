"""Readable summaries for notebooks: the ``_repr_html_`` of models, solutions and network results.

Jupyter shows an object's ``_repr_html_`` in place of its ``repr``; these build small HTML tables
(every text escaped) of what a reader looks for first: the model's parameters with their units,
the scene and the load, the key results with units.
"""

from __future__ import annotations

import html

import numpy as np

from . import registry
from .fields import parameters

#: Rows of a network's node and tube tables shown before "... N more".
ROWS_SHOWN = 8


def number(value, unit: str = "") -> str:
    """A value for a table cell: a number with 6 significant digits, an array as its shape and
    range, anything else as its text; with its unit."""
    suffix = f" {unit}" if unit else ""
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, float, np.integer, np.floating)):
        return f"{float(value):.6g}{suffix}"
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu":
        if value.size == 0:
            return f"empty array {value.shape}"
        finite = value[np.isfinite(value)]
        span = f"{finite.min():.4g} … {finite.max():.4g}{suffix}" if finite.size else "no finite entry"
        return f"array {value.shape}: {span}"
    if isinstance(value, (tuple, list)) and all(isinstance(v, (int, float)) for v in value):
        return "(" + ", ".join(f"{float(v):.6g}" for v in value) + ")" + suffix
    return str(value)


def table(title: str, rows, header=None) -> str:
    """An HTML table under a bold title; ``rows`` are sequences of cell texts (escaped here)."""
    out = [f"<div><strong>{html.escape(title)}</strong>", '<table style="text-align:left">']
    if header:
        out.append("<tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in header) + "</tr>")
    for row in rows:
        out.append("<tr>" + "".join(f"<td>{html.escape(str(cell))}</td>" for cell in row) + "</tr>")
    out.append("</table></div>")
    return "\n".join(out)


def model_rows(model):
    """``(parameter, value with unit, description)`` of each parameter of a model."""
    return [(p.name, number(getattr(model, p.name), p.unit), p.doc) for p in parameters(model)]


def model_html(model, kind: str) -> str:
    """A model's class, registered name and parameters."""
    names = registry.rheologies if kind == "rheology" else registry.walls
    name = names.name_of(model)
    title = f"{kind}: {type(model).__name__}" + (f" ('{name}')" if name else "")
    return table(title, model_rows(model), header=("parameter", "value", "description"))


def columns_html(title: str, columns: dict, units: dict) -> str:
    """The first :data:`ROWS_SHOWN` rows of a table given as columns, with a count of the rest."""
    names = list(columns)
    count = len(columns[names[0]]) if names else 0
    rows = [[number(columns[n][i], units.get(n, "")) for n in names] for i in range(min(count, ROWS_SHOWN))]
    if count > ROWS_SHOWN:
        rows.append([f"… {count - ROWS_SHOWN} more"] + [""] * (len(names) - 1))
    return table(title, rows, header=names)
