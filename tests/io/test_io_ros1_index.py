"""ROS1 index data checked against the records: empty bags, ``info --check``, the fast path.

Bags are written by rosbags' Writer; damage is done by hand at byte positions found with a
small record walker written here from the format specification (Bags/Format/2.0), not with
ertools' own parser.
"""

from __future__ import annotations

import json
import logging
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.rosbag1 import Reader, Writer
from rosbags.typesys import Stores, get_typestore

from ertools import caches
from ertools.cli.main import main
from ertools.io.reader import read_poses
from ertools.io.ros1 import layout
from ertools.io.ros1.check import check_ros1, rebuild_layout
from ertools.io.ros1.entries import kept
from ertools.io.ros1.layout import scan_layout
from ertools.io.summary import summary as bag_summary
from tests.helpers.bagmaker import Spec, write
from tests.helpers.fastpath import REAL_BAG, sample_bags
from tests.helpers.stderr_text import error_messages

T0 = 1_445_609_740_000_000_000
DT = 10_000_000
N = 300
WEEKS = 2_000_000  # seconds added to a time field: ~3 weeks


# --- an independent walker: (position, op, header fields, data position, data length) ------


def records(
    raw: bytes, pos: int = 13
) -> list[tuple[int, int, dict[str, tuple[int, int]], int, int]]:
    """Top-level records; each header field as (value position, value length)."""
    out = []
    while pos < len(raw):
        (hlen,) = struct.unpack_from("<I", raw, pos)
        fields: dict[str, tuple[int, int]] = {}
        f = pos + 4
        while f < pos + 4 + hlen:
            (flen,) = struct.unpack_from("<I", raw, f)
            body = raw[f + 4 : f + 4 + flen]
            eq = body.index(b"=")
            fields[body[:eq].decode()] = (f + 4 + eq + 1, flen - eq - 1)
            f += 4 + flen
        (dlen,) = struct.unpack_from("<I", raw, pos + 4 + hlen)
        op = raw[fields["op"][0]]
        out.append((pos, op, fields, pos + 8 + hlen, dlen))
        pos += 8 + hlen + dlen
    return out


def of_op(raw: bytes, op: int) -> list[tuple[int, int, dict[str, tuple[int, int]], int, int]]:
    return [r for r in records(raw) if r[1] == op]


def add_u32(raw: bytearray, at: int, delta: int) -> None:
    struct.pack_into("<I", raw, at, struct.unpack_from("<I", raw, at)[0] + delta)


def two_topic_bag(path: Path, fmt: str = "ros1") -> Path:
    s = Spec()
    a = s.conn("/pose", "geometry_msgs/PoseStamped")
    b = s.conn("/pose2d", "geometry_msgs/Pose2D")
    for i in range(N):
        t = T0 + i * DT
        s.add(a, t, stamp=t - 1000, frame="world", xyz=(i, 0.5, 0.25), q=(0, 0, 0, 1))
        if i % 3 == 0:
            s.add(b, t + 5, x=float(i), y=1.0, theta=0.1)
    return write(path, fmt, s, chunk_bytes=4000)


def cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, Any, list[str]]:
    code = main(["info", "--format", "json", *args])
    out = capsys.readouterr()
    errors = error_messages(out.err)
    return code, json.loads(out.out), errors


# --- empty bags --------------------------------------------------------------------------------


@pytest.mark.parametrize("with_connection", [True, False])
def test_empty_bag_is_a_valid_bag(
    tmp_path: Path, with_connection: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "empty.bag"
    with Writer(path) as w:
        if with_connection:
            ts = get_typestore(Stores.ROS1_NOETIC)
            w.add_connection("/pose", "geometry_msgs/msg/PoseStamped", typestore=ts)
    with Reader(path) as r:  # the official reader: no messages, the connection if any
        official = {c.topic: "geometry_msgs/PoseStamped" for c in r.connections}
        assert r.message_count == 0
    for check in ([], ["--check"]):
        code, data, errors = cli([str(path), *check], capsys)
        assert (code, errors) == (0, [])
        bag = data["bags"][0]
        assert (bag["messages"], bag["start"], bag["end"], bag["problems"]) == (0, None, None, [])
        assert {t["name"]: t["type"] for t in bag["topics"]} == official
        assert all(t["count"] == 0 for t in bag["topics"])
    s = bag_summary(path)
    assert (s.message_count, s.start_ns, s.end_ns, s.indexed) == (0, 0, 0, True)
    assert check_ros1(path) == []
    if with_connection:
        assert len(read_poses(path, "/pose")) == 0


# --- info --check ------------------------------------------------------------------------------


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "ros1-bz2"])
def test_sound_bags_check_clean(tmp_path: Path, fmt: str) -> None:
    assert check_ros1(two_topic_bag(tmp_path / "b.bag", fmt)) == []


