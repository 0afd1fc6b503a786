"""Frozen dataclasses at a fraction of the start-up cost of ``dataclass(frozen=True)``.

Python 3.11's ``dataclass(frozen=True)`` compiles six methods per class from source: a
command that creates 70 classes spends ~50 ms of its start in the compiler. Here
``dataclasses`` still collects the fields (``fields``, ``replace``, ``asdict`` and
``is_dataclass`` work as ever), ``__init__`` is compiled from the source the standard library
writes, and ``__repr__``, ``__eq__``, ``__hash__``, ``__setattr__`` and ``__delattr__`` are
closures over the field names with the standard library's behaviour (tests/frozen_dataclass/
holds them side by side).
"""

from __future__ import annotations

import dataclasses
import inspect
import sys
from _thread import get_ident
from collections.abc import Callable
from types import CellType, CodeType, FunctionType
from typing import Any, TypeVar, cast, dataclass_transform, overload

_C = TypeVar("_C", bound=type)


class _Factory:
    """The default of an ``__init__`` parameter whose field has a ``default_factory``."""

    def __repr__(self) -> str:
        return "<factory>"


_HAS_FACTORY = _Factory()
# Methods a frozen class may not define itself (the standard library refuses them too).
_REFUSED = ("__setattr__", "__delattr__")


@overload
def frozen_dataclass(cls: _C, /) -> _C: ...


@overload
def frozen_dataclass(*, eq: bool = True, kw_only: bool = False) -> Callable[[_C], _C]: ...


@dataclass_transform(frozen_default=True, field_specifiers=(dataclasses.field, dataclasses.Field))
def frozen_dataclass(
    cls: _C | None = None, /, *, eq: bool = True, kw_only: bool = False
) -> _C | Callable[[_C], _C]:
    """``@dataclass(frozen=True, eq=eq, kw_only=kw_only)``, made cheaply (see the module)."""

    def wrap(cls: _C) -> _C:
        return cast(_C, _make(cls, eq=eq, kw_only=kw_only))

    return wrap if cls is None else wrap(cls)


def _make(cls: type[Any], *, eq: bool, kw_only: bool) -> type[Any]:
    own = dict(cls.__dict__)  # what the class defines itself, before ``dataclasses`` adds to it
    for name in _REFUSED:
        if name in own:
            raise TypeError(f"Cannot overwrite attribute {name} in class {cls.__name__}")
    documented = bool(own.get("__doc__"))
    class_hash = own.get("__hash__", dataclasses.MISSING)
    explicit_hash = not (
        class_hash is dataclasses.MISSING or (class_hash is None and "__eq__" in own)
    )
    # ``dataclasses`` insists that a dataclass's subclass be frozen as its bases are: a subclass
    # has the standard library's __setattr__ and __delattr__ compiled (a few classes).
    inherits = any("__dataclass_fields__" in vars(base) for base in cls.__mro__[1:])
    made = dataclasses.dataclass(
        cls, init=False, repr=False, eq=False, frozen=inherits, kw_only=kw_only
    )
    fields = dataclasses.fields(made)
    _refuse_init_vars(made, fields)
    methods: dict[str, Callable[..., Any]] = {
        "__init__": _init(made, fields),
        "__repr__": _repr(tuple(f.name for f in fields if f.repr)),
    }
    if not inherits:
        names = frozenset(f.name for f in fields)
        methods["__setattr__"] = _setattr(made, names)
        methods["__delattr__"] = _delattr(made, names)
    if eq:
        compared = tuple(f.name for f in fields if f.compare)
        methods["__eq__"] = _eq(compared)
        if not explicit_hash:
            hashed = tuple(f.name for f in fields if (f.compare if f.hash is None else f.hash))
            methods["__hash__"] = _hash(hashed)
    for name, method in methods.items():
        # A method the class defines itself stays, as with ``dataclass`` (but ``__hash__``,
        # which Python sets to None beside a class's own ``__eq__``).
        if name not in own or (name == "__hash__" and own[name] is None):
            method.__qualname__ = f"{made.__qualname__}.{name}"
            setattr(made, name, method)
    if not documented:
        made.__doc__ = _signature_doc(made)
    # Say what the class is, as ``dataclass(frozen=True, eq=eq)`` would: a subclass made by
    # either decorator reads ``frozen`` here.
    params: Any = made.__dataclass_params__
    params.init, params.repr, params.eq, params.frozen = True, True, eq, True
    return made


