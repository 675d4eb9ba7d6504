"""Wrong or missing keywords as :class:`~tubefsi.KeywordError` (``docs/verification.md``, "Fuzzing").

Python binds a call's arguments before the callee runs, and a keyword it cannot bind is its own
``TypeError``. Here every public entry point (:func:`checked_keywords`) and every model, coupler
and tube class (the metaclasses :class:`KeywordChecked` and :class:`KeywordCheckedABC`, which
the base classes use, so plugins' models get it too) catch that ``TypeError``, and only when the
arguments do not bind to the signature replace it by a :class:`~tubefsi.KeywordError` that names
the keyword, suggests the closest valid one and lists the valid ones. The success path of a
function costs one Python call frame, that of an attrs model none (its ``__init__`` checks the
arguments itself, :func:`_check_init`); the signature is read only on the error path.
"""

from __future__ import annotations

import abc
import functools

from .errors import KeywordError

__all__ = ["checked_keywords", "KeywordChecked", "KeywordCheckedABC", "keyword_error"]


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
    name = name or f"{getattr(target, '__qualname__', repr(target))}()"
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


def checked_keywords(function, recover=None, *, name=None, method=None):
    """Decorate a public function or method: a call whose arguments do not bind raises
    :class:`~tubefsi.KeywordError` instead of Python's ``TypeError``. ``recover``, optional, is
    ``(exception class, handler)``: where the call raises that exception, ``handler(function, args,
    kwargs)`` answers instead (None: the exception stands). ``name(args)``, optional, is what the
    error calls the callee and ``method`` is passed to :func:`keyword_error`. One call frame on the
    ordinary path."""
    caught, handler = recover if recover is not None else (_Never, None)

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError:
            error = keyword_error(function, args, kwargs, None if name is None else name(args), method=method)
            if error is None:
                raise
        except caught:
            found = handler(function, args, kwargs)
            if found is None:
                raise
            return found
        raise error

    return wrapper


class _Missing:
    """The default the checked ``__init__`` gives a required parameter (so that a missing one is
    seen inside the call instead of by Python's binding, which no frame could catch)."""

    __slots__ = ()

    def __repr__(self):
        return "<missing>"


_MISSING = _Missing()


def _reject(instance, original, args, kwargs, named):
    """Raise the :class:`~tubefsi.KeywordError` of a construction whose arguments do not bind to
    ``original`` (the ``__init__`` as written or generated), from what the checked ``__init__`` got."""
    given = {k: v for k, v in named.items() if v is not _MISSING}       # (all keyword-only)
    called = type(instance)
    # the class called, where this is its __init__; else the class that owns it (a subclass's own
    # __init__ called it: the keywords listed are this one's)
    owner = called.__name__ if getattr(called.__init__, "__globals__", {}).get("_tubefsi_init") is original \
        else original.__qualname__.rpartition(".")[0] or called.__name__
    error = keyword_error(original, (instance,) + args, {**given, **kwargs}, name=f"{owner}()", method=True)
    if error is None:                     # (not reached: the checked __init__ calls this only on a miss)
        raise TypeError(f"{type(instance).__name__}() got arguments that do not bind to its signature")
    raise error


def _float_guard(name, attribute, namespace):
    """The test under which ``attribute``'s converter and validator would pass the value of the
    parameter ``name`` through unchanged (a float in its interval, a str among its options;
    True for a field with neither), with its bounds put into ``namespace``; None if unknown."""
    converter = getattr(attribute.converter, "converter", attribute.converter)     # (an attrs.Converter)
    validator = attribute.validator
    if converter is not None and not getattr(converter, "passes_floats", False):
        return None
    interval = getattr(validator, "float_interval", None)
    if interval is not None:
        low, high, low_open, high_open = interval
        namespace[f"_tubefsi_low_{name}"], namespace[f"_tubefsi_high_{name}"] = low, high
        return (f"type({name}) is float and _tubefsi_low_{name} {'<' if low_open else '<='} {name} "
                f"{'<' if high_open else '<='} _tubefsi_high_{name}")
    options = getattr(validator, "string_options", None)
    if options is not None and converter is None:
        namespace[f"_tubefsi_options_{name}"] = tuple(options)
        return f"type({name}) is str and {name} in _tubefsi_options_{name}"
    if validator is None:
        return f"type({name}) is float" if converter is not None else "True"
    return None


