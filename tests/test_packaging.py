"""What a user gets besides the code (issue 27, item 5): the package's namespace, its licence in
the metadata, the typing marker, the citation file and the changelog.

The wheel itself (that these files ship, that it installs into a fresh environment and solves)
is checked by CI, which builds and installs it (``.ci/run``).
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import tubefsi

ROOT = Path(__file__).resolve().parents[1]
PROJECTS = [ROOT, *sorted(p.parent for p in (ROOT / "plugins").glob("*/pyproject.toml"))]


def test_the_namespace_holds_only_public_names_and_submodules():
    """Contract: every public attribute of ``tubefsi`` (no leading underscore) is in ``__all__`` or
    is one of its submodules; the helpers ``__init__`` imports (sys, importlib, types) were
    ``tubefsi.sys`` and the like. In a fresh interpreter, after every lazy name has loaded."""
    code = ("import types, tubefsi\n"
            "for name in tubefsi.__all__: getattr(tubefsi, name)\n"
            "extra = [n for n in dir(tubefsi) if not n.startswith('_') and n not in tubefsi.__all__\n"
            "         and not (isinstance(getattr(tubefsi, n), types.ModuleType)\n"
            "                  and getattr(tubefsi, n).__name__ == 'tubefsi.' + n)]\n"
            "assert not extra, extra\n"
            "assert not any(hasattr(tubefsi, n) for n in ('sys', 'importlib', 'types'))\n")
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("project", PROJECTS, ids=lambda p: "tubefsi" if p == ROOT else p.name)
def test_licence_is_an_spdx_expression_with_its_file(project):
    """PEP 639, the form setuptools no longer warns about: ``license`` an SPDX string, the text in
    ``license-files`` (which exist), and no ``License ::`` classifier beside it (an error)."""
    meta = tomllib.loads((project / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert meta["license"] == "BSD-3-Clause"
    assert meta["license-files"] and all((project / f).is_file() for f in meta["license-files"])
    assert "BSD 3-Clause License" in (project / meta["license-files"][0]).read_text(encoding="utf-8")
    assert not [c for c in meta["classifiers"] if c.startswith("License ::")]
    assert meta["keywords"] and any(c.startswith("Topic :: Scientific/Engineering") for c in meta["classifiers"])


def test_the_package_is_marked_typed_and_ships_the_marker():
    """PEP 561: ``py.typed`` beside ``__init__.py`` and declared as package data (a source file
    that is not a module ships only if declared)."""
    assert (Path(tubefsi.__file__).parent / "py.typed").is_file()
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    assert "py.typed" in setuptools["package-data"]["tubefsi"]


def test_citation_file_cites_the_software_and_the_chapter():
    """CITATION.cff (CFF 1.2.0): tubefsi as the preferred citation at the package's version, and the
    chapter it implements (the one ``tubefsi.chapter`` names) among the references."""
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0"
    for key in ("message", "title", "authors"):
        assert cff[key]
    assert cff["version"] == cff["preferred-citation"]["version"] == tubefsi.__version__
    assert cff["preferred-citation"]["type"] == "software" and "tubefsi" in cff["preferred-citation"]["title"]
    chapter = cff["references"][0]
    assert chapter["title"] == "On the deformation of a hyperelastic tube due to steady viscous flow within"
    assert [a["family-names"] for a in chapter["authors"]] == ["Anand", "Christov"]
    from tubefsi import chapter as module

    assert chapter["title"] in re.sub(r"\s+", " ", module.__doc__)


def test_changelog_has_the_current_version():
    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert re.search(rf"^## \[?{re.escape(tubefsi.__version__)}\]?", text, re.M)


def _public_signatures():
    import importlib

    from tubefsi import Network, NetworkSolution, Problem, Solution

    advise_module = importlib.import_module("tubefsi.advise")     # the module: tubefsi.advise is the function
    methods = {Problem: ["__init__", "solve", "max_flow_rate"],
               Network: ["__init__", "add_tube", "set_pressure", "set_inflow", "set_position", "solve"],
               NetworkSolution: ["solution", "to_csv", "to_json"],
               Solution: ["pressure", "radius", "displacement", "pressure_gradient", "wall_shear_stress", "velocity",
                          "to_dataframe", "to_xarray", "diagnostics", "dpressure_drop_dparameter"]}
    targets = [tubefsi.solve, tubefsi.max_flow_rate, tubefsi.select_coupler, tubefsi.fit, tubefsi.advise,
               advise_module.diagnostics]
    targets += [getattr(cls, name) for cls, names in methods.items() for name in names]
    return targets


@pytest.mark.parametrize("function", _public_signatures(), ids=lambda f: f.__qualname__)
def test_public_parameters_are_annotated_and_resolve(function):
    """Issue 27 item 5: every parameter of the public entry points, the Network methods and the
    Solution accessors has a type annotation, and ``typing.get_type_hints`` resolves them (every
    name in them exists: a type checker, or a tool reading them at run time, can use them)."""
    import inspect
    import typing

    params = [p for p in inspect.signature(inspect.unwrap(function)).parameters.values()
              if p.name not in ("self", "cls")]
    assert all(p.annotation is not inspect.Parameter.empty for p in params), \
        [p.name for p in params if p.annotation is inspect.Parameter.empty]
    hints = typing.get_type_hints(function)
    assert {p.name for p in params} <= set(hints)


def test_tube_fields_are_annotated_and_resolve():
    import typing

    hints = typing.get_type_hints(tubefsi.Tube)
    assert {"radius", "thickness", "length"} <= set(hints)
    assert hints["radius"] != float       # a number, an array, a Profile or a function of z


def test_type_checkers_see_every_lazy_name():
    """The public names load on first use (``tubefsi.__getattr__``), which a type checker cannot
    follow: ``__init__``'s ``if TYPE_CHECKING:`` block imports each of them for it, else
    ``tubefsi.solve`` would be ``Any`` to mypy and the annotations would not reach users."""
    import ast

    tree = ast.parse(Path(tubefsi.__file__).read_text(encoding="utf-8"))
    blocks = [n for n in tree.body if isinstance(n, ast.If) and ast.unparse(n.test).endswith("TYPE_CHECKING")]
    declared = {alias.asname or alias.name for block in blocks for node in block.body
                if isinstance(node, ast.ImportFrom) for alias in node.names}
    assert declared == set(tubefsi._LAZY)
