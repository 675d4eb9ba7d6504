"""tubefsi.dimensionless: the chapter's groups of a scene, and scenes built from groups."""

import math

import attrs
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi import dimensionless as nd
from tubefsi.fields import real
from tubefsi.registry import rheologies, walls
from tubefsi.rheology.base import Rheology
from tubefsi.testing.profiles import scaled
from tubefsi.walls.hyperelastic import HyperelasticWall, ThickWall

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)


def power_law(n, m=0.02):
    return rheologies["power-law"](consistency=m, index=n)


# ------------------------------------------------------------------------------ scales
@pytest.mark.parametrize("n", [0.5, 0.7, 1.0, 1.6])
def test_flow_controlled_scales(n):
    q, a, L, m = 2e-9, TUBE.radius, TUBE.length, 0.02
    pc = nd.pressure_scale(power_law(n), TUBE, flow_rate=q)
    assert pc == pytest.approx((q / (math.pi * a * a)) ** n * m * L / a ** (n + 1), rel=1e-14)
    # V_z = [a^(n+1) P_c/(m L)]^(1/n) is the mean velocity q/(pi a^2): qbar = 1 by construction
    assert nd.velocity_scale(power_law(n), TUBE, pc) == pytest.approx(q / (math.pi * a * a), rel=1e-13)
    g = nd.groups(power_law(n), "rigid", TUBE, flow_rate=q)
    assert (g.control, g.qbar) == ("flow", pytest.approx(1.0, rel=1e-13))


@pytest.mark.parametrize("n", [0.5, 0.7, 1.0, 1.6])
def test_scales_turn_the_flow_law_into_the_chapters_dimensionless_form(n):
    """Rigid tube: dp/dz = -2[(3+1/n) qbar]^n in the chapter's variables, flow- or pressure-controlled."""
    fluid = power_law(n)
    sol = tubefsi.solve(fluid, "rigid", TUBE, flow_rate=3e-9)
    g = nd.groups(fluid, "rigid", TUBE, flow_rate=3e-9)
    assert sol.pressure_drop / g.pressure_scale == pytest.approx(2 * (3 + 1 / n) ** n, rel=1e-13)
    # pressure-controlled: P_c = dp, so dpbar = 1 and qbar = (1/2)^(1/n) / (3 + 1/n)
    gp = nd.groups(fluid, "rigid", TUBE, pressure_drop=sol.pressure_drop)
    assert gp.control == "pressure" and gp.pressure_scale == sol.pressure_drop
    assert gp.qbar == pytest.approx(0.5 ** (1 / n) / (3 + 1 / n), rel=1e-12)
    assert nd.dimensionless_flow_rate(fluid, TUBE, 3e-9, sol.pressure_drop) == pytest.approx(gp.qbar, rel=1e-14)


def test_newtonian_is_the_power_law_with_n_1():
    a = nd.groups(rheologies["newtonian"](viscosity=0.02), "rigid", TUBE, flow_rate=1e-9)
    b = nd.groups(power_law(1.0), "rigid", TUBE, flow_rate=1e-9)
    assert a == b


# ------------------------------------------------------------------------------ gamma, beta
@pytest.mark.parametrize(("c1", "c2"), [(1.5e3, -0.5e3), (1e3, 1e3), (2e3, 0.0)])
@pytest.mark.parametrize("theory", ["thin", "thick"])
def test_gamma_and_beta_follow_their_definitions(c1, c2, theory):
    wall = walls[f"{theory}-mooney-rivlin"](c1=c1, c2=c2)
    pc, tb = 250.0, TUBE.reduced_thickness
    assert nd.gamma(wall, TUBE, pc) == pytest.approx(pc / (2 * (c1 + c2) * tb), rel=1e-14)
    assert nd.beta(wall, TUBE, pc) == pytest.approx(pc / (6 * (c1 + c2) * tb), rel=1e-14)   # E = 6(c1+c2)


@pytest.mark.parametrize("nu", [-0.2, 0.3, 0.5])
def test_linear_wall_gamma_uses_its_shear_modulus(nu):
    wall = walls["thick-linear"](youngs_modulus=9e3, poisson_ratio=nu)
    assert nd.gamma(wall, TUBE, 100.0) == pytest.approx(2 * (1 + nu) * nd.beta(wall, TUBE, 100.0), rel=1e-14)
    assert nd.beta(wall, TUBE, 100.0) == pytest.approx(100.0 / (9e3 * TUBE.reduced_thickness), rel=1e-14)


def test_rigid_wall_has_zero_fsi_parameters():
    g = nd.groups(power_law(0.7), "rigid", TUBE, flow_rate=1e-9)
    assert g.gamma == 0.0 and g.beta == 0.0


