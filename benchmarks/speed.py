r"""Speed of tubefsi against the chapter's method, on every call shape, in one process.

Run ``python benchmarks/speed.py`` (about a minute on two cores), ``--quick`` for a smoke test at
small sizes (seconds; its numbers mean nothing), ``--json FILE`` to also write the table as data.

The baseline
------------
The chapter's method, written as a careful user would write it
(``tubefsi.testing.reference.chapter_baseline``, shared with ``examples/work_precision.py``): for
each point, ``scipy.integrate.odeint`` at its default tolerances integrates the deflection ODE
``d lam/dz = -G(q, a lam)/P'(lam)`` of a power-law fluid from the outlet to the inlet, with a
scalar right-hand side on plain floats (``lam = y.item()``, ``math`` only, constants hoisted),
then evaluates the tube law in closed form at the inlet. Nothing of tubefsi runs inside it.

The call shapes
---------------
Scene unless stated: tube a = 100 um, t = 30 um, L = 1 cm; power law m = 0.017 Pa s^n, n = 0.7;
thick neo-Hookean wall, mu = 2 kPa.

1. ``thick curve``: one ``tubefsi.solve`` on a 10^4-point flow curve (q up to 0.9 of the maximum
   flow rate) against 10^4 baseline ODEs (timed on an evenly spaced subsample, per point);
2. ``thin curve``: the same flow rates in a thin reference-thickness neo-Hookean wall (tubefsi's
   closed-form coupler);
3. ``monte carlo``: one scalar solve with a fresh wall each call
   (``walls["thick-neo-hookean"](shear_modulus=mu_i)``, then ``solve(...).pressure_drop``)
   against one baseline ODE, per call;
4. ``numpy loop``: the loop everyone writes, ``for q in np.linspace(...): solve(..., flow_rate=q)``
   (NumPy scalars) through one scene, against one baseline ODE per flow rate;
5. ``random scenes``: 10^4 scenes with every parameter random (mu, m, n, a, t, L, q), one
   broadcast ``solve`` (model parameters and ``Tube`` fields as arrays) against the baseline per
   scene. If the broadcast call raises, a Python loop of scalar solves (models built in the
   loop) is timed instead and the row says "loop";
6. ``infeasible scenes``: the same, with 10 % of the scenes given 1.1-2 times their maximum flow
   rate and ``on_infeasible="nan"`` (the baseline per feasible scene: it has no answer for the
   others);
7. ``carreau curve``: a 10^4-point Carreau-Yasuda curve (blood, Cho & Kensey constants) in the
   thick wall against the power-law baseline at the same flow rates, per point;
8. ``carreau scalar``: one scalar Carreau-Yasuda solve with fresh fluid parameters each call
   (absolute time, the median of 100 calls as a Monte Carlo makes them; a fresh fluid is served
   by its flow map, no table). The first few calls after start-up are slower, while the
   interpreter specializes the code: the note gives the median of the first seven;
8b. ``carreau scenes``: 10^3 random Carreau-Yasuda scenes (every fluid, wall and tube parameter and
   q random), one broadcast call, against the baseline per scene (the power law of each fluid's
   high-shear asymptote, same q, tube and wall);
9. ``fit``: ``tubefsi.fit`` of 3 parameters (wall.shear_modulus, rheology.consistency,
   rheology.index) to 20 synthetic points with 1 % noise (absolute time);
10. ``import``: ``import tubefsi`` wall time over ``import numpy`` wall time, each in a fresh
   subprocess.

How it is timed
---------------
tubefsi and the baseline run in this one process, in alternating passes (A B, B A, ...); each
row reports the median of the passes and the range of the per-pass ratios. A pass of a flow
curve is one tubefsi call on the whole curve, or the baseline on the whole subsample. Before the
passes, one untimed call on the same scene warms process-level and per-scene caches (the time
of that first call is in the note). Where a cache keyed by parameter values could be hit across
passes (Monte Carlo, random scenes, Carreau scalar, fit), every pass draws new parameters. Each
row draws from its own generator, seeded by its name: its scenes are the same whichever rows run
before it (``--only``) and however many calls they make.

Accuracy: the larger relative difference of pressure drop and inlet displacement from tubefsi's
default answer (``solve`` with ``coupler="auto"``), maximised over the points compared; "ref"
where the timed tubefsi call *is* the default answer. The baseline's ~1e-6 is odeint's defaults.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import zlib
import time

try:
    import resource                     # (POSIX only: the page-fault count in the random-scenes row's note)
except ImportError:                     # pragma: no cover
    resource = None

import attrs
import numpy as np
import scipy

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference.chapter_baseline import chapter_thick, chapter_thin

A, T, LEN = 1e-4, 3e-5, 1e-2          # m
M, N, MU = 0.017, 0.7, 2e3            # Pa s^n, -, Pa
TUBE = tubefsi.Tube(radius=A, thickness=T, length=LEN)
Q_MC = 1e-9                            # m^3/s, the Monte Carlo flow rate (inlet strain ~0.4)
Q_CARREAU = 1.2e-9                     # m^3/s, top of the Carreau curve (inlet strain ~0.74)


@attrs.frozen
class Sizes:
    """How much is measured: the published table by default, :data:`QUICK` for a smoke test."""

    points: int = 10_000       # flow-curve points and random scenes per tubefsi call
    sample: int = 200          # baseline ODEs per pass (and scalar solves per pass of a loop)
    repeats: int = 7           # interleaved passes per row; medians reported
    calls: int = 200           # scalar solves per Monte Carlo pass
    carreau_calls: int = 100   # fresh-fluid Carreau solves (one each; the first ones after start-up are slower)
    fits: int = 5              # fits, each on fresh noise
    imports: int = 7           # fresh subprocesses per module


QUICK = Sizes(points=200, sample=8, repeats=3, calls=10, carreau_calls=4, fits=2, imports=5)


@attrs.define
class Row:
    """One call shape: its measured value against its target."""

    key: str
    shape: str
    kind: str                  # "ratio": baseline / tubefsi, at least the target; "absolute": seconds, or
                               # "ratio-max": tubefsi / numpy, at most the target
    unit: str                  # what a time is per: "point", "call", "scene", "fit", "import"
    target: float
    tubefsi_s: float = math.nan
    baseline_s: float = math.nan
    value: float = math.nan    # the ratio, or the absolute time (s)
    low: float = math.nan      # range of the per-pass values
    high: float = math.nan
    err_baseline: float | str = "-"
    err_tubefsi: float | str = "-"
    note: str = ""

    @property
    def met(self) -> bool:
        if not math.isfinite(self.value):
            return False
        return self.value >= self.target if self.kind == "ratio" else self.value <= self.target


# ============================================================================ helpers
def power_law(m=M, n=N):
    return rheologies["power-law"](consistency=m, index=n)


def thick(mu=MU):
    return walls["thick-neo-hookean"](shear_modulus=mu)


def interleaved(passes, repeats):
    """Seconds per unit of each pass, ``repeats`` times, alternating the order of the passes.

    ``passes`` maps a name to ``(function, units)``; the function receives the pass number.
    """
    names = list(passes)
    times = {name: [] for name in names}
    for r in range(repeats):
        for name in names if r % 2 == 0 else names[::-1]:
            fn, units = passes[name]
            t0 = time.perf_counter()
            fn(r)
            times[name].append((time.perf_counter() - t0) / units)
    return times


def fill_ratio(row, ours, theirs):
    """Medians, the ratio of the medians and the range of the per-pass ratios."""
    row.tubefsi_s, row.baseline_s = statistics.median(ours), statistics.median(theirs)
    row.value = row.baseline_s / row.tubefsi_s
    per_pass = [b / t for b, t in zip(theirs, ours)]
    row.low, row.high = min(per_pass), max(per_pass)


def fill_absolute(row, times):
    row.tubefsi_s = row.value = statistics.median(times)
    row.low, row.high = min(times), max(times)


def rel_diff(dp, u, dp_ref, u_ref):
    """Larger relative difference of (pressure drop, inlet displacement), maximised over points."""
    dp, u, dp_ref, u_ref = (np.asarray(v, dtype=float) for v in (dp, u, dp_ref, u_ref))
    return float(max(np.max(np.abs(dp / dp_ref - 1)), np.max(np.abs(u / u_ref - 1))))


def subsample(size, count):
    """``count`` evenly spaced indices of ``range(size)``, both ends included."""
    return np.unique(np.linspace(0, size - 1, min(count, size)).round().astype(int))


def seconds(s):
    if not math.isfinite(s):
        return "-"
    for scale, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "us")):
        if s >= scale:
            return f"{s / scale:.3g} {unit}"
    return f"{s * 1e9:.3g} ns"


# ============================================================================ call shapes
def flow_curve(row, fluid, wall, q, baseline, sizes, baseline_fluid=None):
    """One tubefsi call on the curve ``q`` against ``baseline`` on a subsample, per point."""
    t0 = time.perf_counter()
    sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)          # the first call: warms the caches
    first = time.perf_counter() - t0
    idx = subsample(q.size, sizes.sample)
    qs = q[idx]
    got = {}

    def ours(_):
        got["sol"] = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)

    def theirs(_):
        got["ref"] = [baseline(qi, N, M, MU, TUBE) for qi in qs]

    times = interleaved({"tubefsi": (ours, q.size), "baseline": (theirs, qs.size)}, sizes.repeats)
    fill_ratio(row, times["tubefsi"], times["baseline"])
    default = sol if baseline_fluid is None else tubefsi.solve(baseline_fluid, wall, TUBE, flow_rate=qs)
    dp_ref, u_ref = ((default.pressure_drop, default.inlet_displacement) if baseline_fluid is not None
                     else (sol.pressure_drop[idx], sol.inlet_displacement[idx]))
    dp, u = zip(*got["ref"])
    row.err_baseline = rel_diff(dp, u, dp_ref, u_ref)
    row.err_tubefsi = "ref"
    strain = sol.inlet_displacement[-1] / A
    row.note = (f"{sol.coupler_name}; inlet strain up to {strain:.3g}; first call {seconds(first)}; "
                f"baseline on {qs.size} of {q.size} points")


def monte_carlo(row, sizes, rng):
    """A scalar solve with a fresh wall each call against one baseline call, per call."""
    fluid = power_law()
    mus = rng.uniform(1e3, 4e3, (sizes.repeats + 1, sizes.calls))      # a new set each pass
    got = {}

    def ours(r):
        got["tubefsi"] = [tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=float(mu)), TUBE,
                                        flow_rate=Q_MC).pressure_drop for mu in mus[r]]

    def theirs(r):
        got["baseline"] = [chapter_thick(Q_MC, N, M, float(mu), TUBE) for mu in mus[r]]

    ours(sizes.repeats)                                                 # warm-up on the spare set
    times = interleaved({"tubefsi": (ours, sizes.calls), "baseline": (theirs, sizes.calls)}, sizes.repeats)
    fill_ratio(row, times["tubefsi"], times["baseline"])
    last = mus[sizes.repeats - 1]
    sols = [tubefsi.solve(fluid, thick(float(mu)), TUBE, flow_rate=Q_MC) for mu in last]
    dp, u = zip(*got["baseline"])
    row.err_baseline = rel_diff(dp, u, [s.pressure_drop for s in sols], [s.inlet_displacement for s in sols])
    row.err_tubefsi = "ref"
    row.note = f"q = {Q_MC:g} m^3/s, mu ~ U(1, 4) kPa; {sizes.calls} calls per pass"


def numpy_loop(row, sizes, rng):
    """``for q in np.linspace(...)``: a scalar solve per NumPy scalar, against one baseline call each."""
    fluid, wall = power_law(), thick()
    qs = [np.linspace(0.1, 1.0, sizes.calls) * Q_MC * rng.uniform(0.9, 1.1) for _ in range(sizes.repeats + 1)]
    got = {}

    def ours(r):
        got["tubefsi"] = [tubefsi.solve(fluid, wall, TUBE, flow_rate=q).pressure_drop for q in qs[r]]

    def theirs(r):
        got["baseline"] = [chapter_thick(float(q), N, M, MU, TUBE) for q in qs[r]]

    ours(sizes.repeats)                                                 # warm-up on the spare set
    times = interleaved({"tubefsi": (ours, sizes.calls), "baseline": (theirs, sizes.calls)}, sizes.repeats)
    fill_ratio(row, times["tubefsi"], times["baseline"])
    last = qs[sizes.repeats - 1]
    sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=last)
    dp, u = zip(*got["baseline"])
    row.err_baseline = rel_diff(dp, u, sol.pressure_drop, sol.inlet_displacement)
    row.err_tubefsi = rel_diff(got["tubefsi"], sol.inlet_displacement, sol.pressure_drop, sol.inlet_displacement)
    row.note = (f"q = 0.1-1 x {Q_MC:g} m^3/s as np.float64, one scene; {sizes.calls} calls per pass; "
                "err tfsi: the loop against one broadcast call")


def random_scenes(count, rng):
    """``count`` scenes with every parameter random; q loads the rigid tube to 5-90 % of the limit pressure.

    A compliant tube needs less than the rigid tube's pressure drop at a given q, and a wall's
    maximum flow rate is reached only above its limit pressure, so every scene has a steady state.
    """
    mu = np.exp(rng.uniform(math.log(1e3), math.log(1e4), count))     # Pa
    m = np.exp(rng.uniform(math.log(5e-3), math.log(5e-2), count))    # Pa s^n
    n = rng.uniform(0.5, 1.0, count)
    a = np.exp(rng.uniform(math.log(5e-5), math.log(2e-4), count))    # m
    t = a * rng.uniform(0.1, 0.5, count)
    length = rng.uniform(5e-3, 2e-2, count)
    load = np.exp(rng.uniform(math.log(0.05), math.log(0.9), count))
    k = 3 * n + 1
    rigid_dp = load * mu * np.log1p(t / a)
    q = math.pi * n / k * (rigid_dp * a**k / (2 * m * length)) ** (1 / n)
    return dict(mu=mu, m=m, n=n, a=a, t=t, length=length, q=q)


def scalar_solve(s, i):
    """tubefsi's default answer for scene ``i`` of ``s``, models built as a user would."""
    tube = tubefsi.Tube(radius=float(s["a"][i]), thickness=float(s["t"][i]), length=float(s["length"][i]))
    return tubefsi.solve(power_law(float(s["m"][i]), float(s["n"][i])), thick(float(s["mu"][i])), tube,
                         flow_rate=float(s["q"][i]))


