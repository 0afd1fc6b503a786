"""Deserializers built from the message definitions stored in each file (never a fixed store).

The 2015 custom messages (``rockin_scoring/BmBoxState`` ...) decode this way with no ROS and
no hand-written type table: their definitions travel inside the bag.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ertools.errors import BagError
from ertools.io import budget
from ertools.io.model import Conn, long_msgtype

_IDL_SEP = "=" * 80 + "\n"


def _store_name(conn: Conn) -> str:
    """The name rosbags registers a connection's type under.

    rosbags files a ``.msg`` definition under ``pkg/msg/Name`` or ``pkg/action/Name`` and
    puts ``msg`` into any other name (a rosbag2 service event ``pkg/srv/Name_Event`` becomes
    ``pkg/srv/msg/Name_Event``); IDL definitions keep their module path.
    """
    name = long_msgtype(conn.msgtype)
    if conn.msgdef_format == "idl":
        return name
    pkg, _, base = name.rpartition("/")
    if pkg.rsplit("/", 1)[-1] in ("msg", "action"):
        return name
    return f"{pkg}/msg/{base}"


class Deserializer:
    """Deserialize raw messages of some connections with their stored definitions."""

    def __init__(self, conns: Sequence[Conn], path: Path) -> None:
        from rosbags.typesys import (  # lazy: rosbags, 100 ms
            Stores,
            TypesysError,
            get_types_from_idl,
            get_types_from_msg,
            get_typestore,
        )

        self.path = path
        types: dict[str, Any] = {}
        for conn in conns:
            if not conn.msgdef.strip() and conn.msgtype.split("/")[-1] != "Empty":
                raise BagError(
                    f"topic {conn.topic}: type {conn.msgtype} has no stored message definition, "
                    "so it cannot be decoded without ROS; re-record with definitions stored",
                    path=path,
                )
            try:
                if conn.msgdef_format == "idl":
                    if conn.msgdef.startswith(f"{_IDL_SEP}IDL: "):
                        for part in conn.msgdef.split(_IDL_SEP)[1:]:
                            types.update(get_types_from_idl(part.split("\n", 1)[1]))
                    else:
                        types.update(get_types_from_idl(conn.msgdef))
                else:
                    types.update(get_types_from_msg(conn.msgdef, _store_name(conn)))
            except (TypesysError, ValueError, IndexError) as err:
                raise BagError(
                    f"topic {conn.topic}: stored definition of {conn.msgtype} does not parse "
                    f"({_first_line(err)})",
                    path=path,
                ) from err
        _check_nesting(types, path)
        self.typestore = get_typestore(Stores.EMPTY)
        try:
            self.typestore.register(types)
        except TypesysError as err:
            raise BagError(f"conflicting stored message definitions ({err})", path=path) from err

    def __call__(self, raw: bytes | memoryview, conn: Conn) -> Any:
        """The message object of ``raw`` (a rosbags dataclass instance)."""
        from rosbags.serde import SerdeError  # lazy: rosbags, 100 ms

        try:
            if conn.encoding == "ros1":
                return self.typestore.deserialize_ros1(raw, _store_name(conn))
            return self.typestore.deserialize_cdr(raw, _store_name(conn))
        except (
            SerdeError,
            ValueError,
            IndexError,
            KeyError,
            struct.error,
            UnicodeDecodeError,
        ) as err:
            raise BagError(
                f"topic {conn.topic}: message of type {conn.msgtype} does not decode with its "
                f"stored definition ({type(err).__name__}: {err})",
                path=self.path,
            ) from err


def _check_nesting(types: dict[str, Any], path: Path) -> None:
    """Refuse stored definitions whose types nest deeper than the budget, or hold themselves:
    rosbags builds and runs its (de)serializers recursively, one level per nested type."""
    depth: dict[str, int] = {}
    for root in types:
        # iterative depth-first walk: a definition thousands of types deep must not recurse
        stack: list[tuple[str, list[str]]] = [(root, _nested(types, root))]
        on_path = {root}
        while stack:
            name, todo = stack[-1]
            if len(stack) > budget.MAX_NESTING:
                raise BagError(
                    budget.over_budget(
                        f"stored definition of {root}",
                        "types nested deeper",
                        f"{budget.MAX_NESTING} levels",
                        "MAX_NESTING",
                    ),
                    path=path,
                )
            if not todo:
                stack.pop()
                on_path.discard(name)
                depth[name] = 1 + max((depth.get(n, 0) for n in _nested(types, name)), default=0)
                continue
            child = todo.pop()
            if child in on_path:
                raise BagError(
                    f"stored definition of {name} holds a field of its own type {child} "
                    "(a recursive definition: not a ROS message)",
                    path=path,
                )
            if child in depth or child not in types:
                continue
            stack.append((child, _nested(types, child)))
            on_path.add(child)
        if depth.get(root, 0) > budget.MAX_NESTING:
            raise BagError(
                budget.over_budget(
                    f"stored definition of {root}",
                    "types nested deeper",
                    f"{budget.MAX_NESTING} levels",
                    "MAX_NESTING",
                ),
                path=path,
            )


def _nested(types: dict[str, Any], name: str) -> list[str]:
    """The message types the fields of ``name`` hold (arrays' and sequences' too)."""
    out = []
    for _field, (kind, detail) in types[name][1]:
        while kind in (3, 4):  # ARRAY, SEQUENCE: ((kind, detail), count)
            (kind, detail), _count = detail
        if kind == 2:  # NAME
            out.append(str(detail))
    return out


def _first_line(err: Exception, limit: int = 160) -> str:
    """The parser's message without the definition text it quotes (dozens of lines)."""
    line = str(err).strip().split("\n", 1)[0]
    return line if len(line) <= limit else line[:limit] + "..."
