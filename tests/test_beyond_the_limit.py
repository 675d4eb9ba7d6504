"""Points beyond the maximum flow rate in a broadcast call: marked (``on_infeasible="nan"``) or
raised exactly there, whichever route tells them — a screening estimate of J(inf) before any
solve (far beyond), J(inf) to the coupler's own tolerance (near the limit) — and the feasible
points are the loop of scalar solves.

References: the maximum flow rate and J(inf) from mpmath (``tubefsi.testing.reference.power_law``:
closed forms or a 30-digit quadrature of the tube law), never from the code under test; the
feasible points against independent scalar solves.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from mpmath import mpf

import tubefsi
from tubefsi.couplers import Quadrature, _inverse
from tubefsi.registry import rheologies, walls
from tubefsi.scene import Scene
from tubefsi.testing.reference.power_law import ref_J_inf, ref_q_max
from tubefsi.testing.reference.tube_laws import RefWall

DPS = 30
pytestmark = pytest.mark.usefixtures("mp_precision")

A = 2.0**-13                     # radius (m): t = tb * A and t / A are exact
#: flow rate / q_max; below the limit a near factor needs a small n (the inlet stretch of
#: 1 - 1e-9 at n = 0.9 is beyond the solver's range, 1e15)
BEYOND = (1 + 1e-9, 1 + 1e-6, 1 + 1e-4, 1 + 1e-3, 1.01, 1.1, 2.0)
BELOW_ANY_N = (0.5, 0.9, 1 - 1e-3)
BELOW_SMALL_N = (1 - 1e-6, 1 - 1e-9)

#: the library's wall, its reference kind and the coupler that answers (the thin current-thickness
#: wall's default is the closed form: the quadrature coupler is asked for the screened route)
WALLS = {"thick": ("thick-neo-hookean", {}, "thick", "auto"),
         "thin-current": ("thin-neo-hookean", {"thickness_convention": "current"}, "thin-current", "quadrature")}


def _cases(rng, size):
    """Per point: n, t/a, mu, L and a factor of q_max; each factor at least twice."""
    n = rng.choice([0.4, 0.5, 0.6, 0.7, 0.8, 0.9], size)
    tb = rng.choice([0.1, 0.3, 1.0], size)
    mu = rng.uniform(1e3, 1e4, size)
    length = rng.uniform(5e-3, 2e-2, size)
    factors = np.resize(np.array(BEYOND + BELOW_ANY_N + BELOW_SMALL_N), size)
    rng.shuffle(factors)
    small = np.isin(factors, BELOW_SMALL_N)
    n[small] = rng.choice([0.4, 0.5], int(small.sum()))
    return n, tb, mu, length, factors


def _reference_q_max(kind, n, tb, mu, length, m):
    return np.array([float(ref_q_max(RefWall(kind, {"shear_modulus": float(mu_i)}, mpf(tb_i)), n_i, m, A, L_i))
                     for n_i, tb_i, mu_i, L_i in zip(n, tb, mu, length)])


@pytest.mark.parametrize("name", tuple(WALLS))
def test_a_broadcast_marks_exactly_the_points_beyond_the_maximum_flow_rate(name):
    reg_name, params, kind, coupler = WALLS[name]
    m = 0.01
    n, tb, mu, length, factors = _cases(np.random.default_rng(17), 48)
    q_max = _reference_q_max(kind, n, tb, mu, length, m)
    q = q_max * factors
    fluid = rheologies["power-law"](consistency=m, index=n)
    wall = walls[reg_name](shear_modulus=mu, **params)
    tube = tubefsi.Tube(radius=A, thickness=tb * A, length=length)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)    # R/L near the limit
        sol = tubefsi.solve(fluid, wall, tube, flow_rate=q, on_infeasible="nan", coupler=coupler)
        beyond = factors > 1
        np.testing.assert_array_equal(sol.feasible, ~beyond)
        assert np.all(np.isnan(sol.pressure_drop[beyond])) and np.all(np.isfinite(sol.pressure_drop[~beyond]))
        for i in np.flatnonzero(~beyond)[::3]:          # the feasible points: the loop of scalar solves
            one = tubefsi.solve(rheologies["power-law"](consistency=m, index=float(n[i])),
                                walls[reg_name](shear_modulus=float(mu[i]), **params),
                                tubefsi.Tube(radius=A, thickness=float(tb[i]) * A, length=float(length[i])),
                                flow_rate=float(q[i]), coupler=coupler)
            assert sol.pressure_drop[i] == pytest.approx(one.pressure_drop, rel=1e-12)
        # without "nan", the first point beyond raises, with its limit
        with pytest.raises(tubefsi.NoSteadyStateError) as info:
            tubefsi.solve(fluid, wall, tube, flow_rate=q, coupler=coupler)
    first = int(np.argmax(beyond))
    assert info.value.limit == pytest.approx(q_max[first], rel=1e-12)


def test_the_screening_estimate_of_j_infinity_bounds_its_error():
    """The screen (J(inf) to 1e-2 from two wide panels) against mpmath: its error estimate bounds
    its error, and beyond_limit tells each target from J(inf) as the reference does."""
    rng = np.random.default_rng(5)
    size = 24
    n = rng.uniform(0.3, 0.95, size)
    tb = rng.choice([0.05, 0.3, 1.0, 3.0], size)
    mu = 2.0e3
    k = 3 * n + 1
    j_ref = np.array([float(ref_J_inf(RefWall("thick", {"shear_modulus": mu}, mpf(t)), 3 * mpf(n_i) + 1))
                      for n_i, t in zip(n, tb)]) * A**k
    scene = Scene(rheology=rheologies["power-law"](consistency=0.01, index=n),
                  wall=walls["thick-neo-hookean"](shear_modulus=mu),
                  tube=tubefsi.Tube(radius=A, thickness=tb * A, length=1e-2)).flat((size,))
    engine, index = Quadrature(), np.arange(size)
    screen = _inverse.j_infinity(engine, scene, index, rtol=1e-2)
    assert np.all(np.abs(screen.value - j_ref) <= screen.error)
    assert np.all(screen.error <= 1e-2 * screen.value)
    for delta in (1e-9, 1e-6, 1e-3, 0.1):
        for sign in (1, -1):
            over, _ = _inverse.beyond_limit(engine, scene, j_ref * (1 + sign * delta), index)
            np.testing.assert_array_equal(over, np.full(size, sign > 0))
