"""Every MCAP layout the ``mcap`` Writer's options produce, read exactly (poses, counts, times).

The scene's ground truth (poses, record and header times, per-topic counts) is what was
written; each layout must give it back, through the indexes where they answer for every
message and record by record otherwise, and ``info`` must say which.
"""

from __future__ import annotations

import json
import logging
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.writer import CompressionType, IndexType, Writer

from ertools.cli.main import main
from ertools.io.mcap import scan as mcap_scan
from ertools.io.reader import read_poses, read_states
from ertools.io.summary import record_times
from ertools.io.summary import summary as bag_summary
from tests.helpers.bagmaker import write
from tests.helpers.scene import Scene

POSE = "/fbm3w/robot_at_work/pose"
BMBOX = "/fbm3w/bmbox_state"
INDEXED, SCAN = "summary+message-indexes", "scan"


def _options() -> dict[str, tuple[dict[str, Any], str, str]]:
    return {
        # id: (Writer options, index info reports, why the indexes do not answer)
        "default": ({}, INDEXED, ""),
        "no-statistics": ({"use_statistics": False}, INDEXED, ""),
        "no-summary-offsets": ({"use_summary_offsets": False}, INDEXED, ""),
        "zstd-no-crc": ({"compression": CompressionType.ZSTD, "enable_crcs": False}, INDEXED, ""),
        "uncompressed": ({"compression": CompressionType.NONE}, INDEXED, ""),
        "channels-only-in-chunks": (
            {"repeat_channels": False},
            SCAN,
            "channels written only inside chunks",
        ),
        "schemas-only-in-chunks": (
            {"repeat_schemas": False},
            SCAN,
            "schemas written only inside chunks",
        ),
        "unchunked": ({"use_chunking": False}, SCAN, "messages outside chunks"),
        "unchunked-no-statistics": (
            {"use_chunking": False, "use_statistics": False},
            SCAN,
            "messages outside chunks",
        ),
        "no-message-indexes": (
            {"index_types": IndexType.ALL & ~IndexType.MESSAGE},
            SCAN,
            "chunks without message indexes",
        ),
        "no-chunk-indexes": (
            {"index_types": IndexType.ALL & ~IndexType.CHUNK},
            SCAN,
            "chunks the summary does not index",
        ),
    }


LAYOUTS = list(_options())


@pytest.fixture(autouse=True)
def plain_logging(monkeypatch: pytest.MonkeyPatch) -> None:
    """The ``ertools`` logger as before any CLI run: an earlier in-process ``main`` leaves its
    stderr handler (a closed capture) and ``propagate=False``, which would hide the INFO
    lines these tests look for."""
    root = logging.getLogger("ertools")
    monkeypatch.setattr(root, "handlers", [])
    monkeypatch.setattr(root, "propagate", True)
    monkeypatch.setattr(root, "level", logging.NOTSET)


def expected_counts(scene: Scene) -> dict[str, int]:
    counts: dict[str, int] = {}
    for ci, _t, _v in scene.spec.msgs:
        topic = scene.spec.conns[ci][0]
        counts[topic] = counts.get(topic, 0) + 1
    return counts


def all_times(scene: Scene) -> np.ndarray:
    return np.array([t for _ci, t, _v in scene.spec.msgs], dtype=np.int64)


def without_summary(src: Path, dst: Path) -> Path:
    """``src`` with its summary section dropped and a footer saying so: a valid, complete MCAP
    file (the specification makes the summary optional)."""
    data = src.read_bytes()
    magic = data[-8:]
    footer = len(data) - 8 - 29
    (summary_start,) = struct.unpack_from("<Q", data, footer + 9)
    assert data[footer] == 0x02 and summary_start > 0
    dst.write_bytes(data[:summary_start] + struct.pack("<BQQQI", 0x02, 20, 0, 0, 0) + magic)
    return dst


