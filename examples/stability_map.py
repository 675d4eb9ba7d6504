r"""Stability map: where each tubefsi method fails or loses accuracy, and how it says so.

Run ``python examples/stability_map.py [OUTDIR]`` (default: the repository's ``docs/``); it writes
``OUTDIR/stability_map.png`` and prints what every panel found. Headless; about a minute.
``--quick`` samples each panel at three points only (a smoke test, not the published map).
The map is discussed in ``docs/stability.md``.

Every number is compared with an independent ``mpmath`` reference (``tubefsi.testing.reference``,
written from the formulas of ``docs/theory.md``, sections "Tube laws" and "Coupling without an
ODE", as in ``examples/work_precision.py``: tube laws with hand-derived slopes,
``J(λ) = ∫_1^λ P'(s) s^k ds`` by ``mpmath.quad``), at the exact double the method receives.
Markers: filled = a number and no warning; hollow = a number *and* a warning
(``tubefsi.AccuracyWarning`` or a SciPy integrator warning); ``×`` on the "raised" line = a
typed ``tubefsi`` error (``ConvergenceError``, ``NoSteadyStateError``); a red ``!`` = an
untyped exception or a NaN/inf (a bug). A dotted grey line is the conditioning floor
``κ · 2.2e-16`` (``κ`` the condition number of the output with respect to the double input,
computed in mpmath): no method working from a double input can beat it.

Panels
------
(a) Removable singularities of the closed forms: thin reference-thickness wall near
    ``n = 2/3`` and thin current-thickness wall near ``n = 1`` (the Newtonian case), at
    λ_in = 1.5, pressure-controlled. tubefsi's closed form (``expm1(c v)/c``) against the
    chapter's formula evaluated naively in floats,
    ``(λ^(3n+2) − 1)/(3n+2) + 3 (λ^(3n−2) − 1)/(3n−2)`` and ``4 (λ^(3n−3) − 1)/(3n−3)``,
    which loses ``log10(1/|n − n*|)`` digits and is ``0/0`` at the double nearest ``n*``.
(b) Approaching the maximum flow rate (flow-controlled) and (c) the limit pressure
    (pressure-controlled): thick neo-Hookean wall, ``t/a = 0.3``, power law ``n = 0.7``.
    Default path against ``ODE(method="odeint")`` (the chapter's defaults),
    ``ODE(method="LSODA", rtol=1e-8)`` and ``ODE()`` (LSODA, SciPy's rtol = 1e-3), each with its
    a-posteriori error check on; at and beyond ``q_max`` / ``p_max`` every method must raise
    ``NoSteadyStateError``.
(d) Small and large strain: the same scene, inlet strain 1e-15 … 1e2, flow-controlled
    (error of the inlet displacement); "naive R − a" is the default solution's
    ``inlet_radius − a``, i.e. the displacement formed after the fact.
(e, f) Heat maps of the default path's error (the largest of Δp and displacement,
    flow-controlled, and q, pressure-controlled) over power-law index ``n`` (0.1 – 3) and
    ``t/a`` (1e-3 – 1e2) at inlet strain 1: thick Mooney–Rivlin (quadrature) and thin
    current-thickness Mooney–Rivlin (closed form). Cells that raise are marked.
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import time
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mpmath  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402
from mpmath import mp, mpf  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi.couplers import ODE  # noqa: E402
from tubefsi.registry import rheologies, walls  # noqa: E402
from tubefsi.testing.reference.power_law import (  # noqa: E402
    flow_rate_cases,
    ref_J_direct,
    ref_phi_inverse,
    ref_q_max,
)
from tubefsi.testing.reference.tube_laws import MooneyRivlin, NeoHookean, RefWall  # noqa: E402

EPS = 2.0**-52
A, LEN, M = 1e-4, 1e-2, 0.01
RAISED_Y = 3.0        # where "raised" markers sit (above every error axis)
TOP = 30.0


def tube_for(tb):
    return tubefsi.Tube(radius=A, thickness=tb * A, length=LEN)


def power_law(n):
    return rheologies["power-law"](consistency=M, index=n)


# ------------------------------------------------------------------------- the reference
def ref_J(wall, lam, k):
    """``J(λ) = ∫_1^λ P'(s) s^k ds``: a positive integrand, on geometrically split intervals."""
    return ref_J_direct(wall, lam, k, geometric=True)


