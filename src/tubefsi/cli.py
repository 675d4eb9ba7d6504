r"""The ``tubefsi`` command: list the registered models, solve a scene, sweep a curve, advise.

::

    tubefsi list
    tubefsi solve --rheology power-law:consistency=0.017,index=0.7 \
                  --wall thick-neo-hookean:shear_modulus=2e3 \
                  --tube radius=1e-4,thickness=3e-5,length=1e-2 --flow-rate 1e-9 [--json]
    tubefsi curve  ... --flow-rate 0:1e-8:200 [--log] [--format csv|json|netcdf] [--output FILE]
                       [--plot FILE] [--density RHO] [--progress]
    tubefsi advise ... --flow-rate 5e-9 [--density 1060]
    tubefsi network FILE [--format json|csv] [--output FILE|PREFIX] [--plot FILE]
    tubefsi reproduce [OUTDIR]

A model is ``NAME`` or ``NAME:key=value,key=value`` with the parameter names of
``tubefsi list`` (SI units); a coupler may take options the same way
(``--coupler quadrature:order=24``). ``--flow-rate`` and ``--pressure-drop`` take
one value or a comma-separated list; negative numbers reach the library's
validation (``--flow-rate -1e-9`` as well as ``--flow-rate=-1e-9``). Output paths and
formats (``--output``, ``--plot``) are checked before anything is computed. Any bad
argument — an unknown model or parameter, a value outside its admissible range, a load
beyond the maximum flow rate, a malformed network file — ends with a one-line
``tubefsi: error: ...`` on stderr and exit status 2; a result outside the model's assumptions
prints ``tubefsi: warning: ...`` lines on stderr (:mod:`tubefsi.validity`), and so does a
plugin that cannot be registered. A closed standard output (``>&-``) or one whose reader stops
(``| head``) ends the command quietly with status 0; characters the output's encoding lacks are
printed as backslash escapes.

The command starts fast: ``--help``, ``--version`` import only the standard library and
the registry; ``list`` imports every registered model but not SciPy, which the models load on
first use (:mod:`tubefsi._lazy`); ``python -m tubefsi`` runs the same command.
"""

from __future__ import annotations

import argparse
import contextlib
import inspect
import io
import json
import os
import re
import reprlib
import sys
import warnings

import numpy as np

from . import __version__, registry
from .errors import InvalidParameterError, ModelValidityWarning, TubefsiError

__all__ = ["main", "parse_model_spec"]

PROG = "tubefsi"


class UsageError(Exception):
    """A command-line argument that cannot be used (reported in one line, exit status 2)."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser that raises instead of printing usage and exiting."""

    def error(self, message):
        raise UsageError(f"{message} (see '{self.prog} --help')")


# ---------------------------------------------------------------------------- model specs
def _parse_value(text: str):
    """``"3"`` -> 3, ``"2e3"`` -> 2000.0, anything else stays a string."""
    for convert in (int, float):
        try:
            return convert(text)
        except ValueError:
            pass
    return text


def parse_model_spec(spec: str) -> tuple[str, dict]:
    """Split ``"NAME:key=value,key=value"`` into the name and a dict of parameters."""
    name, sep, rest = spec.partition(":")
    name = name.strip()
    if not name:
        raise UsageError(f"{spec!r} has no model name (expected NAME or NAME:key=value,...)")
    return name, _parse_pairs(rest, spec) if sep else {}


def _parse_pairs(text: str, spec: str) -> dict:
    params: dict = {}
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq or not key or not value.strip():
            raise UsageError(f"{item!r} in {spec!r} is not key=value")
        if key in params:
            raise UsageError(f"{key!r} given twice in {spec!r}")
        params[key] = _parse_value(value.strip())
    return params


def _build(kind: str, models, spec: str):
    """An instance of the registered model ``NAME`` with the parameters of ``spec``."""
    from .fields import parameters

    name, params = parse_model_spec(spec)
    if name not in models:
        raise UsageError(f"unknown {kind} {name!r}; known: {', '.join(models)}")
    cls = models[name]
    fields = {p.name: p for p in parameters(cls)}
    unknown = [k for k in params if k not in fields]
    if unknown:
        known = ", ".join(fields) or "none"
        raise UsageError(f"{kind} {name!r} has no parameter {unknown[0]!r}; its parameters: {known}")
    missing = [p for p in fields.values() if p.required and p.name not in params]
    if missing:
        raise UsageError(f"{kind} {name!r} needs " + ", ".join(_describe(p) for p in missing)
                         + f" (e.g. {name}:{missing[0].name}=...)")
    _plain_numbers(f"{kind} {name!r}", params, fields)
    return cls(**params)


def _plain_numbers(what, params, fields):
    """A text value for a numeric parameter (``radius=100um``) is a usage error naming the unit."""
    for key, value in params.items():
        p = fields[key]
        if isinstance(value, str) and not p.admissible.startswith("{"):
            unit = f" ({p.unit})" if p.unit and p.unit != "-" else ""
            raise UsageError(f"{what}: {key}={value!r} is not a number; give a plain number in SI units{unit}, "
                             f"e.g. {key}=1e-4")


