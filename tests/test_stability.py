r"""Stability: the default path at the edges of its range, and how the other methods fail.

Part 1 — the default ``solve`` stays within the accuracy contract where methods usually break:
at the removable singularities of the closed forms (``n = 2/3 ± 1e-9`` for thin
reference-thickness walls, ``n = 1 ± 1e-9`` for thin current-thickness walls, and the doubles
nearest 2/3 and 1), at inlet strain ``1e-8``, at ``t/a = 0.01`` and ``2``, at ``1 - 1e-6`` of the
limit pressure, and at 99 % of the maximum flow rate. Each case is checked flow-controlled
(``Δp(q)``, ``u(q)``) and, except near ``q_max``, pressure-controlled (``q(Δp)``, ``u(Δp)``)
against the independent mpmath reference of ``tubefsi.testing.reference`` (40 digits; tube laws and
hand-derived slopes from ``docs/theory.md``, section "Tube laws"). The bound is ``1e-12 * max(1, κ)`` with ``κ`` the
relative condition number of the output with respect to the load, evaluated on the reference
(the same convention as ``test_accuracy_contract.py``, with the same helpers,
``accuracy_helpers.py``; ``e = λ - 1``, ``k = 3n + 1``,
``Ĵ(λ) = ∫_1^λ P'(s) s^k ds``):

* ``u(Δp)``: ``κ = P / (e P')``        * ``q(Δp)``: ``κ = P λ^k / (n Ĵ)``
* ``Δp(q)``: ``κ = n Ĵ / (P λ^k)``      * ``u(q)``: ``κ = n Ĵ / (e P' λ^k)``

``κ`` is ~1 in the well-conditioned cases (singular n, small strain, thickness) and large only
near a limit (``u(Δp)`` ~ λ⁴/4 at 1 - 1e-6 of ``p_max``; ``u(q)`` ~ a few hundred at 99 % of
``q_max``). Loads are the doubles the library receives: the reference is moved to exactly those
doubles (one Newton step from the exact starting state; the shift is ~1e-16 relative).

Part 2 — every failure of a non-default method (``ODE`` with any integrator, ``odeint`` with
the chapter's defaults, low-order ``Quadrature``) is a typed ``tubefsi`` error
(``ConvergenceError``, ``NoSteadyStateError``) or comes with a warning; it never returns NaN/inf
and never a number more than ``FAR = 1e-3`` (relative) from the reference without a warning.
At and beyond the maximum flow rate / limit pressure every method raises.

No timing here: benchmarks live in ``examples/work_precision.py`` and ``benchmarks/``.
"""

from __future__ import annotations

import functools
import math
import warnings

import mpmath
import pytest
from mpmath import mp, mpf

import tubefsi
from tubefsi.couplers import ODE, Quadrature
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference.power_law import ref_J_inf, ref_phi, ref_phi_inverse
from tubefsi.testing.reference.tube_laws import WALLS, stretch_at_pressure

from accuracy_helpers import (  # the scene: A = 2**-13 m, L = 1e-2 m, M = 0.01 Pa s^n
    A,
    L,
    M,
    assert_contract,
    kappas,
    make_tube,
    make_wall,
    power_law,
    ref_wall,
    stretch_for_tail,
)

DPS = 40
pytestmark = pytest.mark.usefixtures("mp_precision")
FAR = 1e-3           # "far from the truth" for a non-default method


# ---------------------------------------------------------------------------- reference
def _J(wall, lam, k):
    """Ĵ(λ) = ∫_1^λ P'(s) s^k ds = ∫_0^ln λ P'(e^x) e^((k+1)x) dx: a positive integrand, no
    cancellation (unit sub-intervals in x)."""
    top = mpmath.log(lam)
    if top == 0:
        return mpf(0)
    pts = [mpf(0)] + [mpf(j) for j in range(1, int(top) + 1) if j < top] + [top]
    return mpmath.quad(lambda x: wall.dP(mpmath.exp(x)) * mpmath.exp((k + 1) * x), pts)


