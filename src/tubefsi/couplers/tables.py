r"""Tables of the separated identity: a coupler's own answers, interpolated on fixed panels.

For a power-law fluid, :math:`G(q, R) = \phi(q)R^{-k}`, and a wall whose tube law its author has
split into a scale and a shape, :math:`P = \mu\,\hat P(\lambda; \bar t, \text{shape})`
(``WallModel._pressure_scale``, ``_shape_key`` and ``_unit_wall``), the separated identity with an
unloaded outlet (``docs/theory.md``, section "Coupling without an ODE") reads
:math:`\hat J(v) = \hat T` with the normalized target :math:`\hat T = L\phi(q)/(\mu a^k)` and

.. math:: \hat J(v) = \int_0^v s^{k+1}\,\hat P'(s)\,du, \qquad s = e^u,

which depends only on the wall's class and shape, :math:`\bar t`, :math:`k` and the coupler that
answers: not on :math:`q`, :math:`\mu`, :math:`m`, :math:`a` or :math:`L`. So one table serves every
scene of that *key*. A :class:`SeparatedTable` holds, as functions of :math:`x = \ln\hat T`, the
inlet log-stretch :math:`y = \ln v` and the pressure drop per unit modulus :math:`w = \ln\hat P`, on
the fixed panels :math:`j \le x \le j + 1` (:math:`j` an integer). A panel is built where a load
first needs it, from the coupler's own direct answers on the *unit* scene (:math:`\mu = 1`, a tube of
unit radius and length) at the panel's Chebyshev nodes, and accepted where its tails and its check
points (direct answers between the nodes) agree to 3e-14 (:func:`~tubefsi.numerics.chebyshev.fit_piecewise`);
a panel that cannot be accepted (near the maximum flow rate, where :math:`v` runs away) leaves its
loads to the direct path. What a panel holds thus depends on its key and :math:`j` alone: which
panels exist changes the time of a solve, never its answer.

The tables live in the one cache behind :func:`tubefsi.solve` (:mod:`tubefsi.numerics.cache`:
bounded, thread-safe, keyed by value: weak references to the classes and the shape's plain values,
never a model; :func:`tubefsi.cache_clear`, :func:`tubefsi.cache_info`). A table holds no model: the
scene of the call that needs a panel builds it.
"""

from __future__ import annotations

import math
import threading
import weakref

import numpy as np

from .. import registry
from ..geometry import Tube
from ..numerics.cache import TABLES, CacheInfo, plain
from ..numerics.chebyshev import PiecewisePolynomial, fit_piecewise
from ..scene import Scene

__all__ = ["SeparatedTable", "table_key", "declares_split", "unit_scene", "cache_clear", "cache_info", "TOL"]

#: The tolerance of a panel, absolute in ln v and in ln P: a little above the direct answers' own
#: scatter (~1e-14), so that the panel's check points can meet it.
TOL = 3e-14
#: The subpanels of degree 8 a panel may be split into before it is left to the direct path.
_MAX_SUBPANELS = 32


def table_key(coupler, scene):
    """The cache key of ``scene``'s table under ``coupler``, or None where no table applies.

    A table needs a power-law fluid (``radius_exponent`` a float), a wall that declares its
    shape/scale split (``_shape_key()`` not None), an unloaded outlet and one shape, ``t/a`` and
    ``k`` for every point. The key holds weak references to the wall's and the coupler's classes,
    the coupler's options and the wall's shape as plain values: a model that could change in place
    (a field holding a list or an array) declares no plain shape and gets no table.
    """
    rheology, tube = scene.rheology, scene.tube
    k = rheology.radius_exponent
    if type(k) is not float or not rheology.separable or type(tube.radius) is not float or type(tube.thickness) is not float:
        return None
    outlet = scene.outlet_pressure
    if type(outlet) is not float or outlet != 0.0:
        return None
    wall = scene.wall
    if not declares_split(type(wall)):
        return None
    shape = wall._shape_key()
    if shape is None or not plain(shape):
        return None
    options = coupler._table_options()
    if options is None:
        return None
    return (weakref.ref(type(coupler)), options, weakref.ref(type(wall)), shape, tube.thickness / tube.radius, k)


def declares_split(cls) -> bool:
    """Whether the instances of the wall class ``cls`` share tables: it declares its shape/scale
    split in its own body (``_shape_key``), or it is a registered wall, whose split the contract
    suite checks (:class:`tubefsi.testing.WallContract`). A subclass that only inherits a split
    may have changed the law or added a parameter: it shares nothing until it declares its own."""
    return "_shape_key" in cls.__dict__ or cls in registry.walls.derived("classes", _classes)


