"""The one-batch solve of a broadcast call (``docs/theory.md``, "Error control"): every scene
from 13 or 17 integrand values (degree 12 on a short interval, else 16; 24, then 32, where the
tail still misses), accepted only where the Chebyshev tail meets the tolerance.

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


def test_a_tail_that_misses_at_degree_16_is_answered_at_a_higher_degree(monkeypatch):
    """Strains of 35-60 % in a thick neo-Hookean wall (t/a = 0.5): the wall's slope varies enough
    over the interval that the degree-16 interpolant's tail misses 1e-14; the one batch answers at
    degree 24 or 32 on the same interval instead of handing the points to safeguarded Newton (which
    is not called), each against mpmath (30 digits) to 1e-13."""
    from tubefsi.couplers import _inverse

    def refuse(*args, **kwargs):
        raise AssertionError("safeguarded Newton was called")

    monkeypatch.setattr(_inverse, "newton", refuse)
    a, length, m, n, tb = 1e-4, 1e-2, 0.05, 0.6123, 0.5
    stretch = [1.35, 1.45, 1.6]
    with mp.workdps(30):
        q, dps, _ = flow_rate_cases(ref_wall("thick-neo-hookean", tb), n, m, a, length, stretch)
    fluid = rheologies["power-law"](consistency=m, index=n)
    wall = walls["thick-neo-hookean"](shear_modulus=2.0e4)       # the reference wall's
    sol = tubefsi.solve(fluid, wall, tubefsi.Tube(radius=a, thickness=tb * a, length=length),
                        flow_rate=np.array([float(x) for x in q]))
    for got, ref in zip(sol.pressure_drop, dps):
        assert abs(got / float(ref) - 1) < 1e-13
