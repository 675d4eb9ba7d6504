"""Reproduce the chapter's two figures, as printed and consistent (PNG and CSV).

The chapter (Anand & Christov, "On the deformation of a hyperelastic tube due to steady
viscous flow within") plots the dimensionless pressure drop against the dimensionless flow
rate for thin walls and thick walls (t/a = 0.3), n = 1 and n = 0.7, several FSI parameters,
hyperelastic (solid) against linear (dashed). This script draws each figure twice:

(a) **as printed** — its labelling "beta = 3 gamma" (the hyperelastic curve of label beta
    uses gamma = beta/3), its printed thin closed form (no factor 3) and its printed thick
    deflection ODE (no factor 4), and its linear closed forms;
(b) **consistent** — the physical scene of each curve solved by ``tubefsi.solve``, with
    gamma = 3 beta (E = 3 mu: the hyperelastic and the linear wall of one colour have the
    same small-strain stiffness). Thin walls use the chapter's reference-thickness law.

Parameter values (the chapter prints none; :data:`tubefsi.chapter.CHAPTER_PARAMETERS`):
qbar in [0, 1] (201 points), beta in {0.5, 1, 2}, n in {1, 0.7}, thick t/a = 0.3, nu = 1/2.
Where a consistent shear-thinning thick tube has a maximum flow rate (``docs/theory.md``,
section "Limits"), its curve ends there (marked x).

Run: ``MPLBACKEND=Agg python examples/reproduce_chapter.py [OUT_DIR]`` (default
``out/chapter``); ``--docs`` writes only the PNGs, into ``docs/chapter`` (the figures of
``docs/verification.md``); ``--points N`` draws each curve with N points instead of 201 (a
quick check). The code is :func:`tubefsi.chapter.reproduce_chapter`.
"""

import argparse
import sys
import time
from pathlib import Path

from tubefsi.chapter import reproduce_chapter

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=ROOT / "out" / "chapter", type=Path,
                        help="output directory (default: the repository's out/chapter)")
    parser.add_argument("--docs", action="store_true", help="write only the PNGs, into docs/chapter")
    parser.add_argument("--points", type=int, default=None, metavar="N",
                        help="points per curve (default 201, the published figures)")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.docs:
        out, formats = ROOT / "docs" / "chapter", ("png",)
    else:
        out, formats = args.out, ("png", "csv")
    t0 = time.perf_counter()
    reproduce_chapter(out, points=args.points, formats=formats, file=sys.stdout)
    print(f"done in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
