r"""Tables of the separated identity, and the one cache that holds them.

For a power-law fluid, :math:`G(q, R) = \phi(q)R^{-k}`, and a wall whose tube law its author has
split into a scale and a shape, :math:`P = \mu\,\hat P(\lambda; \bar t, \text{shape})`
(``WallModel._pressure_scale``, ``_shape_key`` and ``_unit_wall``), the separated identity with an
unloaded outlet (``docs/theory.md``, section "Coupling without an ODE") reads
:math:`\hat J(v) = L\phi(q)/(\mu a^k)` with

.. math:: \hat J(v) = \int_0^v s^{k+1}\,\hat P'(s)\,du, \qquad s = e^u,

which depends only on the wall's class and shape, :math:`\bar t`, :math:`k` and the coupler that
evaluates it: not on :math:`q`, :math:`\mu`, :math:`m`, :math:`a` or :math:`L`. A
:class:`SeparatedTable` holds, for one such key, built from the *unit* wall (:math:`\mu = 1`) on a
tube of unit radius and length (so that its bits depend on the key alone, never on the scene that
first asked for it):

* ``forward``: :math:`x = \ln\hat J(e^y)` as a function of :math:`y = \ln v`;
* ``inverse``: two outputs on the same panels of :math:`x`: :math:`y(x)`, the inlet log-stretch of a
  target, and :math:`w(x) = \ln\hat P(e^{e^{y(x)}})`, the pressure drop per unit modulus;
* ``j_infinity``: :math:`\hat J(\infty)` (the maximum flow rate; ``inf`` where there is none).

Each interpolant is refined until its tail and check points meet the tolerance
(:func:`~tubefsi.numerics.chebyshev.fit_piecewise`), the forward map against the coupler's own
error-controlled :math:`J`, the inverse against Newton's method on the forward map; then the whole
chain is checked once more against fresh evaluations of :math:`J` at 64 targets that were not
interpolated. A table whose checks fail is not published (its scenes take the direct path).

Tables are immutable and live in the one cache behind :func:`tubefsi.solve`
(:data:`tubefsi.numerics.cache.TABLES`: bounded, thread-safe, keyed by value: weak references to the
classes and the shape's plain values, never a model; :func:`tubefsi.cache_clear`,
:func:`tubefsi.cache_info`).
"""

from __future__ import annotations

import math
import weakref

import attrs
import numpy as np

from ..geometry import Tube
from ..numerics.cache import TABLES, CacheInfo, plain
from ..numerics.chebyshev import PiecewisePolynomial, fit_piecewise
from ..scene import Scene

__all__ = ["SeparatedTable", "TABLES", "table_key", "build_table", "cache_clear", "cache_info"]

#: The range of inlet log-stretches a table covers: from 1e-9 to ln(1e4) (stretch 1e4, R/L far beyond
#: the model) or just short of a maximum stretch.
_V_LOW, _V_HIGH = 1e-9, math.log(1e4)
#: Tolerances (absolute in the logarithms): the inverse and the pressure to 2e-14 relative, the
#: forward map to 1e-14 relative to max(1, |ln J|) (it carries the quadrature's own 1e-14).
_TOL_INVERSE, _TOL_FORWARD = 2e-14, 1e-14
#: The largest accepted a-posteriori error of the whole chain (of ln v and of ln P).
_ACCEPT = 1e-13


def table_key(coupler, scene):
    """The cache key of ``scene``'s table under ``coupler``, or None where no table applies.

    A table needs a power-law fluid (``radius_exponent`` a float), a wall that declares its
    shape/scale split (``_shape_key()`` not None), an unloaded outlet and one shape, ``t/a`` and
    ``k`` for every point. The key holds weak references to the wall's and the coupler's classes,
    the coupler's options and the wall's shape as plain values: a model that could change in place
    (a field holding a list or an array) declares no plain shape and gets no table.
    """
    rheology, wall = scene.rheology, scene.wall
    k = rheology.radius_exponent
    if type(k) is not float or not rheology.separable:
        return None
    tb = scene.tube.thickness / scene.tube.radius if type(scene.tube.radius) is float else scene.tb
    if type(tb) is not float:
        return None
    outlet = scene.outlet_pressure
    if type(outlet) is not float or outlet != 0.0:
        return None
    shape = wall._shape_key()
    if shape is None or not plain(shape):
        return None
    options = coupler._table_options()
    if options is None:
        return None
    return (weakref.ref(type(coupler)), options, weakref.ref(type(wall)), shape, tb, k)


