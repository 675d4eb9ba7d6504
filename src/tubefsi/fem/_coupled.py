r"""The partitioned two-way coupling of :mod:`tubefsi.fem` (Dirichlet–Neumann, Aitken).

One iteration, from the interface displacement :math:`x_k` (radial and axial displacement of
every inner-wall node):

1. move the lumen mesh to the wall at :math:`x_k` and solve the Stokes flow there
   (:class:`~tubefsi.fem._fluid.StokesLumen`, Picard on the viscosity to its tolerance);
2. the consistent nodal forces of the fluid's traction (pressure *and* shear) on the wall
   nodes, times :math:`2\pi`, load the wall (:class:`~tubefsi.fem._wall.AxisymmetricWall`);
3. its displacement :math:`\tilde x_k` gives the residual :math:`r_k = \tilde x_k - x_k` and
   :math:`x_{k+1} = x_k + \omega_k r_k`, with Aitken's dynamic relaxation
   :math:`\omega_k = -\omega_{k-1}\, r_{k-1}\cdot(r_k - r_{k-1}) / |r_k - r_{k-1}|^2`
   (:math:`\omega_0` = ``relaxation``).

The viscosity (Picard) iteration of step 1 is solved inexactly, to a tenth of the previous
coupling update (at most 1e-4), tightening to its own tolerance (``min(tol, 1e-10)``, relative
change of the velocity) as the coupling converges. Converged when :math:`\max|r_k| \le`
``tol`` :math:`\cdot\,a`, the pressure drop changed by at most ``tol`` relative since the
previous iteration, and that iteration's fluid solve met the full Picard tolerance;
otherwise, after ``maxiter`` iterations, a :class:`~tubefsi.ConvergenceError`.
"""

from __future__ import annotations

import math
import time

import attrs
import numpy as np

from .._progress import bar
from ..errors import ConvergenceError, InvalidParameterError
from ..walls.rigid import Rigid
from ._fluid import StokesLumen
from ._wall import AxisymmetricWall

__all__ = ["AxisymmetricSolution", "solve_axisymmetric", "axial_grid"]


@attrs.frozen(kw_only=True)
class AxisymmetricSolution:
    """The finite-element reference of one tube (SI units).

    Attributes
    ----------
    pressure_drop : float
        The pressure drop (Pa) by the power balance: viscous dissipation over flow rate,
        :math:`\\Delta p = 2\\pi\\int \\tau\\dot\\gamma\\, r\\,dA / q` (the wall is at rest and the
        end profiles are fully developed, so this is the flux-weighted drop of
        :math:`p - \\tau_{zz}` between the ends). It converges at twice the order of the
        velocity (:math:`h^4` for Q2 and a smooth flow), where the pointwise axis value
        converges at :math:`h` only, the prescribed end profiles not being the discrete
        fully developed flow.
    axis_pressure_drop : float
        :math:`p(0) - p(L)` on the axis (Pa), pointwise: :math:`O(h)` accurate.
    z, pressure : ndarray
        Axial positions (m) and pressure (Pa) on the axis.
    wall_z, radius : ndarray
        Deformed axial position and inner radius (m) of the inner-wall nodes.
    wall_shear_stress : ndarray
        Tangential (downstream) traction of the fluid on the wall (Pa) at those nodes, from
        the consistent nodal forces (``StokesLumen.wall_traction``) and the wall's slope.
    wall_pressure : ndarray
        Normal traction of the fluid on the wall (Pa), :math:`\\approx p` there.
    history : tuple of dict
        Per coupling iteration: ``residual`` (max interface update / a), ``relaxation``,
        ``pressure_drop``, ``picard`` (viscosity iterations of that fluid solve).
    iterations : int
        Coupling iterations.
    elements : dict
        Element counts of the fluid and the wall meshes.
    seconds : float
        Wall-clock time of the solve.
    """

    pressure_drop: float
    axis_pressure_drop: float
    z: np.ndarray
    pressure: np.ndarray
    wall_z: np.ndarray
    radius: np.ndarray
    wall_shear_stress: np.ndarray
    wall_pressure: np.ndarray
    history: tuple
    iterations: int
    elements: dict
    seconds: float


def axial_grid(radius, length, resolution, *, growth=1.25):
    """Vertex grid along the tube: elements of ``radius/resolution`` at both (clamped) ends,
    growing geometrically by ``growth`` up to ``max(2 radius, length/40)`` in the middle."""
    h0, hmax = radius / resolution, max(2.0 * radius, length / 40.0)
    sizes, h, total = [], h0, 0.0
    while total + h < 0.5 * length and h < hmax:
        sizes.append(h)
        total += h
        h = min(h * growth, hmax)
    middle = length - 2.0 * total
    n_mid = max(1, math.ceil(middle / hmax))
    steps = sizes + [middle / n_mid] * n_mid + sizes[::-1]
    z = np.concatenate([[0.0], np.cumsum(steps)])
    z[-1] = length
    return z


