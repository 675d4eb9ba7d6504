"""The command line at its edges (issue 25): malformed network files, output paths and suffixes,
a closed or broken standard output, an ASCII-only one.

The contract each test checks is the command's (``docs/cli.md``): a bad file or argument ends
with exit status 2 and one line ``tubefsi: error: ...`` on stderr that says what is wrong and
where, never ``internal error``; a closed or broken standard output ends the command quietly; an
ASCII-only one still gets every command's output.
"""

from __future__ import annotations

import importlib
import io
import json
import os
import subprocess
import sys

import pytest

from tubefsi import cli
from tubefsi.testing.fuzz._cli import _Broken, _closed     # the fuzz family's streams

SCENE = ["--rheology", "newtonian:viscosity=1e-3", "--wall", "rigid", "--tube", "radius=1e-4,thickness=3e-5,length=1e-2"]
NETWORK = {"rheology": "newtonian:viscosity=1e-3",
           "tubes": [{"u": "a", "v": "b", "name": "ab", "wall": "rigid",
                      "tube": {"radius": 1e-4, "thickness": 3e-5, "length": 1e-2}},
                     {"u": "b", "v": "c", "wall": "rigid", "tube": "radius=1e-4,thickness=3e-5,length=1e-2"}],
           "pressures": {"a": 300, "c": 0}, "positions": {"a": [0, 0], "b": [1, 0], "c": [2, 0]}}


def _fail(argv, capsys):
    """The one error line of a refused command."""
    assert cli.main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.splitlines()) == 1, captured
    assert captured.err.startswith("tubefsi: error: ") and "internal error" not in captured.err
    return captured.err


def _tube(**change):
    return {**NETWORK, "tubes": [{**NETWORK["tubes"][0], **change}, NETWORK["tubes"][1]]}


@pytest.fixture
def no_solve(monkeypatch):
    """Any solve is a test failure: the argument must be refused before computing."""
    def refuse(*args, **kwargs):
        raise AssertionError("computed before checking the outputs")
    monkeypatch.setattr(importlib.import_module("tubefsi.solve"), "solve", refuse)


# ---------------------------------------------------------------------------- network files
@pytest.mark.parametrize("content, words", [
    ("[" * 100_000 + "]" * 100_000, ["nested too deeply"]),                       # the cases
    ('{"tubes": [' + "[" * 100_000 + "]" * 100_000 + "]}", ["nested too deeply"]),
    (json.dumps(_tube(u=[1, 2])), ["tubes[0]", "u:", "node name", "[1, 2]"]),
    (json.dumps(_tube(v={"x": 1})), ["tubes[0]", "v:", "node name"]),
    (json.dumps(_tube(tube=5)), ["tubes[0]", "tube:", "got 5"]),
    (json.dumps(_tube(wall=7)), ["tubes[0]", "wall:", "model spec", "got 7"]),
    (json.dumps({**NETWORK, "rheology": 5}), ["rheology", "model spec"]),
    (json.dumps(_tube(name=[1])), ["tubes[0]", "name:"]),
    (json.dumps(_tube(tube={"radius": [1, 2], "thickness": 3e-5, "length": 1e-2})), ["tubes[0]", "radius"]),
    (json.dumps(_tube(external_pressure="x")), ["tubes[0]", "external_pressure"]),
    (json.dumps(_tube(colour="red")), ["tubes[0]", "unknown key 'colour'"]),       # a typo is not ignored
    (json.dumps({**NETWORK, "pressures": 5}), ["pressures:", "expected an object"]),
    (json.dumps({**NETWORK, "pressures": [["a", 1]]}), ["pressures:", "expected an object"]),
    (json.dumps({**NETWORK, "pressures": {"a": "x", "c": 0}}), ["pressures['a']", "number"]),
    (json.dumps({**NETWORK, "pressures": {"a": -1, "c": 0}}), ["pressures['a']", "[0, inf)"]),
    (json.dumps({**NETWORK, "positions": {"a": 5}}), ["positions['a']", "[x, y]"]),
    (json.dumps({**NETWORK, "positions": {"a": [1]}}), ["positions['a']", "[x, y]"]),
    (json.dumps({**NETWORK, "positions": {"a": {"x": 1}}}), ["positions['a']", "[x, y]"]),
    ('{"tubes": [' + "9" * 5000 + "]}", ["is not JSON"]),                     # beyond Python's int digits
    (json.dumps({**NETWORK, "resistances": 5}), ["resistances:", "expected an object"]),
    (json.dumps({**NETWORK, "resistances": {"c": "x"}}), ["resistances['c']", "resistance:", "number"]),
    (json.dumps({**NETWORK, "resistances": {"b": 0}}), ["resistances['b']", "resistance", "(0, inf)"]),
    (json.dumps({**NETWORK, "resistances": {"b": -1e9}}), ["resistances['b']", "resistance", "(0, inf)"]),
    (json.dumps({**NETWORK, "resistances": {"c": 1e9}}), ["resistances['c']", "one boundary condition"]),
    (json.dumps({**NETWORK, "resistances": {"b": [1e9, 0]}}), ["resistances['b']", "resistance:", "number"]),
    (json.dumps({**NETWORK, "resistances": {"b": {"distal_pressure": 5}}}), ["resistances['b']", "\"resistance\""]),
    (json.dumps({**NETWORK, "resistances": {"b": {"resistance": 1e9, "distal": 5}}}),
     ["resistances['b']", "distal_pressure"]),
    (json.dumps({**NETWORK, "resistances": {"b": {"resistance": 1e9, "distal_pressure": "x"}}}),
     ["resistances['b']", "distal_pressure:", "number"]),
    (json.dumps({**NETWORK, "resistances": {"x": 1e9}}), ["resistances['x']", "no node of any tube"]),
    (json.dumps({**NETWORK, "inflows": {"x": 1e-9}}), ["inflows['x']", "no node of any tube"]),
])
def test_a_malformed_network_file_is_one_error_naming_the_place(content, words, tmp_path, capsys):
    path = tmp_path / "net.json"
    path.write_text(content)
    err = _fail(["network", str(path)], capsys)
    assert "net.json" in err
    for word in words:
        assert word in err


