r"""Accuracy of the default ``tubefsi.solve`` against an independent 40-digit reference.

Where the reference comes from
------------------------------
Nothing in this file calls tubefsi's numerics to build the expected values. The
reference (shared with ``test_accuracy_contract.py``, in ``tubefsi.testing.reference``: the
modules ``tube_laws`` and ``power_law``) is written in ``mpmath`` (``mp.dps = 40``, set for this
module only by the ``mp_precision`` fixture of ``conftest.py``) straight from the physics in
``docs/theory.md`` (section "Tube laws", section "The flow law of a generalized Newtonian
fluid" and the separation of variables of section "Coupling without an ODE"):

* tube laws ``P(lam)`` (``mu`` = shear modulus, ``2 (c1 + c2)`` for Mooney–Rivlin):

  - thick (Lamé, plane strain): ``P = (mu/2) [f(xo) - f(xi)]``, ``f(x) = x + ln x``,
    ``xo = (1+tb)^2 / ((1+tb)^2 - 1 + lam^2)``, ``xi = lam^-2``;
  - thin, reference thickness: ``P = mu tb (lam - lam^-3)``;
  - thin, current thickness: ``P = mu tb (1 - lam^-4)``;
  - thin linear: ``P = (lam - 1) E tb / (1 - nu/2)``; thick linear:
    ``P = (lam - 1) E tb / K``, ``K = [(1+tb)^2 (1+nu) + (1 - 2 nu)] / (2 + tb)``;

* power-law fluid: ``G(q, R) = phi(q) R^-k``, ``k = 3n + 1``,
  ``phi(q) = 2 m [(3n+1) q / (pi n)]^n`` (Newtonian = ``n = 1``, ``m = viscosity``);

* with the outlet at zero pressure (``lam_out = 1``), ``dp/dz = -G`` separates into
  ``L phi(q) = a^k Jhat(lam_in)``, ``Jhat(lam) = int_1^lam P'(s) s^k ds``, which is
  evaluated without ``P'`` by parts, ``Jhat = P(lam) lam^k - k int_1^lam P(s) s^(k-1) ds``
  (``mpmath.quad``, tanh–sinh, on geometrically split sub-intervals).

Each case picks the inlet stretch ``lam_in = 1 + strain`` (an exact ``mpf``, so the
reference displacement ``a * strain`` has no cancellation) — or, for a wall with a
limit pressure, solves ``P(lam_in) = 0.97 p_max`` with ``mp.findroot`` — and then
``dp_ref = P(lam_in)``, ``q_ref = phi^-1(a^k Jhat / L)``, ``u_ref = a (lam_in - 1)``.
The rigid wall is Hagen–Poiseuille for a power law, ``dp = L phi(q) a^-k``.

Maximum flow rate (limit-pressure walls, ``n < 1``): ``L phi(q_max) = a^k J_inf``,
``J_inf = int_1^inf P'(s) s^k ds``. Derivatives derived by hand from the laws above:

* thin current: ``P' = 4 mu tb s^-5``, so ``J_inf = 4 mu tb / (4 - k)`` exactly;
* thick: ``P'(s) = mu [ (1/s + 1/s^3) - (s/b) (xo + xo^2) ]`` with ``b = (1+tb)^2``
  (Leibniz rule on the Lamé integral of ``mu (1/s + 1/s^3)`` from ``lam_o`` to ``lam``,
  ``d lam_o / d lam = lam / (b lam_o)``), which simplifies with ``d = b - 1`` to
  ``P'(s) = mu d ((d+2) s^2 + d) / (s^3 (s^2+d)^2)``. Substituting ``s = 1/t``:
  ``J_inf = mu d int_0^1 ((d+2) + d t^2) t^(3-k) / (1 + d t^2)^2 dt``, and then
  ``t = w^(1/(4-k))`` removes the endpoint singularity ``t^(3-k)`` (without it, tanh–sinh
  loses ~13 digits at n = 0.9):
  ``J_inf = mu d / (4-k) int_0^1 ((d+2) + d t^2) / (1 + d t^2)^2 dw``. This was cross-checked
  to ~1e-40 against ``int_1^inf`` of ``P' s^k`` with the ``(d+2) s^(k-5)`` tail subtracted
  analytically.

All library inputs are floats; the reference converts the very same floats to ``mpf``
(e.g. ``n = 2/3`` is the double nearest 2/3 in both), so the comparison measures the
library's error alone. Tolerances: 1e-10 relative in pressure drop, flow rate and inlet
displacement (the design contract is 1e-12), 1e-9 for the maximum flow rate.
"""

