r"""Cost of a batch of scenes in ``tubefsi.evolve`` against the same scenes one call each.

Run ``python benchmarks/transient_batch.py`` (a minute on two cores; ``--quick``: one tolerance,
fewer scenes). The scene is ``benchmarks/transient.py``'s actuator (a thick neo-Hookean tube,
a = 0.25 mm, t = 0.1 mm, L = 5 cm, mu = 100 kPa; a power-law fluid m = 0.017 Pa s^n, n = 0.7; a
linear chamber V0 = 0.1 ml, C = 10 ul/kPa; 21 output times over 1 s) at ten inlet pressures from
10 to 30 kPa.

Printed, for each setting: the wall time of one batched call and of the ten calls in a loop (the
same-process baseline), their ratio, the right-hand-side evaluations of each, and the largest
gap between a scene of the batch and its call alone (relative to the scene's largest inlet flow).
The settings: error control at ``rtol`` 1e-4 and 1e-6 (the batch refines for its worst scene),
and one run without error control on 64 cells at integrator tolerance 1e-6 (the per-step
overhead alone).
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
    return fluid, wall, tube, tubefsi.Chamber.linear(1e-7, 1e-11)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    fluid, wall, tube, chamber = scene()
    times = np.linspace(0.0, 1.0, 21)
    pressures = np.linspace(1e4, 3e4, 4 if args.quick else 10)
    settings = [dict(rtol=1e-4)] if args.quick else [dict(rtol=1e-4), dict(rtol=1e-6)]
    settings.append(dict(rtol=1e-6, cells=64, error_control=False))
    print(f"{len(pressures)} scenes: inlet pressures {pressures[0]:g} to {pressures[-1]:g} Pa")
    print(f"{'setting':>32} {'batch (s)':>10} {'loop (s)':>9} {'loop/batch':>10} {'rhs batch':>10} "
          f"{'rhs loop':>9} {'cells b/loop':>14} {'gap':>8}")
    for setting in settings:
        start = time.perf_counter()
        batch = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=pressures, outlet=chamber, **setting)
        t_batch = time.perf_counter() - start
        start = time.perf_counter()
        alone = [tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=float(p), outlet=chamber, **setting)
                 for p in pressures]
        t_loop = time.perf_counter() - start
        gap = max(float(np.max(np.abs(batch.inlet_flow_rate[k, 1:] - r.inlet_flow_rate[1:]))
                        / np.max(np.abs(r.inlet_flow_rate[1:]))) for k, r in enumerate(alone))
        cells = f"{batch.cells}/{min(r.cells for r in alone)}-{max(r.cells for r in alone)}"
        label = ", ".join(f"{k}={v}" for k, v in setting.items())
        print(f"{label:>32} {t_batch:10.3f} {t_loop:9.3f} {t_loop / t_batch:10.2f} {batch.evaluations:10d} "
              f"{sum(r.evaluations for r in alone):9d} {cells:>14} {gap:8.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
