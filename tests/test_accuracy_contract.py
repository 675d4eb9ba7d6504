r"""The accuracy contract of issue 3, checked against the 40-digit reference of ``tubefsi.testing.reference``.

    "Default solve is accurate to 1e-12 relative (up to what the problem's condition number
    allows in double precision) in pressure drop, flow rate and inlet displacement, for every
    built-in pair, over: power-law index 0.2 to 2 (including 2/3 and 1), thickness ratio 0.01
    to 2, strain from 1e-6 up to 200 (linear and reference-thickness walls) or to 1 - 1e-6 of a
    limit pressure (thick Mooney–Rivlin/neo-Hookean: p_max = mu ln(1+tb); thin current-thickness:
    p_max = mu tb), and flow rates up to 99 % of a maximum flow rate (tubefsi.max_flow_rate;
    finite only for limit walls with n < 1). Small displacements are computed without
    cancellation."

Every check asserts ``rel_err <= RTOL * max(1, kappa)`` with ``RTOL = 1e-12`` and ``kappa`` the
**relative condition number of the computed quantity with respect to the load** (the one input
that is not a model constant), evaluated on the mpmath reference. Double precision cannot do
better than ``eps * kappa``: the library rounds the load (and the tube law's constants) once,
and that relative perturbation of ``~1e-16`` is amplified ``kappa`` times.

Notation (outlet at zero pressure, ``lam`` = inlet stretch, ``e = lam - 1`` the inlet strain,
``P`` the tube law, ``k = 3n + 1``, ``Jhat(lam) = int_1^lam P'(s) s^k ds``). The separated
identity ``L phi(q) = a^k Jhat(lam)`` with ``phi ~ q^n`` gives
``n d ln q = (P'(lam) lam^k / Jhat) d lam`` and ``dp = P(lam)``, hence the kappas:

* pressure-controlled inlet displacement ``u = a e(dp)``:
  ``kappa = d ln e / d ln dp = P / (e P'(lam))``
  (1 at small strain; ``~ lam^4 / 4`` near a limit pressure, where ``P'`` vanishes);
* pressure-controlled flow rate ``q(dp)``:
  ``kappa = d ln q / d ln dp = P lam^k / (n Jhat)`` (the inverse of the next one);
* flow-controlled pressure drop ``dp(q)``:
  ``kappa = d ln dp / d ln q = n Jhat / (P lam^k)``;
* flow-controlled inlet displacement ``u(q)``:
  ``kappa = d ln e / d ln q = n Jhat / (e P'(lam) lam^k)``. Near the maximum flow rate this is
  large (``~ n / ((4 - k) * tail fraction)``, a few hundred at 99 % of q_max with n = 0.9): the
  inlet stretch runs away as ``q -> q_max``. It is computed here with mpmath from the same formula.

Rigid wall (Hagen–Poiseuille, ``dp = L phi(q) a^-k``): ``kappa = n`` for ``dp(q)``, ``1/n`` for
``q(dp)``.

Inputs are floats, and the reference is computed from *those* floats: the wall constants, the
index ``n`` (so ``2/3`` is the double nearest 2/3 on both sides), the thickness ratio (the tube
radius is ``2**-13`` m, so ``thickness = tb * a`` and ``thickness / a`` are exact), and the load.
A case starts from a "nice" state (``lam = 1 + strain`` exactly, or ``P(lam)`` = a float fraction
of the limit pressure); its loads are the floats ``dp_in = float(P(lam))`` and
``q_in = float(q(lam))``, and the reference is then moved to exactly those loads: Newton on the
closed-form tube law for ``dp_in``, and a third-order Taylor expansion of ``Jhat`` around the
quadrature point for ``q_in`` (the shift is ~1e-16 relative, so the neglected fourth-order term is
far below 40 digits). So each case costs one ``mpmath.quad``.

Near the maximum flow rate, ``lam`` reaches ~1e7 and integration by parts would cancel
``k log10(lam)`` digits, so ``Jhat = J_inf - tail(lam)`` is used (tail in closed form for thin
current walls, a singularity-free quadrature for thick ones; see
``tubefsi.testing.reference.power_law``), and the
inlet stretch is found by Newton on ``ln tail`` in ``ln lam``.

Beyond the documented inlet-stretch cap (1e15), e.g. 99 % of q_max at n = 0.99 (which needs
``lam ~ 1e66``), the library raises ``NoSteadyStateError`` by design; that is tested too.
"""

