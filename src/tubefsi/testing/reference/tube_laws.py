r"""Reference tube laws in ``mpmath``: one wall, :class:`RefWall`, for every theory and material.

Nothing here calls tubefsi. Everything is written from ``docs/theory.md``, section "Tube laws"
(subsections "Thin walls", "Thick walls", "Mooney–Rivlin and neo-Hookean walls", "Linear
walls"), at the caller's ``mp.dps``; ``P(lam)`` is the transmural pressure at the hoop stretch
``lam`` of the inner radius, ``tb`` the thickness ratio ``t/a``.

Materials
---------
A hyperelastic material is its three-dimensional strain energy :math:`W(\lambda_1, \lambda_2,
\lambda_3)` (:class:`NeoHookean`, :class:`MooneyRivlin`, :class:`Gent`, :class:`Demiray`,
:class:`Yeoh`, :class:`Ogden`, :class:`ArrudaBoyce` (the wall-law tutorial's); :class:`HoopFibre`, an
anisotropic one: a neo-Hookean matrix with exponential fibres along the hoop direction). In the clamped (plane-strain) tube a point at the hoop stretch
:math:`s` has principal stretches :math:`(1/s, s, 1)`, so :math:`\hat W(s) = W(1/s, s, 1)`
(:meth:`Material.W_hat`), and the reduced derivative :math:`\hat W'(s)` (:meth:`Material.dW`) is
written by hand from it (checked against ``mpmath.diff`` of :math:`\hat W` by the tests).
Mooney–Rivlin has :math:`I_1 = I_2` on that path, so it is neo-Hookean there with
``mu = 2 (c1 + c2)``: :math:`\hat W'(s) = \mu (s - s^{-3})`. :class:`Linear` holds Young's
modulus and Poisson's ratio of a linear wall.

Wall theories (``kind``)
------------------------
* ``"thin-reference"``: :math:`P = \bar t\,\hat W'(\lambda)`; ``"thin-current"``:
  :math:`P = \bar t\,\hat W'(\lambda)/\lambda`;
* ``"thick"`` (Lamé, plane strain): :math:`P = \int_{\lambda_o}^{\lambda}\hat W'(s)/(s^2-1)\,ds`,
  :math:`\lambda_o^2 = 1 + (\lambda^2-1)/b`, :math:`b = (1+\bar t)^2`, by ``mpmath.quad`` on an
  interval split geometrically toward a locking stretch (Gent); its slope by Leibniz's rule,
  :math:`P'(\lambda) = h(\lambda) - h(\lambda_o)\lambda/(b\lambda_o)` with :math:`h = \hat W'/(s^2-1)`
  (:meth:`Material.lame_integrand`; :math:`\mu(s^2+1)/s^3` for the neo-Hookean type, free of the
  cancellation at :math:`s \to 1`). The slope of a thin wall from a strain energy is
  ``mpmath.diff`` of its law;
* ``"thin-linear"``: ``P = (lam - 1) E tb / (1 - nu/2)``; ``"thick-linear"``:
  ``P = (lam - 1) E tb / K``, ``K = [(1+tb)^2 (1+nu) + (1 - 2 nu)] / (2 + tb)``.

Closed forms (neo-Hookean and Mooney–Rivlin, ``mu`` = shear modulus or ``2 (c1 + c2)``; used
unless ``closed_form=False``), from the laws above:

* thick: ``P = (mu/2) [f(xo) - f(xi)]``, ``f(x) = x + ln x``,
  ``xo = (1+tb)^2 / ((1+tb)^2 - 1 + lam^2)``, ``xi = lam^-2``;
* thin, reference thickness: ``P = mu tb (lam - lam^-3)``; thin, current thickness:
  ``P = mu tb (1 - lam^-4)``;
* hand-derived slopes: thin reference ``P' = mu tb (1 + 3 s^-4)``; thin current
  ``P' = 4 mu tb s^-5``; linear ``P' = 1 / compliance``; thick: Leibniz's rule on the Lamé
  integral of ``mu (1/s + 1/s^3)`` from ``lam_o`` to ``lam`` (``d lam_o / d lam = lam / (b lam_o)``),
  which simplifies with ``d = b - 1`` to ``P'(s) = mu d ((d+2) s^2 + d) / (s^3 (s^2+d)^2)``;
* limit pressures (``docs/theory.md``, section "Limits"): thick ``mu ln(1 + tb)``, thin current
  ``mu tb``; none (``inf``) for thin reference-thickness and linear walls.
"""

