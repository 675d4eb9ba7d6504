"""A parameter study over many networks, mapped over a dask bag (a local cluster of 2 workers).

Each sample is a Y bifurcation of thick neo-Hookean tubes carrying a power-law fluid: the feeding
tube from the inlet (fixed inflow) to the junction, two daughters to outlets at fixed pressures.
Every tube's shear modulus and the fluid's index are drawn at random (moduli log-uniform in [5, 50] kPa,
``n`` uniform in [0.5, 1]). The study asks how the inflow splits: the fraction through the first
daughter, and the inlet pressure. A sample whose inflow no steady state carries gets NaN.

How it scales: the samples are cut into batches, and each batch is solved as ONE network, the
disjoint union of its Ys (every component has its own fixed pressures, so the components do
not interact). One batch of ``B`` samples is one Newton solve with ``3B`` tubes, and each
iteration is one broadcast single-tube solve. The batches are the elements of a ``dask.bag``,
mapped on a ``distributed.LocalCluster`` of 2 single-threaded workers. On a real cluster only
the client changes: ``Client("tcp://scheduler-address:8786")`` (or a ``dask_jobqueue`` /
``dask_kubernetes`` cluster object) instead of the ``LocalCluster``. The same bag then runs on
every worker the scheduler has, and ``--batch`` sets the work per task (about 1 s of work per
batch of 2000 samples here). Without dask installed (the optional extra ``parallel``), the same
map runs serially in this process.

Run: ``python examples/network_study.py [OUT] [--samples N] [--batch B] [--serial]`` (the
default is 10^5 samples, several minutes on two cores); it writes ``study.csv`` and prints a
summary.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

INFLOW = 3e-10                 # m^3/s into each Y
OUTLETS = (0.0, 40.0)          # Pa at the two outlets
TUBES = ((1e-4, 3e-5, 1e-2), (8e-5, 2.5e-5, 8e-3), (7e-5, 2e-5, 1e-2))    # (a, t, L) in m


def draw(samples, seed=0):
    """The random parameters: shear moduli (samples, 3) in Pa and the fluid index (samples,)."""
    rng = np.random.default_rng(seed)
    moduli = np.exp(rng.uniform(np.log(5e3), np.log(5e4), (samples, 3)))
    index = rng.uniform(0.5, 1.0, samples)
    return moduli, index


def solve_batch(batch):
    """One batch ``(start, moduli, index)`` as one network (the disjoint union of its Ys);
    returns rows ``(sample, split fraction, inlet pressure, iterations)``. If some Y of the batch
    has no steady state (``NoSteadyStateError``), the batch is bisected down to that sample, whose
    row holds NaN."""
    start, moduli, index = batch
    try:
        return _solve_union(start, moduli, index)
    except tubefsi.NoSteadyStateError:
        if index.size == 1:
            return [(start, float("nan"), float("nan"), 0)]
        half = index.size // 2                 # bisect down to the samples without a steady state
        return solve_batch((start, moduli[:half], index[:half])) + \
            solve_batch((start + half, moduli[half:], index[half:]))


def _solve_union(start, moduli, index):
    net = tubefsi.Network()
    tubes = [tubefsi.Tube(radius=a, thickness=t, length=length) for a, t, length in TUBES]
    for i in range(index.size):
        fluid = rheologies["power-law"](consistency=0.01, index=float(index[i]))
        ends = [((i, "in"), (i, "j")), ((i, "j"), (i, 1)), ((i, "j"), (i, 2))]
        for (u, v), mu, tube in zip(ends, moduli[i], tubes):
            net.add_tube(u, v, walls["thick-neo-hookean"](shear_modulus=float(mu)), tube, rheology=fluid)
        net.set_inflow((i, "in"), INFLOW).set_pressure((i, 1), OUTLETS[0]).set_pressure((i, 2), OUTLETS[1])
    result = net.solve()
    flow, pressure = result.flow_rate, result.pressure
    return [(start + i, flow[((i, "j"), (i, 1))] / INFLOW, pressure[(i, "in")], result.iterations)
            for i in range(index.size)]


def batches(samples, batch, seed=0):
    moduli, index = draw(samples, seed)
    return [(s, moduli[s:s + batch], index[s:s + batch]) for s in range(0, samples, batch)]


def run(samples, batch, serial=False):
    """The rows of every sample and a note on how they were computed."""
    parts = batches(samples, batch)
    try:
        if serial:
            raise ImportError
        import dask.bag as db
        from dask.distributed import Client, LocalCluster
    except ImportError:
        return [row for part in parts for row in solve_batch(part)], "serially in this process"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster):
        bag = db.from_sequence(parts, npartitions=len(parts))
        rows = bag.map(solve_batch).flatten().compute()      # on the client's cluster
    return sorted(rows), "on a dask LocalCluster of 2 workers"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="network_study_out")
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--batch", type=int, default=2000, help="samples per task (one network each)")
    parser.add_argument("--serial", action="store_true", help="no dask, even if it is installed")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows, how = run(args.samples, args.batch, args.serial)
    elapsed = time.perf_counter() - t0
    split = np.array([r[1] for r in rows])
    p_in = np.array([r[2] for r in rows])
    ok = np.isfinite(split)
    split, p_in = split[ok], p_in[ok]
    print(f"{len(rows)} networks in {elapsed:.1f} s {how} ({len(rows) / elapsed:.0f} networks/s); "
          f"{int(np.sum(~ok))} without a steady state (an inflow beyond a tube's maximum)")
    print(f"split fraction to outlet 1: mean {split.mean():.4f}, 5-95 % [{np.percentile(split, 5):.4f}, "
          f"{np.percentile(split, 95):.4f}]")
    print(f"inlet pressure: mean {p_in.mean():.2f} Pa, 5-95 % [{np.percentile(p_in, 5):.2f}, "
          f"{np.percentile(p_in, 95):.2f}] Pa")
    with open(out / "study.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(["sample", "split_fraction", "inlet_pressure_Pa", "newton_iterations"])
        writer.writerows(rows)
    print(f"wrote {out / 'study.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
