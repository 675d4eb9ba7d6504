"""The curve tables (tubefsi.couplers._tables) and the lean scalar path they serve.

References: the direct, error-controlled path of the same engine with the tables switched off
(the tables must reproduce it to its own accuracy, 1e-13), and closed forms for the Chebyshev
fitter. The direct path itself is checked against mpmath in test_accuracy_contract.py and
against an independent brute force in the contract suites.
"""

from __future__ import annotations

import importlib

import attrs
import numpy as np
import pytest

import tubefsi
import tubefsi.couplers.separated as engine
from tubefsi.couplers._tables import fit_chebyshev
from tubefsi.registry import rheologies, walls

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)

WALLS = [
    walls["thick-neo-hookean"](shear_modulus=2e3),
    walls["thin-neo-hookean"](shear_modulus=2e3),
    walls["thick-mooney-rivlin"](c1=1.5e3, c2=-0.5e3),
    walls["thick-fung"](shear_modulus=2e3, stiffening=2.0),
    walls["thin-fung"](shear_modulus=1e3, stiffening=20.0),
    walls["thick-gent"](shear_modulus=2e3, locking_parameter=3.0),
    walls["thick-yeoh"](c1=1e3, c2=50.0, c3=2.0),
]


def _curve(wall):
    q_max = tubefsi.max_flow_rate(FLUID, wall, TUBE)
    top = 0.95 * q_max if np.isfinite(q_max) else 5e-9
    return np.concatenate([[0.0], np.geomspace(1e-6 * top, top, 400)])


@pytest.mark.parametrize("wall", WALLS, ids=repr)
def test_table_reproduces_the_direct_path(wall, monkeypatch):
    q = _curve(wall)
    engine._TABLES.clear()
    tabled = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)
    assert any(t for t in engine._TABLES.values()), "no table was built for this curve"
    z = np.array([0.0, 0.3, 0.7, 1.0])[:, None] * TUBE.length
    p_tabled = tabled.pressure(z)
    back_tabled = tubefsi.solve(FLUID, wall, TUBE, pressure_drop=tabled.pressure_drop)
    monkeypatch.setattr(engine, "_TABLE_MIN_POINTS", 10**9)
    monkeypatch.setattr(engine, "_worth_building", lambda scene: False)
    engine._TABLES.clear()
    direct = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)
    np.testing.assert_allclose(tabled.pressure_drop, direct.pressure_drop, rtol=1e-13, atol=0)
    np.testing.assert_allclose(tabled.inlet_displacement, direct.inlet_displacement, rtol=1e-13, atol=0)
    np.testing.assert_allclose(p_tabled, direct.pressure(z), rtol=1e-13, atol=1e-300)
    back_direct = tubefsi.solve(FLUID, wall, TUBE, pressure_drop=direct.pressure_drop)
    # near a limit pressure the flow rate is ill-conditioned in the pressure drop: kappa = dln q/dln dp
    kappa = np.ones(q.size)
    kappa[1:] = np.maximum(1.0, np.abs(np.gradient(np.log(q[1:]), np.log(direct.pressure_drop[1:]))))
    assert np.all(np.abs(back_tabled.flow_rate - back_direct.flow_rate) <= 1e-12 * kappa * q)
    assert np.all(np.abs(back_tabled.flow_rate - q) <= 1e-11 * kappa * q)


