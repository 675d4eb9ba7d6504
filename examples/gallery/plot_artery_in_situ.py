"""
An artery in situ: axial pre-stretch
====================================

The HGO media of the rabbit carotid (``walls["thick-hgo"].preset("rabbit-carotid-media")``)
installed at the axial stretches 1.5, 1.7 and 1.9, in tissue
whose pressure is 10 Pa above the outlet's. Left: each installed tube's law, in the radius
(the pre-stretch narrows the lumen at rest, by more than the factor :math:`1/\\sqrt{\\lambda_z}`
of an isotropic wall: the fibres are stretched at rest). Right: the lumen along the installed
length under the same flow (``docs/walls_beyond.md``, section "Arterial walls in situ").
"""

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

blood = rheologies["power-law"](consistency=0.017, index=0.7)
tube = tubefsi.Tube(radius=1.5e-3, thickness=4e-4, length=5e-2)          # stress-free, m
fig, (law, profile) = plt.subplots(1, 2, figsize=(10, 4))
for lz in (1.5, 1.7, 1.9):
    artery = walls["thick-hgo"].preset("rabbit-carotid-media", axial_stretch=lz)
    rest = tubefsi.solve(blood, artery, tube, flow_rate=0.0).tube        # the installed tube at rest
    tb = rest.reduced_thickness
    lam = np.linspace(artery.min_stretch(tb), 1.6, 200)
    law.plot(lam * rest.radius * 1e3, artery.pressure(lam, tb), label=f"$\\lambda_z$ = {lz}")
    sol = tubefsi.solve(blood, artery, tube, flow_rate=2e-6, outlet_pressure=1e3, external_pressure=1.01e3)
    z = np.linspace(0.0, sol.tube.length, 200)
    profile.plot(z * 1e3, sol.radius(z) * 1e3, label=f"$\\lambda_z$ = {lz}: $\\Delta p$ = {sol.pressure_drop:.0f} Pa")
law.set(xlabel="lumen radius R (mm)", ylabel="transmural pressure (Pa)", title="installed tube laws")
profile.set(xlabel="z along the installed tube (mm)", ylabel="R (mm)", title="q = 2 mL/s, outlet 10 Pa below rest")
law.legend()
profile.legend()
fig.tight_layout()
plt.show()