@attrs.frozen(eq=False)
class SeparatedTable:
    """The tables of one key (module docstring). Immutable; holds no model."""

    forward: PiecewisePolynomial        #: y = ln v -> x = ln J_hat
    inverse: PiecewisePolynomial        #: x -> (y, w = ln P_hat)
    j_infinity: float                   #: J_hat(inf), or inf
    error: float                        #: the a-posteriori estimate of the error of ln v and ln P

    @property
    def x_lo(self) -> float:
        return self.inverse.lo

    @property
    def x_hi(self) -> float:
        return self.inverse.hi


def _unit_scene(scene) -> Scene:
    """The scene the table of ``scene``'s key is built on: the unit wall in a tube of unit radius
    and length (t/a kept), the same fluid (only its exponent k enters J) and an unloaded outlet."""
    tb = scene.tube.thickness / scene.tube.radius
    return Scene(rheology=scene.rheology, wall=scene.wall._unit_wall(), tube=Tube(radius=1.0, thickness=tb, length=1.0))


def build_table(coupler, scene):
    """The :class:`SeparatedTable` of ``scene``'s key under ``coupler``, or None where its checks fail."""
    unit = _unit_scene(scene)
    zero = np.zeros(1, dtype=int)
    cap = float(coupler._log_stretch_cap(unit, zero)[0])
    v_hi = min(_V_HIGH, 0.999 * cap)
    y_lo, y_hi = math.log(_V_LOW), math.log(v_hi)

    def log_j(v):
        result = coupler._J(unit, v, np.zeros(v.size, dtype=int))
        ok = np.asarray(result.converged, dtype=bool)
        return np.where(ok, np.log(np.asarray(result.value, dtype=float)), np.nan)

    with np.errstate(all="ignore"):
        forward, _ = fit_piecewise(lambda y: log_j(np.exp(y)), y_lo, y_hi, degree=16, tol=_TOL_FORWARD,
                                   panels=8, relative=True)
    if forward is None:
        return None
    slope = forward.derivative()
    x_lo, x_hi = (float(v) for v in forward(np.array([y_lo, y_hi])))
    grid_y = np.linspace(y_lo, y_hi, 4097)
    grid_x = forward(grid_y)
    if not np.all(np.diff(grid_x) > 0):
        return None
    wall, tb = unit.wall, unit.tb

    def inverse_values(x):
        y = _invert(forward, slope, x, grid_x, grid_y, y_lo, y_hi)
        v = np.exp(y)
        with np.errstate(all="ignore"):
            w = np.log(np.asarray(wall._pressure_at_log_stretch(v, np.expm1(v), tb), dtype=float))
        return np.stack([y, w])

    inverse, _ = fit_piecewise(inverse_values, x_lo, x_hi, degree=8, tol=_TOL_INVERSE, panels=16)
    if inverse is None:
        return None
    # the whole chain against fresh evaluations at targets that were not interpolated: the error
    # of ln v is the miss of ln J over its slope
    x_check = x_lo + (x_hi - x_lo) * (np.arange(64) + 0.37) / 64
    y_check, w_check = inverse.evaluate(x_check)
    with np.errstate(all="ignore"):
        miss_y = np.abs(log_j(np.exp(y_check)) - x_check) / np.abs(slope(y_check))
        v = np.exp(y_check)
        miss_w = np.abs(np.log(np.asarray(wall._pressure_at_log_stretch(v, np.expm1(v), tb), dtype=float)) - w_check)
    error = float(max(np.max(miss_y), np.max(miss_w)))
    if not error <= _ACCEPT:
        return None
    j_inf = coupler._J_infinity(unit, zero)
    return SeparatedTable(forward=forward, inverse=inverse, j_infinity=float(np.asarray(j_inf.value)[0]),
                          error=error)


def _invert(forward, slope, x, grid_x, grid_y, lo, hi):
    """``y`` with ``forward(y) = x`` (arrays): linear interpolation on a grid, then Newton's method
    on the interpolant itself to a few ulp."""
    y = np.interp(x, grid_x, grid_y)
    for _ in range(12):
        step = (forward(y) - x) / slope(y)
        y = np.clip(y - step, lo, hi)
        if np.all(np.abs(step) <= 4e-16 * np.maximum(1.0, np.abs(y))):
            break
    return y


def cache_clear() -> None:
    """Forget every table of the one cache behind :func:`tubefsi.solve` (answers do not change:
    the next solve that needs a table builds it again, to the same bits)."""
    TABLES.clear()


def cache_info() -> CacheInfo:
    """The hits, misses, size and bound of the one cache behind :func:`tubefsi.solve`."""
    return TABLES.info()
