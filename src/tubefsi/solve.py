"""The entry points: :func:`solve`, :func:`max_flow_rate` and :func:`select_coupler`.

``solve`` builds the :class:`~tubefsi.scene.Scene` (:func:`~tubefsi.scene.make_scene`), picks
the coupler, validates the load, runs the coupler (wrapped in
:class:`~tubefsi.couplers.Checked` when it checks itself) on chunks of at most ``CHUNK``
loads and returns a :class:`~tubefsi.Solution`.
"""

from __future__ import annotations

import contextlib
import functools
import math

import attrs
import numpy as np

from . import registry
from ._progress import bar
from ._keywords import checked_keywords
from ._validation import as_load
from .couplers.base import Coupler
from .couplers.checked import checked
from .couplers.graded import Graded
from .couplers.rescaled import Rescaled, in_units
from .errors import InvalidParameterError, NoSteadyStateError, StretchRangeError
from .fields import parameter_shape
from .couplers.separated import _TABLES, SeparatedVariables, curve_span
from .geometry import Tube
from .rheology.base import Rheology
from .rheology.power_law import FactorRangeError
from .scene import Scene, State, _log_max_stretch, _resolve, make_scene
from .solution import Solution
from .validity import SLENDERNESS, check, warn
from .walls.base import WallModel

__all__ = ["solve", "max_flow_rate", "select_coupler"]


#: (rheology class, wall class, coupler registry generation) -> the coupler "auto" picks and its
#: name, or False where the classes are not models (the scalar path's one lookup)
_AUTO: dict = {}


_CONTRACT_COUPLERS: dict = {}


def _contract_couplers():
    """The registered couplers that meet the accuracy contract, one (immutable) instance each,
    cheapest first (by cost rank, then name); built once per state of the registry."""
    generation = registry.couplers.generation
    found = _CONTRACT_COUPLERS.get(generation)
    if found is None:
        ranked = sorted((registry.couplers[name].cost_rank, name) for name in registry.couplers
                        if registry.couplers[name].meets_accuracy_contract)
        found = tuple(registry.couplers[name]() for _, name in ranked)
        _CONTRACT_COUPLERS.clear()
        _CONTRACT_COUPLERS[generation] = found
    return found


def _auto(rheology, wall):
    """``(coupler, name)`` of ``"auto"`` for the pair's classes, or False if they are not models."""
    key = (type(rheology), type(wall), registry.couplers.generation)
    found = _AUTO.get(key)
    if found is None:
        found = False
        if _is(type(rheology), Rheology) and _is(type(wall), WallModel):
            chosen = select_coupler(rheology, wall)
            found = (chosen, registry.couplers.name_of(chosen) or type(chosen).__name__)
        _AUTO[key] = found
    return found


def _in_radius_units(function):
    """:func:`~tubefsi._keywords.checked_keywords` for ``solve``, recovering from
    :class:`~tubefsi.rheology.power_law.FactorRangeError` (a factor of the separated form left
    the doubles: a power law of a large index) by solving again in units of the tube's radius
    (:mod:`tubefsi.couplers.rescaled`); the error stands where that cannot help."""
    return checked_keywords(function, recover=(FactorRangeError, lambda f, a, k: _radius_units(f, a, k)))


def _solve_entry(function):
    """:func:`_in_radius_units` for ``solve``, with the commonest call, ``solve(fluid, wall, tube,
    flow_rate=q)`` for a float ``q``, tried on the lean scalar path before any argument binding
    (a Monte Carlo loop's call: the binding and the general path's option checks were a tenth
    of it). Anything else, or a miss, goes through the checked entry unchanged."""
    entry = _in_radius_units(function)

    @functools.wraps(function)
    def solve(*args, **kwargs):
        if len(args) == 3 and len(kwargs) == 1:
            q = kwargs.get("flow_rate")
            if type(q) is float:
                try:
                    fast = _scalar_flow(args[0], args[1], args[2], q)
                except FactorRangeError:          # the general path recovers from it
                    fast = None
                if fast is not None:
                    return fast
        return entry(*args, **kwargs)

    return solve


