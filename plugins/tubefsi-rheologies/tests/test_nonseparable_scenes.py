"""Many non-separable fluids in one call (issue 26), against independent mpmath solves.

Every plugin fluid, its parameters given as arrays (several fluids broadcast in one
``tubefsi.solve``, the Monte Carlo call shape, served by the flow maps of
``tubefsi.rheology.flow_map`` without a table per fluid), flow-controlled in a thick
neo-Hookean wall and in a stiff thin linear wall, each point against
``tubefsi.testing.reference.rheology.solve_flow_controlled`` (30 digits, the separated identity
integrated over the wall shear rate or stress, written from docs/theory.md; nothing of tubefsi).
The contract: 1e-12 relative (these problems' condition numbers are below 1).
"""

import numpy as np
import pytest
from mpmath import mp, mpf

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference.rheology import (CarreauYasudaRef, RateLawRef, section, solve_flow_controlled,
                                                solve_pressure_controlled, velocity)
from tubefsi.testing.reference.tube_laws import Linear, NeoHookean, RefWall, stretch_at_pressure

TOL = 1e-12


@pytest.fixture(autouse=True, scope="module")
def _precision():
    with mp.workdps(30):
        yield


class CrossRef(CarreauYasudaRef):
    """The Cross law and its slope, written afresh: tau = x (e_inf + (e0 - e_inf) / (1 + (lam x)^m))."""

    def __init__(self, eta0, eta_inf, relaxation_time, exponent, m=24):
        super().__init__(eta0, eta_inf, relaxation_time, 1, 1, m)
        self.exponent = mpf(exponent)

    def tau(self, x):
        return x * (self.einf + (self.e0 - self.einf) / (1 + (self.lam * x) ** self.exponent))

    def dtau(self, x):
        y = (self.lam * x) ** self.exponent
        return self.einf + (self.e0 - self.einf) * (1 + (1 - self.exponent) * y) / (1 + y) ** 2


def _rate_ref(name, p):
    """The shear rate of a rate-natural law at stress t (mpmath), and its yield stress."""
    ty = mpf(p.get("yield_stress", 0))
    if name == "ellis":
        e0, half, a = (mpf(p[k]) for k in ("zero_shear_viscosity", "half_stress", "exponent"))
        return RateLawRef(lambda t: t / e0 * (1 + (t / half) ** (a - 1)))
    if name == "bingham":
        mu = mpf(p["plastic_viscosity"])
        return RateLawRef(lambda t: (t - ty) / mu if t > ty else mpf(0), ty)
    if name == "casson":
        mu = mpf(p["plastic_viscosity"])
        return RateLawRef(lambda t: (mp.sqrt(t) - mp.sqrt(ty)) ** 2 / mu if t > ty else mpf(0), ty)
    if name == "herschel-bulkley":
        k, n = mpf(p["consistency"]), mpf(p["index"])
        return RateLawRef(lambda t: ((t - ty) / k) ** (1 / n) if t > ty else mpf(0), ty)
    raise KeyError(name)


def _ref_fluid(name, p):
    if name in ("carreau-yasuda", "carreau"):
        return CarreauYasudaRef(p["zero_shear_viscosity"], p["infinite_shear_viscosity"], p["relaxation_time"],
                                p["index"], p.get("transition", 2))
    if name == "cross":
        return CrossRef(p["zero_shear_viscosity"], p["infinite_shear_viscosity"], p["relaxation_time"],
                        p["exponent"])
    return _rate_ref(name, p)


