"""`ertools info`: output on every format, and one stderr line + exit 1 on every bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from ertools.cli.main import main
from ertools.errors import BagError
from ertools.io.reader import read_poses
from tests.helpers.bagmaker import write
from tests.helpers.scene import DT, Scene
from tests.helpers.stderr_text import joined_lines
from tests.io.test_io_summary import make_active

POSE = "/fbm3w/robot_at_work/pose"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["info", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_info_json_every_format(
    capsys: pytest.CaptureFixture[str], scene: Scene, scene_bag: tuple[str, Path]
) -> None:
    fmt, path = scene_bag
    code, out, err = run(capsys, str(path), "--format", "json")
    assert code == 0, err
    data = json.loads(out)
    assert data["problems"] == []
    (bag,) = data["bags"]
    topics = {t["name"]: t for t in bag["topics"]}
    assert topics[POSE]["count"] == scene.n
    assert topics[POSE]["type"] == "geometry_msgs/PoseStamped"
    # 50 records DT apart span 0.41 s, under the 1 s a rate needs: no rate, the exact span
    assert topics[POSE]["median_rate_hz"] is None
    assert topics[POSE]["span_s"] == (scene.n - 1) * DT / 1e9
    assert topics["/chatter"]["count"] == 0 and topics["/chatter"]["median_rate_hz"] is None
    assert bag["start"] == pytest.approx(scene.t_rec[0] / 1e9, abs=1e-6)
    assert bag["start_iso"].startswith("2015-10-23T14:15:40")
    assert bag["format"] == {
        "ros1-lz4": "ros1",
        "ros1-bz2": "ros1",
        "mcap-cdr": "mcap",
        "mcap-ros1": "mcap",
    }.get(fmt, fmt)


@pytest.mark.slow
def test_info_table_and_yaml(
    capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path
) -> None:
    path = write(tmp_path / "t.bag", "ros1-lz4", scene.spec, chunk_bytes=2000)
    code, out, _ = run(capsys, str(path), "--check")
    assert code == 0
    line = next(x for x in out.splitlines() if x.strip().startswith(POSE))
    # 49 intervals of 8.333333 ms = 0.408 s: too short for a rate (test_io_info_rates.py)
    assert (scene.n - 1) * DT == 408_333_317
    assert line.split()[1:] == [
        "geometry_msgs/PoseStamped",
        str(scene.n),
        str(scene.n),
        "messages",
        "in",
        "0.408",
        "s",
    ]
    assert "compression: lz4" in out and "duration:" in out
    code, out, _ = run(capsys, str(tmp_path), "--format", "yaml")  # a folder of bags
    assert code == 0
    data = yaml.safe_load(out)
    assert [b["path"] for b in data["bags"]] == [str(path)]


def one_error_line(err: str, *needles: str) -> None:
    lines = [x for x in joined_lines(err) if x.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("ertools: error: ")
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert "Traceback" not in err


def test_empty_random_missing_and_empty_dir(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    empty = tmp_path / "empty.bag"
    empty.write_bytes(b"")
    code, _, err = run(capsys, str(empty))
    assert code == 1
    one_error_line(err, "empty.bag", "empty")
    junk = tmp_path / "junk.bag"
    junk.write_bytes(np.random.default_rng(1).bytes(4096))
    code, _, err = run(capsys, str(junk))
    assert code == 1
    one_error_line(err, "junk.bag", "not a ROS1 bag")
    code, _, err = run(capsys, str(tmp_path / "nope.bag"))
    assert code == 1
    one_error_line(err, "nope.bag", "no such file")
    folder = tmp_path / "nobags"
    folder.mkdir()
    (folder / "notes.txt").write_text("x")
    code, _, err = run(capsys, str(folder))
    assert code == 1
    one_error_line(err, "nobags", "holds no bags")


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["ros1", "ros1-bz2", "mcap-cdr"])
def test_truncated_anywhere(
    capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path, fmt: str
) -> None:
    suffix = ".mcap" if fmt.startswith("mcap") else ".bag"
    good = write(tmp_path / f"good{suffix}", fmt, scene.spec, chunk_bytes=2000)
    data = good.read_bytes()
    rng = np.random.default_rng(7)
    cuts = [1, 5, 12, 20, 100, 4100, *rng.integers(4200, len(data) - 1, 8).tolist(), len(data) - 1]
    for cut in cuts:
        bad = tmp_path / f"cut{cut}{suffix}"
        bad.write_bytes(data[:cut])
        code, _, err = run(capsys, str(bad))
        assert code == 1, f"cut at {cut}: {err}"
        one_error_line(err, bad.name)


@pytest.mark.slow
def test_corrupted_chunk(capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path) -> None:
    good = write(tmp_path / "good.bag", "ros1-lz4", scene.spec, chunk_bytes=2000)
    data = bytearray(good.read_bytes())
    # Overwrite the middle of the second chunk's compressed payload.
    first = data.index(b"compression=lz4")
    second = data.index(b"compression=lz4", first + 1)
    at = second + 60
    data[at : at + 200] = bytes(200)
    bad = tmp_path / "corrupt.bag"
    bad.write_bytes(bytes(data))
    code, _, err = run(capsys, str(bad), "--check")
    assert code == 1
    one_error_line(err, "corrupt.bag", "chunk")
    # Reading the damaged chunk's poses fails the same way (never a silently short stream).
    with pytest.raises(BagError, match="corrupt"):
        read_poses(bad, POSE)


def test_good_and_bad_together(
    capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path
) -> None:
    good = write(tmp_path / "good.bag", "ros1", scene.spec)
    bad = tmp_path / "bad.bag"
    bad.write_bytes(b"#ROSBAG V2.0\n\x00")
    code, out, err = run(capsys, str(good), str(bad), "--format", "json")
    assert code == 1
    data = json.loads(out)
    assert [b["path"] for b in data["bags"]] == [str(good)]
    assert data["problems"][0]["path"] == str(bad)
    one_error_line(err, "bad.bag")


@pytest.mark.slow
def test_corrupted_record_in_uncompressed_chunk(
    capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path
) -> None:
    good = write(tmp_path / "good.bag", "ros1", scene.spec, chunk_bytes=2000)
    data = bytearray(good.read_bytes())
    hits = [i for i in range(len(data)) if data[i : i + 4] == b"op=\x02"]
    at = hits[len(hits) // 2]
    data[at + 3] = 0x09  # a message record's op byte: no longer a message
    bad = tmp_path / "badop.bag"
    bad.write_bytes(bytes(data))
    code, _, err = run(capsys, str(bad), "--check")
    assert code == 1
    # One line per disagreement: the odd record, and the index entry and chunk-info count
    # that still call it a message.
    lines = joined_lines(err)
    assert len(lines) == 3, err
    assert all(x.startswith(f"ertools: error: {bad}: chunk at byte ") for x in lines)
    assert "record of op 9 inside the chunk at offset" in lines[0]
    assert "chunk info counts 1 messages, the chunk holds 0" in lines[1]
    assert "1 index entries point at no message record" in lines[2]
    assert "Traceback" not in err


def test_active_bag_warns_and_exits_0(
    capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path
) -> None:
    good = write(tmp_path / "g.bag", "ros1", scene.spec, chunk_bytes=2000)
    active = make_active(good, tmp_path / "rec.bag.active")
    code, out, err = run(capsys, str(active))
    assert code == 0
    assert "NOT INDEXED" in out and "ros1-active" in out
    assert "warning" in err and "rec.bag.active" in err and "Traceback" not in err


def test_missing_path_among_others(
    capsys: pytest.CaptureFixture[str], scene: Scene, tmp_path: Path
) -> None:
    good = write(tmp_path / "good.bag", "ros1", scene.spec)
    code, out, err = run(capsys, str(tmp_path / "gone.bag"), str(good), "--format", "json")
    assert code == 1
    data = json.loads(out)
    assert [b["path"] for b in data["bags"]] == [str(good)]  # the good bag is still described
    one_error_line(err, "gone.bag", "no such file")


def test_malformed_rosbag2_metadata_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # yaml's own message spans several lines (problem, mark, caret); info says it in one, in
    # the YAML problems list as well as on stderr.
    bag = tmp_path / "broken_rosbag2"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: [unclosed\n  x: {\n")
    code, out, err = run(capsys, str(bag), "--format", "yaml")
    assert code == 1
    lines = joined_lines(err.strip())
    assert len(lines) == 1 and lines[0].startswith("ertools: error:"), err
    assert "broken_rosbag2" in lines[0] and "metadata.yaml" in lines[0]
    (problem,) = yaml.safe_load(out)["problems"]
    assert "\n" not in problem["problem"] and "metadata.yaml" in problem["problem"]