from __future__ import annotations

import functools
import math

import mpmath
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from mpmath import mp, mpf

import tubefsi
from tubefsi.testing.profiles import scaled
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference.power_law import ref_J, ref_J_inf, ref_phi, ref_phi_inverse
from tubefsi.testing.reference.tube_laws import WALLS, RefWall, stretch_at_pressure

import accuracy_helpers
from accuracy_helpers import make_wall

DPS = 40   # working precision of the reference (set per module, restored afterwards)
pytestmark = pytest.mark.usefixtures("mp_precision")

RTOL = 1e-10
RTOL_QMAX = 1e-9

A = 1e-4        # undeformed inner radius (m)
L = 1e-2        # length (m)
M = 0.01        # power-law consistency (Pa s^n)
VISCOSITY = 3.5e-3  # Newtonian viscosity (Pa s)

N_VALUES = (0.3, 2 / 3, 0.7, 1.0, 1.5)
TB_VALUES = (0.05, 0.3, 1.0)
STRAIN_LEVELS = ("1e-4", "0.1", "1", "top")   # "top": strain 3, or 97 % of the limit pressure
NEAR_LIMIT = mpf("0.97")

DEFORMABLE = tuple(WALLS)


# ---------------------------------------------------------------------------- reference (mpmath)
# The tube laws, Jhat by parts, phi and its inverse, J_inf live in tubefsi.testing.reference.
def near_limit_stretch(wall):
    """lam with P(lam) = 0.97 p_max (bracketed, then polished by findroot)."""
    return stretch_at_pressure(wall, NEAR_LIMIT * wall.limit_pressure(), polish=False)


@functools.lru_cache(maxsize=None)
@mp.workdps(DPS)
def reference(wall_name, tb_float, n_float, m_float, level):
    """(q_ref, dp_ref, displacement_ref) as mpf, for the given float inputs."""
    _, params, kind = WALLS[wall_name]
    tb = mpf(tb_float * A) / mpf(A)   # the float thickness passed to Tube, divided exactly
    wall = RefWall(kind, params, tb)
    n, m = mpf(n_float), mpf(m_float)
    k = 3 * n + 1
    if level == "top" and wall.limit_pressure() != mpmath.inf:
        lam = near_limit_stretch(wall)
        strain = lam - 1
    else:
        strain = mpf(3) if level == "top" else mpf(level)
        lam = 1 + strain
    J = ref_J(wall, lam, k)
    q = ref_phi_inverse(J * mpf(A) ** k / mpf(L), n, m)
    return q, wall.P(lam), mpf(A) * strain


@mp.workdps(DPS)
def ref_max_flow_rate(wall_name, tb_float, n_float, m_float):
    _, params, kind = WALLS[wall_name]
    tb = mpf(tb_float * A) / mpf(A)
    wall = RefWall(kind, params, tb)
    n, m = mpf(n_float), mpf(m_float)
    k = 3 * n + 1
    J_inf = ref_J_inf(wall, k)
    return ref_phi_inverse(J_inf * mpf(A) ** k / mpf(L), n, m)


# ---------------------------------------------------------------------------- library side
# make_wall (imported above) and these come from accuracy_helpers, bound to this file's scene
# (radius A = 1e-4 m, not the contract tests' 2**-13 m).
make_tube = functools.partial(accuracy_helpers.make_tube, radius=A, length=L)
power_law = functools.partial(accuracy_helpers.power_law, m=M)


