r"""An independent ``mpmath`` reference for the hyperelastic tube laws and power-law flow in them.

Nothing here calls tubefsi. Each material is written as its three-dimensional strain energy
:math:`W(\lambda_1, \lambda_2, \lambda_3)`; in the clamped (plane-strain) tube a point at the
hoop stretch :math:`s` has principal stretches :math:`(1/s, s, 1)`, so
:math:`\hat W(s) = W(1/s, s, 1)` and the reduced derivative :math:`\hat W'(s)` is written by
hand from it (checked against ``mpmath.diff`` of :math:`\hat W` by the tests). Tube laws
(``DESIGN.md`` §2.3), at the caller's ``mp.dps``:

* thin, reference thickness :math:`P = \bar t\,\hat W'(\lambda)`; current :math:`P = \bar t\,\hat W'(\lambda)/\lambda`;
* thick (Lamé): :math:`P = \int_{\lambda_o}^{\lambda}\hat W'(s)/(s^2-1)\,ds` by ``mpmath.quad``,
  :math:`\lambda_o^2 = 1 + (\lambda^2-1)/(1+\bar t)^2`, the interval split geometrically toward a
  locking stretch (Gent).

Power-law fluid, :math:`G(q, R) = \phi(q) R^{-k}`, :math:`k = 3n+1`,
:math:`\phi(q) = 2m[(3n+1)q/(\pi n)]^n` (§2.2). With the outlet at zero pressure the separated
identity is :math:`J(\lambda_{in}) = L\phi(q)/a^k`, :math:`J(\lambda) = \int_1^\lambda P'(s)s^k ds`,
evaluated directly with :math:`P'` from Leibniz's rule (thick) or ``mpmath.diff`` (thin), or, as a
cross-check, by parts, :math:`J = P(\lambda)\lambda^k - k\int_1^\lambda P(s)s^{k-1}ds`, where only
the tube law itself enters; :math:`\lambda_{in}` by Newton's method with :math:`J' = P'\lambda^k`.
"""

from __future__ import annotations

from mpmath import mp, mpf

__all__ = ["Gent", "Fung", "Ogden", "Yeoh", "TubeLaw", "phi", "phi_inverse", "J", "inlet_stretch"]


def _plane_strain(W):
    return lambda s: W(1 / s, s, mpf(1))


class Gent:
    def __init__(self, shear_modulus, locking_parameter):
        self.mu, self.jm = mpf(shear_modulus), mpf(locking_parameter)
        self.lock = (mp.sqrt(self.jm) + mp.sqrt(self.jm + 4)) / 2

    def W(self, l1, l2, l3):
        return -self.mu * self.jm / 2 * mp.log(1 - (l1**2 + l2**2 + l3**2 - 3) / self.jm)

    def dW(self, s):   # d/ds W(1/s, s, 1): I1 - 3 = (s - 1/s)^2, d(I1)/ds = 2 (s - s^-3)
        return self.mu * (s - s**-3) / (1 - (s - 1 / s) ** 2 / self.jm)


class Fung:
    def __init__(self, shear_modulus, stiffening):
        self.mu, self.b = mpf(shear_modulus), mpf(stiffening)
        self.lock = mp.inf

    def W(self, l1, l2, l3):
        return self.mu / (2 * self.b) * (mp.exp(self.b * (l1**2 + l2**2 + l3**2 - 3)) - 1)

    def dW(self, s):
        return self.mu * (s - s**-3) * mp.exp(self.b * (s - 1 / s) ** 2)


class Yeoh:
    def __init__(self, c1, c2, c3):
        self.c = (mpf(c1), mpf(c2), mpf(c3))
        self.lock = mp.inf

    def W(self, l1, l2, l3):
        i = l1**2 + l2**2 + l3**2 - 3
        return self.c[0] * i + self.c[1] * i**2 + self.c[2] * i**3

    def dW(self, s):
        i = (s - 1 / s) ** 2
        return 2 * (self.c[0] + 2 * self.c[1] * i + 3 * self.c[2] * i**2) * (s - s**-3)


class Ogden:
    """W = sum 2 mu_p / alpha_p^2 (l1^a + l2^a + l3^a - 3)."""

    def __init__(self, moduli, exponents):
        self.terms = [(mpf(m), mpf(a)) for m, a in zip(moduli, exponents)]
        self.lock = mp.inf

    def W(self, l1, l2, l3):
        return mp.fsum(2 * m / a**2 * (l1**a + l2**a + l3**a - 3) for m, a in self.terms)

    def dW(self, s):
        return mp.fsum(2 * m / a * (s ** (a - 1) - s ** (-a - 1)) for m, a in self.terms)


class TubeLaw:
    """P(lam) and P'(lam) of a material in one wall theory: 'reference', 'current' or 'thick'."""

    def __init__(self, material, theory, tb):
        self.mat, self.theory, self.tb = material, theory, mpf(tb)
        self.b = (1 + self.tb) ** 2

    def outer(self, lam):
        return mp.sqrt(1 + (lam * lam - 1) / self.b)

    def _breaks(self, lo, hi):
        pts = [lo, hi]
        lock = self.mat.lock
        if mp.isfinite(lock):       # grade toward the lock: gaps to it halve
            gap = lock - hi
            x = hi - gap
            while x > lo:
                pts.insert(1, x)
                gap *= 2
                x = hi - gap
        return sorted(set(pts))

    def pressure(self, lam):
        lam = mpf(lam)
        if self.theory == "reference":
            return self.tb * self.mat.dW(lam)
        if self.theory == "current":
            return self.tb * self.mat.dW(lam) / lam
        return mp.quad(lambda s: self.mat.dW(s) / (s * s - 1), self._breaks(self.outer(lam), lam))

    def slope(self, lam):
        lam = mpf(lam)
        if self.theory == "thick":  # Leibniz rule on the Lame integral
            lo = self.outer(lam)
            h = lambda s: self.mat.dW(s) / (s * s - 1)
            return h(lam) - h(lo) * lam / (self.b * lo)
        return mp.diff(self.pressure, lam)


def phi(q, m, n):
    q, m, n = mpf(q), mpf(m), mpf(n)
    return 2 * m * ((3 * n + 1) * q / (mp.pi * n)) ** n


def phi_inverse(f, m, n):
    f, m, n = mpf(f), mpf(m), mpf(n)
    return mp.pi * n / (3 * n + 1) * (f / (2 * m)) ** (1 / n)


def J(law, lam, k, by_parts=False):
    r""":math:`\int_1^\lambda P'(s)s^k ds` directly (``P'`` by Leibniz's rule for thick walls), or by parts,
    :math:`P(\lambda)\lambda^k - k\int_1^\lambda P(s)s^{k-1}ds` (only the tube law enters; slower)."""
    lam, k = mpf(lam), mpf(k)
    pts = law._breaks(mpf(1), lam)
    if by_parts:
        return law.pressure(lam) * lam**k - k * mp.quad(lambda s: law.pressure(s) * s ** (k - 1), pts)
    return mp.quad(lambda s: law.slope(s) * s**k, pts)


def inlet_stretch(law, target, k, guess, steps=8):
    """lam with J(lam) = target, by Newton's method from ``guess``."""
    lam = mpf(guess)
    for _ in range(steps):
        step = (J(law, lam, k) - target) / (law.slope(lam) * lam ** mpf(k))
        lam -= step
        if abs(step) < mpf(10) ** (-mp.dps + 4) * lam:
            break
    return lam
