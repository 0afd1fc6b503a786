"""ertools.frozen_dataclass against ``dataclasses.dataclass(frozen=True)``: every class shape
the project uses is written twice, once per decorator, and the two must behave the same
(signature, repr, equality, hash, frozenness, replace, asdict, errors), issue 39 (start-up)."""

from __future__ import annotations

import builtins
import dataclasses
import inspect
import pickle
import sys
import types
from typing import Any

import pytest

from ertools.frozen_dataclass import frozen_dataclass

# Each shape: (class source with {deco} for the decorator's arguments, constructor calls).
SHAPES: dict[str, tuple[str, list[tuple[tuple[Any, ...], dict[str, Any]]]]] = {
    "plain": (
        '''
@{deco}
class C:
    """A docstring."""
    a: int
    b: str
''',
        [((1, "x"), {}), ((), {"a": 2, "b": "y"}), ((1,), {}), ((1, "x", 3), {}), ((), {"c": 1})],
    ),
    "defaults and factories": (
        """
@{deco}
class C:
    a: int
    b: float = 2.5
    c: list[int] = field(default_factory=list)
    d: tuple[int, ...] = field(default=(1,), repr=False)
    e: dict[str, int] = field(default_factory=dict, init=False)
    f: int = field(default=7, init=False)
""",
        [((1,), {}), ((1, 3.0, [4]), {}), ((1,), {"d": (9,)})],
    ),
    "compare and hash switches": (
        """
@{deco}
class C:
    a: int
    b: int = field(compare=False)
    c: int = field(default=0, hash=False)
    d: int = field(default=0, compare=False, hash=True)
""",
        [((1, 2), {}), ((1, 3), {}), ((1, 2, 5, 6), {})],
    ),
    "kw_only": (
        """
@{deco}({kw})
class C:
    a: int
    b: int = 3
""",
        [((), {"a": 1}), ((), {"a": 1, "b": 4})],
    ),
    "post_init": (
        """
@{deco}
class C:
    a: int
    b: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "b", self.a * 2)
        if self.a < 0:
            raise ValueError("negative")
""",
        [((3,), {}), ((-1,), {})],
    ),
    "kw_only field before a required one": (
        "\n@{deco}\nclass C:\n    a: int = field(default=0, kw_only=True)\n    b: int\n",
        [((5,), {}), ((5,), {"a": 2})],
    ),
    "no fields": ("\n@{deco}\nclass C:\n    pass\n", [((), {})]),
    "field named self": (
        "\n@{deco}\nclass C:\n    self: int\n    other: int = 1\n",
        [((5,), {}), ((), {"self": 5, "other": 2})],
    ),
    "own repr and eq": (
        """
@{deco}
class C:
    a: int

    def __repr__(self) -> str:
        return "mine"

    def __eq__(self, other: object) -> bool:
        return True
""",
        [((1,), {})],
    ),
    "own hash": (
        "\n@{deco}\nclass C:\n    a: int\n\n    def __hash__(self) -> int:\n        return 42\n",
        [((1,), {}), ((2,), {})],
    ),
    "eq off": ("\n@{deco}({eq_off})\nclass C:\n    a: int\n", [((1,), {}), ((1,), {})]),
    "classvar": (
        "\n@{deco}\nclass C:\n    a: int\n    K: ClassVar[int] = 3\n",
        [((1,), {})],
    ),
}


def _build(source: str, stdlib: bool) -> type:
    """The class of ``source`` in a module of its own (as the project writes classes, with
    postponed annotations), made by one decorator or the other."""
    module = types.ModuleType(f"shape_{'std' if stdlib else 'ours'}_{abs(hash(source))}")
    sys.modules[module.__name__] = module
    module.__dict__.update(
        dataclass=dataclasses.dataclass,
        field=dataclasses.field,
        frozen_dataclass=frozen_dataclass,
    )
    deco = "dataclass(frozen=True)" if stdlib else "frozen_dataclass"
    kw = "frozen=True, kw_only=True" if stdlib else "kw_only=True"
    eq_off = "frozen=True, eq=False" if stdlib else "eq=False"
    text = source.replace("@{deco}({kw})", f"@{deco.split('(', maxsplit=1)[0]}({kw})")
    text = text.replace("@{deco}({eq_off})", f"@{deco.split('(', maxsplit=1)[0]}({eq_off})")
    text = text.replace("{deco}", deco)
    code = "from __future__ import annotations\nfrom typing import ClassVar\n" + text
    exec(compile(code, module.__name__, "exec"), module.__dict__)
    made: type = module.__dict__["C"]
    return made


def _outcome(call: Any) -> tuple[str, Any]:
    try:
        return ("ok", call())
    except Exception as error:  # the same error, type and message, from both
        return (type(error).__name__, str(error))


