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
import stat
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ertools.errors import BagError, shown
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import kind_of, open_regular, read_regular, why_not
from ertools.io import budget

ROS1_MAGIC = b"#ROSBAG V2.0\n"
MCAP_MAGIC = b"\x89MCAP0\r\n"

BAG_SUFFIXES = (".bag", ".bag.active", ".mcap")
NO_BAGS = "directory holds no bags (.bag, .bag.active, .mcap or rosbag2 folders)"


@frozen_dataclass
class Unreadable:
    """A path that gave no bag, or could not be summarised, with the one-line reason."""

    path: str
    problem: str


@frozen_dataclass
class Found:
    """Bags found under the given paths (sorted), and paths that gave none."""

    bags: tuple[Path, ...]
    problems: tuple[Unreadable, ...]


def is_rosbag2_dir(path: Path) -> bool:
    """A folder that is one rosbag2 bag: it holds ``metadata.yaml`` or sqlite3 storage files
    (False when it cannot be listed)."""
    try:
        with os.scandir(path) as it:
            return _is_rosbag2_listing(list(it))
    except OSError:
        return False


def _is_rosbag2_listing(entries: list[os.DirEntry[str]]) -> bool:
    # a metadata.yaml that is no regular file (a pipe) still marks the folder: its reader
    # then says what is wrong with it
    for e in entries:
        if e.name.endswith(".db3") or (e.name == "metadata.yaml" and not _is_dir(e)):
            return True
    return False


def _is_dir(entry: os.DirEntry[str]) -> bool:
    try:
        return entry.is_dir()
    except OSError:
        return False


def _special(entry: os.DirEntry[str]) -> str:
    """What a directory entry is when it is neither a regular file nor a folder (symbolic
    links followed), "" otherwise or when it cannot be looked at (the reader then says)."""
    try:
        return kind_of(entry.stat().st_mode)
    except OSError:
        return ""


NO_SUCH = "no such file or directory"


def _unreadable(path: Path | str, err: OSError, what: str = "") -> Unreadable:
    return Unreadable(shown(path), f"{what}{why_not(err)}")


def find_bags(paths: Iterable[Path]) -> Found:
    """Bags under ``paths``: ``.bag``, ``.bag.active``, ``.mcap`` files and rosbag2 folders.

    A file named explicitly is taken whatever its name (the reader then says whether it is a
    bag); directories are walked recursively, and a rosbag2 folder counts as one bag. A path
    that does not exist, a folder with no bag, a folder that cannot be listed (no permission,
    a path longer than the system allows) and an entry that is no regular file (a named pipe,
    a device, a socket) are problems, one each, not errors: the caller decides, and the other
    paths are still searched.
    """
    bags: list[Path] = []
    problems: list[Unreadable] = []
    for root in paths:
        try:
            mode = os.stat(root).st_mode
        except FileNotFoundError:
            problems.append(Unreadable(shown(root), NO_SUCH))
            continue
        except OSError as err:
            problems.append(_unreadable(root, err, "cannot look at it: "))
            continue
        if stat.S_ISREG(mode):
            bags.append(root)
            continue
        if not stat.S_ISDIR(mode):
            problems.append(Unreadable(shown(root), f"not a regular file ({kind_of(mode)})"))
            continue
        before = (len(bags), len(problems))
        _walk(root, bags, problems)
        if (len(bags), len(problems)) == before:
            problems.append(Unreadable(shown(root), NO_BAGS))
    unique = sorted(dict.fromkeys(bags), key=str)
    return Found(tuple(unique), tuple(problems))


def _walk(root: Path, bags: list[Path], problems: list[Unreadable]) -> None:
    """The bags under the folder ``root`` (a rosbag2 folder is one; symbolic links to
    folders are not followed, but one to a rosbag2 folder is a bag)."""
    todo = [root]
    while todo:
        here = todo.pop()
        try:
            with os.scandir(here) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError as err:
            problems.append(_unreadable(here, err, "folder skipped: "))
            continue
        if _is_rosbag2_listing(entries):
            bags.append(here)
            continue
        subfolders = []
        for e in entries:
            path = here / e.name
            try:
                folder = e.is_dir()
                link = e.is_symlink()
            except OSError as err:
                problems.append(_unreadable(path, err, "skipped: "))
                continue
            if folder:
                if link:
                    if is_rosbag2_dir(path):
                        bags.append(path)
                else:
                    subfolders.append(path)
            elif e.name.endswith(BAG_SUFFIXES):
                kind = _special(e)
                if kind:
                    problems.append(
                        Unreadable(shown(path), f"not a regular file ({kind}); skipped")
                    )
                else:
                    bags.append(path)
        todo.extend(reversed(subfolders))


