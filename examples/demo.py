"""tubefsi demo: a blood-like shear-thinning fluid in a soft microfluidic tube.

The scene (SI units): a power-law fluid (consistency m = 0.017 Pa s^n, index
n = 0.7, a common fit for blood) flows through a tube of radius 100 um, wall
30 um, length 10 mm, made of a soft gel of shear modulus 2 kPa. The script

* compares five wall models of that one material at a few flow rates (rigid,
  thin/thick linear at its small-strain limit E = 3 mu, nu = 1/2, thin/thick
  neo-Hookean): pressure drop, inlet displacement and the coupler used;
* prints the maximum steady flow rate of each (finite only for the thick
  neo-Hookean wall, whose pressure saturates, with a shear-thinning fluid);
* writes four figures: flow curves of all walls (flow_curves.png), pressure and
  radius profiles (profiles.png), the deformed tube with velocity profiles
  (deformed_tube.png) and the tube laws (tube_laws.png).

Run it with ``make demo`` or ``MPLBACKEND=Agg python examples/demo.py [OUT_DIR]``
(default ``out/demo``). The heart of it::

    import tubefsi
    tube = tubefsi.Tube(radius=100e-6, thickness=30e-6, length=10e-3)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e3)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=[1e-10, 1e-9, 5e-9])
    sol.pressure_drop, sol.inlet_displacement, sol.coupler_name
    tubefsi.max_flow_rate(fluid, wall, tube)
"""

import math
import sys
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")                 # headless: the figures go to files
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi import plotting  # noqa: E402

# ---------------------------------------------------------------------------- the scene
TUBE = dict(radius=100e-6, thickness=30e-6, length=10e-3)      # m
FLUID = ("power-law", dict(consistency=0.017, index=0.7))       # Pa s^n, -
SHEAR_MODULUS = 2e3                                             # Pa (a soft gel)
FLOW_RATES = (1e-10, 1e-9, 5e-9, 1e-8)                          # m^3/s, the columns of the table


def demo_walls(shear_modulus=SHEAR_MODULUS):
    """The five walls, all of one material: the linear ones at its small-strain limit, E = 3 mu."""
    W = tubefsi.registry.walls
    E = 3.0 * shear_modulus
    return {
        "rigid": W["rigid"](),
        "thin-linear": W["thin-linear"](youngs_modulus=E, poisson_ratio=0.5),
        "thick-linear": W["thick-linear"](youngs_modulus=E, poisson_ratio=0.5),
        "thin-neo-hookean": W["thin-neo-hookean"](shear_modulus=shear_modulus),
        "thick-neo-hookean": W["thick-neo-hookean"](shear_modulus=shear_modulus),
    }


# ---------------------------------------------------------------------------- the table
def solve_table(fluid, walls, tube, qs):
    """For each wall: its maximum flow rate, and (coupler, pressure drops, inlet displacements in um).

    A flow rate at or beyond a wall's maximum has no steady state: its cells stay NaN. The table
    compares the walls on purpose where some leave their model's range (the linear walls beyond
    small strain, the softest tube beyond slender): those warnings are caught and returned, one
    line per wall, for the table's footnotes.
    """
    limits, rows, notes = {}, {}, {}
    for name, wall in walls.items():
        limits[name] = tubefsi.max_flow_rate(fluid, wall, tube)
        ok = qs < limits[name]
        dp = np.full(qs.shape, np.nan)
        u = np.full(qs.shape, np.nan)
        coupler = "-"
        if np.any(ok):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", tubefsi.ModelValidityWarning)
                sol = tubefsi.solve(fluid, wall, tube, flow_rate=qs[ok])   # all flow rates in one call
            dp[ok], u[ok], coupler = sol.pressure_drop, 1e6 * sol.inlet_displacement, sol.coupler_name
            notes[name] = [str(w.message).split(":")[0] for w in caught
                           if issubclass(w.category, tubefsi.ModelValidityWarning)]
        rows[name] = (coupler, dp, u)
    return limits, rows, notes


def print_table(title, rows, qs, column, fmt):
    """One table: a line per wall, a column per flow rate ("none" where there is no steady state)."""
    print(title)
    print(f"  {'wall':<19}{'coupler':<13}" + "".join(f"{q:>10.0e}" for q in qs))
    for name, row in rows.items():
        cells = "".join(f"{format(v, fmt):>10}" if np.isfinite(v) else f"{'none':>10}" for v in row[column])
        print(f"  {name:<19}{row[0]:<13}{cells}")
    print("")


# ---------------------------------------------------------------------------- the figures
def save(fig, out_dir, stem, written):
    path = out_dir / f"{stem}.png"
    fig.savefig(path, dpi=130)
    plt.close(fig)
    written.append(path)


