"""Plane-strain kinematics written without cancellation near the unit stretch."""

from __future__ import annotations


def hoop(s):
    r""":math:`s - 1/s = (s-1)(s+1)/s`; with :math:`(s - 1/s)^2 = I_1 - 3` in plane strain."""
    return (s - 1.0) * (s + 1.0) / s


def quartic(s):
    r""":math:`s - s^{-3} = (s-1)(s+1)(s^2+1)/s^3 = \tfrac12\,d(I_1 - 3)/ds`."""
    return (s - 1.0) * (s + 1.0) * (s * s + 1.0) / s**3
