"""The generated timeline folder, shared by the timeline tests."""

from __future__ import annotations

from typing import Any

import pytest
import yaml

from ertools.samples.timeline_folder import generate


@pytest.fixture(scope="session")
def folder(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """``root`` (the bags folder) and ``answers`` of the ``timeline`` scenario."""

    out = tmp_path_factory.mktemp("timeline")
    root, answers = generate(out, seed=0)
    return {"root": root, "answers": yaml.safe_load(answers.read_text(encoding="utf-8"))}
