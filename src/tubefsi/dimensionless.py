r"""The chapter's dimensionless groups, and physical scenes built from them.

Scales (power-law fluid of consistency :math:`m` and index :math:`n`, tube of inner
radius :math:`a`, thickness :math:`t` and length :math:`L`):

================================  ====================================================================
group                             definition
================================  ====================================================================
pressure scale, flow-controlled   :math:`\mathcal P_c = [q/(\pi a^2)]^n\,m L / a^{n+1}`
pressure scale, pressure-control  :math:`\mathcal P_c = \Delta p`
axial velocity scale              :math:`\mathcal V_z = [a^{n+1}\mathcal P_c/(m L)]^{1/n}`
dimensionless flow rate           :math:`\bar q = q/(\mathcal V_z\,\pi a^2)`
                                  (identically 1 under the flow-controlled scale)
reduced thickness                 :math:`\bar t = t/a`
hyperelastic FSI parameter        :math:`\gamma = \mathcal P_c/(2(c_1+c_2)\,\bar t) = \mathcal P_c/(\mu\,\bar t)`
linear FSI parameter              :math:`\beta = \mathcal P_c/(E\,\bar t)`
================================  ====================================================================

:math:`2(c_1+c_2) = \mu` is the small-strain shear modulus of a Mooney–Rivlin wall; for any
wall :math:`\gamma` uses the shear modulus and :math:`\beta` the Young's modulus. An
incompressible wall has :math:`E = 2\mu(1+\nu) = 3\mu`, hence

.. math:: \gamma = 3\beta \qquad(\text{not } \gamma = \beta/3 \text{ as the chapter prints}),

and in general :math:`\gamma = 2(1+\nu)\beta`. With these scales the lubrication law of the
chapter reads :math:`d\bar p/d\bar z = -2[(3+1/n)\bar q]^n\bar R^{-(3n+1)}`, the thin
reference-thickness tube law :math:`\gamma\bar p = \lambda - \lambda^{-3}` and the linear one
:math:`\lambda = 1 + (1-\nu/2)\beta\bar p`.

* :func:`groups` computes every group of a physical scene (:class:`Groups`).
* :func:`scene` goes the other way: a physical scene (:class:`DimensionlessScene`) from
  :math:`(n, \gamma \text{ or } \beta, \bar t, \bar q)`; its ``pressure_drop()`` is
  :math:`\Delta\bar p = \Delta p/\mathcal P_c`, independent of the physical values chosen.

The chapter's equations as printed, and its figures, are in :mod:`tubefsi.chapter`; the
printed relation :math:`\gamma = \beta/3` is item 1 of ``docs/verification.md``, section
"The chapter's printed inconsistencies".
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ._keywords import construct
from .numerics.kernels import as_output as _out
from ._validation import nonnegative_array as _nonnegative_array
from ._validation import positive_scalar as _positive
from .errors import InvalidParameterError
from .geometry import Tube
from .registry import rheologies as _rheologies
from .registry import walls as _walls
from .rheology.base import Rheology
from .scene import resolve
from .solve import max_flow_rate, solve
from .walls.base import WallModel
from .walls.hyperelastic import HyperelasticWall
from .walls.mooney_rivlin import MooneyRivlin

__all__ = [
    "Groups", "groups", "pressure_scale", "velocity_scale", "dimensionless_flow_rate",
    "gamma", "beta", "DimensionlessScene", "scene",
]


# ------------------------------------------------------------------------------- checks
def _power_law(rheology):
    """``(n, m)`` of a power-law (or Newtonian) fluid; the chapter's scales need one."""
    if isinstance(rheology, str):
        rheology = _rheologies[rheology]
    n, m = getattr(rheology, "index", None), getattr(rheology, "consistency", None)
    if not isinstance(rheology, Rheology) or not isinstance(n, (int, float)) or not isinstance(m, (int, float)):
        raise InvalidParameterError("rheology", "a power-law or Newtonian fluid instance", rheology,
                                    "the chapter's scales are defined for tau = m |g|^(n-1) g")
    return float(n), float(m)


