"""
At the edge of validity
=======================

A Newtonian fluid in a thin current-thickness neo-Hookean tube (a = 0.5 mm, t = 10 µm,
L = 5 cm, µ = 1 kPa) has a steady state at every flow rate (``max_flow_rate`` is ``inf``), but
its inlet stretch grows exponentially with the flow rate. ``solve`` warns with
:class:`tubefsi.ModelValidityWarning` once the deformed tube is no longer slender
(R_in/L > 0.1), and the diagnostics give the number. Past an inlet stretch of 1e15 the solver
refuses with :class:`tubefsi.StretchRangeError` (not a physical limit).
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

tube = tubefsi.Tube(radius=5e-4, thickness=1e-5, length=0.05)
wall = walls["thin-neo-hookean"](shear_modulus=1e3, thickness_convention="current")
water = rheologies["newtonian"](viscosity=1e-3)
print("max_flow_rate:", tubefsi.max_flow_rate(water, wall, tube))

q = np.geomspace(1e-9, 1.3e-6, 200)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", tubefsi.ModelValidityWarning)
    sol = tubefsi.solve(water, wall, tube, flow_rate=q)
for w in caught:
    print("warning:", w.message)

try:
    tubefsi.solve(water, wall, tube, flow_rate=1e-5)
except tubefsi.StretchRangeError as exc:
    print("error:", exc)

slender = sol.inlet_radius / tube.length
fig, ax = plt.subplots(figsize=(6.4, 4.2))
ax.loglog(q * 6e10, slender, lw=2)              # m^3/s -> µL/min
ax.axhline(tubefsi.validity.SLENDERNESS, color="C3", ls="--", label="R$_{in}$/L = 0.1: lubrication fails")
ax.fill_between(q * 6e10, slender, 1e20, where=slender > 0.1, color="C3", alpha=0.1)
ax.set_xlabel("flow rate (µL/min)")
ax.set_ylabel("deformed slenderness R$_{in}$/L")
ax.set_ylim(top=1e15)
ax.legend(loc="upper left")
plt.show()