def test_scalar_path_equals_the_general_path(monkeypatch):
    """A loop of scalar solves (a fresh wall each call) takes the lean path once its key repeats;
    its answers are those of the general path, as floats, with working profiles."""
    solve_module = importlib.import_module("tubefsi.solve")     # the module (tubefsi.solve is the function)
    cases = ((2e3, 1e-9), (3e3, 3e-9), (2.5e3, 1e-12))
    with monkeypatch.context() as off:          # the references: no table at all
        off.setattr(engine, "_TABLE_MIN_POINTS", 10**9)
        off.setattr(engine, "_worth_building", lambda scene: False)
        off.setattr(solve_module, "_scalar_flow", lambda *args: None)
        direct = [tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=mu), TUBE, flow_rate=q)
                  for mu, q in cases]
    engine._TABLES.clear()
    engine._SPENT.clear()
    served = []
    real = solve_module._scalar_flow

    def counting(*args):
        out = real(*args)
        served.append(out is not None)
        return out

    monkeypatch.setattr(solve_module, "_scalar_flow", counting)
    # the table is built once the direct solves of the key have cost as much as a build would
    monkeypatch.setattr(engine, "_BUILD_SECONDS", [0.0])
    for _ in range(3):
        fast = [tubefsi.solve(FLUID, walls["thick-neo-hookean"](shear_modulus=mu), TUBE, flow_rate=q)
                for mu, q in cases]
    assert served[:1] == [False] and all(served[-3:]), served
    for f, d in zip(fast, direct):
        assert isinstance(f.pressure_drop, float)
        assert f.pressure_drop == pytest.approx(d.pressure_drop, rel=1e-13)
        assert f.inlet_displacement == pytest.approx(d.inlet_displacement, rel=1e-13)
        assert f.pressure(0.4 * TUBE.length) == pytest.approx(d.pressure(0.4 * TUBE.length), rel=1e-12)
        assert f.coupler_name == d.coupler_name == "quadrature"


def test_a_table_that_fails_its_check_is_not_used(monkeypatch):
    """If the a-posteriori check of a table fails, every point goes to the direct path."""
    import tubefsi.couplers._tables as tables

    real = tables.fit_chebyshev

    def sloppy(f, lo, hi, **kw):                 # an interpolant that is off by 1e-9
        cheb, err = real(f, lo, hi, **kw)
        if cheb is not None:
            off = cheb.coef.copy()
            off[:, 0] += 1e-9
            cheb = tables.Chebyshev(cheb.breaks, off)
        return cheb, err

    monkeypatch.setattr(engine, "fit_chebyshev", sloppy)
    # (the curve interpolation, which would serve the points next, checks inside fit_chebyshev)
    monkeypatch.setattr(engine.SeparatedVariables, "_curve_by_interpolation", lambda self, scene, q: None)
    engine._TABLES.clear()
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    q = _curve(wall)
    sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)
    assert list(engine._TABLES.values()) == [False]
    monkeypatch.setattr(engine, "fit_chebyshev", real)
    monkeypatch.setattr(engine, "_TABLE_MIN_POINTS", 10**9)
    engine._TABLES.clear()
    np.testing.assert_allclose(sol.pressure_drop, tubefsi.solve(FLUID, wall, TUBE, flow_rate=q).pressure_drop,
                               rtol=1e-14, atol=0)


@pytest.mark.parametrize("fn, lo, hi", [(np.sin, 0.0, 10.0), (np.exp, -5.0, 5.0), (np.log1p, 0.0, 100.0)])
def test_chebyshev_fit_meets_its_tolerance(fn, lo, hi):
    cheb, err = fit_chebyshev(fn, lo, hi)
    x = np.linspace(lo, hi, 10001)
    scale = np.maximum(1.0, np.abs(fn(x)))
    assert np.max(np.abs(cheb(x) - fn(x)) / scale) < 1e-14
    assert err < 1e-14
    for xi in x[::997]:
        assert abs(cheb.scalar(float(xi)) - fn(xi)) <= 1e-14 * max(1.0, abs(fn(xi)))
    d = cheb.derivative()
    if fn is np.sin:
        np.testing.assert_allclose(d(x), np.cos(x), atol=1e-12)


def test_chebyshev_fit_gives_up_honestly():
    """A function it cannot resolve (an infinite slope inside) gives no interpolant, not a wrong one."""
    cheb, err = fit_chebyshev(lambda x: np.sqrt(np.abs(x - 0.3)), 0.0, 1.0, max_panels=64)
    assert cheb is None and err == np.inf


