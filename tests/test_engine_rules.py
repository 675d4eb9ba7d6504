"""The engine's rules, through the public API: a cache changes the time of a solve, never its bits.

Each test below failed, or could fail, on the engine before the rewrite (a plain-class wall took
another instance's table; a fluid changed in place kept its flow table and its maximum flow rate;
threads sharing one fluid got wrong answers and IndexErrors; a cheaper plugin coupler was bypassed;
answers depended on what the process had computed before; every fluid and run-time class stayed
alive). Each states its reference:

* an independent implementation of the same law: the built-in ``thin-neo-hookean`` wall of current
  thickness, whose separated integral is in closed form, for a wall written in the test as a plain
  ``_pressure`` (to 1e-12);
* the same computation in a fresh state, to the bit: a fresh instance with the new values after
  :func:`tubefsi.cache_clear`, the same calls in a fresh process and in another order, the
  sequential answers for threads, a Python float for the other spellings of one load, the built-in
  coupler that a plugin wraps;
* ``weakref`` and ``gc`` for what the process keeps alive; :func:`tubefsi.cache_info` for the bound.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import os
import random
import subprocess
import sys
import threading
import warnings
import weakref
from concurrent.futures import ThreadPoolExecutor

import attrs
import numpy as np
import pytest

import tubefsi
from tubefsi import registry
from tubefsi.registry import rheologies, walls
from tubefsi.rheology import Rheology
from tubefsi.walls import HyperelasticWall, ThickWall, WallModel

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
POWER = dict(consistency=0.017, index=0.7)
CARREAU = dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=3.313, index=0.3568)
CROSS = dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=1.007, exponent=1.028)
BINGHAM = dict(yield_stress=0.005, plastic_viscosity=0.0035)


def _same(a, b) -> bool:
    """Bit-for-bit equality of two results (floats or arrays; NaN equal to NaN, shapes equal)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def _bits(solution):
    """The three results of a solve, for a bit-for-bit comparison."""
    return tuple(np.asarray(getattr(solution, name), dtype=float).copy()
                 for name in ("flow_rate", "pressure_drop", "inlet_displacement"))


def _same_bits(x, y) -> bool:
    return all(_same(a, b) for a, b in zip(x, y))


def _subprocess_env():
    """The environment of a child process that imports the very tubefsi (and plugins) under test."""
    import tubefsi_hyperelastic
    import tubefsi_rheologies

    roots = [os.path.dirname(os.path.dirname(m.__file__)) for m in (tubefsi, tubefsi_rheologies, tubefsi_hyperelastic)]
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([*roots, *filter(None, [env.get("PYTHONPATH")])])
    env.setdefault("MPLBACKEND", "Agg")
    return env


# ------------------------------------------------------------------ 1. walls written in the test
class PlainThinWall(WallModel):
    r"""A plain Python class: the thin current-thickness neo-Hookean law :math:`\bar t\mu(1 - \lambda^{-4})`,
    nothing declared (no shape/scale split, no limit pressure)."""

    def __init__(self, modulus):
        self.modulus = modulus

    def _pressure(self, stretch, tb):
        return tb * self.modulus * (1.0 - stretch**-4)


@attrs.define
class MutableThinWall(WallModel):
    """The same law as a non-frozen attrs class (its modulus can change in place)."""

    modulus: float

    def _pressure(self, stretch, tb):
        return tb * self.modulus * (1.0 - stretch**-4)


@attrs.frozen
class DictThinWall(WallModel):
    """The same law, frozen, its parameters in a dict (whose content can change in place)."""

    params: dict

    def _pressure(self, stretch, tb):
        return tb * self.params["modulus"] * (1.0 - stretch**-4)


@attrs.frozen
class DeclaredDictWall(WallModel):
    """Both thin neo-Hookean laws, frozen, the modulus and the convention in a dict, with the
    shape/scale split declared from the dict's content at call time (so it shares tables)."""

    params: dict

    def _pressure(self, stretch, tb):
        mu = self.params["modulus"]
        if self.params["convention"] == "current":
            return tb * mu * (1.0 - stretch**-4)
        return tb * mu * (stretch - stretch**-3)

    def _pressure_scale(self):
        return float(self.params["modulus"])

    def _shape_key(self):
        return (self.params["convention"],)

    def _unit_wall(self):
        return DeclaredDictWall({"modulus": 1.0, "convention": self.params["convention"]})


def _thin(modulus, convention="current"):
    return walls["thin-neo-hookean"](shear_modulus=modulus, thickness_convention=convention)


def _loads():
    """100 flow rates of the power law, 0.05 to 0.4 of its maximum flow rate in the 1 kPa wall: inlet
    hoop strains ~0.16 to ~1.3 there and ~0.035 to ~0.17 in the 4 kPa wall, where the plain law's
    1 - lam^-4 keeps its relative accuracy and the inlet stretch its condition."""
    q_max = tubefsi.max_flow_rate(tubefsi.registry.rheologies["power-law"](**POWER), _thin(1e3), TUBE)
    return q_max * np.geomspace(0.05, 0.4, 100)


def _close(a, b, rtol=1e-12):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and float(np.max(np.abs(a / b - 1.0))) <= rtol


def test_two_plain_class_walls_never_share_an_answer():
    """Two instances of one plain-class wall (1 kPa and 4 kPa), solved alternately (a curve, a
    scalar, a pressure-controlled curve, a Problem), each give the answer of the built-in
    thin-neo-hookean wall (current thickness, closed form) of their own modulus, to 1e-12: the
    engine never hands one instance another's table. (The old engine was 292 % off on a curve and
    9.5 % on a scalar.)"""
    fluid = rheologies["power-law"](**POWER)
    q = _loads()
    one, four = PlainThinWall(1e3), PlainThinWall(4e3)
    ref = {1e3: tubefsi.solve(fluid, _thin(1e3), TUBE, flow_rate=q),
           4e3: tubefsi.solve(fluid, _thin(4e3), TUBE, flow_rate=q)}
    for _ in range(2):
        for wall in (one, four, one):
            mu = wall.modulus
            curve = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
            assert _close(curve.pressure_drop, ref[mu].pressure_drop)
            assert _close(curve.inlet_displacement, ref[mu].inlet_displacement)
            for i in (0, 40, 99):
                point = tubefsi.solve(fluid, wall, TUBE, flow_rate=float(q[i]))
                assert _close(point.pressure_drop, ref[mu].pressure_drop[i])
                assert _close(point.inlet_displacement, ref[mu].inlet_displacement[i])
            back = tubefsi.solve(fluid, wall, TUBE, pressure_drop=ref[mu].pressure_drop[::25])
            assert _close(back.flow_rate, q[::25])
            problem = tubefsi.Problem(fluid, wall, TUBE)
            assert _close(problem.solve(flow_rate=float(q[70])).pressure_drop, ref[mu].pressure_drop[70])
            assert _same_bits(_bits(problem.solve(flow_rate=q)), _bits(curve))


