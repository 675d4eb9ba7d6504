r"""The chapter's dimensionless groups, scenes built from them, and its two figures.

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

.. math:: \gamma = 3\beta \qquad(\text{not } \gamma = \beta/3 \text{ as the chapter prints; DESIGN.md §2.6}),

and in general :math:`\gamma = 2(1+\nu)\beta`. With these scales the lubrication law of the
chapter reads :math:`d\bar p/d\bar z = -2[(3+1/n)\bar q]^n\bar R^{-(3n+1)}`, the thin
reference-thickness tube law :math:`\gamma\bar p = \lambda - \lambda^{-3}` and the linear one
:math:`\lambda = 1 + (1-\nu/2)\beta\bar p`.

* :func:`groups` computes every group of a physical scene (:class:`Groups`).
* :func:`scene` goes the other way: a physical scene (:class:`DimensionlessScene`) from
  :math:`(n, \gamma \text{ or } \beta, \bar t, \bar q)`; its ``pressure_drop()`` is
  :math:`\Delta\bar p = \Delta p/\mathcal P_c`, independent of the physical values chosen.
* The ``printed_*`` functions evaluate the chapter's equations exactly as printed (for
  reproducing its figures, not for use); :func:`linear_pressure_drop` its (correct) linear
  closed forms; :func:`reproduce_chapter` writes both figures as printed and consistent.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import attrs
import numpy as np
from scipy import integrate
from scipy.optimize import elementwise

from .errors import ConvergenceError, InvalidParameterError
from .geometry import Tube
from .walls.base import WallModel
from .walls.hyperelastic import HyperelasticWall

__all__ = [
    "Groups", "groups", "pressure_scale", "velocity_scale", "dimensionless_flow_rate",
    "gamma", "beta", "DimensionlessScene", "scene",
    "printed_thin_pressure_drop", "thin_reference_pressure_drop", "printed_thick_pressure_drop",
    "linear_pressure_drop", "CHAPTER_PARAMETERS", "chapter_curves", "reproduce_chapter",
]


# ------------------------------------------------------------------------------- checks
def _positive(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, "(0, inf)", value) from None
    if not (math.isfinite(v) and v > 0):
        raise InvalidParameterError(name, "(0, inf)", v)
    return v


def _nonnegative_array(name, value):
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, "[0, inf)", value) from None
    if not np.all(np.isfinite(a) & (a >= 0)):
        raise InvalidParameterError(name, "[0, inf)", a[~(np.isfinite(a) & (a >= 0))].flat[0]
                                    if a.ndim else a.item())
    return a


def _out(a, scalar):
    a = np.asarray(a, dtype=float)
    return float(a) if scalar else a


def _power_law(rheology):
    """``(n, m)`` of a power-law (or Newtonian) fluid; the chapter's scales need one."""
    from . import registry
    from .rheology.base import Rheology

    if isinstance(rheology, str):
        rheology = registry.rheologies[rheology]
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
    from . import registry
    from .rheology.base import Rheology
    from .solve import _resolve

    wall = _resolve("wall", wall, WallModel, registry.walls)
    rheology = _resolve("rheology", rheology, Rheology, registry.rheologies)
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
            from .solve import solve

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
        from .solve import max_flow_rate

        qmax = max_flow_rate(self.rheology, self.wall, self.tube, **kwargs)
        vz = velocity_scale(self.rheology, self.tube, self.pressure_scale)
        return qmax / (vz * math.pi * self.tube.radius ** 2)

    def solve(self, **kwargs):
        """``tubefsi.solve`` of this scene at its flow rates (keyword arguments passed on)."""
        from .solve import solve

        return solve(self.rheology, self.wall, self.tube, flow_rate=self.flow_rate, **kwargs)

    def pressure_drop(self, **kwargs):
        r"""Dimensionless pressure drop :math:`\Delta\bar p = \Delta p/\mathcal P_c`."""
        dp = self.solve(**kwargs).pressure_drop
        return _out(np.asarray(dp) / self.pressure_scale, np.ndim(self.qbar) == 0)


