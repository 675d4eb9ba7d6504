"""Each wall against an independent mpmath computation (``tubefsi.testing.reference``, 30 digits).

The reference walls are ``tubefsi.testing.reference.tube_laws.RefWall`` of materials written as
their three-dimensional strain energies (``docs/theory.md``, section "Tube laws"); the flow is
separated as in ``tubefsi.testing.reference.power_law`` (section "Coupling without an ODE").

* the hand-written plane-strain derivatives of the reference against ``mpmath.diff`` of the
  three-dimensional strain energies;
* the tube laws P(lam) and their slopes, every theory, near the Gent lock too;
* the limit points (first pressure peak) of the Ogden and Yeoh examples, and the maximum flow
  rate they imply;
* whole solves of a power-law fluid: in a thick Gent tube (the issue's acceptance scene, 1e-10,
  from small strain to within 1e-4 of the lock), a thick Demiray, a thick Ogden and a thin Yeoh
  tube; flow-controlled against the reference, pressure-controlled back to the same flow rate.
"""

import math

import numpy as np

import pytest
from mpmath import mp, mpf

import tubefsi
from tubefsi.registry import rheologies, walls
from tubefsi.testing.reference import rel_err
from tubefsi.testing.reference import tube_laws as ref
from tubefsi.testing.reference.power_law import inlet_stretch, ref_J_direct, ref_phi, ref_phi_inverse

DPS = 30
TOL = 1e-10


@pytest.fixture(autouse=True, scope="module")
def _precision():
    with mp.workdps(DPS):
        yield


def material(wall):
    """The reference material of a tubefsi wall, from its parameters."""
    name = type(wall).__name__.replace("Thin", "").replace("Thick", "")
    if name == "Gent":
        mat = ref.Gent(wall.shear_modulus, wall.locking_parameter)
    elif name == "Demiray":
        mat = ref.Demiray(wall.shear_modulus, wall.stiffening)
    elif name == "Yeoh":
        mat = ref.Yeoh(wall.c1, wall.c2, wall.c3)
    else:
        mat = ref.Ogden(wall.moduli, wall.exponents)
    # under an axial stretch: the installed law from the 3-D energy (hand-derived dW_axial)
    return mat if wall.axial_stretch == 1 else ref.Installed(mat, wall.axial_stretch)


def theory(wall):
    """The reference wall's kind: "thick", "thin-reference" or "thin-current"."""
    convention = getattr(wall, "thickness_convention", None)
    return "thick" if convention is None else f"thin-{convention}"


NAMES = ["thin-gent", "thick-gent", "thin-demiray", "thick-demiray", "thin-ogden", "thick-ogden", "thin-yeoh", "thick-yeoh"]
WALLS = [walls[n](**kw) for n in NAMES for kw in walls[n]._examples]


@pytest.mark.parametrize("mat", [ref.Gent(2e3, 3.0), ref.Demiray(2e3, 0.7), ref.Yeoh(1e3, -120, 8),
                                 ref.Ogden((2008.5, 14.75, 49.05), (1.3, 5.0, -2.0))], ids=repr)
def test_reference_derivatives_match_the_strain_energy(mat):
    w_hat = lambda s: mat.W(1 / s, s, mpf(1))
    for s in (mpf("1.001"), mpf("1.4"), mpf("2.1")):
        assert rel_err(mat.dW(s), mp.diff(w_hat, s)) < mpf(10) ** -20


@pytest.mark.parametrize("wall", WALLS, ids=repr)
def test_tube_law_and_slope(wall):
    mat = material(wall)
    for tb in (0.05, 0.5, 2.0):
        law = ref.RefWall(theory(wall), mat, tb)
        top = wall.max_stretch(tb)
        for e in (1e-6, 1e-2, 0.4, 1.5):
            lam = 1 + min(e, 0.9 * (top - 1))
            assert rel_err(wall.pressure(lam, tb), law.P(lam)) < 1e-12, (tb, lam)
            assert rel_err(wall.stiffness(lam, tb), law.dP(lam)) < 1e-10, (tb, lam)