def test_a_wall_changed_in_place_gives_the_new_answer():
    """A non-frozen attrs wall whose modulus changes between calls, and a frozen attrs wall whose
    dict field changes content, give the new values' answers: against the built-in closed form of
    the new modulus (1e-12) and, to the bit, a fresh instance with the new values after
    cache_clear. A frozen wall that declares its shape/scale split from its dict gets the table of
    the shape its dict says now (the current, then the reference thickness convention)."""
    fluid = rheologies["power-law"](**POWER)
    q = _loads()
    for wall, change in [(MutableThinWall(1e3), lambda w, mu: setattr(w, "modulus", mu)),
                         (DictThinWall({"modulus": 1e3}), lambda w, mu: w.params.__setitem__("modulus", mu))]:
        for mu in (1e3, 4e3, 1e3, 4e3):
            change(wall, mu)
            curve = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
            point = tubefsi.solve(fluid, wall, TUBE, flow_rate=float(q[50]))
            ref = tubefsi.solve(fluid, _thin(mu), TUBE, flow_rate=q)
            assert _close(curve.pressure_drop, ref.pressure_drop)
            assert _close(point.pressure_drop, ref.pressure_drop[50])
            tubefsi.cache_clear()
            fresh = type(wall)(mu) if type(wall) is MutableThinWall else DictThinWall({"modulus": mu})
            assert _same_bits(_bits(tubefsi.solve(fluid, fresh, TUBE, flow_rate=q)), _bits(curve))
            assert _same_bits(_bits(tubefsi.solve(fluid, fresh, TUBE, flow_rate=float(q[50]))), _bits(point))

    declared = DeclaredDictWall({"modulus": 2e3, "convention": "current"})
    for mu, convention in [(2e3, "current"), (2e3, "reference"), (3e3, "reference"), (3e3, "current")]:
        declared.params.update(modulus=mu, convention=convention)
        ref = tubefsi.solve(fluid, _thin(mu, convention), TUBE, flow_rate=q)
        curve = tubefsi.solve(fluid, declared, TUBE, flow_rate=q)
        assert _close(curve.pressure_drop, ref.pressure_drop)
        assert _close(tubefsi.solve(fluid, declared, TUBE, flow_rate=float(q[50])).pressure_drop,
                      ref.pressure_drop[50])


# ------------------------------------------------------------------ 2. fluids changed in place
@attrs.define
class MutableCarreau(Rheology):
    r"""A Carreau fluid, non-frozen:
    :math:`\tau = \dot\gamma\,\{\eta_\infty + (\eta_0 - \eta_\infty)[1 + (\lambda\dot\gamma)^2]^{(n-1)/2}\}`
    (``_stress`` only: the generic, tabulated flow law; every flow rate has a steady state)."""

    eta0: float
    eta_inf: float
    lam: float
    n: float

    def _stress(self, shear_rate):
        x = self.lam * shear_rate
        return shear_rate * (self.eta_inf + (self.eta0 - self.eta_inf) * (1.0 + x * x) ** (0.5 * (self.n - 1.0)))


@attrs.define
class MutableSisko(Rheology):
    r"""The Carreau law's shear-thinning branch and its infinite-shear viscosity (Sisko), non-frozen:
    :math:`\tau = K\dot\gamma^n + \eta_\infty\dot\gamma` (``_stress`` only). Shear-thinning down to
    zero shear, it has a finite maximum flow rate in a thick neo-Hookean tube."""

    consistency: float
    index: float
    eta_inf: float

    def _stress(self, shear_rate):
        return self.consistency * shear_rate**self.index + self.eta_inf * shear_rate


@attrs.frozen
class RateGivenEllis(Rheology):
    r"""The Ellis law given by its shear rate alone,
    :math:`\dot\gamma = \tau/\eta_0\,[1 + (\tau/\tau_{1/2})^{\alpha - 1}]` (without the plugin's
    closed-form flow function no flow map serves it: each instance builds its own flow table)."""

    zero_shear_viscosity: float
    half_stress: float = 0.01
    exponent: float = 1.6

    def _shear_rate(self, stress):
        return stress / self.zero_shear_viscosity * (1.0 + (stress / self.half_stress) ** (self.exponent - 1.0))


@attrs.frozen
class ListCarreau(Rheology):
    """The Carreau law (no yield stress), frozen, its parameters in a list."""

    params: list

    def _stress(self, shear_rate):
        eta0, lam, n = self.params
        return shear_rate * eta0 * (1.0 + (lam * shear_rate) ** 2) ** (0.5 * (n - 1.0))


class PlainCarreau(Rheology):
    """The Carreau law as a plain class (its parameters in its ``__dict__``)."""

    def __init__(self, eta0, lam, n):
        self.eta0, self.lam, self.n = eta0, lam, n

    def _stress(self, shear_rate):
        return shear_rate * self.eta0 * (1.0 + (self.lam * shear_rate) ** 2) ** (0.5 * (self.n - 1.0))


def _answers(fluid, wall, q, *, with_max=True):
    out = [_bits(tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-9)),
           _bits(tubefsi.solve(fluid, wall, TUBE, flow_rate=q)),
           _bits(tubefsi.solve(fluid, wall, TUBE, pressure_drop=np.array([100.0, 300.0])))]
    if with_max:
        out.append((np.float64(tubefsi.max_flow_rate(fluid, wall, TUBE)),))
    return out