# two parameter sets per fluid (yield-stress fluids well above their yield pressure drop)
SETS = {
    "carreau-yasuda": [dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=3.313,
                            index=0.3568, transition=2.0),
                       dict(zero_shear_viscosity=0.022, infinite_shear_viscosity=0.0022, relaxation_time=0.110,
                            index=0.392, transition=0.644)],
    "carreau": [dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=3.313, index=0.3568),
                dict(zero_shear_viscosity=2.0, infinite_shear_viscosity=0.0, relaxation_time=10.0, index=0.5)],
    "cross": [dict(zero_shear_viscosity=0.056, infinite_shear_viscosity=0.00345, relaxation_time=1.007, exponent=1.028),
              dict(zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0, relaxation_time=0.5, exponent=0.6)],
    "ellis": [dict(zero_shear_viscosity=0.1, half_stress=1.0, exponent=2.5),
              dict(zero_shear_viscosity=0.056, half_stress=0.05, exponent=1.7)],
    "bingham": [dict(yield_stress=0.5, plastic_viscosity=0.01), dict(yield_stress=0.2, plastic_viscosity=0.05)],
    "casson": [dict(yield_stress=0.5, plastic_viscosity=0.01), dict(yield_stress=0.1, plastic_viscosity=0.004)],
    "herschel-bulkley": [dict(yield_stress=0.5, consistency=0.2, index=0.6),
                         dict(yield_stress=0.1, consistency=0.05, index=1.3)],
}
RADIUS, LENGTH = 5e-4, 2e-2
WALLS = {
    "thick neo-Hookean": (walls["thick-neo-hookean"](shear_modulus=5e3), 0.3,
                          RefWall("thick", NeoHookean(5e3), 0.3, closed_form=False), (1e-9, 3e-8)),
    "stiff thin linear": (walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5), 0.05,
                          RefWall("thin-linear", Linear(1e6, 0.5), 0.05), (3e-8, 1e-6)),
}


@pytest.mark.parametrize("wall_name", sorted(WALLS))
@pytest.mark.parametrize("name", sorted(SETS))
def test_fluids_as_arrays_against_mpmath(name, wall_name):
    wall, tb, ref_wall, flow_rates = WALLS[wall_name]
    sets = SETS[name]
    # every parameter set at both flow rates: four scenes in one broadcast call
    params = {k: np.array([s[k] for s in sets for _ in flow_rates], dtype=float) for k in sets[0]}
    q = np.array([f for _ in sets for f in flow_rates])
    tube = tubefsi.Tube(radius=RADIUS, thickness=tb * RADIUS, length=LENGTH)
    sol = tubefsi.solve(rheologies[name](**params), wall, tube, flow_rate=q)
    for i in range(q.size):
        p = {k: float(v[i]) for k, v in params.items()}
        dp, lam = solve_flow_controlled(_ref_fluid(name, p), ref_wall, RADIUS, LENGTH, q[i],
                                        1 + sol.inlet_displacement[i] / RADIUS)
        assert rel_err(sol.pressure_drop[i], dp) < TOL, (i, p)
        assert rel_err(sol.inlet_displacement[i], (lam - 1) * RADIUS) < TOL * max(1.0, float(lam / (lam - 1)) * 1e-3), (i, p)


def test_one_fluid_alone_and_in_a_batch_agree():
    """A scene solved alone (a scalar fluid) and among others (array parameters): the same route,
    the same answer to rounding."""
    sets = SETS["carreau-yasuda"]
    params = {k: np.array([s[k] for s in sets]) for k in sets[0]}
    tube = tubefsi.Tube(radius=RADIUS, thickness=0.3 * RADIUS, length=LENGTH)
    wall = WALLS["thick neo-Hookean"][0]
    batch = tubefsi.solve(rheologies["carreau-yasuda"](**params), wall, tube, flow_rate=[1e-8, 2e-8])
    for i, s in enumerate(sets):
        alone = tubefsi.solve(rheologies["carreau-yasuda"](**s), wall, tube, flow_rate=[1e-8, 2e-8][i])
        assert rel_err(alone.pressure_drop, batch.pressure_drop[i]) < 1e-14


def test_flow_map_vouches_on_the_newtonian_plateau():
    """A Carreau-Yasuda fluid far below its transition (lambda Gamma ~ 0.1-3: the law's Newtonian
    plateau, where the integrand of K grows e^4-fold over a panel of the map) is served by its
    flow map: the map vouches for the wall stress (it charged the rounding of a panel's top to its
    bottom node, refused such fluids, and left them to the much slower Newton route of the
    coupler), and the wall stress it gives has the apparent wall shear rate Gamma =
    (4/3)(g - K(g)/tau^3), K = int_0^g tau^3, by mpmath quadrature (30 digits) at the wall shear
    rate g where the reference law gives that stress."""
    from tubefsi.rheology import flow_map

    p = dict(zero_shear_viscosity=0.0930, infinite_shear_viscosity=0.00509, relaxation_time=0.104,
             index=0.556, transition=1.68)
    ref = CarreauYasudaRef(p["zero_shear_viscosity"], p["infinite_shear_viscosity"], p["relaxation_time"],
                           p["index"], p["transition"])
    rates = np.array([0.5, 1.0, 3.0, 10.0, 30.0])
    tau, ok = flow_map.wall_stress(rheologies["carreau-yasuda"](**p), rates)
    assert ok.all()
    for rate, t in zip(rates, tau):
        g = mp.findroot(lambda x: ref.tau(x) - mpf(float(t)), mpf(float(rate)))
        k = mp.quad(lambda s: ref.tau(s) ** 3, [0, g / 8, g / 2, g])
        gamma = mpf(4) / 3 * (g - k / ref.tau(g) ** 3)
        assert rel_err(rate, gamma) < 1e-14, (rate, float(gamma))


