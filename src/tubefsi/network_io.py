r"""Networks from and to files (``docs/network.md``, "Files").

* **The vascular table form** of the one-dimensional blood-flow community (openBF's model
  tables): one row per vessel, ``Name, sn, tn, wkn, l(m), M, Rp(m), Rd(m), E(Pa), Pext, R1, R2,
  C``. :func:`read_network_table` makes a :class:`~tubefsi.Network` of it,
  :func:`write_network_table` writes one back.
* **VTK polylines** (``.vtp``, VTK's XML PolyData): the nodes are points, every tube a line
  cell with its radius, thickness, length and (given a solution) its results as cell data;
  :func:`write_vtp` and :func:`read_vtp`, for ParaView and other tools.
* :func:`tree_layout`: node positions for drawing and for the points of a ``.vtp`` when the
  network has none (:meth:`~tubefsi.Network.set_position`).

A row's wall is made by a factory ``wall(E, h, R)`` of its elastic modulus, its wall thickness
and its radius (default: :func:`openbf_wall`, the thin linear elastic wall of openBF's tube law);
a table without a thickness column takes openBF's empirical thickness :func:`empirical_thickness`.
"""

from __future__ import annotations

import base64
import csv
import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from ._keywords import checked_keywords
from ._validation import as_array
from .errors import InvalidParameterError, warn_user
from .geometry import Tube
from .network import Network
from .network_solution import NetworkSolution
from .profiles import Profile, sampled
from .registry import walls as _walls
from .scene import resolve
from .walls.base import WallModel

__all__ = ["read_network_table", "write_network_table", "network_table", "empirical_thickness", "openbf_wall",
           "write_vtp", "read_vtp", "tree_layout"]

#: openBF's empirical wall thickness, h = R (a exp(b R) + c exp(d R)) with R in m: a, b (1/m), c, d (1/m)
#: (Avolio 1980; as used by Blanco et al. 2015 for ADAN)
THICKNESS_COEFFICIENTS = (0.2802, -505.3, 0.1324, -11.14)

#: column -> (unit it may be given in, required, default); units are SI only
_COLUMNS = {
    "name": (None, True, None), "sn": (None, True, None), "tn": (None, True, None),
    "wkn": (None, False, None), "m": (None, False, None), "c": ("m^3/pa", False, None),
    "l": ("m", True, None), "rp": ("m", True, None), "rd": ("m", False, None), "e": ("pa", False, None),
    "h": ("m", False, None), "pext": ("pa", False, 0.0), "r1": ("pas/m^3", False, 0.0),
    "r2": ("pas/m^3", False, 0.0), "hd": ("m", False, None), "pd": ("pa", False, None),
}
#: the spellings of a unit that are read as the SI unit above
_UNIT_SPELLINGS = {"pas/m3": "pas/m^3", "pa.s/m^3": "pas/m^3", "pa*s/m^3": "pas/m^3", "m3/pa": "m^3/pa"}
#: the header the writer writes (openBF's, with the optional thickness columns h(m), hd(m) after E(Pa)
#: and the optional distal pressure Pd(Pa) of a resistance outlet at the end)
_HEADER = ("Name", "sn", "tn", "wkn", "l(m)", "M", "Rp(m)", "Rd(m)", "E(Pa)", "Pext", "R1", "R2", "C")


# ---------------------------------------------------------------------------- the wall
def empirical_thickness(radius):
    r"""openBF's empirical wall thickness of an artery of radius ``radius`` (m, array-like):

    .. math::  h = R\,\bigl(a\,e^{bR} + c\,e^{dR}\bigr),\quad a = 0.2802,\ b = -5.053\ \mathrm{cm}^{-1},
               \ c = 0.1324,\ d = -0.1114\ \mathrm{cm}^{-1}

    (Avolio, *Med. Biol. Eng. Comput.* 18:709–718, 1980; used by Blanco et al., *IEEE Trans.
    Biomed. Eng.* 62:736–753, 2015, for ADAN). It gives h/R of about 0.41 at 0.1 mm and 0.11 at
    16 mm (the aortic root)."""
    a, b, c, d = THICKNESS_COEFFICIENTS
    r = np.asarray(radius, dtype=float)
    return r * (a * np.exp(b * r) + c * np.exp(d * r))


def openbf_wall(youngs_modulus, thickness=None, radius=None):
    r"""The default wall of a table row: openBF's tube law, the thin linear elastic wall
    :math:`p = \frac{E h}{(1-\nu^2) R_0}\,(R/R_0 - 1)` with :math:`\nu = 1/2`, i.e.
    ``walls["thin-linear"](youngs_modulus=E, poisson_ratio=0.5)`` (closed and clamped ends agree
    at :math:`\nu = 1/2`). ``thickness`` and ``radius`` are not needed (the tube carries them).
    Arrays give one wall per vessel."""
    return _walls["thin-linear"](youngs_modulus=youngs_modulus, poisson_ratio=0.5)


def _check_openbf_walls(network):
    """Refuse a wall the table cannot hold: the table keeps only ``E`` (and ``h``), and reading
    it back makes :func:`openbf_wall`, so any other linear wall (a ``poisson_ratio`` other than
    1/2, a thick wall) would come back as a different tube law."""
    tubes = network._tubes.columns(network._nodes)
    for batch, index in tubes.by_batch():        # (one check per add_tubes call: its tubes share a wall)
        wall = batch.wall
        ratio = np.asarray(getattr(wall, "poisson_ratio", math.nan), dtype=float)
        if type(wall) is not _walls["thin-linear"] or not np.all(ratio == 0.5):
            raise InvalidParameterError(
                f"tube {tubes.names[int(index[0])]!r}", "openBF's wall, walls['thin-linear'] with poisson_ratio=0.5 (the table "
                "keeps only E and h, and reading it makes that wall: another wall would come back as a "
                "different tube law; write_vtp writes any network, for viewing)", wall)
        if np.any(np.asarray(wall.end_condition) == "open"):
            # closed and clamped ends agree at poisson_ratio 1/2 (K = 3/4); open ends (K = 1) do not
            raise InvalidParameterError(
                f"tube {tubes.names[int(index[0])]!r}, wall end_condition", "'closed' or 'clamped' (the same tube law "
                "at poisson_ratio=0.5, the one the table's reader makes; open ends are another tube law the table "
                "cannot hold)", str(wall.end_condition))


def _wall_maker(wall):
    """``wall`` as a factory ``(E, h, R) -> WallModel``, and whether it needs the column E."""
    if wall is None:
        return openbf_wall, True
    if isinstance(wall, (str, WallModel)) or (isinstance(wall, type) and issubclass(wall, WallModel)):
        model = resolve("wall", wall)
        return (lambda E, h, R: model), False
    if callable(wall):
        return wall, False
    raise InvalidParameterError("wall", "a wall model (instance, class or registered name) or a callable "
                                "wall(E, h, R) returning one", wall)