_MUTABLE = {
    "carreau": (MutableCarreau, [dict(eta0=0.056, eta_inf=0.00345, lam=3.313, n=0.3568),
                                 dict(eta0=0.1, eta_inf=0.00345, lam=3.313, n=0.5),
                                 dict(eta0=0.1, eta_inf=0.001, lam=1.0, n=0.5),
                                 dict(eta0=0.056, eta_inf=0.00345, lam=3.313, n=0.3568)]),
    "sisko": (MutableSisko, [dict(consistency=0.017, index=0.7, eta_inf=0.0035),
                             dict(consistency=0.03, index=0.5, eta_inf=0.0035),
                             dict(consistency=0.03, index=0.5, eta_inf=0.001),
                             dict(consistency=0.017, index=0.7, eta_inf=0.0035)]),
}


@pytest.mark.parametrize("law", sorted(_MUTABLE))
def test_a_fluid_changed_in_place_gets_the_new_flow_law_and_maximum_flow_rate(law):
    """A non-separable attrs fluid changed in place between solves: the pressure drop (a scalar, a
    100-point curve, pressure-controlled) and max_flow_rate (finite for the Sisko law) follow the
    new values, to the bit of a fresh instance with the new values solved after cache_clear;
    going back to the first values gives the first answers again. (The old engine kept the flow
    table and the cached maximum flow rate of the first values.)"""
    cls, values = _MUTABLE[law]
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.geomspace(1e-11, 2e-9, 100)
    fluid = cls(**values[0])
    seen = []
    for new in values:
        for name, value in new.items():
            setattr(fluid, name, value)
        got = _answers(fluid, wall, q)
        tubefsi.cache_clear()
        want = _answers(cls(**new), wall, q)
        assert all(_same_bits(g, w) for g, w in zip(got, want)), new
        seen.append(got)
    for a, b in zip(seen, seen[1:3]):
        assert not _same_bits(a[0], b[0]) and not _same_bits(a[1], b[1]) and not _same_bits(a[2], b[2])
    if law == "sisko":
        assert all(np.isfinite(answer[-1][0]) for answer in seen)
        assert len({float(answer[-1][0]) for answer in seen}) == 3
    assert all(_same_bits(g, w) for g, w in zip(seen[0], seen[3]))


@pytest.mark.parametrize("kind", ["frozen attrs with a list", "plain class"])
def test_a_fluid_whose_parameters_change_in_place_is_never_stale(kind):
    """A frozen attrs fluid whose list field changes content, and a plain-class fluid whose
    attributes change: every solve gives the bits of a fresh fluid of the new values (after
    cache_clear)."""
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = np.geomspace(1e-11, 2e-9, 80)
    fluid = ListCarreau([0.056, 3.313, 0.3568]) if kind != "plain class" else PlainCarreau(0.056, 3.313, 0.3568)
    for eta0, lam, n in [(0.056, 3.313, 0.3568), (0.1, 1.0, 0.5), (0.056, 3.313, 0.3568)]:
        if kind == "plain class":
            fluid.eta0, fluid.lam, fluid.n = eta0, lam, n
        else:
            fluid.params[:] = [eta0, lam, n]
        got = _answers(fluid, wall, q, with_max=False)
        tubefsi.cache_clear()
        fresh = ListCarreau([eta0, lam, n]) if kind != "plain class" else PlainCarreau(eta0, lam, n)
        want = _answers(fresh, wall, q, with_max=False)
        assert all(_same_bits(g, w) for g, w in zip(got, want)), (eta0, lam, n)


def test_a_fluid_subclass_with_its_own_attribute_gets_its_own_flow_table():
    """A plain subclass of the plugin's attrs Carreau with an attribute of its own (a factor on the
    stress, in the instance's ``__dict__``): two instances with different factors give different
    answers, each the bits of itself solved after cache_clear. The flow table's key must hold every
    value the law depends on, not only the attrs fields."""
    carreau = rheologies["carreau"]

    class ScaledCarreau(carreau):
        def __init__(self, factor, **kwargs):
            super().__init__(**kwargs)
            object.__setattr__(self, "factor", factor)

        def _stress(self, shear_rate):
            return self.factor * super()._stress(shear_rate)

    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    kwargs = dict(CARREAU, infinite_shear_viscosity=0.0)
    tubefsi.cache_clear()
    first = tubefsi.solve(ScaledCarreau(1.0, **kwargs), wall, TUBE, flow_rate=1e-9).pressure_drop
    second = tubefsi.solve(ScaledCarreau(2.0, **kwargs), wall, TUBE, flow_rate=1e-9).pressure_drop
    tubefsi.cache_clear()
    alone = tubefsi.solve(ScaledCarreau(2.0, **kwargs), wall, TUBE, flow_rate=1e-9).pressure_drop
    assert first != alone
    assert second == alone, f"factor 2 got {second!r} (the factor-1 fluid's table), alone {alone!r}"


