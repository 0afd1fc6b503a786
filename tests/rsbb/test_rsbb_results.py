"""ertools.rsbb.results: result files as Python 2 PyYAML wrote them, the live score's forms."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta
from pathlib import Path

import pytest

from ertools.errors import ConfigError
from ertools.rsbb.results import load_result, parse_live_score, parse_result_time

# A result file as the 2019 BmBox wrote it for HNF (yaml.dump, default_flow_style=False,
# Python 2: a non-ASCII team comment would carry !!python/unicode, the transform a tuple).
RESULT = """benchmark_info:
  benchmark_code: HNF
  end_description: 'END: benchmark ended normally'
  end_time: 2019-04-10_14:40:01_WEST(+0100)
  params:
    goal_timeout: 120.0
    starting_pose:
    - 0.0
    - 0.0
    - 0.0
    waypoints:
    - - -2.125
      - -1.607
      - 1.558
  run: 2
  start_time: 2019-04-10_14:31:05_WEST(+0100)
  team: !!python/unicode 'Équipe'
referee_score:
- current_value: 1
  desc: The robot bumps into the furniture or people.
  group_name: Penalized Behaviors
  type: uint
score:
  execution_time[s]: 41.2
  orientation_accuracy[rad]: null
  segment_1:
    robot_pose: 'null

      ...

      '
    target_pose: '!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D

      state: [-2.125, -1.607, 1.558]

      '
    timeout: null
  transform: !!python/tuple [1, 2]
"""


def test_a_result_file_with_python_2_tags(tmp_path: Path) -> None:
    path = tmp_path / "result_run_2_2019-04-10_14:31:05_WEST(+0100).yaml"
    path.write_text(RESULT, encoding="utf-8")
    r = load_result(path)
    assert (r.code, r.team, r.run) == ("HNF", "Équipe", 2)
    assert r.end_description == "END: benchmark ended normally"
    assert r.params["waypoints"] == [[-2.125, -1.607, 1.558]]
    assert r.score["segment_1"]["robot_pose"] == "null\n...\n"
    assert r.score["segment_1"]["target_pose"].startswith("!!python/object/new:")
    assert r.score["transform"] == [1, 2]
    assert r.referee_score is not None and r.referee_score[0]["current_value"] == 1


def test_other_python_tags_and_bad_layouts_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "r.yaml"
    path.write_text(
        "benchmark_info: {benchmark_code: HNF, team: a, run: 1}\n"
        "score: !!python/object/apply:os.system ['true']\n"
    )
    with pytest.raises(ConfigError, match="not readable RSBB YAML"):
        load_result(path)
    path.write_text("score: {}\n")
    with pytest.raises(ConfigError, match="no benchmark_info"):
        load_result(path)
    path.write_text("benchmark_info: {benchmark_code: HNF, team: a, run: one}\n")
    with pytest.raises(ConfigError, match="not an integer"):
        load_result(path)
    path.write_text("benchmark_info: {benchmark_code: HNF, team: a, run: 1}\nscore: [1]\n")
    with pytest.raises(ConfigError, match="not a mapping"):
        load_result(path)
    r = load_result(
        _write(tmp_path, "benchmark_info: {benchmark_code: STB, team: a, run: 1, params: None}\n")
    )
    assert r.score == {} and r.params is None and r.referee_score is None


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "ok.yaml"
    p.write_text(text)
    return p


def test_live_score_forms() -> None:
    old = parse_live_score(5, "benchmark_info: {run: 1}\nscore:\n  a: 1\n")
    assert not old.summary_form and old.result == {"benchmark_info": {"run": 1}, "score": {"a": 1}}
    new = parse_live_score(
        6, "benchmark_info: {run: 1}\nscore:\n  g: {x: 2}\n\n\nSCORE SUMMARY:\na: 1\n"
    )
    assert new.summary_form and new.result is not None
    assert new.result["score"] == {"g": {"x": 2}, "a": 1}
    assert parse_live_score(7, "{unclosed").result is None


def test_result_times() -> None:
    t = parse_result_time("2017-12-14_20:37:46_WET(+0000)")
    assert t == datetime(2017, 12, 14, 20, 37, 46, tzinfo=UTC)
    t = parse_result_time("2019-04-10_14:31:05_WEST(+0100)")
    assert t is not None and t.utcoffset() == timedelta(hours=1)
    assert parse_result_time("2019-04-10-14-31-05") is None