def test_flow_map_below_a_law_still_thinning_far_down():
    """A Carreau-Yasuda fluid at wall shear rates e^7-e^16 above its Newtonian plateau, index 0.25:
    tau^3 gamma_w falls by only e^-28 over the sixteen panels below the map's start, so K there
    cannot come from those panels and the bound below them; the map takes it from zero by the
    adaptive quadrature instead, and still vouches. Each wall stress against its apparent rate
    Gamma = (4/3)(g - K(g)/tau^3), K = int_0^g tau^3 by mpmath quadrature (30 digits, split at
    the decades from the plateau up), at the g where the reference law gives that stress."""
    from tubefsi.rheology import flow_map

    p = dict(zero_shear_viscosity=1.0, infinite_shear_viscosity=0.0, relaxation_time=1e3, index=0.25, transition=2.0)
    ref = CarreauYasudaRef(p["zero_shear_viscosity"], p["infinite_shear_viscosity"], p["relaxation_time"],
                           p["index"], p["transition"])
    for rates in (np.array([1e4]), np.array([1e6, 3e6, 1e7])):
        tau, ok = flow_map.wall_stress(rheologies["carreau-yasuda"](**p), rates)
        assert ok.all()
        for rate, t in zip(rates, tau):
            g = mp.findroot(lambda x: ref.tau(x) - mpf(float(t)), mpf(float(rate)))
            edges = [0] + [mpf(10) ** k for k in range(-5, int(mp.log10(g)) + 1)] + [g]
            k = mp.quad(lambda s: ref.tau(s) ** 3, edges)
            gamma = mpf(4) / 3 * (g - k / ref.tau(g) ** 3)
            assert rel_err(rate, gamma) < 1e-14, (rate, float(gamma))


@pytest.mark.parametrize("wall_name", sorted(WALLS))
def test_fresh_scalar_fluids_against_mpmath(wall_name):
    """The benchmark's call shape: one scalar solve per fluid, each with fresh Carreau-Yasuda
    parameters (zero-shear viscosity and relaxation time +-20 %, index +-10 % about blood's), a
    Python float flow rate; each pressure drop and inlet displacement against the mpmath
    reference, to the contract."""
    wall, tb, ref_wall, flow_rates = WALLS[wall_name]
    tube = tubefsi.Tube(radius=RADIUS, thickness=tb * RADIUS, length=LENGTH)
    rng = np.random.default_rng(26)
    base = SETS["carreau-yasuda"][0]
    for _ in range(3):
        p = dict(base, zero_shear_viscosity=base["zero_shear_viscosity"] * rng.uniform(0.8, 1.2),
                 relaxation_time=base["relaxation_time"] * rng.uniform(0.8, 1.2), index=base["index"] * rng.uniform(0.9, 1.1))
        q = float(rng.uniform(*flow_rates))
        sol = tubefsi.solve(rheologies["carreau-yasuda"](**p), wall, tube, flow_rate=q)
        dp, lam = solve_flow_controlled(_ref_fluid("carreau-yasuda", p), ref_wall, RADIUS, LENGTH, q,
                                        1 + sol.inlet_displacement / RADIUS)
        assert rel_err(sol.pressure_drop, dp) < TOL, p
        assert rel_err(sol.inlet_displacement, (lam - 1) * RADIUS) < TOL * max(1.0, float(lam / (lam - 1)) * 1e-3), p


# loaded outlets: the fluid's outlet pressure and the external pressure (transmural 400 Pa)
OUTLET, EXTERNAL = 300.0, -100.0