from __future__ import annotations

import functools
import math

import mpmath
import pytest
from mpmath import mp, mpf

import tubefsi
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference.power_law import (
    ref_J,
    ref_J_inf,
    ref_J_log,
    ref_J_tail,
    ref_phi,
    ref_phi_inverse,
)
from tubefsi.testing.reference.tube_laws import LIMIT_KINDS, WALLS, RefWall, stretch_at_pressure

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
from accuracy_helpers import CONTRACT_RTOL as RTOL  # 1e-12, the contract

DPS = 40          # reference precision
pytestmark = pytest.mark.usefixtures("mp_precision")
MAX_STRETCH = 1e15   # the library's documented cap on the inlet stretch

N_VALUES = (0.2, 0.5, 2 / 3, 1.0, 1.5, 2.0)
TB_VALUES = (0.01, 0.3, 2.0)
STRAINS = ("1e-6", "1e-2", "1")
TOP_NO_LIMIT = ("200",)                      # linear and reference-thickness walls: strain 200
TOP_LIMIT = ("lim-1e-3", "lim-1e-6")         # limit walls: P = (1 - 1e-3) p_max, (1 - 1e-6) p_max
QMAX_N_VALUES = (0.2, 0.5, 2 / 3, 0.9)
QMAX_FRACTIONS = ("0.9", "0.99")

DEFORMABLE = tuple(WALLS)
LIMIT_WALLS = tuple(w for w in DEFORMABLE if WALLS[w][2] in LIMIT_KINDS)


def levels(wall_name):
    return STRAINS + (TOP_LIMIT if wall_name in LIMIT_WALLS else TOP_NO_LIMIT)


def regime(level):
    """The regime a grid level belongs to (for the report)."""
    if level in ("1e-6", "1e-2"):
        return "small strain"
    if level.startswith("lim"):
        return "near limit"
    return "large strain"


# ---------------------------------------------------------------------------- reference
def _dJ(wall, k, lam, order):
    """d^order/dlam^order of Jhat at lam (order >= 1): derivatives of P'(s) s^k."""
    f = lambda s: wall.dP(s) * s**k                                   # noqa: E731
    return f(lam) if order == 1 else mpmath.diff(f, lam, order - 1)


def _taylor(wall, k, lam0, J0):
    """Coefficients of Jhat(lam0 + d) = sum c_j d^j, j = 0..3."""
    return [J0] + [_dJ(wall, k, lam0, j) / math.factorial(j) for j in (1, 2, 3)]


def _poly(c, d):
    return c[0] + d * (c[1] + d * (c[2] + d * c[3]))


def _dpoly(c, d):
    return c[1] + d * (2 * c[2] + d * 3 * c[3])


def _kappas(wall, n, k, e, J):
    """The contract's kappas at the inlet strain ``e`` (exact), ``lam = 1 + e``."""
    return kappas(wall, n, k, 1 + e, J, e=e)


def reference(wall_name, tb_float, n_float, level):
    """Reference for one grid case (consistency M): a dict with the float loads, mpf answers, kappas.

    ``pressure``: (dp_in, q_ref, u_ref, kappa_q, kappa_u);
    ``flow``: (q_in, dp_ref, u_ref, kappa_dp, kappa_u).
    """
    return reference_set(wall_name, tb_float, level)[n_float]


@functools.lru_cache(maxsize=None)
def reference_set(wall_name, tb_float, level):
    """``reference`` for every n in N_VALUES at once (they share the quadrature nodes)."""
    with mp.workdps(DPS):
        return compute_reference(wall_name, tb_float, level, N_VALUES)