@pytest.mark.slow
def test_sample_and_real_bags_check_clean() -> None:

    # (the samples include deliberately truncated bags: those already fail the summary)
    bags = [p for p in sample_bags() if p.suffix == ".bag" and not bag_summary(p).problems]
    if REAL_BAG.is_file():
        bags.append(REAL_BAG)
    if not bags:
        pytest.skip("no sample or real ROS1 bags here")
    for p in bags:
        assert check_ros1(p) == [], p


def damaged(tmp_path: Path, how: str) -> tuple[Path, dict[str, Any]]:
    """A copy of the two-topic bag damaged one way; returns what was changed."""
    good = two_topic_bag(tmp_path / "good.bag")
    raw = bytearray(good.read_bytes())
    infos = of_op(bytes(raw), 0x06)
    chunks = of_op(bytes(raw), 0x05)
    index = of_op(bytes(raw), 0x04)
    last_info = infos[-1]
    what: dict[str, Any] = {"chunk": last_info[2]["chunk_pos"], "chunks": len(chunks)}
    if how == "info-end":
        add_u32(raw, last_info[2]["end_time"][0], WEEKS)
    elif how == "info-start":
        add_u32(raw, last_info[2]["start_time"][0], -WEEKS)
    elif how == "info-start-late":
        add_u32(raw, last_info[2]["start_time"][0] + 4, 1)  # nsec + 1: the first message out
    elif how == "info-end-early":
        at = last_info[2]["end_time"][0] + 4
        assert struct.unpack_from("<I", raw, at)[0] > 0
        add_u32(raw, at, -1)  # nsec - 1: the last message out
    elif how == "info-count":
        add_u32(raw, last_info[3] + 4, 1)  # data: (conn u32, count u32) pairs
    elif how == "info-conn":
        what["conn"] = struct.unpack_from("<I", raw, last_info[3])[0]
        struct.pack_into("<I", raw, last_info[3], 725311778)  # a connection the bag lacks
    elif how == "index-time":
        pos, _op, fields, dpos, _dlen = index[0]
        add_u32(raw, dpos + 12 * 2 + 4, 1)  # third entry: sec, nsec (+1 ns), offset
        what["conn"] = struct.unpack_from("<I", raw, fields["conn"][0])[0]
        what["index"] = pos
    elif how == "index-time-weeks":
        add_u32(raw, index[0][3] + 12 * 2, WEEKS)
    elif how == "index-offset":
        add_u32(raw, index[0][3] + 12 * 2 + 8, 1)  # points one byte into its record
    else:
        raise ValueError(how)
    (what["chunk"],) = struct.unpack_from("<Q", raw, what["chunk"][0])
    path = tmp_path / f"{how}.bag"
    path.write_bytes(bytes(raw))
    return path, what