def broadcast_solve(s):
    tube = tubefsi.Tube(radius=s["a"], thickness=s["t"], length=s["length"])
    return tubefsi.solve(power_law(s["m"], s["n"]), thick(s["mu"]), tube, flow_rate=s["q"])


class _Tube:
    """What the baseline reads of a tube (it takes no tubefsi objects)."""

    __slots__ = ("radius", "length", "reduced_thickness")

    def __init__(self, a, t, length):
        self.radius, self.length, self.reduced_thickness = a, length, t / a


def random_row(row, sizes, rng):
    """Random scenes: one broadcast call (or a loop of scalar solves) against the baseline per scene."""
    sets = [random_scenes(sizes.points, rng) for _ in range(sizes.repeats + 1)]   # a new set each pass
    try:
        sol = broadcast_solve(sets[-1])
        if np.shape(sol.pressure_drop) != (sizes.points,) or not np.all(np.isfinite(sol.pressure_drop)):
            raise ValueError(f"pressure_drop of shape {np.shape(sol.pressure_drop)}")
        mode, why = "broadcast", ""
    except Exception as exc:            # broadcasting of parameters is not there yet: time a loop
        mode, why = "loop", f"the broadcast call raised {type(exc).__name__}: {str(exc)[:90]}"
    if mode == "loop":
        row.shape = row.shape.replace("one broadcast call", "[loop] of scalar solves")
    count = sizes.sample
    tubes = [[_Tube(float(s["a"][i]), float(s["t"][i]), float(s["length"][i])) for i in range(count)] for s in sets]
    got = {}

    if mode == "broadcast":
        def ours(r):
            got["tubefsi"] = broadcast_solve(sets[r])
        units = sizes.points
    else:
        def ours(r):
            got["tubefsi"] = [scalar_solve(sets[r], i) for i in range(count)]
        units = count

    def theirs(r):
        s = sets[r]
        got["baseline"] = [chapter_thick(float(s["q"][i]), float(s["n"][i]), float(s["m"][i]), float(s["mu"][i]),
                                         tubes[r][i]) for i in range(count)]

    times = interleaved({"tubefsi": (ours, units), "baseline": (theirs, count)}, sizes.repeats)
    fill_ratio(row, times["tubefsi"], times["baseline"])
    s = sets[sizes.repeats - 1]
    default = [scalar_solve(s, i) for i in range(count)] if mode == "broadcast" else got["tubefsi"]
    dp_ref = [d.pressure_drop for d in default]
    u_ref = [d.inlet_displacement for d in default]
    dp, u = zip(*got["baseline"])
    row.err_baseline = rel_diff(dp, u, dp_ref, u_ref)
    if mode == "broadcast":
        b = got["tubefsi"]
        row.err_tubefsi = rel_diff(b.pressure_drop[:count], b.inlet_displacement[:count], dp_ref, u_ref)
    else:
        row.err_tubefsi = "ref"
    strain = max(d.inlet_displacement / float(a) for d, a in zip(default, s["a"]))
    faults = ""
    if resource is not None and mode == "broadcast":   # what glibc's returning of freed memory costs
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        ours(0)
        faults = (f"{resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0} minor page faults per call "
                  "(benchmarks/allocator.py)")
    row.note = "; ".join(filter(None, [
        why, f"{units} scenes per tubefsi pass, {count} per baseline pass",
        "mu 1-10 kPa, m 5-50 mPa s^n, n 0.5-1, a 50-200 um, t/a 0.1-0.5, L 5-20 mm, "
        "q: rigid drop 5-90 % of the limit pressure", f"strain up to ~{strain:.2g}", faults]))