def reference_cases(wall, n, lams):
    """Flow rates (doubles) near the inlet stretches ``lams`` and the exact (Δp, u) for them."""
    qs, dps, us = flow_rate_cases(wall, n, M, A, LEN, lams)
    return np.array(qs), dps, us


# ------------------------------------------------------------------------- running a method
def attempt(fn):
    """Run ``fn()``; return (value or None, status, message); status: ok/warned/raised/untyped."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            value = fn()
        except tubefsi.TubefsiError as exc:
            return None, "raised", type(exc).__name__
        except Exception as exc:          # noqa: BLE001 - an untyped failure is what we look for
            return None, "untyped", f"{type(exc).__name__}: {exc}"
    numbers = ((value.flow_rate, value.pressure_drop, value.inlet_displacement)
               if isinstance(value, tubefsi.Solution) else (value,))
    if not all(np.all(np.isfinite(np.asarray(v, dtype=float))) for v in numbers):
        return None, "untyped", "NaN/inf returned"
    kinds = sorted({w.category.__name__ for w in caught if not issubclass(w.category, DeprecationWarning)})
    return value, ("warned" if kinds else "ok"), ", ".join(kinds)


def rel(got, exact):
    return float(abs(mpf(float(got)) / exact - 1))


def silent(xs, results, threshold=1e-3):
    """Points that returned a number with error > threshold and no warning: silent wrong numbers."""
    return [f"{x:.2g}: {e:.1e}" for x, (e, st) in zip(xs, results) if st == "ok" and e is not None and e > threshold]


def draw(ax, x, results, label, color, marker, ls="-"):
    """results: list of (error or None, status). Lines through the numbers; markers by status."""
    x = np.asarray(x, dtype=float)
    err = np.array([e if e is not None else np.nan for e, _ in results], dtype=float)
    status = np.array([s for _, s in results])
    shown = np.where(np.isfinite(err), np.maximum(err, 1e-17), np.nan)
    ax.plot(x, shown, ls=ls, color=color, lw=1.2, label=label, marker=marker, ms=0)
    ok, warned = status == "ok", status == "warned"
    ax.plot(x[ok], shown[ok], ls="none", marker=marker, color=color, ms=6)
    ax.plot(x[warned], shown[warned], ls="none", marker=marker, mfc="white", mec=color, ms=7, mew=1.5)
    raised = status == "raised"
    ax.plot(x[raised], np.full(raised.sum(), RAISED_Y), ls="none", marker="x", color=color, ms=8, mew=2)
    bad = status == "untyped"
    for xi in x[bad]:
        ax.text(xi, RAISED_Y * 1.8, "!", color="red", fontsize=14, fontweight="bold", ha="center", va="center")


def finish(ax, xlabel, ylabel, title, xlog=True, legend_loc="best", bottom=1e-17, ncol=1):
    if xlog:
        ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(bottom, TOP)
    ax.axhline(1e-12, color="k", lw=0.8, ls=":")
    ax.axhline(1.0, color="0.6", lw=0.6)
    ax.text(1.0, RAISED_Y, " raised ", transform=ax.get_yaxis_transform(), ha="right", va="center", fontsize=10,
            color="0.3")
    ax.text(0.0, 1e-12, " 1e-12", transform=ax.get_yaxis_transform(), ha="left", va="bottom", fontsize=10)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=12.5)
    ax.grid(True, which="major", alpha=0.3)
    # the legend inside its own panel, so that it cannot be read as the next panel's
    ax.legend(loc=legend_loc, fontsize=10.5, framealpha=0.9, edgecolor="0.8", ncol=ncol)


def status_marks():
    """A proxy legend for the marker conventions."""
    return [plt.Line2D([], [], ls="none", marker="o", color="k", label="number, no warning"),
            plt.Line2D([], [], ls="none", marker="o", mfc="white", mec="k", mew=1.5, label="number + warning"),
            plt.Line2D([], [], ls="none", marker="x", color="k", mew=2, label="raised a typed tubefsi error"),
            plt.Line2D([], [], ls="none", marker="$!$", color="red", label="untyped exception / NaN (bug)"),
            plt.Line2D([], [], ls=":", color="0.4", label="conditioning floor κ·eps"),
            plt.Line2D([], [], ls=":", color="k", lw=0.8, label="accuracy contract 1e-12")]


def odes():
    return {
        "ODE(odeint): chapter's defaults": (ODE(method="odeint"), "tab:brown", "P"),
        "ODE(LSODA, rtol=1e-8)": (ODE(method="LSODA", rtol=1e-8, atol=1e-11), "tab:red", "^"),
        "ODE() (LSODA, rtol=1e-3)": (ODE(), "tab:orange", "s"),
    }


# ------------------------------------------------------------------------- (a) singular closed forms
def panel_singular(ax, log, points=31):
    lam_float = 1.5
    deltas = np.geomspace(1e-16, 1e-1, points)
    cases = [("thin reference, n → 2/3", "thin-reference", mpf(2) / 3, "tab:blue",
              lambda n, lam: (lam ** (3 * n + 2) - 1) / (3 * n + 2) + 3 * (lam ** (3 * n - 2) - 1) / (3 * n - 2)),
             ("thin current, n → 1", "thin-current", mpf(1), "tab:green",
              lambda n, lam: 4 * (lam ** (3 * n - 3) - 1) / (3 * n - 3))]
    mu, tb = 2e3, 0.3
    tube = tube_for(tb)
    for label, kind, n_star, color, naive_J in cases:
        wall = walls["thin-neo-hookean"](shear_modulus=mu, thickness_convention=kind.split("-")[1])
        rw = RefWall(kind, NeoHookean(mu), mpf(tube.reduced_thickness))
        dp = float(rw.P(mpf(lam_float)))
        lam_ref = mpmath.findroot(lambda s: rw.P(s) - mpf(dp), mpf(lam_float))
        lam_lib = wall.stretch(dp, tube.reduced_thickness)      # the same stretch for the naive formula

        def errors(n):
            k_mp = 3 * mpf(n) + 1
            q_ref = ref_phi_inverse(ref_J(rw, lam_ref, k_mp) * mpf(A) ** k_mp / LEN, mpf(n), mpf(M))
            value, status, _ = attempt(lambda: tubefsi.solve(power_law(n), wall, tube, pressure_drop=dp).flow_rate)
            ours = (None if value is None else rel(value, q_ref), status)
            with np.errstate(all="ignore"):
                J = mu * tube.reduced_thickness * naive_J(np.float64(n), np.float64(lam_lib)) * A ** (3 * n + 1)
                q_naive = math.pi * n / (3 * n + 1) * (J / (2 * M * LEN)) ** (1 / n)
            naive = (rel(q_naive, q_ref), "ok") if math.isfinite(q_naive) else (None, "untyped")
            return ours, naive

        def worse(a, b):
            if a[0] is None or b[0] is None:
                return a if a[0] is None else b
            return a if a[0] >= b[0] else b

        n0 = float(n_star)                                      # the double nearest n*
        x0 = float(abs(mpf(n0) - n_star)) or 1.5e-17            # n = 1 is exact: drawn at the axis edge
        ours0, naive0 = errors(n0)
        xs, ours, naive = [x0], [ours0], [naive0]
        for d in deltas:
            lo, hi = n0 - d, n0 + d
            o1, v1 = errors(lo)
            o2, v2 = errors(hi)
            xs.append(float(max(abs(mpf(lo) - n_star), abs(mpf(hi) - n_star))))
            ours.append(worse(o1, o2))
            naive.append(worse(v1, v2))
        draw(ax, xs, ours, f"{label}: tubefsi closed form", color, "o")
        draw(ax, xs, naive, f"{label}: naive float formula", color, "d", "--")
        log.append(f"(a) {label}: default error at the double nearest n* {ours0[0]:.1e} ({ours0[1]}), worst over "
                   f"|n - n*| = 1e-16..0.1: {max(e for e, _ in ours if e is not None):.1e}; naive formula at n*: "
                   f"{'NaN (0/0)' if naive0[0] is None else f'{naive0[0]:.1e}'}, worst naive error "
                   f"{max(e for e, _ in naive if e is not None):.1e}")
    ax.annotate("naive formula at the double\nnearest n*: 0/0 = NaN", (5e-17, RAISED_Y * 1.5), xytext=(3e-17, 1e-8),
                fontsize=10, arrowprops=dict(arrowstyle="->", lw=0.6))
    finish(ax, "|n − n*|  (leftmost: the double nearest n*)",
           "relative error of q(Δp)", "(a) closed forms at their removable singularities (λ_in = 1.5)",
           legend_loc="lower center", bottom=1e-23)
    ax.set_xlim(1e-17, 0.3)


# ------------------------------------------------------------------------- (b, c) near the limit
def limit_scene():
    tb, mu, n = 0.3, 2e4, 0.7
    tube = tube_for(tb)
    rw = RefWall("thick", NeoHookean(mu), mpf(tube.reduced_thickness))
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    return tube, rw, wall, n


def panel_max_flow(ax, log, points=13):
    tube, rw, wall, n = limit_scene()
    fluid = power_law(n)
    k = 3 * mpf(n) + 1
    q_max = ref_q_max(rw, n, M, A, LEN)
    lams = np.geomspace(2.0, 1e6, points)
    q, dps, us = reference_cases(rw, n, lams)
    x = [float(1 - mpf(qi) / q_max) for qi in q]
    floor = []
    for qi, dp, u in zip(q, dps, us):
        lam = u / mpf(A) + 1
        J = ref_J(rw, lam, k)
        kappa_lam = mpf(n) * J / (lam ** (k + 1) * rw.dP(lam))
        floor.append(float(max(kappa_lam * lam / (lam - 1), mpf(n) * J / (lam**k * dp), 1)) * EPS)
    ax.plot(x, floor, ls=":", color="0.4")
    methods = {"tubefsi default": ("auto", "k", "*")} | odes()
    for label, (coupler, color, marker) in methods.items():
        res = []
        for qi, dp, u in zip(q, dps, us):
            value, status, msg = attempt(lambda: tubefsi.solve(fluid, wall, tube, flow_rate=qi, coupler=coupler))
            err = None if value is None else max(rel(value.pressure_drop, dp), rel(value.inlet_displacement, u))
            res.append((err, status))
        draw(ax, x, res, label, color, marker)
        beyond = []
        for factor in (1.0, 1 + 1e-9, 1.5):
            _, status, msg = attempt(lambda: tubefsi.solve(fluid, wall, tube, flow_rate=float(q_max) * factor,
                                                           coupler=coupler))
            beyond.append(msg if status == "raised" else f"{status} {msg}")
        worst = max((e for e, _ in res if e is not None), default=math.nan)
        flags = {s for _, s in res}
        log.append(f"(b) {label}: worst error {worst:.1e} for 1 - q/q_max >= {min(x):.1e}; statuses {sorted(flags)}; "
                   f"silent > 1e-3 at {silent(x, res) or 'none'}; worst error/floor "
                   f"{max(e / f for (e, _), f in zip(res, floor) if e is not None):.0f}; "
                   f"at q = q_max, q_max(1 + 1e-9), 1.5 q_max: {beyond}")
    finish(ax, "1 − q/q_max", "max rel. error (Δp, inlet displacement)",
           "(b) flow rate → maximum flow rate (thick neo-Hookean, n = 0.7)")
    ax.invert_xaxis()


def panel_limit_pressure(ax, log, points=12):
    tube, rw, wall, n = limit_scene()
    fluid = power_law(n)
    k = 3 * mpf(n) + 1
    p_lim = rw.limit_pressure()
    eps_grid = np.geomspace(0.3, 1e-12, points)
    x, floor, cases = [], [], []
    with mp.workdps(45):
        for e in eps_grid:
            dp = float(p_lim * (1 - mpf(e)))
            target = mpf(dp)
            lo, hi = mpf(1), mpf(2)
            while rw.P(hi) < target:
                lo, hi = hi, 2 * hi
            lam = mpmath.findroot(lambda s: rw.P(s) - target, (lo, hi), solver="anderson")
            J = ref_J(rw, lam, k)
            q = ref_phi_inverse(J * mpf(A) ** k / LEN, mpf(n), mpf(M))
            kappa_q = lam**k * target / (mpf(n) * J)
            cases.append((dp, q))
            x.append(float(1 - target / p_lim))
            floor.append(float(max(kappa_q, 1)) * EPS)
    ax.plot(x, floor, ls=":", color="0.4")
    methods = {"tubefsi default": ("auto", "k", "*")} | odes()
    for label, (coupler, color, marker) in methods.items():
        res = []
        for dp, q in cases:
            value, status, msg = attempt(lambda: tubefsi.solve(fluid, wall, tube, pressure_drop=dp,
                                                               coupler=coupler).flow_rate)
            res.append((None if value is None else rel(value, q), status))
        draw(ax, x, res, label, color, marker)
        beyond = []
        for factor in (1.0, 1.01):
            _, status, msg = attempt(lambda: tubefsi.solve(fluid, wall, tube, pressure_drop=float(p_lim) * factor,
                                                           coupler=coupler))
            beyond.append(msg if status == "raised" else f"{status} {msg}")
        worst = max((e for e, _ in res if e is not None), default=math.nan)
        log.append(f"(c) {label}: worst q error {worst:.1e}; statuses {sorted({s for _, s in res})}; "
                   f"silent > 1e-3 at {silent(x, res) or 'none'}; worst error/floor "
                   f"{max((e / f for (e, _), f in zip(res, floor) if e is not None), default=math.nan):.0f}; "
                   f"raised at 1 - dp/p_max = {[f'{xi:.0e}' for xi, (_, st) in zip(x, res) if st == 'raised']}; "
                   f"at Δp = p_max, 1.01 p_max: {beyond}")
    finish(ax, "1 − Δp/p_max", "relative error of q(Δp)",
           "(c) pressure drop → limit pressure (same scene)")
    ax.invert_xaxis()


# ------------------------------------------------------------------------- (d) strain sweep
def panel_strain(ax, log, points=18):
    tube, rw, wall, n = limit_scene()
    fluid = power_law(n)
    strains = np.geomspace(1e-15, 1e2, points)
    q, dps, us = reference_cases(rw, n, [1 + mpf(float(s)) for s in strains])
    methods = {"tubefsi default": ("auto", "k", "*")} | odes()
    for label, (coupler, color, marker) in methods.items():
        res = []
        for qi, u in zip(q, us):
            value, status, _ = attempt(lambda: tubefsi.solve(fluid, wall, tube, flow_rate=qi,
                                                             coupler=coupler).inlet_displacement)
            res.append((None if value is None else rel(value, u), status))
        draw(ax, strains, res, label, color, marker)
        log.append(f"(d) {label}: worst {max(e for e, _ in res if e is not None):.1e}; "
                   f"statuses {sorted({s for _, s in res})}; silent > 1e-3 at {silent(strains, res) or 'none'}")
    naive = []
    for qi, u in zip(q, us):
        sol = tubefsi.solve(fluid, wall, tube, flow_rate=qi)
        naive.append((rel(sol.inlet_radius - A, u), "ok"))
    draw(ax, strains, naive, "naive R − a (default solution)", "tab:gray", "d", "--")
    # pressure-controlled odeint at the same states
    res = []
    for qi, dp in zip(q, dps):
        value, status, msg = attempt(lambda: tubefsi.solve(fluid, wall, tube, pressure_drop=float(dp),
                                                           coupler=ODE(method="odeint")).flow_rate)
        res.append((None if value is None else rel(value, mpf(qi)), status))
        if status == "untyped":
            log.append(f"(d) ODE(odeint) pressure-controlled at Δp = {float(dp)!r}: UNTYPED {msg}")
    draw(ax, strains, res, "ODE(odeint), pressure-controlled (error of q)", "tab:brown", "P", ":")
    finish(ax, "inlet strain (R − a)/a", "relative error of the inlet displacement",
           "(d) tiny to large strain (thick neo-Hookean, n = 0.7)", legend_loc="lower left", bottom=1e-23)


# ------------------------------------------------------------------------- (e, f) heat maps
def panel_heat(ax, fig, kind, log, n_points=12, tb_points=11):
    ns = np.geomspace(0.1, 3.0, n_points)
    tbs = np.geomspace(1e-3, 1e2, tb_points)
    c1, c2 = 1.5e3, -0.5e3
    if kind == "thick":
        wall = walls["thick-mooney-rivlin"](c1=c1, c2=c2)
        title = "(e) default path: thick Mooney–Rivlin (quadrature), strain 1"
    else:
        wall = walls["thin-mooney-rivlin"](c1=c1, c2=c2, thickness_convention="current")
        title = "(f) default path: thin current Mooney–Rivlin (closed form), strain 1"
    err = np.full((tbs.size, ns.size), np.nan)
    marks = []
    for i, tb in enumerate(tbs):
        tube = tube_for(tb)
        rw = RefWall(kind, MooneyRivlin(c1, c2), mpf(tube.reduced_thickness))
        for j, n in enumerate(ns):
            (q,), (dp,), (u,) = reference_cases(rw, n, [mpf(2)])
            fluid = power_law(n)
            sol, s1, m1 = attempt(lambda: tubefsi.solve(fluid, wall, tube, flow_rate=q))
            sol2, s2, m2 = attempt(lambda: tubefsi.solve(fluid, wall, tube, pressure_drop=float(dp)))
            if sol is None or sol2 is None:
                marks.append((j, i, "x" if "untyped" not in (s1, s2) else "!"))
                log.append(f"({kind} heat map) n={n:.3g} t/a={tb:.3g}: {s1} {m1} / {s2} {m2}")
                continue
            q_ref = ref_phi_inverse(ref_J(rw, mpf(2), 3 * mpf(n) + 1) * mpf(A) ** (3 * mpf(n) + 1) / LEN,
                                    mpf(n), mpf(M))
            err[i, j] = max(rel(sol.pressure_drop, dp), rel(sol.inlet_displacement, u),
                            rel(sol2.flow_rate, q_ref), 1e-17)
            if s1 != "ok" or s2 != "ok":
                marks.append((j, i, "w"))
    image = ax.pcolormesh(np.arange(ns.size + 1), np.arange(tbs.size + 1), err,
                          norm=LogNorm(vmin=1e-16, vmax=1e-11), cmap="viridis", shading="flat")
    for j, i, mark in marks:
        ax.text(j + 0.5, i + 0.5, {"x": "×", "!": "!", "w": "w"}[mark], ha="center", va="center",
                color="red", fontsize=14, fontweight="bold")
    for i in range(tbs.size):
        for j in range(ns.size):
            if np.isfinite(err[i, j]) and err[i, j] > 1e-12:
                ax.text(j + 0.5, i + 0.5, f"{err[i, j]:.0e}", ha="center", va="center", fontsize=8, color="w")
    ax.set_xticks(np.arange(ns.size) + 0.5, [f"{n:.2g}" for n in ns], fontsize=11, rotation=45)
    ax.set_yticks(np.arange(tbs.size) + 0.5, [f"{t:.1g}" for t in tbs], fontsize=11)
    ax.set_xlabel("power-law index n")
    ax.set_ylabel("t/a")
    ax.set_title(title, fontsize=12.5)
    bar = fig.colorbar(image, ax=ax, label="max rel. error (Δp, u, q)", extend="both")
    bar.ax.axhline(1e-12, color="w", lw=2)
    worst = np.nanmax(err)
    log.append(f"({'e' if kind == 'thick' else 'f'}) {kind}: worst default-path error {worst:.1e} over "
               f"n = {ns[0]:.2g}–{ns[-1]:.2g}, t/a = {tbs[0]:.0e}–{tbs[-1]:.0e}; cells above 1e-12: "
               f"{int(np.sum(err > 1e-12))}; marked cells: {len(marks)}")


# ------------------------------------------------------------------------- main
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outdir", nargs="?", default=pathlib.Path(__file__).resolve().parents[1] / "docs",
                        help="where to write stability_map.png")
    parser.add_argument("--quick", action="store_true",
                        help="three points per panel, 3 x 3 heat maps (a smoke test, seconds)")
    args = parser.parse_args(argv)
    outdir = pathlib.Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    line = dict(points=3) if args.quick else {}                      # the line panels (a)-(d)
    heat = dict(n_points=3, tb_points=3) if args.quick else {}       # the heat maps (e, f)
    mp.dps = 30
    t0 = time.perf_counter()
    # two columns, readable where the docs show it (about 900 px wide): 13-point text
    plt.rcParams.update({"font.size": 13, "axes.labelsize": 13, "xtick.labelsize": 12, "ytick.labelsize": 12})
    fig, axes = plt.subplots(3, 2, figsize=(14, 18), constrained_layout=True)
    axes = axes.reshape(2, 3)     # the panels keep their letters (a)-(f), read row by row
    log: list[str] = []
    panels = [(panel_singular, axes[0, 0]), (panel_max_flow, axes[0, 1]), (panel_limit_pressure, axes[0, 2]),
              (panel_strain, axes[1, 0])]
    for fn, ax in panels:
        t = time.perf_counter()
        fn(ax, log, **line)
        log.append(f"   [{fn.__name__}: {time.perf_counter() - t:.1f} s]")
    for kind, ax in (("thick", axes[1, 1]), ("thin-current", axes[1, 2])):
        t = time.perf_counter()
        panel_heat(ax, fig, kind, log, **heat)
        log.append(f"   [heat map {kind}: {time.perf_counter() - t:.1f} s]")
    fig.legend(handles=status_marks(), loc="outside lower center", ncol=3, fontsize=12, frameon=False)
    fig.suptitle("tubefsi stability map: errors against an independent mpmath reference", fontsize=15)
    path = outdir / "stability_map.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print("\n".join(log))
    print(f"\nwrote {path} ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