def compute_reference(wall_name, tb_float, level, n_values):
    """``reference_set`` at the caller's precision (``mp.dps``), uncached."""
    wall = ref_wall(wall_name, tb_float)
    # The grid's inlet state below does not depend on n, so neither do the quadrature nodes of
    # Jhat(lam0) = P lam0^k - k int_0^ln(lam0) P(e^x) e^(kx) dx: remember P at the nodes.
    wall.P = functools.lru_cache(maxsize=None)(wall.P)
    a, length, m = mpf(A), mpf(L), mpf(M)

    # ---- pressure-controlled: the float load dp_in, and the inlet strain e_p exactly at it
    if level.startswith("lim"):
        frac = 1 - mpf(level[len("lim-"):])
        dp_in = float(frac * wall.limit_pressure())
        lam0 = stretch_at_pressure(wall, mpf(dp_in))           # findroot + Newton polish
        e_p = lam0 - 1
    else:
        lam0 = 1 + mpf(level)
        dp_in = float(wall.P(lam0))
        e_p = lam0 - 1
        for _ in range(6):                                     # Newton on the closed-form law
            e_p += (mpf(dp_in) - wall.P(1 + e_p)) / wall.dP(1 + e_p)
    assert abs(wall.P(1 + e_p) / mpf(dp_in) - 1) < mpf(10) ** (10 - mp.dps)

    out = {}
    for n_float in n_values:
        n = mpf(n_float)
        k = 3 * n + 1
        c = _taylor(wall, k, lam0, ref_J_log(wall, lam0, k))   # the one quadrature per n
        J_p = _poly(c, (1 + e_p) - lam0)
        q_p = ref_phi_inverse(J_p * a**k / length, n, m)
        kp = _kappas(wall, n, k, e_p, J_p)

        # ---- flow-controlled: the float load q_in, and the state exactly at it
        q_in = float(q_p)
        target = length * ref_phi(mpf(q_in), n, m) / a**k
        d = (1 + e_p) - lam0
        for _ in range(8):                                      # Newton on the Taylor cubic
            d -= (_poly(c, d) - target) / _dpoly(c, d)
        assert abs(_poly(c, d) / target - 1) < mpf(10) ** (8 - mp.dps)
        assert abs(d) < abs(lam0 - 1) * mpf(10) ** -6         # a tiny shift, so the cubic is exact
        e_q = (lam0 - 1) + d
        kq = _kappas(wall, n, k, e_q, target)
        out[n_float] = dict(
            pressure=(dp_in, q_p, a * e_p, kp["q_of_dp"], kp["u_of_dp"]),
            flow=(q_in, wall.P(1 + e_q), a * e_q, kq["dp_of_q"], kq["u_of_q"]),
        )
    return out


def _stretch_for_tail(wall, k, tail_target):
    """lam with tail(lam) = tail_target: Newton on ln tail in x = ln lam (tail ~ C lam^-(4-k)),
    converged cheaply at 20 digits (at most 40 steps), then polished at ``mp.dps`` (at most 40),
    and checked: ``|tail(lam) / tail_target - 1| < 10^(8 - mp.dps)``."""
    return stretch_for_tail(wall, k, tail_target, steps=40, tol_digits=5, coarse_dps=20, check_digits=8)


@functools.lru_cache(maxsize=None)
@mp.workdps(DPS)
def reference_near_qmax(wall_name, tb_float, n_float, m_float, fraction):
    """Flow-controlled at q_in = float(fraction * q_max): (q_in, dp, u, kappa_dp, kappa_u, lam)."""
    wall = ref_wall(wall_name, tb_float)
    n, m = mpf(n_float), mpf(m_float)
    k = 3 * n + 1
    a, length = mpf(A), mpf(L)
    J_inf = ref_J_inf(wall, k)
    q_max = ref_phi_inverse(J_inf * a**k / length, n, m)
    q_in = float(mpf(fraction) * q_max)
    target = length * ref_phi(mpf(q_in), n, m) / a**k              # = Jhat(lam_in)
    lam = _stretch_for_tail(wall, k, J_inf - target)
    e = lam - 1
    kq = _kappas(wall, n, k, e, target)
    return q_in, wall.P(lam), a * e, kq["dp_of_q"], kq["u_of_q"], lam


# ---------------------------------------------------------------------------- library side
def make_fluid(n, newtonian=False):
    if newtonian:
        return tubefsi.registry.rheologies["newtonian"](viscosity=M)
    return power_law(n)


