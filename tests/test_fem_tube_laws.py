r"""An independent check of the tube laws: finite-element inflation of a plane-strain ring.

The tube laws of ``docs/theory.md``, section "Tube laws", are derived (the thick one from the
Lamé problem, the thin ones from membrane theory). Here felupe — a maintained hyperelastic finite-element library
(the ``verify`` extra) — solves the same boundary-value problem from the 3-D strain energy,
with none of tubefsi's reductions: a quarter ring :math:`a \le r \le a(1+\bar t)` in plane
strain, symmetry on both cut faces, the inner surface moved radially to the stretch
:math:`\lambda` (displacement control: robust up to large stretch and through a limit point),
a (u, p, J) three-field formulation for (near) incompressibility.

The pressure is read from the reaction forces by virtual work: with :math:`f_i` the internal
nodal forces of the inner nodes and :math:`g_i` the nodal forces of a *unit* follower
pressure on the deformed inner boundary (felupe's ``SolidBodyPressure``),
:math:`p = \sum_i f_i\cdot e_r(\theta_i) / \sum_i g_i\cdot e_r(\theta_i)`.

* Materials: felupe's built-in models where they exist (``NeoHooke``; Mooney–Rivlin needs
  ``tensortrax``, felupe's autodiff backend: skipped with a reason when it is missing), and
  for every registered thick hyperelastic wall — plugins included — a felupe material built
  from that wall's own reduced energy derivative ``_dW`` (:class:`ReducedEnergyMaterial`).
* Default mesh: biquadratic quads (Q2, 9 nodes) with a discontinuous bilinear pressure, 2
  elements through the wall and 8 around the quarter; the error is ~1e-6, the test bound 1e-3.
* Refinement: the error in the pressure falls as :math:`h^{2k}` (k = element order: a
  reaction force is a derivative of the energy, which converges at twice the order), i.e.
  ``h^2`` for Q1 and ``h^4`` for Q2. ``examples/fem_refinement.py`` runs the longer study.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import tubefsi
from tubefsi.walls.hyperelastic import ThickWall

fem = pytest.importorskip("felupe", reason="the FEM check needs the 'verify' extra (felupe)")

try:  # felupe's Mooney–Rivlin is a tensortrax (autodiff) model
    import felupe.constitution.tensortrax as _ttx

    _MOONEY_RIVLIN = _ttx.models.hyperelastic.mooney_rivlin
except (ImportError, AttributeError):  # pragma: no cover - depends on the environment
    _ttx = None
    _MOONEY_RIVLIN = None

walls = tubefsi.registry.walls

#: stretches of the inner surface at which the pressure is compared
STRETCHES = (1.01, 1.1, 1.5, 2.0, 3.0)
#: relative tolerance of the issue (the default mesh does ~1e-6)
TOLERANCE = 1e-3


# --------------------------------------------------------------------------------- materials
class ReducedEnergyMaterial:
    r"""A felupe material from a plane-strain reduced energy derivative :math:`\hat W'(\lambda)`.

    Every isotropic incompressible material in plane strain is determined by
    :math:`\hat W(\lambda) = W(1/\lambda, \lambda, 1)`: the in-plane principal stretches of any
    isochoric plane-strain deformation are :math:`(1/\lambda, \lambda)`, with
    :math:`\bar I_1 = \lambda^2 + \lambda^{-2} + 1`. So :math:`\psi = \Phi(\bar I_1)` with
    :math:`\Phi'(\bar I_1) = g = \hat W'(\lambda)/(2(\lambda - \lambda^{-3}))` reproduces the
    material exactly; the stress and tangent are those of felupe's isochoric neo-Hookean
    model (:math:`\psi_{NH} = (\bar I_1 - 3)/2`) rescaled:
    :math:`P = 2g\,P_{NH}`, :math:`\mathbb A = 4g'\,P_{NH}\otimes P_{NH} + 2g\,\mathbb A_{NH}`.
    """

    def __init__(self, wall):
        self.wall = wall
        self._nh = fem.NeoHooke(mu=1.0)          # isochoric part only (no bulk modulus)
        self.x = [np.eye(3), np.zeros(0)]

    # g = Phi'(I1bar) and its derivative, from the wall's dW (and d2W near lambda = 1)
    def _stretch(self, i1):
        c = np.maximum(i1 - 1.0, 2.0)           # lam^2 + lam^-2
        return np.sqrt(0.5 * (c + np.sqrt(np.maximum(c * c - 4.0, 0.0))))

    def g(self, i1):
        lam = self._stretch(i1)
        e = lam - 1.0
        small = np.abs(e) < 1e-5
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = self.wall._dW(lam) / (2.0 * (lam - lam**-3))
        limit = self.wall._d2W(lam) / (2.0 * (1.0 + 3.0 * lam**-4))   # l'Hopital, error O(e)
        return np.where(small, limit, ratio)

    def dg(self, i1, step=1e-6):
        return (self.g(i1 + step) - self.g(i1)) / step

    def _i1bar(self, F):
        J = np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1)))
        return np.einsum("ki...,ki...->...", F, F) * J ** (-2.0 / 3.0)

    def gradient(self, x):
        F, statevars = x[0], x[-1]
        P1 = self._nh.gradient([F, statevars])[0]       # d/dF (I1bar - 3)/2
        return [2.0 * self.g(self._i1bar(F)) * P1, statevars]

    def hessian(self, x):
        F, statevars = x[0], x[-1]
        i1 = self._i1bar(F)
        P1 = self._nh.gradient([F, statevars])[0]
        A1 = self._nh.hessian([F, statevars])[0]
        outer = np.einsum("ij...,kl...->ijkl...", P1, P1)
        return [4.0 * self.dg(i1) * outer + 2.0 * self.g(i1) * A1]


def builtin_material(wall):
    """felupe's own isochoric model of ``wall``'s material, or None if it has none here."""
    from tubefsi.walls.mooney_rivlin import MooneyRivlin
    from tubefsi.walls.neo_hookean import NeoHookean

    if isinstance(wall, NeoHookean):
        return fem.NeoHooke(mu=wall.shear_modulus)
    if isinstance(wall, MooneyRivlin):
        if _MOONEY_RIVLIN is None:
            pytest.skip("felupe's Mooney–Rivlin model needs tensortrax (felupe's autodiff backend): "
                        "add it to the 'verify' extra")
        return _ttx.Hyperelastic(_MOONEY_RIVLIN, C10=wall.c1, C01=wall.c2)
    raise TypeError(f"no felupe built-in for {type(wall).__name__}")


def tangent_shear_modulus(wall, stretch):
    """Largest small-strain-like modulus dW''/4 on [1, stretch]: sets the penalty bulk modulus."""
    lam = np.linspace(1.0, stretch, 64)
    return float(np.max(wall._d2W(lam))) / 4.0


# --------------------------------------------------------------------------------- the FE model
ELEMENTS = {  # order -> (cell construction, region, boundary region)
    1: ("quad", "RegionQuad", "RegionQuadBoundary"),
    2: ("quad9", "RegionBiQuadraticQuad", "RegionBiQuadraticQuadBoundary"),
}


def ring_mesh(tb, n_radial, n_hoop, order):
    """Quarter ring a = 1, polar-structured; quadratic nodes placed on the exact arcs."""
    m = fem.Rectangle(a=(1.0, 0.0), b=(1.0 + tb, 0.5 * math.pi), n=(n_radial + 1, n_hoop + 1))
    if order == 2:
        m = m.add_midpoints_edges().add_midpoints_faces()
    r, th = m.points[:, 0].copy(), m.points[:, 1].copy()
    points = np.column_stack([r * np.cos(th), r * np.sin(th)])
    return fem.Mesh(points, m.cells, m.cell_type), r, th


def _newton_check(n_displacement):
    """Converged when the residual is small relative to the reactions, or when it stalls at
    its round-off floor (which the penalty bulk modulus raises) with a vanishing update."""
    history = []

    def check(dx, x, f, xtol, ftol, dof1=None, dof0=None, items=None, eps=None):
        fnorm = np.linalg.norm(f[dof1]) / max(np.linalg.norm(f[dof0]), 1e-300)
        xnorm = np.linalg.norm(np.ravel(dx)[:n_displacement])       # ring radius a = 1
        stalled = bool(history) and fnorm < 1e-5 and fnorm > 0.1 * history[-1] and xnorm < 1e-9
        history.append(fnorm)
        return xnorm, fnorm, bool(fnorm < ftol or stalled)

    return check


def ring_pressure(material, tb, stretches, *, n_radial=2, n_hoop=8, order=2, bulk_ratio=1e8,
                  shear_modulus=1.0, tangent=None, steps=4):
    """Pressure (Pa) that holds the ring's inner surface at each stretch in ``stretches``.

    ``material`` is an isochoric felupe material; ``bulk_ratio * modulus`` the penalty bulk
    modulus, with ``modulus = tangent(stretch)`` if given (stiffening materials) else
    ``shear_modulus``. The load is ramped in ``steps`` increments between requested
    stretches, each halved on a Newton failure.
    """
    mesh, r, th = ring_mesh(tb, n_radial, n_hoop, order)
    _, region_name, boundary_name = ELEMENTS[order]
    region = getattr(fem, region_name)(mesh)
    field = fem.FieldsMixed(region, n=3, planestrain=True)
    u = field[0]
    umat = fem.NearlyIncompressible(material, bulk=bulk_ratio * shear_modulus)
    solid = fem.SolidBody(umat, field)

    inner = np.isclose(r, 1.0)
    X = mesh.points[inner]
    er = X / np.linalg.norm(X, axis=1, keepdims=True)
    bounds = {
        "symmetry-y": fem.Boundary(u, mask=np.isclose(th, 0.0), skip=(1, 0)),      # u_y = 0
        "symmetry-x": fem.Boundary(u, mask=np.isclose(th, 0.5 * math.pi), skip=(0, 1)),  # u_x = 0
        "inner": fem.Boundary(u, mask=inner, value=np.zeros_like(X)),
    }
    dof0, dof1 = fem.dof.partition(field, bounds)
    boundary = getattr(fem, boundary_name)(mesh, mask=inner, ensure_3d=True)
    boundary_field = fem.FieldContainer([fem.FieldPlaneStrain(boundary, dim=2)])
    unit_pressure = fem.SolidBodyPressure(boundary_field, pressure=1.0)

    def solve_at(stretch):
        if tangent is not None:
            umat.bulk = bulk_ratio * tangent(stretch)
        bounds["inner"].update((stretch - 1.0) * X)
        ext0 = fem.dof.apply(field, bounds, dof0)
        fem.newtonraphson(items=[solid], x0=field, dof1=dof1, dof0=dof0, ext0=ext0, verbose=0,
                          tol=1e-10, maxiter=25, check=_newton_check(u.values.size))

    pressures, current = [], 1.0
    for target in stretches:
        increments = list(np.linspace(current, target, steps + 1)[1:])
        while increments:
            s = increments[0]
            saved = [f.values.copy() for f in field.fields]
            try:
                solve_at(s)
            except fem.NewtonConvergenceError:
                for f, v in zip(field.fields, saved):
                    f.values[:] = v
                if s - current < 1e-4:
                    raise
                increments.insert(0, 0.5 * (current + s))
                continue
            current = increments.pop(0)
        f_int = solid.assemble.vector(field).toarray().ravel()[: u.values.size].reshape(-1, 2)
        boundary_field[0].values[:] = u.values
        f_unit = unit_pressure.assemble.vector(boundary_field).toarray().reshape(-1, 2)
        pressures.append(np.sum(f_int[inner] * er) / np.sum(f_unit[inner] * er))
    return np.array(pressures)


def test_stretches(wall, tb, *, stiffening=1e3):
    """STRETCHES up to 90 % of the way to the wall's maximum stretch (a lock or a limit point)
    and where its tangent modulus dW'' has grown less than ``stiffening``-fold, plus that cap."""
    cap = min(3.0, 1.0 + 0.9 * (wall.max_stretch(tb) - 1.0)) if math.isfinite(wall.max_stretch(tb)) else 3.0
    grid = np.linspace(1.0, cap, 400)
    grown = wall._d2W(grid) / wall._d2W(np.asarray(1.0))
    if np.any(grown > stiffening):
        cap = float(grid[np.argmax(grown > stiffening) - 1])
    picked = [s for s in STRETCHES if s <= cap]
    if cap < STRETCHES[-1] and (not picked or cap - picked[-1] > 0.05):
        picked.append(cap)
    return tuple(picked)


test_stretches.__test__ = False  # a helper, not a test


# --------------------------------------------------------------------------------- cases
def _thick_cases():
    cases = []
    for name in walls:
        cls = walls[name]
        # (the felupe material is the isotropic one of the wall's reduced energy)
        if (isinstance(cls, type) and issubclass(cls, ThickWall) and getattr(cls, "_examples", None)
                and getattr(cls, "isotropic", True)):
            cases += [pytest.param(name, kw, id=f"{name}-{i}") for i, kw in enumerate(cls._examples)]
    return cases


THICK_CASES = _thick_cases()


def _relative(fem_p, law_p):
    return np.abs(np.asarray(fem_p) / np.asarray(law_p) - 1.0)


@pytest.mark.parametrize(("name", "params"), THICK_CASES)
def test_thick_law_matches_fem_of_the_walls_own_energy(name, params):
    """Every registered thick hyperelastic wall: FEM of its own dW vs its thick tube law."""
    wall = walls[name](**params)
    tb = 0.3
    lam = test_stretches(wall, tb)
    mu = float(wall._d2W(np.asarray(1.0))) / 4.0
    # steep stress gradients where the material stiffens more than tenfold: a finer mesh
    fine = tangent_shear_modulus(wall, lam[-1]) > 10.0 * mu
    p_fem = ring_pressure(ReducedEnergyMaterial(wall), tb, lam, shear_modulus=mu,
                          tangent=lambda s: tangent_shear_modulus(wall, s),
                          n_radial=4 if fine else 2, n_hoop=16 if fine else 8)
    rel = _relative(p_fem, wall.pressure(np.array(lam), tb))
    assert np.all(rel < TOLERANCE), dict(zip(lam, rel))


BUILTIN_THICK = [pytest.param(name, kw, id=f"{name}-{i}")
                 for name in ("thick-neo-hookean", "thick-mooney-rivlin")
                 for i, kw in enumerate(walls[name]._examples)
                 if kw.get("axial_stretch", 1.0) == 1.0]      # felupe's plane-strain ring: no pre-stretch


@pytest.mark.parametrize("tb", [0.3, 1.0])
@pytest.mark.parametrize(("name", "params"), BUILTIN_THICK)
def test_thick_law_matches_fem_with_felupes_builtin_material(name, params, tb):
    """Neo-Hookean / Mooney–Rivlin: felupe's own 3-D model vs the closed-form thick law."""
    wall = walls[name](**params)
    material = builtin_material(wall)
    p_fem = ring_pressure(material, tb, STRETCHES, shear_modulus=wall.shear_modulus)
    rel = _relative(p_fem, wall.pressure(np.array(STRETCHES), tb))
    assert np.all(rel < TOLERANCE), dict(zip(STRETCHES, rel))


