"""Each model against an independent mpmath computation (``tubefsi.testing.reference.rheology``, 30 digits).

* the tube flow function of every model against the Rabinowitsch–Mooney integral of its
  constitutive law written afresh (closed forms and the generic tabulated path alike);
* velocity profiles, plug included;
* whole solves in a thick neo-Hookean tube: the Carreau–Yasuda blood preset (the issue's
  acceptance scene, 1e-10), a Bingham and a Herschel–Bulkley fluid; flow-controlled against the
  reference, pressure-controlled back to the same flow rate;
* the yield pressure drop (q -> 0+) and zero flow below it.
"""

import math

import numpy as np
import pytest
from mpmath import mp, mpf

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference.rheology import (CarreauYasudaRef, RateLawRef, solve_flow_controlled, velocity,
                                                yield_pressure_drop)
from tubefsi.testing.reference.tube_laws import NeoHookean, RefWall
from tubefsi_rheologies import PRESETS, preset

DPS = 30
TOL = 1e-10          # the acceptance bound; the measured agreement is ~1e-15


@pytest.fixture(autouse=True, scope="module")
def _precision():
    with mp.workdps(DPS):
        yield


# ---------------------------------------------------------------- constitutive laws, written afresh
def _stress_law(name, p):
    """tau(rate) in mpmath for the stress-natural laws."""
    e0, einf = mpf(p.get("zero_shear_viscosity", 0)), mpf(p.get("infinite_shear_viscosity", 0))
    lam = mpf(p.get("relaxation_time", 1))
    if name == "carreau":
        n = mpf(p["index"])
        return lambda g: g * (einf + (e0 - einf) * (1 + (lam * g) ** 2) ** ((n - 1) / 2))
    if name == "carreau-yasuda":
        n, a = mpf(p["index"]), mpf(p["transition"])
        return lambda g: g * (einf + (e0 - einf) * (1 + (lam * g) ** a) ** ((n - 1) / a))
    if name == "cross":
        m = mpf(p["exponent"])
        return lambda g: g * (einf + (e0 - einf) / (1 + (lam * g) ** m))
    raise KeyError(name)


def _rate_law(name, p):
    """(shear_rate(tau), yield stress) in mpmath for the rate-natural laws."""
    if name == "ellis":
        e0, th, al = mpf(p["zero_shear_viscosity"]), mpf(p["half_stress"]), mpf(p["exponent"])
        return (lambda t: t / e0 * (1 + (t / th) ** (al - 1))), mpf(0)
    ty = mpf(p["yield_stress"])
    if name == "bingham":
        mu = mpf(p["plastic_viscosity"])
        return (lambda t: (t - ty) / mu if t > ty else mpf(0)), ty
    if name == "casson":
        mu = mpf(p["plastic_viscosity"])
        return (lambda t: (mp.sqrt(t) - mp.sqrt(ty)) ** 2 / mu if t > ty else mpf(0)), ty
    if name == "herschel-bulkley":
        k, n = mpf(p["consistency"]), mpf(p["index"])
        return (lambda t: ((t - ty) / k) ** (1 / n) if t > ty else mpf(0)), ty
    raise KeyError(name)


def _rate_from_stress(tau, t):
    """Invert tau(g) = t by bracketing in log g (mpmath)."""
    t = mpf(t)
    f = lambda lg: mp.log(tau(mp.exp(lg)) / t)
    return mp.exp(mp.findroot(f, (mpf(-80), mpf(80)), solver="illinois", tol=mpf(10) ** (-2 * mp.dps + 10)))


_LEVELS = (48, 36, 24, 16, 12, 8, 6, 4, 3, 2, 1, 0)     # break points x 2^-k toward the lower end


def ref_flow_rate(name, p, radius, gradient):
    r"""q = (pi R^3 / tau_w^3) int_0^tau_w tau^2 rate(tau) dtau, by mpmath.quad."""
    R, G = mpf(radius), mpf(gradient)
    tw = G * R / 2
    if name in ("carreau", "carreau-yasuda", "cross"):
        tau = _stress_law(name, p)
        # by parts in the shear rate: int_0^tau_w tau^2 rate dtau = tau_w^3 g_w / 3 - (1/3) int_0^g_w tau(g)^3 dg
        gw = _rate_from_stress(tau, tw)
        pts = [0] + [gw * mpf(2) ** -k for k in _LEVELS]
        integral = (tw**3 * gw - mp.quad(lambda g: tau(g) ** 3, pts)) / 3
    else:
        rate, ty = _rate_law(name, p)
        if tw <= ty:
            return mpf(0)
        pts = [ty + (tw - ty) * mpf(2) ** -k for k in _LEVELS]
        integral = mp.quad(lambda t: t * t * rate(t), [ty] + pts)
    return mp.pi * R**3 / tw**3 * integral


