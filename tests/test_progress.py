"""Progress bars for the long work besides ``solve`` (issue 14): ``fit``, ``Network.solve`` and the
finite-element reference take ``progress=`` like :func:`tubefsi.solve` (``tubefsi._progress.bar``):
a tqdm bar on standard error when asked, the same results either way, no bar for ``"auto"`` off a
terminal, and a typed error for a bad value."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tubefsi
from tubefsi import Network, Tube
from tubefsi.registry import rheologies, walls

pytest.importorskip("tqdm")

TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)


def _shown(capsys, desc):
    err = capsys.readouterr().err
    return f"{desc}:" in err, err


def test_fit_counts_its_model_evaluations(capsys):
    wall = walls["thin-mooney-rivlin"](c1=1.5e3, c2=-0.5e3)
    q = np.geomspace(1e-10, 5e-9, 8)
    dp = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q).pressure_drop
    start = walls["thin-mooney-rivlin"](c1=3e3, c2=-0.5e3)
    quiet = tubefsi.fit(q, dp, FLUID, start, TUBE, parameters=["wall.c1"])
    capsys.readouterr()
    shown = tubefsi.fit(q, dp, FLUID, start, TUBE, parameters=["wall.c1"], progress=True)
    seen, err = _shown(capsys, "tubefsi.fit")
    assert seen and "evaluation" in err
    assert shown.parameters == quiet.parameters
    tubefsi.fit(q, dp, FLUID, start, TUBE, parameters=["wall.c1"], progress="auto")
    assert not _shown(capsys, "tubefsi.fit")[0]
    with pytest.raises(tubefsi.InvalidParameterError, match="progress"):
        tubefsi.fit(q, dp, FLUID, start, TUBE, parameters=["wall.c1"], progress="yes")


def _chain():
    wall = walls["thick-neo-hookean"](shear_modulus=4e3)
    net = Network(rheology=rheologies["power-law"](consistency=0.01, index=0.8))
    piece = Tube(radius=TUBE.radius, thickness=TUBE.thickness, length=TUBE.length / 4)
    for j in range(4):
        net.add_tube(j, j + 1, wall, piece)
    return net.set_inflow(0, 2e-9).set_pressure(4, 0.0)


def test_network_shows_its_newton_steps(capsys):
    quiet = _chain().solve()
    capsys.readouterr()
    shown = _chain().solve(progress=True)
    seen, err = _shown(capsys, "tubefsi.Network.solve")
    assert seen and "Newton step" in err
    assert shown.pressure == quiet.pressure and quiet.iterations > 1
    _chain().solve(progress="auto")
    assert not _shown(capsys, "tubefsi.Network.solve")[0]
    with pytest.raises(tubefsi.InvalidParameterError, match="progress"):
        _chain().solve(progress=2)


def test_fem_reference_shows_its_coupling_iterations(capsys):
    tfem = pytest.importorskip("tubefsi.fem")
    tube = Tube(radius=1e-4, thickness=3e-5, length=8e-4)
    args = (rheologies["newtonian"](viscosity=1e-3), walls["thick-neo-hookean"](shear_modulus=1e4), tube)
    quiet = tfem.solve_axisymmetric(*args, flow_rate=1e-9, resolution=1, tol=1e-6)
    capsys.readouterr()
    shown = tfem.solve_axisymmetric(*args, flow_rate=1e-9, resolution=1, tol=1e-6, progress=True)
    seen, err = _shown(capsys, "tubefsi.fem")
    assert seen and "coupling iteration" in err
    assert shown.pressure_drop == quiet.pressure_drop and quiet.iterations > 1
    assert math.isfinite(shown.pressure_drop)


def test_a_long_sweeps_bar_ends_at_its_total_and_stays(capsys):
    """A sweep over several chunks (and over fluids whose parameters vary, solved one parameter
    set at a time) leaves a finished bar at n/n, not 0 % or a count short of n (issue 27)."""
    n = 21_000                   # more than one chunk (tubefsi.solve.CHUNK, 16384 points)
    tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE,
                  flow_rate=np.linspace(1e-11, 1e-9, n), progress=True)
    err = capsys.readouterr().err
    assert f"{n}/{n}" in err.replace(",", "")
    fluid = rheologies["power-law"](consistency=np.linspace(0.01, 0.02, 7)[:, None], index=0.7)
    tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, flow_rate=np.full((7, 3), 1e-10),
                  progress=True)
    assert "21/21" in capsys.readouterr().err
