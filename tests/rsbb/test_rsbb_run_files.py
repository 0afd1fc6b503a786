"""A run bag opened with its side files (``ertools.rsbb.run_files``), on the HOPF and HPPF
samples: what is found is said first, and another benchmark's bag or result file is refused
with one line naming both benchmarks."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.errors import ConfigError
from ertools.rsbb.run_files import open_run

SAMPLES = Path(__file__).parents[2] / "sample_bags"
HOPF = SAMPLES / "hopf" / "rsbb_logs" / "HOPF" / "simbot" / "run_1_2019-04-11-16-26-40.bag"
HPPF_RESULT = next((SAMPLES / "hppf" / "results" / "HPPF" / "simbot").glob("result_run_1_*.yaml"))


def test_the_side_files_are_found_and_said() -> None:
    said: list[str] = []
    opened = open_run([HOPF], "HOPF", want=("config", "items", "result"), say=said.append)
    assert opened.paths == (HOPF,)
    assert opened.result_file is not None and opened.result_file.code == "HOPF"
    assert [line.split(" found ")[0] for line in said] == [
        "HOPF.yaml",
        "items_with_pose.yaml",
        "the result file",
    ]


def test_another_benchmarks_result_file_is_refused() -> None:
    with pytest.raises(ConfigError, match=r": the result file is a HPPF run's, not HOPF's$"):
        open_run([HOPF], "HOPF", want=("result",), say=print, result=HPPF_RESULT)


def test_another_benchmarks_bag_is_refused_before_anything_is_said() -> None:
    said: list[str] = []
    with pytest.raises(ConfigError, match=r"a HOPF run .*not HPPF's: ertools score hopf"):
        open_run([HOPF], "HPPF", want=("config",), say=said.append)
    assert said == []
