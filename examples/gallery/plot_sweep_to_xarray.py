"""
A parameter sweep as an xarray Dataset
======================================

Array parameters broadcast with the load: here three power-law indices (a row) against 50
flow rates (a column) in one ``solve``. ``sol.to_xarray()`` names a dimension per axis after the
input that varies along it and carries the units; xarray then plots and writes it
(``ds.to_netcdf(...)``). Needs the optional extra ``tubefsi[xarray]``.
"""

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
fluid = rheologies["power-law"](consistency=0.017, index=np.array([0.6, 0.7, 0.8]))
wall = walls["thick-neo-hookean"](shear_modulus=2e3)
sol = tubefsi.solve(fluid, wall, tube, flow_rate=np.linspace(0.0, 5e-10, 50)[:, None])

ds = sol.to_xarray()
print(ds)
fig, ax = plt.subplots(figsize=(6.4, 4.2))
for n in ds["index"].values:
    curve = ds.sel(index=n)
    ax.plot(curve.pressure_drop / 1e3, curve.flow_rate * 6e10, label=f"n = {n:g}")
ax.set_xlabel("pressure drop (kPa)")
ax.set_ylabel("flow rate (µL/min)")
ax.legend(title="power-law index")
plt.show()