def _describe(parameter) -> str:
    unit = f" ({parameter.unit})" if parameter.unit else ""
    adm = f" in {parameter.admissible}" if parameter.admissible else ""
    return f"{parameter.name}{unit}{adm}"


def _load_values(option: str, text: str):
    """A float or a 1-d array from ``"1e-9"`` or ``"1e-9,2e-9"``."""
    items = [t.strip() for t in text.split(",") if t.strip()]
    try:
        values = [float(t) for t in items]
    except ValueError:
        raise UsageError(f"{option} expects a number or a comma-separated list of numbers, got {text!r}") \
            from None
    if not values:
        raise UsageError(f"{option} expects a number, got {text!r}")
    return values[0] if len(values) == 1 else np.array(values)


# ---------------------------------------------------------------------------- list
def _summary(cls) -> str:
    """First phrase of a class's own docstring, without reST math (a class without one is said to
    have none: a base class's description, "Thick-walled theory ...", would misdescribe it)."""
    own = cls.__dict__.get("__doc__")
    if not own:
        return f"{cls.__name__} (no description: its class has no docstring)"
    doc = " ".join(inspect.cleandoc(own).split())
    depth, cut = 0, len(doc)
    for i, ch in enumerate(doc):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(depth - 1, 0)
        elif depth == 0 and (ch == ";" or (ch == "." and (i + 1 == len(doc) or doc[i + 1] == " "))):
            cut = i
            break
    return _plain(doc[:cut]).rstrip(" ,:;")


_SYMBOL = re.compile(r":math:`\\?([A-Za-z]+)`")


def _plain(text: str) -> str:
    """reST to plain text: a math symbol (``:math:`\\mu```) becomes its name, the phrase stops
    at the first formula, ````code```` loses its quotes."""
    text = _SYMBOL.sub(lambda m: m.group(1), text)
    formula = text.find(":math:")
    if formula >= 0:
        text = text[:formula]
    return text.replace("``", "")


def _cmd_list(args, out) -> int:
    from .fields import parameters

    groups = [("rheologies", registry.rheologies), ("walls", registry.walls), ("couplers", registry.couplers)]
    classes = [(title, reg, name, reg[name]) for title, reg in groups for name in reg]
    every = [p for *_, cls in classes for p in parameters(cls)]
    # one set of columns for the whole listing, each as wide as its longest entry
    w_name = max([22] + [len(p.name) + 2 for p in every])
    w_unit = max([9] + [len(p.unit) + 2 for p in every])
    w_adm = max([12] + [len(p.admissible) + 2 for p in every])
    w_model = max([22] + [len(name) + 2 for _, _, name, _ in classes])
    current = None
    for title, reg, name, cls in classes:
        if title != current:
            print(f"{title}:", file=out)
            current = title
        dist = reg.distribution(name)
        origin = "" if dist == "tubefsi" else f"  [{dist}]"
        print(f"  {name:<{w_model}}{_summary(cls)}{origin}", file=out)
        fields = parameters(cls)
        if not fields:
            print(f"      {'(no parameters)' if title != 'couplers' else '(no options)'}", file=out)
        for p in fields:
            default = "" if p.required else f" (default {p.default!r})"
            line = f"      {p.name:<{w_name}}{p.unit or '-':<{w_unit}}{p.admissible:<{w_adm}}{p.doc}{default}"
            print(line.rstrip(), file=out)
    print("\nThin walls take thickness_convention='reference' by default (the chapter's hoop stress pR/t: no "
          "limit pressure);\n'current' (thinning t/lambda) is the thick law's thin limit, with a limit pressure.",
          file=out)
    return 0


# ---------------------------------------------------------------------------- solve
#: The results the commands print, with their units (the table of ``tubefsi.export``).
_OUTPUT_UNITS = {
    "pressure_drop": "Pa",
    "flow_rate": "m^3/s",
    "inlet_pressure": "Pa",
    "inlet_displacement": "m",
    "inlet_radius": "m",
}


def _scene_from_args(args):
    """(fluid, wall, tube, coupler) from the shared scene options."""
    fluid = _build("rheology", registry.rheologies, args.rheology)
    wall = _build("wall", registry.walls, args.wall)
    tube = _tube(args.tube, "--tube")
    coupler = args.coupler
    if coupler != "auto":
        coupler = _build("coupler", registry.couplers, coupler)
    return fluid, wall, tube, coupler


#: Optional ``--tube`` keys: the outlet's radius and thickness of a linearly tapered tube.
_TAPER_KEYS = {"outlet_radius": "radius", "outlet_thickness": "thickness"}


def _tube(text, option):
    """A Tube from ``radius=..,thickness=..,length=..``; with ``outlet_radius=..`` and/or
    ``outlet_thickness=..`` the radius and/or the thickness run linearly from the inlet's value
    (``radius``, ``thickness``) to the outlet's (a :func:`tubefsi.sampled` linear table over
    ``[0, length]``, ``docs/graded.md``)."""
    return _tube_from(_parse_pairs(text, text), option)


