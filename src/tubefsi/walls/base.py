r"""The wall contract: a tube law between transmural pressure and hoop stretch.

A wall law maps the hoop stretch :math:`\lambda = R/a` of the inner surface and the
reduced thickness :math:`\bar t = t/a` to the transmural pressure
:math:`p = P(\lambda; \bar t)` (``docs/theory.md``, section "Tube laws"). Like
:class:`scipy.stats.rv_continuous`, a subclass implements the one natural method,
``_pressure(stretch, reduced_thickness)`` *or* ``_stretch(pressure, reduced_thickness)``,
and the base class derives the rest: the inverse by a safeguarded Newton iteration with a
bracketing fallback, the stiffness :math:`dP/d\lambda` by numerical differentiation. The
contract suite :mod:`tubefsi.testing` checks that every path agrees.

By default a wall models inflation only: stretches :math:`\lambda \ge 1`, pressures
:math:`p \ge 0`. A wall that also holds a negative transmural pressure (an external pressure
above the internal one) says down to which pressure with ``_min_pressure``: the axisymmetric
walls down to their buckling pressure, a collapsible tube law (Shapiro) without bound
(``docs/walls_beyond.md``, section "External pressure and collapse").
"""

from __future__ import annotations

import abc
import math
import types
from typing import ClassVar

import numpy as np

from .._html import model_html
from .._lazy import lazy_module
from ..numerics.quadrature import Integral
from ..numerics.roots import solve_signed
from .._validation import as_array, real_array
from ..fields import evaluate, flat_points, model_at, take
from ..errors import BucklingError, ConvergenceError, InvalidParameterError, NoSteadyStateError

# SciPy on first use (tubefsi._lazy): listing the models must not import it
differentiate = lazy_module("scipy.differentiate", globals(), "differentiate")
elementwise = lazy_module("scipy.optimize.elementwise", globals(), "elementwise")

#: scipy.differentiate tolerances: as tight as the error estimate allows
_DIFF_TOL = types.MappingProxyType({"rtol": 1e-12, "atol": 0.0})

__all__ = ["WallModel"]



