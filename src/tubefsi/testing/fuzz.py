r"""Fuzzing the public contract: every entry point, every registered model and coupler.

The contract (``docs/verification.md``, "Fuzzing"): a public call either raises one of
tubefsi's typed errors — :class:`~tubefsi.InvalidParameterError` for bad input, naming the
parameter; :class:`~tubefsi.NoSteadyStateError` beyond a limit, with a finite limit;
:class:`~tubefsi.ConvergenceError` for a numerical failure — or returns finite values that
pass a cheap independent check; and it does so within a few seconds. A *breach* is anything
else, counted in one of these categories:

==============  ================================================================
``nan``         a NaN or an infinity returned without an error
``wrong``       a finite value that fails its check, or a typed error with wrong words
                (a NaN limit, a misnamed parameter)
``accepted``    a bad input that did not raise :class:`~tubefsi.InvalidParameterError`
``untyped``     any exception that is not a :class:`~tubefsi.TubefsiError`
``hang``        a call over the time bound (``time_limit`` seconds)
==============  ================================================================

Probes come in two kinds, both built from the registries (so a plugin's models are fuzzed by
the same code as the built-ins):

* :func:`bad_input_probes` — deterministic: each parameter of each registered model and
  coupler and each argument of each public entry point (``solve``, ``max_flow_rate``,
  ``Tube``, the :class:`~tubefsi.Solution` accessors, the wall and rheology methods,
  ``advise``) given NaN, infinities, values outside the field's admissible range, strings,
  booleans, complex numbers, ``None`` and arrays with one bad entry; misspelt, unknown and
  missing keywords of every entry point (a :class:`~tubefsi.KeywordError` naming the keyword
  and suggesting the intended one) and of every model, coupler and ``Tube`` constructor
  (Python's own ``TypeError`` naming the keyword will do there); and extreme *valid* inputs (loads of
  ``1e-300`` and ``1e300``, tiny drops on a loaded outlet, stretches of ``1e300``), which must
  give a typed error or a finite value that passes its check.
* :func:`scene_outcomes` — random valid scenes drawn by hypothesis (a registered rheology,
  wall and coupler, their example parameters scaled, a tube, a load below the limits), each
  solved and checked: finite results, the flow-controlled and pressure-controlled solves
  invert each other, the pressure drop lies between the rigid-tube (Hagen–Poiseuille) drop at
  the undeformed and at the inlet radius, it grows with the flow rate, the inlet pressure is
  the tube law at the inlet stretch, and the pressure profile falls from inlet to outlet.

:func:`campaign` runs both and returns a :class:`Report` (counts per category and per entry
point, wall time); ``python -m tubefsi.testing.fuzz`` prints it and exits nonzero on any breach
(``make fuzz``). In a pytest suite, subclass :class:`FuzzContract` and give it the names of the
models to fuzz::

    from tubefsi.testing.fuzz import FuzzContract

    class TestFuzzMyWalls(FuzzContract):
        walls = ("thick-gent", "thin-gent")
        rheologies = ()
        couplers = ()
        scenes = 10

Each model named is paired with the core partners (thick neo-Hookean, thin linear and rigid walls;
power-law and Newtonian fluids) for the entry points that need a pair; the random scenes draw
every registered partner.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import dataclasses
import math
import types
import signal
import sys
import threading
import time
import warnings
from typing import Callable

import attrs
import numpy as np

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import seed as hypothesis_seed
from hypothesis import strategies as st

from .. import registry
from ..advise import advise
from ..errors import InvalidParameterError, KeywordError, NoSteadyStateError, TubefsiError
from ..fit import fit
from ..geometry import Tube
from ..network import Network
from ..solution import Solution
from ..solve import max_flow_rate, solve

__all__ = ["Probe", "Outcome", "Report", "BREACHES", "bad_input_probes", "run_probe", "scene_outcomes",
           "campaign", "FuzzContract", "main"]

#: The categories that are breaches of the contract.
BREACHES = ("nan", "wrong", "accepted", "untyped", "hang")

#: Seconds a single public call may take before it counts as a hang.
TIME_LIMIT = 5.0

_TUBE = types.MappingProxyType({"radius": 1e-4, "thickness": 3e-5, "length": 1e-2})

#: Bad values for any real parameter, whatever its range (NaN, infinities, non-numbers).
_ALWAYS_BAD = (math.nan, -math.inf, "1", "x", True, 1e-9 + 1e-12j, None, [1.0, math.nan], object())


class _Timeout(BaseException):
    """Raised in the calling thread when a probe exceeds its time bound (not an ``Exception``, so
    that no ``except Exception`` in the code under test swallows it)."""


@contextlib.contextmanager
def _time_bound(seconds):
    """Interrupt the block after ``seconds`` (SIGALRM; only in the main thread, elsewhere the
    elapsed time is checked afterwards)."""
    if seconds is None or threading.current_thread() is not threading.main_thread() or not hasattr(signal,
                                                                                                   "setitimer"):
        yield
        return

    def handler(signum, frame):
        raise _Timeout()

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@dataclasses.dataclass(frozen=True)
class Probe:
    """One public call and what the contract expects of it.

    ``bad``: the input is invalid, so the call must raise :class:`~tubefsi.InvalidParameterError`
    (naming ``parameter``, when given); otherwise it may raise any typed error or return values
    that are all finite and pass ``check`` (a function of the result returning ``None`` or the
    reason it fails).
    """

    entry: str
    label: str
    call: Callable
    bad: bool = False
    parameter: str | None = None
    check: Callable | None = None
    allow_inf: bool = False
    #: for a typed error: a function of it returning ``None`` or what is wrong with its words
    words: Callable | None = None
    #: Python's own ``TypeError`` naming ``parameter`` is an answer too (a wrong keyword to a
    #: model, coupler or ``Tube`` constructor, which Python rejects before any code of ours runs)
    type_error: bool = False


@dataclasses.dataclass(frozen=True)
class Outcome:
    """The result of one probe: ``category`` is ``"typed"``, ``"value"`` or one of :data:`BREACHES`."""

    entry: str
    label: str
    category: str
    detail: str = ""
    seconds: float = 0.0

    @property
    def breach(self) -> bool:
        return self.category in BREACHES


def _numbers(result):
    """The floats of a result: numbers, arrays, tuples of them, a Solution's scalar results."""
    if isinstance(result, Solution):
        result = (result.flow_rate, result.pressure_drop, result.inlet_pressure, result.inlet_displacement,
                  result.inlet_radius)
    if isinstance(result, (tuple, list)):
        out = [np.ravel(np.asarray(_numbers(r), dtype=float)) for r in result]
        return np.concatenate(out) if out else np.zeros(0)
    if isinstance(result, (bool, np.bool_)):
        return np.zeros(0)
    if isinstance(result, (int, float, np.ndarray, np.floating, np.integer)):
        a = np.asarray(result)
        if a.dtype.kind == "b":
            return np.zeros(0)
        return np.ravel(a.astype(float))
    return np.zeros(0)          # objects (Advice, Diagnostics, models) are checked by ``check``