def _tube_from(tube_params, option):
    """A Tube from a dict of the keys of :func:`_tube`."""
    expected = ("radius", "thickness", "length")
    unknown = [k for k in tube_params if k not in expected and k not in _TAPER_KEYS]
    if unknown:
        raise UsageError(f"{option} has no parameter {unknown[0]!r}; expected radius, thickness, length (m), and "
                         "optionally outlet_radius, outlet_thickness (m: a linear taper)")
    missing = [k for k in expected if k not in tube_params]
    if missing:
        raise UsageError(f"{option} needs {', '.join(missing)} (m), e.g. radius=1e-4,thickness=3e-5,length=1e-2")
    from .errors import InvalidParameterError
    from .fields import parameters
    from .geometry import Tube
    from .profiles import sampled

    fields = {p.name: p for p in parameters(Tube)}
    fields.update({key: fields[of] for key, of in _TAPER_KEYS.items()})
    _plain_numbers(option, tube_params, fields)
    outlet = {of: tube_params.pop(key) for key, of in _TAPER_KEYS.items() if key in tube_params}
    tube = Tube(**tube_params)
    if not outlet:
        return tube
    try:                                  # the outlet's values, validated as the tube's own
        Tube(**{**tube_params, **outlet})
    except InvalidParameterError as err:
        key = next(k for k, of in _TAPER_KEYS.items() if of == err.parameter)
        raise InvalidParameterError(key, err.admissible, err.value) from None
    ends = [0.0, tube.length]
    return Tube(length=tube.length, **{name: sampled(ends, [tube_params[name], outlet[name]], kind="linear")
                                       if name in outlet else tube_params[name] for name in ("radius", "thickness")})


def _cmd_solve(args, out) -> int:
    fluid, wall, tube, coupler = _scene_from_args(args)
    load = {}
    if args.flow_rate is not None:
        load["flow_rate"] = _load_values("--flow-rate", args.flow_rate)
    else:
        load["pressure_drop"] = _load_values("--pressure-drop", args.pressure_drop)
    from .solve import solve

    sol = solve(fluid, wall, tube, coupler=coupler, outlet_pressure=args.outlet_pressure, density=args.density,
                external_pressure=args.external_pressure, **load)

    result = {}
    for key in _OUTPUT_UNITS:
        value = getattr(sol, key)
        result[key] = float(value) if np.ndim(value) == 0 else np.asarray(value, dtype=float).tolist()
    result["coupler"] = sol.coupler_name
    if args.json:
        json.dump(result, out, indent=2, allow_nan=False)
        out.write("\n")
    else:
        for key, unit in _OUTPUT_UNITS.items():
            value = result[key]
            text = repr(value) if isinstance(value, float) else ", ".join(repr(v) for v in value)
            print(f"{key:<20}{text} {unit}", file=out)
        print(f"{'coupler':<20}{result['coupler']}", file=out)
    return 0