def grid_errors(wall_name, n, tb, level, mode, newtonian=False):
    """[(quantity, rel_err, kappa)] for one grid case, in one control mode."""
    ref = reference(wall_name, tb, n, level)
    fluid, wall, tube = make_fluid(n, newtonian), make_wall(wall_name), make_tube(tb)
    if mode == "pressure":
        dp_in, q_ref, u_ref, k_q, k_u = ref["pressure"]
        sol = tubefsi.solve(fluid, wall, tube, pressure_drop=dp_in)
        return [("q(dp)", rel_err(sol.flow_rate, q_ref), float(k_q)),
                ("u(dp)", rel_err(sol.inlet_displacement, u_ref), float(k_u))]
    q_in, dp_ref, u_ref, k_dp, k_u = ref["flow"]
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q_in)
    return [("dp(q)", rel_err(sol.pressure_drop, dp_ref), float(k_dp)),
            ("u(q)", rel_err(sol.inlet_displacement, u_ref), float(k_u))]


def near_qmax_errors(wall_name, n, tb, fraction):
    q_in, dp_ref, u_ref, k_dp, k_u, _ = reference_near_qmax(wall_name, tb, n, M, fraction)
    sol = tubefsi.solve(make_fluid(n), make_wall(wall_name), make_tube(tb), flow_rate=q_in)
    return [("dp(q)", rel_err(sol.pressure_drop, dp_ref), float(k_dp)),
            ("u(q)", rel_err(sol.inlet_displacement, u_ref), float(k_u))]


# ---------------------------------------------------------------------------- the grid
GRID = [
    pytest.param(wall_name, n, tb, level, id=f"{wall_name}-n{n:.4g}-tb{tb:g}-{level}")
    for wall_name in DEFORMABLE
    for n in N_VALUES
    for tb in TB_VALUES
    for level in levels(wall_name)
]
NEWTONIAN_GRID = [
    pytest.param(wall_name, tb, level, id=f"{wall_name}-tb{tb:g}-{level}")
    for wall_name in DEFORMABLE
    for tb in TB_VALUES
    for level in levels(wall_name)
]
QMAX_GRID = [
    pytest.param(wall_name, n, tb, fraction, id=f"{wall_name}-n{n:.4g}-tb{tb:g}-q{fraction}")
    for wall_name in LIMIT_WALLS
    for n in QMAX_N_VALUES
    for tb in TB_VALUES
    for fraction in QMAX_FRACTIONS
]


@pytest.mark.parametrize(("wall_name", "n", "tb", "level"), GRID)
def test_pressure_controlled(wall_name, n, tb, level):
    """q(dp) and u(dp): kappa_q = P lam^k / (n Jhat), kappa_u = P / (e P')."""
    assert_contract(grid_errors(wall_name, n, tb, level, "pressure"),
                    f"power law n={n!r}, {wall_name}, tb={tb}, {level}, pressure-controlled")


@pytest.mark.parametrize(("wall_name", "n", "tb", "level"), GRID)
def test_flow_controlled(wall_name, n, tb, level):
    """dp(q) and u(q): kappa_dp = n Jhat / (P lam^k), kappa_u = n Jhat / (e P' lam^k)."""
    assert_contract(grid_errors(wall_name, n, tb, level, "flow"),
                    f"power law n={n!r}, {wall_name}, tb={tb}, {level}, flow-controlled")


@pytest.mark.parametrize("mode", ("pressure", "flow"))
@pytest.mark.parametrize(("wall_name", "tb", "level"), NEWTONIAN_GRID)
def test_newtonian(wall_name, tb, level, mode):
    """The Newtonian rheology (viscosity = M) against the n = 1 reference; same kappas."""
    assert_contract(grid_errors(wall_name, 1.0, tb, level, mode, newtonian=True),
                    f"newtonian, {wall_name}, tb={tb}, {level}, {mode}-controlled")