@checked_keywords
def select_coupler(rheology, wall, coupler="auto") -> Coupler:
    """The coupler ``solve`` would use: a name, an instance, or ``"auto"`` (cheapest accurate)."""
    if isinstance(coupler, str) and coupler == "auto":
        for inst in _contract_couplers():
            if inst.supports(rheology, wall):
                return inst
        raise InvalidParameterError("coupler", "a coupler that supports this pair",
                                    "auto", "no registered coupler supports it")
    inst = _resolve("coupler", coupler, Coupler, registry.couplers)
    if not inst.supports(rheology, wall):
        raise InvalidParameterError("coupler", "a coupler that supports this pair", coupler,
                                    f"{type(inst).__name__} does not support {type(rheology).__name__} "
                                    f"with {type(wall).__name__}")
    return inst


@_solve_entry
def solve(rheology, wall, tube, *, flow_rate=None, pressure_drop=None, coupler="auto",
          outlet_pressure=0.0, external_pressure=0.0, on_infeasible="raise", density=None, progress=False) -> Solution:
    r"""Solve steady flow of ``rheology`` through ``tube`` with wall ``wall``.

    Exactly one of ``flow_rate`` (flow-controlled) and ``pressure_drop``
    (pressure-controlled) is given, as a float or an array (every entry >= 0). Every model
    parameter, every ``Tube`` field and the outlet pressure may be arrays too: all broadcast
    together with the load by NumPy's rules (as :mod:`scipy.stats` broadcasts its shape
    parameters), the results have the broadcast shape, and scalars in give floats out.

    Parameters
    ----------
    rheology, wall : model instance, class, or registered name
    tube : Tube
    flow_rate : float or array_like, optional
        Volumetric flow rate q (m^3/s).
    pressure_drop : float or array_like, optional
        Pressure drop p(0) - p(L) (Pa).
    coupler : "auto", registered name, or Coupler instance
        ``"auto"`` takes the cheapest coupler that supports the pair and meets the
        accuracy contract (``closed-form`` where it exists, else ``quadrature``).
    outlet_pressure : float or array_like
        Gauge pressure of the fluid at the outlet, p(L) >= 0 (Pa).
    external_pressure : float or array_like
        Pressure outside the tube, p_e (Pa; any sign): the wall responds to the transmural
        pressure p - p_e. A negative transmural pressure is admitted down to the wall's
        :meth:`~tubefsi.walls.WallModel.min_pressure` (minus the buckling pressure of an
        axisymmetric wall, unbounded for ``shapiro``), else :class:`~tubefsi.BucklingError`.
    on_infeasible : {"raise", "nan"}
        What a point beyond a limit (the maximum flow rate, the limit pressure) gets:
        ``"raise"`` (the default) raises :class:`NoSteadyStateError` for the whole call;
        ``"nan"`` gives that point NaN results and ``False`` in :attr:`Solution.feasible`.
    density : float or array_like, optional
        The fluid's density (kg/m^3): adds the reduced Reynolds number to the validity checks.
    progress : bool or "auto"
        Show a progress bar over the points (tqdm, ``pip install 'tubefsi[progress]'``) for a
        long sweep; ``"auto"``: only if tqdm is installed and standard error is a terminal.

    Every result is checked against the model's assumptions on the *deformed* tube
    (:mod:`tubefsi.validity`: slenderness :math:`R_{in}/L`, the wall law's calibrated strain,
    a linear wall at large strain, the reduced Reynolds number when ``density`` is given); each
    that fails is a :class:`~tubefsi.ModelValidityWarning` (silence it with
    ``warnings.filterwarnings("ignore", category=tubefsi.ModelValidityWarning)``).

    Returns
    -------
    Solution

    Raises
    ------
    InvalidParameterError
        For any input outside its admissible range.
    NoSteadyStateError
        Beyond the wall's limit pressure or the maximum flow rate (``on_infeasible="raise"``).
    StretchRangeError
        Below the maximum flow rate but beyond the solver's range (an inlet stretch over
        ``1e15``; ``docs/theory.md``, section "The maximum flow rate"), whatever ``on_infeasible``.
    """
    if (pressure_drop is None and type(coupler) is str and coupler == "auto"
            and type(outlet_pressure) is float and outlet_pressure == 0.0 and on_infeasible == "raise"
            and density is None and progress is False
            and type(external_pressure) is float and external_pressure == 0.0):
        fast = (_scalar_flow(rheology, wall, tube, flow_rate) if type(flow_rate) is float else
                _curve_flow(rheology, wall, tube, flow_rate) if type(flow_rate) is np.ndarray else None)
        if fast is not None:
            return fast
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure, external_pressure=external_pressure)
    if not scene.graded:
        _radius_power_in_range(scene)
    if (flow_rate is None) == (pressure_drop is None):
        raise InvalidParameterError("flow_rate / pressure_drop", "exactly one of the two",
                                    None, "give flow_rate= or pressure_drop=, not both or neither")
    if on_infeasible not in ("raise", "nan"):
        raise InvalidParameterError("on_infeasible", "{'raise', 'nan'}", on_infeasible)
    rho = None if density is None else as_load("density", density, allow_zero=False)
    chosen = _graded(scene, coupler) if scene.graded else select_coupler(scene.rheology, scene.wall, coupler)
    runner = checked(chosen)            # a self-checking coupler is re-solved finer (AccuracyWarning)
    controlled = "flow_rate" if flow_rate is not None else "pressure_drop"
    load = as_load(controlled, flow_rate if flow_rate is not None else pressure_drop)
    try:
        shape = np.broadcast_shapes(scene.shape, load.shape)
    except ValueError:
        raise InvalidParameterError(controlled, f"arrays that broadcast with the parameters' shape {scene.shape}",
                                    load, f"shape {load.shape}") from None
    if rho is not None and np.broadcast_shapes(shape, rho.shape) != shape:
        raise InvalidParameterError("density", f"an array that broadcasts to the result's shape {shape}", rho)
    flat = scene.flat(shape)
    values = load.ravel() if load.shape == shape else np.broadcast_to(load, shape).ravel()
    method = runner.flow_controlled if controlled == "flow_rate" else runner.pressure_controlled
    n = values.size
    out = _Results(n)
    feasible = np.ones(n, dtype=bool)
    # solve first, and look for the maximum flow rate only if a point failed: the engine's or a
    # graded tube's (whose maximum costs a dozen integrations along z)
    optimistic = controlled == "flow_rate" and (_is(type(chosen), SeparatedVariables)
                                                 or isinstance(chosen, Graded))
    shown = bar(n, progress, "tubefsi.solve")
    with curve_span(flat, values) if optimistic and flat.size == 1 and n > CHUNK else contextlib.nullcontext():
        _solve_chunks(flat, values, method, runner, controlled, optimistic, on_infeasible, out, feasible, shown)
    shown.close()
    # two sums (NaN and inf survive them) of what was computed: the load was validated finite
    computed = "pressure_drop" if controlled == "flow_rate" else "flow_rate"
    with np.errstate(over="ignore", invalid="ignore"):
        quick = math.isfinite(float(out[computed].sum() + out["inlet_strain"].sum()))
    finite = True if quick else (np.isfinite(out["pressure_drop"]) & np.isfinite(out["flow_rate"])
                                 & np.isfinite(out["inlet_strain"]))
    if not quick and not np.all(finite | ~feasible):
        i = int(np.argmax(~finite & feasible))
        raise _beyond_range(controlled, values[i:i + 1], "the result is not a finite double")
    if density is not None:
        density = float(rho) if rho.ndim == 0 else np.broadcast_to(rho, shape).ravel()
    warn(check(flat.uniform_at(0.0) if scene.graded else flat, out["flow_rate"], out["inlet_strain"],
               density=density))
    state = State(*(out[f.name].reshape(shape) for f in attrs.fields(State)))
    return Solution(scene=scene, coupler=chosen, state=state, scalar=shape == (),
                    coupler_name=registry.couplers.name_of(chosen) or type(chosen).__name__,
                    feasible=None if np.all(feasible) else feasible.reshape(shape), density=density,
                    controlled=controlled)


