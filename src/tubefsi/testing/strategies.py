"""Hypothesis strategies and example tables for the contract suites."""

from __future__ import annotations

import math

import pytest
from hypothesis import strategies as st

from .. import registry

__all__ = ["examples", "coupler_cases", "strains", "reduced_thicknesses", "flow_rates"]


def examples(kind: str, name: str | None = None) -> list:
    """Instances built from ``_examples`` of every registered model of ``kind``
    (``"walls"``, ``"rheologies"``), or of the one registered as ``name``."""
    reg = getattr(registry, kind)
    names = [name] if name is not None else list(reg)
    out = []
    for n in names:
        cls = reg[n]
        for kwargs in cls._examples:
            out.append(cls(**kwargs))
    return out


def coupler_cases(walls, fluids=None, *, exclude=("ode",)) -> list:
    """``pytest.param((fluid, wall, coupler))`` for every registered coupler (but ``exclude``)
    that supports each pair, for a :class:`~tubefsi.testing.CouplerContract` fixture.

    ``fluids`` defaults to the first example of ``power-law`` and of ``newtonian``; the ODE
    coupler is left out by default (it is a reference, checked against the others elsewhere).
    """
    if fluids is None:
        fluids = [examples("rheologies", "power-law")[0], examples("rheologies", "newtonian")[0]]
    out = []
    for name in registry.couplers:
        if name in exclude:
            continue
        coupler = registry.couplers[name]()
        for wall in walls:
            for fluid in fluids:
                if coupler.supports(fluid, wall):
                    out.append(pytest.param((fluid, wall, coupler), id=f"{name}-{wall!r}-{fluid!r}"))
    return out


def strains(min_value: float = 1e-6, max_value: float = 3.0):
    """Hoop strains, log-uniform between the bounds."""
    return st.floats(math.log(min_value), math.log(max_value)).map(math.exp)


def reduced_thicknesses(min_value: float = 0.01, max_value: float = 2.0):
    """Thickness ratios t/a, log-uniform."""
    return st.floats(math.log(min_value), math.log(max_value)).map(math.exp)


def flow_rates(min_value: float = 1e-3, max_value: float = 1.0):
    """Fractions of a reference load, log-uniform."""
    return st.floats(math.log(min_value), math.log(max_value)).map(math.exp)
