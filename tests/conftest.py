"""Fixtures shared by tubefsi's own tests.

Plain helpers shared by several test files live in importable modules, not here (``tests/`` and
the plugins' ``tests/`` each have a ``conftest.py`` outside any package, so ``from conftest import``
would depend on which one pytest loaded last): the independent references and their relative
error ``rel_err`` are in ``tubefsi.testing.reference``.
"""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def mp_precision(request):
    """Run the requesting module at ``mp.dps = DPS`` (the module's constant), restoring the
    previous precision afterwards so that the setting never leaks into other test modules.

    Use it for a whole module: ``pytestmark = pytest.mark.usefixtures("mp_precision")``.
    """
    from mpmath import mp

    with mp.workdps(request.module.DPS):
        yield
