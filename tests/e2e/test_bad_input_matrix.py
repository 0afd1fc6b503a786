"""End to end: every reading command of ``ertools`` against every kind of bad input.

The rule under test (the brief's, for every command): bad input gets exactly one line on
stderr starting ``ertools: error:`` that names the file or topic involved, exit status 1 for
unusable data or config and 2 for a usage error, never a traceback, and the input files keep
their bytes and their mtime. YAML is read with ``yaml.safe_load`` only: a ``!!python`` tag is
refused and never run.

Inputs are copies of the sample logs (``sample_bags/``) made once per session, corrupted
copies of them, and tiny bags written here with rosbags' writer (NaN poses, shifted clocks).
Cases run in-process through ``ertools.cli.main.main`` with ``capsys``.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import random
import re
import shutil
import stat
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import Any

import pytest
import yaml
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_typestore

from ertools.cli.main import COMMANDS, main

REPO = Path(__file__).resolve().parents[2]
SAMPLES = REPO / "sample_bags"
FBM1H = SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag"
FBM2H = SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM3W = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
ROBOT = SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"
GT = sorted((SAMPLES / "robotlog").glob("log_fbm2h_mocap_*.bag"))

# Truncation points as fractions of the file: inside the first chunk, the middle, late, and
# (negative) bytes cut from the end, which damages only the index.
TRUNCATIONS = (0.004, 0.37, 0.81, -7)

# The YAML that must never run: it would create this file if loaded unsafely.
SENTINEL_NAME = "HACKED_BY_YAML"


@dataclass(frozen=True)
class Inputs:
    """The session's copies of the sample inputs and the bad files built from them."""

    root: Path
    fbm1h: Path
    items: Path
    fbm2h: Path
    goal: Path
    transform: Path
    timing: Path
    fbm3w: Path
    robot: Path
    gt: tuple[Path, ...]
    empty: Path
    random: Path
    bad_yaml: Path
    list_yaml: Path
    evil_yaml: Path
    nan_all: Path
    nan_part: Path
    nan_robot: Path
    robot_1h: Path
    robot_20s: Path
    robot_stamps_1h: Path

    def mocap_clock_off(self, which: str, shift_s: float) -> Path:
        """The fbm1h/fbm2h log with the mocap poses' header stamps moved by ``shift_s``."""
        out = self.root / f"{which}_mocap_clock_{shift_s:+g}.bag"
        if not out.exists():
            src, topics = {
                "fbm2h": (self.fbm2h, ("/fbm2h/robot_at_home/pose",)),
                "fbm1h": (self.fbm1h, ("/fbm1h/origin/pose", "/fbm1h/ref_board/pose")),
                "fbm3w": (self.fbm3w, ("/fbm3w/robot_at_work/pose",)),
            }[which]
            _shifted_copy(src, out, round(shift_s * 1e9), record_too=False, topics=topics)
        return out

    def truncated(self, source: Path, where: float) -> Path:
        """A copy of ``source`` cut at ``where`` (a fraction, or negative: bytes off the end)."""
        out = self.root / "truncated" / f"{source.stem}_{where}{source.suffix}"
        if not out.exists():
            data = source.read_bytes()
            cut = len(data) + int(where) if where < 0 else int(len(data) * where)
            out.parent.mkdir(exist_ok=True)
            out.write_bytes(data[:cut])
        return out


