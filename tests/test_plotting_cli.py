"""Smoke and behaviour tests of tubefsi.plotting and the ``tubefsi`` command."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import attrs  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import PolyCollection, QuadMesh  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi import cli, plotting  # noqa: E402

W = tubefsi.registry.walls
RH = tubefsi.registry.rheologies

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
TB = TUBE.reduced_thickness
FLUID = RH["power-law"](consistency=0.017, index=0.7)
SOFT = W["thick-neo-hookean"](shear_modulus=2e3)      # limit pressure, finite maximum flow rate
THIN = W["thin-neo-hookean"](shear_modulus=2e3)       # no limit pressure

SCENE_ARGS = ["--rheology", "power-law:consistency=0.017,index=0.7",
              "--wall", "thick-neo-hookean:shear_modulus=2e3",
              "--tube", "radius=1e-4,thickness=3e-5,length=1e-2"]


@pytest.fixture(autouse=True)
def _close_figures(monkeypatch):
    def no_show(*args, **kwargs):  # plotting must never block on a window
        raise AssertionError("plt.show() called")

    monkeypatch.setattr(plt, "show", no_show)
    yield
    plt.close("all")


def _save(fig, tmp_path, name) -> Path:
    path = tmp_path / f"{name}.png"
    fig.savefig(path, dpi=60)
    data = path.read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) > 2000
    return path


def _lines(ax):
    return list(ax.get_lines())


# ---------------------------------------------------------------------------- import
def test_import_does_not_load_pyplot_or_pick_a_backend():
    code = ("import sys, tubefsi, tubefsi.plotting, tubefsi.cli; "
            "print('matplotlib.pyplot' in sys.modules)")
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip() == "False"


# ---------------------------------------------------------------------------- tube law
def test_tube_law_lines_and_limit(tmp_path):
    ax = plotting.plot_tube_law(SOFT, TB)
    lines = _lines(ax)
    assert len(lines) == 3                                  # curve, small-strain tangent, limit
    curve, tangent, limit = lines
    k0 = SOFT.small_strain_modulus(TB)
    lam = np.asarray(curve.get_xdata())
    assert lam[0] == 1.0 and lam[-1] == pytest.approx(3.0)
    np.testing.assert_allclose(curve.get_ydata(), SOFT.pressure(lam, TB) / k0, rtol=1e-12)
    assert limit.get_ydata()[0] == pytest.approx(SOFT.limit_pressure(TB) / k0, rel=1e-12)
    assert ax.get_xlabel() and ax.get_ylabel() and ax.get_title()
    assert [t.get_text() for t in ax.get_legend().get_texts()][0] == "thick-neo-hookean"
    _save(ax.figure, tmp_path, "tube_law")


def test_tube_law_in_pascal_without_limit():
    ax = plotting.plot_tube_law(THIN, TB, normalize=False, max_stretch=2.0, label="thin")
    curve, tangent = _lines(ax)                             # no limit line: the law never saturates
    lam = np.asarray(curve.get_xdata())
    assert lam[-1] == pytest.approx(2.0)
    np.testing.assert_allclose(curve.get_ydata(), THIN.pressure(lam, TB), rtol=1e-12)
    assert "Pa" in ax.get_ylabel()


def test_tube_laws_share_axes_with_one_tangent_and_rigid_vertical_line():
    ax = plotting.plot_tube_law(SOFT, TB)
    plotting.plot_tube_law(THIN, TB, ax=ax)
    plotting.plot_tube_law(W["rigid"](), TB, ax=ax)
    tangents = [ln for ln in _lines(ax) if ln.get_gid() == "tubefsi-small-strain-tangent"]
    assert len(tangents) == 1
    assert len(_lines(ax)) == 3 + 1 + 1                     # soft (3), thin curve, rigid
    rigid = _lines(ax)[-1]
    assert list(rigid.get_xdata()) == [1.0, 1.0]
    lo, hi = ax.get_ylim()
    assert lo == 0.0 and hi >= float(np.max(_lines(ax)[3].get_ydata()))   # autoscaling still on


def test_wall_plot_method_and_bad_max_stretch():
    ax = SOFT.plot(TB, max_stretch=2.5)
    assert np.asarray(_lines(ax)[0].get_xdata())[-1] == pytest.approx(2.5)
    with pytest.raises(tubefsi.InvalidParameterError, match="max_stretch"):
        plotting.plot_tube_law(SOFT, TB, max_stretch=1.0)
    with pytest.raises(tubefsi.InvalidParameterError, match="reduced_thickness"):
        plotting.plot_tube_law(SOFT, -1.0)


# ---------------------------------------------------------------------------- flow curve
def test_flow_curve_default_range_with_maximum_flow_rate(tmp_path):
    ax = plotting.plot_flow_curve(FLUID, SOFT, TUBE, n=50)
    curve, rigid, q_max_line, limit_line = _lines(ax)
    q = np.asarray(curve.get_ydata())
    q_max = tubefsi.max_flow_rate(FLUID, SOFT, TUBE)
    assert q.size == 50 and q[0] == 0.0 and q[-1] == pytest.approx(0.9 * q_max, rel=1e-12)
    np.testing.assert_allclose(curve.get_xdata(), tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=q).pressure_drop,
                               rtol=1e-12)
    assert q_max_line.get_ydata()[0] == pytest.approx(q_max)
    assert limit_line.get_xdata()[0] == pytest.approx(SOFT.limit_pressure(TB))
    # the rigid reference is Hagen-Poiseuille, stiffer than the soft tube at every flow rate
    qr = np.asarray(rigid.get_ydata())
    hp = tubefsi.solve(FLUID, "rigid", TUBE, flow_rate=qr).pressure_drop
    np.testing.assert_allclose(rigid.get_xdata(), hp, rtol=1e-12)
    assert np.max(rigid.get_xdata()) == pytest.approx(1.3 * np.max(curve.get_xdata()))
    inside = qr[1:] < q[-1]
    assert np.all(np.asarray(rigid.get_xdata())[1:][inside] > np.interp(qr[1:][inside], q, curve.get_xdata()))
    assert "Pa" in ax.get_xlabel() and "m³/s" in ax.get_ylabel()
    _save(ax.figure, tmp_path, "flow_curve")


def test_flow_curve_without_limits_and_explicit_rates():
    newt = RH["newtonian"](viscosity=1e-3)
    wall = W["thin-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
    ax = plotting.plot_flow_curve(newt, wall, TUBE, n=20)
    assert len(_lines(ax)) == 2                             # curve + rigid reference only
    rates = np.linspace(0, 1e-9, 7)
    ax2 = plotting.plot_flow_curve(newt, "rigid", TUBE, flow_rates=rates, label="stiff")
    (only,) = _lines(ax2)
    np.testing.assert_array_equal(only.get_ydata(), rates)
    # a newtonian rigid tube is exactly Hagen-Poiseuille: dp = 8 mu L q / (pi a^4)
    np.testing.assert_allclose(only.get_xdata(), 8e-3 * TUBE.length * rates / (np.pi * TUBE.radius**4),
                               rtol=1e-12)


def test_flow_curves_of_several_walls_share_axes():
    ax = plotting.plot_flow_curve(FLUID, THIN, TUBE, n=20, rigid=False, color="k")
    plotting.plot_flow_curve(FLUID, SOFT, TUBE, n=20, ax=ax, rigid=False)
    assert _lines(ax)[0].get_color() == "k"
    assert len(_lines(ax)) == 1 + 3
    assert ax.get_xlim()[1] >= np.max(_lines(ax)[0].get_xdata())


# ---------------------------------------------------------------------------- profiles
def test_profiles_scalar_solution(tmp_path):
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=5e-9)
    fig = plotting.plot_profiles(sol, n=60)
    ax_p, ax_r = fig.axes
    p_lines, r_lines = _lines(ax_p), _lines(ax_r)
    assert len(p_lines) == 2 and len(r_lines) == 2         # profile + limit / profile + undeformed
    z = np.asarray(p_lines[0].get_xdata())
    assert z[0] == 0.0 and z[-1] == pytest.approx(TUBE.length * 1e3)
    assert p_lines[0].get_ydata()[0] == pytest.approx(sol.inlet_pressure, rel=1e-10)
    assert p_lines[0].get_ydata()[-1] == pytest.approx(0.0, abs=1e-9)
    assert r_lines[0].get_ydata()[0] == pytest.approx(sol.inlet_radius / TUBE.radius, rel=1e-10)
    assert "mm" in ax_r.get_xlabel() and "Pa" in ax_p.get_ylabel()
    _save(fig, tmp_path, "profiles")


def test_profiles_of_a_curve_draw_at_most_eight_loads_with_colorbar(tmp_path):
    q = np.linspace(0.0, 1e-8, 40)
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=q)
    fig = sol.plot(n=40)                                   # Solution.plot -> plot_profiles
    assert len(fig.axes) == 3                              # pressure, radius, colorbar
    ax_r = fig.axes[1]
    profiles = [ln for ln in _lines(ax_r) if ln.get_label() != "undeformed"]
    assert len(profiles) == 8
    inlet = sorted(float(ln.get_ydata()[0]) for ln in profiles)
    assert inlet[0] == pytest.approx(1.0) and inlet[-1] == pytest.approx(sol.inlet_radius[-1] / TUBE.radius)
    _save(fig, tmp_path, "profiles_curve")


def test_profiles_into_given_axes_and_newtonian_rigid():
    fig, axes = plt.subplots(1, 2)
    sol = tubefsi.solve(RH["newtonian"](viscosity=1e-3), "rigid", TUBE, pressure_drop=[10.0, 20.0])
    out = plotting.plot_profiles(sol, axes=axes, n=11)
    assert out is fig
    assert len(_lines(axes[0])) == 2                       # two loads, no limit pressure
    np.testing.assert_allclose(np.asarray(_lines(axes[0])[1].get_ydata()), np.linspace(20, 0, 11), atol=1e-9)
    with pytest.raises(tubefsi.InvalidParameterError):
        plotting.plot_profiles(sol, axes=[axes[0]])


# ---------------------------------------------------------------------------- deformed tube
def test_deformed_tube(tmp_path):
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=5e-9)
    ax = plotting.plot_deformed_tube(sol, n=80)
    meshes = [c for c in ax.collections if isinstance(c, QuadMesh)]
    walls = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(meshes) == 1 and len(walls) == 2            # lumen coloured by pressure, wall above and below
    assert len(_lines(ax)) == 4                            # +-R(z), +-a
    upper = _lines(ax)[0]
    assert upper.get_ydata()[0] == pytest.approx(sol.inlet_radius * 1e3, rel=1e-10)
    assert upper.get_xdata()[-1] == pytest.approx(TUBE.length * 1e3)
    cmin, cmax = meshes[0].get_clim()
    assert cmin == pytest.approx(0.0, abs=1e-9) and cmax == pytest.approx(sol.inlet_pressure, rel=1e-10)
    assert len(ax.figure.axes) == 2                        # the colorbar
    assert "Pa" in ax.figure.axes[1].get_ylabel()
    assert "mm" in ax.get_xlabel() and "mm" in ax.get_ylabel()
    _save(ax.figure, tmp_path, "deformed")


def test_deformed_tube_compressible_wall_has_no_wall_band_and_rejects_curves():
    wall = W["thick-linear"](youngs_modulus=6e3, poisson_ratio=0.3)
    sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=1e-9)
    ax = plotting.plot_deformed_tube(sol, n=30)
    assert not any(isinstance(c, PolyCollection) for c in ax.collections)
    curve = tubefsi.solve(FLUID, wall, TUBE, flow_rate=[1e-9, 2e-9])
    with pytest.raises(tubefsi.InvalidParameterError, match="solution"):
        plotting.plot_deformed_tube(curve)
    one = tubefsi.solve(FLUID, wall, TUBE, flow_rate=[1e-9])   # a curve of one load is fine
    plotting.plot_deformed_tube(one, n=30)


# ---------------------------------------------------------------------------- velocity
def test_velocity_profiles(tmp_path):
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=5e-9)
    ax = plotting.plot_velocity_profiles(sol)
    lines = _lines(ax)
    assert len(lines) == 5
    outlet = lines[-1]
    assert float(np.max(outlet.get_xdata())) == pytest.approx(sol.velocity(0.0, TUBE.length) * 1e3, rel=1e-10)
    assert float(np.max(outlet.get_ydata())) == pytest.approx(TUBE.radius * 1e3, rel=1e-10)
    ax2 = plotting.plot_velocity_profiles(sol, [0.0, 5e-3])
    assert len(_lines(ax2)) == 2
    # the flow rate through each section is q: integrate 2 pi r v dr over the upper half
    for ln in _lines(ax2):
        v, r = np.asarray(ln.get_xdata()) * 1e-3, np.asarray(ln.get_ydata()) * 1e-3
        up = r >= 0
        f, x = 2 * np.pi * r[up] * v[up], r[up]
        assert np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)) == pytest.approx(5e-9, rel=2e-3)
    _save(ax.figure, tmp_path, "velocity")
    with pytest.raises(tubefsi.InvalidParameterError):
        plotting.plot_velocity_profiles(sol, [2 * TUBE.length])


# ---------------------------------------------------------------------------- CLI: list
def test_cli_list_names_every_model_and_parameter(capsys):
    assert cli.main(["list"]) == 0
    out = capsys.readouterr().out
    for registry in (tubefsi.registry.rheologies, tubefsi.registry.walls, tubefsi.registry.couplers):
        for name in registry:
            assert f"  {name} " in out
            for field in attrs.fields(registry[name]) if attrs.has(registry[name]) else ():
                assert field.name in out
                if field.metadata.get("admissible"):
                    assert field.metadata["admissible"] in out
    assert "Pa s^n" in out


# ---------------------------------------------------------------------------- CLI: solve
def test_cli_solve_json_matches_library(capsys):
    assert cli.main(["solve", *SCENE_ARGS, "--flow-rate", "1e-9", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=1e-9)
    assert result["pressure_drop"] == sol.pressure_drop
    assert result["flow_rate"] == 1e-9
    assert result["inlet_pressure"] == sol.inlet_pressure
    assert result["inlet_displacement"] == sol.inlet_displacement
    assert result["inlet_radius"] == sol.inlet_radius
    assert result["coupler"] == sol.coupler_name


def test_cli_solve_pressure_controlled_list_outlet_and_coupler(capsys):
    args = ["solve", "--rheology", "newtonian:viscosity=1e-3",
            "--wall", "thin-neo-hookean:shear_modulus=5e3,thickness_convention=current",
            "--tube", "radius=1e-4,thickness=3e-5,length=1e-2",
            "--pressure-drop", "50,100", "--outlet-pressure", "20", "--coupler", "quadrature:order=24", "--json"]
    assert cli.main(args) == 0
    result = json.loads(capsys.readouterr().out)
    wall = W["thin-neo-hookean"](shear_modulus=5e3, thickness_convention="current")
    sol = tubefsi.solve(RH["newtonian"](viscosity=1e-3), wall, TUBE, pressure_drop=[50.0, 100.0],
                        outlet_pressure=20.0, coupler=tubefsi.registry.couplers["quadrature"](order=24))
    assert result["flow_rate"] == list(sol.flow_rate)
    assert result["inlet_pressure"] == [70.0, 120.0]
    assert result["coupler"] == "quadrature"


def test_cli_solve_text_output(capsys):
    assert cli.main(["solve", *SCENE_ARGS, "--flow-rate", "1e-9"]) == 0
    out = capsys.readouterr().out.splitlines()
    keys = [line.split()[0] for line in out]
    assert keys == ["pressure_drop", "flow_rate", "inlet_pressure", "inlet_displacement", "inlet_radius", "coupler"]
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=1e-9)
    assert float(out[0].split()[1]) == sol.pressure_drop


BAD = {
    "unknown rheology": ["solve", "--rheology", "honey", *SCENE_ARGS[2:], "--flow-rate", "1e-9"],
    "unknown wall": ["solve", *SCENE_ARGS[:2], "--wall", "glass", *SCENE_ARGS[4:], "--flow-rate", "1e-9"],
    "unknown key": ["solve", "--rheology", "power-law:consistency=0.017,n=0.7", *SCENE_ARGS[2:],
                    "--flow-rate", "1e-9"],
    "missing key": ["solve", "--rheology", "power-law:consistency=0.017", *SCENE_ARGS[2:], "--flow-rate", "1e-9"],
    "not key=value": ["solve", "--rheology", "power-law:consistency", *SCENE_ARGS[2:], "--flow-rate", "1e-9"],
    "out of range": ["solve", "--rheology", "power-law:consistency=0.017,index=-0.7", *SCENE_ARGS[2:],
                     "--flow-rate", "1e-9"],
    "bad choice": ["solve", *SCENE_ARGS[:2], "--wall", "thin-neo-hookean:shear_modulus=1,thickness_convention=x",
                   *SCENE_ARGS[4:], "--flow-rate", "1e-9"],
    "bad tube": ["solve", *SCENE_ARGS[:4], "--tube", "radius=1e-4,thickness=0,length=1e-2", "--flow-rate", "1e-9"],
    "tube key": ["solve", *SCENE_ARGS[:4], "--tube", "radius=1e-4,length=1e-2", "--flow-rate", "1e-9"],
    "negative load": ["solve", *SCENE_ARGS, "--flow-rate", "-1e-9"],
    "not a number": ["solve", *SCENE_ARGS, "--pressure-drop", "lots"],
    "beyond q_max": ["solve", *SCENE_ARGS, "--flow-rate", "1e-6"],
    "beyond limit": ["solve", *SCENE_ARGS, "--pressure-drop", "1e4"],
    "unsupported coupler": ["solve", *SCENE_ARGS, "--flow-rate", "1e-9", "--coupler", "closed-form"],
    "no load": ["solve", *SCENE_ARGS],
    "both loads": ["solve", *SCENE_ARGS, "--flow-rate", "1", "--pressure-drop", "1"],
    "no command": [],
    "bad command": ["fly"],
}


@pytest.mark.parametrize("argv", list(BAD.values()), ids=list(BAD))
def test_cli_bad_arguments_exit_2_with_one_line(argv, capsys):
    assert cli.main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("tubefsi: error: ")


def test_cli_help_returns_zero(capsys):
    assert cli.main(["--help"]) == 0
    assert "solve" in capsys.readouterr().out
    assert cli.main(["solve", "--help"]) == 0
    assert "--flow-rate" in capsys.readouterr().out


def test_parse_model_spec():
    assert cli.parse_model_spec("rigid") == ("rigid", {})
    assert cli.parse_model_spec("a:x=1,y=2.5e3,z=current") == ("a", {"x": 1, "y": 2500.0, "z": "current"})


# ---------------------------------------------------------------------------- console script
def _console_script():
    exe = Path(sys.executable).with_name("tubefsi")
    return exe if exe.exists() else shutil.which("tubefsi")


@pytest.mark.skipif(_console_script() is None, reason="tubefsi console script not installed")
def test_console_script():
    exe = str(_console_script())
    bad = subprocess.run([exe, "solve", *SCENE_ARGS, "--flow-rate", "1e-6"], capture_output=True, text=True)
    assert bad.returncode == 2
    assert bad.stdout == ""
    assert len(bad.stderr.splitlines()) == 1 and "Traceback" not in bad.stderr
    assert bad.stderr.startswith("tubefsi: error: no steady state")
    good = subprocess.run([exe, "solve", *SCENE_ARGS, "--flow-rate", "1e-9", "--json"], capture_output=True,
                          text=True, check=True)
    # a fresh process solves directly, this one may be served by a cached table (they agree to 1e-13)
    assert json.loads(good.stdout)["pressure_drop"] == pytest.approx(
        tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=1e-9).pressure_drop, rel=1e-13)
