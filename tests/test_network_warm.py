"""A warm start for sweeps (issue 28, item 5): ``Network.solve(initial=previous)`` starts Newton's
method from a previous solution's pressures. The contract: the same answer as the cold start (to
the solver's tolerance; the reference is the cold solve of the same network, itself checked
against independent references in test_network.py) in fewer iterations for a small step."""

from __future__ import annotations

import numpy as np
import pytest

from tubefsi import InvalidParameterError, Network, Tube
from tubefsi.registry import rheologies, walls


def _tree():
    fluid = rheologies["power-law"](consistency=0.01, index=0.7)
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    n = 30
    child = np.arange(1, n + 1)
    parent = (child - 1) // 2
    radii = 1e-4 * np.random.default_rng(1).uniform(0.8, 1.2, n)
    net = Network(rheology=fluid).add_tubes(parent, child, wall, Tube(radius=radii, thickness=3e-5, length=1e-2))
    for leaf in sorted(set(child.tolist()) - set(parent.tolist())):
        net.set_pressure(leaf, 0.0)
    return net


def test_a_warm_start_gives_the_same_answer_in_fewer_iterations():
    net = _tree().set_pressure(0, 800.0)
    previous = net.solve()
    net.set_pressure(0, 800.1)                        # the next point of a fine sweep
    cold = net.solve()
    warm = net.solve(initial=previous)
    np.testing.assert_allclose(warm.pressures, cold.pressures, rtol=1e-13)
    np.testing.assert_allclose(warm.flow_rates, cold.flow_rates, rtol=1e-12)
    assert warm.residual <= 1e-13
    assert warm.iterations < cold.iterations
    # a mapping node -> pressure works the same; nodes it does not know are ignored
    again = net.solve(initial={**previous.pressure, "not a node": 1.0})
    assert again.iterations == warm.iterations
    np.testing.assert_array_equal(again.pressures, warm.pressures)


def test_a_warm_start_from_the_answer_takes_no_iteration():
    net = _tree().set_pressure(0, 500.0)
    result = net.solve()
    assert net.solve(initial=result).iterations <= 1


@pytest.mark.parametrize("initial", [[1.0, 2.0], 3.0, {0: -1.0}, {1: float("nan")}, {1: "high"}])
def test_a_bad_initial_names_it(initial):
    net = _tree().set_pressure(0, 500.0)
    with pytest.raises(InvalidParameterError, match="initial"):
        net.solve(initial=initial)