class _Results(dict):
    """The State fields of every point of a solve, filled chunk by chunk (NaN where no chunk
    answered); a single chunk that answers every point hands over its arrays without a copy."""

    def __init__(self, n):
        super().__init__()
        self.n = n

    def store(self, idx, state):
        """Store ``state`` at the points ``idx`` (indices, or a slice of consecutive points)."""
        size = idx.stop - idx.start if type(idx) is slice else idx.size
        whole = not self and size == self.n
        for f in _STATE_FIELDS:
            value = np.asarray(getattr(state, f), dtype=float)
            if whole and value.shape == (self.n,) and value.flags.writeable:   # not a broadcast view
                self[f] = value
                continue
            if f not in self:
                self[f] = np.full(self.n, np.nan)
            self[f][idx] = np.broadcast_to(value, (size,))

    def __missing__(self, name):          # no chunk answered (every point beyond a limit)
        value = self[name] = np.full(self.n, np.nan)
        return value


_STATE_FIELDS = tuple(f.name for f in attrs.fields(State))


def _solve_chunks(flat, values, method, runner, controlled, optimistic, on_infeasible, out, feasible, shown):
    """Solve every point of ``flat`` in chunks of at most ``CHUNK`` points (one parameter set per
    chunk where a model needs it), storing into ``out`` and ``feasible``."""
    n = values.size
    # a scene of scalars (a curve) is one part, its points in order: chunks are slices
    parts = [(None, flat)] if flat.size == 1 else flat.split(np.arange(n))
    for index, part in parts:
        size = n if index is None else index.size
        for start in range(0, size, CHUNK):
            stop = min(start + CHUNK, size)
            idx = np.arange(start, stop) if index is None and size > CHUNK else (
                slice(start, stop) if index is None else index[start:stop])
            chunk = part if part.size == 1 or stop - start == size else part.take(np.arange(start, stop))
            load = values[idx].copy() if index is None else values[idx]   # (a copy: the state keeps it)
            if optimistic:
                # the engine detects a point beyond the limit itself (its inlet stretch runs away):
                # solve first, and look for the limit (a quadrature to infinity) only if one did
                try:
                    state = method(chunk, load)
                except OverflowError:         # a scene beyond double precision: a typed error
                    raise _beyond_range(controlled, load, "an intermediate quantity overflows") from None
                except (NoSteadyStateError, StretchRangeError) as error:   # the limit decides which
                    if _feasible(runner, chunk, load, controlled, raise_=on_infeasible == "raise") is None:
                        raise error
                else:
                    out.store(idx, state)
                    shown.update(stop - start)
                    continue
            ok = _feasible(runner, chunk, load, controlled, raise_=on_infeasible == "raise")
            go = np.arange(stop - start) if ok is None else np.flatnonzero(ok)
            if ok is not None:
                feasible[idx] = ok
            if go.size == 0:
                shown.update(stop - start)
                continue
            sub = chunk if go.size == stop - start else (chunk.take(go) if chunk.size > 1 else chunk)
            try:
                state = method(sub, load[go])
            except OverflowError:             # a scene beyond double precision: a typed error
                raise _beyond_range(controlled, load[go], "an intermediate quantity overflows") from None
            out.store(np.arange(start, stop)[go] if type(idx) is slice else idx[go], state)
            shown.update(stop - start)


