r"""The HGO tube installed at an axial stretch (``docs/walls_beyond.md``, section "Arterial walls in
situ"): the rest state, the thick law and the membrane law, vectorized and error-controlled.

With stress-free radii :math:`A \le \rho \le B`, the lumen variable :math:`e = \lambda_z s_i^2 - 1`
(:math:`s_i` the hoop stretch of the lumen from the stress-free tube) and :math:`w = (A/\rho)^2`,
incompressibility gives :math:`\lambda_z s(\rho)^2 = 1 + we`, the fibre strain is
:math:`x = I_4 - 1 = x_0 + \cos^2\beta\,we/\lambda_z` with the rest strain of the homogeneous state
:math:`x_0 = (\lambda_z - 1)(\lambda_z(\lambda_z+1)\sin^2\beta - \cos^2\beta)/\lambda_z`, and

.. math::

    p = \frac{1}{\lambda_z}\int_0^{\ln(B/A)} H_w(e)\,du, \qquad u = \ln(\rho/A),\quad
    H_w(e) = \mu\frac{we(2 + we)}{(1 + we)^2} + 4k_1\cos^2\beta\,x^+e^{k_2x^2}.

The rest state :math:`e_0` solves :math:`p = 0`; the installed stretch is
:math:`\lambda = \sqrt{(1 + e)/(1 + e_0)}`, so :math:`e - e_0 = \varepsilon(2+\varepsilon)(1 + e_0)`
exactly, and the tube law integrates the difference :math:`H_w(e) - H_w(e_0)`, formed without
cancellation: :math:`P(1) = 0` exactly and full relative accuracy at small strain. The membrane
(thin) law is :math:`D(\lambda) = s_0^2\lambda\,[H_1(e) - H_1(e_0)]`, :math:`s_0^2 = (1+e_0)/\lambda_z`,
with :math:`H_1(e_0) = 0`.
"""

from __future__ import annotations


import types

import numpy as np

from .._lazy import lazy_module
from ..numerics.cache import TABLES
from ..numerics.quadrature import Integral, adaptive, warn_unconverged
from ..errors import ConvergenceError, InvalidParameterError

elementwise = lazy_module("scipy.optimize.elementwise", globals(), "elementwise")

#: relative tolerance of the quadratures (their estimates are checked: AccuracyWarning beyond)
RTOL = 1e-14
#: k2 x^2 beyond which exp(k2 x^2) would come near overflow: the maximum fibre strain
OVERFLOW = 600.0
_TOL = types.MappingProxyType({"xrtol": 4 * np.finfo(float).eps, "xatol": 1e-300})