def _classes(walls) -> frozenset:
    return frozenset(walls[name] for name in walls)


def unit_scene(scene) -> Scene:
    """The scene a table of ``scene``'s key is built on: the unit wall in a tube of unit radius and
    length (t/a kept), the same fluid (only its exponent k enters J) and an unloaded outlet."""
    tb = scene.tube.thickness / scene.tube.radius
    return Scene(rheology=scene.rheology, wall=scene.wall._unit_wall(), tube=Tube(radius=1.0, thickness=tb, length=1.0))


class SeparatedTable:
    r"""The panels of one key (module docstring); each immutable once built, built under a lock.

    Below ``x_far = x_inf + ln(1 - 1/e)`` (``x_inf = ln J_hat(inf)``, the unit scene's largest
    target: ``inf`` where the wall has no maximum flow rate) the panels are ``[j, j + 1]`` in
    ``x`` (the last one ending at ``x_far``). Between ``x_far`` and ``x_inf``, where the inlet
    stretch runs away, they are ``[1 + i, 2 + i]`` in the *runaway variable*
    :math:`u = -\ln(1 - e^{x - x_{inf}})` (1 at ``x_far``), in which :math:`\ln v` is smooth up
    to the maximum flow rate (:math:`J_\infty - J \propto e^{-\alpha v}` makes :math:`v` affine
    in :math:`u`); beyond ``u = 41`` (a target within ``2e-18`` of the limit) and beyond ``x_inf``
    the direct path answers.
    """

    def __init__(self):
        self._panels = {}               # ("x", j) or ("u", i) -> PiecewisePolynomial of (y, w), or None
        self._lock = threading.Lock()
        self._view = None               # the x-panels last evaluated together, joined (evaluate)
        self._limit = None              # (x_inf, x_far), from the unit scene's J(inf)

    def limit(self, coupler, scene) -> tuple:
        """``(x_inf, x_far)`` of this key (computed once, on the unit scene)."""
        found = self._limit
        if found is None:
            with self._lock:
                found = self._limit
                if found is None:
                    found = self._limit = _limit(coupler, unit_scene(scene))
        return found

    def panel(self, kind: str, i: int, coupler, scene):
        """Panel ``i`` in ``x`` (``kind="x"``) or in the runaway variable (``"u"``), built from
        ``coupler``'s direct answers on ``scene``'s unit scene if missing; None where it could not
        be accepted."""
        found = self._panels.get((kind, i), self)
        if found is self:
            limit = self.limit(coupler, scene)
            with self._lock:
                found = self._panels.get((kind, i), self)
                if found is self:
                    found = self._panels[kind, i] = _build(coupler, unit_scene(scene), kind, i, limit)
        return found

    def scalar(self, x: float, coupler, scene):
        """``(y, w)`` at one float ``x``, or None where its panel leaves it to the direct path."""
        x_inf, x_far = self.limit(coupler, scene)
        if -745.0 < x < x_far and x < 710.0:
            found = self.panel("x", math.floor(x), coupler, scene)
            return None if found is None else found.scalar(x)
        if not x_far <= x < x_inf:
            return None
        u = -math.log(-math.expm1(x - x_inf)) - _U_FAR
        if not u < _RUNAWAY_PANELS:
            return None
        found = self.panel("u", math.floor(u), coupler, scene)
        return None if found is None else found.scalar(u)

    def evaluate(self, x, coupler, scene):
        """``(y, w, served)`` at the finite ``x`` (an array): the points whose panels serve them.
        Where every ``x``-panel the points need is accepted, one lookup over their joined panels
        (:meth:`~tubefsi.numerics.chebyshev.PiecewisePolynomial.join`: the same coefficients,
        the same bits), else one pass per panel; the runaway panels one pass per panel."""
        x_inf, x_far = self.limit(coupler, scene)
        y, w = np.zeros(x.shape), np.zeros(x.shape)
        served = np.zeros(x.shape, dtype=bool)
        near = (x >= x_far) & (x < x_inf)
        inside = np.flatnonzero((x > -745.0) & (x < min(x_far, 710.0)))
        if inside.size:
            self._evaluate_x(x, inside, coupler, scene, y, w, served)
        near = np.flatnonzero(near)
        if near.size:
            with np.errstate(divide="ignore"):
                u = -np.log(-np.expm1(x[near] - x_inf)) - _U_FAR
            self._evaluate_panels("u", u, near, coupler, scene, y, w, served, u < _RUNAWAY_PANELS)
        return y, w, served

    def _evaluate_x(self, x, inside, coupler, scene, y, w, served):
        x_in = x[inside]
        first, last = math.floor(x_in.min()), math.floor(x_in.max())
        pieces = [self.panel("x", j, coupler, scene) for j in range(first, last + 1)]
        if all(piece is not None for piece in pieces):
            view = self._view                   # (first, last, joined): replaced whole, never changed
            if view is None or view[:2] != (first, last):
                view = self._view = (first, last, PiecewisePolynomial.join(pieces))
            if inside.size == x.size:             # (every point: no scatter)
                y[:], w[:] = view[2].evaluate(x_in)
            else:
                y[inside], w[inside] = view[2].evaluate(x_in)
            served[inside] = True
            return
        self._evaluate_panels("x", x_in, inside, coupler, scene, y, w, served, np.ones(inside.size, dtype=bool))

    def _evaluate_panels(self, kind, t, where, coupler, scene, y, w, served, usable):
        """Fill the points ``where`` (at the panel variable ``t``) one panel at a time."""
        j = np.floor(np.where(usable, t, -1.0))
        for i in np.unique(j[usable]):           # (one pass per panel, not per point)
            piece = self.panel(kind, int(i), coupler, scene)
            if piece is None:
                continue
            sel = np.flatnonzero(usable & (j == i))
            y[where[sel]], w[where[sel]] = piece.evaluate(t[sel])
            served[where[sel]] = True

    @property
    def panel_count(self) -> int:
        """The number of panels built (accepted or left to the direct path)."""
        return len(self._panels)


