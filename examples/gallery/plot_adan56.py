"""
An arterial network: ADAN56
===========================

The 77 vessels of ADAN56 (Blanco et al., *IEEE Trans. Biomed. Eng.* 62:736–753, 2015), from
the aortic root to the tibial arteries, as the openBF model hub publishes them: one row per
vessel with its length, its proximal and distal radius, its Young's modulus and, at the 31
terminal vessels, a three-element Windkessel (``tubefsi.datasets.adan56()``; source and
license in ``src/tubefsi/data/README.md``). ``tubefsi.read_network_table`` makes the network
(``docs/network.md``, "Files"):

* the walls are openBF's tube law, a thin linear elastic wall with :math:`\\nu = 1/2` and the
  empirical thickness :math:`h(R)` of Avolio (1980);
* the blood is a Carreau fluid (Cho & Kensey 1991: :math:`\\mu_0 = 0.056` Pa s,
  :math:`\\mu_\\infty = 0.0035` Pa s, :math:`\\lambda = 3.313` s, :math:`n = 0.3568`);
* the mean cardiac output, 5 L/min, enters at the aortic root (node 1), and every terminal
  takes :math:`(p - p_d)/(R_1 + R_2)` to a distal pressure :math:`p_d = 0`: the steady state of
  its Windkessel (the compliance :math:`C` carries no flow at steady state).

39 of the vessels taper (:math:`R_p \\ne R_d`); here each is the uniform tube of its mean
radius (``taper="mean"``). The linear tapers (the default) are graded edges, integrated along
their length at every Newton step: about 100 s of CPU for this network with Newtonian blood, and the
root pressure moves by 0.01 % (``docs/network.md``, "ADAN56").

The mean pressure at the root comes out near 76 mmHg, close to the parallel resistance of the
terminals times the cardiac output (the arteries themselves take a few mmHg). tubefsi says
what the model stretches: with a modulus of 225 kPa the walls reach hoop strains near 0.3,
beyond the small strains of a linear wall, and the short aortic segments (a few mm long,
8–16 mm wide) are not slender, so lubrication theory is an approximation there; both
come as ``ModelValidityWarning``, printed below.
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies

blood = rheologies["carreau"](zero_shear_viscosity=0.056, infinite_shear_viscosity=0.0035,
                              relaxation_time=3.313, index=0.3568)
net = tubefsi.read_network_table(tubefsi.datasets.adan56(), rheology=blood, taper="mean",
                                 distal_pressure=0.0)
net.set_inflow(1, 5e-3 / 60)                  # 5 L/min at the aortic root, m^3/s

with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", tubefsi.ModelValidityWarning)
    # a mass balance of 1e-10 of the throughput: the pressures' rounding (1e-16 of 10 kPa) through
    # the conductances of the short aortic segments allows about 1e-11
    result = net.solve(rtol=1e-10)
for w in caught:
    print("warning:", str(w.message).split(": ", 1)[-1][:110])

mmHg = 133.322
print(f"{len(net.nodes)} nodes, {len(net.tube_names)} vessels, {result.iterations} Newton iterations")
print(f"mean pressure at the aortic root: {result.pressure[1] / mmHg:.1f} mmHg")
table = tubefsi.network_io.network_table(net)     # the network's vessel table, as columns
terminal = np.array(table["R1"])[np.array(table["R1"]) > 0]
print(f"cardiac output x parallel terminal resistance: {5e-3 / 60 / np.sum(1 / terminal) / mmHg:.1f} mmHg")
for name in ("internal_carotid_R", "renal_L", "posterior_tibial_L"):
    print(f"{name:>20}: {result.flow_rate[name] * 6e7:6.1f} mL/min, "
          f"strain {result.strain_u[result.tube_index[name]]:.2f}")

fig, axes = plt.subplots(2, 1, figsize=(7.5, 8.0), layout="constrained")
result.plot(ax=axes[0], color="pressure", cmap="plasma")
axes[0].set_title("ADAN56: mean pressure, tubes as wide as their deformed radius", fontsize=10)
result.plot(ax=axes[1], color="flow_rate", cmap="viridis")
axes[1].set_title("flow rate; x: distance from the aortic root along the vessels", fontsize=10)
plt.show()