def infeasible_row(row, sizes, rng):
    """Random scenes, 10 % of them beyond their maximum flow rate, ``on_infeasible="nan"``: one
    broadcast call against the baseline per feasible scene."""
    sets = []
    for _ in range(sizes.repeats + 1):
        s = random_scenes(sizes.points, rng)
        beyond = rng.random(sizes.points) < 0.1
        tube = tubefsi.Tube(radius=s["a"], thickness=s["t"], length=s["length"])
        q_max = tubefsi.max_flow_rate(power_law(s["m"], s["n"]), thick(s["mu"]), tube)
        s["q"] = np.where(beyond, q_max * rng.uniform(1.1, 2.0, sizes.points), s["q"])
        s["beyond"] = beyond
        sets.append(s)
    count = sizes.sample
    got = {}

    def call(s):
        tube = tubefsi.Tube(radius=s["a"], thickness=s["t"], length=s["length"])
        return tubefsi.solve(power_law(s["m"], s["n"]), thick(s["mu"]), tube, flow_rate=s["q"], on_infeasible="nan")

    def ours(r):
        got["tubefsi"] = call(sets[r])

    feasible = [np.flatnonzero(~s["beyond"])[:count] for s in sets]
    tubes = [[_Tube(float(s["a"][i]), float(s["t"][i]), float(s["length"][i])) for i in f] for s, f in zip(sets, feasible)]

    def theirs(r):
        s = sets[r]
        got["baseline"] = [chapter_thick(float(s["q"][i]), float(s["n"][i]), float(s["m"][i]), float(s["mu"][i]),
                                         tube) for i, tube in zip(feasible[r], tubes[r])]

    times = interleaved({"tubefsi": (ours, sizes.points), "baseline": (theirs, count)}, sizes.repeats)
    fill_ratio(row, times["tubefsi"], times["baseline"])
    s, idx = sets[sizes.repeats - 1], feasible[sizes.repeats - 1]
    sol = got["tubefsi"] if sizes.repeats % 2 else call(s)
    marked = np.array_equal(~np.asarray(sol.feasible), s["beyond"]) if sol.feasible is not None else False
    default = [scalar_solve(s, i) for i in idx]
    dp, u = zip(*got["baseline"]) if sizes.repeats % 2 == 0 else zip(*[chapter_thick(
        float(s["q"][i]), float(s["n"][i]), float(s["m"][i]), float(s["mu"][i]), t) for i, t in zip(idx, tubes[-2])])
    row.err_baseline = rel_diff(dp, u, [d.pressure_drop for d in default], [d.inlet_displacement for d in default])
    row.err_tubefsi = rel_diff(sol.pressure_drop[idx], sol.inlet_displacement[idx], [d.pressure_drop for d in default],
                               [d.inlet_displacement for d in default])
    row.note = (f"{sizes.points} scenes per tubefsi pass, {count} feasible ones per baseline pass; "
                f"{int(s['beyond'].sum())} beyond q_max marked infeasible: {marked}")