def make_figures(fluid, walls, tube, limits, out_dir):
    """Write the four figures into ``out_dir``; return their paths."""
    written = []
    soft = walls["thick-neo-hookean"]
    q_max = limits["thick-neo-hookean"]
    # the curves stop at 90 % of the soft wall's maximum flow rate (beyond it: no steady state)
    if math.isfinite(q_max):
        q_curve = np.linspace(0.0, 0.9 * q_max, 200)
    else:
        q_curve = np.linspace(0.0, FLOW_RATES[-1], 200)
    colors = dict(zip(walls, ("0.15", "C0", "C2", "C1", "C3")))

    # 1. flow curves of every wall, linear axes and log-log axes; they run to 90 % of the soft
    #    wall's maximum flow rate on purpose, past where the inflated inlet stops being slender
    #    and the linear walls leave small strains (the table above warned: docs/scope.md)
    q_log = np.geomspace(1e-4 * q_curve[-1], q_curve[-1], 200)
    fig, (ax_lin, ax_log) = plt.subplots(1, 2, figsize=(11.5, 4.4), layout="constrained")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        for name, wall in walls.items():
            for ax, q_range in ((ax_lin, q_curve), (ax_log, q_log)):
                plotting.plot_flow_curve(fluid, wall, tube, flow_rates=q_range, ax=ax, rigid=False, label=name,
                                         color=colors[name])
    ax_log.set_xscale("log")
    ax_log.set_yscale("log")
    ax_log.autoscale_view()
    ax_lin.set_title("Flow curves: one material, five wall models")
    ax_log.set_title("the same, log–log: all agree at small loads")
    ax_log.get_legend().remove()
    save(fig, out_dir, "flow_curves", written)

    # 2. pressure and radius profiles along the soft tube, at eight flow rates up to where the
    #    inflated inlet leaves the slender-tube assumption (R_in = 0.1 L: docs/scope.md)
    tb = tube.reduced_thickness
    dp_slender = float(soft.pressure(tubefsi.validity.SLENDERNESS * tube.length / tube.radius, tb))
    q_slender = float(tubefsi.solve(fluid, soft, tube, pressure_drop=dp_slender).flow_rate)
    sol_curve = tubefsi.solve(fluid, soft, tube, flow_rate=np.linspace(0.0, 0.99 * q_slender, 8))
    save(plotting.plot_profiles(sol_curve), out_dir, "profiles", written)

    # 3. the deformed soft tube coloured by pressure, and its velocity profiles, at 5e-9 m^3/s
    sol = tubefsi.solve(fluid, soft, tube, flow_rate=FLOW_RATES[2])
    fig, (ax_t, ax_v) = plt.subplots(1, 2, figsize=(12.5, 4.2), layout="constrained",
                                     gridspec_kw=dict(width_ratios=[1.8, 1.0]))
    plotting.plot_deformed_tube(sol, ax=ax_t)
    plotting.plot_velocity_profiles(sol, ax=ax_v)
    save(fig, out_dir, "deformed_tube", written)

    # 4. the tube laws: in kPa up to a stretch of 3, and at small strains divided by the one
    #    shear modulus mu of the material (one scale per panel, stated on its axis)
    fig, (ax_pa, ax_n) = plt.subplots(1, 2, figsize=(11.5, 4.4), layout="constrained")
    for name, wall in walls.items():
        plotting.plot_tube_law(wall, tb, ax=ax_pa, max_stretch=3.0, color=colors[name])
        if not wall.is_rigid:
            plotting.plot_tube_law(wall, tb, ax=ax_n, max_stretch=1.25, normalize=SHEAR_MODULUS,
                                   scale_name=r"\mu", color=colors[name])
    ax_pa.set_title(f"Tube laws of one material ($\\mu$ = {SHEAR_MODULUS:g} Pa, E = 3$\\mu$, "
                    f"t/a = {tb:.3g})", fontsize=10)
    ax_n.set_title("Small strains: each linear wall is the tangent of its neo-Hookean one", fontsize=10)
    ax_pa.legend(frameon=False, loc="upper left")
    ax_n.legend(frameon=False, loc="lower right")
    save(fig, out_dir, "tube_laws", written)
    return written


# ---------------------------------------------------------------------------- main
def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    out_dir = Path(argv[0] if argv else "out/demo")
    out_dir.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()

    tube = tubefsi.Tube(**TUBE)
    fluid = tubefsi.registry.rheologies[FLUID[0]](**FLUID[1])
    walls = demo_walls()
    qs = np.array(FLOW_RATES)

    print(f"tubefsi {tubefsi.__version__} demo: power-law fluid (m = {fluid.consistency:g} Pa s^n, "
          f"n = {fluid.index:g}) in a soft tube")
    print(f"  tube a = {tube.radius * 1e6:g} um, t = {tube.thickness * 1e6:g} um, L = {tube.length * 1e3:g} mm "
          f"(t/a = {tube.reduced_thickness:g}); wall shear modulus mu = {SHEAR_MODULUS:g} Pa, linear walls "
          f"E = 3 mu, nu = 0.5")
    print("")

    limits, rows, notes = solve_table(fluid, walls, tube, qs)
    print_table("pressure drop (Pa) at flow rate q (m^3/s):", rows, qs, 1, ".1f")
    print_table("inlet wall displacement R(0) - a (um) at flow rate q (m^3/s):", rows, qs, 2, ".2f")
    if any(notes.values()):
        print("outside the models' range, shown on purpose to compare the walls (docs/scope.md):")
        for name, lines in notes.items():
            for line in lines:
                print(f"  {name}: {line}")
        print("")
    print("maximum steady flow rate (m^3/s):")
    for name, q_max in limits.items():
        if math.isfinite(q_max):
            note = f"  (the wall's limit pressure is {walls[name].limit_pressure(tube.reduced_thickness):.1f} Pa)"
        else:
            note = "  (every flow rate has a steady state)"
        print(f"  {name:<19}{q_max:.6g}{note}")
    print("")

    for path in make_figures(fluid, walls, tube, limits, out_dir):
        print(f"wrote {path}")
    print(f"done in {time.perf_counter() - start:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
