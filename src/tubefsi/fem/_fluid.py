r"""Axisymmetric generalized Newtonian Stokes flow in the deformed lumen, with scikit-fem.

Unknowns: velocity :math:`(u_r, u_z)` in biquadratic Lagrange elements (Q2) and pressure in
bilinear ones (Q1): the Taylor–Hood pair, inf-sup stable. With the rate of strain
:math:`D` (hoop component :math:`u_r/r`), the shear rate :math:`\dot\gamma = \sqrt{2 D:D}` and
the viscosity :math:`\eta(\dot\gamma) = \tau(\dot\gamma)/\dot\gamma` of the rheology, the weak form
per radian is

.. math::

    \int 2\eta\,D(u):D(v)\,r\,dA - \int p\,\nabla\!\cdot v\,r\,dA = 0, \qquad
    \int q\,\nabla\!\cdot u\,r\,dA = 0,

:math:`\nabla\!\cdot u = \partial_r u_r + u_r/r + \partial_z u_z`. Boundary conditions:
:math:`u_r = 0` on the axis, no slip on the (deformed, steady) wall, and at both clamped
ends (radius :math:`a`) the fully developed profile of the rheology carrying ``flow_rate``,
rescaled so that its discrete flux is ``flow_rate`` exactly; the pressure is pinned to the
outlet pressure on the axis at the outlet. The generalized Newtonian law is met by Picard
iteration on the viscosity, evaluated at the quadrature points.

The mesh is the reference rectangle :math:`\xi \in [0, 1]`, :math:`Z \in [0, L]` mapped
to the lumen: a node on the line :math:`Z_k` goes to
:math:`(r, z) = (\xi\,R_k,\ Z_k + \xi\,w_k)` with :math:`(R_k, Z_k + w_k)` the deformed wall
node of that line (quadratic geometry, so the lumen's boundary is the wall's own).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import bmat
from skfem import (Basis, BilinearForm, ElementQuad1, ElementQuad2, ElementVector, FacetBasis,
                   LinearForm, MeshQuad, MeshQuad2, asm, condense, solve)

from ..errors import ConvergenceError

__all__ = ["StokesLumen"]


@BilinearForm
def _viscous(u, v, w):
    r = w.x[0]
    gu, gv = u.grad, v.grad
    dd = (gu[0, 0] * gv[0, 0] + u[0] * v[0] / r**2 + gu[1, 1] * gv[1, 1]
          + 0.5 * (gu[0, 1] + gu[1, 0]) * (gv[0, 1] + gv[1, 0]))
    return 2.0 * w.eta * dd * r


@BilinearForm
def _divergence(u, q, w):
    r = w.x[0]
    return -(u.grad[0, 0] + u[0] / r + u.grad[1, 1]) * q * r


@LinearForm
def _flux(v, w):
    return v * w.x[0]


def _shear_rate(field, r):
    """:math:`\\sqrt{2 D:D}` of an interpolated velocity field at the quadrature points."""
    g = field.grad
    dd = g[0, 0] ** 2 + (field[0] / r) ** 2 + g[1, 1] ** 2 + 0.5 * (g[0, 1] + g[1, 0]) ** 2
    return np.sqrt(2.0 * dd)


class StokesLumen:
    """The flow in the lumen of one tube: mesh topology, boundary data, Picard solve.

    ``xi`` (radial, 0 to 1) and ``z`` (axial, 0 to L) are the vertex coordinates of the
    reference grid; the wall-node lines are the vertex and mid-edge values of ``z``.
    """

    def __init__(self, rheology, radius, length, flow_rate, xi, z, *, outlet_pressure=0.0,
                 tol=1e-10, maxiter=200):
        self.rheology, self.a, self.L, self.q = rheology, float(radius), float(length), float(flow_rate)
        self.outlet_pressure, self.tol, self.maxiter = float(outlet_pressure), tol, maxiter
        self.ref = MeshQuad2.from_mesh(MeshQuad.init_tensor(np.asarray(xi, float), np.asarray(z, float)))
        self.xi_n, self.z_n = self.ref.doflocs                        # reference node coordinates
        zv = np.asarray(z, float)
        self.lines = np.sort(np.concatenate([zv, 0.5 * (zv[:-1] + zv[1:])]))   # the wall-node lines
        self.line_of = np.abs(self.z_n[:, None] - self.lines[None, :]).argmin(axis=1)
        self.z_n = self.lines[self.line_of]                           # exact line values
        self.eu, self.ep = ElementVector(ElementQuad2()), ElementQuad1()
        ub = Basis(self.ref, self.eu, intorder=6)
        pb = ub.with_element(self.ep)
        self.nu, self.np_ = ub.N, pb.N
        ir, iz = ub.split_indices()                                    # node i -> dofs ir[i], iz[i]
        self.ir, self.iz = ir, iz
        on = lambda mask: np.flatnonzero(mask)                         # noqa: E731
        self.wall_nodes = on(np.isclose(self.xi_n, 1.0))
        self.wall_nodes = self.wall_nodes[np.argsort(self.z_n[self.wall_nodes])]   # one per line
        ends = on(np.isclose(self.z_n, 0.0) | np.isclose(self.z_n, self.L))
        axis = on(np.isclose(self.xi_n, 0.0))
        self.fixed = np.unique(np.concatenate([ir[axis], ir[ends], iz[ends], ir[self.wall_nodes],
                                               iz[self.wall_nodes]]))
        self.inlet_nodes = on(np.isclose(self.z_n, 0.0) & (self.xi_n < 1.0))
        self.end_nodes = on((np.isclose(self.z_n, 0.0) | np.isclose(self.z_n, self.L)) & (self.xi_n < 1.0))
        pxi, pz = pb.doflocs
        self.axis_p = np.flatnonzero(np.isclose(pxi, 0.0))
        self.axis_p = self.axis_p[np.argsort(pz[self.axis_p])]
        self.pin = self.axis_p[-1]                                     # (0, L)
        self.wall_facets = self.ref.facets_satisfying(lambda x: np.isclose(x[0], 1.0))
        self.inlet_facets = self.ref.facets_satisfying(lambda x: np.isclose(x[1], 0.0))
        self.x = None                                                  # last solution (u, p)
        self.history = []

    # ------------------------------------------------------------------ geometry
    def mesh(self, wall_radius, wall_axial):
        """The lumen mesh for wall nodes at radii ``wall_radius`` and axial displacements
        ``wall_axial`` (one per line, ordered by z)."""
        k = self.line_of
        doflocs = np.vstack([self.xi_n * wall_radius[k], self.z_n + self.xi_n * wall_axial[k]])
        return MeshQuad2(doflocs, self.ref.t)

    def _profile(self, mesh):
        """Fully developed end velocity at the end nodes, scaled to the exact discrete flux."""
        g = self.rheology.pressure_gradient(self.q, self.a)
        r = np.minimum(mesh.doflocs[0, self.end_nodes], self.a)
        w = self.rheology.velocity(r, self.a, g)
        inlet = FacetBasis(mesh, ElementQuad2(), facets=self.inlet_facets)
        weights = asm(_flux, inlet)                                   # int phi_i r dr (per radian)
        uz = np.zeros(mesh.doflocs.shape[1])
        uz[self.end_nodes] = w
        flux = 2.0 * math.pi * float(weights @ uz)
        return w * (self.q / flux)

    # ------------------------------------------------------------------ solve
    def solve(self, wall_radius, wall_axial):
        """Stokes flow on the current lumen. Returns the nodal force per radian that the fluid
        exerts on each wall node, shape (lines, 2) as (radial, axial) components."""
        mesh = self.mesh(wall_radius, wall_axial)
        ub = Basis(mesh, self.eu, intorder=6)
        pb = ub.with_element(self.ep)
        B = asm(_divergence, ub, pb)
        x = np.zeros(self.nu + self.np_)
        x[self.iz[self.end_nodes]] = self._profile(mesh)
        x[self.nu + self.pin] = self.outlet_pressure
        if self.x is not None:                                         # warm start (same topology)
            free = np.setdiff1d(np.arange(self.nu), self.fixed)
            x[free] = self.x[free]
        fixed = np.concatenate([self.fixed, [self.nu + self.pin]])
        newtonian = not _shear_dependent(self.rheology)
        eta_ref = float(self.rheology.apparent_viscosity(_wall_shear_rate(self.rheology, self.q, self.a)))
        steps = []
        for it in range(1 if newtonian else self.maxiter):
            if it == 0 and self.x is None:
                eta = np.full(ub.interpolate(x[: self.nu])[0].shape, eta_ref)
            else:
                field = ub.interpolate(x[: self.nu])
                rate = _shear_rate(field, ub.global_coordinates()[0])
                floor = 1e-9 * _wall_shear_rate(self.rheology, self.q, self.a)
                eta = np.asarray(self.rheology.apparent_viscosity(np.maximum(rate, floor)))
            A = asm(_viscous, ub, eta=eta)
            K = bmat([[A, B.T], [B, None]], format="csr")
            x_new = solve(*condense(K, np.zeros(K.shape[0]), x=x, D=fixed))
            change = np.linalg.norm(x_new[: self.nu] - x[: self.nu]) / max(np.linalg.norm(x_new[: self.nu]), 1e-300)
            x = x_new
            steps.append(change)
            if newtonian or (it > 0 and change < self.tol):
                break
        else:
            raise ConvergenceError(f"tubefsi.fem: the Picard iteration on the viscosity did not reach "
                                   f"{self.tol:g} in {self.maxiter} iterations (last change {steps[-1]:.3g})")
        self.history.append(len(steps))
        self.x, self.K, self.ub, self.pb, self.mesh_now = x, K, ub, pb, mesh
        residual = K @ x                                               # reactions at fixed dofs
        w = self.wall_nodes
        return -np.column_stack([residual[self.ir[w]], residual[self.iz[w]]])

    # ------------------------------------------------------------------ outputs
    def dissipation(self):
        """Viscous dissipation :math:`2\\pi\\int \\eta\\dot\\gamma^2 r\\,dA` (W) of the last solution."""
        field = self.ub.interpolate(self.x[: self.nu])
        r = self.ub.global_coordinates()[0]
        rate = _shear_rate(field, r)
        floor = 1e-9 * _wall_shear_rate(self.rheology, self.q, self.a)
        stress = np.asarray(self.rheology.stress(np.maximum(rate, floor))) * (rate >= floor)
        return 2.0 * math.pi * float(np.sum(stress * rate * r * self.ub.dx))

    def axis_pressure(self):
        """(z, p) on the axis, ordered by z."""
        z = self.pb.doflocs[1, self.axis_p]
        return z, self.x[self.nu + self.axis_p]

    def wall_traction(self, force):
        """Traction (Pa) on the wall nodes from their consistent nodal forces (per radian):
        :math:`t_i = F_i / \\int \\phi_i\\, r\\, ds` (row-summed boundary mass: exact for a
        constant traction, local, no spreading of the corner's reaction). The two corner nodes
        carry the end faces' reactions too; their values are extrapolated linearly from the
        two next nodes. Columns: radial, axial."""
        fb = FacetBasis(self.mesh_now, ElementQuad2(), facets=self.wall_facets)
        measure = asm(_flux, fb)[self.wall_nodes]
        t = force / measure[:, None]
        z = self.mesh_now.doflocs[1, self.wall_nodes]
        for end, (i, j) in ((0, (1, 2)), (-1, (-2, -3))):
            t[end] = t[i] + (t[i] - t[j]) * (z[end] - z[i]) / (z[i] - z[j])
        return t


def _shear_dependent(rheology) -> bool:
    """False for a Newtonian law (constant viscosity), checked on the law itself."""
    rates = np.array([1e-3, 1.0, 1e3])
    eta = np.asarray(rheology.apparent_viscosity(rates), dtype=float)
    return not np.allclose(eta, eta[0], rtol=1e-13, atol=0.0)


def _wall_shear_rate(rheology, q, a):
    """Wall shear rate of the fully developed flow of ``q`` in a rigid tube of radius ``a``."""
    g = rheology.pressure_gradient(q, a)
    return float(rheology.shear_rate(0.5 * g * a))
