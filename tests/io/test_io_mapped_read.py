"""Dense chunk groups of closed ROS1 bags read in place through a populated map (issue 39
item 3): the same bytes as the copying read they replace, on the real 2015 bag, every sample
bag and generated bags, and a file cut while it is read ends in one error line."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from ertools.errors import BagError, ErtoolsError
from ertools.io.files import open_bag
from ertools.io.model import POSE_TYPES, PoseSource
from ertools.io.reader import read_pose_sources
from ertools.io.ros1 import runs as ros1_runs
from ertools.io.summary import summary
from tests.helpers.bagmaker import write
from tests.helpers.fastpath import REAL_BAG, sample_bags
from tests.helpers.scene import Scene

REPO = Path(__file__).resolve().parents[2]


def _sources(path: Path) -> list[PoseSource]:
    """Every pose topic of the file by header stamp and by record time, and every tf child
    frame of world: what the scorers read."""
    topics = [t.name for t in summary(path).topics if t.msgtype in POSE_TYPES and t.count]
    out = [PoseSource(topic=t) for t in topics if t not in ("/tf", "/tf_static")]
    out += [PoseSource(topic=t, time_source="record") for t in topics if t != "/tf"]
    if "/tf" in topics:
        out += [PoseSource(frame=f) for f in ("robot_at_work", "robot_at_home", "map")]
    return out


def _as_bytes(streams: list[Any]) -> list[tuple[bytes, ...]]:
    return [(s.t_ns.tobytes(), s.xyz.tobytes(), s.quat_xyzw.tobytes()) for s in streams]


def _read(path: Path, sources: list[PoseSource]) -> list[Any]:
    """Each source alone (or its refusal: a frame the file lacks), then every readable one
    in one read."""
    got: list[Any] = []
    readable = []
    for s in sources:
        try:
            got.append(read_pose_sources(path, [s])[0])
            readable.append(s)
        except ErtoolsError as err:
            got.append(f"{type(err).__name__}: {err}")
    got.append(read_pose_sources(path, readable))
    return got


def _comparable(got: list[Any]) -> list[Any]:
    out: list[Any] = []
    for g in got:
        if isinstance(g, list):
            out.append(_as_bytes(g))
        elif isinstance(g, str):
            out.append(g)
        else:
            out.append(_as_bytes([g]))
    return out


def _recorded() -> list[Any]:
    real = [pytest.param(REAL_BAG, marks=pytest.mark.real, id="real-2015")]
    ros1 = [p for p in sample_bags() if p.is_file() and p.suffix in (".bag", ".active")]
    # (the state-only runs of the RSBB samples have no pose to read)
    samples = [pytest.param(p, id=p.name) for p in ros1 if _sources(p)]
    # `make bench`'s GT hour and robot hour beside camera frames, where they were generated
    bench = [REPO / "build" / "bench" / n for n in ("gt_hour.bag", "robot_hour_with_camera.bag")]
    return real + samples + [pytest.param(p, id=f"bench-{p.name}") for p in bench if p.exists()]


def _spied(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Which maps the reads make: "dense" (populated groups), "sparse" (records far apart)."""
    calls: list[str] = []
    dense, sparse = ros1_runs.populated_group, ros1_runs.mapped_group

    def spy_dense(bag: Any, chunks: list[Any], scratch: list[Any]) -> Any:
        calls.append("dense")
        return dense(bag, chunks, scratch)

    def spy_sparse(bag: Any, chunks: list[Any], scratch: list[Any]) -> Any:
        calls.append("sparse")
        return sparse(bag, chunks, scratch)

    monkeypatch.setattr(ros1_runs, "populated_group", spy_dense)
    monkeypatch.setattr(ros1_runs, "mapped_group", spy_sparse)
    return calls


