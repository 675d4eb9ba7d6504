"""The fuzz campaign's short profile (``docs/verification.md``, "Fuzzing"): every bad-input probe
of the built-in models and of the entry points, the known reproducers, and a few random valid
scenes. ``make fuzz`` runs the long campaign over every registered model."""

import math

import pytest
from tubefsi import InvalidParameterError, NoSteadyStateError
from tubefsi.testing import fuzz
from tubefsi.testing.fuzz import FuzzContract, Probe, run_probe

BUILTIN_WALLS = ("rigid", "thin-linear", "thick-linear", "thin-mooney-rivlin", "thick-mooney-rivlin",
                 "thin-neo-hookean", "thick-neo-hookean")


class TestFuzzBuiltins(FuzzContract):
    rheologies = ("newtonian", "power-law")
    walls = BUILTIN_WALLS
    couplers = None
    core = True
    scenes = 12


# the classifier itself: each category from a call built to produce it
def _raise(exc):
    def call():
        raise exc
    return call


@pytest.mark.parametrize("probe, category", [
    (Probe("e", "typed", _raise(InvalidParameterError("x", "(0, inf)", -1.0)), bad=True, parameter="x"), "typed"),
    (Probe("e", "misnamed", _raise(InvalidParameterError("y", "(0, inf)", -1.0)), bad=True, parameter="x"), "wrong"),
    (Probe("e", "accepted", lambda: 1.0, bad=True), "accepted"),
    (Probe("e", "limit", _raise(NoSteadyStateError("pressure", math.inf)), bad=True), "wrong"),
    (Probe("e", "nan limit", _raise(NoSteadyStateError("pressure", math.nan))), "wrong"),
    (Probe("e", "untyped", _raise(ZeroDivisionError("x"))), "untyped"),
    (Probe("e", "nan", lambda: [1.0, math.nan]), "nan"),
    (Probe("e", "inf allowed", lambda: math.inf, allow_inf=True), "value"),
    (Probe("e", "check", lambda: 2.0, check=lambda v: None if v == 1.0 else "not one"), "wrong"),
    (Probe("e", "value", lambda: 1.0, check=lambda v: None), "value"),
])
def test_outcomes_are_classified(probe, category):
    assert run_probe(probe).category == category


def test_a_hang_is_cut_at_the_time_limit():
    def spin():
        while True:
            pass
    outcome = run_probe(Probe("e", "spin", spin), time_limit=0.2)
    assert outcome.category == "hang" and outcome.seconds < 5


def test_report_counts_per_entry_point():
    report = fuzz.Report([run_probe(Probe("a", "x", lambda: 1.0)), run_probe(Probe("a", "y", lambda: math.nan))], 0.1)
    assert report.counts()["nan"] == 1 and report.by_entry()["a"]["value"] == 1
    assert "1 breaches" in str(report) and "BREACH nan" in str(report)
