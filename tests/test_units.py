"""pint.Quantity arguments are converted to SI at the boundary (dimension checked), and a
Solution returns Quantities; skipped where pint is not installed."""

import math

import numpy as np
import pytest

import tubefsi
from tubefsi.registry import rheologies, walls

pint = pytest.importorskip("pint")
U = pint.UnitRegistry()


def test_quantities_in_give_the_si_answer():
    tube_q = tubefsi.Tube(radius=100 * U.um, thickness=30 * U.um, length=1 * U.cm)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    for got, want in zip((tube_q.radius, tube_q.thickness, tube_q.length), (1e-4, 3e-5, 1e-2)):
        assert got == pytest.approx(want, rel=4e-16)
    fluid_q = rheologies["power-law"](consistency=17 * U("mPa*s**0.7"), index=0.7)
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall_q = walls["thick-neo-hookean"](shear_modulus=2 * U.kPa)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.array([1.0, 6.0]) * U("uL/min")                     # 1 uL/min = 1e-9/60 m^3/s
    a = tubefsi.solve(fluid_q, wall_q, tube_q, flow_rate=q, outlet_pressure=10 * U.Pa)
    b = tubefsi.solve(fluid, wall, tube, flow_rate=np.array([1.0, 6.0]) * 1e-9 / 60, outlet_pressure=10.0)
    np.testing.assert_allclose(a.pressure_drop, b.pressure_drop, rtol=1e-13)
    assert a.pressure(0.5 * U.cm)[0] == pytest.approx(b.pressure(5e-3)[0], rel=1e-13)


def test_wrong_dimensions_are_invalid_parameters():
    with pytest.raises(tubefsi.InvalidParameterError, match="radius must be a quantity in m"):
        tubefsi.Tube(radius=100 * U.Pa, thickness=3e-5, length=1e-2)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    with pytest.raises(tubefsi.InvalidParameterError, match="flow_rate must be a quantity in m\\^3/s"):
        tubefsi.solve(rheologies["newtonian"](viscosity=1e-3), "rigid", tube, flow_rate=3 * U.Pa)
    with pytest.raises(tubefsi.InvalidParameterError, match="shear_modulus"):
        walls["thick-neo-hookean"](shear_modulus=2 * U.m)


def test_solution_returns_quantities():
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    sol = tubefsi.solve(rheologies["newtonian"](viscosity=1e-3), "rigid", tube, flow_rate=1e-9)
    out = sol.to_quantities(U)
    hp = 8 * 1e-3 * 1e-2 * 1e-9 / (math.pi * 1e-4 ** 4)          # Hagen–Poiseuille, Pa
    assert out["pressure_drop"].to("kPa").magnitude == pytest.approx(hp / 1e3, rel=1e-13)
    assert out["flow_rate"].to("uL/min").magnitude == pytest.approx(60.0, rel=1e-13)      # 1e-9 m^3/s = 60 uL/min
    assert out["inlet_radius"].to("um").magnitude == pytest.approx(100.0, rel=1e-15)
