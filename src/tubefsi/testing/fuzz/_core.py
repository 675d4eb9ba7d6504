"""The fuzz campaign's machinery: a :class:`Probe` (one public call and what the contract expects),
its :class:`Outcome` under a time bound (:func:`run_probe`), and the :class:`Report` of a campaign."""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import math
import signal
import threading
import time
import types
import warnings
from typing import Callable

import numpy as np

from ...errors import InvalidParameterError, NoSteadyStateError, TubefsiError
from ...solution import Solution

#: The categories that are breaches of the contract.
BREACHES = ("nan", "wrong", "accepted", "untyped", "hang")

#: Seconds a single public call may take before it counts as a hang.
TIME_LIMIT = 5.0

_TUBE = types.MappingProxyType({"radius": 1e-4, "thickness": 3e-5, "length": 1e-2})

#: Bad values for any real parameter, whatever its range (NaN, infinities, non-numbers).
_ALWAYS_BAD = (math.nan, -math.inf, "1", "x", True, 1e-9 + 1e-12j, None, [1.0, math.nan], object())


class _Timeout(BaseException):
    """Raised in the calling thread when a probe exceeds its time bound (not an ``Exception``, so
    that no ``except Exception`` in the code under test swallows it)."""


@contextlib.contextmanager
def _time_bound(seconds):
    """Interrupt the block after ``seconds`` (SIGALRM; only in the main thread, elsewhere the
    elapsed time is checked afterwards)."""
    if seconds is None or threading.current_thread() is not threading.main_thread() or not hasattr(signal,
                                                                                                   "setitimer"):
        yield
        return

    def handler(signum, frame):
        raise _Timeout()

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@dataclasses.dataclass(frozen=True)
class Probe:
    """One public call and what the contract expects of it.

    ``bad``: the input is invalid, so the call must raise :class:`~tubefsi.InvalidParameterError`
    (naming ``parameter``, when given); otherwise it may raise any typed error or return values
    that are all finite and pass ``check`` (a function of the result returning ``None`` or the
    reason it fails).
    """

    entry: str
    label: str
    call: Callable
    bad: bool = False
    parameter: str | None = None
    check: Callable | None = None
    allow_inf: bool = False
    #: for a typed error: a function of it returning ``None`` or what is wrong with its words
    words: Callable | None = None
    #: Python's own ``TypeError`` naming ``parameter`` is an answer too (a wrong keyword to a
    #: model, coupler or ``Tube`` constructor, which Python rejects before any code of ours runs)
    type_error: bool = False
    #: the family the probe comes from (:data:`tubefsi.testing.fuzz.FAMILIES`; random scenes: "scenes")
    family: str = ""


@dataclasses.dataclass(frozen=True)
class Outcome:
    """The result of one probe: ``category`` is ``"typed"``, ``"value"`` or one of :data:`BREACHES`."""

    entry: str
    label: str
    category: str
    detail: str = ""
    seconds: float = 0.0
    family: str = ""

    @property
    def breach(self) -> bool:
        return self.category in BREACHES


def _numbers(result):
    """The floats of a result: numbers, arrays, tuples of them, a Solution's scalar results."""
    if isinstance(result, Solution):
        result = (result.flow_rate, result.pressure_drop, result.inlet_pressure, result.inlet_displacement,
                  result.inlet_radius)
    if isinstance(result, (tuple, list)):
        out = [np.ravel(np.asarray(_numbers(r), dtype=float)) for r in result]
        return np.concatenate(out) if out else np.zeros(0)
    if isinstance(result, (bool, np.bool_)):
        return np.zeros(0)
    if isinstance(result, (int, float, np.ndarray, np.floating, np.integer)):
        a = np.asarray(result)
        if a.dtype.kind == "b":
            return np.zeros(0)
        return np.ravel(a.astype(float))
    return np.zeros(0)          # objects (Advice, Diagnostics, models) are checked by ``check``


def _typed_words(error):
    """None, or what is wrong with a typed error's words."""
    if isinstance(error, NoSteadyStateError) and not (math.isfinite(error.limit) and error.limit >= 0):
        return f"NoSteadyStateError with limit {error.limit}"
    return None


