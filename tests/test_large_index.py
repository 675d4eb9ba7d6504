"""A power law of a large index (issue 11): :math:`a^{3n+1}` leaves the doubles (n >= 26 at
a = 1e-4 m) though the answer does not; ``solve`` then works in units of the tube's radius
(``tubefsi.couplers.rescaled``). References: mpmath at 40 digits, the tube laws of
``docs/theory.md`` (``tubefsi.testing.reference.tube_laws``) and the separated integral
:math:`L = \\int_1^{\\lambda_{in}} P'(\\lambda)/G(q, a\\lambda)\\,d\\lambda` with
:math:`G = (2m/R)[(3n+1)q/(\\pi n R^3)]^n`, by mpmath's quadrature and root finder."""

import math
import warnings

import numpy as np
import pytest
from mpmath import findroot, mp, mpf, pi, quad

from tubefsi import InvalidParameterError, Tube, max_flow_rate, solve
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference.tube_laws import RefWall

TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
M = 0.017
WALLS = {"thick-neo-hookean": ("thick", dict(shear_modulus=2e3)),
         "thin-linear": ("thin-linear", dict(youngs_modulus=6e3, poisson_ratio=0.5))}


def _reference(n, q, wall):
    """(pressure drop, inlet strain) of flow rate ``q`` (mpmath, 40 digits)."""
    with mp.workdps(40):
        a, t, length, m, n, q = (mpf(x) for x in (TUBE.radius, TUBE.thickness, TUBE.length, M, n, q))
        kind, params = WALLS[wall]
        law = RefWall(kind, params, t / a)

        def gradient(radius):
            return 2 * m * ((3 * n + 1) * q / (pi * n * radius**3)) ** n / radius

        def excess(x):
            return quad(lambda s: law.dP(s) / gradient(a * s), [1, x]) / length - 1

        lam = findroot(excess, 1 + length * gradient(a) / law.dP(1), verify=False)
        assert abs(excess(lam)) < mpf(10) ** -25
        return float(law.P(lam)), float(lam - 1)


@pytest.mark.parametrize("wall", sorted(WALLS))
@pytest.mark.parametrize("n", [26.0, 30.0, 40.0])
def test_a_large_index_is_solved_to_the_reference(n, wall):
    fluid = rheologies["power-law"](consistency=M, index=n)
    model = walls[wall](**WALLS[wall][1])
    dp, strain = _reference(n, 1e-12, wall)
    sol = solve(fluid, model, TUBE, flow_rate=1e-12)
    assert sol.pressure_drop == pytest.approx(dp, rel=1e-12)
    assert sol.inlet_displacement == pytest.approx(TUBE.radius * strain, rel=1e-10)
    back = solve(fluid, model, TUBE, pressure_drop=dp)
    assert back.flow_rate == pytest.approx(1e-12, rel=1e-11)
    # the profile runs from the inlet to the outlet pressure and falls; the gradient at the
    # inlet is G(q, R_in), the radius the inlet radius
    z = np.linspace(0.0, TUBE.length, 5)
    p = sol.pressure(z)
    assert p[0] == pytest.approx(dp, rel=1e-12) and p[-1] == 0.0 and np.all(np.diff(p) < 0)
    assert sol.radius(0.0) == pytest.approx(sol.inlet_radius, rel=1e-14)
    assert sol.pressure_gradient(0.0) == pytest.approx(fluid.pressure_gradient(1e-12, sol.inlet_radius), rel=1e-14)
    assert np.isfinite(sol.dpressure_drop_dflow_rate) and sol.dpressure_drop_dflow_rate > 0
    assert math.isinf(max_flow_rate(fluid, model, TUBE))      # n >= 1: no maximum flow rate


@pytest.mark.parametrize("n", [26.0, 30.0, 60.0])
def test_a_rigid_tube_is_hagen_poiseuille_in_closed_form(n):
    with mp.workdps(40):
        a, length, m, nn, q = (mpf(x) for x in (TUBE.radius, TUBE.length, M, n, "1e-12"))
        dp = float(length * 2 * m * ((3 * nn + 1) * q / (pi * nn * a**3)) ** nn / a)
    fluid = rheologies["power-law"](consistency=M, index=n)
    assert solve(fluid, walls["rigid"](), TUBE, flow_rate=1e-12).pressure_drop == pytest.approx(dp, rel=1e-13)
    assert fluid.pressure_gradient(1e-12, TUBE.radius) == pytest.approx(dp / TUBE.length, rel=1e-13)
    assert solve(fluid, walls["rigid"](), TUBE, pressure_drop=dp).flow_rate == pytest.approx(1e-12, rel=1e-13)


def test_arrays_of_loads_and_beyond_the_doubles():
    fluid = rheologies["power-law"](consistency=M, index=30.0)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.array([5e-13, 1e-12, 1.2e-12])
    sol = solve(fluid, wall, TUBE, flow_rate=q)
    for qi, dpi in zip(q, sol.pressure_drop):
        assert dpi == pytest.approx(_reference(30.0, qi, "thick-neo-hookean")[0], rel=1e-12)
    # a flow rate whose pressure drop is not a double stays a typed error
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InvalidParameterError):
            solve(fluid, walls["rigid"](), TUBE, flow_rate=1.0)
        with pytest.raises(InvalidParameterError):
            solve(fluid, wall, TUBE, flow_rate=1.0)
