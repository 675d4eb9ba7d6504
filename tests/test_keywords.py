"""Wrong and missing keywords (issue 11).

A public function (``solve``, ``max_flow_rate``, ``advise``, ``fit``, the ``Network`` API) raises
a KeywordError: an InvalidParameterError that is also a TypeError, naming the keyword, suggesting
the closest valid one and listing the valid ones. A model, coupler or ``Tube`` constructor is a
plain attrs class and raises Python's own TypeError, naming the keyword; a public function that
builds a model from a caller's dict of keywords (``dimensionless.scene``'s ``wall_options``)
gives the KeywordError. Either way ``except TypeError`` catches it.
"""

import dataclasses
import inspect
import pickle

import attrs
import pytest

import tubefsi
from tubefsi import InvalidParameterError, KeywordError, Network, Tube, advise, fit, max_flow_rate, solve
from tubefsi._keywords import checked_keywords
from tubefsi.couplers.base import Coupler
from tubefsi.fields import positive
from tubefsi.registry import couplers, rheologies, walls
from tubefsi.walls.linear import ThinLinear

TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
WALL = walls["thick-neo-hookean"](shear_modulus=2e3)


# --------------------------------------------------------------------------- public functions

@pytest.mark.parametrize("call, keyword, suggestion", [
    (lambda: solve(FLUID, WALL, TUBE, flow_rat=1e-9), "flow_rat", "flow_rate"),
    (lambda: solve(FLUID, WALL, TUBE, flow_rate=1e-9, outlet=1.0), "outlet", "outlet_pressure"),
    (lambda: max_flow_rate(FLUID, WALL, TUBE, outlet_presure=0.0), "outlet_presure", "outlet_pressure"),
    (lambda: advise(FLUID, WALL, TUBE, flowrate=1e-9), "flowrate", "flow_rate"),
    (lambda: fit([1e-9], [1.0], FLUID, WALL, TUBE, parameter=["wall.shear_modulus"]), "parameter", "parameters"),
    (lambda: Network(fluid=FLUID), "fluid", None),
    (lambda: Network().add_tube("a", "b", WALL, TUBE, nme="t"), "nme", "name"),
    (lambda: Network().solve(tol=1e-9), "tol", "rtol"),
    (lambda: tubefsi.dimensionless.scene(index=0.7, reduced_thickness=0.3, qbar=0.1, beta=1.0, wall="thin-linear",
                                         wall_options={"poison_ratio": 0.3}), "poison_ratio", "poisson_ratio"),
])
def test_a_public_function_names_an_unknown_keyword_with_a_suggestion(call, keyword, suggestion):
    with pytest.raises(KeywordError) as info:
        call()
    error = info.value
    assert isinstance(error, TypeError) and isinstance(error, InvalidParameterError)
    assert error.parameter == keyword and error.suggestion == suggestion and not error.missing
    assert f"unexpected keyword {keyword!r}" in str(error)
    if suggestion:
        assert f"did you mean {suggestion!r}" in str(error) and suggestion in error.valid
    assert all(name in str(error) for name in error.valid)


def test_a_public_function_names_a_missing_keyword_and_misplaced_arguments():
    with pytest.raises(KeywordError, match="missing required keyword 'tube'") as info:
        solve(FLUID, WALL, flow_rate=1e-9)
    assert info.value.missing == ("tube",)
    with pytest.raises(KeywordError, match="missing required keyword 'parameters'"):
        fit([1e-9], [1.0], FLUID, WALL, TUBE)
    with pytest.raises(KeywordError, match="both by position and by keyword"):
        solve(FLUID, WALL, TUBE, tube=TUBE, flow_rate=1e-9)
    with pytest.raises(KeywordError, match=r"^Network\(\): takes 1 positional arguments but 2 were given"):
        Network(FLUID, FLUID)
    with pytest.raises(KeywordError, match=r"^Network\.set_pressure\(\) missing required keyword 'pressure'"):
        Network().set_pressure("a")