@functools.lru_cache(maxsize=None)
def reference(wall_name, tb, n, how, value):
    """Loads (doubles) and exact answers for one state.

    ``how``: "strain" (λ = 1 + value), "limit" (P(λ) = (1 - value) p_max) or "qmax"
    (q = value * q_max, flow-controlled only). Returns a dict with ``flow`` =
    (q_in, Δp_ref, u_ref, κ_Δp, κ_u) and, unless "qmax", ``pressure`` = (Δp_in, q_ref, u_ref, κ_q, κ_u).
    """
    with mp.workdps(DPS):
        wall = ref_wall(wall_name, tb)
        n_mp, a, length, m = mpf(n), mpf(A), mpf(L), mpf(M)
        k = 3 * n_mp + 1
        out = {}
        if how == "qmax":
            J_inf = ref_J_inf(wall, k)
            q_in = float(mpf(value) * ref_phi_inverse(J_inf * a**k / length, n_mp, m))
            target = length * ref_phi(mpf(q_in), n_mp, m) / a**k
            # λ with ∫_λ^∞ P' s^k ds = J_inf - target: one pass of at most 60 Newton steps
            lam = stretch_for_tail(wall, k, J_inf - target, steps=60, tol_digits=6)
            kq = kappas(wall, n_mp, k, lam, target)
            out["flow"] = (q_in, wall.P(lam), a * (lam - 1), kq["dp_of_q"], kq["u_of_q"])
            return out
        if how == "strain":
            lam0 = 1 + mpf(value)
        else:
            lam0 = stretch_at_pressure(wall, (1 - mpf(value)) * wall.limit_pressure())
        J0, slope = _J(wall, lam0, k), wall.dP(lam0) * lam0**k           # Ĵ and Ĵ' at λ0
        # flow-controlled at the double q_in: one Newton step in λ (second order ~1e-32)
        q_in = float(ref_phi_inverse(J0 * a**k / length, n_mp, m))
        target = length * ref_phi(mpf(q_in), n_mp, m) / a**k
        lam_q = lam0 + (target - J0) / slope
        kq = kappas(wall, n_mp, k, lam_q, target)
        out["flow"] = (q_in, wall.P(lam_q), a * (lam_q - 1), kq["dp_of_q"], kq["u_of_q"])
        # pressure-controlled at the double Δp_in: Newton on the closed-form tube law
        dp_in = float(wall.P(lam0))
        lam_p = lam0
        for _ in range(4):
            lam_p += (mpf(dp_in) - wall.P(lam_p)) / wall.dP(lam_p)
        J_p = J0 + slope * (lam_p - lam0)
        kp = kappas(wall, n_mp, k, lam_p, J_p)
        out["pressure"] = (dp_in, ref_phi_inverse(J_p * a**k / length, n_mp, m), a * (lam_p - 1),
                           kp["q_of_dp"], kp["u_of_dp"])
        return out


# ---------------------------------------------------------------------------- library side
def default_path_errors(wall_name, tb, n, how, value):
    """[(quantity, error, κ)] of the default solve, flow- and (if available) pressure-controlled."""
    ref = reference(wall_name, tb, n, how, value)
    fluid, wall, tube = power_law(n), make_wall(wall_name), make_tube(tb)
    q_in, dp_ref, u_ref, k_dp, k_u = ref["flow"]
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q_in)
    errors = [("dp(q)", rel_err(sol.pressure_drop, dp_ref), float(k_dp)),
              ("u(q)", rel_err(sol.inlet_displacement, u_ref), float(k_u))]
    if "pressure" in ref:
        dp_in, q_ref, u_ref, k_q, k_u = ref["pressure"]
        sol = tubefsi.solve(fluid, wall, tube, pressure_drop=dp_in)
        errors += [("q(dp)", rel_err(sol.flow_rate, q_ref), float(k_q)),
                   ("u(dp)", rel_err(sol.inlet_displacement, u_ref), float(k_u))]
    return errors


# ============================================================================ part 1: default path
SINGULAR = [
    # thin reference thickness: (λ^(3n-2) - 1)/(3n-2) at n = 2/3; the thick wall (quadrature) alongside
    *[("thin-neo-hookean-reference", n) for n in (2 / 3 - 1e-9, 2 / 3, 2 / 3 + 1e-9)],
    *[("thick-mooney-rivlin", n) for n in (2 / 3 - 1e-9, 2 / 3, 2 / 3 + 1e-9)],
    # thin current thickness: (λ^(3n-3) - 1)/(3n-3) at n = 1 (Newtonian); linear walls alongside
    *[(w, n) for w in ("thin-neo-hookean-current", "thin-mooney-rivlin-current", "thin-linear")
      for n in (1 - 1e-9, 1.0, 1 + 1e-9)],
]


@pytest.mark.parametrize(("wall_name", "n"), SINGULAR, ids=[f"{w}-n{n!r}" for w, n in SINGULAR])
def test_default_at_removable_singularities(wall_name, n):
    assert_contract(default_path_errors(wall_name, 0.3, n, "strain", "0.5"), f"{wall_name}, n={n!r}")


@pytest.mark.parametrize("wall_name", tuple(WALLS))
def test_default_at_strain_1e_8(wall_name):
    """Small displacements are carried as strains: no ``λ - 1`` cancellation."""
    assert_contract(default_path_errors(wall_name, 0.3, 0.7, "strain", "1e-8"), f"{wall_name}, strain 1e-8")


