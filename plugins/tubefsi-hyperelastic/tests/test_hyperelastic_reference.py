"""Each wall against an independent mpmath computation (``_mp_wall_reference.py``, 30 digits).

* the hand-written plane-strain derivatives of the reference against ``mpmath.diff`` of the
  three-dimensional strain energies;
* the tube laws P(lam) and their slopes, every theory, near the Gent lock too;
* the limit points (first pressure peak) of the Ogden and Yeoh examples, and the maximum flow
  rate they imply;
* whole solves of a power-law fluid: in a thick Gent tube (the issue's acceptance scene, 1e-10,
  from small strain to within 1e-4 of the lock), a thick Fung, a thick Ogden and a thin Yeoh
  tube; flow-controlled against the reference, pressure-controlled back to the same flow rate.
"""

import math

import pytest
from mpmath import mp, mpf

import _mp_wall_reference as ref
import tubefsi
from tubefsi.registry import rheologies, walls

DPS = 30
TOL = 1e-10


@pytest.fixture(autouse=True, scope="module")
def _precision():
    with mp.workdps(DPS):
        yield


def rel(a, b):
    return abs(mpf(a) / mpf(b) - 1)


def material(wall):
    """The reference material of a tubefsi wall, from its parameters."""
    name = type(wall).__name__.replace("Thin", "").replace("Thick", "")
    if name == "Gent":
        return ref.Gent(wall.shear_modulus, wall.locking_parameter)
    if name == "Fung":
        return ref.Fung(wall.shear_modulus, wall.stiffening)
    if name == "Yeoh":
        return ref.Yeoh(wall.c1, wall.c2, wall.c3)
    return ref.Ogden(wall.moduli, wall.exponents)


def theory(wall):
    return getattr(wall, "thickness_convention", "thick")


NAMES = ["thin-gent", "thick-gent", "thin-fung", "thick-fung", "thin-ogden", "thick-ogden", "thin-yeoh", "thick-yeoh"]
WALLS = [walls[n](**kw) for n in NAMES for kw in walls[n]._examples]


@pytest.mark.parametrize("mat", [ref.Gent(2e3, 3.0), ref.Fung(2e3, 0.7), ref.Yeoh(1e3, -120, 8),
                                 ref.Ogden((2008.5, 14.75, 49.05), (1.3, 5.0, -2.0))], ids=repr)
def test_reference_derivatives_match_the_strain_energy(mat):
    w_hat = lambda s: mat.W(1 / s, s, mpf(1))
    for s in (mpf("1.001"), mpf("1.4"), mpf("2.1")):
        assert rel(mat.dW(s), mp.diff(w_hat, s)) < mpf(10) ** -20


@pytest.mark.parametrize("wall", WALLS, ids=repr)
def test_tube_law_and_slope(wall):
    mat = material(wall)
    for tb in (0.05, 0.5, 2.0):
        law = ref.TubeLaw(mat, theory(wall), tb)
        top = wall.max_stretch(tb)
        for e in (1e-6, 1e-2, 0.4, 1.5):
            lam = 1 + min(e, 0.9 * (top - 1))
            assert rel(wall.pressure(lam, tb), law.pressure(lam)) < 1e-12, (tb, lam)
            assert rel(wall.stiffness(lam, tb), law.slope(lam)) < 1e-10, (tb, lam)


@pytest.mark.parametrize("convention", ["reference", "current", "thick"])
def test_gent_near_the_lock(convention):
    jm = 3.0
    wall = (walls["thick-gent"](shear_modulus=2e3, locking_parameter=jm) if convention == "thick" else
            walls["thin-gent"](shear_modulus=2e3, locking_parameter=jm, thickness_convention=convention))
    law = ref.TubeLaw(ref.Gent(2e3, jm), convention, 0.4)
    lock = law.mat.lock
    for gap in (1e-3, 1e-7, 1e-11):
        lam = float(lock * (1 - mpf(gap)))
        p, p_ref = wall.pressure(lam, 0.4), law.pressure(lam)
        # condition number of P at lam: lam P'/P (the float stretch is exact; the lock is rounded)
        cond = float(lam * law.slope(lam) / p_ref) * 1e-16 / gap
        assert rel(p, p_ref) < 1e-12 + 4 * cond, gap
        assert rel(wall.stretch(float(p_ref), 0.4), lam) < 1e-14 + 1e-16 / gap


