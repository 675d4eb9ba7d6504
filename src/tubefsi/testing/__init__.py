"""Public contract suites and hypothesis strategies, for tubefsi and its plugins.

Every registered model is tested by the same code: a model class lists example
parameter sets in ``_examples`` (a tuple of keyword dicts), and the suites here
run on each. A plugin's tests subclass the suites and provide fixtures::

    import pytest
    from tubefsi.testing import WallContract, examples

    class TestMyWalls(WallContract):
        @pytest.fixture(params=examples("walls", "thick-gent"), ids=repr)
        def wall(self, request):
            return request.param

Suites: :class:`WallContract`, :class:`HyperelasticWallContract`,
:class:`RheologyContract`, :class:`CouplerContract`.
"""

from .contracts import CouplerContract, HyperelasticWallContract, RheologyContract, WallContract
from .strategies import examples, flow_rates, reduced_thicknesses, strains

__all__ = [
    "WallContract", "HyperelasticWallContract", "RheologyContract", "CouplerContract",
    "examples", "strains", "reduced_thicknesses", "flow_rates",
]
