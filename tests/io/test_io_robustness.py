"""Damaged files never escape as anything but an ErtoolsError (one line in the CLI)."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np
import pytest

from ertools.errors import ErtoolsError
from ertools.io.info import describe
from ertools.io.reader import read_poses, read_states, read_tf
from tests.helpers.bagmaker import bag_name, write
from tests.helpers.scene import Scene

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "mcap-cdr", "rosbag2-sqlite3"])
def test_cut_or_flipped_bytes_give_ertools_errors(
    tmp_path: Path, scene: Scene, fmt: str, caplog: pytest.LogCaptureFixture
) -> None:
    good = write(bag_name(tmp_path, fmt, "good"), fmt, scene.spec, chunk_bytes=2000)
    rng = np.random.default_rng(11)
    for k in range(10):
        if good.is_dir():
            path = tmp_path / f"case{k}"
            shutil.copytree(good, path)
            target = next(x for x in path.iterdir() if x.suffix in (".db3", ".mcap"))
        else:
            path = tmp_path / f"case{k}{good.suffix}"
            shutil.copy(good, path)
            target = path
        data = bytearray(target.read_bytes())
        if k % 2:
            data = data[: int(rng.integers(1, len(data)))]  # cut anywhere
        else:
            for at in rng.integers(0, len(data), 4):  # flip a few bytes anywhere
                data[int(at)] ^= 0xA5
        target.write_bytes(bytes(data))
        with caplog.at_level(logging.CRITICAL, logger="ertools"):
            for read in (
                lambda p=path: read_poses(p, "/fbm3w/robot_at_work/pose"),
                lambda p=path: read_tf(p, "world", "robot_at_work"),
                lambda p=path: read_states(p, "/fbm3w/bmbox_state"),
                lambda p=path: describe(p, check=True),
            ):
                try:
                    read()
                except ErtoolsError as err:
                    assert str(err)  # a message, never an empty one
