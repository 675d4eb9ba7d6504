"""Solution strategies: closed form, quadrature, ODE integration."""

from .base import Coupler
from .closed_form import ClosedForm
from .ode import ODE
from .quadrature import Quadrature

__all__ = ["Coupler", "ClosedForm", "Quadrature", "ODE"]
