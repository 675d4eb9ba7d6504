r"""Model no more than a scene needs, and no less.

:func:`advise` solves the same scene with the requested model and with every simpler
model it can derive from it — a rigid wall, a linear wall with the same
small-strain stiffness, the thin (current-thickness) version of a thick hyperelastic
material, and a Newtonian fluid in place of a power law with an index near 1 — and
recommends the cheapest whose pressure drop is within ``tolerance`` of the requested
model's. :func:`diagnostics` reports whether the assumptions behind the model hold.

Equivalent linear walls match the requested wall's small-strain slope
:math:`P'(1)`: thin :math:`E = P'(1)(1-\nu/2)/\bar t`, thick :math:`E = P'(1)K/\bar t`,
with :math:`\nu = 1/2` (incompressible). The equivalent Newtonian viscosity is the
power law's apparent viscosity at the rigid tube's wall shear rate.
"""

from __future__ import annotations

import math
import time
import warnings
from typing import Any

import attrs
import numpy as np

from . import registry
from .errors import InvalidParameterError, NoSteadyStateError, TubefsiError
from .rheology.power_law import _PowerLawForms
from .scene import make_scene
from .solve import solve
from .walls.hyperelastic import HyperelasticWall, ThickWall, ThinWall
from .walls.linear import ThickLinear, ThinLinear
from .walls.rigid import Rigid

__all__ = ["advise", "Advice", "Candidate", "diagnostics", "Diagnostics", "ModelValidityWarning"]


class ModelValidityWarning(UserWarning):
    """An assumption of the model (slenderness, small strain, low Reynolds number...) fails."""


@attrs.frozen
class Candidate:
    """One model of the comparison."""

    label: str
    rheology: Any
    wall: Any
    rank: int                     # lower = simpler/cheaper
    pressure_drop: float
    relative_difference: float    # |dp / dp_requested - 1|
    seconds: float
    note: str = ""


@attrs.frozen
class Advice:
    """Result of :func:`advise`: the candidates and the recommendation."""

    requested: Candidate
    candidates: tuple
    recommended: Candidate
    tolerance: float

    def __str__(self) -> str:
        lines = [f"{'model':58s} {'pressure drop (Pa)':>19s} {'rel. diff':>10s}  ok"]
        for c in self.candidates:
            ok = "yes" if c.relative_difference <= self.tolerance else ("-" if math.isnan(c.relative_difference) else "no")
            mark = "  <- recommended" if c is self.recommended else ""
            lines.append(f"{c.label:58s} {c.pressure_drop:19.6g} {c.relative_difference:10.2e}  {ok}{mark}"
                         + (f" ({c.note})" if c.note else ""))
        return "\n".join(lines)


def _material(wall):
    """The material base class of a hyperelastic wall (e.g. NeoHookean for ThickNeoHookean)."""
    for cls in type(wall).__mro__:
        if (isinstance(cls, type) and issubclass(cls, HyperelasticWall) and attrs.has(cls)
                and not issubclass(cls, (ThinWall, ThickWall))):
            return cls
    return None


def _thin_counterpart(wall):
    """The registered thin (current-thickness) wall of the same material, if any."""
    material = _material(wall)
    if material is None:
        return None
    for name in registry.walls:
        cls = registry.walls[name]
        if issubclass(cls, ThinWall) and issubclass(cls, material):
            kwargs = {f.name: getattr(wall, f.name) for f in attrs.fields(material)}
            return cls(**kwargs, thickness_convention="current")
    return None


def _linear_equivalent(wall, tb):
    """The linear wall (same theory) with the same small-strain slope P'(1): a linear tube
    law is fixed by that slope, so thin and thick linear walls would coincide here."""
    slope = wall.small_strain_modulus(tb)
    if isinstance(wall, (ThickWall, ThickLinear)):
        k = (1.0 + tb) ** 2 * 1.5 / (2.0 + tb)
        return ThickLinear(youngs_modulus=slope * k / tb, poisson_ratio=0.5)
    return ThinLinear(youngs_modulus=slope * 0.75 / tb, poisson_ratio=0.5)


