"""The deterministic bad-input probes: every field of every registered model and coupler, every
argument and keyword of every public entry point, and the extreme *valid* inputs of each pair."""

from __future__ import annotations

import math

import attrs
import numpy as np

from ... import registry
from ...advise import advise
from ...errors import KeywordError, NoSteadyStateError
from ...fit import fit
from ...geometry import Tube
from ...network import Network
from ...solve import max_flow_rate, solve
from ._core import _ALWAYS_BAD, _TUBE, Probe, _short

def _bad_for_field(field):
    """Values outside a field's admissible range (besides :data:`_ALWAYS_BAD`)."""
    meta = field.metadata
    if "options" in meta:
        return ("no-such-option", 3.0, None)
    if "low" not in meta:
        return ()
    low, high = meta["low"], meta["high"]
    out = [math.inf] if not (high == math.inf and not meta["high_open"]) else []
    out += list(_ALWAYS_BAD)
    if math.isfinite(low):
        out += [low] if meta["low_open"] else []
        out += [low - max(1.0, abs(low)), low - 1e-300 if low == 0 else low - 1e-9 * abs(low)]
    if math.isfinite(high):
        out += [high] if meta["high_open"] else []
        out += [high + max(1.0, abs(high))]
    return tuple(out)


_KIND = {"rheologies": "rheology", "walls": "wall", "couplers": "coupler"}


def _model_probes(kind, name):
    cls = getattr(registry, kind)[name]
    example = dict(cls._examples[0]) if getattr(cls, "_examples", ()) else {}
    entry = f"{_KIND[kind]}:{name}"
    for field in attrs.fields(cls):
        if not field.init:
            continue
        for value in _bad_for_field(field):
            kwargs = {**example, field.name: value}
            yield Probe(entry, f"{field.name}={_short(value)}", lambda kw=kwargs: cls(**kw), bad=True,
                        parameter=field.name)
    yield from _keyword_probes(entry, cls, example, constructor=True)


def _keyword_probes(entry, target, good, args=(), label="", constructor=False):
    """Wrong and missing keywords of a call ``target(*args, **good)``: a misspelt keyword (its last
    letter dropped, or doubled), a keyword no callable has, and each required keyword left out
    must each raise :class:`~tubefsi.KeywordError` (a ``TypeError`` too) naming it, with the
    intended keyword suggested and the valid ones listed. A ``constructor`` (a model, coupler or
    ``Tube`` class) may raise Python's own ``TypeError`` naming it instead."""
    import inspect

    params = [p for p in inspect.signature(target).parameters.values()
              if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)][len(args):]
    names = [p.name for p in params]
    tag = f"{label} " if label else ""

    def words(intended=None, missing=None):
        def check(error):
            if not (isinstance(error, KeywordError) and isinstance(error, TypeError)):
                return f"{type(error).__name__}, not a KeywordError"
            if intended and error.suggestion != intended:
                return f"suggests {error.suggestion!r}, not {intended!r}"
            if missing and missing not in error.missing:
                return f"missing {error.missing!r}, not {missing!r}"
            if not all(n in str(error) for n in names):
                return "does not list the valid keywords"
            return None
        return check

    if names:
        first = max(names, key=len) if len(names[0]) <= 3 else names[0]
        for typo in (first[:-1], first + first[-1]):
            if sum(n.startswith(typo) or typo.startswith(n) for n in names) != 1:     # ambiguous
                continue
            kwargs = {**good, typo: good.get(first, 1.0)}
            kwargs.pop(first, None)
            yield Probe(entry, f"{tag}keyword {typo}=", lambda kw=kwargs: target(*args, **kw), bad=True,
                        parameter=typo, words=words(intended=first), type_error=constructor)
    yield Probe(entry, f"{tag}keyword no_such_keyword=", lambda: target(*args, **good, no_such_keyword=1.0), bad=True,
                parameter="no_such_keyword", words=words(), type_error=constructor)
    for p in params:
        if p.default is p.empty:
            kwargs = {k: v for k, v in good.items() if k != p.name}
            yield Probe(entry, f"{tag}without {p.name}=", lambda kw=kwargs: target(*args, **kw), bad=True,
                        parameter=p.name, words=words(missing=p.name), type_error=constructor)