def _graded(scene, coupler):
    """The coupler of a tube or wall that varies along z (``docs/graded.md``): :class:`Graded`, with
    ``coupler`` (unless ``"auto"``) for the equivalent uniform tube of a separable taper."""
    if isinstance(coupler, Graded):
        return coupler
    if isinstance(coupler, str) and coupler == "auto":
        return Graded()
    return Graded(uniform=select_coupler(scene.rheology, scene.wall, coupler))


def _beyond_range(controlled, values, why):
    """The typed error of a load (with its scene) whose solution leaves double precision."""
    return InvalidParameterError(controlled, "loads whose solution is within double precision",
                                 float(np.ravel(values)[0]) if np.size(values) else None,
                                 f"{why} (outlet pressure and load must keep every pressure, stretch and "
                                 "flow rate below 1.8e308)")


_SUBCLASS: dict = {}


def _is(cls, base) -> bool:
    """``issubclass``, cached (an ABC's check is slow next to the rest of the scalar path)."""
    key = (cls, base)
    found = _SUBCLASS.get(key)
    if found is None:
        found = _SUBCLASS[key] = issubclass(cls, base)
    return found


_INF = math.inf
_COUPLERS = registry.couplers


#: The scalar path's plan of the last rheology and tube it saw: ``(rheology, tube, radius
#: exponent k, radius a, t/a, length L, a^k)``, read off the two objects once and reused while
#: the next call brings the same two (a Monte Carlo loop over a wall's parameters); both are
#: immutable (a ``Tube``, a rheology that cannot change, :func:`_unchanging`: for any other
#: rheology the plan holds None and is made again each call), so what was read off them stands. A tuple: a loop that changes
#: the fluid or the tube every call pays one tuple for it. (None, None) before the first call.
_LAST_PLAN: list = [(None, None)]
#: The last ``(rheology, q, phi(q))`` of the scalar path (one tuple: a thread never sees half
#: of another's).
_LAST_FLOW: list = [(None, None, None)]