def _pose_bag(path: Path, topic: str, t0_ns: int, n: int, rate_hz: float, nan: Any) -> Path:
    """A ROS1 bag of PoseStamped on ``topic``; ``nan(i)`` says which samples are NaN."""

    ts = get_typestore(Stores.ROS1_NOETIC)
    T = ts.types
    with Writer(path) as w:
        conn = w.add_connection(topic, "geometry_msgs/msg/PoseStamped", typestore=ts)
        for i in range(n):
            t = t0_ns + int(i * 1e9 / rate_hz)
            x = float("nan") if nan(i) else 0.001 * i
            msg = T["geometry_msgs/msg/PoseStamped"](
                header=T["std_msgs/msg/Header"](
                    seq=i,
                    stamp=T["builtin_interfaces/msg/Time"](sec=t // 10**9, nanosec=t % 10**9),
                    frame_id="world",
                ),
                pose=T["geometry_msgs/msg/Pose"](
                    position=T["geometry_msgs/msg/Point"](x, 0.5, 0.0),
                    orientation=T["geometry_msgs/msg/Quaternion"](0.0, 0.0, 0.0, 1.0),
                ),
            )
            w.write(conn, t, ts.serialize_ros1(msg, conn.msgtype))
    return path


def _shifted_copy(
    src: Path, dst: Path, shift_ns: int, *, record_too: bool, topics: tuple[str, ...] = ()
) -> Path:
    """``src`` with the header stamps (of ``topics``, else all) and, with ``record_too``, the
    record times moved by ``shift_ns``."""

    with AnyReader([src]) as reader, Writer(dst) as w:
        ts = reader.typestore  # the bag's own definitions (the 2015 state messages too)
        Time = ts.types["builtin_interfaces/msg/Time"]
        conns = {  # one per ROS1 connection: /rosout and /tf have several publishers
            c.id: w.add_connection(
                c.topic, c.msgtype, typestore=ts, callerid=getattr(c.ext, "callerid", None)
            )
            for c in reader.connections
        }
        for c, t, raw in reader.messages():
            t_out = t + shift_ns if record_too else t
            if topics and c.topic not in topics:
                w.write(conns[c.id], t_out, raw)
                continue
            msg = reader.deserialize(raw, c.msgtype)
            if not hasattr(msg, "header"):
                w.write(conns[c.id], t_out, raw)
                continue
            st = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec + shift_ns
            msg.header.stamp = Time(sec=st // 10**9, nanosec=st % 10**9)
            w.write(conns[c.id], t_out, ts.serialize_ros1(msg, c.msgtype))
    return dst


@pytest.fixture(scope="session")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Inputs:
    if not FBM2H.exists():
        pytest.skip("sample_bags/ not generated (make samples)")
    root = tmp_path_factory.mktemp("e2e_inputs")

    def copy(src: Path, name: str | None = None) -> Path:
        dst = root / (name or src.name)
        shutil.copy2(src, dst)
        return dst

    (root / "empty.bag").write_bytes(b"")
    (root / "random.bag").write_bytes(random.Random(7).randbytes(6000))
    if hasattr(os, "mkfifo"):
        # where a bag or a config should be: an open() of it blocks until a writer comes
        os.mkfifo(root / "fifo.bag")
        os.mkfifo(root / "fifo.yaml")
    (root / "bad.yaml").write_text("goal:\n  waypoints: [1, 2\n  x: : :\n")
    (root / "list.yaml").write_text("- 1\n- 2\n")
    (root / "evil.yaml").write_text(
        f'x: !!python/object/apply:os.system ["touch {root / SENTINEL_NAME}"]\n'
    )
    t0 = 1448020800 * 10**9  # the sample logs' 2015-11-20 12:00:00 UTC
    topic = "/fbm2h/robot_at_home/pose"
    return Inputs(
        root=root,
        fbm1h=copy(FBM1H),
        items=copy(SAMPLES / "fbm1h" / "fbm1h.yaml"),
        fbm2h=copy(FBM2H),
        goal=copy(SAMPLES / "fbm2h" / "fbm2h_goal.yaml"),
        transform=copy(SAMPLES / "fbm2h" / "transform-simbot.yaml"),
        timing=copy(next((SAMPLES / "fbm2h").glob("*_reached_waypoint_timing.yaml"))),
        fbm3w=copy(FBM3W),
        robot=copy(ROBOT),
        gt=tuple(copy(p) for p in GT),
        empty=root / "empty.bag",
        random=root / "random.bag",
        bad_yaml=root / "bad.yaml",
        list_yaml=root / "list.yaml",
        evil_yaml=root / "evil.yaml",
        # 10 s at 120 Hz: all NaN, and NaN from 3.3 s to 7.5 s.
        nan_all=_pose_bag(root / "nan_all.bag", topic, t0, 1200, 120.0, lambda i: True),
        nan_part=_pose_bag(root / "nan_part.bag", topic, t0, 1200, 120.0, lambda i: 400 <= i < 900),
        nan_robot=_pose_bag(
            root / "nan_robot.bag",
            "/rockin/homer/marker_pose",
            t0 + 2 * 10**9,
            100,
            10.0,
            lambda i: True,
        ),
        robot_1h=_shifted_copy(ROBOT, root / "robot_1h.bag", 3600 * 10**9, record_too=True),
        robot_20s=_shifted_copy(ROBOT, root / "robot_20s.bag", 20 * 10**9, record_too=True),
        robot_stamps_1h=_shifted_copy(
            ROBOT, root / "robot_stamps_1h.bag", 3600 * 10**9, record_too=False
        ),
    )


# ---------------------------------------------------------------------------------------------
# The commands: each builds a command line that is right except for the bad input.


def _gt(i: Inputs) -> list[str]:
    return [str(p) for p in i.gt]


Argv = Callable[[Inputs, Path, Path], list[str]]  # (inputs, bad bag, scratch dir) -> argv

BAG_COMMANDS: dict[str, tuple[Argv, str]] = {
    # name: (argv with the bad bag, which good bag is truncated for it)
    "info": (lambda i, b, d: ["info", str(b)], "fbm2h"),
    "timeline": (lambda i, b, d: ["timeline", str(b)], "fbm2h"),
    "score-fbm1h": (lambda i, b, d: ["score", "fbm1h", str(b), "--items", str(i.items)], "fbm1h"),
    "score-fbm1w": (lambda i, b, d: ["score", "fbm1w", str(b), "--items", str(i.items)], "fbm1h"),
    "score-fbm2h": (
        lambda i, b, d: [
            "score",
            "fbm2h",
            str(b),
            "--goal",
            str(i.goal),
            "--transform",
            str(i.transform),
        ],
        "fbm2h",
    ),
    "score-fbm3w": (lambda i, b, d: ["score", "fbm3w", str(b)], "fbm3w"),
    "score-trajectory-robot": (lambda i, b, d: ["score", "trajectory", str(b), *_gt(i)], "robot"),
    "score-trajectory-gt": (lambda i, b, d: ["score", "trajectory", str(i.robot), str(b)], "gt"),
    "noise": (lambda i, b, d: ["noise", str(b)], "fbm3w"),
    "acquire-transform": (
        lambda i, b, d: ["acquire", "transform", str(b), "--team", "qa", "--out-dir", str(d)],
        "fbm2h",
    ),
    "acquire-items": (
        lambda i, b, d: ["acquire", "items", str(b), "--items", str(i.items)],
        "fbm1h",
    ),
    "audit": (lambda i, b, d: ["audit", str(b)], "fbm2h"),
    "export": (
        lambda i, b, d: ["export", str(b), "--topic", "/fbm3w/robot_at_work/pose", "-o", str(d)],
        "fbm3w",
    ),
    "export-pair-robot": (
        lambda i, b, d: ["export", str(b), *_gt(i), "--out-dir", str(d)],
        "robot",
    ),
    "export-pair-gt": (
        lambda i, b, d: ["export", str(i.robot), str(b), "--out-dir", str(d), "--matched"],
        "gt",
    ),
}


def _good_bag(i: Inputs, which: str) -> Path:
    return {"fbm1h": i.fbm1h, "fbm2h": i.fbm2h, "fbm3w": i.fbm3w, "robot": i.robot}.get(
        which, i.gt[0]
    )


# ---------------------------------------------------------------------------------------------
# Running a case and checking the rule.


def _files(argv: list[str]) -> list[Path]:
    """Every existing input file named on the command line (folders walked)."""
    out: list[Path] = []
    for a in argv:
        p = Path(a)
        if p.is_file():
            out.append(p)
        elif p.is_dir():
            out.extend(q for q in sorted(p.rglob("*")) if q.is_file())
    return out


def _snapshot(files: list[Path]) -> dict[Path, tuple[str, int]]:
    return {p: (hashlib.sha256(p.read_bytes()).hexdigest(), p.stat().st_mtime_ns) for p in files}


@dataclass(frozen=True)
class Outcome:
    code: int
    out: str
    err: str


# A command still blocked on a FIFO after this long would block for ever: the watchdog then
# opens the FIFO for writing and closes it (the reader gets an end of file) and the case fails.
FIFO_PATIENCE_S = 30.0


@contextlib.contextmanager
def _fifo_watchdog(argv: list[str]) -> Iterator[list[str]]:
    """Yields the FIFOs of ``argv`` a blocked command was freed from (none when it never
    blocked on one)."""
    fifos = [a for a in argv if Path(a).exists() and stat.S_ISFIFO(os.stat(a).st_mode)]
    freed: list[str] = []
    done = threading.Event()

    def watch() -> None:
        if done.wait(FIFO_PATIENCE_S):
            return
        while not done.is_set():
            for fifo in fifos:
                try:  # succeeds only while a reader is blocked opening it
                    os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
                    freed.append(fifo)
                except OSError:
                    pass
            time.sleep(0.1)

    watcher = threading.Thread(target=watch, daemon=True)
    if fifos:
        watcher.start()
    try:
        yield freed
    finally:
        done.set()
        if fifos:
            watcher.join()


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> Outcome:
    capsys.readouterr()
    files = _files(argv)
    before = _snapshot(files)
    with _fifo_watchdog(argv) as freed:
        code = main(argv)
    captured = capsys.readouterr()
    assert not freed, f"blocked reading the FIFO {freed[0]} (freed after {FIFO_PATIENCE_S} s)"
    assert _snapshot(files) == before, "an input file was modified"
    return Outcome(code, captured.out, captured.err)


def _check_error(result: Outcome, code: int, *names: str) -> str:
    """Exit ``code``, one ``ertools: error:`` line naming one of ``names``, no traceback, every
    other stderr line an ertools note (a third-party message's own lines folded into the one).
    Returns the message."""
    assert "Traceback" not in result.err + result.out
    err = result.err.splitlines()
    starts = [i for i, ln in enumerate(err) if ln.startswith("ertools: error:")]
    assert len(starts) == 1, result.err
    rest = err[: starts[0]] + err[starts[0] + 1 :]
    # (a command group given nothing shows its usage line above the error)
    assert all(ln.startswith(("ertools: ", "usage: ertools ")) for ln in rest), result.err
    message = err[starts[0]]
    assert result.code == code, result.err
    assert "unexpected" not in message, message  # the CLI's wording for a bug
    assert any(n in message for n in names), (names, message)
    return message


# ---------------------------------------------------------------------------------------------
# 1. Bad bags: missing, empty, random bytes, truncated at several offsets.

BAD_BAGS = [
    "missing",
    "empty",
    "random",
    *(f"truncated@{w}" for w in TRUNCATIONS),
    "rosbag2-metadata-malformed",
    "rosbag2-metadata-python-tag",
    "rosbag2-mcap-truncated",
    "mcap-truncated",
    "fifo",
]
ROSBAG2 = next((SAMPLES / "fbm3w").glob("*_mcap"))


def _bad_rosbag2(inputs: Inputs, kind: str) -> Path:
    """A copy of the sample rosbag2 (MCAP storage) folder, damaged as ``kind`` says."""
    out = inputs.root / "rosbag2" / kind
    if out.exists():
        return out
    shutil.copytree(ROSBAG2, out)
    meta = out / "metadata.yaml"
    if kind == "rosbag2-metadata-malformed":
        meta.write_text("rosbag2_bagfile_information: [\n")
    elif kind == "rosbag2-metadata-python-tag":
        tag = f'!!python/object/apply:os.system ["touch {inputs.root / SENTINEL_NAME}"]'
        meta.write_text(f"x: {tag}\n" + meta.read_text())
    else:
        (mcap,) = out.glob("*.mcap")
        mcap.write_bytes(mcap.read_bytes()[: mcap.stat().st_size * 4 // 10])
    return out


@pytest.mark.slow_cases(
    "acquire-items-truncated@-7",
    "acquire-transform-truncated@-7",
    "acquire-transform-truncated@0.81",
    "export-pair-gt-truncated@-7",
    "export-pair-gt-truncated@0.81",
    "info-empty",
    "info-missing",
    "info-random",
    "info-truncated@-7",
    "info-truncated@0.004",
    "score-fbm1h-truncated@-7",
    "score-fbm1w-truncated@-7",
    "score-fbm2h-truncated@-7",
    "score-fbm2h-truncated@0.81",
    "score-fbm3w-truncated@-7",
    "score-fbm3w-truncated@0.81",
    "score-trajectory-gt-truncated@-7",
    "score-trajectory-gt-truncated@0.81",
    "timeline-truncated@-7",
    "timeline-truncated@0.81",
)
@pytest.mark.parametrize("bad", BAD_BAGS)
@pytest.mark.parametrize("command", list(BAG_COMMANDS))
def test_bad_bag(
    command: str,
    bad: str,
    inputs: Inputs,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv_of, which = BAG_COMMANDS[command]
    if bad == "missing":
        bag = inputs.root / "no_such_log.bag"
    elif bad.startswith("truncated@"):
        bag = inputs.truncated(_good_bag(inputs, which), float(bad.split("@")[1]))
    elif bad.startswith("rosbag2-"):
        bag = _bad_rosbag2(inputs, bad)
    elif bad == "mcap-truncated":
        (mcap,) = ROSBAG2.glob("*.mcap")
        bag = inputs.truncated(mcap, 0.4)
    elif bad == "fifo":
        bag = inputs.root / "fifo.bag"
        if not bag.exists():
            pytest.skip("n/a: no FIFOs on this system")
    else:
        bag = getattr(inputs, bad)
    argv = argv_of(inputs, bag, tmp_path / "out")
    result = _run(argv, capsys)
    if command == "timeline" and result.code == 0:
        # timeline surveys logger folders, broken files included: a truncated bag whose
        # messages up to the cut are readable is placed by them (exit 0), and its problem is
        # said on stderr as well as in the table.
        assert "truncated" in bad and "Traceback" not in result.err
        warnings = [ln for ln in result.err.splitlines() if ln.startswith("ertools: warning:")]
        assert len(warnings) == 1 and bag.name in warnings[0], result.err
        assert "truncated" in warnings[0] or "damaged" in warnings[0]
        assert "ertools: error:" not in result.err
        return
    line = _check_error(result, 1, bag.name)
    if bad == "fifo":
        assert "not a regular file (a FIFO)" in line  # said as such, not "no bags there"
    assert not (tmp_path / "out").exists(), "nothing is written when the input is bad"
    assert not (inputs.root / SENTINEL_NAME).exists(), "a YAML python tag was executed"


@pytest.mark.parametrize(
    "bad",
    ["missing", "empty", "random", "truncated-json", "wrong-shape-json", "plain-folder", "fifo"],
)
def test_report_bad_result(
    bad: str, inputs: Inputs, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`report` reads result files and folders: each bad one named on one line, exit 1."""
    path = {
        "missing": tmp_path / "no_such_result.json",
        "empty": inputs.empty,
        "random": inputs.random,
        "truncated-json": tmp_path / "truncated.json",
        "wrong-shape-json": tmp_path / "list.json",
        "plain-folder": tmp_path / "not_a_report",
        "fifo": tmp_path / "fifo.json",
    }[bad]
    if bad == "truncated-json":
        path.write_text('{"name": "fbm2h", "position_accuracy": 0.1')
    elif bad == "wrong-shape-json":
        path.write_text("[1, 2]")
    elif bad == "plain-folder":
        path.mkdir()
    elif bad == "fifo":
        if not hasattr(os, "mkfifo"):
            pytest.skip("n/a: no FIFOs on this system")
        os.mkfifo(path)
    result = _run(["report", str(path), "--report", str(tmp_path / "page")], capsys)
    _check_error(result, 1, path.name)
    assert not (tmp_path / "page" / "index.html").exists()


def test_monitor_missing_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # monitor treats its folder as a usage matter (exit 2), unlike the reading commands (1).
    missing = tmp_path / "no_such_logs"
    _check_error(_run(["monitor", str(missing), "--once"], capsys), 2, missing.name)


def test_timeline_pairs_a_copied_robot_log_once(
    capsys: pytest.CaptureFixture[str],
) -> None:
    folder = SAMPLES / "timeline" / "bags"
    if not folder.is_dir():
        pytest.skip("sample_bags/ not generated (make samples)")
    result = _run(["timeline", str(folder), "--no-clock-check"], capsys)  # bags are not changed
    pairings = [ln for ln in result.out.splitlines() if "homer.bag: GT coverage" in ln]
    # the robot log and its byte copy on the USB stick (sample_bags/README.md) are one
    # recording: paired once, the copy named as such
    assert len(pairings) == 1 and "usb_stick" not in pairings[0]
    copy = "usb_stick/FBM2H_201511201500_homer.bag: same recording as "
    assert any(copy in ln and "robots/homer" in ln for ln in result.out.splitlines())


def test_timeline_writes_no_chart_when_nothing_is_readable(
    inputs: Inputs, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    chart = tmp_path / "timeline.png"
    result = _run(["timeline", str(inputs.random), "--plot", str(chart)], capsys)
    _check_error(result, 1, inputs.random.name)
    assert not chart.exists()


# ---------------------------------------------------------------------------------------------
# 2. Configs: malformed YAML, YAML of the wrong shape, a python tag (never run), missing file.

ConfArgv = Callable[[Inputs, Path], list[str]]

CONFIG_OPTIONS: dict[str, ConfArgv] = {
    "fbm1h--items": lambda i, y: ["score", "fbm1h", str(i.fbm1h), "--items", str(y)],
    "fbm1h--results": lambda i, y: [
        "score",
        "fbm1h",
        str(i.fbm1h),
        "--items",
        str(i.items),
        "--results",
        str(y),
    ],
    "fbm2h--goal": lambda i, y: [
        "score",
        "fbm2h",
        str(i.fbm2h),
        "--goal",
        str(y),
        "--transform",
        str(i.transform),
    ],
    "fbm2h--transform": lambda i, y: [
        "score",
        "fbm2h",
        str(i.fbm2h),
        "--goal",
        str(i.goal),
        "--transform",
        str(y),
    ],
    "fbm2h--reached-timing": lambda i, y: [
        "score",
        "fbm2h",
        str(i.fbm2h),
        "--goal",
        str(i.goal),
        "--transform",
        str(i.transform),
        "--reached",
        "timing",
        str(y),
    ],
    "fbm3w--config": lambda i, y: ["score", "fbm3w", str(i.fbm3w), "--config", str(y)],
    "fbm3w--runs-file": lambda i, y: ["score", "fbm3w", str(i.fbm3w), "--runs-file", str(y)],
    "acquire-items--items": lambda i, y: ["acquire", "items", str(i.fbm1h), "--items", str(y)],
    "record--config": lambda i, y: [
        "record",
        "--config",
        str(y),
        "--out-dir",
        str(y.parent / "rec"),
    ],
}
# audit passes the same files to the scorer; a bad file given explicitly must not end in
# exit 0 with "score not recomputed": it is the scorer's one-line error and exit 1.
AUDIT_CONFIG_OPTIONS: dict[str, ConfArgv] = {
    "audit--goal": lambda i, y: ["audit", str(i.fbm2h), "--goal", str(y)],
    "audit--transform": lambda i, y: ["audit", str(i.fbm2h), "--transform", str(y)],
    "audit--items": lambda i, y: ["audit", str(i.fbm1h), "--items", str(y)],
    "audit--config": lambda i, y: ["audit", str(i.fbm3w), "--config", str(y)],
}
BAD_CONFIGS = ["malformed", "wrong-shape", "python-tag", "missing", "fifo"]


def _bad_config(inputs: Inputs, kind: str) -> Path:
    return {
        "malformed": inputs.bad_yaml,
        "wrong-shape": inputs.list_yaml,
        "python-tag": inputs.evil_yaml,
        "missing": inputs.root / "no_such_config.yaml",
        "fifo": inputs.root / "fifo.yaml",
    }[kind]


def _check_config_case(
    argv_of: ConfArgv, kind: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    config = _bad_config(inputs, kind)
    if kind == "fifo" and not config.exists():
        pytest.skip("n/a: no FIFOs on this system")
    result = _run(argv_of(inputs, config), capsys)
    assert not (inputs.root / SENTINEL_NAME).exists(), "a YAML python tag was executed"
    line = _check_error(result, 1, config.name)
    if kind == "fifo":
        assert "not a regular file (a FIFO)" in line
    if kind == "python-tag":
        assert "python/object" in line  # says which tag it refused


@pytest.mark.parametrize("kind", BAD_CONFIGS)
@pytest.mark.parametrize("option", list(CONFIG_OPTIONS))
def test_bad_config(
    option: str, kind: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    _check_config_case(CONFIG_OPTIONS[option], kind, inputs, capsys)


@pytest.mark.parametrize("kind", BAD_CONFIGS)
@pytest.mark.parametrize("option", list(AUDIT_CONFIG_OPTIONS))
def test_bad_config_audit(
    option: str, kind: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    _check_config_case(AUDIT_CONFIG_OPTIONS[option], kind, inputs, capsys)


def test_audit_bad_config_is_refused_unexecuted_even_when_only_warned(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    """The tag is refused, named, and never run (and the audit exits 1: see above)."""
    result = _run(["audit", str(inputs.fbm2h), "--goal", str(inputs.evil_yaml)], capsys)
    assert not (inputs.root / SENTINEL_NAME).exists()
    assert "Traceback" not in result.err and "evil.yaml" in result.err


@pytest.mark.slow
def test_short_items_order_keeps_the_payloads_of_later_runs(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--items-order 10` fixes run 1 only (the sample shows item 10 first): the totals are
    the answers file's, not nine 'no item named' failures."""

    answers = yaml.safe_load(next((SAMPLES / "fbm1h").glob("*.answers.yaml")).read_text())
    first = answers["expected"]["runs"][0]
    argv = ["score", "fbm1h", str(inputs.fbm1h), "--items", str(inputs.items), "--format", "json"]
    result = _run([*argv, "--items-order", str(first["item_id"])], capsys)
    assert result.code == 0, result.err
    assert "keep the item their payload names" in result.err
    got = json.loads(result.out)
    for key, value in answers["expected"]["totals"].items():
        # The answers' own tolerance for the pose score (mocap noise); the rest are exact.
        tol = answers["tolerance"].get(key, {}).get("abs", 1e-9)
        assert abs(got[key] - value) <= tol, key


def test_results_for_runs_and_items_not_in_the_log_are_said(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    results = inputs.root / "results_elsewhere.yaml"
    results.write_text(
        "- {run: 99, item_class: a, item_instance: a1, x: 0, y: 0, theta: 0}\n"
        "- {item: 77, item_class: a, item_instance: a1, x: 0, y: 0, theta: 0}\n"
    )
    argv = CONFIG_OPTIONS["fbm1h--results"](inputs, results)
    result = _run(argv, capsys)
    warnings = [ln for ln in result.err.splitlines() if results.name in ln]
    assert result.code == 0 and len(warnings) == 2, result.err
    assert "[99]" in warnings[0] and "[77]" in warnings[1]


def test_mislabelled_timing_file(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    # p0 twice, p1 missing: read by order this would silently close the wrong segments.
    bad = inputs.root / "mislabelled_timing.yaml"
    labels = ["p0", "p0", "p2", "p3", "p4", "p5"]
    bad.write_text(
        "reached_waypoint_timing:\n" + "".join(f"- {k}: {2 + i}.5\n" for i, k in enumerate(labels))
    )
    argv = CONFIG_OPTIONS["fbm2h--reached-timing"](inputs, bad)
    line = _check_error(_run(argv, capsys), 1, bad.name)
    assert "'p1'" in line


def test_bad_quaternion_is_printed_as_numbers(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = inputs.root / "transform-zero-quaternion.yaml"
    bad.write_text("marker_to_robot_transform:\n- [0.1, 0.0, 0.0]\n- [0, 0, 0, 0]\n")
    line = _check_error(_run(CONFIG_OPTIONS["fbm2h--transform"](inputs, bad), capsys), 1, bad.name)
    assert "[0.0, 0.0, 0.0, 0.0]" in line and "np." not in line


# ---------------------------------------------------------------------------------------------
# 3. Topics and frames that are not in the log.

TOPIC_CASES: dict[str, Callable[[Inputs], list[str]]] = {
    "fbm2h--topic": lambda i: [
        "score",
        "fbm2h",
        str(i.fbm2h),
        "--goal",
        str(i.goal),
        "--transform",
        str(i.transform),
        "--topic",
        "/no/such/topic",
    ],
    "fbm2h--tf-frame": lambda i: [
        "score",
        "fbm2h",
        str(i.fbm2h),
        "--goal",
        str(i.goal),
        "--tf-frame",
        "no_such_frame",
    ],
    "fbm3w--topic": lambda i: ["score", "fbm3w", str(i.fbm3w), "--topic", "/no/such/topic"],
    "fbm3w--frame": lambda i: ["score", "fbm3w", str(i.fbm3w), "--frame", "no_such_frame"],
    "fbm1h--origin-topic": lambda i: [
        "score",
        "fbm1h",
        str(i.fbm1h),
        "--items",
        str(i.items),
        "--origin-topic",
        "/no/such/topic",
    ],
    "fbm1h--ref-board-frame": lambda i: [
        "score",
        "fbm1h",
        str(i.fbm1h),
        "--items",
        str(i.items),
        "--ref-board-frame",
        "no_such_frame",
    ],
    "noise--topic": lambda i: ["noise", str(i.fbm3w), "--topic", "/no/such/topic"],
    "trajectory--robot-topic": lambda i: [
        "score",
        "trajectory",
        str(i.robot),
        *_gt(i),
        "--robot-topic",
        "/no/such/topic",
    ],
    "trajectory--gt-topic": lambda i: [
        "score",
        "trajectory",
        str(i.robot),
        *_gt(i),
        "--gt-topic",
        "/no/such/topic",
    ],
    "acquire-transform--topic": lambda i: [
        "acquire",
        "transform",
        str(i.fbm2h),
        "--team",
        "qa",
        "--out-dir",
        str(i.root / "tr"),
        "--topic",
        "/no/such/topic",
    ],
    "acquire-items--origin-topic": lambda i: [
        "acquire",
        "items",
        str(i.fbm1h),
        "--items",
        str(i.items),
        "--origin-topic",
        "/no/such/topic",
    ],
    # The default topic of another benchmark: the log is of the wrong kind.
    "fbm2h-on-fbm3w-log": lambda i: [
        "score",
        "fbm2h",
        str(i.fbm3w),
        "--goal",
        str(i.goal),
        "--transform",
        str(i.transform),
    ],
    "fbm1h-on-fbm2h-log": lambda i: ["score", "fbm1h", str(i.fbm2h), "--items", str(i.items)],
    "noise-on-fbm2h-log": lambda i: ["noise", str(i.fbm2h)],
    "audit--benchmark-absent": lambda i: ["audit", str(i.fbm2h), "--benchmark", "fbm1h"],
}


@pytest.mark.parametrize("case", list(TOPIC_CASES))
def test_wrong_topic(case: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    result = _run(TOPIC_CASES[case](inputs), capsys)
    if case in WRONG_BENCHMARK:
        # A log of another benchmark is named for what it is: unusable data (exit 1).
        line = _check_error(result, 1, "this looks like an")
        assert line.endswith(f"ertools score {WRONG_BENCHMARK[case]}"), line
        return
    # Named: the topic or frame asked for, or (for a log of the wrong kind) the log itself.
    _check_error(
        result, 1, "/no/such/topic", "no_such_frame", "fbm3w_mocap", "fbm2h_mocap", "/fbm1h"
    )


# the TOPIC_CASES that give a benchmark another one's log, and the benchmark it is
WRONG_BENCHMARK = {"fbm2h-on-fbm3w-log": "fbm3w", "fbm1h-on-fbm2h-log": "fbm2h"}


def test_wrong_topic_audit(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    result = _run(["audit", str(inputs.fbm2h), "--topic", "/no/such/topic"], capsys)
    _check_error(result, 1, "/no/such/topic")


# ---------------------------------------------------------------------------------------------
# 4. Time windows with no data in them.


def _late_timing(i: Inputs) -> Path:
    path = i.root / "late_timing.yaml"
    path.write_text(
        "reached_waypoint_timing:\n" + "".join(f"- p{k}: {1000 + k}.0\n" for k in range(6))
    )
    return path


def _far_windows(i: Inputs) -> str:
    n = len(yaml.safe_load(i.items.read_text())["items"])
    return ",".join(f"{5000 + 10 * k}:{5005 + 10 * k}" for k in range(n))


WINDOW_CASES: dict[str, tuple[Callable[[Inputs], list[str]], tuple[str, ...]]] = {
    "acquire-transform--at": (
        lambda i: [
            "acquire",
            "transform",
            str(i.fbm2h),
            "--team",
            "qa",
            "--out-dir",
            str(i.root / "tr"),
            "--at",
            "1000",
            "--duration",
            "5",
        ],
        ("1000.000 s", "fbm2h_mocap"),
    ),
    "fbm3w--run": (
        lambda i: ["score", "fbm3w", str(i.fbm3w), "--run", "line:1000:1001:1002"],
        ("1001.000",),
    ),
    "fbm2h--reached-timing": (
        lambda i: [
            "score",
            "fbm2h",
            str(i.fbm2h),
            "--goal",
            str(i.goal),
            "--transform",
            str(i.transform),
            "--reached",
            "timing",
            str(_late_timing(i)),
        ],
        ("late_timing.yaml",),
    ),
    "acquire-items--windows": (
        lambda i: [
            "acquire",
            "items",
            str(i.fbm1h),
            "--items",
            str(i.items),
            "--windows",
            _far_windows(i),
        ],
        ("--windows",),
    ),
}


@pytest.mark.parametrize("case", list(WINDOW_CASES))
def test_empty_window(case: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    argv_of, names = WINDOW_CASES[case]
    result = _run(argv_of(inputs), capsys)
    _check_error(result, 1, *names)
    assert not (inputs.root / "tr" / "transform-qa.yaml").exists()


# ---------------------------------------------------------------------------------------------
# 5. NaN poses.


def _nan_timing(i: Inputs) -> Path:
    # Waypoint k reached at 5 + k s: 5, 6, 7 s fall in nan_part's NaN stretch (3.3 to 7.5 s).
    path = i.root / "nan_timing.yaml"
    path.write_text(
        "reached_waypoint_timing:\n" + "".join(f"- p{k}: {k + 4}.0\n" for k in range(6))
    )
    return path


NAN_CASES: dict[str, tuple[Callable[[Inputs, Path], list[str]], str]] = {
    "fbm2h--reached-timing": (
        lambda i, b: [
            "score",
            "fbm2h",
            str(b),
            "--goal",
            str(i.goal),
            "--transform",
            str(i.transform),
            "--reached",
            "timing",
            str(_nan_timing(i)),
        ],
        "/fbm2h/robot_at_home/pose",
    ),
    "acquire-transform--at": (
        lambda i, b: [
            "acquire",
            "transform",
            str(b),
            "--team",
            "qa",
            "--out-dir",
            str(i.root / "tr"),
            "--at",
            "4",
            "--duration",
            "2",
        ],
        "/fbm2h/robot_at_home/pose",
    ),
    "fbm3w--run": (
        lambda i, b: [
            "score",
            "fbm3w",
            str(b),
            "--topic",
            "/fbm2h/robot_at_home/pose",
            "--run",
            "line:0.5:1:8",
        ],
        "run 0",
    ),
    "trajectory-gt": (
        lambda i, b: ["score", "trajectory", str(i.robot), str(b)],
        "/fbm2h/robot_at_home/pose",
    ),
}


# A NaN as YAML (.nan) or as a bare value; JSON output refuses NaN outright.
NAN_VALUE = re.compile(r"(\.nan\b)|(:\s*nan\b)", re.IGNORECASE)


@pytest.mark.parametrize("which", ["nan_all", "nan_part"])
@pytest.mark.parametrize("case", list(NAN_CASES))
def test_nan_poses(
    case: str, which: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    if case == "trajectory-gt" and which == "nan_part":
        pytest.skip("n/a: part-NaN GT is scored on the valid part: see test_nan_gt_part_is_said")
    if case == "fbm2h--reached-timing" and which == "nan_part":
        pytest.skip("n/a: one error per failed segment: see test_nan_part_fbm2h_warns_and_fails...")
    argv_of, name = NAN_CASES[case]
    bag = getattr(inputs, which)
    result = _run(argv_of(inputs, bag), capsys)
    _check_error(result, 1, name, bag.name)
    assert not NAN_VALUE.search(result.out), "a NaN value reached the output"
    assert not (inputs.root / "tr" / "transform-qa.yaml").exists()


def test_nan_robot_poses(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    result = _run(["score", "trajectory", str(inputs.nan_robot), *_gt(inputs)], capsys)
    _check_error(result, 1, "nan_robot.bag")


def test_nan_part_fbm2h_warns_and_fails_the_segments_in_it(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = NAN_CASES["fbm2h--reached-timing"][0](inputs, inputs.nan_part)
    result = _run(argv, capsys)
    assert result.code == 1 and "Traceback" not in result.err
    # Moments at 5, 6, 7 s lie in the NaN stretch: three failed segments, each named.
    errors = [ln for ln in result.err.splitlines() if ln.startswith("ertools: error:")]
    assert [e.split(":")[2].strip() for e in errors] == ["segment 0", "segment 1", "segment 2"]
    assert "500 marker set pose(s) with NaN" in result.err  # samples 400..899
    assert "position_accuracy: null" in result.out


def test_nan_gt_part_is_said(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    result = _run(["score", "trajectory", str(inputs.nan_robot), str(inputs.nan_part)], capsys)
    # The robot's poses are all NaN: that is the error, not the GT.
    _check_error(result, 1, "nan_robot.bag")


def test_nan_part_noise_ignores_the_nan_steps(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [
        "noise",
        str(inputs.nan_part),
        "--topic",
        "/fbm2h/robot_at_home/pose",
        "--format",
        "json",
    ]
    result = _run(argv, capsys)
    assert result.code == 0 and "Traceback" not in result.err
    # 700 valid samples 1 mm apart (x = 0.001 i) except across the NaN stretch: epsilon 1 mm.
    got = json.loads(result.out)
    assert got["samples"] == 700 and abs(got["epsilon"] - 0.001) < 1e-9


def test_nan_poses_noise(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["noise", str(inputs.nan_all), "--topic", "/fbm2h/robot_at_home/pose"]
    result = _run(argv, capsys)
    line = _check_error(result, 1, "nan_all.bag", "/fbm2h/robot_at_home/pose")
    assert "nan_all.bag" in line and "/fbm2h/robot_at_home/pose" in line and "NaN" in line


# ---------------------------------------------------------------------------------------------
# 6. Unsynchronised clocks (trajectory).


@pytest.mark.parametrize(
    "which,names",
    [
        ("robot_1h", ("no GT file overlaps",)),  # robot clock an hour off: nothing to compare
        ("robot_20s", ("robot_20s.bag",)),  # 20 s off: half the robot log is outside the GT
        ("robot_stamps_1h", ("no GT file overlaps",)),  # header stamps off, record times right
    ],
)
def test_unsynchronised_clocks(
    which: str, names: tuple[str, ...], inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    result = _run(["score", "trajectory", str(getattr(inputs, which)), *_gt(inputs)], capsys)
    _check_error(result, 1, *names)


def test_mistyped_gt_path_among_good_ones(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = inputs.root / "log_fbm2h_mocap_typo.bag"
    argv = ["score", "trajectory", str(inputs.robot), *_gt(inputs), str(missing)]
    _check_error(_run(argv, capsys), 1, missing.name)


def test_robot_log_given_as_its_own_gt(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["score", "trajectory", str(inputs.robot), str(inputs.robot)]
    assert "robot log itself" in _check_error(_run(argv, capsys), 1, inputs.robot.name)


def test_damaged_gt_file_is_named(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    # The second GT file cut in its middle: the robot poses after the first file are then
    # outside the GT (the error), and the damaged file is named in that error.
    cut = inputs.truncated(inputs.gt[1], 0.66)
    argv = ["score", "trajectory", str(inputs.robot), str(inputs.gt[0]), str(cut)]
    line = _check_error(_run(argv, capsys), 1, cut.name)
    assert "outside the GT" in line and "damaged" in line


@pytest.mark.slow
@pytest.mark.parametrize(
    "which,shift_s", [("fbm2h", 3.0), ("fbm2h", -0.4), ("fbm1h", -2.0), ("fbm1h", 0.5)]
)
def test_mocap_clock_off_the_logger_clock(
    which: str, shift_s: float, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    """Poses stamped by a mocap clock seconds off the logger's, states in record time: the
    pose taken at each state moment is another moment's (fbm2h scored 0.398 m instead of
    0.097 m at +3 s, exit 0). Refused, naming the topic and --time-source record."""
    bag = inputs.mocap_clock_off(which, shift_s)
    extra = (
        ["--transform", str(inputs.transform)]
        if which == "fbm2h"
        else ["--items", str(inputs.items)]
    )
    result = _run(["score", which, str(bag), *extra], capsys)
    line = _check_error(result, 1, bag.name)
    assert f"{shift_s:+.3f} s" in line and "--time-source record" in line
    if which == "fbm2h":
        # ... and the way out scores as the answers file says (its 2 mm tolerance).
        answers = yaml.safe_load(next((SAMPLES / "fbm2h").glob("*.answers.yaml")).read_text())
        again = _run(
            ["score", which, str(bag), *extra, "--time-source", "record", "--format", "json"],
            capsys,
        )
        assert again.code == 0
        got = json.loads(again.out)["position_accuracy"]
        assert (
            abs(got - answers["expected"]["position_accuracy"])
            <= answers["tolerance"]["distance_error"]["abs"]
        )


@pytest.mark.slow
def test_fbm3w_header_time_with_mocap_clock_off(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    # Before: 0.099 m instead of 0.00064 m, exit 0 (poses cut 3 s off the state moments).
    bag = inputs.mocap_clock_off("fbm3w", -3.0)
    argv = ["score", "fbm3w", str(bag), "--topic", "/fbm3w/robot_at_work/pose"]
    result = _run([*argv, "--time-source", "header"], capsys)
    line = _check_error(result, 1, bag.name)
    assert "--time-source record" in line
    # The way out it names works: record time scores the run.
    assert _run([*argv, "--time-source", "record"], capsys).code == 0


def test_small_clock_offset_is_never_silent(
    inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    """The sample robot clock runs 0.35 s ahead (answers file): scored, but said loudly."""

    answers = yaml.safe_load(next((SAMPLES / "robotlog").glob("*.answers.yaml")).read_text())
    true_offset = answers["truth"]["offset_s"]  # seconds added to the robot stamps
    result = _run(["score", "trajectory", str(inputs.robot), *_gt(inputs)], capsys)
    assert result.code == 0
    warning = [ln for ln in result.err.splitlines() if "clock audit" in ln]
    assert len(warning) == 1 and "--offset auto --apply-offset" in warning[0]
    # The estimate printed is the true offset within the answers' 10 ms tolerance.
    shown = float(warning[0].split("shifted by ")[1].split()[0])
    assert abs(shown - true_offset) <= answers["tolerance"]["offset_s"]["abs"]


# ---------------------------------------------------------------------------------------------
# 7. Usage errors: exit 2, one line.

USAGE_COMMANDS = [
    ["info"],
    ["timeline"],
    ["score", "fbm1h", "x.bag"],  # --items is required
    ["score", "fbm2h"],
    ["score", "fbm3w"],
    ["score", "trajectory"],  # ROBOT_BAG is required (GT_PATH is not: evo's bag mode)
    ["score", "no_such_benchmark"],
    ["score"],
    ["noise"],
    ["acquire", "transform", "x.bag"],  # --team is required
    ["acquire", "items", "x.bag"],
    ["acquire", "no_such_member"],
    ["audit"],
    ["report", "x.json"],  # --report is required
    ["export"],
    ["record"],
    ["monitor"],
    ["clock"],
]


@pytest.mark.parametrize("argv", USAGE_COMMANDS, ids="-".join)
def test_usage_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    result = _run(argv, capsys)
    line = _check_error(result, 2, "ertools")
    assert "--help" in line  # says where to look


@pytest.mark.parametrize("argv", USAGE_COMMANDS[:-3], ids="-".join)
def test_unknown_option(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    result = _run([*argv, "--no-such-option"], capsys)
    _check_error(result, 2, "--no-such-option", "required", "invalid choice")


OUTPUT_IS_INPUT: dict[str, Callable[[Inputs], tuple[list[str], Path]]] = {
    "info -o BAG": lambda i: (["info", str(i.fbm2h), "-o", str(i.fbm2h)], i.fbm2h),
    "timeline -o BAG": lambda i: (["timeline", str(i.fbm2h), "-o", str(i.fbm2h)], i.fbm2h),
    "score fbm2h -o BAG": lambda i: (
        ["score", "fbm2h", str(i.fbm2h), "--transform", str(i.transform), "-o", str(i.fbm2h)],
        i.fbm2h,
    ),
    "score fbm2h -o TRANSFORM": lambda i: (
        ["score", "fbm2h", str(i.fbm2h), "--transform", str(i.transform), "-o", str(i.transform)],
        i.transform,
    ),
    "score fbm1h --report BAG": lambda i: (
        ["score", "fbm1h", str(i.fbm1h), "--items", str(i.items), "--report", str(i.fbm1h)],
        i.fbm1h,
    ),
    "score fbm3w --plot BAG": lambda i: (
        ["score", "fbm3w", str(i.fbm3w), "--plot", str(i.fbm3w)],
        i.fbm3w,
    ),
    "score trajectory -o GT": lambda i: (
        ["score", "trajectory", str(i.robot), *_gt(i), "-o", str(i.gt[1])],
        i.gt[1],
    ),
    "noise -o BAG": lambda i: (["noise", str(i.fbm3w), "-o", str(i.fbm3w)], i.fbm3w),
    "acquire items -o ITEMS": lambda i: (
        ["acquire", "items", str(i.fbm1h), "--items", str(i.items), "-o", str(i.items)],
        i.items,
    ),
    "audit -o BAG": lambda i: (["audit", str(i.fbm2h), "-o", str(i.fbm2h)], i.fbm2h),
    "export -o BAG": lambda i: (
        ["export", str(i.fbm3w), "--topic", "/fbm3w/robot_at_work/pose", "-o", str(i.fbm3w)],
        i.fbm3w,
    ),
}


@pytest.mark.parametrize("case", list(OUTPUT_IS_INPUT))
def test_output_onto_an_input_is_refused(
    case: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    """`-o run.bag` used to replace the bag with the score; the input must survive."""
    argv, victim = OUTPUT_IS_INPUT[case](inputs)
    result = _run(argv, capsys)  # _run also checks every input's bytes and mtime
    line = _check_error(result, 2, victim.name)
    assert "input" in line


UNWRITABLE_OUTPUT: dict[str, Callable[[Inputs], tuple[list[str], Path]]] = {
    "score fbm2h -o BAG/x.yaml": lambda i: (
        ["score", "fbm2h", str(i.fbm2h), "--transform", str(i.transform)],
        Path("-o"),
    ),
    "score fbm2h --plot BAG/plots": lambda i: (
        ["score", "fbm2h", str(i.fbm2h), "--transform", str(i.transform)],
        Path("--plot"),
    ),
    "timeline --plot BAG/t.png": lambda i: (["timeline", str(i.fbm2h)], Path("--plot")),
    "noise --plot BAG/n.png": lambda i: (["noise", str(i.fbm3w)], Path("--plot")),
    "info -o BAG/x.txt": lambda i: (["info", str(i.fbm2h)], Path("-o")),
}


@pytest.mark.parametrize("case", list(UNWRITABLE_OUTPUT))
def test_unwritable_output_path(
    case: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    """An output under a file (not a folder): one line naming it, exit 1, not "a bug"."""
    argv, flag = UNWRITABLE_OUTPUT[case](inputs)
    blocker = inputs.root / "a_file_not_a_folder.txt"
    blocker.write_text("x")
    target = blocker / case.rsplit("/", 1)[-1]
    result = _run([*argv, str(flag), str(target)], capsys)
    _check_error(result, 1, blocker.name)


@pytest.mark.slow
def test_report_onto_its_own_result_folder_is_refused(
    inputs: Inputs, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`report DIR --out DIR` used to replace the result's own index.html."""
    folder = tmp_path / "fbm2h-report"
    argv = ["score", "fbm2h", str(inputs.fbm2h), "--transform", str(inputs.transform)]
    assert _run([*argv, "--report", str(folder)], capsys).code == 0
    result = _run(
        ["report", str(folder), "--report", str(folder)], capsys
    )  # snapshot: whole folder
    assert "input" in _check_error(result, 2, folder.name)


def test_fbm2h_reached_before_the_bag(inputs: Inputs, capsys: pytest.CaptureFixture[str]) -> None:
    """`--reached timing FILE BAG` (option first) scores as `BAG --reached timing FILE`."""
    common = ["--goal", str(inputs.goal), "--transform", str(inputs.transform), "--format", "json"]
    first = _run(["score", "fbm2h", str(inputs.fbm2h), "--reached", "timing", str(inputs.timing),
                  *common], capsys)  # fmt: skip
    second = _run(["score", "fbm2h", "--reached", "timing", str(inputs.timing), str(inputs.fbm2h),
                   *common], capsys)  # fmt: skip
    assert first.code == second.code == 0 and first.out == second.out


# Every number option refuses NaN, infinities and values no unit of ertools reaches (they used
# to end in "unexpected OverflowError" or, for fbm1's --still nan, in a score).
NUMBER_OPTIONS: dict[str, Callable[[Inputs], list[str]]] = {
    "timeline --clock-tolerance": lambda i: ["timeline", str(i.fbm2h), "--clock-tolerance"],
    "fbm2h --gt-tolerance": lambda i: ["score", "fbm2h", str(i.fbm2h), "--gt-tolerance"],
    "fbm2h --stop-speed": lambda i: ["score", "fbm2h", str(i.fbm2h), "--stop-speed"],
    "fbm1h --still": lambda i: ["score", "fbm1h", str(i.fbm1h), "--items", str(i.items), "--still"],
    "fbm1h --max-window": lambda i: [
        "score", "fbm1h", str(i.fbm1h), "--items", str(i.items), "--max-window"
    ],
    "fbm3w --d-min": lambda i: ["score", "fbm3w", str(i.fbm3w), "--d-min"],
    "trajectory --offset": lambda i: ["score", "trajectory", str(i.robot), *_gt(i), "--offset"],
    "trajectory --offset-range": lambda i: [
        "score", "trajectory", str(i.robot), *_gt(i), "--offset-range"
    ],
    "noise --bin": lambda i: ["noise", str(i.fbm3w), "--bin"],
    "acquire transform --at": lambda i: [
        "acquire", "transform", str(i.fbm2h), "--team", "qa",
        "--out-dir", str(i.root / "tr"), "--at"
    ],
    "acquire items --still-min": lambda i: [
        "acquire", "items", str(i.fbm1h), "--items", str(i.items), "--still-min"
    ],
    "audit --max-silence": lambda i: ["audit", str(i.fbm2h), "--max-silence"],
}  # fmt: skip


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e300"])
@pytest.mark.parametrize("option", list(NUMBER_OPTIONS))
def test_non_finite_number_option(
    option: str, value: str, inputs: Inputs, capsys: pytest.CaptureFixture[str]
) -> None:
    result = _run([*NUMBER_OPTIONS[option](inputs), value], capsys)
    _check_error(result, 2, option.rsplit(maxsplit=1)[-1])


# ---------------------------------------------------------------------------------------------
# 8. Help: every command and member answers --help with its options and an example.


def _every_command() -> Iterator[list[str]]:
    for name, cmd in COMMANDS.items():
        yield [name]
        members = getattr(import_module(cmd.module), "members", None)
        for member in members() if members is not None else ():
            yield [name, member]


@pytest.mark.parametrize("argv", list(_every_command()), ids="-".join)
def test_help(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*argv, "--help"]) == 0
    captured = capsys.readouterr()
    assert captured.err == ""
    out = captured.out
    assert out.startswith(f"usage: ertools {' '.join(argv)}")
    assert "options:" in out and "--help" in out
    # An example: a command line of this very command.
    examples = [ln for ln in out.splitlines() if f"ertools {' '.join(argv)} " in ln]
    assert len(examples) >= 2, out  # the usage line and at least one example
    assert "example" in out.lower() or "e.g." in out
