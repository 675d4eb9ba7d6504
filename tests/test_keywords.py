"""Wrong and missing keywords are a KeywordError (issue 11): an InvalidParameterError that is also a
TypeError, naming the keyword, suggesting the closest valid one and listing the valid ones."""

import inspect
import pickle

import attrs
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi import InvalidParameterError, KeywordError, Network, Tube, advise, fit, max_flow_rate, solve
from tubefsi._keywords import checked_keywords
from tubefsi.fields import positive
from tubefsi.registry import couplers, rheologies, walls
from tubefsi.testing.profiles import scaled
from tubefsi.walls.linear import ThinLinear

TUBE = Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
WALL = walls["thick-neo-hookean"](shear_modulus=2e3)


@pytest.mark.parametrize("call, keyword, suggestion", [
    (lambda: solve(FLUID, WALL, TUBE, flow_rat=1e-9), "flow_rat", "flow_rate"),
    (lambda: solve(FLUID, WALL, TUBE, flow_rate=1e-9, outlet=1.0), "outlet", "outlet_pressure"),
    (lambda: max_flow_rate(FLUID, WALL, TUBE, outlet_presure=0.0), "outlet_presure", "outlet_pressure"),
    (lambda: advise(FLUID, WALL, TUBE, flowrate=1e-9), "flowrate", "flow_rate"),
    (lambda: fit([1e-9], [1.0], FLUID, WALL, TUBE, parameter=["wall.shear_modulus"]), "parameter", "parameters"),
    (lambda: walls["thick-neo-hookean"](shear_modulos=2e3), "shear_modulos", "shear_modulus"),
    (lambda: rheologies["carreau"](zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0, relaxation_time=1.0,
                                   idx=0.5), "idx", "index"),
    (lambda: couplers["quadrature"](ordr=4), "ordr", "order"),
    (lambda: Tube(radius=1e-4, thicknes=3e-5, length=1e-2), "thicknes", "thickness"),
    (lambda: Network(fluid=FLUID), "fluid", None),
    (lambda: Network().add_tube("a", "b", WALL, TUBE, nme="t"), "nme", "name"),
    (lambda: Network().solve(tol=1e-9), "tol", "rtol"),
])
def test_an_unknown_keyword_is_named_with_a_suggestion(call, keyword, suggestion):
    with pytest.raises(KeywordError) as info:
        call()
    error = info.value
    assert isinstance(error, TypeError) and isinstance(error, InvalidParameterError)
    assert error.parameter == keyword and error.suggestion == suggestion and not error.missing
    assert f"unexpected keyword {keyword!r}" in str(error)
    if suggestion:
        assert f"did you mean {suggestion!r}" in str(error) and suggestion in error.valid
    assert all(name in str(error) for name in error.valid)


def test_a_missing_required_keyword_is_named():
    with pytest.raises(KeywordError, match="missing required keyword 'shear_modulus'") as info:
        walls["thick-neo-hookean"]()
    assert info.value.missing == ("shear_modulus",) and info.value.valid == ("shear_modulus", "axial_stretch")
    with pytest.raises(KeywordError, match="missing required keywords 'relaxation_time', 'index'") as info:
        rheologies["carreau"](zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0)
    assert info.value.parameter == "relaxation_time"
    with pytest.raises(KeywordError, match="missing required keyword 'tube'"):
        solve(FLUID, WALL, flow_rate=1e-9)
    with pytest.raises(KeywordError, match="missing required keyword 'parameters'"):
        fit([1e-9], [1.0], FLUID, WALL, TUBE)
    with pytest.raises(KeywordError, match="takes 0 positional arguments but 1 were given"):
        walls["thick-neo-hookean"](2e3)
    with pytest.raises(KeywordError, match="both by position and by keyword"):
        solve(FLUID, WALL, TUBE, tube=TUBE, flow_rate=1e-9)


def test_existing_except_clauses_keep_working():
    for kind in (TypeError, ValueError, InvalidParameterError, tubefsi.TubefsiError):
        with pytest.raises(kind):
            solve(FLUID, WALL, TUBE, flow_rat=1e-9)