def test_existing_except_clauses_keep_working():
    for kind in (TypeError, ValueError, InvalidParameterError, tubefsi.TubefsiError):
        with pytest.raises(kind):
            solve(FLUID, WALL, TUBE, flow_rat=1e-9)
    for call in (lambda: walls["thick-neo-hookean"](shear_modulos=2e3), lambda: Tube(radius=1e-4)):
        with pytest.raises(TypeError):
            call()


def test_a_type_error_from_inside_is_left_alone():
    @checked_keywords
    def broken(x, *, y=1):
        return x + "text"

    with pytest.raises(TypeError) as info:
        broken(1, y=2)
    assert not isinstance(info.value, KeywordError)
    with pytest.raises(KeywordError, match="did you mean 'y'"):
        broken(1, yy=2)


def test_signatures_pickling_and_values_are_unchanged():
    sig = inspect.signature(walls["thick-neo-hookean"])
    assert list(sig.parameters) == ["shear_modulus", "axial_stretch"]
    assert inspect.signature(Tube).parameters["radius"].kind is inspect.Parameter.KEYWORD_ONLY
    assert list(inspect.signature(solve).parameters)[:4] == ["rheology", "wall", "tube", "flow_rate"]
    assert list(inspect.signature(Network).parameters) == ["rheology"]
    assert pickle.loads(pickle.dumps(solve)) is solve
    assert pickle.loads(pickle.dumps(WALL)) == WALL
    with pytest.raises(KeywordError) as info:
        solve(FLUID, WALL, TUBE, flow_rat=1e-9)
    error = info.value
    back = pickle.loads(pickle.dumps(error))
    assert type(back) is KeywordError and str(back) == str(error) and back.suggestion == "flow_rate"
    other = pickle.loads(pickle.dumps(InvalidParameterError("x", "(0, inf)", -1.0)))
    assert other.parameter == "x" and str(other) == "x must be in (0, inf) (got -1.0)"


# --------------------------------------------------------------------------- constructors

@pytest.mark.parametrize("call, keyword", [
    (lambda: walls["thick-neo-hookean"](shear_modulos=2e3), "shear_modulos"),
    (lambda: rheologies["carreau"](zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0, relaxation_time=1.0,
                                   idx=0.5), "idx"),
    (lambda: couplers["quadrature"](ordr=4), "ordr"),
    (lambda: Tube(radius=1e-4, thicknes=3e-5, length=1e-2), "thicknes"),
    (lambda: walls["thick-neo-hookean"](), "shear_modulus"),
    (lambda: rheologies["carreau"](zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0), "relaxation_time"),
])
def test_a_constructor_raises_pythons_type_error_naming_the_keyword(call, keyword):
    with pytest.raises(TypeError) as info:
        call()
    assert type(info.value) is TypeError and repr(keyword) in str(info.value)


def test_models_are_plain_attrs_classes():
    """No hook between the call and attrs' ``__init__``: the bases' metaclass is ``abc.ABCMeta``
    and every registered class's ``__init__`` is the one attrs generated."""
    import abc

    for cls in [walls[n] for n in walls] + [rheologies[n] for n in rheologies] + [couplers[n] for n in couplers]:
        assert type(cls) is abc.ABCMeta, cls
        assert cls.__init__.__code__.co_filename.startswith("<attrs generated"), cls
    assert type(Tube) is type and Tube.__init__.__code__.co_filename.startswith("<attrs generated")


