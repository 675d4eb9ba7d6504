r"""The ``tubefsi`` command: list the registered models, solve one scene, run the demo.

::

    tubefsi list
    tubefsi solve --rheology power-law:consistency=0.017,index=0.7 \
                  --wall thick-neo-hookean:shear_modulus=2e3 \
                  --tube radius=1e-4,thickness=3e-5,length=1e-2 --flow-rate 1e-9 [--json]
    tubefsi demo --out tubefsi-demo

A model is ``NAME`` or ``NAME:key=value,key=value`` with the parameter names of
``tubefsi list`` (SI units); a coupler may take options the same way
(``--coupler quadrature:order=24``). ``--flow-rate`` and ``--pressure-drop`` take
one value or a comma-separated list. Any bad argument — an unknown model or
parameter, a value outside its admissible range, a load beyond the maximum flow
rate — ends with a one-line ``tubefsi: error: ...`` on stderr and exit status 2.

The demo (:func:`run_demo`, also ``examples/demo.py``) compares the built-in walls
for a blood-like shear-thinning fluid in a soft microfluidic tube and writes figures.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

__all__ = ["main", "run_demo", "parse_model_spec"]

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


def _fields(cls):
    import attrs

    return attrs.fields(cls) if attrs.has(cls) else ()


def _build(kind: str, registry, spec: str):
    """An instance of the registered model ``NAME`` with the parameters of ``spec``."""
    import attrs

    name, params = parse_model_spec(spec)
    if name not in registry:
        raise UsageError(f"unknown {kind} {name!r}; known: {', '.join(registry)}")
    cls = registry[name]
    fields = {f.name: f for f in _fields(cls) if f.init}
    unknown = [k for k in params if k not in fields]
    if unknown:
        known = ", ".join(fields) or "none"
        raise UsageError(f"{kind} {name!r} has no parameter {unknown[0]!r}; its parameters: {known}")
    missing = [f for f in fields.values() if f.default is attrs.NOTHING and f.name not in params]
    if missing:
        raise UsageError(f"{kind} {name!r} needs " + ", ".join(_describe_field(f) for f in missing)
                         + f" (e.g. {name}:{missing[0].name}=...)")
    return cls(**params)


def _describe_field(field) -> str:
    meta = field.metadata
    unit = f" ({meta['unit']})" if meta.get("unit") else ""
    adm = f" in {meta['admissible']}" if meta.get("admissible") else ""
    return f"{field.name}{unit}{adm}"


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
    """First phrase of a class docstring, without reST math."""
    import inspect

    doc = " ".join((inspect.getdoc(cls) or "").split())
    depth, cut = 0, len(doc)
    for i, ch in enumerate(doc):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(depth - 1, 0)
        elif depth == 0 and (ch == ";" or (ch == "." and (i + 1 == len(doc) or doc[i + 1] == " "))):
            cut = i
            break
    math_at = doc.find(":math:")
    if 0 <= math_at < cut:
        cut = math_at
    return doc[:cut].rstrip(" ,:;")


def _cmd_list(args, out) -> int:
    from . import registry

    groups = [("rheologies", registry.rheologies), ("walls", registry.walls), ("couplers", registry.couplers)]
    for title, reg in groups:
        print(f"{title}:", file=out)
        for name in reg:
            cls = reg[name]
            dist = reg.distribution(name)
            origin = "" if dist == "tubefsi" else f"  [{dist}]"
            print(f"  {name:<22}{_summary(cls)}{origin}", file=out)
            fields = [f for f in _fields(cls) if f.init]
            if not fields:
                print(f"      {'(no parameters)' if title != 'couplers' else '(no options)'}", file=out)
            for f in fields:
                meta = f.metadata
                unit = meta.get("unit") or "-"
                adm = meta.get("admissible") or ""
                default = "" if f.default is _nothing() else f"  default {f.default!r}"
                doc = meta.get("doc") or ""
                line = f"      {f.name:<22}{unit:<9}{adm:<26}{doc}{default}"
                print(line.rstrip(), file=out)
    return 0


def _nothing():
    import attrs

    return attrs.NOTHING


# ---------------------------------------------------------------------------- solve
_OUTPUT_UNITS = {
    "pressure_drop": "Pa",
    "flow_rate": "m^3/s",
    "inlet_pressure": "Pa",
    "inlet_displacement": "m",
    "inlet_radius": "m",
}


def _scene_from_args(args):
    """(fluid, wall, tube, coupler) from the shared scene options."""
    import tubefsi
    from . import registry

    fluid = _build("rheology", registry.rheologies, args.rheology)
    wall = _build("wall", registry.walls, args.wall)
    tube_params = _parse_pairs(args.tube, args.tube)
    expected = ("radius", "thickness", "length")
    unknown = [k for k in tube_params if k not in expected]
    if unknown:
        raise UsageError(f"--tube has no parameter {unknown[0]!r}; expected radius, thickness, length (m)")
    missing = [k for k in expected if k not in tube_params]
    if missing:
        raise UsageError(f"--tube needs {', '.join(missing)} (m), e.g. --tube radius=1e-4,thickness=3e-5,"
                         "length=1e-2")
    tube = tubefsi.Tube(**tube_params)
    coupler = args.coupler
    if coupler != "auto":
        coupler = _build("coupler", registry.couplers, coupler)
    return fluid, wall, tube, coupler


def _cmd_solve(args, out) -> int:
    import tubefsi

    fluid, wall, tube, coupler = _scene_from_args(args)
    load = {}
    if args.flow_rate is not None:
        load["flow_rate"] = _load_values("--flow-rate", args.flow_rate)
    else:
        load["pressure_drop"] = _load_values("--pressure-drop", args.pressure_drop)
    sol = tubefsi.solve(fluid, wall, tube, coupler=coupler, outlet_pressure=args.outlet_pressure, **load)

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


# ---------------------------------------------------------------------------- demo
#: The demo's scene: a blood-like shear-thinning fluid in a soft microfluidic tube.
DEMO_TUBE = dict(radius=100e-6, thickness=30e-6, length=10e-3)                  # m
DEMO_FLUID = ("power-law", dict(consistency=0.017, index=0.7))                   # Pa s^n, -
DEMO_SHEAR_MODULUS = 2e3                                                         # Pa (soft gel)
DEMO_FLOW_RATES = (1e-10, 1e-9, 5e-9, 1e-8)                                      # m^3/s


def demo_walls(shear_modulus: float = DEMO_SHEAR_MODULUS) -> dict:
    """The demo's walls, all of one material: linear ones at its small-strain limit, E = 3 mu."""
    from . import registry

    W = registry.walls
    E = 3.0 * shear_modulus
    return {
        "rigid": W["rigid"](),
        "thin-linear": W["thin-linear"](youngs_modulus=E, poisson_ratio=0.5),
        "thick-linear": W["thick-linear"](youngs_modulus=E, poisson_ratio=0.5),
        "thin-neo-hookean": W["thin-neo-hookean"](shear_modulus=shear_modulus),
        "thick-neo-hookean": W["thick-neo-hookean"](shear_modulus=shear_modulus),
    }