@pytest.mark.parametrize("tb", (0.01, 2.0))
@pytest.mark.parametrize("wall_name", ("thick-mooney-rivlin", "thin-mooney-rivlin-current",
                                       "thin-neo-hookean-reference", "thick-linear"))
def test_default_at_extreme_thickness(wall_name, tb):
    assert_contract(default_path_errors(wall_name, tb, 0.7, "strain", "1"), f"{wall_name}, t/a={tb}")


LIMIT_WALLS = ("thick-neo-hookean", "thick-mooney-rivlin", "thin-neo-hookean-current", "thin-mooney-rivlin-current")


@pytest.mark.parametrize("n", (0.7, 1.5))
@pytest.mark.parametrize("wall_name", LIMIT_WALLS)
def test_default_near_limit_pressure(wall_name, n):
    """P(λ_in) = (1 - 1e-6) p_max: κ_u(Δp) ~ λ⁴/4 ~ 1e5 there, every other κ is modest."""
    assert_contract(default_path_errors(wall_name, 0.3, n, "limit", "1e-6"), f"{wall_name}, n={n}, 1-1e-6 p_max")


@pytest.mark.parametrize("n", (0.5, 0.7))
@pytest.mark.parametrize("wall_name", LIMIT_WALLS)
def test_default_near_max_flow_rate(wall_name, n):
    assert_contract(default_path_errors(wall_name, 0.3, n, "qmax", "0.99"), f"{wall_name}, n={n}, 0.99 q_max")


# ============================================================================ part 2: other methods
def outcome(run):
    """Run a solve; return ("raised", error) for a typed error, else (solution, warning categories).

    Anything else (an untyped exception) propagates and fails the test; NaN/inf fails here.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            sol = run()
        except tubefsi.TubefsiError as exc:
            return "raised", exc
    for value in (sol.flow_rate, sol.pressure_drop, sol.inlet_displacement):
        assert math.isfinite(float(value)), f"a non-finite result without an error: {value!r}"
    return sol, sorted({w.category.__name__ for w in caught if not issubclass(w.category, DeprecationWarning)})


def assert_never_silently_wrong(run, expected, label):
    """``expected``: [(attribute, exact value)]. Typed error, a warning, or within FAR."""
    sol, info = outcome(run)
    if sol == "raised" or info:
        return
    errors = {name: rel_err(getattr(sol, name), exact) for name, exact in expected}
    far = {name: f"{err:.2g}" for name, err in errors.items() if err > FAR}
    assert not far, f"{label}: silent wrong number (relative error > {FAR:g}, no warning, no error): {far}"


def _odes():
    return {
        "odeint": ODE(method="odeint"),
        "LSODA-default": ODE(),
        "LSODA-1e-8": ODE(method="LSODA", rtol=1e-8, atol=1e-11),
        "RK45-default": ODE(method="RK45"),
        "DOP853-1e-10": ODE(method="DOP853", rtol=1e-10, atol=1e-13),
    }


NON_DEFAULT = {**_odes(), "quadrature-4": Quadrature(order=4), "quadrature-8": Quadrature(order=8)}

#: flow-controlled stress cases in the thick neo-Hookean wall (t/a = 0.3, n = 0.7): near q_max,
#: tiny and moderate strain
FLOW_CASES = [("qmax", "0.5"), ("qmax", "0.8"), ("qmax", "0.9"), ("qmax", "0.99"), ("qmax", "0.999"),
              ("strain", "1e-15"), ("strain", "1e-12"), ("strain", "1e-8"), ("strain", "1")]


@pytest.mark.parametrize(("how", "value"), FLOW_CASES, ids=[f"{h}{v}" for h, v in FLOW_CASES])
@pytest.mark.parametrize("method", tuple(NON_DEFAULT))
def test_non_default_flow_controlled_never_silently_wrong(method, how, value):
    ref = reference("thick-neo-hookean", 0.3, 0.7, how, value)
    q_in, dp_ref, u_ref, *_ = ref["flow"]
    fluid, wall, tube = power_law(0.7), make_wall("thick-neo-hookean"), make_tube(0.3)
    assert_never_silently_wrong(
        lambda: tubefsi.solve(fluid, wall, tube, flow_rate=q_in, coupler=NON_DEFAULT[method]),
        [("pressure_drop", dp_ref), ("inlet_displacement", u_ref)], f"{method} at {how} {value}")


PRESSURE_CASES = [("strain", "1e-12"), ("strain", "1e-8"), ("strain", "1"), ("limit", "0.03")]


@pytest.mark.parametrize(("how", "value"), PRESSURE_CASES, ids=[f"{h}{v}" for h, v in PRESSURE_CASES])
@pytest.mark.parametrize("method", ("odeint", "LSODA-default", "quadrature-4"))
def test_non_default_pressure_controlled_never_silently_wrong(method, how, value):
    """Shooting on q (ODE) must not leak SciPy's bracketing ValueError, nor a wrong q."""
    ref = reference("thick-neo-hookean", 0.3, 0.7, how, value)
    dp_in, q_ref, *_ = ref["pressure"]
    fluid, wall, tube = power_law(0.7), make_wall("thick-neo-hookean"), make_tube(0.3)
    assert_never_silently_wrong(
        lambda: tubefsi.solve(fluid, wall, tube, pressure_drop=dp_in, coupler=NON_DEFAULT[method]),
        [("flow_rate", q_ref)], f"{method}, pressure-controlled at {how} {value}")