#: The lean curve path's last ``(rheology, wall, tube, registry generation, coupler, coupler
#: name, scene)``: a script that draws curve after curve through the same three objects (a
#: parameter study plotting each) resolves and validates them once. Kept only for models that
#: cannot change (:func:`_unchanging`); any other is resolved on every call.
_LAST_CURVE: list = [(None,) * 7]
#: Field values that cannot change in place.
_LEAVES = (float, int, str, bool, type(None))


@attrs.frozen
class _FrozenProbe:
    """A frozen attrs class, for the ``__setattr__`` every frozen attrs class has."""


_FROZEN_SETATTR = _FrozenProbe.__setattr__


@functools.cache
def _field_names(cls) -> tuple[str, ...]:
    return tuple(field.name for field in attrs.fields(cls))


def _unchanging(model) -> bool:
    """Whether nothing of ``model`` can change after it is made: a frozen attrs class whose
    fields all hold floats, ints, strings, booleans, None or tuples of these (a dict, a list or
    an array field could be changed in place, and what was derived from it would go stale).
    What the scalar plan (:data:`_LAST_PLAN`) and the curve path (:data:`_LAST_CURVE`) keep by
    identity."""
    if type(model).__setattr__ is not _FROZEN_SETATTR:
        return False
    for name in _field_names(type(model)):
        value = getattr(model, name)
        if type(value) is tuple:
            if not all(type(item) in _LEAVES for item in value):
                return False
        elif type(value) not in _LEAVES:
            return False
    return True


def _plan(rheology, tube):
    """The scalar path's plan (:data:`_LAST_PLAN`) of ``rheology`` and ``tube``, stored, or None
    where the path does not apply (a field or the radius exponent not a float, a non-separable
    rheology, a^k beyond the doubles: the general path says so)."""
    if not rheology.separable:
        return None
    k = rheology.radius_exponent
    a, t, length = tube.radius, tube.thickness, tube.length
    if type(k) is not float or type(a) is not float or type(t) is not float or type(length) is not float:
        return None
    kept = rheology if _unchanging(rheology) else None     # (one that can change: not kept)
    try:
        plan = (kept, tube, k, a, t / a, length, a**k)
    except OverflowError:
        return None
    _LAST_PLAN[0] = plan
    return plan


def _scalar_flow(rheology, wall, tube, q):
    """The lean scalar path: one flow rate through a scene of scalars whose curve table is cached
    (a Monte Carlo loop over a modulus, a viscosity, the tube's size or the load). None where it
    does not apply; the general path then answers (and builds the table for the next call)."""
    if type(tube) is not Tube or not 0.0 < q < _INF:
        return None
    chosen = _AUTO.get((type(rheology), type(wall), _COUPLERS.generation))
    if chosen is None:                         # first time for this pair of classes
        chosen = _auto(rheology, wall)
    if chosen is False or wall.is_rigid or wall._installed_tube(tube) is not tube:
        return None                            # (False: not a pair of models)
    plan = _LAST_PLAN[0]
    if plan[0] is not rheology or plan[1] is not tube:
        plan = _plan(rheology, tube)
        if plan is None:
            return None
    _, _, k, a, tb, length, radius_power = plan
    try:
        table = _TABLES.get((type(wall), wall._shape_key(), tb, k))
    except TypeError:                          # an array parameter in the wall's shape
        return None
    if not table:
        return None
    scale = wall._pressure_scale()
    if type(scale) is not float:
        return None
    flow = _LAST_FLOW[0]
    if flow[0] is rheology and flow[1] == q:
        phi = flow[2]
    else:
        phi = rheology._flow_factor(q)
        if type(phi) is not float:
            return None
        _LAST_FLOW[0] = (plan[0], q, phi)       # (plan[0]: None for a rheology that is not kept)
    norm = radius_power * scale
    if not 2.2250738585072014e-308 <= norm < _INF:     # a power law of a large index: the general path
        return None
    x = math.log(length * phi / norm)
    if not table.x_lo <= x <= table.x_hi:
        return None
    pair = table.scalar_pair
    if pair is not None:
        y, log_rise = pair(x)
    else:
        y = table.inverse.scalar(x)
        log_rise = table.pressure.scalar(y)
    v = math.exp(y)
    strain = math.expm1(v)
    drop = scale * math.exp(log_rise)
    log_stretch_max = table.log_stretch_max
    if log_stretch_max is None:                # the key's (wall shape, t/a): the same for every scene of it
        log_stretch_max = table.log_stretch_max = _log_max_stretch(wall, tb)
    parts = (rheology, wall, tube, log_stretch_max)
    if a * (1.0 + strain) > SLENDERNESS * length or strain > wall.calibrated_strain:
        warn(check(Scene._trusted(*parts), q, strain))
    return Solution._scalar_flow_controlled(parts, chosen[0], (q, drop, strain, v), chosen[1])


