"""tubefsi demo: a blood-like shear-thinning fluid in a soft microfluidic tube.

The scene (SI units): a power-law fluid (consistency m = 0.017 Pa s^n, index
n = 0.7, a common fit for blood) flows through a tube of radius 100 um, wall
30 um, length 10 mm, made of a soft gel of shear modulus 2 kPa. The script

* compares five wall models of that one material at a few flow rates (rigid,
  thin/thick linear at its small-strain limit E = 3 mu, nu = 1/2, thin/thick
  neo-Hookean): pressure drop, inlet displacement and the coupler used;
* prints the maximum steady flow rate of each (finite only for the thick
  neo-Hookean wall, whose pressure saturates, with a shear-thinning fluid);
* writes figures: flow curves of all walls on one axes, pressure and radius
  profiles, the deformed tube with velocity profiles, and the tube laws.

Run it with ``make demo`` or ``MPLBACKEND=Agg python examples/demo.py [OUT_DIR]``
(default ``out/demo``); ``tubefsi demo --out DIR`` runs the same. The code is
:func:`tubefsi.cli.run_demo`; here is the heart of it::

    import tubefsi
    tube = tubefsi.Tube(radius=100e-6, thickness=30e-6, length=10e-3)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e3)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=[1e-10, 1e-9, 5e-9])
    sol.pressure_drop, sol.inlet_displacement, sol.coupler_name
    tubefsi.max_flow_rate(fluid, wall, tube)
"""

import sys
import time

from tubefsi.cli import run_demo


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    out_dir = argv[0] if argv else "out/demo"
    start = time.perf_counter()
    run_demo(out_dir)
    print(f"done in {time.perf_counter() - start:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
