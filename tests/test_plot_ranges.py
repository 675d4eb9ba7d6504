"""Default plot ranges come from the physics, never from a numerical guard (issue 27, item 1).

A stiffening wall (HGO, Demiray, a user's exponential law) has a "limit pressure" only where double
precision ends (~1e260 Pa); drawn, it flattened every curve onto the axis. References: the
pressures the plotted walls give at the plotted stretches (the axis must hold them, and no more
than a few times them), and the small-strain modulus that bounds the default stretch range.
"""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi.registry import rheologies, walls  # noqa: E402
from tubefsi.walls import WallModel  # noqa: E402
from tubefsi.walls.hgo import PRESETS  # noqa: E402

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)


class Exponential(WallModel):
    """A user's exponential tube law, written as a plain class: P = k (e^{b(lam - 1)} - 1)."""

    def __init__(self, k=500.0, b=12.0):
        self.k, self.b = k, b

    def _pressure(self, stretch, tb):
        return self.k * tb * np.expm1(self.b * (stretch - 1.0))


def stiffening_walls():
    out = [("thick-hgo rabbit media", walls["thick-hgo"](**PRESETS["rabbit-carotid-media"])),
           ("user exponential", Exponential())]
    for name in ("thick-demiray", "thin-demiray", "thin-hgo"):
        if name in walls:
            out.append((name, walls[name](**walls[name]._examples[0])))
    return out


@pytest.mark.parametrize("name, wall", stiffening_walls(), ids=[n for n, _ in stiffening_walls()])
def test_a_stiffening_walls_tube_law_fills_its_axes(name, wall):
    ax = wall.plot(0.3)
    try:
        curve = ax.get_lines()[0]
        lam, p = curve.get_xdata(), curve.get_ydata()
        top = ax.get_ylim()[1]
        assert top <= 1.2 * np.max(p)                 # the axis is the curve's, not a guard's
        scale = wall.pressure(lam[-1], 0.3) / p[-1]  # Pa per axis unit
        k0 = wall.small_strain_modulus(0.3)
        # the range ends at 3 or where the law reaches 20 small-strain moduli, whichever is first
        assert lam[-1] <= 3.0 and p[-1] * scale <= 20 * k0 * (1 + 1e-9) + 1e-12
        assert lam[-1] == 3.0 or math.isclose(p[-1] * scale, 20 * k0, rel_tol=1e-6)
    finally:
        plt.close(ax.figure)


def test_a_physical_limit_pressure_is_still_drawn():
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    ax = wall.plot(0.3)
    try:
        lim = wall.limit_pressure(0.3)
        scale = wall.pressure(ax.get_lines()[0].get_xdata()[-1], 0.3) / ax.get_lines()[0].get_ydata()[-1]
        assert any(np.allclose(line.get_ydata(), lim / scale) for line in ax.get_lines()[1:])
    finally:
        plt.close(ax.figure)


def test_a_stiffening_walls_flow_curve_is_on_its_own_pressure_scale():
    wall = walls["thick-hgo"](**PRESETS["rabbit-carotid-media"])
    ax = tubefsi.plotting.plot_flow_curve(rheologies["power-law"](consistency=0.017, index=0.7), wall, TUBE)
    try:
        drops = ax.get_lines()[0].get_xdata()
        assert ax.get_xlim()[1] <= 1.5 * np.max(drops)      # the rigid reference adds 30 %
    finally:
        plt.close(ax.figure)
