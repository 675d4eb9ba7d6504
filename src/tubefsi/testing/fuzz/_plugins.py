"""The family "hostile plugins": entry points that fail to import (``SystemExit``, ``ImportError``,
``RuntimeError``), that give no class or a class of the wrong base, that re-declare a name; one
at a time, and under warnings-as-errors.

The contract (:mod:`tubefsi.registry`): the built-in models still list and solve (``coupler="auto"``
included), the hostile name is left out, and a :class:`~tubefsi.registry.PluginWarning` names the
distribution and the entry point; under warnings-as-errors the first access raises that warning
and the next one finds every valid provider. The entry points are faked where the registry reads
them (``importlib.metadata.entry_points``, as ``tests/test_registry.py`` does), so nothing is
installed or imported; each probe restores the registries.
"""

from __future__ import annotations

import contextlib
import io
import types
import warnings
from importlib import metadata

from ... import cli, registry
from ...geometry import Tube
from ...registry import PluginWarning
from ...rheology.newtonian import Newtonian
from ...solve import solve
from ...walls.linear import ThinLinear
from ...walls.rigid import Rigid
from ._core import _TUBE, Probe

_GROUPS = {"rheologies": "tubefsi.rheologies", "walls": "tubefsi.walls", "couplers": "tubefsi.couplers"}


class _GoodWall(Rigid):
    """A plugin's valid wall (a rigid tube), for the providers that lose to it or win over it."""


class _EntryPoint:
    """An entry point of a distribution that is not installed: what the registry reads of one."""

    def __init__(self, kind, name, dist, value, load):
        self.kind, self.group, self.name, self.value = kind, _GROUPS[kind], name, value
        self.dist = types.SimpleNamespace(name=dist)
        self._load = load

    def load(self):
        return self._load()


def _raising(exc):
    def load():
        raise exc
    return load


@contextlib.contextmanager
def _installed(*added):
    """The registries with the entry points ``added`` next to the installed ones; restored afterwards."""
    real = metadata.entry_points
    found = {group: [*real(group=group), *(ep for ep in added if ep.group == group)] for group in _GROUPS.values()}

    def entry_points(**params):      # the installed ones read once (parsing their metadata is the slow part)
        return found[params["group"]] if set(params) == {"group"} and params["group"] in found else real(**params)

    metadata.entry_points = entry_points
    registry.refresh()
    try:
        yield
    finally:
        metadata.entry_points = real
        registry.refresh()


#: One hostile entry point each: (kind, name, distribution, value, load).
_HOSTILE = (
    ("walls", "hostile-exit", "hostile-exit-plugin", "hostile_exit:Wall", _raising(SystemExit(3))),
    ("rheologies", "hostile-exit-zero", "hostile-exit-plugin", "hostile_exit:Fluid", _raising(SystemExit(0))),
    ("walls", "hostile-import", "hostile-import-plugin", "hostile_import:Wall",
     _raising(ImportError("needs the missing package xyzzy"))),
    ("couplers", "hostile-runtime", "hostile-runtime-plugin", "hostile_runtime:Coupler",
     _raising(RuntimeError("boom at import"))),
    ("couplers", "hostile-len", "hostile-builtins", "builtins:len", lambda: len),
    ("walls", "hostile-len", "hostile-builtins", "builtins:len", lambda: len),
    ("rheologies", "hostile-none", "hostile-values", "hostile_values:NONE", lambda: None),
    ("walls", "hostile-instance", "hostile-values", "hostile_values:WALL", lambda: Rigid()),
    ("walls", "hostile-fluid", "hostile-wrong-base", "tubefsi.rheology.newtonian:Newtonian", lambda: Newtonian),
    ("couplers", "hostile-wall", "hostile-wrong-base", "tubefsi.walls.rigid:Rigid", lambda: Rigid),
    ("rheologies", "hostile-dict", "hostile-wrong-base", "builtins:dict", lambda: dict),
    ("walls", "rigid", "hostile-takeover", "tubefsi.walls.linear:ThinLinear", lambda: ThinLinear),
    ("couplers", "quadrature", "hostile-takeover", "builtins:len", lambda: len),
)


def _builtin_scene():
    """A built-in scene solved with ``coupler="auto"`` (every registered coupler is ranked)."""
    fluid = registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = registry.walls["thick-neo-hookean"](shear_modulus=2e3)
    return solve(fluid, wall, Tube(**_TUBE), flow_rate=1e-9)


def _names():
    return {kind: set(getattr(registry, kind)) for kind in _GROUPS}


