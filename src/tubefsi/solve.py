"""The entry points: :func:`solve`, :func:`max_flow_rate` and :func:`select_coupler`.

``solve`` builds the :class:`~tubefsi.scene.Scene` (:func:`~tubefsi.scene.make_scene`), picks
the coupler, validates the load, runs the coupler (wrapped in
:class:`~tubefsi.couplers.Checked` when it checks itself) on chunks of at most ``CHUNK``
loads and returns a :class:`~tubefsi.Solution`.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from . import registry
from ._validation import as_load
from .couplers.base import Coupler
from .couplers.checked import checked
from .errors import InvalidParameterError, NoSteadyStateError
from .scene import State, _resolve, make_scene
from .solution import Solution

__all__ = ["solve", "max_flow_rate", "select_coupler"]


def select_coupler(rheology, wall, coupler="auto") -> Coupler:
    """The coupler ``solve`` would use: a name, an instance, or ``"auto"`` (cheapest accurate)."""
    if isinstance(coupler, str) and coupler == "auto":
        candidates = []
        for name in registry.couplers:
            cls = registry.couplers[name]
            if cls.meets_accuracy_contract:
                inst = cls()
                if inst.supports(rheology, wall):
                    candidates.append((cls.cost_rank, name, inst))
        if not candidates:
            raise InvalidParameterError("coupler", "a coupler that supports this pair",
                                        "auto", "no registered coupler supports it")
        return min(candidates, key=lambda c: (c[0], c[1]))[2]
    inst = _resolve("coupler", coupler, Coupler, registry.couplers)
    if not inst.supports(rheology, wall):
        raise InvalidParameterError("coupler", "a coupler that supports this pair", coupler,
                                    f"{type(inst).__name__} does not support {type(rheology).__name__} "
                                    f"with {type(wall).__name__}")
    return inst


def solve(rheology, wall, tube, *, flow_rate=None, pressure_drop=None, coupler="auto",
          outlet_pressure=0.0) -> Solution:
    r"""Solve steady flow of ``rheology`` through ``tube`` with wall ``wall``.

    Exactly one of ``flow_rate`` (flow-controlled) and ``pressure_drop``
    (pressure-controlled) is given, as a float or an array (every entry >= 0).

    Parameters
    ----------
    rheology, wall : model instance, class, or registered name
    tube : Tube
    flow_rate : float or array_like, optional
        Volumetric flow rate q (m^3/s).
    pressure_drop : float or array_like, optional
        Pressure drop p(0) - p(L) (Pa).
    coupler : "auto", registered name, or Coupler instance
        ``"auto"`` takes the cheapest coupler that supports the pair and meets the
        accuracy contract (``closed-form`` where it exists, else ``quadrature``).
    outlet_pressure : float
        Transmural pressure at the outlet, p(L) >= 0 (Pa).

    Returns
    -------
    Solution

    Raises
    ------
    InvalidParameterError
        For any input outside its admissible range.
    NoSteadyStateError
        Beyond the wall's limit pressure or the maximum flow rate.
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure)
    if (flow_rate is None) == (pressure_drop is None):
        raise InvalidParameterError("flow_rate / pressure_drop", "exactly one of the two",
                                    None, "give flow_rate= or pressure_drop=, not both or neither")
    chosen = select_coupler(scene.rheology, scene.wall, coupler)
    runner = checked(chosen)            # a self-checking coupler is re-solved finer (AccuracyWarning)
    if flow_rate is not None:
        q = as_load("flow_rate", flow_rate)
        q_max = _finite_max_flow(chosen, scene, q)
        beyond = (q > 0) & (q >= q_max) if q_max is not None else None
        if beyond is not None and np.any(beyond):
            raise NoSteadyStateError("flow_rate", q_max, q[beyond].flat[0],
                                     "the tube inflates without bound")
        state = _chunked(runner.flow_controlled, scene, q)
        scalar = np.ndim(flow_rate) == 0
    else:
        dp = as_load("pressure_drop", pressure_drop)
        state = _chunked(runner.pressure_controlled, scene, dp)
        scalar = np.ndim(pressure_drop) == 0
    return Solution(scene=scene, coupler=chosen, state=state, scalar=scalar,
                    coupler_name=registry.couplers.name_of(chosen) or type(chosen).__name__)


#: Loads per coupler call: bounds the working memory (a few tens of MB) of any sweep.
CHUNK = 1 << 14


def _chunked(method, scene, load):
    """Run ``method`` on slices of at most CHUNK loads; cost stays linear, memory bounded."""
    if load.size <= CHUNK:
        return method(scene, load)
    flat = load.ravel()
    parts = [method(scene, flat[i:i + CHUNK]) for i in range(0, flat.size, CHUNK)]
    fields = {f.name: np.concatenate([getattr(p, f.name) for p in parts]).reshape(load.shape)
              for f in attrs.fields(State)}
    return State(**fields)


def _finite_max_flow(coupler, scene, q):
    if not math.isfinite(scene.wall.limit_pressure(scene.tb)):     # the rigid wall's included
        return None
    q_max = coupler.max_flow_rate(scene)
    return q_max if math.isfinite(q_max) else None


def max_flow_rate(rheology, wall, tube, *, outlet_pressure=0.0, coupler="auto") -> float:
    r"""The largest flow rate with a steady state (m^3/s); ``inf`` where every flow rate has one.

    Finite only for a wall with a limit pressure (thick or thin-current
    Mooney–Rivlin/neo-Hookean) and a fluid whose :math:`G(q,R)` falls off slowly
    enough in :math:`R`: for a power law, exactly when :math:`n < 1`. Then
    :math:`L\,\phi(q_{max}) = \int_0^\infty s P'(s)/\psi(as)\,du`.
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure)
    return float(select_coupler(scene.rheology, scene.wall, coupler).max_flow_rate(scene))