def _wall_class(wall):
    """``(class, parameters)`` of a wall given as a registered name, a class or an instance."""
    from . import registry

    if isinstance(wall, str):
        try:
            return registry.walls[wall], {}
        except KeyError:
            raise InvalidParameterError("wall", "{" + ", ".join(registry.walls) + "}", wall) from None
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
    from .walls.mooney_rivlin import MooneyRivlin

    if cls.is_rigid:
        if gamma is not None or beta is not None:
            raise InvalidParameterError("gamma / beta", "none for the rigid wall (its FSI parameters are 0)",
                                        gamma if gamma is not None else beta)
        return cls(**params)
    if gamma is None and beta is None:
        raise InvalidParameterError("gamma / beta", "exactly one of the two", None)
    names = {f.name for f in attrs.fields(cls)} if attrs.has(cls) else set()
    if {"youngs_modulus", "poisson_ratio"} <= names:
        nu = float(params.get("poisson_ratio", 0.5))
        e = pressure_scale / (beta * tb) if beta is not None else 2.0 * (1.0 + nu) * pressure_scale / (gamma * tb)
        return cls(**{**params, "youngs_modulus": e, "poisson_ratio": nu})
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
        template = cls(**params)
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
    from . import registry

    fluid = registry.rheologies["power-law"](consistency=_positive("consistency", consistency), index=n)
    flow = q * velocity_scale(fluid, tube, pc) * math.pi * a * a
    scalar = np.ndim(qbar) == 0
    return DimensionlessScene(rheology=fluid, wall=wall_obj, tube=tube, pressure_scale=pc,
                              qbar=_out(q, scalar), flow_rate=_out(flow, scalar))


# ------------------------------------------------------------------------------- the chapter's forms
def _flow_factor(n, qbar):
    r""":math:`X = [(3+1/n)\bar q]^n`: the lubrication law is :math:`d\bar p/d\bar z = -2X\bar R^{-(3n+1)}`."""
    return ((3.0 + 1.0 / n) * np.asarray(qbar, dtype=float)) ** n


def _pow_ratio(k, log_lam):
    r""":math:`(\lambda^k - 1)/k` from :math:`\ln\lambda`, stable, :math:`\ln\lambda` at k = 0."""
    return log_lam if k == 0 else np.expm1(k * log_lam) / k


def _solve_strain(func, target):
    """Strain e >= 0 with func(e) = target (func increasing from 0), vectorized."""
    target = np.asarray(target, dtype=float)

    def f(e, t):
        return func(e) - t

    safe = np.where(target > 0, target, 1.0)
    br = elementwise.bracket_root(f, np.zeros_like(safe), np.full_like(safe, 1e-3), xmin=0.0, args=(safe,))
    res = elementwise.find_root(f, br.bracket, args=(safe,),
                                tolerances=dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300))
    if not np.all(br.success | (target == 0)):
        raise ConvergenceError("the thin closed form has no root for some flow rate (target too large)")
    return np.where(target > 0, res.x, 0.0)


def _thin_reference_pressure(e, gam):
    """gamma p = lam - lam^-3 = ((1+e)^4 - 1)/(1+e)^3, without cancellation."""
    return e * (4.0 + e * (6.0 + e * (4.0 + e))) / (1.0 + e) ** 3 / gam


def printed_thin_pressure_drop(index, gamma, qbar):
    r"""Thin-wall :math:`\Delta\bar p(\bar q)` from the chapter's closed form **as printed**.

    Eq. (flowrate_deflection_nondim):
    :math:`2\gamma X(1-\bar z) = \frac{\lambda^{3n+2}}{3n+2} + \frac{\lambda^{3n-2}}{3n-2} - \frac{6n}{(3n+2)(3n-2)}`
    (the second term lacks the factor 3 of :math:`d(\lambda-\lambda^{-3})/d\lambda = 1 + 3\lambda^{-4}`),
    then :math:`\Delta\bar p = (\lambda_0 - \lambda_0^{-3})/\gamma`.
    """
    return _thin_closed_form(index, gamma, qbar, second=1.0)


