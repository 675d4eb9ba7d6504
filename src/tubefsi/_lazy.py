"""SciPy modules imported on first use, so that ``tubefsi list`` and ``--help`` start fast.

``optimize = lazy_module("scipy.optimize", globals(), "optimize")`` binds a stand-in in the
calling module; the first attribute access (``optimize.brentq``) imports the real module and
rebinds the module-level name to it, so later calls pay nothing. Iterating the registries
imports every model module, and until then none of them needs SciPy: importing it costs about a
second on a cold start, more than the rest of tubefsi together.
"""

from __future__ import annotations

import importlib

__all__ = ["lazy_module"]


class _LazyModule:
    __slots__ = ("_name", "_namespace", "_binding")

    def __init__(self, name, namespace, binding):
        self._name, self._namespace, self._binding = name, namespace, binding

    def _load(self):
        module = importlib.import_module(self._name)
        if self._namespace.get(self._binding) is self:
            self._namespace[self._binding] = module      # the next lookup finds the module itself
        return module

    def __getattr__(self, attr):
        return getattr(self._load(), attr)

    def __repr__(self):
        return f"<lazy module {self._name!r}>"


def lazy_module(name: str, namespace: dict, binding: str):
    """A stand-in for the module ``name``, bound as ``namespace[binding]``, that imports it on
    first attribute access and replaces itself there by the module."""
    return _LazyModule(name, namespace, binding)