def _candidates(rheology, wall, tube, load):
    """(rank, label, rheology, wall) of the requested model and its simpler relatives."""
    tb = tube.reduced_thickness
    name = registry.walls.name_of(wall) or type(wall).__name__
    fluid_name = registry.rheologies.name_of(rheology) or type(rheology).__name__
    out = [(0, "rigid wall", rheology, Rigid())]
    if not wall.is_rigid:
        lin = _linear_equivalent(wall, tb)
        out.append((1, f"{registry.walls.name_of(lin)}, E = {lin.youngs_modulus:.4g} Pa, nu = 1/2 (same P'(1))",
                    rheology, lin))
        if isinstance(wall, ThickWall):
            thin = _thin_counterpart(wall)
            if thin is not None:
                out.append((3, f"{registry.walls.name_of(thin)} (current thickness)", rheology, thin))
    rank = {ThinLinear: 1, ThickLinear: 1}.get(type(wall), 4 if isinstance(wall, ThickWall) else 3)
    rank = 0 if wall.is_rigid else rank
    out = [c for c in out if c[0] < rank]
    if isinstance(rheology, _PowerLawForms) and rheology.index != 1.0 and abs(rheology.index - 1.0) <= 0.2:
        newt = registry.rheologies["newtonian"](viscosity=_equivalent_viscosity(rheology, tube, load))
        out.append((rank, f"{name} with newtonian, mu = {newt.viscosity:.4g} Pa s", newt, wall))
    out.append((rank + 0.5, f"{name} with {fluid_name} (requested)", rheology, wall))
    return sorted(out, key=lambda c: c[0])


def _equivalent_viscosity(rheology, tube, load):
    kind, value = load
    value = float(np.max(value))
    if kind == "flow_rate":
        gradient = rheology.pressure_gradient(value, tube.radius)
    else:
        gradient = value / tube.length
    tau_w = 0.5 * gradient * tube.radius
    return float(tau_w / rheology.shear_rate(tau_w))


def advise(rheology, wall, tube, *, flow_rate=None, pressure_drop=None, tolerance=0.01,
           outlet_pressure=0.0) -> Advice:
    """Compare the requested model with simpler ones on the same scene.

    Parameters
    ----------
    rheology, wall, tube
        The requested model, as for :func:`tubefsi.solve`.
    flow_rate, pressure_drop : float
        The load (exactly one). For a pressure drop, candidates are compared on the
        pressure drop that the requested model needs for the flow rate it predicts.
    tolerance : float
        Largest acceptable relative difference in pressure drop.

    Returns
    -------
    Advice
        ``recommended`` is the simplest candidate within ``tolerance``; ``str(advice)``
        prints the comparison table.
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure)
    rheology, wall = scene.rheology, scene.wall
    if (flow_rate is None) == (pressure_drop is None):
        raise InvalidParameterError("flow_rate / pressure_drop", "exactly one of the two", None)
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance >= 0):
        raise InvalidParameterError("tolerance", "[0, inf)", tolerance)
    if flow_rate is None:
        flow_rate = solve(rheology, wall, tube, pressure_drop=pressure_drop,
                          outlet_pressure=outlet_pressure).flow_rate
    else:  # the requested model must solve: its errors are the caller's, not a candidate's
        solve(rheology, wall, tube, flow_rate=flow_rate, outlet_pressure=outlet_pressure)
    load = ("flow_rate", flow_rate)
    results = []
    reference = None
    for rank, label, fluid, w in _candidates(rheology, wall, tube, load):
        start = time.perf_counter()
        try:
            dp = float(solve(fluid, w, tube, flow_rate=flow_rate, outlet_pressure=outlet_pressure).pressure_drop)
            note = ""
        except (NoSteadyStateError, TubefsiError) as exc:
            dp, note = math.nan, f"{type(exc).__name__}"
        results.append([rank, label, fluid, w, dp, time.perf_counter() - start, note])
        if w is wall and fluid is rheology:
            reference = dp
    cands = tuple(Candidate(label=label, rheology=fluid, wall=w, rank=int(rank), pressure_drop=dp,
                            relative_difference=abs(dp / reference - 1.0) if math.isfinite(dp) else math.nan,
                            seconds=sec, note=note)
                  for rank, label, fluid, w, dp, sec, note in results)
    requested = next(c for c in cands if c.wall is wall and c.rheology is rheology)
    recommended = next(c for c in cands if c.relative_difference <= tolerance)
    return Advice(requested=requested, candidates=cands, recommended=recommended, tolerance=tolerance)


@attrs.frozen
class Diagnostics:
    """Validity of a solution's assumptions; ``warnings`` lists what fails."""

    slenderness: float
    max_strain: float
    inlet_pressure_fraction: float      # p_in / limit pressure (0 if no limit)
    flow_rate_fraction: float           # q / maximum flow rate (0 if none)
    reynolds_number: float | None       # Metzner–Reed, with the given density
    reduced_reynolds_number: float | None   # Re * a / L, what lubrication needs small
    warnings: tuple

    def __str__(self) -> str:
        rows = [("slenderness a/L", self.slenderness), ("max hoop strain", self.max_strain),
                ("p_in / limit pressure", self.inlet_pressure_fraction),
                ("q / max flow rate", self.flow_rate_fraction),
                ("Reynolds number", self.reynolds_number), ("reduced Reynolds Re a/L", self.reduced_reynolds_number)]
        text = "\n".join(f"{k:26s} {'n/a' if v is None else f'{v:.4g}'}" for k, v in rows)
        return text + "".join(f"\nwarning: {w}" for w in self.warnings)