def _entry_keyword_probes():
    """Wrong and missing keywords of every public entry point that takes any (the models' own
    constructors are probed with their bad values, :func:`_model_probes`)."""
    R, W = registry.rheologies, registry.walls
    fluid = R["power-law"](consistency=0.017, index=0.7) if "power-law" in R else None
    wall = W["thick-neo-hookean"](shear_modulus=2e3) if "thick-neo-hookean" in W else None
    tube = Tube(**_TUBE)
    yield from _keyword_probes("Tube", Tube, dict(_TUBE), constructor=True)
    yield from _keyword_probes("Network", Network, dict(rheology=fluid))
    net = Network(rheology=fluid)
    yield from _keyword_probes("Network", net.add_tube, dict(name="t"), args=("a", "b", wall, tube), label="add_tube")
    yield from _keyword_probes("Network", net.set_pressure, dict(pressure=1.0), args=("a",), label="set_pressure")
    yield from _keyword_probes("Network", net.set_inflow, dict(flow_rate=1e-12), args=("a",), label="set_inflow")
    yield from _keyword_probes("Network", net.solve, dict(rtol=1e-13), label="solve")
    if fluid is None or wall is None:
        return
    pair = (fluid, wall, tube)
    yield from _keyword_probes("solve", solve, dict(flow_rate=1e-12), args=pair)
    yield from _keyword_probes("solve", solve, dict(flow_rate=1e-12), args=pair[:2], label="two positional")
    yield from _keyword_probes("max_flow_rate", max_flow_rate, dict(outlet_pressure=0.0), args=pair)
    yield from _keyword_probes("advise", advise, dict(flow_rate=1e-12), args=pair)
    yield from _keyword_probes("fit", fit, dict(parameters=["wall.shear_modulus"]), args=([1e-12], [1.0]) + pair)


def _solve_probes(fluid, wall, tube, tag):
    def call(**kw):
        return lambda: solve(fluid, wall, tube, **kw)

    for load in ("flow_rate", "pressure_drop"):
        for value in (math.nan, math.inf, -1.0, -1e-300, "1", True, 1e-9 + 1e-12j, [1e-12, -1.0], [[math.nan]],
                      object()):
            yield Probe("solve", f"{tag} {load}={_short(value)}", call(**{load: value}), bad=True, parameter=load)
    for value in (math.nan, -1.0, math.inf, "0", True, 1j):
        yield Probe("solve", f"{tag} outlet_pressure={_short(value)}", call(flow_rate=1e-12, outlet_pressure=value),
                    bad=True, parameter="outlet_pressure")
        yield Probe("max_flow_rate", f"{tag} outlet_pressure={_short(value)}",
                    lambda v=value: max_flow_rate(fluid, wall, tube, outlet_pressure=v), bad=True,
                    parameter="outlet_pressure")
    if "consistency" in attrs.fields_dict(type(fluid)):    # an array parameter against a load of another shape
        two = attrs.evolve(fluid, consistency=[fluid.consistency, 2 * fluid.consistency])
        yield Probe("solve", f"{tag} shapes (2,) and (3,)", lambda: solve(two, wall, tube, flow_rate=[1e-12] * 3),
                    bad=True, parameter="flow_rate")
    for value in ("no-such-coupler", 3, None):
        yield Probe("solve", f"{tag} coupler={value!r}", call(flow_rate=1e-12, coupler=value), bad=True,
                    parameter="coupler")
    yield Probe("solve", f"{tag} on_infeasible='x'", call(flow_rate=1e-12, on_infeasible="x"), bad=True,
                parameter="on_infeasible")
    yield Probe("solve", f"{tag} both loads", call(flow_rate=1e-12, pressure_drop=1.0), bad=True)
    yield Probe("solve", f"{tag} no load", call(), bad=True)
    # extreme valid loads: a typed error, or finite values that invert
    for load in ("flow_rate", "pressure_drop"):
        for value in (1e-300, 1e-30, 1e-12, 1e300):
            yield Probe("solve", f"{tag} {load}={value:g}", call(**{load: value}), check=_round_trip(load, value))
        yield Probe("solve", f"{tag} {load}=[]", call(**{load: []}))
        yield Probe("solve", f"{tag} {load}=0", call(**{load: 0.0}), check=_zero_load)
    yield Probe("solve", f"{tag} outlet_pressure=1e300", call(flow_rate=1e-12, outlet_pressure=1e300))
    # tiny drops on a loaded outlet: the small-drop limit, the rigid-tube flow at the outlet radius
    if not wall.is_rigid:
        tb = tube.thickness / tube.radius
        p_out = min(87.6, 0.25 * wall.limit_pressure(tb), 0.01 * wall.small_strain_modulus(tb) * tb)
        for value in (1e-14, 1e-100, 1e-300):
            yield Probe("solve", f"{tag} pressure_drop={value:g}, outlet_pressure={p_out:.4g}",
                        call(pressure_drop=value, outlet_pressure=p_out), check=_small_drop(value))
    yield Probe("max_flow_rate", tag, lambda: max_flow_rate(fluid, wall, tube), check=_max_flow_check(fluid, wall, tube),
                allow_inf=True)