def _quiet():
    """The public methods evaluate the law quietly: a result beyond the doubles is a typed error
    (:func:`_finite`), and an intermediate overflow of a form that stays finite is no news."""
    return np.errstate(over="ignore", invalid="ignore", divide="ignore")


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
    ``_pressure_at_log_stretch(v, strain, tb)``             ``_pressure_at_strain(strain)``: the same at
                                                            :math:`v = \ln\lambda` with
                                                            :math:`e^v - 1` given; override where
                                                            :math:`v` is the cheaper variable
    ``_strain(pressure, tb)``                               ``_stretch - 1``, or the inverse of
                                                            ``_pressure_at_strain`` (Newton, then bracketing)
    ``_stiffness(stretch, tb)``                             :math:`dP/d\lambda` by ``scipy.differentiate``
    ``_log_slope(stretch, tb)``                             :math:`\lambda\,dP/d\lambda` (the wall's factor of
                                                            the separated integrand): ``stretch * _stiffness``
    ``_limit_pressure(tb)``                                 ``inf`` (no limit pressure)
    ``_max_stretch(tb)``                                    ``inf`` (no locking stretch, no peak)
    ``_min_pressure(tb)``                                   0 (inflation only); the most negative transmural
                                                            pressure the law holds (a buckling pressure,
                                                            ``-inf`` for a collapsible tube law)
    ``_min_stretch(tb)``                                    the stretch at ``_min_pressure`` (1 at 0, 0 at
                                                            ``-inf``, else the tube law's inverse)
    ``_installed_tube(tube)``                               the tube itself; the installed tube of a wall
                                                            under axial pre-stretch
    ``_slope_kinks(tb)``                                    ``()``; stretches where :math:`P'` or
                                                            :math:`P''` jumps (fibres engaging): the
                                                            couplers' quadratures split there
    ``_stiffness_decay_exponent(tb)``                       :math:`\kappa` in :math:`P' \sim \lambda^{-\kappa}`,
                                                            estimated (only used with a limit pressure)
    ``_power_law_integral(log_ratio, stretch, k, tb)``      None; a closed form of the separated integral
                                                            of a power-law fluid (with
                                                            ``closed_form_integral = True``)
    ``_power_law_integral_inverse(integral, ...)``          None; its explicit inverse, where there is one
    ``_has_power_law_integral_inverse()``                   whether that inverse is given (overridden)
    ``_pressure_estimate(strain, tb)``                      ``_pressure_at_strain`` as an exact
                                                            :class:`~tubefsi.numerics.quadrature.Integral`;
                                                            a law that integrates returns its estimate
                                                            (the root finders warn only at the answer)
    ``_shape_key()``                                        None; with ``_pressure_scale()`` (1) and
                                                            ``_unit_wall()`` (None), the opt-in split
                                                            ``P = scale * P_hat(stretch; tb, shape)`` that
                                                            lets one table serve every modulus (see below)
    ======================================================  ==============================================

    *The shape/scale split.* A law whose pressure is proportional to one modulus declares it:
    ``_pressure_scale()`` the modulus (a float, or an array per point), ``_shape_key()`` everything
    else the law depends on as plain values (floats, ints, strings, tuples of them) and
    ``_unit_wall()`` the same law at unit modulus (whose ``_pressure_scale()`` is 1.0 and whose
    ``_shape_key()`` is the same). The couplers then share one table among every wall of the same
    class and shape (:mod:`tubefsi.couplers.tables`); ``tubefsi.testing`` checks the declaration.
    The declaration counts for the class whose body defines ``_shape_key`` (and for a registered
    wall, which the contract suite checks): a subclass that only inherits it may have changed the
    law or added a parameter, so its instances share nothing until it defines its own. A law that
    declares nothing gets no table: the same answers, from the direct path.

    Class attributes: ``is_rigid`` (True only for :class:`~tubefsi.walls.Rigid`),
    ``closed_form_integral`` (True where ``_power_law_integral`` is implemented, which makes
    the ``closed-form`` coupler available for power-law fluids) and ``calibrated_strain`` (the
    largest hoop strain the law is meant for: ``solve`` warns beyond it).
    """

    __slots__ = ()

    #: True only for the rigid wall, whose tube law is the vertical line ``stretch = 1``.
    is_rigid: ClassVar[bool] = False
    #: The largest hoop strain the law is meant for (the range its constants were calibrated
    #: on, or 0.05 for small-strain theory): beyond it ``solve`` issues a ModelValidityWarning.
    calibrated_strain: ClassVar[float] = math.inf
    #: Example parameter sets (keyword dicts) run through the contract suites of :mod:`tubefsi.testing`.
    _examples: ClassVar[tuple] = ()
    #: True where ``_power_law_integral`` gives the separated integral of a power-law fluid in
    #: closed form (``docs/theory.md``, section "Closed forms and removable singularities").
    closed_form_integral: ClassVar[bool] = False

    # ------------------------------------------------------------------ public API
    # Every argument broadcasts with the others and with the wall's array parameters (NumPy's
    # rules); scalars give a float, arrays an array of the broadcast shape.
    def pressure(self, stretch, reduced_thickness):
        r"""Transmural pressure :math:`P(\lambda; \bar t)` (Pa) at hoop stretch ``stretch``."""
        tb = _check_thickness(reduced_thickness)

        def fn(wall, lam, tb):
            return wall._pressure_at_strain(wall._check_stretch(lam, tb) - 1.0, tb)

        with _quiet():            # (a value beyond the doubles is the typed error below, not a warning)
            return _finite("stretch", stretch, "pressure", evaluate(self, fn, _as_floats("stretch", stretch), tb))

    def stretch(self, pressure, reduced_thickness):
        r"""Hoop stretch :math:`\lambda = R/a` under transmural pressure ``pressure`` (Pa)."""
        strain = self.strain(pressure, reduced_thickness)
        return 1.0 + strain

    def strain(self, pressure, reduced_thickness):
        r"""Hoop strain :math:`\lambda - 1 = u/a`, computed without forming ``stretch - 1``.

        Raises
        ------
        NoSteadyStateError
            If ``pressure`` reaches the wall's limit pressure.
        """
        tb = _check_thickness(reduced_thickness)

        def fn(wall, p, tb):
            return wall._strain(wall._check_pressure(p, tb), tb)

        with _quiet():
            return _finite("pressure", pressure, "strain", evaluate(self, fn, _as_floats("pressure", pressure), tb))

    def stiffness(self, stretch, reduced_thickness):
        r"""Tube-law slope :math:`dP/d\lambda` (Pa)."""
        tb = _check_thickness(reduced_thickness)

        def fn(wall, lam, tb):
            return wall._stiffness(wall._check_stretch(lam, tb), tb)

        with _quiet():
            return _finite("stretch", stretch, "stiffness", evaluate(self, fn, _as_floats("stretch", stretch), tb))

    def limit_pressure(self, reduced_thickness):
        r"""The pressure the wall can never reach (Pa); ``inf`` for most laws (and where it is
        beyond double precision)."""
        tb = _check_thickness(reduced_thickness)
        with _quiet():
            return _not_nan("reduced_thickness", tb, "limit pressure",
                            evaluate(self, lambda wall, tb: wall._limit_pressure(tb) + 0.0 * tb, tb))

    def max_stretch(self, reduced_thickness):
        """The largest admissible stretch (``inf`` unless the material locks)."""
        tb = _check_thickness(reduced_thickness)
        with _quiet():
            return _not_nan("reduced_thickness", tb, "maximum stretch",
                            evaluate(self, lambda wall, tb: wall._max_stretch(tb) + 0.0 * tb, tb))

    def min_pressure(self, reduced_thickness):
        r"""The most negative transmural pressure the wall holds (Pa): 0 for a wall that only
        inflates, minus the buckling pressure of an axisymmetric wall, ``-inf`` for a collapsible
        tube law."""
        return evaluate(self, lambda wall, tb: wall._min_pressure(tb) + 0.0 * tb,
                        _check_thickness(reduced_thickness))

    def min_stretch(self, reduced_thickness):
        """The smallest admissible stretch: the stretch at :meth:`min_pressure`."""
        return evaluate(self, lambda wall, tb: wall._min_stretch(tb) + 0.0 * tb,
                        _check_thickness(reduced_thickness))

    def small_strain_modulus(self, reduced_thickness):
        r""":math:`dP/d\lambda` at :math:`\lambda = 1` (Pa): the slope of the linear limit."""
        tb = _check_thickness(reduced_thickness)
        with _quiet():
            return _finite("reduced_thickness", tb, "small-strain modulus",
                           evaluate(self, lambda wall, tb: wall._stiffness(np.ones(np.shape(tb)), tb), tb))

    def _repr_html_(self) -> str:
        """The notebook summary: the class, its registered name and the parameters with units."""
        return model_html(self, "wall")

    def plot(self, reduced_thickness, *, ax=None, max_stretch=None, **kwargs):
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

    def _pressure_at_log_stretch(self, log_stretch, strain, tb):
        """Pressure at log-stretch ``log_stretch`` whose strain ``expm1(log_stretch)`` is ``strain``
        (both arrays, given by a caller that has both); override where the log-stretch makes a
        cheaper exact form."""
        return self._pressure_at_strain(strain, tb)

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
        shape, wall, (lam, tb) = flat_points(self, stretch, tb)
        index = np.arange(lam.size)
        if self._natural() == "pressure":
            # central differences (the law is evaluated slightly below stretch 1, where it
            # still exists), steps kept clear of a locking stretch
            room = wall._max_stretch(tb) - lam
            step = 0.1 * np.minimum(lam, np.where(np.isfinite(room), 0.2 * room, np.inf))
            res = differentiate.derivative(lambda s, i: model_at(wall, i)._trial_pressure(s - 1.0, take(tb, i)), lam,
                                           args=(index,), initial_step=step, tolerances=_DIFF_TOL)
            return res.df.reshape(shape)
        # only the inverse is natural: dP/dlam = 1 / (d lam / dp), with steps no smaller than a
        # tenth of the pressure at strain 1e-6 (a strain law written as stretch - 1 cancels below it)
        p = wall._pressure_at_strain(lam - 1.0, tb)
        step = 0.1 * np.maximum(p, wall._pressure_at_strain(np.full(lam.shape, 1e-6), tb))
        res = differentiate.derivative(lambda q, i: model_at(wall, i)._strain(q, take(tb, i)), p, args=(index,),
                                       step_direction=np.where(p > 4 * step, 0, 1),
                                       initial_step=step, tolerances=_DIFF_TOL)
        return (1.0 / res.df).reshape(shape)

    def _log_slope(self, stretch, tb):
        r""":math:`\lambda\,dP/d\lambda = dP/d\ln\lambda` (override where a closed form saves work:
        the separated integrand evaluates it at every node)."""
        return stretch * self._stiffness(stretch, tb)

    def _limit_pressure(self, tb):
        return math.inf

    def _stiffness_decay_exponent(self, tb):
        r"""``kappa`` with :math:`dP/d\lambda \sim \lambda^{-\kappa}` as :math:`\lambda \to \infty`.

        Only used where the limit pressure is finite (to decide whether a maximum
        flow rate exists); estimated numerically unless overridden.
        """
        far = np.zeros(np.shape(tb))
        d0, d1 = self._stiffness(far + 1e5, tb), self._stiffness(far + 1e6, tb)
        return -np.log(d1 / d0) / np.log(10.0)

    def _power_law_integral(self, log_ratio, outlet_stretch, exponent, tb):
        r"""Closed form of :math:`\int_0^v s^{k+1} P'(s)\,du`, :math:`s = \lambda_{out} e^u`, or None.

        A wall that implements it sets ``closed_form_integral = True`` and gets the
        ``closed-form`` coupler for power-law fluids (:math:`k = 3n+1`).
        """
        return None

    def _power_law_integral_inverse(self, integral, outlet_stretch, exponent, tb):
        """Inverse of ``_power_law_integral`` in ``log_ratio`` where it is explicit, else None."""
        return None

    def _has_power_law_integral_inverse(self) -> bool:
        """Whether ``_power_law_integral_inverse`` gives an answer (asked before computing its argument)."""
        return type(self)._power_law_integral_inverse is not WallModel._power_law_integral_inverse

    def _max_stretch(self, tb):
        return math.inf

    def _min_pressure(self, tb):
        return 0.0

    def _installed_tube(self, tube):
        """The tube the flow sees, from the stress-free one (an axial pre-stretch changes it); the
        tube law's stretch is relative to its lumen."""
        return tube

    def _slope_kinks(self, tb):
        """Stretches (arrays aligned with ``tb``, NaN for none) where the tube law's slope or its
        derivative jumps; ``()`` for a smooth law."""
        return ()

    def _collapse_stretch(self, tb):
        """The stretch the law is never evaluated at or below (0; a material that also locks in
        compression raises it); the root finders of the collapsing branch stay above it."""
        return 0.0

    def _min_stretch(self, tb):
        p = np.asarray(self._min_pressure(tb), dtype=float) + 0.0 * np.asarray(tb, dtype=float)
        if np.all(p == 0):
            return 1.0 + 0.0 * p
        finite = np.isfinite(p)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            e = self._strain(np.where(finite, p, 0.0), tb)
        return np.where(p == 0, 1.0, np.where(finite, 1.0 + e, 0.0))

    def _pressure_estimate(self, strain, tb) -> Integral:
        """The pressure at hoop strain with its error estimate (exact unless the law integrates)."""
        return Integral.exact(self._pressure_at_strain(strain, tb))

    def _trial_pressure(self, strain, tb):
        """The pressure at a trial strain of an iteration: no warning (the answer is checked)."""
        return self._pressure_estimate(strain, tb).value

    # -- the opt-in shape/scale split (the class docstring): P = scale * P_hat(stretch; tb, shape)
    def _pressure_scale(self):
        """The modulus the tube law is proportional to (``P = scale * P_hat``); 1 unless declared."""
        return 1.0

    def _shape_key(self):
        """What the tube law depends on besides ``_pressure_scale``, as plain values; None (no
        split declared: no table is shared) unless overridden."""
        return None

    def _unit_wall(self):
        """The same law at unit modulus (``_pressure_scale() == 1.0``, the same ``_shape_key()``),
        for a declared split; None otherwise."""
        return None

    # ------------------------------------------------------------------ generic inverses
    def _invert_pressure(self, pressure, tb):
        """Hoop strain at ``pressure``: safeguarded Newton iteration with the stiffness (vectorized,
        bracketed below a maximum stretch), else bracketed root finding on ``_pressure_at_strain``."""
        shape, wall, (p, tb) = flat_points(self, pressure, tb)
        p = np.broadcast_to(p, (max(1, math.prod(shape)),))   # the root finders index their points
        lam_max = np.asarray(wall._max_stretch(tb), dtype=float) + 0.0 * p
        emax = lam_max - 1.0
        scale = np.maximum(wall._stiffness(np.ones(p.shape), tb), 1e-300)
        fast = wall._newton_strain(p, tb, emax, scale)
        if fast is not None:
            return fast.reshape(shape)
        index = np.arange(p.size)

        def f(e, p, i):
            return model_at(wall, i)._trial_pressure(e, take(tb, i)) - p

        negative = p < 0
        if np.any(negative):                     # the collapsing branch: strains in (min_stretch - 1, 0)
            out = np.zeros(p.shape)
            if not np.all(negative):
                pos = np.flatnonzero(~negative)
                out[pos] = model_at(wall, pos)._invert_pressure(p[pos], take(tb, pos))
            neg = np.flatnonzero(negative)
            bound = np.asarray(wall._collapse_stretch(tb), dtype=float) + 0.0 * p
            xmin = np.nextafter(bound[neg], 1.0) - 1.0        # inside the law's domain (the pressure is checked)
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                bracket = elementwise.bracket_root(f, np.maximum(-np.minimum(-p[neg] / scale[neg], 0.5), 0.5 * xmin),
                                                   np.zeros(neg.size), xmin=xmin, xmax=0.0, args=(p[neg], neg))
                res = elementwise.find_root(f, bracket.bracket, args=(p[neg], neg),
                                            tolerances=dict(xrtol=2 * np.finfo(float).eps, xatol=1e-300))
            if not np.all(bracket.success & res.success):
                bad = neg[int(np.argmax(~(bracket.success & res.success)))]
                raise BucklingError(float(np.broadcast_to(wall._min_pressure(tb), p.shape)[bad]), float(p[bad]),
                                    "the tube law never reaches it")
            out[neg] = res.x
            return out.reshape(shape)

        finite = np.isfinite(emax)
        guess = np.minimum(np.maximum(p / scale, 1e-300), np.where(finite, 0.5 * emax, np.inf))
        # never evaluate the law at a locking stretch (where it is singular): the largest strain
        # searched is that of the last double below the lock (lam - 1 is exact for lam < 2^53)
        xmax = np.where(finite, np.nextafter(lam_max, 1.0) - 1.0, 1e15)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            bracket = elementwise.bracket_root(f, np.zeros_like(p), np.maximum(guess, 1e-300),
                                               xmin=0.0, xmax=xmax, args=(p, index))
        if not np.all(bracket.success | (p == 0)):
            bad = int(np.argmax(~(bracket.success | (p == 0))))
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                top = float(model_at(wall, index[bad:bad + 1])._trial_pressure(
                    xmax[bad:bad + 1] * 0.999999, take(tb, index[bad:bad + 1]))[0])
            limit = float(np.broadcast_to(wall._limit_pressure(tb), p.shape)[bad])
            if not math.isfinite(top):      # the law leaves the doubles before it reaches the pressure
                raise InvalidParameterError("pressure", "pressures the tube law reaches within double precision",
                                            float(p[bad]), "the pressure overflows at a smaller stretch")
            if top < limit or not math.isfinite(limit):   # not a physical limit: the stretch cannot be told
                raise InvalidParameterError(
                    "pressure", f"[0, {top:.10g}] Pa", float(p[bad]),
                    f"beyond it the stretch is the largest the wall admits, {float(np.ravel(lam_max)[bad]):.10g}, to "
                    "double precision" if finite[bad] else "beyond it the strain exceeds 1e15")
            raise NoSteadyStateError("pressure", limit, float(p[bad]), "the tube law never reaches it")
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            res = elementwise.find_root(f, bracket.bracket, args=(p, index),
                                        tolerances=dict(xrtol=2 * np.finfo(float).eps, xatol=1e-300))
        wall._pressure_at_strain(res.x, tb)      # the answer's own error estimate (AccuracyWarning)
        return np.where(p == 0, 0.0, res.x).reshape(shape)

    def _newton_strain(self, p, tb, emax, scale):
        """The Newton path of :meth:`_invert_pressure` (flat, aligned arguments); None where it does
        not converge cleanly."""
        if self._natural() != "pressure":
            return None
        finite = np.isfinite(emax)
        upper = np.where(finite, 0.999999 * emax, np.inf) if np.any(finite) else None
        guess = np.where(finite, np.minimum(p / scale, 0.5 * emax), p / scale)
        lower = None
        if np.any(p < 0):                        # collapsing: strains above -1 (the pressure is checked)
            lower = np.asarray(self._collapse_stretch(tb), dtype=float) - 1.0 + 0.0 * p
            guess = np.maximum(guess, 0.5 * lower)
        try:
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):                        # trial strains: no warnings (the answer is checked below)
                e, ok = solve_signed(lambda x, i: model_at(self, i)._trial_pressure(x, take(tb, i)),
                                     lambda x, i: model_at(self, i)._stiffness(1.0 + x, take(tb, i)),
                                     p, guess=guess, lower=lower, upper=upper, xmax=1e15, maxiter=100)
        except ConvergenceError:
            return None
        with np.errstate(all="ignore"):
            converged = ok & np.isfinite(e) & (np.abs(self._pressure_at_strain(e, tb) - p) <= 1e-12 * np.abs(p))
        return e if np.all(converged) else None

    def _invert_strain(self, strain, tb):
        """Pressure at a strain when only the inverse law ``_strain`` is natural."""
        shape, wall, (e, tb) = flat_points(self, strain, tb)
        e = np.broadcast_to(e, (max(1, math.prod(shape)),))   # with the parameters: a scalar strain too
        index = np.arange(e.size)

        def f(p, e, i):
            return model_at(wall, i)._strain(p, take(tb, i)) - e

        lim = np.asarray(wall._limit_pressure(tb), dtype=float) + 0.0 * e
        low = np.asarray(wall._min_pressure(tb), dtype=float) + 0.0 * e
        hi = np.maximum(np.abs(e), 1e-300) * 10.0
        neg = e < 0                              # the collapsing branch brackets below zero
        bracket = elementwise.bracket_root(f, np.where(neg, np.maximum(-hi, low / 2), 0.0), np.where(neg, 0.0, hi),
                                           xmin=np.where(neg, low, 0.0),
                                           xmax=np.where(neg, 0.0, np.where(np.isfinite(lim), lim, np.inf)),
                                           args=(e, index))
        res = elementwise.find_root(f, bracket.bracket, args=(e, index),
                                    tolerances=dict(xrtol=2 * np.finfo(float).eps, xatol=1e-300))
        return np.where(e == 0, 0.0, res.x).reshape(shape)

    # ------------------------------------------------------------------ validation (vectorized)
    @staticmethod
    def _check_thickness(reduced_thickness):
        """The reduced thickness t/a: finite and > 0 (a float or an array)."""
        return _check_thickness(reduced_thickness)

    def _check_stretch(self, lam, tb):
        """``lam`` (flat, aligned with the wall's parameters) checked against ``[1, max_stretch)``."""
        lam = np.asarray(lam, dtype=float)
        # (the minimum stretch may cost an inverse: only asked for where a stretch is below 1)
        low = np.asarray(self._min_stretch(tb) if np.any(lam < 1) else 1.0, dtype=float)
        values, top, low = np.broadcast_arrays(lam, np.asarray(self._max_stretch(tb), dtype=float), low)
        with np.errstate(invalid="ignore"):
            # (a few ulps below the minimum stretch pass: the inverse at min_pressure is rounded)
            ok = np.isfinite(values) & (values >= low * (1.0 - 8 * np.finfo(float).eps)) & (values > 0) & (values < top)
        if not np.all(ok):
            i = int(np.argmax(~ok.ravel()))
            t, b = float(top.flat[i]), float(low.flat[i])
            lo = "(0" if b == 0 else f"[{b:.10g}"
            raise InvalidParameterError("stretch", f"{lo}, inf)" if t == math.inf else f"{lo}, {t:.10g})",
                                        float(values.flat[i]))
        return lam

    def _check_pressure(self, p, tb):
        """``p`` (flat, aligned) checked against ``[min_pressure, limit_pressure)``."""
        p = np.asarray(p, dtype=float)
        values, lim, low = np.broadcast_arrays(p, np.asarray(self._limit_pressure(tb), dtype=float),
                                               np.asarray(self._min_pressure(tb) if np.any(p < 0) else 0.0,
                                                          dtype=float))
        with np.errstate(invalid="ignore"):
            bad = np.isnan(values) | (values == math.inf) | ((values < 0) & (low == 0))   # a wall that only inflates
            below = (values < low) & (low < 0)
            beyond = values >= lim
        if np.any(bad):
            i = int(np.argmax(bad.ravel()))
            raise InvalidParameterError("pressure", "[0, inf)" if low.flat[i] == 0 else "the real numbers",
                                        float(values.flat[i]))
        if np.any(below):
            i = int(np.argmax(below.ravel()))
            raise BucklingError(float(low.flat[i]), float(values.flat[i]),
                                f"{type(self).__name__} buckles (it is no longer axisymmetric)")
        if np.any(beyond):
            i = int(np.argmax(beyond.ravel()))
            raise NoSteadyStateError("pressure", float(lim.flat[i]), float(values.flat[i]),
                                     f"{type(self).__name__} cannot sustain it")
        return p


