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

and the class attributes ``cost_rank`` (lower is cheaper; ``coupler="auto"`` takes the
cheapest that supports the pair) and ``meets_accuracy_contract`` (whether ``auto`` may pick
it). A coupler that can estimate its own error by solving again at a finer setting returns
that finer version from :meth:`Coupler.refined`; :class:`~tubefsi.couplers.Checked` then
compares the two and warns (``AccuracyWarning``) — one wrapper for every such coupler.

The separated-variables couplers (``closed-form``, ``quadrature``) share an engine,
:class:`~tubefsi.couplers.separated.SeparatedVariables`; a coupler from a plugin may use it
or implement the interface from scratch.
"""

from __future__ import annotations

import abc
from typing import ClassVar

__all__ = ["Coupler"]


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
