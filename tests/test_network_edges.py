"""A network that doubles cannot balance ends in a typed error that says why (issue 25: it was a
ZeroDivisionError inside the solver)."""

import pytest

import tubefsi
from tubefsi.registry import rheologies, walls


def test_tubes_in_series_beyond_double_precision_raise_a_convergence_error_that_says_why():
    # conductances 5 m against 0.1 mm radius: a ratio ~(5e4)^4 / 100 ~ 6e16, beyond 1/eps
    net = tubefsi.Network(rheology=rheologies["newtonian"](viscosity=1e-3))
    net.add_tube("a", "b", walls["rigid"](), tubefsi.Tube(radius=5.0, thickness=1.0, length=1.0))
    net.add_tube("b", "c", walls["rigid"](), tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2))
    net.set_pressure("a", 300.0).set_pressure("c", 0.0)
    with pytest.raises(tubefsi.ConvergenceError, match="conductances differ beyond double precision"):
        net.solve()


@pytest.mark.parametrize("q", [1e-9, 1e-13, 1e-15, 1e-20])
@pytest.mark.parametrize("branches", [1, 2])
def test_bingham_near_its_yield_drop_is_the_chained_single_tubes(q, branches):
    """A Bingham fluid at tiny inflows (the pressure drops just above each tube's yield drop, the
    flow ~ the square of the excess: the new-user review's 1e-15 m^3/s, once a stalled line
    search): in -> j -> (one or two outlets at 0 Pa). Reference: chained flow-controlled
    :func:`tubefsi.solve` calls from the outlets up (q / branches through each outlet tube, then q
    into j), 1e-11."""
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = rheologies["bingham"](yield_stress=0.5, plastic_viscosity=3.5e-3)
    net = tubefsi.Network(rheology=fluid)
    net.add_tube("in", "j", wall, tube)
    outlets = ["a", "b"][:branches]
    for node in outlets:
        net.add_tube("j", node, wall, tube)
        net.set_pressure(node, 0.0)
    result = net.set_inflow("in", q).solve()
    p_j = tubefsi.solve(fluid, wall, tube, flow_rate=q / branches, outlet_pressure=0.0).pressure_drop
    p_in = p_j + tubefsi.solve(fluid, wall, tube, flow_rate=q, outlet_pressure=p_j).pressure_drop
    assert result.pressure["j"] == pytest.approx(p_j, rel=1e-11)
    assert result.pressure["in"] == pytest.approx(p_in, rel=1e-11)
