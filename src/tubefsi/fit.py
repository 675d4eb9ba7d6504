r"""Calibrate wall and rheology parameters from measured (flow rate, pressure drop) data.

:func:`fit` minimizes the sum of squared *relative* residuals
:math:`r_i = \ln(\Delta p_{model}(q_i;\theta)/\Delta p_i)` with
:func:`scipy.optimize.least_squares`, with the analytic Jacobian of the separated identity
(``docs/theory.md``, section "Sensitivities": one weighted quadrature per rheology parameter,
none for the wall's modulus; a forward difference of two solves for other parameters);
parameters whose admissible range is
:math:`(0, \infty)` are fitted through their logarithm, so they stay positive. Standard
errors come from the Gauss–Newton covariance :math:`s^2 (J^T J)^{-1}`,
:math:`s^2 = \sum r_i^2/(m - k)`, mapped back by the delta method.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import attrs
import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize

from ._progress import bar
from .errors import FitWarning, InvalidParameterError, TubefsiError, warn_user
from ._keywords import checked_keywords
from .scene import make_scene
from .solve import solve_unchecked
# for the annotations
from .couplers.base import Coupler
from .geometry import Tube
from .rheology.base import Rheology
from .walls.base import WallModel

__all__ = ["fit", "FitResult"]


@attrs.frozen
class FitResult:
    """Fitted models, parameter values and standard errors."""

    rheology: object
    wall: object
    parameters: dict
    standard_errors: dict
    covariance: np.ndarray
    residuals: np.ndarray
    success: bool
    message: str

    def __str__(self) -> str:
        return _summary(self, "relative")


def _summary(result, residual_kind) -> str:
    """The table of a fit's parameters and standard errors, then its rms residual (``FitResult``,
    ``NetworkFitResult``)."""
    lines = [f"{'parameter':28s} {'value':>14s} {'std. error':>12s}"]
    for name, value in result.parameters.items():
        lines.append(f"{name:28s} {value:14.6g} {result.standard_errors[name]:12.3g}")
    rms = float(np.sqrt(np.mean(result.residuals**2)))
    return "\n".join(lines) + f"\nrms {residual_kind} residual {rms:.3g} ({result.message})"


#: How far (a factor) a parameter fitted through its logarithm may move from its starting value.
SEARCH_FACTOR = 1e4

_NAMES = "a list of names like 'wall.shear_modulus' or 'rheology.index', each once"


def _split(name):
    owner, _, field = name.partition(".") if isinstance(name, str) else ("", "", "")
    if owner not in ("wall", "rheology") or not field:
        raise InvalidParameterError("parameters", _NAMES, name)
    return owner, field


def _parameter_names(parameters):
    """The fitted names, checked: a sequence of distinct strings (a single string is one name)."""
    if isinstance(parameters, str):
        parameters = [parameters]
    try:
        names = list(parameters)
    except TypeError:
        raise InvalidParameterError("parameters", _NAMES, parameters) from None
    if not names:
        raise InvalidParameterError("parameters", _NAMES, parameters, "no parameter to fit")
    for name in names:
        _split(name)
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise InvalidParameterError("parameters", _NAMES, parameters, f"{', '.join(twice)} named twice")
    return names


def _covariance(result, m, logs, values):
    r"""The parameters' covariance: the Gauss–Newton :math:`s^2 (J^T J)^{-1}` of ``result`` (a
    :func:`scipy.optimize.least_squares` result over ``m`` residuals),
    :math:`s^2 = \sum r_i^2/(m - k)`, mapped back by the delta method where a parameter was fitted
    through its logarithm (``logs``; ``values`` the fitted values)."""
    k = result.x.size
    s2 = 2.0 * result.cost / max(m - k, 1)
    try:
        cov_theta = s2 * np.linalg.inv(result.jac.T @ result.jac)
    except np.linalg.LinAlgError:
        cov_theta = np.full((k, k), np.inf)
    scale = np.where(logs, values, 1.0)
    return cov_theta * np.outer(scale, scale)


def _warn_if_unsupported(names, result, at_edge, standard_errors, values, who="tubefsi.fit"):
    """A :class:`~tubefsi.FitWarning` where the data do not support the fit, saying what to try."""
    problems = []
    if not result.success:
        problems.append(f"the optimizer stopped without converging ({result.message})")
    for name in (n for n, edge in zip(names, at_edge) if edge):
        problems.append(f"{name} ended at the edge of its search range (a factor {SEARCH_FACTOR:g} from its start)")
    for name, value in zip(names, values):
        error = standard_errors[name]
        if not math.isfinite(error) or error > abs(value):
            problems.append(f"{name} is not determined by the data (standard error {error:.3g} for a value of "
                            f"{value:.6g})")
    if problems:
        warn_user(f"{who}: " + "; ".join(problems) + ". Try starting values closer to the data (fit one "
                  "parameter first, then the others from its result), fewer parameters, or data over a wider "
                  "range of flow rates.", FitWarning)


@checked_keywords
def fit(flow_rate: ArrayLike, pressure_drop: ArrayLike, rheology: Rheology, wall: WallModel, tube: Tube, *,
        parameters: Sequence[str], outlet_pressure: float = 0.0, coupler: str | Coupler | type[Coupler] = "auto",
        progress: bool | str = False) -> FitResult:
    r"""Least-squares calibration of ``parameters`` from data.

    Parameters
    ----------
    flow_rate, pressure_drop : array_like
        Measured pairs (m^3/s, Pa), all positive.
    rheology, wall : model instances
        Starting values for the fitted parameters; the others stay fixed.
    tube : Tube
    parameters : sequence of str
        Fields to fit, each once, as ``"wall.<field>"`` or ``"rheology.<field>"``,
        e.g. ``["wall.shear_modulus", "rheology.consistency", "rheology.index"]``. A field whose
        admissible range is :math:`(0, \infty)` moves at most a factor ``SEARCH_FACTOR`` (1e4)
        from its starting value.
    progress : bool or "auto"
        Show a progress bar counting the model evaluations (one solve over every data point
        each; tqdm, ``pip install 'tubefsi[progress]'``); ``"auto"``: only if tqdm is installed
        and standard error is a terminal.

    Returns
    -------
    FitResult

    Warns
    -----
    FitWarning
        Where the data do not support the result: the optimizer did not converge, a parameter
        ended at the edge of its search range, or a standard error is not finite or exceeds the
        value; the message says which, and what to try.
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure)
    models = {"rheology": scene.rheology, "wall": scene.wall}
    q = np.asarray(flow_rate, dtype=float)
    dp = np.asarray(pressure_drop, dtype=float)
    if q.shape != dp.shape or q.ndim != 1 or q.size == 0:
        raise InvalidParameterError("flow_rate / pressure_drop", "1-D arrays of one length", q.shape)
    if np.any(~np.isfinite(q) | (q <= 0)) or np.any(~np.isfinite(dp) | (dp <= 0)):
        raise InvalidParameterError("flow_rate / pressure_drop", "(0, inf) elementwise", None)
    names = _parameter_names(parameters)
    if len(names) >= q.size:
        raise InvalidParameterError("parameters", f"fewer than the {q.size} data points", len(names))
    logs, start = [], []
    for name in names:
        owner, field = _split(name)
        model = models[owner]
        fields = {f.name: f for f in attrs.fields(type(model))}
        if field not in fields:
            raise InvalidParameterError("parameters", f"fields of {type(model).__name__}: {', '.join(fields)}", name)
        positive = fields[field].metadata.get("admissible", "").startswith("(0,")
        logs.append(positive)
        value = float(getattr(model, field))
        start.append(math.log(value) if positive else value)
    logs = np.array(logs)

    def natural(theta):
        return np.array([math.exp(t) if lg else t for t, lg in zip(theta, logs)])

    def build(theta):
        values = natural(theta)
        new = dict(models)
        for owner in ("rheology", "wall"):
            changes = {_split(n)[1]: float(v) for n, v in zip(names, values) if _split(n)[0] == owner}
            if changes:
                new[owner] = attrs.evolve(new[owner], **changes)
        return new

    def evaluate(theta):
        """Models, model drops and the solution at ``theta`` (cached: the Jacobian reuses them)."""
        key = theta.tobytes()
        if key not in cache:
            shown.update()
            m = build(theta)
            # beyond the maximum flow rate the drop is continued by its supremum, the limit
            # pressure rise, so trial parameters with no steady state still steer the fit; trial
            # points are not checked for validity (the fitted model is)
            sol = solve_unchecked(m["rheology"], m["wall"], tube, flow_rate=q, outlet_pressure=outlet_pressure,
                                  coupler=coupler, on_infeasible="nan")
            out = np.array(sol.pressure_drop, dtype=float)
            ok = np.isfinite(out)
            if not np.all(ok):
                out[~ok] = m["wall"].limit_pressure(tube.reduced_thickness) - outlet_pressure
            cache.clear()
            cache[key] = (m, sol, ok, out)
        return cache[key]

    def residuals(theta):
        try:
            return np.log(evaluate(theta)[3] / dp)
        except (TubefsiError, ArithmeticError, FloatingPointError):
            return np.full(q.size, 10.0)   # outside the models' admissible range

    def jacobian(theta):
        r"""``d r_i / d theta_j``, :math:`r = \ln\Delta p`: the solution's analytic parameter
        derivatives (``Solution.dpressure_drop_dparameter``) where it has them, a forward
        difference of two solves otherwise."""
        try:
            m, sol, ok, drop = evaluate(theta)
        except (TubefsiError, ArithmeticError, FloatingPointError):
            return np.zeros((q.size, theta.size))
        jac = np.empty((q.size, theta.size))
        values = natural(theta)
        analytic = {}
        if np.all(ok):
            try:                               # every parameter in one pass over the points
                analytic = dict(zip(names, sol._dpressure_drop_dparameters(names)))
            except InvalidParameterError:      # some parameter has none: ask one by one
                for name in names:
                    try:
                        analytic[name] = sol.dpressure_drop_dparameter(name)
                    except InvalidParameterError:
                        pass
        for j, name in enumerate(names):
            column = None
            if name in analytic:
                column = np.asarray(analytic[name], dtype=float) / drop
                column = column * (values[j] if logs[j] else 1.0)
            if column is None or not np.all(np.isfinite(column)):
                h = 1e-7 * max(1.0, abs(theta[j]))
                shifted = theta.copy()
                shifted[j] += h
                saved = dict(cache)
                try:
                    column = (np.log(evaluate(shifted)[3]) - np.log(drop)) / h
                except (TubefsiError, ArithmeticError, FloatingPointError):
                    column = np.zeros(q.size)
                cache.clear()
                cache.update(saved)
            jac[:, j] = column
        return jac

    cache: dict = {}
    # log parameters may move by a factor of up to 1e4 from their starting values
    start = np.array(start)
    span = np.where(logs, math.log(SEARCH_FACTOR), np.inf)
    shown = bar(None, progress, "tubefsi.fit", unit="evaluation")   # the count of evaluations is not known
    try:
        # dogbox: for a few bounded parameters it converged in 6-8 model evaluations where the default
        # trust-region reflective method took 8-13, to the same optimum (benchmarks/speed.py's fit)
        res = optimize.least_squares(residuals, start, jac=jacobian, bounds=(start - span, start + span),
                                     x_scale="jac", method="dogbox", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    finally:
        shown.close()
    values = natural(res.x)
    cov = _covariance(res, q.size, logs, values)
    fitted = build(res.x)
    standard_errors = {n: float(math.sqrt(max(cov[i, i], 0.0))) if np.isfinite(cov[i, i]) else math.inf
                       for i, n in enumerate(names)}
    at_edge = np.isfinite(span) & (np.abs(np.abs(res.x - start) - span) <= 1e-6 * span)
    _warn_if_unsupported(names, res, at_edge, standard_errors, values)
    return FitResult(rheology=fitted["rheology"], wall=fitted["wall"],
                     parameters={n: float(v) for n, v in zip(names, values)},
                     standard_errors=standard_errors,
                     covariance=cov, residuals=res.fun, success=bool(res.success), message=str(res.message))