def _only_stores(fn, names) -> bool:
    """Whether attrs' ``__init__`` body ``fn`` does nothing but what :func:`_fast_block` repeats:
    ``_setattr = _cached_setattr_get(self)``, ``_setattr(name, ...)`` for the fields ``names``
    (each once), the validators under ``if _config._run_validators is True`` and
    ``self.__attrs_post_init__()``. Anything else (a cached hash reset, ``self.x = ...`` through
    a class's own ``__setattr__``, ``__attrs_pre_init__``) and the fast block is not made."""
    import ast

    self_name = fn.args.args[0].arg
    stored = []
    for statement in fn.body:
        if (isinstance(statement, ast.Assign) and len(statement.targets) == 1
                and isinstance(statement.targets[0], ast.Name) and statement.targets[0].id == "_setattr"):
            continue
        call = statement.value if isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Call) else None
        if call is not None and isinstance(call.func, ast.Name) and call.func.id == "_setattr" and call.args \
                and isinstance(call.args[0], ast.Constant):
            stored.append(call.args[0].value)
            continue
        if (call is not None and isinstance(call.func, ast.Attribute) and call.func.attr == "__attrs_post_init__"
                and isinstance(call.func.value, ast.Name) and call.func.value.id == self_name and not call.args):
            continue
        if (isinstance(statement, ast.If) and not statement.orelse
                and ast.unparse(statement.test) == "_config._run_validators is True"
                and all(isinstance(inner, ast.Expr) and isinstance(inner.value, ast.Call)
                        and isinstance(inner.value.func, ast.Name)
                        and inner.value.func.id.startswith("__attr_validator_") for inner in statement.body)):
            continue
        return False
    return sorted(stored) == sorted(names)


def _fast_block(fn, attributes, namespace):
    """Statements that store every field at once where each value is one its converter returns
    unchanged and its validator accepts (:func:`_float_guard`), then return; [] where some field
    is beyond that (another converter or validator, a factory default) or attrs' code does more
    than store, validate and call ``__attrs_post_init__`` (:func:`_only_stores`).

    attrs converts every field, then validates every one; for such values both are identities,
    so storing them is what attrs' code does, without its four calls per field."""
    import ast

    import attrs

    if not attributes or not _only_stores(fn, [a.name for a in attributes]):
        return []
    self_name = fn.args.args[0].arg
    guards, stores = [], []
    for attribute in attributes:
        if not attribute.init or isinstance(attribute.default, attrs.Factory):
            return []
        guard = _float_guard(attribute.alias, attribute, namespace)
        if guard is None:
            return []
        guards.append(guard)
        stores.append(f"    _tubefsi_set({self_name}, {attribute.name!r}, {attribute.alias})")
    if any(isinstance(node, ast.Attribute) and node.attr == "__attrs_post_init__" for node in ast.walk(fn)):
        stores.append(f"    {self_name}.__attrs_post_init__()")
    namespace["_tubefsi_set"] = object.__setattr__
    return ast.parse(f"if {' and '.join(guards)}:\n" + "\n".join(stores) + "\n    return").body


def _checked_source(init, attributes=(), namespace=None):
    """The source of an attrs-generated ``__init__`` with the keyword check inside it, or None
    where it is not such a function of keyword-only parameters (a closure, a positional field:
    Python itself would reject a field given both ways before any code of ours ran).

    Every required parameter gets the default :data:`_MISSING` and the function ``*args`` and
    ``**kwargs``, so that every call binds; its first statement rejects a call with positional
    arguments, an unknown keyword or a missing one. With the class's ``attributes`` (attrs'
    fields) the next one stores values that need no conversion or check beyond its test
    (:func:`_fast_block`, whose constants go into ``namespace``). The rest is attrs' code,
    unchanged."""
    import ast
    import inspect
    import textwrap

    code = init.__code__
    if code.co_freevars or not code.co_filename.startswith("<attrs generated"):
        return None
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(init)))
    except (OSError, SyntaxError, TypeError):
        return None
    fn = tree.body[0]
    if not isinstance(fn, ast.FunctionDef):
        return None
    a = fn.args
    if a.vararg or a.kwarg or a.posonlyargs or len(a.args) != 1:
        return None
    required = [p.arg for p, d in zip(a.kwonlyargs, a.kw_defaults) if d is None]
    a.kw_defaults = [ast.Name("_tubefsi_missing", ast.Load()) if d is None else d for d in a.kw_defaults]
    a.vararg, a.kwarg = ast.arg("_tubefsi_args"), ast.arg("_tubefsi_kwargs")
    test = " or ".join(["_tubefsi_args", "_tubefsi_kwargs"] + [f"{n} is _tubefsi_missing" for n in required])
    named = ", ".join(f"{p.arg!r}: {p.arg}" for p in a.kwonlyargs)
    fast = _fast_block(fn, attributes, {} if namespace is None else namespace)
    fn.body = ast.parse(f"if {test}:\n    _tubefsi_reject({a.args[0].arg}, _tubefsi_init, _tubefsi_args, "
                        f"_tubefsi_kwargs, {{{named}}})").body + fast + fn.body
    return ast.unparse(ast.fix_missing_locations(tree)) + "\n"


