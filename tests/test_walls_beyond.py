"""Walls beyond the uniform clamped tube (``docs/walls_beyond.md``): end conditions of linear
walls, the Shapiro collapsible tube, external pressure, axial pre-stretch.

Every reference is computed here independently of the code under test (mpmath at 30 digits).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi

walls = tubefsi.registry.walls
mp.mp.dps = 30


# ------------------------------------------------------------------ 1. linear end conditions
def lame_strain(p, E, nu, tb, ends):
    r"""Hoop strain of the inner surface from the generalized-plane-strain Lamé problem, in
    displacements: :math:`u_r = A r + B/r`, :math:`\varepsilon_z = e`, 3-D Hooke's law with the Lamé
    constants, :math:`\sigma_r(a) = -p`, :math:`\sigma_r(b) = 0` and the axial condition of
    ``ends`` (closed: axial force :math:`p\pi a^2`; open: none; clamped: :math:`e = 0`), solved as
    a 3x3 linear system in mpmath (none of the closed forms of ``linear.py``)."""
    E, nu, p = mp.mpf(E), mp.mpf(nu), mp.mpf(p)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu)) if nu != 0.5 else None
    mu = E / (2 * (1 + nu))
    a, b = mp.mpf(1), 1 + mp.mpf(tb)

    # stresses are linear in (A, B, e); rows: sigma_r(a) + p = 0, sigma_r(b) = 0, axial condition
    def sig_r(r):   # coefficients of A, B, e
        return [2 * (lam + mu), -2 * mu / r**2, lam]

    sig_z = [2 * lam, mp.mpf(0), lam + 2 * mu]
    rows = [sig_r(a), sig_r(b)]
    rhs = [-p, mp.mpf(0)]
    if ends == "clamped":
        rows.append([0, 0, 1])
        rhs.append(0)
    else:       # uniform sigma_z over the annulus pi (b^2 - a^2): force p pi a^2 (closed) or 0 (open)
        rows.append(sig_z)
        rhs.append(p * a**2 / (b**2 - a**2) if ends == "closed" else 0)
    A, B, _ = mp.lu_solve(mp.matrix(rows), mp.matrix(rhs))
    return A + B / a**2


@pytest.mark.parametrize("ends", ["closed", "open", "clamped"])
@pytest.mark.parametrize("kind", ["thick-linear", "thin-linear"])
@pytest.mark.parametrize("nu", [-0.3, 0.0, 0.3, 0.45])
def test_linear_end_conditions_match_lame(kind, ends, nu):
    E, p = 2.5e5, 7.0
    wall = walls[kind](youngs_modulus=E, poisson_ratio=nu, end_condition=ends)
    for tb in (1e-3, 0.2, 1.5):
        if kind == "thick-linear":
            ref = lame_strain(p, E, nu, tb, ends)
        else:   # the thin wall is the t/a -> 0 limit: K(tb) extrapolated from tiny tb
            h = mp.mpf("1e-12")
            ref = lame_strain(p, E, nu, h, ends) * h / tb
        assert wall.strain(p, tb) == pytest.approx(float(ref), rel=1e-13)


def test_linear_end_conditions_thin_limits_and_incompressible_coincide():
    for ends, k in (("closed", 1 - 0.3 / 2), ("open", 1.0), ("clamped", 1 - 0.3**2)):
        thin = walls["thin-linear"](youngs_modulus=1.0, poisson_ratio=0.3, end_condition=ends)
        assert thin.strain(1.0, 1.0) == pytest.approx(k, rel=1e-15)
    # nu = 1/2: closed ends carry no axial strain, so closed = clamped (the hyperelastic limit)
    closed, clamped = (walls["thick-linear"](youngs_modulus=3.0, poisson_ratio=0.5, end_condition=e)
                       for e in ("closed", "clamped"))
    neo = walls["thick-neo-hookean"](shear_modulus=1.0)
    for tb in (0.1, 1.0):
        assert clamped.small_strain_modulus(tb) == pytest.approx(closed.small_strain_modulus(tb), rel=1e-15)
        assert clamped.small_strain_modulus(tb) == pytest.approx(neo.small_strain_modulus(tb), rel=1e-12)


def test_end_condition_validates_and_enters_the_table_key():
    with pytest.raises(tubefsi.InvalidParameterError, match="end_condition"):
        walls["thin-linear"](youngs_modulus=1.0, poisson_ratio=0.3, end_condition="capped")
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["newtonian"](viscosity=1e-3)
    drops = {}
    for ends in ("closed", "open", "clamped"):
        wall = walls["thick-linear"](youngs_modulus=1e4, poisson_ratio=0.3, end_condition=ends)
        for _ in range(3):          # the third call is served by the cached table / scalar path
            drops.setdefault(ends, []).append(tubefsi.solve(fluid, wall, tube, flow_rate=1e-9).pressure_drop)
    for ends, values in drops.items():
        assert max(values) - min(values) <= 1e-13 * values[0]
    assert len({v[-1] for v in drops.values()}) == 3
