"""Exception types raised by tubefsi.

Every failure the library can foresee is one of these, never a NaN or an
exception from deep inside SciPy.
"""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np

__all__ = [
    "TubefsiError",
    "InvalidParameterError",
    "KeywordError",
    "NoSteadyStateError",
    "BucklingError",
    "ConvergenceError",
    "StretchRangeError",
    "AccuracyWarning",
    "ModelValidityWarning",
    "FitWarning",
    "warn_user",
]


class TubefsiError(Exception):
    """Base class of every tubefsi exception."""

    def __reduce__(self):
        # rebuilt from its message and attributes, not by calling __init__ again (whose arguments
        # differ from ``args``): an error raised in a worker process reaches the caller whole
        return _rebuild, (type(self), self.args, dict(self.__dict__))


def _rebuild(cls, args, state):
    error = cls.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


class InvalidParameterError(TubefsiError, ValueError):
    """A parameter lies outside its admissible range.

    Attributes
    ----------
    parameter : str
        The name of the offending parameter, as the caller spelled it.
    admissible : str
        The admissible range, e.g. ``"(0, inf)"``.
    """

    def __init__(self, parameter: str, admissible: str, value=None, detail: str = ""):
        self.parameter = parameter
        self.admissible = admissible
        self.value = value
        got = "" if value is None else f" (got {_short(value)})"
        extra = f"; {detail}" if detail else ""
        # a range or a set reads "must be in [0, inf)"; a description "must be a coupler that ..."
        joiner = "in " if admissible[:1] in "[({" or admissible.startswith("the ") else ""
        super().__init__(f"{parameter} must be {joiner}{admissible}{got}{extra}")


class KeywordError(InvalidParameterError, TypeError):
    """A call to a public entry point (``solve``, ``max_flow_rate``, ``advise``, ``fit``, the
    ``Network`` API) with an unknown keyword, or without a required one. (A model, coupler or
    ``Tube`` constructor raises Python's own ``TypeError`` instead.)

    Both an :class:`InvalidParameterError` (so ``except tubefsi.InvalidParameterError`` and
    ``except ValueError`` catch it, as every other bad input) and a :class:`TypeError` (what
    Python itself raises for a wrong keyword, so ``except TypeError`` code keeps working).

    Attributes
    ----------
    parameter : str
        The unknown keyword, or the first missing one.
    valid : tuple of str
        The keywords the callable takes.
    missing : tuple of str
        The required keywords not given (empty for an unknown keyword).
    suggestion : str or None
        The valid keyword closest to an unknown one (``difflib``), if any is close.
    """

    def __init__(self, callable_name: str, parameter: str, valid, *, missing=(), suggestion=None, detail: str = ""):
        self.parameter = parameter
        self.valid = tuple(valid)
        self.missing = tuple(missing)
        self.suggestion = suggestion
        self.value = None
        self.admissible = "one of the keywords " + ", ".join(self.valid) if self.valid else "no keyword"
        listing = ", ".join(self.valid) if self.valid else "none"
        if self.missing:
            names = ", ".join(repr(m) for m in self.missing)
            text = f"{callable_name} missing required keyword{'s' if len(self.missing) > 1 else ''} {names}"
        elif detail:
            text = f"{callable_name}: {detail}"
        else:
            hint = f"; did you mean {suggestion!r}?" if suggestion else ""
            text = f"{callable_name} got an unexpected keyword {parameter!r}{hint}"
        TubefsiError.__init__(self, f"{text} (valid keywords: {listing})")


class NoSteadyStateError(TubefsiError, ValueError):
    """The requested load has no steady solution: the tube inflates without bound.

    Attributes
    ----------
    quantity : str
        Which load exceeds its limit: ``"pressure"`` or ``"flow_rate"``.
    limit : float
        The limit (Pa or m^3/s) that the load must stay below.
    """

    def __init__(self, quantity: str, limit: float, value=None, detail: str = "", *, name: str = ""):
        self.quantity = quantity
        self.limit = float(limit)
        unit = "Pa" if quantity == "pressure" else "m^3/s"
        got = "" if value is None else f" (got {_short(value)} {unit})"
        extra = f"; {detail}" if detail else ""
        what = "the limit pressure" if quantity == "pressure" else "the maximum flow rate"
        super().__init__(
            f"no steady state: {name or quantity} must stay below {what} {self.limit:.10g} {unit}{got}{extra}"
        )


