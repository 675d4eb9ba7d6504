"""Random valid scenes drawn by hypothesis, each solved and checked."""

from __future__ import annotations

import math

import attrs
import numpy as np
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import seed as hypothesis_seed
from hypothesis import strategies as st

from ... import registry
from ...errors import InvalidParameterError, NoSteadyStateError
from ...geometry import Tube
from ...solve import max_flow_rate, solve
from ._core import TIME_LIMIT, Probe, run_probe
from ._models import _profile_check, _profiles

def _scene_check(fluid, wall, tube, coupler, load, value, outlet):
    """Solve one scene and check it (returns the reason it fails, or None)."""
    accurate = coupler == "auto" or registry.couplers[coupler].meets_accuracy_contract
    rtol = 1e-7 if accurate else 1e-3

    def run(**kw):
        return solve(fluid, wall, tube, coupler=coupler, outlet_pressure=outlet, **kw)

    sol = run(**{load: value})
    q, dp = sol.flow_rate, sol.pressure_drop
    vals = np.array([q, dp, sol.inlet_pressure, sol.inlet_displacement])
    if not np.all(np.isfinite(vals)):
        return f"non-finite result {vals!r}"
    if q < 0 or dp < 0 or sol.inlet_displacement < 0:
        return f"negative result q={q!r}, dp={dp!r}, u={sol.inlet_displacement!r}"
    if q == 0 or dp == 0:
        return None
    other = "pressure_drop" if load == "flow_rate" else "flow_rate"
    back = run(**{other: dp if other == "pressure_drop" else q})
    got, want = (back.pressure_drop, dp) if other == "pressure_drop" else (back.flow_rate, q)
    # the round trip's condition: d ln q / d ln dp is at most ~1/n (the flow index); allow it
    if abs(got - want) > rtol * 10 * want:
        return f"round trip {load}: {want!r} -> {got!r}"
    if np.any(np.asarray(getattr(wall, "axial_stretch", 1.0)) != 1.0):
        return None     # a prestretched tube: installed length and unloaded radius differ from the Tube's
    a, L = tube.radius, tube.length
    g_rigid = fluid.pressure_gradient(q, a)
    g_inlet = fluid.pressure_gradient(q, a + sol.inlet_displacement)
    if fluid.yield_stress == 0 and not (L * g_inlet * (1 - rtol) <= dp <= L * g_rigid * (1 + rtol)):
        return f"dp={dp!r} outside the rigid-tube bounds [{L * g_inlet!r}, {L * g_rigid!r}]"
    tb = tube.thickness / a
    if not wall.is_rigid:
        e_in, e_sol = wall.strain(sol.inlet_pressure, tb), sol.inlet_displacement / a   # (no 1 + strain)
        if abs(e_in - e_sol) > 1e-6 * abs(e_in):
            return f"tube law at the inlet pressure: strain {e_in!r} != inlet strain {e_sol!r}"
    try:
        more = run(pressure_drop=dp * 1.01).flow_rate
    except NoSteadyStateError:
        more = math.inf
    if not more > q:
        return f"flow rate does not grow with the pressure drop: {q!r} -> {more!r}"
    return _profile_check(_profiles(sol), max(1e-9, 10 * rtol))   # the ODE's profile is the engine's


def _draw_model(draw, kind, name):
    cls = getattr(registry, kind)[name]
    if not cls._examples:
        return cls()
    example = dict(draw(st.sampled_from(cls._examples)))
    kwargs = dict(example)
    for key, value in list(kwargs.items()):
        field = attrs.fields_dict(cls).get(key)
        if type(value) is float and field is not None and field.metadata.get("admissible") == "(0, inf)":
            kwargs[key] = value * math.exp(draw(st.floats(-1.0, 1.0)))
    try:
        return cls(**kwargs)
    except InvalidParameterError:      # the scaled set leaves a joint constraint (Cross): the example
        return cls(**example)


def scene_outcomes(n, rheologies=None, walls=None, couplers=None, *, time_limit=TIME_LIMIT, seed=0):
    """Outcomes of ``n`` random valid scenes drawn by hypothesis from the registered models named."""

    rheologies = sorted(registry.rheologies) if rheologies is None else list(rheologies)
    walls = sorted(registry.walls) if walls is None else list(walls)
    couplers = sorted(registry.couplers) if couplers is None else list(couplers)
    outcomes = []

    @hypothesis_seed(seed)
    @settings(max_examples=n, deadline=None, database=None, suppress_health_check=list(HealthCheck),
              phases=[Phase.generate])
    @given(data=st.data())
    def one(data):
        draw = data.draw
        rname, wname = draw(st.sampled_from(rheologies)), draw(st.sampled_from(walls))
        fluid, wall = _draw_model(draw, "rheologies", rname), _draw_model(draw, "walls", wname)
        radius = math.exp(draw(st.floats(math.log(1e-5), math.log(1e-2))))
        tb = math.exp(draw(st.floats(math.log(0.02), math.log(2.0))))
        slender = math.exp(draw(st.floats(math.log(10.0), math.log(1e4))))
        tube = Tube(radius=radius, thickness=tb * radius, length=slender * radius)
        usable = ["auto"] + [c for c in couplers if registry.couplers[c]().supports(fluid, wall)]
        coupler = draw(st.sampled_from(usable))
        fraction = math.exp(draw(st.floats(math.log(1e-6), math.log(0.9))))
        load = draw(st.sampled_from(("flow_rate", "pressure_drop")))
        outlet = 0.0
        label = f"{rname}={fluid!r} {wname}={wall!r} {tube!r} {coupler} {load} fraction={fraction:.3g}"

        def call():
            nonlocal outlet
            p_lim = wall.limit_pressure(tb)
            scale = min(0.5 * p_lim, wall.small_strain_modulus(tb) * tb) if not wall.is_rigid else 1e3
            if draw(st.booleans()) and not wall.is_rigid:
                outlet = scale * draw(st.floats(0.0, 0.5))
            if load == "pressure_drop":
                value = fraction * (min(p_lim - outlet, scale) if math.isfinite(p_lim) else scale)
            else:
                q_max = max_flow_rate(fluid, wall, tube, outlet_pressure=outlet)
                q_ref = fluid.flow_rate(radius, scale / tube.length)
                value = fraction * min(q_max, q_ref) if math.isfinite(q_max) else fraction * q_ref
            return _scene_check(fluid, wall, tube, coupler, load, value, outlet)

        # a scene is about ten public calls; the ODE coupler (a reference, one integration per point
        # and per shooting step) gets three times as long
        bound = time_limit * (18 if coupler == "ode" else 6)
        outcomes.append(run_probe(Probe(f"scene:{coupler}", label, call, check=lambda why: why, family="scenes"),
                                   bound))

    one()
    return outcomes


# ----------------------------------------------------------------------------- campaign