def run_demo(out_dir="tubefsi-demo", *, file=None) -> list[Path]:
    """Compare the walls on the demo scene, print a table, write PNG figures to ``out_dir``.

    Returns the paths of the figures written.
    """
    import matplotlib.pyplot as plt

    import tubefsi
    from . import plotting

    out = sys.stdout if file is None else file
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)

    tube = tubefsi.Tube(**DEMO_TUBE)
    fluid = tubefsi.registry.rheologies[DEMO_FLUID[0]](**DEMO_FLUID[1])
    walls = demo_walls()
    mu = DEMO_SHEAR_MODULUS
    qs = np.array(DEMO_FLOW_RATES)

    print(f"tubefsi {tubefsi.__version__} demo: power-law fluid (m = {fluid.consistency:g} Pa s^n, "
          f"n = {fluid.index:g}) in a soft tube", file=out)
    print(f"  tube a = {tube.radius * 1e6:g} um, t = {tube.thickness * 1e6:g} um, L = {tube.length * 1e3:g} mm "
          f"(t/a = {tube.reduced_thickness:g}); wall shear modulus mu = {mu:g} Pa, linear walls E = 3 mu, "
          f"nu = 0.5", file=out)
    print("", file=out)

    # ---- the table: pressure drop and inlet displacement per wall and flow rate
    limits, rows = {}, {}
    for name, wall in walls.items():
        limits[name] = tubefsi.max_flow_rate(fluid, wall, tube)
        ok = qs < limits[name]                      # beyond q_max there is no steady state
        dp = np.full(qs.shape, np.nan)
        u = np.full(qs.shape, np.nan)
        coupler = "-"
        if np.any(ok):
            sol = tubefsi.solve(fluid, wall, tube, flow_rate=qs[ok])
            dp[ok], u[ok], coupler = sol.pressure_drop, 1e6 * sol.inlet_displacement, sol.coupler_name
        rows[name] = (coupler, dp, u)

    def table(title, column, fmt):
        print(title, file=out)
        print(f"  {'wall':<19}{'coupler':<13}" + "".join(f"{q:>10.0e}" for q in qs), file=out)
        for name, row in rows.items():
            cells = "".join(f"{format(v, fmt):>10}" if np.isfinite(v) else f"{'none':>10}" for v in row[column])
            print(f"  {name:<19}{row[0]:<13}{cells}", file=out)
        print("", file=out)

    table("pressure drop (Pa) at flow rate q (m^3/s):", 1, ".1f")
    table("inlet wall displacement R(0) - a (um) at flow rate q (m^3/s):", 2, ".2f")
    print("maximum steady flow rate (m^3/s):", file=out)
    for name, q_max in limits.items():
        if math.isfinite(q_max):
            note = f"  (the wall's limit pressure is {walls[name].limit_pressure(tube.reduced_thickness):.1f} Pa)"
        else:
            note = "  (every flow rate has a steady state)"
        print(f"  {name:<19}{q_max:.6g}{note}", file=out)
    print("", file=out)

    # ---- figures
    written: list[Path] = []

    def save(fig, stem):
        path = out_dir / f"{stem}.png"
        fig.savefig(path, dpi=130)
        plt.close(fig)
        written.append(path)

    soft = walls["thick-neo-hookean"]
    q_max = limits["thick-neo-hookean"]
    q_curve = np.linspace(0.0, 0.9 * q_max, 200) if math.isfinite(q_max) else np.linspace(0.0, qs[-1], 200)

    colors = dict(zip(walls, ("0.15", "C0", "C2", "C1", "C3")))
    q_log = np.geomspace(1e-4 * q_curve[-1], q_curve[-1], 200)
    fig, (ax_lin, ax_log) = plt.subplots(1, 2, figsize=(11.5, 4.4), layout="constrained")
    for name, wall in walls.items():
        for ax, q_range in ((ax_lin, q_curve), (ax_log, q_log)):
            plotting.plot_flow_curve(fluid, wall, tube, flow_rates=q_range, ax=ax, rigid=False, label=name,
                                     color=colors[name])
    ax_log.set_xscale("log")
    ax_log.set_yscale("log")
    ax_log.autoscale_view()
    ax_lin.set_title("Flow curves: one material, five wall models")
    ax_log.set_title("the same, log–log: all agree at small loads")
    ax_log.get_legend().remove()
    save(fig, "flow_curves")

    sol_curve = tubefsi.solve(fluid, soft, tube, flow_rate=q_curve)
    save(plotting.plot_profiles(sol_curve), "profiles")

    sol = tubefsi.solve(fluid, soft, tube, flow_rate=DEMO_FLOW_RATES[2])
    fig, (ax_t, ax_v) = plt.subplots(1, 2, figsize=(12.5, 4.2), layout="constrained",
                                     gridspec_kw=dict(width_ratios=[1.8, 1.0]))
    plotting.plot_deformed_tube(sol, ax=ax_t)
    plotting.plot_velocity_profiles(sol, ax=ax_v)
    save(fig, "deformed_tube")

    tb = tube.reduced_thickness
    fig, (ax_n, ax_pa) = plt.subplots(1, 2, figsize=(11.5, 4.4), layout="constrained")
    for name, wall in walls.items():
        if "linear" not in name:       # normalized, a linear wall is the small-strain tangent itself
            plotting.plot_tube_law(wall, tb, ax=ax_n, max_stretch=3.0, color=colors[name])
        plotting.plot_tube_law(wall, tb, ax=ax_pa, max_stretch=3.0, normalize=False, color=colors[name])
    ax_n.set_title(f"Normalized by the small-strain modulus $k_0$ (t/a = {tb:.3g});\n"
                   "the linear walls are the tangent", fontsize=10)
    ax_pa.set_title(f"Tube laws of one material, $\\mu$ = {mu:g} Pa, E = 3$\\mu$", fontsize=10)
    ax_pa.legend(frameon=False, loc="upper left")
    save(fig, "tube_laws")

    for path in written:
        print(f"wrote {path}", file=out)
    return written