def _typed_words(error):
    """None, or what is wrong with a typed error's words."""
    if isinstance(error, NoSteadyStateError) and not (math.isfinite(error.limit) and error.limit >= 0):
        return f"NoSteadyStateError with limit {error.limit}"
    return None


def run_probe(probe: Probe, time_limit: float | None = TIME_LIMIT) -> Outcome:
    """Run ``probe`` under the time bound and classify its outcome."""
    start = time.perf_counter()
    error = result = None
    try:
        with warnings.catch_warnings(), _time_bound(time_limit), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            result = probe.call()
    except _Timeout:
        return Outcome(probe.entry, probe.label, "hang", f"over {time_limit} s", time.perf_counter() - start)
    except Exception as exc:     # classified below
        error = exc
    seconds = time.perf_counter() - start

    def out(category, detail=""):
        return Outcome(probe.entry, probe.label, category, detail, seconds)

    if time_limit is not None and seconds > time_limit:
        return out("hang", f"{seconds:.1f} s")
    if error is not None:
        if probe.type_error and isinstance(error, TypeError) and not isinstance(error, TubefsiError):
            if probe.parameter and probe.parameter not in str(error):
                return out("wrong", f"TypeError does not name {probe.parameter!r}: {error}"[:200])
            return out("typed", "TypeError")
        if not isinstance(error, TubefsiError):
            where = error.__traceback__
            while where is not None and where.tb_next is not None:
                where = where.tb_next
            site = "" if where is None else f" at {where.tb_frame.f_code.co_filename.rsplit('/', 1)[-1]}:{where.tb_lineno}"
            return out("untyped", f"{type(error).__name__}: {error}"[:200] + site)
        words = _typed_words(error)
        if words:
            return out("wrong", words)
        if probe.bad and not isinstance(error, InvalidParameterError):
            return out("accepted", f"{type(error).__name__}: {error}"[:200])
        if probe.bad and probe.parameter and not _names(error.parameter, probe.parameter):
            return out("wrong", f"names {error.parameter!r}, not {probe.parameter!r}")
        why = probe.words(error) if probe.words is not None else None
        if why:
            return out("wrong", why)
        return out("typed", f"{type(error).__name__}")
    if probe.bad:
        return out("accepted", f"returned {_short(result)}")
    values = _numbers(result)
    if values.size and not np.all(np.isfinite(values) | (probe.allow_inf & (values == math.inf))):
        return out("nan", f"returned {_short(result)}")
    if probe.check is not None:
        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore")
                why = probe.check(result)
        except TubefsiError as exc:
            why = None if not _typed_words(exc) else _typed_words(exc)
        except Exception as exc:
            return out("untyped", f"in check: {type(exc).__name__}: {exc}"[:200])
        if why:
            return out("wrong", why)
    return out("value")