from __future__ import annotations

from collections.abc import Mapping

from mpmath import mp, mpf

__all__ = [
    "Material", "NeoHookean", "MooneyRivlin", "Gent", "Demiray", "HoopFibre", "Yeoh", "Ogden", "ArrudaBoyce", "Linear",
    "Installed",
    "material_from_params", "RefWall", "KINDS", "LIMIT_KINDS", "WALLS", "stretch_at_pressure",
]


# ---------------------------------------------------------------------------- materials
class Material:
    """A hyperelastic material given by its strain energy ``W(l1, l2, l3)`` (principal stretches)."""

    #: the hoop stretch at which the plane-strain energy blows up (Gent), else inf
    lock = mp.inf
    #: ``mu`` if the plane-strain energy is ``(mu/2)(s - 1/s)^2`` (the closed forms apply), else None
    neo_hookean_modulus = None

    def W(self, l1, l2, l3):
        raise NotImplementedError

    def dW(self, s):
        """d/ds W(1/s, s, 1), written by hand."""
        raise NotImplementedError

    def W_hat(self, s):
        """The plane-strain energy W(1/s, s, 1)."""
        return self.W(1 / s, s, mpf(1))

    def lame_integrand(self, s):
        """dW(s) / (s^2 - 1), the integrand of the thick-wall (Lamé) law."""
        return self.dW(s) / (s * s - 1)

    def dW_axial(self, s, lz):
        """d/ds W(1/(s lz), s, lz): the reduced energy under the axial stretch lz, by
        ``mpmath.diff`` unless a material writes it by hand."""
        lz = mpf(lz)
        return mp.diff(lambda x: self.W(1 / (x * lz), x, lz), s)

    def __repr__(self):
        return self._repr


class Installed(Material):
    r"""``material`` installed at the axial stretch ``lz`` (``docs/walls_beyond.md``, section "Axial
    pre-stretch"), in the installed tube's stretch :math:`\sigma = s\sqrt{\lambda_z}`:
    ``dW(sigma)`` is :math:`D(\sigma) = \hat W'(\sigma/\sqrt{\lambda_z};\lambda_z)/\sqrt{\lambda_z}`
    from the material's ``dW_axial``, so that :class:`RefWall` gives the installed tube's laws; its
    ``lock`` is the installed one (``lock_axial``, where the material has one)."""

    def __init__(self, material, lz):
        self.material, self.lz = material, mpf(lz)
        self.root = mp.sqrt(self.lz)
        self.lock = material.lock_axial(self.lz) if hasattr(material, "lock_axial") else mp.inf
        self._repr = f"Installed({material!r}, {lz!r})"

    def W(self, l1, l2, l3):
        raise NotImplementedError("the installed material is given by its reduced law")

    def dW(self, sigma):
        return self.material.dW_axial(sigma / self.root, self.lz) / self.root


class NeoHookean(Material):
    """W = (mu/2)(I1 - 3)."""

    def __init__(self, shear_modulus):
        self.mu = self.neo_hookean_modulus = mpf(shear_modulus)
        self._repr = f"NeoHookean({shear_modulus!r})"

    def W(self, l1, l2, l3):
        return self.mu / 2 * (l1**2 + l2**2 + l3**2 - 3)

    def dW(self, s):
        return self.mu * (s - s**-3)

    def lame_integrand(self, s):   # dW(s) / (s^2 - 1), simplified
        return self.mu * (s * s + 1) / s**3


class MooneyRivlin(NeoHookean):
    """W = c1 (I1 - 3) + c2 (I2 - 3); neo-Hookean with mu = 2 (c1 + c2) in plane strain."""

    def __init__(self, c1, c2):
        self.c1, self.c2 = mpf(c1), mpf(c2)
        self.mu = self.neo_hookean_modulus = 2 * (self.c1 + self.c2)
        self._repr = f"MooneyRivlin({c1!r}, {c2!r})"

    def W(self, l1, l2, l3):
        a, b, c = l1**2, l2**2, l3**2
        return self.c1 * (a + b + c - 3) + self.c2 * (a * b + b * c + c * a - 3)


