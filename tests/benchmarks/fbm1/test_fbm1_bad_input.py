"""Every bad input of issue 6: one line naming the run, the other runs still scored, exit 1."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ertools.benchmarks.fbm1.answers import parse_answer_payload
from ertools.benchmarks.fbm1.pipeline import score_fbm1
from ertools.benchmarks.fbm1.runs import runs_from_states
from ertools.cli.main import main
from ertools.configs._yaml import parse_yaml
from ertools.configs.items import ItemList, parse_items
from ertools.states import Machine
from tests.benchmarks.fbm1.fbm1_testkit import (
    ITEMS_YAML,
    RunSpec,
    bodies,
    state_streams,
    write_bag,
    write_items,
)
from tests.helpers.stderr_text import error_messages

GOOD = RunSpec(
    "Place item 3 (b2) on the table",
    "{item_class: b, item_instance: b2, x: 0.35, y: 0.25, theta: 0}",
    (0.3, 0.2, 0.03),
    0.0,
)
# Item 3 sits 5 cm along x and y of an unrotated board at (0.3, 0.2): exactly at the answer.
GOOD_SCORE = 1.0


def _run(bmbox: str = "Place item 1 (a1) on the table", answer: str | None = None) -> RunSpec:
    return RunSpec(bmbox, answer or "{item_class: a, item_instance: a1, x: 0.4, y: 0.2, theta: 0}")


BAD_CASES = {
    "not yaml": (_run(answer="{item_class: a, x: [0.1"), "answer payload is not YAML"),
    "not a mapping": (_run(answer="a a1 0.4 0.2 0"), "answer is not a YAML mapping"),
    "missing fields": (
        _run(answer="{item_class: a, item_instance: a1, x: 0.4}"),
        "answer lacks y, theta",
    ),
    "theta missing": (
        _run(answer="{item_class: a, item_instance: a1, x: 0.4, y: 0.2}"),
        "answer lacks theta",
    ),
    "theta nan": (
        _run(answer="{item_class: a, item_instance: a1, x: 0.4, y: 0.2, theta: .nan}"),
        "answer theta is nan",
    ),
    "theta text": (
        _run(answer="{item_class: a, item_instance: a1, x: 0.4, y: 0.2, theta: north}"),
        "answer theta='north' is not a number",
    ),
    "unknown item id": (_run("Place item 12 (zz) on the table"), "item id 12"),
    "unknown instance": (_run("mystery_box"), "item 'mystery_box'"),
    "no item named": (_run(""), "no item named"),
}


def _items() -> ItemList:
    return parse_items(parse_yaml(ITEMS_YAML), "items.yaml")


@pytest.mark.parametrize("case", list(BAD_CASES))
def test_bad_run_fails_alone(case: str) -> None:
    bad, message = BAD_CASES[case]
    runs = [bad, GOOD]
    streams = state_streams(runs)
    found = runs_from_states(
        streams[Machine.BMBOX], streams[Machine.REFBOX], streams[Machine.CLIENT]
    )
    origin, board = bodies(runs)
    result = score_fbm1(origin, board, found, _items())
    assert len(result.failures) == 1
    assert result.failures[0].startswith("run 1: ")
    assert message in result.failures[0]
    assert "\n" not in result.failures[0]
    r1, r2 = result.runs
    assert r1.status == "failed" and r2.status == "scored"
    # The failed run is left out of the totals; run 2 alone is exact (noiseless board).
    assert r2.pose_score == pytest.approx(GOOD_SCORE, abs=1e-9)
    assert result.totals.pose_score == pytest.approx(GOOD_SCORE, abs=1e-9)
    assert result.totals.accuracy_runs == 1


def _cli(tmp_path: Path, capsys: pytest.CaptureFixture[str], bag: Path, *extra: str) -> tuple:
    items = write_items(tmp_path / "items.yaml")
    code = main(["score", "fbm1h", str(bag), "--items", str(items), "--format", "json", *extra])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.slow
def test_cli_bad_payload_exit_1_other_run_scored(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = write_bag(tmp_path / "bad.bag", [BAD_CASES["theta nan"][0], GOOD])
    code, out, err = _cli(tmp_path, capsys, bag)
    assert code == 1
    errors = [line for line in err.splitlines() if line.startswith("ertools: error:")]
    assert errors == ["ertools: error: run 1: answer theta is nan (client payload)"]
    data = json.loads(out)
    assert data["runs"]["2"]["pose_score"] == pytest.approx(GOOD_SCORE, abs=1e-9)
    assert data["failures"] == ["run 1: answer theta is nan (client payload)"]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("body", "start", "end", "message"),
    [
        # Board lost from before the placement until after the goal (goal at 14 s).
        ("ref_board", 10.5, 14.5, "run 1: ref_board lost at t="),
        # Origin lost 0.8 s before run 1's goal and back after it.
        ("origin", 13.2, 14.3, "run 1: origin lost at t="),
    ],
)
def test_cli_body_lost_during_a_run(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    body: str,
    start: float,
    end: float,
    message: str,
) -> None:
    good_first = RunSpec(
        "Place item 1 (a1) on the table",
        "{item_class: a, item_instance: a1, x: 0.4, y: 0.2, theta: 0}",
    )
    bag = write_bag(tmp_path / "lost.bag", [good_first, GOOD], drop=[(body, start, end)])
    code, out, err = _cli(tmp_path, capsys, bag)
    assert code == 1
    errors = [line for line in err.splitlines() if line.startswith("ertools: error:")]
    assert len(errors) == 1 and message in errors[0], err
    data = json.loads(out)
    assert data["runs"]["1"]["status"] == "failed"
    assert data["runs"]["2"]["pose_score"] == pytest.approx(GOOD_SCORE, abs=1e-9)


@pytest.mark.slow
def test_board_lost_briefly_long_before_the_goal_shortens_the_window(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A 1 s occlusion 2 s before the goal: the stationary window starts after it (< 2 s),
    # the run is still scored.
    bag = write_bag(tmp_path / "occl.bag", [GOOD], drop=[("ref_board", 11.0, 12.0)])
    code, out, err = _cli(tmp_path, capsys, bag)
    assert code == 0, err
    gt = json.loads(out)["runs"]["1"]["ground_truth"]
    start, end = gt["window_s"]
    assert 12.0 < start < 12.1 and end == pytest.approx(14.0, abs=0.01)


@pytest.mark.parametrize("body", ["origin", "ref_board"])
def test_cli_body_missing_from_the_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str
) -> None:
    bag = write_bag(tmp_path / "missing.bag", [GOOD], omit=[body])
    code, out, err = _cli(tmp_path, capsys, bag)
    assert code == 1 and out == ""
    lines = error_messages(err)
    assert len(lines) == 1 and all(
        ln.startswith(("ertools: error:", "  ")) for ln in err.splitlines()
    )
    assert f"/fbm1h/{body}/pose" in lines[0] and f"tf world:{body}" in lines[0]


@pytest.mark.slow
def test_results_file_replaces_payloads_and_bad_entry_fails_its_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = write_bag(tmp_path / "res.bag", [BAD_CASES["not yaml"][0], GOOD])
    results = tmp_path / "results.yaml"
    # Run 1 answered through the file (x off by 0.05 m); item 3 (run 2) with theta missing.
    results.write_text(
        "- {run: 1, item_class: a, item_instance: a1, x: 0.436602540378444, y: 0.2, theta: 0}\n"
        "- {item: 3, item_class: b, item_instance: b2, x: 0.35, y: 0.25}\n",
        encoding="utf-8",
    )
    code, out, _err = _cli(tmp_path, capsys, bag, "--results", str(results))
    assert code == 1
    data = json.loads(out)
    # Run 1: item 1 sits at (0.4, 0.2) (0.1 m along the unrotated board at (0.3, 0.2)).
    assert data["runs"]["1"]["error"]["x"] == pytest.approx(0.036602540378444, abs=1e-9)
    assert data["failures"] == [f"run 2: answer lacks theta ({results})"]
    assert not math.isnan(data["pose_score"])


@pytest.mark.slow
def test_empty_payload_fixed_by_items_order(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    no_name = RunSpec("", GOOD.answer, GOOD.board_xyz, GOOD.board_yaw_deg)
    bag = write_bag(tmp_path / "order.bag", [no_name])
    code, out, err = _cli(tmp_path, capsys, bag)
    assert code == 1 and "run 1: no item named" in err
    code, out, err = _cli(tmp_path, capsys, bag, "--items-order", "3")
    assert code == 0, err
    assert json.loads(out)["runs"]["1"]["pose_score"] == pytest.approx(GOOD_SCORE, abs=1e-9)


@pytest.mark.slow
def test_bad_item_list_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_bag(tmp_path / "x.bag", [GOOD])
    items = write_items(tmp_path / "vanilla.yaml", "items:\n- {class: a, id: 1, instance: a1}\n")
    code = main(["score", "fbm1h", str(bag), "--items", str(items)])
    out, err = capsys.readouterr()
    assert code == 1 and out == ""
    assert err.count("\n") == 1 and "missing 'trans'" in err and "acquire items" in err


def test_numbers_yaml_reads_as_text_are_accepted() -> None:
    a = parse_answer_payload(
        "{item_class: a, item_instance: a1, x: 4e-1, y: '0.2', theta: 1e1}", "run 1"
    )
    assert (a.x, a.y, a.theta_deg) == (0.4, 0.2, 10.0)


@pytest.mark.slow
def test_no_client_topic_needs_results(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_bag(tmp_path / "noclient.bag", [GOOD], no_client=True)
    code, out, err = _cli(tmp_path, capsys, bag)
    assert code == 1 and out == "" and err.count("\n") == 1
    assert "no /fbm1h/client_state" in err and "--results" in err
    results = tmp_path / "r.yaml"
    results.write_text(
        "- {run: 1, item_class: b, item_instance: b2, x: 0.35, y: 0.25, theta: 0}\n", "utf-8"
    )
    code, out, err = _cli(tmp_path, capsys, bag, "--results", str(results))
    assert code == 0, err
    assert json.loads(out)["pose_score"] == pytest.approx(GOOD_SCORE, abs=1e-9)
