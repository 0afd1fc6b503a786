"""The referee-scored RSBB benchmarks: a task run's items, tally, time and end read back from
its simulated bag, the numbers worked out here by hand; a scripted run's items from its result
file; the description's order; bad input in one line."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
import yaml

from ertools.benchmarks import registry
from ertools.benchmarks.base import Audited, Described, Discovered, Reported, Simulated, offers
from ertools.cli.main import main
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_task import COMPLETED, STOPPED, TIMED_OUT, TaskScenario, write_task_run
from tests.helpers.rsbb_replay.scenarios import T0, at, hnf_scenario
from tests.helpers.stderr_text import error_messages

pytestmark = pytest.mark.slow  # each writes and reads a run bag (~0.5 s)

ITEMS = (
    {"group_name": "Achievements", "desc": "door", "type": "bool", "current_value": 1},
    {"group_name": "Achievements", "desc": "furniture", "type": "uint", "current_value": 3},
    {"group_name": "Penalized Behaviors", "desc": "bumps", "type": "uint", "current_value": 2},
    {"group_name": "Disqualifying Behaviors", "desc": "hits", "type": "uint", "current_value": 0},
)


def _task(**changes: object) -> TaskScenario:
    # executing from 2 s to 30 s (robot done), then started again 35-40 s: 33 s in all
    sc = TaskScenario(
        "HGTKMH",
        "teamA",
        1,
        T0,
        ((at(2.0), at(30.0)), (at(35.0), at(40.0))),
        COMPLETED,
        at(45.0),
        at(50.0),
        ITEMS,
    )
    return replace(sc, **changes)  # type: ignore[arg-type]


def _score(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict, str]:  # type: ignore[type-arg]
    code = main(["score", *argv, "--format", "json"])
    out = capsys.readouterr()
    return code, (json.loads(out.out) if out.out else {}), out.err


def test_a_task_run_is_its_items_added_up(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = write_task_run(tmp_path, _task())
    code, score, err = _score(capsys, "hgtkmh", str(bag))
    assert code == 0, err
    assert (score["team"], score["run"]) == ("teamA", 1)  # from the RSBB folder and name
    assert score["achievements"] == 1 + 3  # a bool counts 1, a count its value
    assert score["penalized_behaviors"] == 2
    assert score["disqualifying_behaviors"] == [] and score["status"] == "scored"
    # the GUI ticks are 0.1 s apart from 0.36 s: the spans read 2.06-30.06 and 35.06-40.06
    assert score["execution_time"] == pytest.approx(33.0, abs=1e-9)
    assert score["end"] == COMPLETED
    assert score["erl_rank"] == pytest.approx(4 - 2 / 1000 - 33.0 / 1e7, abs=1e-12)
    assert [i["value"] for i in score["items"]] == [1, 3, 2, 0]
    assert "/core/to_gui" in score["items_source"]


def test_a_disqualified_run_and_a_timeout(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    items = (*ITEMS[:3], {**ITEMS[3], "current_value": 1})
    bag = write_task_run(
        tmp_path, _task(items=items, spans=((at(2.0), at(12.0)),), end_state=TIMED_OUT)
    )
    code, score, err = _score(capsys, "hgtkmh", str(bag))
    assert code == 0, err
    assert score["status"] == "disqualified" and score["disqualifying_behaviors"] == ["hits"]
    assert score["execution_time"] == pytest.approx(10.0, abs=1e-9)
    assert score["end"] == TIMED_OUT
    assert "disqualified: hits" in err


def test_values_entered_before_the_end_are_the_last_ones(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the referee entered the values at 20 s, while the robot still ran; stopped at 25 s
    bag = write_task_run(
        tmp_path,
        _task(spans=((at(2.0), at(25.0)),), end_state=STOPPED, t_scored_ns=at(20.0)),
    )
    _, score, _ = _score(capsys, "hgtkmh", str(bag))
    assert score["achievements"] == 4 and score["end"] == STOPPED


def test_the_description_orders_the_items(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = write_task_run(tmp_path, _task())
    description = tmp_path / "benchmarks_description.yaml"
    description.write_text(
        yaml.safe_dump(
            {
                "benchmarks_description": [
                    {
                        "code": "HGTKMH",
                        "desc": "Task Benchmark 1",
                        "scripted": False,
                        "timeout": 600.0,
                        "scoring": [
                            {"Penalized Behaviors": [{"type": "uint", "desc": "bumps"}]},
                            {
                                "Achievements": [
                                    {"type": "uint", "desc": "furniture"},
                                    {"type": "bool", "desc": "door"},
                                    {"type": "bool", "desc": "window"},
                                ]
                            },
                        ],
                    }
                ]
            }
        )
    )
    code, score, err = _score(capsys, "hgtkmh", str(bag), "--description", str(description))
    assert code == 0, err
    assert [(i["desc"], i["value"]) for i in score["items"]] == [
        ("bumps", 2),
        ("furniture", 3),
        ("door", 1),
        ("window", 0),  # not in the log: counted 0, said
        ("hits", 0),  # not in the description: kept, said
    ]
    assert "item not in the log, counted 0: Achievements: window" in err
    assert "item not in the description, kept: Disqualifying Behaviors: hits" in err


def test_a_scripted_run_takes_its_result_files_items(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    referee = (
        {"group_name": "Penalized Behaviors", "desc": "bumps", "current_value": 3, "type": "uint"},
    )
    sc = replace(hnf_scenario(), code="STB", referee_score=referee)
    paths = write_rsbb_run(tmp_path, sc)
    code, score, err = _score(capsys, "stb", str(paths.bag), "--result", str(paths.result))
    assert code == 0, err
    assert score["penalized_behaviors"] == 3 and score["achievements"] == 0
    # the RefBox's EXECUTING_BENCHMARK at 2 s to its END at 55 s
    assert score["execution_time"] == pytest.approx(53.0, abs=1e-9)
    assert score["end"] == "END: benchmark ended normally"
    assert "result file" in score["items_source"]


def test_bad_input_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_task_run(tmp_path, _task())
    code, _, err = _score(capsys, "hwv", str(bag))  # an HGTKMH run given to hwv
    (line,) = error_messages(err)
    assert code == 1 and "is a HGTKMH run" in line and "Traceback" not in err
    bare = tmp_path / "elsewhere.bag"
    bare.write_bytes(bag.read_bytes())
    code, _, err = _score(capsys, "hwv", str(bare))  # no HWV zone in its GUI messages
    (line,) = error_messages(err)
    assert code == 1 and "no /core/to_gui message shows HWV" in line


@pytest.mark.parametrize("option", ["--plot", "--plots", "--foxglove"])
def test_no_figures_or_foxglove_are_offered(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str
) -> None:
    """Nothing is drawn from referee items: the option is refused before any work, not after
    the score was written (an empty figure, a late --foxglove error)."""
    bag = write_task_run(tmp_path, _task())
    out = tmp_path / "score.json"
    code = main(["score", "hgtkmh", str(bag), "-o", str(out), option, str(tmp_path / "x")])
    assert code == 2 and not out.exists()
    assert f"unrecognized arguments: {option}" in capsys.readouterr().err


SAMPLES = Path(__file__).resolve().parents[3] / "sample_bags"


@pytest.mark.parametrize("name", ["hgtkmh", "hwv", "hcfgac", "stb"])
def test_the_four_are_declared_on_the_protocols(name: str) -> None:
    """Each is its own object of the parts it fills: described, reported (but drawing nothing),
    ranked, simulated in the season sample; not audited (the referee's score is not
    recomputed)."""
    bench = registry.get(name)
    assert all(isinstance(bench, p) for p in (Described, Reported, Discovered, Simulated))
    assert not isinstance(bench, Audited)
    assert not offers(bench, "figures") and not offers(bench, "foxglove")
    assert offers(registry.get("fbm3w"), "figures") and offers(registry.get("fbm3w"), "foxglove")
    assert bench.make_options({"run": 2}).code == name.upper()
    assert isinstance(bench, Simulated)
    # the season sample (committed) has runs of every referee-scored benchmark
    args = bench.sample_args(SAMPLES)
    assert args is not None and f"/rsbb_logs/{name.upper()}/" in Path(args[0]).as_posix()
