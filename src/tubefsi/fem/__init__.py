r"""A two-way coupled axisymmetric finite-element reference for one tube (optional extra ``fem``).

:func:`solve_axisymmetric` solves, with existing finite-element libraries, what the reduced
model approximates: generalized Newtonian Stokes flow in the deformed lumen (scikit-fem,
Taylor–Hood Q2/Q1, Picard on the viscosity) and the hyperelastic wall as an axisymmetric,
large-deformation, incompressible solid with clamped ends (felupe), coupled by pressure and
shear traction one way and the wall's displacement the other (Dirichlet–Neumann fixed point,
Aitken relaxation). ``docs/validity.md`` describes the method, its verification and the
validity map it yields.

Not imported by ``import tubefsi``; importing it without scikit-fem and felupe raises an
``ImportError`` naming the extra.
"""

from __future__ import annotations

try:
    import felupe as _felupe  # noqa: F401
    import tensortrax as _tensortrax  # noqa: F401
    import skfem as _skfem  # noqa: F401
except ImportError as exc:  # pragma: no cover - depends on the environment
    raise ImportError("tubefsi.fem needs scikit-fem, felupe and tensortrax: pip install 'tubefsi[fem]' "
                      f"({exc})") from exc

from ._coupled import AxisymmetricSolution, solve_axisymmetric

__all__ = ["AxisymmetricSolution", "solve_axisymmetric"]