# ------------------------------------------------------------------ 3. threads
def _tasks(fluids, wall):
    """(name, call) pairs through shared objects: scalar and array loads, both controls, a shared
    Problem, max_flow_rate and on_infeasible="nan" (with a thin current-thickness wall, whose limit
    pressure gives a finite maximum flow rate to a yield-stress or power-law fluid)."""
    tasks = []
    curve = np.geomspace(1e-11, 2e-9, 100)
    thin = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="current")
    for name, fluid in fluids.items():
        problem = tubefsi.Problem(fluid, wall, TUBE)
        for q in (2e-10, 7e-10, 1.3e-9):
            tasks.append((f"{name} q={q}", lambda f=fluid, q=q: _bits(tubefsi.solve(f, wall, TUBE, flow_rate=q))))
        tasks.append((f"{name} np q", lambda f=fluid: _bits(tubefsi.solve(f, wall, TUBE, flow_rate=np.float64(9e-10)))))
        tasks.append((f"{name} curve", lambda f=fluid: _bits(tubefsi.solve(f, wall, TUBE, flow_rate=curve))))
        tasks.append((f"{name} short", lambda f=fluid: _bits(tubefsi.solve(f, wall, TUBE, flow_rate=curve[::10]))))
        tasks.append((f"{name} dp", lambda f=fluid: _bits(tubefsi.solve(f, wall, TUBE, pressure_drop=250.0))))
        tasks.append((f"{name} dp curve", lambda f=fluid: _bits(
            tubefsi.solve(f, wall, TUBE, pressure_drop=np.linspace(10.0, 300.0, 7)))))
        tasks.append((f"{name} problem", lambda p=problem: _bits(p.solve(flow_rate=np.array([4e-10, 1.1e-9])))))
        tasks.append((f"{name} max", lambda f=fluid: (np.float64(tubefsi.max_flow_rate(f, thin, TUBE)),)))
        limit = tubefsi.max_flow_rate(fluid, thin, TUBE)
        beyond = np.array([1e-9, 3e-9] + ([1.2 * limit] if np.isfinite(limit) else []))
        tasks.append((f"{name} nan", lambda f=fluid, q=beyond: _bits(
            tubefsi.solve(f, thin, TUBE, flow_rate=q, on_infeasible="nan"))))
    return tasks


def _run_threaded(tasks, reference, threads=8, rounds=1):
    """Every task in every thread, each thread in its own shuffled order, started together after
    cache_clear: no exception and every answer the reference's bits."""
    barrier = threading.Barrier(threads)

    def worker(seed):
        order = list(range(len(tasks))) * rounds
        random.Random(seed).shuffle(order)
        barrier.wait()
        return [(i, tasks[i][1]()) for i in order]

    tubefsi.cache_clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        with ThreadPoolExecutor(threads) as pool:
            results = [f.result() for f in [pool.submit(worker, seed) for seed in range(threads)]]
    wrong = sorted({tasks[i][0] for found in results for i, answer in found if not _same_bits(answer, reference[i])})
    assert not wrong, f"answers under threads differ from the sequential ones: {wrong}"


def test_threads_sharing_non_separable_fluids():
    """8 threads share one Carreau, one Cross and one Bingham fluid (the plugin's registered classes)
    and their walls, each solving scalar, NumPy-scalar, 100-point and 10-point flow rates, pressure
    drops, a shared Problem, max_flow_rate and infeasible points as NaN, in its own
    shuffled order, from an empty cache: no exception, and every answer is the bits of the same call
    made sequentially after cache_clear. (The old engine gave wrong answers and IndexErrors.)"""
    fluids = {"carreau": rheologies["carreau"](**CARREAU), "cross": rheologies["cross"](**CROSS),
              "bingham": rheologies["bingham"](**BINGHAM)}
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    tasks = _tasks(fluids, wall)
    tubefsi.cache_clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        reference = [call() for _, call in tasks]
    _run_threaded(tasks, reference)


def test_threads_on_the_separable_table_path():
    """The same for the separated tables: power-law fluids of two indices with thick neo-Hookean
    walls of two moduli (shared tables per index), scalars, 100-point curves and the rest of the
    calls above, from an empty cache, against the sequential bits."""
    fluids = {"n=0.7": rheologies["power-law"](**POWER), "n=0.5": rheologies["power-law"](consistency=0.02, index=0.5)}
    tasks = []
    for modulus in (2e3, 3e3):
        wall = walls["thick-neo-hookean"](shear_modulus=modulus)
        tasks += [(f"{name} mu={modulus}", call) for name, call in _tasks(fluids, wall)]
    tubefsi.cache_clear()
    reference = [call() for _, call in tasks]
    _run_threaded(tasks, reference)


_COLD_THREADS = r"""
import sys, threading
from concurrent.futures import ThreadPoolExecutor
import tubefsi

barrier = threading.Barrier(8)
fluids = ["carreau", "cross", "bingham", "power-law", "ellis", "casson", "herschel-bulkley", "carreau-yasuda"]
wall_names = ["thick-demiray", "thin-gent", "thick-neo-hookean", "thin-yeoh"]

def first_use(i):
    barrier.wait()
    return (tubefsi.registry.rheologies[fluids[i]].__name__, tubefsi.registry.walls[wall_names[i % 4]].__name__,
            "quadrature" in tubefsi.registry.couplers)

with ThreadPoolExecutor(8) as pool:
    futures = [pool.submit(first_use, i) for i in range(8)]
errors = []
for f in futures:
    try:
        f.result()
    except Exception as exc:
        errors.append(f"{type(exc).__name__}: {exc}")
print(len(errors))
print("\n".join(errors))
"""


def test_threads_reaching_the_registries_first():
    """A fresh process whose first use of the registries is from 8 threads at once (each looks up a
    plugin fluid and wall by its registered name): every lookup succeeds, and none is a
    PluginWarning (a name lost to a race is unknown for the rest of the process). Reference: the
    same lookups made from one thread."""
    env = _subprocess_env()
    for _ in range(2):
        run = subprocess.run([sys.executable, "-W", "error::UserWarning", "-c", _COLD_THREADS], capture_output=True,
                             text=True, env=env, timeout=120)
        assert run.returncode == 0, run.stderr
        count, _, errors = run.stdout.partition("\n")
        assert count == "0", f"first registry lookups from threads failed:\n{errors}"