def _loaded_round_trip(name, wall_name, sets):
    """Flow-controlled at loaded outlets, then pressure-controlled at the pressure drops found,
    each point against the mpmath references (the outlet at the reference wall's stretch under the
    transmural outlet pressure, the inlet at the stretch under that plus the pressure drop)."""
    wall, tb, ref_wall, flow_rates = WALLS[wall_name]
    params = {k: np.array([s[k] for s in sets], dtype=float) for k in sets[0]}
    q = np.array(flow_rates[-1:] * len(sets))
    tube = tubefsi.Tube(radius=RADIUS, thickness=tb * RADIUS, length=LENGTH)
    fluid = rheologies[name](**params) if len(sets) > 1 else rheologies[name](**sets[0])
    sol = tubefsi.solve(fluid, wall, tube, flow_rate=q if len(sets) > 1 else float(q[0]),
                        outlet_pressure=OUTLET, external_pressure=EXTERNAL)
    back = tubefsi.solve(fluid, wall, tube, pressure_drop=sol.pressure_drop,
                         outlet_pressure=OUTLET, external_pressure=EXTERNAL)
    transmural = mpf(OUTLET) - mpf(EXTERNAL)
    lam_out = stretch_at_pressure(ref_wall, transmural)
    dps, qs = np.atleast_1d(sol.pressure_drop), np.atleast_1d(back.flow_rate)
    for i, s in enumerate(sets):
        ref = _ref_fluid(name, s)
        dp, _ = solve_flow_controlled(ref, ref_wall, RADIUS, LENGTH, q[i],
                                      1 + np.atleast_1d(sol.inlet_displacement)[i] / RADIUS, outlet_stretch=lam_out)
        assert rel_err(dps[i], dp) < TOL, ("flow-controlled", i, s)
        lam_in = stretch_at_pressure(ref_wall, transmural + mpf(float(dps[i])))
        flow = solve_pressure_controlled(ref, ref_wall, RADIUS, LENGTH, lam_in, lam_out, q[i] * 1.001)
        assert rel_err(qs[i], flow) < TOL, ("pressure-controlled", i, s)


@pytest.mark.parametrize("name, wall_name, count", [
    ("carreau-yasuda", "thick neo-Hookean", 1), ("cross", "stiff thin linear", 1),
    ("ellis", "thick neo-Hookean", 1), ("herschel-bulkley", "stiff thin linear", 2),
])
def test_loaded_outlets_flow_and_pressure_controlled_against_mpmath(name, wall_name, count):
    """Issue 26's contract at loaded outlets (outlet 300 Pa, external -100 Pa), flow- and
    pressure-controlled, a fluid of arrays (two parameter sets in one call) or of scalars: the
    pressure drop of the flow-controlled solve against
    ``tubefsi.testing.reference.rheology.solve_flow_controlled`` (the outlet at the reference
    wall's stretch under 400 Pa), and the flow rate of the pressure-controlled solve at that drop
    against ``solve_pressure_controlled`` (secant steps in ln q on the same identity, from 1.001
    times the flow rate the drop came from), both to 1e-12 (the problems' condition numbers are
    below 1). The pressure-controlled solve goes through the flow map, with no flow table."""
    tubefsi.cache_clear()
    _loaded_round_trip(name, wall_name, SETS[name][:count])
    assert tubefsi.cache_info().size == 0


@pytest.mark.slow
@pytest.mark.parametrize("wall_name", sorted(WALLS))
@pytest.mark.parametrize("name", sorted(SETS))
def test_every_fluid_at_loaded_outlets_against_mpmath(name, wall_name):
    """As above, every plugin fluid, both parameter sets, both walls."""
    _loaded_round_trip(name, wall_name, SETS[name])


