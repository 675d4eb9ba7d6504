"""Hostile plugins (issue 25): an entry point whose import calls ``sys.exit`` or raises, one that
gives no class or a class of the wrong base, and a broken provider under warnings-as-errors.

The contract each test checks is the registry's (:mod:`tubefsi.registry`): the plugin is left out
with a :class:`PluginWarning` naming its distribution and entry point, the built-in models still
list and solve (``coupler="auto"`` included), and under warnings-as-errors the warning raises once
without losing any valid provider. The plugins are real distributions written to a temporary
directory on ``sys.path`` (as in ``tests/test_registry.py``).
"""

from __future__ import annotations

import re
import sys
import textwrap
import warnings

import pytest

import tubefsi
from tubefsi import cli, registry
from tubefsi.registry import PluginWarning
from tubefsi.testing.fuzz import bad_input_probes, run_probe

SCENE = ["--rheology", "power-law:consistency=0.017,index=0.7", "--wall", "thick-neo-hookean:shear_modulus=2000",
         "--tube", "radius=1e-4,thickness=3e-5,length=1e-2"]
GOOD_WALL = "from tubefsi.walls.rigid import Rigid\n\nclass Wall(Rigid):\n    '''A plugin's rigid wall.'''\n"


@pytest.fixture
def install(tmp_path, monkeypatch):
    """``install(dist, entry_points, {module: source})``: a throw-away distribution on sys.path;
    sys.path, the modules and the registries are restored afterwards."""
    written = []

    def install(dist, entry_points, modules=None):
        root = tmp_path / dist
        info = root / f"{re.sub(r'[-_.]+', '_', dist)}-1.0.dist-info"
        info.mkdir(parents=True)
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 1.0\n")
        (info / "entry_points.txt").write_text(textwrap.dedent(entry_points))
        for module, source in (modules or {}).items():
            (root / f"{module}.py").write_text(source)
            written.append(module)
        monkeypatch.syspath_prepend(str(root))
        registry.refresh()

    yield install
    for module in written:
        sys.modules.pop(module, None)
    registry.refresh()


def _solve_builtin():
    """A built-in scene with coupler="auto": every registered coupler is ranked."""
    fluid = registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = registry.walls["thick-neo-hookean"](shear_modulus=2e3)
    return tubefsi.solve(fluid, wall, tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2), flow_rate=1e-9)


def _plugin_messages(record):
    return " | ".join(str(w.message) for w in record if issubclass(w.category, PluginWarning))


def test_a_plugin_calling_sys_exit_on_import_is_a_warning(install, capsys):
    """The issue: ``tubefsi list`` exited 3, silently."""
    install("exit-plugin", """
        [tubefsi.walls]
        exit-wall = exit_plugin_walls:Wall
        """, {"exit_plugin_walls": "import sys\nsys.exit(3)\n"})
    assert cli.main(["list"]) == 0
    captured = capsys.readouterr()
    assert "thick-neo-hookean" in captured.out and "exit-wall" not in captured.out
    (line,) = captured.err.splitlines()
    assert line.startswith("tubefsi: warning: ") and "exit-plugin" in line and "'exit-wall'" in line
    assert "SystemExit: 3" in line and "exit_plugin_walls:Wall" in line      # the entry point itself


@pytest.mark.parametrize("raised", ["RuntimeError('boom')", "SystemExit(0)", "BaseException('odd')"])
def test_whatever_an_import_raises_is_a_warning(raised, install):
    install("raising-plugin", """
        [tubefsi.rheologies]
        raising = raising_plugin_fluids:Fluid
        """, {"raising_plugin_fluids": f"raise {raised}\n"})
    with pytest.warns(PluginWarning, match=r"'raising' from raising-plugin failed to load"):
        assert "raising" not in registry.rheologies
    assert _solve_builtin().pressure_drop > 0


def test_keyboard_interrupt_goes_through(install):
    install("interrupted-plugin", """
        [tubefsi.walls]
        interrupted = interrupted_plugin_walls:Wall
        """, {"interrupted_plugin_walls": "raise KeyboardInterrupt\n"})
    with pytest.raises(KeyboardInterrupt):
        registry.walls["interrupted"]


def test_a_non_class_coupler_leaves_auto_to_the_builtins(install):
    """The issue: ``builtins:len`` as a coupler broke every ``auto`` solve, built-ins included."""
    reference = _solve_builtin()
    install("len-plugin", """
        [tubefsi.couplers]
        len = builtins:len
        """)
    with pytest.warns(PluginWarning) as record:
        sol = _solve_builtin()
    message = _plugin_messages(record)
    assert "'len' from len-plugin" in message and "builtins:len" in message
    assert "not a subclass of tubefsi.couplers.Coupler" in message
    assert "len" not in registry.couplers
    assert sol.pressure_drop == reference.pressure_drop        # the scene without the plugin, to the digit