# ------------------------------------------------------------------ 4. history independence
_HISTORY = r"""
import sys, random, warnings
import numpy as np
import tubefsi
from tubefsi.registry import rheologies as R, walls as W
warnings.simplefilter("ignore")

T = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
T2 = tubefsi.Tube(radius=1.5e-4, thickness=3e-5, length=2e-2)
F = {"pl7": R["power-law"](consistency=0.017, index=0.7), "pl5": R["power-law"](consistency=0.004, index=0.5),
     "car": R["carreau"](zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=3.313,
                         index=0.3568),
     "bing": R["bingham"](yield_stress=0.005, plastic_viscosity=0.0035)}
WL = {"thick": W["thick-neo-hookean"](shear_modulus=2e3), "thin": W["thin-neo-hookean"](shear_modulus=2e3,
      thickness_convention="current"), "demiray": W["thick-demiray"](shear_modulus=2e3, stiffening=2.0),
      "tfung": W["thin-demiray"](shear_modulus=1e3, stiffening=20.0), "ref": W["thin-neo-hookean"](shear_modulus=1e3)}
CURVE = np.geomspace(1e-11, 2e-9, 100)


def hexes(x):
    return " ".join(float(v).hex() for v in np.ravel(np.asarray(x, dtype=float)))


def sol(**kw):
    def call(f, w, tube=T):
        s = tubefsi.solve(F[f], WL[w], tube, **kw)
        return hexes(s.flow_rate) + " | " + hexes(s.pressure_drop) + " | " + hexes(s.inlet_displacement)
    return call


CALLS = {}
for f in F:
    for w in ("thick", "thin", "demiray"):
        CALLS[f"{f}/{w}/q"] = (sol(flow_rate=7e-10), f, w)
        CALLS[f"{f}/{w}/curve"] = (sol(flow_rate=CURVE, on_infeasible="nan"), f, w)
    CALLS[f"{f}/thick/dp"] = (sol(pressure_drop=np.array([50.0, 150.0, 250.0])), f, "thick")
    CALLS[f"{f}/tfung/dp1"] = (sol(pressure_drop=120.0), f, "tfung")
    CALLS[f"{f}/thick/max"] = (lambda f, w: tubefsi.max_flow_rate(F[f], WL[w], T).hex(), f, "thick")
CALLS["pl7/thin/max"] = (lambda f, w: tubefsi.max_flow_rate(F[f], WL[w], T).hex(), "pl7", "thin")
CALLS["pl7/ref/q-tube2"] = (lambda f, w: sol(flow_rate=1.1e-9)(f, w, T2), "pl7", "ref")
CALLS["car/ref/curve-out"] = (sol(flow_rate=CURVE[::3], outlet_pressure=30.0), "car", "ref")
CALLS["pl7/thick/profile"] = (lambda f, w: hexes(tubefsi.solve(F[f], WL[w], T, flow_rate=CURVE[::7]).pressure(
    np.linspace(0.0, 1e-2, 5)[:, None])), "pl7", "thick")


def unrelated(i):
    # other fluids, walls and tubes: fill the one cache past its bound (evictions included)
    fluid = R["power-law"](consistency=0.017, index=0.3 + 0.01 * (i % 60)) if i % 2 else \
        R["cross"](zero_shear_viscosity=0.05 + 0.001 * i, infinite_shear_viscosity=0.003, relaxation_time=1.0,
                   exponent=0.8)
    wall = W["thick-neo-hookean"](shear_modulus=1e3 + 10.0 * i)
    tube = tubefsi.Tube(radius=1e-4, thickness=(2e-5, 3e-5, 4e-5)[i % 3], length=1e-2)
    q = np.geomspace(1e-12, 1e-10, 70 if i % 5 == 0 else 3)
    tubefsi.solve(fluid, wall, tube, flow_rate=q, on_infeasible="nan")
    tubefsi.solve(fluid, wall, tube, flow_rate=float(q[-1]) * 1.3)


names = list(CALLS)
if sys.argv[1] == "shuffled":
    random.Random(int(sys.argv[2])).shuffle(names)
    names = names[::-1]
for k, name in enumerate(names):
    if sys.argv[1] == "shuffled":
        for j in range(3):
            unrelated(3 * k + j)
    call, f, w = CALLS[name]
    print(name, "=", call(f, w), flush=True)
"""


def test_answers_do_not_depend_on_the_process_history(tmp_path):
    """A fixed list of 40 mixed calls (power law, Carreau and Bingham; thick and thin neo-Hookean,
    thick and thin Demiray walls; scalars, 100-point curves, pressure-controlled, an outlet pressure,
    another tube, max_flow_rate, a profile) run in two fresh processes: in order, and in a
    shuffled reverse order with ~120 unrelated solves interleaved (other fluids, walls and tubes,
    enough to evict from the cache). Every call prints the same bits in both. (The old engine's
    answers depended on what the process had computed before.)"""
    script = tmp_path / "history.py"
    script.write_text(_HISTORY)
    env = _subprocess_env()

    def run(*args):
        out = subprocess.run([sys.executable, str(script), *args], capture_output=True, text=True, env=env,
                             timeout=300)
        assert out.returncode == 0, out.stderr
        lines = [line.partition(" = ") for line in out.stdout.splitlines()]
        return {name: value for name, _, value in lines}

    ordered = run("ordered")
    shuffled = run("shuffled", "7")
    assert len(ordered) >= 40 and ordered.keys() == shuffled.keys()
    differ = [name for name in ordered if ordered[name] != shuffled[name]]
    assert not differ, f"calls whose bits depend on the history: {differ}"
    # and the same calls here, in this process's own (other) history: the same bits
    ns = {}
    with warnings.catch_warnings():
        exec(compile(_HISTORY.split("\nnames = list(CALLS)")[0], "history", "exec"), ns)
        for name in ("pl7/thick/q", "car/thick/curve", "bing/thin/q", "pl5/thick/max"):
            call, f, w = ns["CALLS"][name]
            assert call(f, w) == ordered[name], name


