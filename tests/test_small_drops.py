"""Pressure drops far below a loaded outlet (issue 11): the small-drop limit.

For :math:`\\Delta p \\ll p_{out}` the tube is uniform to first order, at the outlet radius
:math:`R_{out} = a\\,P^{-1}(p_{out})`, so :math:`q = Q(R_{out}, \\Delta p/L)`, the rigid-tube flow
(relative correction :math:`O(\\Delta p / (\\lambda P'(\\lambda)))`, below 1e-16 for these drops).
The reference is mpmath: the tube law of ``docs/theory.md`` inverted at 40 digits
(``tubefsi.testing.reference.tube_laws``) and the rigid-tube flows in closed form (Newtonian,
power law; Carreau–Yasuda at its zero-shear viscosity, the shear rates here being ~1e-15 1/s
and below). Before the fix a drop of 1e-60 Pa and below with a loaded outlet was a
ConvergenceError (Newton on ln F from the strain-difference start, which is 0 there, only
bisected), and the Carreau–Yasuda reproducer at 1e-14 Pa gave NaN.
"""

import math
import warnings

import pytest
from mpmath import mp, mpf, pi

from tubefsi import ModelValidityWarning, Tube, solve
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference.tube_laws import RefWall, stretch_at_pressure

TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
OUTLET = 87.6

FLUIDS = {
    "newtonian": dict(viscosity=1e-3),
    "power-law": dict(consistency=0.017, index=0.7),
    "carreau-yasuda": rheologies["carreau-yasuda"]._examples[0],
}
WALLS = {
    "thick-linear": (dict(youngs_modulus=6e3, poisson_ratio=0.5), "thick-linear"),
    "thick-neo-hookean": (dict(shear_modulus=2e3), "thick"),
    "thin-linear": (dict(youngs_modulus=3e4, poisson_ratio=0.45), "thin-linear"),
}


def _reference(fluid, wall, dp):
    with mp.workdps(40):
        ref = RefWall(WALLS[wall][1], WALLS[wall][0], mpf(TUBE.thickness) / mpf(TUBE.radius))
        radius = mpf(TUBE.radius) * stretch_at_pressure(ref, mpf(OUTLET))
        g = mpf(dp) / mpf(TUBE.length)
        params = FLUIDS[fluid]
        if fluid == "power-law":
            n, m = mpf(params["index"]), mpf(params["consistency"])
            q = pi * n / (3 * n + 1) * (g / (2 * m)) ** (1 / n) * radius ** (3 + 1 / n)
        else:
            mu = mpf(params.get("viscosity", params.get("zero_shear_viscosity")))
            q = pi * radius**4 * g / (8 * mu)
        return float(q)


@pytest.mark.parametrize("wall", sorted(WALLS))
@pytest.mark.parametrize("fluid", sorted(FLUIDS))
@pytest.mark.parametrize("dp", [1e-14, 1e-60, 1e-100, 1e-200])
def test_a_tiny_drop_on_a_loaded_outlet_is_the_rigid_flow_at_the_outlet_radius(fluid, wall, dp):
    model = walls[wall](**WALLS[wall][0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        sol = solve(rheologies[fluid](**FLUIDS[fluid]), model, TUBE, pressure_drop=dp, outlet_pressure=OUTLET)
    q = _reference(fluid, wall, dp)
    assert math.isfinite(sol.flow_rate)
    assert sol.flow_rate == pytest.approx(q, rel=1e-12)
    assert sol.inlet_pressure == pytest.approx(OUTLET + dp, rel=1e-15)
    # and back: the flow-controlled solve at that flow rate gives the drop
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        back = solve(rheologies[fluid](**FLUIDS[fluid]), model, TUBE, flow_rate=sol.flow_rate, outlet_pressure=OUTLET)
    assert back.pressure_drop == pytest.approx(dp, rel=1e-10)