def _small_drop(dp):
    """A drop far below the outlet pressure: the flow of the rigid tube at the outlet radius (the
    limit Δp → 0; the tube's radius varies by a relative Δp / (λ P'(λ)) along it)."""
    def check(sol):
        scene = sol.scene
        radius, length = scene.tube.radius * scene.outlet_stretch, scene.tube.length
        q_ref = sol.rheology.flow_rate(radius, dp / length)
        if q_ref < 1e-250 or not q_ref > 0:                  # below what the doubles resolve
            return None if sol.flow_rate <= max(q_ref, 1e-250) else f"q={sol.flow_rate!r}, reference {q_ref!r}"
        return None if abs(sol.flow_rate - q_ref) <= 1e-9 * q_ref else f"q={sol.flow_rate!r}, reference {q_ref!r}"

    return check


def _zero_load(sol):
    if sol.flow_rate != 0.0 or sol.pressure_drop != 0.0:
        return f"zero load gives q={sol.flow_rate!r}, dp={sol.pressure_drop!r}"
    return None


def _round_trip(load, value):
    def check(sol):
        if load == "flow_rate":
            if sol.pressure_drop <= 0 or sol.inlet_displacement < 0:
                return f"dp={sol.pressure_drop!r}, u={sol.inlet_displacement!r} at q={value:g}"
            if sol.pressure_drop < 1e-250:     # below what the inverse resolves
                return None
            back = solve(sol.rheology, sol.wall, sol.tube, pressure_drop=sol.pressure_drop).flow_rate
            q = value
        else:
            if sol.flow_rate < 0:
                return f"q={sol.flow_rate!r} at dp={value:g}"
            if not sol.flow_rate > 1e-250:     # below a yield stress, or below what G resolves
                return None
            back = solve(sol.rheology, sol.wall, sol.tube, flow_rate=sol.flow_rate).pressure_drop
            q = value
        if abs(back - q) <= 1e-6 * q:
            return None
        if load == "flow_rate":   # near a yield stress q(dp) is ill-conditioned: compare the drops
            again = solve(sol.rheology, sol.wall, sol.tube, flow_rate=max(back, 1e-300)).pressure_drop
            if abs(again - sol.pressure_drop) <= 1e-9 * sol.pressure_drop:
                return None
        return f"round trip {value:g} -> {back!r}"

    return check


def _max_flow_check(fluid, wall, tube):
    def check(q_max):
        if not q_max > 0:
            return f"max_flow_rate {q_max!r}"
        if math.isinf(q_max):
            return None
        below = solve(fluid, wall, tube, flow_rate=q_max * (1 - 1e-3))
        if not np.isfinite(below.pressure_drop):
            return "no finite solution just below max_flow_rate"
        try:
            solve(fluid, wall, tube, flow_rate=q_max * (1 + 1e-3))
        except NoSteadyStateError as exc:
            return None if abs(exc.limit - q_max) <= 1e-6 * q_max else f"limit {exc.limit!r} != {q_max!r}"
        return "a solution above max_flow_rate"

    return check


