r"""Cost of ``tubefsi.evolve``: a soft actuator inflating through its supply tube.

Run ``python benchmarks/transient.py`` (a minute or two on two cores; ``--quick``: the loosest
tolerances only). The scene: a thick neo-Hookean tube (a = 0.25 mm, t = 0.1 mm, L = 5 cm,
mu = 100 kPa), a power-law fluid (m = 0.017 Pa s^n, n = 0.7), a linear chamber at the end
(V0 = 0.1 ml, C = 10 ul/kPa), a 20 kPa step at the inlet, 41 output times over 2 s.

Printed:

* the **work–precision table**: for each requested ``rtol``, the wall time of the
  error-controlled call, its right-hand-side evaluations, the cells of its finest run and the
  integrator tolerance it settled on, its own error estimate (space + time) and the true error of
  the inlet-flow history against a reference independent of the error control: runs on 128, 256
  and 512 cells at integrator tolerance 1e-10, the last two Richardson-extrapolated (the gap to the
  extrapolation of the first two is printed: an upper bound of the reference's error);
* the **baseline**: one run on 512 cells at integrator tolerance 1e-6 without error control (the
  last column: each call's time relative to it);
* **cost against cells**: one run at a fixed integrator tolerance for 64 ... 4096 cells: its time,
  right-hand-side evaluations (the integrator's steps: the same for a cost linear in the cells),
  the time per cell and evaluation, and the time per cell relative to the 256-cell run (a
  same-process baseline; below ~256 cells the Python overhead of a step dominates): flat means
  linear cost.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import tubefsi


def scene():
    tube = tubefsi.Tube(radius=2.5e-4, thickness=1e-4, length=0.05)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=1e5)
    chamber = tubefsi.Chamber.linear(1e-7, 1e-11)
    return fluid, wall, tube, dict(inlet_pressure=2e4, outlet=chamber)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--plot", metavar="PNG", help="also draw the work-precision chart into this file")
    args = parser.parse_args(argv)
    fluid, wall, tube, bc = scene()
    times = np.linspace(0.0, 2.0, 41)
    grids, ref_tol = ((32, 64, 128), 1e-8) if args.quick else ((128, 256, 512), 1e-10)
    runs = [tubefsi.evolve(fluid, wall, tube, times, rtol=ref_tol, cells=n, error_control=False, **bc).inlet_flow_rate[1:]
            for n in grids]
    q_ref = runs[2] + (runs[2] - runs[1]) / 3.0
    gap = np.max(np.abs(runs[1] + (runs[1] - runs[0]) / 3.0 - q_ref)) / np.max(np.abs(q_ref))
    print(f"reference: {grids} cells at integrator rtol {ref_tol:g}, extrapolated; bound on its error {gap:.2g}")
    # the same-process baseline: one run on 512 cells at integrator rtol 1e-6, no error control
    start = time.perf_counter()
    tubefsi.evolve(fluid, wall, tube, times, rtol=1e-6, cells=512, error_control=False, **bc)
    baseline = time.perf_counter() - start
    print(f"baseline: one run, 512 cells, integrator rtol 1e-6, no error control: {baseline:.3f} s")
    print(f"{'rtol':>8} {'time (s)':>9} {'rhs evals':>10} {'cells':>6} {'int. rtol':>10} {'estimate':>9} "
          f"{'(space':>8} {'time)':>8} {'true error':>10} {'t90 (s)':>9} {'/baseline':>9}")
    controlled = []                      # (rtol, time, estimate, true error) for the chart
    for rtol in ((1e-2, 1e-3) if args.quick else (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)):
        start = time.perf_counter()
        r = tubefsi.evolve(fluid, wall, tube, times, rtol=rtol, **bc)
        elapsed = time.perf_counter() - start
        error = np.max(np.abs(r.inlet_flow_rate[1:] - q_ref)) / np.max(np.abs(q_ref))
        controlled.append((rtol, elapsed, r.error_estimate, error))
        print(f"{rtol:8.0e} {elapsed:9.3f} {r.evaluations:10d} {r.cells:6d} {r.integrator_rtol:10.0e} "
              f"{r.error_estimate:9.2g} {r.space_error:8.2g} {r.time_error:8.2g} {error:10.2g} {r.settling_time(0.9):9.4f} {elapsed / baseline:9.2f}")
    print("\ncost against cells (integrator rtol 1e-6, no error control)")
    print(f"{'cells':>6} {'time (s)':>9} {'rhs evals':>10} {'us/(cell*eval)':>15} {'us/cell':>9} {'/ at 256':>9}")
    base = None
    for n in ((64, 128, 256) if args.quick else (64, 128, 256, 512, 1024, 2048, 4096)):
        start = time.perf_counter()
        r = tubefsi.evolve(fluid, wall, tube, times, rtol=1e-6, cells=n, error_control=False, **bc)
        elapsed = time.perf_counter() - start
        per_cell = elapsed / n * 1e6
        if n == 256:
            base = per_cell
        ratio = f"{per_cell / base:9.2f}" if base else f"{'-':>9}"
        print(f"{n:6d} {elapsed:9.3f} {r.evaluations:10d} {per_cell / r.evaluations:15.3f} {per_cell:9.1f} {ratio}")
    if args.plot:
        plot(args.plot, controlled, fixed_runs(fluid, wall, tube, times, bc, q_ref, args.quick), baseline)


def fixed_runs(fluid, wall, tube, times, bc, q_ref, quick):
    """Single runs without error control (cells, integrator rtol) -> (time, true error): what a
    user who picks a grid and a tolerance by hand gets, and does not know the error of."""
    out = []
    for n, tol in ((16, 1e-4), (32, 1e-5), (64, 1e-6), (128, 1e-7)) + (() if quick else ((256, 1e-8), (512, 1e-9))):
        start = time.perf_counter()
        r = tubefsi.evolve(fluid, wall, tube, times, rtol=tol, cells=n, error_control=False, **bc)
        elapsed = time.perf_counter() - start
        out.append((n, tol, elapsed, np.max(np.abs(r.inlet_flow_rate[1:] - q_ref)) / np.max(np.abs(q_ref))))
    return out


def plot(path, controlled, fixed, baseline):
    """The work-precision chart: the true error of the inlet-flow history against the wall time,
    for the error-controlled calls (with their own estimates) and single hand-picked runs."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
    rtol, elapsed, estimate, error = (np.array(c) for c in zip(*controlled))
    ax.loglog(elapsed, error, "o-", color="C0", label="evolve(rtol=...): true error")
    ax.loglog(elapsed, estimate, "o", mfc="none", color="C0", label="evolve(rtol=...): its estimate")
    for r, t, e in zip(rtol, elapsed, error):
        ax.annotate(f"rtol {r:.0e}", (t, e), textcoords="offset points", xytext=(6, -10), fontsize=8)
    n, tol, t_fixed, e_fixed = (np.array(c) for c in zip(*fixed))
    ax.loglog(t_fixed, e_fixed, "s--", color="C1", label="one run, cells and tolerance by hand (no estimate)")
    for k, t, e in zip(n, t_fixed, e_fixed):
        ax.annotate(f"{int(k)}", (t, e), textcoords="offset points", xytext=(-4, 6), fontsize=8, color="C1")
    ax.axvline(baseline, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel("wall time of the call (s)")
    ax.set_ylabel("relative error of the inlet-flow history")
    ax.set_title("Transient: a soft actuator inflating through its tube", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    ax.grid(True, which="both", alpha=0.3)
    fig.savefig(path, dpi=130)
    print(f"chart: {path}")


if __name__ == "__main__":
    main()
