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
from typing import Any

import attrs
import numpy as np
from numpy.typing import ArrayLike

from . import registry, validity
from ._validation import as_load
from ._keywords import checked_keywords
from .errors import InvalidParameterError, ModelValidityWarning, NoSteadyStateError, TubefsiError, warn_user
from .rheology.power_law import _PowerLawForms
from .scene import make_scene
from .solve import max_flow_rate, solve, solve_unchecked
from .walls.hyperelastic import HyperelasticWall, ThickWall, ThinWall
from .walls.linear import ThickLinear, ThinLinear
from .walls.rigid import Rigid
# for the annotations
from .geometry import Tube
from .rheology.base import Rheology
from .solution import Solution
from .walls.base import WallModel

__all__ = ["advise", "Advice", "Candidate", "diagnostics", "Diagnostics", "ModelValidityWarning"]


@attrs.frozen
class Candidate:
    """One model of the comparison."""

    label: str
    rheology: Any
    wall: Any
    rank: int                     # lower = simpler/cheaper
    pressure_drop: float          # or an array, for an array of loads
    relative_difference: float    # |dp / dp_requested - 1|, the largest over the loads
    seconds: float
    note: str = ""


@attrs.frozen
class Advice:
    """Result of :func:`advise`: the candidates and the recommendation."""

    requested: Candidate
    candidates: tuple
    recommended: Candidate
    tolerance: float
    #: The requested model's own expected error in the pressure drop from its clamped ends, by
    #: the measured validity map (``docs/validity.md``; NaN where the map does not apply).
    expected_model_error: float = math.nan

    def __str__(self) -> str:
        curve = np.ndim(self.requested.pressure_drop) > 0
        width = max([58] + [len(c.label) for c in self.candidates])
        head = "max pressure drop (Pa)" if curve else "pressure drop (Pa)"
        lines = [f"{'model':{width}s} {head:>22s} {'max rel. diff' if curve else 'rel. diff':>13s}  ok"]
        for c in self.candidates:
            ok = "yes" if c.relative_difference <= self.tolerance else ("-" if math.isnan(c.relative_difference) else "no")
            mark = "  <- recommended" if c is self.recommended else ""
            dp = float(np.max(c.pressure_drop))
            lines.append(f"{c.label:{width}s} {dp:22.6g} {c.relative_difference:13.2e}  {ok}{mark}"
                         + (f" ({c.note})" if c.note else ""))
        if math.isfinite(self.expected_model_error):
            lines.append(f"expected error of the reduced model itself (clamped ends, validity map): "
                         f"{self.expected_model_error:.2g}")
        return "\n".join(lines)


def _material(wall):
    """The material base class of a hyperelastic wall (e.g. NeoHookean for ThickNeoHookean)."""
    for cls in type(wall).__mro__:
        if (isinstance(cls, type) and issubclass(cls, HyperelasticWall) and attrs.has(cls)
                and not issubclass(cls, (ThinWall, ThickWall))):
            return cls
    return None


def _thin_counterpart(wall, convention="current"):
    """The registered thin wall of the same material with the thickness ``convention``, if any."""
    material = _material(wall)
    if material is None:
        return None
    for name in registry.walls:
        cls = registry.walls[name]
        if issubclass(cls, ThinWall) and issubclass(cls, material):
            kwargs = {f.name: getattr(wall, f.name) for f in attrs.fields(material)}
            return cls(**kwargs, thickness_convention=convention)
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
            for convention, why in (("current", "the thick law's thin limit"),
                                    ("reference", "the thin walls' default; first-order agreement only")):
                thin = _thin_counterpart(wall, convention)
                if thin is not None:
                    out.append((3, f"{registry.walls.name_of(thin)}:thickness_convention={convention} ({why})",
                                rheology, thin))
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


