"""The one-batch solve of a broadcast call (``docs/theory.md``, "Error control"): every scene
from 13 or 17 integrand values (degree 12 on a short interval, else 16), accepted only where the
Chebyshev tail meets the tolerance.

References: mpmath (``tubefsi.testing.reference.power_law.flow_rate_cases``, 30 digits) for
the scenes it answers, and the adaptive Gauss–Kronrod path (scalar solves, another algorithm)
for a batch it must hand over (a stiff wall, large strains).
"""

from __future__ import annotations

import numpy as np
import pytest
from mpmath import mp

import tubefsi
from accuracy_helpers import ref_wall
from tubefsi.couplers import separated
from tubefsi.registry import rheologies, walls
from tubefsi.scene import make_scene
from tubefsi.testing.reference.power_law import flow_rate_cases


@pytest.fixture
def count(monkeypatch):
    """How many points the one-batch solve was offered and how many it answered."""
    seen = {"offered": 0, "solved": 0}
    real = separated.solve_integral

    def counting(*args, **kwargs):
        x, solved, short = real(*args, **kwargs)
        seen["offered"] += solved.size
        seen["solved"] += int(np.count_nonzero(solved))
        return x, solved, short

    monkeypatch.setattr(separated, "solve_integral", counting)
    return seen


def test_a_broadcast_of_thick_walls_meets_mpmath(count):
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
    assert count["offered"] == size and count["solved"] >= size - 8     # the path under test answered most
    for i, ref in exact.items():
        assert abs(sol.pressure_drop[i] / float(ref) - 1) < 1e-13


def test_a_stiff_batch_is_handed_to_the_adaptive_path(count):
    """Fung b = 20 at large strain: the interpolant's tail refuses, the adaptive path answers,
    and each entry equals its scalar solve (which runs the adaptive path alone)."""
    size = 70
    fluid = rheologies["power-law"](consistency=0.01, index=0.8)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    q = np.geomspace(1e-7, 1e-5, size)
    wall = walls["thick-fung"](shear_modulus=np.linspace(1e3, 1.2e3, size), stiffening=20.0)  # no shared table
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    assert count["offered"] == size and count["solved"] < size
    for i in (0, size // 2, size - 1):
        one = tubefsi.solve(fluid, walls["thick-fung"](shear_modulus=float(wall.shear_modulus[i]), stiffening=20.0),
                            tube, flow_rate=float(q[i]))
        assert abs(sol.pressure_drop[i] / one.pressure_drop - 1) < 1e-13


def test_short_intervals_take_degree_12_and_the_answer_is_the_points_own(monkeypatch):
    """Scenes with short intervals (small strain) are answered at degree 12, the others at 16
    (and a degree-12 miss is retried at 16, not handed on): both against mpmath at 1e-13, and
    each point's answer the same bits whichever batch it comes in (reversed, or a few of them)."""
    degrees = []
    real = separated.solve_integral

    def recording(*args, **kwargs):
        x, solved, short = real(*args, **kwargs)
        degrees.append((kwargs.get("degree"), solved.size, int(np.count_nonzero(solved))))
        return x, solved, short

    monkeypatch.setattr(separated, "solve_integral", recording)
    size = 72
    a, length, mu, m, tb = 2.0**-13, 1e-2, 2.0e4, 0.01, 0.3
    n = np.where(np.arange(size) % 2 == 0, 0.7, 0.9)
    stretch = np.geomspace(1.001, 1.45, size)              # ln(stretch) from 1e-3 to 0.37
    q = np.empty(size)
    exact = {}
    with mp.workdps(30):
        for i in range(size):
            qs, dps, _ = flow_rate_cases(ref_wall("thick-neo-hookean", tb), n[i], m, a, length, [stretch[i]])
            q[i] = qs[0]
            if i in (0, 20, size - 20, size - 1):
                exact[i] = dps[0]
    fluid = rheologies["power-law"](consistency=m, index=n)
    wall = walls["thick-neo-hookean"](shear_modulus=mu)
    tube = tubefsi.Tube(radius=a, thickness=tb * a, length=length)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    by_degree = {}
    for degree, offered, solved in degrees:
        by_degree[degree] = by_degree.get(degree, 0) + solved
    assert by_degree.get(12, 0) >= 10 and by_degree.get(16, 0) >= 10, degrees
    for i, ref in exact.items():
        assert abs(sol.pressure_drop[i] / float(ref) - 1) < 1e-13
    back = tubefsi.solve(rheologies["power-law"](consistency=m, index=n[::-1]), wall, tube, flow_rate=q[::-1])
    np.testing.assert_array_equal(back.pressure_drop[::-1], sol.pressure_drop)
    few = np.r_[0:8, size - 60:size]                        # 68 points, another mix of both degrees
    part = tubefsi.solve(rheologies["power-law"](consistency=m, index=n[few]), wall, tube, flow_rate=q[few])
    np.testing.assert_array_equal(part.pressure_drop, sol.pressure_drop[few])


def test_the_integrand_at_the_outlet_is_the_integrand_at_zero():
    """The linear guess's slope, computed without the exponentials of u = 0, is the integrand's
    value there to the bit, for array parameters and for a wall whose slope is generic."""
    rng = np.random.default_rng(2)
    size = 300
    tube = tubefsi.Tube(radius=rng.uniform(5e-5, 2e-4, size), thickness=rng.uniform(1e-5, 5e-5, size), length=1e-2)
    fluid = rheologies["power-law"](consistency=rng.uniform(0.005, 0.05, size), index=rng.uniform(0.4, 1.2, size))
    for wall in (walls["thick-neo-hookean"](shear_modulus=rng.uniform(1e3, 1e4, size)),
                 walls["thick-fung"](shear_modulus=2e3, stiffening=rng.uniform(0.5, 20.0, size)),
                 walls["thin-mooney-rivlin"](c1=1e3, c2=rng.uniform(0.0, 500.0, size))):
        scene = make_scene(fluid, wall, tube).flat((size,))
        engine = tubefsi.select_coupler(fluid, wall)
        points = scene.at(np.arange(size))
        np.testing.assert_array_equal(engine._integrand_at_outlet(points, (size,)),
                                      engine.integrand(points, np.zeros(size)))