def _repoint_class_cells(function, old, new) -> None:
    """Point the closure cells of ``function`` that hold the class ``old`` at ``new`` (what attrs
    does for a slotted class's own methods)."""
    for cell in getattr(function, "__closure__", None) or ():
        try:
            if cell.cell_contents is old:
                cell.cell_contents = new
        except ValueError:                 # an empty cell
            pass


def _check_init(cls) -> None:
    """Give ``cls`` an ``__init__`` that raises :class:`~tubefsi.KeywordError` for arguments that do
    not bind, if its own ``__init__`` (in its ``__dict__``) is not one yet.

    An attrs-generated ``__init__`` is compiled again with the check as its first statement and
    a store of plain in-range floats as its second (:func:`_checked_source`: no frame more than
    attrs' own, and none for the converters and validators of a model built in a loop from
    floats); any other one is wrapped (one frame more). The signature shown is the original's."""
    import inspect
    import linecache

    init = cls.__dict__.get("__init__")
    if init is None or not inspect.isfunction(init):
        return
    if getattr(init, "_keyword_checked", False):
        owner = init._keyword_owner
        if owner is not cls:
            # the class made again with this __init__ (attrs' slotted class): attrs points the
            # __class__ cells (super()) of the functions in its dict at the new class, but the
            # function this one wraps is not in it
            _repoint_class_cells(getattr(init, "__wrapped__", None), owner, cls)
            init._keyword_owner = cls
        return
    namespace = dict(init.__globals__, _tubefsi_missing=_MISSING, _tubefsi_reject=_reject, _tubefsi_init=init)
    source = _checked_source(init, getattr(cls, "__attrs_attrs__", ()), namespace)
    if source is not None:
        source = ("# attrs' __init__ with the keyword check of tubefsi._keywords (_check_init) first\n"
                  + source)
        filename = f"{init.__code__.co_filename[:-1]}, keyword-checked>"
        exec(compile(source, filename, "exec"), namespace)     # noqa: S102 (attrs' own code, rewritten)
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)   # for tracebacks
        checked = namespace[init.__name__]
        checked.__qualname__, checked.__module__, checked.__doc__ = init.__qualname__, init.__module__, init.__doc__
        checked.__annotations__ = dict(init.__annotations__)
    else:                                      # named after the class called, as a model is
        checked = checked_keywords(init, name=lambda args: f"{type(args[0]).__name__}()", method=True)
    checked.__signature__ = inspect.signature(init)
    checked._keyword_checked, checked._keyword_owner = True, cls
    type.__setattr__(cls, "__init__", checked)


class KeywordChecked(type):
    """Metaclass: constructing the class with arguments that do not bind to its ``__init__``
    raises :class:`~tubefsi.KeywordError`.

    The check is inside ``__init__`` itself (:func:`_check_init`, applied to every class made
    with this metaclass and to every ``__init__`` set on it later), not in a ``__call__``
    of the metaclass: that frame and its re-packing of the arguments were a third of the cost
    of building a model."""

    def __init__(cls, name, bases, namespace, **kwargs):
        super().__init__(name, bases, namespace, **kwargs)
        _check_init(cls)          # a slotted attrs class is made with its __init__, a plain one may have its own

    def __setattr__(cls, name, value):
        # an __init__ set on the finished class: attrs' for a dict class, a dataclass's, a user's
        super().__setattr__(name, value)
        if name == "__init__":
            _check_init(cls)

    @property
    def __signature__(cls):
        # what ``inspect.signature`` (and so the documentation) shows: ``__init__`` without ``self``
        import inspect

        signature = inspect.signature(cls.__init__)
        return signature.replace(parameters=list(signature.parameters.values())[1:],
                                 return_annotation=inspect.Signature.empty)


class KeywordCheckedABC(KeywordChecked, abc.ABCMeta):
    """:class:`KeywordChecked` for abstract bases (``WallModel``, ``Rheology``, ``Coupler``)."""
