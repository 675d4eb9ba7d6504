r"""Hyperelastic walls: an incompressible isotropic material in plane strain.

The tube is clamped (axial stretch 1), so a material point at radius :math:`r`
moves to :math:`R` with stretches :math:`(r/R, R/r, 1)`. The reduced strain
energy is :math:`\hat W(\lambda) = W(1/\lambda, \lambda, 1)` and a material
subclass gives only its derivative ``_dW(stretch)`` (or ``_energy(stretch)``,
differentiated numerically, or, for an isotropic :math:`W(I_1, I_2)`, ``_W1`` and ``_W2``,
which also serve an axial pre-stretch: ``docs/walls_beyond.md``, section "Axial pre-stretch").
The wall theory is chosen by composition:

================================  ==========================================================
theory                            tube law :math:`P(\lambda; \bar t)`
================================  ==========================================================
thin, reference thickness         :math:`\bar t\,\hat W'(\lambda)`  (hoop stress :math:`pR/t`)
thin, current thickness           :math:`\bar t\,\hat W'(\lambda)/\lambda`  (thickness :math:`t/\lambda`)
thick (Lamé, exact)               :math:`\int_{\lambda_o}^{\lambda} \frac{\hat W'(s)}{s^2-1}\,ds`,
                                  :math:`\lambda_o^2 = 1 + (\lambda^2-1)/(1+\bar t)^2`
================================  ==========================================================

A new material is a dozen lines::

    @attrs.frozen(kw_only=True)
    class Gent(HyperelasticWall):                 # the material: parameters and dW
        shear_modulus: float = positive(unit="Pa")
        locking_parameter: float = positive()

        def _dW(self, stretch):
            i1 = (stretch - 1 / stretch) ** 2     # I1 - 3 in plane strain
            return self.shear_modulus * (stretch - stretch**-3) / (1 - i1 / self.locking_parameter)

        def _locking_stretch(self):               # I1 - 3 = J_m: the tube's maximum stretch
            jm = self.locking_parameter
            return 0.5 * (jm**0.5 + (jm + 4) ** 0.5)

    @attrs.frozen(kw_only=True)
    class ThinGent(ThinWall, Gent): ...           # the wall theories, by composition

    @attrs.frozen(kw_only=True)
    class ThickGent(ThickWall, Gent): ...
"""

from __future__ import annotations

import abc
import functools
import math
import types

import attrs
import numpy as np

from .._lazy import lazy_module
from ..numerics.kernels import rows_dot
from ..numerics.quadrature import (GAUSS_WEIGHTS, KRONROD_NODES, KRONROD_WEIGHTS, Integral, adaptive, adaptive_to_pole,
                                   warn_unconverged)
from ..errors import InvalidParameterError
from ..geometry import Tube
from ..fields import choice, evaluate, flat_points, model_at, parameter_shape, positive, real
from .base import WallModel

# SciPy on first use (tubefsi._lazy): listing the models must not import it
differentiate = lazy_module("scipy.differentiate", globals(), "differentiate")

#: scipy.differentiate tolerances: as tight as the error estimate allows
_DIFF_TOL = types.MappingProxyType({"rtol": 1e-12, "atol": 0.0})

__all__ = ["HyperelasticWall", "ThinWall", "ThickWall", "THICKNESS_CONVENTIONS", "axial_stretch", "AXIAL_STRETCH_RANGE",
           "InstalledTube"]

THICKNESS_CONVENTIONS = ("reference", "current")


def _quartic(s):
    r""":math:`s - s^{-3} = (s-1)(1 + 1/s)(1 + 1/s^2)`, free of cancellation near 1 and of overflow
    (a double wherever the value is: the product form's :math:`s^3` is inf/inf at :math:`s = 10^{300}`)."""
    return (s - 1.0) * (1.0 + 1.0 / s) * (1.0 + 1.0 / (s * s))


def _times(c, x):
    """``c * x`` where a zero coefficient contributes nothing, even at an ``x`` beyond the doubles
    (a law's term that is absent, not 0 * inf = NaN)."""
    with np.errstate(invalid="ignore", over="ignore"):
        return np.where(c == 0, 0.0, c * x)


