"""CLI `curve` and `advise`: outputs agree with the library; bad arguments exit 2 with one line."""

import csv
import io
import json

import numpy as np
import pytest

import tubefsi
from tubefsi.cli import main
from tubefsi.registry import rheologies, walls

SCENE = ["--rheology", "power-law:consistency=0.017,index=0.7", "--wall", "thick-neo-hookean:shear_modulus=2000",
         "--tube", "radius=1e-4,thickness=3e-5,length=1e-2"]
TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
WALL = walls["thick-neo-hookean"](shear_modulus=2000.0)


def test_curve_csv_matches_solve(capsys):
    assert main(["curve", *SCENE, "--flow-rate", "1e-10:1e-8:7", "--log"]) == 0
    rows = list(csv.reader(io.StringIO(capsys.readouterr().out)))
    assert rows[0][0] == "pressure_drop (Pa)" and len(rows) == 8
    q = np.geomspace(1e-10, 1e-8, 7)
    expected = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q).pressure_drop
    # the first call may solve directly and the next one from the table it paid for (1e-13 apart)
    np.testing.assert_allclose([float(r[0]) for r in rows[1:]], expected, rtol=1e-13)


def test_curve_json_and_plot(tmp_path, capsys):
    plot = tmp_path / "curve.png"
    assert main(["curve", *SCENE, "--pressure-drop", "0:500:5", "--format", "json", "--plot", str(plot)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["coupler"] == "quadrature" and data["pressure_drop"] == [0.0, 125.0, 250.0, 375.0, 500.0]
    back = tubefsi.solve(FLUID, WALL, TUBE, pressure_drop=np.array(data["pressure_drop"]))
    np.testing.assert_allclose(data["flow_rate"], back.flow_rate, rtol=1e-13)
    assert plot.stat().st_size > 10_000


def test_advise_prints_table_and_recommendation(capsys):
    assert main(["advise", *SCENE, "--flow-rate", "5e-9", "--density", "1060"]) == 0
    text = capsys.readouterr().out
    assert "recommended: thick-neo-hookean with power-law (requested)" in text
    assert "rigid wall" in text and "Reynolds number" in text


@pytest.mark.parametrize("args", [
    ["curve", *SCENE, "--flow-rate", "1e-8:0"],
    ["curve", *SCENE, "--flow-rate", "a:b"],
    ["curve", *SCENE, "--flow-rate", "0:1e-8", "--log"],
    ["curve", *SCENE, "--pressure-drop", "0:1e4:5"],            # beyond the limit pressure
    ["advise", *SCENE, "--flow-rate", "-1"],
    ["advise", *SCENE],
])
def test_bad_arguments_exit_2_with_one_line(args, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("tubefsi: error:") and err.count("\n") == 1
