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
:class:`RheologyContract`, :class:`CouplerContract` (whose ``case`` fixture
:func:`coupler_cases` fills: every registered coupler that supports each pair). Those compare a
model's paths with each other. :class:`AccuracyContract` (``case`` fixture: ``(rheology, wall)``,
filled by :func:`accuracy_cases`) compares the *default answers* of ``tubefsi.solve`` — pressure
drop, flow rate, inlet displacement, profiles — with :func:`brute_force`, an independent
evaluation by a different algorithm (tanh–sinh quadrature of the separated identity in the
pressure, bracketing roots of the forward tube law) that calls only the models' public methods,
to ``1e-11 max(1, kappa)``; a law the default path gets wrong fails there::

    from tubefsi.testing import AccuracyContract, accuracy_cases, examples

    class TestMyWallsAccuracy(AccuracyContract):
        @pytest.fixture(params=accuracy_cases(examples("walls", "thick-gent")))
        def case(self, request):
            return request.param

Independent references live in the subpackage :mod:`tubefsi.testing.reference`, which this
module does not import (its mpmath modules need ``mpmath``, from the ``test`` extra); import its
modules directly:

* ``tubefsi.testing.reference.tube_laws`` — the tube laws in mpmath: one reference wall for the
  closed-form built-in laws and for any material given by its strain energy;
* ``tubefsi.testing.reference.power_law`` — power-law flow, separated (the integral ``Jhat``, its
  tail, the maximum flow rate);
* ``tubefsi.testing.reference.rheology`` — generalized Newtonian flow (Carreau–Yasuda, laws
  given by their shear rate, yield stress included) through the Rabinowitsch–Mooney integral;
* ``tubefsi.testing.reference.chapter_baseline`` — the chapter's method (``odeint`` at its
  default tolerances, one ODE per point), the baseline of the speed benchmarks;
* ``tubefsi.testing.reference.rel_err`` — the relative error of a result against a reference.

Nothing there calls tubefsi's numerics.

Hypothesis profiles are in :mod:`tubefsi.testing.profiles`: ``ci`` (seeded, the default) and
``explore`` (randomized, ten times the examples), chosen by ``TUBEFSI_HYPOTHESIS_PROFILE``. A test
directory loads one in its ``conftest.py`` before the suites are imported::

    from tubefsi.testing.profiles import load_profile

    load_profile()

That is why the names below are imported on first use (PEP 562), not with the package: importing
``tubefsi.testing.profiles`` must not create the suites' hypothesis settings, which take their
unset values from the profile active when they are created.
"""

_LAZY = {
    "WallContract": "contracts", "HyperelasticWallContract": "contracts", "RheologyContract": "contracts",
    "CouplerContract": "contracts", "AccuracyContract": "contracts", "brute_force": "contracts",
    "BruteForce": "contracts", "accuracy_cases": "contracts",
    "examples": "strategies", "coupler_cases": "strategies", "strains": "strategies",
    "reduced_thicknesses": "strategies", "flow_rates": "strategies",
}

__all__ = [
    "WallContract", "HyperelasticWallContract", "RheologyContract", "CouplerContract", "AccuracyContract",
    "brute_force", "BruteForce", "examples", "coupler_cases", "accuracy_cases", "strains", "reduced_thicknesses",
    "flow_rates",
]


def __getattr__(name):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    try:
        from . import contracts, strategies     # noqa: F401 - imported here on purpose (the docstring says why)
    except ModuleNotFoundError as exc:
        raise ModuleNotFoundError(f"tubefsi.testing.{name} needs {exc.name}, from the test extra: "
                                  "pip install '.[test]' in a clone of tubefsi (docs/installation.md)",
                                  name=exc.name) from exc

    value = getattr({"contracts": contracts, "strategies": strategies}[module], name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
