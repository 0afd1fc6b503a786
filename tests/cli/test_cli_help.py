"""What a newcomer reads first: every --help without developer text or deprecated spellings,
the usage of a command group given nothing, -V, error lines of a readable length, and a log
given to the wrong benchmark named for what it is."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from ertools.benchmarks import registry
from ertools.cli import main as main_module
from ertools.cli.main import COMMANDS, main
from ertools.cli.text import error_text
from tests.helpers.bagmaker import Spec, write
from tests.helpers.stderr_text import error_messages, joined_lines

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"

MEMBERS = {"score": registry.names(), "acquire": ("transform", "items")}
HELPS = [[name] for name in COMMANDS] + [[g, m] for g, ms in MEMBERS.items() for m in ms]
# Text meant for developers: Sphinx roles, reST literals, module paths, internals.
DEVELOPER_TEXT = re.compile(
    r":(mod|func|class|meth|attr):|``|no code of its own|\bertools\.[a-z_]+\.[a-z_]+"
)


def _help(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main([*argv, "--help"]) == 0
    return capsys.readouterr().out


@pytest.mark.parametrize("argv", HELPS, ids=" ".join)
def test_help_has_no_developer_text(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(argv, capsys)
    assert not DEVELOPER_TEXT.findall(text), DEVELOPER_TEXT.findall(text)


@pytest.mark.parametrize("name", registry.names())
def test_help_examples_use_no_deprecated_spelling(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    text = _help(["score", name], capsys)
    examples = [ln for ln in text.splitlines() if ln.strip().startswith("ertools ")]
    assert examples
    old = {f for i in registry.get(name).inputs for f in i.old_flags}
    for line in examples:
        words = set(line.split())
        assert not words & old, f"{line!r} uses {words & old}"
        # --plot takes a file; a folder (`--plot plots/`) is the old spelling of --plots
        assert not re.search(r"--plot \S+/(\s|$)", line), line


def test_a_group_alone_shows_a_usage_naming_what_it_needs(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["score"]) == 2
    err = capsys.readouterr().err
    # the error wraps past the CLI's line limit as the registry grows: one message again
    usage, error = joined_lines(err)
    assert usage.startswith("usage: ertools score ")
    for needed in (*registry.names(), "BAG..."):
        assert needed in usage
    assert error.startswith("ertools: error: ertools score: the following arguments are required")
    assert "ARGS" not in err and "NAME (fbm1h" in error


def test_minus_v_is_the_version(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["-V"]) == 0
    short = capsys.readouterr().out
    assert main(["--version"]) == 0
    assert short == capsys.readouterr().out and short.startswith("ertools 0.")


def test_a_long_error_stays_one_line() -> None:
    detail = "; ".join(f"frame_{i} (in run.bag:/tf; seen {i} times)" for i in range(30))
    message = f"run.bag: no such tf frame robot; frames there: {detail}; give --tf P:C"
    # nothing lost, nothing wrapped: the clauses stay joined by "; " on the one line
    assert error_text(message) == f"ertools: error: {message}"
    # a parser's text with newlines and indents (PyYAML's "<stream\n    end>") folded
    yaml_text = "bad.yaml: not YAML: expected '<document start>', but found\n  '<stream\n    end>'"
    assert error_text(yaml_text) == (
        "ertools: error: bad.yaml: not YAML: expected '<document start>', but found '<stream end>'"
    )
    assert error_text("short: one line") == "ertools: error: short: one line"


def _log(tmp_path: Path, namespace: str) -> Path:
    """A small log with the topics of one benchmark (a state topic and a pose topic)."""
    spec = Spec()
    pose = spec.conn(f"/{namespace}/robot/pose", "geometry_msgs/PoseStamped")
    state = spec.conn(f"/{namespace}/bmbox_state", "rockin_scoring/BmBoxState")
    for i in range(5):
        t = 1_448_020_800_000_000_000 + i * 100_000_000
        spec.add(pose, t, stamp=t, frame="world", xyz=(i, 0.0, 0.0), q=(0.0, 0.0, 0.0, 1.0))
        spec.add(state, t, state=0, payload="")
    return write(tmp_path / f"log_{namespace}.bag", "ros1", spec)


LOGS = {
    "fbm1h": SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag",
    "fbm2h": SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag",
    "fbm3w": SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag",
    "trajectory": SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag",
}
TITLES = {
    "fbm1h": "FBM1@Home",
    "fbm1w": "FBM1@Work",
    "fbm2h": "FBM2@Home",
    "fbm3w": "FBM3@Work",
    "trajectory": "Offline trajectory benchmark",
}
NAMESPACES = {"trajectory": "rockin"}
# The benchmarks whose logs their topics name (the RSBB benchmarks share /rsbb/...: their run
# bags are told apart by their folder, rsbb_logs/<CODE>/, tests/benchmarks/hnf/).
NAMED = [n for n in registry.names() if getattr(registry.get(n), "log_namespace", "")]
PAIRS = [(asked, log) for asked in NAMED for log in NAMED if asked != log]


@pytest.mark.parametrize(("asked", "log"), PAIRS)
def test_a_log_of_another_benchmark_is_named(
    asked: str, log: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = LOGS.get(log) or _log(tmp_path, log)
    # exit 1: the file is unusable for this command, not the command line (docs/cli.md)
    assert main(["score", asked, str(bag)]) == 1
    err = capsys.readouterr().err
    ns = NAMESPACES.get(log, log)
    assert err.splitlines() == [
        f"ertools: error: {bag}: this looks like an {TITLES[log]} log (topics /{ns}/...): "
        f"ertools score {log}"
    ]


def test_a_chosen_source_is_taken_as_given(capsys: pytest.CaptureFixture[str]) -> None:
    """--topic names the poses: the log is scored as the user says, not second-guessed."""
    main(["score", "fbm3w", str(LOGS["fbm2h"]), "--topic", "/fbm2h/robot_at_home/pose"])
    assert "looks like" not in capsys.readouterr().err


REAL = ROOT.parent / "shared" / "real_bags"
REAL_BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"


def test_a_gt_only_log_says_everything_it_needs_at_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    if not REAL_BAG.exists():
        pytest.skip("../shared/real_bags not present")
    assert main(["score", "fbm2h", str(REAL_BAG)]) == 1
    err = capsys.readouterr().err
    timing = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0_reached_waypoint_timing.yaml"
    goal = REAL / "fbm2h_test_optitrackless_goal.yaml"
    # one message, on one line however long the checkout's path makes it
    assert error_messages(err)[0].startswith(
        f"ertools: error: {REAL_BAG}: no benchmark state topics"
    )
    assert f"--reached timing {timing} --goal {goal}" in error_messages(err)[0]
    printed = [ln for ln in err.splitlines() if ln.startswith("ertools: error:")]
    assert printed == error_messages(err)
    # what it says, run: it scores (the README's numbers)
    assert main(["score", "fbm2h", str(REAL_BAG), "--reached", "timing", str(timing),
                 "--goal", str(goal)]) == 0  # fmt: skip
    assert "position_accuracy: 0.063047605" in capsys.readouterr().out
    # alone in a folder: the options, with FILE for what is not there
    lone = tmp_path / REAL_BAG.name
    lone.symlink_to(REAL_BAG)
    assert main(["score", "fbm2h", str(lone)]) == 1
    assert "--reached timing FILE --goal FILE" in capsys.readouterr().err


def test_the_readme_shows_that_message_as_printed(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    if not REAL_BAG.exists():
        pytest.skip("../shared/real_bags not present")
    monkeypatch.chdir(ROOT)
    bag = "../shared/real_bags/log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"
    assert main(["score", "fbm2h", bag]) == 1
    err = capsys.readouterr().err
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert f"```text\n$ ertools score fbm2h {bag}\n{err}```" in readme


@pytest.mark.parametrize("columns", [None, "57", "0", "wide"])
def test_help_wraps_at_the_width_argparse_would_use(
    columns: str | None, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # cli.main's formatter asks os for the width instead of shutil (2 ms of start-up): the help
    # must wrap where argparse's own formatter, which asks shutil, wraps it
    if columns is None:
        monkeypatch.delenv("COLUMNS", raising=False)
    else:
        monkeypatch.setenv("COLUMNS", columns)
    ours = _help(["score", "trajectory"], capsys)
    with monkeypatch.context() as m:
        m.setattr(main_module, "_Formatter", argparse.RawDescriptionHelpFormatter)
        theirs = _help(["score", "trajectory"], capsys)
    assert ours == theirs
    if columns == "57":  # options' help wrapped at 55 columns, not the default 78
        assert max(len(line) for line in ours.splitlines() if line.startswith("  -")) <= 55
