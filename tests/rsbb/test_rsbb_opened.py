"""A run bag opened with its side files (``ertools.rsbb.opened``), on the HOPF, HPPF and HNF
samples: what is found is said first (the team transform also for the result file's team), and
another benchmark's bag or result file is refused with one line naming both benchmarks."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import pytest

from ertools.errors import ConfigError
from ertools.rsbb.opened import open_run

SAMPLES = Path(__file__).parents[2] / "sample_bags"
HOPF = SAMPLES / "hopf" / "rsbb_logs" / "HOPF" / "simbot" / "run_1_2019-04-11-16-26-40.bag"
HNF = SAMPLES / "hnf" / "rsbb_logs" / "HNF" / "simbot" / "run_1_2019-04-10-14-31-06.bag"
HPPF_RESULT = next((SAMPLES / "hppf" / "results" / "HPPF" / "simbot").glob("result_run_1_*.yaml"))
HNF_RESULT = next((SAMPLES / "hnf" / "results" / "HNF" / "simbot").glob("result_run_1_*.yaml"))


@dataclass(frozen=True)
class Given:
    """A benchmark's side-file options, none of them given unless said."""

    config: Path | None = None
    result: Path | None = None
    transform: Path | None = None
    team: str | None = None


def test_the_side_files_are_found_and_said() -> None:
    said: list[str] = []
    opened = open_run([HOPF], "HOPF", Given(), want=("config", "items", "result"), say=said.append)
    assert opened.paths == (HOPF,)
    assert opened.result_file is not None and opened.result_file.code == "HOPF"
    assert opened.team == "simbot" and opened.transform is None
    assert [line.split(" found ")[0] for line in said] == [
        "HOPF.yaml",
        "items_with_pose.yaml",
        "the result file",
    ]


def test_outside_the_layout_the_result_files_team_finds_the_transform(tmp_path: Path) -> None:
    # a bag, its result file and transform-simbot.yaml side by side: no layout names the team
    bag = tmp_path / HNF.name
    shutil.copyfile(HNF, bag)
    shutil.copyfile(HNF_RESULT, tmp_path / HNF_RESULT.name)
    transform = SAMPLES / "hnf" / "rsbb_etc" / "transforms" / "transform-simbot.yaml"
    shutil.copyfile(transform, tmp_path / transform.name)
    said: list[str] = []
    opened = open_run([bag], "HNF", Given(), want=("transform", "result"), say=said.append)
    assert opened.side.team is None and opened.team == "simbot"
    assert opened.transform_file() == tmp_path / "transform-simbot.yaml"
    assert said == [
        f"the result file found beside the bag: {tmp_path / HNF_RESULT.name}",
        f"transform-simbot.yaml found beside the bag: {tmp_path / 'transform-simbot.yaml'}",
    ]


def test_a_given_team_and_transform_are_taken_as_given(tmp_path: Path) -> None:
    transform = tmp_path / "mine.yaml"
    transform.write_text("markerset_to_robot_transform: [[0, 0, 0], [0, 0, 0, 1]]\n")
    said: list[str] = []
    given = Given(transform=transform, team="homer")
    opened = open_run([HNF], "HNF", given, want=("transform",), say=said.append)
    assert opened.team == "homer" and opened.transform_file() == transform and said == []


def test_a_missing_transform_is_refused_when_asked_for(tmp_path: Path) -> None:
    bag = tmp_path / HNF.name
    shutil.copyfile(HNF, bag)
    opened = open_run([bag], "HNF", Given(), want=("transform",), say=print)
    assert opened.team is None and opened.transform is None
    with pytest.raises(ConfigError, match=r"^no transform-<team>\.yaml .*give --transform FILE"):
        opened.transform_file()


def test_another_benchmarks_result_file_is_refused() -> None:
    with pytest.raises(ConfigError, match=r": the result file is a HPPF run's, not HOPF's$"):
        open_run([HOPF], "HOPF", Given(result=HPPF_RESULT), want=("result",), say=print)


def test_another_benchmarks_bag_is_refused_before_anything_is_said() -> None:
    said: list[str] = []
    with pytest.raises(ConfigError, match=r"a HOPF run .*not HPPF's: ertools score hopf"):
        open_run([HOPF], "HPPF", Given(), want=("config",), say=said.append)
    assert said == []