def check_case(fluid, wall_name, tb, n, m, level):
    """Solve flow- and pressure-controlled; return the relative errors (dict)."""
    q_ref, dp_ref, u_ref = reference(wall_name, tb, n, m, level)
    wall, tube = make_wall(wall_name), make_tube(tb)

    sol = tubefsi.solve(fluid, wall, tube, flow_rate=float(q_ref))
    sol2 = tubefsi.solve(fluid, wall, tube, pressure_drop=float(dp_ref))
    return {
        "dp (flow-controlled)": rel_err(sol.pressure_drop, dp_ref),
        "u (flow-controlled)": rel_err(sol.inlet_displacement, u_ref),
        "q (pressure-controlled)": rel_err(sol2.flow_rate, q_ref),
        "u (pressure-controlled)": rel_err(sol2.inlet_displacement, u_ref),
    }


def assert_errors(errors, label):
    bad = {key: err for key, err in errors.items() if not err <= RTOL}
    assert not bad, f"{label}: relative errors above {RTOL:g}: {bad}"


# ---------------------------------------------------------------------------- the grid
GRID = [
    pytest.param(wall_name, n, tb, level, id=f"{wall_name}-n{n:.4g}-tb{tb:g}-e{level}")
    for wall_name in DEFORMABLE
    for n in N_VALUES
    for tb in TB_VALUES
    for level in STRAIN_LEVELS
]


@pytest.mark.parametrize(("wall_name", "n", "tb", "level"), GRID)
def test_power_law_matches_reference(wall_name, n, tb, level):
    errors = check_case(power_law(n), wall_name, tb, n, M, level)
    assert_errors(errors, f"{wall_name}, n={n!r}, tb={tb}, strain level {level}")


@pytest.mark.parametrize("wall_name", DEFORMABLE)
@pytest.mark.parametrize("tb", TB_VALUES)
@pytest.mark.parametrize("level", STRAIN_LEVELS)
def test_newtonian_matches_reference(wall_name, tb, level):
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=VISCOSITY)
    errors = check_case(fluid, wall_name, tb, 1.0, VISCOSITY, level)
    assert_errors(errors, f"newtonian, {wall_name}, tb={tb}, strain level {level}")


@pytest.mark.parametrize("n", N_VALUES + (None,), ids=lambda n: "newtonian" if n is None else f"n{n:.4g}")
@pytest.mark.parametrize("tb", TB_VALUES)
@pytest.mark.parametrize("q", (1e-14, 1e-11, 1e-8))
def test_rigid_is_hagen_poiseuille(n, tb, q):
    if n is None:
        fluid = tubefsi.registry.rheologies["newtonian"](viscosity=VISCOSITY)
        n_mp, m_mp = mpf(1), mpf(VISCOSITY)
    else:
        fluid = power_law(n)
        n_mp, m_mp = mpf(n), mpf(M)
    k = 3 * n_mp + 1
    dp_ref = mpf(L) * ref_phi(mpf(q), n_mp, m_mp) * mpf(A) ** -k
    wall, tube = tubefsi.registry.walls["rigid"](), make_tube(tb)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
    sol2 = tubefsi.solve(fluid, wall, tube, pressure_drop=float(dp_ref))
    errors = {
        "dp (flow-controlled)": rel_err(sol.pressure_drop, dp_ref),
        "q (pressure-controlled)": rel_err(sol2.flow_rate, mpf(q)),
    }
    assert_errors(errors, f"rigid, n={n!r}, q={q}")
    assert sol.inlet_displacement == 0.0
    assert sol2.inlet_displacement == 0.0


# ---------------------------------------------------------------------------- maximum flow rate
LIMIT_WALLS = ("thick-neo-hookean", "thin-neo-hookean-current")