CURVE_CASES = [
    (rheologies["carreau-yasuda"](**rheologies["carreau-yasuda"]._examples[0]),
     walls["thick-neo-hookean"](shear_modulus=2e3), 0.0),
    (rheologies["bingham"](**rheologies["bingham"]._examples[0]), walls["thick-mooney-rivlin"](c1=1.5e3, c2=-0.5e3),
     0.0),
    (FLUID, walls["thick-fung"](shear_modulus=2e3, stiffening=2.0), 300.0),     # separable, loaded outlet
]


@pytest.mark.parametrize("case", CURVE_CASES, ids=lambda c: f"{type(c[0]).__name__}-{type(c[1]).__name__}-{c[2]:g}")
def test_curve_interpolation_reproduces_the_direct_path(case, monkeypatch):
    """A long curve with no table (non-separable fluid, loaded outlet) interpolates ln v(ln q)
    between direct solves: it must agree with the direct path point by point (1e-13)."""
    fluid, wall, p_out = case
    q_max = tubefsi.max_flow_rate(fluid, wall, TUBE, outlet_pressure=p_out)
    top = 0.9 * q_max if np.isfinite(q_max) else 3e-9
    q = np.geomspace(1e-4 * top, top, 300)
    calls = []
    real = engine.SeparatedVariables._curve_by_interpolation

    def spy(self, scene, flow):
        out = real(self, scene, flow)
        calls.append(out is not None)
        return out

    monkeypatch.setattr(engine.SeparatedVariables, "_curve_by_interpolation", spy)
    curve = tubefsi.solve(fluid, wall, TUBE, flow_rate=q, outlet_pressure=p_out)
    assert calls == [True]
    sample = q[::23]
    monkeypatch.setattr(engine, "_TABLE_MIN_POINTS", 10**9)
    direct = tubefsi.solve(fluid, wall, TUBE, flow_rate=sample, outlet_pressure=p_out)
    np.testing.assert_allclose(curve.pressure_drop[::23], direct.pressure_drop, rtol=1e-13, atol=0)
    np.testing.assert_allclose(curve.inlet_displacement[::23], direct.inlet_displacement, rtol=1e-13, atol=0)


def test_a_chunked_curve_builds_one_interpolant(monkeypatch):
    """A curve of several chunks through one scene (10^6 points at the real chunk size; 300 points
    in chunks of 64 here) fits ln v(ln q) once over the whole call, and each chunk's points agree
    with the direct path (1e-13), the chunk edges included."""
    import sys

    solve_module = sys.modules["tubefsi.solve"]
    fluid, wall, _ = CURVE_CASES[0]
    q = np.geomspace(3e-13, 3e-9, 300)
    fits = []
    real = engine.SeparatedVariables._fit_log_stretch

    def spy(self, scene, lo, hi):
        fits.append((lo, hi))
        return real(self, scene, lo, hi)

    monkeypatch.setattr(engine.SeparatedVariables, "_fit_log_stretch", spy)
    monkeypatch.setattr(solve_module, "CHUNK", 64)
    curve = tubefsi.solve(fluid, wall, TUBE, flow_rate=q)
    assert fits == [(pytest.approx(np.log(q[0]), rel=1e-15), pytest.approx(np.log(q[-1]), rel=1e-15))]
    sample = np.r_[0, 63, 64, 127, 128, 150, 299]
    monkeypatch.setattr(engine, "_TABLE_MIN_POINTS", 10**9)
    direct = tubefsi.solve(fluid, wall, TUBE, flow_rate=q[sample])
    np.testing.assert_allclose(curve.pressure_drop[sample], direct.pressure_drop, rtol=1e-13, atol=0)
    np.testing.assert_allclose(curve.inlet_displacement[sample], direct.inlet_displacement, rtol=1e-13, atol=0)