class Gent(Material):
    """W = -(mu jm / 2) ln(1 - (I1 - 3)/jm)."""

    def __init__(self, shear_modulus, locking_parameter):
        self.mu, self.jm = mpf(shear_modulus), mpf(locking_parameter)
        self.lock = (mp.sqrt(self.jm) + mp.sqrt(self.jm + 4)) / 2
        self._repr = f"Gent({shear_modulus!r}, {locking_parameter!r})"

    def W(self, l1, l2, l3):
        return -self.mu * self.jm / 2 * mp.log(1 - (l1**2 + l2**2 + l3**2 - 3) / self.jm)

    def dW(self, s):   # I1 - 3 = (s - 1/s)^2, d(I1)/ds = 2 (s - s^-3)
        return self.mu * (s - s**-3) / (1 - (s - 1 / s) ** 2 / self.jm)

    def dW_axial(self, s, lz):   # I1 = s^2 + lz^2 + 1/(s lz)^2, dI1/ds = 2 (s - s^-3 lz^-2)
        i1 = s * s + lz * lz + 1 / (s * lz) ** 2 - 3
        return self.mu * (s - s**-3 / lz**2) / (1 - i1 / self.jm)

    def lock_axial(self, lz):
        """The installed stretch sigma = s sqrt(lz) where I1 - 3 = jm on the inflation side:
        y = sigma^2 solves y/lz + 1/(y lz) = jm + 3 - lz^2, a quadratic."""
        B = lz * (self.jm + 3 - lz * lz)
        return mp.sqrt((B + mp.sqrt(B * B - 4)) / 2)


class Demiray(Material):
    """W = (mu / 2b)(exp(b (I1 - 3)) - 1)."""

    def __init__(self, shear_modulus, stiffening):
        self.mu, self.b = mpf(shear_modulus), mpf(stiffening)
        self._repr = f"Demiray({shear_modulus!r}, {stiffening!r})"

    def W(self, l1, l2, l3):
        return self.mu / (2 * self.b) * (mp.exp(self.b * (l1**2 + l2**2 + l3**2 - 3)) - 1)

    def dW(self, s):
        return self.mu * (s - s**-3) * mp.exp(self.b * (s - 1 / s) ** 2)

    def dW_axial(self, s, lz):
        i1 = s * s + lz * lz + 1 / (s * lz) ** 2 - 3
        return self.mu * (s - s**-3 / lz**2) * mp.exp(self.b * i1)


class HoopFibre(Material):
    """A neo-Hookean matrix with one family of exponential fibres along the hoop direction:
    W = (mu/2)(I1 - 3) + k1/(2 k2) (exp(k2 (I4 - 1)^2) - 1), with I4 = l2^2 the squared hoop
    stretch (Holzapfel–Gasser–Ogden type, fibres at 0 degrees to the circumference).

    On the plane-strain path (1/s, s, 1): dW = mu (s - s^-3) + 2 k1 s (s^2 - 1) exp(k2 (s^2 - 1)^2),
    and dW / (s^2 - 1) = mu (s^2 + 1) / s^3 + 2 k1 s exp(k2 (s^2 - 1)^2), free of the cancellation
    at s -> 1.
    """

    def __init__(self, shear_modulus, k1, k2):
        self.mu, self.k1, self.k2 = mpf(shear_modulus), mpf(k1), mpf(k2)
        self._repr = f"HoopFibre({shear_modulus!r}, {k1!r}, {k2!r})"

    def W(self, l1, l2, l3):
        fibre = self.k1 / (2 * self.k2) * (mp.exp(self.k2 * (l2**2 - 1) ** 2) - 1)
        return self.mu / 2 * (l1**2 + l2**2 + l3**2 - 3) + fibre

    def dW(self, s):
        return self.mu * (s - s**-3) + 2 * self.k1 * s * (s * s - 1) * mp.exp(self.k2 * (s * s - 1) ** 2)

    def lame_integrand(self, s):   # dW(s) / (s^2 - 1), simplified
        return self.mu * (s * s + 1) / s**3 + 2 * self.k1 * s * mp.exp(self.k2 * (s * s - 1) ** 2)