class StretchRangeError(InvalidParameterError):
    """A flow rate the model answers but the solver does not: its inlet stretch would exceed
    ``MAX_STRETCH`` (``1e15``) times the outlet stretch.

    Not a physical limit: the flow rate is below :func:`tubefsi.max_flow_rate` (the one limit,
    often ``inf`` then), so a steady state exists, but a tube inflated that far left the model's
    assumptions (a slender tube, ``R/L`` small) long before (``docs/theory.md``, section "The
    maximum flow rate"; ``docs/scope.md``).

    Attributes
    ----------
    limit : float
        The largest flow rate within the solver's range at that point (m^3/s).
    """

    #: The load the range bounds (as :attr:`NoSteadyStateError.quantity`).
    quantity = "flow_rate"

    def __init__(self, limit: float, value=None, detail: str = ""):
        self.limit = float(limit)
        super().__init__("flow_rate", f"[0, {self.limit:.6g}] m^3/s, the flow rates whose inlet stretch stays "
                         "below 1e15 (the solver's range, not a physical limit)", value, detail)


class ConvergenceError(TubefsiError, ArithmeticError):
    """An iterative method did not reach its tolerance (a non-default method's failure)."""


def _short(value) -> str:
    if isinstance(value, (tuple, list)):      # a name such as ("in", "j"), a list of columns: as written
        text = repr(value)
        return text if len(text) <= 60 else text[:57] + "..."
    try:
        a = np.asarray(value)
    except Exception:          # noqa: BLE001 (a ragged list: the error must still be raised, with its words)
        text = repr(value)
        return text if len(text) <= 60 else text[:57] + "..."
    if a.ndim == 0:
        return f"{a.item()!r}"
    return f"array of shape {a.shape}"


class AccuracyWarning(UserWarning):
    """A non-default method's result is less accurate than its tolerance promises."""


class ModelValidityWarning(UserWarning):
    """A result leaves an assumption of the model (a slender tube, small strain for a linear
    wall, the wall law's calibrated range, a small reduced Reynolds number...).

    :func:`tubefsi.solve` issues it for the deformed tube; silence it with the standard
    filter, ``warnings.filterwarnings("ignore", category=tubefsi.ModelValidityWarning)``
    (``docs/scope.md``).
    """


class FitWarning(UserWarning):
    """A fit whose result the data do not support: the optimizer did not converge, a parameter
    ended at the edge of its search range, or a standard error is not finite or exceeds its
    value (:func:`tubefsi.fit`; the message says which, and what to try)."""


_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))


def warn_user(message: str, category: type[Warning]) -> None:
    """Issue a warning attributed to the first caller outside tubefsi (the user's line)."""
    frame, level = sys._getframe(0), 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE_DIR):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)


class BucklingError(NoSteadyStateError):
    """A transmural pressure below the most negative one the wall holds: an axisymmetric tube
    buckles there (the tube law no longer applies), or a tube law ends.

    Attributes
    ----------
    quantity : str
        ``"transmural_pressure"``.
    limit : float
        The lowest admissible transmural pressure (Pa, negative): minus the buckling pressure.
    """

    def __init__(self, limit: float, value=None, detail: str = ""):
        self.quantity = "transmural_pressure"
        self.limit = float(limit)
        got = "" if value is None else f" (got {_short(value)})"
        extra = f"; {detail}" if detail else ""
        TubefsiError.__init__(self, f"no steady state: the transmural pressure must stay above {self.limit:.10g} Pa"
                              f" (minus the buckling pressure){got}{extra}")
