"""The "extremes" family: every registered wall and rheology at the edges of its valid range.

Each numeric field of each registered model is set, one at a time, to extreme *valid* values read
from its metadata (the smallest positive double, 1e-300, 1e300, the largest double, the ends of a
bounded range and the doubles next to them), and the model's methods are called at extreme valid
arguments (stretches of 1e-300, 1 + eps and 1e300, pressures and shear rates of 1e-300 and 1e300,
thicknesses at the ends of the admissible range); each registered pair is also solved at a
pressure drop of 1e260 Pa and its profiles read. The contract is the campaign's: a typed error, or
finite values that pass a cheap check (sign, monotonicity, a round trip where it is cheap).
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from ... import registry
from ...errors import TubefsiError
from ...geometry import Tube
from ...solve import solve
from ...walls.base import THICKNESS_RANGE
from ._core import _TUBE, Probe, _short

_MAX = float(np.finfo(float).max)
_TINY = 5e-324
#: the stretch just above 1
_ONE_UP = float(np.nextafter(1.0, 2.0))
#: the pressure drop of the solves (Pa): the pressures stay doubles, the flows and stretches may not
_HUGE_DROP = 1e260


def extreme_values(field) -> tuple:
    """Valid values at the edges of a field's range (its metadata ``low``, ``high``, ``low_open``,
    ``high_open``): the ends of a closed range and the doubles next to them, and toward an infinite
    or zero end 1e300 and the largest double, 1e-300 and the smallest positive double. Empty for a
    field without a numeric range (options, tuples)."""
    meta = field.metadata
    if "low" not in meta:
        return ()
    low, high, low_open, high_open = meta["low"], meta["high"], meta["low_open"], meta["high_open"]
    out = []
    if low == -math.inf:
        out += [-_MAX, -1e300]
    else:
        out += [] if low_open else [low]
        out += [float(np.nextafter(low, math.inf))]
        if low == 0.0:
            out += [1e-300]
    if high == math.inf:
        out += [1e300, _MAX]
    else:
        out += [] if high_open else [high]
        out += [float(np.nextafter(high, -math.inf))]
    if low < 0.0 < high and low == -math.inf:        # a real line: tiny values of either sign
        out += [-1e-300, 1e-300]
    return tuple(dict.fromkeys(v for v in out if _inside(v, low, high, low_open, high_open)))


def _inside(v, low, high, low_open, high_open) -> bool:
    return (v > low if low_open else v >= low) and (v < high if high_open else v <= high)


def _tuple_extremes(value) -> tuple:
    """Extreme entries of a tuple field (Ogden's moduli and exponents): its first entry replaced."""
    return tuple((v,) + tuple(value[1:]) for v in (1e-300, 1e300, -1e300))


def _variants(cls):
    """``(label, kwargs)``: the first example with one field at an extreme valid value."""
    example = dict(cls._examples[0]) if cls._examples else {}
    for field in attrs.fields(cls):
        if not field.init:
            continue
        values = extreme_values(field)
        current = example.get(field.name, field.default)
        if not values and isinstance(current, tuple) and current and all(isinstance(v, float) for v in current):
            values = _tuple_extremes(current)
        for value in values:
            yield f"{field.name}={_short(value)}", {**example, field.name: value}


# ------------------------------------------------------------------------------------------ walls
def _wall_method_probes(name, wall, entry, tag=""):
    """The wall's methods at extreme valid arguments (at the thickness 0.3 and at the ends of the
    admissible thickness range)."""
    tb = 0.3
    for lam in (_ONE_UP, 1.0 + 1e-8, 1e300, 1e-300):
        yield Probe(entry, f"{tag}pressure({lam!r}, {tb})", lambda la=lam: wall.pressure(la, tb),
                    check=_pressure_check(lam))
        yield Probe(entry, f"{tag}stiffness({lam!r}, {tb})", lambda la=lam: wall.stiffness(la, tb),
                    check=_nonnegative("stiffness"))
    for p in (1e-300, 1e300):
        yield Probe(entry, f"{tag}strain({p!r}, {tb})", lambda pp=p: wall.strain(pp, tb),
                    check=_strain_check(wall, p, tb))
    for t in THICKNESS_RANGE:
        yield Probe(entry, f"{tag}limits({t!r})", lambda tt=t: _limits(wall, tt), check=_limits_check, allow_inf=True)


def _pressure_check(lam):
    def check(p):
        if (lam >= 1.0 and p < 0) or (lam < 1.0 and p > 0):
            return f"pressure {p!r} at stretch {lam!r}"
        return None

    return check


def _nonnegative(what):
    def check(value):
        return None if np.all(np.asarray(value) >= 0) else f"negative {what} {value!r}"

    return check


def _strain_check(wall, p, tb):
    def check(strain):
        if strain < 0:
            return f"strain {strain!r} at pressure {p!r}"
        if 1e-8 < strain < 1e15:                 # cheap round trip where the stretch resolves it
            back = wall.pressure(1.0 + strain, tb)
            if abs(back - p) > 1e-6 * p:
                return f"pressure(1 + strain({p!r})) = {back!r}"
        return None

    return check


def _limits(wall, tb):
    return wall.limit_pressure(tb), wall.max_stretch(tb), wall.small_strain_modulus(tb)


def _limits_check(result):
    p_lim, lam_max, modulus = result
    if not (p_lim > 0 and lam_max > 1 and 0 < modulus < math.inf):
        return f"limit_pressure {p_lim!r}, max_stretch {lam_max!r}, small_strain_modulus {modulus!r}"
    return None


def _wall_at(wall, tb=0.3):
    """A wall's law at moderate stretches, its stiffness and limits: checked for sign and order."""
    top = float(wall.max_stretch(tb))
    lam = np.array([_ONE_UP, 1.0 + 1e-3, 1.5])
    lam = lam[lam < top] if math.isfinite(top) else lam
    if lam.size < 3 and math.isfinite(top):
        lam = np.append(lam, 1.0 + 0.5 * (top - 1.0))
    return lam, wall.pressure(lam, tb), wall.stiffness(lam, tb), _limits(wall, tb)


def _wall_at_check(result):
    lam, p, k, limits = result
    order = np.argsort(lam)
    if np.any(p < 0) or np.any(np.diff(p[order]) < 0):
        return f"pressures {p!r} at stretches {lam!r}: negative or decreasing"
    if np.any(k < 0):
        return f"negative stiffness {k!r}"
    if np.max(k) < 1e-300:                 # a subnormal modulus: its limits may underflow to 0
        p_lim, lam_max, modulus = limits
        return None if p_lim >= 0 and lam_max > 1 and 0 <= modulus < math.inf else f"limits {limits!r}"
    return _limits_check(limits)


def _wall_probes(name):
    cls = registry.walls[name]
    if cls.is_rigid:
        return
    entry = f"wall:{name}"
    example = dict(cls._examples[0]) if cls._examples else {}
    yield from _wall_method_probes(name, cls(**example), entry)
    for label, kwargs in _variants(cls):
        yield Probe(entry, f"{label}: moderate stretches", lambda kw=kwargs: _wall_at(cls(**kw)),
                    check=_wall_at_check, allow_inf=True)
        yield Probe(entry, f"{label}: pressure(1e300)", lambda kw=kwargs: cls(**kw).pressure(1e300, 0.3),
                    check=_pressure_check(1e300))
        yield Probe(entry, f"{label}: stiffness(1e300)", lambda kw=kwargs: cls(**kw).stiffness(1e300, 0.3),
                    check=_nonnegative("stiffness"))
        yield Probe(entry, f"{label}: strain(1e300)", lambda kw=kwargs: cls(**kw).strain(1e300, 0.3),
                    check=_nonnegative("strain"))


# ------------------------------------------------------------------------------------- rheologies
def _law_check(fluid, gamma):
    """stress(gamma) and shear_rate of it: a yield stress at least, and the round trip where the
    excess stress resolves the shear rate."""
    def check(result):
        stress, back = result
        ty = float(fluid.yield_stress)
        if stress < ty or back < 0:
            return f"stress {stress!r}, shear rate {back!r} at shear rate {gamma!r}"
        if 1e-250 < gamma < 1e250 and stress > ty * (1 + 1e-6) and abs(back - gamma) > 1e-6 * gamma:
            return f"shear_rate(stress({gamma!r})) = {back!r}"
        return None

    return check


def _velocities(fluid, radius, g):
    return fluid.velocity(np.array([0.0, 0.5 * radius, radius]), radius, g)


def _velocity_check(v):
    slack = 1e-300            # (subnormal velocities have lost their digits)
    if not (v[0] + slack >= v[1] and v[1] + slack >= v[2] >= 0.0 and v[2] <= 1e-12 * v[0] + slack):
        return f"velocity {v!r} at r = 0, R/2, R"
    return None


def _flow_rate_check(fluid, radius, g):
    def check(q):
        if q < 0:
            return f"flow rate {q!r}"
        if 1e-250 < q < 1e250 and 1e-250 < g:
            back = fluid.pressure_gradient(q, radius)
            # G(q) may be ill-conditioned (a power law of index n: d ln G / d ln q = n, 1e300 at
            # most): then the gradient need only lie between those of q (1 -+ 1e-9)
            if abs(back - g) > 1e-6 * g and not _between(g, fluid, q, radius):
                return f"pressure_gradient(flow_rate({g!r})) = {back!r}"
        return None

    return check


def _between(g, fluid, q, radius) -> bool:
    def gradient(qq):
        try:
            return fluid.pressure_gradient(qq, radius)
        except TubefsiError:            # beyond the doubles
            return math.inf

    return gradient(q * (1 - 1e-9)) <= g <= gradient(q * (1 + 1e-9))


def _rheology_method_probes(fluid, entry, tag=""):
    for gamma in (_TINY, 1e-300, 1e300, _MAX):
        yield Probe(entry, f"{tag}stress({gamma!r})", lambda g=gamma: _law(fluid, g), check=_law_check(fluid, gamma))
        yield Probe(entry, f"{tag}shear_rate({gamma!r})", lambda g=gamma: fluid.shear_rate(g),
                    check=_nonnegative("shear rate"))
        yield Probe(entry, f"{tag}apparent_viscosity({gamma!r})", lambda g=gamma: fluid.apparent_viscosity(g),
                    check=_nonnegative("viscosity"))
    for radius, g in ((1e-4, 1e-300), (1e-4, 1e300), (1e-300, 1e3), (1e300, 1e-300)):
        yield Probe(entry, f"{tag}flow_rate({radius!r}, {g!r})", lambda r=radius, gg=g: fluid.flow_rate(r, gg),
                    check=_flow_rate_check(fluid, radius, g))
        yield Probe(entry, f"{tag}velocity(r, {radius!r}, {g!r})", lambda r=radius, gg=g: _velocities(fluid, r, gg),
                    check=_velocity_check)
    for q in (1e-300, 1e300):
        yield Probe(entry, f"{tag}pressure_gradient({q!r}, 1e-4)", lambda qq=q: fluid.pressure_gradient(qq, 1e-4),
                    check=_nonnegative("pressure gradient"))


def _law(fluid, gamma):
    stress = fluid.stress(gamma)
    return stress, fluid.shear_rate(stress)


def _fluid_at(fluid):
    """A fluid (returned along, for the check) at moderate arguments: its law, a flow rate and a
    velocity profile."""
    g = 1e3
    return fluid, _law(fluid, 1.0), fluid.flow_rate(1e-4, g), _velocities(fluid, 1e-4, g)


def _fluid_at_check(result):
    fluid, law, q, v = result
    return _law_check(fluid, 1.0)(law) or _flow_rate_check(fluid, 1e-4, 1e3)(q) or _velocity_check(v)


def _rheology_probes(name):
    cls = registry.rheologies[name]
    entry = f"rheology:{name}"
    yield from _rheology_method_probes(cls(**cls._examples[0]), entry)
    for label, kwargs in _variants(cls):
        yield Probe(entry, f"{label}: moderate arguments", lambda kw=kwargs: _fluid_at(cls(**kw)),
                    check=_fluid_at_check)
        yield Probe(entry, f"{label}: velocity at G = 1e300",
                    lambda kw=kwargs: _velocities(cls(**kw), 1e-4, 1e300), check=_velocity_check)


# ------------------------------------------------------------------------------------------ solve
def _huge_drop(fluid, wall, tube, drop):
    sol = solve(fluid, wall, tube, pressure_drop=drop)
    z = np.linspace(0.0, float(sol.tube.length), 3)
    return sol, sol.pressure(z), sol.velocity(0.0, z)


def _huge_drop_check(fluid, drop):
    def check(result):
        sol, p, v = result
        q = sol.flow_rate
        if q < 0 or np.any(v < 0) or np.any(np.diff(p) > 0):
            return f"q={q!r}, p(z)={p!r}, v(0, z)={v!r}"
        if abs(p[0] - sol.inlet_pressure) > 1e-9 * sol.inlet_pressure:
            return f"p(0)={p[0]!r}, inlet pressure {sol.inlet_pressure!r}"
        # the wall stress at the undeformed radius far beyond the yield stress: the fluid flows
        a, length = float(sol.tube.radius), float(sol.tube.length)
        if (q == 0 or np.any(v == 0)) and drop * a / (2.0 * length) > 10.0 * float(fluid.yield_stress):
            return f"no flow (q={q!r}, v(0, z)={v!r}) at a wall stress far beyond the yield stress"
        return None

    return check


def _solve_probes(chosen):
    tube = Tube(**_TUBE)
    for fluid, wall, tag in chosen.pairs():
        if not tag.split()[0].endswith("#0"):
            continue
        yield Probe("solve", f"{tag} pressure_drop={_HUGE_DROP:g}: profiles",
                    lambda f=fluid, w=wall: _huge_drop(f, w, tube, _HUGE_DROP), check=_huge_drop_check(fluid, _HUGE_DROP))


def extremes_family(chosen):
    """The family: every named wall and rheology at extreme valid values, and each pair at a huge drop."""
    for name in chosen.walls:
        yield from _wall_probes(name)
    for name in chosen.rheologies:
        yield from _rheology_probes(name)
    yield from _solve_probes(chosen)