def thin_reference_pressure_drop(index, gamma, qbar):
    r"""The same with the factor 3 restored: the closed form that follows from the chapter's
    thin tube law :math:`\gamma\bar p = \lambda - \lambda^{-3}` and its flow law,
    :math:`2\gamma X = \frac{\lambda^{3n+2}-1}{3n+2} + 3\,\frac{\lambda^{3n-2}-1}{3n-2}`."""
    return _thin_closed_form(index, gamma, qbar, second=3.0)


def _thin_closed_form(index, gam, qbar, *, second):
    n, gam = _positive("index", index), _positive("gamma", gam)
    q = _nonnegative_array("qbar", qbar)
    target = 2.0 * gam * _flow_factor(n, q)

    def lhs(e):
        ln = np.log1p(e)
        return _pow_ratio(3 * n + 2, ln) + second * _pow_ratio(3 * n - 2, ln)

    e0 = _solve_strain(lhs, target)
    return _out(_thin_reference_pressure(e0, gam), np.ndim(qbar) == 0)


def _thick_law(lam, tb, strain=None):
    r""":math:`f(x_o) - f(x_i) = p/(c_1+c_2)`, :math:`f(x) = x + \ln x` (eq. pressure_deformation_thick), stable."""
    b = (1.0 + tb) ** 2
    d = b - 1.0
    e = lam - 1.0 if strain is None else strain
    x = e * (2.0 + e)
    return np.log1p(x * d / (b + x)) + x * d / ((1.0 + x) * (b + x))


def _thick_brace(u, tb):
    r"""The brace :math:`B(\bar u)` of eq. (non_dim_flow_rate_coupled_thick), as printed.

    It equals :math:`-P'(\lambda)/(c_1+c_2)` (:func:`_thick_slope`), but its four terms of
    size :math:`2/\lambda` cancel to :math:`O(\lambda^{-5})`: use it for moderate strains only.
    """
    b = (1.0 + tb) ** 2
    lam = 1.0 + u
    den = b + u * u + 2.0 * u
    return 2.0 * b * lam / den**2 + 2.0 * lam / den - 2.0 / lam - 2.0 / lam**3


def _thick_slope(lam, tb):
    r""":math:`-B = d[f(x_o) - f(x_i)]/d\lambda = 2\lambda d\,[\lambda^2(d+2) + d]/[\lambda^4(\lambda^2+d)^2]`,
    :math:`d = (1+\bar t)^2 - 1`: the printed brace without its cancellation."""
    d = tb * (2.0 + tb)
    lam2 = lam * lam
    return 2.0 * lam * d * (lam2 * (d + 2.0) + d) / (lam2 * lam2 * (lam2 + d) ** 2)


def printed_thick_pressure_drop(index, gamma, qbar, reduced_thickness, *, factor=1.0, max_stretch=1e6):
    r"""Thick-wall :math:`\Delta\bar p(\bar q)` from the chapter's deflection ODE **as printed**.

    Eq. (non_dim_flow_rate_coupled_thick): :math:`B(\bar u)\,d\bar u/d\bar z =
    \text{factor}\cdot\bar t\gamma X(1+\bar u)^{-(1+3n)}`, :math:`\bar u(1) = 0`, then
    :math:`2\bar t\gamma\Delta\bar p = f(x_o) - f(x_i)` at :math:`\bar u(0)`
    (eq. deflection_pressure_thick_nondim). The chapter prints ``factor = 1``; the thick tube
    law and the flow law give ``factor = 4``.

    The ODE is separable: :math:`\int_0^{\bar u(0)} (-B)(1+\bar u)^{1+3n}\,d\bar u = \text{factor}
    \cdot\bar t\gamma X`. The left side is integrated once per curve (in :math:`\ln\lambda`,
    ``solve_ivp`` DOP853, rtol 1e-12, with :math:`B` in its cancellation-free form), then
    inverted per point; this solves the printed equation far more accurately than the
    chapter's ``odeint`` at default tolerances. Flow rates the ODE cannot reach (for
    ``n < 1`` the integral converges as :math:`\bar u\to\infty`) give ``nan``.
    """
    n, gam = _positive("index", index), _positive("gamma", gamma)
    tb = _positive("reduced_thickness", reduced_thickness)
    q = _nonnegative_array("qbar", qbar)
    target = factor * tb * gam * _flow_factor(n, q)

    def rhs(v, y):                                   # v = ln(lambda); du = lambda dv
        lam = np.exp(v)
        return [_thick_slope(lam, tb) * lam ** (2.0 + 3.0 * n)]

    sol = integrate.solve_ivp(rhs, (0.0, math.log(max_stretch)), [0.0], method="DOP853", rtol=1e-12,
                              atol=1e-15, dense_output=True)
    total = sol.y[0, -1]

    def reach(v, t):
        return sol.sol(v)[0] - t

    flat = np.ravel(target)
    inside = (flat > 0) & (flat < total)
    v0 = np.full(flat.shape, np.nan)
    v0[flat == 0] = 0.0
    if np.any(inside):
        hi = np.full(int(inside.sum()), float(sol.t[-1]))
        res = elementwise.find_root(reach, (np.zeros_like(hi), hi), args=(flat[inside],),
                                    tolerances=dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300))
        v0[inside] = res.x
    dp = _thick_law(np.exp(v0), tb, strain=np.expm1(v0)) / (2.0 * tb * gam)
    return _out(dp.reshape(np.shape(target)), np.ndim(qbar) == 0)