@pytest.mark.parametrize("decay", [0.05, 1.0])
def test_chebyshev_lookup_against_numpy_chebval(decay):
    """Both evaluation rules (Horner in the monomial basis where the conversion is benign, i.e.
    for decaying coefficients; Clenshaw otherwise) agree with numpy's chebval on each panel."""
    from tubefsi.couplers._tables import Chebyshev
    rng = np.random.default_rng(4)
    breaks = np.array([0.0, 0.3, 0.5, 1.2, 2.0])
    coef = rng.standard_normal((4, 11)) * decay ** np.arange(11)
    table = Chebyshev(breaks, coef)
    assert table._horner == (decay < 1)
    x = rng.uniform(0.0, 2.0, 500)
    j = np.clip(np.searchsorted(breaks, x, side="right") - 1, 0, 3)
    t = 2.0 * (x - breaks[j]) / np.diff(breaks)[j] - 1.0
    ref = np.array([np.polynomial.chebyshev.chebval(ti, coef[ji]) for ti, ji in zip(t, j)])
    scale = np.abs(coef).sum(axis=1)[j]      # rounding ~ eps sum |c_k| x degree (Horner), x degree^2 (Clenshaw)
    bound = 4e-16 if decay < 1 else 1e-14
    assert np.max(np.abs(table(x) - ref) / scale) < bound
    assert max(abs(table.scalar(float(xi)) - ri) / si for xi, ri, si in zip(x[:50], ref, scale)) < bound


def test_chebyshev_lookup_at_the_ends_and_breaks_and_in_place():
    """At the ends of the range and on either side of every breakpoint (where the bucket lookup
    may pick the neighbouring panel, or one past the last, whose gathers clip) an interpolant of
    sin is still within its tolerance; evaluating into the argument's own array (``out=x``, the
    curve path) gives the same values, for both evaluation rules."""
    from tubefsi.couplers._tables import Chebyshev
    cheb, _ = fit_chebyshev(np.sin, -1.0, 7.0)
    b = cheb.breaks
    x = np.concatenate([b, np.nextafter(b, np.inf)[:-1], np.nextafter(b, -np.inf)[1:], np.linspace(-1.0, 7.0, 101)])
    got = cheb(x)
    assert np.max(np.abs(got - np.sin(x))) < 1e-14
    rough = Chebyshev(b, np.random.default_rng(7).standard_normal(cheb.coef.shape))     # Clenshaw
    assert cheb._horner and not rough._horner
    for table in (cheb, rough):
        inplace = x.copy()
        assert table(inplace, out=inplace) is inplace
        np.testing.assert_array_equal(inplace, table(x))


def test_the_scalar_rule_is_the_array_rule_bit_for_bit():
    """The scalar path's unrolled Horner rule per panel does the array rule's operations in its
    order: the same bits at every point (and a second call, from the cached rule, too)."""
    cheb, _ = fit_chebyshev(np.log1p, 0.0, 100.0)
    assert cheb._horner
    x = np.concatenate([cheb.breaks, np.random.default_rng(2).uniform(0.0, 100.0, 300)])
    array = cheb(x)
    for _ in range(2):
        assert [cheb.scalar(float(v)) for v in x] == array.tolist()


def test_the_scalar_state_is_a_state():
    from tubefsi.scene import State, _scalar_state
    made = _scalar_state(1e-9, 2.5e3, 0.25, np.log1p(0.25))
    assert made == State(1e-9, 2.5e3, 0.25, np.log1p(0.25)) and type(made) is State


@pytest.mark.parametrize("fn, lo, hi", [(np.sin, -1.0, 7.0), (np.log1p, 0.0, 100.0), (np.arctan, 0.0, 30.0)])
def test_uniform_fit_meets_its_tolerance_everywhere(fn, lo, hi):
    """The low-degree uniform interpolant (the array path of a table's inverse) against the
    function itself (numpy's, to an ulp) at 2e5 points it was not fitted or checked at, at both
    ends, and evaluated into its argument's own array."""
    from tubefsi.couplers._tables import fit_uniform
    fast, err = fit_uniform(fn, lo, hi)
    assert fast is not None and err <= 2e-15
    x = np.concatenate([[lo, hi, np.nextafter(hi, -np.inf)], np.random.default_rng(7).uniform(lo, hi, 200_000)])
    want = fn(x)
    assert np.max(np.abs(fast(x) - want) / np.maximum(1.0, np.abs(want))) <= 4e-15
    same = x.copy()
    assert np.array_equal(fast(same, out=same), fast(x))