#: Within this distance of stretch 1 the thick integrand :math:`D(s)/(s^2-1)` of a material that
#: gives only ``_dW`` is formed from its slope (:func:`_secant_slope`) instead of the ratio, whose
#: cancellation costs up to :math:`\epsilon_{mach}/(2|s-1|)` relative for :math:`D = \mu(s - s^{-3})`
#: (measured: 1.2e-14 at :math:`|s-1| = 1/256`, 8e-16 at 1/16): with an exact ``_d2W`` (the material's)
#: to 1/8, where both are good to 2e-16; with ``scipy.differentiate``'s (good to 1e-14..1e-13 at a
#: point; its interpolant, 1e-14..5e-14) to 1/256, where the two meet at about 1e-14.
_SECANT_REACH = 0.125
_SECANT_REACH_NUMERICAL = 1.0 / 256.0
#: The fixed rule's embedded 10-point Gauss value must agree with its 21-point Kronrod value to
#: this: then the Kronrod value (exact for degree 31) is good to rounding; else the point keeps
#: the caller's other path (a slope too steep for a fixed rule over that interval).
_SECANT_CHECK = 1e-10
#: A numerical slope is interpolated from ``_CHEB`` Chebyshev points (first kind) on
#: :math:`[1 - r, 1 + r]` (its singularities at least 16 r away: coefficients fall like
#: :math:`32^{-k}`), and its interpolant integrated by the ``_CHEB // 2``-point Gauss–Legendre rule
#: (exact for it); the last two coefficients must be below ``_CHEB_TAIL`` of the largest.
_CHEB = 12
_CHEB_TAIL = 1e-12


