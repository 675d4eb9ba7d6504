"""Wrong or missing keywords as :class:`~tubefsi.KeywordError` (``docs/verification.md``, "Fuzzing").

Python binds a call's arguments before the callee runs, and a keyword it cannot bind is its own
``TypeError``. A public entry point decorated with :func:`checked_keywords` (``solve``,
``max_flow_rate``, ``advise``, ``fit``, the ``Network`` API) catches that ``TypeError`` and,
only when the arguments do not bind to its signature, replaces it by a
:class:`~tubefsi.KeywordError` that names the keyword, suggests the closest valid one and lists
the valid ones. The success path costs one Python call frame; the signature is read only on the
error path.

Model, coupler and ``Tube`` constructors are plain attrs classes and are not wrapped: a wrong
keyword there is Python's own ``TypeError`` (a model is built per solve in a Monte Carlo loop,
and a wrapper would cost more than the check is worth). Where a public function builds a model
from a user's keyword dict it calls :func:`construct`, which gives the ``KeywordError``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, TypeVar

from .errors import KeywordError

__all__ = ["checked_keywords", "construct", "keyword_error"]

#: the type of a decorated function: the decorators keep its signature for type checkers
Function = TypeVar("Function", bound=Callable[..., Any])


def keyword_error(target, args, kwargs, name=None, *, method=None):
    """The :class:`~tubefsi.KeywordError` of a call of ``target`` with ``args`` and ``kwargs``
    that does not bind to its signature; ``None`` if it binds (the ``TypeError`` came from inside).
    A method's ``self`` or ``cls`` is in ``args`` and is not listed as a keyword; ``method``
    says whether ``target`` is one (None: a function defined in a class body whose first
    parameter is ``self`` or ``cls``)."""
    import difflib
    import inspect

    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return None
    try:
        signature.bind(*args, **kwargs)
    except TypeError:
        pass
    else:
        return None
    kinds = inspect.Parameter
    params = signature.parameters.values()
    if method is None:
        method = "." in getattr(target, "__qualname__", "") and next(iter(signature.parameters), "") in ("self", "cls")
    bound_self = 1 if method and args else 0
    valid = [p.name for p in params if p.kind in (kinds.POSITIONAL_OR_KEYWORD, kinds.KEYWORD_ONLY)][bound_self:]
    # a constructor is named as the class is called: "Network()", not "Network.__init__()"
    name = name or f"{getattr(target, '__qualname__', repr(target)).removesuffix('.__init__')}()"
    if not any(p.kind is kinds.VAR_KEYWORD for p in params):
        unknown = [k for k in kwargs if k not in valid]
        if unknown:
            word = unknown[0]
            close = [v for v in valid if v.startswith(word) or word.startswith(v)]     # a short form first
            close = close or difflib.get_close_matches(word, valid, n=1, cutoff=0.6)
            return KeywordError(name, word, valid, suggestion=close[0] if close else None)
    positional = [p for p in params if p.kind in (kinds.POSITIONAL_ONLY, kinds.POSITIONAL_OR_KEYWORD)]
    if not any(p.kind is kinds.VAR_POSITIONAL for p in params) and len(args) > len(positional):
        return KeywordError(name, "positional arguments", valid,
                            detail=f"takes {len(positional) - bound_self} positional arguments but "
                                   f"{len(args) - bound_self} were given "
                                   "(give the others by keyword)")
    given = {p.name for p in positional[:len(args)]} | set(kwargs)
    twice = [p.name for p in positional[:len(args)] if p.name in kwargs]
    if twice:
        return KeywordError(name, twice[0], valid, detail=f"got {twice[0]!r} both by position and by keyword")
    missing = [p.name for p in params if p.default is p.empty and p.name not in given
               and p.kind not in (kinds.VAR_POSITIONAL, kinds.VAR_KEYWORD)]
    if missing:
        return KeywordError(name, missing[0], valid, missing=missing)
    return None


class _Never(Exception):
    """Raised by nothing: the exception a wrapper without ``recover`` catches."""


def checked_keywords(function: Function, recover: tuple | None = None) -> Function:
    """Decorate a public function or method: a call whose arguments do not bind raises
    :class:`~tubefsi.KeywordError` instead of Python's ``TypeError``. ``recover``, optional, is
    ``(exception class, handler)``: where the call raises that exception, ``handler(function, args,
    kwargs)`` answers instead (None: the exception stands). One call frame on the ordinary path."""
    caught, handler = recover if recover is not None else (_Never, None)

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError:
            error = keyword_error(function, args, kwargs)
            if error is None:
                raise
        except caught:
            found = handler(function, args, kwargs)
            if found is None:
                raise
            return found
        raise error

    return wrapper  # type: ignore[return-value]  # functools.wraps: the same signature


def construct(cls, kwargs: dict):
    """``cls(**kwargs)``, for a public function that builds a model from a dict of keywords its
    caller gave: keywords that do not bind to the class raise :class:`~tubefsi.KeywordError`
    (any other error, a ``TypeError`` from inside included, stands)."""
    try:
        return cls(**kwargs)
    except TypeError:
        error = keyword_error(cls, (), kwargs, name=f"{cls.__name__}()", method=False)
        if error is None:
            raise
    raise error