@pytest.mark.parametrize(("wall_name", "n", "tb", "fraction"), QMAX_GRID)
def test_near_max_flow_rate(wall_name, n, tb, fraction):
    """Flow-controlled at 90 % / 99 % of q_max. kappa_u = d ln e / d ln q = n Jhat / (e P' lam^k)
    is large here (computed with mpmath); kappa_dp = n Jhat / (P lam^k) is small."""
    assert_contract(near_qmax_errors(wall_name, n, tb, fraction),
                    f"power law n={n!r}, {wall_name}, tb={tb}, {fraction} q_max, flow-controlled")


@pytest.mark.parametrize(("n", "newtonian"), [pytest.param(n, False, id=f"n{n:.4g}") for n in N_VALUES]
                         + [pytest.param(1.0, True, id="newtonian")])
@pytest.mark.parametrize("q", (1e-13, 1e-9))
def test_rigid(n, q, newtonian):
    """Hagen–Poiseuille: kappa = n for dp(q), 1/n for q(dp)."""
    with mp.workdps(DPS):
        nn, k = mpf(n), 3 * mpf(n) + 1
        dp_ref = mpf(L) * ref_phi(mpf(q), nn, mpf(M)) * mpf(A) ** -k
        dp_in = float(dp_ref)
        q_ref = ref_phi_inverse(mpf(dp_in) * mpf(A) ** k / mpf(L), nn, mpf(M))
    fluid, wall, tube = make_fluid(n, newtonian), tubefsi.registry.walls["rigid"](), make_tube(0.3)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    sol2 = tubefsi.solve(fluid, wall, tube, pressure_drop=dp_in)
    assert_contract([("dp(q)", rel_err(sol.pressure_drop, dp_ref), n),
                     ("q(dp)", rel_err(sol2.flow_rate, q_ref), 1 / n)], f"rigid, n={n!r}, q={q}")
    assert sol.inlet_displacement == 0.0 and sol2.inlet_displacement == 0.0


# ---------------------------------------------------------------------------- beyond the stretch cap
@pytest.mark.parametrize("wall_name", LIMIT_WALLS)
@pytest.mark.parametrize("tb", TB_VALUES)
def test_beyond_stretch_cap_raises(wall_name, tb):
    """n = 0.99 at 99 % of q_max needs an inlet stretch ~1e66 > 1e15: a steady state exists, beyond
    the solver's range: StretchRangeError (an InvalidParameterError, not NoSteadyStateError), by design.

    The error's ``limit`` is the flow rate that reaches the cap (stretch 1e15): below the load and
    below q_max; it is compared with the reference q(lam = 1e15) to 1e-12 * max(1, 1/n).
    """
    n = 0.99
    with mp.workdps(DPS):
        wall_ref = ref_wall(wall_name, tb)
        nn = mpf(n)
        k = 3 * nn + 1
        J_inf = ref_J_inf(wall_ref, k)
        q_max = ref_phi_inverse(J_inf * mpf(A) ** k / mpf(L), nn, mpf(M))
        q_in = float(mpf("0.99") * q_max)
        target = mpf(L) * ref_phi(mpf(q_in), nn, mpf(M)) / mpf(A) ** k
        lam_needed = _stretch_for_tail(wall_ref, k, J_inf - target)
        assert lam_needed > 1e15                      # the premise: beyond the cap
        J_cap = J_inf - ref_J_tail(wall_ref, mpf(MAX_STRETCH), k)
        q_cap = ref_phi_inverse(J_cap * mpf(A) ** k / mpf(L), nn, mpf(M))
    with pytest.raises(tubefsi.StretchRangeError) as info:
        tubefsi.solve(make_fluid(n), make_wall(wall_name), make_tube(tb), flow_rate=q_in)
    exc = info.value
    assert exc.quantity == "flow_rate" and "below max_flow_rate" in str(exc)
    assert isinstance(exc.limit, float) and math.isfinite(exc.limit)
    assert 0 < exc.limit < q_in
    assert rel_err(exc.limit, q_cap) <= RTOL * max(1.0, 1 / n), (exc.limit, float(q_cap))


# ---------------------------------------------------------------------------- the reference itself
@pytest.mark.parametrize("wall_name", DEFORMABLE)
def test_reference_derivative_is_the_tube_law_slope(wall_name):
    """The hand-derived P' (used for kappas, Taylor shifts, tails) is d/dlam of the tube law."""
    with mp.workdps(DPS):
        for tb in TB_VALUES:
            wall = ref_wall(wall_name, tb)
            for lam in (mpf(1) + mpf("1e-6"), mpf("1.5"), mpf(31), mpf(201)):
                numeric = mpmath.diff(wall.P, lam)
                assert abs(numeric / wall.dP(lam) - 1) < mpf(10) ** (12 - DPS)


