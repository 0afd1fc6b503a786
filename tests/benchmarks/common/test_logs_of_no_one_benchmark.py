"""Logs that are not one benchmark's own: a benchmarking box's state log given alone (the 2015
layout: states in one file, the mocap logger's poses in its own) asks for the mocap files, not
for a pose topic among none; a mocap logger's file of every arena is named so."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.cli.main import main
from tests.helpers.bagmaker import Spec, write
from tests.helpers.stderr_text import joined_lines

ROOT = Path(__file__).resolve().parents[3]

ITEMS = ROOT / "sample_bags" / "fbm1h" / "fbm1h.yaml"


def _state_log(tmp_path: Path, ns: str) -> Path:
    spec = Spec()
    for machine in ("BmBox", "RefBox", "Client"):
        state = spec.conn(f"/{ns}/{machine.lower()}_state", f"rockin_scoring/{machine}State")
        for i in range(5):
            spec.add(state, 1_448_020_800_000_000_000 + i * 100_000_000, state=0, payload="")
    return write(tmp_path / f"log_{ns}_2015-11-20-12-00-00_0.bag", "ros1", spec)


@pytest.mark.parametrize("ns", ["fbm2h", "fbm3w"])
def test_a_state_log_alone_asks_for_the_mocap_files(
    ns: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = _state_log(tmp_path, ns)
    assert main(["score", ns, str(bag)]) == 1
    (message,) = joined_lines(capsys.readouterr().err)
    assert message.startswith(f"ertools: error: {bag}: no ")
    assert "give the mocap logger's files too, as further BAGs" in message
    assert "choose one with" not in message


def test_fbm1_states_without_a_run_say_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """FBM1 finds its runs first: none (the box never left its first state) is one line, not
    an 'unexpected ValueError ... this is a bug'."""
    bag = _state_log(tmp_path, "fbm1h")
    assert main(["score", "fbm1h", str(bag), "--items", str(ITEMS)]) == 1
    (message,) = joined_lines(capsys.readouterr().err)
    assert message == (
        f"ertools: error: {bag}: /fbm1h/bmbox_state: no run found (the benchmarking box sent "
        "no goal in 5 state messages)"
    )


def _mocap_log(tmp_path: Path) -> Path:
    """A mocap logger's file recording every arena (the sample competition's gtlogger)."""
    spec = Spec()
    poses = [
        spec.conn(f"/{ns}/{body}/pose", "geometry_msgs/PoseStamped")
        for ns, body in (("fbm1h", "origin"), ("fbm2h", "robot_at_home"), ("fbm3w", "robot"))
    ]
    for i in range(5):
        t = 1_448_020_800_000_000_000 + i * 100_000_000
        for c in poses:
            spec.add(c, t, stamp=t, frame="world", xyz=(i, 0.0, 0.0), q=(0.0, 0.0, 0.0, 1.0))
    return write(tmp_path / "log_mocap_2015-11-20-08-59-58_0.bag", "ros1", spec)


@pytest.mark.parametrize(
    ("name", "advice"),
    [
        ("fbm1w", "give it after the benchmark's own log (ertools score fbm1w LOG MOCAP...), "),
        ("trajectory", "give it as GT_PATH after the ROBOT_BAG: ertools score trajectory "),
    ],
)
def test_a_mocap_log_of_several_benchmarks_is_named_so(
    name: str, advice: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Not 'this looks like an FBM1@Home log' because /fbm1h/ has a topic more than the rest."""
    bag = _mocap_log(tmp_path)
    assert main(["score", name, str(bag)]) == 1  # the file, not the command line
    (message,) = joined_lines(capsys.readouterr().err)
    assert message.startswith(
        f"ertools: error: {bag}: this log holds the poses of several benchmarks (/fbm1h/..., "
        "/fbm2h/..., /fbm3w/...), as a mocap logger's file does"
    )
    assert advice in message and "ROBOT_BAG MOCAP..." in message


SAMPLES = ROOT / "sample_bags"
ROBOT = SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"


@pytest.mark.parametrize(("gt", "warned"), [("fbm3w", True), ("robotlog", False)])
def test_trajectory_gt_of_the_other_arena_is_said(
    gt: str, warned: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    """An FBM2@Home robot log against a folder of FBM3@Work mocap files (both arenas record at
    once at a venue, so their times overlap): scored as asked, with a warning naming both."""
    assert main(["score", "trajectory", str(ROBOT), str(SAMPLES / gt), "--draws", "0"]) == 0
    err = capsys.readouterr().err
    said = (
        "ertools: warning: the robot log's name says fbm2h, but the GT /fbm3w/robot_at_work/pose "
        "is the FBM3@Work arena's: check GT_PATH (or --gt-topic)"
    )
    assert (said in err) == warned, err
    assert ("the robot log's name says" in err) == warned
