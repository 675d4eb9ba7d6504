"""Lazy, cached, read-only registries of models and couplers, fed by entry points.

Three entry-point groups — ``tubefsi.rheologies``, ``tubefsi.walls``,
``tubefsi.couplers`` — declare every model, the built-ins included (in tubefsi's
own ``pyproject.toml``). An extension package adds names by declaring its own::

    [project.entry-points."tubefsi.walls"]
    thick-gent = "tubefsi_hyperelastic.gent:ThickGent"

A name is loaded on first access of the registry; a plugin that fails to import,
or a name declared twice, gives a warning naming the distribution, never an error.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Mapping
from importlib import metadata

__all__ = ["rheologies", "walls", "couplers", "refresh", "Registry", "PluginWarning"]


class PluginWarning(UserWarning):
    """A plugin could not be loaded, or declared a name already taken."""


class Registry(Mapping):
    """A read-only ``Mapping[str, type]`` over one entry-point group."""

    def __init__(self, group: str):
        self.group = group
        self._entries: dict[str, type] | None = None
        self._origin: dict[str, str] = {}

    def _load(self) -> dict[str, type]:
        if self._entries is None:
            entries: dict[str, type] = {}
            origin: dict[str, str] = {}
            for ep in metadata.entry_points(group=self.group):
                dist = ep.dist.name if ep.dist is not None else "<unknown distribution>"
                if ep.name in entries:
                    if origin[ep.name] == dist:  # the same distribution seen twice (editable installs)
                        continue
                    warnings.warn(f"{self.group}: {ep.name!r} from {dist} ignored; already provided by "
                                  f"{origin[ep.name]}", PluginWarning, stacklevel=3)
                    continue
                try:
                    entries[ep.name] = ep.load()
                except Exception as exc:  # a broken plugin must not break the registry
                    warnings.warn(f"{self.group}: {ep.name!r} from {dist} failed to load: "
                                  f"{type(exc).__name__}: {exc}", PluginWarning, stacklevel=3)
                    continue
                origin[ep.name] = dist
            self._entries, self._origin = entries, origin
        return self._entries

    def __getitem__(self, name: str) -> type:
        entries = self._load()
        try:
            return entries[name]
        except KeyError:
            raise KeyError(f"{name!r} is not a registered {self.group.split('.')[-1][:-1]}; "
                           f"known: {', '.join(sorted(entries))}") from None

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

    def refresh(self) -> None:
        """Forget the cache; the next access reads the entry points again."""
        self._entries = None
        self._origin = {}

    def __repr__(self) -> str:
        return f"Registry({self.group!r}: {', '.join(self)})"


rheologies = Registry("tubefsi.rheologies")
walls = Registry("tubefsi.walls")
couplers = Registry("tubefsi.couplers")


def refresh() -> None:
    """Refresh all three registries (after installing a plugin at run time)."""
    for reg in (rheologies, walls, couplers):
        reg.refresh()