@pytest.mark.parametrize("target, what", [
    ("builtins:len", "a builtin_function_or_method"),
    ("tubefsi.rheology.newtonian:Newtonian", "the class tubefsi.rheology.newtonian.Newtonian"),
    ("builtins:dict", "the class builtins.dict"),
])
def test_a_wall_that_is_no_wall_model_is_left_out_with_a_warning(target, what, install, capsys):
    """The issue: a non-class wall was accepted without a warning and failed later in the CLI."""
    install("odd-walls", f"""
        [tubefsi.walls]
        odd-wall = {target}
        """)
    with pytest.warns(PluginWarning) as record:
        names = list(registry.walls)
    message = _plugin_messages(record)
    assert f"'odd-wall' from odd-walls gives {what}, not a subclass of tubefsi.walls.WallModel" in message
    assert target in message and "odd-wall" not in names and "thick-neo-hookean" in names
    registry.refresh()
    err = _fail(["solve", "--rheology", "newtonian:viscosity=1e-3", "--wall", "odd-wall", *SCENE[4:],
                 "--flow-rate", "1e-9"], capsys)
    assert "unknown wall 'odd-wall'" in err


def test_a_missing_name_is_named_in_the_singular():
    with pytest.raises(KeyError, match="'no-such-fluid' is not a registered rheology; known: "):
        registry.rheologies["no-such-fluid"]


def _fail(argv, capsys):
    assert cli.main(argv) == 2
    captured = capsys.readouterr()
    error = [line for line in captured.err.splitlines() if not line.startswith("tubefsi: warning: ")]
    assert len(error) == 1 and error[0].startswith("tubefsi: error: ") and "internal error" not in error[0]
    return error[0]


@pytest.mark.parametrize("first", ["lookup", "listing"])
def test_warnings_as_errors_keep_the_valid_provider(first, install):
    """The issue: under ``warnings.simplefilter("error")`` the broken provider sorting first raised
    its warning before the valid one was registered, and the name was gone for good."""
    install("aaa-broken", """
        [tubefsi.walls]
        shared-wall = aaa_broken_walls:Wall
        """, {"aaa_broken_walls": "raise ImportError('needs xyzzy')\n"})
    install("bbb-good", """
        [tubefsi.walls]
        shared-wall = bbb_good_walls:Wall
        """, {"bbb_good_walls": GOOD_WALL})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(PluginWarning, match=r"'shared-wall' from aaa-broken failed to load: ImportError"):
            registry.walls["shared-wall"] if first == "lookup" else list(registry.walls)
        assert registry.walls["shared-wall"].__module__ == "bbb_good_walls"          # no warning the second time
        assert registry.walls.distribution("shared-wall") == "bbb-good"
        assert {"shared-wall", "rigid", "thick-neo-hookean"} <= set(registry.walls)
        assert _solve_builtin().pressure_drop > 0


def test_warnings_as_errors_on_the_command_line(install, capsys):
    """``python -W error -m tubefsi list`` with a broken plugin: one error line naming it (not an
    internal error), and the registry intact for the next command."""
    install("exit-plugin", """
        [tubefsi.walls]
        exit-wall = exit_plugin_walls:Wall
        """, {"exit_plugin_walls": "import sys\nsys.exit(3)\n"})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert "exit-plugin" in _fail(["list"], capsys)
        assert cli.main(["list"]) == 0
    assert "thick-neo-hookean" in capsys.readouterr().out


def test_the_hostile_plugins_family_finds_no_breach_and_leaves_no_trace():
    before = {kind: dict(getattr(registry, kind)) for kind in ("rheologies", "walls", "couplers")}
    probes = bad_input_probes(families=["hostile plugins"])
    assert len(probes) >= 30
    breaches = [o for o in map(run_probe, probes) if o.breach]
    assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)
    assert {kind: dict(getattr(registry, kind)) for kind in before} == before


BROKEN_COUPLERS = '''
from tubefsi.couplers.quadrature import Quadrature


class NoBuild(Quadrature):
    """A coupler that cannot be built."""

    cost_rank = -10

    def __init__(self):
        raise RuntimeError("no licence server")


class NoSupports(Quadrature):
    """A coupler whose supports() raises."""

    cost_rank = -9

    def supports(self, rheology, wall):
        raise KeyError("lookup table missing")
'''


def test_a_plugin_coupler_that_raises_is_passed_over_by_auto(install):
    """A coupler of the right base that raises when built or asked what it supports is left out of
    ``auto`` with a warning naming it; the built-ins answer, to the bit."""
    reference = _solve_builtin()
    install("broken-couplers", """
        [tubefsi.couplers]
        no-build = broken_couplers:NoBuild
        no-supports = broken_couplers:NoSupports
        """, {"broken_couplers": BROKEN_COUPLERS})
    with pytest.warns(PluginWarning) as record:
        sol = _solve_builtin()
    message = _plugin_messages(record)
    assert "'no-build'" in message and "no licence server" in message
    assert "'no-supports'" in message and "lookup table missing" in message
    assert sol.pressure_drop == reference.pressure_drop and sol.coupler_name == reference.coupler_name