class Yeoh(Material):
    """W = c1 (I1 - 3) + c2 (I1 - 3)^2 + c3 (I1 - 3)^3."""

    def __init__(self, c1, c2, c3):
        self.c = (mpf(c1), mpf(c2), mpf(c3))
        self._repr = f"Yeoh({c1!r}, {c2!r}, {c3!r})"

    def W(self, l1, l2, l3):
        i = l1**2 + l2**2 + l3**2 - 3
        return self.c[0] * i + self.c[1] * i**2 + self.c[2] * i**3

    def dW(self, s):
        i = (s - 1 / s) ** 2
        return 2 * (self.c[0] + 2 * self.c[1] * i + 3 * self.c[2] * i**2) * (s - s**-3)

    def dW_axial(self, s, lz):
        i = s * s + lz * lz + 1 / (s * lz) ** 2 - 3
        return 2 * (self.c[0] + 2 * self.c[1] * i + 3 * self.c[2] * i**2) * (s - s**-3 / lz**2)


class Ogden(Material):
    """W = sum 2 mu_p / alpha_p^2 (l1^a + l2^a + l3^a - 3)."""

    def __init__(self, moduli, exponents):
        self.terms = [(mpf(m), mpf(a)) for m, a in zip(moduli, exponents)]
        self._repr = f"Ogden({tuple(moduli)!r}, {tuple(exponents)!r})"

    def W(self, l1, l2, l3):
        return mp.fsum(2 * m / a**2 * (l1**a + l2**a + l3**a - 3) for m, a in self.terms)

    def dW(self, s):
        return mp.fsum(2 * m / a * (s ** (a - 1) - s ** (-a - 1)) for m, a in self.terms)

    def dW_axial(self, s, lz):   # d/ds [(s lz)^-a + s^a + lz^a]
        return mp.fsum(2 * m / a * (s ** (a - 1) - s ** (-a - 1) * lz ** (-a)) for m, a in self.terms)


class ArrudaBoyce(Material):
    """The Arruda–Boyce (eight-chain) rubber in its five-term series, the material of the wall-law
    tutorial (``docs/tutorials/wall-law-in-a-script.md``):
    W = mu sum_i C_i / lm^(2i-2) (I1^i - 3^i), C = (1/2, 1/20, 11/1050, 19/7000, 519/673750)."""

    C = (mpf(1) / 2, mpf(1) / 20, mpf(11) / 1050, mpf(19) / 7000, mpf(519) / 673750)

    def __init__(self, shear_modulus, chain_stretch):
        self.mu, self.lm = mpf(shear_modulus), mpf(chain_stretch)
        self._repr = f"ArrudaBoyce({shear_modulus!r}, {chain_stretch!r})"

    def W(self, l1, l2, l3):
        i1 = l1**2 + l2**2 + l3**2
        return self.mu * mp.fsum(c / self.lm ** (2 * i - 2) * (i1**i - 3**i) for i, c in enumerate(self.C, start=1))

    def dW(self, s):   # I1 = s^2 + s^-2 + 1, dI1/ds = 2 (s - s^-3)
        i1 = s * s + s**-2 + 1
        return 2 * self.mu * mp.fsum(c * i * i1 ** (i - 1) / self.lm ** (2 * i - 2)
                                     for i, c in enumerate(self.C, start=1)) * (s - s**-3)


class Linear:
    """A linear wall's constants (no strain energy): Young's modulus and Poisson's ratio."""

    lock = mp.inf
    neo_hookean_modulus = None

    def __init__(self, youngs_modulus, poisson_ratio):
        self.E, self.nu = mpf(youngs_modulus), mpf(poisson_ratio)
        self._repr = f"Linear({youngs_modulus!r}, {poisson_ratio!r})"

    def __repr__(self):
        return self._repr


