"""Fixtures shared by tubefsi's own tests.

Plain helpers shared by several test files live in importable modules, not here (``tests/`` and
the plugins' ``tests/`` each have a ``conftest.py`` outside any package, so ``from conftest import``
would depend on which one pytest loaded last): the independent references and their relative
error ``rel_err`` are in ``tubefsi.testing.reference``.

Every test directory (``tests/``, ``examples/``, each plugin's ``tests/``) loads the same
hypothesis profile in its own conftest, with :func:`tubefsi.testing.profiles.load_profile`.
"""

from __future__ import annotations

import pytest

from tubefsi.testing.profiles import load_profile

# the hypothesis profile, before any test module imports the suites: TUBEFSI_HYPOTHESIS_PROFILE,
# "ci" (seeded) unless set; "explore" for randomized runs with ten times the examples
# (tubefsi.testing.profiles; docs/verification.md, "Random tests")
load_profile()


@pytest.fixture(scope="module")
def mp_precision(request):
    """Run the requesting module at ``mp.dps = DPS`` (the module's constant), restoring the
    previous precision afterwards so that the setting never leaks into other test modules.

    Use it for a whole module: ``pytestmark = pytest.mark.usefixtures("mp_precision")``.
    """
    from mpmath import mp

    with mp.workdps(request.module.DPS):
        yield
