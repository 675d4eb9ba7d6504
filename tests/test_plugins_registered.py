"""The extension packages in ``plugins/`` are separate distributions, found only through entry points.

``make test`` installs every ``plugins/*/pyproject.toml`` (editable); these tests check that
the registries then list their names, that tubefsi itself never imports them, and that each
plugin's models are served by the core's generic paths.
"""

import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest

from tubefsi import registry

ROOT = Path(__file__).resolve().parents[1]
PLUGINS = {
    "tubefsi-rheologies": ("tubefsi_rheologies", "tubefsi.rheologies",
                           ["bingham", "carreau", "carreau-yasuda", "casson", "cross", "ellis", "herschel-bulkley"]),
    "tubefsi-hyperelastic": ("tubefsi_hyperelastic", "tubefsi.walls",
                             ["thick-demiray", "thick-gent", "thick-ogden", "thick-yeoh",
                              "thin-demiray", "thin-gent", "thin-ogden", "thin-yeoh"]),
}


def _installed(dist):
    try:
        metadata.distribution(dist)
    except metadata.PackageNotFoundError:
        return False
    return True


@pytest.mark.parametrize("dist", sorted(PLUGINS))
def test_plugin_is_installed_and_registered(dist):
    assert (ROOT / "plugins" / dist / "pyproject.toml").is_file()
    assert _installed(dist), f"{dist} is not installed: `make install` installs every plugins/*/ editable"
    module, group, names = PLUGINS[dist]
    reg = registry.rheologies if group == "tubefsi.rheologies" else registry.walls
    for name in names:
        assert name in reg
        assert reg.distribution(name) == dist
        assert reg[name].__module__.startswith(module + ".")
    declared = sorted(ep.name for ep in metadata.distribution(dist).entry_points if ep.group == group)
    assert declared == sorted(names)


def test_the_core_never_imports_a_plugin():
    for path in (ROOT / "src" / "tubefsi").rglob("*.py"):
        text = path.read_text()
        for module, _, _ in PLUGINS.values():
            assert f"import {module}" not in text and f"from {module}" not in text, path
    code = ("import sys, tubefsi, tubefsi.solve, tubefsi.testing\n"
            "assert not any(m.startswith(('tubefsi_rheologies', 'tubefsi_hyperelastic')) for m in sys.modules)\n"
            "from tubefsi import registry\n"
            "registry.walls['thick-gent']; registry.rheologies['carreau']\n"
            "assert 'tubefsi_hyperelastic' in sys.modules and 'tubefsi_rheologies' in sys.modules\n")
    if not all(_installed(d) for d in PLUGINS):
        pytest.skip("plugins not installed")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_plugin_models_use_the_generic_paths():
    """Nothing in the solver special-cases a plugin: the default coupler serves them."""
    import tubefsi

    fluid = registry.rheologies["herschel-bulkley"](yield_stress=0.5, consistency=0.2, index=0.6)
    wall = registry.walls["thick-gent"](shear_modulus=5e3, locking_parameter=3.0)
    tube = tubefsi.Tube(radius=5e-4, thickness=1.5e-4, length=2e-2)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=[0.0, 1e-9, 1e-8])
    assert sol.coupler_name == "quadrature"
    assert sol.pressure_drop[0] == 0.0 and 0 < sol.pressure_drop[1] < sol.pressure_drop[2]
    back = tubefsi.solve(fluid, wall, tube, pressure_drop=sol.pressure_drop[1:])
    assert back.flow_rate == pytest.approx([1e-9, 1e-8], rel=1e-10)
