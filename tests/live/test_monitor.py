"""The log monitor on a growing recording, a stalled file, several files and no file."""

from __future__ import annotations

import os
import shutil
import threading
import time
from pathlib import Path

import pytest

from ertools.cli.main import main
from ertools.configs.mocap import parse_mocap_config
from ertools.live.monitor import Monitor, MonitorOptions
from ertools.live.recorder import Recorder, RecordOptions
from ertools.live.simulate import SimulatedBody, SimulatedMotive
from ertools.live.tail import is_finished, read_complete

pytestmark = pytest.mark.xdist_group("timing")

CONFIG = parse_mocap_config(
    "rigid_bodies:\n"
    "  '3': {pose: robot_at_home/pose, child_frame_id: robot_at_home}\n"
    "  '6': {pose: origin/pose, child_frame_id: origin}\n"
)
RATE = 200.0


@pytest.mark.slow
def test_monitor_follows_a_growing_recording(tmp_path: Path) -> None:
    options = RecordOptions(
        out_dir=tmp_path, name="mon", namespace="/fbm2h", group=None, port=0,
        interface="127.0.0.1", flush_interval_s=0.2, health_interval_s=60,
    )  # fmt: skip
    recorder = Recorder(CONFIG, options)
    port = recorder.open()
    rec = threading.Thread(target=recorder.run, daemon=True)
    rec.start()
    assert recorder.ready.wait(5)
    # Body 3 tracked for the first 2.2 s (440 frames), then lost until the end (4.6 s).
    motive = SimulatedMotive(
        target=("127.0.0.1", port),
        bodies=(SimulatedBody(3, untracked=(1000 + 440, 1000 + 10_000)), SimulatedBody(6)),
        n_frames=920,
        rate_hz=RATE,
    )
    sender = motive.start()
    # 1 s windows and drop_fraction 0.25: the machine running the tests is shared, and a
    # thread stalled for a few hundred ms delivers its frames in a burst; a lost body still
    # goes to 0 Hz, far below any fraction.
    monitor = Monitor(
        MonitorOptions(tmp_path, interval_s=1.0, min_growth_bps=1000, drop_fraction=0.25)
    )
    checks = []
    try:
        time.sleep(0.3)
        monitor.check()  # baseline
        for _ in range(4):
            time.sleep(1.0)
            checks.append(monitor.check())
    finally:
        motive.stop.set()
        sender.join(timeout=5)
        recorder.stop_event.set()
        rec.join(timeout=5)
    recorded = read_complete(recorder.files[0]).messages

    def count_rate(topic: str, end_ns: int) -> float:
        """Messages of the finished file inside the check's window, counted independently."""
        n = sum(
            1
            for m in recorded
            if m.topic == topic and end_ns - 1_000_000_000 < m.log_time_ns <= end_ns
        )
        return n / 1.0

    healthy, late = checks[:2], checks[-1]
    for c in healthy:
        assert c.warnings == ()
        assert c.growth_bps is not None and c.growth_bps > 1000
        assert c.window_end_ns is not None
        for topic in ("/fbm2h/robot_at_home/pose", "/fbm2h/origin/pose"):
            assert c.rates_hz[topic] == count_rate(topic, c.window_end_ns) > 0  # exact
    assert late.rates_hz["/fbm2h/robot_at_home/pose"] == 0.0
    assert late.rates_hz["/fbm2h/origin/pose"] > 0
    warned = [w for c in checks[2:] for w in c.warnings]
    assert any("/fbm2h/robot_at_home/pose rate dropped to" in w for w in warned)
    assert not any("origin" in w for w in warned)
    assert late.active == (recorder.files[0],)
    # Every frame the simulator sent is in the file (body 6 is always tracked).
    assert sum(m.topic == "/fbm2h/origin/pose" for m in recorded) == len(motive.sent)