@checked_keywords
def advise(rheology: Rheology | type[Rheology] | str, wall: WallModel | type[WallModel] | str, tube: Tube, *,
           flow_rate: float | ArrayLike | None = None, pressure_drop: float | ArrayLike | None = None,
           tolerance: float = 0.01, outlet_pressure: float | ArrayLike = 0.0) -> Advice:
    """Compare the requested model with simpler ones on the same scene.

    The candidates: a rigid wall; the linear wall of the same theory with the same
    small-strain slope; for a thick hyperelastic wall, the thin wall of the same material in
    both thickness conventions — ``current`` (the thick law's limit as t/a -> 0, with the
    same limit pressure) and ``reference`` (the default of the thin walls: no limit pressure,
    equal to the others to first order in strain only; ``docs/theory.md``, section "Thin
    walls"), each labelled with the exact ``thickness_convention`` it uses; and a Newtonian
    fluid for a power law with an index within 0.2 of 1.

    Parameters
    ----------
    rheology, wall, tube
        The requested model, as for :func:`tubefsi.solve`.
    flow_rate, pressure_drop : float or array_like
        The load (exactly one), a value or an array of values (a curve): models are then
        compared on their largest relative difference over the loads. For a pressure drop,
        candidates are compared on the pressure drop that the requested model needs for the
        flow rate it predicts.
    tolerance : float
        Largest acceptable relative difference in pressure drop.

    Returns
    -------
    Advice
        ``recommended`` is the simplest candidate within ``tolerance``; ``str(advice)``
        prints the comparison table. The candidates' ``solve`` calls are silent: the
        requested model's own solve issues any :class:`~tubefsi.ModelValidityWarning`.
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure)
    rheology, wall = scene.rheology, scene.wall
    if (flow_rate is None) == (pressure_drop is None):
        raise InvalidParameterError("flow_rate / pressure_drop", "exactly one of the two", None)
    if not (isinstance(tolerance, (int, float)) and not isinstance(tolerance, bool) and math.isfinite(tolerance) and tolerance >= 0):
        raise InvalidParameterError("tolerance", "[0, inf)", tolerance)
    if scene.shape != ():
        raise InvalidParameterError("rheology / wall / tube", "scalar parameters (advise compares one scene)",
                                    None, f"got parameters of shape {scene.shape}; call advise per scene")
    if flow_rate is None:
        own = solve(rheology, wall, tube, pressure_drop=pressure_drop, outlet_pressure=outlet_pressure)
        flow_rate = own.flow_rate
    else:  # the requested model must solve: its errors are the caller's, not a candidate's
        own = solve(rheology, wall, tube, flow_rate=flow_rate, outlet_pressure=outlet_pressure)
    if not np.any(np.asarray(flow_rate) > 0):       # nothing to compare: every candidate gives 0
        raise InvalidParameterError("flow_rate" if pressure_drop is None else "pressure_drop", "(0, inf)",
                                    flow_rate if pressure_drop is None else pressure_drop,
                                    "advice compares the pressure drops of a flowing tube; this load gives no flow")
    load = ("flow_rate", flow_rate)
    results = []
    reference = None
    for rank, label, fluid, w in _candidates(rheology, wall, tube, load):
        start = time.perf_counter()
        try:
            # a candidate's own validity is not the question (no process-wide filter: threads)
            dp = solve_unchecked(fluid, w, tube, flow_rate=flow_rate, outlet_pressure=outlet_pressure).pressure_drop
            note = ""
        except (NoSteadyStateError, TubefsiError) as exc:
            dp, note = math.nan, f"{type(exc).__name__}"
        results.append([rank, label, fluid, w, dp, time.perf_counter() - start, note])
        if w is wall and fluid is rheology:
            reference = dp

    def difference(dp):
        if np.ndim(dp) == 0 and math.isnan(dp):
            return math.nan
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.abs(np.asarray(dp) / reference - 1.0)
        rel = np.where(np.asarray(reference) == np.asarray(dp), 0.0, rel)   # q = 0: both 0
        return float(np.max(rel))

    cands = tuple(Candidate(label=label, rheology=fluid, wall=w, rank=int(rank), pressure_drop=dp,
                            relative_difference=difference(dp), seconds=sec, note=note)
                  for rank, label, fluid, w, dp, sec, note in results)
    requested = next(c for c in cands if c.wall is wall and c.rheology is rheology)
    recommended = next(c for c in cands if c.relative_difference <= tolerance)
    return Advice(requested=requested, candidates=cands, recommended=recommended, tolerance=tolerance,
                  expected_model_error=_expected_model_error(own))


@attrs.frozen
class Diagnostics:
    """Validity of a solution's assumptions; ``warnings`` lists what fails."""

    slenderness: float                  # undeformed a / L
    max_strain: float                   # largest inlet hoop strain
    inlet_pressure_fraction: float      # p_in / limit pressure (0 if no limit)
    flow_rate_fraction: float           # q / maximum flow rate (0 if none)
    reynolds_number: float | None       # Metzner–Reed, with the given density, where Re R/L is largest
    reduced_reynolds_number: float | None   # Re * R / L, what lubrication needs small
    warnings: tuple
    deformed_slenderness: float = math.nan   # largest R_in / L: the deformed tube's
    expected_model_error: float = math.nan   # |dp_tubefsi / dp_exact - 1| from clamped ends (validity map)

    def __str__(self) -> str:
        rows = [("slenderness a/L", self.slenderness), ("deformed slenderness R/L", self.deformed_slenderness),
                ("max hoop strain", self.max_strain),
                ("expected model error", self.expected_model_error),
                ("p_in / limit pressure", self.inlet_pressure_fraction),
                ("q / max flow rate", self.flow_rate_fraction),
                ("Reynolds number", self.reynolds_number), ("reduced Reynolds Re R/L", self.reduced_reynolds_number)]
        text = "\n".join(f"{k:26s} {'n/a' if v is None else f'{v:.4g}'}" for k, v in rows)
        return text + "".join(f"\nwarning: {w}" for w in self.warnings)