def material_from_params(params: Mapping):
    """The reference material of a built-in wall's constructor parameters (the :data:`WALLS`
    dicts): ``c1, c2`` (Mooney–Rivlin), ``shear_modulus`` (neo-Hookean) or ``youngs_modulus,
    poisson_ratio`` (linear); ``thickness_convention`` is the wall's ``kind``, ignored here."""
    p = {key: value for key, value in params.items() if key != "thickness_convention"}
    if set(p) == {"c1", "c2"}:
        return MooneyRivlin(**p)
    if set(p) == {"shear_modulus"}:
        return NeoHookean(**p)
    if set(p) == {"youngs_modulus", "poisson_ratio"}:
        return Linear(**p)
    raise ValueError(f"no reference material for the parameters {sorted(p)}")


# ---------------------------------------------------------------------------- the wall
HYPERELASTIC_KINDS = ("thick", "thin-reference", "thin-current")
LINEAR_KINDS = ("thin-linear", "thick-linear")
KINDS = HYPERELASTIC_KINDS + LINEAR_KINDS
#: Kinds with a limit pressure (for the neo-Hookean type, closed forms).
LIMIT_KINDS = ("thick", "thin-current")


class RefWall:
    """The tube law ``P(lam; tb)`` and its slope ``dP`` in mpmath (module docstring).

    ``kind``: one of :data:`KINDS`. ``material``: a :class:`Material` (hyperelastic kinds) or
    :class:`Linear`, or a dict of a built-in wall's parameters (:func:`material_from_params`).
    ``closed_form``: use the neo-Hookean closed forms and hand-derived slopes where the material
    has them (default); ``False`` derives the law from ``dW`` as for any other material.

    Attributes: ``kind``, ``material``, ``tb`` (mpf), ``b = (1+tb)^2``, ``mu`` (the neo-Hookean
    modulus when the closed forms are in use, else None), ``compliance`` (linear walls,
    ``d lam / dp``).
    """

    def __init__(self, kind, material, tb, closed_form=True):
        if isinstance(material, Mapping):
            material = material_from_params(material)
        if kind not in KINDS:
            raise ValueError(f"unknown kind {kind!r}; one of {KINDS}")
        if (kind in LINEAR_KINDS) != isinstance(material, Linear):
            raise ValueError(f"a {kind!r} wall cannot be made of {material!r}")
        self.kind, self.material, self.tb = kind, material, mpf(tb)
        self.b = (1 + self.tb) ** 2
        self.mu = material.neo_hookean_modulus if closed_form else None
        if kind in LINEAR_KINDS:
            E, nu, tb = material.E, material.nu, self.tb
            if kind == "thin-linear":
                factor = 1 - nu / 2
            else:
                factor = ((1 + tb) ** 2 * (1 + nu) + (1 - 2 * nu)) / (2 + tb)
            self.compliance = factor / (E * tb)      # d lam / dp

    def __repr__(self):
        return f"RefWall({self.kind!r}, {self.material!r}, tb={self.tb}, closed_form={self.mu is not None})"

    @property
    def lock(self):
        """The stretch where the material locks (inf but for Gent)."""
        return self.material.lock

    def outer(self, lam):
        """The outer-radius stretch of a thick wall, ``sqrt(1 + (lam^2 - 1)/b)``."""
        return mp.sqrt(1 + (lam * lam - 1) / self.b)

    def breaks(self, lo, hi):
        """Break points of [lo, hi] for ``mpmath.quad``, graded toward a finite lock (gaps to it
        halve); just [lo, hi] without one."""
        pts = [lo, hi]
        lock = self.lock
        if mp.isfinite(lock):
            gap = lock - hi
            x = hi - gap
            while x > lo:
                pts.insert(1, x)
                gap *= 2
                x = hi - gap
        return sorted(set(pts))

    def P(self, lam):
        """The tube law at the stretch ``lam``."""
        lam = mpf(lam)
        tb, kind = self.tb, self.kind
        if self.mu is not None:                       # neo-Hookean type: closed forms
            if kind == "thick":
                b = (1 + tb) ** 2
                xo = b / (b - 1 + lam**2)
                xi = 1 / lam**2
                return self.mu / 2 * ((xo + mp.log(xo)) - (xi + mp.log(xi)))
            if kind == "thin-reference":
                return self.mu * tb * (lam - lam**-3)
            return self.mu * tb * (1 - lam**-4)
        if kind in LINEAR_KINDS:
            return (lam - 1) / self.compliance
        if kind == "thin-reference":
            return tb * self.material.dW(lam)
        if kind == "thin-current":
            return tb * self.material.dW(lam) / lam
        return mp.quad(self.material.lame_integrand, self.breaks(self.outer(lam), lam))

    def dP(self, s):
        """P'(s): hand-derived for the closed forms, Leibniz's rule (thick) or ``mpmath.diff``
        (thin) otherwise."""
        s = mpf(s)
        kind = self.kind
        if self.mu is not None:
            if kind == "thin-current":
                return 4 * self.mu * self.tb * s**-5
            if kind == "thick":
                d = (1 + self.tb) ** 2 - 1
                return self.mu * d * ((d + 2) * s**2 + d) / (s**3 * (s**2 + d) ** 2)
            return self.mu * self.tb * (1 + 3 * s**-4)
        if kind in LINEAR_KINDS:
            return 1 / self.compliance
        if kind == "thick":                           # Leibniz's rule on the Lamé integral
            lo = self.outer(s)
            h = self.material.lame_integrand
            return h(s) - h(lo) * s / (self.b * lo)
        return mp.diff(self.P, s)

    def limit_pressure(self):
        """sup P: closed forms (neo-Hookean type) and linear walls only."""
        if self.mu is not None:
            if self.kind == "thick":
                return self.mu * mp.log(1 + self.tb)
            if self.kind == "thin-current":
                return self.mu * self.tb
            return mp.inf
        if self.kind in LINEAR_KINDS:
            return mp.inf
        raise NotImplementedError("the limit pressure of a general material: find the first zero of dP")