def solve_axisymmetric(rheology, wall, tube, *, flow_rate, resolution=4, outlet_pressure=0.0,
                       tol=1e-8, maxiter=60, relaxation=0.5, ends="clamped", progress=False):
    r"""Steady two-way coupled axisymmetric finite-element solution of one tube.

    Parameters
    ----------
    rheology : Rheology
        Any generalized Newtonian law; it enters only through ``apparent_viscosity``.
    wall : WallModel
        A neo-Hookean or Mooney–Rivlin wall (thin or thick: the solid has the tube's
        thickness either way), at ``axial_stretch = 1``; or ``rigid`` (the fluid alone).
    tube : Tube
        Scalar radius, thickness and length.
    flow_rate : float
        Flow rate (m^3/s), > 0.
    resolution : int
        Elements across the lumen radius (and per radius along z at the ends); the wall gets
        ``ceil(resolution t/a)`` elements through its thickness.
    tol, maxiter, relaxation
        Coupling tolerance (relative to the radius and to the pressure drop), iteration cap
        and the initial Aitken factor.
    ends : {"clamped", "sliding"}
        Wall ends clamped (the reference scene), or free to slide radially.
    progress : bool or "auto"
        Show a progress bar over the coupling iterations (tqdm, ``pip install
        'tubefsi[progress]'``; ``"auto"``: only if tqdm is installed and standard error is a
        terminal); it ends at convergence, usually well before ``maxiter``.

    Returns
    -------
    AxisymmetricSolution
    """
    t0 = time.perf_counter()
    if np.size(flow_rate) != 1 or not float(np.asarray(flow_rate).reshape(())) > 0.0:
        raise InvalidParameterError("flow_rate", "one flow rate in (0, inf) m^3/s", flow_rate)
    q = float(np.asarray(flow_rate).reshape(()))
    if np.ndim(rheology.apparent_viscosity(1.0)) != 0:
        raise InvalidParameterError("rheology", "a rheology with scalar parameters", repr(rheology),
                                    "tubefsi.fem solves one scene at a time")
    if int(resolution) != resolution or resolution < 1:
        raise InvalidParameterError("resolution", "integers >= 1", resolution)
    fields = (tube.radius, tube.thickness, tube.length)
    if any(callable(v) or np.size(v) != 1 for v in fields):
        raise InvalidParameterError("tube", "a uniform tube with scalar radius, thickness and length",
                                    repr(tube), "tubefsi.fem solves one tube at a time")
    a, t, L = (float(np.asarray(v).reshape(())) for v in fields)
    z = axial_grid(a, L, int(resolution))
    xi = np.linspace(0.0, 1.0, int(resolution) + 1)
    fluid = StokesLumen(rheology, a, L, q, xi, z, outlet_pressure=outlet_pressure, tol=min(1e-10, tol))
    rigid = isinstance(wall, Rigid)
    solid = None if rigid else AxisymmetricWall(wall, a, t, z, max(1, math.ceil(resolution * t / a)), ends=ends)
    if not rigid and not np.allclose(solid.lines, fluid.lines, rtol=0, atol=1e-12 * L):
        raise AssertionError("tubefsi.fem: the wall and lumen meshes do not share their interface nodes")
    n = len(fluid.lines)
    x = np.zeros((n, 2))
    omega, r_prev, dp_prev, history = float(relaxation), None, None, []
    picard_tol = fluid.tol
    shown = bar(maxiter, progress, "tubefsi.fem", unit="coupling iteration")
    try:
        for k in range(maxiter):
            # inexact inner solves: the viscosity iteration to a tenth of the last coupling update
            fluid.tol = picard_tol if r_prev is None else min(1e-4, max(picard_tol, 0.1 * history[-1]["residual"]))
            force = fluid.solve(a + x[:, 0], x[:, 1])
            dp = fluid.dissipation() / q
            x_wall = x if rigid else solid.solve(2.0 * math.pi * force)
            r = x_wall - x
            if r_prev is not None:
                dr = (r - r_prev).ravel()
                omega = -omega * float(r_prev.ravel() @ dr) / max(float(dr @ dr), 1e-300)
            res = float(np.max(np.abs(r))) / a
            history.append({"residual": res, "relaxation": omega, "pressure_drop": dp,
                            "picard": fluid.history[-1]})
            shown.update()
            if rigid or (res <= tol and dp_prev is not None and abs(dp - dp_prev) <= tol * abs(dp)
                         and fluid.tol <= picard_tol * (1 + 1e-12)):
                break
            x, r_prev, dp_prev = x + omega * r, r, dp
        else:
            raise ConvergenceError(f"tubefsi.fem: the coupling did not converge in {maxiter} iterations "
                                   f"(interface update {res:.3g} a, tolerance {tol:g})")
    finally:
        shown.close()
    zp, p = fluid.axis_pressure()
    traction = fluid.wall_traction(force)
    wall_z, radius = fluid.lines + x[:, 1], a + x[:, 0]
    slope = np.gradient(radius, wall_z)                           # dR/dz of the deformed wall
    norm = np.sqrt(1.0 + slope**2)
    shear = (traction[:, 1] + slope * traction[:, 0]) / norm      # along the tangent (R', 1)
    normal = (traction[:, 0] - slope * traction[:, 1]) / norm     # along the normal (1, -R')
    return AxisymmetricSolution(
        pressure_drop=dp, axis_pressure_drop=float(p[0] - p[-1]), z=zp, pressure=p, wall_z=wall_z, radius=radius,
        wall_shear_stress=shear, wall_pressure=normal, history=tuple(history),
        iterations=len(history),
        elements={"fluid": int(fluid.ref.t.shape[1]), "wall": 0 if rigid else int(solid.mesh.cells.shape[0])},
        seconds=time.perf_counter() - t0)
