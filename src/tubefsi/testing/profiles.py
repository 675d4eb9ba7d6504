"""Hypothesis settings profiles for tubefsi's tests and its plugins' tests.

Two profiles, selected by the environment variable ``TUBEFSI_HYPOTHESIS_PROFILE``:

``ci`` (the default)
    Seeded: ``derandomize=True``, so every test draws the same examples on every machine and in
    every fresh clone (the seed is a hash of the test function's source, so it changes only when
    the test does); no example database, no deadline, ``print_blob=True`` (a failure prints the
    ``@reproduce_failure`` line that replays it). Each test runs the ``max_examples`` written on
    it. ``make test`` uses this profile, and so does CI.

``explore``
    Randomized (new examples on every run), with the example database in
    ``.hypothesis/`` so that a failure found once is replayed first on the next run, no deadline,
    ``print_blob=True``, and :data:`EXPLORE_FACTOR` times each test's own ``max_examples`` (1000
    for a test that sets none). ``make test-explore`` uses it.

Any other registered profile (hypothesis's own ``default``, say) can be named in the variable
too; an unknown name is an error. Hypothesis's ``--hypothesis-profile=NAME`` option overrides the
variable (it loads after the conftests).

A test directory selects the profile in its ``conftest.py``, *before* anything imports
``tubefsi.testing``'s suites (a hypothesis ``settings`` object takes the values it does not set
from the profile active when it is created, and the contract suites create theirs on import)::

    from tubefsi.testing.profiles import load_profile

    load_profile()

Importing this module imports nothing else of tubefsi. A test whose ``max_examples`` should grow
under ``explore`` writes it through :func:`scaled`::

    from hypothesis import given, settings
    from tubefsi.testing.profiles import scaled

    @settings(deadline=None, max_examples=scaled(20))   # 20 under ci, 200 under explore
    @given(...)
    def test_something(...):
        ...

(A number written directly stays as written under every profile: hypothesis lets a test's own
settings win over the profile's.)
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

__all__ = ["PROFILE_VARIABLE", "DEFAULT_PROFILE", "EXPLORE_FACTOR", "register_profiles", "load_profile", "scaled"]

#: the environment variable naming the profile
PROFILE_VARIABLE = "TUBEFSI_HYPOTHESIS_PROFILE"
#: the profile used when the variable is unset or empty
DEFAULT_PROFILE = "ci"
#: how many times its own ``max_examples`` a test runs under ``explore`` (through :func:`scaled`)
EXPLORE_FACTOR = 10

_FACTORS = {"explore": EXPLORE_FACTOR}


def register_profiles() -> None:
    """Register the profiles ``ci`` and ``explore`` (replacing hypothesis's built-in ``ci``,
    which this one equals but for being independent of the hypothesis version)."""
    base = settings.get_profile("default")
    settings.register_profile("ci", base, derandomize=True, database=None, deadline=None, print_blob=True,
                              suppress_health_check=[HealthCheck.too_slow])
    settings.register_profile("explore", base, derandomize=False, deadline=None, print_blob=True,
                              max_examples=base.max_examples * EXPLORE_FACTOR,
                              suppress_health_check=[HealthCheck.too_slow])


def load_profile(name: str | None = None) -> str:
    """Register the profiles and load ``name``, else the one named by ``TUBEFSI_HYPOTHESIS_PROFILE``,
    else ``ci``; returns the name loaded. Idempotent: each test directory's conftest may call it."""
    register_profiles()
    name = name or os.environ.get(PROFILE_VARIABLE) or DEFAULT_PROFILE
    settings.load_profile(name)          # hypothesis.errors.InvalidArgument for an unknown name
    return name


def scaled(max_examples: int) -> int:
    """``max_examples`` for a test that runs that many under ``ci``: the number itself under every
    profile but ``explore``, :data:`EXPLORE_FACTOR` times it there. Call it where the test is
    decorated (at import, after :func:`load_profile`)."""
    return max_examples * _FACTORS.get(settings.get_current_profile_name(), 1)