def _wall_probes(name):
    cls = registry.walls[name]
    wall = cls(**cls._examples[0]) if cls._examples else cls()
    entry = f"wall:{name}"
    methods = [("pressure", ("stretch", "reduced_thickness"), (1.1, 0.3)),
               ("stretch", ("pressure", "reduced_thickness"), (1.0, 0.3)),
               ("strain", ("pressure", "reduced_thickness"), (1.0, 0.3)),
               ("stiffness", ("stretch", "reduced_thickness"), (1.1, 0.3)),
               ("limit_pressure", ("reduced_thickness",), (0.3,)),
               ("max_stretch", ("reduced_thickness",), (0.3,)),
               ("small_strain_modulus", ("reduced_thickness",), (0.3,))]
    for method, names, good in methods:
        fn = getattr(wall, method)
        for i, pname in enumerate(names):
            bad = [math.nan, -math.inf, "x", True, 1j, None, [1.0, math.nan]]
            if pname == "reduced_thickness":      # (a negative pressure or a stretch below 1 may be
                bad += [0.0, math.inf, -1.0]      # admissible: walls that collapse)
            if pname == "stretch":
                bad += [0.0, math.inf]
            if pname == "pressure":
                bad += [math.inf]
            for value in bad:
                args = list(good)
                args[i] = value
                yield Probe(entry, f"{method}({pname}={_short(value)})", lambda a=tuple(args), f=fn: f(*a), bad=True,
                            parameter=pname)
    if wall.is_rigid:
        return
    tb_values = (1e-300, 1e-8, 0.3, 1e8, 1e300)
    for tb in tb_values:
        for lam in (1.0 + 1e-15, 1.0 + 1e-300, 1.5, 1e3, 1e300):
            yield Probe(entry, f"pressure({lam:g}, {tb:g})", lambda la=lam, t=tb: wall.pressure(la, t),
                        check=_tube_law_check(wall, lam, tb))
        for p in (1e-300, 1e-12, 1.0, 1e5, 1e300):
            yield Probe(entry, f"stretch({p:g}, {tb:g})", lambda pp=p, t=tb: wall.strain(pp, t),
                        check=_inverse_check(wall, p, tb))
        yield Probe(entry, f"limit_pressure({tb:g})", lambda t=tb: (wall.limit_pressure(t), wall.max_stretch(t)),
                    check=_limits_check(wall, tb), allow_inf=True)


def _tube_law_check(wall, lam, tb):
    def check(p):
        if p < 0:
            return f"negative pressure {p!r}"
        if lam < 1e3 and p > 0:
            back = wall.stretch(p, tb)
            if abs(back - lam) > 1e-6 * (lam - 1.0) + 1e-15 * lam:
                return f"stretch(pressure({lam:g})) = {back!r}"
        return None

    return check


def _inverse_check(wall, p, tb):
    def check(strain):
        if not strain > 0 and not (strain == 0 and p < 1e-300 * wall.small_strain_modulus(tb)):   # underflow
            return f"strain {strain!r} at p={p:g}"
        back = wall.pressure(1.0 + strain, tb) if strain > 1e-8 else None
        if back is not None and abs(back - p) > 1e-6 * p:
            return f"pressure(stretch({p:g})) = {back!r}"
        return None

    return check


def _limits_check(wall, tb):
    def check(result):
        p_lim, lam_max = result
        if not p_lim > 0 or not lam_max > 1:
            return f"limit_pressure {p_lim!r}, max_stretch {lam_max!r}"
        return None

    return check


def _rheology_probes(name):
    cls = registry.rheologies[name]
    fluid = cls(**cls._examples[0])
    entry = f"rheology:{name}"
    methods = [("stress", ("shear_rate",), (1.0,)), ("shear_rate", ("stress",), (1.0,)),
               ("apparent_viscosity", ("shear_rate",), (1.0,)),
               ("flow_rate", ("radius", "pressure_gradient"), (1e-4, 1e3)),
               ("pressure_gradient", ("flow_rate", "radius"), (1e-9, 1e-4)),
               ("velocity", ("r", "radius", "pressure_gradient"), (5e-5, 1e-4, 1e3))]
    for method, names, good in methods:
        fn = getattr(fluid, method)
        for i, pname in enumerate(names):
            bad = [math.nan, math.inf, -1.0, "x", True, 1j, None, [1.0, math.nan]]
            if pname == "radius":
                bad += [0.0]
            if pname == "r":
                bad += [2e-4]
            for value in bad:
                args = list(good)
                args[i] = value
                yield Probe(entry, f"{method}({pname}={_short(value)})", lambda a=tuple(args), f=fn: f(*a), bad=True,
                            parameter=pname)
    for q in (0.0, 1e-300, 1e-100, 1e-20, 1e-9, 1e3, 1e300):
        for radius in (1e-300, 1e-4, 1e300):
            yield Probe(entry, f"pressure_gradient({q:g}, {radius:g})",
                        lambda qq=q, r=radius: fluid.pressure_gradient(qq, r), check=_flow_check(fluid, q, radius))
    for q in (0.0, 1e-300, 1e-9):
        yield Probe(entry, f"velocity at q={q:g}",
                    lambda qq=q: fluid.velocity([0.0, 5e-5, 1e-4], 1e-4, fluid.pressure_gradient(qq, 1e-4)),
                    check=lambda v: None if v[0] >= v[1] >= v[2] == 0 else f"velocity {v!r}")