def _behaviour(cls: type, calls: list[tuple[tuple[Any, ...], dict[str, Any]]]) -> list[Any]:
    seen: list[Any] = [
        str(inspect.signature(cls)),
        cls.__doc__,
        getattr(cls, "__match_args__", None),
        [f.name for f in dataclasses.fields(cls)],
        dataclasses.is_dataclass(cls),
        repr(cls.__dataclass_params__),  # type: ignore[attr-defined]
        dict(cls.__dict__["__init__"].__annotations__),
    ]
    made = [_outcome(lambda a=a, k=k: cls(*a, **k)) for a, k in calls]
    objs = [obj for status, obj in made if status == "ok"]
    seen.append([(s, repr(o) if s == "ok" else o) for s, o in made])
    for x in objs:
        hashed = type(x).__hash__ is not object.__hash__  # type: ignore[comparison-overlap]
        seen.append(_outcome(lambda x=x, h=hashed: hash(x) if h else "identity"))
        seen.append(_outcome(lambda x=x: setattr(x, "a", 0)))
        seen.append(_outcome(lambda x=x: setattr(x, "new", 0)))
        seen.append(_outcome(lambda x=x: delattr(x, "a")))
        seen.append(_outcome(lambda x=x: dataclasses.asdict(x)))
        seen.append(_outcome(lambda x=x: repr(dataclasses.replace(x))))
        seen.append(_outcome(lambda x=x: repr(pickle.loads(pickle.dumps(x)))))
        seen.append([x == y for y in objs] + [x == object(), x != objs[0]])
    first = [obj for obj in objs[:1]]
    for x in first:
        factory_lists = [v for v in vars(x).values() if isinstance(v, list | dict)]
        other = cls(*calls[0][0], **calls[0][1])
        seen.append(all(v is not w for v in factory_lists for w in vars(other).values()))
    return seen


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_behaves_as_the_standard_library(shape: str) -> None:
    source, calls = SHAPES[shape]
    assert _behaviour(_build(source, True), calls) == _behaviour(_build(source, False), calls)


def test_inheritance_and_own_frozen_errors() -> None:
    source = """
@{deco}
class Base:
    a: int
    b: int = 1

@{deco}
class C(Base):
    c: int = 2

class Plain(C):
    pass
"""
    std, ours = _build(source, True), _build(source, False)
    calls: list[tuple[tuple[Any, ...], dict[str, Any]]] = [((1,), {}), ((1, 2, 3), {})]
    assert _behaviour(std, calls) == _behaviour(ours, calls)
    for cls in (std, ours):
        plain = sys.modules[cls.__module__].__dict__["Plain"]
        obj = plain(1)
        obj.extra = 5  # a plain subclass may add attributes, not assign fields
        assert obj.extra == 5
        with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign to field 'a'"):
            obj.a = 3


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("\n@{deco}\nclass C:\n    a: int = 1\n    b: int\n", "non-default argument 'b' follows"),
        (
            "\n@{deco}\nclass C:\n    a: int\n    def __setattr__(self, n, v): pass\n",
            "Cannot overwrite attribute __setattr__",
        ),
    ],
)
def test_refuses_what_the_standard_library_refuses(source: str, message: str) -> None:
    for stdlib in (True, False):
        with pytest.raises(TypeError, match=message):
            _build(source, stdlib)


def test_no_init_var() -> None:
    source = "\n@{deco}\nclass C:\n    a: int\n    b: InitVar[int]\n"
    with pytest.raises(TypeError, match=r"C\.b: frozen_dataclass has no InitVar"):
        _build(source.replace("\n@", "\nfrom dataclasses import InitVar\n@"), False)


def test_compiles_one_template_per_shape() -> None:
    """The reason for the module: classes of one shape share one compiled ``__init__``
    template, where the standard library compiles six methods per class (counted through
    ``exec`` and ``compile``, which both reach)."""
    counted = {"n": 0}
    real_compile, real_exec = builtins.compile, builtins.exec

    def counting_exec(source: Any, *args: Any, **kwargs: Any) -> Any:
        if isinstance(source, str) and "def __create_fn__" in source:
            counted["n"] += 1
        return real_exec(source, *args, **kwargs)

    def counting_compile(source: Any, *args: Any, **kwargs: Any) -> Any:
        if isinstance(source, str) and "def __create_fn__" in source:
            counted["n"] += 1
        return real_compile(source, *args, **kwargs)

    # two classes of one shape no other test has (eleven fields, a factory in the middle)
    fields = [f"    {{p}}{i}: int" for i in range(5)] + [
        "    {p}5: list[int] = field(default_factory=list)"
    ]
    fields += [f"    {{p}}{i}: int = {i}" for i in range(6, 11)]
    body = "\n".join(fields)
    source = "".join(
        f"\n@{{deco}}\nclass {c}:\n{body.format(p=p)}\n" for c, p in (("C", "a"), ("D", "b"))
    )
    results = {}
    for stdlib in (True, False):
        counted["n"] = 0
        builtins.exec, builtins.compile = counting_exec, counting_compile
        try:
            _build(source, stdlib)
        finally:
            builtins.exec, builtins.compile = real_exec, real_compile
        results[stdlib] = counted["n"]
    assert results[True] == 12 and results[False] <= 1
    calls: list[tuple[tuple[Any, ...], dict[str, Any]]] = [
        ((0, 1, 2, 3, 4), {}),
        ((0, 1, 2, 3, 4, [9]), {"a10": 7}),
        ((0, 1, 2, 3), {}),  # missing a4: the same message from both
    ]
    assert _behaviour(_build(source, True), calls) == _behaviour(_build(source, False), calls)


def test_mixes_with_the_standard_library() -> None:
    """A class of either decorator may be the other's base (a benchmark written outside the
    package subclasses ``ResultBase`` with ``@dataclass(frozen=True)``), and a mutable
    dataclass may not subclass a frozen one, as ever."""

    @frozen_dataclass
    class Ours:
        a: int

    @dataclasses.dataclass(frozen=True)
    class Theirs(Ours):
        b: int = 2

    @frozen_dataclass
    class OursAgain(Theirs):
        c: int = 3

    obj = OursAgain(1)
    assert repr(obj) == "test_mixes_with_the_standard_library.<locals>.OursAgain(a=1, b=2, c=3)"
    assert obj == OursAgain(1) and hash(obj) == hash((1, 2, 3))
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign to field 'b'"):
        obj.b = 5  # type: ignore[misc]
    with pytest.raises(TypeError, match="cannot inherit non-frozen dataclass from a frozen one"):

        @dataclasses.dataclass
        class Mutable(Ours):  # type: ignore[misc]
            d: int = 4
