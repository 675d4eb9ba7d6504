r"""Networks at scale, end to end: building, solving and reading every result, against the rigid
Newtonian sparse solve of the same graph.

Run ``python benchmarks/network_scale.py`` (a few minutes on two cores); ``--quick`` for a smoke
test (small graphs, numbers meaningless); ``--json FILE`` to also write the table.

The two graphs (issue 28, item 5):

* **lattice**: a 2-D capillary bed, an ``m x m`` square lattice of nodes (``m = 224``: 99 904
  segments, cycles everywhere); the left column at a fixed pressure, the right column at zero;
  radii 5 um times [0.7, 1.3], lengths 60 um times [0.8, 1.2], thickness 0.3 radii, thick
  neo-Hookean moduli 4 kPa times [0.5, 2]; the inlet pressure 60 % of the smallest limit pressure;
* **tree**: a random binary tree of ``2^17 - 1 = 131 071`` vessels as in ``benchmarks/network.py``
  (Murray's law with random factors), the root at 85 % of the smallest limit pressure, every leaf
  at zero.

The fluid is one power law (m = 0.01 Pa s^n, n = 0.8). Two timed runs, side by side in
alternating passes in one process (median of the passes):

* **nonlinear**: ``Network()`` + one ``add_tubes`` call from the arrays + the boundary conditions
  (one ``set_pressures`` call for the fixed nodes), ``solve()``, then reading every result: the arrays
  ``pressures``, ``flow_rates``, ``pressure_drops``, ``radius_u/v``, ``strain_u/v``,
  ``wall_shear_stress_u/v``, and every flow rate by name (``result.flow_rate[name]`` for every
  tube);
* **linear**: the rigid Newtonian network of the same graph written as a careful user would:
  Hagen–Poiseuille conductances ``pi a^4 / (8 mu L)``, the weighted Laplacian by
  ``scipy.sparse.coo_matrix`` (to CSR), the free block and the fixed columns by slicing,
  ``scipy.sparse.linalg.spsolve`` for the free pressures, and the flow of every tube from them.

The target (issue 28): nonlinear / linear <= 30 for each graph.
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

TARGET = 30.0
VISCOSITY = 1e-2


def lattice(m, seed=0):
    """Arrays of an m x m lattice: (u, v, radius, thickness, length, modulus, fixed nodes, their
    pressures). Node k = row * m + col; edges to the right and downwards."""
    rng = np.random.default_rng(seed)
    k = np.arange(m * m).reshape(m, m)
    u = np.concatenate([k[:, :-1].ravel(), k[:-1, :].ravel()])
    v = np.concatenate([k[:, 1:].ravel(), k[1:, :].ravel()])
    n = u.size
    radius = 5e-6 * rng.uniform(0.7, 1.3, n)
    thickness = 0.3 * radius
    length = 60e-6 * rng.uniform(0.8, 1.2, n)
    modulus = 4e3 * rng.uniform(0.5, 2.0, n)
    limit = float(np.min(modulus * np.log1p(thickness / radius)))
    fixed = np.concatenate([k[:, 0], k[:, -1]])
    p_fixed = np.concatenate([np.full(m, 0.6 * limit), np.zeros(m)])
    return u, v, radius, thickness, length, modulus, fixed, p_fixed


def tree(depth, seed=0):
    """Arrays of a random binary tree of 2^depth - 1 vessels (``benchmarks/network.py``)."""
    rng = np.random.default_rng(seed)
    n = 2**depth - 1
    v = np.arange(1, n + 1)
    u = np.where(v == 1, 0, v // 2)
    generation = np.floor(np.log2(v)).astype(int)
    radius = 1e-4 * 2.0 ** (-generation / 3) * rng.uniform(0.85, 1.15, n)
    thickness = 0.3 * radius * rng.uniform(0.8, 1.2, n)
    length = 40 * radius * rng.uniform(0.7, 1.3, n)
    modulus = 4e3 * rng.uniform(0.5, 2.0, n)
    limit = float(np.min(modulus * np.log1p(thickness / radius)))
    leaves = np.setdiff1d(v, u)
    fixed = np.concatenate([[0], leaves])
    p_fixed = np.concatenate([[0.85 * limit], np.zeros(leaves.size)])
    return u, v, radius, thickness, length, modulus, fixed, p_fixed


def nonlinear(graph):
    """Build (add_tubes), solve and read every result; returns the result and a checksum."""
    u, v, radius, thickness, length, modulus, fixed, p_fixed = graph
    net = tubefsi.Network(rheology=rheologies["power-law"](consistency=0.01, index=0.8))
    net.add_tubes(u, v, walls["thick-neo-hookean"](shear_modulus=modulus),
                  tubefsi.Tube(radius=radius, thickness=thickness, length=length))
    net.set_pressures(fixed, p_fixed)
    result = net.solve()
    total = 0.0
    for a in (result.pressures, result.flow_rates, result.pressure_drops, result.radius_u, result.radius_v,
              result.strain_u, result.strain_v, result.wall_shear_stress_u, result.wall_shear_stress_v):
        total += float(a[-1])
    by_name = result.flow_rate
    for name in result.tube_names:
        total += by_name[name]
    return result, total


def linear(graph):
    """The rigid Newtonian network: conductances, Laplacian, one sparse solve, every flow."""
    u, v, radius, thickness, length, modulus, fixed, p_fixed = graph
    n_nodes = int(max(u.max(), v.max())) + 1
    c = math.pi * radius**4 / (8 * VISCOSITY * length)
    rows = np.concatenate([u, u, v, v])
    cols = np.concatenate([u, v, u, v])
    vals = np.concatenate([c, -c, -c, c])
    lap = sp.coo_matrix((vals, (rows, cols)), shape=(n_nodes, n_nodes)).tocsr()
    is_fixed = np.zeros(n_nodes, dtype=bool)
    is_fixed[fixed] = True
    p = np.zeros(n_nodes)
    p[fixed] = p_fixed
    free = np.flatnonzero(~is_fixed)
    rhs = -(lap[free][:, fixed] @ p_fixed)
    p[free] = spla.spsolve(lap[free][:, free].tocsc(), rhs)
    return p, c * (p[u] - p[v])


def measure(label, graph, passes):
    result, _ = nonlinear(graph)          # warm caches; checked below
    linear(graph)
    t_non, t_lin = [], []
    for k in range(passes):
        for which in ((0, 1) if k % 2 == 0 else (1, 0)):
            t0 = time.perf_counter()
            if which == 0:
                result, _ = nonlinear(graph)
                t_non.append(time.perf_counter() - t0)
            else:
                linear(graph)
                t_lin.append(time.perf_counter() - t0)
    strain = float(np.max(np.maximum(result.strain_u, result.strain_v)))
    return {"graph": label, "tubes": len(result.tube_names), "nodes": len(result.nodes),
            "nonlinear_s": statistics.median(t_non), "linear_s": statistics.median(t_lin),
            "ratio": statistics.median(t_non) / statistics.median(t_lin), "iterations": result.iterations,
            "residual": result.residual, "max_strain": strain}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small graphs, one pass (a smoke test)")
    parser.add_argument("--json", help="also write the rows to this JSON file")
    args = parser.parse_args(argv)
    m, depth, passes = (12, 7, 1) if args.quick else (224, 17, 3)
    rows = [measure("lattice", lattice(m), passes), measure("tree", tree(depth), passes)]
    print(f"{'graph':>8} {'tubes':>7} {'nonlinear (s)':>14} {'linear (s)':>11} {'ratio':>7} {'Newton its':>10} "
          f"{'residual':>9} {'max strain':>10}")
    for r in rows:
        print(f"{r['graph']:>8} {r['tubes']:7d} {r['nonlinear_s']:14.3f} {r['linear_s']:11.4f} {r['ratio']:7.1f} "
              f"{r['iterations']:10d} {r['residual']:9.1e} {r['max_strain']:10.3f}")
    print(f"target: ratio <= {TARGET:g} end to end" + (" (quick run: sizes too small to judge)" if args.quick else ""))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"quick": args.quick, "rows": rows, "target": TARGET}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