def test_a_plugin_model_gets_it_from_its_base_class():
    @attrs.frozen(kw_only=True)
    class Stiff(ThinLinear):
        extra: float = positive(doc="a plugin's own parameter", default=1.0)

    with pytest.raises(KeywordError, match="did you mean 'extra'"):
        Stiff(youngs_modulus=1e4, poisson_ratio=0.3, extr=2.0)
    assert Stiff(youngs_modulus=1e4, poisson_ratio=0.3).extra == 1.0


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
    assert pickle.loads(pickle.dumps(solve)) is solve
    assert pickle.loads(pickle.dumps(WALL)) == WALL
    with pytest.raises(KeywordError) as info:
        solve(FLUID, WALL, TUBE, flow_rat=1e-9)
    error = info.value
    back = pickle.loads(pickle.dumps(error))
    assert type(back) is KeywordError and str(back) == str(error) and back.suggestion == "flow_rate"
    other = pickle.loads(pickle.dumps(InvalidParameterError("x", "(0, inf)", -1.0)))
    assert other.parameter == "x" and str(other) == "x must be in (0, inf) (got -1.0)"


def _model_classes():
    from tubefsi.network import Network as _Network
    return [walls[n] for n in walls] + [rheologies[n] for n in rheologies] + [couplers[n] for n in couplers] + [
        Tube, _Network]


def test_the_check_is_inside_init_with_attrs_own_code():
    """Every model, coupler and tube class has a checked ``__init__``; where attrs generated it,
    the checked one is attrs' own code compiled again (no frame in between, no ``__call__`` on
    the metaclass), and it builds what attrs' original builds, for every example parameter set."""
    from tubefsi._keywords import KeywordChecked
    assert "__call__" not in vars(KeywordChecked)
    for cls in _model_classes():
        init = cls.__init__
        assert init._keyword_checked, cls
        original = init.__globals__.get("_tubefsi_init")
        if cls.__name__ != "Network":
            assert original is not None and original.__code__.co_filename.startswith("<attrs generated"), cls
            assert inspect.signature(init) == inspect.signature(original)
        for kwargs in getattr(cls, "_examples", ()):
            by_attrs = object.__new__(cls)
            original(by_attrs, **kwargs)
            assert cls(**kwargs) == by_attrs


@pytest.mark.parametrize("slots", [True, False])
def test_a_plugin_class_in_every_form_gets_the_check(slots):
    """attrs classes with and without slots, positional fields, and a hand-written ``__init__``."""
    @attrs.frozen(kw_only=False, slots=slots)
    class Positional(ThinLinear):
        extra: float = positive(doc="a plugin's own parameter", default=1.0)

    # (the base's fields are keyword-only; the plugin's own field is positional)
    made = Positional(2.0, youngs_modulus=1e4, poisson_ratio=0.3)
    assert (made.youngs_modulus, made.poisson_ratio, made.extra) == (1e4, 0.3, 2.0)
    assert Positional(youngs_modulus=1e4, poisson_ratio=0.3) == Positional(1.0, youngs_modulus=1e4, poisson_ratio=0.3)
    with pytest.raises(KeywordError, match="did you mean 'extra'"):
        Positional(youngs_modulus=1e4, poisson_ratio=0.3, extr=2.0)
    with pytest.raises(KeywordError, match="missing required keyword 'poisson_ratio'"):
        Positional(2.0, youngs_modulus=1e4)
    with pytest.raises(KeywordError, match="takes 1 positional arguments but 2 were given"):
        Positional(2.0, 3.0, youngs_modulus=1e4, poisson_ratio=0.3)
    with pytest.raises(KeywordError, match="both by position and by keyword"):
        Positional(2.0, extra=3.0, youngs_modulus=1e4, poisson_ratio=0.3)
    with pytest.raises(InvalidParameterError, match="extra"):
        Positional(-1.0, youngs_modulus=1e4, poisson_ratio=0.3)

    class Handwritten(ThinLinear):
        def __init__(self, *, stiffness):
            super().__init__(youngs_modulus=stiffness, poisson_ratio=0.3)

    assert Handwritten(stiffness=2e4).youngs_modulus == 2e4
    with pytest.raises(KeywordError, match="did you mean 'stiffness'"):
        Handwritten(stifness=2e4)


@settings(deadline=None, max_examples=scaled(60))
@given(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, -0.0, 1.0, 90.0]),
                          st.integers(-3, 3), st.sampled_from(["thin", "thick", "reference", "current", "other"])),
                min_size=6, max_size=6))
