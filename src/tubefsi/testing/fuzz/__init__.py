r"""Fuzzing the public contract: every entry point, every registered model and coupler.

The contract (``docs/verification.md``, "Fuzzing"): a public call either raises one of
tubefsi's typed errors — :class:`~tubefsi.InvalidParameterError` for bad input, naming the
parameter; :class:`~tubefsi.NoSteadyStateError` beyond a limit, with a finite limit;
:class:`~tubefsi.ConvergenceError` for a numerical failure — or returns finite values that
pass a cheap independent check; and it does so within a few seconds. A *breach* is anything
else, counted in one of these categories:

==============  ================================================================
``nan``         a NaN or an infinity returned without an error
``wrong``       a finite value that fails its check, or a typed error with wrong words
                (a NaN limit, a misnamed parameter)
``accepted``    a bad input that did not raise :class:`~tubefsi.InvalidParameterError`
``untyped``     any exception that is not a :class:`~tubefsi.TubefsiError`
``hang``        a call over the time bound (``time_limit`` seconds)
==============  ================================================================

Probes come in two kinds, both built from the registries (so a plugin's models are fuzzed by
the same code as the built-ins):

* :func:`bad_input_probes` — deterministic: each parameter of each registered model and
  coupler and each argument of each public entry point (``solve``, ``max_flow_rate``,
  ``Tube``, the :class:`~tubefsi.Solution` accessors, the wall and rheology methods,
  ``advise``) given NaN, infinities, values outside the field's admissible range, strings,
  booleans, complex numbers, ``None`` and arrays with one bad entry; misspelt, unknown and
  missing keywords of every entry point (a :class:`~tubefsi.KeywordError` naming the keyword
  and suggesting the intended one) and of every model, coupler and ``Tube`` constructor
  (Python's own ``TypeError`` naming the keyword will do there); and extreme *valid* inputs (loads of
  ``1e-300`` and ``1e300``, tiny drops on a loaded outlet, stretches of ``1e300``), which must
  give a typed error or a finite value that passes its check.
* :func:`scene_outcomes` — random valid scenes drawn by hypothesis (a registered rheology,
  wall and coupler, their example parameters scaled, a tube, a load below the limits), each
  solved and checked: finite results, the flow-controlled and pressure-controlled solves
  invert each other, the pressure drop lies between the rigid-tube (Hagen–Poiseuille) drop at
  the undeformed and at the inlet radius, it grows with the flow rate, the inlet pressure is
  the tube law at the inlet stretch, and the pressure profile falls from inlet to outlet.

:func:`campaign` runs both and returns a :class:`Report` (counts per category and per entry
point, wall time); ``python -m tubefsi.testing.fuzz`` prints it and exits nonzero on any breach
(``make fuzz``). In a pytest suite, subclass :class:`FuzzContract` and give it the names of the
models to fuzz::

    from tubefsi.testing.fuzz import FuzzContract

    class TestFuzzMyWalls(FuzzContract):
        walls = ("thick-gent", "thin-gent")
        rheologies = ()
        couplers = ()
        scenes = 10

Each model named is paired with the core partners (thick neo-Hookean, thin linear and rigid walls;
power-law and Newtonian fluids) for the entry points that need a pair; the random scenes draw
every registered partner.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from typing import NamedTuple

try:
    import hypothesis  # noqa: F401 - the random scenes need it; say so before anything fails inside
except ModuleNotFoundError as exc:
    raise ModuleNotFoundError("tubefsi.testing.fuzz needs hypothesis, from the test extra: pip install '.[test]' "
                              "in a clone of tubefsi (docs/installation.md)", name=exc.name) from exc

from ... import registry
from ...geometry import Tube
from ._extremes import extremes_family
from ._core import BREACHES, TIME_LIMIT, _TUBE, Outcome, Probe, Report, run_probe
from ._cli import _cli_family
from ._inputs import _inputs_family
from ._known import _known_probes
from ._models import (_advise_probes, _entry_keyword_probes, _model_probes, _rheology_probes, _solution_probes,
                      _solve_probes, _tube_probes, _wall_probes)
from ._plugins import _plugins_family
from ._scenes import scene_outcomes
from ._solutions import solution_probes
from ._transients import argument_probes, transient_probes

__all__ = ["Probe", "Outcome", "Report", "BREACHES", "TIME_LIMIT", "FAMILIES", "Selection", "bad_input_probes", "run_probe", "scene_outcomes",
           "campaign", "FuzzContract", "main"]


class Selection(NamedTuple):
    """The registered names a campaign fuzzes, and whether it includes the model-free probes."""

    rheologies: list
    walls: list
    couplers: list
    core: bool

    def pairs(self):
        """``(rheology, wall, tag)`` instances: each named model with the core partners (each
        rheology with a few walls, each wall with a few fluids), one pair per example set."""
        partners_w = [w for w in ("thick-neo-hookean", "thin-linear", "rigid") if w in registry.walls]
        partners_r = [r for r in ("power-law", "newtonian") if r in registry.rheologies]
        names = [(r, w) for r in self.rheologies for w in partners_w] + [(r, w) for w in self.walls for r in partners_r]
        for rname, wname in dict.fromkeys(names):
            rc, wc = registry.rheologies[rname], registry.walls[wname]
            for i, (rk, wk) in enumerate(zip(rc._examples, wc._examples or ({},))):
                yield rc(**rk), wc(**wk), f"{rname}#{i} {wname}#{i}"


def _fields_family(chosen):
    """Bad values of every field of every named model and coupler, and of their methods' arguments."""
    for name in chosen.rheologies:
        yield from _model_probes("rheologies", name)
        yield from _rheology_probes(name)
    for name in chosen.walls:
        yield from _model_probes("walls", name)
        yield from _wall_probes(name)
    for name in chosen.couplers:
        yield from _model_probes("couplers", name)
    if chosen.core:
        yield from _tube_probes()


