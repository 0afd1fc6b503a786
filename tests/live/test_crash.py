"""kill -9 of a recorder subprocess: the file cut short stays readable, minus at most 1 s."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from ertools.errors import BagError
from ertools.io.reader import read_poses
from ertools.live.simulate import SimulatedBody, SimulatedMotive
from ertools.live.tail import is_finished, read_complete
from tests.live.live_helpers import free_udp_port, read_mcap

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("timing")]

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def killed_recording(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int, SimulatedMotive]:
    """A recorder subprocess receiving 200 Hz frames, killed with SIGKILL after ~2 s."""
    out = tmp_path_factory.mktemp("crash")
    port = free_udp_port()
    cmd = [
        sys.executable, "-m", "ertools.cli.main", "record",
        "--config", str(REPO / "configs" / "mocap_home.yaml"),
        "--out-dir", str(out), "--namespace", "/fbm2h",
        "--unicast", "--interface", "127.0.0.1", "--port", str(port),
        "--duration", "30", "--health", "100",
    ]  # fmt: skip
    with open(out / "stderr.txt", "wb") as err:
        proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL, stderr=err)
    try:
        deadline = time.monotonic() + 10
        while not list(out.glob("*.mcap")):
            assert proc.poll() is None, (out / "stderr.txt").read_text()
            assert time.monotonic() < deadline, "recorder did not start"
            time.sleep(0.05)
        motive = SimulatedMotive(
            target=("127.0.0.1", port),
            bodies=(SimulatedBody(3), SimulatedBody(6, radius=2.0)),
            n_frames=2000,
            rate_hz=200.0,
        )
        thread = threading.Thread(target=motive.run, daemon=True)
        thread.start()
        time.sleep(2.2)
        t_kill = time.time_ns()
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=5)
        motive.stop.set()
        thread.join(timeout=5)
    finally:
        if proc.poll() is None:
            proc.kill()
    (path,) = out.glob("*.mcap")
    return path, t_kill, motive


def test_killed_file_is_readable_up_to_the_last_second(
    killed_recording: tuple[Path, int, SimulatedMotive],
) -> None:
    path, t_kill, motive = killed_recording
    assert not is_finished(path)  # no summary, no footer: cut short
    messages, clean = read_mcap(path)
    assert not clean  # the reader met the cut
    poses = [(t, m) for topic, t, m in messages if topic == "/fbm2h/robot_at_home/pose"]
    assert len(poses) > 100
    # The recorder flushes every 0.5 s: what it had received more than 1 s before the kill
    # is on disk (the bound), whatever the scheduler did.
    assert t_kill - poses[-1][0] <= 1_000_000_000
    # And what is there is exactly the beginning of what was sent, in order.
    sent = [rb.position for f in motive.sent for rb in f.rigid_bodies if rb.body_id == 3]
    got = [(m.pose.position.x, m.pose.position.y, m.pose.position.z) for _, m in poses]
    assert got == sent[: len(got)]
    # Our own follower (the monitor's) finds the same messages.
    ours = read_complete(path)
    assert not ours.finished and ours.complete_bytes <= ours.size_bytes
    assert [(m.topic, m.log_time_ns) for m in ours.messages] == [(t, lt) for t, lt, _ in messages]


def test_ertools_io_reads_the_killed_file(
    killed_recording: tuple[Path, int, SimulatedMotive],
) -> None:
    path, _, _ = killed_recording
    messages, _ = read_mcap(path)
    expected = [m for topic, _, m in messages if topic == "/fbm2h/robot_at_home/pose"]
    try:
        stream = read_poses(path, "/fbm2h/robot_at_home/pose")
    except BagError as err:  # imperative xfail: runs the checks as soon as io can read it
        pytest.xfail(f"ertools.io cannot read an MCAP cut short yet: {err}")
    assert len(stream) == len(expected)
    assert stream.xyz[-1].tolist() == [
        expected[-1].pose.position.x,
        expected[-1].pose.position.y,
        expected[-1].pose.position.z,
    ]