@pytest.mark.parametrize("wall_name", LIMIT_WALLS)
@pytest.mark.parametrize("n", (0.5, 0.7, 0.9))
@pytest.mark.parametrize("tb", TB_VALUES)
def test_max_flow_rate_matches_reference(wall_name, n, tb):
    q_ref = ref_max_flow_rate(wall_name, tb, n, M)
    got = tubefsi.max_flow_rate(power_law(n), make_wall(wall_name), make_tube(tb))
    assert rel_err(got, q_ref) <= RTOL_QMAX, (got, q_ref)


@pytest.mark.parametrize("wall_name", LIMIT_WALLS + ("thick-mooney-rivlin", "thin-mooney-rivlin-current"))
@pytest.mark.parametrize("n", (1.0, 1.5))
def test_max_flow_rate_infinite_for_n_at_least_one(wall_name, n):
    assert tubefsi.max_flow_rate(power_law(n), make_wall(wall_name), make_tube(0.3)) == math.inf


@pytest.mark.parametrize("wall_name", LIMIT_WALLS)
def test_max_flow_rate_infinite_for_newtonian(wall_name):
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=VISCOSITY)
    assert tubefsi.max_flow_rate(fluid, make_wall(wall_name), make_tube(0.3)) == math.inf


@pytest.mark.parametrize("wall_name", ("thin-mooney-rivlin-reference", "thin-neo-hookean-reference",
                                       "thin-linear", "thick-linear", "rigid"))
@pytest.mark.parametrize("n", (0.3, 0.7, 1.5))
def test_max_flow_rate_infinite_without_limit_pressure(wall_name, n):
    wall = tubefsi.registry.walls["rigid"]() if wall_name == "rigid" else make_wall(wall_name)
    assert tubefsi.max_flow_rate(power_law(n), wall, make_tube(0.3)) == math.inf


# ---------------------------------------------------------------------------- hypothesis
@settings(deadline=None, max_examples=scaled(15))
@given(
    n=st.floats(min_value=0.3, max_value=1.5),
    tb=st.floats(min_value=0.05, max_value=1.0),
    log_strain=st.floats(min_value=-4.0, max_value=math.log10(3.0)),
    c1=st.floats(min_value=1e2, max_value=1e5),
    c2_ratio=st.floats(min_value=-0.9, max_value=1.0),
)
def test_thick_mooney_rivlin_hypothesis(n, tb, log_strain, c1, c2_ratio):
    c2 = c1 * c2_ratio
    assume(c1 + c2 > 0)
    thickness = tb * A
    tb_mp = mpf(thickness) / mpf(A)
    ref_wall = RefWall("thick", dict(c1=c1, c2=c2), tb_mp)
    strain = mpf(10.0**log_strain)
    lam = 1 + strain
    dp_ref = ref_wall.P(lam)
    assume(dp_ref <= NEAR_LIMIT * ref_wall.limit_pressure())
    n_mp, k = mpf(n), 3 * mpf(n) + 1
    q_ref = ref_phi_inverse(ref_J(ref_wall, lam, k) * mpf(A) ** k / mpf(L), n_mp, mpf(M))
    u_ref = mpf(A) * strain

    fluid = power_law(n)
    wall = tubefsi.registry.walls["thick-mooney-rivlin"](c1=c1, c2=c2)
    tube = tubefsi.Tube(radius=A, thickness=thickness, length=L)
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=float(q_ref))
    sol2 = tubefsi.solve(fluid, wall, tube, pressure_drop=float(dp_ref))
    errors = {
        "dp (flow-controlled)": rel_err(sol.pressure_drop, dp_ref),
        "u (flow-controlled)": rel_err(sol.inlet_displacement, u_ref),
        "q (pressure-controlled)": rel_err(sol2.flow_rate, q_ref),
        "u (pressure-controlled)": rel_err(sol2.inlet_displacement, u_ref),
    }
    assert_errors(errors, f"thick MR c1={c1!r} c2={c2!r}, n={n!r}, tb={tb!r}, strain={float(strain)!r}")
