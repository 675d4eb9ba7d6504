r"""The rheology contract: a generalized Newtonian fluid in simple shear.

A subclass implements ``_stress(shear_rate)`` *or* ``_shear_rate(stress)`` (for
positive arguments). The base class derives the inverse, the apparent viscosity
and, from the Rabinowitsch–Mooney integral with :math:`\tau = G r/2`,

.. math::

    q(R, G) = \frac{\pi R^3}{\tau_w^3}\int_0^{\tau_w} \tau^2\,\dot\gamma(\tau)\,d\tau,
    \qquad \tau_w = \frac{G R}{2},

the tube flow function, its inverse ``pressure_gradient(q, R)`` and the velocity
profile :math:`v(r) = \int_r^R \dot\gamma(G\rho/2)\,d\rho`.

A *separable* rheology (Newtonian, power law) has
:math:`G(q, R) = \phi(q)\,\psi(R)`; it sets ``separable = True`` and implements
``_flow_factor`` (:math:`\phi`), ``_flow_factor_inverse`` and ``_radius_factor``
(:math:`\psi`). Couplers then reuse one integral for a whole flow curve.

A *yield-stress* fluid (Bingham, Herschel–Bulkley, Casson, ...) has a field
``yield_stress`` :math:`\tau_y > 0`: ``_shear_rate`` is 0 for :math:`\tau \le \tau_y`
and ``_stress(shear_rate)`` tends to :math:`\tau_y` as the shear rate tends to 0. The
generic paths integrate only over the yielded region: no flow while the wall stress
:math:`GR/2 \le \tau_y`, a plug :math:`r < 2\tau_y/G` in the velocity profile, and
:math:`G(q, R) \to 2\tau_y/R` (the yield gradient) as :math:`q \to 0^+`.
"""

from __future__ import annotations

import abc
import math
from typing import ClassVar

import attrs
import numpy as np

from .._html import model_html
from .._validation import as_array
from ..errors import InvalidParameterError
from ..fields import _array_fields, broadcast_model, evaluate, model_at, parameter_sets
from ..numerics.quadrature import unit_integral
from . import flow_map
from .flow_law import check, flow_table, rate_natural_rate, stress_natural_rate

__all__ = ["Rheology"]


def _overrides(obj, name) -> bool:
    return getattr(type(obj), name) is not getattr(Rheology, name)


