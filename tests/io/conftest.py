"""Fixtures of the reader tests: a small known scene written in every format."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.helpers.bagmaker import FORMATS, bag_name, write
from tests.helpers.scene import Scene, make_scene


@pytest.fixture(scope="session")
def scene() -> Scene:
    return make_scene()


@pytest.fixture(scope="session", params=FORMATS)
def scene_bag(
    request: pytest.FixtureRequest, scene: Scene, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, Path]:
    fmt = str(request.param)
    d = tmp_path_factory.mktemp(fmt)
    # Small chunks so the scene spans several chunks (ROS1 and MCAP).
    return fmt, write(bag_name(d, fmt), fmt, scene.spec, chunk_bytes=2000)