def diagnostics(solution, *, density=None, warn=True) -> Diagnostics:
    """Check a :class:`~tubefsi.Solution`'s assumptions (see :meth:`tubefsi.Solution.diagnostics`)."""
    tube, wall = solution.tube, solution.wall
    tb = tube.reduced_thickness
    messages = []
    eps = tube.slenderness
    if eps > 0.1:
        messages.append(f"the tube is not slender (a/L = {eps:.3g} > 0.1): lubrication theory is inaccurate")
    strain = float(np.max(solution.state.inlet_strain))
    if isinstance(wall, (ThinLinear, ThickLinear)) and strain > 0.05:
        messages.append(f"hoop strain {strain:.3g} > 0.05 with a linear wall: use a hyperelastic wall")
    if isinstance(wall, ThinWall) and tb > 0.1:
        messages.append(f"thin-wall theory with t/a = {tb:.3g} > 0.1: use the thick wall")
    limit = wall.limit_pressure(tb)
    p_frac = float(np.max(solution.outlet_pressure + solution.state.pressure_drop)) / limit
    if p_frac > 0.9:
        messages.append(f"inlet pressure at {100 * p_frac:.1f} % of the limit pressure {limit:.4g} Pa: "
                        "the tube is close to unbounded inflation")
    q_max = solution.max_flow_rate
    q_frac = float(np.max(solution.state.flow_rate)) / q_max
    if q_frac > 0.9:
        messages.append(f"flow rate at {100 * q_frac:.1f} % of the maximum flow rate {q_max:.4g} m^3/s")
    re = rre = None
    if density is not None:
        q = float(np.max(solution.state.flow_rate))
        diameter = 2.0 * tube.radius
        velocity = q / (math.pi * tube.radius**2)
        if q > 0:
            tau_w = 0.5 * solution.rheology.pressure_gradient(q, tube.radius) * tube.radius
            eta = tau_w / (8.0 * velocity / diameter)   # Metzner–Reed apparent viscosity
            re = float(density) * velocity * diameter / eta
        else:
            re = 0.0
        rre = re * eps
        if rre > 0.1:
            messages.append(f"reduced Reynolds number Re a/L = {rre:.3g} > 0.1: inertia is not negligible")
    if warn:
        for m in messages:
            warnings.warn(m, ModelValidityWarning, stacklevel=3)
    return Diagnostics(slenderness=eps, max_strain=strain, inlet_pressure_fraction=p_frac,
                       flow_rate_fraction=q_frac, reynolds_number=re, reduced_reynolds_number=rre,
                       warnings=tuple(messages))
