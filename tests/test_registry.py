"""Entry-point registries: built-ins declared in pyproject, lazy, cached, warn on broken plugins."""

import collections.abc
import importlib
import re
import sys
import textwrap
import warnings
from importlib import metadata

import pytest

import tubefsi
from tubefsi import registry
from tubefsi.registry import PluginWarning, Registry

BUILTIN_WALLS = {"rigid", "thin-linear", "thick-linear", "thin-mooney-rivlin", "thick-mooney-rivlin",
                 "thin-neo-hookean", "thick-neo-hookean"}


def test_builtins_come_from_our_entry_points():
    assert BUILTIN_WALLS <= set(registry.walls)
    assert {"newtonian", "power-law"} <= set(registry.rheologies)
    assert {"closed-form", "quadrature", "ode"} <= set(registry.couplers)
    assert registry.walls.distribution("thick-mooney-rivlin") == "tubefsi"
    assert registry.walls.name_of(registry.walls["rigid"]()) == "rigid"


def test_registry_is_a_read_only_mapping():
    assert isinstance(registry.walls, collections.abc.Mapping)
    with pytest.raises(TypeError):
        registry.walls["x"] = object
    with pytest.raises(KeyError, match="known:"):
        registry.walls["no-such-wall"]


def test_lazy_and_cached():
    reg = Registry("tubefsi.walls")
    assert reg._entries is None  # nothing read at construction
    first = reg["rigid"]
    assert reg._entries is not None and reg["rigid"] is first
    reg.refresh()
    assert reg._entries is None and reg["rigid"] is first


@pytest.fixture
def fake_plugins(tmp_path, monkeypatch):
    """Two installed distributions: one broken, one re-declaring a built-in name."""
    for dist, body in {
        "broken_plugin-1.0": """
            [tubefsi.walls]
            broken-wall = broken_plugin_module_that_does_not_exist:Wall
            """,
        "dup_plugin-1.0": """
            [tubefsi.walls]
            rigid = tubefsi.walls.linear:ThinLinear
            """,
    }.items():
        info = tmp_path / f"{dist}.dist-info"
        info.mkdir()
        name = dist.split("-")[0]
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
        (info / "entry_points.txt").write_text(textwrap.dedent(body))
    monkeypatch.syspath_prepend(str(tmp_path))
    yield
    registry.refresh()


def test_broken_or_duplicate_plugin_is_a_warning_naming_it(fake_plugins):
    reg = Registry("tubefsi.walls")
    with pytest.warns(PluginWarning) as record:
        names = list(reg)
    messages = " ".join(str(w.message) for w in record)
    assert "broken-wall" in messages and "broken_plugin" in messages
    assert "'rigid'" in messages and "dup_plugin" in messages
    assert "broken-wall" not in names
    assert reg["thick-neo-hookean"] is registry.walls["thick-neo-hookean"]
    assert reg["rigid"].__name__ in ("Rigid", "ThinLinear")  # no crash (the built-in wins: see below)


