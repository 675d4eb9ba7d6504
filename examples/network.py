"""A microvascular-like network of soft tubes: an arteriolar tree, capillaries, a venular tree.

Blood (a shear-thinning power law) enters the arteriole at a given flow rate and leaves the
venule at a fixed (transmural) pressure. The arteriolar tree bifurcates ``depth`` times with
Murray's law (each daughter ``2^(-1/3)`` of its parent's radius, times a random factor); its
terminal arterioles feed capillaries, which drain into a mirrored venular tree (wider, thinner
walled). Every vessel is a thick neo-Hookean tube. The network has loops: flow may take any
path from the arteriole to the venule.

Writes into the output directory: ``network.png`` (the network coloured by pressure, vessels as
wide as their deformed radius), ``network_nodes.csv``, ``network_tubes.csv``, ``network.json``
and ``generations.csv`` (flow and strain per generation, also printed with the solve's summary
and the inlet pressure of the rigid network: the same graph with rigid walls).

Run: ``python examples/network.py [OUT] [--depth N]``.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls


#: the inflow into the arteriole per capillary (m^3/s) and the venular outlet pressure (Pa)
PER_CAPILLARY, OUTLET = 5e-12 / 32, 100.0


def build(depth=5, seed=1, rigid=False):
    """The network; node names ("a", g, j) (arteriolar), ("v", g, j) (venular), positions set."""
    rng = np.random.default_rng(seed)
    blood = rheologies["power-law"](consistency=0.017, index=0.7)
    net = tubefsi.Network(rheology=blood)

    def wall(mu):
        return walls["rigid"]() if rigid else walls["thick-neo-hookean"](shear_modulus=mu)

    def vessel(a, t_over_a, length_over_a):
        return tubefsi.Tube(radius=a, thickness=t_over_a * a, length=length_over_a * a)

    x_end = 2 * depth + 3
    net.set_position("inlet", (-1.0, 0.0)).set_position("outlet", (x_end + 1.0, 0.0))
    for side, x0, sign in (("a", 0.0, 1), ("v", x_end, -1)):
        for g in range(depth + 1):
            for j in range(2**g):
                net.set_position((side, g, j), (x0 + sign * g, 10 * ((j + 0.5) / 2**g - 0.5)))
    radii = {}
    for side, root_radius, t_over_a, mu in (("a", 40e-6, 0.25, 6e3), ("v", 60e-6, 0.2, 5e3)):
        radii[(side, 0, 0)] = root_radius
        for g in range(1, depth + 1):
            for j in range(2**g):
                radii[(side, g, j)] = radii[(side, g - 1, j // 2)] * 2 ** (-1 / 3) * rng.uniform(0.9, 1.1)
        for (s, g, j), a in radii.items():
            if s != side:
                continue
            parent = ("inlet" if side == "a" else "outlet") if g == 0 else (side, g - 1, j // 2)
            tube = vessel(a, t_over_a, 30 * rng.uniform(0.7, 1.3))
            modulus = mu * rng.uniform(0.7, 1.4)
            if side == "a":
                net.add_tube(parent, (s, g, j), wall(modulus), tube)
            else:
                net.add_tube((s, g, j), parent, wall(modulus), tube)
    for j in range(2**depth):                               # capillaries: arteriole j -> venule j
        a = 5e-6 * rng.uniform(0.8, 1.2)
        net.add_tube(("a", depth, j), ("v", depth, j), wall(4e3 * rng.uniform(0.7, 1.4)), vessel(a, 0.3, 100))
    net.set_inflow("inlet", PER_CAPILLARY * 2**depth).set_pressure("outlet", OUTLET)
    return net


def generation_table(result, depth):
    """Rows (kind, generation, vessels, mean flow rate, mean strain at the inflow end)."""
    table = result.tube_table()
    rows = []
    for kind in ("arteriole", "capillary", "venule"):
        for g in range(depth + 1) if kind != "capillary" else [depth + 1]:
            flows, strains = [], []
            for name, q, ru, rv in zip(table["name"], table["flow_rate"], table["radius_u"], table["radius_v"]):
                u, v = name
                if kind == "arteriole" and isinstance(v, tuple) and v[0] == "a" and v[1] == g \
                        or kind == "venule" and isinstance(u, tuple) and u[0] == "v" and u[1] == g \
                        or kind == "capillary" and isinstance(u, tuple) and isinstance(v, tuple) and u[0] != v[0]:
                    a = result.net._tubes[name].tube.radius
                    flows.append(q)
                    strains.append(max(ru, rv) / a - 1)
            rows.append((kind, g, len(flows), float(np.mean(flows)), float(np.mean(strains))))
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="network_out")
    parser.add_argument("--depth", type=int, default=5, help="bifurcations of each tree (default 5)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    net = build(args.depth)
    result = net.solve()
    rigid = build(args.depth, rigid=True).solve()
    inflow = PER_CAPILLARY * 2**args.depth
    print(f"{len(result.nodes)} nodes, {len(result.tube_names)} vessels; Newton iterations: {result.iterations}; "
          f"largest mass imbalance / throughput: {result.residual:.1e}")
    print(f"inlet pressure: soft {result.pressure['inlet']:.6g} Pa, rigid {rigid.pressure['inlet']:.6g} Pa "
          f"(outlet {OUTLET:g} Pa, inflow {inflow:g} m^3/s)")
    print(f"{'vessels':>10} {'gen':>4} {'count':>5} {'mean q (m^3/s)':>15} {'mean strain':>12}")
    rows = generation_table(result, args.depth)
    for kind, g, count, q, strain in rows:
        print(f"{kind:>10} {g:4d} {count:5d} {q:15.4e} {strain:12.4f}")
    with open(out / "generations.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(["vessels", "generation", "count", "mean flow rate (m^3/s)", "mean strain"])
        writer.writerows([kind, g, count, f"{q:.4e}", f"{strain:.4f}"] for kind, g, count, q, strain in rows)

    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(10, 5.5), layout="constrained")
    result.plot(ax=ax)
    ax.set_title(f"microvascular-like network: {len(result.tube_names)} soft vessels, "
                 f"inflow {inflow:g} m$^3$/s", fontsize=10)
    ax.figure.savefig(out / "network.png", dpi=150)
    result.to_csv(out / "network")
    result.to_json(out / "network.json")
    print(f"wrote {out / 'network.png'}, {out / 'network_nodes.csv'}, {out / 'network_tubes.csv'}, "
          f"{out / 'network.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