@pytest.mark.parametrize("wall_name", [w for w in DEFORMABLE if WALLS[w][2] not in ("thin-linear", "thick-linear")])
def test_reference_closed_forms_match_the_strain_energy(wall_name):
    """The closed forms used here equal the same wall derived from its strain energy (the route
    of the plugins' materials: Lamé quadrature, Leibniz's rule, mpmath.diff), and the
    hand-written plane-strain dW is the derivative of W(1/s, s, 1)."""
    with mp.workdps(DPS):
        for tb in TB_VALUES:
            wall = ref_wall(wall_name, tb)
            generic = RefWall(wall.kind, wall.material, wall.tb, closed_form=False)
            assert wall.mu is not None and generic.mu is None
            for lam in (mpf(1) + mpf("1e-6"), mpf("1.5"), mpf(31), mpf(201)):
                assert abs(generic.P(lam) / wall.P(lam) - 1) < mpf(10) ** (12 - DPS)
                assert abs(generic.dP(lam) / wall.dP(lam) - 1) < mpf(10) ** (12 - DPS)
                numeric = mpmath.diff(wall.material.W_hat, lam)
                assert abs(numeric / wall.material.dW(lam) - 1) < mpf(10) ** (12 - DPS)


@pytest.mark.parametrize("wall_name", DEFORMABLE)
def test_reference_integrators_agree(wall_name):
    """Jhat by parts integrated in ln s on one interval (used here) equals the geometric-split
    integration in s (used by test_reference_accuracy.py)."""
    with mp.workdps(DPS):
        wall = ref_wall(wall_name, 0.3)
        k = 3 * mpf(2 / 3) + 1
        for lam in (mpf(1) + mpf("1e-6"), mpf(40)):
            assert abs(ref_J_log(wall, lam, k) / ref_J(wall, lam, k) - 1) < mpf(10) ** (12 - DPS)


@pytest.mark.parametrize("wall_name", LIMIT_WALLS)
def test_reference_tail_matches_integration_by_parts(wall_name):
    """J_inf - tail(lam) (used near q_max) equals Jhat(lam) by parts (used elsewhere)."""
    with mp.workdps(DPS):
        for tb in TB_VALUES:
            wall = ref_wall(wall_name, tb)
            wall.P = functools.lru_cache(maxsize=None)(wall.P)
            for n in QMAX_N_VALUES:
                k = 3 * mpf(n) + 1
                for lam in (mpf("1.5"), mpf(40)):
                    by_parts = ref_J_log(wall, lam, k)
                    via_tail = ref_J_inf(wall, k) - ref_J_tail(wall, lam, k)
                    assert abs(via_tail / by_parts - 1) < mpf(10) ** (12 - DPS)


@pytest.mark.parametrize(("wall_name", "n", "tb", "level"), [
    ("thick-neo-hookean", 2.0, 2.0, "lim-1e-6"),
    ("thick-mooney-rivlin", 0.2, 0.01, "1e-6"),
    ("thin-neo-hookean-reference", 2.0, 0.01, "200"),
])
def test_reference_is_converged_in_precision(wall_name, n, tb, level):
    """The hardest references agree with a 60-digit recomputation to far below 1e-12."""
    base = reference(wall_name, tb, n, level)
    with mp.workdps(60):
        finer = compute_reference(wall_name, tb, level, (n,))[n]
    for mode in ("pressure", "flow"):
        assert base[mode][0] == finer[mode][0]                  # the same float loads
        for x, y in zip(base[mode][1:3], finer[mode][1:3]):
            assert abs(x / y - 1) < mpf(10) ** -28


def test_tube_thickness_ratio_is_exact():
    """The reference's tb is the float the library sees: a = 2**-13 makes tb * a / a exact."""
    for tb in TB_VALUES:
        assert make_tube(tb).reduced_thickness == tb