CASES = [(name, dict(kw)) for name in ["carreau", "carreau-yasuda", "cross", "ellis", "bingham", "casson",
                                      "herschel-bulkley"] for kw in rheologies[name]._examples]


@pytest.mark.parametrize("name, params", CASES, ids=[f"{n}-{i}" for i, (n, _) in enumerate(CASES)])
def test_flow_function_against_rabinowitsch_mooney(name, params):
    fluid = rheologies[name](**params)
    ty = params.get("yield_stress", 0.0)
    radius = 1e-4
    for wall_stress in (ty * 1.001 + 1e-4, 3 * ty + 1e-2, 3 * ty + 50.0):
        gradient = 2 * wall_stress / radius
        q = fluid.flow_rate(radius, gradient)
        ref = ref_flow_rate(name, params, radius, gradient)
        assert rel_err(q, ref) < 1e-12, (wall_stress, q, ref)
        assert rel_err(fluid.pressure_gradient(float(ref), radius), gradient) < 1e-12


@pytest.mark.parametrize("name", ["bingham", "casson", "herschel-bulkley", "ellis", "carreau-yasuda"])
def test_velocity_profile(name):
    params = dict(rheologies[name]._examples[0])
    fluid = rheologies[name](**params)
    radius = 1e-4
    ty = params.get("yield_stress", 0.0)
    gradient = 2 * (4 * ty + 1.0) / radius
    for frac in (0.0, 0.1, 0.2, 0.5, 0.9, 0.999):
        r = frac * radius
        if name == "carreau-yasuda":
            # by parts in the shear rate: v = (2/G) ([tau rate] - int tau(g) dg) between r and R
            tau = _stress_law(name, params)
            G = mpf(gradient)
            t_r, t_w = G * r / 2, G * radius / 2
            g_r = _rate_from_stress(tau, t_r) if r > 0 else mpf(0)
            g_w = _rate_from_stress(tau, t_w)
            ref = 2 / G * (t_w * g_w - t_r * g_r - mp.quad(tau, [g_r, g_w]))
        else:
            rate, _ = _rate_law(name, params)
            ref = velocity(rate, radius, gradient, r, ty)
        assert rel_err(fluid.velocity(r, radius, gradient), ref) < 1e-11, frac
    if ty > 0:
        r_plug = 2 * ty / gradient
        v = fluid.velocity(np.linspace(0, r_plug, 5), radius, gradient)
        assert np.all(v == v[0]) and v[0] > fluid.velocity(1.5 * r_plug, radius, gradient)


# ---------------------------------------------------------------- solves in a thick neo-Hookean tube
TUBE = tubefsi.Tube(radius=5e-4, thickness=1.5e-4, length=2e-2)
WALL = walls["thick-neo-hookean"](shear_modulus=5e3)
REF_WALL = RefWall("thick", NeoHookean(5e3), 0.3, closed_form=False)   # the Lamé integral, by quadrature


def _check_solve(fluid, ref_fluid, flow_rates):
    sol = tubefsi.solve(fluid, WALL, TUBE, flow_rate=flow_rates)
    assert sol.coupler_name == "quadrature"
    a = TUBE.radius
    for i, q in enumerate(flow_rates):
        dp, lam = solve_flow_controlled(ref_fluid, REF_WALL, a, TUBE.length, q, 1 + sol.inlet_displacement[i] / a)
        assert rel_err(sol.pressure_drop[i], dp) < TOL
        assert rel_err(sol.inlet_displacement[i], (lam - 1) * a) < TOL
        back = tubefsi.solve(fluid, WALL, TUBE, pressure_drop=float(dp))
        assert rel_err(back.flow_rate, q) < TOL


def test_carreau_yasuda_blood_in_a_thick_neo_hookean_tube():
    """The acceptance scene: default solve within 1e-10 of the reference (measured ~1e-15)."""
    fluid = preset("blood-carreau-yasuda")
    ref = CarreauYasudaRef(**{"eta0": 0.056, "eta_inf": 0.00345, "relaxation_time": 3.313, "index": 0.3568,
                              "transition": 2})
    _check_solve(fluid, ref, [1e-9, 3e-8])      # inlet strains ~2e-3 and ~0.03


def test_bingham_in_a_thick_neo_hookean_tube():
    fluid = rheologies["bingham"](yield_stress=0.5, plastic_viscosity=0.01)
    rate, ty = _rate_law("bingham", {"yield_stress": 0.5, "plastic_viscosity": 0.01})
    _check_solve(fluid, RateLawRef(rate, ty), [2e-9])