@pytest.mark.parametrize("name, wall_name", [
    ("carreau-yasuda", "thick neo-Hookean"), ("ellis", "stiff thin linear"), ("herschel-bulkley", "thick neo-Hookean"),
])
def test_profiles_against_mpmath(name, wall_name):
    """The fields along the tube of a non-separable fluid (two parameter sets in one call): at two
    sections, the pressure, the radius and the wall shear stress against
    ``tubefsi.testing.reference.rheology.section`` (the section's wall parameter x by Newton's
    method on the separated identity from x to the outlet, 30 digits: R = a lambda(x), p = P(lambda),
    tau_w = tau(x)), the velocity at half the radius (a law given by its shear rate) against
    ``reference.rheology.velocity`` (mpmath.quad of the shear rate over the yielded annulus), and
    the plug radius against its closed form R tau_y / tau_w (0 without a yield stress); all to
    1e-12 (these fields' condition numbers are below 1/n, n >= 0.36)."""
    wall, tb, ref_wall, flow_rates = WALLS[wall_name]
    sets = SETS[name]
    params = {k: np.array([s[k] for s in sets], dtype=float) for k in sets[0]}
    q = np.array([flow_rates[-1]] * len(sets))
    tube = tubefsi.Tube(radius=RADIUS, thickness=tb * RADIUS, length=LENGTH)
    sol = tubefsi.solve(rheologies[name](**params), wall, tube, flow_rate=q)
    z = np.array([0.25, 0.6])[:, None] * LENGTH                       # (2 sections, 2 fluids)
    pressure, radius, stress = sol.pressure(z), sol.radius(z), sol.wall_shear_stress(z)
    plug = sol.plug_radius(z)
    r = 0.5 * radius
    speed = sol.velocity(r, z) if name != "carreau-yasuda" else None
    for k in range(z.shape[0]):
        for i, s in enumerate(sets):
            ref = _ref_fluid(name, s)
            x, lam = section(ref, ref_wall, RADIUS, LENGTH - z[k, 0], q[i], radius[k, i] / RADIUS)
            big_r, tau_w = RADIUS * lam, ref.stress(x)
            assert rel_err(pressure[k, i], ref_wall.P(lam)) < TOL, ("pressure", k, i)
            assert rel_err(radius[k, i], big_r) < TOL, ("radius", k, i)
            assert rel_err(stress[k, i], tau_w) < TOL, ("wall shear stress", k, i)
            tau_y = mpf(s.get("yield_stress", 0))
            if tau_y > 0:
                assert rel_err(plug[k, i], big_r * tau_y / tau_w) < TOL, ("plug radius", k, i)
            else:
                assert plug[k, i] == 0.0
            if speed is not None:
                gradient = 2 * tau_w / big_r
                v = velocity(ref.rate, big_r, gradient, mpf(float(r[k, i])), tau_y)
                assert rel_err(speed[k, i], v) < TOL, ("velocity", k, i)


@pytest.mark.parametrize("name, wall_name", [("carreau-yasuda", "thick neo-Hookean"), ("cross", "stiff thin linear")])
def test_a_long_profile_against_mpmath(name, wall_name):
    """A profile at 400 sections of one tube (a fluid of scalar parameters, one flow rate): ln v as
    a function of ln(L - z) interpolated between direct solves (as a long flow curve is), the
    pressure and the radius at five sections, the outlet's last micrometre among them, against
    ``reference.rheology.section`` (30 digits) to the contract."""
    wall, tb, ref_wall, flow_rates = WALLS[wall_name]
    s = SETS[name][0]
    tube = tubefsi.Tube(radius=RADIUS, thickness=tb * RADIUS, length=LENGTH)
    sol = tubefsi.solve(rheologies[name](**s), wall, tube, flow_rate=flow_rates[-1])
    z = np.linspace(0.0, LENGTH * (1 - 5e-5), 400)
    pressure, radius = sol.pressure(z), sol.radius(z)
    ref = _ref_fluid(name, s)
    for k in (1, 133, 271, 398, 399):
        x, lam = section(ref, ref_wall, RADIUS, LENGTH - z[k], flow_rates[-1], radius[k] / RADIUS)
        assert rel_err(pressure[k], ref_wall.P(lam)) < TOL, ("pressure", k)
        assert rel_err(radius[k], RADIUS * lam) < TOL, ("radius", k)


# three random Carreau-Yasuda scenes of benchmarks/speed.py (seed 0) at large strain (inlet hoop
# strain 1.35, 1.81, 2.95) in thick neo-Hookean walls: (eta0, eta_inf, lambda, n, a, mu, radius,
# thickness, length, q)
LARGE_STRAIN = [
    (0.06228562484922824, 0.011811417837823164, 0.12236509909568986, 0.6149100451715732, 1.85576117174781,
     1146.7378611964014, 0.00012179159985095326, 6.0510938398440505e-05, 0.010103863953051833, 4.823559425592525e-10),
    (0.08089759185658386, 0.002462636390124906, 0.15985196636848195, 0.518027390312046, 1.9023791554311509,
     1340.7829292678678, 0.0001260104884431586, 1.4583000311635098e-05, 0.011897351743290523, 1.0281831808425217e-10),
    (0.03236596912494325, 0.005504441134756138, 0.9676216754179924, 0.7881752071246132, 1.6964361154515912,
     1479.375771007614, 5.071121856977281e-05, 1.5252768280626676e-05, 0.01419075052559373, 2.6170603208864123e-11),
]


