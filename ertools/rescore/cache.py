"""The rescore cache in ``DIR/cache``: a second run recomputes only what changed.

An execution's key is the SHA-256 of everything its score depends on: the ertools version,
the benchmark and its registry entry, the team, the SHA-256 of every bag and input file and
every other input value. Fix one team's transform and only that team's executions get a new
key. Entries are the outcomes as JSON (``DIR/cache/outcomes/<key>.json``); an entry whose
report folder has gone is recomputed.

Hashing terabytes of mocap at every run would cost more than scoring, so file hashes are
remembered by (path, size, modification time, inode) in ``DIR/cache/hashes.json``, the way
``git`` trusts its index: a file rewritten in place with the same size and time is not seen
(docs/rescore.md says so).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools import __version__, atomic
from ertools.report.records import sha256_file
from ertools.rescore.jobs import Job, Outcome

CACHE_VERSION = 1


def _sha256_file(path: Path) -> str:
    return sha256_file(path)


class FileHashes:
    """SHA-256 of files, remembered across runs by (size, mtime, inode)."""

    def __init__(self, store: Path | None) -> None:
        self.store = store
        self.known: dict[str, list[Any]] = {}
        self.changed = False
        if store is not None and store.is_file():
            try:
                loaded = json.loads(store.read_text(encoding="utf-8"))
                if isinstance(loaded, dict):
                    self.known = loaded
            except (OSError, ValueError):  # a damaged memo only costs the hashing again
                self.known = {}

    @staticmethod
    def _stamp(path: Path) -> list[int]:
        if path.is_dir():  # a rosbag2 folder: its files' stamps together
            stats = [p.stat() for p in sorted(path.rglob("*")) if p.is_file()]
            return [
                sum(s.st_size for s in stats),
                max((s.st_mtime_ns for s in stats), default=0),
                0,
            ]
        st = path.stat()
        return [st.st_size, st.st_mtime_ns, st.st_ino]

    def sha256(self, path: Path) -> str:
        key = str(path.resolve())
        stamp = self._stamp(path)
        known = self.known.get(key)
        if known is not None and known[:3] == stamp:
            return str(known[3])
        digest = _sha256_file(path)
        self.known[key] = [*stamp, digest]
        self.changed = True
        return digest

    def size(self, path: Path) -> int:
        return self._stamp(path)[0]

    def save(self) -> None:
        if self.store is None or not self.changed:
            return
        self.store.parent.mkdir(parents=True, exist_ok=True)
        atomic.write_text(self.store, json.dumps(self.known, sort_keys=True))


def value_record(value: Any, hashes: FileHashes) -> Any:
    """An input value as the key and ``results.json`` record it: files by their hash."""
    if isinstance(value, Path):
        return {"path": str(value), "sha256": hashes.sha256(value)}
    if isinstance(value, tuple | list):
        return [value_record(v, hashes) for v in value]
    return value


def job_key(job: Job, hashes: FileHashes) -> str:
    """The cache key of a job: what its outcome depends on, hashed."""
    material = {
        "cache": CACHE_VERSION,
        "ertools": __version__,
        "benchmark": job.benchmark,
        "target": job.target,
        "team": job.team,
        "bags": [hashes.sha256(Path(b)) for b in job.bags],
        "values": {k: _hash_only(value_record(v, hashes)) for k, v in sorted(job.values.items())},
        "report": job.report_dir is not None,
    }
    text = json.dumps(material, sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _hash_only(record: Any) -> Any:
    # a file's content counts, not where it lies (a folder copied elsewhere stays cached)
    if isinstance(record, dict) and "sha256" in record:
        return record["sha256"]
    if isinstance(record, list):
        return [_hash_only(r) for r in record]
    return record


class Cache:
    """Outcomes by key in ``root`` (None: no cache, every job recomputed)."""

    def __init__(self, root: Path | None) -> None:
        self.root = root

    def _path(self, key: str) -> Path | None:
        return None if self.root is None else self.root / "outcomes" / f"{key}.json"

    def get(self, key: str, job: Job) -> Outcome | None:
        path = self._path(key)
        if path is None or not path.is_file():
            return None
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            outcome = Outcome.from_dict({**data, "id": job.id})
        except (OSError, ValueError, KeyError, TypeError):
            return None
        if outcome.report is not None and not Path(outcome.report).is_file():
            return None  # its report folder was removed: score again to write it
        return outcome

    def put(self, key: str, outcome: Outcome) -> None:
        """Keep a scored or unscoreable outcome; a failure (a bug, a dead worker) may not
        happen again, so it is computed again next time."""
        path = self._path(key)
        if path is None or outcome.status == "failed":
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic.write_text(path, json.dumps(outcome.to_dict(), allow_nan=False))


def records(values: Mapping[str, Any], hashes: FileHashes) -> list[dict[str, Any]]:
    """``results.json``'s ``inputs`` of an execution: files with their hash, other values."""
    out: list[dict[str, Any]] = []
    for name, value in values.items():
        record = value_record(value, hashes)
        if isinstance(record, dict):
            out.append({"name": name, **record})
        elif isinstance(record, list) and record and all(isinstance(r, dict) for r in record):
            out.extend({"name": name, **r} for r in record)
        else:
            out.append({"name": name, "value": record})
    return out
