"""Reproducers of breaches once found, each with its check (those whose models are not registered
are left out)."""

from __future__ import annotations

import math

from ... import registry
from ...advise import advise
from ...geometry import Tube
from ...solve import max_flow_rate, solve
from ._core import _TUBE, Probe
from ._models import _round_trip, _small_drop


def _known_probes():
    """Reproducers of breaches once found (the issue tracker's fuzz campaign), each with its check;
    those whose models are not registered are left out."""
    R, W = registry.rheologies, registry.walls
    tube = Tube(**_TUBE)
    out = []

    def have(*names):
        return all(n in R or n in W for n in names)

    def drop_near(reference, rtol):
        def check(sol):
            dp = sol.pressure_drop
            return None if abs(dp - reference) <= rtol * reference else f"dp={dp!r}, reference {reference!r}"
        return check

    if have("power-law", "thick-neo-hookean", "rigid", "thin-linear"):
        nh = W["thick-neo-hookean"](shear_modulus=2e3)
        # 40-digit references (mpmath: the Lame tube law and the separated integral, tests/test_large_index.py)
        for n, reference in ((26.0, 1.3803462372831439), (30.0, 1.1497201863833393)):
            fluid = R["power-law"](consistency=0.017, index=n)
            out.append(Probe("solve", f"known: power law n={n:g}, thick NH, q=1e-12",
                             lambda f=fluid: solve(f, nh, tube, flow_rate=1e-12), check=drop_near(reference, 1e-12)))
            out.append(Probe("solve", f"known: power law n={n:g}, thick NH, dp={reference}",
                             lambda f=fluid, d=reference: solve(f, nh, tube, pressure_drop=d),
                             check=lambda sol: None if abs(sol.flow_rate - 1e-12) <= 1e-11 * 1e-12
                             else f"q={sol.flow_rate!r}, reference 1e-12"))
            for w in ("rigid", "thin-linear"):
                wall = W[w](**W[w]._examples[0])
                out.append(Probe("solve", f"known: power law n={n:g}, {w}, q=1e-12",
                                 lambda f=fluid, wl=wall: solve(f, wl, tube, flow_rate=1e-12),
                                 check=_round_trip("flow_rate", 1e-12)))
        fluid = R["power-law"](consistency=0.017, index=0.7)
        out.append(Probe("solve", "known: solve(0.999999 max_flow_rate)",
                         lambda f=fluid, w=nh: solve(f, w, tube, flow_rate=0.999999 * max_flow_rate(f, w, tube))))
        p_half = 0.5 * nh.limit_pressure(0.3)
        for ratio in (1e6, 1e9, 1e12):     # q against the rigid tube at the outlet radius
            dp = p_half / ratio
            radius = tube.radius * nh.stretch(p_half, 0.3)
            q_ref = fluid.flow_rate(radius, dp / tube.length)
            out.append(Probe("solve", f"known: outlet pressure p_lim/2, p_out/dp={ratio:g}",
                             lambda d=dp, f=fluid, w=nh: solve(f, w, tube, pressure_drop=d, outlet_pressure=p_half),
                             check=lambda sol, r=q_ref, k=ratio: None if abs(sol.flow_rate - r) <= 1e-9 * r + 4 / k * r
                             else f"q={sol.flow_rate!r}, rigid-outlet reference {r!r}"))
        out.append(Probe("advise", "known: advise(flow_rate=0)",
                         lambda f=fluid, w=nh: advise(f, w, tube, flow_rate=0.0)))
        out.append(Probe("Tube", "known: t/a = 1e304", lambda f=fluid, w=nh: solve(
            f, w, Tube(radius=1e-300, thickness=1e4, length=1e-2), flow_rate=1e-9)))
        for name in ("thick-mooney-rivlin", "thick-neo-hookean", "thin-neo-hookean"):
            wall = W[name](**W[name]._examples[0])
            out.append(Probe(f"wall:{name}", "known: pressure(1e300, 0.3)", lambda w=wall: w.pressure(1e300, 0.3),
                             check=lambda p, w=wall: None if 0 < p <= w.limit_pressure(0.3) else f"p={p!r}"))
        thin = W["thin-neo-hookean"](shear_modulus=2e3)
        out.append(Probe("wall:thin-neo-hookean", "known: stretch(1e300 Pa)", lambda w=thin: w.stretch(1e300, 0.3),
                         check=lambda lam: None if abs(lam - 1e300 / 600.0) <= 1e-12 * lam else f"stretch {lam!r}"))
    if have("bingham", "thick-neo-hookean"):
        fluid = R["bingham"](yield_stress=0.5, plastic_viscosity=0.05)
        for w in ("thick-neo-hookean", "rigid"):
            wall = W[w](**W[w]._examples[0])

            def rest_profile(w=wall, f=fluid):
                sol = solve(f, w, tube, pressure_drop=50.0)
                return sol.pressure([0.0, 1e-12, 0.5 * tube.length]), sol.inlet_pressure

            out.append(Probe("Solution.pressure", f"known: Bingham below yield, {w}", rest_profile,
                             check=lambda r: None if r[0][0] == r[1] and r[0][0] >= r[0][1] > r[0][2] > 0
                             else f"pressure {r[0]!r}, inlet {r[1]!r}"))
    if have("thin-ogden", "thin-neo-hookean", "newtonian"):
        fluid = R["newtonian"](viscosity=1e-3)
        twin = W["thin-ogden"](moduli=(2e3,), exponents=(2.0,))
        nh = W["thin-neo-hookean"](shear_modulus=2e3)
        out.append(Probe("solve", "known: thin Ogden alpha=2 = thin neo-Hookean at dp=1e-8",
                         lambda f=fluid, a=twin, b=nh: (solve(f, a, tube, pressure_drop=1e-8).flow_rate,
                                                        solve(f, b, tube, pressure_drop=1e-8).flow_rate),
                         check=lambda q: None if abs(q[0] - q[1]) <= 1e-12 * q[1] else f"q={q[0]!r} vs {q[1]!r}"))
        tiny = W["thin-ogden"](moduli=(2e3,), exponents=(1e-16,))
        out.append(Probe("wall:thin-ogden", "known: exponent 1e-16 limits",
                         lambda w=tiny: (w.limit_pressure(0.3), w.max_stretch(0.3)), allow_inf=True,
                         check=lambda r: None if r[0] > 0 and (math.isfinite(r[1]) or math.isinf(r[0]))
                         else f"limit_pressure {r[0]!r} with max_stretch {r[1]!r}"))
    if have("thick-gent", "power-law"):
        fluid = R["power-law"](consistency=0.017, index=0.7)
        gent = W["thick-gent"](shear_modulus=2e3, locking_parameter=10.0)
        out.append(Probe("solve", "known: thick Gent Jm=10 at dp=1e5",
                         lambda f=fluid, w=gent: solve(f, w, tube, pressure_drop=1e5)))
    for name in ("carreau", "cross", "ellis", "carreau-yasuda"):
        if have(name, "thick-neo-hookean"):
            fluid = R[name](**R[name]._examples[0])
            nh = W["thick-neo-hookean"](shear_modulus=2e3)
            out.append(Probe("solve", f"known: {name} dp=1e-11 (inlet strain < 2e-14)",
                             lambda f=fluid, w=nh: solve(f, w, tube, pressure_drop=1e-11),
                             check=lambda sol, f=fluid: None if abs(sol.flow_rate / f.flow_rate(
                                 tube.radius, 1e-11 / tube.length) - 1) < 1e-10 else f"q={sol.flow_rate!r}"))
    if have("carreau-yasuda", "thick-linear"):     # the networks' dead end: NaN once, then ConvergenceError
        fluid = R["carreau-yasuda"](**R["carreau-yasuda"]._examples[0])
        lin = W["thick-linear"](youngs_modulus=6e3, poisson_ratio=0.5)
        for dp in (1e-14, 1e-100):
            out.append(Probe("solve", f"known: carreau-yasuda thick-linear dp={dp:g}, p_out=87.6",
                             lambda f=fluid, w=lin, d=dp: solve(f, w, tube, pressure_drop=d, outlet_pressure=87.6),
                             check=_small_drop(dp)))
    if have("carreau", "thick-gent"):
        fluid = R["carreau"](**R["carreau"]._examples[0])
        out.append(Probe("solve", "known: carreau thick-gent q=1e-300", lambda f=fluid: solve(
            f, W["thick-gent"](**W["thick-gent"]._examples[0]), tube, flow_rate=1e-300)))
    if have("carreau-yasuda", "thick-demiray"):
        fluid = R["carreau-yasuda"](**R["carreau-yasuda"]._examples[0])
        fung = W["thick-demiray"](shear_modulus=1082.1, stiffening=3.1333)
        long = Tube(radius=3.2235e-3, thickness=3.54e-4, length=1.4378)
        out.append(Probe("solve", "known: carreau-yasuda thick Demiray q=1.734e-11",
                         lambda f=fluid, w=fung, t=long: solve(f, w, t, flow_rate=1.734e-11)))
    return out