def test_a_network_file_of_binary_garbage(tmp_path, capsys):
    path = tmp_path / "net.json"
    path.write_bytes(bytes(range(256)))
    assert "not UTF-8" in _fail(["network", str(path)], capsys)


def test_a_huge_integer_in_the_file_is_refused_not_an_overflow(tmp_path, capsys):
    path = tmp_path / "net.json"
    path.write_text(json.dumps({**NETWORK, "pressures": {"a": 10**400, "c": 0}}))
    assert "pressures['a']" in _fail(["network", str(path)], capsys)


def test_what_the_file_format_accepts_still_solves(tmp_path, capsys):
    """The documented forms (a tube as an object or a string, numbers as strings in the object,
    integer tube names, node positions) give the library's network, to the last digit."""
    import tubefsi

    spec = _tube(name=7, tube={"radius": "1e-4", "thickness": 3e-5, "length": 1e-2})
    path = tmp_path / "net.json"
    path.write_text(json.dumps(spec))
    assert cli.main(["network", str(path)]) == 0
    data = json.loads(capsys.readouterr().out)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    net = tubefsi.Network(rheology=fluid).add_tube("a", "b", "rigid", tube, name=7).add_tube("b", "c", "rigid", tube)
    ref = net.set_pressure("a", 300.0).set_pressure("c", 0.0).solve()
    assert {t["name"]: t["flow_rate"] for t in data["tubes"]}[7] == ref.flow_rate[7]


def test_resistance_outlets_in_the_file_are_the_librarys(tmp_path, capsys):
    """A file's resistance outlets (a number R, or an object with a distal pressure) give the
    network of :meth:`Network.set_resistance` to the last digit; and, as an independent check, the
    rigid Newtonian chain a -> b -> c with c an outlet R to p_d is the series circuit: the flow
    (p_a - p_d) / (2 R_tube + R), R_tube = 8 mu L / (pi a^4) (Poiseuille)."""
    import math

    import tubefsi

    r_out, p_d = 5e11, 40.0
    for given, distal in ((r_out, 0.0), ({"resistance": r_out, "distal_pressure": p_d}, p_d)):
        spec = {**NETWORK, "pressures": {"a": 300}, "resistances": {"c": given}}
        path = tmp_path / "net.json"
        path.write_text(json.dumps(spec))
        assert cli.main(["network", str(path)]) == 0
        data = json.loads(capsys.readouterr().out)
        flows = {t["name"]: t["flow_rate"] for t in data["tubes"]}
        fluid = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
        tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
        net = tubefsi.Network(rheology=fluid).add_tube("a", "b", "rigid", tube, name="ab")
        net.add_tube("b", "c", "rigid", tube).set_pressure("a", 300.0).set_resistance("c", r_out, distal)
        assert flows["ab"] == net.solve().flow_rate["ab"]
        r_tube = 8 * 1e-3 * 1e-2 / (math.pi * 1e-4**4)
        assert flows["ab"] == pytest.approx((300.0 - distal) / (2 * r_tube + r_out), rel=1e-10)


