r"""Helpers shared by the accuracy tests: ``test_accuracy_contract.py``, ``test_stability.py`` and
``test_reference_accuracy.py``.

Import them as ``from accuracy_helpers import ...`` (pytest's default import mode puts ``tests/``
on ``sys.path``; not from ``conftest``, of which every test directory has its own). The
independent references themselves live in ``tubefsi.testing.reference``; what is here builds
the library's side of a case (walls, tubes, fluids), evaluates the condition numbers of the
accuracy contract on a reference wall, finds a stretch near the maximum flow rate and asserts
the contract.

The contract's scene (``A``, ``L``, ``M``, the defaults of :func:`make_tube` and
:func:`power_law`) is that of ``test_accuracy_contract.py`` and ``test_stability.py``: the tube
radius is a power of two, so ``thickness = tb * A`` and ``thickness / A`` are exact and the
reference's ``tb`` is the very float the library sees. ``test_reference_accuracy.py`` passes its
own radius.

Condition numbers (:func:`kappas`; ``e = lam - 1``, ``k = 3n + 1``,
``Jhat(lam) = int_1^lam P'(s) s^k ds``; derived in the docstring of
``test_accuracy_contract.py``):

* ``u(dp)``: ``kappa = P / (e P')``          * ``q(dp)``: ``kappa = P lam^k / (n Jhat)``
* ``dp(q)``: ``kappa = n Jhat / (P lam^k)``   * ``u(q)``: ``kappa = n Jhat / (e P' lam^k)``
"""

from __future__ import annotations

import mpmath
from mpmath import mp, mpf

import tubefsi
from tubefsi.testing.reference.power_law import ref_J_tail
from tubefsi.testing.reference.tube_laws import WALLS, RefWall

A = 2.0**-13      # undeformed inner radius (m); a power of two: tb * A and thickness / A are exact
L = 1e-2          # length (m)
M = 0.01          # power-law consistency (Pa s^n); also the Newtonian viscosity (shares references)

CONTRACT_RTOL = 1e-12    # the accuracy contract: rel_err <= CONTRACT_RTOL * max(1, kappa)


# ---------------------------------------------------------------------------- library side
def make_wall(wall_name):
    """The library's built-in wall of ``tubefsi.testing.reference.tube_laws.WALLS[wall_name]``."""
    reg_name, params, _ = WALLS[wall_name]
    return tubefsi.registry.walls[reg_name](**params)


def make_tube(tb, radius=A, length=L):
    """A tube of thickness ratio ``tb`` (thickness ``tb * radius``)."""
    return tubefsi.Tube(radius=radius, thickness=tb * radius, length=length)


def power_law(n, m=M):
    """The library's power-law fluid of index ``n`` and consistency ``m``."""
    return tubefsi.registry.rheologies["power-law"](consistency=m, index=n)


# ---------------------------------------------------------------------------- reference side
def ref_wall(wall_name, tb):
    """The reference wall of ``WALLS[wall_name]`` at the thickness ratio ``mpf(tb)`` (closed forms)."""
    _, params, kind = WALLS[wall_name]
    return RefWall(kind, params, mpf(tb))


def kappas(wall, n, k, lam, J, e=None):
    """The relative condition numbers of the contract at the inlet stretch ``lam`` (module
    docstring); ``J = Jhat(lam)``. ``e``: the inlet strain ``lam - 1`` when the caller has it
    exactly (then ``lam`` should be ``1 + e``), else computed from ``lam``."""
    e = lam - 1 if e is None else e
    P, dP = wall.P(lam), wall.dP(lam)
    return dict(
        u_of_dp=P / (e * dP),
        q_of_dp=P * lam**k / (n * J),
        dp_of_q=n * J / (P * lam**k),
        u_of_q=n * J / (e * dP * lam**k),
    )


def stretch_for_tail(wall, k, tail_target, *, steps, tol_digits, coarse_dps=None, check_digits=None):
    """lam with ``tail(lam) = int_lam^inf P' s^k ds = tail_target`` (a limit wall, ``k < 4``):
    Newton on ``ln tail`` in ``x = ln lam``, from the asymptote ``tail ~ C lam^-(4-k)``.

    The schedule is the caller's: at most ``steps`` Newton steps per pass, a pass converged when
    ``|dx| < 10^(tol_digits - dps) max(1, |x|)`` at its precision ``dps``; one pass at the
    caller's ``mp.dps``, or, with ``coarse_dps``, first a cheap one at ``min(coarse_dps, mp.dps)``
    digits and then a polish at ``mp.dps``. A pass that does not converge raises
    ``AssertionError``. ``check_digits``: also assert
    ``|tail(lam) / tail_target - 1| < 10^(check_digits - mp.dps)`` at the end.
    """
    alpha = 4 - k
    d = (1 + wall.tb) ** 2 - 1
    C = wall.mu * d * (d + 2) / alpha if wall.kind == "thick" else 4 * wall.mu * wall.tb / alpha
    x = mpmath.log(C / tail_target) / alpha
    passes = (mp.dps,) if coarse_dps is None else (min(coarse_dps, mp.dps), mp.dps)
    for dps in passes:
        with mp.workdps(dps):
            for _ in range(steps):
                lam = mpmath.exp(x)
                tail = ref_J_tail(wall, lam, k)
                dx = mpmath.log(tail / tail_target) * tail / (wall.dP(lam) * lam ** (k + 1))
                x += dx
                if abs(dx) < mpf(10) ** (tol_digits - dps) * max(1, abs(x)):
                    break
            else:
                raise AssertionError("reference Newton did not converge")
    lam = mpmath.exp(x)
    if check_digits is not None:
        assert abs(ref_J_tail(wall, lam, k) / tail_target - 1) < mpf(10) ** (check_digits - mp.dps)
    return lam


# ---------------------------------------------------------------------------- the contract
def assert_contract(errors, label, rtol=CONTRACT_RTOL):
    """``errors``: [(quantity, relative error, kappa)]; each must be ``<= rtol * max(1, kappa)``."""
    bad = [f"{name}: err {err:.3g} > {rtol:g} * max(1, kappa={kappa:.3g})"
           for name, err, kappa in errors if not err <= rtol * max(1.0, kappa)]
    assert not bad, f"{label}: " + "; ".join(bad)