@pytest.mark.parametrize("convention", ["reference", "current", "thick"])
def test_gent_near_the_lock(convention):
    jm = 3.0
    wall = (walls["thick-gent"](shear_modulus=2e3, locking_parameter=jm) if convention == "thick" else
            walls["thin-gent"](shear_modulus=2e3, locking_parameter=jm, thickness_convention=convention))
    law = ref.RefWall("thick" if convention == "thick" else f"thin-{convention}", ref.Gent(2e3, jm), 0.4)
    lock = law.material.lock
    for gap in (1e-3, 1e-7, 1e-11):
        lam = float(lock * (1 - mpf(gap)))
        p, p_ref = wall.pressure(lam, 0.4), law.P(lam)
        # condition number of P at lam: lam P'/P (the float stretch is exact; the lock is rounded)
        cond = float(lam * law.dP(lam) / p_ref) * 1e-16 / gap
        assert rel_err(p, p_ref) < 1e-12 + 4 * cond, gap
        assert rel_err(wall.stretch(float(p_ref), 0.4), lam) < 1e-14 + 1e-16 / gap


def _peak(law, guess):
    return mp.findroot(law.dP, mpf(guess))


@pytest.mark.parametrize("wall", [w for w in WALLS if math.isfinite(w.limit_pressure(0.3))
                                  and type(w).__name__ not in ("ThickDemiray", "ThinDemiray")], ids=repr)
def test_limit_points(wall):
    mat = material(wall)
    for tb in (0.05, 0.3, 2.0):
        top = wall.max_stretch(tb)
        law = ref.RefWall(theory(wall), mat, tb)
        if math.isfinite(top):      # a first pressure peak: P'(top) = 0, limit = P(top)
            peak = _peak(law, top)
            assert rel_err(top, peak) < 1e-12
            assert rel_err(wall.limit_pressure(tb), law.P(peak)) < 1e-12
        else:                       # an asymptote as lam -> inf
            assert rel_err(wall.limit_pressure(tb), law.P(mpf(10) ** 8)) < 1e-12


# ---------------------------------------------------------------- solves
TUBE = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
M, N = 0.017, 0.7
K = 3 * N + 1


def _check_flow_controlled(wall, flow_rates, tol=TOL):
    a, L, tb = TUBE.radius, TUBE.length, TUBE.reduced_thickness
    law = ref.RefWall(theory(wall), material(wall), tb)
    sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=flow_rates)
    out = []
    for i, q in enumerate(flow_rates):
        target = mpf(L) * ref_phi(q, N, M) / mpf(a) ** K
        lam = inlet_stretch(law, target, K, 1 + sol.inlet_displacement[i] / a)
        dp = law.P(lam)
        err = (rel_err(sol.pressure_drop[i], dp), rel_err(sol.inlet_displacement[i], (lam - 1) * a))
        assert max(err) < tol, (q, err)
        back = tubefsi.solve(FLUID, wall, TUBE, pressure_drop=float(dp))
        assert rel_err(back.flow_rate, q) < tol
        out.append((float(lam), float(max(err))))
    return out


def test_power_law_in_a_thick_gent_tube():
    """The acceptance scene: default solve within 1e-10 of the reference, up to 1e-4 of the lock."""
    wall = walls["thick-gent"](shear_modulus=2e3, locking_parameter=3.0)
    lock = wall.max_stretch(0.5)
    result = _check_flow_controlled(wall, [1e-11, 1e-9, 1e-7, 1e-6])
    assert result[0][0] - 1 < 0.02 and lock - result[-1][0] < 2e-4


def test_power_law_in_a_thick_fung_tube():
    """Exponential stiffening: the quadrature narrows its panels where the integrand grows fast."""
    _check_flow_controlled(walls["thick-demiray"](shear_modulus=2e3, stiffening=0.7), [1e-9, 1e-7, 1e-5])


