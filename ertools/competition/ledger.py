"""Every file under the scanned folders, in exactly one place: the ledger of a rescore.

An organiser hands over a folder and must be able to check that nothing in it was silently
left out. Each file is given one place, the first that claims it in this order: the log of an
execution (``execution``), a GT file of one (``gt``), a robot log compared with the GT
(``robot-log``), an input file of one (``input``: a goal list, a config, a transform, a
timing file), else a ``problem`` with its kind and reason (an unreadable bag, a copy, a GT
recording that is no execution, or a file that is not a log and that no input names:
``unused``). A file inside a rosbag2 folder belongs to that folder's bag.

Pure: the files are listed by the IO edge (:func:`ertools.competition.found.list_files`); the
claims come from ``results.json``'s rows and problems (:func:`account`) or from the draft
(:mod:`ertools.competition.draft`).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from ertools.frozen_dataclass import frozen_dataclass

PLACES = ("execution", "gt", "robot-log", "input", "problem")
TIMING_SUFFIX = "_reached_waypoint_timing.yaml"
UNUSED = "unused"


@frozen_dataclass
class Claim:
    """``path`` (absolute) has this place; ``owner`` is the execution it belongs to."""

    path: str
    place: str
    owner: str | None = None
    kind: str | None = None
    reason: str | None = None


@frozen_dataclass
class Entry:
    """One file of the folder and its place (``path`` relative to the folder)."""

    path: str
    place: str
    execution: str | None
    kind: str | None
    reason: str | None

    def to_dict(self) -> dict[str, Any]:
        return {
            "path": self.path,
            "place": self.place,
            "execution": self.execution,
            "kind": self.kind,
            "reason": self.reason,
        }


def root_of(folders: Sequence[str]) -> str:
    """The folder paths are shown relative to: the scanned folders' common folder (a scanned
    file counts as its folder: the IO edge passes folders)."""
    return os.path.commonpath(list(folders)) if folders else ""


def relative(path: str, root: str) -> str:
    """``path`` relative to ``root`` when inside it (else as given)."""
    if root and (path == root or path.startswith(root.rstrip("/") + "/")):
        return os.path.relpath(path, root)
    return path


_LOG_SUFFIXES = (".bag", ".bag.active", ".mcap", ".db3")


def _unused_reason(path: str) -> str:
    if path.endswith(_LOG_SUFFIXES):
        return "a log no execution uses (see the problems of the logs around it)"
    if path.endswith(TIMING_SUFFIX):
        return (
            "a reached-waypoint timing file no execution uses (its log is scored from its state "
            "topics, or is not here)"
        )
    return "not a log, and no input of any execution names it"


def place_files(files: Iterable[str], claims: Sequence[Claim], root: str) -> list[Entry]:
    """Each of ``files`` (absolute) in one place: its first claim (in :data:`PLACES` order), a
    claim on the rosbag2 folder holding it, or ``problem``/``unused``."""
    rank = {place: i for i, place in enumerate(PLACES)}
    best: dict[str, Claim] = {}
    for given in claims:
        held = best.get(given.path)
        if held is None or rank[given.place] < rank[held.place]:
            best[given.path] = given
    entries = []
    for path in sorted(set(files)):
        claim: Claim | None = best.get(path)
        folder = path
        while claim is None and os.path.dirname(folder) not in ("", folder):
            folder = os.path.dirname(folder)  # a file of a rosbag2 folder: the folder's place
            if folder == root or not folder.startswith(root):
                break  # the scanned folder's own problems are not its files'
            claim = best.get(folder)
        if claim is None:
            claim = Claim(path, "problem", kind=UNUSED, reason=_unused_reason(path))
        entries.append(
            Entry(relative(path, root), claim.place, claim.owner, claim.kind, claim.reason)
        )
    return entries


def _record_paths(value: Any) -> list[str]:
    """The files of ``inputs`` records, also those inside a value (``reached: [timing,
    {path, sha256}]``)."""
    if isinstance(value, dict):
        own = [str(value["path"])] if value.get("path") else []
        return own + [p for v in value.values() for p in _record_paths(v)]
    if isinstance(value, list):
        return [p for v in value for p in _record_paths(v)]
    return []


def claims_of(doc: Mapping[str, Any]) -> list[Claim]:
    """The places ``results.json``'s rows and problems give files."""
    claims: list[Claim] = []
    for row in doc.get("executions") or []:
        bags = [str(b) for b in row.get("bags") or []]
        if not bags:
            continue
        ident = str(row.get("id"))
        if row.get("of") is None:
            claims.append(Claim(bags[0], "execution", ident))
            owner = ident
        else:
            claims.append(Claim(bags[0], "robot-log", str(row["of"])))
            owner = str(row["of"])
        claims += [Claim(b, "gt", owner) for b in bags[1:]]
        claims += [Claim(path, "input", owner) for path in _record_paths(row.get("inputs"))]
    for problem in doc.get("problems") or []:
        if problem.get("path"):
            claims.append(
                Claim(
                    str(problem["path"]),
                    "problem",
                    kind=str(problem.get("kind")),
                    reason=str(problem.get("message")),
                )
            )
    return claims


def account(
    doc: Mapping[str, Any],
    files: Sequence[str],
    folders: Sequence[str],
    robot_logs: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """``doc`` with ``root`` (the scanned folders' common folder), ``files`` (every file under
    them, each in one place, relative to ``root``) and every unused file added to
    ``problems`` (kind ``unused``).

    ``robot_logs``: robot log -> the benchmark log of its execution, for the robot logs that
    have no row of their own (no topic to compare: a warning of their execution says so).
    """
    root = root_of(folders)
    ids = {
        str(row["bags"][0]): str(row["id"])
        for row in doc.get("executions") or []
        if row.get("of") is None and row.get("bags")
    }
    extra = [Claim(robot, "robot-log", ids.get(log)) for robot, log in (robot_logs or {}).items()]
    manifest = (doc.get("manifest") or {}).get("path")
    if manifest:  # kept with the logs: an input of every execution
        extra.append(Claim(str(manifest), "input", kind="manifest", reason="the manifest"))
    entries = place_files(files, [*claims_of(doc), *extra], root)
    unused = [
        {"kind": UNUSED, "path": os.path.join(root, e.path), "message": e.reason}
        for e in entries
        if e.kind == UNUSED
    ]
    return {
        **doc,
        "root": root,
        "files": [e.to_dict() for e in entries],
        "problems": [*doc.get("problems", []), *unused],
    }


__all__ = ["Claim", "Entry", "account", "claims_of", "place_files", "relative", "root_of"]
