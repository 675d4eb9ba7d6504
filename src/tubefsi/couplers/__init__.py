"""Solution strategies: closed form, quadrature, ODE integration (see :mod:`tubefsi.couplers.base`).

====================  ==========================================================================
module                contents
====================  ==========================================================================
``base``              :class:`Coupler`, the abstract interface
``separated``         :class:`~tubefsi.couplers.separated.SeparatedVariables`, the engine of the
                      separated-variables identity shared by ``closed-form`` and ``quadrature``
``closed_form``       :class:`ClosedForm` (registered ``closed-form``)
``quadrature``        :class:`Quadrature` (registered ``quadrature``)
``ode``               :class:`ODE` (registered ``ode``), the chapter's method
``checked``           :class:`Checked`, the a-posteriori check of any self-checking coupler
``graded``            :class:`Graded`, tubes and walls that vary along z (``docs/graded.md``)
====================  ==========================================================================
"""

from .base import Coupler
from .checked import Checked, checked
from .closed_form import ClosedForm
from .graded import Graded
from .ode import ODE
from .quadrature import Quadrature
from .separated import SeparatedVariables

__all__ = ["Coupler", "SeparatedVariables", "ClosedForm", "Quadrature", "ODE", "Checked", "checked", "Graded"]
