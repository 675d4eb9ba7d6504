r"""The wall contract: a tube law between transmural pressure and hoop stretch.

A wall law maps the hoop stretch :math:`\lambda = R/a` of the inner surface and the
reduced thickness :math:`\bar t = t/a` to the transmural pressure
:math:`p = P(\lambda; \bar t)` (``docs/theory.md``, section "Tube laws"). Like
:class:`scipy.stats.rv_continuous`, a subclass implements the one natural method,
``_pressure(stretch, reduced_thickness)`` *or* ``_stretch(pressure, reduced_thickness)``,
and the base class derives the rest: the inverse by a safeguarded Newton iteration with a
bracketing fallback, the stiffness :math:`dP/d\lambda` by numerical differentiation. The
contract suite :mod:`tubefsi.testing` checks that every path agrees.

tubefsi models inflation: stretches :math:`\lambda \ge 1`, pressures :math:`p \ge 0`.
"""

from __future__ import annotations

import abc
import math
from typing import ClassVar

import numpy as np
from scipy import differentiate
from scipy.optimize import elementwise

from .._numerics import as_output, solve_increasing
from .._quadrature import quiet
from .._validation import as_array
from ..errors import ConvergenceError, InvalidParameterError, NoSteadyStateError

#: scipy.differentiate tolerances: as tight as the error estimate allows
_DIFF_TOL = dict(rtol=1e-12, atol=0.0)

__all__ = ["WallModel"]


def _overrides(obj, name) -> bool:
    return getattr(type(obj), name) is not getattr(WallModel, name)


