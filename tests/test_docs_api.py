"""Every public name is in the API reference (docs/api.rst) and has a docstring."""

from __future__ import annotations

import importlib
import inspect
import re
import types
from pathlib import Path

import pytest

API = Path(__file__).resolve().parents[1] / "docs" / "api.rst"

PUBLIC_MODULES = [
    "tubefsi", "tubefsi.fields", "tubefsi.scene", "tubefsi.couplers", "tubefsi.walls", "tubefsi.rheology",
    "tubefsi.registry", "tubefsi.errors", "tubefsi.advise", "tubefsi.fit", "tubefsi.network", "tubefsi.dimensionless",
    "tubefsi.chapter", "tubefsi.plotting", "tubefsi.cli", "tubefsi.testing", "tubefsi.validity", "tubefsi.export",
    "tubefsi.fem", "tubefsi.network_io", "tubefsi.datasets",
]

_DIRECTIVE = re.compile(r"^\.\. (autofunction|autoclass|automodule|py:data):: (\S+)\s*$")


def _resolve(dotted, module=False):
    """The object a directive names: the module itself for ``automodule``, else, as autodoc
    does, an attribute of the longest importable parent module."""
    if module:
        return importlib.import_module(dotted)
    parts = dotted.split(".")
    for cut in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            obj = getattr(obj, name)
        return obj
    raise ImportError(dotted)


def _documented():
    """``(ids of documented objects, names of modules documented with all their members)``."""
    objects, whole_modules = set(), set()
    lines = API.read_text(encoding="utf-8").splitlines()
    for i, line in enumerate(lines):
        match = _DIRECTIVE.match(line)
        if not match:
            continue
        kind, target = match.groups()
        obj = _resolve(target, module=kind == "automodule")
        objects.add(id(obj))
        if kind == "automodule":
            options = []
            for nxt in lines[i + 1:]:
                if not nxt.startswith("   "):
                    break
                options.append(nxt.strip())
            members = next((o for o in options if o.startswith(":members:")), None)
            if members is not None:
                listed = members[len(":members:"):].strip()
                names = [n.strip() for n in listed.split(",")] if listed else list(getattr(obj, "__all__", ()))
                for name in names:
                    objects.add(id(getattr(obj, name)))
                if not listed:
                    whole_modules.add(target)
    return objects, whole_modules


DOCUMENTED, WHOLE = _documented()
NAMES = [(m, n) for m in PUBLIC_MODULES for n in importlib.import_module(m).__all__]


@pytest.mark.parametrize("module, name", NAMES, ids=[f"{m}.{n}" for m, n in NAMES])
def test_public_name_is_in_the_api_reference(module, name):
    obj = getattr(importlib.import_module(module), name)
    if isinstance(obj, types.ModuleType):
        assert obj.__name__ in WHOLE or id(obj) in DOCUMENTED, f"module {obj.__name__} is not in docs/api.rst"
        return
    assert id(obj) in DOCUMENTED, f"{module}.{name} is not in docs/api.rst"


@pytest.mark.parametrize("module, name", NAMES, ids=[f"{m}.{n}" for m, n in NAMES])
def test_public_name_has_a_docstring(module, name):
    obj = getattr(importlib.import_module(module), name)
    if isinstance(obj, (dict, tuple, list)) or not (inspect.isclass(obj) or callable(obj)
                                                   or isinstance(obj, types.ModuleType)):
        return   # data (a registry, a table of parameters): documented by the directive's text
    assert (inspect.getdoc(obj) or "").strip(), f"{module}.{name} has no docstring"
