"""Format detection: ROS1 bag (indexed or ``.active``), rosbag2 directory, standalone MCAP.

Detection reads the first bytes (magic) and, for directories, ``metadata.yaml``; the file name
is only used to tell a still-recording ``.bag.active`` from a closed bag.
"""

from __future__ import annotations

from pathlib import Path

from ertools.errors import BagError

ROS1_MAGIC = b"#ROSBAG V2.0\n"
MCAP_MAGIC = b"\x89MCAP0\r\n"


def bag_paths(paths: str | Path | list[str | Path] | tuple[str | Path, ...]) -> list[Path]:
    """One path or a sequence of paths as a non-empty list of Paths."""
    if isinstance(paths, (str, Path)):
        return [Path(paths)]
    out = [Path(p) for p in paths]
    if not out:
        raise BagError("no bag given")
    return out


def _rosbag2_storage(path: Path) -> str:
    meta = path / "metadata.yaml"
    if meta.is_file():
        import yaml

        try:
            data = yaml.safe_load(meta.read_text(encoding="utf-8"))
            storage = str(data["rosbag2_bagfile_information"]["storage_identifier"])
        except (yaml.YAMLError, KeyError, TypeError, UnicodeDecodeError) as err:
            # The YAML parser's message spans several lines (mark, caret): one line here.
            why = " ".join(str(err).split())
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
        raise BagError("no such file or directory", path=p)
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
        raise BagError(f"ROS1 bag version {version} is not supported (only 2.0)", path=p)
    if head[: len(MCAP_MAGIC)] == MCAP_MAGIC:
        return "mcap"
    raise BagError(
        f"not a ROS1 bag, rosbag2 bag or MCAP file (unknown magic bytes {head[:8]!r})",
        path=p,
    )