def carreau_yasuda(**changes):
    """Blood as a Carreau-Yasuda fluid (Cho & Kensey's constants, a = 2)."""
    try:
        from tubefsi_rheologies import preset
        base = preset("blood-carreau-yasuda")
    except ImportError:                 # the plugin's class only: its first example is the same fluid
        cls = rheologies["carreau-yasuda"]
        base = cls(**cls._examples[0])
    return attrs.evolve(base, **changes)


def carreau_scalar(row, sizes, rng):
    """A scalar Carreau-Yasuda solve, fresh fluid parameters each call: absolute time per call."""
    base = carreau_yasuda()
    wall = thick()
    times = []
    for _ in range(sizes.carreau_calls + 1):
        changes = dict(zero_shear_viscosity=base.zero_shear_viscosity * rng.uniform(0.8, 1.2),
                       relaxation_time=base.relaxation_time * rng.uniform(0.8, 1.2),
                       index=base.index * rng.uniform(0.9, 1.1))
        t0 = time.perf_counter()
        fluid = rheologies["carreau-yasuda"](**{**attrs.asdict(base), **changes})
        tubefsi.solve(fluid, wall, TUBE, flow_rate=Q_MC).pressure_drop
        times.append(time.perf_counter() - t0)
    warm_fluid = carreau_yasuda()
    tubefsi.solve(warm_fluid, wall, TUBE, flow_rate=Q_MC)
    t0 = time.perf_counter()
    tubefsi.solve(warm_fluid, wall, TUBE, flow_rate=Q_MC * 1.01)
    warm = time.perf_counter() - t0
    fill_absolute(row, times[1:])                        # the first call also warms the process
    row.note = (f"q = {Q_MC:g} m^3/s, eta0 and lambda +-20 %, n +-10 %; median of {sizes.carreau_calls} calls, "
                f"each with a fresh fluid (of the first 7 after the untimed one: {seconds(statistics.median(times[1:8]))}); "
                f"the same fluid again: {seconds(warm)}")


