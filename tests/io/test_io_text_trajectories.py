"""Text trajectories as pose sources (issue 26): TUM, KITTI, EuRoC ground truth, ertools' CSV.

Detected by content, forced with --input-format; values checked against evo's own readers
(an independent parser) on evo's test data, and against exact decimal arithmetic for the
stamps; a bad value is one line naming its row and column; ertools' CSV export reads back
exactly.
"""

from __future__ import annotations

import json
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

from ertools.cli.main import main
from ertools.errors import BagError
from ertools.exporting.formats import format_csv, format_tum
from ertools.io.text import _plain_decimal_ns, read_text_poses, sniff
from ertools.streams import PoseStream
from tests.helpers.stderr_text import error_messages

REPO = Path(__file__).resolve().parents[2]
EVO_DATA = REPO.parent / "shared" / "evo_testdata"


def _evo_data(name: str) -> Path:
    path = EVO_DATA / name
    if not path.exists():
        pytest.skip(f"n/a: {path} absent (evo's test data, see ../shared/evo_testdata/README.md)")
    return path


def _stream(n: int = 50, seed: int = 1) -> PoseStream:
    rng = np.random.default_rng(seed)
    t = 1_447_934_399_000_000_000 + np.cumsum(rng.integers(1, 50_000_000, n)).astype(np.int64)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    return PoseStream(t, rng.normal(size=(n, 3)) * 10, q, frame_id="wor,ld", source="x")


@pytest.mark.parametrize(
    ("name", "kind"),
    [
        ("freiburg1_xyz-groundtruth.txt", "tum"),
        ("freiburg1_xyz-rgbdslam.txt", "tum"),
        ("KITTI_00_gt.txt", "kitti"),
        ("V102_groundtruth.csv", "euroc"),
        ("ROS_example.bag", None),
    ],
)
def test_sniffed_by_content(name: str, kind: str | None) -> None:
    assert sniff(_evo_data(name)) == kind


def test_tum_as_evo_reads_it() -> None:
    pytest.importorskip("evo", reason="evo is in the dev extra")
    # lazy: evo is the dev extra's (importorskip above) and takes ~1 s to import
    from evo.tools import file_interface

    path = _evo_data("freiburg1_xyz-groundtruth.txt")
    ours = read_text_poses(path)
    evo = file_interface.read_tum_trajectory_file(str(path))
    np.testing.assert_array_equal(ours.t_s, evo.timestamps)
    np.testing.assert_array_equal(ours.xyz, evo.positions_xyz)
    np.testing.assert_array_equal(ours.quat_xyzw, np.roll(evo.orientations_quat_wxyz, -1, axis=1))
    # The nanoseconds are the decimal text exactly (no float on the way).
    rows = [ln.split()[0] for ln in path.read_text().splitlines() if not ln.startswith("#")]
    assert ours.t_ns.tolist() == [int(Decimal(r) * 10**9) for r in rows]


@pytest.mark.slow
def test_euroc_as_evo_reads_it() -> None:
    pytest.importorskip("evo", reason="evo is in the dev extra")
    # lazy: evo is the dev extra's (importorskip above) and takes ~1 s to import
    from evo.tools import file_interface

    path = _evo_data("V102_groundtruth.csv")
    ours = read_text_poses(path)
    evo = file_interface.read_euroc_csv_trajectory(str(path))
    np.testing.assert_array_equal(ours.t_s, evo.timestamps)
    np.testing.assert_array_equal(ours.xyz, evo.positions_xyz)
    np.testing.assert_array_equal(ours.quat_xyzw, np.roll(evo.orientations_quat_wxyz, -1, axis=1))
    first = path.read_text().splitlines()[1].split(",")[0]
    assert int(ours.t_ns[0]) == int(first)


@pytest.mark.slow
def test_kitti_as_evo_reads_it() -> None:
    pytest.importorskip("evo", reason="evo is in the dev extra")
    # lazy: evo is the dev extra's (importorskip above) and takes ~1 s to import
    from evo.tools import file_interface

    path = _evo_data("KITTI_00_ORB.txt")
    ours = read_text_poses(path)
    evo = file_interface.read_kitti_poses_file(str(path))
    np.testing.assert_array_equal(ours.xyz, evo.positions_xyz)
    # Rotations: the same up to the sign of the quaternion, and KITTI's rounding of R.
    dots = np.abs(np.sum(ours.quat_xyzw * np.roll(evo.orientations_quat_wxyz, -1, axis=1), 1))
    assert np.all(dots > 1 - 1e-6)
    assert ours.t_ns.tolist() == [i * 10**9 for i in range(len(ours))]


def test_csv_export_reads_back_exactly(tmp_path: Path) -> None:
    s = _stream()
    path = tmp_path / "poses.csv"
    path.write_text(format_csv(s))
    back = read_text_poses(path)
    assert back.t_ns.tolist() == s.t_ns.tolist()
    assert np.array_equal(back.xyz, s.xyz) and np.array_equal(back.quat_xyzw, s.quat_xyzw)
    assert back.frame_id == "wor,ld"  # the quoted comma undone