def linear_pressure_drop(index, beta, qbar, *, reduced_thickness=None, poisson_ratio=0.5):
    r"""Linear-wall :math:`\Delta\bar p(\bar q)`: the chapter's eq. (q-dp-linear-elastic) (thin,
    ``reduced_thickness=None``, :math:`K = 1-\nu/2`) or eq. (q-dp-linear-elastic-thick)
    (:math:`K = [(1+\bar t)^2(1+\nu) + 1 - 2\nu]/(2+\bar t)`):
    :math:`\Delta\bar p = \frac{1}{K\beta}\left(\{1 + 2(2+3n)K\beta X\}^{1/(2+3n)} - 1\right)`.
    Both follow from the linear tube laws; tubefsi's ``thin-linear``/``thick-linear`` agree."""
    n, b = _positive("index", index), _positive("beta", beta)
    q = _nonnegative_array("qbar", qbar)
    nu = float(poisson_ratio)
    if reduced_thickness is None:
        k = 1.0 - 0.5 * nu
    else:
        tb = _positive("reduced_thickness", reduced_thickness)
        k = ((1.0 + tb) ** 2 * (1.0 + nu) + (1.0 - 2.0 * nu)) / (2.0 + tb)
    kb = k * b
    x = _flow_factor(n, q)
    dp = np.expm1(np.log1p(2.0 * (2.0 + 3.0 * n) * kb * x) / (2.0 + 3.0 * n)) / kb
    return _out(dp, np.ndim(qbar) == 0)


# ------------------------------------------------------------------------------- the figures
#: The parameters of the reproduced figures (the chapter prints none; these are in its ranges).
CHAPTER_PARAMETERS = {
    "indices": (1.0, 0.7),               # panels (a) Newtonian, (b) shear-thinning
    "betas": (0.5, 1.0, 2.0),            # the curve labels, "beta (= 3 gamma)" in the chapter
    "qbar": (0.0, 1.0),                  # flow-rate axis
    "points": 201,
    "thick_reduced_thickness": 0.3,
    "poisson_ratio": 0.5,
}