def _one_hostile(ep):
    """With ``ep`` installed: the registries listed, a built-in scene solved, the warnings given."""
    def call():
        before = _names()
        with _installed(ep), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            names, sol = _names(), _builtin_scene()
            provider = getattr(registry, ep.kind).get(ep.name)
        messages = [str(w.message) for w in caught if issubclass(w.category, PluginWarning)]
        return sol, {"before": before, "names": names, "provider": provider, "messages": messages,
                     "restored": _names() == before}

    def check(result):
        _, info = result
        if not info["restored"]:
            return "the registries were not restored"
        if info["names"] != info["before"]:
            return f"the names changed: {sorted(info['names'][ep.kind] ^ info['before'][ep.kind])}"
        builtin = ep.name in info["before"][ep.kind]
        if builtin and info["provider"] is not getattr(registry, ep.kind)[ep.name]:
            return f"{ep.name!r} taken over by {info['provider']!r}"
        return _named(info["messages"], ep)
    return call, check


def _named(messages, ep):
    """None, or why no warning names the distribution and the entry point."""
    if any(ep.dist.name in m and repr(ep.name) in m for m in messages):
        return None
    return f"no PluginWarning names {ep.dist.name} and {ep.name!r}: {messages}"


def _cli_list(ep, error=False):
    """``tubefsi list`` with ``ep`` installed (``error``: under warnings-as-errors, then again)."""
    def call():
        runs = []
        with _installed(ep), warnings.catch_warnings():
            warnings.simplefilter("error" if error else "always")
            for _ in range(2 if error else 1):
                out, err = io.StringIO(), io.StringIO()
                with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                    try:
                        status = cli.main(["list"])
                    except SystemExit as exc:       # a breach to report, not the campaign's end
                        status = f"SystemExit({exc.code!r})"
                runs.append((status, out.getvalue(), err.getvalue()))
        return runs

    def check(runs):
        status, out, err = runs[0]
        if "internal error" in err or "Traceback" in err:
            return err[:300]
        lines = [line for line in err.splitlines() if ep.dist.name in line]
        if error:
            if status != 2 or len(err.splitlines()) != 1 or not err.startswith("tubefsi: error: ") or not lines:
                return f"under warnings-as-errors: status {status!r}, stderr {err[:300]!r}"
            status, out, err = runs[1]                # the registry kept everything else
            lines = [True]
        if status != 0 or "rigid" not in out or not lines:
            return f"status {status!r}, stderr {err[:300]!r}"
        return None
    return call, check


def _warnings_as_errors():
    """A broken provider sorting before a valid one, the first access under warnings-as-errors:
    it raises the broken one's warning, and the valid provider is there the next time."""
    bad = _EntryPoint("walls", "hostile-shared", "aaa-hostile", "aaa_hostile:Wall", _raising(SystemExit(1)))
    good = _EntryPoint("walls", "hostile-shared", "bbb-good", "bbb_good:Wall", lambda: _GoodWall)
    for first in ("lookup", "listing"):
        def call(first=first):
            with _installed(bad, good), warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    if first == "lookup":
                        registry.walls["hostile-shared"]
                    else:
                        list(registry.walls)
                    raised = None
                except PluginWarning as exc:
                    raised = str(exc)
                return _builtin_scene(), {"raised": raised, "provider": registry.walls.get("hostile-shared"),
                                          "origin": registry.walls.distribution("hostile-shared")}

        def check(result):
            _, info = result
            if info["raised"] is None:
                return "no PluginWarning raised under warnings-as-errors"
            if "aaa-hostile" not in info["raised"] or "'hostile-shared'" not in info["raised"]:
                return f"the warning does not name the plugin: {info['raised']}"
            if info["provider"] is not _GoodWall or info["origin"] != "bbb-good":
                return f"the valid provider was dropped: {info['provider']!r} from {info['origin']}"
            return None

        yield Probe("registry", f"warnings as errors: first access by {first}", call, check=check)
    coupler = _EntryPoint("couplers", "hostile-len", "hostile-builtins", "builtins:len", lambda: len)

    def auto_twice():
        with _installed(coupler), warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                _builtin_scene()
                raised = None
            except PluginWarning as exc:
                raised = str(exc)
            return _builtin_scene(), raised

    yield Probe("registry", "warnings as errors: coupler=auto with a non-class coupler", auto_twice,
                check=lambda r: None if r[1] and "hostile-builtins" in r[1] else f"raised {r[1]!r}")


def _plugins_family(chosen):
    """The probes of the family "hostile plugins" (model-free: with ``chosen.core`` only)."""
    if not chosen.core:
        return
    for spec in _HOSTILE:
        ep = _EntryPoint(*spec)
        label = f"{ep.kind} {ep.name} = {ep.value} from {ep.dist.name}"
        call, check = _one_hostile(ep)
        yield Probe("registry", label, call, check=check)
        call, check = _cli_list(ep)
        yield Probe("cli list", label, call, check=check)
    for spec in _HOSTILE[:3]:
        ep = _EntryPoint(*spec)
        call, check = _cli_list(ep, error=True)
        yield Probe("cli list", f"warnings as errors: {ep.kind} {ep.name} from {ep.dist.name}", call, check=check)
    yield from _warnings_as_errors()
