"""Reads report their bytes: one call per group of chunks, adding up to the bytes of the
chunks read, as counted here by walking the files independently (ROS1 records by hand, MCAP
through the ``mcap`` library's summary)."""

from __future__ import annotations

import fcntl
import io
import os
import pty
import re
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest
from mcap.reader import make_reader

import ertools.progress
from ertools.cli.main import main
from ertools.io import bulk, pipeline
from ertools.io.files import open_bag
from ertools.io.info import describe
from ertools.io.ros1.check import check_ros1
from ertools.progress import Bar, reporting
from tests.helpers.bagmaker import bag_name, write
from tests.helpers.fastpath import fast_batch
from tests.helpers.scene import Scene
from tests.helpers.stderr_text import error_messages

TOPIC = "/fbm3w/robot_at_work/pose"


class Recorder:
    """A reporter that keeps every call: ``tasks`` of [label, total, unit, advances]."""

    def __init__(self) -> None:
        self.tasks: list[tuple[str, int, str, list[int]]] = []

    def task(self, label: str, total: int, unit: str) -> None:
        self.tasks.append((label, total, unit, []))

    def advance(self, n: int) -> None:
        self.tasks[-1][3].append(n)


@pytest.fixture(autouse=True)
def wide(monkeypatch: pytest.MonkeyPatch) -> None:
    # lines are cut to the terminal's width (tests/progress/test_progress.py): these check labels
    monkeypatch.setenv("COLUMNS", "200")


@pytest.fixture
def small_groups(monkeypatch: pytest.MonkeyPatch) -> None:
    # ~3 chunks of 2000 bytes per group: every read spans many groups (as in test_io_pipeline)
    monkeypatch.setattr(pipeline, "GROUP_BYTES", 6000)
    monkeypatch.setattr(pipeline, "workers", lambda: 2)


def _ros1_records(path: Path) -> list[tuple[int, dict[bytes, bytes], int]]:
    """(position, header fields, data length) of every top-level record, walked by hand."""
    data = path.read_bytes()
    pos, out = 13, []
    while pos + 4 <= len(data):
        (hlen,) = struct.unpack_from("<I", data, pos)
        header = data[pos + 4 : pos + 4 + hlen]
        (dlen,) = struct.unpack_from("<I", data, pos + 4 + hlen)
        fields, at = {}, 0
        while at < len(header):
            (n,) = struct.unpack_from("<I", header, at)
            name, _, value = header[at + 4 : at + 4 + n].partition(b"=")
            fields[name] = value
            at += 4 + n
        out.append((pos, fields, dlen))
        pos += 8 + hlen + dlen
    return out


def _ros1_chunk_bytes(path: Path, topic: str | None) -> list[int]:
    """Data lengths (bytes on disk) of the chunks holding ``topic`` (any topic: None)."""
    records = _ros1_records(path)
    conns = {
        struct.unpack("<I", f[b"conn"])[0]
        for _p, f, _n in records
        if f[b"op"] == b"\x07" and (topic is None or f[b"topic"] == topic.encode())
    }
    chunks: list[tuple[int, set[int]]] = []
    for _pos, fields, dlen in records:
        if fields[b"op"] == b"\x05":
            chunks.append((dlen, set()))
        elif fields[b"op"] == b"\x04":  # index data records follow their chunk
            chunks[-1][1].add(struct.unpack("<I", fields[b"conn"])[0])
    return [dlen for dlen, cids in chunks if cids & conns]


def _mcap_chunk_bytes(path: Path, topic: str | None) -> list[int]:
    out = []
    for file in [path] if path.is_file() else sorted(path.glob("*.mcap")):
        with file.open("rb") as f:
            summary = make_reader(f).get_summary()
        assert summary is not None
        ids = {c.id for c in summary.channels.values() if topic is None or c.topic == topic}
        out += [
            c.compressed_size for c in summary.chunk_indexes if ids & set(c.message_index_offsets)
        ]
    return out


def _expected(fmt: str, path: Path, topic: str | None) -> list[int]:
    return (
        _ros1_chunk_bytes(path, topic) if fmt.startswith("ros1") else _mcap_chunk_bytes(path, topic)
    )


def _check_counts(
    task: tuple[str, int, str, list[int]], expected_total: int, several: bool = True
) -> None:
    _label, total, unit, steps = task
    assert unit == "B"
    assert total == expected_total
    assert len(steps) >= (2 if several else 1)  # several groups: the count moves meanwhile
    assert all(n > 0 for n in steps)  # so the running count only increases
    assert sum(steps) == total


