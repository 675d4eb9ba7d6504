"""tubefsi's public contract suites, run on every model this distribution registers.

tubefsi's own ``tests/test_contracts.py`` runs the suites on the built-in models only, so these
fluids go through each suite here, once.
"""

import numpy as np
import pytest
import tubefsi
from tubefsi import registry
from tubefsi.couplers import Quadrature
from tubefsi.testing import AccuracyContract, CouplerContract, RheologyContract, examples
from tubefsi.testing.fuzz import FuzzContract

NAMES = ["carreau", "carreau-yasuda", "cross", "ellis", "bingham", "casson", "herschel-bulkley"]
FLUIDS = [fluid for name in NAMES for fluid in examples("rheologies", name)]


def test_registered_through_entry_points():
    for name in NAMES:
        assert registry.rheologies.distribution(name) == "tubefsi-rheologies"
        assert registry.rheologies[name]._examples


class TestRheologies(RheologyContract):
    @pytest.fixture(params=FLUIDS, ids=repr)
    def rheology(self, request):
        return request.param


def _cases():
    """Each fluid in one core wall (the walls taken in turn): a limit-pressure thick wall, a
    thin current-thickness wall with a limit pressure, a linear wall."""
    walls = ["thick-neo-hookean", "thin-mooney-rivlin", "thin-linear"]
    out = []
    for i, name in enumerate(NAMES):
        fluid = examples("rheologies", name)[0]
        wall_name = walls[i % len(walls)]
        wall = examples("walls", wall_name)[-1]
        out.append(pytest.param((fluid, wall, Quadrature()), id=f"{name}-{wall_name}"))
    return out


class TestCouplers(CouplerContract):
    @pytest.fixture(params=_cases())
    def case(self, request):
        return request.param


class TestAccuracy(AccuracyContract):          # the default answers against the brute force
    @pytest.fixture(params=_cases())           # (its coupler is ignored: the default path is checked)
    def case(self, request):
        return request.param


@pytest.mark.parametrize("name", NAMES)
def test_bad_parameters_raise_naming_the_parameter(name):
    cls = registry.rheologies[name]
    good = dict(cls._examples[0])
    for key in good:
        bad = dict(good, **{key: -1.0})
        with pytest.raises(tubefsi.InvalidParameterError, match=key):
            cls(**bad)
        with pytest.raises(tubefsi.InvalidParameterError, match=key):
            cls(**dict(good, **{key: float("nan")}))


def test_cross_rejects_a_non_monotone_stress():
    cross = registry.rheologies["cross"]
    with pytest.raises(tubefsi.InvalidParameterError, match="exponent"):
        cross(zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0, relaxation_time=1.0, exponent=1.5)
    ok = cross(zero_shear_viscosity=1.0, infinite_shear_viscosity=0.1, relaxation_time=1.0, exponent=1.5)
    g = np.geomspace(1e-3, 1e3, 400)
    assert np.all(np.diff(ok.stress(g)) > 0)


def test_infinite_shear_viscosity_cannot_exceed_the_zero_shear_one():
    with pytest.raises(tubefsi.InvalidParameterError, match="infinite_shear_viscosity"):
        registry.rheologies["carreau"](zero_shear_viscosity=1e-3, infinite_shear_viscosity=2e-3,
                                       relaxation_time=1.0, index=0.5)


def test_whole_curve_is_one_vectorized_call():
    """A 2000-point curve of a non-separable fluid: one call, the same as point by point."""
    fluid = registry.rheologies["carreau-yasuda"](**registry.rheologies["carreau-yasuda"]._examples[0])
    wall = registry.walls["thick-neo-hookean"](shear_modulus=5e3)
    tube = tubefsi.Tube(radius=5e-4, thickness=1.5e-4, length=2e-2)
    q = np.linspace(0, 5e-8, 2000)
    curve = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    assert curve.pressure_drop.shape == q.shape and curve.pressure_drop[0] == 0.0
    assert np.all(np.diff(curve.pressure_drop) > 0)
    for i in (1, 700, 1999):
        single = tubefsi.solve(fluid, wall, tube, flow_rate=float(q[i])).pressure_drop
        assert single == pytest.approx(curve.pressure_drop[i], rel=1e-12)


@pytest.mark.slow
class TestFuzz(FuzzContract):                  # typed errors or checked finite values, in bounded time
    rheologies = tuple(NAMES)
    walls = ()
    couplers = ()
    scenes = 8
