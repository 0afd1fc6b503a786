"""What a report records about its files: name, path, SHA-256 and size
(:class:`FileRecord`), and the safe file stems of its CSV tables."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import Any

from ertools.frozen_dataclass import frozen_dataclass

_CHUNK = 1 << 20


@frozen_dataclass
class FileRecord:
    """An input or config file as the report records it."""

    name: str
    path: str
    sha256: str
    size: int

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "path": self.path, "sha256": self.sha256, "size": self.size}


def sha256_file(path: Path) -> str:
    """SHA-256 of a file, read in chunks (bags are large); of a directory (rosbag2), the
    SHA-256 of the sorted list of '<relative path> <sha256 of that file>' lines."""
    if path.is_dir():
        lines = [
            f"{p.relative_to(path).as_posix()} {sha256_file(p)}\n"
            for p in sorted(path.rglob("*"))
            if p.is_file()
        ]
        return hashlib.sha256("".join(lines).encode()).hexdigest()
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        while chunk := fh.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def file_record(path: Path) -> FileRecord:
    size = (
        sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
        if path.is_dir()
        else path.stat().st_size
    )
    return FileRecord(path.name, str(path), sha256_file(path), size)


def csv_stem(name: str) -> str:
    """A table name as a safe file stem (the table names come from the scorers)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip(".") or "table"