class Rheology(abc.ABC):
    r"""Abstract base of every rheology (see the module docstring for the contract). Its
    parameters are numbers or arrays, never functions of z (``varies_along_z = False``).

    Hooks (arrays of positive arguments; implement one of the first two, override the
    others for speed or accuracy):

    ===============================  ======================================================================
    hook (arguments)                 default
    ===============================  ======================================================================
    ``_stress(shear_rate)``          natural hook, or the inverse of ``_shear_rate`` (a root solve)
    ``_shear_rate(stress)``          natural hook, or the inverse of ``_stress``
    ``_apparent_shear_rate``         ``(wall_stress, excess=None)``: :math:`\Gamma = 4q/(\pi R^3)` by the
                                     Rabinowitsch–Mooney integral (error-controlled adaptive quadrature)
    ``_flow_rate``                   ``(radius, pressure_gradient)``: :math:`\pi R^3\Gamma(GR/2)/4`
    ``_pressure_gradient``           ``(flow_rate, radius)``: the inverse, from the flow map built for
                                     the call (:mod:`~tubefsi.rheology.flow_map`), else a cached,
                                     error-checked table of :math:`\ln(\tau_w - \tau_y)` against :math:`\ln\Gamma`
    ``_velocity``                    ``(r, radius, pressure_gradient)``:
                                     :math:`\int_r^R \dot\gamma(G\rho/2)\,d\rho` by adaptive quadrature
    ``_flow_index``                  ``(flow_rate, radius)``: :math:`\partial\ln G/\partial\ln q`, from the
                                     wall shear rate (for the sensitivities)
    ``_log_gradient_derivative``     ``(parameter, flow_rate, radius)``: :math:`\partial\ln G/\partial\theta`
                                     (a central difference; for :func:`tubefsi.fit`)
    ``_flow_factor``                 separable rheologies only: :math:`\phi(q)` in :math:`G = \phi(q)\psi(R)`,
    ``_flow_factor_inverse``         its inverse,
    ``_radius_factor``               and :math:`\psi(R)`
    ``_log_flow_factor``             :math:`\ln\phi(q)` (default: the log of ``_flow_factor``)
    ===============================  ======================================================================

    Class attributes: ``separable``, ``radius_exponent`` (:math:`k` with
    :math:`\psi(R) = R^{-k}`, for power-law-like fluids: enables the ``closed-form``
    coupler; None otherwise), ``yield_stress`` (0 unless the fluid declares a
    ``yield_stress`` field), ``_gradient_scales`` (the fields :math:`\theta` that :math:`G` is
    proportional to: their sensitivities need no integral along the tube) and ``_examples``
    (parameter sets for the contract suites).
    """

    __slots__ = ()

    #: True when ``pressure_gradient(q, R) = phi(q) * psi(R)``.
    separable: ClassVar[bool] = False
    #: Parameters may not be functions of z (a fluid does not vary along the tube).
    varies_along_z: ClassVar[bool] = False
    #: :math:`k` with :math:`G(q, R) = \phi(q) R^{-k}` (power law: :math:`3n+1`); None if not of that form.
    radius_exponent = None
    #: The yield stress (Pa); a yield-stress fluid declares it as a field.
    yield_stress = 0.0
    #: Fields :math:`\theta` with :math:`G \propto \theta` (:math:`\partial\ln G/\partial\theta = 1/\theta`).
    _gradient_scales: ClassVar[tuple] = ()
    #: Example parameter sets (keyword dicts) run through the contract suites of :mod:`tubefsi.testing`.
    _examples: ClassVar[tuple] = ()

    # ------------------------------------------------------------------ public API
    # Arguments and array parameters broadcast together (tubefsi.fields.evaluate); a
    # non-separable rheology is evaluated per parameter set (its flow table is per set).
    def _evaluate(self, fn, *args):
        return evaluate(self, fn, *args, per_set=not self.separable)

    def stress(self, shear_rate):
        """Shear stress (Pa) at shear rate ``shear_rate`` (1/s, >= 0)."""
        g = as_array("shear_rate", shear_rate, "[0, inf)", lambda a: a >= 0)
        with _quiet():
            return _finite_result("shear_rate", g, "stress",
                                  self._evaluate(lambda m, g: _masked(m, "_stress", g > 0, g), g))

    def shear_rate(self, stress):
        """Shear rate (1/s) at shear stress ``stress`` (Pa, >= 0)."""
        t = as_array("stress", stress, "[0, inf)", lambda a: a >= 0)
        with _quiet():
            return _finite_result("stress", t, "shear rate",
                                  self._evaluate(lambda m, t: _masked(m, "_shear_rate", t > 0, t), t))

    def _repr_html_(self) -> str:
        """The notebook summary: the class, its registered name and the parameters with units."""
        return model_html(self, "rheology")

    def apparent_viscosity(self, shear_rate):
        r"""Apparent viscosity :math:`\eta = \tau/\dot\gamma` (Pa s), shear rate > 0."""
        g = as_array("shear_rate", shear_rate, "(0, inf)", lambda a: a > 0)
        with _quiet():
            return _finite_result("shear_rate", g, "apparent viscosity",
                                  self._evaluate(lambda m, g: m._stress(g) / g, g))

    def flow_rate(self, radius, pressure_gradient):
        r"""Flow rate :math:`q(R, G)` (m^3/s) in a rigid tube of radius ``radius`` (m)
        under pressure gradient :math:`G = -dp/dz` (Pa/m)."""
        r = as_array("radius", radius, "(0, inf)", lambda a: a > 0)
        g = as_array("pressure_gradient", pressure_gradient, "[0, inf)", lambda a: a >= 0)
        with _quiet():
            out = self._evaluate(lambda m, r, g: _masked(m, "_flow_rate", g > 0, r, g), r, g)
        return _finite_result("pressure_gradient", g, "flow rate", out)

    def pressure_gradient(self, flow_rate, radius):
        r"""Pressure gradient :math:`G(q, R) = -dp/dz` (Pa/m) that drives ``flow_rate`` (m^3/s)."""
        q = as_array("flow_rate", flow_rate, "[0, inf)", lambda a: a >= 0)
        r = as_array("radius", radius, "(0, inf)", lambda a: a > 0)
        out = self._evaluate(lambda m, q, r: _masked(m, "_pressure_gradient", q > 0, q, r), q, r)
        _finite_result("flow_rate", q, "pressure gradient", out)
        return out

    def velocity(self, r, radius, pressure_gradient):
        r"""Axial velocity (m/s) at radial position ``r`` (0 <= r <= radius)."""
        rr = as_array("r", r, "[0, radius]", lambda a: a >= 0)
        big_r = as_array("radius", radius, "(0, inf)", lambda a: a > 0)
        g = as_array("pressure_gradient", pressure_gradient, "[0, inf)", lambda a: a >= 0)
        rb, bb = np.broadcast_arrays(rr, big_r)
        if np.any(rb > bb * (1 + 1e-12)):
            raise _invalid("r", "[0, radius]", rb[rb > bb * (1 + 1e-12)].flat[0])
        with _quiet():
            out = self._evaluate(lambda m, rr, big_r, g: _masked(
                m, "_velocity", g > 0, np.minimum(rr, big_r), big_r, g), rr, big_r, g)
        return _finite_result("pressure_gradient", g, "velocity", out)

    # ------------------------------------------------------------------ hooks
    def _stress(self, shear_rate):
        if not _overrides(self, "_shear_rate"):
            raise TypeError(f"{type(self).__name__} must implement _stress or _shear_rate")
        g = np.asarray(shear_rate, dtype=float)
        tau_y = float(self.yield_stress)
        scale = float(np.asarray(self._shear_rate(np.asarray([tau_y + 1.0]))).ravel()[0])
        guess = tau_y + (g / scale if scale > 0 else g)        # the Newtonian law through tau_y + 1
        return _solve_increasing(self._shear_rate, g, guess, 0.0, lower=tau_y, name="shear_rate")

    def _shear_rate(self, stress):
        if not _overrides(self, "_stress"):
            raise TypeError(f"{type(self).__name__} must implement _stress or _shear_rate")
        t = np.asarray(stress, dtype=float)
        if _holds_arrays(self):
            # fluids given as arrays, one per point (broadcast against the stresses): each point's
            # root with its own parameters (the iteration asks for subsets of the points)
            shape = np.broadcast_shapes(t.shape, *(np.shape(getattr(self, n)) for n in _array_fields(type(self))))
            flat = broadcast_model(self, shape)
            tf = np.broadcast_to(t, shape).ravel()
            tau_y = np.broadcast_to(np.asarray(self.yield_stress, dtype=float), shape).ravel()
            live = np.flatnonzero(tf > tau_y)
            out = np.zeros(tf.size)
            if live.size:
                sub = model_at(flat, live)
                scale = np.asarray(sub._stress(np.ones(live.size)), dtype=float) - tau_y[live]
                guess = np.where(scale > 0, (tf[live] - tau_y[live]) / np.where(scale > 0, scale, 1.0), tf[live])
                out[live] = _solve_increasing(sub._stress, tf[live], guess, tau_y[live],
                                              law_at=lambda idx: model_at(sub, idx)._stress)
            return out.reshape(shape)
        tau_y = float(self.yield_stress)
        flowing = t > tau_y
        out = np.zeros(t.shape)
        if np.any(flowing):
            tt = t[flowing]
            scale = float(np.asarray(self._stress(np.ones(1))).ravel()[0]) - tau_y
            guess = (tt - tau_y) / scale if scale > 0 else tt
            out[flowing] = _solve_increasing(self._stress, tt, guess, tau_y)
        return out

    def _flow_rate(self, radius, pressure_gradient):
        if self.separable:
            return self._flow_factor_inverse(pressure_gradient / self._radius_factor(radius))
        tau_w = 0.5 * pressure_gradient * radius
        with np.errstate(invalid="ignore"):
            rate = self._apparent_shear_rate(tau_w)
        # a wall stress beyond the doubles carries a flow beyond them (inf, where the closed forms'
        # ratios of stresses are inf/inf): the caller's typed error, not a NaN that reads as no flow
        return 0.25 * math.pi * radius**3 * np.where(tau_w == math.inf, math.inf, rate)

    def _rabinowitsch_mooney(self, radius, pressure_gradient):
        """The generic flow function (quadrature), whatever the subclass overrides."""
        return 0.25 * math.pi * radius**3 * Rheology._apparent_shear_rate(self, 0.5 * pressure_gradient * radius)

    def _apparent_shear_rate(self, wall_stress, excess=None):
        r"""Apparent wall shear rate :math:`\Gamma = 4q/(\pi R^3)` at wall stress :math:`\tau_w`.

        ``excess``, if given, is :math:`\tau_w - \tau_y` computed by the caller without
        cancellation (the flow table passes it): near the yield point the flow depends on it,
        not on :math:`\tau_w`. Overrides must accept it.

        :math:`\Gamma = 4\int_0^1 t^2\dot\gamma(\tau_w t)\,dt` when the shear rate is natural;
        else, integrating by parts in the shear rate,
        :math:`\Gamma = \tfrac43\dot\gamma_w\int_0^1 \bigl[1 - (\tau(\dot\gamma_w t)/\tau_w)^3\bigr]dt`.
        With a yield stress the first runs over the yielded part
        :math:`\tau_y/\tau_w < t < 1` only (0 when :math:`\tau_w \le \tau_y`). Both by adaptive
        Gauss–Kronrod quadrature graded toward :math:`t = 0`
        (:func:`tubefsi.numerics.quadrature.unit_integral`), to a relative error estimate of 1e-14
        per point: a kinked law is resolved by bisection at its kink; a point that misses the
        tolerance is an ``AccuracyWarning`` stating its estimate. Closed forms (Buckingham–Reiner
        for Bingham, ...) may override it.
        """
        tau_w = np.asarray(wall_stress, dtype=float)
        if _overrides(self, "_shear_rate"):
            gamma, res = rate_natural_rate(self, tau_w, excess if float(self.yield_stress) > 0 else None)
        else:
            flowing = tau_w > float(self.yield_stress)
            rate_w = np.zeros(tau_w.shape)
            if np.any(flowing):
                rate_w[flowing] = self._shear_rate(tau_w[flowing])
            gamma, res = stress_natural_rate(self, rate_w, tau_w)
        check("the Rabinowitsch–Mooney integral", res)
        return gamma

    def _pressure_gradient(self, flow_rate, radius):
        r""":math:`G(q, R)`; at ``q = 0`` the limit :math:`q \to 0^+`: 0, or the yield gradient
        :math:`2\tau_y/R` of a yield-stress fluid (non-separable rheologies)."""
        if self.separable:
            return self._flow_factor(flow_rate) * self._radius_factor(radius)
        q = np.asarray(flow_rate, dtype=float)
        r = np.asarray(radius, dtype=float)
        rate = np.multiply(r, r)                   # 4 q / (pi R^3), in place: few temporaries
        rate *= r
        if isinstance(rate, np.ndarray) and rate.ndim and rate.shape == np.broadcast_shapes(q.shape, r.shape):
            np.divide(q, rate, out=rate)
        else:
            rate = q / rate
        rate *= 4.0 / math.pi
        if _holds_arrays(self) or flow_map.kind(self) is not None:    # the flow map, per call
            out = _mapped_wall_stress(self, rate)
        else:                       # a law the maps do not serve: its flow table
            out = flow_table(self).wall_stress(self, rate)
        out *= 2.0
        out /= r
        return out

    def _velocity(self, r, radius, pressure_gradient):
        return self._velocity_generic(r, radius, pressure_gradient)

    def _velocity_generic(self, r, radius, pressure_gradient):
        r""":math:`v(r) = \int_r^R \dot\gamma(G\rho/2)\,d\rho` by adaptive quadrature graded toward
        the lower end (the plug radius of a yield-stress fluid, where the shear rate behaves as a
        power of the distance); for a stress-natural law, by parts in the shear rate,
        :math:`\frac{2}{G}\bigl[\int_{\dot\gamma_r}^{\dot\gamma_w}(\tau_w - \tau(g))\,dg
        + \dot\gamma_r(\tau_w - \tau_r)\bigr]` (positive terms: no cancellation)."""
        r, radius, g = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (r, radius, pressure_gradient)))
        shape = r.shape
        r, radius, g = r.ravel(), radius.ravel(), g.ravel()
        out = np.zeros(r.shape)
        tau_y = float(self.yield_stress)
        if _overrides(self, "_shear_rate"):
            lower = np.maximum(r, np.minimum(radius, 2.0 * tau_y / g)) if tau_y > 0.0 else r
            width = radius - lower       # the yielded annulus only: the plug moves rigidly
            live = np.flatnonzero(width > 0)
            if live.size:
                lo, wd, kk = lower[live], width[live], 0.5 * g[live]

                def f(u, idx):
                    return self._shear_rate(_positive(kk[idx, None] * (lo[idx, None] + wd[idx, None] * u)))

                rounding = None
                if tau_y > 0.0:      # near the plug the law resolves tau - tau_y only to eps tau_y
                    def rounding(u, idx):
                        return 4.0 * np.finfo(float).eps * tau_y / _positive(kk[idx, None] * wd[idx, None] * u)

                res = unit_integral(f, live.size, relative_rounding=rounding)
                out[live] = wd * res.value
                check("the velocity integral", (res, live))
            return out.reshape(shape)
        tau_r, tau_w = 0.5 * g * r, 0.5 * g * radius
        live = np.flatnonzero(radius > r)
        if live.size:
            tr, tw = tau_r[live], tau_w[live]
            rate_r = np.zeros(live.size)
            moving = tr > tau_y
            if np.any(moving):
                rate_r[moving] = self._shear_rate(tr[moving])
            rate_w = self._shear_rate(tw)
            span = rate_w - rate_r

            def f(u, idx):
                # tau(g) <= tau_w inside the tube: a rounding above it counts nothing (no negative velocity)
                return np.maximum(tw[idx, None] - self._stress(_positive(rate_r[idx, None] + span[idx, None] * u)), 0.0)

            # tau_w - tau(g) is rounded to a few eps tau_w: near the wall that is all there is of it
            res = unit_integral(f, live.size, rounding=lambda idx: 4.0 * np.finfo(float).eps * tw[idx])
            # (2/G) times each term, with 2 gap / G = R - r: no product of a shear rate and a
            # stress, which leaves the doubles long before the velocity does
            out[live] = span * (2.0 * (res.value / g[live])) + rate_r * (radius[live] - r[live])
            check("the velocity integral", (res, live))
        return out.reshape(shape)

    def _flow_index(self, flow_rate, radius):
        r"""The local flow index :math:`k = \partial\ln G/\partial\ln q` at fixed radius (1 for a
        Newtonian fluid, n for a power law): the sensitivities of a solve are built from it
        (``docs/theory.md``, section "Sensitivities").

        From the Rabinowitsch–Mooney integral,
        :math:`d\ln\Gamma/d\ln\tau_w = 4\dot\gamma(\tau_w)/\Gamma - 3`, so
        :math:`k = \Gamma/(4\dot\gamma_w - 3\Gamma)`; at ``q = 0`` the limit
        :math:`q \to 0^+` (taken at an apparent shear rate of 1e-30/s)."""
        q = np.asarray(flow_rate, dtype=float)
        r = np.asarray(radius, dtype=float)
        rate = 4.0 * q / (math.pi * r**3)
        rate = np.where(rate > 0, rate, 1e-30)
        tau_w = 0.5 * r * self._pressure_gradient(0.25 * math.pi * r**3 * rate, r)
        rate_w = self._shear_rate(tau_w)
        return rate / (4.0 * rate_w - 3.0 * rate)

    def _log_gradient_derivative(self, parameter: str, flow_rate, radius):
        r""":math:`\partial\ln G/\partial\theta` at fixed flow rate and radius, for the field
        ``parameter`` :math:`\theta` (the derivatives of a fit: ``docs/theory.md``, section
        "Sensitivities"). The default: central differences of :math:`\ln G` at relative steps
        1e-3 and 5e-4, Richardson-extrapolated (truncation :math:`O(10^{-12})`, rounding
        :math:`\sim 10^{-13}|\ln G|`); closed forms override it."""
        value = np.asarray(getattr(self, parameter), dtype=float)
        step = 1e-3 * np.where(value == 0, 1.0, np.abs(value))

        def central(h):
            up = attrs.evolve(self, **{parameter: value + h})._pressure_gradient(flow_rate, radius)
            down = attrs.evolve(self, **{parameter: value - h})._pressure_gradient(flow_rate, radius)
            return (np.log(up) - np.log(down)) / (2.0 * h)

        return (4.0 * central(0.5 * step) - central(step)) / 3.0

    # separable rheologies implement these three
    def _flow_factor(self, flow_rate):
        raise NotImplementedError

    def _flow_factor_inverse(self, factor):
        raise NotImplementedError

    def _log_flow_factor(self, flow_rate):
        r""":math:`\ln\phi(q)` (optional, for speed and range: the tables work in logs)."""
        with np.errstate(divide="ignore"):
            return np.log(self._flow_factor(flow_rate))

    def _radius_factor(self, radius):
        raise NotImplementedError


