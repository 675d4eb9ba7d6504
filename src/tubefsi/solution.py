"""The result of :func:`tubefsi.solve`: loads, inlet state and lazy profiles.

A :class:`Solution` talks only to its coupler: the profiles and the maximum flow rate are
the coupler's (:meth:`~tubefsi.couplers.Coupler.profile`,
:meth:`~tubefsi.couplers.Coupler.max_flow_rate`). ``diagnostics`` and ``plot`` are accessors
that reach :mod:`tubefsi.advise` and :mod:`tubefsi.plotting` on purpose, at call time.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np
from numpy.typing import ArrayLike

from . import _html
from . import export
from .numerics.kernels import as_output
from ._validation import as_array
from .couplers.base import Coupler
from .errors import InvalidParameterError
from .profiles import Profile
from .scene import Scene, State

__all__ = ["Solution"]

#: Points per coupler call of a profile (bounded working memory).
_CHUNK = 1 << 14


def _broadcast_with(name, value, shape, what="the solution's shape"):
    """The shape of ``value`` broadcast with ``shape`` by NumPy's rules, or the typed error that
    says which shapes are allowed."""
    try:
        return np.broadcast_shapes(np.shape(value), shape)
    except ValueError:
        hint = ("; for every point at each of several positions pass a column, z[:, None]"
                if name == "z" and len(shape) == 1 and np.ndim(value) == 1 else "")
        raise InvalidParameterError(name, f"a number or an array that broadcasts with {what} {shape}{hint}",
                                    value) from None


def max_flow_rate_of(scene, coupler):
    """The coupler's maximum flow rate of ``scene``: a float, or an array of the scene's shape
    (one coupler call per part of the flat scene, as :meth:`~tubefsi.scene.Scene.split` gives)."""
    if scene.shape == ():
        return float(coupler.max_flow_rate(scene))
    flat = scene.flat(scene.shape)
    out = np.empty(flat.size)
    for index, part in flat.split(np.arange(flat.size)):
        out[index] = coupler.max_flow_rate(part)
    return out.reshape(scene.shape)


@attrs.frozen(kw_only=True)
class Solution:
    """Flow rate, pressure drop, inlet state and profiles of a steady FSI problem.

    Scalars for a scalar load, arrays (the load's shape) otherwise. Profiles are
    computed on demand and broadcast ``z`` against the load's shape like a NumPy
    ufunc: for a curve of ``N`` loads and ``M`` positions pass ``z[:, None]``.
    """

    scene: Scene
    coupler: Coupler
    state: State
    scalar: bool = True
    #: The registered name of the coupler (its class name if it is not registered).
    coupler_name: str = ""
    #: Where ``solve(..., on_infeasible="nan")`` found no steady state (None: nowhere); read
    #: :attr:`feasible`.
    _feasible: object = attrs.field(default=None, alias="feasible")
    #: The fluid density given to ``solve`` (kg/m^3; None if not given), for the Reynolds number.
    density: object = None
    #: The load ``solve`` was given: ``"flow_rate"`` or ``"pressure_drop"``.
    controlled: str = "flow_rate"

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
        """Outlet (gauge) pressure of the fluid, p(L) (Pa)."""
        return self.scene.gauge_outlet_pressure

    @property
    def external_pressure(self) -> float:
        """External pressure p_e (Pa); the wall responds to p - p_e."""
        return self.scene.external_pressure

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
        return as_output(self.scene.gauge_outlet_pressure + self.state.pressure_drop, self.scalar)

    @property
    def inlet_displacement(self):
        """Radial displacement of the inner wall at the inlet, R(0) - a (m), without cancellation."""
        return as_output(self._undeformed(0.0) * self.state.inlet_strain, self.scalar)

    @property
    def inlet_radius(self):
        """Deformed inner radius at the inlet R(0) (m)."""
        return as_output(self._undeformed(0.0) * (1.0 + self.state.inlet_strain), self.scalar)

    def _undeformed(self, z):
        """The undeformed radius a(z) (m): the tube's radius, evaluated at ``z`` for a graded tube."""
        a = self.tube.radius
        return a(np.asarray(z, dtype=float)) if isinstance(a, Profile) else a

    @property
    def feasible(self) -> np.ndarray:
        """Where the load has a steady state: a boolean array of the results' shape (0-d for a
        scalar solve); ``False`` only at the points that ``solve(..., on_infeasible="nan")`` gave
        NaN results."""
        shape = np.shape(self.state.flow_rate)
        if self._feasible is None:
            return np.ones(shape, dtype=bool)
        return np.array(np.broadcast_to(self._feasible, shape), dtype=bool)

    @property
    def max_flow_rate(self):
        """The largest flow rate with a steady state in this scene (m^3/s; ``inf`` where there is
        none): a float, or an array of the scene's shape where its parameters are arrays (as
        :func:`tubefsi.max_flow_rate` gives it)."""
        return max_flow_rate_of(self.scene, self.coupler)

    # ------------------------------------------------------------------ profiles
    def _profile(self, z):
        """``(strain, pressure_rise, flow_rate)`` at ``z`` from the coupler, broadcast with the loads
        (and the scene's array parameters); NaN at infeasible points."""
        z = as_array("z", z, "[0, L] (m)", lambda a: a >= 0)
        st = self.state
        shape = _broadcast_with("z", z, np.shape(st.flow_rate))
        length = np.broadcast_to(np.asarray(self.tube.length, dtype=float), shape) if np.ndim(self.tube.length) \
            else self.tube.length
        zz = np.broadcast_to(z, shape)
        if np.any(zz > length):
            bad = zz > length
            raise InvalidParameterError("z", f"[0, L] (m), L = {np.max(np.asarray(length)):g}", float(zz[bad].flat[0]))
        n = int(np.prod(shape, dtype=int))
        zf = zz.ravel()
        strain, rise = np.full(n, np.nan), np.full(n, np.nan)
        fields, parts = self._parts(shape)
        for idx, chunk, sub in parts:
            e, r = self.coupler.profile(chunk, sub, zf[idx])
            strain[idx], rise[idx] = np.broadcast_to(e, idx.shape), np.broadcast_to(r, idx.shape)
        return strain.reshape(shape), rise.reshape(shape), fields["flow_rate"].reshape(shape)

    def _parts(self, shape):
        """The state broadcast to ``shape`` and flattened (a dict), and an iterator over
        ``(positions, flat scene, state)`` for its feasible points, in chunks of bounded memory
        and one parameter set per chunk where a model needs it (:meth:`Scene.split`)."""
        st = self.state
        flat = self.scene.flat(shape) if self.scene.shape != () else self.scene
        fields = {name: np.broadcast_to(np.asarray(value, dtype=float), shape).ravel()
                  for name, value in zip(State._fields, st)}
        ok = np.flatnonzero(np.isfinite(fields["flow_rate"]))

        def parts():
            for index, part in flat.split(ok):
                for start in range(0, index.size, _CHUNK):
                    idx = index[start:start + _CHUNK]
                    chunk = part if part.size == 1 or idx.size == index.size else \
                        part.take(np.arange(start, start + idx.size))
                    yield idx, chunk, State(**{k: v[idx] for k, v in fields.items()})

        return fields, parts()

    # ------------------------------------------------------------------ sensitivities
    def _sensitivities(self):
        """The coupler's three derivatives per point, in the loads' shape (NaN where infeasible)."""
        shape = np.shape(self.state.flow_rate)
        out = np.full((3, int(np.prod(shape, dtype=int))), np.nan)
        _, parts = self._parts(shape)
        for idx, chunk, sub in parts:
            out[:, idx] = self.coupler.sensitivities(chunk, sub)
        return [as_output(row.reshape(shape), self.scalar) for row in out]

    @property
    def dpressure_drop_dflow_rate(self):
        r""":math:`d\Delta p/dq` at a fixed outlet pressure (Pa s/m^3): :math:`G_{in}K/q`, with
        :math:`K = \int_0^L \partial\ln G/\partial\ln q\,dz` (``docs/theory.md``, section
        "Sensitivities"); :math:`L\,\phi'(q)\,\psi(R_{in})` for a separable rheology."""
        return self._sensitivities()[0]

    @property
    def dflow_rate_dinlet_pressure(self):
        r""":math:`\partial q/\partial p_{in}` at a fixed outlet pressure (m^3/(s Pa)):
        :math:`1/(d\Delta p/dq)`, for pressure-controlled problems and networks."""
        return self._sensitivities()[1]

    @property
    def dflow_rate_doutlet_pressure(self):
        r""":math:`\partial q/\partial p_{out}` at a fixed inlet pressure (m^3/(s Pa)):
        :math:`-q/(G_{out}K)`, negative; it differs from :math:`-\partial q/\partial p_{in}` because
        the tube inflates with the outlet pressure."""
        return self._sensitivities()[2]

    def dpressure_drop_dparameter(self, parameter: str):
        r""":math:`\partial\Delta p/\partial\theta` at fixed flow rate and outlet pressure, for a model
        parameter named ``"rheology.<field>"`` or ``"wall.<field>"`` (Pa per unit of the field).

        From the separated identity (``docs/theory.md``, section "Sensitivities"): for a rheology
        parameter, :math:`G_{in}\int_0^L \partial_\theta\ln G\,dz` (closed forms for the power
        law and the Newtonian fluid; otherwise central differences of :math:`\ln G` at relative
        steps 1e-3 and 5e-4, Richardson-extrapolated). For the wall, only the modulus that scales
        its tube law, :math:`P = \mu\hat P` with :math:`\hat P` free of it (the shear modulus of a
        neo-Hookean wall, Young's modulus of a linear one: the field whose doubling doubles the
        tube law and leaves the wall's shape parameters unchanged), with an unloaded outlet:
        :math:`(\Delta p - L G_{in})/\mu`. Other wall parameters raise
        ``InvalidParameterError`` (difference two solves). 0 where ``q = 0``.
        """
        return self._dpressure_drop_dparameters((parameter,))[0]

    def _dpressure_drop_dparameters(self, parameters):
        """:meth:`dpressure_drop_dparameter` of each of ``parameters`` (a list of arrays or
        floats), in one pass over the points: the chunks, their state and the inlet gradient are
        shared (``tubefsi.fit``'s Jacobian asks for every fitted parameter at once)."""
        if self.scene.graded:
            raise InvalidParameterError("parameter", "a parameter of a uniform tube's solve (a graded tube: "
                                        "difference two solves)", parameters[0] if parameters else None)
        kinds = []
        for parameter in parameters:
            owner, _, field = parameter.partition(".")
            model = {"rheology": self.rheology, "wall": self.wall}.get(owner)
            if model is None or not attrs.has(type(model)) or field not in attrs.fields_dict(type(model)):
                raise InvalidParameterError("parameter", "'rheology.<field>' or 'wall.<field>' of the solved models",
                                            parameter)
            if owner == "wall" and not self._is_pressure_scale(field):
                raise InvalidParameterError(
                    "parameter", "a rheology field, or the wall's modulus with an unloaded outlet (others: "
                    "difference two solves)", parameter)
            kinds.append((owner, field))
        shape = np.shape(self.state.flow_rate)
        out = np.full((len(kinds), int(np.prod(shape, dtype=int))), np.nan)
        fields, parts = self._parts(shape)
        for idx, chunk, sub in parts:
            q = np.asarray(sub.flow_rate)
            value = np.zeros((len(kinds), idx.size))
            live = np.flatnonzero(q > 0)
            if live.size:
                part = chunk if live.size == idx.size else chunk.take(live)
                state = sub.take(live)
                pts = part.at(np.arange(live.size))
                r_in = pts.radius * (1.0 + state.inlet_strain)
                g_in = pts.rheology._pressure_gradient(state.flow_rate, r_in)
                for j, (owner, field) in enumerate(kinds):
                    if owner == "rheology" and field in type(pts.rheology)._gradient_scales:
                        # G proportional to the field: d ln G / d theta = 1/theta all along the tube
                        value[j, live] = g_in * pts.length / np.asarray(getattr(pts.rheology, field), dtype=float)
                    elif owner == "rheology":
                        def weight(rheology, flow_rate, radius, field=field):
                            return rheology._log_gradient_derivative(field, flow_rate, radius)

                        value[j, live] = g_in * self.coupler.length_integral(part, state, weight)
                    else:
                        modulus = np.asarray(getattr(pts.wall, field), dtype=float)
                        value[j, live] = (state.pressure_drop - pts.length * g_in) / modulus
            out[:, idx] = value
        return [as_output(row.reshape(shape), self.scalar) for row in out]

    def _is_pressure_scale(self, field) -> bool:
        """Whether the wall's tube law is proportional to ``field`` (and the outlet unloaded)."""
        wall = self.wall
        if np.any(np.asarray(self.outlet_pressure) != 0) or wall.is_rigid:
            return False
        try:
            value = np.asarray(getattr(wall, field), dtype=float)
            doubled = attrs.evolve(wall, **{field: 2.0 * value})
            return bool(np.all(np.asarray(doubled._pressure_scale()) == 2.0 * np.asarray(wall._pressure_scale()))
                        and doubled._shape_key() == wall._shape_key())
        except (TypeError, ValueError):
            return False

    def _out(self, value, *arguments):
        return as_output(value, self.scalar and all(np.ndim(a) == 0 for a in arguments))

    def pressure(self, z: float | ArrayLike) -> float | np.ndarray:
        """Pressure p(z) (Pa) at axial position ``z`` in [0, L] (m)."""
        _, rise, _ = self._profile(z)
        return self._out(self.outlet_pressure + rise, z)

    def radius(self, z: float | ArrayLike) -> float | np.ndarray:
        """Deformed inner radius R(z) (m)."""
        strain, _, _ = self._profile(z)
        return self._out(self._undeformed(z) * (1.0 + strain), z)

    def displacement(self, z: float | ArrayLike) -> float | np.ndarray:
        """Radial wall displacement R(z) - a (m), without cancellation."""
        strain, _, _ = self._profile(z)
        return self._out(self._undeformed(z) * strain, z)

    def pressure_gradient(self, z: float | ArrayLike) -> float | np.ndarray:
        """Local pressure gradient G = -dp/dz (Pa/m)."""
        strain, _, q = self._profile(z)
        return self._out(self.rheology.pressure_gradient(q, self._undeformed(z) * (1.0 + strain)), z)

    def wall_shear_stress(self, z: float | ArrayLike) -> float | np.ndarray:
        """Wall shear stress tau_w = G R / 2 (Pa)."""
        strain, _, q = self._profile(z)
        big_r = self._undeformed(z) * (1.0 + strain)
        return self._out(0.5 * self.rheology.pressure_gradient(q, big_r) * big_r, z)

    def plug_radius(self, z: float | ArrayLike) -> float | np.ndarray:
        r"""Radius of the unyielded plug :math:`r_p(z)` (m) of a yield-stress fluid at axial position
        ``z``: where the shear stress :math:`\tau(r) = \tau_w r/R` stays below the yield stress
        :math:`\tau_y` the fluid moves rigidly, so

        .. math::

            r_p(z) = \min\Bigl(R(z), \frac{\tau_y}{\tau_w(z)}R(z)\Bigr) = \min\Bigl(R(z), \frac{2\tau_y}{G(z)}\Bigr),

        the whole section (:math:`R`) where the fluid is at rest, and 0 for a fluid without a yield
        stress (``docs/results.md``, section "Fields along the tube")."""
        strain, _, q = self._profile(z)
        big_r = self._undeformed(z) * (1.0 + strain)
        tau_y = np.asarray(self.rheology.yield_stress, dtype=float)
        if not np.any(tau_y > 0):
            return self._out(np.zeros(np.shape(big_r)) + 0.0 * big_r, z)
        g = self.rheology.pressure_gradient(q, big_r)
        with np.errstate(divide="ignore", invalid="ignore"):
            plug = np.where(g > 0, np.minimum(big_r, 2.0 * tau_y / np.where(g > 0, g, 1.0)), big_r)
        return self._out(np.where(tau_y > 0, plug, 0.0) + 0.0 * big_r, z)

    def velocity(self, r: float | ArrayLike, z: float | ArrayLike) -> float | np.ndarray:
        """Axial velocity v(r, z) (m/s) at radial position ``r`` in [0, R(z)] (m)."""
        r_arr = as_array("r", r, "[0, R(z)] (m)", lambda a: a >= 0)
        strain, _, q = self._profile(z)
        big_r = self._undeformed(z) * (1.0 + strain)
        g = self.rheology.pressure_gradient(q, big_r)
        _broadcast_with("r", r_arr, np.shape(big_r), "the shape of the solution and z")
        r_arr, big_r, g = np.broadcast_arrays(r_arr, big_r, g)
        if np.any(r_arr > big_r * (1 + 1e-12)) or np.any(r_arr < 0):
            raise InvalidParameterError("r", "[0, R(z)] (m)", r_arr[(r_arr > big_r) | (r_arr < 0)].flat[0])
        return self._out(self.rheology.velocity(np.minimum(r_arr, big_r), big_r, g), z, r)

    # ------------------------------------------------------------------ tables (optional extras)
    def to_dataframe(self, dims: Sequence[str] | None = None):
        """The results as a :class:`pandas.DataFrame`, one row per point: the inputs that vary
        (the load, array parameters), then pressure drop, flow rate, inlet pressure, inlet
        displacement and inlet radius (SI; units in ``frame.attrs["units"]``). Needs pandas
        (``pip install 'tubefsi[pandas]'``); ``dims`` names the axes (:mod:`tubefsi.export`)."""
        return export.to_dataframe(self, dims)

    def to_xarray(self, dims: Sequence[str] | None = None):
        """The results as an :class:`xarray.Dataset`: one named dimension per broadcast axis
        (the input that varies along it, or ``dims``), the varying inputs as coordinates, the
        results as data variables with ``units`` attributes. Needs xarray
        (``pip install 'tubefsi[xarray]'``); ``dataset.to_netcdf(path)`` writes NetCDF."""
        return export.to_xarray(self, dims)

    def to_quantities(self, registry=None) -> dict:
        """Pressure drop, flow rate, inlet pressure, inlet displacement and inlet radius as
        :class:`pint.Quantity` objects (``pip install 'tubefsi[units]'``; ``registry`` a
        :class:`pint.UnitRegistry`, default pint's application registry). Every argument of
        ``solve`` and of the models may be a Quantity too: it is converted to SI on the way in."""
        return export.to_quantities(self, registry)

    # ------------------------------------------------------------------ accessors (upper layers)
    def diagnostics(self, *, density: float | ArrayLike | None = None, warn: bool = True):
        """Validity of the model's assumptions for this solution.

        Reports the slenderness a/L, the largest hoop strain, the closeness to a
        limit pressure and to the maximum flow rate, and (given the fluid's
        ``density`` in kg/m^3) the Metzner–Reed Reynolds number; each failed
        assumption is a :class:`~tubefsi.advise.ModelValidityWarning` (unless
        ``warn=False``) and a line in the result's ``warnings``. ``expected_model_error``
        is the relative error of the pressure drop that the clamped ends cause, as the
        finite-element validity map measured it (``docs/validity.md``).
        """
        if self.scene.graded:
            raise InvalidParameterError("solution", "the solution of a uniform tube (the diagnostics do not cover "
                                        "tapered and graded tubes yet; solve checks each graded result at its inlet "
                                        "section)", self)
        from .advise import diagnostics

        return diagnostics(self, density=density, warn=warn)

    def plot(self, **kwargs):
        """Pressure and radius profiles; see :func:`tubefsi.plotting.plot_profiles`."""
        from .plotting import plot_profiles

        return plot_profiles(self, **kwargs)

    def _repr_html_(self) -> str:
        """The notebook summary: the load and the key results with units, the models and the tube."""
        control = "flow-controlled" if self.controlled == "flow_rate" else "pressure-controlled"
        results = [("flow rate", _html.number(self.flow_rate, "m^3/s")),
                   ("pressure drop", _html.number(self.pressure_drop, "Pa")),
                   ("inlet pressure", _html.number(self.inlet_pressure, "Pa")),
                   ("outlet pressure", _html.number(self.outlet_pressure, "Pa")),
                   ("inlet displacement", _html.number(self.inlet_displacement, "m")),
                   ("inlet radius", _html.number(self.inlet_radius, "m"))]
        feasible = self.feasible
        if not feasible.all():
            results.append(("feasible", f"{int(feasible.sum())} of {feasible.size} points"))
        tube = self.tube
        geometry = [(name, _html.number(getattr(tube, name), "m")) for name in ("radius", "thickness", "length")]
        return "\n".join([
            _html.table(f"Solution ({control}, coupler '{self.coupler_name}', shape {np.shape(self.state.flow_rate)})",
                        results),
            _html.model_html(self.rheology, "rheology"), _html.model_html(self.wall, "wall"),
            _html.table("tube", geometry)])

    def __repr__(self) -> str:
        return (f"Solution(flow_rate={self.flow_rate!r}, pressure_drop={self.pressure_drop!r}, "
                f"inlet_displacement={self.inlet_displacement!r}, coupler={self.coupler_name!r})")