class WallModel(abc.ABC):
    r"""Abstract base of every wall law (see the module docstring for the contract).

    Hooks (all take arrays and the reduced thickness ``tb``; implement one of the first two,
    override the others for speed or accuracy):

    ======================================================  ==============================================
    hook                                                    default
    ======================================================  ==============================================
    ``_pressure(stretch, tb)``                              natural hook, or from ``_strain`` by a root solve
    ``_stretch(pressure, tb)``                              natural hook, or ``1 + _strain``
    ``_pressure_at_strain(strain, tb)``                     ``_pressure(1 + strain)``; override to keep
                                                            full accuracy at tiny strain
    ``_strain(pressure, tb)``                               ``_stretch - 1``, or the inverse of
                                                            ``_pressure_at_strain`` (Newton, then bracketing)
    ``_stiffness(stretch, tb)``                             :math:`dP/d\lambda` by ``scipy.differentiate``
    ``_limit_pressure(tb)``                                 ``inf`` (no limit pressure)
    ``_max_stretch(tb)``                                    ``inf`` (no locking stretch, no peak)
    ``_stiffness_decay_exponent(tb)``                       :math:`\kappa` in :math:`P' \sim \lambda^{-\kappa}`,
                                                            estimated (only used with a limit pressure)
    ``_power_law_integral(log_ratio, stretch, k, tb)``      None; a closed form of the separated integral
                                                            of a power-law fluid (with
                                                            ``closed_form_integral = True``)
    ``_power_law_integral_inverse(integral, ...)``          None; its explicit inverse, where there is one
    ======================================================  ==============================================

    Class attributes: ``is_rigid`` (True only for :class:`~tubefsi.walls.Rigid`) and
    ``closed_form_integral`` (True where ``_power_law_integral`` is implemented, which makes
    the ``closed-form`` coupler available for power-law fluids).
    """

    __slots__ = ()

    #: True only for the rigid wall, whose tube law is the vertical line ``stretch = 1``.
    is_rigid: ClassVar[bool] = False
    #: Example parameter sets (keyword dicts) run through the contract suites of :mod:`tubefsi.testing`.
    _examples: ClassVar[tuple] = ()
    #: True where ``_power_law_integral`` gives the separated integral of a power-law fluid in
    #: closed form (``docs/theory.md``, section "Closed forms and removable singularities").
    closed_form_integral: ClassVar[bool] = False

    # ------------------------------------------------------------------ public API
    def pressure(self, stretch, reduced_thickness):
        r"""Transmural pressure :math:`P(\lambda; \bar t)` (Pa) at hoop stretch ``stretch``."""
        tb = self._check_thickness(reduced_thickness)
        lam = self._check_stretch(stretch, tb)
        return as_output(self._pressure_at_strain(lam - 1.0, tb), _is_scalar(stretch, reduced_thickness))

    def stretch(self, pressure, reduced_thickness):
        r"""Hoop stretch :math:`\lambda = R/a` under transmural pressure ``pressure`` (Pa)."""
        return as_output(1.0 + np.asarray(self.strain(pressure, reduced_thickness)),
                         _is_scalar(pressure, reduced_thickness))

    def strain(self, pressure, reduced_thickness):
        r"""Hoop strain :math:`\lambda - 1 = u/a`, computed without forming ``stretch - 1``.

        Raises
        ------
        NoSteadyStateError
            If ``pressure`` reaches the wall's limit pressure.
        """
        tb = self._check_thickness(reduced_thickness)
        p = self._check_pressure(pressure, tb)
        return as_output(self._strain(p, tb), _is_scalar(pressure, reduced_thickness))

    def stiffness(self, stretch, reduced_thickness):
        r"""Tube-law slope :math:`dP/d\lambda` (Pa)."""
        tb = self._check_thickness(reduced_thickness)
        lam = self._check_stretch(stretch, tb)
        return as_output(self._stiffness(lam, tb), _is_scalar(stretch, reduced_thickness))

    def limit_pressure(self, reduced_thickness) -> float:
        r"""The pressure the wall can never reach (Pa); ``inf`` for most laws."""
        return float(self._limit_pressure(self._check_thickness(reduced_thickness)))

    def max_stretch(self, reduced_thickness) -> float:
        """The largest admissible stretch (``inf`` unless the material locks)."""
        return float(self._max_stretch(self._check_thickness(reduced_thickness)))

    def small_strain_modulus(self, reduced_thickness) -> float:
        r""":math:`dP/d\lambda` at :math:`\lambda = 1` (Pa): the slope of the linear limit."""
        tb = self._check_thickness(reduced_thickness)
        return float(self._stiffness(np.asarray(1.0), tb))

    def plot(self, reduced_thickness, *, ax=None, max_stretch=3.0, **kwargs):
        """Plot this wall's tube law; see :func:`tubefsi.plotting.plot_tube_law`."""
        from ..plotting import plot_tube_law

        return plot_tube_law(self, reduced_thickness, ax=ax, max_stretch=max_stretch, **kwargs)

    # ------------------------------------------------------------------ hooks
    def _natural(self) -> str:
        """Which side of the tube law the subclass implements: 'pressure' or 'stretch'."""
        if _overrides(self, "_pressure") or _overrides(self, "_pressure_at_strain"):
            return "pressure"
        if _overrides(self, "_stretch") or _overrides(self, "_strain"):
            return "stretch"
        raise TypeError(f"{type(self).__name__} must implement _pressure or _stretch")

    def _pressure(self, stretch, tb):
        """Natural hook: pressure at ``stretch`` (array, >= 1) for thickness ratio ``tb``."""
        self._natural()
        return self._pressure_at_strain(stretch - 1.0, tb)

    def _pressure_at_strain(self, strain, tb):
        """Pressure at hoop strain; override for accuracy at tiny strain."""
        if _overrides(self, "_pressure"):
            return self._pressure(1.0 + strain, tb)
        self._natural()
        return self._invert_strain(strain, tb)

    def _stretch(self, pressure, tb):
        return 1.0 + self._strain(pressure, tb)

    def _strain(self, pressure, tb):
        self._natural()
        if _overrides(self, "_stretch"):
            return self._stretch(pressure, tb) - 1.0
        return self._invert_pressure(pressure, tb)

    def _stiffness(self, stretch, tb):
        lam = np.asarray(stretch, dtype=float)
        if self._natural() == "pressure":
            # central differences (the law is evaluated slightly below stretch 1, where it
            # still exists), steps kept clear of a locking stretch
            room = self._max_stretch(tb) - lam
            step = 0.1 * np.minimum(lam, np.where(np.isfinite(room), 0.2 * room, np.inf))
            res = differentiate.derivative(lambda s: self._pressure_at_strain(s - 1.0, tb), lam,
                                           initial_step=step, tolerances=_DIFF_TOL)
            return res.df
        # only the inverse is natural: dP/dlam = 1 / (d lam / dp), with steps no smaller than a
        # tenth of the pressure at strain 1e-6 (a strain law written as stretch - 1 cancels below it)
        p = self._pressure_at_strain(lam - 1.0, tb)
        step = 0.1 * np.maximum(p, self._pressure_at_strain(np.asarray(1e-6), tb))
        res = differentiate.derivative(lambda q: self._strain(q, tb), p,
                                       step_direction=np.where(p > 4 * step, 0, 1),
                                       initial_step=step, tolerances=_DIFF_TOL)
        return 1.0 / res.df

    def _limit_pressure(self, tb):
        return math.inf

    def _stiffness_decay_exponent(self, tb):
        r"""``kappa`` with :math:`dP/d\lambda \sim \lambda^{-\kappa}` as :math:`\lambda \to \infty`.

        Only used where the limit pressure is finite (to decide whether a maximum
        flow rate exists); estimated numerically unless overridden.
        """
        lam = np.array([1e5, 1e6])
        d = self._stiffness(lam, tb)
        return float(-np.log(d[1] / d[0]) / np.log(lam[1] / lam[0]))

    def _power_law_integral(self, log_ratio, outlet_stretch, exponent, tb):
        r"""Closed form of :math:`\int_0^v s^{k+1} P'(s)\,du`, :math:`s = \lambda_{out} e^u`, or None.

        A wall that implements it sets ``closed_form_integral = True`` and gets the
        ``closed-form`` coupler for power-law fluids (:math:`k = 3n+1`).
        """
        return None

    def _power_law_integral_inverse(self, integral, outlet_stretch, exponent, tb):
        """Inverse of ``_power_law_integral`` in ``log_ratio`` where it is explicit, else None."""
        return None

    def _max_stretch(self, tb):
        return math.inf

    # ------------------------------------------------------------------ generic inverses
    def _invert_pressure(self, pressure, tb):
        """Hoop strain at ``pressure``: safeguarded Newton iteration with the stiffness (vectorized,
        bracketed below a maximum stretch), else bracketed root finding on ``_pressure_at_strain``."""
        p = np.asarray(pressure, dtype=float)
        lam_max = self._max_stretch(tb)
        emax = lam_max - 1.0
        scale = max(self._stiffness(np.asarray(1.0), tb), 1e-300)
        fast = self._newton_strain(p, tb, emax, scale)
        if fast is not None:
            return fast

        def f(e, p):
            return self._pressure_at_strain(e, tb) - p

        guess = np.minimum(np.maximum(p / scale, 1e-300), 0.5 * emax if math.isfinite(emax) else np.inf)
        # never evaluate the law at a locking stretch (where it is singular): the largest strain
        # searched is that of the last double below the lock (lam - 1 is exact for lam < 2^53)
        xmax = float(np.nextafter(lam_max, 1.0)) - 1.0 if math.isfinite(emax) else 1e15
        with quiet():
            bracket = elementwise.bracket_root(f, np.zeros_like(p) + 0.0, np.maximum(guess, 1e-300) * 1.0,
                                               xmin=0.0, xmax=xmax, args=(p,))
        if not np.all(bracket.success | (p == 0)):
            bad = ~(bracket.success | (p == 0))
            limit = float(np.max(self._pressure_at_strain(np.asarray(xmax * 0.999999), tb)))
            raise NoSteadyStateError("pressure", min(limit, self._limit_pressure(tb)),
                                     p[bad].flat[0], "the tube law never reaches it")
        with quiet():
            res = elementwise.find_root(f, bracket.bracket, args=(p,),
                                        tolerances=dict(xrtol=2 * np.finfo(float).eps, xatol=1e-300))
        self._pressure_at_strain(res.x, tb)      # the answer's own error estimate (AccuracyWarning)
        return np.where(p == 0, 0.0, res.x)

    def _newton_strain(self, p, tb, emax, scale):
        """The Newton path of :meth:`_invert_pressure`; None where it does not converge cleanly."""
        if self._natural() != "pressure":
            return None
        upper = 0.999999 * emax if math.isfinite(emax) else None
        guess = np.minimum(p / scale, 0.5 * emax) if math.isfinite(emax) else p / scale
        try:
            with quiet():                        # trial strains: no warnings (the answer is checked below)
                e, ok = solve_increasing(lambda x, i: self._pressure_at_strain(x, tb),
                                         lambda x, i: self._stiffness(1.0 + x, tb),
                                         p, guess=guess, upper=upper, xmax=1e15, maxiter=100)
        except ConvergenceError:
            return None
        with np.errstate(all="ignore"):
            converged = ok & np.isfinite(e) & (np.abs(self._pressure_at_strain(e, tb) - p) <= 1e-12 * p)
        return e if np.all(converged) else None

    def _invert_strain(self, strain, tb):
        """Pressure at a strain when only the inverse law ``_strain`` is natural."""
        e = np.asarray(strain, dtype=float)

        def f(p, e):
            return self._strain(p, tb) - e

        lim = self._limit_pressure(tb)
        hi = np.maximum(e, 1e-300) * 10.0
        bracket = elementwise.bracket_root(f, np.zeros_like(e), hi, xmin=0.0,
                                           xmax=lim if math.isfinite(lim) else None, args=(e,))
        res = elementwise.find_root(f, bracket.bracket, args=(e,),
                                    tolerances=dict(xrtol=2 * np.finfo(float).eps, xatol=1e-300))
        return np.where(e == 0, 0.0, res.x)

    # ------------------------------------------------------------------ validation
    @staticmethod
    def _check_thickness(reduced_thickness) -> float:
        try:
            tb = float(reduced_thickness)
        except (TypeError, ValueError):
            raise InvalidParameterError("reduced_thickness", "(0, inf)", reduced_thickness) from None
        if not (math.isfinite(tb) and tb > 0):
            raise InvalidParameterError("reduced_thickness", "(0, inf)", tb)
        return tb

    def _check_stretch(self, stretch, tb):
        lam_max = self._max_stretch(tb)
        if math.isfinite(lam_max):
            return as_array("stretch", stretch, f"[1, {lam_max:.10g})", lambda a: (a >= 1) & (a < lam_max))
        return as_array("stretch", stretch, "[1, inf)", lambda a: a >= 1)

    def _check_pressure(self, pressure, tb):
        p = as_array("pressure", pressure, "[0, inf)", lambda a: a >= 0)
        lim = self._limit_pressure(tb)
        if np.any(p >= lim):
            raise NoSteadyStateError("pressure", lim, p[p >= lim].flat[0],
                                     f"{type(self).__name__} cannot sustain it")
        return p


def _is_scalar(*values) -> bool:
    return all(np.ndim(v) == 0 for v in values)
