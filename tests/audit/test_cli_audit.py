"""``ertools audit`` end to end on a bag written from hand-built state streams."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ertools.cli.main import main
from ertools.simulator.writer import BagWriter
from ertools.states import Machine
from tests.helpers.audit_streams import BMBOX, CLIENT, REFBOX, T0_NS, heartbeat, write_bag
from tests.helpers.stderr_text import error_messages, joined_lines


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    return write_bag(
        tmp_path / "fbm2h_states.bag",
        [
            heartbeat(Machine.BMBOX, BMBOX, 20.0, drop=(5.0, 7.0), topic="/fbm2h/bmbox_state"),
            heartbeat(Machine.REFBOX, REFBOX, 20.0, topic="/fbm2h/refbox_state"),
            heartbeat(Machine.CLIENT, CLIENT, 20.0, topic="/fbm2h/client_state"),
        ],
    )


def test_audit_json_from_bag(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["audit", str(bag), "--format", "json", "--no-rescore"])
    out = capsys.readouterr()
    assert code == 0, out.err
    data = json.loads(out.out)
    assert data["benchmark"] == "fbm2h"  # inferred from the topics' namespace
    assert data["start"] == pytest.approx(T0_NS / 1e9, abs=1e-6)
    assert [(x["from"], x["to"]) for x in data["illegal_transitions"]] == [
        ("EXECUTING_GOAL", "TRANSMITTING_GOAL")
    ]
    assert data["silences"][0]["duration"] == pytest.approx(2.0, abs=1e-9)
    assert data["early_ends"][0]["reason"] == "timeout"
    assert [r["outcome"] for r in data["runs"].values()] == ["completed", "timeout"]


@pytest.mark.slow
def test_audit_text_report_and_strict(
    bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = tmp_path / "report"
    code = main(
        ["audit", str(bag), "--no-rescore", "--format", "text", "--report", str(report), "--strict"]
    )
    out = capsys.readouterr()
    assert code == 1  # 3 findings with --strict
    assert "ILLEGAL" in out.out and "SILENCE" in out.out
    assert "3 finding(s)" in out.err
    assert (report / "index.html").exists() and (report / "audit_timeline.csv").exists()
    meta = json.loads((report / "result.json").read_text())
    assert meta["audit"]["illegal_transitions"] == 1 and meta["audit"]["silences"] == 1


def test_max_silence_option(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["audit", str(bag), "--format", "json", "--no-rescore", "--max-silence", "3"]) == 0
    assert json.loads(capsys.readouterr().out)["silences"] == []


def test_rescore_failure_keeps_the_audit(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # The bag has no mocap poses: the fbm2h scorer fails, the audit is still printed.
    code = main(["audit", str(bag), "--format", "yaml"])
    out = capsys.readouterr()
    assert code == 0
    assert "score not recomputed" in out.err
    assert "illegal_transitions" in out.out


SAMPLE_FBM2H = (
    Path(__file__).resolve().parents[2]
    / "sample_bags"
    / "fbm2h"
    / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
)


@pytest.mark.parametrize(
    ("option", "value", "named"),
    [
        # A topic the log does not have (a value no scorer takes, `--hits -5`, is a usage
        # error of the parser, exit 2: tests/cli/test_cli_vocabulary.py).
        ("--topic", "/no/such/topic", "/no/such/topic"),
    ],
)
def test_bad_explicit_input_is_an_error(
    option: str, value: str, named: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # The sample log can be re-scored (exit 0 without the option); with a bad input the user
    # named, the scorer's error is theirs to fix: one line and exit 1, not a warning.
    code = main(["audit", str(SAMPLE_FBM2H), "--format", "yaml", option, value])
    err = capsys.readouterr().err
    assert code == 1
    lines = joined_lines(err.strip())
    assert len(lines) == 1 and lines[0].startswith("ertools: error:") and named in lines[0], err
    assert "score not recomputed" not in err


def test_explicit_input_on_a_log_without_poses_is_an_error(
    bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The states-only bag of test_rescore_failure_keeps_the_audit: without inputs a warning,
    # with an input the user named (here a valid one) the scorer's error stands.
    code = main(["audit", str(bag), "--format", "yaml", "--hits", "2"])
    err = capsys.readouterr().err
    assert code == 1 and err.startswith("ertools: error:"), err
    # a states-only log: the poses are in the mocap logger's files
    assert "holds no poses at all" in err and "mocap logger's files" in err, err


def test_input_of_another_benchmark_keeps_the_warning(
    bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # --items is not an fbm2h input: it is said to be unused, and the score that cannot be
    # recomputed from the log stays a warning (exit 0).
    code = main(["audit", str(bag), "--format", "yaml", "--items", str(bag)])
    err = capsys.readouterr().err
    assert code == 0
    assert "--items is not used by fbm2h" in err or "score not recomputed" in err


def test_bag_without_states_is_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "poses.bag"
    with BagWriter(path, "ros1") as bag:
        bag.write_string("/rosout_text", T0_NS, "hello")
    code = main(["audit", str(path)])
    err = error_messages(capsys.readouterr().err)
    assert code == 1
    assert len(err) == 1 and "no benchmark state topics" in err[0]
    # no benchmark's topics either: the generic hint
    assert "`ertools score NAME ... --reached timing`" in err[0]


SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"


@pytest.mark.parametrize(
    ("log", "command"),
    [
        ("robotlog/FBM2H_201511201200_homer.bag", "ertools score trajectory"),
        ("stationary/log_fbm3w_noise_2015-11-20-09-00-00_0.bag", "ertools score fbm3w"),
    ],
)
def test_a_log_without_states_names_the_score_command_for_it(
    log: str, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A robot's own log is no GT-only log: `--reached timing` would not help it."""
    assert main(["audit", str(SAMPLES / log)]) == 1
    (err,) = error_messages(capsys.readouterr().err)
    assert "nothing to audit" in err and f"scores with `{command}`" in err
    assert "--reached" not in err


def test_missing_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["audit", str(tmp_path / "nope.bag")]) == 1
    assert "no such file" in capsys.readouterr().err


def test_several_benchmarks_need_benchmark_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = write_bag(
        tmp_path / "two.bag",
        [
            heartbeat(Machine.BMBOX, BMBOX, 20.0, topic="/fbm2h/bmbox_state"),
            heartbeat(Machine.BMBOX, BMBOX[:4], 5.0, topic="/fbm3w/bmbox_state"),
        ],
    )
    assert main(["audit", str(bag), "--no-rescore"]) == 2  # a usage error
    assert "several benchmarks (fbm2h, fbm3w): give --benchmark" in capsys.readouterr().err
    assert (
        main(["audit", str(bag), "--benchmark", "fbm3w", "--no-rescore", "--format", "json"]) == 0
    )
    data = json.loads(capsys.readouterr().out)
    assert data["benchmark"] == "fbm3w" and data["transitions_checked"] == 3
