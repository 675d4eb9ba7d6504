"""Speed ratio of a vectorized flow curve against the chapter's method, in one process.

The chapter's method: for each flow rate, integrate the thick-wall deflection ODE
with ``scipy.integrate.odeint`` at its default tolerances (a lean, scalar,
pure-float right-hand side, so the baseline is not slowed by our own overhead),
then evaluate the tube law at the inlet. tubefsi: one ``solve`` call on the whole
array. Prints time per point and the ratio; run ``python benchmarks/speed.py``.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from scipy.integrate import odeint

import tubefsi
from tubefsi.registry import rheologies, walls

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
N_CURVE = 10_000
N_BASELINE = 200


def chapter_thick(q, n, m, mu, tube):
    """Pressure drop by odeint on d lam/dz = -G(q, a lam) / P'(lam) (thick neo-Hookean / MR)."""
    a, L, tb = tube.radius, tube.length, tube.reduced_thickness
    d = tb * (2 + tb)
    phi = 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n
    k = 3 * n + 1

    def rhs(lam, z):
        lam2 = lam * lam
        slope = mu * lam * d * (lam2 * (d + 2) + d) / (lam2 * lam2 * (lam2 + d) ** 2)
        return -phi * (a * lam) ** -k / slope

    lam_in = odeint(rhs, 1.0, [L, 0.0])[-1, 0]
    x = lam_in**2 - 1
    b = (1 + tb) ** 2
    return 0.5 * mu * (math.log1p(x * d / (b + x)) + x * d / ((1 + x) * (b + x)))


def chapter_thin(q, n, m, mu, tube):
    """Thin reference-thickness wall by odeint on the same deflection ODE."""
    a, L, tb = tube.radius, tube.length, tube.reduced_thickness
    phi = 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n
    k = 3 * n + 1

    def rhs(lam, z):
        return -phi * (a * lam) ** -k / (mu * tb * (1 + 3 * lam**-4))

    lam_in = odeint(rhs, 1.0, [L, 0.0])[-1, 0]
    return mu * tb * (lam_in - lam_in**-3)


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
    ref = np.array([baseline(qi, n, m, mu, TUBE) for qi in sample])
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
