"""Speed ratio of a vectorized flow curve against the chapter's method, in one process.

The chapter's method: for each flow rate, integrate the thick-wall deflection ODE
with ``scipy.integrate.odeint`` at its default tolerances (a lean, scalar,
pure-float right-hand side, so the baseline is not slowed by our own overhead),
then evaluate the tube law at the inlet (``tubefsi.testing.reference.chapter_baseline``,
shared with ``examples/work_precision.py``). tubefsi: one ``solve`` call on the whole
array. Prints time per point and the ratio; run ``python benchmarks/speed.py``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference.chapter_baseline import chapter_thick, chapter_thin

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
N_CURVE = 10_000
N_BASELINE = 200


def run(label, wall, baseline, n=0.7, m=0.017, mu=2e3, q_top=None):
    fluid = rheologies["power-law"](consistency=m, index=n)
    q_top = q_top or 0.9 * min(tubefsi.max_flow_rate(fluid, wall, TUBE), 2e-8)
    q = np.linspace(q_top / N_CURVE, q_top, N_CURVE)
    tubefsi.solve(fluid, wall, TUBE, flow_rate=q[:10])  # warm caches
    t0 = time.perf_counter()
    sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    ours = (time.perf_counter() - t0) / N_CURVE
    sample = q[:: N_CURVE // N_BASELINE]
    t0 = time.perf_counter()
    ref = np.array([baseline(qi, n, m, mu, TUBE)[0] for qi in sample])     # (pressure drop, displacement)
    theirs = (time.perf_counter() - t0) / sample.size
    err = np.max(np.abs(ref / sol.pressure_drop[:: N_CURVE // N_BASELINE] - 1))
    print(f"{label:38s} {sol.coupler_name:12s} {ours * 1e6:9.2f} us/pt {theirs * 1e6:9.1f} us/pt "
          f"ratio {theirs / ours:8.0f}x  (odeint rel. diff {err:.1e})")
    return theirs / ours


def main() -> int:
    print(f"{'scene':38s} {'coupler':12s} {'tubefsi':>15s} {'odeint':>15s}")
    r1 = run("thick neo-Hookean, power law n=0.7", walls["thick-neo-hookean"](shear_modulus=2e3), chapter_thick)
    r2 = run("thin neo-Hookean (ref.), power law n=0.7", walls["thin-neo-hookean"](shear_modulus=2e3),
             chapter_thin, q_top=1e-8)
    print(f"\nthick ratio {r1:.0f}x (contract >= 100x), closed form ratio {r2:.0f}x (contract >= 1000x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
