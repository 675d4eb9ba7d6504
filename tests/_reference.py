r"""An independent ``mpmath`` reference for ``tubefsi.solve`` (shared by the accuracy tests).

Nothing here calls tubefsi's numerics. Everything is written straight from the physics in
``DESIGN.md`` §2 (tube laws §2.3, power-law flow law §2.2, separation of variables §2.4).
The functions work at whatever ``mp.dps`` the caller sets (the test modules use 40 or more
digits, through ``mp.workdps``); they never change the global precision.

This is a plain module, not a test file: ``tests/`` has no ``__init__.py``, so pytest's default
``rootdir``/``prepend`` import mode puts ``tests/`` on ``sys.path`` and the test modules import
it as ``from _reference import ...``.

Tube laws ``P(lam)`` (``mu`` = shear modulus, ``2 (c1 + c2)`` for Mooney–Rivlin):

* thick (Lamé, plane strain): ``P = (mu/2) [f(xo) - f(xi)]``, ``f(x) = x + ln x``,
  ``xo = (1+tb)^2 / ((1+tb)^2 - 1 + lam^2)``, ``xi = lam^-2``;
* thin, reference thickness: ``P = mu tb (lam - lam^-3)``;
* thin, current thickness: ``P = mu tb (1 - lam^-4)``;
* thin linear: ``P = (lam - 1) E tb / (1 - nu/2)``; thick linear: ``P = (lam - 1) E tb / K``,
  ``K = [(1+tb)^2 (1+nu) + (1 - 2 nu)] / (2 + tb)``.

Power-law fluid: ``G(q, R) = phi(q) R^-k``, ``k = 3n + 1``, ``phi(q) = 2 m [(3n+1) q / (pi n)]^n``
(Newtonian = ``n = 1``, ``m = viscosity``). With the outlet at zero pressure (``lam_out = 1``),
``dp/dz = -G`` separates into ``L phi(q) = a^k Jhat(lam_in)``,
``Jhat(lam) = int_1^lam P'(s) s^k ds``, evaluated without ``P'`` by parts,
``Jhat = P(lam) lam^k - k int_1^lam P(s) s^(k-1) ds`` (``mpmath.quad``, tanh–sinh, on
geometrically split sub-intervals: ``ref_J``; or in ``x = ln s`` on one interval: ``ref_J_log``).

Hand-derived derivatives ``P'(s)`` (checked against ``mpmath.diff`` of ``P`` in
``test_accuracy_contract.py``):

* thin reference: ``P' = mu tb (1 + 3 s^-4)``; thin current: ``P' = 4 mu tb s^-5``;
  linear: ``P' = 1 / compliance``;
* thick: Leibniz rule on the Lamé integral of ``mu (1/s + 1/s^3)`` from ``lam_o`` to ``lam``
  (``d lam_o / d lam = lam / (b lam_o)``, ``b = (1+tb)^2``), which simplifies with ``d = b - 1``
  to ``P'(s) = mu d ((d+2) s^2 + d) / (s^3 (s^2+d)^2)``.

Limit walls (thick, thin current) and ``k < 4`` (``n < 1``): ``J_inf = int_1^inf P'(s) s^k ds``
is finite. Thin current: ``J_inf = 4 mu tb / (4 - k)`` and the tail
``int_lam^inf P' s^k ds = 4 mu tb lam^(k-4) / (4 - k)`` exactly. Thick: substituting ``s = 1/t``,
``int_lam^inf P' s^k ds = mu d int_0^(1/lam) ((d+2) + d t^2) t^(3-k) / (1 + d t^2)^2 dt``, and
``t = w^(1/(4-k))`` removes the endpoint singularity ``t^(3-k)`` (without it, tanh–sinh loses
~13 digits at n = 0.9):
``tail(lam) = mu d / (4-k) int_0^(lam^-(4-k)) ((d+2) + d t^2) / (1 + d t^2)^2 dw``
(``J_inf = tail(1)``). Near the maximum flow rate ``Jhat(lam) = J_inf - tail(lam)`` is used, since
integration by parts at ``lam ~ 1e7`` would cancel ``k log10(lam)`` digits.
"""

from __future__ import annotations

import mpmath
from mpmath import mpf

__all__ = [
    "WALLS", "LIMIT_KINDS", "RefWall", "split_geometric", "ref_J", "ref_J_log", "ref_J_inf", "ref_J_tail",
    "ref_phi", "ref_phi_inverse", "stretch_at_pressure", "exact_ratio", "rel_err",
]

# name -> (registry name, constructor kwargs, reference law kind). The parameters are chosen so
# that the library's 2 (c1 + c2) is exact in floating point.
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

#: Reference law kinds with a limit pressure.
LIMIT_KINDS = ("thick", "thin-current")