def carreau_scenes_draw(count, rng):
    """``count`` Carreau-Yasuda scenes with every parameter random (the issue-26 Monte Carlo): eta0,
    eta_inf / eta0, lambda, n, a (transition), mu, a, t, L and q; q loads the rigid tube, at the
    fluid's zero-shear viscosity, to 5-90 % of the limit pressure times 1-20 (shear thinning carries more)."""
    s = random_scenes(count, rng)
    s["e0"] = np.exp(rng.uniform(math.log(0.02), math.log(0.1), count))
    s["einf"] = s["e0"] * np.exp(rng.uniform(math.log(0.02), math.log(0.2), count))
    s["lam"] = np.exp(rng.uniform(math.log(0.1), math.log(10.0), count))
    s["n"] = rng.uniform(0.3, 0.8, count)
    s["tr"] = rng.uniform(0.6, 2.5, count)
    load = np.exp(rng.uniform(math.log(0.05), math.log(0.9), count)) * np.exp(rng.uniform(0.0, math.log(20.0), count))
    s["q"] = math.pi * s["a"] ** 4 * load * s["mu"] * np.log1p(s["t"] / s["a"]) / (8 * s["e0"] * s["length"])
    s["m"] = s["e0"] * s["lam"] ** (s["n"] - 1)      # the baseline's power law: the fluid's high-shear asymptote
    return s