# ---------------------------------------------------------------------------- the built-in walls
#: name -> (registry name, constructor kwargs, reference kind). The parameters are chosen so that
#: the library's 2 (c1 + c2) is exact in floating point. ``RefWall(kind, kwargs, tb)`` is the
#: reference of ``tubefsi.registry.walls[registry name](**kwargs)``.
WALLS = {
    "thick-mooney-rivlin": ("thick-mooney-rivlin", dict(c1=3.0e3, c2=-1.0e3), "thick"),
    "thick-neo-hookean": ("thick-neo-hookean", dict(shear_modulus=2.0e4), "thick"),
    "thin-mooney-rivlin-reference": ("thin-mooney-rivlin",
                                     dict(c1=2.0e4, c2=5.0e3, thickness_convention="reference"),
                                     "thin-reference"),
    "thin-mooney-rivlin-current": ("thin-mooney-rivlin",
                                   dict(c1=8.0e3, c2=-2.5e3, thickness_convention="current"),
                                   "thin-current"),
    "thin-neo-hookean-reference": ("thin-neo-hookean",
                                   dict(shear_modulus=1.0e3, thickness_convention="reference"),
                                   "thin-reference"),
    "thin-neo-hookean-current": ("thin-neo-hookean",
                                 dict(shear_modulus=6.0e4, thickness_convention="current"),
                                 "thin-current"),
    "thin-linear": ("thin-linear", dict(youngs_modulus=3.0e4, poisson_ratio=0.45), "thin-linear"),
    "thick-linear": ("thick-linear", dict(youngs_modulus=1.0e5, poisson_ratio=0.3), "thick-linear"),
}


def stretch_at_pressure(wall, target, polish=True):
    """lam with P(lam) = target (bracketed, then findroot, then Newton on the strain)."""
    lo, hi = mpf(1), mpf(2)
    while wall.P(hi) < target:
        lo, hi = hi, 2 * hi
    lam = mp.findroot(lambda s: wall.P(s) - target, (lo, hi), solver="anderson")
    if polish:
        for _ in range(8):
            step = (target - wall.P(lam)) / wall.dP(lam)
            lam += step
            if abs(step) <= abs(lam - 1) * mp.eps * 16:
                break
    assert abs(wall.P(lam) / target - 1) < mpf(10) ** (-(mp.dps - 10))
    return lam