def test_power_law_in_a_thick_ogden_tube_and_its_maximum_flow_rate():
    wall = walls["thick-ogden"](moduli=(2008.5, 14.75, 49.05), exponents=(1.3, 5.0, -2.0))
    tb = TUBE.reduced_thickness
    q_max = tubefsi.max_flow_rate(FLUID, wall, TUBE)
    law = ref.RefWall("thick", material(wall), tb)
    peak = _peak(law, wall.max_stretch(tb))
    q_ref = ref_phi_inverse(ref_J_direct(law, peak, K) * mpf(TUBE.radius) ** K / mpf(TUBE.length), N, M)
    assert rel_err(q_max, q_ref) < TOL
    _check_flow_controlled(wall, [0.01 * q_max, 0.5 * q_max])
    with pytest.raises(tubefsi.NoSteadyStateError) as info:
        tubefsi.solve(FLUID, wall, TUBE, flow_rate=1.001 * q_max)
    assert info.value.limit == pytest.approx(q_max)
    with pytest.raises(tubefsi.NoSteadyStateError):
        tubefsi.solve(FLUID, wall, TUBE, pressure_drop=wall.limit_pressure(tb))


def test_power_law_in_a_thin_yeoh_tube():
    _check_flow_controlled(walls["thin-yeoh"](c1=1e3, c2=50.0, c3=2.0), [1e-10, 1e-8, 3e-7])


def test_a_thick_gent_tube_near_its_lock_meets_the_contract_or_says_so():
    """Toward the locking stretch the tube law is so steep that the rounding of the inlet stretch
    moves the pressure drop by more than the contract allows (the problem itself stays well
    conditioned in q): every answer is within 1e-12 max(1, kappa) of the mpmath reference
    (kappa = d ln dp / d ln q by central differences of solves) or comes with an AccuracyWarning;
    at least one point of the sweep is close enough to need the warning, and one far enough not to."""
    import warnings

    wall = walls["thick-gent"](shear_modulus=2e3, locking_parameter=3.0)
    a, L, tb = TUBE.radius, TUBE.length, TUBE.reduced_thickness
    law = ref.RefWall("thick", material(wall), tb)
    outcomes = []
    for q in (1e-7, 1e-6, 2e-6, 3e-6):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q)
        warned = any(issubclass(w.category, tubefsi.AccuracyWarning) for w in caught)
        h = 1e-5
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            up, down = (tubefsi.solve(FLUID, wall, TUBE, flow_rate=q * (1 + s * h)).pressure_drop for s in (1, -1))
        kappa = abs(math.log(up / down)) / (2 * h)
        target = mpf(L) * ref_phi(q, N, M) / mpf(a) ** K
        lam = inlet_stretch(law, target, K, 1 + sol.inlet_displacement / a)
        err = rel_err(sol.pressure_drop, law.P(lam))
        assert err <= 1e-12 * max(1.0, kappa) or warned, (q, err, kappa)
        outcomes.append(warned)
    assert outcomes[0] is False and any(outcomes)


@pytest.mark.parametrize("name", ["thick-demiray", "thin-demiray"])
def test_fung_profiles_end_at_the_outlet_state(name):
    """With an outlet pressure, the profiles end where the tube law puts the outlet: p(L) = p_out
    exactly and R(L) = a lambda(p_out), against the mpmath inverse of the tube law (the outlet is not
    interpolated: a profile at z = L is the outlet state itself)."""
    from tubefsi.testing.reference.tube_laws import stretch_at_pressure

    wall = walls[name](shear_modulus=1e3, stiffening=20.0)
    law = ref.RefWall(theory(wall), material(wall), TUBE.reduced_thickness)
    for p_out in (0.0, 50.0, 500.0):
        lam_out = stretch_at_pressure(law, mpf(p_out)) if p_out else mpf(1)
        for q in (1e-9, 3e-8, np.array([1e-9, 1e-8, 3e-8]), np.geomspace(1e-10, 3e-8, 100)):
            sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=q, outlet_pressure=p_out)
            length = np.full(np.shape(q), TUBE.length)
            assert np.all(np.asarray(sol.pressure(length)) == p_out)
            for r in np.ravel(sol.radius(length)):
                assert rel_err(r, mpf(TUBE.radius) * lam_out) < 1e-14