def _peak(law, guess):
    return mp.findroot(law.slope, mpf(guess))


@pytest.mark.parametrize("wall", [w for w in WALLS if math.isfinite(w.limit_pressure(0.3))
                                  and type(w).__name__ not in ("ThickFung", "ThinFung")], ids=repr)
def test_limit_points(wall):
    mat = material(wall)
    for tb in (0.05, 0.3, 2.0):
        top = wall.max_stretch(tb)
        law = ref.TubeLaw(mat, theory(wall), tb)
        if math.isfinite(top):      # a first pressure peak: P'(top) = 0, limit = P(top)
            peak = _peak(law, top)
            assert rel(top, peak) < 1e-12
            assert rel(wall.limit_pressure(tb), law.pressure(peak)) < 1e-12
        else:                       # an asymptote as lam -> inf
            assert rel(wall.limit_pressure(tb), law.pressure(mpf(10) ** 8)) < 1e-12


# ---------------------------------------------------------------- solves
TUBE = tubefsi.Tube(radius=1e-4, thickness=5e-5, length=1e-2)
FLUID = rheologies["power-law"](consistency=0.017, index=0.7)
M, N = 0.017, 0.7
K = 3 * N + 1


def _check_flow_controlled(wall, flow_rates, tol=TOL):
    a, L, tb = TUBE.radius, TUBE.length, TUBE.reduced_thickness
    law = ref.TubeLaw(material(wall), theory(wall), tb)
    sol = tubefsi.solve(FLUID, wall, TUBE, flow_rate=flow_rates)
    out = []
    for i, q in enumerate(flow_rates):
        target = mpf(L) * ref.phi(q, M, N) / mpf(a) ** K
        lam = ref.inlet_stretch(law, target, K, 1 + sol.inlet_displacement[i] / a)
        dp = law.pressure(lam)
        err = (rel(sol.pressure_drop[i], dp), rel(sol.inlet_displacement[i], (lam - 1) * a))
        assert max(err) < tol, (q, err)
        back = tubefsi.solve(FLUID, wall, TUBE, pressure_drop=float(dp))
        assert rel(back.flow_rate, q) < tol
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
    _check_flow_controlled(walls["thick-fung"](shear_modulus=2e3, stiffening=0.7), [1e-9, 1e-7, 1e-5])


def test_power_law_in_a_thick_ogden_tube_and_its_maximum_flow_rate():
    wall = walls["thick-ogden"](moduli=(2008.5, 14.75, 49.05), exponents=(1.3, 5.0, -2.0))
    tb = TUBE.reduced_thickness
    q_max = tubefsi.max_flow_rate(FLUID, wall, TUBE)
    law = ref.TubeLaw(material(wall), "thick", tb)
    peak = _peak(law, wall.max_stretch(tb))
    q_ref = ref.phi_inverse(ref.J(law, peak, K) * mpf(TUBE.radius) ** K / mpf(TUBE.length), M, N)
    assert rel(q_max, q_ref) < TOL
    _check_flow_controlled(wall, [0.01 * q_max, 0.5 * q_max])
    with pytest.raises(tubefsi.NoSteadyStateError) as info:
        tubefsi.solve(FLUID, wall, TUBE, flow_rate=1.001 * q_max)
    assert info.value.limit == pytest.approx(q_max)
    with pytest.raises(tubefsi.NoSteadyStateError):
        tubefsi.solve(FLUID, wall, TUBE, pressure_drop=wall.limit_pressure(tb))


def test_power_law_in_a_thin_yeoh_tube():
    _check_flow_controlled(walls["thin-yeoh"](c1=1e3, c2=50.0, c3=2.0), [1e-10, 1e-8, 3e-7])