#: Runaway panels, in units of u from u = 1: beyond them a target is within e^-41 of J(inf)
#: (the direct path answers).
_RUNAWAY_PANELS = 40
_U_FAR = 1.0


def _limit(coupler, unit) -> tuple:
    """``(x_inf, x_far)``: ``ln J_hat(inf)`` of the unit scene (``inf`` where it is not finite or
    not converged: then every panel is in ``x``) and where the runaway panels start in ``x``
    (at ``u = _U_FAR = 1``: closer to ``x_inf`` the ``x``-panels would need ever more
    subpanels, and closer to ``x_far`` the ``u``-panels, as ``u ~ ln(x_inf - x)`` there)."""
    with np.errstate(all="ignore"):
        found = coupler._J_infinity(unit, np.zeros(1, dtype=int))
    value = float(np.ravel(found.value)[0])
    if not (0.0 < value < math.inf and bool(np.all(found.converged))):
        return math.inf, math.inf
    x_inf = math.log(value)
    return x_inf, x_inf + math.log(-math.expm1(-_U_FAR))


def _build(coupler, unit, kind, i, limit):
    """The interpolant of ``(ln v, ln P_hat)`` on panel ``i`` in ``x`` (``[i, i + 1]``, the last one
    ending at ``x_far``) or in the runaway variable ``u`` (``[1 + i, 2 + i]``, shifted
    to ``[i, i + 1]``) from ``coupler``'s direct answers on the unit scene, or None where it
    cannot be accepted."""
    tb = unit.tb
    x_inf, x_far = limit
    j_inf = math.exp(x_inf) if x_inf < math.inf else math.inf

    def answers(t):
        target = np.exp(t) if kind == "x" else -j_inf * np.expm1(-(t + _U_FAR))
        v, ok, final = coupler._solve_J(unit, target, np.zeros(t.size, dtype=int))
        estimate = unit.wall._pressure_estimate(np.expm1(v), tb)
        good = ok & np.asarray(final.converged) & np.asarray(estimate.converged) & (v > 0)
        with np.errstate(all="ignore"):
            return np.where(good, np.stack([np.log(v), np.log(np.asarray(estimate.value, dtype=float))]), np.nan)

    hi = min(float(i + 1), x_far) if kind == "x" else float(i + 1)
    # in u, the answers themselves are only as accurate as J (relative 1e-14) allows: the problem's
    # condition number, 1/(1 - T/J_inf) = e^u, amplifies it; the panel's tolerance follows
    tol = TOL if kind == "x" else TOL * math.exp(_U_FAR + hi)
    with np.errstate(all="ignore"):
        fitted, _ = fit_piecewise(answers, float(i), hi, degree=8, tol=tol, panels=2, max_panels=_MAX_SUBPANELS)
    return fitted


def cache_clear() -> None:
    """Forget every table of the one cache behind :func:`tubefsi.solve` (answers do not change:
    the next solve that needs a table builds it again, to the same bits)."""
    TABLES.clear()


def cache_info() -> CacheInfo:
    """The hits, misses, size and bound of the one cache behind :func:`tubefsi.solve`."""
    return TABLES.info()
