"""The generic (one-method) paths of the base classes, through the whole solver.

A power law written as a *non-separable* rheology (only ``_stress`` or only
``_shear_rate``) must reproduce the built-in closed-form power law; this exercises
the tabulated flow function, the non-separable couplers and max_flow_rate.
"""

import re

import attrs
import numpy as np
import pytest

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.rheology import Rheology
from tubefsi.testing import RheologyContract
from tubefsi.walls import WallModel

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)


@attrs.frozen
class StressOnlyPowerLaw(Rheology):
    consistency: float = 0.017
    index: float = 0.7

    def _stress(self, shear_rate):
        return self.consistency * shear_rate**self.index


@attrs.frozen
class RateOnlyPowerLaw(Rheology):
    consistency: float = 0.017
    index: float = 0.7

    def _shear_rate(self, stress):
        return (stress / self.consistency) ** (1 / self.index)


class TestGenericRheologyContract(RheologyContract):
    @pytest.fixture(params=[StressOnlyPowerLaw(), RateOnlyPowerLaw(index=1.3)], ids=repr)
    def rheology(self, request):
        return request.param


@pytest.mark.parametrize("generic", [StressOnlyPowerLaw, RateOnlyPowerLaw])
@pytest.mark.parametrize("wall_name", ["thick-neo-hookean", "thin-linear", "thin-mooney-rivlin"])
def test_non_separable_path_matches_closed_forms(generic, wall_name):
    wall = walls[wall_name](**walls[wall_name]._examples[0])
    fluid = generic()
    assert not fluid.separable
    ref = rheologies["power-law"](consistency=0.017, index=0.7)
    q = np.geomspace(1e-13, 0.9 * min(tubefsi.max_flow_rate(ref, wall, TUBE), 1e-8), 200)
    a = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    b = tubefsi.solve(ref, wall, TUBE, flow_rate=q)
    assert a.coupler_name == "quadrature"
    np.testing.assert_allclose(a.pressure_drop, b.pressure_drop, rtol=1e-12, atol=0)
    np.testing.assert_allclose(a.inlet_displacement, b.inlet_displacement, rtol=1e-12, atol=0)
    back = tubefsi.solve(fluid, wall, TUBE, pressure_drop=b.pressure_drop[::20])
    np.testing.assert_allclose(back.flow_rate, q[::20], rtol=1e-11, atol=0)
    np.testing.assert_allclose(a.pressure(0.3 * TUBE.length), b.pressure(0.3 * TUBE.length), rtol=1e-12)


def test_non_separable_maximum_flow_rate():
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    ref = tubefsi.max_flow_rate(rheologies["power-law"](consistency=0.017, index=0.7), wall, TUBE)
    assert tubefsi.max_flow_rate(StressOnlyPowerLaw(), wall, TUBE) == pytest.approx(ref, rel=1e-10)
    assert tubefsi.max_flow_rate(StressOnlyPowerLaw(index=1.2), wall, TUBE) == np.inf
    with pytest.raises(tubefsi.NoSteadyStateError):
        tubefsi.solve(StressOnlyPowerLaw(), wall, TUBE, flow_rate=1.01 * ref)


def test_wall_given_only_by_its_inverse_law():
    @attrs.frozen
    class InverseLinear(WallModel):
        """lam = 1 + 3 p / (4 E tb): the thin linear wall, written as stretch(p)."""

        def _stretch(self, pressure, tb):
            return 1.0 + 0.75 * pressure / (6e3 * tb)

    fluid = rheologies["power-law"](consistency=0.017, index=0.7)
    ref = walls["thin-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
    q = np.array([1e-11, 1e-9, 5e-9])
    # the tube law of a wall given by its inverse is itself a root solve, and its slope a difference
    # of it: the integral cannot reach 1e-14 and says so, with its estimate (a few 1e-9)
    with pytest.warns(tubefsi.AccuracyWarning, match="estimated relative error up to") as caught:
        a = tubefsi.solve(fluid, InverseLinear(), TUBE, flow_rate=q)
    estimate = max(float(re.search(r"up to ([0-9.e+-]+)", str(w.message)).group(1)) for w in caught
                   if issubclass(w.category, tubefsi.AccuracyWarning))
    b = tubefsi.solve(fluid, ref, TUBE, flow_rate=q)
    assert estimate < 1e-7
    np.testing.assert_allclose(a.pressure_drop, b.pressure_drop, rtol=2 * estimate)
