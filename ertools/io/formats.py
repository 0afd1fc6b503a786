"""What is a bag: finding bags under paths, and format detection (ROS1 bag, indexed or
``.active``; rosbag2 directory; standalone MCAP).

Finding goes by name (``.bag``, ``.bag.active``, ``.mcap`` files; a folder with
``metadata.yaml`` or ``*.db3`` files is one rosbag2 bag); detection reads the first bytes
(magic) and, for directories, ``metadata.yaml``; the file name is only used to tell a
still-recording ``.bag.active`` from a closed bag.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from ertools import yamlin
from ertools.errors import BagError

ROS1_MAGIC = b"#ROSBAG V2.0\n"
MCAP_MAGIC = b"\x89MCAP0\r\n"

BAG_SUFFIXES = (".bag", ".bag.active", ".mcap")
NO_BAGS = "directory holds no bags (.bag, .bag.active, .mcap or rosbag2 folders)"


@dataclass(frozen=True)
class Unreadable:
    """A path that gave no bag, or could not be summarised, with the one-line reason."""

    path: str
    problem: str


@dataclass(frozen=True)
class Found:
    """Bags found under the given paths (sorted), and paths that gave none."""

    bags: tuple[Path, ...]
    problems: tuple[Unreadable, ...]


def is_rosbag2_dir(path: Path) -> bool:
    """A folder that is one rosbag2 bag: it holds ``metadata.yaml`` or sqlite3 storage files."""
    return (path / "metadata.yaml").is_file() or any(path.glob("*.db3"))


def find_bags(paths: Iterable[Path]) -> Found:
    """Bags under ``paths``: ``.bag``, ``.bag.active``, ``.mcap`` files and rosbag2 folders.

    A file named explicitly is taken whatever its name (the reader then says whether it is a
    bag); directories are walked recursively, and a rosbag2 folder counts as one bag. A path
    that does not exist, or a folder with no bag, is a problem, not an error: the caller
    decides.
    """
    bags: list[Path] = []
    problems: list[Unreadable] = []
    for root in paths:
        if not root.exists():
            problems.append(Unreadable(str(root), "no such file or directory"))
            continue
        if root.is_file() or is_rosbag2_dir(root):
            bags.append(root)
            continue
        before = len(bags)
        for dirpath, dirnames, filenames in os.walk(root):
            here = Path(dirpath)
            keep = []
            for d in sorted(dirnames):
                if is_rosbag2_dir(here / d):
                    bags.append(here / d)
                else:
                    keep.append(d)
            dirnames[:] = keep  # do not descend into rosbag2 folders
            bags.extend(here / f for f in sorted(filenames) if f.endswith(BAG_SUFFIXES))
        if len(bags) == before:
            problems.append(Unreadable(str(root), NO_BAGS))
    unique = sorted(dict.fromkeys(bags), key=str)
    return Found(tuple(unique), tuple(problems))


def expand(paths: Iterable[Path]) -> list[Path]:
    """Files and rosbag2 folders as given; other folders replaced by the bags inside.

    Raises:
        BagError: a path is missing, or a folder holds no bag.
    """
    out: list[Path] = []
    for p in paths:
        found = find_bags([p])
        if found.problems:
            raise BagError(found.problems[0].problem, path=p)
        out.extend(found.bags)
    return out


def bag_paths(paths: str | Path | list[str | Path] | tuple[str | Path, ...]) -> list[Path]:
    """One path or a sequence of paths as a non-empty list of Paths."""
    if isinstance(paths, (str, Path)):
        return [Path(paths)]
    out = [Path(p) for p in paths]
    if not out:
        raise BagError("no bag given")
    return out


def metadata_problem(err: Exception) -> str:
    """What is wrong with a ``metadata.yaml``, on one line and without its text: PyYAML's own
    message quotes the offending line, and the file may be anything (a symlink to a secret)."""
    mark = getattr(err, "problem_mark", None)
    if isinstance(err, yamlin.DuplicateKeyError) and mark is not None:
        return f"a key given twice, at line {mark.line + 1}"  # its name is the file's text
    if mark is not None:
        problem = getattr(err, "problem", None) or "malformed YAML"
        return f"{problem} at line {mark.line + 1}, column {mark.column + 1}"
    if isinstance(err, UnicodeDecodeError):
        return f"not UTF-8 text (byte {err.start})"
    if isinstance(err, KeyError | TypeError):
        return "no rosbag2_bagfile_information.storage_identifier"
    return type(err).__name__


def _rosbag2_storage(path: Path) -> str:
    meta = path / "metadata.yaml"
    if meta.is_file():
        try:
            data = yamlin.load(meta.read_text(encoding="utf-8"))
            storage = str(data["rosbag2_bagfile_information"]["storage_identifier"])
        except (yamlin.YAMLError, KeyError, TypeError, UnicodeDecodeError) as err:
            why = metadata_problem(err)
            raise BagError(
                f"unreadable rosbag2 metadata.yaml ({why}); re-create it with `ros2 bag reindex`",
                path=path,
            ) from err
        if storage in ("sqlite3", "mcap"):
            return f"rosbag2-{storage}"
        raise BagError(f"unsupported rosbag2 storage {storage!r}", path=path)
    if any(path.glob("*.db3")):
        return "rosbag2-sqlite3"
    raise BagError(
        "directory is not a rosbag2 bag (no metadata.yaml); give the bag files inside it",
        path=path,
    )


def detect_format(path: str | Path) -> str:
    """``ros1``, ``ros1-active``, ``rosbag2-sqlite3``, ``rosbag2-mcap`` or ``mcap``.

    Raises:
        BagError: missing path, empty file, or bytes that are no bag.
    """
    p = Path(path)
    if not p.exists():
        raise BagError("no such file or directory", path=p, transient=True)
    if p.is_dir():
        return _rosbag2_storage(p)
    try:
        with p.open("rb") as f:
            head = f.read(len(ROS1_MAGIC))
    except OSError as err:
        raise BagError(f"cannot open: {err.strerror}", path=p) from err
    if not head:
        raise BagError("empty file (0 bytes): not a bag", path=p)
    if len(head) < len(ROS1_MAGIC) and (ROS1_MAGIC.startswith(head) or MCAP_MAGIC.startswith(head)):
        raise BagError(
            f"truncated: the file ends after {len(head)} bytes, inside its magic", path=p
        )
    if head.startswith(ROS1_MAGIC):
        return "ros1-active" if p.name.endswith(".active") else "ros1"
    if head.startswith(b"#ROSBAG V"):
        version = head[len("#ROSBAG V") :].split(b"\n")[0].decode("ascii", "replace")
        if re.fullmatch(r"[0-9]\.[0-9]", version):  # else it is no version: not quoted
            raise BagError(f"ROS1 bag version {version} is not supported (only 2.0)", path=p)
    if head[: len(MCAP_MAGIC)] == MCAP_MAGIC:
        return "mcap"
    # What the file holds is not said: it may be anything (a path to /etc/passwd), and this
    # line reaches results.json and the published pages. Whether it is text is said: a text
    # trajectory given where a bag is expected.
    text = all(32 <= b < 127 or b in (9, 10, 13) for b in head)
    raise BagError(
        "not a ROS1 bag, rosbag2 bag or MCAP file: it does not begin with '#ROSBAG V2.0' "
        "(ROS1) or MCAP's magic bytes"
        + (
            "; a text file (if it is a TUM, KITTI or EuRoC trajectory, `score trajectory` "
            "and `export` read it)"
            if text
            else ""
        ),
        path=p,
    )
