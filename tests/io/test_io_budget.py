"""The budget of one input (ertools/io/budget.py, docs/io.md): a file just under each limit
reads; just over it gets one BagError naming the file, the record or byte offset, and the
limit; decompression bombs stop at the size their chunk declares, with memory measured.

The files are built byte by byte (tests/io/hostile_files.py) from the format specifications,
so what is expected (sizes, payloads, offsets) is known from how they were written. Limits are
lowered with monkeypatch where the real one would cost a test hundreds of megabytes; the real
limits are met by bombs that cost a few kilobytes to build.
"""

from __future__ import annotations

import bz2
import shutil
import sqlite3
import subprocess
import sys
import tracemalloc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import lz4.frame
import pytest
import yaml
import zstandard
from mcap.reader import make_reader
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode

from ertools.cli.main import main
from ertools.errors import BagError
from ertools.io import budget
from ertools.io.files import open_bag
from ertools.io.info import describe
from ertools.io.messages import read_messages
from ertools.io.reader import read_poses, read_states
from ertools.io.summary import summary as bag_summary
from tests.helpers.bagmaker import build, typestore, write
from tests.helpers.scene import Scene
from tests.io.hostile_files import (
    McapChannel,
    McapChunk,
    Ros1Chunk,
    Ros1Conn,
    bz2_bomb,
    bz2_zeros,
    mcap_file,
    mcap_message,
    message_record,
    ros1_bag,
    string_payload,
    u32,
    zstd_frame,
)

T0 = 1_448_020_800 * 10**9  # the 2015 sample logs' start
MiB = 1 << 20


@contextmanager
def peak_memory() -> Iterator[list[int]]:
    """The peak of memory Python allocated inside the block (bytes objects, bytearrays and
    NumPy arrays included), in one list item once the block is done."""
    tracemalloc.start()
    out: list[int] = []
    try:
        yield out
    finally:
        out.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()


def _refusal(read: Callable[[], Any], *words: str) -> str:
    """What ``read`` refused with: its BagError, or the problem `info` (``describe``) found
    (it describes the other bags and says each one's problem), holding ``words``."""
    try:
        got = read()
    except BagError as err:
        text = str(err)
    else:
        said = [getattr(got, "fatal_problem", None), *getattr(got, "check_problems", ())]
        assert any(said), f"read without a refusal: {got}"
        text = "; ".join(p for p in said if p)
    assert "\n" not in text
    for word in words:
        assert word in text, text
    return text


def _cdr_string(text: str) -> bytes:
    raw = text.encode() + b"\0"
    return b"\x00\x01\x00\x00" + u32(len(raw)) + raw


# --- ROS1 bombs: a bz2 chunk declaring its true size, followed by a gigabyte of zeros -------


def _ros1_bomb(path: Path, extra: int, compression: str = "bz2") -> Path:
    conn = Ros1Conn(0, "/fbm3w/notes")
    if compression == "bz2":
        compress = bz2_bomb(extra)
    else:  # one lz4 frame whose stated and real content is the records, then zeros

        def compress(inner: bytes) -> bytes:
            return lz4.frame.compress(inner + bytes(extra))

    chunk = Ros1Chunk([(0, T0, string_payload("hello"))], compression, compress)
    return ros1_bag(path, [conn], [chunk])


@pytest.mark.slow
@pytest.mark.parametrize("compression", ["bz2", "lz4"])
def test_a_ros1_chunk_that_inflates_past_its_declared_size_is_refused_there(
    tmp_path: Path, compression: str
) -> None:
    """Finding 12: ``layout.decompress`` ignored the chunk's ``size`` (a 790 KiB bz2 bag took
    plain `info` to 8.4 GB). A gigabyte of zeros past the declared size (64 MiB for lz4, its
    ratio is 255 at most) is never produced: the peak stays within a few MiB."""
    extra = (1 << 30) if compression == "bz2" else 64 * MiB
    bag = _ros1_bomb(tmp_path / "bomb.bag", extra, compression)
    assert bag.stat().st_size < 400_000
    # the true records: connection record and one message record (the declared size)
    declared = len(Ros1Conn(0, "/fbm3w/notes").record()) + len(
        message_record(0, T0, string_payload("hello"))
    )
    for read in (
        lambda: describe(bag),
        lambda: describe(bag, check=True),
        lambda: read_messages(bag, "/fbm3w/notes"),
    ):
        with peak_memory() as peak:
            text = _refusal(read, f"more than the {declared} bytes its header declares")
        assert "at byte 4109" in text  # the chunk record follows the 4096-byte bag header
        # 16 MiB: the bag's own bytes, one decompression step (4 MiB) and NumPy's arrays
        assert peak[0] < 16 * MiB, f"peak {peak[0] / MiB:.0f} MiB"


