"""tubefsi's public contract suites, run on every wall this distribution registers.

tubefsi's own ``tests/test_contracts.py`` runs the suites on the built-in models only, so these
walls go through each suite here, once.
"""

import math

import pytest
import tubefsi
from tubefsi import registry
from tubefsi.testing import (AccuracyContract, CouplerContract, HyperelasticWallContract, accuracy_cases,
                             coupler_cases, examples)
from tubefsi.testing.fuzz import FuzzContract

NAMES = ["thin-gent", "thick-gent", "thin-demiray", "thick-demiray", "thin-ogden", "thick-ogden", "thin-yeoh", "thick-yeoh"]
WALLS = [wall for name in NAMES for wall in examples("walls", name)]


def test_registered_through_entry_points():
    for name in NAMES:
        assert registry.walls.distribution(name) == "tubefsi-hyperelastic"
        assert registry.walls[name]._examples


class TestWalls(HyperelasticWallContract):      # includes every WallContract test
    @pytest.fixture(params=WALLS, ids=repr)
    def wall(self, request):
        return request.param


class TestCouplers(CouplerContract):
    @pytest.fixture(params=coupler_cases(WALLS))
    def case(self, request):
        return request.param


class TestAccuracy(AccuracyContract):          # the default answers against the brute force
    @pytest.fixture(params=accuracy_cases(WALLS))
    def case(self, request):
        return request.param


@pytest.mark.parametrize("name", NAMES)
def test_bad_parameters_raise_naming_the_parameter(name):
    cls = registry.walls[name]
    good = dict(cls._examples[0])
    for key, value in good.items():
        if key == "thickness_convention":
            with pytest.raises(tubefsi.InvalidParameterError, match=key):
                cls(**dict(good, **{key: "middle"}))
            continue
        if key not in ("c2", "exponents"):      # those may be negative
            bad = tuple(-abs(v) for v in value) if isinstance(value, tuple) else -1.0
            with pytest.raises(tubefsi.InvalidParameterError, match=key):
                cls(**dict(good, **{key: bad}))
        nan = (float("nan"),) * len(value) if isinstance(value, tuple) else float("nan")
        with pytest.raises(tubefsi.InvalidParameterError):
            cls(**dict(good, **{key: nan}))


def test_ogden_term_counts_must_match():
    with pytest.raises(tubefsi.InvalidParameterError, match="exponents"):
        registry.walls["thick-ogden"](moduli=(1e3, 1e3), exponents=(2.0,))
    with pytest.raises(tubefsi.InvalidParameterError, match="exponents"):
        registry.walls["thick-ogden"](moduli=(1e3,), exponents=(0.0,))


def test_gent_stretch_beyond_the_lock_is_rejected():
    wall = registry.walls["thick-gent"](shear_modulus=1e3, locking_parameter=3.0)
    lock = wall.max_stretch(0.3)
    assert lock == pytest.approx((math.sqrt(3) + math.sqrt(7)) / 2, rel=1e-15)
    with pytest.raises(tubefsi.InvalidParameterError, match="stretch"):
        wall.pressure(lock, 0.3)
    assert wall.limit_pressure(0.3) == math.inf
    # every pressure has a stretch below the lock, as far as double precision resolves it
    # (the thick Gent pressure grows only logarithmically toward the lock)
    top = wall.pressure(lock * (1 - 1e-15), 0.3)
    assert wall.stretch(0.999 * top, 0.3) < lock
    # beyond: not "no steady state" (the limit pressure is infinite) but a pressure whose stretch
    # double precision cannot tell from the lock, a typed error giving the resolvable range
    with pytest.raises(tubefsi.InvalidParameterError, match="pressure"):
        wall.stretch(1e3 * top, 0.3)


@pytest.mark.slow
class TestFuzz(FuzzContract):                  # typed errors or checked finite values, in bounded time
    rheologies = ()
    walls = tuple(NAMES)
    couplers = ()
    scenes = 8