#: thin enough that the thin current-thickness law is within 1e-3 of the exact solution
THIN_TB = 2e-4

BUILTIN_THIN = [pytest.param("thin-neo-hookean", {"shear_modulus": 2e3}, id="neo-hookean"),
                pytest.param("thin-mooney-rivlin", {"c1": 1.5e3, "c2": -0.5e3}, id="mooney-rivlin-c2<0"),
                pytest.param("thin-mooney-rivlin", {"c1": 1e3, "c2": 0.2e3}, id="mooney-rivlin-c2>0")]


@pytest.fixture(scope="module")
def thin_ring_cache():
    return {}


def _thin_fem(cache, name, params):
    key = (name, tuple(sorted(params.items())))
    if key not in cache:
        wall = walls[name](**params)
        cache[key] = ring_pressure(builtin_material(wall), THIN_TB, STRETCHES, n_radial=1, n_hoop=8,
                                   shear_modulus=wall.shear_modulus)
    return cache[key]


@pytest.mark.parametrize(("name", "params"), BUILTIN_THIN)
def test_thin_current_thickness_law_matches_fem_of_a_thin_ring(name, params, thin_ring_cache):
    """At t/a = 2e-4 the exact (FEM) ring is the thin *current*-thickness law to 1e-3."""
    wall = walls[name](**params, thickness_convention="current")
    p_fem = _thin_fem(thin_ring_cache, name, params)
    rel = _relative(p_fem, wall.pressure(np.array(STRETCHES), THIN_TB))
    assert np.all(rel < TOLERANCE), dict(zip(STRETCHES, rel))


