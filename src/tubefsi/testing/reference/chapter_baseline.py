"""The chapter's method: ``scipy.integrate.odeint`` at its default tolerances, one ODE per point.

The baseline of the speed ratios in ``benchmarks/speed.py`` and ``examples/work_precision.py``.
For each flow rate ``q`` it integrates the deflection ODE ``d lam/dz = -G(q, a lam) / P'(lam)``
of a power-law fluid (``G = phi(q) R^-k``, ``k = 3n + 1``, ``phi(q) = 2 m [(3n+1) q / (pi n)]^n``)
from the outlet (``lam(L) = 1``) to the inlet with ``odeint``'s default tolerances, then evaluates
the tube law at the inlet stretch (``docs/theory.md``, sections "Lubrication", "The flow law of a
generalized Newtonian fluid" and "Tube laws"). The right-hand side is lean, scalar and
pure-float, so the baseline is not slowed by tubefsi's own overhead. It calls nothing of
tubefsi: ``tube`` is read through ``tube.radius``, ``tube.length`` and ``tube.reduced_thickness``
only (a ``tubefsi.Tube`` or anything with those attributes). Needs scipy, not mpmath.

Each function returns ``(pressure_drop, inlet_displacement)``.
"""

from __future__ import annotations

import math

from scipy.integrate import odeint

__all__ = ["chapter_thick", "chapter_thin"]


def chapter_thick(q, n, m, mu, tube):
    """Thick neo-Hookean / Mooney–Rivlin wall (shear modulus ``mu``), power law (``m``, ``n``)."""
    a, L, tb = tube.radius, tube.length, tube.reduced_thickness
    d = tb * (2 + tb)
    phi = 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n
    k = 3 * n + 1

    def rhs(lam, z):
        lam2 = lam * lam
        slope = mu * lam * d * (lam2 * (d + 2) + d) / (lam2 * lam2 * (lam2 + d) ** 2)
        return -phi * (a * lam) ** -k / slope

    lam_in = odeint(rhs, 1.0, [L, 0.0])[-1, 0]
    x = lam_in**2 - 1
    b = (1 + tb) ** 2
    return 0.5 * mu * (math.log1p(x * d / (b + x)) + x * d / ((1 + x) * (b + x))), a * (lam_in - 1)


def chapter_thin(q, n, m, mu, tube):
    """Thin reference-thickness neo-Hookean wall (shear modulus ``mu``), power law (``m``, ``n``)."""
    a, L, tb = tube.radius, tube.length, tube.reduced_thickness
    phi = 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n
    k = 3 * n + 1

    def rhs(lam, z):
        return -phi * (a * lam) ** -k / (mu * tb * (1 + 3 * lam**-4))

    lam_in = odeint(rhs, 1.0, [L, 0.0])[-1, 0]
    return mu * tb * (lam_in - lam_in**-3), a * (lam_in - 1)
