r"""The coupler interface: how a solution strategy meets :func:`tubefsi.solve`.

A coupler solves the lubrication problem :math:`dp/dz = -G(q, R(p))`, :math:`p(L) = p_{out}`
(``docs/theory.md``, section "Lubrication") for one :class:`~tubefsi.scene.Scene` and an array
of loads. It is a small immutable (``attrs`` frozen) object whose fields are its options,
and it is either abstract or final. Hooks a concrete coupler implements:

=============================================  ===================================================
hook                                           returns
=============================================  ===================================================
``supports(rheology, wall)``                   whether it can solve the pair
``flow_controlled(scene, flow_rate)``          a :class:`~tubefsi.scene.State` per flow rate
``pressure_controlled(scene, pressure_drop)``  a :class:`~tubefsi.scene.State` per pressure drop
``max_flow_rate(scene)``                       the largest flow rate with a steady state (or inf)
``profile(scene, state, z)``                   the hoop strain and pressure rise at positions z
=============================================  ===================================================

and, optionally (each has a default built on the hooks above):

=============================================  ===================================================
hook                                           default
=============================================  ===================================================
``flow_controlled_point(scene, flow_rate)``    one float: ``flow_controlled`` of a one-point array
``solve_feasible(scene, load, controlled)``    the limit first, then the points below it (NaN and
                                               ``False`` beyond: ``on_infeasible="nan"``)
``limit_pressure(scene)``                      the wall's limit pressure
``length_integral(scene, state, weight)``      :math:`\int_0^L w\,dz` over the coupler's profile
                                               (the derivatives of :meth:`sensitivities` and
                                               :func:`tubefsi.fit`)
=============================================  ===================================================

Class attributes ``cost_rank`` (lower is cheaper; ``coupler="auto"`` takes the cheapest that
supports the pair) and ``meets_accuracy_contract`` (whether ``auto`` may pick it). Every solve
that ``auto`` gives a coupler is answered by that coupler alone. A coupler that can estimate its own error by solving again at a finer setting returns
that finer version from :meth:`Coupler.refined`; :class:`~tubefsi.couplers.Checked` then
compares the two and warns (``AccuracyWarning``) — one wrapper for every such coupler.

The separated-variables couplers (``closed-form``, ``quadrature``) share an engine,
:class:`~tubefsi.couplers.separated.SeparatedVariables`; a coupler from a plugin may use it
or implement the interface from scratch.
"""

from __future__ import annotations

import abc
import math
from typing import ClassVar

import numpy as np

from ..numerics.quadrature import adaptive, warn_unconverged
from ..scene import State

__all__ = ["Coupler"]


def _flow_index(rheology, flow_rate, radius):
    return rheology._flow_index(flow_rate, radius)