@pytest.mark.parametrize(
    ("how", "expected"),
    [
        ("info-end", ["its messages span"]),
        ("info-start", ["its messages span"]),
        ("info-start-late", ["its messages span"]),
        ("info-count", ["chunk info counts"]),
        ("index-time", ["1 index entries disagree with their record's time"]),
        ("index-offset", ["1 index entries point at no message", "1 message records not in"]),
    ],
)
def test_check_reports_each_disagreement(
    tmp_path: Path, how: str, expected: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    path, what = damaged(tmp_path, how)
    lines = check_ros1(path)
    assert len(lines) == len(expected), lines
    first_chunk = of_op(path.read_bytes(), 0x05)[0][0]
    chunk = what["chunk"] if how.startswith("info") else first_chunk
    for line, text in zip(lines, expected, strict=True):
        assert text in line
        assert line.startswith(f"chunk at byte {chunk}: ")
    code, data, errors = cli(["--check", str(path)], capsys)
    assert code == 1
    assert len(errors) == len(expected)  # one stderr line each
    assert all(e.startswith(f"ertools: error: {path}: chunk at byte ") for e in errors)
    assert data["bags"][0]["problems"] == lines
    code, _data, errors = cli([str(path)], capsys)
    if how in ("info-start-late", "info-count"):
        # the two index records contradict each other (index-data times outside the chunk
        # info's span, or other counts): the summary says so without reading the records
        assert code == 1 and len(errors) == 1 and "damaged index" in errors[0]
    elif how in ("index-time", "index-offset"):
        # an entry of the first chunk, which bounds its connection's span: the summary
        # checks those entries against their records (a damaged one would move the span)
        assert code == 1 and len(errors) == 1 and "damaged index" in errors[0]
    else:
        # moved outwards, or wrong in both alike: only the records tell (--check)
        assert (code, errors) == (0, [])


def test_check_names_the_times(tmp_path: Path) -> None:
    path, what = damaged(tmp_path, "info-end")
    # The last chunk holds the last messages: record times up to T0 + (N - 1) DT; its end
    # moved WEEKS seconds on.
    (line,) = check_ros1(path)
    last = T0 + (N - 1) * DT  # the last pose (the last Pose2D is message 297's)
    end = last + WEEKS * 1_000_000_000
    assert f"to {end // 10**9}.{end % 10**9:09d}" in line
    assert f"to {last // 10**9}.{last % 10**9:09d}" in line
    assert f"chunk at byte {what['chunk']}" in line


# --- the fast path ---------------------------------------------------------------------------


def truth_record_times() -> np.ndarray:
    return T0 + np.arange(N, dtype=np.int64) * DT


@pytest.mark.parametrize("how", ["info-start-late", "info-end-early", "index-time-weeks"])
def test_fast_path_distrusts_an_index_that_contradicts_itself(
    tmp_path: Path, how: str, caplog: pytest.LogCaptureFixture
) -> None:
    path, _what = damaged(tmp_path, how)
    with caplog.at_level(logging.WARNING, logger="ertools"):
        rec = read_poses(path, "/pose", time_source="record")
    # the records' own times, not the index's
    np.testing.assert_array_equal(rec.t_ns, truth_record_times())
    np.testing.assert_array_equal(rec.xyz[:, 0], np.arange(N, dtype=np.float64))
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1
    assert "outside its chunk info" in warnings[0] and "scanning every record" in warnings[0]


def test_fast_path_distrusts_a_chunk_info_naming_an_unknown_connection(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """The last chunk info's first connection id damaged (found by fuzzing): planned from it,
    the last chunk dropped out of its real connection's read without a word."""
    path, _what = damaged(tmp_path, "info-conn")
    with caplog.at_level(logging.WARNING, logger="ertools"):
        rec = read_poses(path, "/pose", time_source="record")
    np.testing.assert_array_equal(rec.t_ns, truth_record_times())
    np.testing.assert_array_equal(rec.xyz[:, 0], np.arange(N, dtype=np.float64))
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and "connection 725311778, which the bag lacks" in warnings[0]


@pytest.mark.parametrize("how", ["info-end", "info-start"])
def test_a_wider_chunk_span_contradicts_no_read(
    tmp_path: Path, how: str, caplog: pytest.LogCaptureFixture
) -> None:
    """A chunk info moved weeks outwards: every index time still lies inside it, so the read
    (planned from the index data's own times) is right and says nothing; --check finds it."""

    path, _what = damaged(tmp_path, how)
    with caplog.at_level(logging.WARNING, logger="ertools"):
        rec = read_poses(path, "/pose", time_source="record")
    np.testing.assert_array_equal(rec.t_ns, truth_record_times())
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
    if how == "info-end":
        # what trusting the chunk info gives: rosbags' reader moves the bag's end by weeks
        with Reader(path) as r:
            assert r.end_time - 1 == int(truth_record_times()[-1]) + WEEKS * 1_000_000_000
    assert len(check_ros1(path)) == 1


def test_fast_path_on_a_sound_bag_warns_nothing(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = two_topic_bag(tmp_path / "b.bag")
    with caplog.at_level(logging.WARNING, logger="ertools"):
        rec = read_poses(path, "/pose", time_source="record")
    np.testing.assert_array_equal(rec.t_ns, truth_record_times())
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4"])
def test_rebuilt_layout_equals_the_record_by_record_scan(tmp_path: Path, fmt: str) -> None:
    path = two_topic_bag(tmp_path / "b.bag", fmt)
    size = path.stat().st_size
    first = records(path.read_bytes())[0]
    header_end = first[3] + first[4]
    with path.open("rb") as f:
        fast = rebuild_layout(f, path, size, header_end, "test")
        slow = scan_layout(f, path, size, header_end, "test")
    assert [c.id for c in fast.conns] == [c.id for c in slow.conns] == [0, 1]
    assert [(c.topic, c.msgtype, c.msgdef) for c in fast.conns] == [
        (c.topic, c.msgtype, c.msgdef) for c in slow.conns
    ]
    assert len(fast.chunks) == len(slow.chunks) > 3
    for a, b in zip(fast.chunks, slow.chunks, strict=True):
        assert (a.pos, a.start_ns, a.end_ns, a.counts) == (b.pos, b.start_ns, b.end_ns, b.counts)
        assert a.entries is not None and b.entries is not None
        for cid in b.entries:
            np.testing.assert_array_equal(a.entries[cid][0], b.entries[cid][0])
            np.testing.assert_array_equal(a.entries[cid][1], b.entries[cid][1])
    # and the total is what was written: N poses, one Pose2D every third
    assert sum(c.counts.get(0, 0) for c in fast.chunks) == N
    assert sum(c.counts.get(1, 0) for c in fast.chunks) == N // 3


def test_message_record_without_its_conn_field(tmp_path: Path) -> None:
    """A renamed header field: the record is reported unreadable and the index entry and
    chunk-info count that still call it a message disagree (regression: no crash)."""
    good = two_topic_bag(tmp_path / "good.bag")
    raw = bytearray(good.read_bytes())
    chunk = of_op(bytes(raw), 0x05)[1]
    at = raw.index(b"conn=", chunk[3] + 200)  # a message record's header inside chunk 2
    raw[at + 3] = ord("X")
    bad = tmp_path / "noconn.bag"
    bad.write_bytes(bytes(raw))
    lines = check_ros1(bad)
    assert lines[0].startswith(f"chunk at byte {chunk[0]}: unreadable record at chunk offset")
    assert any("index entries point at no message record" in x for x in lines[1:])
    assert any("chunk info counts" in x for x in lines[1:])


def test_a_header_claiming_an_empty_index_over_chunks_is_not_an_empty_bag(tmp_path: Path) -> None:
    """Only a header followed by nothing is an empty bag: chunks after a header that says
    "no connections, no chunks, index at the end" are scanned and flagged."""
    raw = bytearray(two_topic_bag(tmp_path / "b.bag").read_bytes())
    _pos, _op, fields, _dpos, _dlen = records(bytes(raw))[0]
    struct.pack_into("<Q", raw, fields["index_pos"][0], len(raw))
    struct.pack_into("<I", raw, fields["conn_count"][0], 0)
    struct.pack_into("<I", raw, fields["chunk_count"][0], 0)
    path = tmp_path / "liar.bag"
    path.write_bytes(bytes(raw))
    s = bag_summary(path)
    assert (s.message_count, s.indexed) == (N + N // 3, False)
    assert s.problems


def test_a_scan_is_made_once_per_file_version(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An unindexed bag (a recording's ``.active`` file) is scanned record by record; one
    command opens it several times (summary, states, poses): the scan is kept by the file's
    identity, made again when the file changes and after ``ertools.caches.clear()``."""

    raw = bytearray(two_topic_bag(tmp_path / "b.bag").read_bytes())
    _pos, _op, fields, _dpos, _dlen = records(bytes(raw))[0]
    struct.pack_into("<Q", raw, fields["index_pos"][0], 0)  # "recording not closed"
    path = tmp_path / "b.bag.active"
    path.write_bytes(bytes(raw))
    scans: list[Path] = []
    real = layout.scan_layout

    def counted(f: Any, p: Path, size: int, pos: int, why: str) -> layout.Ros1Layout:
        scans.append(p)
        return real(f, p, size, pos, why)

    monkeypatch.setattr(layout, "scan_layout", counted)
    caches.clear()
    first = layout.read_layout(path)
    assert not first.indexed and sum(c.counts.get(0, 0) for c in first.chunks) == N
    assert layout.read_layout(path) is first
    assert bag_summary(path).message_count == N + N // 3
    assert len(scans) == 1
    # the recorder wrote on: another version of the file
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    second = layout.read_layout(path)
    assert second is not first and len(scans) == 2
    # only the latest version of a path is kept
    st = path.stat()
    latest = (str(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
    assert [k for k in layout._SCANNED if k[0] == str(path)] == [latest]
    caches.clear()
    layout.read_layout(path)
    assert len(scans) == 3
    # an indexed bag is read from its index, never scanned
    sound = two_topic_bag(tmp_path / "sound.bag")
    assert layout.read_layout(sound).indexed and len(scans) == 3


def test_an_index_is_read_once_per_file_version_and_handed_out_as_copies(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A command reads a bag's index for its summary and again to read its poses: the index
    is parsed once per file version (again once the file changes, and after
    ``ertools.caches.clear()``), and every caller gets chunks of its own, none of them read
    yet, whatever an earlier reader filled in."""

    path = two_topic_bag(tmp_path / "b.bag")
    # the chunk records by the independent walker: op 5 is a chunk
    chunk_pos = [pos for pos, op, *_ in records(path.read_bytes()) if op == 5]
    parsed: list[Path] = []
    real = layout._read_layout

    def counted(f: Any, p: Path, size: int) -> layout.Ros1Layout:
        parsed.append(p)
        return real(f, p, size)

    monkeypatch.setattr(layout, "_read_layout", counted)
    caches.clear()
    first = layout.read_layout(path)
    assert [c.pos for c in first.chunks] == chunk_pos and len(chunk_pos) > 1
    assert bag_summary(path).message_count == N + N // 3
    poses = read_poses(path, "/pose")
    assert len(parsed) == 1 and len(poses) == N
    second = layout.read_layout(path)
    assert len(parsed) == 1 and second is not first
    assert [c.pos for c in second.chunks] == chunk_pos
    assert all(a is not b for a, b in zip(first.chunks, second.chunks, strict=True))
    # the summary and the read filled in the chunks they read, not the copies handed out
    assert all(c.data_pos == -1 and c.compression == "" for c in second.chunks)
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    layout.read_layout(path)
    assert len(parsed) == 2
    caches.clear()
    layout.read_layout(path)
    assert len(parsed) == 3


def test_a_window_keeps_a_slice_where_it_keeps_one_stretch() -> None:
    """What a window keeps of a connection's entries indexes them as its mask does: None
    for all, a slice for one stretch (views, no copies), the mask otherwise."""
    rng = np.random.default_rng(39)
    values = np.arange(50) * 7
    masks = [np.ones(50, bool), np.zeros(50, bool), np.arange(50) >= 20, np.arange(50) < 3]
    masks += [(np.arange(50) >= a) & (np.arange(50) < b) for a, b in ((5, 6), (10, 40))]
    masks += [rng.random(50) < p for p in (0.1, 0.5, 0.9)]
    for mask in masks:
        got = kept(mask)
        assert np.array_equal(values if got is None else values[got], values[mask])
        stretch = np.flatnonzero(mask)
        one = not len(stretch) or bool(stretch[-1] - stretch[0] == len(stretch) - 1)
        assert isinstance(got, slice) is (one and not bool(mask.all()))
    assert kept(None) is None
