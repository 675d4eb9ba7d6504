"""
A stenosed tube
===============

A soft tube of inner radius 1 mm with a smooth stenosis halfway along (the lumen narrowed by
40 %), blood-like shear-thinning fluid, neo-Hookean wall (``docs/graded.md``). The radius is a
function of the axial position ``z``:

* with the wall thickness proportional to the radius (``t/a`` constant, a uniform material) the
  tube law is the same at every section and the problem still separates: tubefsi solves the
  uniform tube of the *equivalent length* :math:`\\int_0^L (a(L)/a(z))^{3n+1}dz`, exactly;
* with a wall of constant thickness (``t/a`` larger in the throat) it does not, and tubefsi
  integrates the lubrication ODE along ``z`` with error control.

Much of the pressure drop falls across the throat. The soft wall inflates the upstream part of
the tube by about 10 %; a wall of constant thickness is relatively thicker, hence stiffer, in the
throat, which then widens less and costs a little more pressure.
"""

import matplotlib.pyplot as plt
import numpy as np

import tubefsi
from tubefsi.registry import rheologies, walls

L, a0 = 40e-3, 1e-3                                   # m


def radius(z):
    """The lumen: a Gaussian stenosis of depth 40 % and width L/10 at z = L/2 (vectorized)."""
    return a0 * (1.0 - 0.4 * np.exp(-((z - L / 2) / (L / 10)) ** 2))


fluid = rheologies["power-law"](consistency=0.017, index=0.7)
wall = walls["thick-neo-hookean"](shear_modulus=600.0)
q = 5e-8                                              # m^3/s

proportional = tubefsi.Tube(radius=radius, thickness=lambda z: 0.2 * radius(z), length=L)
constant = tubefsi.Tube(radius=radius, thickness=0.2 * a0, length=L)
uniform = tubefsi.Tube(radius=a0, thickness=0.2 * a0, length=L)

fig, axes = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6), layout="constrained")
for tube, label in ((proportional, "t/a constant (separable)"), (constant, "t constant (integrated)")):
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    z = np.linspace(0.0, L, 81)
    axes[0].plot(z * 1e3, sol.pressure(z), label=f"{label}: Δp = {sol.pressure_drop:.1f} Pa")
    axes[1].plot(z * 1e3, sol.radius(z) * 1e3, label=label)
ref = tubefsi.solve(fluid, wall, uniform, flow_rate=q)
axes[0].plot(z * 1e3, ref.pressure(z), color="0.5", lw=1, ls="--", label=f"no stenosis: Δp = {ref.pressure_drop:.1f} Pa")
axes[1].plot(z * 1e3, radius(z) * 1e3, color="0.5", lw=0.9, ls=":", label="undeformed lumen a(z)")
axes[0].set_ylabel("pressure $p$ (Pa)")
axes[1].set_ylabel("radius $R$ (mm)")
axes[1].set_xlabel("axial position $z$ (mm)")
for ax in axes:
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False, fontsize=8)
fig.suptitle("Power-law fluid through a stenosed neo-Hookean tube", fontsize=11)

# a measured lumen works the same way, as a table (monotone cubic interpolation between knots)
table = tubefsi.sampled(np.linspace(0.0, L, 21), radius(np.linspace(0.0, L, 21)))
measured = tubefsi.solve(fluid, wall, tubefsi.Tube(radius=table, thickness=0.2 * a0, length=L), flow_rate=q)
print(f"pressure drop, analytic lumen {tubefsi.solve(fluid, wall, constant, flow_rate=q).pressure_drop:.6g} Pa, "
      f"tabulated lumen {measured.pressure_drop:.6g} Pa")
plt.show()