def test_large_strain_scenes_against_mpmath():
    """Scenes whose separated integrand a degree-32 interpolant over the whole interval cannot
    resolve (its tail missed: they went to the slower Newton route, ~4 in 1000 random scenes) are
    solved on the interval cut into pieces; their pressure drops and inlet displacements against
    ``solve_flow_controlled`` (30 digits) to 1e-12 (condition numbers below 1). Pressure-controlled
    at those drops (the map's route: its bracket of q once fell short of the root at such strains,
    the inlet's rigid tube taken at the outlet's radius), the flow rates come back."""
    cols = list(zip(*LARGE_STRAIN))
    e0, einf, lam, n, tr, mu, a, t, length, q = (np.array(c) for c in cols)
    fluid = rheologies["carreau-yasuda"](zero_shear_viscosity=e0, infinite_shear_viscosity=einf,
                                         relaxation_time=lam, index=n, transition=tr)
    sol = tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=mu),
                        tubefsi.Tube(radius=a, thickness=t, length=length), flow_rate=q)
    for i, row in enumerate(LARGE_STRAIN):
        ref = CarreauYasudaRef(*row[:5])
        wall = RefWall("thick", NeoHookean(row[5]), mpf(row[7]) / mpf(row[6]))
        dp, stretch = solve_flow_controlled(ref, wall, row[6], row[8], row[9], 1 + sol.inlet_displacement[i] / row[6])
        assert rel_err(sol.pressure_drop[i], dp) < TOL, i
        assert rel_err(sol.inlet_displacement[i], (stretch - 1) * row[6]) < TOL, i
    # pressure-controlled at those (checked) pressure drops: the flow rates back, to 1e-12 times the
    # condition number d ln q / d ln dp (its inverse from the solution's own derivative)
    back = tubefsi.solve(fluid, walls["thick-neo-hookean"](shear_modulus=mu),
                         tubefsi.Tube(radius=a, thickness=t, length=length), pressure_drop=sol.pressure_drop)
    kappa = np.maximum(1.0, sol.pressure_drop / (q * sol.dpressure_drop_dflow_rate))
    assert np.all(np.abs(back.flow_rate / q - 1) < TOL * kappa)


def test_pressure_control_of_fluid_arrays_in_a_kinked_wall():
    """A thin HGO wall's slope kinks where its fibres engage, which the flow map's route leaves to
    the bracketed search of the error-controlled identity; with fluids given as arrays that search
    raised an IndexError (the law's generic inverse takes one fluid). Now the flow rates of the
    pressure drops that the flow-controlled solve (a different route: one batch per point) gives
    come back to 1e-13, a Carreau-Yasuda and a Herschel-Bulkley fluid of two parameter sets each."""
    from tubefsi.walls.hgo import ThinHGO

    wall = ThinHGO(shear_modulus=1e3, fibre_stiffness=5e3, fibre_exponent=2.0, fibre_angle=0.7,
                   thickness_convention="current")
    tube = tubefsi.Tube(radius=5e-4, thickness=5e-5, length=2e-2)
    q = np.array([1e-9, 2e-9])
    for name in ("carreau-yasuda", "herschel-bulkley"):
        params = {k: np.array([s[k] for s in SETS[name]], dtype=float) for k in SETS[name][0]}
        fluid = rheologies[name](**params)
        sol = tubefsi.solve(fluid, wall, tube, flow_rate=q)
        back = tubefsi.solve(fluid, wall, tube, pressure_drop=sol.pressure_drop)
        assert np.all(np.abs(back.flow_rate / q - 1) < 1e-13), name


def test_sensitivities_of_fluid_arrays():
    """The sensitivities of a solve of fluids given as arrays (their local flow index needs the law's
    inverse, which took one fluid: an IndexError) equal those of each fluid solved alone (a scalar
    fluid: the law's inverse of that fluid), to 1e-12."""
    sets = SETS["carreau-yasuda"]
    params = {k: np.array([s[k] for s in sets]) for k in sets[0]}
    tube = tubefsi.Tube(radius=RADIUS, thickness=0.3 * RADIUS, length=LENGTH)
    wall = WALLS["thick neo-Hookean"][0]
    q = [1e-8, 2e-8]
    batch = tubefsi.solve(rheologies["carreau-yasuda"](**params), wall, tube, flow_rate=q).dpressure_drop_dflow_rate
    for i, s in enumerate(sets):
        alone = tubefsi.solve(rheologies["carreau-yasuda"](**s), wall, tube, flow_rate=q[i]).dpressure_drop_dflow_rate
        assert abs(batch[i] / alone - 1) < 1e-12