def test_uniform_fit_gives_up_honestly():
    """A function no rule of the budget resolves (a square-root singularity at the end) gets
    None, and the table keeps its degree-10 inverse; so does one whose panel coordinate's rounding
    (an absolute eps (hi - lo) in x: arctan's slope 1 at 0, 30 from the lower end) exceeds the
    tolerance."""
    from tubefsi.couplers._tables import fit_uniform
    fast, err = fit_uniform(lambda x: np.sqrt(np.maximum(1.0 - x, 0.0)), 0.0, 1.0)
    assert fast is None and err == np.inf
    assert fit_uniform(np.arctan, -30.0, 30.0)[0] is None


def test_thin_reference_pressure_from_the_log_stretch_against_mpmath():
    r"""The thin reference-thickness law from :math:`v = \ln\lambda` (:math:`-\lambda\,\mathrm{expm1}(-4v)`
    with :math:`\lambda = 1 + \mathrm{expm1}(v)`, the curve path) against :math:`\lambda - \lambda^{-3}` in 40-digit mpmath, from
    :math:`v = 10^{-12}` to 650, within 4 ulp; the current-thickness law and other arguments fall
    back to the strain form exactly."""
    import mpmath
    mpmath.mp.dps = 40
    wall = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="reference")
    v = np.concatenate([np.geomspace(1e-12, 650.0, 400), [3e-9, 0.5, 2.0]])
    got = wall._pressure_at_log_stretch(v, np.expm1(v), 0.3)
    lam = [mpmath.exp(mpmath.mpf(float(x))) for x in v]
    want = np.array([float(2e3 * mpmath.mpf(0.3) * (s - s**-3)) for s in lam])
    assert np.max(np.abs(got / want - 1)) <= 4 * 2.2e-16
    current = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="current")
    assert np.array_equal(current._pressure_at_log_stretch(v[:50], np.expm1(v[:50]), 0.3),
                          current._pressure_at_strain(np.expm1(v[:50]), 0.3))
    far = np.array([1.0, 701.0])                         # past v = 700: the strain form
    assert np.array_equal(wall._pressure_at_log_stretch(far, np.expm1(far), 0.3),
                          wall._pressure_at_strain(np.expm1(far), 0.3))


def test_the_lean_curve_path_is_the_general_path_bit_for_bit():
    """A 1-D curve through a scene of scalars whose table is built takes the lean curve path of
    ``solve``; its answers are the general path's to the last bit (the general path forced by an
    option that changes nothing here, ``on_infeasible="nan"``), as are its validity warnings.
    It declines, and the general path answers, where the table does not serve every point (a
    zero flow rate), where the wall has an explicit inverse (thin, current thickness), and for
    arrays of more than one dimension."""
    solve_module = importlib.import_module("tubefsi.solve")
    wall = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="reference")
    q = np.geomspace(1e-12, 3e-8, 500)
    tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)                     # builds the table
    lean = solve_module._curve_flow(FLUID, wall, TUBE, q)
    assert lean is not None
    general = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q, on_infeasible="nan")
    for name in ("pressure_drop", "inlet_displacement", "flow_rate"):
        assert np.array_equal(getattr(lean, name), getattr(general, name))
    z = np.array([0.0, 0.4, 1.0])[:, None] * TUBE.length
    assert np.array_equal(lean.pressure(z), general.pressure(z))
    assert lean.coupler_name == general.coupler_name and lean.feasible is None and not lean.scalar
    assert lean.flow_rate is not q                                    # the solution keeps a copy
    with pytest.warns(tubefsi.ModelValidityWarning, match="not slender"):
        assert solve_module._curve_flow(FLUID, wall, TUBE, np.geomspace(1e-9, 1e-2, 100)) is not None
    assert solve_module._curve_flow(FLUID, wall, TUBE, np.r_[0.0, q]) is None
    current = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="current")
    assert solve_module._curve_flow(FLUID, current, TUBE, q[:10]) is None
    assert solve_module._curve_flow(FLUID, wall, TUBE, q.reshape(20, 25)) is None
    np.testing.assert_array_equal(tubefsi.solve(FLUID, wall, TUBE, flow_rate=q.reshape(20, 25)).pressure_drop,
                                  general.pressure_drop.reshape(20, 25))