# ---------------------------------------------------------------------------- output paths
@pytest.mark.parametrize("suffix, words", [(".png", ["'.png'", "--plot"]), (".xlsx", ["'.xlsx'", ".csv"]),
                                           (".txt", ["'.txt'", "--format"])])
def test_an_output_suffix_that_is_no_table_format_is_refused_before_computing(suffix, words, tmp_path, no_solve,
                                                                               capsys):
    path = tmp_path / f"y{suffix}"
    err = _fail(["curve", *SCENE, "--flow-rate", "0:1e-9:3", "--output", str(path)], capsys)
    for word in words:
        assert word in err
    assert not path.exists()


def test_an_explicit_format_takes_any_file_name(tmp_path, capsys):
    path = tmp_path / "y.txt"
    assert cli.main(["curve", *SCENE, "--flow-rate", "0:1e-9:3", "--format", "csv", "--output", str(path)]) == 0
    assert path.read_text().startswith("pressure_drop (Pa),")


@pytest.mark.parametrize("argv", [
    ["curve", *SCENE, "--flow-rate", "0:1e-9:3", "--output", ""],
    ["curve", *SCENE, "--flow-rate", "0:1e-9:3", "--plot", ""],
    ["network", "net.json", "--output", ""],
    ["network", "net.json", "--plot", ""],
    ["reproduce", ""],
], ids=["curve --output", "curve --plot", "network --output", "network --plot", "reproduce"])
def test_an_empty_output_path_is_refused(argv, no_solve, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)            # the old code wrote ``reproduce ""``'s figures here
    assert "needs a file name" in _fail(argv, capsys)


def test_network_output_suffix(tmp_path, capsys):
    path = tmp_path / "net.json"
    path.write_text(json.dumps(NETWORK))
    err = _fail(["network", str(path), "--output", str(tmp_path / "out.png")], capsys)
    assert "'.png'" in err and "--format csv" in err
    assert cli.main(["network", str(path), "--output", str(tmp_path / "out.json")]) == 0
    assert json.loads((tmp_path / "out.json").read_text())["tubes"]


# ---------------------------------------------------------------------------- standard output
@pytest.mark.parametrize("stdout", [None, _closed, _Broken], ids=["None", "closed", "broken pipe"])
@pytest.mark.parametrize("argv", [["solve", *SCENE, "--flow-rate", "1e-9", "--json"], ["list"], ["--help"]],
                         ids=["solve --json", "list", "--help"])
def test_a_closed_or_broken_stdout_ends_quietly(argv, stdout, monkeypatch, capsys):
    """``tubefsi ... >&-`` (Python's sys.stdout is then None) and ``tubefsi ... | head``: status 0,
    nothing on stderr (the issue: an AttributeError reported as an internal error)."""
    monkeypatch.setattr(sys, "stdout", stdout() if stdout else None)
    assert cli.main(argv) == 0
    assert capsys.readouterr().err == ""


def test_a_closed_stdout_still_writes_the_output_file(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "stdout", None)
    assert cli.main(["curve", *SCENE, "--flow-rate", "0:1e-9:3", "--output", str(tmp_path / "c.csv")]) == 0
    assert len((tmp_path / "c.csv").read_text().splitlines()) == 4


@pytest.mark.parametrize("argv", [["list"], ["--help"], ["curve", "--help"], ["solve", *SCENE, "--flow-rate", "1e-9"]])
def test_an_ascii_only_stdout_gets_every_command(argv, monkeypatch):
    stream = io.TextIOWrapper(io.BytesIO(), encoding="ascii")
    monkeypatch.setattr(sys, "stdout", stream)
    assert cli.main(argv) == 0
    stream.flush()
    text = stream.buffer.getvalue().decode("ascii")
    assert text
    if argv == ["--help"]:
        assert "fluid\\u2013structure" in text            # the dash degraded, not lost


@pytest.mark.parametrize("env", [{"PYTHONIOENCODING": "ascii"}, {"LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0"}],
                         ids=["PYTHONIOENCODING=ascii", "LC_ALL=C"])
def test_an_ascii_terminal_in_a_fresh_process(env):
    """The issue's conditions themselves: ``tubefsi list`` exited 2 on an en dash."""
    result = subprocess.run([sys.executable, "-m", "tubefsi", "list"], capture_output=True,
                            env={**os.environ, **env}, timeout=120)
    assert result.returncode == 0, result.stderr
    assert b"rigid" in result.stdout and result.stdout.isascii() and result.stderr == b""
