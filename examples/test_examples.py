"""Smoke tests of the example scripts: each one runs at small sizes, writes its outputs, and
prints numbers that make sense.

Each script is imported as a module and its ``main`` called with its small-size option
(``--quick``, ``--points N``; the demo and the fit are small already), writing into
``tmp_path``. The assertions check what a reader of the output would check: the files exist
and are real images or tables, and the printed numbers agree with what the script claims
(known limits, convergence rates, errors within the documented contracts).
"""

from __future__ import annotations

import csv
import importlib.util
import math
import re
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import tubefsi  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent
FLOAT = r"[-+]?(?:\d+\.?\d*(?:e[-+]?\d+)?|inf|nan)"


def load(name):
    """The example script ``examples/<name>.py`` as a fresh module."""
    spec = importlib.util.spec_from_file_location(f"examples_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def numbers(pattern, text):
    """Every match of ``pattern`` (with FLOAT groups) in ``text``, as tuples of floats."""
    found = re.findall(pattern.replace("FLOAT", f"({FLOAT})"), text)
    assert found, f"no line matches {pattern!r}"
    return [tuple(float(v) for v in (m if isinstance(m, tuple) else (m,))) for m in found]


def assert_pngs(directory, names, min_bytes=10_000):
    assert sorted(p.name for p in Path(directory).glob("*.png")) == sorted(names)
    for name in names:
        data = (Path(directory) / name).read_bytes()
        assert data.startswith(b"\x89PNG") and len(data) > min_bytes, name


# ---------------------------------------------------------------------------- demo.py
def test_demo_writes_its_table_and_four_figures(tmp_path, capsys):
    out = tmp_path / "demo"
    with warnings.catch_warnings():           # the demo's scenes are valid, or say why not
        warnings.simplefilter("error", tubefsi.ModelValidityWarning)
        assert load("demo").main([str(out)]) == 0
    text = capsys.readouterr().out
    notes = text.split("shown on purpose to compare the walls")[1].split("maximum steady flow rate")[0]
    assert "thin-linear: inlet hoop strain" in notes and "thick-linear: inlet hoop strain" in notes
    for name in ("rigid", "thin-linear", "thick-linear", "thin-neo-hookean", "thick-neo-hookean",
                 "maximum steady flow rate"):
        assert name in text
    assert_pngs(out, ["deformed_tube.png", "flow_curves.png", "profiles.png", "tube_laws.png"])

    # the pressure-drop table: the rigid wall is Hagen–Poiseuille for a power law, and every
    # compliant wall needs less pressure than the rigid one at every flow rate
    table = text.split("pressure drop (Pa)")[1].split("inlet wall displacement")[0]
    rows = {line.split()[0]: [float(v) for v in line.split()[2:]] for line in table.strip().splitlines()[2:]}
    assert len(rows) == 5 and all(len(v) == 4 for v in rows.values())
    m, n, a, length = 0.017, 0.7, 100e-6, 10e-3
    for q, dp in zip((1e-10, 1e-9, 5e-9, 1e-8), rows["rigid"]):
        exact = length * 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n / a ** (3 * n + 1)
        assert dp == pytest.approx(exact, abs=0.05)
    for name, dps in rows.items():
        assert dps == sorted(dps)                                  # more flow, more pressure
        if name != "rigid":
            assert all(d < r for d, r in zip(dps, rows["rigid"]))
    # only the thick neo-Hookean wall has a finite maximum flow rate, reached at its limit
    # pressure mu ln(1 + t/a)
    (q_max, p_lim), = numbers(r"thick-neo-hookean\s+FLOAT  \(the wall's limit pressure is FLOAT Pa\)", text)
    assert 1e-8 < q_max < 2e-8                                     # the table's largest flow rate is below it
    assert p_lim == pytest.approx(2e3 * math.log(1.3), abs=0.05)
    assert text.count("(every flow rate has a steady state)") == 4


# ---------------------------------------------------------------------------- fit_synthetic.py
def test_fit_synthetic_recovers_the_parameters(tmp_path, capsys):
    assert load("fit_synthetic").main([str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert_pngs(tmp_path, ["fit.png"])
    fitted = numbers(r"true\s+FLOAT\s+fitted\s+FLOAT\s+\(FLOAT std\. errors\)", text)
    assert len(fitted) == 3
    for true, value, z in fitted:
        assert abs(z) < 3 and value == pytest.approx(true, rel=0.2)


# ---------------------------------------------------------------------------- reproduce_chapter.py
def _curves(path):
    curves = {}
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            key = (row["n"], row["beta_label"], row["wall"])
            curves.setdefault(key, []).append((float(row["qbar"]), float(row["dpbar"]) if row["dpbar"] else None))
    return curves


def test_reproduce_chapter_writes_both_variants_of_both_figures(tmp_path, capsys):
    points = 11
    with warnings.catch_warnings():     # the chapter's curves leave the model's range: said, not warned
        warnings.simplefilter("error", tubefsi.ModelValidityWarning)
        assert load("reproduce_chapter").main([str(tmp_path), "--points", str(points)]) == 0
    text = capsys.readouterr().out
    assert "linear walls reach inlet strains up to" in text
    assert f"({points} points)" in text
    stems = [f"{f}_{v}" for f in ("thin", "thick") for v in ("printed", "consistent")]
    assert_pngs(tmp_path, [f"{s}.png" for s in stems])
    curves = {s: _curves(tmp_path / f"{s}.csv") for s in stems}
    for stem, by_key in curves.items():
        assert len(by_key) == 2 * 3 * 2                            # n, beta labels, hyperelastic/linear
        for key, curve in by_key.items():
            assert len(curve) == points and curve[0] == (0.0, 0.0)
            dps = [dp for _, dp in curve if dp is not None]
            assert all(b >= a for a, b in zip(dps, dps[1:])), (stem, key)      # increasing, or saturated
    # the chapter's linear closed forms are right: printed and consistent linear curves agree
    for figure in ("thin", "thick"):
        for key, curve in curves[f"{figure}_printed"].items():
            if key[2] == "linear":
                other = curves[f"{figure}_consistent"][key]
                for (_, a), (_, b) in zip(curve, other):
                    assert a == pytest.approx(b, rel=1e-6, abs=1e-12), (figure, key)
    # a consistent shear-thinning thick tube has a maximum flow rate: some curve ends early
    thick = curves["thick_consistent"]
    assert any(dp is None for key, c in thick.items() if key[0] == "0.7" for _, dp in c)
    assert all(dp is not None for key, c in thick.items() if key[0] == "1" for _, dp in c)


# ---------------------------------------------------------------------------- stability_map.py
def test_stability_map_quick(tmp_path, capsys):
    assert load("stability_map").main([str(tmp_path), "--quick"]) == 0
    text = capsys.readouterr().out
    assert_pngs(tmp_path, ["stability_map.png"])
    assert "UNTYPED" not in text and "untyped" not in text
    # (a) the closed forms stay accurate at their removable singularities; the naive formula is 0/0
    worst = numbers(r"default error at the double nearest n\* FLOAT \(ok\), worst over [^:]*: FLOAT", text)
    assert len(worst) == 2 and all(e0 < 1e-14 and e < 1e-13 for e0, e in worst)
    assert text.count("naive formula at n*: NaN (0/0)") == 2
    # (b, c) the default path near the maximum flow rate and the limit pressure, and a typed error beyond
    (b,), = numbers(r"\(b\) tubefsi default: worst error FLOAT", text)
    (c,), = numbers(r"\(c\) tubefsi default: worst q error FLOAT", text)
    assert b < 1e-8 and c < 1e-6
    assert "1.5 q_max: ['NoSteadyStateError', 'NoSteadyStateError', 'NoSteadyStateError']" in text
    assert text.count("1.01 p_max: ['NoSteadyStateError', 'NoSteadyStateError']") == 4
    assert "silent > 1e-3 at none" in text and "silent > 1e-3 at [" not in text
    # (d) tiny to large strain, (e, f) the heat maps: within the accuracy contract
    (d,), = numbers(r"\(d\) tubefsi default: worst FLOAT", text)
    assert d < 1e-12
    heat = numbers(r"worst default-path error FLOAT .*cells above 1e-12: FLOAT; marked cells: FLOAT", text)
    assert len(heat) == 2 and all(e < 1e-12 and above == 0 and marked == 0 for e, above, marked in heat)


# ---------------------------------------------------------------------------- work_precision.py
def test_work_precision_quick(tmp_path, capsys):
    assert load("work_precision").main([str(tmp_path), "--quick"]) == 0
    text = capsys.readouterr().out
    assert_pngs(tmp_path, ["work_precision.png"])
    scenes = re.split(r"\n(?=\d\. )", text)[1:]
    assert len(scenes) == 4
    row = re.compile(r"^  (\S.*?)\s+(FLOAT)\s+(FLOAT) us\s+(\d+)\s+FLOATx".replace("FLOAT", FLOAT), re.MULTILINE)
    for scene in scenes:
        # label: (max relative error, microseconds per point, points timed)
        rows = {m[1]: (float(m[2]), float(m[3]), int(m[4])) for m in row.finditer(scene)}
        assert {"auto (default)", "Quadrature(order=24)", "ODE(LSODA, rtol=1e-06)",
                "ODE(method='odeint')"} <= set(rows), scene
        for label, (err, per, count) in rows.items():
            assert 0 <= err < 1e-1 and 0 < per < 1e6 and count >= 2, (label, scene)
        # the default path meets the accuracy contract (relative 1e-12, or nearly so near the limit)
        assert rows["auto (default)"][0] < 1e-11, scene
        # the default path is much faster than the per-point ODE methods
        assert rows["auto (default)"][1] < rows["ODE(method='odeint')"][1], scene
    assert "ClosedForm()" in scenes[0] and "chapter odeint (lean)" in scenes[2]
    assert "chapter odeint (lean)" not in scenes[3]


# ---------------------------------------------------------------------------- fem_refinement.py
def test_fem_refinement_quick(tmp_path, capsys):
    pytest.importorskip("felupe")
    assert load("fem_refinement").main([str(tmp_path), "--quick"]) == 0
    text = capsys.readouterr().out
    assert_pngs(tmp_path, ["fem_refinement.png"])
    rows = numbers(r"Q(\d)\s+\d+x\d+\s+FLOAT\s+FLOAT", text)
    assert [int(order) for order, *_ in rows] == [1, 1, 2, 2]
    for order, err, rate in rows:
        assert 0 < err < 1e-2
        if not math.isnan(rate):              # a reaction force converges at twice the element order
            assert rate == pytest.approx(2 * order, abs=0.2)
    walls = numbers(r"stretches up to FLOAT: max relative error FLOAT", text)
    assert len(walls) >= 1 and all(top > 1 and err < 1e-4 for top, err in walls)


# ---------------------------------------------------------------------------- network.py
def test_network_writes_its_plot_and_tables(tmp_path, capsys):
    assert load("network").main([str(tmp_path), "--depth", "3"]) == 0
    text = capsys.readouterr().out
    assert_pngs(tmp_path, ["network.png"])
    (iterations, imbalance), = numbers(r"Newton iterations: FLOAT; largest mass imbalance / throughput: FLOAT", text)
    assert iterations >= 1 and imbalance <= 1e-13
    (soft, rigid, inflow), = numbers(r"inlet pressure: soft FLOAT Pa, rigid FLOAT Pa \(outlet 100 Pa, inflow FLOAT", text)
    assert 100.0 < soft < rigid          # the inflated vessels need less pressure than rigid ones
    rows = numbers(r"arteriole\s+FLOAT\s+FLOAT\s+FLOAT\s+FLOAT", text)
    for g, count, q, strain in rows:     # each generation of the tree carries the whole inflow
        assert count == 2**g and q * count == pytest.approx(inflow, rel=1e-12) and strain > 0
    with open(tmp_path / "network_tubes.csv", newline="") as fh:
        tubes = list(csv.DictReader(fh))
    assert len(tubes) == 2 * (2**4 - 1) + 2**3
    assert all(float(t["radius_u"]) > 0 and math.isfinite(float(t["flow_rate"])) for t in tubes)


# ---------------------------------------------------------------------------- validity_map.py
def test_validity_map_quick_is_first_order_in_slenderness(tmp_path, capsys):
    """Two slenderness values of the Newtonian thick-wall scene: tubefsi under-predicts the
    pressure drop by an amount first order in a/L, within the end-layer bound of
    docs/validity.md ((3n+1) strain (a+t)/L), and the FE change from resolution 2 to 4 is well
    below the modelling error."""
    pytest.importorskip("skfem")
    pytest.importorskip("felupe")
    assert load("validity_map").main([str(tmp_path), "--quick"]) == 0
    text = capsys.readouterr().out
    assert_pngs(tmp_path, ["validity_map.png"])
    rows = numbers(r"a/L = FLOAT\s+error = FLOAT  FE change 2->4 = FLOAT", text)
    assert [s for s, *_ in rows] == [0.2, 0.1]
    for s, err, change in rows:
        assert -4 * 0.05 * 1.3 * s < err < 0 and abs(change) < 0.2 * abs(err)
    (order,), = numbers(r"order = FLOAT", text)
    assert order == pytest.approx(1.0, abs=0.3)
    with open(tmp_path / "validity_map.csv", newline="") as fh:
        assert len(list(csv.DictReader(fh))) == 2


# ---------------------------------------------------------------------------- network_study.py
def test_network_study_maps_batches_over_dask(tmp_path, capsys):
    pytest.importorskip("dask.bag")
    pytest.importorskip("distributed")
    study = load("network_study")
    assert study.main([str(tmp_path), "--samples", "60", "--batch", "30"]) == 0
    text = capsys.readouterr().out
    (count, _), = numbers(r"FLOAT networks in FLOAT s on a dask LocalCluster of 2 workers", text)
    (failed,), = numbers(r"FLOAT without a steady state", text)
    assert count == 60 and failed == 0
    with open(tmp_path / "study.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["sample"]) for r in rows] == list(range(60))
    # the same samples solved one by one, serially, give the same split (the batches are
    # disjoint unions: their components do not interact)
    moduli, index = study.draw(60)
    one = study.solve_batch((7, moduli[7:8], index[7:8]))[0]
    assert float(rows[7]["split_fraction"]) == pytest.approx(one[1], rel=1e-12)
    assert 0.5 < float(rows[7]["split_fraction"]) < 1.0


# ---------------------------------------------------------------------------- gallery, README
@pytest.mark.parametrize("script", sorted(p.name for p in (EXAMPLES / "gallery").glob("plot_*.py")))
def test_gallery_scripts_do_not_warn(script, tmp_path, monkeypatch, capsys):
    """A gallery figure is a valid scene, or catches and prints the warning it shows on purpose."""
    import matplotlib.pyplot as plt

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(plt, "show", lambda *a, **k: None)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.ModelValidityWarning)
        exec(compile((EXAMPLES / "gallery" / script).read_text(), script, "exec"), {"__name__": "__main__"})
    plt.close("all")


def test_readme_snippet_does_not_warn(tmp_path, monkeypatch):
    block = re.findall(r"```python\n(.*?)```", (EXAMPLES.parent / "README.md").read_text(), flags=re.S)[0]
    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tubefsi.ModelValidityWarning)
        exec(compile(block, "README.md", "exec"), {})
