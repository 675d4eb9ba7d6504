"""The one-batch solve of a broadcast call (``docs/theory.md``, "Error control"): every scene
from 13 or 17 integrand values (degree 12 on a short interval, else 16), accepted only where the
Chebyshev tail meets the tolerance.

References: mpmath (``tubefsi.testing.reference.power_law.flow_rate_cases``, 30 digits) for
the scenes it answers, and the adaptive Gauss–Kronrod path (scalar solves, another algorithm)
for a batch it must hand over (a stiff wall, large strains).
"""

from __future__ import annotations

import numpy as np
from mpmath import mp

import tubefsi
from accuracy_helpers import ref_wall
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference.power_law import flow_rate_cases


def test_a_broadcast_of_thick_walls_meets_mpmath():
    """80 scenes (t/a, n and the inlet stretch differ), six of them against mpmath at 1e-13."""
    rng = np.random.default_rng(11)
    size = 80
    a, length, mu, m = 2.0**-13, 1e-2, 2.0e4, 0.01
    tb = rng.choice([0.1, 0.25, 0.5], size)
    n = rng.choice([0.6, 0.8, 1.0], size)
    stretch = rng.uniform(1.02, 1.4, size)
    q = np.empty(size)
    exact = {}
    with mp.workdps(30):
        for i in range(size):
            qs, dps, _ = flow_rate_cases(ref_wall("thick-neo-hookean", tb[i]), n[i], m, a, length, [stretch[i]])
            q[i] = qs[0]
            if i < 6:
                exact[i] = dps[0]
    fluid = rheologies["power-law"](consistency=m, index=n)
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    sol = tubefsi.solve(fluid, wall, tubefsi.Tube(radius=a, thickness=tb * a, length=length), flow_rate=q)
    for i, ref in exact.items():
        assert abs(sol.pressure_drop[i] / float(ref) - 1) < 1e-13


def test_a_stiff_batch_is_handed_to_the_adaptive_path():
    """Demiray b = 20 at large strain: the interpolant's tail refuses, the adaptive path answers,
    and each entry equals its scalar solve (which runs the adaptive path alone)."""
    size = 70
    fluid = rheologies["power-law"](consistency=0.01, index=0.8)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    q = np.geomspace(1e-7, 1e-5, size)
    wall = walls["thick-demiray"](shear_modulus=np.linspace(1e3, 1.2e3, size), stiffening=20.0)  # no shared table
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    for i in (0, size // 2, size - 1):
        one = tubefsi.solve(fluid, walls["thick-demiray"](shear_modulus=float(wall.shear_modulus[i]), stiffening=20.0),
                            tube, flow_rate=float(q[i]))
        assert abs(sol.pressure_drop[i] / one.pressure_drop - 1) < 1e-13