def test_the_scalar_pair_is_each_interpolant_bit_for_bit():
    """One panel search and one generated rule give both values of a pair, each the bits of its
    own scalar rule; a pair of interpolants on different panels is refused."""
    from tubefsi.couplers._tables import ScalarPair, fit_on_breaks
    first, _ = fit_chebyshev(np.log1p, 0.0, 100.0)
    second, err = fit_on_breaks(lambda v: np.sqrt(1.0 + v), first.breaks)
    assert second is not None and err <= 5e-14
    pair = ScalarPair(first, second)
    x = np.concatenate([first.breaks, np.random.default_rng(3).uniform(0.0, 100.0, 300)])
    for _ in range(2):
        assert [pair(float(v)) for v in x] == [(first.scalar(float(v)), second.scalar(float(v))) for v in x]
    other, _ = fit_chebyshev(np.arctan, 0.0, 100.0)
    with pytest.raises(ValueError):
        ScalarPair(first, other)
    # a function that no degree-10 series resolves on these panels: refused, not fitted
    assert fit_on_breaks(lambda v: np.abs(v - 50.3), first.breaks) == (None, np.inf)


def test_a_scalar_path_solution_is_a_whole_solution():
    """The scalar path builds its scene on first use: the solution compares equal to the general
    path's, pickles, copies, and reports its scene, tube and profiles."""
    import copy
    import pickle
    solve_module = importlib.import_module("tubefsi.solve")
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    tubefsi.solve(FLUID, wall, TUBE, flow_rate=np.geomspace(1e-12, 1e-9, 100))     # builds the table
    fast = solve_module._scalar_flow(FLUID, wall, TUBE, 1e-9)
    assert fast is not None and "scene" not in vars(fast) and "state" not in vars(fast)
    drop, q = fast.pressure_drop, fast.flow_rate
    assert type(drop) is float and q == 1e-9 and "state" not in vars(fast)     # read without a State
    unbuilt = pickle.loads(pickle.dumps(fast))
    general = tubefsi.solve(FLUID, wall, TUBE, flow_rate=1e-9, on_infeasible="nan")
    assert type(fast.state) is type(general.state) and fast.state.pressure_drop == drop
    for name in ("flow_rate", "pressure_drop", "inlet_strain", "log_stretch"):
        assert getattr(fast.state, name) == pytest.approx(getattr(general.state, name), rel=1e-13)
    assert unbuilt.state == fast.state and unbuilt.pressure_drop == drop
    assert fast.scene == general.scene and fast.tube is TUBE and fast.wall is wall
    assert fast.pressure_drop == pytest.approx(general.pressure_drop, rel=1e-13)
    back = pickle.loads(pickle.dumps(fast))
    assert back.pressure_drop == fast.pressure_drop and back.scene == fast.scene
    assert copy.deepcopy(fast).inlet_displacement == fast.inlet_displacement
    assert fast.pressure(0.5 * TUBE.length) == pytest.approx(general.pressure(0.5 * TUBE.length), rel=1e-12)
    with pytest.raises(AttributeError, match="no attribute 'scenery'"):
        fast.scenery


