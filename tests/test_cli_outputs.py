"""The command line as a new user meets it: outputs and formats checked before computing,
negative numbers reaching validation, tables in CSV/JSON/NetCDF, log axes, warnings, a fast
start; and progress bars in the library."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi import cli  # noqa: E402

SCENE = ["--rheology", "power-law:consistency=0.017,index=0.7", "--wall", "thick-neo-hookean:shear_modulus=2000",
         "--tube", "radius=1e-4,thickness=3e-5,length=1e-2"]
FLUID = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
WALL = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2000.0)
TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)


def _fail(argv, capsys):
    assert cli.main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.splitlines()) == 1, captured
    return captured.err


@pytest.fixture
def no_solve(monkeypatch):
    """Any solve is a test failure: the argument must be rejected before computing."""
    def refuse(*args, **kwargs):
        raise AssertionError("computed before checking the outputs")
    monkeypatch.setattr(importlib.import_module("tubefsi.solve"), "solve", refuse)


def test_a_bad_plot_format_fails_before_computing(no_solve, capsys, tmp_path):
    err = _fail(["curve", *SCENE, "--flow-rate", "0:1e-9:5", "--plot", str(tmp_path / "out.jpgx")], capsys)
    assert "'jpgx'" in err and "png" in err


@pytest.mark.parametrize("extra", [["--output", "/no/such/dir/curve.csv"], ["--format", "netcdf"],
                                   ["--plot", "/no/such/dir/curve.png"]])
def test_bad_outputs_fail_before_computing(extra, no_solve, capsys):
    _fail(["curve", *SCENE, "--flow-rate", "0:1e-9:5", *extra], capsys)


def test_negative_numbers_reach_validation(capsys):
    for argv in (["solve", *SCENE, "--flow-rate", "-1e-9"], ["solve", *SCENE, "--flow-rate=-1e-9"],
                 ["curve", *SCENE, "--flow-rate", "-1e-9:1e-9"]):
        err = _fail(argv, capsys)
        assert "expected one argument" not in err
    assert "flow_rate must be in [0, inf)" in _fail(["solve", *SCENE, "--flow-rate", "-1e-9"], capsys)
    assert "START" in _fail(["curve", *SCENE, "--flow-rate", "-1e-9:1e-9"], capsys)


def test_messages_say_what_is_expected(capsys):
    err = _fail(["solve", *SCENE[:4], "--tube", "radius=100um,thickness=3e-5,length=1e-2", "--flow-rate", "1e-9"],
                capsys)
    assert "plain number in SI units (m)" in err
    err = _fail(["solve", *SCENE, "--flow-rate", "1e-9", "--coupler", "closed-form"], capsys)
    assert "coupler must be a coupler that supports" in err
    err = _fail(["solve", *SCENE, "--pressure-drop", "4000"], capsys)
    assert "the inlet pressure must stay below the limit pressure" in err


def test_table_formats_from_the_suffix(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    q = np.linspace(0.0, 1e-9, 5)
    ref = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q)
    assert cli.main(["curve", *SCENE, "--flow-rate", "0:1e-9:5", "--output", str(tmp_path / "c.nc")]) == 0
    with xr.open_dataset(tmp_path / "c.nc", engine="scipy") as ds:
        np.testing.assert_array_equal(ds.flow_rate.values, q)
        np.testing.assert_allclose(ds.pressure_drop.values, ref.pressure_drop, rtol=1e-14)
        assert ds.pressure_drop.attrs["units"] == "Pa"
    assert cli.main(["curve", *SCENE, "--flow-rate", "0:1e-9:5", "--output", str(tmp_path / "c.json")]) == 0
    data = json.loads((tmp_path / "c.json").read_text())
    np.testing.assert_allclose(data["pressure_drop"], ref.pressure_drop, rtol=1e-14)


def test_log_points_on_log_axes(tmp_path, monkeypatch):
    scales = []
    original = Figure.savefig

    def record(fig, *args, **kwargs):
        ax = fig.axes[0]
        scales.append((ax.get_xscale(), ax.get_yscale()))
        return original(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    assert cli.main(["curve", *SCENE, "--flow-rate", "1e-11:1e-9:5", "--log", "--plot", str(tmp_path / "a.png"),
                     "--output", str(tmp_path / "a.csv")]) == 0
    assert cli.main(["curve", *SCENE, "--flow-rate", "1e-11:1e-9:5", "--plot", str(tmp_path / "b.png"),
                     "--output", str(tmp_path / "b.csv")]) == 0
    assert scales == [("log", "log"), ("linear", "linear")]


def test_validity_warnings_are_one_line_each(capsys):
    assert cli.main(["solve", *SCENE, "--flow-rate", "1e-8"]) == 0     # R_in/L > 0.1
    err = capsys.readouterr().err.splitlines()
    assert err and all(line.startswith("tubefsi: warning: ") for line in err)
    assert any("not slender" in line for line in err)


def test_list_columns_and_notes(capsys):
    assert cli.main(["list"]) == 0
    out = capsys.readouterr().out
    assert "Newtonian fluid of dynamic viscosity mu" in out and "c1 + c2 > 0" in out
    assert "thickness_convention='reference' by default" in out
    rows = [line for line in out.splitlines() if line.startswith("      ") and "(no " not in line]
    units = {line.index(line.split()[1], len(line.split()[0]) + 6) for line in rows}
    assert len(units) == 1                      # one unit column for every parameter of every model


def test_help_and_version_start_without_scipy():
    code = ("import sys; from tubefsi import cli; cli.main(['--version']); cli.main(['--help']); "
            "print('scipy' in sys.modules, 'matplotlib' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[-1] == "False False"


def test_list_starts_without_scipy():
    """``python -m tubefsi list`` imports every registered model (plugins too) and lists it, and
    none of them loads SciPy before a computation needs it (tubefsi._lazy)."""
    code = ("import runpy, sys\n"
            "sys.argv = ['tubefsi', 'list']\n"
            "try:\n"
            "    runpy.run_module('tubefsi', run_name='__main__')\n"
            "except SystemExit as exc:\n"
            "    assert not exc.code, exc.code\n"
            "loaded = sorted(m for m in sys.modules if m == 'scipy' or m.startswith('scipy.'))\n"
            "print('SCIPY', loaded, 'matplotlib' in sys.modules, file=sys.stderr)\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    for name in ("thick-neo-hookean", "thin-demiray", "ode", "quadrature", "newtonian", "bingham"):
        assert f"  {name} " in run.stdout, name
    assert run.stderr.strip().splitlines()[-1] == "SCIPY [] False"


def test_lazy_scipy_modules_bind_themselves_on_first_use():
    from tubefsi._lazy import lazy_module

    namespace = {}
    namespace["special"] = lazy_module("scipy.special", namespace, "special")
    assert "lazy" in repr(namespace["special"])
    assert namespace["special"].gamma(5.0) == 24.0                  # imports, then answers
    import scipy.special

    assert namespace["special"] is scipy.special                   # rebound: no proxy on later calls


def test_progress_bar(capsys, monkeypatch):
    pytest.importorskip("tqdm")
    q = np.linspace(0.0, 1e-9, 7)
    quiet = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q)
    capsys.readouterr()
    shown = tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q, progress=True)
    err = capsys.readouterr().err
    assert "tubefsi.solve:" in err and "/7" in err
    np.testing.assert_array_equal(shown.pressure_drop, quiet.pressure_drop)
    tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q, progress="auto")          # not a terminal: no bar
    assert "tubefsi.solve:" not in capsys.readouterr().err
    with pytest.raises(tubefsi.InvalidParameterError, match="progress"):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q, progress="yes")
    monkeypatch.setitem(sys.modules, "tqdm", None)
    with pytest.raises(ImportError, match=r"tubefsi\[progress\]"):
        tubefsi.solve(FLUID, WALL, TUBE, flow_rate=q, progress=True)


NETWORK = {"rheology": "power-law:consistency=0.017,index=0.7",
           "tubes": [{"u": "a", "v": "b", "name": "ab", "wall": "thick-neo-hookean:shear_modulus=2000",
                      "tube": {"radius": 1e-4, "thickness": 3e-5, "length": 1e-2}},
                     {"u": "b", "v": "c", "name": "bc", "wall": "rigid",
                      "tube": "radius=1e-4,thickness=3e-5,length=1e-2"}],
           "pressures": {"a": 300, "c": 0}, "positions": {"a": [0, 0], "b": [1, 0], "c": [2, 0]}}


def test_network_file_matches_the_library(tmp_path, capsys):
    path = tmp_path / "net.json"
    path.write_text(json.dumps(NETWORK))
    assert cli.main(["network", str(path), "--plot", str(tmp_path / "net.png")]) == 0
    data = json.loads(capsys.readouterr().out)
    net = tubefsi.Network(rheology=FLUID)
    net.add_tube("a", "b", WALL, TUBE, name="ab").add_tube("b", "c", "rigid", TUBE, name="bc")
    ref = net.set_pressure("a", 300.0).set_pressure("c", 0.0).solve()
    by_name = {t["name"]: t for t in data["tubes"]}
    assert by_name["ab"]["flow_rate"] == pytest.approx(ref.flow_rate["ab"], rel=1e-13)
    assert (tmp_path / "net.png").stat().st_size > 5_000
    assert cli.main(["network", str(path), "--format", "csv", "--output", str(tmp_path / "t")]) == 0
    assert (tmp_path / "t_tubes.csv").read_text().startswith("name,u,v,flow_rate")


@pytest.mark.parametrize("content, extra, message", [
    ("{", [], "is not JSON"),
    (json.dumps({"tubes": []}), [], "non-empty list 'tubes'"),
    (json.dumps({**NETWORK, "pipes": 1}), [], "unknown key 'pipes'"),
    (json.dumps(NETWORK), ["--format", "csv"], "give --output PREFIX"),
    (json.dumps(NETWORK), ["--plot", "net.jpgx"], "'jpgx'"),
])
def test_network_file_errors(content, extra, message, tmp_path, capsys):
    path = tmp_path / "net.json"
    path.write_text(content)
    assert message in _fail(["network", str(path), *extra], capsys)


def test_tapered_tube_on_the_command_line(capsys):
    """``--tube ...,outlet_radius=..,outlet_thickness=..`` is the linear taper the library solves
    from ``tubefsi.sampled`` (the same numbers, to the last digit); one outlet value tapers that
    field only; a bad outlet value is one error line naming the key and its range."""
    taper = "radius=1e-4,thickness=3e-5,length=1e-2,outlet_radius=6e-5"
    scene = [*SCENE[:-1], taper]
    for extra, thickness in ((",outlet_thickness=1.8e-5", tubefsi.sampled([0, 1e-2], [3e-5, 1.8e-5], kind="linear")),
                             ("", 3e-5)):
        scene[-1] = taper + extra
        assert cli.main(["solve", *scene, "--flow-rate", "1e-10,5e-10", "--json"]) == 0
        result = json.loads(capsys.readouterr().out)
        tube = tubefsi.Tube(radius=tubefsi.sampled([0, 1e-2], [1e-4, 6e-5], kind="linear"), thickness=thickness,
                            length=1e-2)
        sol = tubefsi.solve(FLUID, WALL, tube, flow_rate=np.array([1e-10, 5e-10]))
        assert result["pressure_drop"] == sol.pressure_drop.tolist()
        assert result["inlet_radius"] == sol.inlet_radius.tolist()
        assert result["coupler"] == "Graded"
    for bad, key in (("outlet_radius=-6e-5", "outlet_radius"), ("outlet_thickness=0", "outlet_thickness")):
        err = _fail(["solve", *SCENE[:-1], "radius=1e-4,thickness=3e-5,length=1e-2," + bad, "--flow-rate", "1e-10"],
                    capsys)
        assert key in err and "(0, inf)" in err
    err = _fail(["solve", *SCENE[:-1], "radius=1e-4,thickness=3e-5,length=1e-2,outlet_radius=6um", "--flow-rate",
                 "1e-10"], capsys)
    assert "outlet_radius" in err and "plain number" in err
    err = _fail(["solve", *SCENE[:-1], "radius=1e-4,thickness=3e-5,length=1e-2,inlet_radius=1e-4", "--flow-rate",
                 "1e-10"], capsys)
    assert "outlet_radius" in err
