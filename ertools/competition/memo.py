"""What a rescore learnt about each log, remembered for the next run (``DIR/cache/files.json``).

A warm rerun of a season finds every score in the cache, yet discovering the executions still
read every log: each recording's clock check (decoding its first second of poses) and each
benchmark log's state payloads (for the team they name), two thirds of a warm run's time on
a 108-execution season (docs/performance.md). Both depend on the file's bytes alone, so they
are remembered by the file's (size, modification time, inode), the stamp the hashes of
``cache/hashes.json`` are trusted by: a log rewritten in place keeping its size and time is
not seen (docs/rescore.md says so); any other change reads the file again.

Nothing found in the memo is trusted beyond its shape: a row of another shape is dropped and
its file read again; a damaged memo costs only the reading.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.atomic import write_text
from ertools.errors import watching
from ertools.io.clock import ClockCheck

MEMO_VERSION = 1
CLOCK = "clock"
TEAM = "team:"  # + the benchmark's namespace (a log may hold several)


def _stamp(path: Path) -> list[int] | None:
    try:
        st = path.stat()
    except OSError:
        return None
    return [st.st_size, st.st_mtime_ns, st.st_ino]


def _row(value: Any) -> bool:
    return (
        isinstance(value, dict)
        and isinstance(value.get("stamp"), list)
        and len(value["stamp"]) == 3
        and all(isinstance(v, int) and not isinstance(v, bool) for v in value["stamp"])
    )


class FileMemo:
    """Facts about files by (path, stamp), in ``store`` (None: nothing remembered).

    A fact is looked up with :meth:`get` and a function computing it: the function runs
    when the file changed (or is not known), and its value is kept for :meth:`save`.
    Remembered across ertools versions only if equal: another version may read logs
    differently. ``load`` False: nothing is taken from ``store``, every fact is computed and
    the store rewritten (``--no-cache``).
    """

    def __init__(self, store: Path | None, *, load: bool = True) -> None:
        self.store = store
        self.rows: dict[str, dict[str, Any]] = {}
        self.changed = False
        if store is None or not load or not store.is_file():
            return
        try:
            loaded = json.loads(store.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return
        if (
            isinstance(loaded, dict)
            and loaded.get("memo") == MEMO_VERSION
            and loaded.get("ertools") == __version__
            and isinstance(loaded.get("files"), dict)
        ):
            self.rows = {k: v for k, v in loaded["files"].items() if _row(v)}

    def get(
        self,
        path: str | Path,
        fact: str,
        compute: Callable[[], Any],
        valid: Callable[[Any], bool] = lambda value: True,
    ) -> Any:
        """``fact`` of ``path``: remembered while the file's stamp is the same (and the
        value ``valid``), else ``compute()`` (a JSON value), remembered."""
        key = str(Path(path).resolve())
        stamp = _stamp(Path(path))
        row = self.rows.get(key)
        if (
            stamp is not None
            and row is not None
            and row["stamp"] == stamp
            and fact in row
            and valid(row[fact])
        ):
            return row[fact]
        with watching() as met:
            value = compute()
        # a fact learnt while the file was missing for a moment, or unreadable, is the
        # moment's, not the bytes': computed again next time; and one whose file changed
        # while it was read belongs to neither stamp
        if stamp is not None and not met and _stamp(Path(path)) == stamp:
            if row is None or row["stamp"] != stamp:
                row = self.rows[key] = {"stamp": stamp}
            row[fact] = value
            self.changed = True
        return value

    def save(self) -> None:
        if self.store is None or not self.changed:
            return
        self.store.parent.mkdir(parents=True, exist_ok=True)
        doc = {"memo": MEMO_VERSION, "ertools": __version__, "files": self.rows}
        write_text(self.store, json.dumps(doc, sort_keys=True))
        self.changed = False


def clock_to_json(check: ClockCheck | None) -> Any:
    """A clock check as the memo keeps it (its file is the row's)."""
    if check is None:
        return None
    return [check.topic, check.offset_ns, check.samples, check.error]


def clock_json_valid(value: Any) -> bool:
    return value is None or (
        isinstance(value, list)
        and len(value) == 4
        and isinstance(value[0], str)
        and all(isinstance(v, int) and not isinstance(v, bool) for v in value[1:3])
        and isinstance(value[3], str)
    )


def clock_from_json(path: str, value: Any) -> ClockCheck | None:
    """The check of ``path`` from its memo value (:func:`clock_json_valid`)."""
    if value is None:
        return None
    return ClockCheck(path, value[0], value[1], value[2], error=value[3])


def team_json_valid(value: Any) -> bool:
    return value is None or isinstance(value, str)
