"""Run the public contract suites on every registered model and coupler (plugins included)."""

import pytest

from tubefsi import registry
from tubefsi.testing import (CouplerContract, HyperelasticWallContract, RheologyContract, WallContract,
                             examples)
from tubefsi.walls import HyperelasticWall

WALLS = examples("walls")
RHEOLOGIES = examples("rheologies")


def test_every_registered_model_has_examples():
    for kind in ("walls", "rheologies"):
        reg = getattr(registry, kind)
        for name in reg:
            assert getattr(reg[name], "_examples", ()), f"{kind} {name!r} lists no _examples"


class TestWalls(WallContract):
    @pytest.fixture(params=WALLS, ids=repr)
    def wall(self, request):
        return request.param


class TestHyperelasticWalls(HyperelasticWallContract):
    @pytest.fixture(params=[w for w in WALLS if isinstance(w, HyperelasticWall)], ids=repr)
    def wall(self, request):
        return request.param


class TestRheologies(RheologyContract):
    @pytest.fixture(params=RHEOLOGIES, ids=repr)
    def rheology(self, request):
        return request.param


def _cases():
    fluids = [examples("rheologies", "power-law")[0], examples("rheologies", "newtonian")[0]]
    out = []
    for name in registry.couplers:
        if name == "ode":
            continue
        coupler = registry.couplers[name]()
        for wall in WALLS:
            for fluid in fluids:
                if coupler.supports(fluid, wall):
                    out.append(pytest.param((fluid, wall, coupler), id=f"{name}-{wall!r}-{fluid!r}"))
    return out


class TestCouplers(CouplerContract):
    @pytest.fixture(params=_cases())
    def case(self, request):
        return request.param