@pytest.mark.parametrize(("name", "params"), BUILTIN_THIN)
def test_thin_reference_thickness_law_is_off_by_the_stretch(name, params, thin_ring_cache):
    """The chapter's thin law (undeformed thickness) overestimates the exact ring by the
    factor lambda: 1 % at stretch 1.01, 200 % at stretch 3 (``docs/verification.md``, section
    "The chapter's printed inconsistencies", item 4)."""
    wall = walls[name](**params, thickness_convention="reference")
    lam = np.array(STRETCHES)
    p_fem = _thin_fem(thin_ring_cache, name, params)
    p_ref = wall.pressure(lam, THIN_TB)
    assert np.all(_relative(p_fem * lam, p_ref) < TOLERANCE)
    assert np.all(p_ref / p_fem - 1.0 > 0.9 * (lam - 1.0))


def test_reduced_energy_material_reproduces_felupes_neo_hooke():
    """The generic material (used for plugin walls) equals felupe's NeoHooke for a neo-Hookean dW."""
    wall = walls["thick-neo-hookean"](shear_modulus=2e3)
    rng = np.random.default_rng(1)
    F = np.eye(3)[:, :, None, None] + 0.2 * rng.standard_normal((3, 3, 4, 5))
    F[2, :2] = F[:2, 2] = 0.0
    F[2, 2] = 1.0
    ours, theirs = ReducedEnergyMaterial(wall), fem.NeoHooke(mu=2e3)
    x = [F, np.zeros((0, 4, 5))]
    np.testing.assert_allclose(ours.gradient(x)[0], theirs.gradient(x)[0], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ours.hessian(x)[0], theirs.hessian(x)[0], rtol=1e-6, atol=1e-6)


# --------------------------------------------------------------------------------- refinement
def _errors(order, levels, tb=0.3, stretches=(1.1, 1.5, 2.0, 3.0)):
    wall = walls["thick-neo-hookean"](shear_modulus=1.0)
    exact = wall.pressure(np.array(stretches), tb)
    return [float(np.max(_relative(ring_pressure(fem.NeoHooke(mu=1.0), tb, stretches, n_radial=nr,
                                                 n_hoop=nh, order=order), exact)))
            for nr, nh in levels]


@pytest.mark.parametrize(("order", "levels", "rate"), [(1, [(2, 8), (4, 16)], 2.0), (2, [(1, 4), (2, 8)], 4.0)],
                         ids=["Q1", "Q2"])
def test_error_falls_at_twice_the_element_order(order, levels, rate):
    """Halving h divides the pressure error by 2^(2k): rate 2 for Q1, 4 for Q2; the default
    mesh (Q2, 2 x 8) is within 1e-5 of the thick law (t/a = 0.3, stretches 1.1 to 3)."""
    coarse, fine = _errors(order, levels)
    observed = math.log2(coarse / fine)
    assert abs(observed - rate) < 0.3, (coarse, fine, observed)
    if order == 2:
        assert fine < 1e-5
