"""Entry-point registries: built-ins declared in pyproject, lazy, cached, warn on broken plugins."""

import collections.abc
import sys
import textwrap

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
    assert reg["rigid"].__name__ in ("Rigid", "ThinLinear")  # first declaration wins, either way no crash


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
