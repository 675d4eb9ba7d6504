"""
Inflating a soft actuator through its supply tube
=================================================

A soft actuator (a chamber of 0.1 ml that takes 10 µl per kPa) is fed through a thick
neo-Hookean tube (a = 0.25 mm, t = 0.1 mm, µ = 100 kPa) by a 20 kPa pressure step.
``tubefsi.evolve`` integrates the transient (``docs/transients.md``); left: the 90 % inflation
time against the tube's length for power-law fluids of index n (consistency 0.05 Pa sⁿ); right:
the chamber pressure of the 5 cm tube. A shear-thinning fluid fills faster through a long tube:
its resistance falls as the flow rises.
"""

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

wall = walls["thick-neo-hookean"](shear_modulus=1e5)
actuator = tubefsi.Chamber.linear(1e-7, 1e-11)          # V0 (m^3), dV/dp (m^3/Pa)
lengths = np.array([0.02, 0.05, 0.2])                   # m
fig, (ax_t, ax_p) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
for n in (0.5, 0.7, 1.0):
    fluid = rheologies["power-law"](consistency=0.05, index=n)
    t90 = []
    for length in lengths:
        tube = tubefsi.Tube(radius=2.5e-4, thickness=1e-4, length=length)
        # the span: six RC times, R from the steady flow at half the step
        resistance = 1e4 / tubefsi.solve(fluid, wall, tube, pressure_drop=1e4).flow_rate
        times = np.linspace(0.0, 6 * resistance * 1e-11, 31)
        r = tubefsi.evolve(fluid, wall, tube, times, inlet_pressure=2e4, outlet=actuator, rtol=1e-2)
        t90.append(r.settling_time(0.9))
        if length == 0.05:
            ax_p.semilogx(r.times[1:], r.chamber_pressure[1:] / 1e3, label=f"n = {n}")
    ax_t.loglog(lengths * 100, t90, "o-", label=f"n = {n}")
ax_t.set(xlabel="tube length (cm)", ylabel="90 % inflation time (s)")
ax_t.set_xticks(lengths * 100, [f"{v * 100:g}" for v in lengths], minor=False)
ax_t.set_xticks([], minor=True)
ax_p.set(xlabel="t (s)", ylabel="chamber pressure (kPa)", title="L = 5 cm")
ax_t.legend()
ax_p.legend()
plt.show()
