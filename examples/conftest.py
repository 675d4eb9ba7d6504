"""Loads tubefsi's hypothesis profile for this directory's tests, before they import the suites:
``TUBEFSI_HYPOTHESIS_PROFILE``, ``ci`` (seeded: the same examples on every machine) unless set,
``explore`` for randomized runs with ten times the examples (:mod:`tubefsi.testing.profiles`)."""

from tubefsi.testing.profiles import load_profile

load_profile()