# ---------------------------------------------------------------------------- main
def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=PROG, description="Steady fluid–structure interaction in soft tubes.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("list", help="list the registered rheologies, walls and couplers with their parameters")
    p.set_defaults(run=_cmd_list)

    p = sub.add_parser("solve", help="solve one scene (or a list of loads)",
                       description="Solve steady flow through a soft tube. " + _SCENE_HELP)
    _add_scene_args(p)
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--flow-rate", metavar="Q[,Q...]", help="flow rate(s) (m^3/s)")
    load.add_argument("--pressure-drop", metavar="DP[,DP...]", help="pressure drop(s) (Pa)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--density", type=float, metavar="RHO",
                   help="fluid density (kg/m^3): warn where the reduced Reynolds number is not small")
    p.set_defaults(run=_cmd_solve)

    p = sub.add_parser("evolve", help="a transient (inflation, settling) as CSV, netCDF and a figure",
                       description="Integrate the transient flow through a soft tube (docs/transients.md).")
    p.add_argument("--rheology", required=True, metavar="NAME[:k=v,...]")
    p.add_argument("--wall", required=True, metavar="NAME[:k=v,...]")
    p.add_argument("--tube", required=True, metavar="radius=..,thickness=..,length..", help="uniform tube (m)")
    inlet = p.add_mutually_exclusive_group(required=True)
    inlet.add_argument("--inlet-pressure", type=float, metavar="P", help="a pressure step at the inlet (Pa)")
    inlet.add_argument("--inlet-flow-rate", type=float, metavar="Q", help="a pump at the inlet (m^3/s)")
    p.add_argument("--outlet", choices=("open", "closed"), default="open", help="open (default) or a dead end")
    p.add_argument("--chamber", metavar="V0,C", help="a linear chamber V = V0 + C p at the outlet (m^3, m^3/Pa)")
    p.add_argument("--outlet-pressure", type=float, default=None, metavar="P",
                   help="open outlet's pressure (Pa, default 0; refused with a closed end or a chamber)")
    p.add_argument("--external-pressure", type=float, default=0.0, metavar="PE", help="pressure outside (Pa)")
    p.add_argument("--t-end", type=float, required=True, metavar="T", help="last time (s)")
    p.add_argument("--steps", type=int, default=101, metavar="N", help="output times from 0 to T (default 101)")
    p.add_argument("--rtol", type=float, default=1e-4, help="relative accuracy of the inlet history (default 1e-4)")
    p.add_argument("--density", type=float, metavar="RHO", help="fluid density (kg/m^3): warn where inertia counts")
    p.add_argument("--output", metavar="FILE", type=_path, help="the histories as CSV (default: standard output)")
    p.add_argument("--netcdf", metavar="FILE", type=_path, help="also the fields as netCDF (needs xarray)")
    p.add_argument("--plot", metavar="FILE", type=_path, help="also a figure (PNG, SVG, PDF, ...)")
    p.set_defaults(run=_cmd_evolve)

    p = sub.add_parser("reproduce", help="the chapter's figures, as printed and consistent (PNG and CSV)")
    p.add_argument("out", nargs="?", default="chapter-figures", metavar="OUTDIR", type=_path,
                   help="output directory (default: ./chapter-figures)")
    p.add_argument("--png-only", action="store_true", help="write the figures without their CSV data")
    p.set_defaults(run=_cmd_reproduce)

    p = sub.add_parser("curve", help="a flow-rate–pressure-drop curve as CSV or JSON (optionally a plot)",
                       description="Sweep flow rates or pressure drops. " + _SCENE_HELP)
    _add_scene_args(p)
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--flow-rate", metavar="START:STOP[:N]", help="flow-rate range (m^3/s), N points")
    load.add_argument("--pressure-drop", metavar="START:STOP[:N]", help="pressure-drop range (Pa), N points")
    p.add_argument("--log", action="store_true", help="log-spaced points (START > 0), and log axes with --plot")
    p.add_argument("--format", choices=("csv", "json", "netcdf"), default=None,
                   help="table format (default: from the --output suffix .csv/.json/.nc, else csv; "
                        "netcdf needs xarray)")
    p.add_argument("--output", metavar="FILE", type=_path,
                   help="write the table to FILE (.csv, .json, .nc) instead of standard output")
    p.add_argument("--plot", metavar="FILE", type=_path, help="also save a plot of the curve (PNG, SVG, PDF, ...)")
    p.add_argument("--density", type=float, metavar="RHO",
                   help="fluid density (kg/m^3): warn where the reduced Reynolds number is not small")
    p.add_argument("--progress", action="store_true",
                   help="show a progress bar (tqdm; shown anyway on a terminal when tqdm is installed)")
    p.set_defaults(run=_cmd_curve)

    p = sub.add_parser("network", help="solve a network of tubes described in a JSON file",
                       description="Solve a network (Kirchhoff over its tubes) described in FILE: "
                                   '{"rheology": "NAME:k=v,...", "tubes": [{"u": "a", "v": "b", "name": "ab", '
                                   '"wall": "NAME:k=v,...", "tube": {"radius": 1e-4, "thickness": 3e-5, '
                                   '"length": 1e-2}}, ...], "pressures": {"a": 500}, "inflows": {}, '
                                   '"resistances": {"c": {"resistance": 1e11, "distal_pressure": 0}}}. '
                                   + _SCENE_HELP)
    p.add_argument("file", metavar="FILE", help="the network description (JSON)")
    p.add_argument("--format", choices=("json", "csv"), default=None,
                   help="json (default: nodes and tubes) or csv (two tables, PREFIX_nodes.csv, PREFIX_tubes.csv)")
    p.add_argument("--output", metavar="FILE|PREFIX", type=_path,
                   help="write the result here (FILE.json, or PREFIX with --format csv) instead of standard output")
    p.add_argument("--plot", metavar="FILE", type=_path, help="also save a plot of the network")
    p.set_defaults(run=_cmd_network)

    p = sub.add_parser("advise", help="compare the model with simpler ones on the same scene",
                       description="Recommend the cheapest model within a tolerance. " + _SCENE_HELP)
    _add_scene_args(p)
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--flow-rate", type=float, metavar="Q", help="flow rate (m^3/s)")
    load.add_argument("--pressure-drop", type=float, metavar="DP", help="pressure drop (Pa)")
    p.add_argument("--tolerance", type=float, default=0.01, help="relative pressure-drop tolerance (0.01)")
    p.add_argument("--density", type=float, metavar="RHO", help="fluid density (kg/m^3), for diagnostics")
    p.set_defaults(run=_cmd_advise)
    return parser


_SCENE_HELP = "Models are NAME or NAME:key=value,...; see 'tubefsi list'. SI units throughout."


def _path(text):
    """An output path (argparse type): not empty, which would silently mean standard output."""
    if not text:
        raise argparse.ArgumentTypeError("needs a file name, got an empty string")
    return text


def _add_scene_args(p):
    p.add_argument("--rheology", required=True, metavar="NAME[:k=v,...]",
                   help="e.g. power-law:consistency=0.017,index=0.7")
    p.add_argument("--wall", required=True, metavar="NAME[:k=v,...]",
                   help="e.g. thick-neo-hookean:shear_modulus=2e3")
    p.add_argument("--tube", required=True, metavar="radius=..,thickness=..,length=..",
                   help="undeformed tube (m); outlet_radius=.., outlet_thickness=.. make a linear taper from the "
                        "inlet's radius and thickness to these")
    p.add_argument("--outlet-pressure", type=float, default=0.0, metavar="P",
                   help="outlet (gauge) pressure of the fluid (Pa, default 0)")
    p.add_argument("--external-pressure", type=float, default=0.0, metavar="PE",
                   help="pressure outside the tube (Pa, any sign, default 0): the wall sees p - PE")
    p.add_argument("--coupler", default="auto", metavar="NAME[:k=v,...]",
                   help="auto (default), closed-form, quadrature, ode, or a plugin's")