def _keywords_family(chosen):
    if chosen.core:
        yield from _entry_keyword_probes()


def _solutions_family(chosen):
    """A solution's accessors at every shape of argument, for the first pair of each model."""
    tube = Tube(**_TUBE)
    for fluid, wall, tag in chosen.pairs():
        if tag.split()[0].endswith("#0"):
            yield from solution_probes(fluid, wall, tube, tag)


def _transients_family(chosen):
    """``evolve`` for the first pair of each model, and its own arguments at bad values."""
    tube = Tube(**_TUBE)
    for fluid, wall, tag in chosen.pairs():
        if tag.split()[0].endswith("#0"):
            yield from transient_probes(fluid, wall, tube, tag)
    if chosen.core and "power-law" in registry.rheologies and "thick-neo-hookean" in registry.walls:
        yield from argument_probes(registry.rheologies["power-law"](consistency=0.017, index=0.7),
                                   registry.walls["thick-neo-hookean"](shear_modulus=2e3), tube)


def _known_family(chosen):
    if chosen.core:
        yield from _known_probes()


def _entry_points_family(chosen):
    """Bad and extreme valid arguments of ``solve``, the Solution's accessors and ``advise``, pair by pair."""
    tube = Tube(**_TUBE)
    for fluid, wall, tag in chosen.pairs():
        yield from _solve_probes(fluid, wall, tube, tag)
        if tag.split()[0].endswith("#0"):
            yield from _solution_probes(fluid, wall, tube, tag)
            yield from _advise_probes(fluid, wall, tube, tag)


#: The probe families: a name and a function of a :class:`Selection` giving its probes. A family
#: that finds a breach later is widened here (``docs/verification.md``, "Fuzzing").
FAMILIES = {
    "fields": _fields_family,
    "keywords": _keywords_family,
    "entry points": _entry_points_family,
    "solutions": _solutions_family,
    "known": _known_family,
    "cli files": _cli_family,
    "hostile plugins": _plugins_family,
    "extremes": extremes_family,
    "inputs": _inputs_family,
    "transients": _transients_family,
}


def bad_input_probes(rheologies=None, walls=None, couplers=None, *, core=True, families=None):
    """The deterministic probes of the registered models named (default: every registered one),
    each labelled with its family (:data:`FAMILIES`; ``families``: only these).

    ``core``: include the probes that belong to no model (``Tube``, keywords, the command line,
    plugins, the known reproducers).
    """
    chosen = Selection(list(registry.rheologies) if rheologies is None else list(rheologies),
                       list(registry.walls) if walls is None else list(walls),
                       list(registry.couplers) if couplers is None else list(couplers), core)
    probes = []
    for family, make in FAMILIES.items():
        if families is None or family in families:
            probes += [dataclasses.replace(probe, family=family) for probe in make(chosen)]
    return probes


def campaign(scenes=250, *, rheologies=None, walls=None, couplers=None, time_limit=TIME_LIMIT, progress=None):
    """Run every bad-input probe and ``scenes`` random valid scenes; returns a :class:`Report`."""
    start = time.perf_counter()
    outcomes = []
    for probe in bad_input_probes(rheologies, walls, couplers):
        outcomes.append(run_probe(probe, time_limit))
        if progress and outcomes[-1].breach:
            progress(outcomes[-1])
    if scenes:
        outcomes += scene_outcomes(scenes, rheologies, walls, couplers, time_limit=time_limit)
    return Report(outcomes, time.perf_counter() - start)


class FuzzContract:
    """The fuzz campaign as a pytest suite: set ``rheologies``, ``walls`` and ``couplers`` to the
    registered names to fuzz (``None``: every registered one), ``scenes`` to the number of
    random valid scenes. Each test fails listing its breaches."""

    rheologies: tuple | None = None
    walls: tuple | None = None
    couplers: tuple | None = None
    #: also the probes that belong to no model (``Tube``, the known reproducers)
    core: bool = False
    scenes: int = 20
    time_limit: float = TIME_LIMIT

    def test_bad_inputs_give_typed_errors(self):
        probes = bad_input_probes(self.rheologies, self.walls, self.couplers, core=self.core)
        breaches = [o for o in (run_probe(p, self.time_limit) for p in probes) if o.breach]
        assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)

    def test_random_scenes_pass_their_checks(self):
        if not self.scenes:
            return
        rheologies = self.rheologies if self.rheologies else None
        walls = self.walls if self.walls else None
        outcomes = scene_outcomes(self.scenes, rheologies, walls, self.couplers, time_limit=self.time_limit)
        breaches = [o for o in outcomes if o.breach]
        assert not breaches, "\n".join(f"{o.category}: {o.entry} [{o.label}] {o.detail}" for o in breaches)


def main(argv=None) -> int:
    """``python -m tubefsi.testing.fuzz [--scenes N] [--time-limit S]``: print the report; exit 1 on a breach."""
    parser = argparse.ArgumentParser(prog="python -m tubefsi.testing.fuzz", description=main.__doc__)
    parser.add_argument("--scenes", type=int, default=250, help="random valid scenes (default 250)")
    parser.add_argument("--time-limit", type=float, default=TIME_LIMIT, help="seconds per call")
    args = parser.parse_args(argv)
    report = campaign(args.scenes, time_limit=args.time_limit)
    print(report)
    return 1 if report.breaches else 0