@pytest.mark.parametrize("slots", [True, False])
def test_a_plugin_class_in_every_form_constructs_and_rejects_bad_keywords(slots):
    """attrs classes with and without slots, keyword-only and positional fields, a hand-written
    ``__init__`` calling ``super().__init__``, one in a slotted attrs class, a dataclass."""
    @attrs.frozen(kw_only=True, slots=slots)
    class Stiff(ThinLinear):
        extra: float = positive(doc="a plugin's own parameter", default=1.0)

    assert Stiff(youngs_modulus=1e4, poisson_ratio=0.3).extra == 1.0
    assert Stiff(youngs_modulus=1e4, poisson_ratio=0.3, extra=2.0).extra == 2.0
    with pytest.raises(TypeError, match="'extr'"):
        Stiff(youngs_modulus=1e4, poisson_ratio=0.3, extr=2.0)
    with pytest.raises(TypeError, match="'poisson_ratio'"):
        Stiff(youngs_modulus=1e4)
    with pytest.raises(InvalidParameterError, match="extra"):
        Stiff(youngs_modulus=1e4, poisson_ratio=0.3, extra=-1.0)

    @attrs.frozen(kw_only=False, slots=slots)
    class Positional(ThinLinear):
        extra: float = positive(doc="a plugin's own parameter", default=1.0)

    # (the base's fields are keyword-only; the plugin's own field is positional)
    made = Positional(2.0, youngs_modulus=1e4, poisson_ratio=0.3)
    assert (made.youngs_modulus, made.poisson_ratio, made.extra) == (1e4, 0.3, 2.0)
    assert Positional(youngs_modulus=1e4, poisson_ratio=0.3) == Positional(1.0, youngs_modulus=1e4, poisson_ratio=0.3)
    with pytest.raises(TypeError, match="'extr'"):
        Positional(youngs_modulus=1e4, poisson_ratio=0.3, extr=2.0)
    with pytest.raises(TypeError, match="'poisson_ratio'"):
        Positional(2.0, youngs_modulus=1e4)
    with pytest.raises(TypeError, match="positional argument"):
        Positional(2.0, 3.0, youngs_modulus=1e4, poisson_ratio=0.3)
    with pytest.raises(TypeError, match="'extra'"):
        Positional(2.0, extra=3.0, youngs_modulus=1e4, poisson_ratio=0.3)
    with pytest.raises(InvalidParameterError, match="extra"):
        Positional(-1.0, youngs_modulus=1e4, poisson_ratio=0.3)

    class Handwritten(ThinLinear):
        def __init__(self, *, stiffness):
            super().__init__(youngs_modulus=stiffness, poisson_ratio=0.3)

    assert Handwritten(stiffness=2e4).youngs_modulus == 2e4
    with pytest.raises(TypeError, match="'stifness'"):
        Handwritten(stifness=2e4)

    @attrs.frozen(kw_only=True, slots=slots)
    class HandwrittenAttrs(ThinLinear):
        def __init__(self, *, stiffness):
            super().__init__(youngs_modulus=stiffness, poisson_ratio=0.3)    # (super() of the class attrs made)

    assert HandwrittenAttrs(stiffness=3e4).youngs_modulus == 3e4
    with pytest.raises(TypeError, match="'stifness'"):
        HandwrittenAttrs(stifness=3e4)

    class BadSuper(ThinLinear):
        def __init__(self, *, stiffness):
            super().__init__(youngs_modulus=stiffness, poisson_ratio=0.3, stifness=1.0)

    with pytest.raises(TypeError, match="'stifness'"):
        BadSuper(stiffness=2e4)


def test_a_dataclass_coupler_constructs_and_rejects_bad_keywords():
    @dataclasses.dataclass(frozen=True, kw_only=True)
    class DataCoupler(Coupler):
        tolerance: float = 1e-6

    DataCoupler.__abstractmethods__ = frozenset()      # (its methods do not matter here)
    assert DataCoupler(tolerance=1e-3).tolerance == 1e-3
    with pytest.raises(TypeError, match="'tolerence'"):
        DataCoupler(tolerence=1e-8)


def test_every_registered_example_constructs():
    for cls in [walls[n] for n in walls] + [rheologies[n] for n in rheologies] + [couplers[n] for n in couplers]:
        for kwargs in getattr(cls, "_examples", ()):
            assert cls(**kwargs) == cls(**kwargs), cls
