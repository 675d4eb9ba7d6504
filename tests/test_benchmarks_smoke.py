"""Smoke test of ``benchmarks/speed.py``, and the chapter baseline against tubefsi's answers.

No wall-clock threshold is asserted here (timings on a shared machine are noise; the targets are
checked by reading the benchmark's table). The test runs ``speed.py --quick`` as a module, as
``examples/test_examples.py`` runs the examples, and checks what a reader checks: every call shape
has a row, every measured value is a finite positive number, and the JSON holds the same table.
The baseline's *accuracy* is not timing, so it is asserted: the lean ``odeint`` of
``tubefsi.testing.reference.chapter_baseline`` agrees with tubefsi's default answer to about
odeint's default tolerances.
"""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference.chapter_baseline import chapter_thick, chapter_thin

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)


def load(name):
    spec = importlib.util.spec_from_file_location(f"benchmarks_{name}", BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_speed_quick_prints_every_call_shape_with_finite_values(tmp_path, capsys):
    speed = load("speed")
    out = tmp_path / "speed.json"
    assert speed.main(["--quick", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    keys = [key for key, *_ in speed.ROWS]
    assert len(keys) == 11
    data = json.loads(out.read_text())
    assert data["quick"] is True and [r["key"] for r in data["rows"]] == keys
    lines = text.splitlines()
    for i, r in enumerate(data["rows"], 1):
        # the data: a finite positive measurement of every call shape, against its target
        assert math.isfinite(r["value"]) and r["value"] > 0 and math.isfinite(r["tubefsi_s"]), r["key"]
        assert isinstance(r["met"], bool) and r["target"] > 0
        if r["kind"] == "ratio":
            assert math.isfinite(r["baseline_s"]) and r["baseline_s"] > 0, r["key"]
        if isinstance(r["err_baseline"], float):              # the baseline solves the same problem
            assert r["err_baseline"] < 1e-4, r["key"]
        # the printed table: a numbered row with the same measured value and target, and a note
        value, target = speed.value_text(speed.Row(**{k: v for k, v in r.items() if k != "met"}))
        row = [line for line in lines if line.startswith(f"{i:2d} {r['shape']}")]
        assert len(row) == 1 and value in row[0] and target in row[0], (r["key"], row)
        assert any(line.startswith(f"{i:2d}. {r['key']}: ") for line in lines), r["key"]
    assert "targets met" in text and "FAILED" not in text
    assert "loop" in text or "broadcast" in text            # the random scenes say how they were solved


@pytest.mark.parametrize("name, baseline", [("thick-neo-hookean", chapter_thick), ("thin-neo-hookean", chapter_thin)])
def test_chapter_baseline_agrees_with_tubefsi(name, baseline):
    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    wall = walls[name](shear_modulus=2e3)
    thick_wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = 0.9 * tubefsi.max_flow_rate(fluid, thick_wall, TUBE) * np.array([1e-4, 0.01, 0.3, 0.7, 1.0])
    sol = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    for qi, dp, u in zip(q, sol.pressure_drop, sol.inlet_displacement):
        got_dp, got_u = baseline(qi, 0.7, 0.017, 2e3, TUBE)
        assert type(got_dp) is float and type(got_u) is float
        assert got_dp == pytest.approx(dp, rel=1e-5) and got_u == pytest.approx(u, rel=1e-5), qi


def test_network_benchmark_quick_prints_finite_ratios(tmp_path, capsys):
    """``benchmarks/network.py --quick``: a row per tree size with finite positive times (no
    threshold: timings on a shared machine are noise) and a converged mass balance."""
    network = load("network")
    out = tmp_path / "network.json"
    assert network.main(["--quick", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert [r["tubes"] for r in data["rows"]] == [63, 255]
    for r in data["rows"]:
        assert r["nonlinear_s"] > 0 and r["linear_s"] > 0 and math.isfinite(r["ratio"])
        assert r["mass_balance"] <= 1e-12 and r["iterations"] >= 1
    assert "ratio" in capsys.readouterr().out


def test_allocator_quick_prints_both_settings(capsys):
    """benchmarks/allocator.py --quick: both malloc settings get a finite positive time per call."""
    allocator = load("allocator")
    assert allocator.main(["--quick"]) == 0
    out = capsys.readouterr().out
    rows = {line.split("  ")[0]: line for line in out.splitlines() if line.startswith(("glibc", "GLIBC"))}
    assert set(rows) == {"glibc defaults", "GLIBC_TUNABLES set"}
    for line in rows.values():
        ms = float(line.split()[2])
        assert math.isfinite(ms) and ms > 0
    assert float(out.rsplit(":", 1)[1]) > 0