class Law:
    """The constants of an HGO wall at its points (scalars, or arrays aligned with the points)."""

    __slots__ = ("mu", "k2", "c2", "lz", "x0", "a")

    def __init__(self, mu, k1, k2, beta, lz):
        c2, s2 = np.cos(beta) ** 2, np.sin(beta) ** 2
        self.mu, self.k2, self.c2, self.lz = mu, k2, c2, lz
        self.x0 = (lz - 1.0) * (s2 * lz * (lz + 1.0) - c2) / lz
        self.a = 4.0 * k1 * c2

    @classmethod
    def of(cls, wall):
        return cls(wall.shear_modulus, wall.fibre_stiffness, wall.fibre_exponent, wall.fibre_angle,
                   wall.axial_stretch)

    def at(self, index, column=False):
        """The constants at the flat points ``index`` (a column to meet ``(n, nodes)`` arrays)."""
        out = object.__new__(Law)
        for name in Law.__slots__:
            v = getattr(self, name)
            if np.ndim(v):
                v = np.broadcast_to(v, (max(np.size(v), 1),))[index]
                v = v[:, None] if column else v
            setattr(out, name, v)
        return out

    # -- the integrand and its pieces
    def fibre(self, x):
        r""":math:`x^+e^{k_2x^2}`."""
        with np.errstate(over="ignore", invalid="ignore"):
            return np.where(x > 0, x * np.exp(self.k2 * x * x), 0.0)

    def strain(self, y):
        """The fibre strain at ``y = w e``."""
        return self.x0 + self.c2 * y / self.lz

    def H(self, w, e):
        y = w * e
        return self.mu * (y * (2.0 + y) / ((1.0 + y) * (1.0 + y))) + self.a * self.fibre(self.strain(y))

    def dH(self, w, e0, d):
        r""":math:`H_w(e_0 + d) - H_w(e_0)` without cancellation (``docs/walls_beyond.md``)."""
        y0, dy = w * e0, w * d
        y1 = y0 + dy
        matrix = dy * (2.0 + y0 + y1) / ((1.0 + y0) ** 2 * (1.0 + y1) ** 2)
        xa, dx = self.strain(y0), self.c2 * dy / self.lz
        xb = xa + dx
        with np.errstate(over="ignore", invalid="ignore"):
            both = dx * np.exp(self.k2 * xb * xb) + xa * np.exp(self.k2 * xa * xa) * np.expm1(self.k2 * dx * (xa + xb))
            fib = np.where((xa > 0) & (xb > 0), both, self.fibre(xb) - self.fibre(xa))
        return self.mu * matrix + self.a * fib

    def H_e(self, w, e):
        r""":math:`\partial H_w/\partial e` (a jump where the fibres engage)."""
        y = w * e
        x = self.strain(y)
        with np.errstate(over="ignore", invalid="ignore"):
            fib = np.where(x > 0, np.exp(self.k2 * x * x) * (1.0 + 2.0 * self.k2 * x * x), 0.0)
        return self.mu * 2.0 * w / (1.0 + y) ** 3 + self.a * self.c2 * w / self.lz * fib

    def kink(self, e, width):
        r"""The :math:`u` in :math:`(0, \mathrm{width})` where the fibres engage in state ``e``, else ``width``."""
        with np.errstate(divide="ignore", invalid="ignore"):
            w = -self.x0 * self.lz / (self.c2 * e)
            u = np.where((w > 0) & (w < 1), -0.5 * np.log(w), np.inf)
        return np.where(u < width, u, width)

    def max_strain_at_lumen(self):
        r"""The lumen variable :math:`e` where the lumen fibres reach :math:`k_2x^2 = 600` (inf without)."""
        with np.errstate(divide="ignore"):
            return np.where(self.c2 * self.a > 0, (np.sqrt(OVERFLOW / self.k2) - self.x0) * self.lz
                            / np.where(self.c2 > 0, self.c2, 1.0), np.inf)


def integrate(f, width, kinks, what, atol=0.0, *, warn=True):
    """``sum`` of adaptive quadratures of ``f(u, index)`` over ``[0, width]`` split at ``kinks``
    (per point, ``width`` where none); with ``warn`` an ``AccuracyWarning`` gives the estimate where
    one does not converge (trial points of an iteration pass False)."""
    width = np.asarray(width, dtype=float)
    edges = np.sort(np.stack([np.zeros_like(width)] + [np.minimum(k, width) for k in kinks] + [width]), axis=0)
    value = np.zeros(width.shape)
    error = np.zeros(width.shape)
    ok = np.ones(width.shape, dtype=bool)
    atol = np.broadcast_to(atol, width.shape)
    for lo, hi in zip(edges[:-1], edges[1:]):
        idx = np.flatnonzero(hi > lo)                 # only the pieces that are there
        if idx.size == 0:
            continue
        part = adaptive(lambda u, i: f(u, idx[i]), lo[idx], hi[idx], rtol=RTOL, atol=np.min(atol[idx]))
        value[idx] += part.value
        error[idx] += part.error
        ok[idx] &= part.converged
    # a piece that holds a tiny part of the integral may miss its own relative tolerance: the
    # point is judged on its total
    ok |= error <= np.maximum(atol, RTOL * np.abs(value))
    if warn:
        warn_unconverged(what, Integral(value=value, error=error, converged=ok, panels=np.zeros(value.shape, int)))
    return value