# ---------------------------------------------------------------------------- reading the table
class _Table:
    """The raw cells of a table: ``columns`` (normalized name -> list of cells), ``where[k]``
    (how row ``k`` is called in a message: a line of a file, a row of a DataFrame), ``source``."""

    def __init__(self, source, header, rows, where):
        self.source, self.where = source, where
        self.columns = {}
        self.spelled = {}
        for j, raw in enumerate(header):
            key, unit = _column_key(raw)
            raw = str(raw).strip()
            if key not in _COLUMNS:
                raise InvalidParameterError(f"{source}, column {raw!r}", f"one of the table's columns "
                                            f"({', '.join(_HEADER)}, h(m), hd(m), Pd(Pa))", raw)
            expected = _COLUMNS[key][0]
            if unit is not None and _UNIT_SPELLINGS.get(unit, unit) != expected:
                raise InvalidParameterError(f"{source}, column {raw!r}", f"SI units ({expected or 'none'})", raw)
            if key in self.columns:
                raise InvalidParameterError(f"{source}, column {raw!r}", "a column named once", raw)
            self.columns[key] = [row[j] for row in rows]
            self.spelled[key] = str(raw).strip()
        for key, (_, required, _) in _COLUMNS.items():
            if required and key not in self.columns:
                raise InvalidParameterError(f"{source}", f"a table with a column {key!r}", list(header))

    def error(self, key, k, admissible, value):
        return InvalidParameterError(f"{self.source}, {self.where[k]}, column {self.spelled[key]!r}", admissible,
                                     value)

    def numbers(self, key, admissible, predicate, default=None, empty=False):
        """Column ``key`` as floats (a missing or empty cell takes ``default``; with ``empty``
        an empty cell is NaN); the first cell that is no number or fails ``predicate`` is an
        error naming its row and column."""
        cells = self.columns.get(key)
        n = len(self.where)
        if cells is None:
            if default is None:
                return None
            return np.full(n, float(default))
        try:                                        # every cell a number: NumPy parses them at once
            values = np.array(cells).astype(float)
        except (TypeError, ValueError):
            values = None
        if values is not None and values.shape == (n,) and not np.any(np.isnan(values)):
            return self._checked(key, cells, values, admissible, predicate)
        if values is not None and values.shape == (n,) and empty:     # (a DataFrame's empty cells: NaN)
            return self._checked(key, cells, values, admissible, predicate, empty=True)
        values = np.empty(n)
        for k, cell in enumerate(cells):            # a cell is text (a file) or a number (a DataFrame)
            text = cell.strip() if isinstance(cell, str) else cell
            if text == "" or text is None or (isinstance(text, float) and math.isnan(text)):
                if empty:
                    values[k] = math.nan
                    continue
                if default is None:
                    raise self.error(key, k, admissible, "an empty cell")
                values[k] = default
                continue
            try:
                values[k] = float(text)
            except (TypeError, ValueError):
                raise self.error(key, k, admissible, text) from None
        return self._checked(key, cells, values, admissible, predicate, empty)

    def _checked(self, key, cells, values, admissible, predicate, empty=False):
        """``values``, or the error naming the first cell that is not finite or fails ``predicate``
        (with ``empty``, NaN is an empty cell: allowed)."""
        with np.errstate(invalid="ignore"):
            bad = ~(np.isfinite(values) & predicate(values))
        if empty:
            bad &= ~np.isnan(values)
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            raise self.error(key, k, admissible, cells[k].strip() if isinstance(cells[k], str) else cells[k])
        return values

    def names(self, key, empty=False):
        """Column ``key`` as node or vessel names: integers where a cell is one (an integral
        float of a DataFrame, or the text "1.0" of a file, included: 1.0 -> 1), else its text; with ``empty``, an empty cell
        is None."""
        cells = self.columns[key]
        if all(isinstance(c, str) for c in cells):     # a file's column: integers at once where all are
            text = np.char.strip(np.array(cells, dtype=str))
            digits = np.char.lstrip(text, "+-")
            if text.size and np.all(np.char.isdigit(digits)) and np.all(np.char.str_len(text) - np.char.str_len(digits)
                                                                          <= 1):
                return text.astype(np.int64).tolist()
        out = []
        for k, cell in enumerate(self.columns[key]):
            if isinstance(cell, (int, np.integer)) and not isinstance(cell, bool):
                out.append(int(cell))
                continue
            if isinstance(cell, (float, np.floating)) and math.isfinite(cell) and float(cell).is_integer():
                out.append(int(cell))
                continue
            text = str(cell).strip() if cell is not None else ""
            if text == "" or (isinstance(cell, (float, np.floating)) and math.isnan(cell)):   # (a DataFrame's NaN)
                if empty:
                    out.append(None)
                    continue
                raise self.error(key, k, "a name (not empty)", "an empty cell")
            integer = _INTEGER.fullmatch(text)        # "2" and "2.0" are the node 2
            out.append(int(integer.group(1)) if integer else text)
        return out


#: a cell that names an integer node or vessel: digits, and a point with zeros only ("2.0", as a
#: spreadsheet writes an integer)
_INTEGER = re.compile(r"([+-]?\d+)(?:\.0*)?")


def _column_key(raw):
    """``"Rp(m)"`` -> ``("rp", "m")``; ``" sn"`` -> ``("sn", None)``."""
    text = str(raw).strip()
    match = re.fullmatch(r"([^()]*?)\s*(?:\(([^()]*)\))?", text)
    name, unit = (match.group(1), match.group(2)) if match else (text, None)
    return name.strip().lower(), (None if unit is None else unit.replace(" ", "").lower())