def _tube(tube):
    if not isinstance(tube, Tube):
        raise InvalidParameterError("tube", "a tubefsi.Tube", tube)
    return tube


# ------------------------------------------------------------------------------- scales
def pressure_scale(rheology, tube, *, flow_rate=None, pressure_drop=None):
    r"""The chapter's pressure scale :math:`\mathcal P_c` (Pa).

    Flow-controlled (``flow_rate`` q): :math:`[q/(\pi a^2)]^n m L/a^{n+1}`.
    Pressure-controlled (``pressure_drop``): :math:`\Delta p` itself. Give exactly one.
    """
    if (flow_rate is None) == (pressure_drop is None):
        raise InvalidParameterError("flow_rate / pressure_drop", "exactly one of the two", None)
    return _pressure_scale(rheology, _tube(tube), flow_rate, pressure_drop)


def _pressure_scale(rheology, tube, flow_rate, pressure_drop):
    n, m = _power_law(rheology)
    if pressure_drop is not None:
        dp = _nonnegative_array("pressure_drop", pressure_drop)
        return _out(dp, np.ndim(pressure_drop) == 0)
    q = _nonnegative_array("flow_rate", flow_rate)
    a, L = tube.radius, tube.length
    return _out((q / (math.pi * a * a)) ** n * m * L / a ** (n + 1.0), np.ndim(flow_rate) == 0)


def velocity_scale(rheology, tube, pressure_scale):
    r"""Axial velocity scale :math:`\mathcal V_z = [a^{n+1}\mathcal P_c/(mL)]^{1/n}` (m/s)."""
    n, m = _power_law(rheology)
    tube = _tube(tube)
    pc = _nonnegative_array("pressure_scale", pressure_scale)
    return _out((tube.radius ** (n + 1.0) * pc / (m * tube.length)) ** (1.0 / n), np.ndim(pressure_scale) == 0)


def dimensionless_flow_rate(rheology, tube, flow_rate, pressure_scale):
    r""":math:`\bar q = q/(\mathcal V_z\,\pi a^2)` for the pressure scale ``pressure_scale``."""
    q = _nonnegative_array("flow_rate", flow_rate)
    vz = velocity_scale(rheology, tube, _positive("pressure_scale", pressure_scale)) \
        if np.ndim(pressure_scale) == 0 else velocity_scale(rheology, tube, pressure_scale)
    a = tube.radius
    return _out(q / (np.asarray(vz) * math.pi * a * a), np.ndim(flow_rate) == 0 and np.ndim(pressure_scale) == 0)


def _moduli(wall):
    """(shear modulus, Young's modulus) of a wall at small strain; inf for the rigid wall."""
    if not isinstance(wall, WallModel):
        raise InvalidParameterError("wall", "a wall model instance", wall)
    if wall.is_rigid:
        return math.inf, math.inf
    if hasattr(wall, "youngs_modulus") and hasattr(wall, "poisson_ratio"):
        e, nu = float(wall.youngs_modulus), float(wall.poisson_ratio)
        return e / (2.0 * (1.0 + nu)), e
    if isinstance(wall, HyperelasticWall):
        mu = getattr(wall, "shear_modulus", None)
        if not isinstance(mu, (int, float)):
            # dW = mu (lam - lam^-3) + O((lam-1)^2) for every material: mu = dW''(1)/4
            mu = float(wall._d2W(np.asarray(1.0))) / 4.0
        return float(mu), 3.0 * float(mu)           # incompressible: E = 2 mu (1 + 1/2)
    raise InvalidParameterError("wall", "a hyperelastic, linear or rigid wall", wall,
                                "gamma and beta need a shear and a Young's modulus")


def gamma(wall, tube, pressure_scale):
    r"""Hyperelastic FSI parameter :math:`\gamma = \mathcal P_c/(2(c_1+c_2)\bar t) = \mathcal P_c/(\mu\bar t)`.

    For a linear wall :math:`\mu = E/(2(1+\nu))`; 0 for the rigid wall.
    """
    mu, _ = _moduli(wall)
    pc = _nonnegative_array("pressure_scale", pressure_scale)
    return _out(pc / (mu * _tube(tube).reduced_thickness), np.ndim(pressure_scale) == 0)


