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