def carreau_broadcast(s):
    fluid = rheologies["carreau-yasuda"](zero_shear_viscosity=s["e0"], infinite_shear_viscosity=s["einf"],
                                         relaxation_time=s["lam"], index=s["n"], transition=s["tr"])
    tube = tubefsi.Tube(radius=s["a"], thickness=s["t"], length=s["length"])
    return tubefsi.solve(fluid, thick(s["mu"]), tube, flow_rate=s["q"])


def carreau_scenes_row(row, sizes, rng):
    """10^3 random Carreau-Yasuda scenes in one broadcast call against the power-law baseline per scene."""
    count_scenes = min(sizes.points, 1000)
    sets = [carreau_scenes_draw(count_scenes, rng) for _ in range(sizes.repeats + 1)]
    carreau_broadcast(sets[-1])                     # (warms the process, not a fluid: each pass draws new ones)
    count = sizes.sample
    tubes = [[_Tube(float(s["a"][i]), float(s["t"][i]), float(s["length"][i])) for i in range(count)] for s in sets]
    got = {}

    def ours(r):
        got["tubefsi"] = carreau_broadcast(sets[r])

    def theirs(r):
        s = sets[r]
        got["baseline"] = [chapter_thick(float(s["q"][i]), float(s["n"][i]), float(s["m"][i]), float(s["mu"][i]),
                                         tubes[r][i]) for i in range(count)]

    times = interleaved({"tubefsi": (ours, count_scenes), "baseline": (theirs, count)}, sizes.repeats)
    fill_ratio(row, times["tubefsi"], times["baseline"])
    s = sets[sizes.repeats - 1]
    b = carreau_broadcast(s)
    alone = []
    for i in range(min(count, 20)):                 # the default answer of a scene alone (a scalar fluid)
        fluid = rheologies["carreau-yasuda"](zero_shear_viscosity=float(s["e0"][i]),
                                             infinite_shear_viscosity=float(s["einf"][i]),
                                             relaxation_time=float(s["lam"][i]), index=float(s["n"][i]),
                                             transition=float(s["tr"][i]))
        tube = tubefsi.Tube(radius=float(s["a"][i]), thickness=float(s["t"][i]), length=float(s["length"][i]))
        alone.append(tubefsi.solve(fluid, thick(float(s["mu"][i])), tube, flow_rate=float(s["q"][i])))
    row.err_tubefsi = rel_diff(b.pressure_drop[:len(alone)], b.inlet_displacement[:len(alone)],
                               [d.pressure_drop for d in alone], [d.inlet_displacement for d in alone])
    strain = float(np.max(b.inlet_displacement / s["a"]))
    row.note = (f"{count_scenes} scenes per tubefsi pass, {count} per baseline pass; eta0 20-100 mPa s, "
                "eta_inf/eta0 0.02-0.2, lambda 0.1-10 s, n 0.3-0.8, a 0.6-2.5, mu 1-10 kPa, a 50-200 um, t/a 0.1-0.5, "
                f"L 5-20 mm; strain up to ~{strain:.2g}; baseline: the power law of each fluid's high-shear "
                "asymptote at the same q; err tfsi: the broadcast call against each scene solved alone")


