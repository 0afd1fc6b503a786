"""The sqlite3 storage files of a rosbag2 folder, read only: one query, or a topic's rows in
batches. A module of its own so that reading other formats imports no sqlite3."""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import I64, U8
from ertools.errors import BagError
from ertools.inputs import check_regular, why_not

ROWS_PER_BATCH = 100_000


def _connect(db: Path) -> sqlite3.Connection:
    # Read-only: an input file is never modified (not even a journal is created). sqlite
    # opens the path itself: a named pipe there would block it, so the type is checked first.
    try:
        check_regular(db)
    except OSError as err:
        raise sqlite3.OperationalError(f"unable to open database file: {why_not(err)}") from err
    return sqlite3.connect(f"{db.resolve().as_uri()}?mode=ro", uri=True)


def query(db: Path, sql: str) -> list[Any]:
    """All rows of one read-only query on a storage file.

    Raises:
        BagError: the file is not a readable sqlite3 database.
    """
    try:
        con = _connect(db)
    except sqlite3.Error as err:
        raise BagError(f"cannot open sqlite3 storage ({err})", path=db) from err
    try:
        return con.execute(sql).fetchall()
    except (sqlite3.Error, UnicodeDecodeError) as err:
        raise BagError(f"damaged sqlite3 storage ({err})", path=db) from err
    finally:
        con.close()


def topic_rows(
    files: list[Path], topics: list[str], lo: int | None, hi: int | None
) -> Iterator[tuple[U8, I64, I64, I64]]:
    """Batches of (bytes, data starts, data lengths, timestamps) of ``topics``' messages in
    [lo, hi], ordered by time, file after file."""
    for db in files:
        try:
            con = _connect(db)
        except sqlite3.Error as err:
            raise BagError(f"cannot open sqlite3 storage ({err})", path=db) from err
        try:
            marks = ",".join("?" * len(topics))
            ids = [
                r[0] for r in con.execute(f"SELECT id FROM topics WHERE name IN ({marks})", topics)
            ]
            if not ids:
                continue
            marks = ",".join("?" * len(ids))
            query = f"SELECT timestamp, data FROM messages WHERE topic_id IN ({marks})"
            args: list[int] = list(ids)
            if lo is not None:
                query += " AND timestamp >= ?"
                args.append(lo)
            if hi is not None:
                query += " AND timestamp <= ?"
                args.append(hi)
            cur = con.execute(query + " ORDER BY timestamp, id", args)
            while rows := cur.fetchmany(ROWS_PER_BATCH):
                t = np.fromiter((r[0] for r in rows), dtype=np.int64, count=len(rows))
                lengths = np.fromiter((len(r[1]) for r in rows), dtype=np.int64, count=len(rows))
                starts = np.zeros(len(rows), dtype=np.int64)
                np.cumsum(lengths[:-1], out=starts[1:])
                buf = np.frombuffer(b"".join(r[1] for r in rows), dtype=np.uint8)
                yield buf, starts, lengths, t
        except (sqlite3.Error, UnicodeDecodeError) as err:
            raise BagError(f"damaged sqlite3 storage ({err})", path=db) from err
        finally:
            con.close()
