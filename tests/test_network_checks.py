"""The checks and messages of the Network's public methods and of its plot (issue 28, a
new user's review): every mistake an InvalidParameterError (or KeywordError) naming the
argument, names shown as names, counts as counts."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

import tubefsi
from tubefsi import InvalidParameterError, KeywordError
from tubefsi.registry import rheologies, walls

matplotlib.use("Agg")

NEWTONIAN = rheologies["newtonian"](viscosity=3.5e-3)
WALL = walls["thin-linear"](youngs_modulus=2e5, poisson_ratio=0.5)
TUBE = tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05)


def _y():
    net = tubefsi.Network(rheology=NEWTONIAN)
    net.add_tube("in", "j", WALL, TUBE).add_tube("j", "a", WALL, TUBE).add_tube("j", "b", WALL, TUBE)
    return net


@pytest.mark.parametrize("call, message", [
    (lambda n: n.add_tube("in", "j", WALL, TUBE), r"name must be a name no other tube has \(got \('in', 'j'\)\)"),
    (lambda n: n.remove_tube(("x", "y")), r"name must be a name of one of the network's tubes \(got \('x', 'y'\)\)"),
    (lambda n: n.set_pressures(["a", "b"], [1.0, 2.0, 3.0]), r"pressures must be a number or an array of length 2 "
                                                              r"\(one per node\) \(got array of shape \(3,\)\)"),
    (lambda n: n.set_inflow("a", 1e-6).set_pressure("a", 0.0), "it has an inflow already"),
    (lambda n: n.add_tubes(["x", "y"], ["z"], WALL, TUBE), "v must be a sequence of 2 node names, as long as u; "
                                                           "it has 1"),
    (lambda n: n.add_tube(["a"], "c", WALL, TUBE), r"u must be a hashable node name .*\(got \['a'\]\)"),
    (lambda n: n.add_tube("a", "c", WALL, TUBE, name=["x"]), r"name must be a hashable name"),
    (lambda n: n.add_tubes(np.array([["x", "y"]]), ["z"], WALL, TUBE), r"u must be a 1-D sequence of names "
                                                                       r"\(got array of shape \(1, 2\)\)"),
    (lambda n: n.add_tubes(["x", "y"], ["z", "w"], WALL, TUBE, external_pressure=[1.0, 2.0, 3.0]),
     r"external_pressure must be a number or an array of length 2 \(got array of shape \(3,\)\)"),
    (lambda n: n.set_position("a", (1,)), r"xy must be a point \(x, y\) or \(x, y, z\)"),
    (lambda n: n.set_position("a", (1.0, np.nan)), r"xy must be a point"),
    (lambda n: n.set_position("a", "xy"), r"xy must be a point"),
    (lambda n: n.set_position(["a"], (0, 0)), r"node must be a hashable node name \(got \['a'\]\)"),
])
def test_mistakes_name_the_argument_and_show_names_as_names(call, message):
    """Tuple names were shown as "array of shape (2,)", set_pressures' count as the shape of the
    shape; set_position raised a bare IndexError and took NaN and unknown nodes; an unhashable
    node gave "TypeError: unhashable type"."""
    with pytest.raises(InvalidParameterError, match=message):
        call(_y())


def test_a_numpy_integer_max_iterations_is_an_integer():
    net = _y().set_inflow("in", 1e-6).set_pressure("a", 0.0).set_pressure("b", 0.0)
    assert net.solve(max_iterations=np.int64(50)).pressures.tolist() == net.solve().pressures.tolist()
    for bad in (0, 2.5, True):
        with pytest.raises(InvalidParameterError, match="max_iterations must be an integer >= 1"):
            net.solve(max_iterations=bad)


def test_add_tubes_orders_nodes_as_add_tube_does():
    """A loop of add_tube and one add_tubes over the same tubes give the nodes in the same order
    (first appearance, u[0], v[0], u[1], ...), so the node arrays of their solutions align."""
    u, v = ["t0", "b0", "t0", "t1"], ["t1", "b1", "b0", "b1"]
    one = tubefsi.Network(rheology=NEWTONIAN)
    for a, b in zip(u, v):
        one.add_tube(a, b, WALL, TUBE)
    bulk = tubefsi.Network(rheology=NEWTONIAN).add_tubes(u, v, WALL, TUBE)
    assert bulk.nodes == one.nodes == ["t0", "t1", "b0", "b1"]


def test_a_point_set_in_3d_is_drawn_in_the_x_y_plane():
    net = _y().set_inflow("in", 1e-6).set_pressure("a", 0.0).set_pressure("b", 0.0)
    for node, xyz in zip(net.nodes, [(0, 0, 0), (1, 0, 5), (2, 1, 5), (2, -1, 5)]):
        net.set_position(node, xyz)
    ax = net.solve().plot()
    segments = ax.collections[0].get_segments()
    assert [s.tolist() for s in segments] == [[[0, 0], [1, 0]], [[1, 0], [2, 1]], [[1, 0], [2, -1]]]


@pytest.mark.parametrize("kwargs, error, message", [
    ({"colour": "pressure"}, KeywordError, "colour"),
    ({"cmap": "nope"}, InvalidParameterError, "cmap must be a matplotlib Colormap"),
    ({"max_width": -1}, InvalidParameterError, r"max_width must be in \(0, inf\)"),
    ({"max_width": np.nan}, InvalidParameterError, "max_width"),
    ({"positions": {"in": (0, 0), "j": (1, 0), "a": (2, 1), "b": (2,)}}, InvalidParameterError,
     r"positions\['b'\] must be a point"),
    ({"positions": [(0, 0)]}, InvalidParameterError, "positions must be a mapping"),
])
def test_plot_arguments_are_checked(kwargs, error, message):
    """plot(cmap="nope") and 3-D or short positions raised matplotlib's ValueError, plot(colour=)
    a plain TypeError, and plot(max_width=-1) drew nothing."""
    result = _y().set_inflow("in", 1e-6).set_pressure("a", 0.0).set_pressure("b", 0.0).solve()
    with pytest.raises(error, match=message):
        result.plot(**kwargs)