def _holds_arrays(model) -> bool:
    return any(np.ndim(getattr(model, n)) for n in _array_fields(type(model)))


def _mapped_wall_stress(model, rate):
    r""":math:`\tau_w` at the apparent rates ``rate`` of a fluid (its array parameters broadcast
    against ``rate``): from :func:`~tubefsi.rheology.flow_map.wall_stress`, built for the call,
    where it vouches for a point, else from the flow table of that point's parameter set (no table
    is shared between sets; a fluid the maps serve gets one only where its map fails)."""
    tau, ok = flow_map.wall_stress(model, rate) if flow_map.kind(model) is not None else (None, None)
    shape = np.broadcast_shapes(np.shape(rate), *(np.shape(getattr(model, n)) for n in _array_fields(type(model))))
    if tau is None:
        tau, ok = np.full(shape, np.nan), np.zeros(shape, dtype=bool)
    if np.all(ok):
        return tau
    tau, flat_rate = tau.ravel(), np.broadcast_to(rate, shape).ravel()
    missing = np.flatnonzero(~ok.ravel())
    sub = model_at(broadcast_model(model, shape), missing)
    for part, scalar in parameter_sets(sub, (missing.size,)):
        tau[missing[part]] = flow_table(scalar).wall_stress(scalar, flat_rate[missing[part]])
    return tau.reshape(shape)