#: The admissible reduced thickness t/a: every tube law is evaluated in double precision there
#: (``(1 + t/a)^2`` and ``t/a`` times a modulus stay far inside its range).
THICKNESS_RANGE = (1e-100, 1e100)


def _finite(name, value, result_name, result):
    """``result`` if every entry is finite, else an :class:`InvalidParameterError` naming the
    argument whose value takes the result beyond double precision (or gives it no value)."""
    r = np.asarray(result)
    if np.all(np.isfinite(r)):
        return result
    bad = int(np.argmax(~np.isfinite(r).ravel()))
    v = np.broadcast_to(np.asarray(value, dtype=float), r.shape).ravel()[bad]
    raise InvalidParameterError(name, f"values whose {result_name} is a finite double", float(v),
                                f"the {result_name} would be {r.ravel()[bad]!r}")


def _not_nan(name, value, result_name, result):
    """``result`` (which may be infinite: no limit), or an :class:`InvalidParameterError` naming the
    argument where it has no value."""
    r = np.asarray(result)
    if not np.any(np.isnan(r)):
        return result
    bad = int(np.argmax(np.isnan(r).ravel()))
    v = np.broadcast_to(np.asarray(value, dtype=float), r.shape).ravel()[bad]
    raise InvalidParameterError(name, f"values whose {result_name} is a double", float(v),
                                f"the {result_name} has no value there in double precision")


def _check_thickness(reduced_thickness):
    """The reduced thickness t/a, in :data:`THICKNESS_RANGE` (a float or an array)."""
    low, high = THICKNESS_RANGE
    return as_array("reduced_thickness", reduced_thickness, f"[{low:g}, {high:g}]", lambda a: (a >= low) & (a <= high))


def _as_floats(name, value):
    """A float array of ``value``; the range is checked by the caller (it depends on the wall)."""
    a = real_array(name, value, "the real numbers")
    if not np.all(np.isfinite(a) | (a == np.inf)):
        raise InvalidParameterError(name, "the real numbers", float(a[np.isnan(a)].flat[0]) if a.ndim else float(a))
    return a