@pytest.mark.parametrize("method", tuple(NON_DEFAULT) + ("auto",))
@pytest.mark.parametrize("factor", (1.0 + 1e-6, 1.5))
def test_beyond_max_flow_rate_raises(method, factor):
    fluid, wall, tube = power_law(0.7), make_wall("thick-neo-hookean"), make_tube(0.3)
    coupler = "auto" if method == "auto" else NON_DEFAULT[method]
    q_max = tubefsi.max_flow_rate(fluid, wall, tube)
    with pytest.raises(tubefsi.NoSteadyStateError) as info:
        tubefsi.solve(fluid, wall, tube, flow_rate=q_max * factor, coupler=coupler)
    # the limit the error reports: the default's to the contract, any other method's not far off
    assert info.value.limit == pytest.approx(q_max, rel=1e-12 if method == "auto" else FAR)


@pytest.mark.parametrize("method", tuple(NON_DEFAULT) + ("auto",))
def test_at_max_flow_rate_raises(method):
    """At the double q_max of the default path (a few ulps above the exact q_max, so no steady
    state exists): a typed error, whichever method."""
    fluid, wall, tube = power_law(0.7), make_wall("thick-neo-hookean"), make_tube(0.3)
    coupler = "auto" if method == "auto" else NON_DEFAULT[method]
    q_max = tubefsi.max_flow_rate(fluid, wall, tube)
    with pytest.raises(tubefsi.TubefsiError):
        tubefsi.solve(fluid, wall, tube, flow_rate=q_max, coupler=coupler)


@pytest.mark.parametrize("method", tuple(NON_DEFAULT) + ("auto",))
@pytest.mark.parametrize("factor", (1.0, 1.01))
def test_at_and_beyond_limit_pressure_raises(method, factor):
    fluid, wall, tube = power_law(0.7), make_wall("thick-neo-hookean"), make_tube(0.3)
    coupler = "auto" if method == "auto" else NON_DEFAULT[method]
    p_max = wall.limit_pressure(tube.reduced_thickness)
    with pytest.raises(tubefsi.NoSteadyStateError) as info:
        tubefsi.solve(fluid, wall, tube, pressure_drop=p_max * factor, coupler=coupler)
    assert info.value.limit == pytest.approx(p_max, rel=1e-12)


@pytest.mark.parametrize("strain", ("1e3", "1e6"))
def test_odeint_excess_work_is_a_convergence_error(strain):
    """Huge inlet stretch with n >= 1 (no q_max, no limit): odeint's default mxstep runs out
    ("excess work done") — a ConvergenceError, not a number. The default path is exact there."""
    ref = reference("thin-neo-hookean-reference", 0.3, 1.5, "strain", strain)
    q_in, dp_ref, u_ref, k_dp, k_u = ref["flow"]
    fluid, wall, tube = power_law(1.5), make_wall("thin-neo-hookean-reference"), make_tube(0.3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")            # SciPy's ODEintWarning accompanies the failure
        with pytest.raises(tubefsi.ConvergenceError):
            tubefsi.solve(fluid, wall, tube, flow_rate=q_in, coupler=ODE(method="odeint"))
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q_in)
    assert_contract([("dp(q)", rel_err(sol.pressure_drop, dp_ref), float(k_dp)),
                     ("u(q)", rel_err(sol.inlet_displacement, u_ref), float(k_u))], f"default at strain {strain}")


@pytest.mark.parametrize("method", ("odeint", "LSODA-default", "RK45-default", "DOP853-1e-10"))
@pytest.mark.parametrize("strain", ("1e3", "1e6"))
def test_ode_at_huge_stretch_never_silently_wrong(method, strain):
    ref = reference("thin-neo-hookean-reference", 0.3, 1.5, "strain", strain)
    q_in, dp_ref, u_ref, *_ = ref["flow"]
    fluid, wall, tube = power_law(1.5), make_wall("thin-neo-hookean-reference"), make_tube(0.3)
    assert_never_silently_wrong(
        lambda: tubefsi.solve(fluid, wall, tube, flow_rate=q_in, coupler=NON_DEFAULT[method]),
        [("pressure_drop", dp_ref), ("inlet_displacement", u_ref)], f"{method} at strain {strain}")