# ------------------------------------------------------------------ the rest state
def membrane_rest(law, n):
    r"""The membrane's rest state: :math:`e_0` with :math:`H_1(e_0) = 0`, at ``n`` points (0 where the
    fibres are slack in the homogeneous state)."""
    x0 = np.broadcast_to(law.x0, (n,))
    a = np.broadcast_to(law.a, (n,))
    e0 = np.zeros(n)
    need = np.flatnonzero((x0 > 0) & (a > 0))
    if need.size == 0:
        return e0
    part = law.at(need)
    with np.errstate(divide="ignore"):
        lo = np.maximum(-part.x0 * part.lz / np.where(part.c2 > 0, part.c2, 1e-300), -1.0 + 1e-12)
    lo = np.broadcast_to(lo, need.shape)
    low_value = part.H(1.0, lo)
    if not np.all(low_value < 0):
        bad = need[int(np.argmax(~(low_value < 0)))]
        raise InvalidParameterError("axial_stretch", "values whose fibre pre-tension leaves the lumen open",
                                    float(np.broadcast_to(law.lz, (n,))[bad]),
                                    "the fibres stretched at rest would close the lumen")

    def f(e, i):
        return law.at(need[i]).H(1.0, e)

    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        res = elementwise.find_root(f, (lo, np.zeros(need.size)), args=(np.arange(need.size),), tolerances=_TOL)
    if not np.all(res.success):
        raise ConvergenceError("the rest state of the pre-stretched HGO membrane did not converge")
    e0[need] = res.x
    return e0


def thick_rest(law, tb, installed):
    r"""The thick tube's rest state :math:`e_0` (``p = 0``) at the points of ``tb`` (flat): the
    installed reduced thickness if ``installed`` (then :math:`\ln(B/A) = \tfrac12\ln(1 + (1+e)\bar
    t'(2+\bar t'))` moves with :math:`e`), else the stress-free one."""
    tb = np.asarray(tb, dtype=float)
    n = tb.size
    e0 = membrane_rest(law, n)
    need = np.flatnonzero(e0 < 0)
    if need.size == 0:
        return e0
    d = tb * (2.0 + tb)

    def width(e, i):
        return 0.5 * np.log1p((1.0 + e) * d[i]) if installed else 0.5 * np.log1p(d[i])

    def f(e, i, warn=False):
        idx = need[i]
        part = law.at(idx)
        w_end = width(e, idx)

        def g(u, j):
            return law.at(idx[j], column=True).H(np.exp(-2.0 * u), e[j, None])

        scale = (np.abs(part.H(1.0, e)) + np.abs(part.H(np.exp(-2.0 * w_end), e))) * w_end
        return integrate(g, w_end, [part.kink(e, w_end)], "the rest state of the pre-stretched HGO tube",
                         atol=1e-16 * scale, warn=warn)

    top = e0[need]
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        bracket = elementwise.bracket_root(f, top - 0.05 * (1.0 + top), top, xmin=np.full(need.size, -1.0 + 1e-12),
                                           xmax=top, args=(np.arange(need.size),))
        res = elementwise.find_root(f, bracket.bracket, args=(np.arange(need.size),), tolerances=_TOL)
    if not np.all(bracket.success & res.success):
        raise ConvergenceError("the rest state of the pre-stretched thick HGO tube did not converge")
    f(res.x, np.arange(need.size), warn=True)     # the root's own quadrature, its estimate checked (AccuracyWarning)
    e0[need] = res.x
    return e0


def _rest_scalar(constants, tb, kind):
    """The rest state of one wall (plain values): solved once per value, in the one cache."""
    def solve():
        law = Law(*constants)
        if kind == "membrane":
            return float(membrane_rest(law, 1)[0])
        return float(thick_rest(law, np.array([tb]), kind == "installed")[0])

    return TABLES.get(("HGO rest state", constants, tb, kind), solve)


