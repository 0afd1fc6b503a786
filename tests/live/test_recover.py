"""`ertools record --recover FILE` (issue 25, item 12): a recording killed with kill -9 made
whole. The kill point is chosen, not raced: the writing process kills itself right after a
chosen flush (what a recorder's crash leaves: complete chunks, no summary, no footer), and the
same file is also cut at chosen bytes (a chunk half written when the power went).

Afterwards mcap's default reader (`make_reader(...).iter_messages()`, which Foxglove's reading
resembles) and `ertools info` read every message that was complete, and nothing more."""

from __future__ import annotations

import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader

from ertools.cli.main import main
from ertools.live.recover import RECOVERY_METADATA
from ertools.live.rosmsg import Ros2Serializer
from ertools.live.tail import is_finished

pytestmark = pytest.mark.xdist_group("timing")

TOPICS = ("/fbm2h/robot_at_home/pose2d", "/fbm2h/origin/pose2d")
PER_FLUSH = 50  # messages between two flushes (a flush closes a chunk)
FLUSHES = 4  # flushes before the kill


def message(i: int) -> tuple[str, int, tuple[float, float, float]]:
    """The i-th message the writer sends: its topic, log time and pose (known here)."""
    return TOPICS[i % 2], 1_448_020_800_000_000_000 + i * 5_000_000, (0.01 * i, -0.02 * i, 0.1)


WRITER = textwrap.dedent(
    """
    import os, signal
    from pathlib import Path
    from tests.live.test_recover import FLUSHES, PER_FLUSH, message
    from ertools.live.logfile import LogFile
    from ertools.live.rosmsg import POSE_2D, Ros2Serializer

    serializer = Ros2Serializer()
    log = LogFile(Path({path!r}), serializer, compression="zstd")
    log.add_metadata("clock", {{"ntp_offset_s": "0.0012"}})
    for i in range(PER_FLUSH * FLUSHES + 17):  # 17 more, never flushed: lost in the kill
        topic, t_ns, (x, y, theta) = message(i)
        log.write(log.channel(topic, POSE_2D), t_ns, serializer.pose2d(x, y, theta))
        if (i + 1) % PER_FLUSH == 0:
            log.flush()
    os.kill(os.getpid(), signal.SIGKILL)  # the kill point: after the last flush
    """
)


@pytest.fixture(scope="module")
def killed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("killed")
    path = folder / "log_fbm2h_mocap_2015-11-20-12-00-00_0.mcap"
    script = WRITER.format(path=str(path))
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}  # tests.live
    proc = subprocess.run([sys.executable, "-c", script], env=env, check=False)
    assert proc.returncode == -signal.SIGKILL
    assert not is_finished(path)
    return path


def mcap_default_read(path: Path) -> list[tuple[str, int, bytes]]:
    with open(path, "rb") as f:
        return [
            (channel.topic, msg.log_time, msg.data)
            for _, channel, msg in make_reader(f).iter_messages()
        ]


def expected(n: int) -> list[tuple[str, int, bytes]]:
    serializer = Ros2Serializer()
    out = []
    for i in range(n):
        topic, t_ns, (x, y, theta) = message(i)
        out.append((topic, t_ns, serializer.pose2d(x, y, theta)))
    return out


def info_messages(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, int, str]:
    code = main(["info", str(path), "--format", "json"])
    out, err = capsys.readouterr()
    (bag,) = json.loads(out)["bags"]
    return code, int(bag["messages"]), err


@pytest.mark.slow
def test_a_killed_recording_made_whole(
    killed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / killed.name
    shutil.copyfile(killed, path)
    cut = path.read_bytes()
    # before: mcap's default reader refuses it, ertools info says how to recover it
    with pytest.raises((McapError, Exception)):
        mcap_default_read(path)
    _, _, err = info_messages(path, capsys)
    assert f"`ertools record --recover {path}` makes it whole" in err

    assert main(["record", "--recover", str(path)]) == 0
    err = capsys.readouterr().err
    n = PER_FLUSH * FLUSHES  # every flushed message; the 17 unflushed died with the process
    assert f"{n} messages kept" in err
    assert is_finished(path)
    assert mcap_default_read(path) == expected(n)
    code, count, err = info_messages(path, capsys)
    assert code == 0 and count == n and "not indexed" not in err
    # the cut bytes kept as they were; the recovery says what it did
    assert (tmp_path / (path.name + ".cut")).read_bytes() == cut

    with open(path, "rb") as f:
        metadata = {m.name: m.metadata for m in make_reader(f).iter_metadata()}
    assert metadata["clock"] == {"ntp_offset_s": "0.0012"}
    assert metadata[RECOVERY_METADATA]["messages"] == str(n)
    assert metadata[RECOVERY_METADATA]["original_size_bytes"] == str(len(cut))
    # twice is harmless: the file is whole now
    assert main(["record", "--recover", str(path)]) == 0
    assert "already whole" in capsys.readouterr().err


def chunk_ends(path: Path) -> list[int]:
    """The byte offsets where each chunk record of ``path`` ends (read by hand: op, length)."""

    data = path.read_bytes()
    ends, pos = [], 8  # after the magic
    while pos + 9 <= len(data):
        op, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        if pos + 9 + length > len(data):
            break
        pos += 9 + length
        if op == 0x06:
            ends.append(pos)
    return ends


@pytest.mark.slow_cases("mid-chunk")
@pytest.mark.parametrize("where", ["mid-chunk", "after-chunk", "one-byte-into-next"])
def test_a_cut_inside_a_record_keeps_the_complete_chunks(
    where: str, killed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ends = chunk_ends(killed)
    assert len(ends) >= FLUSHES  # one chunk per flush at least (metadata may add records)
    third = ends[2]  # the chunk of messages 100-149 ends here
    cut_at = {
        "mid-chunk": (ends[1] + ends[2]) // 2,
        "after-chunk": third,
        "one-byte-into-next": third + 1,
    }[where]
    path = tmp_path / killed.name
    path.write_bytes(killed.read_bytes()[:cut_at])
    assert main(["record", "--recover", str(path)]) == 0
    capsys.readouterr()
    # chunks hold the messages flushed together: 2 whole chunks before a mid-chunk cut, 3 else
    n = PER_FLUSH * (2 if where == "mid-chunk" else 3)
    assert mcap_default_read(path) == expected(n)
    assert info_messages(path, capsys)[1] == n


def test_recover_refuses_a_file_that_is_no_mcap(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.mcap"
    path.write_bytes(b"root:x:0:0:SECRET\n" * 4)
    assert main(["record", "--recover", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"ertools: error: {path}: cannot recover") and "SECRET" not in err
    assert path.read_bytes() == b"root:x:0:0:SECRET\n" * 4
    assert not (tmp_path / "x.mcap.cut").exists()