@pytest.mark.slow
@pytest.mark.parametrize("path", _recorded())
def test_mapped_read_equals_the_copying_read(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each source alone and all in one read, byte for byte what the reads through
    ``preadv`` copies give; closed uncompressed bags went through the map, ``.active``
    files never."""
    if not path.exists():
        pytest.skip(f"{path} not present")
    sources = _sources(path)
    assert sources, f"{path.name} has no pose source"
    calls = _spied(monkeypatch)
    mapped = _comparable(_read(path, sources))
    with open_bag(path) as bag:
        closed = bag.format == "ros1" and bag.layout.indexed  # type: ignore[attr-defined]
        plain = set(bag.compressions()) == {"none"}  # type: ignore[attr-defined]
    # dense groups of closed uncompressed bags are mapped (a pose topic between camera
    # frames: sparse maps only, as before); nothing else is
    if "dense" in calls:
        assert closed and plain
    if closed and plain:
        assert ("dense" in calls) is ("camera" not in path.name) and calls
    monkeypatch.setattr(ros1_runs, "MAP_POPULATE", 0)
    calls.clear()
    copied = _comparable(_read(path, sources))
    assert "dense" not in calls
    assert mapped == copied


@pytest.mark.parametrize("chunk_bytes", [1500, 40_000])
def test_mapped_read_of_generated_bags_equals_the_copying_read(
    tmp_path: Path, scene: Scene, monkeypatch: pytest.MonkeyPatch, chunk_bytes: int
) -> None:
    """The scene (two /tf publishers, Pose2D by record time) in one group and in many."""
    path = write(tmp_path / "s.bag", "ros1", scene.spec, chunk_bytes=chunk_bytes)
    sources = _sources(path)
    calls = _spied(monkeypatch)
    mapped = _comparable(_read(path, sources))
    assert "dense" in calls
    monkeypatch.setattr(ros1_runs, "MAP_POPULATE", 0)
    assert _comparable(_read(path, sources)) == mapped


def test_an_active_file_is_copied_not_mapped(
    tmp_path: Path, scene: Scene, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A bag still being recorded may change under a map: positional reads only."""
    closed = write(tmp_path / "s.bag", "ros1", scene.spec, chunk_bytes=1500)
    active = tmp_path / "s.bag.active"
    shutil.copyfile(closed, active)
    sources = [PoseSource(topic="/fbm3w/robot_at_work/pose")]
    calls = _spied(monkeypatch)
    got = read_pose_sources(active, sources)
    assert "dense" not in calls
    assert _as_bytes(got) == _as_bytes(read_pose_sources(closed, sources))


def test_a_bag_cut_after_it_was_opened_is_refused_in_one_line(tmp_path: Path, scene: Scene) -> None:
    """Cut between reading its index and mapping its chunks (a copy over it, a sync): the
    group that lies past the new end is refused, not mapped (reading it would raise SIGBUS)."""
    path = write(tmp_path / "s.bag", "ros1", scene.spec, chunk_bytes=1500)
    with open_bag(path) as bag:
        bag.compressions()  # type: ignore[attr-defined]  # (each chunk's data found)
        chunks = bag.layout.chunks  # type: ignore[attr-defined]
        os.truncate(path, chunks[len(chunks) // 2].pos)
        with pytest.raises(BagError, match="cut off by end of file") as err:
            ros1_runs.populated_group(bag, chunks, [])  # type: ignore[arg-type]
    assert "\n" not in str(err.value)


def test_a_bag_cut_while_mapped_ends_in_one_error_line(tmp_path: Path, scene: Scene) -> None:
    """Cut while its chunks are mapped (the kernel then answers a read of the lost pages
    with SIGBUS): one error line naming the file, exit status 1, no traceback."""
    path = write(tmp_path / "s.bag", "ros1", scene.spec, chunk_bytes=1500)
    script = f"""
import os
from ertools.io.ros1 import runs
from ertools.io.reader import read_poses
from ertools.io.model import PoseSource
real = runs.populated_group
def cut_then_map(bag, chunks, scratch):
    group = real(bag, chunks, scratch)
    os.truncate(bag.path, 0)  # what `cp other.bag` over it does first
    return group
runs.populated_group = cut_then_map
read_poses({str(path)!r}, "/fbm3w/robot_at_work/pose")
print("not reached")
"""
    done = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        cwd=REPO,
        timeout=120,
        check=False,
    )
    assert done.returncode == 1
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("ertools: error: ")
    assert str(path) in lines[0] and "changed" in lines[0]