# ------------------------------------------------------------------ 5. one load, many spellings
@pytest.mark.parametrize("scene", ["table (power law, thick neo-Hookean)", "direct (Carreau)"])
def test_every_spelling_of_one_load_gives_the_same_bits(scene):
    """1e-9 as a Python float, a NumPy scalar, a 0-d array, a 1-element array (then the results have
    shape (1,)) and a one-element list give the same bits; so do an integer load and its float (a
    pressure drop of 300 Pa; a flow rate of 1 m^3/s through a tube of radius 1 m), outlet_pressure 0 and 0.0,
    and Problem(...).solve against tubefsi.solve. Reference: the Python float's solve."""
    tubefsi.cache_clear()
    fluid = rheologies["power-law"](**POWER) if scene.startswith("table") else rheologies["carreau"](**CARREAU)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    big = tubefsi.Tube(radius=1.0, thickness=0.3, length=100.0)
    big_wall = walls["thick-neo-hookean"](shear_modulus=20.0)
    problem, big_problem = tubefsi.Problem(fluid, wall, TUBE), tubefsi.Problem(fluid, big_wall, big)
    cases = [(TUBE, wall, problem, "flow_rate", 1e-9, [np.float64(1e-9), np.array(1e-9)]),
             (TUBE, wall, problem, "pressure_drop", 300.0, [300, np.int64(300), np.float64(300.0), np.array(300)]),
             (big, big_wall, big_problem, "flow_rate", 1.0, [1, np.int64(1), np.float64(1.0), np.array(1.0)])]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        for tube, w, prob, load, value, spellings in cases:
            reference = tubefsi.solve(fluid, w, tube, **{load: value})
            assert type(reference.pressure_drop) is float and type(reference.flow_rate) is float
            want = _bits(reference)
            for other in spellings:
                assert _same_bits(_bits(tubefsi.solve(fluid, w, tube, **{load: other})), want), (load, repr(other))
                assert _same_bits(_bits(prob.solve(**{load: other})), want), ("Problem", load, repr(other))
            for one in (np.array([value]), [value]):
                got = tubefsi.solve(fluid, w, tube, **{load: one})
                assert np.shape(got.pressure_drop) == (1,)
                assert _same_bits([x[0] for x in _bits(got)], want), (load, repr(one))
                assert _same_bits([x[0] for x in _bits(prob.solve(**{load: one}))], want), ("Problem", load)
            assert _same_bits(_bits(prob.solve(**{load: value})), want)
            for outlet in (0, 0.0, np.float64(0.0), np.array(0.0)):
                assert _same_bits(_bits(tubefsi.solve(fluid, w, tube, outlet_pressure=outlet, **{load: value})),
                                  want), ("outlet_pressure", repr(outlet))
                assert _same_bits(_bits(tubefsi.Problem(fluid, w, tube, outlet_pressure=outlet).solve(
                    **{load: value})), want), ("Problem outlet_pressure", repr(outlet))
    # a curve and a maximum flow rate: the Problem's are the function's
    q = np.geomspace(1e-11, 2e-9, 100)
    assert _same_bits(_bits(problem.solve(flow_rate=q)), _bits(tubefsi.solve(fluid, wall, TUBE, flow_rate=q)))
    assert _same(problem.max_flow_rate(), tubefsi.max_flow_rate(fluid, wall, TUBE))


# ------------------------------------------------------------------ 6. a plugin coupler that auto picks
_PLUGIN = r'''
"""A coupler for the tests: the built-in quadrature, counted, registered cheapest of all."""
from typing import ClassVar

import attrs

from tubefsi.couplers import Coupler, Quadrature

CALLS = []


@attrs.frozen
class CountingCoupler(Coupler):
    cost_rank: ClassVar[int] = -5
    inner: Coupler = attrs.field(factory=Quadrature)

    def supports(self, rheology, wall):
        return True

    def _count(self, name):
        CALLS.append(name)

    def flow_controlled(self, scene, flow_rate):
        self._count("flow_controlled")
        return self.inner.flow_controlled(scene, flow_rate)

    def flow_controlled_point(self, scene, flow_rate):
        self._count("flow_controlled_point")
        return self.inner.flow_controlled_point(scene, flow_rate)

    def pressure_controlled(self, scene, pressure_drop):
        self._count("pressure_controlled")
        return self.inner.pressure_controlled(scene, pressure_drop)

    def solve_feasible(self, scene, load, controlled):
        self._count("solve_feasible")
        return self.inner.solve_feasible(scene, load, controlled)

    def limit_pressure(self, scene):
        self._count("limit_pressure")
        return self.inner.limit_pressure(scene)

    def max_flow_rate(self, scene):
        self._count("max_flow_rate")
        return self.inner.max_flow_rate(scene)

    def profile(self, scene, state, z):
        self._count("profile")
        return self.inner.profile(scene, state, z)

    def length_integral(self, scene, state, weight, *, uniform=False):
        self._count("length_integral")
        return self.inner.length_integral(scene, state, weight, uniform=uniform)
'''


@contextlib.contextmanager
def _registered_coupler(tmp_path, name="cheap-counting", module="tubefsi_rules_cheap_coupler"):
    """The coupler of ``_PLUGIN`` installed as a distribution declaring the entry point
    ``tubefsi.couplers: name``, the registries refreshed; afterwards sys.path, the module and the
    registries restored."""
    root = tmp_path / "plugin"
    info = root / f"{module}-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(f"[tubefsi.couplers]\n{name} = {module}:CountingCoupler\n")
    (root / f"{module}.py").write_text(_PLUGIN)
    try:
        with pytest.MonkeyPatch.context() as mp:
            mp.syspath_prepend(str(root))
            registry.refresh()
            yield importlib.import_module(module)
    finally:
        sys.modules.pop(module, None)
        registry.refresh()