def test_tum_export_reads_back_exactly(tmp_path: Path) -> None:
    s = _stream(seed=2)
    path = tmp_path / "poses.tum"
    path.write_text(format_tum(s))
    back = read_text_poses(path)
    assert back.t_ns.tolist() == s.t_ns.tolist()
    assert np.array_equal(back.xyz, s.xyz) and np.array_equal(back.quat_xyzw, s.quat_xyzw)


def test_tum_stamps_in_exponent_notation(tmp_path: Path) -> None:
    """evo's own writer (np.savetxt) writes stamps as 1.305031102160407066e+09."""
    path = tmp_path / "evo.txt"
    path.write_text("1.305031102160407066e+09 1 2 3 0 0 0 1\n1.3050311022e+09 1 2 3 0 0 0 1\n")
    s = read_text_poses(path, "tum")
    assert s.t_ns.tolist() == [1_305_031_102_160_407_066, 1_305_031_102_200_000_000]


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("# c\n1.0 1 2 3 0 0 0 1\n2.0 1 2 x 0 0 0 1\n", "row 3, column 4 (z) is not a number"),
        ("1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0\n", "row 2: 7 values, a TUM row has 8"),
        ("1.0 1 2 3 0 0 0 1\n2.0 1 2 nan 0 0 0 1\n", "row 2, column 4 (z) is not a finite"),
        ("1.0 1 2 3 0 0 0 1\n2.0.1 1 2 3 0 0 0 1\n", "row 2, column 1 (t)"),
    ],
    ids=["word", "short-row", "nan", "bad-time"],
)
def test_bad_value_names_row_and_column(
    tmp_path: Path, text: str, needle: str, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "robot.tum"
    path.write_text(text)
    with pytest.raises(BagError, match=None) as err:
        read_text_poses(path)
    assert needle in str(err.value)
    # On the command line: one line, exit 1, no traceback.
    gt = tmp_path / "gt.tum"
    gt.write_text("0.5 1 2 3 0 0 0 1\n2.5 1 2 3 0 0 0 1\n")
    assert main(["score", "trajectory", str(path), str(gt)]) == 1
    err_text = capsys.readouterr().err
    lines = error_messages(err_text)
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err_text


def test_input_format_forces_the_reader(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A TUM file named .bag is still read as TUM (content decides); --input-format bag
    refuses it as a bag."""
    path = tmp_path / "robot.bag"
    path.write_text("1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0 1\n")
    gt = tmp_path / "gt.txt"
    gt.write_text("0.5 1 2 3 0 0 0 1\n2.5 1 2 4 0 0 0 1\n")
    argv = ["score", "trajectory", str(path), str(gt), "--max-gap", "5"]
    assert main([*argv, "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["compared"] == 2
    # linear GT at t=1: z = 3 + (1-0.5)/2 = 3.25; at t=2: 3.75 -> errors 0.25 and 0.75
    assert out["position_error"] == pytest.approx(0.5, abs=1e-12)
    code = main([*argv, "--input-format", "bag"])
    assert code == 1
    assert "not a ROS1 bag" in capsys.readouterr().err


@pytest.mark.slow
def test_export_converts_text(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = _evo_data("V102_groundtruth.csv")
    out = tmp_path / "v102.tum"
    assert main(["export", str(src), "--format", "tum", "-o", str(out)]) == 0
    capsys.readouterr()
    a, b = read_text_poses(src), read_text_poses(out)
    assert a.t_ns.tolist() == b.t_ns.tolist()
    assert np.array_equal(a.xyz, b.xyz) and np.array_equal(a.quat_xyzw, b.quat_xyzw)


def test_text_has_no_record_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    robot, gt = tmp_path / "robot.tum", tmp_path / "gt.tum"
    robot.write_text("1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0 1\n")
    gt.write_text("0.5 1 2 3 0 0 0 1\n2.5 1 2 4 0 0 0 1\n")
    assert main(["score", "trajectory", str(robot), str(gt), "--time-source", "record"]) == 2
    assert "TUM text trajectory: it has only its stamps" in capsys.readouterr().err


@pytest.mark.slow
def test_decimal_stamps_exact_on_random_text() -> None:
    """The vectorised decimal -> ns path against Python's Decimal, on random stamps with 0 to 9
    decimals, negative ones, and the forms it hands to Decimal (exponent, >9 decimals)."""

    rng = np.random.default_rng(26)
    tokens = []
    for k in rng.integers(0, 10, 20_000).tolist():
        whole = int(rng.integers(0, 2_000_000_000))
        sign = "-" if rng.random() < 0.1 else ""
        frac = f".{int(rng.integers(0, 10**k)):0{k}d}" if k else ""
        tokens.append(f"{sign}{whole}{frac}")
    ns, plain = _plain_decimal_ns(tokens)
    assert plain.all()
    assert ns.tolist() == [int(Decimal(t) * 10**9) for t in tokens]
    odd = ["1e9", ".5", "1.0000000001", "1.2.3", "-", "9223372036.5"]
    assert not _plain_decimal_ns(odd)[1].any()