def _range(option, text, log):
    parts = text.split(":")
    if len(parts) not in (2, 3):
        raise UsageError(f"{option} takes START:STOP or START:STOP:N, got {text!r}")
    try:
        start, stop = float(parts[0]), float(parts[1])
        count = int(parts[2]) if len(parts) == 3 else 101
    except ValueError:
        raise UsageError(f"{option} takes numbers START:STOP[:N], got {text!r}") from None
    if not (np.isfinite(start) and np.isfinite(stop) and 0 <= start < stop and count >= 2):
        raise UsageError(f"{option} needs 0 <= START < STOP and N >= 2, got {text!r}")
    if log:
        if start <= 0:
            raise UsageError(f"--log needs START > 0 in {option}")
        return np.geomspace(start, stop, count)
    return np.linspace(start, stop, count)


_FORMATS = {".csv": "csv", ".json": "json", ".nc": "netcdf", ".nc4": "netcdf", ".netcdf": "netcdf"}


def _writable(option, path):
    """``path`` can be created: its directory exists and is writable, and it is not a directory."""
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise UsageError(f"{option} {path!r} is a directory; give a file name")
    if not os.path.isdir(folder):
        raise UsageError(f"{option} {path!r}: the directory {folder!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise UsageError(f"{option} {path!r}: the directory {folder!r} is not writable")


def _check_outputs(args):
    """The table format and the plot format, checked before anything is computed."""
    fmt = args.format
    if args.output:
        _writable("--output", args.output)
        suffix = os.path.splitext(args.output)[1].lower()
        if fmt is None and suffix and suffix not in _FORMATS:   # y.png, y.xlsx: not a table this writes
            hint = "; a figure is --plot FILE" if suffix.lstrip(".") in _figure_formats() else ""
            raise UsageError(f"--output {args.output!r}: {suffix!r} is not a table format; use .csv, .json or .nc "
                             f"(or give --format){hint}")
        if fmt is None:
            fmt = _FORMATS.get(suffix, "csv")
    fmt = fmt or "csv"
    if fmt == "netcdf":
        if not args.output:
            raise UsageError("--format netcdf needs --output FILE (NetCDF is a binary file)")
        try:
            import xarray  # noqa: F401
        except ImportError:
            raise UsageError("--format netcdf needs xarray: pip install 'tubefsi[xarray]'") from None
    if args.plot:
        _writable("--plot", args.plot)
        supported = _figure_formats()
        ext = os.path.splitext(args.plot)[1].lower().lstrip(".")
        if ext not in supported:
            raise UsageError(f"--plot {args.plot!r}: the format {ext or '(none)'!r} is not one matplotlib writes; "
                             f"use one of {', '.join(sorted(supported))}")
    return fmt


def _figure_formats():
    """The file formats matplotlib writes (png, pdf, svg, ...)."""
    from matplotlib.figure import Figure

    return Figure().canvas.get_supported_filetypes()


def _cmd_curve(args, out) -> int:
    fmt = _check_outputs(args)
    if args.plot and args.external_pressure != 0.0:
        raise InvalidParameterError("--external-pressure", "0 with --plot (the flow-curve plot takes none)",
                                    args.external_pressure)
    fluid, wall, tube, coupler = _scene_from_args(args)
    from .solve import solve

    kind = "flow_rate" if args.flow_rate is not None else "pressure_drop"
    option = "--flow-rate" if kind == "flow_rate" else "--pressure-drop"
    values = _range(option, getattr(args, kind), args.log)
    sol = solve(fluid, wall, tube, coupler=coupler, outlet_pressure=args.outlet_pressure, density=args.density,
                external_pressure=args.external_pressure, progress=True if args.progress else "auto", **{kind: values})
    if fmt == "netcdf":
        ds = sol.to_xarray()
        if "feasible" in ds:                  # NetCDF 3 has no booleans
            ds["feasible"] = ds["feasible"].astype("i1")
        ds.to_netcdf(args.output, engine="scipy")
    else:
        columns = list(_OUTPUT_UNITS)
        data = {k: np.atleast_1d(getattr(sol, k)).tolist() for k in columns}
        stream = open(args.output, "w", encoding="utf-8") if args.output else out
        try:
            if fmt == "json":
                json.dump({"coupler": sol.coupler_name, "units": _OUTPUT_UNITS, **data}, stream, allow_nan=False)
                stream.write("\n")
            else:
                stream.write(",".join(f"{k} ({_OUTPUT_UNITS[k]})" for k in columns) + "\n")
                for row in zip(*(data[k] for k in columns)):
                    stream.write(",".join(repr(float(v)) for v in row) + "\n")
        finally:
            if args.output:
                stream.close()
    if args.plot:
        from .plotting import plot_flow_curve

        ax = plot_flow_curve(fluid, wall, tube, flow_rates=np.atleast_1d(sol.flow_rate), coupler=coupler,
                             outlet_pressure=args.outlet_pressure)
        if args.log:                          # log-spaced points on log axes
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.autoscale()
        ax.figure.savefig(args.plot, dpi=130)
    return 0


#: The keys of a network file, and of each of its tubes: required, then optional (``docs/cli.md``).
_NETWORK_KEYS = ("rheology", "tubes", "pressures", "inflows", "resistances", "positions")
_RESISTANCE_KEYS = ("resistance", "distal_pressure")
_TUBE_KEYS = ("u", "v", "wall", "tube")
_TUBE_OPTIONAL = ("name", "rheology", "external_pressure")


def _network_from_file(path):
    """A :class:`~tubefsi.Network` from a JSON description (``docs/cli.md``, "Networks"). Whatever
    is malformed is a :class:`UsageError` naming the file and the place in it (``tubes[2]: wall:
    ...``), checked here field by field: JSON holds any type anywhere, and a list where a node name
    or a number belongs would otherwise fail deep inside the library."""
    from .network import Network

    spec = _read_json(path)
    if not isinstance(spec, dict) or not isinstance(spec.get("tubes"), list) or not spec["tubes"]:
        raise UsageError(f"{path!r}: expected an object with a non-empty list 'tubes'")
    _only_keys(path, "", spec, _NETWORK_KEYS)
    with _located(path, "rheology"):
        fluid = _model_at("rheology", registry.rheologies, spec["rheology"]) if "rheology" in spec else None
    net = Network(rheology=fluid)
    for i, item in enumerate(spec["tubes"]):
        place = f"tubes[{i}]"
        if not isinstance(item, dict) or not set(_TUBE_KEYS) <= set(item):
            raise UsageError(f"{path!r}, {place}: expected an object with u, v, wall, tube (and optionally "
                             f"name, rheology, external_pressure), got {reprlib.repr(item)}")
        _only_keys(path, place, item, _TUBE_KEYS + _TUBE_OPTIONAL)
        with _located(path, place):
            name = item.get("name")
            if name is not None and not (isinstance(name, str) or type(name) is int):
                raise UsageError(f"name: a tube's name is a string or an integer, got {reprlib.repr(name)}")
            wall = _model_at("wall", registry.walls, item["wall"])
            rheology = _model_at("rheology", registry.rheologies, item["rheology"]) if "rheology" in item else None
            net.add_tube(_node_at("u", item["u"]), _node_at("v", item["v"]), wall, _tube_at(item["tube"]), name=name,
                         rheology=rheology,
                         external_pressure=_number_at("external_pressure", item.get("external_pressure", 0.0), "Pa"))
    for key, unit in (("pressures", "Pa"), ("inflows", "m^3/s"), ("resistances", "Pa s/m^3"),
                      ("positions", "[x, y]")):
        entries = spec.get(key, {})
        if not isinstance(entries, dict):
            raise UsageError(f"{path!r}, {key}: expected an object {{node: {unit}}}, got {reprlib.repr(entries)}")
        nodes = set(net.nodes)
        for node, value in entries.items():
            with _located(path, f"{key}[{node!r}]"):
                if key != "positions" and node not in nodes:    # (else refused only by the solve, placeless)
                    raise UsageError(f"node {node!r} is no node of any tube")
                if key == "pressures":
                    net.set_pressure(node, _number_at("pressure", value, unit))
                elif key == "inflows":
                    net.set_inflow(node, _number_at("inflow", value, unit))
                elif key == "resistances":
                    net.set_resistance(node, *_resistance_at(value))
                elif isinstance(value, list) and len(value) == 2:
                    net.set_position(node, [_number_at("x", value[0], "plot units"),
                                            _number_at("y", value[1], "plot units")])
                else:
                    raise UsageError(f"expected a position [x, y] (two numbers), got {reprlib.repr(value)}")
    return net


def _read_json(path):
    """The JSON value in the file ``path``; a file that cannot be read or is not JSON is a UsageError."""
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh)
    except OSError as exc:
        raise UsageError(f"cannot read the network file {path!r}: {exc.strerror or exc}") from None
    except RecursionError:       # Python's json recurses once per level of nesting
        raise UsageError(f"{path!r}: the JSON is nested too deeply to read (a network file is a few levels deep)") \
            from None
    except UnicodeDecodeError as exc:
        raise UsageError(f"{path!r} is not JSON: not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise UsageError(f"{path!r} is not JSON: {exc.msg} at line {exc.lineno}") from None
    except ValueError as exc:    # e.g. an integer of more digits than Python converts
        raise UsageError(f"{path!r} is not JSON that can be read: {exc}") from None


@contextlib.contextmanager
def _located(path, place):
    """A usage or parameter error of the block, as one UsageError naming the file and the place in it."""
    try:
        yield
    except (UsageError, InvalidParameterError) as exc:
        raise UsageError(f"{path!r}, {place}: {exc}") from None


def _only_keys(path, place, obj, known):
    unknown = sorted(set(obj) - set(known))
    if unknown:
        where = f"{path!r}, {place}" if place else f"{path!r}"
        raise UsageError(f"{where}: unknown key {unknown[0]!r}; keys: {', '.join(known)}")


def _model_at(kind, models, spec):
    """The model of a spec from a file, which must be a string like the command line's."""
    if not isinstance(spec, str):
        raise UsageError(f"{kind}: expected a model spec, a string NAME or 'NAME:key=value,...', "
                         f"got {reprlib.repr(spec)}")
    return _build(kind, models, spec)


def _node_at(key, node):
    # a string: the keys of 'pressures', 'inflows', 'resistances' and 'positions', which name nodes, are strings in JSON
    if not isinstance(node, str):
        raise UsageError(f"{key}: a node name is a string, got {reprlib.repr(node)}")
    return node


def _number_at(key, value, unit):
    """A JSON number as a float (its range is the library's to check)."""
    if type(value) not in (int, float):
        raise UsageError(f"{key}: expected a number ({unit}), got {reprlib.repr(value)}")
    try:
        return float(value)
    except OverflowError:          # an integer written out with hundreds of digits
        raise UsageError(f"{key}: {reprlib.repr(value)} is beyond the floating-point numbers ({unit})") from None


def _resistance_at(value):
    """``(resistance, distal_pressure)`` of a resistance outlet from a file: a number R (Pa s/m^3,
    to a distal pressure of 0) or an object ``{"resistance": R, "distal_pressure": P}`` (P optional)."""
    if isinstance(value, dict):
        unknown = sorted(set(value) - set(_RESISTANCE_KEYS))
        if unknown or "resistance" not in value:
            raise UsageError(f"expected a resistance R (Pa s/m^3) or an object {{\"resistance\": R, "
                             f"\"distal_pressure\": P}} (P in Pa, optional), got {reprlib.repr(value)}")
        return (_number_at("resistance", value["resistance"], "Pa s/m^3"),
                _number_at("distal_pressure", value.get("distal_pressure", 0.0), "Pa"))
    return _number_at("resistance", value, "Pa s/m^3"), 0.0


def _tube_at(geometry):
    """A Tube from a file: an object of numbers, or the command line's ``radius=..,...`` string."""
    if isinstance(geometry, str):
        return _tube(geometry, "tube")
    if not isinstance(geometry, dict):
        raise UsageError("tube: expected an object {\"radius\": .., \"thickness\": .., \"length\": ..} (m) or "
                         f"'radius=..,thickness=..,length=..', got {reprlib.repr(geometry)}")
    params = {}
    for key, value in geometry.items():     # a number, or a number written as a string ("1e-4")
        params[key] = _parse_value(value) if isinstance(value, str) else _number_at(f"tube: {key}", value, "m")
    return _tube_from(params, "tube")


def _cmd_network(args, out) -> int:
    if args.format == "csv" and not args.output:
        raise UsageError("--format csv writes two tables: give --output PREFIX")
    if args.output:
        _writable("--output", args.output + "_nodes.csv" if args.format == "csv" else args.output)
        suffix = os.path.splitext(args.output)[1].lower()
        if args.format is None and suffix not in ("", ".json"):
            raise UsageError(f"--output {args.output!r}: the result is JSON, not {suffix!r}; give FILE.json "
                             "(or --format csv --output PREFIX for two CSV tables)")
    if args.plot:
        _check_outputs(argparse.Namespace(format="csv", output=None, plot=args.plot))
    net = _network_from_file(args.file)
    if args.plot and set(net.nodes) - set(net.positions):
        try:
            import networkx  # noqa: F401
        except ImportError:
            raise UsageError("--plot needs the nodes' positions (a 'positions' object in FILE) or networkx "
                             "for a layout: pip install 'tubefsi[network]'") from None
    result = net.solve(progress="auto")      # a bar on a terminal, when tqdm is installed
    if args.format == "csv":
        for written in result.to_csv(args.output):
            print(f"wrote {written}", file=out)
    elif args.output:
        result.to_json(args.output)
        print(f"wrote {args.output}", file=out)
    else:
        out.write(result.to_json() + "\n")
    if args.plot:
        ax = result.plot()
        ax.figure.savefig(args.plot, dpi=130)
    return 0


def _cmd_evolve(args, out) -> int:
    from .evolve import Chamber, evolve

    fluid = _build("rheology", registry.rheologies, args.rheology)
    wall = _build("wall", registry.walls, args.wall)
    tube = _tube(args.tube, "--tube")
    outlet = args.outlet
    if args.chamber is not None:
        values = _load_values("--chamber", args.chamber)
        if np.ndim(values) != 1 or len(values) != 2:
            raise UsageError(f"--chamber takes V0,C (m^3, m^3/Pa), got {args.chamber!r}")
        outlet = Chamber.linear(float(values[0]), float(values[1]))
    if not (args.t_end > 0 and args.steps >= 2):
        raise UsageError("--t-end must be > 0 and --steps >= 2")
    result = evolve(fluid, wall, tube, np.linspace(0.0, args.t_end, args.steps), inlet_pressure=args.inlet_pressure,
                    inlet_flow_rate=args.inlet_flow_rate, outlet=outlet,
                    outlet_pressure=args.outlet_pressure,
                    external_pressure=args.external_pressure, rtol=args.rtol, density=args.density)
    result.to_csv(args.output if args.output is not None else out)
    if args.netcdf is not None:
        result.to_xarray().to_netcdf(args.netcdf)
    if args.plot is not None:
        result.plot().savefig(args.plot, dpi=130)
    return 0


def _cmd_reproduce(args, out) -> int:
    from .chapter import reproduce_chapter

    reproduce_chapter(args.out, formats=("png",) if args.png_only else ("png", "csv"), file=out)
    return 0


def _cmd_advise(args, out) -> int:
    from .advise import advise
    from .solve import solve

    fluid, wall, tube, _ = _scene_from_args(args)
    if args.external_pressure != 0.0:
        raise InvalidParameterError("--external-pressure", "0 for advise (its simpler models take none)",
                                    args.external_pressure)
    load = {"flow_rate": args.flow_rate} if args.flow_rate is not None else {"pressure_drop": args.pressure_drop}
    advice = advise(fluid, wall, tube, tolerance=args.tolerance, outlet_pressure=args.outlet_pressure,
                            **load)
    print(advice, file=out)
    print(f"\nrecommended: {advice.recommended.label}", file=out)
    with warnings.catch_warnings():           # the diagnostics below list them
        warnings.simplefilter("ignore", ModelValidityWarning)
        sol = solve(fluid, wall, tube, outlet_pressure=args.outlet_pressure, **load)
    print("\ndiagnostics of the requested model:", file=out)
    print(sol.diagnostics(density=args.density, warn=False), file=out)
    return 0


_NUMBERS = re.compile(r"^-[0-9.][0-9eE.+\-]*([,:][-+]?[0-9.][0-9eE.+\-]*)*$")


def _join_negative_values(argv):
    """``--flow-rate -1e-9`` as ``--flow-rate=-1e-9``: argparse takes ``-1e-9`` for an option, so
    a negative number (or list, or range) after an option reaches the library's validation."""
    out = []
    for item in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and _NUMBERS.match(item):
            out[-1] = f"{out[-1]}={item}"
        else:
            out.append(item)
    return out


def _error(message) -> int:
    text = " ".join(str(message).split()) or "unknown error"
    print(f"{PROG}: error: {text}", file=sys.stderr)
    return 2


class _Discard(io.TextIOBase):
    """Standard output when it is closed (``tubefsi ... >&-``, where Python's ``sys.stdout`` is
    None): what is written goes nowhere, as with ``print``."""

    def writable(self) -> bool:
        return True

    def write(self, text) -> int:
        return len(text)


def _standard_output():
    """``sys.stdout`` as the commands write to it: a character its encoding lacks as a backslash
    escape (an ASCII-only stream: ``LC_ALL=C``, ``PYTHONIOENCODING=ascii``; the docstrings that
    ``list`` and ``--help`` print have dashes and Greek letters; under the C locale Python's
    handler is ``surrogateescape``, which fails there too), and a closed stream as one that
    discards (the commands still write their files)."""
    for stream in (sys.stdout, sys.stderr):
        if (stream is not None and not getattr(stream, "closed", False) and hasattr(stream, "reconfigure")
                and getattr(stream, "errors", None) in ("strict", "surrogateescape")):
            stream.reconfigure(errors="backslashreplace")
    if sys.stdout is None or getattr(sys.stdout, "closed", False):
        return _Discard()
    return sys.stdout


def main(argv=None) -> int:
    """Run the ``tubefsi`` command with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    out = _standard_output()
    parser = _parser()
    argv = _join_negative_values(sys.argv[1:] if argv is None else list(argv))
    try:
        with contextlib.redirect_stdout(out):      # --help and --version print to sys.stdout
            args = parser.parse_args(argv)
    except UsageError as exc:
        return _error(exc)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    if args.command is None:
        return _error("a command is required: list, solve, curve, network, advise, evolve or reproduce "
                      "(see 'tubefsi --help')")
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ModelValidityWarning)
            status = args.run(args, out)
        for w in caught:
            if issubclass(w.category, (ModelValidityWarning, registry.PluginWarning)):
                print(f"{PROG}: warning: {' '.join(str(w.message).split())}", file=sys.stderr)
            else:
                warnings.showwarning(w.message, w.category, w.filename, w.lineno)
        return status
    except (UsageError, ValueError, TubefsiError, Warning) as exc:
        # InvalidParameterError and NoSteadyStateError are ValueErrors; ConvergenceError a TubefsiError;
        # a Warning raised is one made an error (python -W error), e.g. a broken plugin's
        return _error(exc)
    except KeyError as exc:  # a registry lookup with its own message
        return _error(exc.args[0] if exc.args else exc)
    except BrokenPipeError:  # `tubefsi list | head`: the reader has what it wanted, as with a closed stdout
        return 0
    except OSError as exc:  # an output path that cannot be written: the user's to fix, not a bug
        where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        return _error(f"cannot write{where}: {exc.strerror or exc}")
    except Exception as exc:  # a bug of ours: still one line, but say what it was
        return _error(f"internal error ({type(exc).__name__}: {exc}); please report it")


if __name__ == "__main__":
    sys.exit(main())
