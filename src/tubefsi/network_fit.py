r"""Calibrate a :class:`~tubefsi.Network` from measured node pressures and tube flow rates
(``docs/network.md``, "Calibration").

The parameters are per-group wall moduli (a group: a set of tubes sharing one value of the
modulus that scales their walls' tube law, :math:`P = \mu\hat P(\lambda)`) and terminal
resistances of resistance outlets. Each is fitted through its logarithm
:math:`\theta = \ln\mu` or :math:`\ln R` by :func:`scipy.optimize.least_squares`, minimizing

.. math::  \sum_{i} \Bigl(\frac{p_i(\theta) - \hat p_i}{\sigma_p}\Bigr)^2
           + \sum_{e} \Bigl(\frac{q_e(\theta) - \hat q_e}{\sigma_q}\Bigr)^2

over the measured nodes :math:`i` and tubes :math:`e`. The Jacobian is analytic, by the implicit
function theorem on the Kirchhoff system :math:`F(p, \theta) = 0` of the free pressures:

.. math::  \frac{dp}{d\theta} = -\Bigl(\frac{\partial F}{\partial p}\Bigr)^{-1}\frac{\partial F}{\partial\theta},
           \qquad
           \frac{dq_e}{d\theta} = \frac{\partial q_e}{\partial p_u}\frac{dp_u}{d\theta}
           + \frac{\partial q_e}{\partial p_v}\frac{dp_v}{d\theta} + \frac{\partial q_e}{\partial\theta},

with the tubes' exact derivatives at the solution (feeders included), :math:`\mu\,\partial
q_e/\partial\mu` from :meth:`tubefsi.network_groups._Groups.modulus_derivative`, and
:math:`\partial F_i/\partial\ln R_i = (p_i - p_{d,i})/R_i` at a resistance outlet. Standard errors
come from the Gauss–Newton covariance :math:`s^2(J^TJ)^{-1}`, :math:`s^2 = \sum r^2/(m - k)`, mapped
back by the delta method, as :func:`tubefsi.fit` does.
"""

from __future__ import annotations

import math

import attrs
import numpy as np
import scipy.sparse as sp
from scipy import optimize
from scipy.sparse import linalg as spla

from ._validation import as_array
from .errors import ConvergenceError, InvalidParameterError, TubefsiError
from .fields import _array_fields
from .fit import SEARCH_FACTOR, _covariance, _summary, _warn_if_unsupported
from .network_groups import _Groups
from .network_solution import NetworkSolution, _hashable

__all__ = ["NetworkFitResult", "fit_network"]


@attrs.frozen
class NetworkFitResult:
    """A calibrated network: the network with the fitted values, its solution, the fitted
    parameters (``"modulus[<group>]"``, ``"resistance[<node>]"``) and their standard errors."""

    network: object
    solution: NetworkSolution
    parameters: dict
    standard_errors: dict
    covariance: np.ndarray
    residuals: np.ndarray
    success: bool
    message: str

    def __str__(self) -> str:
        return _summary(self, "weighted")


def _scale_field(wall, label):
    """The field of ``wall`` that scales its tube law: doubling it doubles ``_pressure_scale()``
    and keeps the wall's shape (``Solution.dpressure_drop_dparameter``'s test)."""
    if wall.is_rigid:
        raise InvalidParameterError(label, "tubes with a compliant wall (a modulus to fit)", wall)
    for field in _array_fields(type(wall)):
        value = getattr(wall, field)
        if np.ndim(value) != 0:
            continue
        try:
            doubled = attrs.evolve(wall, **{field: 2.0 * float(value)})
            if doubled._pressure_scale() == 2.0 * wall._pressure_scale() and doubled._shape_key() == wall._shape_key():
                return field
        except (TypeError, ValueError, InvalidParameterError):
            continue
    raise InvalidParameterError(label, "tubes whose wall has a modulus that scales its tube law", wall)


def _observations(net, pressure, flow_rate):
    """``(node indices, values, tube indices, values)`` of the measurements, checked."""
    nodes, tubes = net._nodes, list(net._tubes)
    where = {name: i for i, name in enumerate(tubes)}
    out = []
    for label, data, index in (("pressure", pressure, nodes), ("flow_rate", flow_rate, where)):
        data = {} if data is None else data
        if not hasattr(data, "items"):
            raise InvalidParameterError(label, "a mapping (node or tube name -> measured value)", data)
        at, values = [], []
        for key, value in data.items():
            i = index.get(key) if _hashable(key) else None
            if i is None:
                raise InvalidParameterError(label, f"{'nodes' if label == 'pressure' else 'tube names'} of the network",
                                            key)
            at.append(i)
            values.append(float(as_array(f"{label}[{key!r}]", value, "finite numbers", np.isfinite)))
        out += [np.array(at, dtype=int), np.array(values)]
    return out


