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
        # lazy: rosbags only on the per-message path (~0.1 s to import)
        from rosbags.typesys import (
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
        self.typestore = get_typestore(Stores.EMPTY)
        try:
            self.typestore.register(types)
        except TypesysError as err:
            raise BagError(f"conflicting stored message definitions ({err})", path=path) from err

    def __call__(self, raw: bytes | memoryview, conn: Conn) -> Any:
        """The message object of ``raw`` (a rosbags dataclass instance)."""
        # lazy: rosbags only on the per-message path (~0.1 s to import)
        from rosbags.serde import SerdeError

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


def _first_line(err: Exception, limit: int = 160) -> str:
    """The parser's message without the definition text it quotes (dozens of lines)."""
    line = str(err).strip().split("\n", 1)[0]
    return line if len(line) <= limit else line[:limit] + "..."