@functools.cache
def _chebyshev_rule():
    """``(points, analysis, nodes, weights)``: the Chebyshev points on [-1, 1], the matrix from values
    there to Chebyshev coefficients, and the Gauss–Legendre rule on [0, 1]."""
    j = np.arange(_CHEB) + 0.5
    points = np.cos(np.pi * j / _CHEB)
    analysis = (2.0 / _CHEB) * np.cos(np.pi * np.outer(np.arange(_CHEB), j) / _CHEB)
    analysis[0] *= 0.5
    x, w = np.polynomial.legendre.leggauss(_CHEB // 2)
    return points, analysis, 0.5 * (1.0 + x), 0.5 * w


def _fixed_sum(w, y):
    """``sum_i w[i] y[i]`` over the leading axis of ``y``, accumulated in the order of ``i`` for every
    entry alike (so an entry's bits do not depend on the others)."""
    acc = w[0] * y[0]
    for i in range(1, len(w)):
        acc = acc + w[i] * y[i]
    return acc


def _secant_slope(wall, h, reach):
    r"""``(m, ok)``: :math:`m = \int_0^1 D'(1 + t h)\,dt = (D(1+h) - D(1))/h` at the strains ``h``
    (broadcast with ``wall``'s array parameters), free of the cancellation of :math:`D(1+h) - D(1)`
    at small :math:`h`: :math:`D'` is smooth and non-zero at 1, so rounding its argument costs nothing.

    Where ``ok`` (else ``m`` is NaN and the caller keeps its other path):

    * an exact ``_d2W`` (``wall._slope_given()``): the 21-point Gauss–Kronrod rule on
      :math:`t \in [0, 1]` (the constants of :mod:`tubefsi.numerics.quadrature`), for :math:`|h| \le` ``reach``
      and at most a quarter of the way to a locking stretch (below 1, to its inverse: the
      plane-strain invariants are symmetric in :math:`\lambda \leftrightarrow 1/\lambda`), which keeps
      :math:`D'`'s singularities seven half-widths from the interval's middle (the embedded Gauss
      rule converges like :math:`13.9^{-20}` there), and where that Gauss value agrees to
      ``_SECANT_CHECK``;
    * a numerical ``_d2W`` (``scipy.differentiate``, whose rounding differs from one argument to the
      next by 1e-14): the Chebyshev interpolant of :math:`D'` on :math:`[1 - r, 1 + r]`,
      :math:`r = \min(` ``reach``, ``_SECANT_REACH_NUMERICAL``, a sixteenth of the way to a locking
      stretch or its inverse), from its values at ``_CHEB`` fixed points per parameter set,
      integrated exactly by Gauss–Legendre: smooth in :math:`h` (the quadrature that integrates it
      sees no noise), as accurate as the numerical slope; for :math:`|h| \le r`, where the
      interpolant's last coefficients are below ``_CHEB_TAIL``.

    Shared by the thick wall's integrand near stretch 1 and, with an exact slope, the thin wall's
    law at small strain.
    """
    h = np.asarray(h, dtype=float)
    params = parameter_shape(wall)
    shape = np.broadcast_shapes(h.shape, params)
    lock = np.asarray(wall._locking_stretch(), dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        up, down = lock - 1.0, 1.0 - 1.0 / lock                 # room to the lock and to its inverse
    m = np.full(shape, np.nan)
    if wall._slope_given():
        with np.errstate(invalid="ignore"):
            limit = np.where(h >= 0, np.minimum(reach, 0.25 * up), np.minimum(reach, 0.25 * down))
            near = np.abs(h) <= limit
        if not np.any(near):
            return m, np.zeros(shape, dtype=bool)
        _, flat, (hf, near) = flat_points(wall, h, near)
        hf, near = np.broadcast_to(hf, m.size), np.flatnonzero(np.broadcast_to(near, m.size))
        hn = hf[near]
        with np.errstate(over="ignore", invalid="ignore"):
            slope = model_at(flat, near, column=True)._d2W(1.0 + hn[:, None] * KRONROD_NODES)
            slope = np.broadcast_to(np.asarray(slope, dtype=float), (near.size, KRONROD_NODES.size))
            kronrod = rows_dot(slope, KRONROD_WEIGHTS)          # (no BLAS: a point's bits do not depend on its batch)
            gauss = rows_dot(slope[:, 1::2], GAUSS_WEIGHTS)
            good = np.isfinite(kronrod) & (np.abs(kronrod - gauss) <= _SECANT_CHECK * np.abs(kronrod))
        m.reshape(-1)[near] = np.where(good, kronrod, np.nan)
        return m, np.isfinite(m)
    with np.errstate(invalid="ignore"):
        r = np.minimum(np.minimum(reach, _SECANT_REACH_NUMERICAL), np.minimum(up, down) / 16.0)
        y = h / r                                               # the strain in units of the table's reach
        near = np.abs(y) <= 1.0
    if not np.any(near):
        return m, np.zeros(shape, dtype=bool)
    points, analysis, nodes, weights = _chebyshev_rule()
    lead = (_CHEB,) + (1,) * len(params)                # the points ahead of the parameters' axes
    with np.errstate(over="ignore", invalid="ignore"):
        values = np.asarray(wall._d2W(1.0 + r * points.reshape(lead)), dtype=float)   # (_CHEB, *parameters)
        values = np.broadcast_to(values, (_CHEB,) + np.broadcast_shapes(values.shape[1:], np.shape(r)))
        # every sum below runs over its short axis in one fixed order, elementwise over the points
        # (a reduction by einsum or BLAS may change its order with the batch: tubefsi.numerics.kernels.blocked_matmul)
        coef = [_fixed_sum(analysis[k], values) for k in range(_CHEB)]
        tail = np.abs(coef[-1]) + np.abs(coef[-2])
        ok = near & np.isfinite(tail) & (tail <= _CHEB_TAIL * np.max(np.abs(coef), axis=0))
        # Clenshaw at z = t y for the Gauss nodes t (|z| <= 1), then the rule
        z = nodes.reshape((-1,) + (1,) * len(shape)) * np.where(ok, y, 0.0)
        b1 = b2 = 0.0
        for k in range(_CHEB - 1, 0, -1):
            b1, b2 = coef[k] + 2.0 * z * b1 - b2, b1
        m = np.where(ok, _fixed_sum(weights, coef[0] + z * b1 - b2), np.nan)
    return np.array(np.broadcast_to(m, shape)), np.array(np.broadcast_to(ok, shape))


#: The admissible axial pre-stretch: there the invariants of the installed rest state,
#: :math:`I_1 - 3 \sim \lambda_z^2` and :math:`I_2 - 3 \sim 2/\lambda_z^2`, and the installed
#: cross-section (:math:`1/\sqrt{\lambda_z}`) are doubles with room to spare (each material checks
#: what its own law makes of them: Demiray's and Gent's rest state, a finite installed modulus).
AXIAL_STRETCH_RANGE = (1e-100, 1e100)


def axial_stretch(*, array=True):
    """The ``axial_stretch`` parameter of a material that supports an axial pre-stretch
    (``docs/walls_beyond.md``, section "Axial pre-stretch"): in :data:`AXIAL_STRETCH_RANGE`, default 1;
    a single number with ``array=False`` (a material whose other parameters are no arrays either)."""
    low, high = AXIAL_STRETCH_RANGE
    return real(low=low, high=high, low_open=False, high_open=False, default=1.0,
                doc="axial pre-stretch lambda_z: installed / stress-free length", along=False, array=array)


class HyperelasticWall(WallModel):
    r"""Abstract base of plane-strain incompressible hyperelastic walls (a material; pick a theory).

    Hooks of a material (arrays of stretches; implement ``_dW``, ``_W1`` or ``_energy``, override
    the others for speed or accuracy). With an ``axial_stretch`` :math:`\lambda_z` field (the
    ``axial_stretch()`` parameter) the stretch is the installed tube's and ``_dW`` is its law
    :math:`D(\lambda) = \hat W'(\lambda/\sqrt{\lambda_z};\lambda_z)/\sqrt{\lambda_z}`
    (``docs/walls_beyond.md``, section "Axial pre-stretch"; :math:`\hat W'` at :math:`\lambda_z = 1`):

    ================================  ================================================================
    hook                              default
    ================================  ================================================================
    ``_dW(stretch)``                  natural hook: :math:`D(\lambda)`, or from ``_W1``/``_W2``, or
                                      ``_energy`` differentiated numerically
    ``_W1(i1, i2)``                   natural hook of an isotropic material :math:`W(I_1, I_2)`:
                                      :math:`\partial W/\partial I_1` at :math:`I_1 - 3 =` ``i1``, :math:`I_2 - 3 =` ``i2``;
                                      the base derives :math:`D = F(\lambda - \lambda^{-3})`,
                                      :math:`F = 2(W_1 + \lambda_z^2W_2)/\lambda_z`, its slope and the thick
                                      integrand :math:`F(\lambda^2+1)/\lambda^3` at every :math:`\lambda_z`
    ``_W2(i1, i2)``                   0; :math:`\partial W/\partial I_2`
    ``_W_second(i1, i2)``             None (then :math:`D'` numerically); ``(W11, W12, W22)``
    ``_energy(stretch)``              :math:`\hat W(\lambda)` (optional natural hook, plane strain)
    ``_d2W(stretch)``                 :math:`D'(\lambda)`: from the invariants, else by ``scipy.differentiate``
    ``_current_slope(stretch)``       :math:`d(D/\lambda)/d\lambda` (thin wall, current thickness)
    ``_locking_stretch()``            ``inf``; the stretch where :math:`D` blows up (Gent)
    ``_thick_integrand(s)``           :math:`D(s)/(s^2-1)`, near :math:`s = 1` (where the ratio cancels)
                                      the mean of ``_d2W`` over :math:`[1, s]` over :math:`s + 1`;
                                      override with a form free of the removable singularity
    ``_installed_cross_section``      ``(radius, thickness)`` of the installed tube at rest: the
                                      stress-free ones over :math:`\sqrt{\lambda_z}` (a homogeneous rest state)
    ``_homogeneous_rest()``           True; False where the rest state is solved for (fibres)
    ================================  ================================================================

    The theory (:class:`ThinWall` with a ``thickness_convention``, or :class:`ThickWall`) gives
    ``_integral_pressure`` (the pressure with its error estimate, from which ``_pressure_at_strain``
    follows unless a closed form overrides it) and ``_stiffness``; the :class:`~tubefsi.walls.WallModel` hooks
    (``_limit_pressure``, ``_max_stretch``, ...) may be overridden as for any wall.
    """

    __slots__ = ()

    #: Whether the material is isotropic (then its small-strain limit is the linear wall with
    #: E = 3 mu, nu = 1/2); fibre-reinforced materials set False.
    isotropic = True

    def dW(self, stretch):
        r"""Reduced strain-energy derivative :math:`\hat W'(\lambda)` (Pa), broadcast with the parameters."""
        return evaluate(self, lambda wall, lam: wall._dW(lam), np.asarray(stretch, dtype=float))

    def _dW(self, stretch):
        if self._uses_invariants():
            return self._invariant_factor(stretch)[0] * _quartic(stretch)
        if type(self)._energy is HyperelasticWall._energy:
            raise TypeError(f"{type(self).__name__} must implement _dW, _W1 or _energy")
        shape, wall, (lam,) = flat_points(self, stretch)
        res = differentiate.derivative(lambda x, i: model_at(wall, i)._energy(x), lam, args=(np.arange(lam.size),),
                                       initial_step=0.1 * lam, tolerances=_DIFF_TOL)
        return res.df.reshape(shape)

    def _energy(self, stretch):
        """Reduced strain energy :math:`\\hat W(\\lambda)` (optional natural hook)."""
        raise NotImplementedError

    def _d2W(self, stretch):
        r""":math:`\hat W''(\lambda)`, numerically unless overridden (steps clear of a locking stretch)."""
        if self._uses_invariants():
            second = self._invariant_second(stretch)
            if second is not None:
                return second
        shape, wall, (lam,) = flat_points(self, stretch)
        room = wall._locking_stretch() - lam
        step = 0.1 * np.minimum(lam, np.where(np.isfinite(room), 0.2 * room, np.inf))
        res = differentiate.derivative(lambda x, i: model_at(wall, i)._dW(x), lam, args=(np.arange(lam.size),),
                                       initial_step=step, tolerances=_DIFF_TOL)
        return res.df.reshape(shape)

    # -- isotropic materials W(I1, I2): the installed law from the invariant derivatives
    def _W1(self, i1, i2):
        r""":math:`W_1 = \partial W/\partial I_1` at :math:`I_1 - 3 =` ``i1``, :math:`I_2 - 3 =` ``i2``
        (optional natural hook of an isotropic material; then every :math:`\lambda_z` is served)."""
        raise NotImplementedError

    def _W2(self, i1, i2):
        r""":math:`W_2 = \partial W/\partial I_2` (0 unless overridden)."""
        return 0.0

    def _W_second(self, i1, i2):
        r"""``(W11, W12, W22)``, the second derivatives, or None (then :math:`D'` numerically)."""
        return None

    def _uses_invariants(self) -> bool:
        return type(self)._W1 is not HyperelasticWall._W1

    def _installed_invariants(self, s):
        r""":math:`(I_1 - 3, I_2 - 3)` at the installed stretch :math:`s` (stretches
        :math:`(1/(s\sqrt{\lambda_z}), s/\sqrt{\lambda_z}, \lambda_z)` from the stress-free tube):
        :math:`h/\lambda_z + (\lambda_z-1)^2(\lambda_z+2)/\lambda_z` and
        :math:`\lambda_z h + (\lambda_z-1)^2(2\lambda_z+1)/\lambda_z^2`, :math:`h = (s - 1/s)^2`,
        free of cancellation (exactly :math:`h, h` at :math:`\lambda_z = 1`)."""
        lz = self._axial()
        h = ((s - 1.0) * (s + 1.0) / s) ** 2
        if type(lz) is float and lz == 1.0:
            return h, h
        d = (lz - 1.0) ** 2
        return h / lz + d * (lz + 2.0) / lz, lz * h + d * (2.0 * lz + 1.0) / (lz * lz)

    def _axial(self):
        return getattr(self, "axial_stretch", 1.0)

    def _invariant_factor(self, s):
        r"""``(F, i1, i2)``: :math:`F = 2(W_1 + \lambda_z^2 W_2)/\lambda_z`, so that
        :math:`D(s) = F\,(s - s^{-3})` (``docs/walls_beyond.md``, section "Axial pre-stretch")."""
        lz = self._axial()
        i1, i2 = self._installed_invariants(s)
        with np.errstate(over="ignore", invalid="ignore"):
            w = self._W1(i1, i2)
            if type(self)._W2 is not HyperelasticWall._W2:
                w = w + lz * lz * self._W2(i1, i2)
            return (2.0 / lz) * w, i1, i2

    def _invariant_second(self, s):
        r""":math:`D'(s) = F(1 + 3s^{-4}) + (4/\lambda_z)(s - s^{-3})^2 K`,
        :math:`K = (W_{11} + \lambda_z^2W_{12})/\lambda_z + \lambda_z(W_{12} + \lambda_z^2W_{22})`; None without
        ``_W_second``."""
        factor, i1, i2 = self._invariant_factor(s)
        k = self._invariant_curvature(i1, i2)
        if k is None:
            return None
        q = _quartic(s)
        with np.errstate(over="ignore", invalid="ignore"):
            return factor * (1.0 + 3.0 * s**-4) + _times(4.0 / self._axial() * k, q * q)

    def _invariant_curvature(self, i1, i2):
        second = self._W_second(i1, i2)
        if second is None:
            return None
        lz = self._axial()
        w11, w12, w22 = second
        with np.errstate(over="ignore", invalid="ignore"):
            return (w11 + lz * lz * w12) / lz + lz * (w12 + lz * lz * w22)

    def _current_slope(self, s):
        r""":math:`d(D/s)/ds`, the slope of the thin current-thickness law per :math:`\bar t`: from the
        invariants as :math:`[4Fs^{-4} + (4/\lambda_z)(s - s^{-3})^2K]/s` (no cancellation at large
        stretch), else :math:`(D' - D/s)/s`."""
        if self._uses_invariants():
            factor, i1, i2 = self._invariant_factor(s)
            k = self._invariant_curvature(i1, i2)
            if k is not None:
                q = _quartic(s)
                with np.errstate(over="ignore", invalid="ignore"):
                    # (q q / s as (q / s) q: no overflow of q^2 where the slope is a double)
                    return 4.0 * factor * s**-5 + _times(4.0 / self._axial() * k, (q / s) * q)
        return (self._d2W(s) - self._dW(s) / s) / s

    def _locking_stretch(self) -> float:
        r"""The stretch at which the material locks (:math:`\hat W' \to \infty`, e.g. Gent); ``inf``.

        It is every tube's maximum stretch (the inner surface is the most stretched); the
        thick-wall integral grades its nodes toward it.
        """
        return math.inf

    def _max_stretch(self, tb):
        return self._locking_stretch()

    def _installed_tube(self, tube):
        r"""The tube as installed at the axial stretch :math:`\lambda_z` (``axial_stretch``, for the
        materials that have it): radius and thickness over :math:`\sqrt{\lambda_z}` (incompressible),
        length times :math:`\lambda_z`; the tube itself at :math:`\lambda_z = 1`."""
        lz = getattr(self, "axial_stretch", 1.0)
        if lz == 1.0 if type(lz) is float else (np.ndim(lz) == 0 and lz == 1.0):
            return tube
        if isinstance(tube, InstalledTube):          # a solution's tube, solved again: already installed
            if np.array_equal(np.broadcast_to(tube.axial_stretch, np.shape(lz)), lz):
                return tube
            raise InvalidParameterError("tube", "a stress-free Tube", tube,
                                        f"it is installed at the axial stretch {tube.axial_stretch}, not {lz}")
        radius, thickness = self._installed_cross_section(tube)
        return InstalledTube(radius=radius, thickness=thickness, length=tube.length * lz, axial_stretch=lz)

    def _homogeneous_rest(self) -> bool:
        """Whether the installed tube at rest is the stress-free one scaled (True: :math:`D(1) = 0`,
        and the plane Lamé integral of :math:`D` is the thick law); False for pre-stretched fibres."""
        return True

    def _installed_cross_section(self, tube):
        r"""``(radius, thickness)`` of the installed tube at rest: the stress-free ones over
        :math:`\sqrt{\lambda_z}` (a homogeneous state, where :math:`D(1) = 0`, as for every isotropic
        material); a material whose rest state is not homogeneous (fibres) solves for it."""
        shrink = 1.0 / np.sqrt(self.axial_stretch)
        return tube.radius * shrink, tube.thickness * shrink


    def _collapse_stretch(self, tb):
        # plane strain: the invariants are symmetric in lambda <-> 1/lambda, so a material that
        # locks at lambda_max locks in compression at 1/lambda_max
        return 1.0 / np.asarray(self._locking_stretch(), dtype=float)

    def _ring_modulus(self, tb):
        r""":math:`\mu_0 = \hat W''(1)/4`, the small-strain shear modulus, aligned with ``tb``."""
        return 0.25 * np.asarray(self._d2W(np.ones(np.shape(tb))), dtype=float)

    def _thick_integrand(self, s):
        r""":math:`g(s) = \hat W'(s)/(s^2-1)`; override with a form free of the removable singularity.

        Near :math:`s = 1` the ratio cancels (:math:`D(s)` is a difference of terms of order 1 that
        vanishes at 1: relative rounding :math:`\epsilon_{mach}/(2|s-1|)` for :math:`\mu(s - s^{-3})`), so
        there, with :math:`D(1) = 0` (a homogeneous rest state), it is formed from the slope:
        :math:`g(s) = \int_0^1 D'(1 + t(s-1))\,dt\,/\,(s+1)` (:func:`_secant_slope`), within
        ``_SECANT_REACH`` of 1, where it meets the ratio to 2e-16 (``_SECANT_REACH_NUMERICAL`` with a
        numerical ``_d2W``, to about 1e-14: the numerical slope's own accuracy)."""
        s = np.asarray(s, dtype=float)
        if self._uses_invariants():               # D(s)/(s^2 - 1) = F(s) (1 + s^-2)/s: no singularity
            return self._invariant_factor(s)[0] * ((1.0 + 1.0 / (s * s)) / s)
        with np.errstate(invalid="ignore", divide="ignore"):
            g = self._dW(s) / ((s - 1.0) * (s + 1.0))
        if not self._homogeneous_rest():          # D(1) != 0 in general: no secant through (1, 0)
            near = np.abs(s - 1.0) < 1e-7
            if np.any(near):
                g = np.where(near, 0.5 * self._d2W(np.ones_like(s)), g)
            return g
        reach = _SECANT_REACH if self._slope_given() else _SECANT_REACH_NUMERICAL
        h = s - 1.0
        if not np.any(np.abs(h) <= reach):        # (the common case far from rest: one reduction)
            return g
        m, ok = _secant_slope(self, h, reach)
        if not np.any(ok):
            return g
        with np.errstate(invalid="ignore"):
            return np.where(ok, m / (s + 1.0), g)

    def _slope_given(self) -> bool:
        """Whether :math:`D'` is exact (``_d2W`` overridden, or from the invariants' second derivatives),
        rather than ``scipy.differentiate``'s."""
        if type(self)._d2W is not HyperelasticWall._d2W:
            return True
        return self._uses_invariants() and type(self)._W_second is not HyperelasticWall._W_second

    #: What the theory's integral is called in an ``AccuracyWarning`` (:class:`ThinWall`, :class:`ThickWall`).
    _INTEGRAL = "the wall's integral"

    def _pressure_at_strain(self, strain, tb):
        result = self._integral_pressure(strain, tb)
        warn_unconverged(self._INTEGRAL, result)
        return result.value

    def _pressure_estimate(self, strain, tb):
        if type(self)._pressure_at_strain is not HyperelasticWall._pressure_at_strain:   # a closed form overrides it
            return Integral.exact(self._pressure_at_strain(strain, tb))
        return self._integral_pressure(strain, tb)

    @abc.abstractmethod
    def _integral_pressure(self, strain, tb) -> Integral:
        """The pressure at hoop strain by the theory's own formula, with its error estimate."""


@attrs.frozen(kw_only=True, slots=False)
class ThinWall(HyperelasticWall):
    r"""Thin-walled (membrane) theory; ``thickness_convention`` picks the hoop stress.

    ``"reference"``: :math:`\sigma_\theta = pR/t` with the undeformed thickness
    (the chapter's convention), :math:`P = \bar t\,\hat W'(\lambda)`.
    ``"current"``: the thickness thins to :math:`t/\lambda` by incompressibility,
    :math:`P = \bar t\,\hat W'(\lambda)/\lambda`; this is the :math:`\bar t\to 0`
    limit of the thick theory.

    The default is ``"reference"``, so that the chapter's results reproduce; its consequence
    for a Mooney–Rivlin or neo-Hookean wall: **no limit pressure** (the law grows like
    :math:`\lambda`), hence no maximum flow rate, where the ``"current"`` law and the thick
    wall saturate at a limit pressure. Choose ``"current"`` for a thin wall that should behave
    like the thick one (:func:`tubefsi.advise` compares a thick wall with both;
    ``docs/theory.md``, section "Thin walls").
    """

    thickness_convention: str = choice(THICKNESS_CONVENTIONS, default="reference",
                                       doc="hoop stress with the reference thickness (the chapter's; no limit "
                                           "pressure) or the current one (the thick law's thin limit)")

    #: Below this hoop strain, :math:`\hat W'(1 + \varepsilon)` is integrated from the strain itself.
    _SMALL_STRAIN = 0.1

    _INTEGRAL = "the thin-wall law at small strain"

    def _integral_pressure(self, strain, tb):
        lam = 1.0 + strain
        dw = self._dW_at_strain(strain)
        p = tb * dw.value
        return attrs.evolve(dw, value=p if self.thickness_convention == "reference" else p / lam)

    def _dW_at_strain(self, strain) -> Integral:
        r""":math:`\hat W'(1+\varepsilon)` without rounding :math:`1 + \varepsilon` where it matters,
        with its error estimate.

        Forming the stretch :math:`1 + \varepsilon` rounds the strain to the spacing of doubles
        near 1, a relative error :math:`\epsilon_{mach}/\varepsilon` in :math:`\hat W'` (which
        vanishes at 1). Below ``_SMALL_STRAIN`` the derivative is therefore integrated,
        :math:`\hat W'(1+\varepsilon) = \varepsilon\int_0^1 \hat W''(1+t\varepsilon)\,dt`: with an exact
        ``_d2W`` by the fixed Gauss–Kronrod rule of :func:`_secant_slope` (shared with the thick wall's
        integrand), else, or where that rule does not apply (a locking stretch nearer than four
        strains, a slope too steep for it), by adaptive Gauss–Kronrod quadrature, which averages a
        numerical slope's rounding (1e-14, where the thick wall's table of it is good to 5e-14: the
        thick wall needs a smooth integrand, this one does not). ``_d2W`` is smooth and non-zero at 1,
        so rounding its argument costs nothing.
        """
        shape, wall, (e,) = flat_points(self, strain)
        e = np.broadcast_to(e, (max(1, math.prod(shape)),))   # with the parameters: a scalar strain too
        out = np.array(wall._dW(1.0 + e), dtype=float) + 0.0 * e
        error = np.zeros(out.shape)
        converged = np.ones(out.shape, dtype=bool)
        small = np.flatnonzero(np.abs(e) < self._SMALL_STRAIN)
        if small.size:
            es = e[small]
            if self._slope_given():
                mean, ok = _secant_slope(model_at(wall, small), es, self._SMALL_STRAIN)
            else:       # a numerical slope: adaptive quadrature averages its rounding (1e-14; the table, 5e-14)
                mean, ok = np.full(es.shape, np.nan), np.zeros(es.shape, dtype=bool)
            rest = np.flatnonzero(~ok)
            if rest.size:
                er = es[rest]

                def f(t, i):
                    return model_at(wall, small[rest[i]], column=True)._d2W(1.0 + t * er[i, None])

                result = adaptive(f, 0.0, 1.0 + 0.0 * er, rtol=1e-14)
                mean[rest] = result.value
                error[small[rest]] = np.abs(er) * result.error
                converged[small[rest]] = result.converged
            out[small] = es * mean
        return Integral(value=out.reshape(shape), error=error.reshape(shape), converged=converged.reshape(shape),
                        panels=np.zeros(shape, dtype=int))

    def _min_pressure(self, tb):
        r"""Minus the long-ring buckling pressure :math:`\mu_0\bar t^3` (:math:`E = 3\mu_0`,
        :math:`\nu = 1/2` in :math:`E t^3/(4(1-\nu^2)a^3)`; ``docs/walls_beyond.md``, section "Buckling")."""
        return -self._ring_modulus(tb) * tb**3

    def _stiffness(self, stretch, tb):
        if self.thickness_convention == "reference":
            return tb * self._d2W(stretch)
        return tb * self._current_slope(stretch)


class ThickWall(HyperelasticWall):
    r"""Thick-walled theory: the exact plane-strain Lamé solution (see module docstring)."""

    __slots__ = ()

    #: Relative tolerance of the Lamé integral (its error estimate is checked, ``AccuracyWarning`` beyond).
    _RTOL = 1e-14

    _INTEGRAL = "the thick-wall (Lamé) integral"

    def _integral_pressure(self, strain, tb):
        return self._lame(strain, tb)

    def _lame(self, strain, tb) -> Integral:
        r""":math:`\int_{\ln\lambda_o}^{\ln\lambda} s\,\hat W'(s)/(s^2-1)\,du`, :math:`s = e^u`, by adaptive
        Gauss–Kronrod quadrature with an a-posteriori error estimate per point; graded toward a
        locking stretch in :math:`\ln(\ln\lambda_{max} - u)`."""
        shape, wall, (e, tb) = flat_points(self, strain, tb)
        e = np.broadcast_to(e, (max(1, math.prod(shape)),))   # the quadrature indexes its points
        b = (1.0 + tb) ** 2
        d = tb * (2.0 + tb)                                 # b - 1, exactly at any t/a (b rounds to 1 at 1e-100)
        x = e * (2.0 + e)                                   # lam^2 - 1
        log_lam_o = 0.5 * np.log1p(x / b)
        width = 0.5 * np.log1p(x * d / (b + x))             # ln(lam / lam_o), no cancellation
        # a collapsing tube (lam < 1) has width < 0: integrate -f(-u) over [0, -width]
        sign = np.where(e < 0, -1.0, 1.0)
        width = np.abs(width)
        lam_max = np.asarray(wall._locking_stretch(), dtype=float) + 0.0 * e
        with np.errstate(divide="ignore", invalid="ignore"):
            pole = np.where(np.isfinite(lam_max) & (e >= 0), np.log(lam_max) - log_lam_o, np.inf)   # the lock, in u
            gap = np.where(np.isfinite(lam_max), -np.log1p((e - (lam_max - 1.0)) / lam_max),  # ln(lam_max/lam)
                           np.inf)

        log_lam_o = np.broadcast_to(log_lam_o, e.shape)

        def f(u, idx):
            sg = sign[idx, None]
            s = np.exp(log_lam_o[idx, None] + sg * u)
            return sg * s * model_at(wall, idx, column=True)._thick_integrand(s)

        result = adaptive_to_pole(f, 0.0, width, pole, gap=gap, rtol=self._RTOL)
        return Integral(value=result.value.reshape(shape), error=result.error.reshape(shape),
                        converged=result.converged.reshape(shape), panels=result.panels.reshape(shape))

    def _min_pressure(self, tb):
        r"""Minus the long-ring buckling pressure taken at the outer radius,
        :math:`\mu_0\bar t^3/(1+\bar t)^3` (a conservative bound; ``docs/walls_beyond.md``, section
        "Buckling")."""
        return -self._ring_modulus(tb) * (tb / (1.0 + tb)) ** 3

    def _stiffness(self, stretch, tb):
        # g(lam) - g(lam_o) lam / (b lam_o) = [g(lam) - g(lam_o)] + g(lam_o) (b lam_o - lam)/(b lam_o),
        # b lam_o - lam = d (b + lam^2)/(b lam_o + lam), d = b - 1 = t/a (2 + t/a): the share of g(lam_o)
        # without the cancellation of lam/(b lam_o) against 1 (all of it at t/a = 1e-100, where the
        # small-strain modulus g(1) d/b would come out 0)
        # (the share in ratios of lam, and past lam^2's overflow lam_o = sqrt(lam^2 + d)/(1 + t/a):
        # doubles at lam = 1e300; the first form is exactly 1 at lam = 1, where fibres engage)
        lam = np.asarray(stretch, dtype=float)
        b = (1.0 + tb) ** 2
        d = tb * (2.0 + tb)
        with np.errstate(over="ignore"):
            lam_o = np.sqrt(1.0 + (lam * lam - 1.0) / b)
        if not np.all(np.isfinite(lam_o)):
            lam_o = np.where(np.isfinite(lam_o), lam_o, np.hypot(lam, np.sqrt(d)) / (1.0 + tb))
        g_o = self._thick_integrand(lam_o)
        with np.errstate(over="ignore", invalid="ignore"):
            share = d * ((b / lam + lam) / (b * lam_o)) / (b * lam_o / lam + 1.0)
        return (self._thick_integrand(lam) - g_o) + g_o * share


@attrs.frozen(kw_only=True)
class InstalledTube(Tube):
    r"""A tube as installed at an axial stretch (what :attr:`tubefsi.Solution.tube` is for a wall
    with ``axial_stretch``): radius and thickness over :math:`\sqrt{\lambda_z}`, length times
    :math:`\lambda_z`; solving again with it and the same wall does not install it twice."""

    axial_stretch: float = positive(doc="the axial stretch it is installed at")