def beta(wall, tube, pressure_scale):
    r"""Linear FSI parameter :math:`\beta = \mathcal P_c/(E\bar t)`; :math:`E = 3\mu` for a hyperelastic wall."""
    _, e = _moduli(wall)
    pc = _nonnegative_array("pressure_scale", pressure_scale)
    return _out(pc / (e * _tube(tube).reduced_thickness), np.ndim(pressure_scale) == 0)


@attrs.frozen(kw_only=True)
class Groups:
    r"""The chapter's groups of one scene (floats, or arrays for an array of loads)."""

    control: str                 #: "flow", "pressure" or "reference" (an explicit scale)
    index: float                 #: power-law index n
    reduced_thickness: float     #: t/a
    pressure_scale: object       #: P_c (Pa)
    velocity_scale: object       #: V_z (m/s)
    qbar: object                 #: q / (V_z pi a^2)
    gamma: object                #: P_c / (2 (c1 + c2) t/a)
    beta: object                 #: P_c / (E t/a)


def groups(rheology, wall, tube, *, flow_rate=None, pressure_drop=None, pressure_scale=None) -> Groups:
    r"""The chapter's dimensionless groups of a physical scene.

    * ``flow_rate`` only: the flow-controlled scale (:math:`\bar q = 1` by construction).
    * ``pressure_drop`` (and optionally ``flow_rate``): :math:`\mathcal P_c = \Delta p`;
      without ``flow_rate`` the flow rate is solved for (``tubefsi.solve``) to give :math:`\bar q`.
    * ``pressure_scale``: a fixed reference scale, as in the chapter's figures, where
      :math:`\bar q` varies along a curve at fixed :math:`\gamma`, :math:`\beta`.

    ``rheology`` must be a power-law or Newtonian fluid; ``wall`` a hyperelastic, linear or
    rigid wall (instances or registered names).
    """
    wall = resolve("wall", wall)
    rheology = resolve("rheology", rheology)
    n, _ = _power_law(rheology)
    tube = _tube(tube)
    if pressure_scale is not None:
        control = "reference"
        pc = _positive("pressure_scale", pressure_scale)
        if flow_rate is None:
            raise InvalidParameterError("flow_rate", "[0, inf)", None, "a reference scale needs the flow rate")
    elif pressure_drop is not None:
        control = "pressure"
        pc = _pressure_scale(rheology, tube, None, pressure_drop)
        if flow_rate is None:
            flow_rate = solve(rheology, wall, tube, pressure_drop=pressure_drop).flow_rate
    elif flow_rate is not None:
        control = "flow"
        pc = _pressure_scale(rheology, tube, flow_rate, None)
    else:
        raise InvalidParameterError("flow_rate / pressure_drop / pressure_scale", "at least one load", None)
    vz = velocity_scale(rheology, tube, pc)
    q = _nonnegative_array("flow_rate", flow_rate)
    with np.errstate(invalid="ignore", divide="ignore"):
        qbar = np.where(np.asarray(vz) > 0, q / (np.asarray(vz) * math.pi * tube.radius ** 2), 0.0)
    scalar = np.ndim(qbar) == 0 and np.ndim(pc) == 0
    return Groups(control=control, index=n, reduced_thickness=tube.reduced_thickness,
                  pressure_scale=_out(pc, np.ndim(pc) == 0), velocity_scale=_out(vz, np.ndim(vz) == 0),
                  qbar=_out(qbar, scalar), gamma=gamma(wall, tube, pc), beta=beta(wall, tube, pc))