@pytest.mark.slow
def test_info_on_a_bz2_bomb_is_one_line_and_small_in_a_fresh_process(tmp_path: Path) -> None:
    """The whole command in its own process: its peak resident memory stays near the
    interpreter's (about 40 MB here), not the gigabyte the bomb holds. VmHWM, not ru_maxrss:
    Linux carries the forking parent's peak into the child's ru_maxrss across exec."""
    if not Path("/proc/self/status").exists():
        pytest.skip("n/a: the peak is read from /proc/self/status (Linux)")
    bag = _ros1_bomb(tmp_path / "bomb.bag", 1 << 30)
    code = (
        "import sys\n"
        "from ertools.cli.main import main\n"
        "status = main(['info', sys.argv[1]])\n"
        "hwm = [ln for ln in open('/proc/self/status') if ln.startswith('VmHWM:')][0]\n"
        "print(f'peak_kib={hwm.split()[1]}', file=sys.stderr)\n"
        "sys.exit(status)\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", code, str(bag)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 1, run.stderr
    lines = run.stderr.splitlines()
    errors = [ln for ln in lines if ln.startswith("ertools: error:")]
    # one error, its detail (if the line is long) on indented lines below
    message = " ".join(ln.strip() for ln in lines if not ln.startswith("peak_kib="))
    assert len(errors) == 1 and "bomb.bag" in errors[0] and "its header declares" in message
    peak_kib = int(next(ln for ln in lines if ln.startswith("peak_kib=")).split("=")[1])
    assert peak_kib < 200 * 1024, f"peak RSS {peak_kib / 1024:.0f} MiB"


def test_a_ros1_chunk_declaring_more_than_the_chunk_budget_is_refused_unread(
    tmp_path: Path,
) -> None:
    """An honest bz2 chunk of 264 MiB (33 streams of 8 MiB of zeros): over
    MAX_CHUNK_BYTES (256 MiB), refused from its header, nothing decompressed."""
    step = 8 * MiB
    extra = 33 * step

    def compress(inner: bytes) -> bytes:
        return bz2.compress(inner) + bz2_zeros(step) * 33

    conn = Ros1Conn(0, "/fbm3w/notes")
    msg = (0, T0, string_payload("hello"))
    declared = len(conn.record()) + len(message_record(*msg)) + extra
    bag = ros1_bag(tmp_path / "big.bag", [conn], [Ros1Chunk([msg], "bz2", compress, declared)])
    with peak_memory() as peak:
        _refusal(
            lambda: read_messages(bag, "/fbm3w/notes"),
            f"{declared} bytes uncompressed",
            "over the budget of 256 MiB",
            "MAX_CHUNK_BYTES",
            "at byte 4109",
        )
    assert peak[0] < 16 * MiB


# --- just under and just over each limit --------------------------------------------------------


def _ros1_sized(path: Path, size: int, compression: str) -> tuple[Path, str]:
    """A ROS1 bag of one chunk of exactly ``size`` bytes uncompressed; its one message's
    text."""
    conn = Ros1Conn(0, "/fbm3w/notes")
    overhead = len(conn.record()) + len(message_record(0, T0, string_payload("")))
    text = "x" * (size - overhead)
    compress = {"bz2": bz2.compress, "lz4": lz4.frame.compress, "none": None}[compression]
    chunk = Ros1Chunk([(0, T0, string_payload(text))], compression, compress)
    return ros1_bag(path, [conn], [chunk]), text


def _mcap_sized(path: Path, size: int, compression: str) -> tuple[Path, str]:
    overhead = len(mcap_message(1, T0, _cdr_string("")))
    text = "x" * (size - overhead)
    chunk = McapChunk([(1, T0, _cdr_string(text))], compression)
    return mcap_file(path, [McapChannel(1, "/fbm3w/notes")], [chunk]), text


@pytest.mark.parametrize(
    ("fmt", "compression"),
    [("ros1", "bz2"), ("ros1", "lz4"), ("ros1", "none"), ("mcap", "zstd"), ("mcap", "lz4")],
)
def test_the_chunk_budget_just_under_and_just_over(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fmt: str, compression: str
) -> None:
    monkeypatch.setattr(budget, "MAX_CHUNK_BYTES", 64 * 1024)
    make = _ros1_sized if fmt == "ros1" else _mcap_sized
    under, text = make(tmp_path / f"under.{fmt}", 64 * 1024, compression)
    (msg,) = read_messages(under, "/fbm3w/notes")
    assert msg.msg.data == text and msg.t_ns == T0
    assert describe(under, check=True).check_problems == ()
    over, _text = make(tmp_path / f"over.{fmt}", 64 * 1024 + 1, compression)
    kind = "stored" if compression == "none" else "uncompressed"
    for read in (lambda: read_messages(over, "/fbm3w/notes"), lambda: describe(over)):
        _refusal(
            read,
            over.name,
            "at byte",
            f"{64 * 1024 + 1} bytes {kind}",
            "over the budget of 65536 bytes (MAX_CHUNK_BYTES",
        )


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_the_per_file_inflation_budget_just_under_and_just_over(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fmt: str
) -> None:
    """All chunks of a file may declare MAX_INFLATE_PER_BYTE x its size + MAX_CHUNK_BYTES:
    here 10 x the file + 64 KiB. Chunks of 16 KiB of one letter compress a hundredfold: three
    of them fit in the allowance of their (1 to 5 KB) file, thirty do not."""
    monkeypatch.setattr(budget, "MAX_CHUNK_BYTES", 64 * 1024)
    monkeypatch.setattr(budget, "MAX_INFLATE_PER_BYTE", 10)
    text = "y" * (16 * 1024)

    def make(path: Path, n: int) -> Path:
        if fmt == "ros1":
            conn = Ros1Conn(0, "/fbm3w/notes")
            chunks = [
                Ros1Chunk([(0, T0 + i, string_payload(text))], "bz2", bz2.compress)
                for i in range(n)
            ]
            return ros1_bag(path, [conn], chunks)
        chunks_m = [McapChunk([(1, T0 + i, _cdr_string(text))], "zstd") for i in range(n)]
        return mcap_file(path, [McapChannel(1, "/fbm3w/notes")], chunks_m)

    under = make(tmp_path / f"under.{fmt}", 3)
    assert budget.allowance(under.stat().st_size) > 3 * 16 * 1024
    assert len(read_messages(under, "/fbm3w/notes")) == 3
    over = make(tmp_path / f"over.{fmt}", 30)
    assert budget.allowance(over.stat().st_size) < 30 * 16 * 1024
    for read in (lambda: read_messages(over, "/fbm3w/notes"), lambda: describe(over)):
        _refusal(read, over.name, "MAX_INFLATE_PER_BYTE", "over the budget of")


def test_the_record_header_budget_just_under_and_just_over(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A connection record's header holds its topic: 4 KiB allowed here."""
    monkeypatch.setattr(budget, "MAX_RECORD_HEADER_BYTES", 4096)

    def make(path: Path, header_len: int) -> Path:
        # the header: op (4+4), conn (4+9), topic (4+6+len(name))
        name = "/" + "n" * (header_len - 8 - 13 - 10 - 1)
        conn = Ros1Conn(0, name)
        return ros1_bag(path, [conn], [Ros1Chunk([(0, T0, string_payload("hi"))])])

    under = make(tmp_path / "under.bag", 4096)
    (topic,) = bag_summary(under).topics
    assert len(topic.name) == 4096 - 31
    over = make(tmp_path / "over.bag", 4097)
    _refusal(
        lambda: bag_summary(over),
        "over.bag",
        "record at byte",
        "a header of 4097 bytes",
        "MAX_RECORD_HEADER_BYTES",
    )


# --- MCAP: a valid 16 MB chunk reads, a 2 GiB one is refused without inflating it ------------


@pytest.mark.slow
def test_a_valid_mcap_with_a_16_mb_chunk_reads(tmp_path: Path, scene: Scene) -> None:
    """Finding 13: one message of 16 MB (a 4000 x 4000 occupancy grid's data, zeros: zstd
    stores it in a few hundred bytes, 30,000 times smaller) was "damaged chunk record".
    Written by the mcap library; the library reads it with its CRCs checked."""
    path = tmp_path / "map.mcap"
    with path.open("wb") as f:
        w = McapWriter(f, compression=CompressionType.ZSTD)
        w.start(profile="ros2", library="ertools-tests")
        sid = w.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
        big = w.register_channel("/fbm3w/map", "cdr", sid)
        small = w.register_channel("/fbm3w/notes", "cdr", sid)
        w.add_message(small, log_time=T0, data=_cdr_string("before"), publish_time=T0)
        w.add_message(big, log_time=T0 + 1, data=bytes(16_000_000), publish_time=T0 + 1)
        w.add_message(small, log_time=T0 + 2, data=_cdr_string("after"), publish_time=T0 + 2)
        w.finish()
    assert path.stat().st_size < 100_000
    with path.open("rb") as f:
        theirs = [
            (c.topic, m.log_time, len(m.data))
            for _s, c, m in make_reader(f, validate_crcs=True).iter_messages()
        ]
    assert theirs == [
        ("/fbm3w/notes", T0, 15),
        ("/fbm3w/map", T0 + 1, 16_000_000),
        ("/fbm3w/notes", T0 + 2, 14),
    ]
    for check in (False, True):
        info = describe(path, check=check)
        assert info.fatal_problem is None and info.check_problems == ()
        assert {t.name: t.count for t in info.summary.topics} == {
            "/fbm3w/map": 1,
            "/fbm3w/notes": 2,
        }
    notes = read_messages(path, "/fbm3w/notes")
    assert [m.msg.data for m in notes] == ["before", "after"]
    with open_bag(path) as bag:
        grid = [(t, data) for _c, t, data in bag.raw(bag.topic_conns("/fbm3w/map"))]
    assert grid == [(T0 + 1, bytes(16_000_000))]


def _mcap_bomb(path: Path, zeros: int, declared: int | None = None) -> Path:
    chunk = McapChunk(
        [(1, T0, _cdr_string("hello"))], "zstd", size=declared, zeros=(2, T0 + 1, zeros)
    )
    channels = [McapChannel(1, "/fbm3w/notes"), McapChannel(2, "/fbm3w/map")]
    return mcap_file(path, channels, [chunk])


def test_a_2_gib_mcap_chunk_is_refused_without_inflating_it(tmp_path: Path) -> None:
    """Finding 12: a valid 66 KB MCAP whose one zstd chunk holds 2 GiB (its frame and its
    chunk record both say so) took `score` to 2.2 GB; the old guard allowed 1000 x the
    compressed size. Now over the budget, with the file and the limit named; nothing is
    inflated."""
    bomb = _mcap_bomb(tmp_path / "bomb.mcap", 2 << 30)
    assert bomb.stat().st_size < 100_000
    for read in (
        lambda: describe(bomb),
        lambda: describe(bomb, check=True),
        lambda: read_messages(bomb, "/fbm3w/notes"),
        lambda: bag_summary(bomb, exact=True),
    ):
        with peak_memory() as peak:
            _refusal(read, "bomb.mcap", "over the budget", "MAX_")
        assert peak[0] < 16 * MiB


def test_an_mcap_chunk_whose_frame_says_more_than_its_record_stops_there(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A chunk record declaring 1 KiB whose zstd frame holds (and says it holds) 512 MiB:
    zstandard's ``decompress(max_output_size=)`` and the mcap library trust the frame. The
    per-file allowance is set high, so the chunk is read: it stops at the declared size."""
    monkeypatch.setattr(budget, "MAX_INFLATE_PER_BYTE", 10**6)
    bomb = _mcap_bomb(tmp_path / "liar.mcap", 512 * MiB, declared=1024)
    for read in (
        lambda: describe(bomb, check=True),
        lambda: read_messages(bomb, "/fbm3w/notes"),
    ):
        with peak_memory() as peak:
            _refusal(read, "liar.mcap", "more than the 1024 bytes its header declares")
        assert peak[0] < 16 * MiB


# --- rosbag2: metadata.yaml and storage files compressed whole ---------------------------------


@pytest.mark.slow
def test_metadata_size_and_nesting_just_under_and_just_over(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, scene: Scene
) -> None:
    good = write(tmp_path / "r2", "rosbag2-sqlite3", scene.spec)
    meta = good / "metadata.yaml"
    text = meta.read_text()
    monkeypatch.setattr(budget, "MAX_METADATA_BYTES", len(text) + 100)
    meta.write_text(text + "#" * 99 + "\n")  # exactly the limit
    assert bag_summary(good).message_count == len(scene.spec.msgs)
    meta.write_text(text + "#" * 100 + "\n")
    _refusal(lambda: bag_summary(good), "r2", "metadata.yaml", "MAX_METADATA_BYTES")

    def nested(depth: int) -> str:
        return text + "extra: " + "[" * depth + "]" * depth + "\n"

    monkeypatch.setattr(budget, "MAX_METADATA_BYTES", 1 << 20)
    # the document's own mapping is one level: 63 more fit in 64
    meta.write_text(nested(budget.MAX_NESTING - 1))
    assert bag_summary(good).message_count == len(scene.spec.msgs)
    meta.write_text(nested(budget.MAX_NESTING))
    _refusal(lambda: bag_summary(good), "r2", "metadata.yaml at line", "MAX_NESTING")
    # far deeper than PyYAML's recursion allows: still the one line, no RecursionError
    meta.write_text(nested(5000))
    _refusal(lambda: bag_summary(good), "r2", "nested deeper")


@pytest.mark.slow
def test_a_file_compressed_storage_copy_within_the_budget(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, scene: Scene
) -> None:
    """A storage file compressed whole is copied decompressed: up to MAX_FILE_COPY_BYTES."""
    good = write(tmp_path / "plain", "rosbag2-mcap", scene.spec)
    (storage,) = good.glob("*.mcap")
    raw = storage.read_bytes()
    zipped = tmp_path / "zipped"
    zipped.mkdir()
    (zipped / (storage.name + ".zstd")).write_bytes(zstandard.ZstdCompressor().compress(raw))
    info = yaml.safe_load((good / "metadata.yaml").read_text())
    bag = info["rosbag2_bagfile_information"]
    bag.update(compression_format="zstd", compression_mode="FILE")
    bag["relative_file_paths"] = [storage.name + ".zstd"]
    for entry in bag.get("files", []):
        entry["path"] = storage.name + ".zstd"
    (zipped / "metadata.yaml").write_text(yaml.safe_dump(info))
    monkeypatch.setattr(budget, "MAX_FILE_COPY_BYTES", len(raw))
    assert len(read_poses(zipped, "/fbm3w/robot_at_work/pose")) == len(
        read_poses(good, "/fbm3w/robot_at_work/pose")
    )
    other = tmp_path / "zipped2"
    shutil.copytree(zipped, other)
    monkeypatch.setattr(budget, "MAX_FILE_COPY_BYTES", len(raw) - 1)
    _refusal(
        lambda: read_poses(other, "/fbm3w/robot_at_work/pose"),
        storage.name + ".zstd",
        f"more than {len(raw) - 1} bytes uncompressed",
        "MAX_FILE_COPY_BYTES",
    )


# --- the CLI: one line naming the file --------------------------------------------------------


def test_the_cli_says_a_bomb_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bomb = _mcap_bomb(tmp_path / "bomb.mcap", 2 << 30)
    ros1 = _ros1_bomb(tmp_path / "bomb.bag", 1 << 30)
    for argv in (["info", str(bomb)], ["info", "--check", str(ros1)], ["noise", str(bomb)]):
        assert main(argv) == 1
        err = capsys.readouterr().err
        (line,) = [ln for ln in err.splitlines() if ln.startswith("ertools: error:")]
        assert "bomb." in line and "Traceback" not in err


# --- nesting of stored message definitions --------------------------------------------------

SEP = "=" * 80 + "\n"


def _nested_type_bag(path: Path, levels: int) -> Path:
    """A topic whose type holds a type that holds a type... ``levels`` types in all, the last
    one an int32."""
    parts = [f"pkg/A{i + 1} a\n" for i in range(levels - 1)] + ["int32 x\n"]
    definition = parts[0] + "".join(f"{SEP}MSG: pkg/A{i}\n{parts[i]}" for i in range(1, levels))
    conn = Ros1Conn(0, "/deep", msgtype="pkg/A0", definition=definition, md5="0" * 32)
    return ros1_bag(path, [conn], [Ros1Chunk([(0, T0, u32(5))])])


def test_message_type_nesting_just_under_and_just_over(tmp_path: Path) -> None:
    """rosbags builds its deserializers recursively, a level per nested type: 3,000 levels
    was a RecursionError (a traceback in the API, "unexpected" in the CLI)."""
    under = _nested_type_bag(tmp_path / "under.bag", budget.MAX_NESTING)
    (msg,) = read_messages(under, "/deep")
    inner = msg.msg
    for _ in range(budget.MAX_NESTING - 1):
        inner = inner.a
    assert inner.x == 5
    over = _nested_type_bag(tmp_path / "over.bag", budget.MAX_NESTING + 1)
    _refusal(lambda: read_messages(over, "/deep"), "over.bag", "pkg/msg/A0", "MAX_NESTING")
    far = _nested_type_bag(tmp_path / "far.bag", 3000)
    _refusal(lambda: read_messages(far, "/deep"), "far.bag", "nested deeper")


def test_a_recursive_message_type_is_refused(tmp_path: Path) -> None:
    conn = Ros1Conn(
        0, "/loop", msgtype="pkg/Loop", definition="pkg/Loop[] children\nint32 x\n", md5="0" * 32
    )
    bag = ros1_bag(tmp_path / "loop.bag", [conn], [Ros1Chunk([(0, T0, u32(0) + u32(5))])])
    _refusal(lambda: read_messages(bag, "/loop"), "loop.bag", "its own type pkg/msg/Loop")


# --- rosbag2 compressed message by message ----------------------------------------------------


def test_a_rosbag2_message_whose_frame_says_300_mib_is_refused_unread(
    tmp_path: Path, scene: Scene
) -> None:
    """A bag written by rosbags with ``compression_mode: message``; one state message's blob
    replaced by a zstd frame of 300 MiB of zeros (1.9 KiB, its header saying so): rosbags'
    ``zstd.decompress`` inflated it whole. Over MAX_CHUNK_BYTES now, refused from the frame's
    header; the bag's other reads are unaffected."""

    path = tmp_path / "r2"
    ts = typestore(False)
    writer = Writer2(path, version=9)
    writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    with writer:
        conns: dict[str, Any] = {}
        for seq, (ci, t, v) in enumerate(scene.spec.msgs):
            topic, msgtype, _caller = scene.spec.conns[ci]
            if topic not in conns:
                conns[topic] = writer.add_connection(
                    topic, msgtype.replace("/", "/msg/"), typestore=ts
                )
            conn = conns[topic]
            writer.write(conn, t, ts.serialize_cdr(build(ts, False, msgtype, v, seq), conn.msgtype))
    states = read_states(path, "/fbm3w/bmbox_state")
    assert len(states.t_ns) == sum(
        1 for ci, _t, _v in scene.spec.msgs if scene.spec.conns[ci][0] == "/fbm3w/bmbox_state"
    )
    poses = read_poses(path, "/fbm3w/robot_at_work/pose")
    (db,) = path.glob("*.db3")
    with sqlite3.connect(db) as con:
        (topic_id,) = con.execute(
            "SELECT id FROM topics WHERE name = '/fbm3w/bmbox_state'"
        ).fetchone()
        con.execute(
            "UPDATE messages SET data = ? WHERE id = (SELECT min(id) FROM messages WHERE "
            "topic_id = ?)",
            (zstd_frame(b"", 300 * MiB), topic_id),
        )
    with peak_memory() as peak:
        _refusal(
            lambda: read_states(path, "/fbm3w/bmbox_state"),
            "r2",
            "/fbm3w/bmbox_state",
            f"{300 * MiB} bytes uncompressed",
            "MAX_CHUNK_BYTES",
        )
    # rosbags' reader and its generated deserializers take ~16 MiB of their own here; the
    # message would have been 300
    assert peak[0] < 64 * MiB
    assert len(read_poses(path, "/fbm3w/robot_at_work/pose")) == len(poses)