class RefWall:
    """The tube law P(lam; tb) in mpmath, from DESIGN.md §2.3 (no tubefsi numerics)."""

    def __init__(self, kind, params, tb):
        self.kind = kind
        self.tb = tb
        if "c1" in params:
            self.mu = 2 * (mpf(params["c1"]) + mpf(params["c2"]))
        elif "shear_modulus" in params:
            self.mu = mpf(params["shear_modulus"])
        else:
            E, nu = mpf(params["youngs_modulus"]), mpf(params["poisson_ratio"])
            if kind == "thin-linear":
                factor = 1 - nu / 2
            else:
                factor = ((1 + tb) ** 2 * (1 + nu) + (1 - 2 * nu)) / (2 + tb)
            self.compliance = factor / (E * tb)      # d lam / dp

    def P(self, lam):
        tb = self.tb
        if self.kind == "thick":
            b = (1 + tb) ** 2
            xo = b / (b - 1 + lam**2)
            xi = 1 / lam**2
            return self.mu / 2 * ((xo + mpmath.log(xo)) - (xi + mpmath.log(xi)))
        if self.kind == "thin-reference":
            return self.mu * tb * (lam - lam**-3)
        if self.kind == "thin-current":
            return self.mu * tb * (1 - lam**-4)
        return (lam - 1) / self.compliance            # linear walls

    def limit_pressure(self):
        if self.kind == "thick":
            return self.mu * mpmath.log(1 + self.tb)
        if self.kind == "thin-current":
            return self.mu * self.tb
        return mpmath.inf

    def dP(self, s):
        """Hand-derived P'(s) (see the module docstring)."""
        if self.kind == "thin-current":
            return 4 * self.mu * self.tb * s**-5
        if self.kind == "thick":
            d = (1 + self.tb) ** 2 - 1
            return self.mu * d * ((d + 2) * s**2 + d) / (s**3 * (s**2 + d) ** 2)
        if self.kind == "thin-reference":
            return self.mu * self.tb * (1 + 3 * s**-4)
        if self.kind in ("thin-linear", "thick-linear"):
            return 1 / self.compliance
        raise ValueError(self.kind)


def split_geometric(lo, hi):
    """Geometric sub-intervals of [lo, hi] (lo >= 1) for mpmath.quad."""
    pts = [lo]
    while pts[-1] * 2 < hi:
        pts.append(pts[-1] * 2)
    pts.append(hi)
    return pts


def ref_J(wall, lam, k):
    """Jhat(lam) = int_1^lam P'(s) s^k ds = P(lam) lam^k - k int_1^lam P(s) s^(k-1) ds."""
    if lam == 1:
        return mpf(0)
    tail = mpmath.quad(lambda s: wall.P(s) * s ** (k - 1), split_geometric(mpf(1), lam))
    return wall.P(lam) * lam**k - k * tail


def ref_J_log(wall, lam, k):
    """Jhat(lam) by parts as ``ref_J``, but integrated in x = ln s on one interval:
    ``k int_1^lam P(s) s^(k-1) ds = k int_0^(ln lam) P(e^x) e^(kx) dx`` (3x faster at lam ~ 200)."""
    if lam == 1:
        return mpf(0)
    tail = mpmath.quad(lambda x: wall.P(mpmath.exp(x)) * mpmath.exp(k * x), [0, mpmath.log(lam)])
    return wall.P(lam) * lam**k - k * tail


def ref_J_tail(wall, lam, k):
    """int_lam^inf P'(s) s^k ds, finite for a limit wall and k < 4 (module docstring)."""
    alpha = 4 - k
    if not alpha > 0:
        raise ValueError("the tail is infinite for k >= 4")
    if wall.kind == "thin-current":
        return 4 * wall.mu * wall.tb * lam ** (-alpha) / alpha
    if wall.kind != "thick":
        raise ValueError(wall.kind)
    d = (1 + wall.tb) ** 2 - 1

    def integrand(w):               # t = w^(1/alpha): t^(3-k) dt = dw / alpha
        t2 = w ** (2 / alpha)
        return ((d + 2) + d * t2) / (1 + d * t2) ** 2

    return wall.mu * d / alpha * mpmath.quad(integrand, [0, lam ** (-alpha)])


def ref_J_inf(wall, k):
    """J_inf = int_1^inf P'(s) s^k ds (limit walls, k < 4)."""
    if wall.kind == "thin-current":
        return 4 * wall.mu * wall.tb / (4 - k)
    return ref_J_tail(wall, mpf(1), k)


def ref_phi(q, n, m):
    return 2 * m * ((3 * n + 1) * q / (mpmath.pi * n)) ** n


def ref_phi_inverse(phi, n, m):
    return mpmath.pi * n / (3 * n + 1) * (phi / (2 * m)) ** (1 / n)


def stretch_at_pressure(wall, target, polish=True):
    """lam with P(lam) = target (bracketed, then findroot, then Newton on the strain)."""
    lo, hi = mpf(1), mpf(2)
    while wall.P(hi) < target:
        lo, hi = hi, 2 * hi
    lam = mpmath.findroot(lambda s: wall.P(s) - target, (lo, hi), solver="anderson")
    if polish:
        for _ in range(8):
            step = (target - wall.P(lam)) / wall.dP(lam)
            lam += step
            if abs(step) <= abs(lam - 1) * mpmath.eps * 16:
                break
    assert abs(wall.P(lam) / target - 1) < mpf(10) ** (-(mpmath.mp.dps - 10))
    return lam


def exact_ratio(num, den):
    """The exact ratio of two floats as mpf (the value a float thickness/radius stands for)."""
    return mpf(num) / mpf(den)


def rel_err(got, ref):
    return float(abs((mpf(got) - ref) / ref))
