"""The one cache behind :func:`tubefsi.solve`: an explicit, bounded, thread-safe object.

Tables (the separated identity's, :mod:`tubefsi.couplers.tables`; a fluid's flow law,
:mod:`tubefsi.rheology.flow_law`) are accelerators: a table changes the time a solve takes, never
its answer, because what a table holds depends only on its key, and the key describes everything
it depends on by value (plain numbers and strings, weak references to classes: never a model, so
the cache keeps no model or class alive). :data:`TABLES` holds at most 64 of them, the oldest
leaving first; :func:`tubefsi.cache_clear` empties it and :func:`tubefsi.cache_info`
reports it.
"""

from __future__ import annotations

import threading

import attrs

__all__ = ["TableCache", "CacheInfo", "TABLES", "plain", "instance_values", "keep_on_class"]

_PLAIN = (float, int, str, bool, type(None))


def plain(value) -> bool:
    """Whether ``value`` is a plain value (a float, int, string, bool, None, or a tuple of them):
    what a key may hold, since it cannot change in place."""
    if type(value) is tuple:
        for item in value:
            if type(item) not in _PLAIN and not (type(item) is tuple and plain(item)):
                return False
        return True
    return type(value) in _PLAIN


def keep_on_class(cls, name: str, value):
    """Keep ``value``, derived from the class ``cls`` alone, on the class itself as ``name`` (as
    attrs keeps its field list there: no module-level cache, which would keep a class made at run
    time alive) and return it. A caller reads it back with ``cls.__dict__.get(name)`` (the class's
    own, not a base's); a class that takes no attributes has it computed on every call."""
    try:
        type.__setattr__(cls, name, value)
    except TypeError:
        pass
    return value


def _slot_names(cls) -> tuple:
    """The names of the slots the instances of ``cls`` have, across its classes."""
    found = cls.__dict__.get("_tubefsi_slot_names")
    if found is not None:
        return found
    names = []
    for klass in reversed(cls.__mro__):
        slots = klass.__dict__.get("__slots__", ())
        for name in ((slots,) if isinstance(slots, str) else slots):
            if name not in ("__dict__", "__weakref__") and name not in names:
                names.append(name)
    return keep_on_class(cls, "_tubefsi_slot_names", tuple(names))


def instance_values(obj):
    """Every value ``obj`` holds, as ``(name, value)`` pairs in a fixed order — its slots across its
    classes (attrs fields included), then its ``__dict__`` sorted by name — or None where one is
    not a plain value: what a key by value needs (a subclass's own attributes included, so two
    instances that differ in any of them never share a table)."""
    values = tuple((name, getattr(obj, name, None)) for name in _slot_names(type(obj)))
    state = getattr(obj, "__dict__", None)
    if state:
        values += tuple(sorted(state.items()))
    return values if plain(values) else None


@attrs.frozen
class CacheInfo:
    """What :meth:`TableCache.info` reports."""

    hits: int
    misses: int
    size: int
    maxsize: int


class TableCache:
    """A bounded, thread-safe cache of tables, keyed by value.

    ``get(key, build)`` returns the table of ``key``, building it with ``build()`` on a miss (a
    failed build, None, is remembered as such). Beyond ``maxsize`` entries the oldest leaves first.
    A hit reads one dictionary entry (atomic in CPython: no lock); a miss takes the lock to insert.
    Two threads that miss the same key at once may both build: the tables are equal to the bit,
    and the first one inserted is kept. Clearing changes the time of later calls, never their
    answers. The hit and miss counts are for information (a hit is counted without the lock).
    """

    def __init__(self, maxsize: int = 64):
        self.maxsize = int(maxsize)
        self._entries = {}
        self._lock = threading.Lock()
        self._hits = self._misses = 0

    def get(self, key, build):
        found = self._entries.get(key, self)
        if found is not self:
            self._hits += 1
            return found
        table = build()
        with self._lock:
            self._misses += 1
            table = self._entries.setdefault(key, table)
            while len(self._entries) > self.maxsize:
                del self._entries[next(iter(self._entries))]
        return table

    def clear(self) -> None:
        """Forget every table (and the counts)."""
        with self._lock:
            self._entries.clear()
            self._hits = self._misses = 0

    def info(self) -> CacheInfo:
        with self._lock:
            return CacheInfo(self._hits, self._misses, len(self._entries), self.maxsize)

    def __len__(self) -> int:
        return len(self._entries)


#: The one cache behind :func:`tubefsi.solve`: at most 64 tables (a few hundred kB each).
TABLES = TableCache(maxsize=64)