def _chunked(scene_bag: tuple[str, Path]) -> tuple[str, Path]:
    fmt, path = scene_bag
    if fmt == "rosbag2-sqlite3":
        pytest.skip("n/a: sqlite rows are not read in chunks (no byte progress)")
    return fmt, path


def test_topic_read_reports_the_bytes_of_its_chunks(
    scene_bag: tuple[str, Path], small_groups: None
) -> None:
    fmt, path = _chunked(scene_bag)
    rec = Recorder()
    with reporting(rec):
        batch = fast_batch(path, TOPIC)
    assert len(batch) == 50
    (task,) = rec.tasks
    assert task[0] == f"reading {TOPIC} from {path.name}"
    expected = _expected(fmt, path, TOPIC)
    # rosbags' rosbag2 writer makes one chunk whatever the size asked for
    several = fmt != "rosbag2-mcap"
    assert len(expected) >= (6 if several else 1)
    _check_counts(task, sum(expected), several)


def test_no_reporter_no_report(scene_bag: tuple[str, Path], small_groups: None) -> None:
    # without a reporter in scope nothing is called (and nothing fails)
    _fmt, path = _chunked(scene_bag)
    assert len(fast_batch(path, TOPIC)) == 50


def test_load_all_chunks_reports_every_chunk(
    scene_bag: tuple[str, Path], small_groups: None
) -> None:
    fmt, path = _chunked(scene_bag)
    if fmt == "rosbag2-mcap":
        pytest.skip("n/a: the chunk floor is measured on single files")
    rec = Recorder()
    with open_bag(path) as bag:
        bulk.load_all_chunks(bag, progress=rec)
    (task,) = rec.tasks
    _check_counts(task, sum(_expected(fmt, path, None)))


def test_check_reports_the_whole_file_then_its_chunks(
    scene_bag: tuple[str, Path], tmp_path: Path
) -> None:
    fmt, path = _chunked(scene_bag)
    rec = Recorder()
    if fmt.startswith("ros1"):
        assert check_ros1(path, rec) == []
        reading, checking = rec.tasks
        # every record after the bag header: the whole file
        _check_counts(reading, path.stat().st_size)
        _check_counts(checking, sum(_expected(fmt, path, None)))
    else:
        info = describe(path, check=True, progress=rec)
        assert info.checked and not info.check_problems
        files = [path] if path.is_file() else sorted(path.glob("*.mcap"))
        assert len(rec.tasks) == len(files)
        for task, file in zip(rec.tasks, files, strict=True):
            _check_counts(task, sum(_mcap_chunk_bytes(file, None)), fmt != "rosbag2-mcap")


def test_ros1_active_check_reports_its_chunks(scene: Scene, tmp_path: Path) -> None:
    # a bag still being recorded (no index): checked chunk by chunk from a scan
    path = write(bag_name(tmp_path, "ros1"), "ros1", scene.spec, chunk_bytes=2000)
    active = path.with_suffix(".bag.active")
    records = _ros1_records(path)
    index_pos = next(p for p, f, _n in records if f[b"op"] in (b"\x07", b"\x06"))
    data = path.read_bytes()[:index_pos]  # the chunks, none of the index after them
    active.write_bytes(data)
    rec = Recorder()
    info = describe(active, check=True, progress=rec)
    assert info.checked
    (task,) = rec.tasks
    _check_counts(task, sum(_ros1_chunk_bytes(path, None)))


# The command line: a bar on a terminal's stderr only, none with --quiet, and nothing left.


@pytest.fixture
def ros1_bag(scene: Scene, tmp_path: Path) -> Path:
    return write(bag_name(tmp_path, "ros1-lz4"), "ros1-lz4", scene.spec, chunk_bytes=2000)


class Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def no_delay(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(ertools.progress, "DELAY_S", 0.0)


@pytest.mark.slow
def test_cli_no_bar_when_stderr_is_not_a_terminal(
    ros1_bag: Path, no_delay: None, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["info", "--check", str(ros1_bag)]) == 0
    err = capsys.readouterr().err
    assert "\r" not in err and "\x1b" not in err and "[#" not in err


@pytest.mark.slow_cases("False")
@pytest.mark.parametrize("quiet", [False, True])
def test_cli_bar_on_a_terminal_unless_quiet(
    ros1_bag: Path,
    no_delay: None,
    quiet: bool,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    assert main(["info", "--check", *(["-q"] if quiet else []), str(ros1_bag)]) == 0
    out = capsys.readouterr().out
    assert "every chunk decompressed" in out  # the result itself, on stdout
    err = tty.getvalue()
    if quiet:
        assert err == ""
        return
    size = ros1_bag.stat().st_size
    full = "[" + "#" * 24 + "]"
    assert f"\rertools: reading {ros1_bag.name} {full} {size / 1000:.1f} kB/" in err
    assert f"\rertools: checking chunks of {ros1_bag.name} {full}" in err
    # the bar is wiped before the notes: after the last wipe, notes only, each on its line
    tail = err[err.rindex("\r\x1b[K") + 4 :]
    assert "reading" not in tail and "#" not in tail
    assert all(line.startswith("ertools: ") for line in tail.split("\r\n") if line), (
        tail
    )  # wiped at the end: no bar left behind


def _on_a_pty(argv: list[str], columns: int | None) -> tuple[int, bytes, str]:
    """(exit status, stdout, what the terminal got on stderr) of ``ertools ARGV`` run with
    stderr on a new pseudo-terminal (``columns`` wide, or of no size: the fallback 200)."""

    code = (
        "import sys, ertools.progress as p; p.DELAY_S = 0.0\n"
        "from ertools.cli.main import main\n"
        "sys.exit(main(sys.argv[1:]))\n"
    )
    master, slave = pty.openpty()
    if columns is not None:
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    try:
        proc = subprocess.run(
            [sys.executable, "-c", code, *argv],
            stderr=slave,
            stdout=subprocess.PIPE,
            env={**os.environ, "COLUMNS": "200"},  # used only when the terminal has no size
            timeout=120,
            check=False,
        )
    finally:
        os.close(slave)
    chunks = []  # a few kB: the terminal's buffer holds them until the process is done
    while True:
        try:
            got = os.read(master, 65536)
        except OSError:  # EIO: the terminal's other side is closed and drained
            break
        if not got:
            break
        chunks.append(got)
    os.close(master)
    return proc.returncode, proc.stdout, b"".join(chunks).decode()


TRAJECTORY = ["score", "trajectory", "--robot-topic", "/odom", "--gt-topic", TOPIC]


@pytest.mark.slow
def test_cli_bar_through_a_real_pty(ros1_bag: Path) -> None:
    """The real thing: ``isatty`` answered by the system, output read off the terminal."""
    code, out, err = _on_a_pty([*TRAJECTORY, str(ros1_bag)], None)
    assert code == 0, err
    assert b"ate" in out  # the score itself, on stdout
    for topic in ("/odom", TOPIC):  # the robot's log, then the GT from it
        assert f"\rertools: reading {topic} from {ros1_bag.name} [" in err
    # the bar is wiped before the notes: after the last wipe, notes only, each on its line
    tail = err[err.rindex("\r\x1b[K") + 4 :]
    assert "reading" not in tail and "#" not in tail
    assert all(line.startswith("ertools: ") for line in tail.split("\r\n") if line), tail


@pytest.mark.slow
def test_bar_appears_for_a_slow_read_only(scene: Scene, tmp_path: Path, small_groups: None) -> None:
    """Real clock, real delay: a read slowed to ~1 s shows the bar, a quick one shows none."""

    path = write(bag_name(tmp_path, "ros1"), "ros1", scene.spec, chunk_bytes=2000)

    class Slow(Bar):
        def advance(self, n: int) -> None:
            time.sleep(0.05)  # a slow disk: each group of chunks takes 50 ms
            super().advance(n)

    slow_tty, quick_tty = Tty(), Tty()
    with reporting(Slow(slow_tty, delay_s=0.3)) as bar:
        fast_batch(path, TOPIC)
    assert bar is not None and len(bar_steps := _steps(slow_tty.getvalue())) >= 2
    assert bar_steps[-1].startswith(f"ertools: reading {TOPIC} from {path.name} [{'#' * 24}]")
    with reporting(Bar(quick_tty, delay_s=0.3)):
        fast_batch(path, TOPIC)  # a few ms
    assert quick_tty.getvalue() == ""


def _steps(text: str) -> list[str]:
    return [s.removesuffix("\x1b[K") for s in text.split("\r") if s]


def test_cli_notes_and_errors_start_on_a_wiped_line(
    ros1_bag: Path,
    no_delay: None,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # the scene's one run is cut off by the log's end before its path: read as the benchmark
    # stopped there (issue 23), so no run to score: reads, a run found, warnings and deviation
    # lines, all on a terminal that shows the bar, and the score with no best run on stdout
    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    assert main(["score", "fbm3w", str(ros1_bag)]) == 0
    out = capsys.readouterr().out
    assert "best_run: null" in out and "status: interrupted" in out
    err = tty.getvalue()
    assert "\rertools: scoring runs [" + "#" * 24 + "] 1/1 runs" in err
    lines = err.split("\n")
    assert lines[-1] == ""  # ends with a whole line
    for line in lines[:-1]:  # what a terminal shows of each line: the text after its last \r
        shown = line.split("\r")[-1].removeprefix("\x1b[K")
        assert shown.startswith("ertools: ") and "[##" not in shown and "[--" not in shown, line
    assert any("ertools: warning: the log ends at t=0.400 s inside run 0" in ln for ln in lines)
    assert "ertools: differs from 2015:" in lines[-2]


def test_cli_error_after_a_read_starts_on_a_wiped_line(
    ros1_bag: Path, no_delay: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the robot topic is read (bar drawn), then the GT topic is missing: an ErtoolsError
    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    argv = ["score", "trajectory", str(ros1_bag), "--robot-topic", "/odom", "--gt-topic", "/no"]
    assert main(argv) == 1
    err = tty.getvalue()
    bar, error = err.rsplit("\r", 1)
    assert f"\rertools: reading /odom from {ros1_bag.name} [{'#' * 24}]" in bar
    assert error.startswith("\x1b[Kertools: error: GT topic /no is not in the robot log")
    assert len(error_messages(error.removeprefix("\x1b[K"))) == 1 and error.endswith("\n")


@pytest.mark.parametrize("where", ["group", "member"])
def test_cli_quiet_reaches_a_group_member(
    ros1_bag: Path, no_delay: None, where: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # `ertools score -q fbm3w BAG` and `ertools score fbm3w BAG -q` both silence the bar
    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    argv = ["score", "-q", "fbm3w", str(ros1_bag)] if where == "group" else [
        "score", "fbm3w", str(ros1_bag), "-q"
    ]  # fmt: skip
    assert main(argv) == 0  # the scene's run is cut off before its path (see above)
    err = tty.getvalue()
    assert "ertools: warning: the log ends at t=0.400 s inside run 0" in err
    assert "\r" not in err and "\x1b" not in err


def test_cli_info_counts_bags_not_the_reads_inside(
    no_delay: None, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # the timeline sample: 9 files; whatever describe reads inside, the bar counts bags
    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    folder = Path(__file__).resolve().parents[2] / "sample_bags/timeline/bags"
    main(["info", str(folder)])
    capsys.readouterr()
    shown = _steps(tty.getvalue())
    labels = {s.split(" [")[0] for s in shown if " [" in s}
    assert labels == {"ertools: reading indexes"}
    assert f"ertools: reading indexes [{'#' * 24}] 9/9 bags" in shown


@pytest.mark.slow
def test_cli_bar_fits_a_narrow_terminal(ros1_bag: Path) -> None:
    # 60 columns, asked of the terminal itself: every redraw fits in 59 (no wrapped rows);
    # the rate goes first, then the middle of the label, the bar and amounts stay whole
    code, _out, err = _on_a_pty([*TRAJECTORY, str(ros1_bag)], 60)
    assert code == 0, err
    # the bar's redraws, not the score's interval lines ("[0.41, 0.88] mm") printed after them
    bar = re.compile(r" \[[#\-]+\] ")
    drawn = [s.removesuffix("\x1b[K") for s in err.split("\r") if bar.search(s)]
    assert len(drawn) >= 4  # two reads, each at its start and end
    assert all(len(d) <= 59 for d in drawn), drawn
    assert all(d.startswith("ertools: reading") and d.endswith(" kB") for d in drawn), drawn
    # the GT topic's read done, its bytes counted here: with the 10-cell bar, 59 - 9
    # ("ertools: ") - 2 (" [") - 27 ("##########] 17.4 kB/17.4 kB") - 3 ("...") = 18
    # characters of the label, its first and last 9
    size = f"{sum(_ros1_chunk_bytes(ros1_bag, TOPIC)) / 1000:.1f} kB"
    tail = f"] {size}/{size}"
    label = f"reading {TOPIC} from {ros1_bag.name}"
    keep = 59 - 9 - 2 - (10 + len(tail)) - 3
    done = f"ertools: {label[: keep // 2]}...{label[-(keep - keep // 2) :]} [{'#' * 10}{tail}"
    assert done in drawn, drawn