def _masked(model, hook, mask, *args):
    """``model.<hook>(*args)`` where ``mask`` holds, 0 elsewhere (flat arguments, or scalars; the
    model's array parameters aligned with the flat arguments)."""
    shape = np.broadcast_shapes(*(np.shape(a) for a in args), np.shape(mask))
    mask = np.broadcast_to(mask, shape)
    out = np.zeros(shape)
    if shape == ():
        return getattr(model, hook)(*args) if mask else 0.0
    index = np.flatnonzero(mask.ravel())
    if index.size:
        sub = model_at(model, index) if any(np.ndim(getattr(model, n)) for n in _array_fields(type(model))) \
            else model
        picked = [np.broadcast_to(a, shape).ravel()[index] for a in args]
        out.ravel()[index] = getattr(sub, hook)(*picked)
    return out


def _quiet():
    """The public methods evaluate the law quietly: a result beyond the doubles is a typed error
    (:func:`_finite_result`), and an intermediate overflow of a form that stays finite is no news."""
    return np.errstate(over="ignore", invalid="ignore", divide="ignore")


def _finite_result(name, value, what, result):
    """``result``; :class:`InvalidParameterError` naming ``name`` where it is not a finite double
    (the true value leaves double precision: the forms are written to stay finite wherever it does)."""
    ok = np.isfinite(result)
    if np.all(ok):
        return result
    i = int(np.argmax(~np.ravel(ok)))
    raise InvalidParameterError(name, f"values whose {what} is a finite double",
                                float(np.broadcast_to(value, np.shape(result)).ravel()[i]),
                                f"the {what} would be {np.ravel(result)[i]!r}")