@checked_keywords
def diagnostics(solution: Solution, *, density: float | ArrayLike | None = None, warn: bool = True) -> Diagnostics:
    """Check a :class:`~tubefsi.Solution`'s assumptions on the deformed tube (see
    :meth:`tubefsi.Solution.diagnostics` and :mod:`tubefsi.validity`), and how close it is to
    the limit pressure and the maximum flow rate."""
    tube, wall, st = solution.tube, solution.wall, solution.state
    tb = tube.reduced_thickness
    density = solution.density if density is None else density
    shape = np.shape(st.flow_rate)
    flat = solution.scene.flat(shape) if solution.scene.shape != () else solution.scene
    if density is not None:
        rho = as_load("density", density, allow_zero=False)
        density = float(rho) if rho.ndim == 0 else np.broadcast_to(rho, shape).ravel()
    found = validity.check(flat, np.ravel(st.flow_rate), np.ravel(st.inlet_strain), density=density)
    messages = list(found.messages)
    eps = float(np.max(tube.slenderness))
    if np.any(np.asarray(tb) > 0.1) and isinstance(wall, ThinWall):
        messages.append(f"thin-wall theory with t/a = {float(np.max(tb)):.3g} > 0.1: use the thick wall")
    limit = np.asarray(wall.limit_pressure(tb), dtype=float)
    with np.errstate(invalid="ignore"):
        p_frac = float(np.nanmax(np.asarray(solution.scene.outlet_pressure + st.pressure_drop) / limit,   # transmural
                                 initial=0.0))
    if p_frac > 0.9:
        messages.append(f"inlet pressure at {100 * p_frac:.1f} % of the limit pressure {float(np.min(limit)):.4g} Pa: "
                        "the tube is close to unbounded inflation")
    q_max = np.asarray(max_flow_rate(solution.rheology, wall, tube, outlet_pressure=solution.outlet_pressure,
                                     external_pressure=solution.external_pressure, coupler=solution.coupler),
                       dtype=float)
    with np.errstate(invalid="ignore"):
        q_frac = float(np.nanmax(np.asarray(st.flow_rate) / q_max, initial=0.0))
    if q_frac > 0.9:
        messages.append(f"flow rate at {100 * q_frac:.1f} % of the maximum flow rate {float(np.min(q_max)):.4g} m^3/s")
    if warn:
        for m in messages:
            warn_user(m, ModelValidityWarning)
    return Diagnostics(slenderness=eps, max_strain=found.max_strain, inlet_pressure_fraction=p_frac,
                       flow_rate_fraction=q_frac, reynolds_number=found.reynolds_number,
                       reduced_reynolds_number=found.reduced_reynolds_number, warnings=tuple(messages),
                       deformed_slenderness=found.deformed_slenderness,
                       expected_model_error=_expected_model_error(solution))


def _expected_model_error(solution) -> float:
    """Largest end-effect error of the pressure drop over the solution's points
    (:func:`tubefsi.validity.end_effect_error`, ``docs/validity.md``); NaN for a tube whose
    fields vary along z (the map covers uniform tubes only) or a rigid wall (no inflation)."""
    tube, st = solution.tube, solution.state
    if any(callable(v) for v in (tube.radius, tube.thickness, tube.length)):
        return math.nan
    q = np.asarray(st.flow_rate, dtype=float)
    strain = np.asarray(st.inlet_strain, dtype=float)
    r_in = np.asarray(tube.radius, dtype=float) * (1.0 + strain)
    ok = np.isfinite(q) & np.isfinite(strain) & (q > 0)
    if not np.any(ok):
        return 0.0 if np.all(np.isfinite(q)) else math.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        k = solution.rheology._flow_index(np.where(ok, q, 1.0), np.broadcast_to(r_in, q.shape))
        err = validity.end_effect_error(k, strain, tube.radius, tube.thickness, tube.length)
    return float(np.max(np.where(ok, err, 0.0)))
