"""The result of :func:`tubefsi.solve`: loads, inlet state and lazy profiles."""

from __future__ import annotations

import attrs
import numpy as np

from ._numerics import as_output
from ._validation import as_array
from .couplers.base import Scene, State
from .errors import InvalidParameterError

__all__ = ["Solution"]


@attrs.frozen(kw_only=True)
class Solution:
    """Flow rate, pressure drop, inlet state and profiles of a steady FSI problem.

    Scalars for a scalar load, arrays (the load's shape) otherwise. Profiles are
    computed on demand and broadcast ``z`` against the load's shape like a NumPy
    ufunc: for a curve of ``N`` loads and ``M`` positions pass ``z[:, None]``.
    """

    scene: Scene
    coupler: object
    state: State
    scalar: bool = True

    # ------------------------------------------------------------------ loads
    @property
    def rheology(self):
        return self.scene.rheology

    @property
    def wall(self):
        return self.scene.wall

    @property
    def tube(self):
        return self.scene.tube

    @property
    def outlet_pressure(self) -> float:
        """Outlet (gauge, transmural) pressure (Pa)."""
        return self.scene.outlet_pressure

    @property
    def flow_rate(self):
        """Volumetric flow rate q (m^3/s)."""
        return as_output(self.state.flow_rate, self.scalar)

    @property
    def pressure_drop(self):
        """Pressure drop p(0) - p(L) (Pa)."""
        return as_output(self.state.pressure_drop, self.scalar)

    @property
    def inlet_pressure(self):
        """Inlet pressure p(0) = outlet pressure + pressure drop (Pa)."""
        return as_output(self.scene.outlet_pressure + self.state.pressure_drop, self.scalar)

    @property
    def inlet_displacement(self):
        """Radial displacement of the inner wall at the inlet, R(0) - a (m), without cancellation."""
        return as_output(self.tube.radius * self.state.inlet_strain, self.scalar)

    @property
    def inlet_radius(self):
        """Deformed inner radius at the inlet R(0) (m)."""
        return as_output(self.tube.radius * (1.0 + self.state.inlet_strain), self.scalar)

    @property
    def coupler_name(self) -> str:
        from .registry import couplers

        return couplers.name_of(self.coupler) or type(self.coupler).__name__

    # ------------------------------------------------------------------ profiles
    def _log_stretch(self, z):
        """Log-stretch v(z) solving L - z = H(v; q), broadcast against the load shape."""
        L = self.tube.length
        z = as_array("z", z, f"[0, {L:g}] (m)", lambda a: (a >= 0) & (a <= L))
        scene, st = self.scene, self.state
        z, q, v_in = np.broadcast_arrays(z, st.flow_rate, st.log_stretch)
        if self.wall.is_rigid:
            return z, q, np.zeros_like(z)
        frac = (L - z) / L
        engine = self.coupler
        if not engine.separates_variables:
            from .couplers.quadrature import Quadrature

            engine = Quadrature()
        v, _ = engine.solve_log_stretch(scene, np.where(q == 0, 0.0, frac * scene.target(q)), q,
                                        upper=v_in * (1 + 1e-12) + 1e-300)
        return z, q, np.where(frac == 1.0, v_in, v)

    def pressure(self, z):
        """Pressure p(z) (Pa) at axial position ``z`` in [0, L] (m)."""
        z_, q, v = self._log_stretch(z)
        if self.wall.is_rigid:
            g = self.rheology._pressure_gradient(q, self.tube.radius)
            p = self.outlet_pressure + (self.tube.length - z_) * np.where(q == 0, 0.0, g)
        else:
            p = self.outlet_pressure + self.scene.pressure_rise(v)
        return as_output(p, self.scalar and np.ndim(z) == 0)

    def radius(self, z):
        """Deformed inner radius R(z) (m)."""
        _, _, v = self._log_stretch(z)
        return as_output(self.tube.radius * (1.0 + self.scene.strain_at(v)), self.scalar and np.ndim(z) == 0)

    def displacement(self, z):
        """Radial wall displacement R(z) - a (m), without cancellation."""
        _, _, v = self._log_stretch(z)
        return as_output(self.tube.radius * self.scene.strain_at(v), self.scalar and np.ndim(z) == 0)

    def pressure_gradient(self, z):
        """Local pressure gradient G = -dp/dz (Pa/m)."""
        _, q, v = self._log_stretch(z)
        big_r = self.tube.radius * (1.0 + self.scene.strain_at(v))
        return as_output(self.rheology.pressure_gradient(q, big_r), self.scalar and np.ndim(z) == 0)

    def wall_shear_stress(self, z):
        """Wall shear stress tau_w = G R / 2 (Pa)."""
        _, q, v = self._log_stretch(z)
        big_r = self.tube.radius * (1.0 + self.scene.strain_at(v))
        g = self.rheology.pressure_gradient(q, big_r)
        return as_output(0.5 * g * big_r, self.scalar and np.ndim(z) == 0)

    def velocity(self, r, z):
        """Axial velocity v(r, z) (m/s) at radial position ``r`` in [0, R(z)] (m)."""
        r_arr = np.asarray(r, dtype=float)
        _, q, v = self._log_stretch(z)
        big_r = self.tube.radius * (1.0 + self.scene.strain_at(v))
        g = self.rheology.pressure_gradient(q, big_r)
        r_arr, big_r, g = np.broadcast_arrays(r_arr, big_r, g)
        if np.any(r_arr > big_r * (1 + 1e-12)) or np.any(r_arr < 0):
            raise InvalidParameterError("r", "[0, R(z)] (m)", r_arr[(r_arr > big_r) | (r_arr < 0)].flat[0])
        out = self.rheology.velocity(np.minimum(r_arr, big_r), big_r, g)
        return as_output(out, self.scalar and np.ndim(z) == 0 and np.ndim(r) == 0)

    def diagnostics(self, *, density=None, warn=True):
        """Validity of the model's assumptions for this solution.

        Reports the slenderness a/L, the largest hoop strain, the closeness to a
        limit pressure and to the maximum flow rate, and (given the fluid's
        ``density`` in kg/m^3) the Metzner–Reed Reynolds number; each failed
        assumption is a :class:`~tubefsi.advise.ModelValidityWarning` (unless
        ``warn=False``) and a line in the result's ``warnings``.
        """
        from .advise import diagnostics

        return diagnostics(self, density=density, warn=warn)

    def plot(self, **kwargs):
        """Pressure and radius profiles; see :func:`tubefsi.plotting.plot_profiles`."""
        from .plotting import plot_profiles

        return plot_profiles(self, **kwargs)

    def __repr__(self) -> str:
        return (f"Solution(flow_rate={self.flow_rate!r}, pressure_drop={self.pressure_drop!r}, "
                f"inlet_displacement={self.inlet_displacement!r}, coupler={self.coupler_name!r})")
