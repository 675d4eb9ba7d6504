"""What the C allocator costs a large broadcast solve: ``python benchmarks/allocator.py``.

The random-scene sweep of ``benchmarks/speed.py`` (its "random scenes" row: 10^4 scenes, every parameter random,
one broadcast call) is timed in two fresh processes that differ only in glibc's malloc settings:
the defaults, and ``GLIBC_TUNABLES`` keeping freed memory in the process
(``glibc.malloc.trim_threshold``, ``glibc.malloc.mmap_threshold``). With the defaults, glibc
returns the arrays of a call (megabytes: points x quadrature nodes) to the system when they are
freed and the next call takes a page fault per 4 KiB to get them back; the script prints the
minor page faults and the time per call of each. tubefsi does not change the allocator itself:
that is a setting of the whole process, which a library has no business changing; a user whose
work is such sweeps can set the variable (docs/benchmarks.md, "The allocator").

Linux with glibc only: elsewhere the variable does nothing and the two rows agree (without
POSIX's ``resource`` module, on Windows, the fault column says "n/a").
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys

TUNABLES = "glibc.malloc.trim_threshold=268435456:glibc.malloc.mmap_threshold=33554432"

CHILD = r"""
import json, sys, time
try:
    import resource
except ImportError:                               # not POSIX: no fault count
    resource = None
sys.path.insert(0, {here!r})
import numpy as np
import speed
rng = np.random.default_rng(20240613)
sets = [speed.random_scenes({points}, rng) for _ in range({calls} + 1)]
speed.broadcast_solve(sets[-1])                   # warm-up: tables, caches
times, faults = [], []
def minor_faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt if resource is not None else 0
for s in sets[:-1]:
    f0 = minor_faults()
    t0 = time.perf_counter()
    speed.broadcast_solve(s)
    times.append(time.perf_counter() - t0)
    faults.append(minor_faults() - f0 if resource is not None else None)
print(json.dumps({{"times": times, "faults": faults}}))
"""


def run(tunables, calls, points):
    """One fresh process: glibc's defaults (``tunables`` None: any GLIBC_TUNABLES of this
    process's environment removed) or ``tunables`` added to those already set."""
    env = dict(os.environ)
    already = env.pop("GLIBC_TUNABLES", "")
    if tunables is not None:
        env["GLIBC_TUNABLES"] = f"{already}:{tunables}" if already else tunables
    code = CHILD.format(here=os.path.dirname(os.path.abspath(__file__)), calls=calls, points=points)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    """Print the table; ``--quick``: 200 scenes, two calls, one process each (a smoke test)."""
    quick = "--quick" in (sys.argv[1:] if argv is None else argv)
    points, calls, rounds = (200, 2, 1) if quick else (10_000, 7, 3)
    rows = {"glibc defaults": None, "GLIBC_TUNABLES set": TUNABLES}
    got = {name: {"times": [], "faults": []} for name in rows}
    for r in range(rounds):                       # alternate the two, as speed.py does its passes
        for name in (list(rows) if r % 2 == 0 else list(rows)[::-1]):
            result = run(rows[name], calls, points)
            got[name]["times"] += result["times"]
            got[name]["faults"] += result["faults"]
    print(f"{points} random scenes (the random-scenes row of benchmarks/speed.py), one broadcast call; {rounds} "
          f"process{'es' if rounds > 1 else ''} x {calls} calls each")
    print(f"{'malloc':<22}{'ms per call (median)':>22}{'range':>16}{'minor faults per call (median)':>34}")
    medians = {}
    for name, g in got.items():
        medians[name] = statistics.median(g["times"])
        faults = [f for f in g["faults"] if f is not None]
        shown = f"{statistics.median(faults):.0f}" if faults else "n/a"
        print(f"{name:<22}{medians[name] * 1e3:>22.2f}{min(g['times']) * 1e3:>8.2f}-{max(g['times']) * 1e3:<7.2f}"
              f"{shown:>34}")
    ratio = medians["glibc defaults"] / medians["GLIBC_TUNABLES set"]
    print(f"ratio (defaults / tunables): {ratio:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