@attrs.frozen(kw_only=True)
class _Gentish(ThickWall, HyperelasticWall):
    """A material that only gives dW (no shear_modulus field): mu from dW''(1)/4."""

    mu0: float = 3e3

    def _dW(self, s):
        return self.mu0 * (s - s**-3) / (1 - (s - 1 / s) ** 2 / 5.0)


def test_any_hyperelastic_wall_uses_its_small_strain_shear_modulus():
    wall = _Gentish()
    assert nd.gamma(wall, TUBE, 100.0) == pytest.approx(100.0 / (3e3 * TUBE.reduced_thickness), rel=1e-8)
    assert nd.gamma(wall, TUBE, 100.0) == pytest.approx(3 * nd.beta(wall, TUBE, 100.0), rel=1e-14)


def test_arrays_broadcast():
    q = np.array([1e-10, 1e-9, 1e-8])
    g = nd.groups(power_law(0.7), walls["thick-neo-hookean"](shear_modulus=2e3), TUBE, flow_rate=q)
    assert np.shape(g.pressure_scale) == (3,) and np.allclose(g.qbar, 1.0)
    assert np.allclose(np.asarray(g.gamma) / np.asarray(g.beta), 3.0)


def test_pressure_controlled_groups_solve_for_the_flow_rate():
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    g = nd.groups(power_law(0.7), wall, TUBE, pressure_drop=150.0)
    q = tubefsi.solve(power_law(0.7), wall, TUBE, pressure_drop=150.0).flow_rate
    assert g.qbar == pytest.approx(nd.dimensionless_flow_rate(power_law(0.7), TUBE, q, 150.0), rel=1e-14)


# ------------------------------------------------------------------------------ the reverse
@settings(deadline=None, max_examples=scaled(25))
@given(n=st.floats(0.3, 2.0), tb=st.floats(0.01, 2.0), qbar=st.floats(0.0, 2.0), gam=st.floats(0.01, 10.0),
       wall=st.sampled_from(["thick-mooney-rivlin", "thin-mooney-rivlin", "thick-neo-hookean",
                             "thin-neo-hookean", "thick-linear", "thin-linear"]))
def test_scene_round_trips_through_groups(n, tb, qbar, gam, wall):
    sc = nd.scene(index=n, reduced_thickness=tb, qbar=qbar, gamma=gam, wall=wall)
    g = sc.groups
    assert g.index == n and g.reduced_thickness == pytest.approx(tb, rel=1e-15)
    assert g.qbar == pytest.approx(qbar, rel=1e-13, abs=1e-300)
    assert g.gamma == pytest.approx(gam, rel=1e-13)
    assert g.beta == pytest.approx(gam / 3.0, rel=1e-13)        # every wall here has nu = 1/2


@pytest.mark.parametrize("wall", ["thick-mooney-rivlin", "thin-linear", "thick-linear", "thin-neo-hookean"])
def test_dimensionless_pressure_drop_does_not_depend_on_the_physical_values(wall):
    q = np.array([0.02, 0.1, 0.18])          # below the thick wall's maximum flow rate 0.19
    ref = nd.scene(index=0.7, reduced_thickness=0.3, qbar=q, beta=1.0, wall=wall).pressure_drop()
    other = nd.scene(index=0.7, reduced_thickness=0.3, qbar=q, beta=1.0, wall=wall, pressure_scale=3.7e4,
                     radius=2e-3, length=0.7, consistency=0.013).pressure_drop()
    np.testing.assert_allclose(other, ref, rtol=1e-11)


def test_scene_sets_the_modulus_from_gamma_or_beta():
    sc = nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.5, gamma=2.0, wall="thick-linear",
                  wall_options={"poisson_ratio": 0.3}, pressure_scale=600.0)
    # gamma = P_c/(G t/a) with G = E/(2(1+nu))
    assert sc.wall.youngs_modulus == pytest.approx(2 * 1.3 * 600.0 / (2.0 * 0.3), rel=1e-14)
    sc = nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.5, beta=2.0, wall="thick-neo-hookean",
                  pressure_scale=600.0)
    assert sc.wall.shear_modulus == pytest.approx(600.0 / (3 * 2.0 * 0.3), rel=1e-14)   # E = 3 mu


def test_scene_keeps_a_mooney_rivlin_instances_constant_ratio_and_options():
    template = walls["thin-mooney-rivlin"](c1=3.0, c2=-1.0, thickness_convention="current")
    sc = nd.scene(index=0.7, reduced_thickness=0.1, qbar=0.3, gamma=1.0, wall=template, pressure_scale=100.0)
    assert sc.wall.thickness_convention == "current"
    assert sc.wall.c2 / (sc.wall.c1 + sc.wall.c2) == pytest.approx(-0.5, rel=1e-14)
    assert 2 * (sc.wall.c1 + sc.wall.c2) == pytest.approx(100.0 / 0.1, rel=1e-14)


