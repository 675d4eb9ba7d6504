"""
Flow curves of one material in five wall models
===============================================

A blood-like power-law fluid (m = 0.017 Pa s^n, n = 0.7) in a soft tube (a = 100 µm,
t = 30 µm, L = 10 mm, shear modulus 2 kPa). The rigid tube is Hagen–Poiseuille; the linear
walls are the small-strain limit of the neo-Hookean ones (E = 3µ, ν = 1/2); only the thick
neo-Hookean wall has a limit pressure, hence a maximum steady flow rate for this
shear-thinning fluid (dashed line). The linear walls are drawn past their range on purpose: over
most of their curves the inlet strain is past the 5 % of their small-strain theory, and the
``ModelValidityWarning`` that says so is caught and printed below the figure. Each curve stops
where the inflated inlet would reach a tenth of the tube's length (the slender-tube limit), and
the axes are in µL/min and Pa.
"""

import warnings

import matplotlib.pyplot as plt

import tubefsi
from tubefsi.plotting import plot_flow_curve
from tubefsi.registry import rheologies, walls

tube = tubefsi.Tube(radius=100e-6, thickness=30e-6, length=10e-3)      # m
fluid = rheologies["power-law"](consistency=0.017, index=0.7)         # Pa s^n, -
mu = 2e3                                                               # Pa

fig, ax = plt.subplots(figsize=(6.4, 4.4))
for label, wall in [("thin linear", walls["thin-linear"](youngs_modulus=3 * mu, poisson_ratio=0.5)),
                    ("thick linear", walls["thick-linear"](youngs_modulus=3 * mu, poisson_ratio=0.5)),
                    ("thin neo-Hookean", walls["thin-neo-hookean"](shear_modulus=mu)),
                    ("thick neo-Hookean", walls["thick-neo-hookean"](shear_modulus=mu))]:
    with warnings.catch_warnings(record=True) as caught:       # the linear walls, past their range
        warnings.simplefilter("always", tubefsi.ModelValidityWarning)
        plot_flow_curve(fluid, wall, tube, ax=ax, label=label, rigid=label == "thin linear")
    for w in caught:
        print(f"{label}: {str(w.message).split(':')[0]} (drawn on purpose, to compare)")
ax.legend(loc="lower right")
ax.set_title("power-law fluid, n = 0.7, in a 2 kPa tube")
plt.show()
