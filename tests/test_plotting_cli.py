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


UNITS = {sym: size for kind in plotting._UNITS.values() for sym, size in kind}


def _unit_of(label):
    """The SI size of the unit named in an axis label's last parentheses, e.g. 'q (µL/min)'."""
    sym = label[label.rindex("(") + 1:label.rindex(")")]
    assert sym in UNITS, label
    return UNITS[sym]


def _no_offsets(fig):
    """Every Axes reads without an offset or a multiplier such as '1e-8' beside its ticks."""
    fig.canvas.draw()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            assert axis.get_offset_text().get_text() == "", (ax.get_title(), axis.get_offset_text().get_text())


# ---------------------------------------------------------------------------- tube law
def test_tube_law_lines_and_limit_in_kpa(tmp_path):
    ax = plotting.plot_tube_law(SOFT, TB)
    lines = _lines(ax)
    assert len(lines) == 3                                  # curve, small-strain tangent, limit
    curve, tangent, limit = lines
    scale = _unit_of(ax.get_ylabel())
    assert "Pa" in ax.get_ylabel()
    lam = np.asarray(curve.get_xdata())
    assert lam[0] == 1.0 and lam[-1] == pytest.approx(3.0)
    np.testing.assert_allclose(curve.get_ydata(), SOFT.pressure(lam, TB) / scale, rtol=1e-12)
    assert limit.get_ydata()[0] == pytest.approx(SOFT.limit_pressure(TB) / scale, rel=1e-12)
    assert ax.get_xlabel() and ax.get_title()
    assert [t.get_text() for t in ax.get_legend().get_texts()][0] == "thick-neo-hookean"
    _no_offsets(ax.figure)
    _save(ax.figure, tmp_path, "tube_law")


def test_tube_law_in_pascal_without_limit():
    ax = plotting.plot_tube_law(THIN, TB, normalize=False, max_stretch=2.0, label="thin")
    curve, tangent = _lines(ax)                             # no limit line: the law never saturates
    lam = np.asarray(curve.get_xdata())
    assert lam[-1] == pytest.approx(2.0)
    np.testing.assert_allclose(curve.get_ydata(), THIN.pressure(lam, TB) / _unit_of(ax.get_ylabel()), rtol=1e-12)
    assert "Pa" in ax.get_ylabel()


def test_normalized_tube_laws_share_one_scale_stated_on_the_axis():
    """One normalisation per Axes: the first wall's k0 divides every later wall too, the y label
    names it with its value, the limit is labelled without a unit, and a rigid wall adds no line."""
    ax = plotting.plot_tube_law(SOFT, TB, normalize=True)
    plotting.plot_tube_law(THIN, TB, ax=ax, normalize=True)
    plotting.plot_tube_law(W["rigid"](), TB, ax=ax, normalize=True)
    k0 = SOFT.small_strain_modulus(TB)
    assert THIN.small_strain_modulus(TB) != pytest.approx(k0)    # the two scales would differ
    curves = [ln for ln in _lines(ax) if ln.get_label() in ("thick-neo-hookean", "thin-neo-hookean")]
    assert len(curves) == 2
    for ln, wall in zip(curves, (SOFT, THIN)):
        lam = np.asarray(ln.get_xdata())
        np.testing.assert_allclose(ln.get_ydata(), wall.pressure(lam, TB) / k0, rtol=1e-12)
    assert "k_0" in ax.get_ylabel() and "thick-neo-hookean" in ax.get_ylabel()
    assert "Pa" in ax.get_ylabel()                               # the scale's value, with its unit
    assert not any(np.all(np.asarray(ln.get_xdata()) == 1.0) for ln in _lines(ax))   # no rigid line
    limit_text = [t.get_text() for t in ax.texts if t.get_text().startswith("limit")]
    assert limit_text and "Pa" not in limit_text[0]
    assert float(limit_text[0].split()[-1]) == pytest.approx(SOFT.limit_pressure(TB) / k0, rel=1e-2)
    tangents = [ln for ln in _lines(ax) if ln.get_gid() == "tubefsi-small-strain-tangent"]
    assert len(tangents) == 2 and sum(ln.get_label() == "small-strain tangents" for ln in tangents) == 1
    np.testing.assert_allclose(tangents[0].get_ydata(), np.asarray(tangents[0].get_xdata()) - 1.0, rtol=1e-12)


