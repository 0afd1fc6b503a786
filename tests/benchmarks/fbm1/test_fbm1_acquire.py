"""`ertools acquire items`: a Listing 9 round trip through a simulated acquisition log.

Truth: three items with known transforms T_board_item. For each, the referee puts the board so
that the item stands exactly at the table origin: T_origin_board = T_board_item^-1. The board
waits beside the table (far from the origin) before and after, and moves for 1 s between
placements of 3 s. Mocap noise 0.2 mm / 0.5 mrad per body.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from ertools.cli.main import main
from ertools.configs.items import load_items
from ertools.simulator.mocap import MocapNoise, frame_times, publish_mocap, simulate_mocap
from ertools.simulator.writer import BagWriter

S = 1_000_000_000
T0 = 1_448_030_000 * S
TABLE_XYZ = np.array([1.0, 2.0, 0.7])
TABLE_ROT = Rotation.from_euler("z", 30, degrees=True)
# (id, class, instance, trans, (roll, pitch, yaw) deg)
ITEMS = [
    (1, "a", "a1", (0.03, 0.04, 0.001), (0.2, -0.3, -20.0)),
    (2, "Bearing Boxes ", "AX-16", (-0.02, -0.25, -0.01), (0.0, 0.0, 0.0)),
    (3, "c", "c1", (0.0, 0.1, 0.0), (0.5, 0.1, 45.0)),
]
# Keyframes (seconds, pose index): -1 = beside the table, k = item k at the origin.
KEYS = [(0.0, -1), (2.0, -1), (3.0, 0), (6.0, 0), (7.0, 1), (10.0, 1), (11.0, 2), (14.0, 2)]
KEYS += [(15.0, -1), (16.0, -1)]
SIGMA_M, SIGMA_RAD = 2e-4, 5e-4


def _origin_board(k: int) -> tuple[np.ndarray, Rotation]:
    """T_origin_board while item k is at the origin (or the board beside the table)."""
    if k < 0:
        return np.array([1.5, 0.0, 0.0]), Rotation.identity()
    _, _, _, trans, rpy = ITEMS[k]
    r_bi = Rotation.from_euler("xyz", rpy, degrees=True)
    r_ob = r_bi.inv()
    return -r_ob.apply(np.asarray(trans)), r_ob


def _write_log(path: Path, vanilla: Path) -> None:
    t = frame_times(T0, 16.0)
    secs = (t - T0) / S
    key_t = np.array([k[0] for k in KEYS])
    key_p, key_r = zip(*(_origin_board(k[1]) for k in KEYS), strict=True)
    p_ob = np.column_stack([np.interp(secs, key_t, np.array(key_p)[:, i]) for i in range(3)])
    r_ob = Slerp(key_t, Rotation.concatenate(key_r))(np.clip(secs, 0, key_t[-1]))
    p_wb = TABLE_ROT.apply(p_ob) + TABLE_XYZ
    r_wb = TABLE_ROT * r_ob
    rng = np.random.default_rng(7)
    noise = MocapNoise(sigma_m=SIGMA_M, sigma_rad=SIGMA_RAD)
    n = t.size
    table = simulate_mocap(
        t, np.tile(TABLE_XYZ, (n, 1)), np.tile(TABLE_ROT.as_quat(), (n, 1)), rng=rng, noise=noise
    )
    board = simulate_mocap(t, p_wb, r_wb.as_quat(), rng=rng, noise=noise)
    with BagWriter(path, "ros1") as bag:
        publish_mocap(bag, "fbm1h", "origin", table)
        publish_mocap(bag, "fbm1h", "ref_board", board)
    vanilla.write_text(
        "items:\n"
        + "".join(
            f"- class: '{c}'\n  id: {i}\n  instance: {inst}\n  rot: [0, 0, 0, 1]\n"
            "  trans: [0, 0, 0]\n"
            for i, c, inst, _, _ in ITEMS
        ),
        encoding="utf-8",
    )


# Mean of 240 to 310 samples; per sample ~0.3 mm (two bodies, 0.5 mrad at up to 0.25 m): standard
# error ~0.02 mm; 0.2 mm is 10 standard errors. Rotation: 0.7 mrad / sqrt(300) ~ 0.002 deg.
TOL_M = 2e-4
TOL_DEG = 0.02


def _check(path: Path) -> None:
    got = load_items(path)
    for (item_id, cls, inst, trans, rpy), item in zip(ITEMS, got.items, strict=True):
        assert (item.id, item.item_class, item.instance) == (item_id, cls, inst)
        assert item.trans == pytest.approx(trans, abs=TOL_M)
        r_true = Rotation.from_euler("xyz", rpy, degrees=True)
        assert item.rot is not None
        angle = (r_true.inv() * Rotation.from_quat(item.rot)).magnitude()
        assert math.degrees(angle) < TOL_DEG
        assert item.spread is not None and item.spread.samples >= 230  # >= 2 s at 120 Hz
        # Spread: per-sample scatter, ~0.3 mm; anything above 1 mm would mean motion.
        assert 5e-5 < item.spread.position_m < 1e-3


@pytest.mark.slow
def test_acquire_found_phases_round_trip(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, vanilla, out = tmp_path / "acq.bag", tmp_path / "vanilla.yaml", tmp_path / "fbm1h.yaml"
    _write_log(bag, vanilla)
    code = main(["acquire", "items", str(bag), "--items", str(vanilla), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    _check(out)
    # Found windows: the three 3 s placements, trimmed 0.2 s at both ends.
    windows = [i.spread for i in load_items(out).items]
    for w, start in zip(windows, (3.0, 7.0, 11.0), strict=True):
        assert w is not None
        assert w.start_s == pytest.approx(start + 0.2, abs=0.02)
        assert w.end_s == pytest.approx(start + 3.0 - 0.2, abs=0.02)
    assert "differs from 2015" in err


def test_acquire_given_windows(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag, vanilla, out = tmp_path / "acq.bag", tmp_path / "vanilla.yaml", tmp_path / "fbm1h.yaml"
    _write_log(bag, vanilla)
    code = main(
        [
            "acquire",
            "items",
            str(bag),
            "--items",
            str(vanilla),
            "--windows",
            "3.5:5.5,7.5:9.5,11.5:13.5",
            "-o",
            str(out),
        ]
    )
    assert code == 0, capsys.readouterr().err
    _check(out)


def test_acquire_wrong_number_of_phases(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag, vanilla = tmp_path / "acq.bag", tmp_path / "vanilla.yaml"
    _write_log(bag, vanilla)
    code = main(["acquire", "items", str(bag), "--items", str(vanilla), "--still-min", "3.5"])
    out, err = capsys.readouterr()
    assert code == 1 and out == ""
    assert "found 0 still phase(s)" in err and "--windows" in err and err.count("\n") == 1


def test_acquire_window_without_tracking_fails_that_item(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, vanilla = tmp_path / "acq.bag", tmp_path / "vanilla.yaml"
    _write_log(bag, vanilla)
    code = main(
        [
            "acquire",
            "items",
            str(bag),
            "--items",
            str(vanilla),
            "--windows",
            "3.5:5.5,7.5:9.5,20:22",
        ]
    )
    out, err = capsys.readouterr()
    assert code == 1
    assert "ertools: error: item 3 (c1): origin not tracked" in err
    # Items 1 and 2 are still acquired and written; item 3 keeps its placeholders.
    assert out.count("spread:") == 2


def test_acquire_no_item_measured_prints_only_the_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, vanilla, out_file = tmp_path / "acq.bag", tmp_path / "vanilla.yaml", tmp_path / "o.yaml"
    _write_log(bag, vanilla)
    argv = ["acquire", "items", str(bag), "--items", str(vanilla), "-o", str(out_file)]
    # the log ends at 16 s: the first window runs past it, the others lie after it (one
    # window inside the log, so the list is not refused as a whole)
    code = main([*argv, "--windows", "15.5:20,17:18,18:19"])
    out, err = capsys.readouterr()
    assert code == 1 and out == "" and not out_file.exists()  # not the vanilla list back
    lines = err.splitlines()
    assert [x.split(":")[2].strip() for x in lines] == [
        "item 1 (a1)",
        "item 2 (AX-16)",
        "item 3 (c1)",
    ]
    assert all(x.startswith("ertools: error: ") for x in lines)