def test_herschel_bulkley_in_a_thick_neo_hookean_tube():
    params = {"yield_stress": 0.5, "consistency": 0.2, "index": 0.6}
    rate, ty = _rate_law("herschel-bulkley", params)
    _check_solve(rheologies["herschel-bulkley"](**params), RateLawRef(rate, ty), [2e-8])


def test_yield_pressure_drop_and_no_flow_below_it():
    fluid = rheologies["bingham"](yield_stress=0.5, plastic_viscosity=0.01)
    dp_yield = float(yield_pressure_drop(0.5, REF_WALL, TUBE.radius, TUBE.length))
    # q -> 0+: the pressure drop tends to the yield drop (excess ~ sqrt(q) for a Bingham fluid)
    tiny = tubefsi.solve(fluid, WALL, TUBE, flow_rate=[1e-16, 1e-40])
    assert tiny.pressure_drop[0] > dp_yield * (1 + 1e-9)
    assert rel_err(tiny.pressure_drop[1], dp_yield) < 1e-12
    assert tubefsi.solve(fluid, WALL, TUBE, flow_rate=0.0).pressure_drop == 0.0    # convention
    below = tubefsi.solve(fluid, WALL, TUBE, pressure_drop=[0.5 * dp_yield, dp_yield * (1 - 1e-9)])
    assert np.all(below.flow_rate == 0.0)
    above = tubefsi.solve(fluid, WALL, TUBE, pressure_drop=dp_yield * (1 + 1e-6))
    assert 0 < above.flow_rate < 1e-18
    # a rigid tube yields at the gradient 2 tau_y / a
    rigid = tubefsi.solve(fluid, "rigid", TUBE, pressure_drop=[0.99, 1.01] * np.array(2 * 0.5 * TUBE.length
                                                                                       / TUBE.radius))
    assert rigid.flow_rate[0] == 0.0 < rigid.flow_rate[1]


def test_velocity_field_has_a_plug():
    fluid = rheologies["herschel-bulkley"](yield_stress=0.5, consistency=0.2, index=0.6)
    sol = tubefsi.solve(fluid, WALL, TUBE, flow_rate=2e-8)
    z = 0.5 * TUBE.length
    big_r = sol.radius(z)
    g = fluid.pressure_gradient(2e-8, big_r)
    r_plug = 2 * 0.5 / g
    assert 0 < r_plug < big_r
    v = sol.velocity(np.linspace(0, 0.99 * r_plug, 4), z)
    np.testing.assert_allclose(v, v[0], rtol=1e-14)
    assert sol.velocity(big_r, z) == 0.0
    # the flux (Gauss-Legendre on the plug and on the yielded annulus) is the flow rate
    x, w = np.polynomial.legendre.leggauss(40)
    r = np.concatenate([r_plug * (x + 1) / 2, r_plug + (big_r - r_plug) * (x + 1) / 2])
    wt = np.concatenate([r_plug * w / 2, (big_r - r_plug) * w / 2])
    flux = np.sum(wt * 2 * math.pi * r * sol.velocity(r, z))
    assert flux == pytest.approx(2e-8, rel=1e-12)


def test_maximum_flow_rate_of_a_yield_stress_fluid():
    """A yield-stress fluid behaves like G = 2 tau_y / R far out: a finite maximum flow rate in a
    tube with a limit pressure; none at all if the yield drop exceeds the limit pressure."""
    fluid = rheologies["bingham"](yield_stress=0.5, plastic_viscosity=0.01)
    q_max = tubefsi.max_flow_rate(fluid, WALL, TUBE)
    assert 0 < q_max < math.inf
    tubefsi.solve(fluid, WALL, TUBE, flow_rate=0.99 * q_max)
    with pytest.raises(tubefsi.NoSteadyStateError):
        tubefsi.solve(fluid, WALL, TUBE, flow_rate=1.01 * q_max)
    stiff_fluid = rheologies["bingham"](yield_stress=500.0, plastic_viscosity=0.01)
    assert tubefsi.max_flow_rate(stiff_fluid, WALL, TUBE) == 0.0
    assert tubefsi.solve(stiff_fluid, WALL, TUBE, pressure_drop=0.9 * 5e3 * math.log1p(0.3)).flow_rate == 0.0


# ---------------------------------------------------------------- presets
@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_build_and_cite(name):
    entry = PRESETS[name]
    fluid = preset(name)
    assert rheologies.name_of(fluid) == entry.rheology
    assert len(entry.citation) > 40 and any(ch.isdigit() for ch in entry.citation)
    for key, value in entry.parameters.items():
        assert getattr(fluid, key) == value
    with pytest.raises(KeyError, match="not a preset"):
        preset("ketchup-nonexistent")