def test_tube_law_by_a_given_scale_and_rigid_in_pascal():
    mu = 2e3
    ax = plotting.plot_tube_law(THIN, TB, normalize=mu, scale_name=r"\mu")
    (curve, _) = _lines(ax)
    lam = np.asarray(curve.get_xdata())
    np.testing.assert_allclose(curve.get_ydata(), THIN.pressure(lam, TB) / mu, rtol=1e-12)
    assert r"$p\,/\,\mu$" in ax.get_ylabel() and "2 kPa" in ax.get_ylabel()
    ax2 = plotting.plot_tube_law(W["rigid"](), TB)              # on a pressure axis: the line lambda = 1
    assert list(_lines(ax2)[0].get_xdata()) == [1.0, 1.0]
    with pytest.raises(tubefsi.InvalidParameterError, match="normalize"):
        plotting.plot_tube_law(W["rigid"](), TB, normalize=True)
    with pytest.raises(tubefsi.InvalidParameterError, match="normalize"):
        plotting.plot_tube_law(THIN, TB, normalize=-1.0)


def test_tube_laws_share_axes_and_autoscale():
    ax = plotting.plot_tube_law(SOFT, TB)
    plotting.plot_tube_law(THIN, TB, ax=ax)
    plotting.plot_tube_law(W["rigid"](), TB, ax=ax)
    assert len(_lines(ax)) == 3 + 2 + 1                     # soft (3), thin curve + tangent, rigid
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
def test_flow_curve_default_range_stops_where_the_tube_stops_being_slender(tmp_path):
    """The 10 mm tube reaches R_in = 0.1 L (inlet stretch 10) well below 0.9 q_max: the default
    curve stops just short of it, and draws without a ModelValidityWarning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.ModelValidityWarning)
        ax = plotting.plot_flow_curve(FLUID, SOFT, TUBE, n=50)
    curve, rigid, q_max_line, limit_line = _lines(ax)
    p_unit, q_unit = _unit_of(ax.get_xlabel()), _unit_of(ax.get_ylabel())
    assert "µL/min" in ax.get_ylabel() and "Pa" in ax.get_xlabel()
    q = np.asarray(curve.get_ydata()) * q_unit
    q_max = tubefsi.max_flow_rate(FLUID, SOFT, TUBE)
    assert q.size == 50 and q[0] == 0.0 and q[-1] < 0.9 * q_max
    last = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=q[-1])
    assert 0.09 < last.inlet_radius / TUBE.length <= 0.1           # at the slenderness limit
    np.testing.assert_allclose(np.asarray(curve.get_xdata()) * p_unit,
                               tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=q).pressure_drop, rtol=1e-12)
    assert q_max_line.get_ydata()[0] * q_unit == pytest.approx(q_max)
    assert limit_line.get_xdata()[0] * p_unit == pytest.approx(SOFT.limit_pressure(TB))
    # the rigid reference is Hagen-Poiseuille, stiffer than the soft tube at every flow rate
    qr = np.asarray(rigid.get_ydata()) * q_unit
    hp = tubefsi.solve(FLUID, "rigid", TUBE, flow_rate=qr).pressure_drop
    np.testing.assert_allclose(np.asarray(rigid.get_xdata()) * p_unit, hp, rtol=1e-12)
    assert np.max(rigid.get_xdata()) == pytest.approx(1.3 * np.max(curve.get_xdata()))
    inside = qr[1:] < q[-1]
    assert np.all(np.asarray(rigid.get_xdata())[1:][inside] > np.interp(qr[1:][inside], q, curve.get_xdata()))
    _no_offsets(ax.figure)
    _save(ax.figure, tmp_path, "flow_curve")


def test_flow_curve_of_a_short_tube_keeps_the_maximum_flow_rate_range():
    """A tube short of nothing: L = 1 m reaches R_in = 0.1 L only at stretch 1000, past 0.9 q_max."""
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1.0)
    ax = plotting.plot_flow_curve(FLUID, SOFT, tube, n=20, rigid=False)
    q = np.asarray(_lines(ax)[0].get_ydata()) * _unit_of(ax.get_ylabel())
    assert q[-1] == pytest.approx(0.9 * tubefsi.max_flow_rate(FLUID, SOFT, tube), rel=1e-12)


def test_flow_curve_without_limits():
    newt = RH["newtonian"](viscosity=1e-3)
    wall = W["thin-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
    ax = plotting.plot_flow_curve(newt, wall, TUBE, n=20)
    assert len(_lines(ax)) == 2                             # curve + rigid reference only


def test_flow_curve_explicit_rates():
    newt = RH["newtonian"](viscosity=1e-3)
    rates = np.linspace(0, 1e-9, 7)
    ax2 = plotting.plot_flow_curve(newt, "rigid", TUBE, flow_rates=rates, label="stiff")
    (only,) = _lines(ax2)
    np.testing.assert_allclose(np.asarray(only.get_ydata()) * _unit_of(ax2.get_ylabel()), rates, rtol=1e-15)
    # a newtonian rigid tube is exactly Hagen-Poiseuille: dp = 8 mu L q / (pi a^4)
    np.testing.assert_allclose(np.asarray(only.get_xdata()) * _unit_of(ax2.get_xlabel()),
                               8e-3 * TUBE.length * rates / (np.pi * TUBE.radius**4), rtol=1e-12)
    _no_offsets(ax2.figure)


def test_flow_curves_of_several_walls_share_axes_and_units():
    ax = plotting.plot_flow_curve(FLUID, THIN, TUBE, n=20, rigid=False, color="k")
    label = ax.get_ylabel()
    plotting.plot_flow_curve(FLUID, SOFT, TUBE, flow_rates=np.linspace(0, 1e-12, 5), ax=ax, rigid=False)
    assert ax.get_ylabel() == label                         # the second (tiny) curve keeps the first's unit
    assert _lines(ax)[0].get_color() == "k"
    assert len(_lines(ax)) == 1 + 3
    assert ax.get_xlim()[1] >= np.max(_lines(ax)[0].get_xdata())
    np.testing.assert_allclose(np.asarray(_lines(ax)[1].get_ydata()) * _unit_of(label), np.linspace(0, 1e-12, 5))


# ---------------------------------------------------------------------------- profiles
def test_profiles_scalar_solution(tmp_path):
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=5e-9)
    fig = plotting.plot_profiles(sol, n=60)
    ax_p, ax_r = fig.axes
    p_lines, r_lines = _lines(ax_p), _lines(ax_r)
    assert len(p_lines) == 2 and len(r_lines) == 2         # profile + limit / profile + undeformed
    p_unit = _unit_of(ax_p.get_ylabel())
    z = np.asarray(p_lines[0].get_xdata()) * _unit_of(ax_r.get_xlabel())
    assert z[0] == 0.0 and z[-1] == pytest.approx(TUBE.length)
    assert p_lines[0].get_ydata()[0] * p_unit == pytest.approx(sol.inlet_pressure, rel=1e-10)
    assert p_lines[0].get_ydata()[-1] == pytest.approx(0.0, abs=1e-9)
    assert r_lines[0].get_ydata()[0] == pytest.approx(sol.inlet_radius / TUBE.radius, rel=1e-10)
    assert "mm" in ax_r.get_xlabel() and "Pa" in ax_p.get_ylabel()
    _no_offsets(fig)
    _save(fig, tmp_path, "profiles")


def test_profiles_of_a_small_load_keep_the_axis_and_state_the_limit_off_axis():
    """The limit pressure (525 Pa) far above a small load's profile (~100 Pa) is not drawn (it
    would squeeze the profile into the bottom fifth): a note states it, the profile spans the axis."""
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=1e-10)
    fig = sol.plot(n=40)
    ax_p = fig.axes[0]
    (profile,) = _lines(ax_p)                              # no limit line
    top = float(np.max(profile.get_ydata()))
    lo, hi = ax_p.get_ylim()
    assert lo <= 0.0 and top <= hi <= 1.15 * top           # the profile covers the axis
    notes = [t.get_text() for t in ax_p.texts if "limit pressure" in t.get_text()]
    assert notes and "524.7 Pa" in notes[0]


def test_profiles_of_a_curve_have_a_discrete_legend_and_show_the_undeformed_radius(tmp_path):
    q = np.linspace(0.0, 5e-9, 40)                          # q = 0 first: its profile is the undeformed one
    sol = tubefsi.solve(FLUID, SOFT, TUBE, flow_rate=q)
    fig = sol.plot(n=40)                                   # Solution.plot -> plot_profiles
    assert len(fig.axes) == 2                              # pressure, radius: no colour bar
    ax_p, ax_r = fig.axes
    profiles = [ln for ln in _lines(ax_r) if ln.get_label() != "undeformed"]
    assert len(profiles) == 8
    inlet = sorted(float(ln.get_ydata()[0]) for ln in profiles)
    assert inlet[0] == pytest.approx(1.0) and inlet[-1] == pytest.approx(sol.inlet_radius[-1] / TUBE.radius)
    # the undeformed reference is drawn over the profiles, so the q = 0 line cannot hide it
    (undeformed,) = [ln for ln in _lines(ax_r) if ln.get_label() == "undeformed"]
    assert undeformed.get_zorder() > max(ln.get_zorder() for ln in profiles)
    assert "undeformed" in [t.get_text() for t in ax_r.get_legend().get_texts()]
    # one legend entry (a distinct colour) per drawn flow rate, in the unit of its title, and the limit
    (legend,) = fig.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert len(texts) == 8 + 1 and texts[-1] == "limit pressure"
    unit = _unit_of(legend.get_title().get_text())
    drawn = np.unique(sol.flow_rate[np.round(np.linspace(0, 39, 8)).astype(int)])
    np.testing.assert_allclose([float(t) * unit for t in texts[:-1]], drawn, rtol=2e-3)
    assert len({tuple(ln.get_color()) for ln in profiles}) == 8
    lo, hi = ax_p.get_ylim()
    assert hi >= max(float(np.max(ln.get_ydata())) for ln in _lines(ax_p))
    _no_offsets(fig)
    _save(fig, tmp_path, "profiles_curve")


def test_profiles_into_given_axes_and_newtonian_rigid():
    fig, axes = plt.subplots(1, 2)
    sol = tubefsi.solve(RH["newtonian"](viscosity=1e-3), "rigid", TUBE, pressure_drop=[10.0, 20.0])
    out = plotting.plot_profiles(sol, axes=axes, n=11)
    assert out is fig
    assert len(_lines(axes[0])) == 2                       # two loads, no limit pressure
    np.testing.assert_allclose(np.asarray(_lines(axes[0])[1].get_ydata()) * _unit_of(axes[0].get_ylabel()),
                               np.linspace(20, 0, 11), atol=1e-9)
    assert len(axes[0].get_legend().get_texts()) == 2      # the legend on the given Axes
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
    assert "µm" in ax.get_ylabel() and "mm" in ax.get_xlabel()
    assert upper.get_ydata()[0] * _unit_of(ax.get_ylabel()) == pytest.approx(sol.inlet_radius, rel=1e-10)
    assert upper.get_xdata()[-1] * _unit_of(ax.get_xlabel()) == pytest.approx(TUBE.length)
    cmin, cmax = meshes[0].get_clim()
    assert cmin == pytest.approx(0.0, abs=1e-9) and cmax == pytest.approx(sol.inlet_pressure, rel=1e-10)
    assert len(ax.figure.axes) == 2                        # the colorbar
    assert "Pa" in ax.figure.axes[1].get_ylabel()
    assert "µL/min" in ax.get_title()
    _no_offsets(ax.figure)
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
    v_unit, r_unit = _unit_of(ax.get_xlabel()), _unit_of(ax.get_ylabel())
    outlet = lines[-1]
    assert float(np.max(outlet.get_xdata())) * v_unit == pytest.approx(sol.velocity(0.0, TUBE.length), rel=1e-10)
    assert float(np.max(outlet.get_ydata())) * r_unit == pytest.approx(TUBE.radius, rel=1e-10)
    ax2 = plotting.plot_velocity_profiles(sol, [0.0, 5e-3])
    assert len(_lines(ax2)) == 2
    # the flow rate through each section is q: integrate 2 pi r v dr over the upper half
    for ln in _lines(ax2):
        v, r = np.asarray(ln.get_xdata()) * v_unit, np.asarray(ln.get_ydata()) * r_unit
        up = r >= 0
        f, x = 2 * np.pi * r[up] * v[up], r[up]
        assert np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)) == pytest.approx(5e-9, rel=2e-3)
    _no_offsets(ax.figure)
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