# ------------------------------------------------------------------------------- reverse
@attrs.frozen(kw_only=True)
class DimensionlessScene:
    r"""A physical scene built from dimensionless groups by :func:`scene`.

    ``flow_rate`` is the physical q (m^3/s) for each requested :math:`\bar q`;
    :meth:`pressure_drop` returns :math:`\Delta\bar p = \Delta p/\mathcal P_c`.
    """

    rheology: object
    wall: WallModel
    tube: Tube
    pressure_scale: float
    qbar: object
    flow_rate: object

    @property
    def groups(self) -> Groups:
        """The groups of this scene under its reference pressure scale (round trip)."""
        return groups(self.rheology, self.wall, self.tube, flow_rate=self.flow_rate,
                      pressure_scale=self.pressure_scale)

    def max_qbar(self, **kwargs) -> float:
        r"""Largest :math:`\bar q` with a steady state (``inf`` where every flow rate has one)."""
        qmax = max_flow_rate(self.rheology, self.wall, self.tube, **kwargs)
        vz = velocity_scale(self.rheology, self.tube, self.pressure_scale)
        return qmax / (vz * math.pi * self.tube.radius ** 2)

    def solve(self, **kwargs):
        """``tubefsi.solve`` of this scene at its flow rates (keyword arguments passed on)."""
        return solve(self.rheology, self.wall, self.tube, flow_rate=self.flow_rate, **kwargs)

    def pressure_drop(self, **kwargs):
        r"""Dimensionless pressure drop :math:`\Delta\bar p = \Delta p/\mathcal P_c`."""
        dp = self.solve(**kwargs).pressure_drop
        return _out(np.asarray(dp) / self.pressure_scale, np.ndim(self.qbar) == 0)


def _wall_class(wall):
    """``(class, parameters)`` of a wall given as a registered name, a class or an instance."""
    if isinstance(wall, str):
        try:
            return _walls[wall], {}
        except KeyError:
            raise InvalidParameterError("wall", "{" + ", ".join(_walls) + "}", wall) from None
    if isinstance(wall, type) and issubclass(wall, WallModel):
        return wall, {}
    if isinstance(wall, WallModel):
        return type(wall), (attrs.asdict(wall, recurse=False) if attrs.has(type(wall)) else {})
    raise InvalidParameterError("wall", "a registered wall name, class or instance", wall)


def _scaled(value, factor):
    if isinstance(value, tuple):
        return tuple(v * factor for v in value)
    return value * factor


def _build_wall(cls, params, *, gamma, beta, pressure_scale, tb):
    """``cls`` with its modulus set so that the wall has the FSI parameter ``gamma`` or ``beta``.

    Linear walls get ``E`` (with ``nu`` from ``params``, default 1/2). A hyperelastic wall is
    built from ``params`` (a template: ``shear_modulus`` and Mooney–Rivlin ``c1`` default to
    1) and every field in Pa (its moduli) is scaled by one factor: the small-strain shear
    modulus becomes the target and the shape of the law (``c2/(c1+c2)``, Gent's ``J_m``,
    Ogden's exponents and modulus ratios, ...) is kept.
    """
    if cls.is_rigid:
        if gamma is not None or beta is not None:
            raise InvalidParameterError("gamma / beta", "none for the rigid wall (its FSI parameters are 0)",
                                        gamma if gamma is not None else beta)
        return construct(cls, params)            # (wall_options: a wrong keyword is a KeywordError)
    if gamma is None and beta is None:
        raise InvalidParameterError("gamma / beta", "exactly one of the two", None)
    names = {f.name for f in attrs.fields(cls)} if attrs.has(cls) else set()
    if {"youngs_modulus", "poisson_ratio"} <= names:
        nu = float(params.get("poisson_ratio", 0.5))
        e = pressure_scale / (beta * tb) if beta is not None else 2.0 * (1.0 + nu) * pressure_scale / (gamma * tb)
        return construct(cls, {**params, "youngs_modulus": e, "poisson_ratio": nu})
    if not issubclass(cls, HyperelasticWall):
        raise InvalidParameterError("wall", "a hyperelastic, linear or rigid wall", cls.__name__)
    mu = pressure_scale / (gamma * tb) if gamma is not None else pressure_scale / (3.0 * beta * tb)
    params = dict(params)
    if "shear_modulus" in names:
        params.setdefault("shear_modulus", 1.0)
    if issubclass(cls, MooneyRivlin) and not {"c1", "c2"} <= params.keys():
        params.setdefault("c1", 1.0)
        params.setdefault("c2", 0.0)
    try:
        template = construct(cls, params)
    except TypeError as exc:
        raise InvalidParameterError("wall_options", f"the parameters of {cls.__name__} (a template whose "
                                    "moduli are rescaled)", params, str(exc)) from None
    factor = mu / _moduli(template)[0]
    moduli = {f.name: _scaled(getattr(template, f.name), factor) for f in attrs.fields(cls)
              if f.metadata.get("unit") == "Pa"}
    if "shear_modulus" in names:
        moduli["shear_modulus"] = mu
    built = attrs.evolve(template, **moduli)
    if not math.isclose(_moduli(built)[0], mu, rel_tol=1e-9):
        raise InvalidParameterError("wall", "a wall whose moduli are attrs fields with metadata unit 'Pa'",
                                    cls.__name__, "its small-strain shear modulus cannot be set")
    return built


