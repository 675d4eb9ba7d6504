r"""Verification of the finite-element reference ``tubefsi.fem`` itself, and one coupled case.

References, none taken from the code under test:

* rigid tube, Newtonian: Hagen–Poiseuille, :math:`\Delta p = 8\mu L q/(\pi a^4)`, wall shear stress
  :math:`4\mu q/(\pi a^3)`; Taylor–Hood (Q2/Q1) contains the exact solution (a parabola and a
  linear pressure), so it is reproduced to round-off;
* rigid tube, power law: the closed form :math:`G = 2m[(3n+1)q/(\pi n)]^n a^{-(3n+1)}` (written
  here from docs/theory.md, "Rheology"); the pressure drop by the power balance falls as
  :math:`h^4` (twice the velocity's order: the discrete flow minimizes the energy);
* the wall alone, ends sliding (generalized plane strain at axial stretch 1): the exact thick
  tube law (Lamé/Rivlin, closed form in ``wall.pressure``); biquadratic elements converge the
  displacement at :math:`h^4` (as the plane-strain ring of tests/test_fem_tube_laws.py);
* the coupled tube against ``tubefsi.solve``: the difference is the modelling error, bounded by
  the end-layer estimate of docs/validity.md, :math:`|\delta| \le (3n+1)\,\varepsilon_{in}\,(a+t)/L`,
  and first order in a/L (observed order within 0.3 of 1 as L/a doubles).
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import tubefsi

pytest.importorskip("skfem", reason="tubefsi.fem needs the 'fem' extra (scikit-fem)")
pytest.importorskip("felupe", reason="tubefsi.fem needs the 'fem' extra (felupe)")

import tubefsi.fem as tfem  # noqa: E402
from tubefsi.fem._wall import AxisymmetricWall  # noqa: E402

rheologies, walls = tubefsi.registry.rheologies, tubefsi.registry.walls
A = 1e-3


def test_fem_is_not_imported_with_tubefsi_and_names_its_extra():
    code = ("import sys, tubefsi; assert 'tubefsi.fem' not in sys.modules and 'skfem' not in sys.modules; "
            "sys.modules['skfem'] = None\n"
            "try:\n    import tubefsi.fem\nexcept ImportError as e:\n    print(e)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "tubefsi[fem]" in out


def test_rigid_newtonian_tube_is_hagen_poiseuille_to_round_off():
    mu, q, L = 1e-3, 1e-9, 8 * A
    sol = tfem.solve_axisymmetric(rheologies["newtonian"](viscosity=mu), walls["rigid"](),
                                  tubefsi.Tube(radius=A, thickness=0.3 * A, length=L), flow_rate=q, resolution=2)
    dp = 8 * mu * L * q / (math.pi * A**4)
    assert sol.pressure_drop == pytest.approx(dp, rel=1e-10)
    assert sol.axis_pressure_drop == pytest.approx(dp, rel=1e-10)
    np.testing.assert_allclose(sol.pressure, dp * (1 - sol.z / L), rtol=0, atol=1e-10 * dp)
    np.testing.assert_allclose(sol.wall_shear_stress, 4 * mu * q / (math.pi * A**3), rtol=1e-8)
    np.testing.assert_allclose(sol.radius, A)


def _power_law_error(n, resolution):
    m, q, L = 1e-2, 1e-9, 2 * A
    G = 2 * m * ((3 * n + 1) * q / (math.pi * n)) ** n * A ** -(3 * n + 1)
    sol = tfem.solve_axisymmetric(rheologies["power-law"](consistency=m, index=n), walls["rigid"](),
                                  tubefsi.Tube(radius=A, thickness=0.3 * A, length=L), flow_rate=q,
                                  resolution=resolution)
    return abs(sol.pressure_drop / (G * L) - 1)


def test_rigid_power_law_tube_converges_at_fourth_order():
    """n = 0.5: the discrete flow minimizes the power-law energy, whose value, (n+1)^-1 times the
    dissipation q dp, is therefore second order in the velocity's H1 error (h^2 for Q2): the
    pressure drop error falls as h^4, 4e-5 at 4 elements across the radius."""
    coarse, fine = _power_law_error(0.5, 2), _power_law_error(0.5, 4)
    assert abs(math.log2(coarse / fine) - 4.0) < 0.3, (coarse, fine)
    assert fine < 1e-4


def _wall_stretch_error(wall, tb, stretch, n_thickness):
    """Sliding ends, the exact tube-law pressure as consistent nodal forces on the deformed
    inner cylinder (Simpson weights of the Q2 edge), ramped in 4 steps: stretch error."""
    L = 2 * A
    z = np.linspace(0, L, 3)
    solid = AxisymmetricWall(wall, A, tb * A, z, n_thickness, ends="sliding")
    h = z[1] - z[0]
    weights = np.where(np.arange(len(solid.lines)) % 2 == 1, 2 * h / 3, h / 3)
    weights[[0, -1]] = h / 6
    p = wall.pressure(stretch, tb)
    for s in np.linspace(0.25, 1.0, 4):
        d = solid.solve(np.column_stack([2 * math.pi * s * p * stretch * A * weights, 0 * weights]))
    return float(np.max(np.abs((A + d[:, 0]) / (A * stretch) - 1)))


@pytest.mark.parametrize(("name", "params"), [("thick-neo-hookean", {"shear_modulus": 1e4}),
                                              ("thick-mooney-rivlin", {"c1": 1.5e4, "c2": -0.5e4})])
def test_uncoupled_wall_is_the_exact_tube_law_at_fourth_order(name, params):
    wall = walls[name](**params)
    coarse, fine = _wall_stretch_error(wall, 0.3, 1.5, 1), _wall_stretch_error(wall, 0.3, 1.5, 2)
    assert abs(math.log2(coarse / fine) - 4.0) < 0.3, (coarse, fine)
    assert fine < 1e-6


@pytest.fixture(scope="module")
def coupled():
    """Newtonian, thick neo-Hookean t/a = 0.3, inlet strain 5 % (tubefsi), L/a = 10 and 20."""
    fluid = rheologies["newtonian"](viscosity=1e-3)
    wall = walls["thick-neo-hookean"](shear_modulus=1e4)
    out = {}
    for ratio in (10, 20):
        tube = tubefsi.Tube(radius=A, thickness=0.3 * A, length=ratio * A)
        with pytest.warns(tubefsi.ModelValidityWarning) if ratio == 10 else _nothing():
            q = float(tubefsi.solve(fluid, wall, tube, pressure_drop=wall.pressure(1.05, 0.3)).flow_rate)
            red = tubefsi.solve(fluid, wall, tube, flow_rate=q)
        out[ratio] = (red, tfem.solve_axisymmetric(fluid, wall, tube, flow_rate=q, resolution=2))
    return out


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_coupled_case_agrees_with_tubefsi_within_the_end_layer_bound(coupled):
    for ratio, (red, fe) in coupled.items():
        delta = red.pressure_drop / fe.pressure_drop - 1
        strain = red.inlet_displacement / A
        bound = (3 * 1 + 1) * strain * (1 + 0.3) / ratio
        assert abs(delta) <= bound, (ratio, delta, bound)
        assert delta < 0                         # clamped ends narrow the inlet: the FE drop is larger
        assert fe.history[-1]["residual"] <= 1e-8
        # far from the ends the wall shear stress and radius are the lubrication ones to O(a/L)
        mid = np.argmin(np.abs(fe.wall_z - 0.5 * ratio * A))
        assert fe.radius[mid] == pytest.approx(red.radius(fe.wall_z[mid]), rel=2 * bound * strain)
        assert fe.wall_shear_stress[mid] == pytest.approx(red.wall_shear_stress(fe.wall_z[mid]), rel=2 * bound)


def test_coupled_difference_is_first_order_in_slenderness(coupled):
    d10, d20 = (red.pressure_drop / fe.pressure_drop - 1 for red, fe in coupled.values())
    assert abs(math.log2(d10 / d20) - 1.0) < 0.3, (d10, d20)


def test_bad_input_is_refused_with_the_parameter_named():
    fluid = rheologies["newtonian"](viscosity=1e-3)
    tube = tubefsi.Tube(radius=A, thickness=0.3 * A, length=10 * A)
    wall = walls["thick-neo-hookean"](shear_modulus=1e4)
    with pytest.raises(tubefsi.InvalidParameterError, match="flow_rate"):
        tfem.solve_axisymmetric(fluid, wall, tube, flow_rate=0.0)
    with pytest.raises(tubefsi.InvalidParameterError, match="resolution"):
        tfem.solve_axisymmetric(fluid, wall, tube, flow_rate=1e-9, resolution=0)
    with pytest.raises(tubefsi.InvalidParameterError, match="wall"):
        tfem.solve_axisymmetric(fluid, walls["thick-linear"](youngs_modulus=3e4, poisson_ratio=0.5), tube,
                                flow_rate=1e-9)
    with pytest.raises(tubefsi.InvalidParameterError, match="flow_rate"):
        tfem.solve_axisymmetric(fluid, wall, tube, flow_rate=[1e-9, 2e-9])
    with pytest.raises(tubefsi.InvalidParameterError, match="rheology"):
        tfem.solve_axisymmetric(rheologies["newtonian"](viscosity=[1e-3, 2e-3]), wall, tube, flow_rate=1e-9)
    with pytest.raises(tubefsi.InvalidParameterError, match="wall"):
        tfem.solve_axisymmetric(fluid, walls["thick-neo-hookean"](shear_modulus=[1e4, 2e4]), tube, flow_rate=1e-9)
    with pytest.raises(tubefsi.InvalidParameterError, match="tube"):
        tfem.solve_axisymmetric(fluid, wall, tubefsi.Tube(radius=[A, 2 * A], thickness=0.3 * A, length=10 * A),
                                flow_rate=1e-9)
