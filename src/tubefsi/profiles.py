r"""Parameters that vary along the tube: :class:`Profile` and :func:`sampled`.

A :class:`~tubefsi.Tube` field (radius :math:`a(z)`, thickness :math:`t(z)`) or a wall parameter
(a modulus :math:`\mu(z)`) may be given as a function of the axial position :math:`z` (m, 0 at the
inlet, :math:`L` at the outlet) instead of a number: a tapered needle, a stenosis, a channel cast
with graded stiffness (``docs/graded.md``). Any callable is accepted and wrapped in a
:class:`Profile`; it is called with a float array of positions and must return an array of the
same shape (or a scalar: a constant). A table of measured values is a :func:`sampled` profile.

Every evaluation is checked: a value outside the parameter's admissible range, a NaN or a result
of the wrong shape raises :class:`~tubefsi.InvalidParameterError` naming the parameter and the
position.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from .errors import InvalidParameterError

__all__ = ["Profile", "sampled"]


def _constant(value):
    return lambda z: np.full(np.shape(z), value)


@attrs.frozen(eq=False, repr=False)
class Profile:
    r"""A parameter as a function of the axial position :math:`z` (m): ``Profile(function)``.

    The parameter it stands for (its name and admissible range) is bound when a model or a
    :class:`~tubefsi.Tube` takes it; calling the profile then validates the values.

    Parameters
    ----------
    function : callable
        ``function(z)`` for a float array ``z`` (m, 0 at the inlet): an array of ``z``'s shape, or
        a scalar (a constant profile). Vectorized: it is called with many positions at once.
    breakpoints : sequence of float, optional
        Positions (m) where the function or its derivatives jump (the knots of a table, the ends
        of a stenosis): the integration along the tube never steps across one.
    span : (float, float), optional
        The positions the function is defined on (default: all); a tube longer than the span
        is an :class:`~tubefsi.InvalidParameterError`.
    """

    function: object
    breakpoints: tuple = attrs.field(default=(), converter=lambda b: tuple(sorted(float(x) for x in b)))
    span: tuple = (-math.inf, math.inf)
    name: str = "profile"
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = True
    high_open: bool = True
    #: ``(value factor, position factor)``: the profile is ``value * function(position * z)``.
    scale: tuple = (1.0, 1.0)

    def bind(self, name, low=-math.inf, high=math.inf, low_open=True, high_open=True) -> Profile:
        """This profile standing for the parameter ``name`` with the admissible interval given."""
        return attrs.evolve(self, name=name, low=low, high=high, low_open=low_open, high_open=high_open)

    def scaled(self, value=1.0, position=1.0) -> Profile:
        r"""The profile :math:`z \mapsto` ``value`` :math:`\cdot f(` ``position`` :math:`\cdot z)` (an
        installed tube: radius over :math:`\sqrt{\lambda_z}`, position over :math:`\lambda_z`)."""
        v, p = self.scale
        return attrs.evolve(self, scale=(v * float(value), p * float(position)),
                            breakpoints=tuple(b / float(position) for b in self.breakpoints),
                            span=tuple(s / float(position) for s in self.span))

    @property
    def admissible(self) -> str:
        lo = "(" if self.low_open else "["
        hi = ")" if self.high_open else "]"
        return f"functions of z with values in {lo}{self.low:g}, {self.high:g}{hi}"

    def __call__(self, z):
        """The values at the positions ``z`` (m), validated (``InvalidParameterError``)."""
        z = np.asarray(z, dtype=float)
        v_scale, z_scale = self.scale
        try:
            with np.errstate(all="ignore"):
                raw = self.function(z * z_scale if z_scale != 1.0 else z)
        except InvalidParameterError:
            raise
        except Exception as exc:           # a user function that fails: name it, keep the cause
            raise InvalidParameterError(self.name, self.admissible, self.function,
                                        f"calling it at z of shape {z.shape} raised {type(exc).__name__}: {exc}") from exc
        try:
            values = np.asarray(raw, dtype=float)
        except (TypeError, ValueError):
            raise InvalidParameterError(self.name, self.admissible, raw, "it returned no real numbers") from None
        if values.shape != z.shape:
            if values.ndim != 0:
                raise InvalidParameterError(self.name, self.admissible, self.function,
                                            f"called with z of shape {z.shape} it returned shape {values.shape}; "
                                            "it must be vectorized (same shape as z) or return a scalar")
            values = np.full(z.shape, float(values))
        if v_scale != 1.0:
            values = values * v_scale
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(values) | ((values == math.inf) & (self.high == math.inf) & (not self.high_open))
            ok &= (values > self.low) if self.low_open else (values >= self.low)
            ok &= (values < self.high) if self.high_open else (values <= self.high)
        if not np.all(ok):
            i = int(np.argmax(~ok.ravel()))
            raise InvalidParameterError(self.name, self.admissible, float(values.ravel()[i]),
                                        f"its value at z = {float(z.ravel()[i]):.17g} m")
        return values

    def check_span(self, length) -> None:
        """Raise ``InvalidParameterError`` unless the profile is defined on ``[0, length]``."""
        lo, hi = self.span
        top = float(np.max(length))
        if lo > 0 or hi < top * (1 - 1e-12):
            raise InvalidParameterError(self.name, f"a profile defined on [0, L], L = {top:g} m", self,
                                        f"it is defined on [{lo:g}, {hi:g}] m")

    # arithmetic with numbers and other profiles (the installed tube, t/a)
    def _combine(self, other, op, symbol):
        if isinstance(other, Profile):
            f, g = self, other
            return Profile(lambda z: op(f(z), g(z)), breakpoints=self.breakpoints + other.breakpoints,
                           span=(max(self.span[0], other.span[0]), min(self.span[1], other.span[1])),
                           name=f"{self.name} {symbol} {other.name}")
        if np.ndim(other) != 0:
            return NotImplemented
        c, f = float(other), self
        return Profile(lambda z: op(f(z), c), breakpoints=self.breakpoints, span=self.span,
                       name=f"{self.name} {symbol} {c:g}")

    def __mul__(self, other):
        return self._combine(other, np.multiply, "*")

    def __rmul__(self, other):
        return self._combine(other, np.multiply, "*")

    def __truediv__(self, other):
        return self._combine(other, np.divide, "/")

    def __rtruediv__(self, other):
        if isinstance(other, Profile) or np.ndim(other) != 0:
            return NotImplemented
        c, f = float(other), self
        return Profile(lambda z: c / f(z), breakpoints=self.breakpoints, span=self.span, name=f"{c:g} / {self.name}")

    def __repr__(self) -> str:
        return f"Profile({getattr(self.function, '__name__', type(self.function).__name__)}, name={self.name!r})"


def sampled(z, values, *, kind="pchip") -> Profile:
    r"""A :class:`Profile` interpolating a table of ``values`` at the positions ``z`` (m).

    Parameters
    ----------
    z : array_like
        Strictly increasing positions (m) covering the tube, ``z[0] <= 0`` and ``z[-1] >= L``.
    values : array_like
        The parameter's values there (same length).
    kind : {"pchip", "linear"}
        ``"pchip"`` (default): the monotone piecewise-cubic Hermite interpolant
        (:class:`scipy.interpolate.PchipInterpolator`, continuous slope, no overshoot: positive
        data stay positive); ``"linear"``: piecewise linear. Either way the knots are the
        profile's breakpoints: the integration along the tube stops at each one.
    """
    zz = np.asarray(z, dtype=float)
    vv = np.asarray(values, dtype=float)
    if zz.ndim != 1 or zz.size < 2 or not np.all(np.isfinite(zz)) or not np.all(np.diff(zz) > 0):
        raise InvalidParameterError("z", "a strictly increasing 1-D array of at least 2 finite positions", z)
    if vv.shape != zz.shape or not np.all(np.isfinite(vv)):
        raise InvalidParameterError("values", f"finite values, one per position (shape {zz.shape})", values)
    if kind == "linear":
        def function(x):
            return np.interp(x, zz, vv)
    elif kind == "pchip":
        from scipy.interpolate import PchipInterpolator

        function = PchipInterpolator(zz, vv, extrapolate=False)
    else:
        raise InvalidParameterError("kind", "{'pchip', 'linear'}", kind)
    inner = tuple(zz[1:-1])
    return Profile(function, breakpoints=inner, span=(float(zz[0]), float(zz[-1])))


def as_profile(value, field=None):
    """``value`` as a :class:`Profile` bound to ``field`` (an attrs field) if it is a callable or a
    profile; None otherwise."""
    if isinstance(value, (bool, str, bytes, int, float, np.ndarray, np.generic)) or not callable(value):
        return None
    profile = value if isinstance(value, Profile) else Profile(value)
    if field is None:
        return profile
    meta = field.metadata
    return profile.bind(field.name, meta.get("low", -math.inf), meta.get("high", math.inf),
                        meta.get("low_open", True), meta.get("high_open", True))