def run_probe(probe: Probe, time_limit: float | None = TIME_LIMIT) -> Outcome:
    """Run ``probe`` under the time bound and classify its outcome."""
    start = time.perf_counter()
    error = result = None
    try:
        with warnings.catch_warnings(), _time_bound(time_limit), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            result = probe.call()
    except _Timeout:
        return Outcome(probe.entry, probe.label, "hang", f"over {time_limit} s", time.perf_counter() - start,
                       probe.family)
    except Exception as exc:     # classified below
        error = exc
    seconds = time.perf_counter() - start

    def out(category, detail=""):
        return Outcome(probe.entry, probe.label, category, detail, seconds, probe.family)

    if time_limit is not None and seconds > time_limit:
        return out("hang", f"{seconds:.1f} s")
    if error is not None:
        if probe.type_error and isinstance(error, TypeError) and not isinstance(error, TubefsiError):
            if probe.parameter and probe.parameter not in str(error):
                return out("wrong", f"TypeError does not name {probe.parameter!r}: {error}"[:200])
            return out("typed", "TypeError")
        if not isinstance(error, TubefsiError):
            where = error.__traceback__
            while where is not None and where.tb_next is not None:
                where = where.tb_next
            site = "" if where is None else f" at {where.tb_frame.f_code.co_filename.rsplit('/', 1)[-1]}:{where.tb_lineno}"
            return out("untyped", f"{type(error).__name__}: {error}"[:200] + site)
        words = _typed_words(error)
        if words:
            return out("wrong", words)
        if probe.bad and not isinstance(error, InvalidParameterError):
            return out("accepted", f"{type(error).__name__}: {error}"[:200])
        if probe.bad and probe.parameter and not _names(error.parameter, probe.parameter):
            return out("wrong", f"names {error.parameter!r}, not {probe.parameter!r}")
        why = probe.words(error) if probe.words is not None else None
        if why:
            return out("wrong", why)
        return out("typed", f"{type(error).__name__}")
    if probe.bad:
        return out("accepted", f"returned {_short(result)}")
    values = _numbers(result)
    if values.size and not np.all(np.isfinite(values) | (probe.allow_inf & (values == math.inf))):
        return out("nan", f"returned {_short(result)}")
    if probe.check is not None:
        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore")
                why = probe.check(result)
        except TubefsiError as exc:
            why = None if not _typed_words(exc) else _typed_words(exc)
        except Exception as exc:
            return out("untyped", f"in check: {type(exc).__name__}: {exc}"[:200])
        if why:
            return out("wrong", why)
    return out("value")


def _names(given, expected) -> bool:
    given, expected = str(given), str(expected)
    return expected in given or given in expected


def _short(value) -> str:
    text = repr(value)
    return text if len(text) < 120 else text[:117] + "..."



@dataclasses.dataclass
class Report:
    """Counts of a campaign: per category, per family and per entry point; the breaches; wall time."""

    outcomes: list
    seconds: float

    @property
    def breaches(self):
        return [o for o in self.outcomes if o.breach]

    def counts(self):
        return collections.Counter(o.category for o in self.outcomes)

    def by_entry(self):
        table = collections.defaultdict(collections.Counter)
        for o in self.outcomes:
            table[o.entry.split(":")[0] if o.entry.startswith(("wall:", "rheology:", "coupler:")) else o.entry][
                o.category] += 1
        return table

    def by_family(self):
        table = collections.defaultdict(collections.Counter)
        for o in self.outcomes:
            table[o.family or "other"][o.category] += 1
        return table

    def __str__(self) -> str:
        cats = ("typed", "value") + BREACHES
        total = self.counts()
        lines = []
        for title, table in (("family", self.by_family()), ("entry point", self.by_entry())):
            lines.append(f"{title:28s}" + "".join(f"{c:>10s}" for c in cats))
            for key, counter in sorted(table.items()):
                lines.append(f"{key:28s}" + "".join(f"{counter[c]:10d}" for c in cats))
            lines.append(f"{'total':28s}" + "".join(f"{total[c]:10d}" for c in cats))
            lines.append("")
        bad = [o for o in self.outcomes if not o.entry.startswith("scene:")]
        lines.append(f"{len(bad)} probes, {len(self.outcomes) - len(bad)} random scenes, "
                     f"{len(self.breaches)} breaches, {self.seconds:.1f} s")
        for o in self.breaches[:200]:
            lines.append(f"BREACH {o.category}: {o.entry} [{o.label}] {o.detail}")
        return "\n".join(lines)