def _positive(x):
    return np.maximum(x, np.finfo(float).tiny)


def _solve_increasing(law, target, guess, floor, lower=0.0, name="stress", law_at=None):
    r"""``x > lower`` with ``law(x) = target`` elementwise, for an increasing law with
    ``law(lower+) = floor < target``: a bracket by steps doubling in :math:`\ln(x - lower)` from
    ``guess``, geometric bisection down to a ratio of 2, then Illinois (regula falsi) steps to a
    relative width of 4 eps. Vectorized; about a dozen law evaluations per point."""
    target = np.asarray(target, dtype=float)
    shape = target.shape
    t = target.ravel()
    n = t.size
    if n == 0:
        return np.zeros(shape)
    big, tiny = 1e300, 1e-300

    def f(x, idx=None):
        fn = law if idx is None or law_at is None else law_at(idx)     # (a law of one fluid per point)
        with np.errstate(over="ignore", invalid="ignore"):
            v = np.asarray(fn(lower + x), dtype=float) - (t if idx is None else t[idx])
        return np.where(np.isnan(v), np.inf, v)

    d = np.clip(np.broadcast_to(np.asarray(guess, dtype=float), shape).ravel() - lower, tiny, big)
    fd = f(d)
    lo = np.where(fd < 0, d, 0.0)
    flo = np.where(fd < 0, fd, floor - t)
    hi = np.where(fd >= 0, d, np.inf)
    fhi = np.where(fd >= 0, fd, np.inf)
    for k in range(11):                       # expand: factors e^1, e^2, e^4, ... (up to e^1024)
        up = np.flatnonzero(~np.isfinite(hi))
        down = np.flatnonzero((lo == 0.0) & (d > tiny) & np.isfinite(hi))
        if not up.size and not down.size:
            break
        if up.size:
            with np.errstate(over="ignore"):
                x = np.minimum(np.maximum(lo[up], d[up]) * math.exp(2.0**k), big)
            v = f(x, up)
            below = v < 0
            lo[up[below]], flo[up[below]] = x[below], v[below]
            hi[up[~below]], fhi[up[~below]] = x[~below], v[~below]
            at_top = up[below & (x >= big)]
            hi[at_top], fhi[at_top] = big, np.inf          # beyond the representable range
        if down.size:
            x = np.maximum(np.minimum(hi[down], d[down]) * math.exp(-(2.0**k)), tiny)
            v = f(x, down)
            below = v < 0
            lo[down[below]], flo[down[below]] = x[below], v[below]
            hi[down[~below]], fhi[down[~below]] = x[~below], v[~below]
            d[down[~below & (x <= tiny)]] = tiny
    top = np.flatnonzero(hi >= big)
    if top.size:             # the root lies past the largest double the law is evaluated at?
        beyond = f(np.full(top.size, big), top) < 0
        if np.any(beyond):
            at_big = float(np.asarray(law(lower + big), dtype=float).ravel()[0])
            raise InvalidParameterError(name, f"[0, {at_big:.6g}] (the law's value at {big:g})",
                                        float(t[top[np.argmax(beyond)]]), "beyond the range of double precision")
    side = np.zeros(n, dtype=int)             # the end kept last time: -1 low, +1 high (Illinois)
    for _ in range(200):
        live = np.flatnonzero((hi - lo > 4.0 * np.finfo(float).eps * hi) & (flo < 0) & (fhi > 0))
        if not live.size:
            break
        a, b, fa, fb = lo[live], hi[live], flo[live], fhi[live]
        wide = (a <= 0.5 * b) | ~np.isfinite(fb)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            x = np.where(wide, np.where(a > 0, np.sqrt(a) * np.sqrt(b), 0.5 * b), a - fa * (b - a) / (fb - fa))
        x = np.where((x > a) & (x < b), x, 0.5 * (a + b))
        v = f(x, live)
        below = v < 0
        hit = v == 0
        # Illinois: halve the value at the end that stays twice in a row
        keep_hi = below & (side[live] == 1) & ~wide
        keep_lo = ~below & (side[live] == -1) & ~wide
        fhi[live[keep_hi]] *= 0.5
        flo[live[keep_lo]] *= 0.5
        lo[live[below]], flo[live[below]] = x[below], v[below]
        hi[live[~below]], fhi[live[~below]] = x[~below], v[~below]
        side[live] = np.where(below, 1, -1)
        lo[live[hit]] = hi[live[hit]] = x[hit]
    x = np.where(np.abs(flo) < np.abs(fhi), lo, hi)
    return (lower + x).reshape(shape)


def _invalid(name, admissible, value):
    return InvalidParameterError(name, admissible, value)
