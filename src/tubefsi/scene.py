r"""The scene: resolved models, the tube and the boundary state; and what a coupler returns.

A :class:`Scene` is everything a coupler needs except the load: the rheology, the wall,
the tube and the outlet pressure, plus the outlet state derived from them once. Build one
with :func:`make_scene`, which accepts registered names, classes or instances and
validates every argument. A coupler returns a :class:`State`: arrays of one shape.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from .errors import InvalidParameterError, NoSteadyStateError
from .geometry import Tube
from .registry import rheologies as _rheologies
from .registry import walls as _walls
from .rheology.base import Rheology
from .walls.base import WallModel

__all__ = ["Scene", "State", "make_scene", "resolve"]


@attrs.frozen
class State:
    r"""What a coupler returns: arrays of one shape (the loads' shape).

    Attributes
    ----------
    flow_rate : ndarray
        Flow rate q (m^3/s).
    pressure_drop : ndarray
        Pressure drop p(0) - p(L) (Pa).
    inlet_strain : ndarray
        Hoop strain at the inlet, R(0)/a - 1, never formed by subtraction.
    log_stretch : ndarray
        :math:`v = \ln(\lambda_{in}/\lambda_{out})`, the inlet log-stretch relative to the outlet.
    """

    flow_rate: np.ndarray
    pressure_drop: np.ndarray
    inlet_strain: np.ndarray
    log_stretch: np.ndarray


@attrs.frozen(kw_only=True)
class Scene:
    r"""A rheology, a wall, a tube and an outlet pressure: everything but the load.

    Build it with :func:`make_scene` (which validates); the outlet state is derived once:

    Attributes
    ----------
    outlet_strain, outlet_stretch : float
        The hoop strain and stretch at the outlet, under ``outlet_pressure``.
    log_stretch_max : float
        :math:`\ln(\lambda_{max}/\lambda_{out})`, the largest log-stretch the wall admits
        (``inf`` unless it locks or its tube law peaks).
    """

    rheology: Rheology
    wall: WallModel
    tube: Tube
    outlet_pressure: float = 0.0

    outlet_strain: float = attrs.field(init=False)
    outlet_stretch: float = attrs.field(init=False)
    log_stretch_max: float = attrs.field(init=False)

    def __attrs_post_init__(self):
        # the hoop strain at the outlet, once: every J evaluation needs it
        strain = 0.0 if self.outlet_pressure == 0 else float(
            self.wall._strain(np.asarray(self.outlet_pressure), self.tb))
        object.__setattr__(self, "outlet_strain", strain)
        object.__setattr__(self, "outlet_stretch", 1.0 + strain)
        lam_max = float(self.wall._max_stretch(self.tb))
        object.__setattr__(self, "log_stretch_max", math.log(lam_max / (1.0 + strain)))

    @property
    def tb(self) -> float:
        """The reduced thickness t/a of the tube."""
        return self.tube.reduced_thickness


_KINDS = {"rheology": (Rheology, _rheologies), "wall": (WallModel, _walls)}


def resolve(kind: str, value):
    """A model instance from a registered name, a class (built with its defaults) or an instance.

    ``kind`` is ``"rheology"`` or ``"wall"``; anything else raises
    :class:`~tubefsi.InvalidParameterError` naming ``kind``.
    """
    base, registry = _KINDS[kind]
    return _resolve(kind, value, base, registry)


def _resolve(kind, value, base, registry):
    if isinstance(value, str):
        try:
            value = registry[value]
        except KeyError as exc:
            raise InvalidParameterError(kind, "{" + ", ".join(registry) + "}", value) from exc
    if isinstance(value, type) and issubclass(value, base):
        try:
            value = value()
        except TypeError as exc:
            raise InvalidParameterError(kind, f"an instance of {base.__name__}", value,
                                        f"{value.__name__} needs parameters: {exc}") from None
    if not isinstance(value, base):
        raise InvalidParameterError(kind, f"an instance of {base.__name__} or a registered name", value)
    return value


def make_scene(rheology, wall, tube, *, outlet_pressure=0.0) -> Scene:
    """Resolve and validate the models, the tube and the outlet pressure into a :class:`Scene`.

    Raises
    ------
    InvalidParameterError
        For an unknown name, a wrong type or an outlet pressure outside ``[0, inf)``.
    NoSteadyStateError
        If the outlet pressure already reaches the wall's limit pressure.
    """
    rheology = resolve("rheology", rheology)
    wall = resolve("wall", wall)
    if not isinstance(tube, Tube):
        raise InvalidParameterError("tube", "a tubefsi.Tube", tube)
    try:
        p_out = float(outlet_pressure)
    except (TypeError, ValueError):
        raise InvalidParameterError("outlet_pressure", "[0, inf)", outlet_pressure) from None
    if not (math.isfinite(p_out) and p_out >= 0):
        raise InvalidParameterError("outlet_pressure", "[0, inf)", p_out)
    lim = wall.limit_pressure(tube.reduced_thickness)
    if p_out >= lim:
        raise NoSteadyStateError("pressure", lim, p_out, "the outlet pressure already exceeds it")
    return Scene(rheology=rheology, wall=wall, tube=tube, outlet_pressure=p_out)