def _refuse_init_vars(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> None:
    plain = {f.name for f in fields}
    for name, f in cls.__dict__["__dataclass_fields__"].items():
        kind = f.type if isinstance(f.type, str) else type(f.type).__name__
        if name not in plain and "InitVar" in kind:
            raise TypeError(f"{cls.__qualname__}.{name}: frozen_dataclass has no InitVar")


# A body line of ``__init__``: the field's value is its parameter ("arg"), its factory's
# product unless the parameter is given ("either"), or its factory's product ("make").
_Line = tuple[str, int]
# The shape of an ``__init__``: its body lines (each with its parameter's index, or -1), the
# number of positional and keyword-only parameters, whether ``__post_init__`` is called.
_Shape = tuple[tuple[_Line, ...], int, int, bool]
_TEMPLATES: dict[_Shape, CodeType] = {}


def _init(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> Callable[..., None]:
    """``__init__`` as ``dataclass(frozen=True)`` writes it: the same parameters, defaults,
    annotations and body, from a template compiled once per shape (classes of the same shape
    differ only in names, which the template's code object takes over)."""
    self_name = "__dataclass_self__" if "self" in {f.name for f in fields} else "self"
    params = [f for f in fields if f.init and not f.kw_only]
    keyword = [f for f in fields if f.init and f.kw_only]
    signature = params + keyword
    seen_default = False
    for f in params:
        if _has_default(f):
            seen_default = True
        elif seen_default:
            raise TypeError(f"non-default argument {f.name!r} follows default argument")
    index = {f.name: i for i, f in enumerate(signature)}
    lines: list[_Line] = []
    values: dict[str, Any] = {"__dataclass_builtins_object__": object}
    attributes: list[str] = []
    for f in fields:
        factory = f.default_factory is not dataclasses.MISSING
        if not (f.init or factory):
            continue  # the class attribute holds the default, as with ``dataclass``
        kind = "arg" if not factory else "either" if f.init else "make"
        lines.append((kind, index[f.name] if f.init else -1))
        if factory:
            values[f"_f{len(attributes)}"] = f.default_factory
            values["_HAS_DEFAULT_FACTORY"] = _HAS_FACTORY
        attributes.append(f.name)
    shape: _Shape = (tuple(lines), len(params), len(keyword), hasattr(cls, "__post_init__"))
    template = _TEMPLATES.get(shape)
    if template is None:
        template = _TEMPLATES[shape] = _template(shape)
    names = {f"@{j}": name for j, name in enumerate(attributes)}
    code = template.replace(
        co_varnames=(
            self_name,
            *(f.name for f in signature),
            *template.co_varnames[1 + len(signature) :],
        ),
        co_consts=tuple(names.get(c, c) if isinstance(c, str) else c for c in template.co_consts),
        co_qualname=f"{cls.__qualname__}.__init__",
    )
    module = sys.modules.get(cls.__module__)
    init = FunctionType(
        code,
        module.__dict__ if module else {},
        "__init__",
        tuple(_default(f) for f in params if _has_default(f)) or None,
        tuple(CellType(values[name]) for name in code.co_freevars),
    )
    init.__kwdefaults__ = {f.name: _default(f) for f in keyword if _has_default(f)} or None
    init.__annotations__ = {f.name: f.type for f in signature} | {"return": None}
    return init


def _has_default(f: dataclasses.Field[Any]) -> bool:
    return f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING


def _default(f: dataclasses.Field[Any]) -> Any:
    return _HAS_FACTORY if f.default_factory is not dataclasses.MISSING else f.default


def _template(shape: _Shape) -> CodeType:
    """The code of an ``__init__`` of ``shape``: parameters ``_p<i>``, attribute names
    ``"@<j>"`` (no identifier is spelt so), factories ``_f<j>``, in the closure the standard
    library's source gives it."""
    lines, positional, keyword, post_init = shape
    params = ["self", *(f"_p{i}" for i in range(positional))]
    if keyword:
        params += ["*", *(f"_p{positional + i}" for i in range(keyword))]
    body = []
    for j, (kind, i) in enumerate(lines):
        value = {
            "arg": f"_p{i}",
            "either": f"_f{j}() if _p{i} is _HAS_DEFAULT_FACTORY else _p{i}",
            "make": f"_f{j}()",
        }[kind]
        body.append(f"__dataclass_builtins_object__.__setattr__(self,'@{j}',{value})")
    if post_init:
        body.append("self.__post_init__()")
    factories = [f"_f{j}" for j, (kind, _) in enumerate(lines) if kind != "arg"]
    outer = ["__dataclass_builtins_object__", "_HAS_DEFAULT_FACTORY", *factories]
    inner = "\n".join(f"  {line}" for line in body or ["pass"])
    source = (
        f"def __create_fn__({', '.join(outer)}):\n"
        f" def __init__({', '.join(params)}):\n{inner}\n"
        " return __init__"
    )
    module = compile(source, "<string>", "exec", dont_inherit=True)
    create = next(c for c in module.co_consts if isinstance(c, CodeType))
    return next(c for c in create.co_consts if isinstance(c, CodeType))


def _repr(names: tuple[str, ...]) -> Callable[[Any], str]:
    running: set[tuple[int, int]] = set()

    def __repr__(self: Any) -> str:  # noqa: N807 - the name a traceback shows
        key = (id(self), get_ident())
        if key in running:
            return "..."
        running.add(key)
        try:
            inside = ", ".join(f"{name}={getattr(self, name)!r}" for name in names)
        finally:
            running.discard(key)
        return f"{self.__class__.__qualname__}({inside})"

    return __repr__


def _eq(names: tuple[str, ...]) -> Callable[[Any, object], Any]:
    def __eq__(self: Any, other: object) -> Any:  # noqa: N807 - the name a traceback shows
        if other.__class__ is self.__class__:
            return tuple(getattr(self, n) for n in names) == tuple(getattr(other, n) for n in names)
        return NotImplemented

    return __eq__


def _hash(names: tuple[str, ...]) -> Callable[[Any], int]:
    def __hash__(self: Any) -> int:  # noqa: N807 - the name a traceback shows
        return hash(tuple(getattr(self, n) for n in names))

    return __hash__


def _setattr(cls: Any, names: frozenset[str]) -> Callable[[Any, str, Any], None]:
    def __setattr__(self: Any, name: str, value: Any) -> None:  # noqa: N807 - the name a traceback shows
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    return __setattr__


def _delattr(cls: Any, names: frozenset[str]) -> Callable[[Any, str], None]:
    def __delattr__(self: Any, name: str) -> None:  # noqa: N807 - the name a traceback shows
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    return __delattr__


def _signature_doc(cls: type) -> str:
    try:
        text = str(inspect.signature(cls)).replace(" -> None", "")
    except (TypeError, ValueError):
        text = ""
    return cls.__name__ + text