def test_the_scalar_plan_gives_the_bits_of_a_fresh_one():
    """The scalar path keeps what it read off the last rheology and tube (solve._LAST_PLAN) and
    the last flow factor (solve._LAST_FLOW): a loop that changes the fluid, the tube, the wall
    and the flow rate in every pattern gets, call by call, the bits a fresh plan gives, and the
    general path's answer to 1e-13; two threads that share the plan get their own answers."""
    import threading
    solve_module = importlib.import_module("tubefsi.solve")
    fluids = [FLUID, rheologies["power-law"](consistency=0.02, index=0.9)]
    tubes = [TUBE, tubefsi.Tube(radius=1.2e-4, thickness=3e-5, length=1.5e-2)]
    for fluid in fluids:
        for tube in tubes:          # build every key's table
            tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=2e3), tube,
                          flow_rate=np.geomspace(1e-12, 1e-9, 100))
    rng = np.random.default_rng(7)
    calls = [(fluids[rng.integers(2)], tubes[rng.integers(2)], float(rng.uniform(1e3, 4e3)),
              float(rng.choice([1e-10, 5e-10, 1e-9]))) for _ in range(60)]

    def run(fresh):
        out = []
        for fluid, tube, mu, q in calls:
            if fresh:
                solve_module._LAST_PLAN[0], solve_module._LAST_FLOW[0] = (None, None), (None, None, None)
            sol = solve_module._scalar_flow(fluid, walls["thick-neo-hookean"](shear_modulus=mu), tube, q)
            out.append((sol.pressure_drop, sol.inlet_displacement))
        return out

    kept, fresh = run(False), run(True)
    assert kept == fresh
    for (fluid, tube, mu, q), (drop, _) in zip(calls[:8], kept):
        general = tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=mu), tube, flow_rate=q,
                                on_infeasible="nan")     # (an option the scalar path does not take)
        assert drop == pytest.approx(general.pressure_drop, rel=1e-13)
    answers = {}

    def worker(name, q):
        answers[name] = [solve_module._scalar_flow(FLUID, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, q)
                         .pressure_drop for _ in range(2000)]

    threads = [threading.Thread(target=worker, args=(q, q)) for q in (1e-10, 1e-9)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for q, got in answers.items():
        solve_module._LAST_PLAN[0], solve_module._LAST_FLOW[0] = (None, None), (None, None, None)
        alone = solve_module._scalar_flow(FLUID, walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, q).pressure_drop
        assert set(got) == {alone}


def test_the_scalar_plan_keeps_no_mutable_rheology():
    """A rheology that can change after it is made (a subclass with a plain __setattr__, or a
    frozen one holding a dict) is read afresh on every call: changing it changes the answer
    (the plan keeps only rheologies that cannot change, solve._unchanging, and Tubes)."""
    from tubefsi.rheology.power_law import PowerLaw

    class Mutable(PowerLaw):
        __setattr__ = object.__setattr__

    fluid = Mutable(consistency=0.01, index=0.8)
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    tubefsi.solve(fluid, wall, TUBE, flow_rate=np.geomspace(1e-12, 1e-9, 100))     # builds the table
    before = tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-9).pressure_drop
    fluid.consistency = 0.02
    after = tubefsi.solve(fluid, wall, TUBE, flow_rate=1e-9).pressure_drop
    fresh = tubefsi.solve(Mutable(consistency=0.02, index=0.8), wall, TUBE, flow_rate=1e-9).pressure_drop
    assert after == fresh and after > 1.2 * before

    @attrs.frozen(kw_only=True)
    class Scaled(PowerLaw):
        """Frozen, but holding a dict that scales its flow factor."""
        settings: dict = attrs.field(factory=lambda: {"factor": 1.0}, eq=False)

        def _flow_factor(self, flow_rate):
            return self.settings["factor"] * super()._flow_factor(flow_rate)

    scaled = Scaled(consistency=0.01, index=0.8)
    tubefsi.solve(scaled, wall, TUBE, flow_rate=np.geomspace(1e-12, 1e-9, 100))    # builds the table
    once = tubefsi.solve(scaled, wall, TUBE, flow_rate=1e-9).pressure_drop
    scaled.settings["factor"] = 2.0
    twice = tubefsi.solve(scaled, wall, TUBE, flow_rate=1e-9).pressure_drop
    assert once == pytest.approx(before, rel=1e-13) and twice > 1.2 * once