def _curve_flow(rheology, wall, tube, flow_rate):
    """The lean path of a flow curve: a 1-D array of at most ``CHUNK`` flow rates through a scene
    of scalars whose table is built and serves every point
    (:meth:`~tubefsi.couplers.separated.SeparatedVariables.curve_from_table`). The same answer as
    the general path, without its chunks, masks and index arrays (a third of a 10^4-point call's
    time at a table's speed). None where it does not apply; the general path then answers."""
    if (type(tube) is not Tube or flow_rate.ndim != 1 or not 0 < flow_rate.size <= CHUNK
            or type(tube.radius) is not float or type(tube.thickness) is not float or type(tube.length) is not float):
        return None
    last = _LAST_CURVE[0]
    if last[0] is rheology and last[1] is wall and last[2] is tube and last[3] == _COUPLERS.generation:
        coupler, name, scene = last[4:]
    else:
        chosen = _auto(rheology, wall)
        if chosen is False or not _is(type(chosen[0]), SeparatedVariables) or chosen[0].refined() is not None:
            return None
        if parameter_shape(rheology) != () or parameter_shape(wall) != ():     # array parameters: a broadcast solve
            return None
        coupler, name = chosen
        scene = make_scene(rheology, wall, tube)
        if scene.shape != () or scene.graded or wall.is_rigid:
            return None
        _radius_power_in_range(scene)
        if _unchanging(rheology) and _unchanging(wall):
            _LAST_CURVE[0] = (rheology, wall, tube, _COUPLERS.generation, coupler, name, scene)
    q = as_load("flow_rate", flow_rate).copy()             # (a copy: the solution keeps it)
    state = coupler.curve_from_table(scene, q)
    if state is None:
        return None
    with np.errstate(over="ignore", invalid="ignore"):     # (NaN and inf survive the sums)
        if not math.isfinite(float(state.pressure_drop.sum() + state.inlet_strain.sum())):
            return None
    warn(check(scene, q, state.inlet_strain))
    return Solution(scene=scene, coupler=coupler, state=state, scalar=False, coupler_name=name)


#: Points per coupler call: bounds the working memory (a few tens of MB) of any sweep.
CHUNK = 1 << 14


def _feasible(coupler, scene, load, controlled, *, raise_):
    """The points below every limit (None: all of them); raises for the first one beyond if ``raise_``."""
    if controlled == "flow_rate":
        limit = np.asarray(coupler.max_flow_rate(scene), dtype=float)
        if not np.any(np.isfinite(limit)):
            return None
        beyond = (load > 0) & (load >= limit)
        quantity, detail = "flow_rate", "the tube inflates without bound"
    else:
        limit = np.asarray(coupler.limit_pressure(scene) if scene.graded else scene.wall.limit_pressure(scene.tb),
                           dtype=float) - scene.outlet_pressure
        if not np.any(np.isfinite(limit)):
            return None
        beyond = load >= limit
        limit = limit + np.asarray(scene.outlet_pressure)
        quantity, detail = "pressure", "the inlet pressure is the outlet pressure plus the pressure drop"
    beyond = np.broadcast_to(beyond, load.shape)
    if not np.any(beyond):
        return None
    if raise_:
        i = int(np.argmax(beyond))
        value = float(load[i]) if quantity == "flow_rate" else float(
            np.broadcast_to(np.asarray(scene.outlet_pressure), load.shape)[i] + load[i])
        raise NoSteadyStateError(quantity, float(np.broadcast_to(limit, load.shape)[i]), value, detail,
                                 name="" if quantity == "flow_rate" else "the inlet pressure")
    return ~beyond