def _names(given, expected) -> bool:
    given, expected = str(given), str(expected)
    return expected in given or given in expected


def _short(value) -> str:
    text = repr(value)
    return text if len(text) < 120 else text[:117] + "..."


# ----------------------------------------------------------------------------- bad inputs
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


def _known_probes():
    """Reproducers of breaches once found (the issue tracker's fuzz campaign), each with its check;
    those whose models are not registered are left out."""
    R, W = registry.rheologies, registry.walls
    tube = Tube(**_TUBE)
    out = []

    def have(*names):
        return all(n in R or n in W for n in names)

    def drop_near(reference, rtol):
        def check(sol):
            dp = sol.pressure_drop
            return None if abs(dp - reference) <= rtol * reference else f"dp={dp!r}, reference {reference!r}"
        return check

    if have("power-law", "thick-neo-hookean", "rigid", "thin-linear"):
        nh = W["thick-neo-hookean"](shear_modulus=2e3)
        # 40-digit references (mpmath: the Lame tube law and the separated integral, tests/test_large_index.py)
        for n, reference in ((26.0, 1.3803462372831439), (30.0, 1.1497201863833393)):
            fluid = R["power-law"](consistency=0.017, index=n)
            out.append(Probe("solve", f"known: power law n={n:g}, thick NH, q=1e-12",
                             lambda f=fluid: solve(f, nh, tube, flow_rate=1e-12), check=drop_near(reference, 1e-12)))
            out.append(Probe("solve", f"known: power law n={n:g}, thick NH, dp={reference}",
                             lambda f=fluid, d=reference: solve(f, nh, tube, pressure_drop=d),
                             check=lambda sol: None if abs(sol.flow_rate - 1e-12) <= 1e-11 * 1e-12
                             else f"q={sol.flow_rate!r}, reference 1e-12"))
            for w in ("rigid", "thin-linear"):
                wall = W[w](**W[w]._examples[0])
                out.append(Probe("solve", f"known: power law n={n:g}, {w}, q=1e-12",
                                 lambda f=fluid, wl=wall: solve(f, wl, tube, flow_rate=1e-12),
                                 check=_round_trip("flow_rate", 1e-12)))
        fluid = R["power-law"](consistency=0.017, index=0.7)
        out.append(Probe("solve", "known: solve(0.999999 max_flow_rate)",
                         lambda f=fluid, w=nh: solve(f, w, tube, flow_rate=0.999999 * max_flow_rate(f, w, tube))))
        p_half = 0.5 * nh.limit_pressure(0.3)
        for ratio in (1e6, 1e9, 1e12):     # q against the rigid tube at the outlet radius
            dp = p_half / ratio
            radius = tube.radius * nh.stretch(p_half, 0.3)
            q_ref = fluid.flow_rate(radius, dp / tube.length)
            out.append(Probe("solve", f"known: outlet pressure p_lim/2, p_out/dp={ratio:g}",
                             lambda d=dp, f=fluid, w=nh: solve(f, w, tube, pressure_drop=d, outlet_pressure=p_half),
                             check=lambda sol, r=q_ref, k=ratio: None if abs(sol.flow_rate - r) <= 1e-9 * r + 4 / k * r
                             else f"q={sol.flow_rate!r}, rigid-outlet reference {r!r}"))
        out.append(Probe("advise", "known: advise(flow_rate=0)",
                         lambda f=fluid, w=nh: advise(f, w, tube, flow_rate=0.0)))
        out.append(Probe("Tube", "known: t/a = 1e304", lambda f=fluid, w=nh: solve(
            f, w, Tube(radius=1e-300, thickness=1e4, length=1e-2), flow_rate=1e-9)))
        for name in ("thick-mooney-rivlin", "thick-neo-hookean", "thin-neo-hookean"):
            wall = W[name](**W[name]._examples[0])
            out.append(Probe(f"wall:{name}", "known: pressure(1e300, 0.3)", lambda w=wall: w.pressure(1e300, 0.3),
                             check=lambda p, w=wall: None if 0 < p <= w.limit_pressure(0.3) else f"p={p!r}"))
        thin = W["thin-neo-hookean"](shear_modulus=2e3)
        out.append(Probe("wall:thin-neo-hookean", "known: stretch(1e300 Pa)", lambda w=thin: w.stretch(1e300, 0.3),
                         check=lambda lam: None if abs(lam - 1e300 / 600.0) <= 1e-12 * lam else f"stretch {lam!r}"))
    if have("bingham", "thick-neo-hookean"):
        fluid = R["bingham"](yield_stress=0.5, plastic_viscosity=0.05)
        for w in ("thick-neo-hookean", "rigid"):
            wall = W[w](**W[w]._examples[0])

            def rest_profile(w=wall, f=fluid):
                sol = solve(f, w, tube, pressure_drop=50.0)
                return sol.pressure([0.0, 1e-12, 0.5 * tube.length]), sol.inlet_pressure

            out.append(Probe("Solution.pressure", f"known: Bingham below yield, {w}", rest_profile,
                             check=lambda r: None if r[0][0] == r[1] and r[0][0] >= r[0][1] > r[0][2] > 0
                             else f"pressure {r[0]!r}, inlet {r[1]!r}"))
    if have("thin-ogden", "thin-neo-hookean", "newtonian"):
        fluid = R["newtonian"](viscosity=1e-3)
        twin = W["thin-ogden"](moduli=(2e3,), exponents=(2.0,))
        nh = W["thin-neo-hookean"](shear_modulus=2e3)
        out.append(Probe("solve", "known: thin Ogden alpha=2 = thin neo-Hookean at dp=1e-8",
                         lambda f=fluid, a=twin, b=nh: (solve(f, a, tube, pressure_drop=1e-8).flow_rate,
                                                        solve(f, b, tube, pressure_drop=1e-8).flow_rate),
                         check=lambda q: None if abs(q[0] - q[1]) <= 1e-12 * q[1] else f"q={q[0]!r} vs {q[1]!r}"))
        tiny = W["thin-ogden"](moduli=(2e3,), exponents=(1e-16,))
        out.append(Probe("wall:thin-ogden", "known: exponent 1e-16 limits",
                         lambda w=tiny: (w.limit_pressure(0.3), w.max_stretch(0.3)), allow_inf=True,
                         check=lambda r: None if r[0] > 0 and (math.isfinite(r[1]) or math.isinf(r[0]))
                         else f"limit_pressure {r[0]!r} with max_stretch {r[1]!r}"))
    if have("thick-gent", "power-law"):
        fluid = R["power-law"](consistency=0.017, index=0.7)
        gent = W["thick-gent"](shear_modulus=2e3, locking_parameter=10.0)
        out.append(Probe("solve", "known: thick Gent Jm=10 at dp=1e5",
                         lambda f=fluid, w=gent: solve(f, w, tube, pressure_drop=1e5)))
    for name in ("carreau", "cross", "ellis", "carreau-yasuda"):
        if have(name, "thick-neo-hookean"):
            fluid = R[name](**R[name]._examples[0])
            nh = W["thick-neo-hookean"](shear_modulus=2e3)
            out.append(Probe("solve", f"known: {name} dp=1e-11 (inlet strain < 2e-14)",
                             lambda f=fluid, w=nh: solve(f, w, tube, pressure_drop=1e-11),
                             check=lambda sol, f=fluid: None if abs(sol.flow_rate / f.flow_rate(
                                 tube.radius, 1e-11 / tube.length) - 1) < 1e-10 else f"q={sol.flow_rate!r}"))
    if have("carreau-yasuda", "thick-linear"):     # the networks' dead end: NaN once, then ConvergenceError
        fluid = R["carreau-yasuda"](**R["carreau-yasuda"]._examples[0])
        lin = W["thick-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
        for dp in (1e-14, 1e-100):
            out.append(Probe("solve", f"known: carreau-yasuda thick-linear dp={dp:g}, p_out=87.6",
                             lambda f=fluid, w=lin, d=dp: solve(f, w, tube, pressure_drop=d, outlet_pressure=87.6),
                             check=_small_drop(dp)))
    if have("carreau", "thick-gent"):
        fluid = R["carreau"](**R["carreau"]._examples[0])
        out.append(Probe("solve", "known: carreau thick-gent q=1e-300", lambda f=fluid: solve(
            f, W["thick-gent"](**W["thick-gent"]._examples[0]), tube, flow_rate=1e-300)))
    if have("carreau-yasuda", "thick-fung"):
        fluid = R["carreau-yasuda"](**R["carreau-yasuda"]._examples[0])
        fung = W["thick-fung"](shear_modulus=1082.1, stiffening=3.1333)
        long = Tube(radius=3.2235e-3, thickness=3.54e-4, length=1.4378)
        out.append(Probe("solve", "known: carreau-yasuda thick Fung q=1.734e-11",
                         lambda f=fluid, w=fung, t=long: solve(f, w, t, flow_rate=1.734e-11)))
    return out


def bad_input_probes(rheologies=None, walls=None, couplers=None, *, core=True):
    """The deterministic probes of the registered models named (default: every registered one).

    ``core``: include the probes of the entry points that do not depend on a model (``Tube``)
    and of the pairs of each named model with a core partner.
    """
    rheologies = list(registry.rheologies) if rheologies is None else list(rheologies)
    walls = list(registry.walls) if walls is None else list(walls)
    couplers = list(registry.couplers) if couplers is None else list(couplers)
    tube = Tube(**_TUBE)
    probes = []
    for name in rheologies:
        probes += _model_probes("rheologies", name)
        probes += _rheology_probes(name)
    for name in walls:
        probes += _model_probes("walls", name)
        probes += _wall_probes(name)
    for name in couplers:
        probes += _model_probes("couplers", name)
    if core:
        probes += _tube_probes()
        probes += _entry_keyword_probes()
        probes += _known_probes()
    # every named model in pairs: each rheology with a few walls, each wall with a few fluids
    partners_w = [w for w in ("thick-neo-hookean", "thin-linear", "rigid") if w in registry.walls]
    partners_r = [r for r in ("power-law", "newtonian") if r in registry.rheologies]
    pairs = [(r, w) for r in rheologies for w in partners_w] + [(r, w) for w in walls for r in partners_r]
    for rname, wname in dict.fromkeys(pairs):
        rc, wc = registry.rheologies[rname], registry.walls[wname]
        for i, (rk, wk) in enumerate(zip(rc._examples, wc._examples or ({},))):
            fluid, wall = rc(**rk), wc(**wk)
            tag = f"{rname}#{i} {wname}#{i}"
            probes += _solve_probes(fluid, wall, tube, tag)
            if i == 0:
                probes += _solution_probes(fluid, wall, tube, tag)
                probes += _advise_probes(fluid, wall, tube, tag)
    return probes


# ----------------------------------------------------------------------------- random scenes
def _scene_check(fluid, wall, tube, coupler, load, value, outlet):
    """Solve one scene and check it (returns the reason it fails, or None)."""
    accurate = coupler == "auto" or registry.couplers[coupler].meets_accuracy_contract
    rtol = 1e-7 if accurate else 1e-3

    def run(**kw):
        return solve(fluid, wall, tube, coupler=coupler, outlet_pressure=outlet, **kw)

    sol = run(**{load: value})
    q, dp = sol.flow_rate, sol.pressure_drop
    vals = np.array([q, dp, sol.inlet_pressure, sol.inlet_displacement])
    if not np.all(np.isfinite(vals)):
        return f"non-finite result {vals!r}"
    if q < 0 or dp < 0 or sol.inlet_displacement < 0:
        return f"negative result q={q!r}, dp={dp!r}, u={sol.inlet_displacement!r}"
    if q == 0 or dp == 0:
        return None
    other = "pressure_drop" if load == "flow_rate" else "flow_rate"
    back = run(**{other: dp if other == "pressure_drop" else q})
    got, want = (back.pressure_drop, dp) if other == "pressure_drop" else (back.flow_rate, q)
    # the round trip's condition: d ln q / d ln dp is at most ~1/n (the flow index); allow it
    if abs(got - want) > rtol * 10 * want:
        return f"round trip {load}: {want!r} -> {got!r}"
    if np.any(np.asarray(getattr(wall, "axial_stretch", 1.0)) != 1.0):
        return None     # a prestretched tube: installed length and unloaded radius differ from the Tube's
    a, L = tube.radius, tube.length
    g_rigid = fluid.pressure_gradient(q, a)
    g_inlet = fluid.pressure_gradient(q, a + sol.inlet_displacement)
    if fluid.yield_stress == 0 and not (L * g_inlet * (1 - rtol) <= dp <= L * g_rigid * (1 + rtol)):
        return f"dp={dp!r} outside the rigid-tube bounds [{L * g_inlet!r}, {L * g_rigid!r}]"
    tb = tube.thickness / a
    if not wall.is_rigid:
        e_in, e_sol = wall.strain(sol.inlet_pressure, tb), sol.inlet_displacement / a   # (no 1 + strain)
        if abs(e_in - e_sol) > 1e-6 * abs(e_in):
            return f"tube law at the inlet pressure: strain {e_in!r} != inlet strain {e_sol!r}"
    try:
        more = run(pressure_drop=dp * 1.01).flow_rate
    except NoSteadyStateError:
        more = math.inf
    if not more > q:
        return f"flow rate does not grow with the pressure drop: {q!r} -> {more!r}"
    return _profile_check(_profiles(sol), max(1e-9, 10 * rtol))   # the ODE's profile is the engine's


def _draw_model(draw, kind, name):
    cls = getattr(registry, kind)[name]
    if not cls._examples:
        return cls()
    example = dict(draw(st.sampled_from(cls._examples)))
    kwargs = dict(example)
    for key, value in list(kwargs.items()):
        field = attrs.fields_dict(cls).get(key)
        if type(value) is float and field is not None and field.metadata.get("admissible") == "(0, inf)":
            kwargs[key] = value * math.exp(draw(st.floats(-1.0, 1.0)))
    try:
        return cls(**kwargs)
    except InvalidParameterError:      # the scaled set leaves a joint constraint (Cross): the example
        return cls(**example)


def scene_outcomes(n, rheologies=None, walls=None, couplers=None, *, time_limit=TIME_LIMIT, seed=0):
    """Outcomes of ``n`` random valid scenes drawn by hypothesis from the registered models named."""

    rheologies = sorted(registry.rheologies) if rheologies is None else list(rheologies)
    walls = sorted(registry.walls) if walls is None else list(walls)
    couplers = sorted(registry.couplers) if couplers is None else list(couplers)
    outcomes = []

    @hypothesis_seed(seed)
    @settings(max_examples=n, deadline=None, database=None, suppress_health_check=list(HealthCheck),
              phases=[Phase.generate])
    @given(data=st.data())
    def one(data):
        draw = data.draw
        rname, wname = draw(st.sampled_from(rheologies)), draw(st.sampled_from(walls))
        fluid, wall = _draw_model(draw, "rheologies", rname), _draw_model(draw, "walls", wname)
        radius = math.exp(draw(st.floats(math.log(1e-5), math.log(1e-2))))
        tb = math.exp(draw(st.floats(math.log(0.02), math.log(2.0))))
        slender = math.exp(draw(st.floats(math.log(10.0), math.log(1e4))))
        tube = Tube(radius=radius, thickness=tb * radius, length=slender * radius)
        usable = ["auto"] + [c for c in couplers if registry.couplers[c]().supports(fluid, wall)]
        coupler = draw(st.sampled_from(usable))
        fraction = math.exp(draw(st.floats(math.log(1e-6), math.log(0.9))))
        load = draw(st.sampled_from(("flow_rate", "pressure_drop")))
        outlet = 0.0
        label = f"{rname}={fluid!r} {wname}={wall!r} {tube!r} {coupler} {load} fraction={fraction:.3g}"

        def call():
            nonlocal outlet
            p_lim = wall.limit_pressure(tb)
            scale = min(0.5 * p_lim, wall.small_strain_modulus(tb) * tb) if not wall.is_rigid else 1e3
            if draw(st.booleans()) and not wall.is_rigid:
                outlet = scale * draw(st.floats(0.0, 0.5))
            if load == "pressure_drop":
                value = fraction * (min(p_lim - outlet, scale) if math.isfinite(p_lim) else scale)
            else:
                q_max = max_flow_rate(fluid, wall, tube, outlet_pressure=outlet)
                q_ref = fluid.flow_rate(radius, scale / tube.length)
                value = fraction * min(q_max, q_ref) if math.isfinite(q_max) else fraction * q_ref
            return _scene_check(fluid, wall, tube, coupler, load, value, outlet)

        # a scene is about ten public calls; the ODE coupler (a reference, one integration per point
        # and per shooting step) gets three times as long
        bound = time_limit * (18 if coupler == "ode" else 6)
        outcomes.append(run_probe(Probe(f"scene:{coupler}", label, call, check=lambda why: why), bound))

    one()
    return outcomes


# ----------------------------------------------------------------------------- campaign
@dataclasses.dataclass
class Report:
    """Counts of a campaign: per category, per entry point and category; the breaches; wall time."""

    outcomes: list
    seconds: float

    @property
    def breaches(self):
        return [o for o in self.outcomes if o.breach]

    def counts(self):
        return collections.Counter(o.category for o in self.outcomes)

    def by_entry(self):
        table = collections.defaultdict(collections.Counter)
        for o in self.outcomes:
            table[o.entry.split(":")[0] if o.entry.startswith(("wall:", "rheology:", "coupler:")) else o.entry][
                o.category] += 1
        return table

    def __str__(self) -> str:
        cats = ("typed", "value") + BREACHES
        lines = [f"{'entry point':28s}" + "".join(f"{c:>10s}" for c in cats)]
        for entry, counter in sorted(self.by_entry().items()):
            lines.append(f"{entry:28s}" + "".join(f"{counter[c]:10d}" for c in cats))
        total = self.counts()
        lines.append(f"{'total':28s}" + "".join(f"{total[c]:10d}" for c in cats))
        bad = [o for o in self.outcomes if not o.entry.startswith("scene:")]
        lines.append(f"{len(bad)} probes, {len(self.outcomes) - len(bad)} random scenes, "
                     f"{len(self.breaches)} breaches, {self.seconds:.1f} s")
        for o in self.breaches[:200]:
            lines.append(f"BREACH {o.category}: {o.entry} [{o.label}] {o.detail}")
        return "\n".join(lines)


def campaign(scenes=250, *, rheologies=None, walls=None, couplers=None, time_limit=TIME_LIMIT, progress=None):
    """Run every bad-input probe and ``scenes`` random valid scenes; returns a :class:`Report`."""
    start = time.perf_counter()
    outcomes = []
    for probe in bad_input_probes(rheologies, walls, couplers):
        outcomes.append(run_probe(probe, time_limit))
        if progress and outcomes[-1].breach:
            progress(outcomes[-1])
    if scenes:
        outcomes += scene_outcomes(scenes, rheologies, walls, couplers, time_limit=time_limit)
    return Report(outcomes, time.perf_counter() - start)


class FuzzContract:
    """The fuzz campaign as a pytest suite: set ``rheologies``, ``walls`` and ``couplers`` to the
    registered names to fuzz (``None``: every registered one), ``scenes`` to the number of
    random valid scenes. Each test fails listing its breaches."""

    rheologies: tuple | None = None
    walls: tuple | None = None
    couplers: tuple | None = None
    #: also the probes that belong to no model (``Tube``, the known reproducers)
    core: bool = False
    scenes: int = 20
    time_limit: float = TIME_LIMIT

    def test_bad_inputs_give_typed_errors(self):
        probes = bad_input_probes(self.rheologies, self.walls, self.couplers, core=self.core)
        breaches = [o for o in (run_probe(p, self.time_limit) for p in probes) if o.breach]
        assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)

    def test_random_scenes_pass_their_checks(self):
        if not self.scenes:
            return
        rheologies = self.rheologies if self.rheologies else None
        walls = self.walls if self.walls else None
        outcomes = scene_outcomes(self.scenes, rheologies, walls, self.couplers, time_limit=self.time_limit)
        breaches = [o for o in outcomes if o.breach]
        assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)


def main(argv=None) -> int:
    """``python -m tubefsi.testing.fuzz [--scenes N] [--time-limit S]``: print the report; exit 1 on a breach."""
    parser = argparse.ArgumentParser(prog="python -m tubefsi.testing.fuzz", description=main.__doc__)
    parser.add_argument("--scenes", type=int, default=250, help="random valid scenes (default 250)")
    parser.add_argument("--time-limit", type=float, default=TIME_LIMIT, help="seconds per call")
    args = parser.parse_args(argv)
    report = campaign(args.scenes, time_limit=args.time_limit)
    print(report)
    return 1 if report.breaches else 0


if __name__ == "__main__":
    sys.exit(main())
