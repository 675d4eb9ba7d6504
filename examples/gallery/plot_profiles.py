"""
Pressure and radius along the tube
==================================

``sol.plot()`` draws the profiles of a solution: the pressure falls from the inlet to the
outlet and the tube, inflated by it, narrows towards the outlet. A curve of loads gives one
line per load.
"""

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

tube = tubefsi.Tube(radius=100e-6, thickness=30e-6, length=10e-3)
fluid = rheologies["power-law"](consistency=0.017, index=0.7)
wall = walls["thick-neo-hookean"](shear_modulus=2e3)

sol = tubefsi.solve(fluid, wall, tube, flow_rate=np.array([1e-10, 5e-10, 1e-9, 2e-9]))
sol.plot()
plt.show()