def test_the_checked_init_accepts_and_rejects_as_attrs_does(values):
    """The checked ``__init__`` (with its store of in-range floats) against attrs' original on
    the same arguments: equal models, or the same error with the same message."""
    for cls in _model_classes()[:-1]:
        if getattr(cls, "__abstractmethods__", None):
            continue
        names = [a.alias for a in attrs.fields(cls) if a.init]
        if not names or len(names) > len(values):
            continue
        kwargs = dict(zip(names, values))
        original = cls.__init__.__globals__["_tubefsi_init"]
        by_attrs = object.__new__(cls)
        try:
            original(by_attrs, **kwargs)
        except Exception as error:            # noqa: BLE001 (compared below)
            expected = error
        else:
            expected = None
        if expected is None:
            assert cls(**kwargs) == by_attrs, (cls, kwargs)
        else:
            with pytest.raises(type(expected)) as info:
                cls(**kwargs)
            assert str(info.value) == str(expected), (cls, kwargs)


def test_the_check_holds_for_every_way_a_plugin_class_gets_its_init():
    """A cached hash, a dict class whose base has its own ``__attrs_init_subclass__``, a
    dataclass, a class's own ``__setattr__`` (which attrs' code goes through: the fast store must
    not bypass it), and the name a hand-written ``__init__``'s bad ``super().__init__`` call gets."""
    import dataclasses

    from tubefsi.couplers.base import Coupler

    @attrs.frozen(kw_only=True, cache_hash=True)
    class Hashed(ThinLinear):
        pass

    assert hash(Hashed(youngs_modulus=1e4, poisson_ratio=0.3)) == hash(Hashed(youngs_modulus=1e4, poisson_ratio=0.3))

    @attrs.frozen(kw_only=True, slots=False)
    class Registering(ThinLinear):
        @classmethod
        def __attrs_init_subclass__(cls):        # a plugin's own registration hook
            pass

    @attrs.frozen(kw_only=True, slots=False)
    class Child(Registering):
        extra: float = positive(default=1.0)

    with pytest.raises(KeywordError, match="did you mean 'extra'"):
        Child(youngs_modulus=1e4, poisson_ratio=0.3, extr=2.0)

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class DataCoupler(Coupler):
        tolerance: float = 1e-6

    DataCoupler.__abstractmethods__ = frozenset()      # (its methods do not matter here)
    assert DataCoupler(tolerance=1e-3).tolerance == 1e-3
    with pytest.raises(KeywordError, match="did you mean 'tolerance'"):
        DataCoupler(tolerence=1e-8)

    seen = []

    @attrs.define(kw_only=True, on_setattr=attrs.setters.NO_OP)
    class Watched(Coupler):
        tol: float = positive(default=1e-6)

        def __setattr__(self, name, value):
            seen.append(name)
            object.__setattr__(self, name, value)

    Watched.__abstractmethods__ = frozenset()
    Watched(tol=1e-3)
    Watched(tol=1)
    assert seen == ["tol", "tol"]

    class Handwritten(ThinLinear):
        def __init__(self, *, stiffness):
            super().__init__(youngs_modulus=stiffness, poisson_ratio=0.3, stifness=1.0)

    with pytest.raises(KeywordError, match=r"^ThinLinear\(\) got an unexpected keyword 'stifness'"):
        Handwritten(stiffness=2e4)


def test_a_hand_written_init_in_a_slotted_attrs_class_and_one_set_later():
    """A slotted attrs class keeps its own ``__init__`` (whose ``super()`` must see the class
    attrs made), and an ``__init__`` written outside any class and set on it later is checked
    with ``self`` not counted as a keyword or a positional argument."""
    @attrs.frozen(kw_only=True)
    class Stiff(ThinLinear):
        def __init__(self, *, stiffness):
            super().__init__(youngs_modulus=stiffness, poisson_ratio=0.3)

    assert Stiff(stiffness=2e4).youngs_modulus == 2e4
    with pytest.raises(KeywordError, match=r"did you mean 'stiffness'\? \(valid keywords: stiffness\)"):
        Stiff(stifness=2e4)

    def init(self, *, stiffness):
        ThinLinear.__init__(self, youngs_modulus=stiffness, poisson_ratio=0.3)

    class Later(ThinLinear):
        pass

    Later.__init__ = init
    assert Later(stiffness=3e4).youngs_modulus == 3e4
    with pytest.raises(KeywordError, match=r"\(valid keywords: stiffness\)$"):
        Later(stifness=3e4)
    with pytest.raises(KeywordError, match="takes 0 positional arguments but 1 were given"):
        Later(3e4)