def fit_network(net, *, pressure=None, flow_rate=None, moduli=None, resistances=None, pressure_sigma=None,
                flow_sigma=None, rtol=1e-13) -> NetworkFitResult:
    """Least-squares calibration of a network; see :meth:`tubefsi.Network.fit`."""
    node_at, p_obs, tube_at, q_obs = _observations(net, pressure, flow_rate)
    m = p_obs.size + q_obs.size
    moduli = {} if moduli is None else moduli
    resistances = [] if resistances is None else list(resistances)
    if not hasattr(moduli, "items"):
        raise InvalidParameterError("moduli", "a mapping group name -> list of tube names", moduli)
    names, start, groups = [], [], []
    owner: dict = {}
    for group, members in moduli.items():
        members = [members] if isinstance(members, str) or not hasattr(members, "__iter__") else list(members)
        if not members:
            raise InvalidParameterError(f"moduli[{group!r}]", "a non-empty list of tube names", members)
        value, field = None, None
        for name in members:
            t = net._tubes.get(name) if _hashable(name) else None
            if t is None:
                raise InvalidParameterError(f"moduli[{group!r}]", "tube names of the network", name)
            if name in owner:
                raise InvalidParameterError(f"moduli[{group!r}]", "tubes in one group each", name,
                                            f"it is in group {owner[name]!r} too")
            owner[name] = group
            if t.graded:
                raise InvalidParameterError(f"moduli[{group!r}]", "uniform tubes (a graded tube's modulus: not yet)",
                                            name)
            wall = t.models()[0]
            f = _scale_field(wall, f"moduli[{group!r}]")
            v = float(getattr(wall, f))
            if value is None:
                value, field = v, f
            elif v != value or f != field:
                raise InvalidParameterError(f"moduli[{group!r}]", "tubes that start from one value of one modulus",
                                            name, f"{f} = {v:g} where the group's first tube has {field} = {value:g}")
        names.append(f"modulus[{group}]")
        start.append(math.log(value))
        groups.append(("modulus", members, field))
    for node in resistances:
        if not _hashable(node) or node not in net._resistance:
            raise InvalidParameterError("resistances", "nodes of the network with a resistance outlet", node)
        names.append(f"resistance[{node}]")
        start.append(math.log(net._resistance[node][0]))
        groups.append(("resistance", node, None))
    k = len(names)
    if k == 0:
        raise InvalidParameterError("moduli / resistances", "at least one parameter to fit", None)
    if m <= k:
        raise InvalidParameterError("pressure / flow_rate", f"more measurements than the {k} parameters", m)
    sigma_p = _sigma("pressure_sigma", pressure_sigma, p_obs)
    sigma_q = _sigma("flow_sigma", flow_sigma, q_obs)
    start = np.array(start)

    def network_at(theta):
        new = net._snapshot()
        for (kind, what, field), value in zip(groups, np.exp(theta)):
            if kind == "resistance":
                new._resistance[what] = (float(value), new._resistance[what][1])
                continue
            for name in what:
                t = new._tubes[name]
                wall, tube, fluid = t.models()
                new._tubes[name] = attrs.evolve(t, wall=attrs.evolve(wall, **{field: float(value)}), tube=tube,
                                                rheology=fluid, row=None)
        return new

    cache: dict = {}
    last: list = [None]

    def evaluate(theta):
        key = theta.tobytes()
        if key not in cache:
            new = network_at(theta)
            result = new.solve(rtol=rtol, initial=last[0])
            last[0] = result
            cache.clear()
            cache[key] = (new, result)
        return cache[key]

    def residuals(theta):
        try:
            _, result = evaluate(theta)
        except (TubefsiError, ArithmeticError, FloatingPointError):
            return np.full(m, 1e3)        # no steady state at these trial values: far off
        return np.concatenate([(result.p[node_at] - p_obs) / sigma_p, (result.q[tube_at] - q_obs) / sigma_q])

    def jacobian(theta):
        try:
            new, result = evaluate(theta)
        except (TubefsiError, ArithmeticError, FloatingPointError):
            return np.zeros((m, k))
        dp, dq = _derivatives(new, result, groups)
        return np.vstack([dp[node_at] / sigma_p, dq[tube_at] / sigma_q])

    span = math.log(SEARCH_FACTOR)
    res = optimize.least_squares(residuals, start, jac=jacobian, bounds=(start - span, start + span), x_scale="jac",
                                 method="dogbox", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    values = np.exp(res.x)
    cov = _covariance(res, m, np.ones(k, dtype=bool), values)
    standard_errors = {n: float(math.sqrt(max(cov[i, i], 0.0))) if np.isfinite(cov[i, i]) else math.inf
                       for i, n in enumerate(names)}
    at_edge = np.abs(np.abs(res.x - start) - span) <= 1e-6 * span
    _warn_if_unsupported(names, res, at_edge, standard_errors, values, who="Network.fit")
    new, result = evaluate(res.x)
    return NetworkFitResult(network=new, solution=result, parameters={n: float(v) for n, v in zip(names, values)},
                            standard_errors=standard_errors, covariance=cov, residuals=res.fun,
                            success=bool(res.success), message=str(res.message))


def _sigma(label, sigma, observed):
    """The scale of a kind of residual: given, else the root mean square of the measured values
    (1 where they are all zero)."""
    if sigma is not None:
        return float(as_array(label, sigma, "(0, inf)", lambda a: np.isfinite(a) & (a > 0)))
    rms = float(np.sqrt(np.mean(observed**2))) if observed.size else 1.0
    return rms if rms > 0 else 1.0


def _derivatives(net, result, groups):
    r"""``(dp/dtheta, dq/dtheta)``: the node pressures' and tube flows' derivatives by the fitted
    log-parameters at ``result`` (arrays of shape (nodes, k) and (tubes, k)), by the implicit
    function theorem on the Kirchhoff system over every node without a fixed pressure."""
    tubes = result.tubes
    U, V, p = result.U, result.V, result.p
    n_nodes, n_tubes = p.size, len(tubes)
    du = p[U] - p[V]
    forward = du >= 0
    drop = np.abs(du)
    outlet = np.where(forward, p[V], p[U])
    q, d_in, d_out, scale = _Groups(tubes, np.ones(n_tubes, dtype=bool)).modulus_derivative(drop, outlet, forward)
    gu = np.where(forward, d_in, -d_out)
    gv = np.where(forward, d_out, -d_in)
    sign = np.where(forward, 1.0, -1.0)
    index = result.node_index
    fixed = np.zeros(n_nodes, dtype=bool)
    for node in net._pressure:
        fixed[index[node]] = True
    g_out = np.zeros(n_nodes)
    for node, (r, _) in net._resistance.items():
        g_out[index[node]] = 1.0 / r
    # direct derivatives: of each tube's flow, then of the balance F
    tube_index = result.tube_index
    direct_q = np.zeros((n_tubes, len(groups)))
    direct_F = np.zeros((n_nodes, len(groups)))
    for j, (kind, what, _) in enumerate(groups):
        if kind == "modulus":
            at = np.array([tube_index[name] for name in what])
            direct_q[at, j] = sign[at] * scale[at]
        else:
            i = index[what]
            r, p_d = net._resistance[what]
            direct_F[i, j] = (p[i] - p_d) / r
    direct_F += _incidence(U, V, n_nodes, direct_q)
    free = np.flatnonzero(~fixed)
    where = np.full(n_nodes, -1)
    where[free] = np.arange(free.size)
    rows = np.concatenate([U, U, V, V, free])
    cols = np.concatenate([U, V, U, V, free])
    vals = np.concatenate([-gu, -gv, gu, gv, -g_out[free]])
    keep = ~fixed[rows] & ~fixed[cols]
    if not np.all(np.isfinite(vals[keep])):
        raise ConvergenceError("Network.fit: a tube's derivative by its end pressures is not finite at the "
                               "solution (a tube without flow whose fluid is not Newtonian at rest)")
    jac = sp.csc_matrix((vals[keep], (where[rows[keep]], where[cols[keep]])), shape=(free.size, free.size))
    dp = np.zeros((n_nodes, len(groups)))
    if free.size:
        solved = spla.splu(jac).solve(-np.ascontiguousarray(direct_F[free]))
        dp[free] = solved.reshape(free.size, len(groups))
    dq = gu[:, None] * dp[U] + gv[:, None] * dp[V] + direct_q
    return dp, dq


def _incidence(U, V, n_nodes, per_tube):
    """Per node, the sum over its tubes of ``per_tube`` (rows aligned with the tubes) entering it
    minus leaving it."""
    out = np.zeros((n_nodes, per_tube.shape[1]))
    np.add.at(out, V, per_tube)
    np.subtract.at(out, U, per_tube)
    return out
