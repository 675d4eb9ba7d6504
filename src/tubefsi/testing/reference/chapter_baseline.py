"""The chapter's method, written lean: ``scipy.integrate.odeint`` at its default tolerances, one ODE per point.

The baseline of the speed ratios in ``benchmarks/speed.py`` and ``examples/work_precision.py``.
For each flow rate ``q`` it integrates the deflection ODE ``d lam/dz = -G(q, a lam) / P'(lam)``
of a power-law fluid (``G = phi(q) R^-k``, ``k = 3n + 1``, ``phi(q) = 2 m [(3n+1) q / (pi n)]^n``)
from the outlet (``lam(L) = 1``, zero outlet pressure) to the inlet with ``odeint``'s default
tolerances (``rtol = atol = 1.49012e-8``, no Jacobian), then evaluates the tube law in closed form
at the inlet stretch (``docs/theory.md``, sections "Lubrication", "The flow law of a generalized
Newtonian fluid" and "Tube laws").

It is written as a careful user would write it, so that a speed ratio against it is honest:

* the right-hand side unpacks odeint's one-element state array once (``lam = y.item()``) and
  does plain-float arithmetic on Python floats (``math`` only, no NumPy): arithmetic on the
  one-element ndarray itself costs about a microsecond per operation and made an earlier version
  of this baseline about 8 to 10 times slower;
* every constant of the right-hand side (``phi``, ``mu``, ``a^k``, ...) is hoisted out of it, and
  ``-G/P'`` is simplified to one power and one division;
* the result is returned as Python floats.

It calls nothing of tubefsi: ``tube`` is read through ``tube.radius``, ``tube.length`` and
``tube.reduced_thickness`` only (a ``tubefsi.Tube`` or anything with those attributes). It needs
scipy, not mpmath. Its accuracy is that of ``odeint``'s defaults: a relative error of about 1e-7 to
1e-5 in the pressure drop and the inlet displacement (the error is controlled per step, not
globally), larger as the flow rate nears the maximum flow rate of a thick wall.

Each function returns ``(pressure_drop, inlet_displacement)``.
"""

from __future__ import annotations

import math

from scipy.integrate import odeint

__all__ = ["chapter_thick", "chapter_thin"]


def _phi(q, n, m):
    """``phi(q) = 2 m [(3n+1) q / (pi n)]^n``: the power-law flow law is ``G = phi(q) R^-(3n+1)``."""
    return 2.0 * m * ((3.0 * n + 1.0) * q / (math.pi * n)) ** n


def chapter_thick(q, n, m, mu, tube):
    """Thick neo-Hookean / Mooney–Rivlin wall (shear modulus ``mu``), power law (``m``, ``n``).

    Tube law (Lamé): ``P(lam) = (mu/2) [ln(1 + x d/(b + x)) + x d/((1 + x)(b + x))]``, ``x = lam^2 - 1``,
    ``b = (1 + tb)^2``, ``d = b - 1``; slope ``P' = mu d ((d + 2) lam^2 + d) / (lam^3 (lam^2 + d)^2)``.
    """
    a, L, tb = float(tube.radius), float(tube.length), float(tube.reduced_thickness)
    q, n, m, mu = float(q), float(n), float(m), float(mu)
    k = 3.0 * n + 1.0
    d = tb * (2.0 + tb)
    c = _phi(q, n, m) / (mu * d * a**k)          # -G/P' = -c lam^(3-k) (lam^2 + d)^2 / ((d + 2) lam^2 + d)
    e, d2 = 3.0 - k, d + 2.0

    def rhs(y, _z):
        lam = y.item()
        s2 = lam * lam
        w = s2 + d
        return -c * lam**e * w * w / (d2 * s2 + d)

    lam_in = float(odeint(rhs, 1.0, (L, 0.0))[-1, 0])
    x = lam_in * lam_in - 1.0
    b = 1.0 + d
    dp = 0.5 * mu * (math.log1p(x * d / (b + x)) + x * d / ((1.0 + x) * (b + x)))
    return dp, a * (lam_in - 1.0)


def chapter_thin(q, n, m, mu, tube):
    """Thin reference-thickness neo-Hookean wall (shear modulus ``mu``), power law (``m``, ``n``).

    Tube law: ``P(lam) = mu tb (lam - lam^-3)``; slope ``P' = mu tb (1 + 3 lam^-4)``.
    """
    a, L, tb = float(tube.radius), float(tube.length), float(tube.reduced_thickness)
    q, n, m, mu = float(q), float(n), float(m), float(mu)
    k = 3.0 * n + 1.0
    c = _phi(q, n, m) / (mu * tb * a**k)         # -G/P' = -c lam^(4-k) / (lam^4 + 3)
    e = 4.0 - k

    def rhs(y, _z):
        lam = y.item()
        s2 = lam * lam
        return -c * lam**e / (s2 * s2 + 3.0)

    lam_in = float(odeint(rhs, 1.0, (L, 0.0))[-1, 0])
    return mu * tb * (lam_in - lam_in**-3), a * (lam_in - 1.0)