@pytest.mark.parametrize("pair", ["power law, thick (quadrature)", "power law, thin (closed form)", "carreau, thick"])
def test_a_registered_cheaper_coupler_answers_every_solve_auto_gives_it(tmp_path, pair):
    """A plugin coupler registered through the entry-point group with cost_rank -5 (below every
    built-in): coupler="auto" gives it seven kinds of solve — a float, a NumPy scalar, a 100-point
    curve, pressure-controlled, on_infeasible="nan" past the maximum flow rate, max_flow_rate, a
    profile — and each reaches it (its call counter grows), Solution.coupler is it and
    Solution.coupler_name its registered name. Its answers are the bits of the built-in quadrature
    it wraps (the reference). After it is uninstalled, auto is back to a built-in."""
    fluid = rheologies["carreau"](**CARREAU) if pair.startswith("carreau") else rheologies["power-law"](**POWER)
    wall = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="current") if "thin" in pair \
        else walls["thick-neo-hookean"](shear_modulus=2e3)
    q_max = tubefsi.max_flow_rate(fluid, wall, TUBE)
    top = q_max if np.isfinite(q_max) else 2e-9
    curve = np.geomspace(1e-3, 0.9, 100) * top
    beyond = np.concatenate([curve[::10], [1.1 * top]]) if np.isfinite(q_max) else curve[::10]
    z = np.linspace(0.0, TUBE.length, 5)
    solves = {
        "float": lambda c: tubefsi.solve(fluid, wall, TUBE, flow_rate=7e-10, coupler=c),
        "numpy scalar": lambda c: tubefsi.solve(fluid, wall, TUBE, flow_rate=np.float64(7e-10), coupler=c),
        "curve": lambda c: tubefsi.solve(fluid, wall, TUBE, flow_rate=curve, coupler=c),
        "pressure": lambda c: tubefsi.solve(fluid, wall, TUBE, pressure_drop=np.array([80.0, 200.0]), coupler=c),
        "nan": lambda c: tubefsi.solve(fluid, wall, TUBE, flow_rate=beyond, on_infeasible="nan", coupler=c),
        "max_flow_rate": lambda c: tubefsi.max_flow_rate(fluid, wall, TUBE, coupler=c),
        "profile": lambda c: tubefsi.solve(fluid, wall, TUBE, flow_rate=curve[::20], coupler=c).pressure(z[:, None]),
    }

    def outcome(result):
        if isinstance(result, tubefsi.Solution):
            return _bits(result)
        return (np.asarray(result, dtype=float),)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        reference = {name: outcome(call("quadrature")) for name, call in solves.items()}
        with _registered_coupler(tmp_path) as plugin:
            cls = plugin.CountingCoupler
            assert isinstance(tubefsi.select_coupler(fluid, wall), cls)
            problem = tubefsi.Problem(fluid, wall, TUBE)
            assert isinstance(problem.coupler, cls) and problem.coupler_name == "cheap-counting"
            for name, call in solves.items():
                before = len(plugin.CALLS)
                result = call("auto")
                assert len(plugin.CALLS) > before, f"the {name} solve bypassed the registered cheaper coupler"
                if isinstance(result, tubefsi.Solution):
                    assert isinstance(result.coupler, cls) and result.coupler_name == "cheap-counting", name
                assert _same_bits(outcome(result), reference[name]), name
            before = len(plugin.CALLS)
            assert _same_bits(_bits(problem.solve(flow_rate=7e-10)), reference["float"])
            assert len(plugin.CALLS) > before
    assert not isinstance(tubefsi.select_coupler(fluid, wall), cls)
    assert "cheap-counting" not in registry.couplers


# ------------------------------------------------------------------ 7. nothing kept alive
def test_a_fluid_and_a_wall_solved_once_are_released_without_clearing():
    """A non-separable fluid (the plugin's Carreau) and its wall, solved once each way (scalar,
    curve, max_flow_rate, pressure-controlled), are garbage once the caller drops them: the
    cache still holds their tables (keyed by value), not them. Reference: weakref + gc."""
    fluid = rheologies["carreau"](**CARREAU)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    solution = tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-9)
    tubefsi.solve(fluid, wall, TUBE, flow_rate=np.geomspace(1e-11, 2e-9, 100))
    tubefsi.solve(fluid, wall, TUBE, pressure_drop=100.0)
    tubefsi.max_flow_rate(fluid, wall, TUBE)
    tubefsi.Problem(fluid, wall, TUBE).solve(flow_rate=2e-10)
    refs = weakref.ref(fluid), weakref.ref(wall)
    size = tubefsi.cache_info().size
    del fluid, wall, solution
    gc.collect()
    assert [r() for r in refs] == [None, None]
    assert tubefsi.cache_info().size == size > 0


def _run_time_classes():
    """Fluid and wall classes made at run time (a class statement in a function and type(...)),
    solved through every path they have, their instances dropped: weak references to the classes."""

    # (laws given by their shear rate: no flow map serves them, so each builds its flow table)
    @attrs.frozen
    class RunTimeFluid(Rheology):
        eta0: float

        def _shear_rate(self, stress):
            return stress / self.eta0 * (1.0 + (stress / 0.01) ** 0.6)

    class RunTimePlainFluid(Rheology):
        def __init__(self, eta0):
            self.eta0 = eta0

        def _shear_rate(self, stress):
            return stress / self.eta0 * (1.0 + (stress / 0.02) ** 0.5)

    plain_wall = type("RunTimeWall", (WallModel,), {
        "__init__": lambda self, modulus: setattr(self, "modulus", modulus),
        "_pressure": lambda self, stretch, tb: tb * self.modulus * (1.0 - stretch**-4)})
    split_wall = type("RunTimeNeoHookean", (walls["thick-neo-hookean"],),    # (declaring its split)
                      {"__module__": __name__, "_shape_key": walls["thick-neo-hookean"]._shape_key})
    power = rheologies["power-law"](**POWER)
    curve = np.geomspace(1e-11, 1e-9, 100)
    for fluid in (RunTimeFluid(0.05), RunTimePlainFluid(0.04)):
        for wall in (plain_wall(2e3), split_wall(shear_modulus=2e3)):
            tubefsi.solve(fluid, wall, TUBE, flow_rate=5e-10)
            tubefsi.solve(fluid, wall, TUBE, flow_rate=curve)
    tubefsi.solve(power, split_wall(shear_modulus=2e3), TUBE, flow_rate=5e-10)     # its separated table
    tubefsi.solve(power, split_wall(shear_modulus=3e3), TUBE, flow_rate=curve)
    tubefsi.max_flow_rate(power, split_wall(shear_modulus=2e3), TUBE)
    return [weakref.ref(c) for c in (RunTimeFluid, RunTimePlainFluid, plain_wall, split_wall)]


def test_classes_made_at_run_time_are_released_without_clearing():
    """Run-time fluid classes (attrs and plain) and wall classes (a plain WallModel and a subclass
    of thick-neo-hookean that declares its shape/scale split, so its tables are keyed by a weak
    reference to it) are released once their instances are gone, the cache still holding their
    tables: no cache_clear is needed."""
    tubefsi.cache_clear()
    refs = _run_time_classes()
    gc.collect()
    size = tubefsi.cache_info().size
    assert size >= 3                                   # their flow tables and separated tables
    assert [r() for r in refs] == [None] * len(refs)
    assert tubefsi.cache_info().size == size


