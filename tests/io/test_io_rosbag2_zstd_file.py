"""rosbag2 bags compressed file by file (issue 26): `ros2 bag record --compression-mode file`,
here written by `rosbags-convert --compress zstd --compress-mode file` from a bag of the
project's writer. The MCAP and the sqlite3 variant give the same `info` (but for the path,
size, compression and index lines) and the same score as the uncompressed bag, and the other
readers (`export`, `timeline`, `info --check`) read them too.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.simulator.writer import BagWriter

pytestmark = pytest.mark.slow

BIN = Path(sys.executable).parent
NS = 1_000_000_000
# What differs between a bag and its compressed copy, by construction.
CONTAINER_KEYS = {"path", "size_bytes", "compression", "index", "version"}


def _write(path: Path, fmt: str) -> None:
    t = 1_700_000_000 * NS + np.arange(0, 20 * NS, NS // 50)
    s = (t - t[0]) / NS
    gt = np.column_stack([np.cos(s / 3), np.sin(s / 3), 0 * s])
    tr = t[::5]  # at GT samples: the linear GT is the sample, the error exactly 0.02 m
    sr = (tr - t[0]) / NS
    robot = np.column_stack([np.cos(sr / 3) + 0.02, np.sin(sr / 3), 0 * sr])
    with BagWriter(path, fmt) as bag:  # type: ignore[arg-type]
        bag.write_pose_stamped("/gt", t, t, "world", gt, quat_from_yaw(s / 3))
        bag.write_pose_stamped("/robot", tr, tr, "world", robot, quat_from_yaw(sr / 3))


def _compress(src: Path, dst: Path, storage: str) -> None:
    exe = BIN / "rosbags-convert"
    if not exe.exists():
        pytest.skip("n/a: rosbags-convert not installed (rosbags is a dependency)")
    subprocess.run(
        [
            str(exe),
            "--src",
            str(src),
            "--dst",
            str(dst),
            "--dst-storage",
            storage,
            "--compress",
            "zstd",
            "--compress-mode",
            "file",
        ],
        check=True,
        capture_output=True,
        timeout=120,
    )


@pytest.fixture(scope="module", params=["mcap", "sqlite3"])
def pair(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Any:
    storage = request.param
    d = tmp_path_factory.mktemp(f"zstd_{storage}")
    plain, packed = d / "plain", d / "packed"
    _write(plain, f"rosbag2-{storage}")
    _compress(plain, packed, storage)
    meta = (packed / "metadata.yaml").read_text()
    assert "compression_mode: file" in meta and "zstd" in meta
    assert list(packed.glob("*.zstd")), "rosbags-convert wrote no compressed storage file"
    return plain, packed


def _json(capsys: pytest.CaptureFixture[str], *argv: str) -> Any:
    code = main([*argv, "--format", "json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    return json.loads(out.out)


def test_same_info(pair: Any, capsys: pytest.CaptureFixture[str]) -> None:
    plain, packed = pair
    a = _json(capsys, "info", str(plain))["bags"][0]
    b = _json(capsys, "info", str(packed))["bags"][0]
    assert b["compression"] == "zstd (file)" and b["problems"] == []
    assert {k: v for k, v in a.items() if k not in CONTAINER_KEYS} == {
        k: v for k, v in b.items() if k not in CONTAINER_KEYS
    }


def test_info_check(pair: Any, capsys: pytest.CaptureFixture[str]) -> None:
    _plain, packed = pair
    assert main(["info", "--check", str(packed)]) == 0
    assert "error" not in capsys.readouterr().err


def test_same_score(pair: Any, capsys: pytest.CaptureFixture[str]) -> None:
    plain, packed = pair
    argv = ["score", "trajectory", "--robot-topic", "/robot", "--gt-topic", "/gt"]
    a = _json(capsys, *argv[:2], str(plain), *argv[2:])
    b = _json(capsys, *argv[:2], str(packed), *argv[2:])
    assert a["compared"] == 200 and a["position_error"] == pytest.approx(0.02, abs=1e-9)
    for key in ("position_error", "rmse", "max", "compared", "orientation_error"):
        assert a[key] == b[key], key


def test_same_export_and_timeline(
    pair: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plain, packed = pair
    before = {f.name: f.read_bytes() for f in packed.iterdir()}
    outs = []
    for bag in (plain, packed):
        out = tmp_path / f"{bag.name}.csv"
        assert (
            main(["export", str(bag), "--topic", "/robot", "--format", "csv", "-o", str(out)]) == 0
        )
        outs.append(out.read_text())
        assert main(["timeline", str(bag), "--format", "json"]) == 0
    capsys.readouterr()
    assert outs[0] == outs[1] and outs[0].count("\n") == 201
    # Decompressed into a temporary folder: the bag's own files untouched, none added.
    assert {f.name: f.read_bytes() for f in packed.iterdir()} == before