def test_the_lean_curve_path_keeps_only_frozen_models():
    """The lean curve path resolves the last (rheology, wall, tube) once (solve._LAST_CURVE):
    a second curve through the same objects gives the bits of a fresh resolution; a wall or
    rheology that can change after it is made (a plain __setattr__, or a frozen class with a
    dict field) is resolved afresh each call, so changing it changes the answer."""
    from tubefsi.walls.neo_hookean import ThinNeoHookean
    from tubefsi.rheology.power_law import PowerLaw
    solve_module = importlib.import_module("tubefsi.solve")
    q = np.geomspace(1e-12, 1e-9, 300)
    wall = walls["thin-neo-hookean"](shear_modulus=2e3, thickness_convention="reference")
    first = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)                    # builds the table
    kept = solve_module._curve_flow(FLUID, wall, TUBE, q)
    assert solve_module._LAST_CURVE[0][:3] == (FLUID, wall, TUBE)
    solve_module._LAST_CURVE[0] = (None,) * 7
    fresh = solve_module._curve_flow(FLUID, wall, TUBE, q)
    assert np.array_equal(kept.pressure_drop, fresh.pressure_drop)
    assert np.array_equal(kept.pressure_drop, first.pressure_drop)

    class MutableWall(ThinNeoHookean):
        __setattr__ = object.__setattr__

    class MutableFluid(PowerLaw):
        __setattr__ = object.__setattr__

    soft = MutableWall(shear_modulus=2e3, thickness_convention="reference")
    fluid = MutableFluid(consistency=0.01, index=0.8)
    tubefsi.solve(fluid, soft, TUBE, flow_rate=q)                          # builds its class's table
    before = solve_module._curve_flow(fluid, soft, TUBE, q)
    assert before is not None and solve_module._LAST_CURVE[0][1] is not soft
    soft.shear_modulus = 4e3
    fluid.consistency = 0.02
    after = solve_module._curve_flow(fluid, soft, TUBE, q)
    stiff = walls["thin-neo-hookean"](shear_modulus=4e3, thickness_convention="reference")
    want = tubefsi.solve(rheologies["power-law"](consistency=0.02, index=0.8), stiff, TUBE, flow_rate=q)
    assert np.array_equal(after.pressure_drop, want.pressure_drop)
    assert not np.allclose(after.pressure_drop, before.pressure_drop)

    @attrs.frozen(kw_only=True)
    class Clamped(ThinNeoHookean):
        """Frozen, but holding a dict that sets how long the tube is installed."""
        settings: dict = attrs.field(factory=lambda: {"stretch": 1.0}, eq=False)

        def _installed_tube(self, tube):
            f = self.settings["stretch"]
            return tube if f == 1.0 else tubefsi.Tube(radius=tube.radius, thickness=tube.thickness,
                                                      length=tube.length * f)

    clamped = Clamped(shear_modulus=2e3, thickness_convention="reference")
    tubefsi.solve(FLUID, clamped, TUBE, flow_rate=q)                      # builds its class's table
    short = solve_module._curve_flow(FLUID, clamped, TUBE, q)
    assert short is not None and solve_module._LAST_CURVE[0][1] is not clamped
    clamped.settings["stretch"] = 2.0
    long = solve_module._curve_flow(FLUID, clamped, TUBE, q)
    assert long.scene.tube.length == 2 * TUBE.length
    assert np.all(long.pressure_drop > short.pressure_drop)