def test_a_run_time_subclass_of_a_limit_point_wall_is_released():
    """A run-time subclass of the hyperelastic plugin's thick Ogden wall whose tube law peaks (one
    term, exponent 1: a limit point found by a scan), solved once, its instance dropped: the class
    and the instance are released, without clearing the cache and after clearing it."""
    power = rheologies["power-law"](**POWER)

    def solve_once():
        cls = type("RunTimeOgden", (walls["thick-ogden"],), {"__module__": __name__})
        wall = cls(moduli=(2e3,), exponents=(1.0,))
        assert np.isfinite(wall.limit_pressure(0.3))
        tubefsi.solve(power, wall, TUBE, flow_rate=1e-10)
        return weakref.ref(wall), weakref.ref(cls)

    refs = solve_once()
    gc.collect()
    kept_without_clearing = [r() is not None for r in refs]
    tubefsi.cache_clear()
    gc.collect()
    kept_after_clearing = [r() is not None for r in refs]
    assert kept_without_clearing == [False, False], \
        f"kept alive (wall, class): {kept_without_clearing}; after cache_clear: {kept_after_clearing}"


# ------------------------------------------------------------------ 8. the cache is bounded
def test_the_cache_is_bounded_and_clearing_changes_no_answer():
    """200 distinct fluids (100 Ellis fluids given by their shear rate, each its own flow table; 100 power laws, each its
    own separated table) keep cache_info().size within maxsize at every step; the first fluid's
    answer after its table was evicted is its first answer's bits; and cache_clear changes no
    answer (a scalar and a curve through a table, a Carreau scalar and curve, max_flow_rate)."""
    tubefsi.cache_clear()
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    maxsize = tubefsi.cache_info().maxsize
    first = {}
    for i in range(200):
        fluid = RateGivenEllis(zero_shear_viscosity=0.0035 * (1 + i / 997)) if i % 2 else \
            rheologies["power-law"](consistency=0.017, index=0.5 + i / 997)
        answer = _bits(tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-10))
        if i < 2:
            first[i] = (fluid, answer)
        info = tubefsi.cache_info()
        assert info.size <= maxsize, (i, info)
    assert tubefsi.cache_info().misses >= 200 > maxsize
    for fluid, answer in first.values():                  # evicted long ago: built again, the same bits
        assert _same_bits(_bits(tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-10)), answer)

    curve = np.geomspace(1e-11, 2e-9, 100)
    calls = [lambda: _bits(tubefsi.solve(rheologies["power-law"](**POWER), wall, TUBE, flow_rate=7e-10)),
             lambda: _bits(tubefsi.solve(rheologies["power-law"](**POWER), wall, TUBE, flow_rate=curve)),
             lambda: _bits(tubefsi.solve(rheologies["carreau"](**CARREAU), wall, TUBE, flow_rate=7e-10)),
             lambda: _bits(tubefsi.solve(rheologies["carreau"](**CARREAU), wall, TUBE, flow_rate=curve)),
             lambda: (np.float64(tubefsi.max_flow_rate(rheologies["power-law"](**POWER), wall, TUBE)),)]
    before = [call() for call in calls]
    warm = [call() for call in calls]               # from the tables the first round built
    tubefsi.cache_clear()
    assert tubefsi.cache_info().size == 0
    after = [call() for call in calls]
    assert all(_same_bits(a, b) and _same_bits(a, c) for a, b, c in zip(before, warm, after))


@attrs.frozen(kw_only=True)
class _Declared(ThickWall, HyperelasticWall):
    """A Gent-like law written the tutorial's way, declaring its shape/scale split in its body."""

    mu: float = 2e3

    def _dW(self, s):
        return self.mu * (s - s**-3) / (1.0 - (s - 1.0 / s) ** 2 / 50.0)

    def _pressure_scale(self):
        return self.mu

    def _shape_key(self):
        return ()

    def _unit_wall(self):
        return attrs.evolve(self, mu=1.0)


@attrs.frozen(kw_only=True)
class _Offset(_Declared):
    """A subclass whose law is no longer proportional to mu, declaring nothing."""

    def _dW(self, s):
        return super()._dW(s) + 500.0 * (s - s**-3)


@attrs.frozen(kw_only=True)
class _Written(ThickWall, HyperelasticWall):
    """_Offset's law written out, without a split (the reference: it shares no table)."""

    mu: float = 2e3

    def _dW(self, s):
        return self.mu * (s - s**-3) / (1.0 - (s - 1.0 / s) ** 2 / 50.0) + 500.0 * (s - s**-3)


def test_a_subclass_that_changes_the_law_does_not_inherit_the_split():
    """A wall class that declares its split in its body shares one table between its instances;
    a subclass that changes the law (W' + 500 Pa (lambda - lambda^-3), no longer proportional to
    mu) and declares nothing shares none: its answers are the same law written out without a split
    (the reference), to 1e-12, scalar and curve, after the parent's table exists. A split inherited
    from the parent would scale the subclass's unit law (off by ~20 %)."""
    power = rheologies["power-law"](**POWER)
    curve = np.geomspace(1e-11, 5e-10, 80)
    tubefsi.cache_clear()
    tubefsi.solve(power, _Declared(mu=1e3), TUBE, flow_rate=curve)
    assert tubefsi.cache_info().size == 1                  # the declared split's table
    for mu in (1e3, 3e3):
        reference = tubefsi.solve(power, _Written(mu=mu), TUBE, flow_rate=curve)
        got = tubefsi.solve(power, _Offset(mu=mu), TUBE, flow_rate=curve)
        np.testing.assert_allclose(got.pressure_drop, reference.pressure_drop, rtol=1e-12)
        one = tubefsi.solve(power, _Offset(mu=mu), TUBE, flow_rate=5e-10).pressure_drop
        assert one == pytest.approx(tubefsi.solve(power, _Written(mu=mu), TUBE, flow_rate=5e-10).pressure_drop,
                                    rel=1e-12)
    assert tubefsi.cache_info().size == 1                  # neither made a table of its own
