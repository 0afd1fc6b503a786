"""The rescore cache in ``DIR/cache``: a second run recomputes only what changed.

An execution's key is the SHA-256 of everything its score depends on: the ertools version,
the benchmark and its registry entry, the team, the SHA-256 of every bag and input file and
every other input value. Fix one team's transform and only that team's executions get a new
key. Entries are the outcomes as JSON (``DIR/cache/outcomes/<key>.json``) with the SHA-256 of
every file of the execution's report folder and a checksum of the whole.

Nothing found in the cache is trusted: an entry that does not match its schema (a status not
known, a rank value that is not a finite number, a report that is not a path...) or its
checksum (edited by hand), or whose report folder lacks a file or holds a changed one (a PNG
truncated by a kill), is a miss: the execution is scored again and the run says so once. Only
verdicts about the data are kept: an outcome caused by the machine (a report folder that could
not be written, a disk full) is computed again next time. The checksum catches accidents and
hand edits, not forgery: the cache is not signed (docs/rescore.md).

Hashing terabytes of mocap at every run would cost more than scoring, so file hashes are
remembered by (path, size, modification time, inode) in ``DIR/cache/hashes.json``, the way
``git`` trusts its index: a file rewritten in place with the same size and time is not seen
(docs/rescore.md says so). The report files' hashes are remembered the same way: a warm rerun
checks each report folder file by file from its stamps, reading only the files that changed
(ertools writes every file by renaming a new one over it: a new inode, never the same stamp).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools._version import __version__
from ertools.atomic import write_text
from ertools.competition.jobs import Job, Outcome
from ertools.report.records import sha256_file

CACHE_VERSION = 2
STATUSES = ("scored", "unscoreable")
_READS = 3  # times a file changing while it is hashed is read again


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
            except (OSError, ValueError):  # a damaged memo only costs the hashing again
                loaded = {}
            if isinstance(loaded, dict):  # rows of another shape are hashed again
                self.known = {k: v for k, v in loaded.items() if _hash_row(v)}

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

    def sha256(self, path: Path, key: str | None = None) -> str:
        """The file's SHA-256, remembered by ``key`` (its resolved path unless given).

        A file that changes while it is read (its stamp before and after differ) is read
        again; one that keeps changing is not remembered: the hash is of bytes that are gone.
        """
        key = key if key is not None else str(path.resolve())
        stamp = self._stamp(path)
        known = self.known.get(key)
        if known is not None and known[:3] == stamp:
            return str(known[3])
        for _ in range(_READS):
            digest = _sha256_file(path)
            after = self._stamp(path)
            if after == stamp:
                self.known[key] = [*stamp, digest]
                self.changed = True
                break
            stamp = after
        return digest

    def size(self, path: Path) -> int:
        return self._stamp(path)[0]

    def save(self) -> None:
        if self.store is None or not self.changed:
            return
        self.store.parent.mkdir(parents=True, exist_ok=True)
        write_text(self.store, json.dumps(self.known, sort_keys=True))


def job_files(job: Job) -> list[Path]:
    """Every file a job reads by name: its bags, then the files among its input values."""
    files = [Path(b) for b in job.bags]
    for value in job.values.values():
        for item in value if isinstance(value, tuple | list) else (value,):
            if isinstance(item, Path):
                files.append(item)
    return list(dict.fromkeys(files))


def file_state(path: Path) -> tuple[Any, ...] | None:
    """What says a file is unchanged (size, times, inode; of each file of a rosbag2 folder),
    finer than the hash memo's stamp: the change time, which no tool sets back, counts too.
    None: the file is gone (or cannot be looked at)."""
    try:
        if path.is_dir():
            return tuple(
                (p.relative_to(path).as_posix(), *_stat_state(p))
                for p in sorted(path.rglob("*"))
                if p.is_file()
            )
        return _stat_state(path)
    except OSError:
        return None


def _stat_state(path: Path) -> tuple[int, ...]:
    st = path.stat()
    return (st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino, st.st_dev)


Fingerprints = dict[str, tuple[tuple[Any, ...] | None, str]]


def fingerprints(job: Job, hashes: FileHashes) -> Fingerprints:
    """Each of the job's files' state and SHA-256 as it is keyed (taken after :func:`job_key`,
    whose hashes are remembered: nothing is read again)."""
    out: Fingerprints = {}
    for path in job_files(job):
        state = file_state(path)
        try:
            digest = hashes.sha256(path)
        except OSError:  # gone since it was keyed: said after scoring
            digest = ""
        # changed while it was hashed: looked at again after scoring
        out[str(path)] = (state if file_state(path) == state else None, digest)
    return out


def changed_files(before: Fingerprints, hashes: FileHashes) -> list[str]:
    """The files of ``before`` whose bytes are not those keyed any more: gone, or of another
    SHA-256 (a file whose state is unchanged is not read again)."""
    changed = []
    for name, (state, digest) in before.items():
        path = Path(name)
        now = file_state(path)
        if state is not None and now == state:
            continue
        try:
            if now is None or hashes.sha256(path) != digest:
                changed.append(name)
        except OSError:
            changed.append(name)
    return changed


def _hash_row(row: Any) -> bool:
    """A ``hashes.json`` row: [size, mtime_ns, inode, sha256 hex]."""
    return (
        isinstance(row, list)
        and len(row) == 4
        and all(isinstance(v, int) and not isinstance(v, bool) for v in row[:3])
        and isinstance(row[3], str)
        and len(row[3]) == 64
        and all(c in "0123456789abcdef" for c in row[3])
    )


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
    """Outcomes by key in ``root`` (None: no cache, every job recomputed).

    ``invalid`` lists the entries found and refused (schema, checksum, report folder), each
    with why: the caller says so once. ``hashes``: where the report files' SHA-256 are
    remembered by stamp, as the inputs' are (a warm rerun of a season then reads none of its
    ~2,000 report files; None: each is read and hashed at every check).
    """

    def __init__(self, root: Path | None, hashes: FileHashes | None = None) -> None:
        self.root = root
        self.hashes = hashes
        self.invalid: list[tuple[Path, str]] = []

    def _path(self, key: str) -> Path | None:
        return None if self.root is None else self.root / "outcomes" / f"{key}.json"

    def get(self, key: str, job: Job) -> Outcome | None:
        path = self._path(key)
        if path is None or not path.is_file():
            return None
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            self.invalid.append((path, "not JSON"))
            return None
        why = _invalid_entry(data)
        if why is not None:
            self.invalid.append((path, why))
            return None
        outcome = Outcome.from_dict({**data["outcome"], "id": job.id})
        if outcome.report is not None:
            why = _changed_report(Path(outcome.report), data["report_files"], self.hashes)
            if why is not None:  # removed, or damaged (a kill while it was written)
                self.invalid.append((path, why))
                return None
        return outcome

    def put(self, key: str, outcome: Outcome) -> None:
        """Keep a scored or unscoreable outcome; a failure (a bug, a dead worker) or a
        problem of the machine (a folder not writable) may not happen again, so it is computed
        again next time."""
        path = self._path(key)
        if path is None or outcome.status not in STATUSES or outcome.machine:
            return
        record = outcome.to_dict()
        files = {}
        if outcome.report is not None:
            folder = Path(outcome.report).parent
            base = str(folder.resolve())
            files = {
                rel: _report_sha256(p, base, rel, self.hashes)
                for p in sorted(folder.rglob("*"))
                if p.is_file()
                for rel in [p.relative_to(folder).as_posix()]
            }
        entry = {"cache": CACHE_VERSION, "outcome": record, "report_files": files}
        entry["checksum"] = _checksum(entry)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text(path, json.dumps(entry, allow_nan=False))


def _checksum(entry: Mapping[str, Any]) -> str:
    material = {k: v for k, v in entry.items() if k != "checksum"}
    return hashlib.sha256(json.dumps(material, sort_keys=True).encode("utf-8")).hexdigest()


def _strings(value: Any) -> bool:
    return isinstance(value, list) and all(isinstance(v, str) for v in value)


def _optional(value: Any, kind: type | tuple[type, ...]) -> bool:
    return value is None or isinstance(value, kind)


def _invalid_entry(data: Any) -> str | None:
    """Why a cache entry cannot be used (None: it can)."""
    if not isinstance(data, dict) or data.get("cache") != CACHE_VERSION:
        return "not an entry of this cache version"
    if data.get("checksum") != _checksum(data):
        return "checksum mismatch (edited or damaged)"
    outcome, files = data.get("outcome"), data.get("report_files")
    if not isinstance(outcome, dict) or not isinstance(files, dict):
        return "no outcome or report file list"
    rank, seconds = outcome.get("rank_value"), outcome.get("seconds", 0.0)
    checks = {
        "status": outcome.get("status") in STATUSES,
        "reason": _optional(outcome.get("reason"), str),
        "score": _optional(outcome.get("score"), dict),
        "rank_value": rank is None
        or (isinstance(rank, int | float) and not isinstance(rank, bool) and math.isfinite(rank)),
        "warnings": _strings(outcome.get("warnings", [])),
        "deviations": _strings(outcome.get("deviations", [])),
        "live_differences": _strings(outcome.get("live_differences", [])),
        "report": _optional(outcome.get("report"), str),
        "seconds": isinstance(seconds, int | float) and math.isfinite(seconds) and seconds >= 0,
        "error": _optional(outcome.get("error"), str),
        "machine": outcome.get("machine", False) is False,
        "report_files": all(isinstance(k, str) and isinstance(v, str) for k, v in files.items()),
    }
    bad = [name for name, ok in checks.items() if not ok]
    return f"invalid {', '.join(bad)}" if bad else None


def _report_sha256(path: Path, base: str, rel: str, hashes: FileHashes | None) -> str:
    # the folder resolved once, not each of its files (a resolve is a stat per path part)
    return _sha256_file(path) if hashes is None else hashes.sha256(path, f"{base}/{rel}")


def _changed_report(
    index: Path, files: Mapping[str, str], hashes: FileHashes | None = None
) -> str | None:
    """Why the report folder of ``index`` is not the one cached (None: it is, file by file;
    with ``hashes``, a file whose stamp is the one remembered is not read again)."""
    folder = index.parent
    if not index.is_file() or index.relative_to(folder).as_posix() not in files:
        return "its report folder is gone"
    base = str(folder.resolve())
    for rel, digest in files.items():
        path = folder / rel
        if ".." in Path(rel).parts or not path.is_file():
            return f"report file {rel} is missing"
        if _report_sha256(path, base, rel, hashes) != digest:
            return f"report file {rel} has changed"
    return None


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