def regular_files(paths: Iterable[Path]) -> tuple[list[Path], list[Unreadable]]:
    """Every regular file under ``paths`` (a file given is itself), and one problem per path
    or folder that cannot be listed or looked at. Symbolic links to folders are followed once
    (a link back up the tree is not walked again)."""
    files: list[Path] = []
    problems: list[Unreadable] = []
    seen: set[tuple[int, int]] = set()
    todo = list(paths)[::-1]
    while todo:
        here = todo.pop()
        try:
            st = os.stat(here)
        except OSError as err:
            problems.append(_unreadable(here, err, "skipped: "))
            continue
        if stat.S_ISREG(st.st_mode):
            files.append(here)
            continue
        if not stat.S_ISDIR(st.st_mode) or (st.st_dev, st.st_ino) in seen:
            continue
        seen.add((st.st_dev, st.st_ino))
        try:
            with os.scandir(here) as it:
                names = sorted(e.name for e in it)
        except OSError as err:
            problems.append(_unreadable(here, err, "folder skipped: "))
            continue
        todo.extend(here / name for name in reversed(names))
    return files, problems


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
    from ertools.yamlin import DuplicateKeyError  # lazy: PyYAML 10-20 ms, rosbag2 only

    mark = getattr(err, "problem_mark", None)
    if isinstance(err, DuplicateKeyError) and mark is not None:
        return f"a key given twice, at line {mark.line + 1}"  # its name is the file's text
    if mark is not None:
        problem = getattr(err, "problem", None) or "malformed YAML"
        return f"{problem} at line {mark.line + 1}, column {mark.column + 1}"
    if isinstance(err, UnicodeDecodeError):
        return f"not UTF-8 text (byte {err.start})"
    if isinstance(err, KeyError | TypeError):
        return "no rosbag2_bagfile_information.storage_identifier"
    return type(err).__name__


def metadata_errors() -> tuple[type[Exception], ...]:
    """What :func:`load_metadata` raises for a text that does not parse, and a metadata without
    its keys (an ``except`` clause's: PyYAML is imported only when one is raised)."""
    from ertools.yamlin import YAMLError  # lazy: PyYAML 10-20 ms, rosbag2 only

    return (YAMLError, KeyError, TypeError, UnicodeDecodeError)


def load_metadata(path: Path) -> Any:
    """The parsed ``metadata.yaml`` of the rosbag2 folder ``path``, read as any input is
    (a regular file, within :data:`~ertools.io.budget.MAX_METADATA_BYTES` and
    :data:`~ertools.io.budget.MAX_NESTING` levels).

    Raises:
        OSError: it cannot be read (or is no regular file).
        BagError: over the budget.
        yaml.YAMLError, UnicodeDecodeError: it does not parse.
    """
    import yaml  # lazy: PyYAML (~25 ms) only for a rosbag2 folder's metadata.yaml

    from ertools.yamlin import load as load_yaml  # lazy: PyYAML 10-20 ms, rosbag2 only

    meta = path / "metadata.yaml"
    raw = read_regular(meta, budget.MAX_METADATA_BYTES)
    if len(raw) > budget.MAX_METADATA_BYTES:
        raise BagError(
            budget.over_budget(
                "metadata.yaml",
                f"more than {budget.MAX_METADATA_BYTES} bytes",
                budget.MAX_METADATA_BYTES,
                "MAX_METADATA_BYTES",
            ),
            path=path,
        )
    text = raw.decode("utf-8")
    # PyYAML builds nested nodes recursively (a deep file is a RecursionError); its event
    # parser is not recursive, so the depth is measured first
    depth = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > budget.MAX_NESTING:
                line = event.start_mark.line + 1 if event.start_mark else 0
                raise BagError(
                    budget.over_budget(
                        f"metadata.yaml at line {line}",
                        "nested deeper",
                        f"{budget.MAX_NESTING} levels",
                        "MAX_NESTING",
                    ),
                    path=path,
                )
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1
    return load_yaml(text)


def _rosbag2_storage(path: Path) -> str:
    meta = path / "metadata.yaml"
    if os.path.exists(meta) and not meta.is_dir():
        try:
            data = load_metadata(path)
            storage = str(data["rosbag2_bagfile_information"]["storage_identifier"])
        except OSError as err:
            raise BagError(f"unreadable metadata.yaml ({why_not(err)})", path=path) from err
        except metadata_errors() as err:
            why = metadata_problem(err)
            raise BagError(
                f"unreadable rosbag2 metadata.yaml ({why}); re-create it with `ros2 bag reindex`",
                path=path,
            ) from err
        if storage in ("sqlite3", "mcap"):
            return f"rosbag2-{storage}"
        raise BagError(f"unsupported rosbag2 storage {storage!r}", path=path)
    if is_rosbag2_dir(path):
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
    try:
        mode = os.stat(p).st_mode
    except FileNotFoundError as err:
        raise BagError(NO_SUCH, path=p) from err
    except OSError as err:
        raise BagError(f"cannot open: {why_not(err)}", path=p) from err
    if stat.S_ISDIR(mode):
        return _rosbag2_storage(p)
    try:
        with open_regular(p) as f:
            head = f.read(len(ROS1_MAGIC))
    except OSError as err:
        raise BagError(f"cannot open: {why_not(err)}", path=p) from err
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