def _read_csv(path):
    """The header, the rows and their line numbers of a CSV file; ``#`` starts a comment line;
    a trailing empty column (openBF's rows end with a comma) is dropped."""
    label = Path(path).name
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            lines = [(i + 1, line) for i, line in enumerate(fh) if line.strip() and not line.lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as err:
        raise InvalidParameterError("source", "a readable CSV file (UTF-8)", label, str(err)) from None
    if not lines:
        raise InvalidParameterError(label, "a table with a header and at least one row", "an empty file")
    parsed = [(i, row) for i, row in zip((i for i, _ in lines), csv.reader(line for _, line in lines))]
    header = parsed[0][1]
    while header and header[-1].strip() == "":
        header = header[:-1]
    rows, where = [], []
    for i, row in parsed[1:]:
        if len(row) > len(header) and any(cell.strip() for cell in row[len(header):]):
            raise InvalidParameterError(f"{label}, line {i}", f"{len(header)} cells, one per column of the header",
                                        len(row))
        if len(row) < len(header):
            raise InvalidParameterError(f"{label}, line {i}", f"{len(header)} cells, one per column of the header",
                                        len(row))
        rows.append(row[:len(header)])
        where.append(f"line {i}")
    if not rows:
        raise InvalidParameterError(label, "a table with a header and at least one row", "a header only")
    return _Table(label, header, rows, where)


def _read_frame(frame):
    """A DataFrame's table; the empty ``Unnamed: N`` columns pandas makes of a trailing
    delimiter (``pandas.read_csv`` of openBF's rows, which end with a comma) are dropped."""
    header = [str(c) for c in frame.columns]
    rows = [list(r) for r in frame.itertuples(index=False, name=None)]
    keep = [j for j, name in enumerate(header)
            if not (re.fullmatch(r"Unnamed: \d+", name) and all(_blank(row[j]) for row in rows))]
    header, rows = [header[j] for j in keep], [[row[j] for j in keep] for row in rows]
    if not rows:
        raise InvalidParameterError("DataFrame", "a table with at least one row", "no rows")
    return _Table("DataFrame", header, rows, [f"row {k}" for k in range(len(rows))])


def _blank(cell) -> bool:
    """Whether a DataFrame cell is empty (None, NaN or blank text)."""
    if cell is None:
        return True
    if isinstance(cell, str):
        return cell.strip() == ""
    return isinstance(cell, (float, np.floating)) and math.isnan(cell)


@checked_keywords
def read_network_table(source, *, rheology=None, wall=None, thickness=None, distal_pressure=0.0, taper="linear"):
    r"""A :class:`~tubefsi.Network` from a table of vessels (the openBF model table form).

    Parameters
    ----------
    source : str, path or pandas.DataFrame
        A CSV file (lines starting with ``#`` are comments) or a DataFrame with the same columns.
        One row per vessel; the columns (case and spaces do not matter, a unit in parentheses
        must be the SI one given here):

        ============  ==============================================================
        ``Name``      the vessel's (tube's) name (an empty cell: the default ``(sn, tn)``)
        ``sn, tn``    source and target node (integers stay integers)
        ``l(m)``      length
        ``Rp(m)``     proximal (inlet) radius
        ``Rd(m)``     distal radius (optional: ``Rp``)
        ``E(Pa)``     elastic modulus (needed by the default wall)
        ``h(m)``      wall thickness (optional: :func:`empirical_thickness`, or ``thickness``;
                      an empty cell: that rule for this vessel)
        ``hd(m)``     distal wall thickness (optional, with ``h(m)``: a thickness running
                      linearly from ``h`` to ``hd``; an empty cell: ``h``)
        ``Pext``      external pressure (Pa, optional: 0)
        ``R1, R2``    terminal resistances (Pa s/m^3, optional: 0); ``R1 + R2 > 0`` makes
                      ``tn`` a resistance outlet, :meth:`~tubefsi.Network.set_resistance`
        ``Pd(Pa)``    the distal pressure of the vessel's resistance outlet (optional: the
                      keyword ``distal_pressure``; an empty cell too)
        ``C``         terminal compliance (m^3/Pa): ignored, it carries no flow at steady state
        ``wkn, M``    openBF's Windkessel label and mesh points: ignored
        ============  ==============================================================

    rheology : model, class or registered name, optional
        The fluid (``Network(rheology=...)``).
    wall : callable, model, class or registered name, optional
        A wall model shared by every vessel, or a factory ``wall(E, h, R)`` of the vessel's
        modulus, thickness and proximal radius returning its wall (called with arrays, one
        entry per vessel, for runs of uniform vessels; ``E`` is NaN without an ``E(Pa)``
        column). Default :func:`openbf_wall`, which needs the column ``E(Pa)``.
    thickness : callable, optional
        Without an ``h(m)`` column: the thickness as a function of the radius (arrays in,
        arrays out); default :func:`empirical_thickness`.
    distal_pressure : float
        The distal pressure (Pa) of every resistance outlet (the venous pressure; default 0).
    taper : {"linear", "mean"}
        A vessel with ``Rp != Rd``: ``"linear"`` makes a tapered :class:`~tubefsi.Tube` whose
        radius runs linearly from ``Rp`` to ``Rd`` (a :func:`~tubefsi.sampled` linear profile,
        the thickness following the radius); ``"mean"`` a uniform tube of the mean radius.

    Returns
    -------
    Network
        Its tubes in the order of the rows, named by ``Name``; the inlet (an inflow or a
        pressure) is yours to set, e.g. ``net.set_inflow(1, 8.3e-5)``.

    Raises
    ------
    InvalidParameterError
        A malformed table: the message names the file, the line (or the DataFrame's row) and
        the column.
    """
    if taper not in ("linear", "mean"):
        raise InvalidParameterError("taper", "'linear' or 'mean'", taper)
    if isinstance(source, (str, os.PathLike)):
        table = _read_csv(source)
    elif hasattr(source, "columns") and hasattr(source, "itertuples"):
        table = _read_frame(source)
    else:
        raise InvalidParameterError("source", "a path to a CSV file or a pandas.DataFrame", source)
    make_wall, needs_e = _wall_maker(wall)
    if thickness is not None and not callable(thickness):
        raise InvalidParameterError("thickness", "a function of the radius (m -> m)", thickness)
    p_d = as_array("distal_pressure", distal_pressure, "a finite number (Pa)", np.isfinite)
    if p_d.ndim:
        raise InvalidParameterError("distal_pressure", "a finite number (Pa), one for every outlet", distal_pressure)
    p_d = float(p_d)

    sn, tn = table.names("sn"), table.names("tn")
    # an empty Name is the default name (sn, tn), as add_tube gives it
    names = [(a, b) if name is None else name for name, a, b in zip(table.names("name", empty=True), sn, tn)]
    length = table.numbers("l", "(0, inf) m", lambda a: a > 0)
    rp = table.numbers("rp", "(0, inf) m", lambda a: a > 0)
    rd = table.numbers("rd", "(0, inf) m", lambda a: a > 0) if "rd" in table.columns else rp.copy()
    if needs_e and "e" not in table.columns:
        raise InvalidParameterError(table.source, "a column E(Pa) (the default wall needs the elastic modulus; "
                                    "or give wall=)", list(table.spelled.values()))
    modulus = table.numbers("e", "(0, inf) Pa", lambda a: a > 0) if "e" in table.columns else \
        np.full(len(names), math.nan)
    # h(m): the (proximal) thickness, an empty cell the rule's; hd(m): the distal one, an empty
    # cell h's (or the rule's where h is empty)
    h = table.numbers("h", "(0, inf) m", lambda a: a > 0, empty=True) if "h" in table.columns else None
    hd = table.numbers("hd", "(0, inf) m", lambda a: a > 0, empty=True) if "hd" in table.columns else None
    if hd is not None and h is None:
        raise InvalidParameterError(table.source, "a column h(m) with the column hd(m) (hd is the distal thickness)",
                                    list(table.spelled.values()))
    p_ext = table.numbers("pext", "finite numbers (Pa)", lambda a: a == a, default=0.0)
    r1 = table.numbers("r1", "[0, inf) Pa s/m^3", lambda a: a >= 0, default=0.0)
    r2 = table.numbers("r2", "[0, inf) Pa s/m^3", lambda a: a >= 0, default=0.0)
    pd = table.numbers("pd", "finite numbers (Pa)", lambda a: a == a, empty=True) if "pd" in table.columns else None
    seen = {}
    for k, (name, a, b) in enumerate(zip(names, sn, tn)):
        if a == b:
            raise table.error("tn", k, "a node other than sn (a vessel joins two nodes)", b)
        if name in seen:
            raise table.error("name", k, f"a name no other vessel has ({table.where[seen[name]]} has it)", name)
        seen[name] = k
    rule = empirical_thickness if thickness is None else thickness
    if taper == "mean":
        rp = rd = 0.5 * (rp + rd)
    by_rule = np.ones(len(names), dtype=bool) if h is None else np.isnan(h)
    if hd is None:
        hd = np.full(len(names), math.nan)
    h0 = np.asarray(rule(rp), dtype=float) if h is None else np.where(by_rule, np.asarray(rule(rp), dtype=float), h)
    if np.any(by_rule) and not np.all(np.isfinite(h0) & (h0 > 0)):
        k = int(np.flatnonzero(~(np.isfinite(h0) & (h0 > 0)))[0])
        raise table.error("rp", k, "a radius whose thickness(radius) is a positive number", rp[k])
    if np.any(by_rule & ~np.isnan(hd)):
        k = int(np.flatnonzero(by_rule & ~np.isnan(hd))[0])
        raise table.error("hd", k, "an empty cell where h(m) is empty (the thickness rule's vessel)", hd[k])
    h1 = np.where(np.isnan(hd), h0, hd)            # the distal thickness of a vessel whose h is given
    tapered = (rp != rd) | (~by_rule & (h1 != h0))

    net = Network(rheology=rheology)
    # runs of consecutive rows, uniform or tapered: the uniform ones in one add_tubes each (the
    # order of the rows is kept)
    cuts = np.flatnonzero(np.diff(tapered.astype(np.int8))) + 1
    for run in np.split(np.arange(len(names)), cuts):
        if not tapered[run[0]]:
            net.add_tubes([sn[k] for k in run], [tn[k] for k in run], make_wall(modulus[run], h0[run], rp[run]),
                          Tube(radius=rp[run], thickness=h0[run], length=length[run]),
                          names=[names[k] for k in run], external_pressure=p_ext[run])
            continue
        for k in run:
            ends = [0.0, length[k]]
            radius = sampled(ends, [rp[k], rd[k]], kind="linear") if rp[k] != rd[k] else float(rp[k])
            if by_rule[k]:
                wall_thickness = Profile(_ThicknessOf(rule, rp[k], rd[k], length[k]))
            elif h1[k] != h0[k]:
                wall_thickness = sampled(ends, [h0[k], h1[k]], kind="linear")
            else:
                wall_thickness = float(h0[k])
            net.add_tube(sn[k], tn[k], make_wall(float(modulus[k]), float(h0[k]), float(rp[k])),
                         Tube(radius=radius, thickness=wall_thickness, length=float(length[k])), name=names[k],
                         external_pressure=float(p_ext[k]))
    terminal = np.flatnonzero(r1 + r2 > 0)
    if pd is not None and np.any(~np.isnan(pd) & (pd != 0) & (r1 + r2 == 0)):
        k = int(np.flatnonzero(~np.isnan(pd) & (pd != 0) & (r1 + r2 == 0))[0])
        raise table.error("pd", k, "0 or empty on a vessel without a terminal resistance (R1 + R2 = 0)", pd[k])
    outlets = {}
    for k in terminal:
        if tn[k] in outlets:
            raise table.error("r1", k, f"one terminal resistance per node ({table.where[outlets[tn[k]]]} gives "
                              f"node {tn[k]!r} one)", r1[k])
        outlets[tn[k]] = k
        distal = p_d if pd is None or math.isnan(pd[k]) else float(pd[k])
        net.set_resistance(tn[k], float(r1[k] + r2[k]), distal_pressure=distal)
    return net


class _ThicknessOf:
    """The thickness of a linearly tapered vessel, ``rule(a(z))`` with ``a`` linear from ``rp``
    at 0 to ``rd`` at ``length`` (a callable for :class:`~tubefsi.Profile`)."""

    def __init__(self, rule, rp, rd, length):
        self.rule, self.rp, self.rd, self.length = rule, float(rp), float(rd), float(length)
        self.__name__ = "thickness(radius(z))"

    def __call__(self, z):
        a = self.rp + (self.rd - self.rp) * np.asarray(z, dtype=float) / self.length
        return np.asarray(self.rule(a), dtype=float)


# ---------------------------------------------------------------------------- writing the table
#: the fractions of a graded tube's length where its laws are probed (irregular: no symmetric
#: profile passes for linear by chance)
_PROBES = np.array([0.0, 0.137, 0.29, 0.5, 0.71, 0.863, 1.0])
#: how a file rebuilds a graded tube's radius and thickness from their end values
LINEAR, EMPIRICAL, OTHER = 0, 1, 2


def _ends(tube):
    """``(a(0), a(L), t(0), t(L), L, radius law, thickness law)`` of a tube (uniform or
    graded). The laws are what the files can rebuild from the end values: :data:`LINEAR` (a
    uniform value included), :data:`EMPIRICAL` (the thickness :func:`empirical_thickness` of
    the radius) or :data:`OTHER`, found by comparing the tube at seven positions (to 1e-12)."""
    length = float(tube.length)
    a, t = tube.at(_PROBES * length)
    a = np.broadcast_to(np.asarray(a, dtype=float), _PROBES.shape)
    t = np.broadcast_to(np.asarray(t, dtype=float), _PROBES.shape)

    def linear(f):
        return bool(np.allclose(f, f[0] + (f[-1] - f[0]) * _PROBES, rtol=1e-12, atol=0))

    radius_law = LINEAR if linear(a) else OTHER
    if linear(t):
        thickness_law = LINEAR
    elif np.allclose(t, empirical_thickness(a), rtol=1e-12, atol=0):
        thickness_law = EMPIRICAL
    else:
        thickness_law = OTHER
    return float(a[0]), float(a[-1]), float(t[0]), float(t[-1]), length, radius_law, thickness_law


def _modulus(wall, length):
    """``(E at the inlet, law)`` of a wall's ``youngs_modulus`` (NaN without one): the law
    :data:`OTHER` where it varies along the tube (the files hold one number per tube)."""
    modulus = getattr(wall, "youngs_modulus", math.nan)
    if not isinstance(modulus, Profile):
        return float(modulus), LINEAR
    values = np.broadcast_to(np.asarray(modulus(_PROBES * length), dtype=float), _PROBES.shape)
    return float(values[0]), LINEAR if np.all(values == values[0]) else OTHER


def _geometry(network) -> dict:
    """Per tube, in the network's order: ``name``, ``u``, ``v`` (lists) and the arrays ``a0``,
    ``a1`` (radius at the two ends), ``t0``, ``t1`` (thickness), ``length``, ``E`` (the wall's
    ``youngs_modulus``, NaN for a wall without one) and ``p_ext``. The tubes that share their
    models (one :meth:`~tubefsi.Network.add_tubes` call) are read in one indexing each; a graded
    tube on its own."""
    if not isinstance(network, Network):
        raise InvalidParameterError("network", "a tubefsi.Network", network)
    tubes = network._tubes.columns(network._nodes)
    n = len(tubes)
    nodes = list(network._nodes)
    out = {"name": list(tubes.names), "u": list(map(nodes.__getitem__, tubes.U.tolist())),
           "v": list(map(nodes.__getitem__, tubes.V.tolist())), "p_ext": np.array(tubes.external, dtype=float)}
    for key in ("a0", "a1", "t0", "t1", "length", "E"):
        out[key] = np.empty(n)
    out["radius_law"], out["thickness_law"], out["modulus_law"] = (np.full(n, LINEAR) for _ in range(3))
    for batch, index in tubes.by_batch():
        if batch.graded:
            for k in index.tolist():
                wall, tube, _ = tubes[k].models()
                (out["a0"][k], out["a1"][k], out["t0"][k], out["t1"][k], out["length"][k], out["radius_law"][k],
                 out["thickness_law"][k]) = _ends(tube)
                out["E"][k], out["modulus_law"][k] = _modulus(wall, out["length"][k])
            continue
        first = batch                   # (its tubes share its models: one indexing each)
        rows = np.zeros(index.size, dtype=int) if batch.rows is None else batch.rows[tubes.place[index]]

        def take(value):
            a = np.asarray(value, dtype=float)
            return a[rows] if a.ndim else np.full(rows.size, float(a))

        out["a0"][index] = out["a1"][index] = take(first.tube.radius)
        out["t0"][index] = out["t1"][index] = take(first.tube.thickness)
        out["length"][index] = take(first.tube.length)
        out["E"][index] = take(getattr(first.wall, "youngs_modulus", math.nan))
    return out


@checked_keywords
def network_table(network, *, thickness="auto") -> dict:
    r"""The table form of ``network`` as columns (header -> list), the columns of
    :func:`write_network_table` (``pandas.DataFrame(network_table(net))`` takes them).

    ``E(Pa)`` is each wall's ``youngs_modulus`` (the table holds openBF's wall only,
    :func:`openbf_wall`: another wall, or open ends, is an error naming the tube); ``R1`` the
    terminal resistance of a resistance outlet at the vessel's target node, ``R2 = C = 0`` (the
    table keeps only the steady state), and a column ``Pd(Pa)`` with the outlets' distal
    pressures where one is not 0; ``M`` one mesh point per millimetre (openBF's usual, at least
    5). A tube named by default, ``(u, v)``, gets an empty ``Name`` (the reader gives it that
    name back); other names and the nodes must be integers or text that reads back as itself
    (not integer-like, no surrounding blanks or line breaks), else an error names them.

    ``thickness``: ``"auto"`` writes an ``h(m)`` column unless every thickness is
    :func:`empirical_thickness` of its radius, which the reader recomputes; ``True`` always
    writes it, ``False`` never (a thickness the reader would not recompute then warns). With
    ``h(m)``, a thickness running linearly along a tapered vessel (:meth:`tubefsi.Tube.tapered`)
    adds the distal thickness ``hd(m)``, and a tapered vessel whose thickness is the empirical one
    of its radius gets an empty ``h`` cell (the reader's rule). A radius that is not linear along
    the vessel, or a thickness neither linear nor empirical, is an error naming the tube.
    """
    if thickness not in ("auto", True, False):
        raise InvalidParameterError("thickness", "'auto', True or False", thickness)
    g = _geometry(network)
    if not g["name"]:
        raise InvalidParameterError("network", "a network with at least one tube", network)
    bad = ~np.isfinite(g["E"])
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise InvalidParameterError(f"tube {g['name'][k]!r}", "a wall with a youngs_modulus (the table form holds "
                                    "linear elastic walls)", type(network._tubes[g["name"][k]].wall).__name__)
    _check_openbf_walls(network)
    if np.any(g["modulus_law"] == OTHER):
        k = int(np.flatnonzero(g["modulus_law"] == OTHER)[0])
        raise InvalidParameterError(f"tube {g['name'][k]!r}, wall youngs_modulus", "one number along the tube (the "
                                    "table's E(Pa) holds one per vessel)", "a modulus that varies along it")
    for key, what in (("radius_law", "radius"), ("thickness_law", "thickness")):
        if np.any(g[key] == OTHER):
            k = int(np.flatnonzero(g[key] == OTHER)[0])
            raise InvalidParameterError(
                f"tube {g['name'][k]!r}, {what}", "uniform or linear along the tube" + (
                    " (or the empirical thickness of the radius)" if what == "thickness" else "") +
                " (the table holds its two end values, and the reader makes it so)", "another profile")
    names = [_table_name("tube", name, default=(a, b)) for name, a, b in zip(g["name"], g["u"], g["v"])]
    u = [_table_name("node", node) for node in g["u"]]
    v = [_table_name("node", node) for node in g["v"]]
    resistance = network._resistance
    # a resistance outlet on the first vessel that ends at its node
    first_into = {}
    for k, b in enumerate(g["v"]):
        first_into.setdefault(b, k)
    n = len(g["name"])
    terminal, distal = np.zeros(n), np.zeros(n)
    lost = [node for node in resistance if node not in first_into]
    if lost:
        raise InvalidParameterError("network", "resistance outlets at the target node of a tube (the table puts "
                                    "R1 on the vessel that ends there)", lost[0])
    for node, (r, p_d) in resistance.items():
        terminal[first_into[node]], distal[first_into[node]] = r, p_d
    columns = {"Name": names, "sn": u, "tn": v, "wkn": [0] * n,
               "l(m)": g["length"].tolist(), "M": np.maximum(5, np.round(g["length"] * 1e3)).astype(int).tolist(),
               "Rp(m)": g["a0"].tolist(), "Rd(m)": g["a1"].tolist(), "E(Pa)": g["E"].tolist(),
               "Pext": g["p_ext"].tolist(), "R1": terminal.tolist(), "R2": [0.0] * n, "C": [0.0] * n}
    if np.any(distal != 0):
        columns["Pd(Pa)"] = distal.tolist()
    h_p, h_d, r_p, r_d = g["t0"], g["t1"], g["a0"], g["a1"]
    by_rule = g["thickness_law"] == EMPIRICAL
    # what the reader makes without an h(m) column: the empirical thickness (a law along a tapered vessel)
    rule = by_rule | ((r_p == r_d) & (h_p == h_d) & np.isclose(h_p, empirical_thickness(r_p), rtol=1e-12, atol=0))
    if thickness is False and not np.all(rule):
        k = int(np.flatnonzero(~rule)[0])
        warn_user(f"write_network_table(thickness=False): tube {g['name'][k]!r} (and {int(np.sum(~rule)) - 1} more) "
                  "has a wall thickness other than empirical_thickness of its radius, which read_network_table "
                  "makes without an h(m) column: the table reads back as another network", UserWarning)
    if thickness is True or (thickness == "auto" and not np.all(rule)):
        graded_rule = by_rule & (r_p != r_d)
        h = [None if graded_rule[k] else float(h_p[k]) for k in range(n)]
        extra = {"h(m)": h}
        if np.any(~by_rule & (h_p != h_d)):
            extra["hd(m)"] = [float(h_d[k]) if not by_rule[k] and h_d[k] != h_p[k] else None for k in range(n)]
        columns = {**{k: columns[k] for k in _HEADER[:9]}, **extra, **{k: columns[k] for k in columns
                                                                         if k not in _HEADER[:9]}}
    return columns


def _table_name(kind, name, default=None):
    """A tube or node name as the table's cell: an integer (NumPy's too) as a plain one, text as
    itself, a tube's default name ``(u, v)`` as an empty cell; anything the reader would read
    back as another name is an error naming it."""
    if default is not None and isinstance(name, tuple) and name == default:
        return None
    if isinstance(name, (int, np.integer)) and not isinstance(name, (bool, np.bool_)):
        return int(name)
    if isinstance(name, str) and name and name == name.strip() and not _INTEGER.fullmatch(name) \
            and "\n" not in name and "\r" not in name:
        return name
    raise InvalidParameterError(
        f"{kind} name {name!r}", "an integer or text that reads back as itself (not an integer's digits, such "
        "as '12' or '12.0', no "
        "surrounding blanks or line breaks)" + (", or the default name (u, v)" if kind == "tube" else "") +
        ": the table writes names as text", name)


@checked_keywords
def write_network_table(network, path, *, thickness="auto", comment=None):
    """Write ``network`` as a table of vessels (CSV, the columns of :func:`network_table`;
    numbers with all their digits, so that :func:`read_network_table` gives the same network
    back; an empty cell where :func:`network_table` has None). ``comment`` (text) goes first,
    each line after ``#``; a name starting with ``#`` is quoted (the reader would take its line
    for a comment), as one with a comma or a quote is. Returns the path."""
    columns = network_table(network, thickness=thickness)
    try:
        fh = open(path, "w", newline="", encoding="utf-8")
    except OSError as err:
        raise InvalidParameterError("path", "a file that can be written", str(path), str(err)) from None
    with fh:
        for line in ([] if comment is None else str(comment).splitlines()):
            fh.write(f"# {line}\n")
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(list(columns))
        for row in zip(*columns.values()):
            cells = ["" if x is None else repr(x) if isinstance(x, float) else str(x) for x in row]
            if cells[0].startswith("#"):          # (csv quotes only a delimiter, a quote or a line break)
                fh.write('"' + cells[0].replace('"', '""') + '",')
                cells = cells[1:]
            writer.writerow(cells)
    return path


# ---------------------------------------------------------------------------- layout
@checked_keywords
def tree_layout(network, *, root=None) -> dict:
    r"""Node positions ``node -> (x, y)`` (m) that draw a network as a tree: ``x`` the distance
    from ``root`` along the tubes (their lengths), ``y`` the leaves one apart in depth-first
    order and every other node midway between its first and last child. The tree is the
    breadth-first spanning tree from ``root`` (default the first node with an inflow, else
    the first node; a graph with loops draws its other tubes across it, and each further
    component of the graph starts at its first node). Vectorized per level of the tree: the
    cost is O(n log n) for n nodes, and a lattice's tree has about as many levels as hops
    across it."""
    if not isinstance(network, Network):
        raise InvalidParameterError("network", "a tubefsi.Network", network)
    nodes = network.nodes
    index = {node: i for i, node in enumerate(nodes)}
    n = len(nodes)
    if n == 0:
        return {}
    g = _geometry(network)
    u = np.array([index[a] for a in g["u"]], dtype=np.int64)
    v = np.array([index[b] for b in g["v"]], dtype=np.int64)
    length = g["length"]
    graph = sp.coo_matrix((np.ones(u.size), (u, v)), shape=(n, n)).tocsr()
    if root is None:
        root = next((node for node in nodes if node in network._inflow), nodes[0])
    elif root not in index:
        raise InvalidParameterError("root", "a node of the network", root)
    count, label = csgraph.connected_components(graph, directed=False)
    starts = [index[root]] + [int(np.flatnonzero(label == c)[0]) for c in range(count) if c != label[index[root]]]
    x, y = np.zeros(n), np.zeros(n)
    row = 0.0
    # the length of the tube between two nodes (either way; the first tube of parallel ones),
    # looked up by the key a * n + b
    keys = np.concatenate([u * n + v, v * n + u])
    order_keys = np.argsort(keys, kind="stable")
    keys, key_length = keys[order_keys], np.concatenate([length, length])[order_keys]
    for start in starts:
        # the breadth-first spanning tree (shallow: a level per hop from the root), its nodes in
        # depth-first order (a subtree's leaves next to each other)
        _, pred = csgraph.breadth_first_order(graph, start, directed=False, return_predecessors=True)
        children = np.flatnonzero(pred >= 0)
        parents = pred[children]
        tree = sp.coo_matrix((np.ones(children.size), (parents, children)), shape=(n, n)).tocsr()
        order = csgraph.depth_first_order(tree, start, directed=True, return_predecessors=False)
        depth = np.zeros(n, dtype=np.int64)
        hops = csgraph.shortest_path(tree, method="D", directed=True, unweighted=True, indices=start)
        depth[order] = hops[order].astype(np.int64)
        by_level = order[np.argsort(depth[order], kind="stable")]
        levels = np.split(by_level, np.flatnonzero(np.diff(depth[by_level])) + 1)
        step = np.zeros(n)
        step[children] = key_length[np.searchsorted(keys, parents * n + children)]
        for at in levels[1:]:                     # x: the distance from the root along the tree
            x[at] = x[pred[at]] + step[at]
        has_child = np.zeros(n, dtype=bool)
        has_child[parents] = True
        leaves = order[~has_child[order]]
        y[leaves] = row + np.arange(leaves.size)
        for at in levels[:0:-1]:                  # y: midway between the first and last child
            low, high = np.full(n, np.inf), np.full(n, -np.inf)
            np.minimum.at(low, pred[at], y[at])
            np.maximum.at(high, pred[at], y[at])
            done = np.unique(pred[at])
            y[done] = 0.5 * (low[done] + high[done])
        row += leaves.size + 1
    scale = float(np.max(x) - np.min(x)) / max(row, 1.0) if np.ptp(x) > 0 else 1.0
    return {node: (float(x[i]), float(-y[i] * scale)) for i, node in enumerate(nodes)}


# ---------------------------------------------------------------------------- VTK polylines
#: cell arrays of the geometry (per tube) and of a solution (NetworkSolution attribute names)
_GEOMETRY = ("radius", "radius_proximal", "radius_distal", "thickness_proximal", "thickness_distal", "length",
             "youngs_modulus", "external_pressure", "radius_law", "thickness_law", "modulus_law")
_RESULTS = {"flow_rate": "flow_rates", "pressure_drop": "pressure_drops", "radius_u": "radius_u",
            "radius_v": "radius_v", "strain_u": "strain_u", "strain_v": "strain_v",
            "wall_shear_stress_u": "wall_shear_stress_u", "wall_shear_stress_v": "wall_shear_stress_v"}
_NODE_DATA = ("fixed_pressure", "inflow", "resistance", "distal_pressure")


def _positions(network, positions):
    if positions is not None and not hasattr(positions, "keys"):
        raise InvalidParameterError("positions", "a mapping node -> (x, y) or (x, y, z) (m)", positions)
    pos = dict(network.positions if positions is None else positions)
    if any(node not in pos for node in network.nodes):
        pos = {**tree_layout(network), **pos}
    xyz = np.zeros((len(network.nodes), 3))
    for i, node in enumerate(network.nodes):
        try:
            p = np.asarray(pos[node], dtype=float).ravel()
        except (TypeError, ValueError):
            p = np.array([math.nan])
        if p.size not in (2, 3) or not np.all(np.isfinite(p)):
            raise InvalidParameterError(f"positions[{node!r}]", "two or three finite coordinates (m)", pos[node])
        xyz[i, :p.size] = p
    return xyz


def _data_array(parent, name, values, components=1):
    """A ``DataArray`` in VTK's inline binary form: base64 of a UInt64 byte count followed by
    the little-endian values (exact, NaN included)."""
    values = np.asarray(values)
    dtype = np.dtype("<i8") if values.dtype.kind in "iub" else np.dtype("<f8")
    raw = np.ascontiguousarray(values, dtype=dtype).tobytes()
    element = ET.SubElement(parent, "DataArray", type="Int64" if dtype.kind == "i" else "Float64", Name=name,
                            format="binary")
    if components != 1:
        element.set("NumberOfComponents", str(components))
    element.text = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")
    return element


@checked_keywords
def write_vtp(network_or_solution, path, *, positions=None):
    """Write a network (or a solved one: a :class:`~tubefsi.NetworkSolution`, results included)
    as VTK polylines, a ``.vtp`` file (VTK XML PolyData, inline binary data arrays: exact, and
    NaN where a value is missing) for ParaView and other tools.

    Points are the nodes, at ``positions`` (node -> (x, y) or (x, y, z), m), else at those of
    :meth:`~tubefsi.Network.set_position`, else at :func:`tree_layout`'s. Every tube is a line
    cell from its ``u`` to its ``v``. Cell data: ``radius`` (the mean of the two ends, for
    ParaView's Tube filter), ``radius_proximal``, ``radius_distal``, ``thickness_proximal``,
    ``thickness_distal``, ``length`` (m), ``youngs_modulus`` (Pa, NaN for a wall without one),
    ``external_pressure`` (Pa), ``radius_law`` and ``thickness_law`` (how the profile runs
    between the two ends: 0 linear, 1 the :func:`empirical_thickness` of the radius, 2 another
    law, which :func:`read_vtp` makes linear with a warning), ``modulus_law`` (2 where the
    ``youngs_modulus``, its inlet value here, varies along the tube); given a solution also
    ``flow_rate`` (m^3/s), ``pressure_drop`` (Pa), ``radius_u``, ``radius_v`` (deformed, m), ``strain_u``, ``strain_v``,
    ``wall_shear_stress_u``, ``wall_shear_stress_v`` (Pa). Point data: the boundary conditions
    ``fixed_pressure``, ``inflow``, ``resistance``, ``distal_pressure`` (NaN where a node has
    none), ``node`` (the node names, where they are all integers, NumPy's too) and, given a
    solution, ``pressure`` (Pa). Returns the path."""
    if isinstance(network_or_solution, NetworkSolution):
        solution, network = network_or_solution, network_or_solution.net
    elif isinstance(network_or_solution, Network):
        solution, network = None, network_or_solution
    else:
        raise InvalidParameterError("network_or_solution", "a tubefsi.Network or a NetworkSolution",
                                    network_or_solution)
    nodes = network.nodes
    index = {node: i for i, node in enumerate(nodes)}
    g = _geometry(network)
    if not g["name"]:
        raise InvalidParameterError("network_or_solution", "a network with at least one tube", network_or_solution)
    xyz = _positions(network, positions)
    cells = dict(zip(_GEOMETRY, (0.5 * (g["a0"] + g["a1"]), g["a0"], g["a1"], g["t0"], g["t1"], g["length"], g["E"],
                                 g["p_ext"], g["radius_law"], g["thickness_law"], g["modulus_law"])))
    connectivity = np.array([[index[a] for a in g["u"]], [index[b] for b in g["v"]]], dtype=np.int64).T
    if solution is not None:
        for key, attribute in _RESULTS.items():
            cells[key] = getattr(solution, attribute)
    points = {"fixed_pressure": [network._pressure.get(n, math.nan) for n in nodes],
              "inflow": [network._inflow.get(n, math.nan) for n in nodes],
              "resistance": [network._resistance.get(n, (math.nan, math.nan))[0] for n in nodes],
              "distal_pressure": [network._resistance.get(n, (math.nan, math.nan))[1] for n in nodes]}
    if all(isinstance(n, (int, np.integer)) and not isinstance(n, (bool, np.bool_)) for n in nodes):
        points["node"] = np.array([int(n) for n in nodes], dtype=np.int64)
    if solution is not None:
        points["pressure"] = solution.pressures
    root = ET.Element("VTKFile", type="PolyData", version="1.0", byte_order="LittleEndian", header_type="UInt64")
    piece = ET.SubElement(ET.SubElement(root, "PolyData"), "Piece", NumberOfPoints=str(len(nodes)),
                          NumberOfVerts="0", NumberOfLines=str(len(g["name"])), NumberOfStrips="0", NumberOfPolys="0")
    _data_array(ET.SubElement(piece, "Points"), "Points", xyz, components=3)
    lines = ET.SubElement(piece, "Lines")
    _data_array(lines, "connectivity", connectivity)
    _data_array(lines, "offsets", 2 * np.arange(1, len(g["name"]) + 1, dtype=np.int64))
    point_data = ET.SubElement(piece, "PointData")
    for key, values in points.items():
        _data_array(point_data, key, np.asarray(values))
    cell_data = ET.SubElement(piece, "CellData", Scalars="radius")
    for key, values in cells.items():
        _data_array(cell_data, key, np.asarray(values, dtype=float))
    ET.indent(root)
    try:
        ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    except OSError as err:
        raise InvalidParameterError("path", "a file that can be written", str(path), str(err)) from None
    return path


def _vtp_arrays(path):
    """``(points, lines, point data, cell data)`` of a ``.vtp`` file of line cells (ASCII or
    uncompressed inline binary data arrays)."""
    label = Path(path).name
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as err:
        raise InvalidParameterError("path", "a readable VTK XML PolyData file (.vtp)", label, str(err)) from None
    piece = root.find("PolyData/Piece") if root.tag == "VTKFile" and root.get("type") == "PolyData" else None
    if piece is None:
        raise InvalidParameterError(label, "a VTKFile of type PolyData with a Piece", root.tag)

    header = {"UInt32": np.dtype("u4"), "UInt64": np.dtype("u8")}.get(root.get("header_type", "UInt32"))
    order = "<" if root.get("byte_order", "LittleEndian") == "LittleEndian" else ">"
    kinds = {"Float64": "f8", "Float32": "f4", "Int64": "i8", "Int32": "i4", "UInt64": "u8", "UInt32": "u4",
             "Int8": "i1", "UInt8": "u1", "Int16": "i2", "UInt16": "u2"}

    def values(element, what):
        form, kind = element.get("format", "ascii"), kinds.get(element.get("type"))
        text = (element.text or "").strip()
        try:
            if form == "ascii":
                return np.array(text.split(), dtype=float)
            if form == "binary" and kind is not None and header is not None and root.get("compressor") is None:
                raw = base64.b64decode(text)
                size = int(np.frombuffer(raw[:header.itemsize], dtype=header.newbyteorder(order))[0])
                data = raw[header.itemsize:header.itemsize + size]
                return np.frombuffer(data, dtype=np.dtype(kind).newbyteorder(order)).astype(float)
        except (ValueError, TypeError, IndexError):
            raise InvalidParameterError(f"{label}, {what}", "numbers", text[:40]) from None
        raise InvalidParameterError(f"{label}, {what}", "ASCII or uncompressed inline binary data arrays",
                                    f"format={form!r}, type={element.get('type')!r}")

    points = piece.find("Points/DataArray")
    if points is None:
        raise InvalidParameterError(label, "a Points data array", None)
    xyz = values(points, "Points").reshape(-1, int(points.get("NumberOfComponents", "3")))
    arrays = {a.get("Name"): a for a in piece.findall("Lines/DataArray")}
    if "connectivity" not in arrays or "offsets" not in arrays:
        raise InvalidParameterError(label, "line cells (Lines with connectivity and offsets)", sorted(arrays))
    conn = values(arrays["connectivity"], "Lines connectivity").astype(np.int64)
    offsets = values(arrays["offsets"], "Lines offsets").astype(np.int64)
    if not np.array_equal(offsets, 2 * np.arange(1, offsets.size + 1)) or conn.size != 2 * offsets.size:
        raise InvalidParameterError(f"{label}, Lines", "line cells of two points each (one per tube)", offsets[:5])
    lines = conn.reshape(-1, 2)
    if lines.size and (lines.min() < 0 or lines.max() >= len(xyz)):
        raise InvalidParameterError(f"{label}, Lines connectivity", f"point indices in [0, {len(xyz)})",
                                    int(lines.max()))
    point_data = {a.get("Name"): values(a, f"PointData {a.get('Name')!r}") for a in piece.findall("PointData/DataArray")}
    cell_data = {a.get("Name"): values(a, f"CellData {a.get('Name')!r}") for a in piece.findall("CellData/DataArray")}
    for kind, data, n in (("PointData", point_data, len(xyz)), ("CellData", cell_data, len(lines))):
        for key, a in data.items():
            if a.size != n:
                raise InvalidParameterError(f"{label}, {kind} {key!r}", f"{n} values", a.size)
    return xyz, lines, point_data, cell_data


@checked_keywords
def read_vtp(path, *, rheology=None, wall=None):
    """A :class:`~tubefsi.Network` from a ``.vtp`` file of line cells (as :func:`write_vtp`
    writes them; ASCII or uncompressed inline binary data arrays, as VTK writes them with
    ``SetDataModeToAscii`` or ``SetDataModeToBinary`` and no compressor).

    Each line cell is a tube from its first point to its second. Its radius is the cell data
    ``radius_proximal`` and ``radius_distal`` (a linear taper where they differ), else
    ``radius``; its thickness ``thickness_proximal``/``thickness_distal``, else ``thickness``,
    else :func:`empirical_thickness` of the radius; its length ``length``, else the distance
    between its points. ``wall`` is a model or a factory ``wall(E, h, R)`` as in
    :func:`read_network_table` (the cell data ``youngs_modulus`` gives ``E``); ``thickness_law``
    1 makes the thickness :func:`empirical_thickness` of the radius along the tube, and a law
    2 (one the file does not hold) is read as linear with a warning. Nodes are named by the
    point data ``node`` if present (integers, distinct), else by their index; they take the
    positions of the points ((x, y), or (x, y, z) when a point has a z other than 0) and the
    boundary conditions of the point data ``fixed_pressure``, ``inflow``, ``resistance`` with
    ``distal_pressure`` (NaN: none; an error names the file and the point). Results in the file
    are not read.
    """
    label = Path(path).name
    xyz, lines, point_data, cell_data = _vtp_arrays(path)
    n_tubes = len(lines)
    if n_tubes == 0:
        raise InvalidParameterError(label, "at least one line cell", 0)
    if "node" in point_data:
        node = point_data["node"]
        with np.errstate(invalid="ignore"):
            bad = ~(np.isfinite(node) & (node == np.round(node)) & (np.abs(node) < 2.0**53))
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise InvalidParameterError(f"{label}, point {i}, point data 'node'", "integers (the node names)",
                                        float(node[i]))
        names = node.astype(np.int64).tolist()
        if len(set(names)) != len(names):
            seen = set()
            i = next(i for i, name in enumerate(names) if name in seen or seen.add(name))
            raise InvalidParameterError(f"{label}, point {i}, point data 'node'", "distinct integers (a name per "
                                        "point)", names[i])
    else:
        names = list(range(len(xyz)))

    def cell(key, fallback=None):
        return cell_data.get(key, fallback)

    rp = cell("radius_proximal", cell("radius"))
    if rp is None:
        raise InvalidParameterError(label, "cell data radius or radius_proximal (m)", sorted(cell_data))
    rd = cell("radius_distal", rp)
    length = cell("length", np.linalg.norm(xyz[lines[:, 1]] - xyz[lines[:, 0]], axis=1))
    hp = cell("thickness_proximal", cell("thickness", empirical_thickness(rp)))
    hd = cell("thickness_distal", hp if "thickness_proximal" in cell_data or "thickness" in cell_data
              else empirical_thickness(rd))
    modulus = cell("youngs_modulus", np.full(n_tubes, math.nan))
    p_ext = cell("external_pressure", np.zeros(n_tubes))
    for key, a, ok in (("radius", rp, rp > 0), ("radius_distal", rd, rd > 0), ("length", length, length > 0),
                       ("thickness", hp, hp > 0), ("thickness_distal", hd, hd > 0),
                       ("external_pressure", p_ext, np.isfinite(p_ext))):
        with np.errstate(invalid="ignore"):
            bad = ~(np.isfinite(a) & ok)
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            raise InvalidParameterError(f"{label}, cell {k}, cell data {key!r}", "finite numbers > 0 (m)"
                                        if key != "external_pressure" else "finite numbers (Pa)", float(a[k]))
    make_wall, needs_e = _wall_maker(wall)
    if needs_e and not np.all(np.isfinite(modulus) & (modulus > 0)):
        k = int(np.flatnonzero(~(np.isfinite(modulus) & (modulus > 0)))[0])
        raise InvalidParameterError(f"{label}, cell {k}, cell data 'youngs_modulus'", "(0, inf) Pa (the default wall "
                                    "needs it; or give wall=)", float(modulus[k]) if k < modulus.size else None)
    u = [names[i] for i in lines[:, 0]]
    v = [names[i] for i in lines[:, 1]]
    # tubes are named (u, v); one of several between the same nodes (u, v, its cell index)
    pairs = lines[:, 0] * len(xyz) + lines[:, 1]
    _, first, counts = np.unique(pairs, return_index=True, return_counts=True)
    shared = np.isin(pairs, pairs[first[counts > 1]])
    names_of = [(u[k], v[k], k) if shared[k] else (u[k], v[k]) for k in range(n_tubes)]
    thickness_law = cell("thickness_law", np.zeros(n_tubes))
    approximated = ((cell("radius_law", np.zeros(n_tubes)) == OTHER) | (thickness_law == OTHER)
                    | (cell("modulus_law", np.zeros(n_tubes)) == OTHER))
    if np.any(approximated):
        k = int(np.flatnonzero(approximated)[0])
        warn_user(f"read_vtp: {label}, cell {k} (and {int(np.sum(approximated)) - 1} more): its radius, thickness or "
                  "modulus ran along the tube by a law the file does not hold (radius_law or thickness_law 2, or a "
                  "youngs_modulus that varies along it, modulus_law 2); it is read as linear between the two "
                  "ends (the modulus as its inlet value), another tube than the one written", UserWarning)
    by_rule = thickness_law == EMPIRICAL
    graded = (rp != rd) | (hp != hd) | by_rule
    net = Network(rheology=rheology)
    cuts = np.flatnonzero(np.diff(graded.astype(np.int8))) + 1
    for run in np.split(np.arange(n_tubes), cuts):
        if not graded[run[0]]:
            net.add_tubes([u[k] for k in run], [v[k] for k in run], make_wall(modulus[run], hp[run], rp[run]),
                          Tube(radius=rp[run], thickness=hp[run], length=length[run]), external_pressure=p_ext[run],
                          names=[names_of[k] for k in run])
            continue
        for k in run:
            if by_rule[k]:
                tube = Tube(length=float(length[k]), thickness=Profile(_ThicknessOf(empirical_thickness, rp[k], rd[k],
                                                                                    length[k])),
                            radius=float(rp[k]) if rp[k] == rd[k] else sampled([0.0, float(length[k])],
                                                                                  [rp[k], rd[k]], kind="linear"))
            else:
                tube = Tube.tapered(length=float(length[k]), radius=float(rp[k]), outlet_radius=float(rd[k]),
                                    thickness=float(hp[k]), outlet_thickness=float(hd[k]))
            net.add_tube(u[k], v[k], make_wall(float(modulus[k]), float(hp[k]), float(rp[k])), tube,
                         name=names_of[k], external_pressure=float(p_ext[k]))
    used = np.array([node in net._nodes for node in names], dtype=bool)
    if not np.all(np.isfinite(xyz[used])):
        i = int(np.flatnonzero(used & ~np.all(np.isfinite(xyz), axis=1))[0])
        raise InvalidParameterError(f"{label}, point {i}, Points", "finite coordinates (m)", xyz[i].tolist())
    flat = xyz.shape[1] < 3 or not np.any(xyz[used, 2])       # (x, y) unless a point has a z
    points = xyz[:, :2] if flat else xyz[:, :3]
    # the positions in one pass (checked above, as set_position checks one)
    net.positions.update((node, tuple(p)) for node, p, keep in zip(names, points.tolist(), used) if keep)
    with_bc = np.zeros(len(names), dtype=bool)
    for key in ("fixed_pressure", "inflow", "resistance"):
        if key in point_data:
            with_bc |= np.isfinite(point_data[key])
    for i in np.flatnonzero(used & with_bc).tolist():
        node = names[i]
        bc = {key: float(point_data[key][i]) for key in _NODE_DATA if key in point_data}
        for key, setter in (("fixed_pressure", net.set_pressure), ("inflow", net.set_inflow),
                            ("resistance", net.set_resistance)):
            if not math.isfinite(bc.get(key, math.nan)):
                continue
            p_d = bc.get("distal_pressure", math.nan)
            try:
                setter(node, bc[key], *([p_d if math.isfinite(p_d) else 0.0] if key == "resistance" else []))
            except InvalidParameterError as err:       # the file, the point and its array, then what was wrong
                raise InvalidParameterError(f"{label}, point {i} (node {node!r}), point data {key!r}",
                                            err.admissible, bc[key] if err.parameter != "node" else err.value,
                                            err.args[0].split("; ", 1)[1] if "; " in err.args[0] else "") from None
    return net
