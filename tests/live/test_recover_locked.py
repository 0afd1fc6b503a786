"""`ertools record --recover` on a recording still being written (issue 36, finding 7): a
recorder holds its file's lock from the first byte to the last, and `--recover` refuses a
locked file, naming why, instead of cutting it under the recorder's feet. The recorder is a
process of its own, paused at a chosen point (it waits for a go file): no race."""

from __future__ import annotations

import contextlib
import hashlib
import io
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from ertools.cli.main import main
from ertools.errors import BagError
from ertools.live.recover import recover
from ertools.live.tail import is_finished

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("timing")]

RECORDER = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from ertools.live.logfile import LogFile
    from ertools.live.rosmsg import POSE_2D, Ros2Serializer

    path, go = Path(sys.argv[1]), Path(sys.argv[2])
    serializer = Ros2Serializer()
    log = LogFile(path, serializer)
    channel = log.channel("/fbm2h/robot_at_home/pose2d", POSE_2D)
    for i in range(100):
        log.write(channel, 1_448_020_800_000_000_000 + i, serializer.pose2d(0.0, 0.0, 0.0))
    log.flush()
    path.with_name("ready").write_text("")
    while not go.exists():  # recording on: the test recovers now
        time.sleep(0.01)
    for i in range(100, 150):
        log.write(channel, 1_448_020_800_000_000_000 + i, serializer.pose2d(0.0, 0.0, 0.0))
    log.close()
    print(log.messages)
    """
)
DEADLINE_S = 60.0


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.skipif(sys.platform == "win32", reason="flock")
def test_recover_refuses_a_recording_being_written(tmp_path: Path) -> None:
    path = tmp_path / "log_fbm2h_mocap_2015-11-20-12-00-00_0.mcap"
    go = tmp_path / "go"
    proc = subprocess.Popen(
        [sys.executable, "-c", RECORDER, str(path), str(go)],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        end = time.monotonic() + DEADLINE_S
        while not (tmp_path / "ready").exists():
            assert proc.poll() is None and time.monotonic() < end, "the recorder did not start"
            time.sleep(0.01)
        before = sha256(path)
        with pytest.raises(BagError, match="being recorded"):
            recover(path)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            code = main(["record", "--recover", str(path)])
        assert code == 1
        # one message (a long path puts its clauses on lines: ertools.cli.text.error_text)
        assert "; ".join(line.strip() for line in err.getvalue().splitlines()) == (
            f"ertools: error: {path}: is being recorded (a recorder holds its lock); "
            "--recover is for a recording cut short"
        )
        assert sha256(path) == before and not path.with_name(path.name + ".cut").exists()
    finally:
        go.write_text("")
        out, _ = proc.communicate(timeout=DEADLINE_S)
    assert proc.returncode == 0 and out.split() == ["150"]
    assert is_finished(path)  # the recorder finished its file, whole
    done = recover(path)  # unlocked now, and whole: nothing to do
    assert done.kept is None and done.size_bytes == path.stat().st_size
