"""Hypothesis strategies and example tables for the contract suites."""

from __future__ import annotations

from hypothesis import strategies as st

from .. import registry

__all__ = ["examples", "strains", "reduced_thicknesses", "flow_rates"]


def examples(kind: str, name: str | None = None) -> list:
    """Instances built from ``_examples`` of every registered model of ``kind``
    (``"walls"``, ``"rheologies"``), or of the one registered as ``name``."""
    reg = getattr(registry, kind)
    names = [name] if name is not None else list(reg)
    out = []
    for n in names:
        cls = reg[n]
        for kwargs in getattr(cls, "_examples", ()):
            out.append(cls(**kwargs))
    return out


def strains(min_value: float = 1e-6, max_value: float = 3.0):
    """Hoop strains, log-uniform between the bounds."""
    import math

    return st.floats(math.log(min_value), math.log(max_value)).map(math.exp)


def reduced_thicknesses(min_value: float = 0.01, max_value: float = 2.0):
    """Thickness ratios t/a, log-uniform."""
    import math

    return st.floats(math.log(min_value), math.log(max_value)).map(math.exp)


def flow_rates(min_value: float = 1e-3, max_value: float = 1.0):
    """Fractions of a reference load, log-uniform."""
    import math

    return st.floats(math.log(min_value), math.log(max_value)).map(math.exp)