def _flow_check(fluid, q, radius):
    def check(g):
        underflow = q > 0 and math.log(q) - 4.0 * math.log(radius) < -700.0    # G below the doubles
        if g < 0 or ((q == 0) != (g == 0) and not (g == 0 and underflow)):
            return f"G={g!r} at q={q:g}"
        if g > 0 and q > 1e-250:
            back = fluid.flow_rate(radius, g)
            # near a yield stress q(G) is ill-conditioned: then compare the gradients
            if abs(back - q) > 1e-6 * q and abs(fluid.pressure_gradient(max(back, 1e-300), radius) - g) > 1e-9 * g:
                return f"flow_rate(pressure_gradient({q:g})) = {back!r}"
        return None

    return check


def _tube_probes():
    for field in attrs.fields(Tube):
        for value in _bad_for_field(field):
            yield Probe("Tube", f"{field.name}={_short(value)}", lambda kw={**_TUBE, field.name: value}: Tube(**kw),
                        bad=True, parameter=field.name)
    for kwargs in (dict(radius=5e-324, thickness=3e-5, length=1e-2), dict(radius=1e-300, thickness=1e4, length=1e-2),
                   dict(radius=1e300, thickness=1e-300, length=1e300)):
        yield Probe("Tube", f"{kwargs}", lambda kw=kwargs: Tube(**kw).reduced_thickness,
                    check=lambda tb: None if 0 < tb < math.inf else f"t/a = {tb!r}")


def _solution_probes(fluid, wall, tube, tag):
    def sol():
        return solve(fluid, wall, tube, flow_rate=1e-12)

    L = tube.length
    for method in ("pressure", "radius", "displacement", "pressure_gradient", "wall_shear_stress"):
        for value in (math.nan, -1.0, 2 * L, "x", True, 1j, None, [0.0, math.nan]):
            yield Probe(f"Solution.{method}", f"{tag} z={_short(value)}", lambda m=method, v=value: getattr(sol(), m)(v),
                        bad=True, parameter="z")
    for value in (math.nan, -1.0, 1.0, "x", 1j):
        yield Probe("Solution.velocity", f"{tag} r={_short(value)}", lambda v=value: sol().velocity(v, 0.0), bad=True,
                    parameter="r")
        yield Probe("Solution.velocity", f"{tag} z={_short(value)}", lambda v=value: sol().velocity(0.0, v), bad=True,
                    parameter="z")
    for value in (math.nan, math.inf, -1.0, 0.0, "x", 1j):
        yield Probe("Solution.diagnostics", f"{tag} density={_short(value)}",
                    lambda v=value: sol().diagnostics(density=v, warn=False), bad=True, parameter="density")
    yield Probe("Solution.profiles", tag, lambda: _profiles(sol()), check=_profile_check)


def _profiles(sol):
    z = np.linspace(0.0, sol.tube.length, 9)
    return (sol.pressure(z), sol.radius(z), sol.displacement(z), sol.pressure_gradient(z), sol.wall_shear_stress(z),
            sol.velocity(0.0, z), sol.inlet_pressure, sol.outlet_pressure)


def _profile_check(result, rtol=1e-9):
    p, radius, u, g, tau, v, p_in, p_out = result
    if np.any(np.diff(p) > 1e-12 * abs(p[0])) or np.any(np.diff(radius) > 1e-12 * radius[0]):
        return "pressure or radius grows along the tube"
    if abs(p[0] - p_in) > rtol * p_in or abs(p[-1] - p_out) > rtol * max(p_in, 1e-300):
        return f"p(0)={p[0]!r}, p(L)={p[-1]!r} against {p_in!r}, {p_out!r}"
    if np.any(u < 0) or np.any(g < 0) or np.any(tau < 0) or np.any(v < 0):
        return "negative displacement, gradient, stress or velocity"
    return None


def _advise_probes(fluid, wall, tube, tag):
    for load in ("flow_rate", "pressure_drop"):
        for value in (math.nan, -1.0, math.inf, "x", 1j):
            yield Probe("advise", f"{tag} {load}={_short(value)}",
                        lambda kw={load: value}: advise(fluid, wall, tube, **kw), bad=True, parameter=load)
        yield Probe("advise", f"{tag} {load}=0", lambda kw={load: 0.0}: advise(fluid, wall, tube, **kw))
    for value in (math.nan, -1.0, math.inf, True, "x"):
        yield Probe("advise", f"{tag} tolerance={_short(value)}",
                    lambda v=value: advise(fluid, wall, tube, flow_rate=1e-12, tolerance=v), bad=True,
                    parameter="tolerance")


