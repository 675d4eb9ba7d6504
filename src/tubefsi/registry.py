"""Lazy, cached, read-only registries of models and couplers, fed by entry points.

Three entry-point groups — ``tubefsi.rheologies``, ``tubefsi.walls``,
``tubefsi.couplers`` — declare every model, the built-ins included (in tubefsi's
own ``pyproject.toml``). An extension package adds names by declaring its own::

    [project.entry-points."tubefsi.walls"]
    thick-gent = "tubefsi_hyperelastic.gent:ThickGent"

The entry points are read on first access of a registry, and a name's class is
imported when that name is first looked up (iterating a registry imports them all);
both are cached until :func:`refresh`.

When several distributions declare the same name, the provider does not depend on
the order of ``sys.path`` or of the entry points:

1. a built-in name (declared by the distribution ``tubefsi``) always resolves to
   tubefsi's own model: a plugin cannot take it over;
2. between plugins, the distribution whose normalized name (PEP 503: lower case,
   each run of ``-``, ``_`` and ``.`` as one ``-``) sorts first wins.

Each provider left out is a :class:`PluginWarning` naming both distributions and the
one used; its entry point is not imported. An entry point that fails to import (whatever
it raises, ``SystemExit`` included; only ``KeyboardInterrupt`` goes through) or that gives
something other than a subclass of the group's base class (:class:`~tubefsi.rheology.Rheology`,
:class:`~tubefsi.walls.WallModel`, :class:`~tubefsi.couplers.Coupler`) is a
:class:`PluginWarning` naming the distribution, the entry point and what went wrong, never an
error, and the next provider in that order is tried. The warnings are given once the
registry is consistent, so that under warnings-as-errors the first one raises but loses
nothing: the next access finds every name resolved. The same distribution seen twice
(editable installs can list it twice) counts once, silently.
"""

from __future__ import annotations

import difflib
import importlib
import re
import sys
import threading
import warnings
from collections.abc import Iterator, Mapping
from importlib import metadata

__all__ = ["rheologies", "walls", "couplers", "refresh", "Registry", "PluginWarning"]

BUILTIN_DISTRIBUTION = "tubefsi"
_UNKNOWN = "<unknown distribution>"

#: What one entry of each group is, in messages.
_KINDS = {"tubefsi.rheologies": "rheology", "tubefsi.walls": "wall", "tubefsi.couplers": "coupler"}

#: The class every entry point of a group must give a subclass of: (module, name, public name).
#: Imported when a name is first resolved (the models import it anyway), not with the registry,
#: which ``tubefsi --help`` imports alone.
_BASES = {
    "tubefsi.rheologies": ("tubefsi.rheology.base", "Rheology", "tubefsi.rheology.Rheology"),
    "tubefsi.walls": ("tubefsi.walls.base", "WallModel", "tubefsi.walls.WallModel"),
    "tubefsi.couplers": ("tubefsi.couplers.base", "Coupler", "tubefsi.couplers.Coupler"),
}


class PluginWarning(UserWarning):
    """A plugin could not be loaded, or declared a name already taken."""


def _normalize(name: str) -> str:
    """PEP 503 normalized distribution name."""
    return re.sub(r"[-_.]+", "-", name).lower()


def _warn_all(messages) -> None:
    """Give each warning (under warnings-as-errors the first one raises: the registry is
    consistent by then, so nothing is lost)."""
    for message in messages:
        _warn(message)


def _warn(message: str) -> None:
    """Warn, attributing the warning to the first caller outside this module and the Mapping mixins."""
    frame, level = sys._getframe(1), 2
    while frame is not None and frame.f_globals.get("__name__") in (__name__, "_collections_abc"):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, PluginWarning, stacklevel=level)