@pytest.fixture
def install(tmp_path):
    """Install throw-away distributions (dist-info + module) on sys.path for one test.

    ``install(name, entry_points, modules, first=True)`` writes ``<name>-1.0.dist-info``
    (escaped) and the modules into their own directory, puts it first (or last) on sys.path
    and refreshes the registries. Afterwards sys.path, the modules and the registries are restored.
    """
    written = []
    with pytest.MonkeyPatch.context() as mp:

        def install(name, entry_points, modules=None, first=True):
            root = tmp_path / name
            # escaped as a wheel would (importlib reads the name up to the first '-' of the directory)
            info = root / f"{re.sub(r'[-_.]+', '_', name)}-1.0.dist-info"
            info.mkdir(parents=True)
            (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
            (info / "entry_points.txt").write_text(textwrap.dedent(entry_points))
            for module, source in (modules or {}).items():
                (root / f"{module}.py").write_text(textwrap.dedent(source))
                written.append(module)
            if first:
                mp.syspath_prepend(str(root))
            else:  # after site-packages (do not mix with first=True in one test)
                mp.setattr(sys, "path", [*sys.path, str(root)])
                importlib.invalidate_caches()
            registry.refresh()

        yield install
    for module in written:
        sys.modules.pop(module, None)
    registry.refresh()


def _providers(group, name):
    """The distributions declaring ``name``, in discovery order."""
    return [ep.dist.name for ep in metadata.entry_points(group=group) if ep.name == name]


def _messages(record):
    return [str(w.message) for w in record if issubclass(w.category, PluginWarning)]


@pytest.mark.parametrize("first", [True, False], ids=["plugin-first", "plugin-last"])
def test_builtin_name_cannot_be_taken_over(install, first):
    from tubefsi.walls.neo_hookean import ThickNeoHookean

    install("tubefsi-bad", """
        [tubefsi.walls]
        thick-neo-hookean = tubefsi_bad_walls:Impostor
        """, {"tubefsi_bad_walls": "class Impostor:\n    pass\n"}, first=first)
    # both discovery orders are really exercised
    assert _providers("tubefsi.walls", "thick-neo-hookean") == (
        ["tubefsi-bad", "tubefsi"] if first else ["tubefsi", "tubefsi-bad"])
    with pytest.warns(PluginWarning) as record:
        assert registry.walls["thick-neo-hookean"] is ThickNeoHookean
    (message,) = _messages(record)
    assert "'thick-neo-hookean'" in message and "tubefsi-bad" in message
    assert re.search(r"using tubefsi\b(?!-)", message)
    assert registry.walls.distribution("thick-neo-hookean") == "tubefsi"
    assert registry.walls.name_of(ThickNeoHookean) == "thick-neo-hookean"
    assert BUILTIN_WALLS <= set(registry.walls)
    assert "tubefsi_bad_walls" not in sys.modules  # the losing entry point is never imported


@pytest.mark.parametrize("order", [("alpha_walls", "Zeta-Walls"), ("Zeta-Walls", "alpha_walls")])
def test_collision_between_plugins_does_not_depend_on_discovery_order(install, order):
    # normalized names: alpha-walls < zeta-walls (the raw names sort the other way: 'Z' < 'a')
    modules = {"alpha_walls": ("alpha_walls_mod", "AlphaWall"), "Zeta-Walls": ("zeta_walls_mod", "ZetaWall")}
    for dist in order:
        module, cls = modules[dist]
        install(dist, f"""
            [tubefsi.walls]
            fake-wall = {module}:{cls}
            only-{cls.lower()} = {module}:{cls}
            """, {module: f"from tubefsi.walls import WallModel\n\nclass {cls}(WallModel):\n    pass\n"})
    assert _providers("tubefsi.walls", "fake-wall") == list(reversed(order))  # each install goes first
    registry.walls["rigid"]
    assert "alpha_walls_mod" not in sys.modules and "zeta_walls_mod" not in sys.modules  # lazy per name
    with pytest.warns(PluginWarning) as record:
        assert registry.walls["fake-wall"].__name__ == "AlphaWall"
    (message,) = _messages(record)
    assert "'fake-wall'" in message and "alpha_walls" in message and "Zeta-Walls" in message
    assert "using alpha_walls" in message
    assert registry.walls.distribution("fake-wall") == "alpha_walls"
    assert "zeta_walls_mod" not in sys.modules  # the losing entry point is never imported
    assert registry.walls["only-zetawall"].__name__ == "ZetaWall"  # the loser's other names are unaffected


@pytest.mark.parametrize("order", [("aaa-broken", "bbb-good"), ("bbb-good", "aaa-broken")])
def test_broken_plugin_warns_and_does_not_block_a_lower_priority_provider(install, order):
    plugins = {
        "aaa-broken": ("""
            [tubefsi.walls]
            fake-wall = aaa_broken_walls:Wall
            only-broken = aaa_broken_walls:Wall
            """, {"aaa_broken_walls": "raise ImportError('needs the missing package xyzzy')\n"}),
        "bbb-good": ("""
            [tubefsi.walls]
            fake-wall = bbb_good_walls:GoodWall
            """, {"bbb_good_walls": "from tubefsi.walls import WallModel\n\nclass GoodWall(WallModel):\n    pass\n"}),
    }
    for dist in order:
        install(dist, *plugins[dist])
    with pytest.warns(PluginWarning) as record:
        assert registry.walls["fake-wall"].__name__ == "GoodWall"
    (message,) = _messages(record)
    assert "'fake-wall'" in message and "aaa-broken" in message
    assert "ImportError" in message and "xyzzy" in message
    assert registry.walls.distribution("fake-wall") == "bbb-good"
    with pytest.warns(PluginWarning, match=r"'only-broken' from aaa-broken failed to load: ImportError"):
        names = list(registry.walls)
    assert "only-broken" not in names and "only-broken" not in registry.walls
    assert BUILTIN_WALLS | {"fake-wall"} <= set(names)
    with pytest.raises(KeyError, match="known:"):
        registry.walls["only-broken"]


def test_same_distribution_seen_twice_is_silent(monkeypatch):
    real = metadata.entry_points
    monkeypatch.setattr(metadata, "entry_points", lambda **params: [*real(**params), *real(**params)])
    reg = Registry("tubefsi.walls")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PluginWarning)
        assert BUILTIN_WALLS <= set(reg)
    assert reg.distribution("rigid") == "tubefsi"


def test_model_defined_in_a_script_needs_no_packaging():
    import attrs
    import numpy as np

    from tubefsi.walls import WallModel

    @attrs.frozen
    class StiffeningWall(WallModel):
        """p = E tb (lam^2 - 1): defined only by its tube law."""

        _examples = ({},)

        def _pressure(self, stretch, tb):
            return 1e3 * tb * (stretch * stretch - 1.0)

    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = registry.rheologies["newtonian"](viscosity=1e-3)
    sol = tubefsi.solve(fluid, StiffeningWall(), tube, flow_rate=1e-9)
    assert sol.coupler_name == "quadrature"
    # independent check: tube law p = 300 (lam^2 - 1) with the Newtonian separated integral
    # 8 mu q L / (pi a^4) = int_1^lam P'(s) s^4 ds = 600 (lam^6 - 1)/6
    lam = (1 + 8e-3 * 1e-9 * 1e-2 / (np.pi * 1e-16) / 100.0) ** (1 / 6)
    assert sol.pressure_drop == pytest.approx(300.0 * (lam**2 - 1), rel=1e-12)
    assert sys.modules[__name__]  # (keeps the local class alive in the module namespace)