def rest(wall, tb, kind):
    """:math:`e_0` at the flat points of ``tb`` (aligned with the wall's flat parameters); ``kind``:
    ``"membrane"``, ``"installed"`` (thick, installed thickness) or ``"stress-free"`` (thick).
    Kept in the one cache for scalar walls (by value)."""
    constants = (wall.shear_modulus, wall.fibre_stiffness, wall.fibre_exponent, wall.fibre_angle,
                 wall.axial_stretch)
    tb = np.asarray(tb, dtype=float)
    if all(np.ndim(c) == 0 for c in constants):
        if kind == "membrane":
            return _rest_scalar(tuple(float(c) for c in constants), 0.0, kind) + 0.0 * tb
        values, inverse = np.unique(tb.ravel(), return_inverse=True)
        out = np.array([_rest_scalar(tuple(float(c) for c in constants), float(t), kind) for t in values])
        return out[inverse].reshape(tb.shape)
    law = Law(*constants)
    points = np.broadcast(tb, *constants)
    if points.size == 0:                        # an empty array of parameters: no point
        return np.zeros(points.shape)
    n = points.size
    if kind == "membrane":
        return membrane_rest(law, n).reshape(points.shape)
    return thick_rest(law, np.broadcast_to(tb, (n,)), kind == "installed")


# ------------------------------------------------------------------ the tube laws
def _lumen(strain, e0):
    """``(e, e - e0)`` at the installed hoop strain: :math:`e - e_0 = \\varepsilon(2+\\varepsilon)(1+e_0)`."""
    d = strain * (2.0 + strain) * (1.0 + e0)
    return e0 + d, d


def thick_pressure(wall, strain, tb, slope=False):
    """The thick installed law (or, with ``slope``, :math:`dP/d\\lambda`) at flat aligned points."""
    strain = np.asarray(strain, dtype=float)
    tb = np.broadcast_to(np.asarray(tb, dtype=float), strain.shape)
    law = Law.of(wall)
    e0 = rest(wall, tb, "installed")
    e, d = _lumen(strain, e0)
    width = 0.5 * np.log1p((1.0 + e0) * tb * (2.0 + tb))

    if slope:
        def g(u, j):
            return law.at(j, column=True).H_e(np.exp(-2.0 * u), e[j, None])
    else:
        def g(u, j):
            return law.at(j, column=True).dH(np.exp(-2.0 * u), e0[j, None], d[j, None])

    kinks = [law.kink(e, width), law.kink(e0, width)]
    value = integrate(g, width, kinks, "the pre-stretched thick HGO law") / law.lz
    return value * 2.0 * (1.0 + strain) * (1.0 + e0) if slope else value


def membrane(wall, strain, slope=False):
    r""":math:`D(\lambda) = s_0^2\lambda[H_1(e) - H_1(e_0)]` (or :math:`D'`) at the installed strain."""
    strain = np.asarray(strain, dtype=float)
    law = Law.of(wall)
    e0 = rest(wall, np.zeros(strain.shape), "membrane")
    e, d = _lumen(strain, e0)
    s02 = (1.0 + e0) / law.lz
    lam = 1.0 + strain
    if slope:
        return s02 * (law.dH(1.0, e0, d) + lam * law.H_e(1.0, e) * 2.0 * lam * (1.0 + e0))
    return s02 * lam * law.dH(1.0, e0, d)


def max_stretch(wall, tb, kind):
    """The installed stretch where the lumen fibres reach the overflow bound."""
    law = Law.of(wall)
    e0 = rest(wall, tb, kind)
    emax = law.max_strain_at_lumen()
    with np.errstate(invalid="ignore"):
        return np.sqrt((1.0 + emax) / (1.0 + e0))
