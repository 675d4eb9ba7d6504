r"""Cost of a soft-tube network against the linear rigid Newtonian network of the same graph.

Run ``python benchmarks/network.py`` (about a minute on two cores); ``--quick`` for a smoke test
(small trees, numbers meaningless); ``--json FILE`` to also write the table.

The graph: a random binary tree of ``2^d - 1`` tubes (``d`` = 12 and 15: 4095 and 32767 tubes).
The root tube leaves the inlet node at a fixed pressure; every leaf ends at a node at zero
pressure. Each generation's radius is its parent's times ``2^(-1/3)`` (Murray's law) times a
random factor in [0.85, 1.15]; lengths are 40 radii times a random factor in [0.7, 1.3]; the wall
thickness is 0.3 radii times [0.8, 1.2]; the shear modulus of each thick neo-Hookean wall is
4 kPa times [0.5, 2]. The fluid is one power law (m = 0.01 Pa s^n, n = 0.8). The inlet pressure
is 85 % of the smallest limit pressure of the tree, so the tubes near the root inflate strongly.

The two timed solves, side by side in alternating passes in one process (median of the passes):

* **nonlinear**: ``Network.solve()`` — grouping, the rigid start, Newton with one broadcast
  ``tubefsi.solve`` per iteration, to a mass balance of 1e-13 of the throughput;
* **linear**: the rigid Newtonian network of the same graph written as a careful user would:
  Hagen–Poiseuille conductances ``pi a^4 / (8 mu L)`` (NumPy), the weighted graph Laplacian
  assembled with ``scipy.sparse.coo_matrix``, and ``scipy.sparse.linalg.spsolve`` for the free
  pressures.

The target (issue 12): nonlinear / linear <= 100 for 4095 tubes.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse import linalg as spla

import tubefsi
from tubefsi.registry import rheologies, walls

TARGET = 100.0


def random_tree(depth, seed=0):
    """Arrays of a random binary tree of 2^depth - 1 tubes: parent node, child node, radius,
    thickness, length, shear modulus (tube i runs from node parent[i] to node i + 1; node 0 is the inlet)."""
    rng = np.random.default_rng(seed)
    n = 2**depth - 1
    child = np.arange(1, n + 1)
    parent = np.where(child == 1, 0, child // 2)       # heap order below the root tube 0 -> 1
    generation = np.floor(np.log2(child)).astype(int)
    radius = 1e-4 * 2.0 ** (-generation / 3) * rng.uniform(0.85, 1.15, n)
    thickness = 0.3 * radius * rng.uniform(0.8, 1.2, n)
    length = 40 * radius * rng.uniform(0.7, 1.3, n)
    modulus = 4e3 * rng.uniform(0.5, 2.0, n)
    return parent, child, radius, thickness, length, modulus


def build_network(depth, seed=0):
    parent, child, radius, thickness, length, modulus = random_tree(depth, seed)
    fluid = rheologies["power-law"](consistency=0.01, index=0.8)
    net = tubefsi.Network(rheology=fluid)
    for i in range(parent.size):
        net.add_tube(int(parent[i]), int(child[i]), walls["thick-neo-hookean"](shear_modulus=float(modulus[i])),
                     tubefsi.Tube(radius=float(radius[i]), thickness=float(thickness[i]), length=float(length[i])))
    limit = np.min(modulus * np.log1p(thickness / radius))
    p_in = 0.85 * limit
    net.set_pressure(0, p_in)
    leaves = set(child.tolist()) - set(parent.tolist())
    for leaf in leaves:
        net.set_pressure(leaf, 0.0)
    return net, p_in


def linear_solve(parent, child, radius, length, p_in, viscosity=1e-2):
    """The rigid Newtonian network: Laplacian assembly and one sparse solve."""
    n_nodes = child.size + 1
    c = math.pi * radius**4 / (8 * viscosity * length)
    rows = np.concatenate([parent, parent, child, child])
    cols = np.concatenate([parent, child, parent, child])
    vals = np.concatenate([c, -c, -c, c])
    lap = sp.coo_matrix((vals, (rows, cols)), shape=(n_nodes, n_nodes)).tocsr()
    fixed = np.zeros(n_nodes, dtype=bool)
    fixed[0] = True
    fixed[np.setdiff1d(child, parent)] = True
    p = np.zeros(n_nodes)
    p[0] = p_in
    free = np.flatnonzero(~fixed)
    rhs = -lap[free][:, fixed] @ p[fixed]
    p[free] = spla.spsolve(lap[free][:, free].tocsc(), rhs)
    return p


def measure(depth, passes):
    net, p_in = build_network(depth)
    parent, child, radius, thickness, length, modulus = random_tree(depth)
    result = net.solve()                 # warm caches; checked below
    linear_solve(parent, child, radius, length, p_in)
    t_non, t_lin = [], []
    for k in range(passes):
        order = (0, 1) if k % 2 == 0 else (1, 0)
        for which in order:
            t0 = time.perf_counter()
            if which == 0:
                result = net.solve()
                t_non.append(time.perf_counter() - t0)
            else:
                linear_solve(parent, child, radius, length, p_in)
                t_lin.append(time.perf_counter() - t0)
    table = result.node_table()
    balance = max(abs(x) for x, fixed in zip(table["inflow"], table["fixed"]) if not fixed)
    through = result.flow_rate[(0, 1)]
    tubes = result.tube_table()
    strain = float(np.max(np.maximum(tubes["radius_u"], tubes["radius_v"]) / radius - 1))
    return {"tubes": int(child.size), "nonlinear_s": statistics.median(t_non), "linear_s": statistics.median(t_lin),
            "ratio": statistics.median(t_non) / statistics.median(t_lin), "iterations": result.iterations,
            "mass_balance": balance / through, "max_strain": strain}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small trees, one pass (a smoke test)")
    parser.add_argument("--json", help="also write the rows to this JSON file")
    args = parser.parse_args(argv)
    depths, passes = ((6, 8), 1) if args.quick else ((12, 15), 5)
    rows = [measure(d, passes if d < 15 else 3) for d in depths]
    print(f"{'tubes':>7} {'nonlinear (s)':>14} {'linear (s)':>11} {'ratio':>7} {'Newton its':>10} "
          f"{'mass balance':>12} {'max strain':>10}")
    for r in rows:
        print(f"{r['tubes']:7d} {r['nonlinear_s']:14.4f} {r['linear_s']:11.5f} {r['ratio']:7.1f} "
              f"{r['iterations']:10d} {r['mass_balance']:12.1e} {r['max_strain']:10.3f}")
    print(f"target: ratio <= {TARGET:g} at 4095 tubes" + (" (quick run: sizes too small to judge)" if args.quick else ""))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"quick": args.quick, "rows": rows, "target": TARGET}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