@pytest.fixture
def unfinished(tmp_path: Path) -> Path:
    """A recorder file cut short (its first 60 %), as a recorder that hangs leaves it."""
    src = tmp_path / "src"
    options = RecordOptions(out_dir=src, name="x", group=None, port=0, interface="127.0.0.1")
    recorder = Recorder(CONFIG, options)
    port = recorder.open()
    rec = threading.Thread(target=recorder.run, daemon=True)
    rec.start()
    assert recorder.ready.wait(5)
    SimulatedMotive(("127.0.0.1", port), (SimulatedBody(6),), n_frames=60, rate_hz=RATE).run()
    recorder.stop_event.set()
    rec.join(timeout=5)
    data = recorder.files[0].read_bytes()
    logs = tmp_path / "logs"
    logs.mkdir()
    out = logs / "log_x_2015-10-23-16-15-40_0.mcap"
    out.write_bytes(data[: int(len(data) * 0.6)])
    assert not is_finished(out)
    return out


@pytest.mark.slow
def test_stalled_file_warns_about_growth(unfinished: Path) -> None:
    wall = time.time()
    os.utime(unfinished, (wall, wall))
    monitor = Monitor(MonitorOptions(unfinished.parent, interval_s=1.0, min_growth_bps=500))
    first = monitor.check(now=100.0, wall=wall + 0.5)
    assert first.warnings == () and first.active == (unfinished,)
    second = monitor.check(now=102.0, wall=wall + 2.5)  # not grown in 2 s
    assert second.growth_bps == 0.0
    assert second.warnings == (
        f"{unfinished.name} grew 0 B/s over the last 2.0 s, expected >= 500 B/s",
    )
    # Growth is bytes over time: 3000 more bytes in 1.5 s is 2000 B/s.
    with open(unfinished, "ab") as f:
        f.write(b"\0" * 3000)
    third = monitor.check(now=103.5, wall=wall + 3.0)
    assert third.growth_bps == pytest.approx(2000.0)
    assert third.warnings == ()
    # Long untouched: no longer "being written", and the monitor says so.
    later = monitor.check(now=200.0, wall=time.time() + 100)
    assert len(later.warnings) == 1
    assert "no log file is being written" in later.warnings[0] and "unfinished" in later.warnings[0]


@pytest.mark.slow
def test_several_files_and_no_file(unfinished: Path, tmp_path: Path) -> None:
    other = unfinished.with_name("log_y_2015-10-23-16-15-41_0.mcap")
    shutil.copy(unfinished, other)
    check = Monitor(MonitorOptions(unfinished.parent)).check()
    assert any("several files are being written at once" in w for w in check.warnings)
    # Two loggers in one folder, one monitor each (the 2015 log_prefix).
    only_x = Monitor(MonitorOptions(unfinished.parent, prefix="log_x_")).check()
    assert only_x.warnings == () and only_x.active == (unfinished,)
    empty = tmp_path / "empty"
    empty.mkdir()
    assert Monitor(MonitorOptions(empty)).check().warnings == (f"no log file in {empty}",)


def test_ros1_active_bag_growth(tmp_path: Path) -> None:
    bag = tmp_path / "log_home_mocap_2015-10-23-16-15-40_0.bag.active"
    bag.write_bytes(b"#ROSBAG V2.0\n")
    monitor = Monitor(MonitorOptions(tmp_path, min_growth_bps=100))
    monitor.check(now=0.0)
    with open(bag, "ab") as f:
        f.write(b"\0" * 50)
    check = monitor.check(now=1.0)
    assert check.growth_bps == pytest.approx(50.0)
    assert check.warnings == (f"{bag.name} grew 50 B/s over the last 1.0 s, expected >= 100 B/s",)


@pytest.mark.slow
def test_cli_once_on_a_stalled_folder(unfinished: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["monitor", str(unfinished.parent), "--once", "--interval", "0.2", "--bell"])
    captured = capsys.readouterr()
    assert code == 1
    assert unfinished.name in captured.out  # the status line
    assert "\aertools: monitor: WARNING: " in captured.err and "grew 0 B/s" in captured.err


def test_cli_rejects_a_missing_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["monitor", str(tmp_path / "nope"), "--once"]) == 2
    assert "is not a folder" in capsys.readouterr().err