def fit_timing(row, sizes, rng):
    """``tubefsi.fit`` of 3 parameters to 20 synthetic points (1 % noise, fresh noise each fit)."""
    truth = dict(mu=MU, m=M, n=N)
    wall, fluid = thick(), power_law()
    q = np.geomspace(0.02, 0.7, 20) * tubefsi.max_flow_rate(fluid, wall, TUBE)
    clean = tubefsi.solve(fluid, wall, TUBE, flow_rate=q).pressure_drop
    names = ["wall.shear_modulus", "rheology.consistency", "rheology.index"]
    times, worst = [], 0.0
    for _ in range(sizes.fits + 1):
        dp = clean * np.exp(0.01 * rng.standard_normal(q.size))
        t0 = time.perf_counter()
        res = tubefsi.fit(q, dp, power_law(0.03, 0.6), thick(3e3), TUBE, parameters=names)
        times.append(time.perf_counter() - t0)
        for name, true in zip(names, truth.values()):
            worst = max(worst, abs(res.parameters[name] - true) / res.standard_errors[name])
    fill_absolute(row, times[1:])
    row.note = (f"q 2-70 % of q_max; start mu 3 kPa, m 0.03, n 0.6; every fitted parameter within "
                f"{worst:.2g} standard errors of the truth (1 % noise); {sizes.fits} fits")


def import_time(module):
    code = f"import time; t0 = time.perf_counter(); import {module}; print(time.perf_counter() - t0)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(out.stdout.strip())


def imports(row, sizes):
    """``import tubefsi`` over ``import numpy``, each in fresh subprocesses, alternating."""
    import_time("numpy"), import_time("tubefsi")         # compile any stale bytecode first
    got = {"numpy": [], "tubefsi": []}
    for r in range(sizes.imports):
        for module in ("numpy", "tubefsi") if r % 2 == 0 else ("tubefsi", "numpy"):
            got[module].append(import_time(module))
    row.tubefsi_s, row.baseline_s = statistics.median(got["tubefsi"]), statistics.median(got["numpy"])
    row.value = row.tubefsi_s / row.baseline_s
    per_pass = [t / n for t, n in zip(got["tubefsi"], got["numpy"])]
    row.low, row.high = min(per_pass), max(per_pass)
    row.note = f"median of {sizes.imports} fresh subprocesses each; baseline column: import numpy"


# ============================================================================ the table
ROWS = [
    # key, call shape, kind, unit, target
    ("thick curve", "{N}-pt flow curve, thick neo-Hookean + power law", "ratio", "point", 300),
    ("thin curve", "{N}-pt flow curve, thin neo-Hookean (closed form)", "ratio", "point", 1000),
    ("monte carlo", "scalar solve, fresh wall each call (Monte Carlo)", "ratio", "call", 5),
    ("numpy loop", "for q in np.linspace(...): solve (NumPy scalars)", "ratio", "call", 5),
    ("random scenes", "{N} random scenes, one broadcast call", "ratio", "scene", 30),
    ("infeasible scenes", "{N} random scenes, 10 % beyond q_max, on_infeasible='nan'", "ratio", "scene", 30),
    ("carreau curve", "{N}-pt Carreau-Yasuda curve, thick wall", "ratio", "point", 10),
    ("carreau scalar", "scalar Carreau-Yasuda solve, fresh fluid", "absolute", "call", 0.5e-3),
    ("carreau scenes", "10^3 random Carreau-Yasuda scenes, one call", "ratio", "scene", 0.5),
    ("fit", "tubefsi.fit, 20 points, 3 parameters", "absolute", "fit", 30e-3),
    ("import", "import tubefsi / import numpy", "ratio-max", "import", 2),
]


#: The seed of every row's generator (with the row's name).
SEED = 20240613


def measure(sizes, only=None):
    fluid, wall = power_law(), thick()
    q_top = 0.9 * tubefsi.max_flow_rate(fluid, wall, TUBE)
    q = np.linspace(q_top / sizes.points, q_top, sizes.points)
    q_cy = np.linspace(Q_CARREAU / sizes.points, Q_CARREAU, sizes.points)
    jobs = {
        "thick curve": lambda row, rng: flow_curve(row, fluid, wall, q, chapter_thick, sizes),
        "thin curve": lambda row, rng: flow_curve(
            row, fluid, walls["thin-neo-hookean"](shear_modulus=MU, thickness_convention="reference"), q,
            chapter_thin, sizes),
        "monte carlo": lambda row, rng: monte_carlo(row, sizes, rng),
        "numpy loop": lambda row, rng: numpy_loop(row, sizes, rng),
        "random scenes": lambda row, rng: random_row(row, sizes, rng),
        "infeasible scenes": lambda row, rng: infeasible_row(row, sizes, rng),
        "carreau curve": lambda row, rng: flow_curve(row, carreau_yasuda(), wall, q_cy, chapter_thick, sizes,
                                                baseline_fluid=fluid),
        "carreau scalar": lambda row, rng: carreau_scalar(row, sizes, rng),
        "carreau scenes": lambda row, rng: carreau_scenes_row(row, sizes, rng),
        "fit": lambda row, rng: fit_timing(row, sizes, rng),
        "import": lambda row, rng: imports(row, sizes),
    }
    rows = []
    for key, shape, kind, unit, target in ROWS:
        if only and key not in only:
            continue
        count = "10^4" if sizes.points == 10_000 else str(sizes.points)
        row = Row(key, shape.replace("{N}", count), kind, unit, target)
        try:
            # each row its own generator (seeded by its name): a row's draws do not depend on which
            # rows ran before it or on how many calls they made
            jobs[key](row, np.random.default_rng([SEED, zlib.crc32(key.encode())]))
        except Exception as exc:        # report the row as failed and go on with the others
            row.note = f"FAILED: {type(exc).__name__}: {exc}"[:300]
        if key == "carreau curve" and not row.note.startswith("FAILED"):
            row.note += "; baseline: the power-law fluid at the same flow rates"
        rows.append(row)
        print(f"  measured {key} ({row.value:.3g})", file=sys.stderr, flush=True)
    return rows


