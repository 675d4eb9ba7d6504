"""The layers of the package: the data flow runs one way and no import doubles back.

Models → scene → couplers → Solution → solve → the user-facing modules: every import of a
tubefsi module (module-level *and* inside functions, read from the source with ``ast``) goes
to the same or a lower layer, and the import graph has no cycle. The only exceptions are the
documented accessors that reach an upper layer on purpose, at call time
(``WallModel.plot``, ``Solution.plot``, ``Solution.diagnostics``, ``NetworkSolution.plot``).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "tubefsi"

#: Lower layers first; a module may import only from its own layer or below.
LAYERS = [
    {"tubefsi.errors", "tubefsi.fields", "tubefsi.numerics", "tubefsi._validation",
     "tubefsi._progress", "tubefsi._units", "tubefsi._lazy", "tubefsi.profiles", "tubefsi._keywords",
     "tubefsi.registry", "tubefsi._html"},
    {"tubefsi.geometry", "tubefsi.rheology", "tubefsi.walls"},
    {"tubefsi.scene"},
    {"tubefsi.couplers"},
    {"tubefsi.solution", "tubefsi.validity", "tubefsi.export"},
    {"tubefsi.solve"},
    {"tubefsi.advise", "tubefsi.fit", "tubefsi.dimensionless", "tubefsi.network", "tubefsi.network_solution",
     "tubefsi.network_io", "tubefsi.datasets",
     "tubefsi.network_groups", "tubefsi.network_solver", "tubefsi.network_fit", "tubefsi.evolve"},
    {"tubefsi.fem"},
    {"tubefsi.chapter", "tubefsi.plotting"},
    {"tubefsi.cli", "tubefsi.testing", "tubefsi"},
]

#: (importer, imported) pairs allowed to point upward: the documented accessors.
ACCESSORS = {
    ("tubefsi.walls.base", "tubefsi.plotting"),       # WallModel.plot
    ("tubefsi.solution", "tubefsi.plotting"),         # Solution.plot
    ("tubefsi.solution", "tubefsi.advise"),           # Solution.diagnostics
    ("tubefsi.network_solution", "tubefsi.plotting"),  # NetworkSolution.plot
}


def _module(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES = {_module(p): p for p in SRC.rglob("*.py")}


def _imports(name: str, path: Path):
    """``(imported module, line, at module level)`` for every tubefsi import in ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    top = {id(node) for node in tree.body}
    for node in tree.body:       # imports for type checkers only (never run) count as module-level
        if isinstance(node, ast.If) and ast.unparse(node.test).endswith("TYPE_CHECKING"):
            top |= {id(n) for n in node.body}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            targets = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in MODULES] or [target]
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        else:
            continue
        for t in targets:
            if t == "tubefsi" or t.startswith("tubefsi."):
                yield t, node.lineno, id(node) in top


def _layer(name: str) -> int:
    for rank, layer in enumerate(LAYERS):
        if any(name == m or name.startswith(m + ".") for m in layer):
            return rank
    raise AssertionError(f"{name} is in no layer of test_architecture.LAYERS: add it")


EDGES = [(m, t, line, top) for m, p in MODULES.items() for t, line, top in _imports(m, p)
         if t != m and not m.startswith(t + ".")]   # a module's own package is its __init__


def test_every_module_has_a_layer():
    for name in MODULES:
        _layer(name)


@pytest.mark.parametrize("importer, imported, line, top", EDGES, ids=[f"{e[0]}:{e[2]}" for e in EDGES])
def test_imports_go_down_the_layers(importer, imported, line, top):
    if (importer, imported) in ACCESSORS:
        assert not top, f"the accessor import {importer} -> {imported} must stay inside its method"
        return
    assert _layer(imported) <= _layer(importer), (
        f"{importer} (line {line}) imports {imported}, an upper layer")


#: Modules of the top layer that import lazily, inside functions, on purpose: the command line
#: starts without SciPy for --help, --version; tubefsi.testing imports its suites on first use, so
#: that a conftest can load a hypothesis profile (tubefsi.testing.profiles) before the suites
#: create their settings (a downward import can make no cycle).
LAZY = {"tubefsi.cli", "tubefsi.testing"}


def test_function_level_imports_only_where_documented():
    """Inside functions a tubefsi module is imported only by the accessors (no hidden cycle)."""
    inner = [(m, t, line) for m, t, line, top in EDGES
             if not top and (m, t) not in ACCESSORS and not (m in LAZY and _layer(t) <= _layer(m))]
    assert inner == []


def test_the_import_graph_has_no_cycle():
    graph = {m: set() for m in MODULES}
    for importer, imported, _, _ in EDGES:
        if (importer, imported) in ACCESSORS or imported not in MODULES:
            continue
        graph[importer].add(imported)
    state: dict[str, int] = {}

    def visit(node, path):
        state[node] = 1
        for nxt in graph[node]:
            if state.get(nxt) == 1:
                raise AssertionError("import cycle: " + " -> ".join(path[path.index(nxt):] + [nxt]))
            if nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = 2

    for node in graph:
        if node not in state:
            visit(node, [node])


@pytest.mark.parametrize("path", sorted(MODULES.values()), ids=lambda p: p.name)
def test_sources_compile_without_warnings(path):
    """No invalid escape sequence (a docstring with TeX that should be raw) or other warning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        compile(path.read_text(encoding="utf-8"), str(path), "exec")


def test_import_is_light_and_public_names_resolve():
    """``import tubefsi`` loads neither SciPy nor matplotlib (the public names load on first use),
    and the functions that share a submodule's name stay functions after that submodule loads."""
    import subprocess
    import sys

    code = ("import sys, tubefsi\n"
            "assert not any(m.split('.')[0] in ('scipy', 'matplotlib') for m in sys.modules), "
            "sorted(m for m in sys.modules if m.startswith(('scipy', 'matplotlib')))[:5]\n"
            "import importlib, types\n"
            "for name in ('solve', 'advise', 'fit'):\n"
            "    importlib.import_module('tubefsi.' + name)\n"
            "    assert isinstance(getattr(tubefsi, name), types.FunctionType), name\n"
            "assert tubefsi.Tube.__name__ == 'Tube' and callable(tubefsi.max_flow_rate)\n"
            "assert set(tubefsi.__all__) <= set(dir(tubefsi))\n")
    subprocess.run([sys.executable, "-c", code], check=True)
