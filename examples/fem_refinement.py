"""Mesh-refinement study of the finite-element check of the tube laws (needs the ``verify`` extra).

A quarter ring (t/a = 0.3) of neo-Hookean material in plane strain is inflated by
displacement control to inner stretches 1.1, 1.5, 2 and 3 with felupe (see
``tests/test_fem_tube_laws.py`` for the model); the pressure read from the reaction forces is
compared with tubefsi's closed-form thick tube law. For bilinear (Q1, mean-dilatation
pressure) and biquadratic (Q2, discontinuous bilinear pressure) quadrilaterals the script
prints the largest relative error over the stretches at each mesh and the observed rate
``log2(e_h / e_{h/2})``, and plots them. A reaction force is a derivative of the energy, so
it converges at twice the element order: expect 2 for Q1 and 4 for Q2, until the error
meets the penalty (bulk modulus 1e8 mu) and round-off floor near 1e-8.

Then it prints the relative error of every registered thick hyperelastic wall (its own
``_dW`` as the felupe material) on the default test mesh.

Run: ``MPLBACKEND=Agg python examples/fem_refinement.py [OUT_DIR]`` (default
``docs/chapter``; writes ``fem_refinement.png``). About a minute. ``--quick`` keeps the two
coarsest meshes of each element and the neo-Hookean wall only (a few seconds; a smoke test,
not the published study).
"""

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))          # the FE model lives with its tests

import test_fem_tube_laws as fe  # noqa: E402

import tubefsi  # noqa: E402

TB = 0.3
STRETCHES = (1.1, 1.5, 2.0, 3.0)
STUDY = {  # order -> meshes (elements through the wall, elements around the quarter)
    1: [(2, 8), (4, 16), (8, 32), (16, 64)],
    2: [(1, 4), (2, 8), (4, 16), (8, 32)],
}


def refinement(levels_per_order=None):
    """The study of ``STUDY``; ``levels_per_order`` keeps only the coarsest meshes of each element."""
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=1.0)
    exact = wall.pressure(np.array(STRETCHES), TB)
    rows = []
    for order, levels in STUDY.items():
        previous = None
        for nr, nh in levels[:levels_per_order]:
            t0 = time.perf_counter()
            p = fe.ring_pressure(fe.fem.NeoHooke(mu=1.0), TB, STRETCHES, n_radial=nr, n_hoop=nh, order=order)
            err = float(np.max(np.abs(p / exact - 1.0)))
            rate = math.log2(previous / err) if previous else math.nan
            rows.append(dict(order=order, n_radial=nr, n_hoop=nh, h=TB / nr, error=err, rate=rate,
                             seconds=time.perf_counter() - t0))
            previous = err
    return rows


def all_walls(names=None):
    """Every registered thick hyperelastic wall (or those of ``names``) on the default test mesh."""
    rows = []
    for case in fe.THICK_CASES:
        name, params = case.values
        if names is not None and name not in names:
            continue
        wall = tubefsi.registry.walls[name](**params)
        lam = fe.test_stretches(wall, TB)
        mu = float(wall._d2W(np.asarray(1.0))) / 4.0
        fine = fe.tangent_shear_modulus(wall, lam[-1]) > 10.0 * mu
        p = fe.ring_pressure(fe.ReducedEnergyMaterial(wall), TB, lam, shear_modulus=mu,
                             tangent=lambda s, w=wall: fe.tangent_shear_modulus(w, s),
                             n_radial=4 if fine else 2, n_hoop=16 if fine else 8)
        rel = np.abs(p / wall.pressure(np.array(lam), TB) - 1.0)
        rows.append((case.id, max(lam), float(rel.max())))
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out_dir", nargs="?", default=ROOT / "docs" / "chapter",
                        help="where to write fem_refinement.png (default: the repository's docs/chapter)")
    parser.add_argument("--quick", action="store_true",
                        help="two meshes per element, the neo-Hookean wall only (a smoke test)")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    rows = refinement(2 if args.quick else None)
    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    print(f"thick neo-Hookean ring, t/a = {TB}, stretches {STRETCHES}: max relative error in pressure")
    print(f"{'element':>8} {'mesh':>8} {'error':>10} {'rate':>6} {'time/s':>7}")
    for r in rows:
        print(f"{'Q' + str(r['order']):>8} {r['n_radial']:>3}x{r['n_hoop']:<4} {r['error']:10.3e} "
              f"{r['rate']:6.2f} {r['seconds']:7.2f}")
    print("\nevery registered thick hyperelastic wall, FEM of its own dW vs its tube law (default mesh):")
    for ident, top, err in all_walls(("thick-neo-hookean",) if args.quick else None):
        print(f"  {ident:<22} stretches up to {top:5.3f}: max relative error {err:.2e}")

    import matplotlib.pyplot as plt
    from matplotlib.ticker import FixedFormatter, FixedLocator, NullFormatter, NullLocator

    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    for order, marker in ((1, "o"), (2, "s")):
        sel = [r for r in rows if r["order"] == order]
        h = np.array([r["h"] for r in sel])
        e = np.array([r["error"] for r in sel])
        ax.loglog(h, e, marker + "-", lw=2, ms=7, label=f"Q{order}: observed")
        slope = 2 * order
        ax.loglog(h, 0.4 * e[0] * (h / h[0]) ** slope, ":", lw=1.5, color=ax.lines[-1].get_color(),
                  label=f"slope {slope} (twice the order), offset")
    ax.set_xlabel("radial element size h / a", fontsize=12)
    ax.set_ylabel("max relative error in pressure", fontsize=12)
    ax.set_title("FEM (felupe) ring vs thick tube law, t/a = 0.3, λ ≤ 3", fontsize=11)
    ticks = sorted({round(r["h"], 4) for r in rows})
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_major_formatter(FixedFormatter([f"{t:g}" for t in ticks]))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())
    floor = min(r["error"] for r in rows)
    ax.annotate("penalty / round-off floor", xy=(min(r["h"] for r in rows if r["order"] == 2), floor),
                xytext=(0.05, floor * 0.25), fontsize=9, arrowprops=dict(arrowstyle="->", lw=0.8))
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=10)
    fig.savefig(out / "fem_refinement.png", dpi=110)
    plt.close(fig)
    print(f"\nwrote {out / 'fem_refinement.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
