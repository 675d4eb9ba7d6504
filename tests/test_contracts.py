"""Run the public contract suites on tubefsi's own models and couplers, each model once.

The built-in models are those the registry attributes to the distribution ``tubefsi``; a plugin's
models go through the same suites in the plugin's own tests
(``plugins/*/tests/test_*_contracts.py``), so they are not repeated here. A hyperelastic wall
runs :class:`HyperelasticWallContract`, which includes every :class:`WallContract` test; the
other walls run :class:`WallContract`. Only the check that every registered model (plugins
included) lists ``_examples`` covers them all.
"""

import pytest

from tubefsi import registry
from tubefsi.testing import (AccuracyContract, CouplerContract, HyperelasticWallContract, RheologyContract,
                             WallContract, accuracy_cases, coupler_cases, examples)
from tubefsi.walls import HyperelasticWall

BUILTIN = "tubefsi"     # the distribution that registers tubefsi's own models


def _own(kind):
    """Example instances of the models of ``kind`` registered by tubefsi itself."""
    reg = getattr(registry, kind)
    return [model for name in reg if reg.distribution(name) == BUILTIN for model in examples(kind, name)]


WALLS = _own("walls")
RHEOLOGIES = _own("rheologies")


def test_every_registered_model_has_examples():
    for kind in ("walls", "rheologies"):
        reg = getattr(registry, kind)
        for name in reg:
            assert getattr(reg[name], "_examples", ()), f"{kind} {name!r} lists no _examples"


class TestWalls(WallContract):
    @pytest.fixture(params=[w for w in WALLS if not isinstance(w, HyperelasticWall)], ids=repr)
    def wall(self, request):
        return request.param


class TestHyperelasticWalls(HyperelasticWallContract):      # includes every WallContract test
    @pytest.fixture(params=[w for w in WALLS if isinstance(w, HyperelasticWall)], ids=repr)
    def wall(self, request):
        return request.param


class TestRheologies(RheologyContract):
    @pytest.fixture(params=RHEOLOGIES, ids=repr)
    def rheology(self, request):
        return request.param


class TestCouplers(CouplerContract):
    @pytest.fixture(params=coupler_cases(WALLS))
    def case(self, request):
        return request.param


class TestAccuracy(AccuracyContract):
    """Every wall with the default fluids (power law, Newtonian); the other fluid examples in a
    thick (limit-pressure) and a thin reference-thickness (closed-form) wall."""

    @pytest.fixture(params=accuracy_cases(WALLS) + accuracy_cases(
        [examples("walls", "thick-neo-hookean")[0], examples("walls", "thin-mooney-rivlin")[0]],
        [f for f in RHEOLOGIES if f not in (examples("rheologies", "power-law")[0],
                                            examples("rheologies", "newtonian")[0])]))
    def case(self, request):
        return request.param
