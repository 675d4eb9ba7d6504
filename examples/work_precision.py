r"""Work–precision chart: relative error against time per point for every tubefsi method.

Run ``python examples/work_precision.py [OUTDIR]`` (default: the repository's ``docs/``); it writes
``OUTDIR/work_precision.png`` and prints a table (error, time per point, speed ratio against
the chapter's method). Headless (matplotlib Agg); about 70 s on two cores. ``--quick`` runs
every step at small sizes (3 reference points, 2 quadrature orders, one ODE method at one
tolerance, a tiny time budget: seconds; a smoke test, not the published chart).

Scenes (tube: a = 100 µm, t = 30 µm, L = 1 cm; power-law fluid m = 0.017 Pa s^n, n = 0.7)
--------------------------------------------------------------------------------------------
1. *thin closed form*: thin reference-thickness neo-Hookean wall (μ = 2 kPa), strains 0.01–3;
2. *thick Mooney–Rivlin, moderate load*: c1 = 1.5 kPa, c2 = −0.5 kPa, strains 0.02–1.5
   (up to 33 % of the maximum flow rate);
3. *thick Mooney–Rivlin, near the limit*: the same wall at 78–99.8 % of the maximum flow rate
   (inlet stretch 10–2000, inlet pressure up to within 1e-13 of the limit pressure);
4. *non-separable*: a script-local Carreau fluid (blood-like: μ0 = 0.056 Pa s,
   μ∞ = 3.45 mPa s, λ = 3.313 s, n = 0.3568) that implements only ``_stress``, in a thick
   neo-Hookean wall (μ = 2 kPa), q = 2e-11 … 1.2e-9 m³/s (strains 0.02–0.74). It exercises
   the generic path a rheology plugin gets: the Rabinowitsch–Mooney flow function of
   ``_stress`` alone, and its inverse.

Methods: ``coupler="auto"`` (the default), ``ClosedForm()`` (scene 1), ``Quadrature(order=k)``
for k = 4, 6, 8, 12, 16, 24, 32, ``ODE`` with DOP853, LSODA and Radau at rtol = 1e-4 … 1e-12
(atol = rtol/1000, ``check_error=False`` so that the integrator alone is timed; scene 4 uses
rtol = 1e-4, 1e-8, 1e-12 only), ``ODE(method="odeint")`` (the chapter's ``odeint`` defaults inside tubefsi) and the lean
chapter baseline of ``benchmarks/speed.py`` (a scalar, pure-float right-hand side for
``scipy.integrate.odeint`` at its default tolerances, one ODE per point;
``tubefsi.testing.reference.chapter_baseline``). Scene 4 has no lean baseline (the chapter
treats power laws only); its ratios are against ``ODE(method="odeint")``.

Reference values (independent of tubefsi's numerics)
-----------------------------------------------------
All references come from ``tubefsi.testing.reference``, written in ``mpmath`` straight from the
formulas of ``docs/theory.md`` without calling tubefsi's numerics, here at ``mp.dps = 30``:

* tube laws (section "Tube laws"; ``tube_laws.RefWall``): thin reference ``P = μ t̄ (λ − λ⁻³)``;
  thick (Lamé) ``P = (μ/2)[f(x_o) − f(x_i)]``, ``f(x) = x + ln x``, ``x_o = b/(b − 1 + λ²)``,
  ``x_i = λ⁻²``, ``b = (1 + t̄)²``, ``μ = 2(c1 + c2)``; hand-derived slopes
  ``P' = μ t̄ (1 + 3 s⁻⁴)`` and ``P' = μ d ((d+2) s² + d) / (s³ (s² + d)²)``, ``d = b − 1``
  (checked against ``mpmath.diff`` of ``P`` when the script starts);
* power law (section "The flow law of a generalized Newtonian fluid"; ``power_law``):
  ``G(q, R) = φ(q) R^−k``, ``k = 3n + 1``, ``φ(q) = 2m[(3n+1)q/(πn)]^n``;
  separation (section "Coupling without an ODE") with the outlet at zero pressure:
  ``L φ(q) = a^k ∫_1^λin P'(s) s^k ds``
  (a positive integrand, ``mpmath.quad`` on geometrically split intervals — no cancellation,
  also at λ = 2000). Each scene picks exact inlet stretches λ, gets ``q``, rounds it to the
  double that the methods receive, and moves λ by one Newton step so that the reference is the
  exact answer for that double (the rounding would otherwise show near the limit;
  ``power_law.flow_rate_cases``); the maximum flow rate is ``φ⁻¹(a^k ∫_1^∞ P'(s) s^k ds / L)``
  (``power_law.ref_q_max``);
* Carreau (scene 4; ``rheology.CarreauYasudaRef`` with transition 2 and
  ``rheology.solve_flow_controlled``): with the wall shear rate γ as parameter, the Rabinowitsch–Mooney integral gives
  ``4q/(πR³) = Γ(γ) = 4/σ(γ)³ ∫_0^γ σ² σ' x dx`` and ``G = 2σ(γ)/R``; the separated identity
  becomes an integral over γ between the inlet and outlet wall shear rates (fixed
  Gauss–Legendre rules on geometrically graded sub-intervals), and the inlet wall shear rate
  is its root by Newton's method (``mp.dps = 25``; for each flow rate, a double, starting from
  the inlet stretch of the linearised tube law).

``examples/stability_map.py`` uses the same references (and ``RefWall``'s thin
current-thickness law ``μ t̄ (1 − λ⁻⁴)``, ``P' = 4 μ t̄ λ⁻⁵``).

The error of a method is the larger relative error of pressure drop and inlet displacement,
maximised over the reference points (40 in scenes 1–3, 10 in scene 4), flow-controlled.

Timing
------
Vectorized methods (closed form, quadrature): best of 3 calls on N = 2000 flow rates spanning
the scene (N = 400 in scene 4), divided by N, after a warm-up call. Per-point methods (ODE,
odeint, the lean baseline): a call on up to 40 of the reference points — fewer when a pilot
point shows the method would exceed about 2 s — divided by the number of points; best of 3
such calls where that fits in 2 s, else one. All in
one process, so the ratios compare like with like.
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import time
import warnings

import attrs
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mpmath  # noqa: E402
import numpy as np  # noqa: E402
from mpmath import mp, mpf  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi.couplers import ODE, ClosedForm, Quadrature  # noqa: E402
from tubefsi.registry import rheologies, walls  # noqa: E402
from tubefsi.rheology import Rheology  # noqa: E402
from tubefsi.testing.reference.chapter_baseline import chapter_thick, chapter_thin  # noqa: E402
from tubefsi.testing.reference.power_law import flow_rate_cases, ref_q_max  # noqa: E402
from tubefsi.testing.reference.rheology import CarreauYasudaRef, solve_flow_controlled  # noqa: E402
from tubefsi.testing.reference.tube_laws import MooneyRivlin, NeoHookean, RefWall  # noqa: E402

mp.dps = 30

A, T, LEN = 1e-4, 3e-5, 1e-2          # m
M_FLUID, N_FLUID = 0.017, 0.7         # Pa s^n, -
TUBE = tubefsi.Tube(radius=A, thickness=T, length=LEN)

N_VECTOR = 2000
N_REF = 40
BUDGET = 2.0                           # s of timed work per per-point method and scene
QUAD_ORDERS = (4, 6, 8, 12, 16, 24, 32)
RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
ODE_METHODS = ("DOP853", "LSODA", "Radau")
ERROR_FLOOR = 1e-16


@attrs.frozen
class Sizes:
    """How much the chart measures: the published chart by default, :data:`QUICK` for a smoke test."""

    n_ref: int = N_REF                  # reference points of scenes 1-3
    n_vector: int = N_VECTOR            # flow rates per timed call of a vectorized method, scenes 1-3
    carreau_ref: int = 10               # the same two for scene 4
    carreau_vector: int = 400
    budget: float = BUDGET
    quad_orders: tuple = QUAD_ORDERS
    rtols: tuple = RTOLS
    ode_methods: tuple = ODE_METHODS


#: ``--quick``: every scene and every kind of method once, at small sizes (seconds)
QUICK = Sizes(n_ref=3, n_vector=20, carreau_ref=2, carreau_vector=10, budget=0.01, quad_orders=(8, 24),
              rtols=(1e-6,), ode_methods=("LSODA",))


# ============================================================================ reference (mpmath)
# RefWall, flow_rate_cases, ref_q_max, CarreauYasudaRef and solve_flow_controlled (imported above)
# come from tubefsi.testing.reference (module docstring).
def check_slope(wall):
    """The reference's hand-derived slope ``P'`` against ``mpmath.diff`` of its tube law."""
    for lam in (mpf("1.001"), mpf("1.7"), mpf(30)):
        num = mpmath.diff(wall.P, lam)
        assert abs(num / wall.dP(lam) - 1) < mpf(10) ** -20, (wall, lam)


def power_law_reference(wall, n, m, lams, a=A, length=LEN):
    """Flow rates (doubles) and exact (Δp, u) for them, at inlet stretches near ``lams``."""
    qs, dps, us = flow_rate_cases(wall, n, m, a, length, lams)
    return np.array(qs), dps, us


# ---------------------------------------------------------------------------- Carreau
@attrs.frozen(kw_only=True)
class Carreau(Rheology):
    """Carreau fluid σ = γ̇ [μ∞ + (μ0 − μ∞)(1 + (λγ̇)²)^((n−1)/2)]: only ``_stress``, so not separable."""

    zero_shear_viscosity: float = 0.056
    infinite_shear_viscosity: float = 0.00345
    relaxation_time: float = 3.313
    index: float = 0.3568

    def _stress(self, shear_rate):
        mu0, mui = self.zero_shear_viscosity, self.infinite_shear_viscosity
        lt, n = self.relaxation_time, self.index
        return shear_rate * (mui + (mu0 - mui) * (1.0 + (lt * shear_rate) ** 2) ** (0.5 * (n - 1.0)))


def carreau_reference(fluid, wall, qs, a=A, length=LEN):
    """Exact (Δp, u) for a Carreau fluid in ``wall`` at the flow rates ``qs`` (module docstring)."""
    dps, us = [], []
    with mp.workdps(25):
        ref = CarreauYasudaRef(fluid.zero_shear_viscosity, fluid.infinite_shear_viscosity,
                               fluid.relaxation_time, fluid.index, transition=2)
        a, length = mpf(a), mpf(length)
        for q in qs:
            q = float(q)
            rate = 4 * mpf(q) / (mpmath.pi * a**3)              # Γ at the undeformed radius
            gradient = 2 * ref.tau(ref.at_apparent(rate, rate)) / a
            guess = 1 + length * gradient / wall.dP(mpf(1))    # the linearised tube law
            dp, lam = solve_flow_controlled(ref, wall, a, length, q, guess)
            dps.append(dp)
            us.append(a * (lam - 1))
    return np.asarray(qs, dtype=float), dps, us


# ============================================================================ the chapter's method
# chapter_thick, chapter_thin (imported above) come from tubefsi.testing.reference.chapter_baseline,
# shared with benchmarks/speed.py: a lean scalar odeint per point at default tolerances, returning
# (pressure drop, inlet displacement).


# ============================================================================ scenes
@attrs.frozen
class Scene:
    key: str
    title: str
    fluid: object
    wall: object
    q_ref: np.ndarray
    dp_ref: list
    u_ref: list
    baseline: object = None         # f(q) -> (dp, u), or None
    n_vector: int = N_VECTOR
    n_per_point: int = N_REF
    note: str = ""


def build_scenes(sizes=Sizes()):
    tb = TUBE.reduced_thickness
    fluid = rheologies["power-law"](consistency=M_FLUID, index=N_FLUID)
    scenes = []

    mu = 2e3
    thin = RefWall("thin-reference", NeoHookean(mu), tb)
    check_slope(thin)
    q, dp, u = power_law_reference(thin, N_FLUID, M_FLUID, 1 + np.geomspace(0.01, 3, sizes.n_ref))
    scenes.append(Scene("thin", "1. thin neo-Hookean (ref. thickness), power law n = 0.7: closed form",
                        fluid, walls["thin-neo-hookean"](shear_modulus=mu, thickness_convention="reference"),
                        q, dp, u, baseline=lambda qi: chapter_thin(qi, N_FLUID, M_FLUID, mu, TUBE),
                        n_vector=sizes.n_vector))

    c1, c2 = 1.5e3, -0.5e3
    mu = 2 * (c1 + c2)
    thick = RefWall("thick", MooneyRivlin(c1, c2), tb)
    check_slope(thick)
    mr = walls["thick-mooney-rivlin"](c1=c1, c2=c2)
    q_max = ref_q_max(thick, N_FLUID, M_FLUID, A, LEN)
    q, dp, u = power_law_reference(thick, N_FLUID, M_FLUID, 1 + np.geomspace(0.02, 1.5, sizes.n_ref))
    scenes.append(Scene("moderate", "2. thick Mooney–Rivlin, power law n = 0.7: moderate load",
                        fluid, mr, q, dp, u, baseline=lambda qi: chapter_thick(qi, N_FLUID, M_FLUID, mu, TUBE),
                        note=f"q/q_max {q.min() / float(q_max):.3g}–{q.max() / float(q_max):.3g}",
                        n_vector=sizes.n_vector))
    q, dp, u = power_law_reference(thick, N_FLUID, M_FLUID, np.geomspace(10, 2000, sizes.n_ref))
    p_lim = thick.limit_pressure()
    scenes.append(Scene("limit", "3. thick Mooney–Rivlin, power law n = 0.7: near the maximum flow rate",
                        fluid, mr, q, dp, u, baseline=lambda qi: chapter_thick(qi, N_FLUID, M_FLUID, mu, TUBE),
                        note=f"q/q_max {q.min() / float(q_max):.4f}–{q.max() / float(q_max):.4f}, "
                             f"1 - dp/p_lim down to {float(1 - max(dp) / p_lim):.1e}",
                        n_vector=sizes.n_vector))

    carreau = Carreau()
    nh = RefWall("thick", NeoHookean(2e3), tb)
    q, dp, u = carreau_reference(carreau, nh, np.geomspace(2e-11, 1.2e-9, sizes.carreau_ref))
    scenes.append(Scene("carreau", "4. Carreau fluid (non-separable), thick neo-Hookean",
                        carreau, walls["thick-neo-hookean"](shear_modulus=2e3), q, dp, u,
                        n_vector=sizes.carreau_vector, n_per_point=sizes.carreau_ref,
                        note="ratios against ODE(method='odeint')"))
    return scenes


# ============================================================================ measurement
def max_error(dp, u, dp_ref, u_ref):
    err = 0.0
    for a, b in zip(np.ravel(dp), dp_ref):
        err = max(err, float(abs(mpf(float(a)) / b - 1)))
    for a, b in zip(np.ravel(u), u_ref):
        err = max(err, float(abs(mpf(float(a)) / b - 1)))
    return err


def best_of(fn, repeat):
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def ode(method, rtol=None):
    kw = {} if rtol is None else dict(rtol=rtol, atol=rtol * 1e-3)
    try:
        return ODE(method=method, check_error=False, **kw)
    except TypeError:             # a tubefsi without the a-posteriori check
        return ODE(method=method, **kw)


def methods_for(scene, sizes=Sizes()):
    """(family, label, coupler or callable, per_point)."""
    out = [("auto", "auto (default)", "auto", False)]
    if scene.key == "thin":
        out.append(("closed form", "ClosedForm()", ClosedForm(), False))
    for k in sizes.quad_orders:
        out.append(("quadrature", f"Quadrature(order={k})", Quadrature(order=k, check_error=False), False))
    # the generic (non-separable) flow law makes each right-hand side evaluation a root find:
    # fewer tolerances there keep the script within a few minutes
    rtols = sizes.rtols[::2] if scene.key == "carreau" else sizes.rtols
    for method in sizes.ode_methods:
        for rtol in rtols:
            if method == "Radau" and rtol < 1e-10:
                continue           # minutes per point near the limit; adds nothing to the chart
            out.append((f"ODE {method}", f"ODE({method}, rtol={rtol:.0e})", ode(method, rtol), True))
    out.append(("odeint", "ODE(method='odeint')", ode("odeint"), True))
    if scene.baseline is not None:
        out.append(("chapter", "chapter odeint (lean)", scene.baseline, True))
    return out


def repeats(pilot, count, budget=BUDGET):
    """Best of 3 for per-point methods when that fits the time budget, else a single pass."""
    return 3 if 3 * pilot * count < budget else 1


def run_method(scene, coupler, per_point, budget=BUDGET):
    """Return (time per point, error, n points timed, note)."""
    q_ref = scene.q_ref
    if callable(coupler) and not isinstance(coupler, tubefsi.couplers.Coupler):
        pilot = best_of(lambda: coupler(q_ref[-1]), 1)
        count = int(min(scene.n_per_point, max(5, budget / max(pilot, 1e-9))))
        idx = np.unique(np.linspace(0, q_ref.size - 1, count).round().astype(int))
        res = []
        elapsed = best_of(lambda: res.append([coupler(qi) for qi in q_ref[idx]]),
                          repeats(pilot, idx.size, budget))
        dp, u = zip(*res[-1])
        return elapsed / idx.size, max_error(dp, u, [scene.dp_ref[i] for i in idx],
                                             [scene.u_ref[i] for i in idx]), idx.size, ""

    def solve(q):
        return tubefsi.solve(scene.fluid, scene.wall, TUBE, flow_rate=q, coupler=coupler)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if per_point:
                pilot = best_of(lambda: solve(q_ref[-1:]), 1)
                count = int(min(scene.n_per_point, max(3, budget / max(pilot, 1e-9))))
                idx = np.unique(np.linspace(0, q_ref.size - 1, count).round().astype(int))
                sols = []
                per = best_of(lambda: sols.append(solve(q_ref[idx])), repeats(pilot, idx.size, budget)) / idx.size
                sol = sols[-1]
            else:
                idx = np.arange(q_ref.size)
                sol = solve(q_ref)
                dense = np.linspace(q_ref.min(), q_ref.max(), scene.n_vector)
                solve(dense[:10])
                per = best_of(lambda: solve(dense), 3) / scene.n_vector
        except tubefsi.TubefsiError as exc:
            return math.nan, math.nan, 0, f"raised {type(exc).__name__}"
    note = ""
    kinds = sorted({w.category.__name__ for w in caught})
    if kinds:
        note = "warned " + ", ".join(kinds)
    err = max_error(sol.pressure_drop, sol.inlet_displacement,
                    [scene.dp_ref[i] for i in idx], [scene.u_ref[i] for i in idx])
    return per, err, idx.size, note


# ============================================================================ chart
STYLE = {
    "auto": dict(color="k", marker="*", ms=14, ls="none", zorder=5),
    "closed form": dict(color="tab:green", marker="D", ms=8, ls="none", zorder=4),
    "quadrature": dict(color="tab:blue", marker="o", ms=6, ls="-", zorder=3),
    "ODE DOP853": dict(color="tab:orange", marker="s", ms=6, ls="-"),
    "ODE LSODA": dict(color="tab:red", marker="^", ms=6, ls="-"),
    "ODE Radau": dict(color="tab:purple", marker="v", ms=6, ls="-"),
    "odeint": dict(color="tab:brown", marker="P", ms=10, ls="none"),
    "chapter": dict(color="tab:gray", marker="X", ms=11, ls="none"),
}
LEGEND = {
    "auto": "tubefsi default (auto)",
    "closed form": "closed form",
    "quadrature": "Quadrature, order 4–32 (labelled)",
    "ODE DOP853": "ODE DOP853, rtol 1e-4…1e-12",
    "ODE LSODA": "ODE LSODA, rtol 1e-4…1e-12",
    "ODE Radau": "ODE Radau, rtol 1e-4…1e-10",
    "odeint": "ODE(method='odeint'): chapter's defaults in tubefsi",
    "chapter": "chapter's method (lean scalar odeint)",
}


def plot(scenes, results, path):
    fig, axes = plt.subplots(2, 2, figsize=(13, 10.5), constrained_layout=True)
    for ax, scene in zip(axes.flat, scenes):
        rows = results[scene.key]
        families = {}
        for fam, label, per, err, *_ in rows:
            if math.isfinite(per):
                families.setdefault(fam, []).append((per, max(err, ERROR_FLOOR), label))
        for fam, pts in families.items():
            x, y, labels = zip(*pts)
            ax.plot(x, y, **STYLE[fam])
            if fam == "quadrature":          # order labels, alternately left and right
                for i, (xi, yi, lab) in enumerate(zip(x, y, labels)):
                    ax.annotate(lab.split("=")[1].rstrip(")"), (xi, yi), textcoords="offset points",
                                xytext=(6, 2) if i % 2 == 0 else (-6, -9), ha="left" if i % 2 == 0 else "right",
                                fontsize=8, color="tab:blue")
        ax.axhline(1e-12, color="k", lw=0.8, ls=":")
        ax.text(0.99, 1e-12, "accuracy contract 1e-12", transform=ax.get_yaxis_transform(), ha="right",
                va="bottom", fontsize=8)
        base = [per for fam, _, per, *_ in rows if fam == ("chapter" if scene.baseline else "odeint")]
        if base and math.isfinite(base[0]):
            ax.axvline(base[0] / 100, color="k", lw=0.8, ls="--")
            what = "chapter's time" if scene.baseline else "ODE(odeint) time"
            ax.text(base[0] / 100, 0.02, f" 1/100 of the\n {what}", transform=ax.get_xaxis_transform(),
                    fontsize=8, va="bottom")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(1e-16, 1e-1)
        ax.set_xlabel("time per point (s)")
        ax.set_ylabel("max relative error (Δp, inlet displacement)")
        ax.set_title(scene.title, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
    handles = [plt.Line2D([], [], **{**STYLE[f], "ls": STYLE[f]["ls"]}) for f in LEGEND]
    fig.legend(handles, list(LEGEND.values()), loc="outside lower center", ncol=3, fontsize=9, frameon=False)
    fig.suptitle("tubefsi work–precision (errors against an independent mpmath reference; "
                 f"errors below {ERROR_FLOOR:g} drawn at it)", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ============================================================================ main
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outdir", nargs="?", default=pathlib.Path(__file__).resolve().parents[1] / "docs",
                        help="where to write work_precision.png")
    parser.add_argument("--quick", action="store_true", help="every step at small sizes (a smoke test, seconds)")
    args = parser.parse_args(argv)
    outdir = pathlib.Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    sizes = QUICK if args.quick else Sizes()

    t_start = time.perf_counter()
    scenes = build_scenes(sizes)
    print(f"references: {time.perf_counter() - t_start:.1f} s (mpmath, dps {mp.dps})")
    results = {}
    for scene in scenes:
        rows = []
        for fam, label, coupler, per_point in methods_for(scene, sizes):
            per, err, count, note = run_method(scene, coupler, per_point, sizes.budget)
            rows.append((fam, label, per, err, count, note))
        base_fam = "chapter" if scene.baseline is not None else "odeint"
        base = next(per for fam, _, per, *_ in rows if fam == base_fam)
        results[scene.key] = rows
        print(f"\n{scene.title}" + (f"  ({scene.note})" if scene.note else ""))
        print(f"  {'method':28s} {'max rel. error':>14s} {'time/point':>12s} {'points':>6s} "
              f"{'speed-up vs chapter':>20s}  note")
        for fam, label, per, err, count, note in rows:
            ratio = base / per if math.isfinite(per) else math.nan
            per_s = f"{per * 1e6:9.2f} us" if math.isfinite(per) else "         -"
            print(f"  {label:28s} {err:14.1e} {per_s:>12s} {count:6d} {ratio:19.1f}x  {note}")
    path = outdir / "work_precision.png"
    plot(scenes, results, path)
    print(f"\nwrote {path} ({time.perf_counter() - t_start:.0f} s in all)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