def scene(*, index, reduced_thickness, qbar, gamma=None, beta=None, wall="thick-mooney-rivlin",
          wall_options=None, pressure_scale=1.0e3, radius=1.0e-4, length=1.0e-2,
          consistency=1.0) -> DimensionlessScene:
    r"""A physical scene with the chapter's groups :math:`(n, \gamma \text{ or } \beta, \bar t, \bar q)`.

    Parameters
    ----------
    index : float
        Power-law index :math:`n` (the fluid is ``power-law`` with ``consistency``).
    reduced_thickness : float
        :math:`\bar t = t/a`.
    qbar : float or array_like
        Dimensionless flow rate(s) :math:`\bar q` under the reference ``pressure_scale``.
    gamma, beta : float
        Exactly one (none for the rigid wall): :math:`\gamma = \mathcal P_c/(\mu\bar t)` or
        :math:`\beta = \mathcal P_c/(E\bar t)`. The wall's modulus is set from it
        (:math:`E = 2\mu(1+\nu)`, i.e. :math:`E = 3\mu` for a hyperelastic wall:
        :math:`\gamma = 3\beta`).
    wall : str, wall class or instance
        A linear wall (``poisson_ratio`` from the instance or ``wall_options``, else 1/2), the
        rigid wall, or any hyperelastic wall. A hyperelastic instance (or ``wall_options``) is
        a template: its moduli (fields in Pa) are rescaled together, so the shape of its law
        is kept — e.g. Mooney–Rivlin's ``c2/(c1+c2)`` (``c2 = 0`` by default).
    wall_options : dict
        Wall parameters, e.g. ``{"thickness_convention": "current"}``.
    pressure_scale, radius, length, consistency : float
        The physical values (SI). :math:`\Delta\bar p` does not depend on them.
    """
    n = _positive("index", index)
    tb = _positive("reduced_thickness", reduced_thickness)
    q = _nonnegative_array("qbar", qbar)
    pc = _positive("pressure_scale", pressure_scale)
    if gamma is not None and beta is not None:
        raise InvalidParameterError("gamma / beta", "exactly one of the two", None)
    g = None if gamma is None else _positive("gamma", gamma)
    b = None if beta is None else _positive("beta", beta)
    cls, params = _wall_class(wall)
    wall_obj = _build_wall(cls, {**params, **(wall_options or {})}, gamma=g, beta=b, pressure_scale=pc, tb=tb)
    a = _positive("radius", radius)
    tube = Tube(radius=a, thickness=tb * a, length=_positive("length", length))
    fluid = _rheologies["power-law"](consistency=_positive("consistency", consistency), index=n)
    flow = q * velocity_scale(fluid, tube, pc) * math.pi * a * a
    scalar = np.ndim(qbar) == 0
    return DimensionlessScene(rheology=fluid, wall=wall_obj, tube=tube, pressure_scale=pc,
                              qbar=_out(q, scalar), flow_rate=_out(flow, scalar))