def chapter_curves(figure, variant, *, points=None, parameters=None):
    r"""The curves of one reproduced figure as a list of dicts (one per curve).

    ``figure``: ``"thin"`` or ``"thick"``; ``variant``: ``"printed"`` (hyperelastic curve at
    :math:`\gamma = \beta/3` from the printed closed form / ODE, as the chapter labels them) or
    ``"consistent"`` (``tubefsi.solve`` of the physical scene at :math:`\gamma = 3\beta`, i.e. the
    same small-strain Young's modulus as the dashed linear curve). Each dict holds ``n``,
    ``beta`` (the label), ``gamma`` (used), ``wall`` (``"hyperelastic"``/``"linear"``), ``qbar``,
    ``dpbar`` (``nan`` where no steady state exists) and ``qbar_max``. Thin walls use the
    chapter's reference-thickness law, whose :math:`\Delta\bar p(\bar q; \gamma)` does not depend on
    :math:`\bar t` (the scene uses :math:`\bar t = 0.1`).
    """
    if figure not in ("thin", "thick"):
        raise InvalidParameterError("figure", "{'thin', 'thick'}", figure)
    if variant not in ("printed", "consistent"):
        raise InvalidParameterError("variant", "{'printed', 'consistent'}", variant)
    par = {**CHAPTER_PARAMETERS, **(parameters or {})}
    qbar = np.linspace(*par["qbar"], points or par["points"])
    tb = par["thick_reduced_thickness"] if figure == "thick" else None
    nu = par["poisson_ratio"]
    curves = []
    for n in par["indices"]:
        for b in par["betas"]:
            # hyperelastic
            if variant == "printed":
                g = b / 3.0
                if figure == "thin":
                    dp = printed_thin_pressure_drop(n, g, qbar)
                else:
                    dp = printed_thick_pressure_drop(n, g, qbar, tb)
                qmax = float(qbar[np.isfinite(dp)][-1]) if np.isnan(dp).any() else math.inf
            else:
                g = 3.0 * b
                wall = "thin-mooney-rivlin" if figure == "thin" else "thick-mooney-rivlin"
                opts = {"thickness_convention": "reference"} if figure == "thin" else None
                sc = scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar, gamma=g, wall=wall,
                           wall_options=opts)
                qmax = sc.max_qbar()
                ok = qbar < qmax
                dp = np.full(qbar.shape, np.nan)
                dp[ok] = scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar[ok], gamma=g, wall=wall,
                               wall_options=opts).pressure_drop()
            curves.append(dict(n=n, beta=b, gamma=g, wall="hyperelastic", qbar=qbar, dpbar=np.asarray(dp),
                               qbar_max=qmax))
            # linear (nu = 1/2): the chapter's closed forms, or tubefsi for the consistent variant
            if variant == "printed":
                dpl = linear_pressure_drop(n, b, qbar, reduced_thickness=tb, poisson_ratio=nu)
            else:
                dpl = scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar, beta=b,
                            wall="thin-linear" if figure == "thin" else "thick-linear",
                            wall_options={"poisson_ratio": nu}).pressure_drop()
            curves.append(dict(n=n, beta=b, gamma=b * 2.0 * (1.0 + nu), wall="linear", qbar=qbar,
                               dpbar=np.asarray(dpl), qbar_max=math.inf))
    return curves


def _title(figure, variant, tb):
    wall = "Thin wall" if figure == "thin" else f"Thick wall (t/a = {tb:g})"
    if variant == "printed":
        error = "closed form without the factor 3" if figure == "thin" else "deflection ODE without the factor 4"
        return f"{wall}, as printed: hyperelastic at γ = β/3, {error}"
    return f"{wall}, consistent: hyperelastic at γ = 3β (the same E = 3μ as the linear wall), tubefsi"


def _write_csv(path, figure, variant, curves):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["figure", "variant", "n", "beta_label", "gamma_used", "wall", "qbar", "dpbar"])
        for c in curves:
            for qb, dp in zip(c["qbar"], c["dpbar"]):
                w.writerow([figure, variant, f"{c['n']:g}", f"{c['beta']:g}", f"{c['gamma']:.12g}", c["wall"],
                            f"{qb:.12g}", f"{dp:.12g}" if np.isfinite(dp) else ""])
    return path


