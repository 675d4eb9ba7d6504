"""The undeformed tube."""

from __future__ import annotations

import math
from collections.abc import Callable

import attrs
import numpy as np
from numpy.typing import ArrayLike

from .errors import InvalidParameterError
from .fields import positive
from .profiles import Profile, sampled

__all__ = ["Tube"]


@attrs.frozen(kw_only=True)
class Tube:
    r"""An undeformed straight tube, clamped at both ends.

    ``radius`` and ``thickness`` may be functions of the axial position :math:`z` (m, 0 at the
    inlet): a callable, a :class:`~tubefsi.Profile` or a :func:`~tubefsi.sampled` table (a
    tapered or stenosed tube, ``docs/graded.md``); :attr:`graded` is then True and
    :attr:`reduced_thickness` is the profile :math:`t(z)/a(z)`.

    Parameters
    ----------
    radius : float, array or function of z
        Undeformed inner radius :math:`a` (m).
    thickness : float, array or function of z
        Wall thickness :math:`t` (m).
    length : float or array
        Length :math:`L` (m). Lubrication theory assumes :math:`a/L \ll 1`.
    """

    radius: float | ArrayLike | Profile | Callable = positive(unit="m", doc="undeformed inner radius a")
    thickness: float | ArrayLike | Profile | Callable = positive(unit="m", doc="wall thickness t")
    length: float | ArrayLike = positive(unit="m", doc="tube length L", along=False)

    def __attrs_post_init__(self):
        if self.graded:                  # checked along z where the scene evaluates it
            for name in ("radius", "thickness"):
                if isinstance(getattr(self, name), Profile):
                    getattr(self, name).check_span(self.length)
            return
        tb = np.asarray(self.thickness) / np.asarray(self.radius)
        if tb.size and not (tb.min() > 0 and tb.max() < math.inf):   # t/a beyond the doubles (NaN fails both)
            raise InvalidParameterError("thickness", "values with a finite, nonzero t/a", self.thickness,
                                        f"t/a = {np.ravel(tb)[np.argmin(np.isfinite(tb) & (tb > 0))]!r} with radius "
                                        f"{self.radius!r}")

    @classmethod
    def tapered(cls, *, length: float, radius: float, outlet_radius: float, thickness: float,
                outlet_thickness: float | None = None) -> Tube:
        r"""A linearly tapered tube: the radius runs from ``radius`` at :math:`z = 0` to
        ``outlet_radius`` at :math:`z = L` = ``length``,

        .. math::  a(z) = a_0 + (a_L - a_0)\,z/L, \qquad t(z) = t_0 + (t_L - t_0)\,z/L,

        and the thickness from ``thickness`` to ``outlet_thickness`` (default: the same ``t/a`` as
        at the inlet, :math:`t_L = t_0 a_L/a_0`). Each is a linear :func:`~tubefsi.sampled` table
        over :math:`[0, L]` (``docs/graded.md``); equal ends give a uniform tube. All numbers (m,
        > 0); the command line's ``outlet_radius=..``."""
        values = {}
        for name, value in (("length", length), ("radius", radius), ("outlet_radius", outlet_radius),
                            ("thickness", thickness), ("outlet_thickness", outlet_thickness)):
            if name == "outlet_thickness" and value is None:
                value = values["thickness"] * values["outlet_radius"] / values["radius"]
            try:
                x = float(value)
            except (TypeError, ValueError):
                x = math.nan
            if np.ndim(value) != 0 or not (0 < x < math.inf):
                raise InvalidParameterError(name, "a number in (0, inf) m", value)
            values[name] = x
        ends = [0.0, values["length"]]
        fields = {}
        for name in ("radius", "thickness"):
            inlet, outlet = values[name], values[f"outlet_{name}"]
            fields[name] = inlet if inlet == outlet else sampled(ends, [inlet, outlet], kind="linear")
        return cls(length=values["length"], **fields)

    @property
    def graded(self) -> bool:
        """Whether the radius or the thickness is a function of z (a :class:`~tubefsi.Profile`)."""
        return isinstance(self.radius, Profile) or isinstance(self.thickness, Profile)

    def at(self, z):
        """The radius and thickness at the positions ``z`` (m): ``(a(z), t(z))``, validated."""
        a, t = (v(z) if isinstance(v, Profile) else v for v in (self.radius, self.thickness))
        return a, t

    @property
    def reduced_thickness(self) -> float:
        r"""Thickness ratio :math:`\bar t = t/a` (dimensionless)."""
        return self.thickness / self.radius

    @property
    def slenderness(self) -> float:
        r""":math:`\epsilon = a/L`; lubrication theory needs it small."""
        return self.radius / self.length