@checked_keywords
def max_flow_rate(rheology, wall, tube, *, outlet_pressure=0.0, external_pressure=0.0, coupler="auto"):
    r"""The largest flow rate with a steady state (m^3/s); ``inf`` where every flow rate has one.

    Finite only for a wall with a limit pressure (thick or thin-current
    Mooney–Rivlin/neo-Hookean) and a fluid whose :math:`G(q,R)` falls off slowly
    enough in :math:`R`: for a power law, exactly when :math:`n < 1`. Then
    :math:`L\,\phi(q_{max}) = \int_0^\infty s P'(s)/\psi(as)\,du`. Array parameters broadcast
    (an array of the scene's shape comes back).
    """
    scene = make_scene(rheology, wall, tube, outlet_pressure=outlet_pressure, external_pressure=external_pressure)
    try:
        if not scene.graded:
            _radius_power_in_range(scene)
    except FactorRangeError:
        if type(tube.radius) is not float or not (_plain(tube.thickness) and _plain(tube.length)):
            raise
        unit = tube.radius       # in units of the radius (the limit is a flow rate: times unit^3)
        return max_flow_rate(rheology, wall, in_units(tube, unit), outlet_pressure=outlet_pressure,
                             external_pressure=external_pressure, coupler=coupler) * unit**3
    chosen = _graded(scene, coupler) if scene.graded else select_coupler(scene.rheology, scene.wall, coupler)
    if scene.shape == ():
        return float(chosen.max_flow_rate(scene))
    flat = scene.flat(scene.shape)
    out = np.empty(flat.size)
    for index, part in flat.split(np.arange(flat.size)):
        out[index] = chosen.max_flow_rate(part)
    return out.reshape(scene.shape)


def _radius_units(function, args, kwargs):
    """The solve of ``function(*args, **kwargs)`` in units of the tube's (scalar, constant)
    radius, as a Solution of the original scene, or None where it does not apply or fails too."""
    import inspect

    call = inspect.signature(function).bind(*args, **kwargs)
    call.apply_defaults()
    given = dict(call.arguments)
    tube = given["tube"]
    if type(tube) is not Tube or given["density"] is not None or type(tube.radius) is not float:
        return None
    if not (_plain(tube.thickness) and _plain(tube.length)):     # a tapered or graded tube: the error stands
        return None
    scene = make_scene(given["rheology"], given["wall"], tube, outlet_pressure=given["outlet_pressure"],
                       external_pressure=given["external_pressure"])
    if scene.graded:             # a model varying along z: z would need the change of unit too
        return None
    unit = tube.radius
    if given["flow_rate"] is not None:
        given["flow_rate"] = as_load("flow_rate", given["flow_rate"]) / unit**3
    given["tube"] = in_units(tube, unit)
    try:
        inner = function(**given)
    except FactorRangeError:
        return None
    q = np.asarray(inner.state.flow_rate, dtype=float) * unit**3
    live = np.isfinite(q) & (np.asarray(inner.state.pressure_drop) > 0)
    if np.any(live & ~((q >= np.finfo(float).tiny) & (q < math.inf))):
        return None                    # the flow rate itself leaves the doubles: the error stands
    state = State(q if q.ndim else float(q), inner.state.pressure_drop, inner.state.inlet_strain,
                  inner.state.log_stretch)
    return Solution(scene=scene, coupler=Rescaled(inner=inner.coupler, unit=unit), state=state, scalar=inner.scalar,
                    coupler_name=inner.coupler_name, feasible=inner.feasible, controlled=inner.controlled)


def _radius_power_in_range(scene):
    """Raise FactorRangeError where a power law's :math:`a^{3n+1}` leaves the normal doubles (the
    engine's normalization of the separated integral; then :func:`solve` works in units of the
    radius). One scalar test for a scalar radius."""
    k = scene.rheology.radius_exponent
    if type(k) is not float:
        return
    a = scene.tube.radius
    if type(a) is float:
        if k * abs(math.log(a)) <= 700.0:
            return
    elif not isinstance(a, np.ndarray) or k * float(np.max(np.abs(np.log(a)))) <= 700.0:
        return                       # (a radius along z: the graded coupler's own range checks)
    raise FactorRangeError("index", f"indices with a^(3n+1) within double precision at radius a", k,
                           "R^-(3n+1) leaves the range of double precision")


def _plain(value) -> bool:
    """A tube field of numbers (not a profile along z)."""
    return type(value) is float or isinstance(value, np.ndarray)