def reproduce_chapter(output_dir="chapter-figures", *, points=None, parameters=None, formats=("png", "csv"),
                      file=None):
    """Write the chapter's two figures, as printed and consistent, as PNG and CSV.

    Four figures ``{thin,thick}_{printed,consistent}.png`` (two panels each: n = 1 and
    n = 0.7; solid hyperelastic, dashed linear, one colour per beta label) and the same
    curves as ``.csv`` (long format: figure, variant, n, beta_label, gamma_used, wall, qbar,
    dpbar; an empty dpbar where no steady state exists). ``formats`` picks ``"png"`` and/or
    ``"csv"``; ``parameters`` overrides entries of :data:`CHAPTER_PARAMETERS`. Returns the
    written paths; prints the parameter values and the paths to ``file`` if given.
    """
    for f in formats:
        if f not in ("png", "csv"):
            raise InvalidParameterError("formats", "a subset of {'png', 'csv'}", f)
    import matplotlib.pyplot as plt

    out = Path(output_dir)
    out.mkdir(parents=True, exist_ok=True)
    par = {**CHAPTER_PARAMETERS, **(parameters or {})}
    written = []
    colors = plt.get_cmap("viridis")(np.linspace(0.0, 0.8, len(par["betas"])))
    for figure in ("thin", "thick"):
        for variant in ("printed", "consistent"):
            curves = chapter_curves(figure, variant, points=points, parameters=par)
            stem = f"{figure}_{variant}"
            if "csv" in formats:
                written.append(_write_csv(out / f"{stem}.csv", figure, variant, curves))
            if "png" not in formats:
                continue
            fig, axes = plt.subplots(1, len(par["indices"]), figsize=(11.5, 5.4), layout="constrained")
            axes = np.atleast_1d(axes)
            for ax, n in zip(axes, par["indices"]):
                for color, b in zip(colors, par["betas"]):
                    for c in curves:
                        if c["n"] != n or c["beta"] != b:
                            continue
                        hyper = c["wall"] == "hyperelastic"
                        label = (f"β = {b:g}, hyperelastic (γ = {c['gamma']:.3g})" if hyper
                                 else f"β = {b:g}, linear")
                        ax.plot(c["qbar"], c["dpbar"], "-" if hyper else "--", color=color, lw=2.0 if hyper else 1.6,
                                label=label)
                        if hyper and math.isfinite(c["qbar_max"]) and c["qbar_max"] <= c["qbar"][-1]:
                            ok = np.isfinite(c["dpbar"])
                            ax.plot(c["qbar"][ok][-1], c["dpbar"][ok][-1], "x", color=color, ms=9, mew=2)
                kind = "Newtonian" if n == 1 else ("shear-thinning" if n < 1 else "shear-thickening")
                ax.set_title(f"n = {n:g} ({kind})", fontsize=12)
                ax.set_xlabel(r"dimensionless flow rate $\bar q$", fontsize=12)
                ax.set_ylabel(r"dimensionless pressure drop $\Delta\bar p$", fontsize=12)
                ax.set_xlim(par["qbar"])
                ax.set_ylim(bottom=0.0)
                ax.tick_params(labelsize=10)
                ax.grid(alpha=0.3)
            handles, labels = axes[0].get_legend_handles_labels()   # one column per beta
            fig.legend(handles, labels, loc="outside lower center", ncol=len(par["betas"]), fontsize=10,
                       frameon=False)
            note = ("solid: hyperelastic Mooney–Rivlin, dashed: linear (ν = 1/2)"
                    + ("; ×: last steady state (maximum flow rate)" if any(
                        math.isfinite(c["qbar_max"]) and c["qbar_max"] <= c["qbar"][-1] for c in curves) else ""))
            fig.suptitle(_title(figure, variant, par["thick_reduced_thickness"]) + "\n" + note, fontsize=11.5)
            fig.savefig(out / f"{stem}.png", dpi=110)
            plt.close(fig)
            written.append(out / f"{stem}.png")
    if file is not None:
        print(f"chapter figures: n in {par['indices']}, beta labels {par['betas']}, "
              f"qbar in [{par['qbar'][0]:g}, {par['qbar'][1]:g}] ({points or par['points']} points), "
              f"thick t/a = {par['thick_reduced_thickness']:g}, linear nu = {par['poisson_ratio']:g}; "
              "printed: gamma = beta/3, consistent: gamma = 3 beta", file=file)
        for p in written:
            print(f"wrote {p}", file=file)
    return written