class Registry(Mapping):
    """A read-only ``Mapping[str, type]`` over one entry-point group."""

    def __init__(self, group: str):
        self.group = group
        self._entries: dict[str, type] | None = None  # names resolved so far; None: entry points unread
        self._origin: dict[str, str] = {}
        self._pending: dict[str, list[tuple[str, metadata.EntryPoint]]] = {}  # name -> providers, by priority
        self._derived: dict = {}    # what callers derived from the registry (derived()), until refresh()
        # reading the entry points and importing a provider happen under this lock (a lookup that
        # finds its name resolved takes none): two threads never import one name at once, and no
        # thread sees a name half-resolved
        self._lock = threading.RLock()

    def _read(self) -> dict[str, type]:
        """Read the entry points (once) and order each name's providers; import nothing."""
        if self._entries is None:
            providers: dict[str, dict[object, tuple[tuple, str, metadata.EntryPoint]]] = {}
            for ep in metadata.entry_points(group=self.group):
                dist = ep.dist.name if ep.dist is not None and ep.dist.name else None
                if dist is None:  # no distribution to rank by: after every named one, by target
                    key, rank, dist = ("?", ep.value), (2, "", ep.value), _UNKNOWN
                else:
                    key = _normalize(dist)
                    rank = (0 if key == BUILTIN_DISTRIBUTION else 1, key, "")
                # the same distribution seen twice (editable installs): the first one found counts
                providers.setdefault(ep.name, {}).setdefault(key, (rank, dist, ep))
            self._pending = {name: [(dist, ep) for _, dist, ep in sorted(found.values(), key=lambda t: t[0])]
                             for name, found in providers.items()}
            self._entries, self._origin = {}, {}
        return self._entries

    def _resolve(self, name: str) -> list[str]:
        """Import the first provider of ``name`` that loads and gives a model of this group;
        return the warnings to give (failures, wrong kinds, providers left out), which the
        caller gives once the registry is consistent."""
        candidates = self._pending.pop(name, None) or []
        messages = []
        for i, (dist, ep) in enumerate(candidates):
            where, entry = f"{self.group}: {name!r} from {dist}", f"(entry point {name} = {ep.value}); left out"
            try:
                obj = ep.load()
            except KeyboardInterrupt:
                raise
            except BaseException as exc:  # a broken plugin, even one calling sys.exit, must not break the registry
                messages.append(f"{where} failed to load: {type(exc).__name__}: {exc} {entry}")
                continue
            wrong = self._wrong_kind(obj)
            if wrong:
                messages.append(f"{where} {wrong} {entry}")
                continue
            self._entries[name], self._origin[name] = obj, dist
            if _normalize(dist) == BUILTIN_DISTRIBUTION:
                why = "a built-in name cannot be taken over by a plugin"
            else:
                why = "between plugins, the distribution whose normalized name sorts first wins"
            for other, _ in candidates[i + 1:]:
                messages.append(f"{self.group}: {name!r} is provided by both {dist} and {other}; using {dist} ({why})")
            break
        return messages

    def _wrong_kind(self, obj) -> str | None:
        """None, or what is wrong with ``obj`` as a model of this group (not a subclass of its base)."""
        if self.group not in _BASES:
            return None
        module, attr, public = _BASES[self.group]
        if isinstance(obj, type) and issubclass(obj, getattr(importlib.import_module(module), attr)):
            return None
        what = f"the class {obj.__module__}.{obj.__qualname__}" if isinstance(obj, type) else f"a {type(obj).__name__}"
        return f"gives {what}, not a subclass of {public}"

    def _load(self) -> dict[str, type]:
        """Resolve every name, then warn."""
        with self._lock:
            entries = self._read()
            messages = [m for name in list(self._pending) for m in self._resolve(name)]
        _warn_all(messages)
        return entries

    def _get(self, name: str) -> type | None:
        entries = self._entries
        found = None if entries is None else entries.get(name)
        if found is not None:
            return found
        with self._lock:
            entries = self._read()
            messages = self._resolve(name) if name in self._pending else []
        _warn_all(messages)
        return entries.get(name)

    def __getitem__(self, name: str) -> type:
        obj = self._get(name)
        if obj is None:
            close = self.closest(name)
            hint = f" (did you mean {close!r}?)" if close else ""
            raise KeyError(f"{name!r} is not a registered {_KINDS.get(self.group, self.group)}{hint}; "
                           f"known: {', '.join(sorted(self._load()))}")
        return obj

    def closest(self, name) -> str | None:
        """The registered name closest to a misspelt ``name`` (difflib's ratio at least 0.6), or None."""
        close = difflib.get_close_matches(str(name), sorted(self._load()), n=1, cutoff=0.6)
        return close[0] if close else None

    def __contains__(self, name) -> bool:
        return isinstance(name, str) and self._get(name) is not None

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(self._load()))

    def __len__(self) -> int:
        return len(self._load())

    def distribution(self, name: str) -> str:
        """The distribution that provides ``name``."""
        self[name]
        return self._origin[name]

    def name_of(self, model) -> str | None:
        """The registered name of a model class or instance, if any."""
        cls = model if isinstance(model, type) else type(model)
        for name, obj in self._load().items():
            if obj is cls:
                return name
        return None

    def derived(self, name: str, compute):
        """``compute(self)``, computed once per state of the registry (e.g. the couplers that
        ``coupler="auto"`` tries, in order) and forgotten by :meth:`refresh`."""
        found = self._derived.get(name)
        if found is None:
            with self._lock:
                found = self._derived.get(name)
                if found is None:
                    found = self._derived[name] = compute(self)
        return found

    def refresh(self) -> None:
        """Forget the cache; the next access reads the entry points again."""
        with self._lock:
            self._entries = None
            self._origin = {}
            self._pending = {}
            self._derived = {}

    def __reduce__(self):
        # pickled by reference (a worker process has its own registries, and a lock pickles not)
        return _registry_of, (self.group,)

    def __repr__(self) -> str:
        return f"Registry({self.group!r}: {', '.join(self)})"


rheologies = Registry("tubefsi.rheologies")
walls = Registry("tubefsi.walls")
couplers = Registry("tubefsi.couplers")


def _registry_of(group: str) -> Registry:
    """The module's registry of an entry-point group (what a pickled registry becomes)."""
    return {r.group: r for r in (rheologies, walls, couplers)}[group]


def refresh() -> None:
    """Refresh all three registries (after installing a plugin at run time)."""
    for reg in (rheologies, walls, couplers):
        reg.refresh()
