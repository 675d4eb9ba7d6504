"""Plane-strain kinematics written without cancellation near the unit stretch."""

from __future__ import annotations


def hoop(s):
    r""":math:`s - 1/s = (s-1)(1 + 1/s)`; with :math:`(s - 1/s)^2 = I_1 - 3` in plane strain (no
    overflow: a double wherever the value is)."""
    return (s - 1.0) * (1.0 + 1.0 / s)


def quartic(s):
    r""":math:`s - s^{-3} = (s-1)(1 + 1/s)(1 + 1/s^2) = \tfrac12\,d(I_1 - 3)/ds` (the core's form,
    :func:`tubefsi.walls.hyperelastic._quartic`, bit for bit)."""
    return (s - 1.0) * (1.0 + 1.0 / s) * (1.0 + 1.0 / (s * s))