@attrs.frozen(kw_only=True)
class _Yeohish(ThickWall, HyperelasticWall):
    """A plugin-like material whose moduli are several fields in Pa."""

    c1: float = real(unit="Pa")
    c2: float = real(unit="Pa")
    c3: float = real(unit="Pa")

    def _dW(self, s):
        y = (s - 1 / s) ** 2
        return 2 * (self.c1 + 2 * self.c2 * y + 3 * self.c3 * y * y) * (s - s**-3)


def test_scene_rescales_a_templates_moduli_together():
    sc = nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.2, gamma=2.0, wall=_Yeohish(c1=1.0, c2=0.1, c3=0.01),
                  pressure_scale=300.0)
    assert (sc.wall.c2 / sc.wall.c1, sc.wall.c3 / sc.wall.c1) == (pytest.approx(0.1), pytest.approx(0.01))
    assert sc.groups.gamma == pytest.approx(2.0, rel=1e-12)
    with pytest.raises(tubefsi.InvalidParameterError) as err:       # its modulus is not a field in Pa
        nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.2, gamma=2.0, wall=_Gentish())
    assert err.value.parameter == "wall"


REGISTERED_HYPERELASTIC = [pytest.param(walls[name](**kw), id=f"{name}-{i}") for name in walls
                           if issubclass(walls[name], HyperelasticWall)
                           for i, kw in enumerate(getattr(walls[name], "_examples", ()))]


@pytest.mark.parametrize("template", REGISTERED_HYPERELASTIC)
def test_scene_accepts_every_registered_hyperelastic_wall_as_a_template(template):
    sc = nd.scene(index=0.7, reduced_thickness=0.2, qbar=0.05, beta=0.4, wall=template)
    assert type(sc.wall) is type(template)
    assert sc.groups.beta == pytest.approx(0.4, rel=1e-9)
    assert sc.wall.small_strain_modulus(0.2) / template.small_strain_modulus(0.2) == pytest.approx(
        nd.beta(template, sc.tube, sc.pressure_scale) / 0.4, rel=1e-9)


def test_max_qbar_is_the_maximum_flow_rate():
    sc = nd.scene(index=0.7, reduced_thickness=0.3, qbar=0.1, gamma=3.0)
    qmax = sc.max_qbar()
    assert 0.1 < qmax < math.inf
    with pytest.raises(tubefsi.NoSteadyStateError):
        nd.scene(index=0.7, reduced_thickness=0.3, qbar=1.001 * qmax, gamma=3.0).pressure_drop()
    assert nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.1, gamma=3.0).max_qbar() == math.inf


# ------------------------------------------------------------------------------ errors
@pytest.mark.parametrize(("kwargs", "parameter"), [
    (dict(gamma=1.0, beta=1.0), "gamma / beta"),
    (dict(), "gamma / beta"),
    (dict(gamma=-1.0), "gamma"),
    (dict(beta=math.nan), "beta"),
    (dict(gamma=1.0, index=0.0), "index"),
    (dict(gamma=1.0, reduced_thickness=-0.1), "reduced_thickness"),
    (dict(gamma=1.0, qbar=-0.2), "qbar"),
    (dict(gamma=1.0, wall="no-such-wall"), "wall"),
])
def test_scene_rejects_bad_groups(kwargs, parameter):
    args = dict(index=0.7, reduced_thickness=0.3, qbar=0.5) | kwargs
    with pytest.raises(tubefsi.InvalidParameterError) as err:
        nd.scene(**args)
    assert err.value.parameter == parameter


def test_rigid_scene_needs_no_fsi_parameter():
    sc = nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.5, wall="rigid")
    assert sc.pressure_drop() == pytest.approx(2 * 4 * 0.5, rel=1e-13)     # 2 (3+1/n) qbar
    with pytest.raises(tubefsi.InvalidParameterError):
        nd.scene(index=1.0, reduced_thickness=0.3, qbar=0.5, wall="rigid", gamma=1.0)


class _NotAPowerLaw(Rheology):
    def _stress(self, shear_rate):
        return shear_rate + shear_rate**2


def test_scales_need_a_power_law_fluid():
    with pytest.raises(tubefsi.InvalidParameterError) as err:
        nd.pressure_scale(_NotAPowerLaw(), TUBE, flow_rate=1e-9)
    assert err.value.parameter == "rheology"


def test_pressure_scale_needs_exactly_one_load():
    with pytest.raises(tubefsi.InvalidParameterError):
        nd.pressure_scale(power_law(0.7), TUBE)
    with pytest.raises(tubefsi.InvalidParameterError):
        nd.pressure_scale(power_law(0.7), TUBE, flow_rate=1e-9, pressure_drop=10.0)
    with pytest.raises(tubefsi.InvalidParameterError):
        nd.groups(power_law(0.7), "rigid", TUBE, flow_rate=-1e-9)