def check_reads(path: Path, scene: Scene) -> None:
    """Poses, states, counts and times of ``path`` are those written."""
    poses = read_poses(path, POSE)
    np.testing.assert_array_equal(poses.xyz, scene.xyz)
    np.testing.assert_array_equal(poses.quat_xyzw, scene.quat)
    np.testing.assert_array_equal(poses.t_ns, scene.t_hdr)
    states = read_states(path, BMBOX)
    # the scene logs the BmBox state i // 12 every 12th pose
    np.testing.assert_array_equal(states.state, np.arange(len(states.state)))
    assert len(states.state) == (scene.n + 11) // 12
    t_all = all_times(scene)
    for exact in (False, True):
        s = bag_summary(path, exact=exact)
        assert s.problems == ()
        assert {t.name: t.count for t in s.topics if t.count} == expected_counts(scene)
        assert (s.start_ns, s.end_ns) == (int(t_all.min()), int(t_all.max()))
    np.testing.assert_array_equal(record_times(path)[POSE], scene.t_rec)


@pytest.mark.slow_cases(
    "channels-only-in-chunks", "no-chunk-indexes", "no-message-indexes", "schemas-only-in-chunks"
)
@pytest.mark.parametrize("layout", LAYOUTS)
def test_layout_read_exactly(
    layout: str,
    tmp_path: Path,
    scene: Scene,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    options, index, why = _options()[layout]
    path = write(tmp_path / f"{layout}.mcap", "mcap-cdr", scene.spec, chunk_bytes=2000, **options)
    with caplog.at_level(logging.INFO, logger="ertools"):
        check_reads(path, scene)
    fell_back = "reading the file record by record" in caplog.text
    assert fell_back == (index == SCAN)
    if why:
        assert why in caplog.text
    code = main(["info", "--format", "json", str(path)])
    out, err = capsys.readouterr()
    assert code == 0 and err == ""
    (bag,) = json.loads(out)["bags"]
    assert bag["index"] == index
    assert bag["messages"] == len(scene.spec.msgs)


@pytest.mark.slow
def test_no_summary_section(
    tmp_path: Path, scene: Scene, capsys: pytest.CaptureFixture[str]
) -> None:
    full = write(tmp_path / "full.mcap", "mcap-cdr", scene.spec, chunk_bytes=2000)
    path = without_summary(full, tmp_path / "bare.mcap")
    check_reads(path, scene)
    assert main(["info", "--format", "json", str(path)]) == 0
    out, err = capsys.readouterr()
    assert err == ""  # complete: no warning, no problem
    (bag,) = json.loads(out)["bags"]
    assert bag["index"] == SCAN and bag["problems"] == [] and not bag["indexed"]
    assert main(["info", "--check", str(path)]) == 0


def test_attachments_and_metadata_keep_the_indexes(
    tmp_path: Path,
    scene: Scene,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    finish = Writer.finish

    def finish_with_extras(self: Any) -> None:
        # between the last chunk and the summary: bytes no chunk index covers
        self.add_attachment(
            create_time=1, log_time=2, name="map.yaml", media_type="text/yaml", data=b"a" * 500
        )
        self.add_metadata("run", {"benchmark": "fbm3w"})
        finish(self)

    monkeypatch.setattr(Writer, "finish", finish_with_extras)
    path = write(tmp_path / "extras.mcap", "mcap-cdr", scene.spec, chunk_bytes=2000)
    check_reads(path, scene)
    assert main(["info", "--format", "json", str(path)]) == 0
    (bag,) = json.loads(capsys.readouterr().out)["bags"]
    assert bag["index"] == INDEXED


def test_statistics_that_disagree_with_the_message_indexes(
    tmp_path: Path, scene: Scene, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path / "s.mcap", "mcap-cdr", scene.spec, chunk_bytes=2000, enable_crcs=False)
    data = bytearray(path.read_bytes())
    # the statistics record (op 0x0B) starts with its uint64 message count
    at = data.rindex(b"\x0b", 0, len(data) - 8 - 29)
    while struct.unpack_from("<Q", data, at + 9)[0] != len(scene.spec.msgs):
        at = data.rindex(b"\x0b", 0, at)
    struct.pack_into("<Q", data, at + 9, len(scene.spec.msgs) + 7)
    path.write_bytes(bytes(data))
    assert main(["info", "--format", "json", str(path)]) == 1
    out, err = capsys.readouterr()
    assert f"statistics record counts {len(scene.spec.msgs) + 7} messages" in err
    (bag,) = json.loads(out)["bags"]
    assert bag["messages"] == len(scene.spec.msgs)  # counted from the message indexes


def _insert_private_record(path: Path, after_messages: int) -> None:
    """Put a record of an unknown opcode (0x80: the specification's private range, which
    readers skip) after the given number of top-level messages, walking the records here
    with a plain loop."""
    data = path.read_bytes()
    pos, seen = 8, 0
    while seen < after_messages:
        op, n = struct.unpack_from("<BQ", data, pos)
        pos += 9 + n
        seen += op == 0x05
    private = struct.pack("<BQ", 0x80, 5) + b"hello"
    path.write_bytes(data[:pos] + private + data[pos:])


@pytest.mark.parametrize(("window", "run"), [(300, 1), (1000, 3), (1 << 22, 16)])
@pytest.mark.parametrize("chunked", [False, True])
def test_scan_finds_every_record(
    window: int,
    run: int,
    chunked: bool,
    tmp_path: Path,
    scene: Scene,
    monkeypatch: pytest.MonkeyPatch,
) -> None:

    # small windows (a few records) and early bulk reads: record chains cut at window edges
    monkeypatch.setattr(mcap_scan, "WINDOW", window)
    monkeypatch.setattr(mcap_scan, "RUN_TO_BULK", run)
    full = write(
        tmp_path / "full.mcap", "mcap-cdr", scene.spec, chunk_bytes=20000, use_chunking=chunked
    )
    path = without_summary(full, tmp_path / "bare.mcap")
    if not chunked:
        _insert_private_record(path, 40)
    found = mcap_scan.scan_mcap(path, keep=frozenset({1}))
    assert found.complete and found.problem == ""
    topic_of = {cid: ch.topic for cid, ch in found.channels.items()}
    got: dict[str, list[int]] = {}
    for cid, t in zip(found.channel_id.tolist(), found.log_time.tolist(), strict=True):
        got.setdefault(topic_of[cid], []).append(t)
    want: dict[str, list[int]] = {}
    for ci, t, _v in scene.spec.msgs:
        want.setdefault(scene.spec.conns[ci][0], []).append(t)
    assert got == want  # every message, in the order written
    # the kept payloads: channel 1's messages only, each as long as its record says
    kept = np.concatenate([r[3] for r in found.payloads])
    assert set(found.channel_id[kept].tolist()) == {1}
    assert len(kept) == int((found.channel_id == 1).sum())


@pytest.mark.slow
def test_verbose_says_why_a_file_is_read_record_by_record(
    tmp_path: Path, scene: Scene, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path / "r.mcap", "mcap-cdr", scene.spec, repeat_channels=False)
    assert main(["info", "-v", str(path)]) == 0
    err = capsys.readouterr().err
    assert "channels written only inside chunks; reading the file record by record" in err
    indexed = write(tmp_path / "i.mcap", "mcap-cdr", scene.spec)
    assert main(["info", "-v", str(indexed)]) == 0
    assert "record by record" not in capsys.readouterr().err


@pytest.mark.slow
def test_rosbag2_mcap_storage_without_summary(tmp_path: Path, scene: Scene) -> None:
    folder = write(tmp_path / "r2", "rosbag2-mcap", scene.spec)
    (storage,) = folder.glob("*.mcap")
    without_summary(storage, tmp_path / "bare.mcap").replace(storage)
    s = bag_summary(folder, exact=True)
    assert s.index == "metadata.yaml+scan" and s.problems == ()
    assert {t.name: t.count for t in s.topics if t.count} == expected_counts(scene)
    t_all = all_times(scene)
    assert (s.start_ns, s.end_ns) == (int(t_all.min()), int(t_all.max()))
    poses = read_poses(folder, POSE)  # rosbags' reader, as the fast path steps aside
    np.testing.assert_array_equal(poses.xyz, scene.xyz)
    np.testing.assert_array_equal(poses.t_ns, scene.t_hdr)
