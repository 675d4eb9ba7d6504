r"""Validity map: how far tubefsi's reduced model is from the two-way coupled FE reference.

Run ``python examples/validity_map.py [OUTDIR]`` (default: the repository's ``docs/``); it
writes ``OUTDIR/validity_map.png`` and ``OUTDIR/validity_map.csv`` and prints the table and the
headline numbers. Headless; a few minutes on one core. ``--quick`` runs two slenderness values
of one scene only (a smoke test, not the published map). The map is discussed in
``docs/validity.md``.

For every scene (rheology, wall, t/a, inlet strain) and slenderness a/L, the flow rate is the
one at which tubefsi predicts the given inlet strain; ``tubefsi.fem.solve_axisymmetric`` (ends
clamped, resolution 2 and 4) gives the reference pressure drop, and the modelling error is
``dp_tubefsi / dp_fe - 1`` at resolution 4; the change from resolution 2 to 4 bounds the FE
discretization error. Per scene: the observed order in a/L (smallest two a/L), the fit
``delta = C0 + C1 (a/L) + C2 (a/L)^2`` (C0: what does not vanish with a/L, i.e. the wall
theory's own error), the a/L where ``|delta|`` reaches 1 % and 10 %, and the end-effect length
``l_end = |C1| a / ((3n+1) eps_in)`` (the length of tube whose radius the clamped ends hold at
a instead of its pressure-vessel value: see docs/validity.md). ``--cached`` redraws the figure
and the summary from the committed CSV.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

ROOT = Path(__file__).resolve().parents[1]
A = 1e-3                                                    # m: the map is in a/L, t/a, n, strain
SLENDERNESS = (0.2, 0.1, 0.05, 0.025, 0.0125, 0.005)
SCENES = {  # name -> (rheology, wall, t/a, inlet strain)
    "newtonian, thick neo-Hookean t/a=0.3, strain 5%": (("newtonian", {"viscosity": 1e-3}),
                                                         ("thick-neo-hookean", {"shear_modulus": 1e4}), 0.3, 0.05),
    "power law n=0.5, thick neo-Hookean t/a=0.3, strain 5%": (("power-law", {"consistency": 1e-2, "index": 0.5}),
                                                               ("thick-neo-hookean", {"shear_modulus": 1e4}), 0.3, 0.05),
    "newtonian, thick neo-Hookean t/a=0.3, strain 30%": (("newtonian", {"viscosity": 1e-3}),
                                                          ("thick-neo-hookean", {"shear_modulus": 1e4}), 0.3, 0.3),
    "newtonian, thin neo-Hookean t/a=0.05, strain 5%": (("newtonian", {"viscosity": 1e-3}),
                                                         ("thin-neo-hookean", {"shear_modulus": 1e4,
                                                                               "thickness_convention": "current"}),
                                                         0.05, 0.05),
    "newtonian, thick Mooney-Rivlin t/a=1, strain 5%": (("newtonian", {"viscosity": 1e-3}),
                                                         ("thick-mooney-rivlin", {"c1": 1.5e4, "c2": -0.5e4}), 1.0, 0.05),
}


def scene_row(scene, slenderness, resolutions=(2, 4)):
    import tubefsi.fem as tfem

    (rname, rkw), (wname, wkw), tb, strain = SCENES[scene]
    fluid, wall = rheologies[rname](**rkw), walls[wname](**wkw)
    tube = tubefsi.Tube(radius=A, thickness=tb * A, length=A / slenderness)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)   # a/L = 0.2 is the point
        q = float(tubefsi.solve(fluid, wall, tube, pressure_drop=wall.pressure(1.0 + strain, tb)).flow_rate)
        red = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    row = {"scene": scene, "a_over_L": slenderness, "t_over_a": tb, "n": float(getattr(fluid, "index", 1.0)),
           "strain": strain, "flow_rate": q, "dp_tubefsi": float(red.pressure_drop)}
    for res in resolutions:
        fe = tfem.solve_axisymmetric(fluid, wall, tube, flow_rate=q, resolution=res)
        row[f"dp_fe_{res}"] = fe.pressure_drop
        row[f"seconds_{res}"] = fe.seconds
        row[f"iterations_{res}"] = fe.iterations
    top = max(resolutions)
    row["error"] = row["dp_tubefsi"] / row[f"dp_fe_{top}"] - 1.0
    row["fe_change"] = row[f"dp_fe_{top}"] / row[f"dp_fe_{min(resolutions)}"] - 1.0
    return row


def summarize(rows):
    """Per scene: the observed order (smallest two a/L), the fit ``delta = C0 + C1 (a/L) +
    C2 (a/L)^2`` (C0: the part that does not vanish with a/L, from the wall theory), the a/L of
    1 % and 10 % error on the fit, ``l_end/a`` and the median time of one FE solve."""
    out = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        rs = sorted((r for r in rows if r["scene"] == scene), key=lambda r: float(r["a_over_L"]))
        x = np.array([float(r["a_over_L"]) for r in rs])
        d = np.array([float(r["error"]) for r in rs])
        order = math.log(abs(d[1] / d[0])) / math.log(x[1] / x[0]) if len(rs) > 1 else float("nan")
        basis = [np.ones_like(x), x, x * x][: max(1, min(3, len(rs) - 0))]
        coef = np.linalg.lstsq(np.column_stack(basis), d, rcond=None)[0] if len(rs) > 2 else \
            np.array([0.0, d[0] / x[0], 0.0])
        c0, c1, c2 = (list(coef) + [0.0, 0.0])[:3]

        def reach(level):
            grid = np.geomspace(1e-4, 1.0, 4001)
            hit = np.abs(c0 + c1 * grid + c2 * grid**2) >= level
            return float(grid[np.argmax(hit)]) if hit.any() else float("inf")

        n, strain = float(rs[0]["n"]), float(rs[0]["strain"])
        out[scene] = {"order": order, "C0": float(c0), "C1": float(c1), "C2": float(c2),
                      "aL_1pc": reach(0.01), "aL_10pc": reach(0.10),
                      "l_end_over_a": abs(float(c1)) / ((3 * n + 1) * strain),
                      "seconds": float(np.median([float(r["seconds_4"]) for r in rs]))}
    return out


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for scene in dict.fromkeys(r["scene"] for r in rows):
        rs = sorted((r for r in rows if r["scene"] == scene), key=lambda r: float(r["a_over_L"]))
        err = np.array([float(r["error"]) for r in rs])
        line, = ax.loglog([float(r["a_over_L"]) for r in rs], np.abs(err), "o-", label=scene)
        pos = err > 0                                   # hollow: tubefsi above the FE
        ax.loglog(np.array([float(r["a_over_L"]) for r in rs])[pos], np.abs(err)[pos], "o",
                  mfc="white", color=line.get_color())
    x = np.array([min(SLENDERNESS), max(SLENDERNESS)])
    ax.loglog(x, 0.1 * x, "k:", label="slope 1")
    for level in (0.01, 0.1):
        ax.axhline(level, color="grey", lw=0.6)
    ax.set_xlabel("a / L")
    ax.set_ylabel("|Δp_tubefsi / Δp_FE − 1|  (hollow: > 0)")
    ax.set_title("tubefsi vs the two-way coupled axisymmetric FE reference (clamped ends)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir", nargs="?", default=str(ROOT / "docs"))
    parser.add_argument("--quick", action="store_true", help="two a/L values of one scene")
    parser.add_argument("--cached", action="store_true",
                        help="redraw the figure and the summary from OUTDIR/validity_map.csv, no FE solve")
    args = parser.parse_args(argv)
    outdir = Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    if args.cached:
        with open(outdir / "validity_map.csv", newline="") as fh:
            rows = list(csv.DictReader(fh))
        plot(rows, outdir / "validity_map.png")
        report(rows)
        return 0
    scenes = list(SCENES)[:1] if args.quick else list(SCENES)
    slenderness = (0.2, 0.1) if args.quick else SLENDERNESS
    rows, t0 = [], time.perf_counter()
    for scene in scenes:
        for s in slenderness:
            row = scene_row(scene, s)
            rows.append(row)
            print(f"{scene:55s} a/L = {s:<7g} error = {row['error']:+.4e}  FE change 2->4 = "
                  f"{row['fe_change']:+.2e}  FE solve {row['seconds_4']:.2f} s, {row['iterations_4']} iterations",
                  flush=True)
    with open(outdir / "validity_map.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    plot(rows, outdir / "validity_map.png")
    report(rows)
    print(f"total {time.perf_counter() - t0:.1f} s")
    return 0


def report(rows):
    for scene, s in summarize(rows).items():
        print(f"{scene:55s} order = {s['order']:.3f}  C0 = {s['C0']:+.2e}  C1 = {s['C1']:+.4f}  "
              f"C2 = {s['C2']:+.4f}  1% at a/L = {s['aL_1pc']:.3g}  10% at a/L = {s['aL_10pc']:.3g}  "
              f"l_end/a = {s['l_end_over_a']:.3f}  median FE solve = {s['seconds']:.2f} s")


if __name__ == "__main__":
    sys.exit(main())