class Coupler(abc.ABC):
    """Abstract solution strategy (see the module docstring for the hooks).

    Loads arrive as float arrays (entries >= 0, already validated); the returned
    :class:`~tubefsi.scene.State` has their shape. Points beyond a limit raise
    :class:`~tubefsi.NoSteadyStateError`; a numerical failure raises
    :class:`~tubefsi.ConvergenceError`.
    """

    __slots__ = ()

    #: Lower is cheaper; ``coupler="auto"`` takes the cheapest that supports the pair.
    cost_rank: ClassVar[int] = 100
    #: Whether ``auto`` may pick it (it meets the 1e-12 accuracy contract,
    #: ``docs/verification.md``, section "Contracts").
    meets_accuracy_contract: ClassVar[bool] = True

    @abc.abstractmethod
    def supports(self, rheology, wall) -> bool:
        """Whether this coupler can solve ``rheology`` flowing in ``wall``."""

    @abc.abstractmethod
    def flow_controlled(self, scene, flow_rate):
        """Solve for the pressure drop at each flow rate (float array, m^3/s); a ``State``."""

    def flow_controlled_point(self, scene, flow_rate: float):
        """One flow rate (a float) through a scene of scalars: a ``State`` of floats. The default is
        :meth:`flow_controlled` of a one-point array; a coupler with a cheaper way for one point
        overrides it (it must give the bits :meth:`flow_controlled` gives a one-point array)."""
        return self.flow_controlled(scene, np.array([flow_rate], dtype=float)).first()

    @abc.abstractmethod
    def pressure_controlled(self, scene, pressure_drop):
        """Solve for the flow rate at each pressure drop (float array, Pa); a ``State``."""

    @abc.abstractmethod
    def max_flow_rate(self, scene) -> float:
        """The largest flow rate with a steady state (m^3/s); ``inf`` where every one has one."""

    @abc.abstractmethod
    def profile(self, scene, state, z):
        r"""``(strain, pressure_rise)`` at positions ``z`` (m), broadcast against the state's shape.

        ``strain`` is the hoop strain :math:`\lambda(z) - 1` (never formed by subtraction) and
        ``pressure_rise`` is :math:`p(z) - p_{out}`.
        """

    def limit_pressure(self, scene):
        """The transmural pressure the wall of each point of a flat scene never reaches (Pa; inf
        for most laws): the wall's :meth:`~tubefsi.walls.WallModel.limit_pressure`."""
        return scene.wall.limit_pressure(scene.tb)

    def solve_feasible(self, scene, load, controlled: str):
        """``(State, feasible)``: the solution at the points of ``load`` (a flat array of flow rates
        or pressure drops, ``controlled`` says which) that have a steady state, NaN and ``False``
        in ``feasible`` at those beyond a limit (``feasible`` None: every point has one).

        The default finds the limit first (:meth:`max_flow_rate`, or :meth:`limit_pressure` minus
        the outlet pressure) and solves the points below it; an engine that sees a point run away
        overrides it. A point beyond the solver's range that is below the limit still raises.
        """
        load = np.asarray(load, dtype=float)
        if controlled == "flow_rate":
            limit = np.asarray(self.max_flow_rate(scene), dtype=float)
            beyond = (load > 0) & (load >= limit)
        else:
            limit = np.asarray(self.limit_pressure(scene), dtype=float) - np.asarray(scene.outlet_pressure, dtype=float)
            beyond = load >= limit
        beyond = np.broadcast_to(beyond, load.shape)
        method = self.flow_controlled if controlled == "flow_rate" else self.pressure_controlled
        if not np.any(beyond):
            return method(scene, load), None
        feasible = ~beyond
        go = np.flatnonzero(feasible)
        fields = {f: np.full(load.shape, np.nan) for f in ("flow_rate", "pressure_drop", "inlet_strain", "log_stretch")}
        fields["flow_rate" if controlled == "flow_rate" else "pressure_drop"] = load.copy()
        if go.size:
            sub = scene.take(go) if scene.size > 1 else scene
            state = method(sub, load[go])
            for name in fields:
                fields[name][go] = np.broadcast_to(np.asarray(getattr(state, name), dtype=float), go.shape)
        return State(**fields), feasible

    def length_integral(self, scene, state, weight, *, uniform=False):
        r""":math:`\int_0^L w(q, R(z))\,dz` per point of a flat scene (m times ``w``), for a weight
        ``w = weight(rheology, flow_rate, radius)`` (arrays; ``rheology`` the points' own, whose
        parameters are aligned with them); ``uniform``: ``w`` does not depend on R.

        With :math:`w = k = \partial\ln G/\partial\ln q` it is the :math:`K` of
        :meth:`sensitivities`; with :math:`w = \partial_\theta\ln G` the derivative of a solve
        with respect to a rheology parameter (:func:`tubefsi.fit`; ``docs/theory.md``, section
        "Sensitivities"). The default integrates ``w`` over this coupler's :meth:`profile` by
        adaptive Gauss–Kronrod quadrature in :math:`z` (relative tolerance 1e-12, a warning
        otherwise); couplers with a cheaper form override it. Points with ``q = 0`` are not
        asked for.
        """
        q = np.asarray(state.flow_rate, dtype=float)
        n = q.size
        length = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (n,))
        radius = np.broadcast_to(np.asarray(scene.tube.radius, dtype=float), (n,))
        if uniform:
            r_out = radius * np.broadcast_to(np.asarray(scene.outlet_stretch, dtype=float), (n,))
            return length * weight(scene.rheology, q, r_out)
        fields = state.arrays(n)

        def f(z, idx):
            rows = np.repeat(idx, z.shape[1])
            part = scene.take(rows) if scene.size != 1 else scene
            strain, _ = self.profile(part, state.take(rows), z.ravel())
            r = radius[rows] * (1.0 + np.asarray(strain))
            return np.asarray(weight(part.rheology, fields["flow_rate"][rows], r)).reshape(z.shape)

        result = adaptive(f, np.zeros(n), length, rtol=1e-12)
        if not np.all(result.converged):
            warn_unconverged("a length integral of the sensitivities", result)
        return result.value

    def sensitivities(self, scene, state):
        r"""The derivatives of a solve at each point of a flat scene: ``(dpressure_drop_dflow_rate,
        dflow_rate_dinlet_pressure, dflow_rate_doutlet_pressure)``.

        With :math:`F(q, p_{in}, p_{out}) = \int_{p_{out}}^{p_{in}} dp/G(q, R(p)) - L = 0` and
        :math:`\partial_q F = -K/q`, :math:`K = \int_0^L k\,dz` (:meth:`length_integral`):
        :math:`d\Delta p/dq = G_{in} K/q`, :math:`\partial q/\partial p_{in} = q/(G_{in}K)`,
        :math:`\partial q/\partial p_{out} = -q/(G_{out}K)`, :math:`G_{in}, G_{out}` the pressure
        gradients at the ends. At ``q = 0`` the limit :math:`q \to 0^+` (the tube uniform).
        """
        q = np.asarray(state.flow_rate, dtype=float).ravel()
        n = q.size
        rheo = scene.rheology
        a = np.broadcast_to(np.asarray(scene.tube.radius, dtype=float), (n,))
        length = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), (n,))
        r_out = a * np.broadcast_to(np.asarray(scene.outlet_stretch, dtype=float), (n,))
        r_in = a * (1.0 + np.broadcast_to(np.asarray(state.inlet_strain, dtype=float), (n,)))
        flowing = q > 0
        k_int = np.empty(n)
        if np.any(flowing):
            live = np.flatnonzero(flowing)
            part = scene if live.size == n else scene.take(live)
            sub = state.take(live)
            k_int[live] = self.length_integral(part, sub, _flow_index, uniform=rheo.separable)
        # q = 0: the tube is uniform at the outlet radius; the limit at an apparent shear rate 1e-30/s
        q_use = np.where(flowing, q, 0.25e-30 * math.pi * r_out**3)
        r_in = np.where(flowing, r_in, r_out)
        if not np.all(flowing):
            still = ~flowing
            # (over every point: a fluid's array parameters are aligned with all of them)
            k = np.broadcast_to(np.asarray(rheo._flow_index(q_use, r_out), dtype=float), (n,))
            k_int[still] = length[still] * k[still]
        g_in = rheo._pressure_gradient(q_use, r_in)
        g_out = rheo._pressure_gradient(q_use, r_out)
        with np.errstate(divide="ignore", over="ignore"):
            slope = g_in * (k_int / q_use)
            return slope, q_use / (g_in * k_int), -q_use / (g_out * k_int)

    def refined(self) -> Coupler | None:
        """A finer version of this coupler for an a-posteriori error check, or None (no check).

        :class:`~tubefsi.couplers.Checked` solves with both and warns when they differ by
        more than :meth:`error_threshold`.
        """
        return None

    def error_threshold(self) -> float:
        """Largest relative difference from :meth:`refined` accepted without a warning."""
        return 1e-8

    def describe(self) -> str:
        """A short description for messages (default: the class name)."""
        return type(self).__name__

