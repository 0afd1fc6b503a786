"""The one bag finder (ertools.io.formats): what counts as a bag, in which order, and the two
ways a caller meets a path that gives none (a problem listed, or a BagError)."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.errors import BagError
from ertools.io.formats import NO_BAGS, expand, find_bags


def _tree(root: Path) -> None:
    (root / "day" / "late").mkdir(parents=True)
    (root / "day" / "b.bag").write_bytes(b"")
    (root / "day" / "a.mcap").write_bytes(b"")
    (root / "day" / "late" / "c.bag.active").write_bytes(b"")
    (root / "day" / "readme.txt").write_text("not a bag")
    sqlite = root / "day" / "r2"  # a rosbag2 folder without metadata.yaml: its .db3 decides
    sqlite.mkdir()
    (sqlite / "r2_0.db3").write_bytes(b"")
    (sqlite / "inner.bag").write_bytes(b"")  # inside a rosbag2 folder: not a bag of its own


def test_find_bags_lists_files_and_rosbag2_folders_sorted(tmp_path: Path) -> None:
    _tree(tmp_path)
    found = find_bags([tmp_path])
    names = [p.relative_to(tmp_path).as_posix() for p in found.bags]
    assert names == ["day/a.mcap", "day/b.bag", "day/late/c.bag.active", "day/r2"]
    assert found.problems == ()


def test_expand_takes_the_same_bags_and_raises_where_find_bags_lists(tmp_path: Path) -> None:
    _tree(tmp_path)
    (tmp_path / "empty").mkdir()
    assert expand([tmp_path]) == list(find_bags([tmp_path]).bags)
    # A file named explicitly is kept whatever its name: the reader judges it.
    note = tmp_path / "day" / "readme.txt"
    assert expand([note]) == [note]
    found = find_bags([tmp_path / "empty", tmp_path / "missing"])
    assert found.bags == ()
    assert [p.problem for p in found.problems] == [NO_BAGS, "no such file or directory"]
    with pytest.raises(BagError, match="holds no bags"):
        expand([tmp_path / "empty"])
    with pytest.raises(BagError, match="no such file"):
        expand([tmp_path / "missing"])