def _cmd_demo(args, out) -> int:
    run_demo(args.out, file=out)
    return 0


# ---------------------------------------------------------------------------- main
def _parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = _Parser(prog=PROG, description="Steady fluid–structure interaction in soft tubes.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("list", help="list the registered rheologies, walls and couplers with their parameters")
    p.set_defaults(run=_cmd_list)

    p = sub.add_parser("demo", help="run the demo and write its figures")
    p.add_argument("--out", default="tubefsi-demo", metavar="DIR",
                   help="directory for the PNG figures (default: ./tubefsi-demo)")
    p.set_defaults(run=_cmd_demo)

    p = sub.add_parser("solve", help="solve one scene (or a list of loads)",
                       description="Solve steady flow through a soft tube. " + _SCENE_HELP)
    _add_scene_args(p)
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--flow-rate", metavar="Q[,Q...]", help="flow rate(s) (m^3/s)")
    load.add_argument("--pressure-drop", metavar="DP[,DP...]", help="pressure drop(s) (Pa)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(run=_cmd_solve)

    p = sub.add_parser("reproduce", help="the chapter's figures, as printed and consistent (PNG and CSV)")
    p.add_argument("out", nargs="?", default="chapter-figures", metavar="OUTDIR",
                   help="output directory (default: ./chapter-figures)")
    p.add_argument("--png-only", action="store_true", help="write the figures without their CSV data")
    p.set_defaults(run=_cmd_reproduce)

    p = sub.add_parser("curve", help="a flow-rate–pressure-drop curve as CSV or JSON (optionally a plot)",
                       description="Sweep flow rates or pressure drops. " + _SCENE_HELP)
    _add_scene_args(p)
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--flow-rate", metavar="START:STOP[:N]", help="flow-rate range (m^3/s), N points")
    load.add_argument("--pressure-drop", metavar="START:STOP[:N]", help="pressure-drop range (Pa), N points")
    p.add_argument("--log", action="store_true", help="log-spaced points (START > 0)")
    p.add_argument("--format", choices=("csv", "json"), default="csv", help="output format (default csv)")
    p.add_argument("--output", metavar="FILE", help="write the table to FILE instead of standard output")
    p.add_argument("--plot", metavar="FILE", help="also save a plot of the curve (PNG, SVG, PDF)")
    p.set_defaults(run=_cmd_curve)

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


def _add_scene_args(p):
    p.add_argument("--rheology", required=True, metavar="NAME[:k=v,...]",
                   help="e.g. power-law:consistency=0.017,index=0.7")
    p.add_argument("--wall", required=True, metavar="NAME[:k=v,...]",
                   help="e.g. thick-neo-hookean:shear_modulus=2e3")
    p.add_argument("--tube", required=True, metavar="radius=..,thickness=..,length=..",
                   help="undeformed tube (m)")
    p.add_argument("--outlet-pressure", type=float, default=0.0, metavar="P",
                   help="transmural outlet pressure (Pa, default 0)")
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


def _cmd_curve(args, out) -> int:
    import tubefsi

    fluid, wall, tube, coupler = _scene_from_args(args)
    if args.flow_rate is not None:
        sol = tubefsi.solve(fluid, wall, tube, coupler=coupler, outlet_pressure=args.outlet_pressure,
                            flow_rate=_range("--flow-rate", args.flow_rate, args.log))
    else:
        sol = tubefsi.solve(fluid, wall, tube, coupler=coupler, outlet_pressure=args.outlet_pressure,
                            pressure_drop=_range("--pressure-drop", args.pressure_drop, args.log))
    columns = list(_OUTPUT_UNITS)
    data = {k: np.atleast_1d(getattr(sol, k)).tolist() for k in columns}
    stream = open(args.output, "w", encoding="utf-8") if args.output else out
    try:
        if args.format == "json":
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

        ax = plot_flow_curve(fluid, wall, tube, flow_rates=np.atleast_1d(sol.flow_rate))
        ax.figure.savefig(args.plot, dpi=130)
    return 0


def _cmd_reproduce(args, out) -> int:
    from .dimensionless import reproduce_chapter

    reproduce_chapter(args.out, formats=("png",) if args.png_only else ("png", "csv"), file=out)
    return 0


def _cmd_advise(args, out) -> int:
    import tubefsi

    fluid, wall, tube, _ = _scene_from_args(args)
    load = {"flow_rate": args.flow_rate} if args.flow_rate is not None else {"pressure_drop": args.pressure_drop}
    advice = tubefsi.advise(fluid, wall, tube, tolerance=args.tolerance, outlet_pressure=args.outlet_pressure,
                            **load)
    print(advice, file=out)
    print(f"\nrecommended: {advice.recommended.label}", file=out)
    sol = tubefsi.solve(fluid, wall, tube, outlet_pressure=args.outlet_pressure, **load)
    print("\ndiagnostics of the requested model:", file=out)
    print(sol.diagnostics(density=args.density, warn=False), file=out)
    return 0


def _error(message) -> int:
    text = " ".join(str(message).split()) or "unknown error"
    print(f"{PROG}: error: {text}", file=sys.stderr)
    return 2


def main(argv=None) -> int:
    """Run the ``tubefsi`` command with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    from .errors import TubefsiError

    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except UsageError as exc:
        return _error(exc)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    if args.command is None:
        return _error("a command is required: list, solve, curve, advise, demo or reproduce (see 'tubefsi --help')")
    try:
        return args.run(args, sys.stdout)
    except (UsageError, ValueError, TubefsiError) as exc:
        # InvalidParameterError and NoSteadyStateError are ValueErrors; ConvergenceError a TubefsiError
        return _error(exc)
    except KeyError as exc:  # a registry lookup with its own message
        return _error(exc.args[0] if exc.args else exc)
    except BrokenPipeError:  # `tubefsi list | head`
        return 0
    except Exception as exc:  # a bug of ours: still one line, but say what it was
        return _error(f"internal error ({type(exc).__name__}: {exc}); please report it")


if __name__ == "__main__":
    sys.exit(main())