def value_text(row):
    if row.kind == "absolute":
        return seconds(row.value), f"<= {seconds(row.target)}"
    sense = "<=" if row.kind == "ratio-max" else ">="
    digits = 3 if row.value < 100 else 4
    return f"{row.value:.{digits}g}x", f"{sense} {row.target:g}x"


def error_text(e):
    return e if isinstance(e, str) else f"{e:.1e}"


def table(rows):
    """The table a reader checks, then one note per row (what was solved, sizes, caveats)."""
    head = (f"{'#':>2s} {'call shape':54s} {'tubefsi':>9s} {'baseline':>9s} {'per':>6s} {'measured':>9s} "
            f"{'range':>13s} {'target':>9s} {'met':>4s} {'err base':>8s} {'err tfsi':>8s}")
    lines = [head, "-" * len(head)]
    for i, row in enumerate(rows, 1):
        value, target = value_text(row)
        if not math.isfinite(row.low):
            spread = "-"
        elif row.kind == "absolute":
            spread = f"{seconds(row.low)}-{seconds(row.high)}"
        else:
            spread = f"{row.low:.3g}-{row.high:.3g}"
        lines.append(f"{i:2d} {row.shape:54s} {seconds(row.tubefsi_s):>9s} {seconds(row.baseline_s):>9s} "
                     f"{row.unit:>6s} {value:>9s} {spread:>13s} {target:>9s} {'yes' if row.met else 'NO':>4s} "
                     f"{error_text(row.err_baseline):>8s} {error_text(row.err_tubefsi):>8s}")
    lines.append("")
    lines += [f"{i:2d}. {row.key}: {row.note}" for i, row in enumerate(rows, 1)]
    return "\n".join(lines)


def machine():
    load = os.getloadavg() if hasattr(os, "getloadavg") else (math.nan,) * 3
    return dict(date=datetime.date.today().isoformat(), cores=os.cpu_count(), platform=platform.platform(),
                processor=platform.processor() or platform.machine(), python=platform.python_version(),
                numpy=np.__version__, scipy=scipy.__version__, tubefsi=tubefsi.__version__,
                load_average=[round(v, 2) for v in load])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes: a smoke test (seconds), not a measurement")
    parser.add_argument("--json", metavar="FILE", help="also write the table as JSON to FILE")
    parser.add_argument("--only", nargs="*", metavar="KEY", help=f"measure only these rows: {[r[0] for r in ROWS]}")
    args = parser.parse_args(argv)
    sizes = QUICK if args.quick else Sizes()
    before = machine()
    t0 = time.perf_counter()
    rows = measure(sizes, args.only)
    after = machine()
    print(f"tubefsi {before['tubefsi']} speed against the chapter's method (lean scalar odeint, default tolerances)"
          f"{'  [--quick: smoke-test sizes, not a measurement]' if args.quick else ''}")
    print(f"{before['date']}, {before['cores']} cores, {before['platform']}, Python {before['python']}, "
          f"NumPy {before['numpy']}, SciPy {before['scipy']}; load average {before['load_average'][0]} before, "
          f"{after['load_average'][0]} after")
    print(f"ratio = baseline time / tubefsi time per {{point, call, scene}}: median of {sizes.repeats} "
          f"interleaved passes (range: per-pass ratios); absolute rows: median time per call or fit;\n"
          f"import: tubefsi / numpy. err: relative difference from tubefsi's default answer ('ref': it is)\n")
    print(table(rows))
    failed = [r.key for r in rows if not math.isfinite(r.value)]
    print(f"\n{sum(r.met for r in rows)} of {len(rows)} targets met; {time.perf_counter() - t0:.0f} s in all"
          + (f"; FAILED: {', '.join(failed)}" if failed else ""))
    if args.json:
        data = dict(machine=before, load_average_after=after["load_average"], quick=args.quick,
                    sizes=attrs.asdict(sizes),
                    rows=[{**attrs.asdict(r), "met": r.met} for r in rows])
        with open(args.json, "w") as fh:
            json.dump(data, fh, indent=2, default=float)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
