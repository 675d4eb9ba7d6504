"""Notebook summaries (issue 27, item 8): a Solution, a network result and a model show the scene,
the load and the key results with units as HTML. References: the objects' own public values,
formatted independently here."""

from __future__ import annotations

import html

import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.walls import WallModel

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
WALL = walls["thick-neo-hookean"](shear_modulus=2e3)


def test_a_solution_shows_its_load_results_models_and_tube():
    sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=1e-9)
    text = html.unescape(sol._repr_html_())
    for expected in ("flow-controlled", f"{sol.pressure_drop:.6g} Pa", f"{sol.inlet_radius:.6g} m", "1e-09 m^3/s",
                     "PowerLaw ('power-law')", "0.017 Pa s^n", "ThickNeoHookean ('thick-neo-hookean')", "2000 Pa",
                     "0.0001 m", "'quadrature'"):
        assert expected in text, expected


def test_an_array_solution_shows_shapes_ranges_and_infeasible_points():
    q_max = tubefsi.max_flow_rate(FLUID, WALL, TUBE)
    sol = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=np.array([0.1, 0.5, 2.0]) * q_max, on_infeasible="nan")
    text = html.unescape(sol._repr_html_())
    assert "shape (3,)" in text and "array (3,)" in text and "2 of 3 points" in text


class Plain(WallModel):
    """A wall written as a plain class."""

    def __init__(self, k=1e3):
        self.k = k

    def _pressure(self, stretch, tb):
        return self.k * tb * (stretch - 1.0)


def test_models_show_their_parameters_and_a_plain_class_its_name():
    assert "small-strain shear modulus" in WALL._repr_html_()
    assert "consistency" in FLUID._repr_html_()
    assert "Plain" in Plain()._repr_html_()


def test_a_network_result_shows_its_size_and_the_first_rows_of_its_tables():
    net = tubefsi.Network(rheology=FLUID)
    for j in range(12):
        net.add_tube(j, j + 1, WALL, TUBE)
    net.set_pressure(0, 100.0).set_pressure(12, 0.0)
    result = net.solve()
    text = html.unescape(result._repr_html_())
    assert "NetworkSolution" in text and "tubes</td><td>12" in text and "… 4 more" in text
    assert f"{result.tube_table()['flow_rate'][0]:.6g} m^3/s" in text
