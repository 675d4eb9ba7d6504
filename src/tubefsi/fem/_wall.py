r"""The tube wall as an axisymmetric, large-deformation, incompressible solid, with felupe.

The wall occupies :math:`0 \le Z \le L`, :math:`a \le R \le a + t` (felupe's axisymmetric
convention: first coordinate axial, second radial). Biquadratic quads (Q2, 9 nodes) with a
(u, p, J) three-field formulation (felupe's ``FieldsMixed`` + ``NearlyIncompressible``) and a
penalty bulk modulus ``bulk_ratio`` times the shear modulus. The material is felupe's own
3-D model of the wall's strain energy: ``NeoHooke(mu)`` for a neo-Hookean wall, the
tensortrax Mooney–Rivlin model ``(C10, C01) = (c1, c2)`` for a Mooney–Rivlin one. The plane-
strain tube laws use only :math:`\hat W(\lambda)`, which does not determine the 3-D energy
of other laws; those are refused (:func:`material`).

Ends: ``"clamped"`` (both displacement components zero on the end faces: the issue's
scene) or ``"sliding"`` (axial displacement zero, radial free: generalized plane strain at
axial stretch 1 everywhere, the exact tube law, used to verify the wall alone). The load is
a set of nodal forces on the inner-surface nodes (felupe's ``PointLoad``), the consistent
forces of the fluid's traction on the current configuration; Newton–Raphson (felupe)
converges the residual relative to the reactions to ``tol``.
"""

from __future__ import annotations

import attrs
import numpy as np

import felupe as fem
import felupe.constitution.tensortrax as ttx

from ..errors import ConvergenceError, InvalidParameterError
from ..walls.mooney_rivlin import MooneyRivlin
from ..walls.neo_hookean import NeoHookean

__all__ = ["AxisymmetricWall", "material"]


def material(wall):
    """felupe's 3-D isochoric model of ``wall``'s material, and its shear modulus (Pa)."""
    if any(np.size(getattr(wall, f.name)) != 1 for f in attrs.fields(type(wall))
           if isinstance(getattr(wall, f.name), (float, int, np.ndarray, list, tuple))):
        raise InvalidParameterError("wall", "a wall with scalar parameters", repr(wall),
                                    "tubefsi.fem solves one scene at a time")
    if getattr(wall, "axial_stretch", 1.0) != 1.0:
        raise InvalidParameterError("wall.axial_stretch", "{1} (tubefsi.fem clamps the tube at its "
                                    "stress-free length)", wall.axial_stretch)
    if isinstance(wall, NeoHookean):
        return fem.NeoHooke(mu=float(wall.shear_modulus)), float(wall.shear_modulus)
    if isinstance(wall, MooneyRivlin):
        model = ttx.Hyperelastic(ttx.models.hyperelastic.mooney_rivlin, C10=float(wall.c1), C01=float(wall.c2))
        return model, float(wall.shear_modulus)
    raise InvalidParameterError("wall", "a neo-Hookean or Mooney–Rivlin wall (thin or thick): walls "
                                "whose 3-D strain energy tubefsi.fem knows", type(wall).__name__,
                                "a plane-strain tube law fixes only W(1/lam, lam, 1), not the energy of "
                                "the axisymmetric deformation near the clamped ends")


def _check(n_displacement, length):
    """Converged when the residual is small relative to the reactions, or when it stalls at
    its round-off floor with a vanishing update (relative to the tube length)."""
    history = []

    def check(dx, x, f, xtol, ftol, dof1=None, dof0=None, items=None, eps=None):
        fnorm = np.linalg.norm(f[dof1]) / max(np.linalg.norm(f[dof0]), 1e-300)
        xnorm = np.linalg.norm(np.ravel(dx)[:n_displacement]) / length
        stalled = bool(history) and fnorm < 1e-6 and fnorm > 0.1 * history[-1] and xnorm < 1e-11
        history.append(fnorm)
        return xnorm, fnorm, bool(fnorm < ftol or stalled)

    return check


class AxisymmetricWall:
    """The wall's mesh (on the axial vertex grid ``z`` of the lumen), fields and solve."""

    def __init__(self, wall, radius, thickness, z, n_thickness, *, ends="clamped", bulk_ratio=1e7,
                 tol=1e-9, maxiter=30):
        umat, mu = material(wall)
        self.a, self.t, self.tol, self.maxiter = float(radius), float(thickness), tol, maxiter
        z = np.asarray(z, float)
        self.L = float(z[-1])
        m = fem.Rectangle(a=(0.0, 0.0), b=(1.0, 1.0), n=(len(z), n_thickness + 1))
        m.points[:, 0] = np.interp(m.points[:, 0], np.linspace(0.0, 1.0, len(z)), z)
        m.points[:, 1] = self.a + self.t * m.points[:, 1]
        m = m.add_midpoints_edges().add_midpoints_faces()
        self.mesh = m
        region = fem.RegionBiQuadraticQuad(m)
        self.field = fem.FieldsMixed(region, n=3, axisymmetric=True)
        self.u = self.field[0]
        self.solid = fem.SolidBody(fem.NearlyIncompressible(umat, bulk=bulk_ratio * mu), self.field)
        Z, R = m.points[:, 0], m.points[:, 1]
        inner = np.flatnonzero(np.isclose(R, self.a))
        self.inner = inner[np.argsort(Z[inner])]                       # one node per lumen line
        self.lines = Z[self.inner]
        end = np.isclose(Z, 0.0) | np.isclose(Z, self.L)
        if ends == "clamped":
            bounds = {"ends": fem.Boundary(self.u, mask=end)}
        elif ends == "sliding":
            bounds = {"ends": fem.Boundary(self.u, mask=end, skip=(0, 1))}   # u_z = 0, u_r free
        else:
            raise InvalidParameterError("ends", "{'clamped', 'sliding'}", ends)
        self.bounds = bounds
        self.dof0, self.dof1 = fem.dof.partition(self.field, bounds)
        self.ext0 = fem.dof.apply(self.field, bounds, self.dof0)
        self.applied = np.zeros((len(self.inner), 2))
        self.load = fem.PointLoad(self.field, self.inner, values=self.applied)
        self.iterations = []

    def solve(self, force):
        """Equilibrium under nodal forces ``force`` (N, total over the circumference) on the inner
        nodes, shape (lines, 2) as (radial, axial); returns the inner nodes' displacement,
        same shape and order."""
        target = np.column_stack([force[:, 1], force[:, 0]])           # felupe order (z, r)
        start, step = self.applied, 1.0
        done = 0.0
        while done < 1.0:                                              # bisect the load on failure
            trial = min(1.0, done + step)
            saved = [f.values.copy() for f in self.field.fields]
            self.load.update(start + trial * (target - start))
            try:
                res = fem.newtonraphson(items=[self.solid, self.load], x0=self.field, dof1=self.dof1,
                                        dof0=self.dof0, ext0=self.ext0, verbose=0, tol=self.tol,
                                        maxiter=self.maxiter, check=_check(self.u.values.size, self.L))
            except fem.NewtonConvergenceError as exc:
                for f, v in zip(self.field.fields, saved):
                    f.values[:] = v
                step *= 0.5
                if step < 1.0 / 64:
                    raise ConvergenceError("tubefsi.fem: the wall's Newton iteration did not converge "
                                           f"even in load steps of 1/64 ({exc})") from exc
                continue
            done = trial
            self.iterations.append(int(getattr(res, "iterations", -1)))
        self.applied = target
        d = self.u.values[self.inner]
        return np.column_stack([d[:, 1], d[:, 0]])
