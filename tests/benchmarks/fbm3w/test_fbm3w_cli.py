"""``ertools score fbm3w``: outputs, options and every bad input of the issue, in-process."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from ertools.benchmarks.fbm3w.shapes import builtin_shapes
from ertools.cli.main import main
from ertools.simulator.writer import BagWriter
from tests.benchmarks.fbm3w.fbm3w_kit import Sample
from tests.benchmarks.fbm3w.fbm3w_synth import one_run
from tests.benchmarks.fbm3w.protocol_logs import generate, write_bag, write_config
from tests.helpers.stderr_text import error_messages


def score(*args: str, draws: bool = False) -> int:
    """``ertools score fbm3w ARGS``; without the Monte Carlo draws of the intervals (the
    outputs and options are the subject here) unless ``draws``: the command as typed."""
    argv = ["score", "fbm3w", *map(str, args)]
    return main(argv if draws or "--draws" in argv else [*argv, "--draws", "0"])


def one_line_error(err: str) -> str:
    lines = error_messages(err)
    assert len(lines) >= 1, err
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.slow
def test_default_yaml_and_json(fbm3w_sample: Sample, capsys: pytest.CaptureFixture[str]) -> None:
    assert score(fbm3w_sample.bag, "--config", fbm3w_sample.config, draws=True) == 0
    out = yaml.safe_load(capsys.readouterr().out)
    # Listing 16's keys in its order, then the interval and how it was obtained (issue 28)
    listing = ["best_distance_error", "best_run", "execution_time", "runs_details"]
    assert list(out) == [*listing, "best_distance_error_interval", "uncertainty"]
    assert list(out["runs_details"][0])[:4] == [
        "spec",
        "distance_error",
        "execution_time",
        "distance_error_interval",
    ]
    assert score(fbm3w_sample.bag, "--config", fbm3w_sample.config, "--draws", "0") == 0
    assert list(yaml.safe_load(capsys.readouterr().out)) == listing
    assert out["best_run"] == fbm3w_sample.answers["expected"]["best_run"]
    assert score(fbm3w_sample.bag, "--format", "json") == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data["runs_details"]) == ["0", "1", "2", "3", "4"]
    assert data["runs_details"]["4"]["status"] == "timeout"


@pytest.mark.slow
def test_sweep_plot_and_notes(
    fbm3w_sample: Sample, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plots = tmp_path / "plots"
    assert score(fbm3w_sample.bag, "--d-min-sweep", "0.0002:0.0008:3", "--plot", plots) == 0
    err = capsys.readouterr().err
    assert "d_min [mm]" in err and "0.5000" in err  # the middle value of the sweep, in mm
    assert "differs from 2015" in err
    names = sorted(p.name for p in plots.iterdir())
    assert names == [
        "fbm3w_d_min_sweep.png",
        *(f"fbm3w_run{i}.png" for i in range(4)),
        "fbm3w_runs.png",
    ]


@pytest.mark.slow
def test_runs_file(
    fbm3w_sample: Sample, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    runs = [
        {"spec": s, "reference": r, "start": a, "end": b} for s, r, a, b in fbm3w_sample.windows()
    ]
    runs_file = tmp_path / "runs.yaml"
    runs_file.write_text(yaml.safe_dump(runs), encoding="utf-8")
    assert score(fbm3w_sample.bag, "--runs-file", runs_file, "--format", "json") == 0
    data = json.loads(capsys.readouterr().out)
    for key, run in data["runs_details"].items():
        exp = fbm3w_sample.expected_run(int(key))
        # same windows as the states mode: the answers' tolerance (frame from noisy samples)
        tol = fbm3w_sample.answers["tolerance"]["distance_error"]["abs"]
        assert run["distance_error"] == pytest.approx(exp["distance_error"], abs=tol)
    runs_file.write_text("- {spec: line, start: 1}\n", encoding="utf-8")
    assert score(fbm3w_sample.bag, "--runs-file", runs_file) == 1
    assert "missing key(s) reference, end" in one_line_error(capsys.readouterr().err)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (None, "run list file not found"),
        ("- [unclosed\n", "malformed run list at line"),
    ],
)
def test_runs_file_messages(
    fbm3w_sample: Sample,
    tmp_path: Path,
    content: str | None,
    expected: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # load_yaml appends " file" itself: the message must not read "runs file file not found".
    runs_file = tmp_path / "runs.yaml"
    if content is not None:
        runs_file.write_text(content, encoding="utf-8")
    assert score(fbm3w_sample.bag, "--runs-file", runs_file) == 1
    line = one_line_error(capsys.readouterr().err)
    assert expected in line and "runs.yaml" in line
    assert "file file" not in line


@pytest.mark.slow
@pytest.mark.parametrize(
    "source", [["--topic", "/fbm3w/robot_at_work/pose"], ["--frame", "robot_at_work"]]
)
def test_other_pose_sources(
    fbm3w_sample: Sample, source: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert score(fbm3w_sample.bag, "--format", "json") == 0
    pose2d = json.loads(capsys.readouterr().out)["runs_details"]
    assert score(fbm3w_sample.bag, *source, "--format", "json") == 0
    captured = capsys.readouterr()
    other = json.loads(captured.out)["runs_details"]
    assert "2015 used /fbm3w/robot_at_work/pose2d" in captured.err
    for key in ("0", "1", "2", "3"):
        # same positions; the record/header times differ by 20-300 us, so a window edge may
        # take or drop one stationary sample: at most the start sample's noise (0.07 mm)
        # moves the frame origin
        assert other[key]["distance_error"] == pytest.approx(
            pose2d[key]["distance_error"], abs=2e-4
        )


@pytest.mark.slow
def test_explicit_windows_and_auto_notes(
    fbm3w_sample: Sample, capsys: pytest.CaptureFixture[str]
) -> None:
    runs = [f"--run={s}:{r}:{a}:{b}" for s, r, a, b in fbm3w_sample.windows()]
    assert score(fbm3w_sample.bag, *runs) == 0
    out = yaml.safe_load(capsys.readouterr().out)
    assert [d["run_finding"] for d in out["runs_details"].values()] == ["windows"] * 4
    assert score(fbm3w_sample.bag, "--runs", "auto") == 0
    err = capsys.readouterr().err
    assert "run 0 (line) found at reference" in err


def test_bad_runs_fail_alone(fbm3w_sample: Sample, capsys: pytest.CaptureFixture[str]) -> None:
    good = fbm3w_sample.windows()[0]
    args = [
        f"--run={good[0]}:{good[1]}:{good[2]}:{good[3]}",
        "--run=line:0.1:0.2:0.21",  # before the mocap starts: no sample
        "--run=line:1.0:1.2:1.8",  # the robot stands still at the reference: zero length
        f"--run=nope:{good[1]}:{good[2]}:{good[3]}",  # unknown shape
    ]
    assert score(fbm3w_sample.bag, *args) == 1
    captured = capsys.readouterr()
    out = yaml.safe_load(captured.out)
    details = out["runs_details"]
    assert details[0]["status"] == "scored"
    assert out["best_run"] == 0
    assert [details[i]["status"] for i in (1, 2, 3)] == ["failed"] * 3
    assert "0 pose sample(s)" in details[1]["error"]
    assert "zero length" in details[2]["error"]
    assert "unknown shape 'nope'" in details[3]["error"]
    errors = [ln for ln in captured.err.splitlines() if ln.startswith("ertools: error:")]
    assert len(errors) == 3 and "Traceback" not in captured.err


@pytest.mark.slow
def test_forbidden_shape_expression(
    fbm3w_sample: Sample, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = tmp_path / "evil.yaml"
    cfg.write_text(
        "runs_specifications: [evil, spline, line, spline, line]\n"
        "shapes:\n  evil: {x: \"__import__('os')\", y: '0'}\n",
        encoding="utf-8",
    )
    assert score(fbm3w_sample.bag, "--config", cfg) == 1
    captured = capsys.readouterr()
    out = yaml.safe_load(captured.out)
    assert out["runs_details"][0]["status"] == "failed"
    assert "not allowed" in out["runs_details"][0]["error"]
    assert all(out["runs_details"][i]["status"] == "scored" for i in (1, 2, 3))
    assert "run 0 (evil)" in one_line_error(captured.err)


@pytest.mark.slow
def test_user_shape_scores_like_the_builtin(
    fbm3w_sample: Sample, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = tmp_path / "mine.yaml"
    # the line of Listing 15 written as a user expression must give the same numbers
    cfg.write_text(
        "runs_specifications: [myline, spline, line, spline, line]\n"
        "shapes:\n  myline: {x: '0.15*l', y: '0.045*l'}\n",
        encoding="utf-8",
    )
    assert score(fbm3w_sample.bag, "--config", cfg, "--format", "json") == 0
    mine = json.loads(capsys.readouterr().out)["runs_details"]["0"]
    assert score(fbm3w_sample.bag, "--format", "json") == 0
    builtin = json.loads(capsys.readouterr().out)["runs_details"]["0"]
    assert mine["distance_error"] == pytest.approx(builtin["distance_error"], abs=1e-15)


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["--topic", "/nope"], 1, "/nope"),
        (["--d-min-sweep", "a:b"], 2, "START:STOP:N"),
        (["--d-min-sweep", "0.1:0.2:0"], 2, "between 1 and 500"),
        (["--d-min", "-1"], 2, ">= 0"),  # a usage error: one home, make_options (issue 16)
        (["--d-min", "-0.001"], 2, "--d-min must be >= 0 m, got -0.001"),
        (["--run", "line:1:2"], 1, "SPEC:REF_T:START_T:END_T"),
        (["--run", "line:1:5:2"], 1, "before START_T"),
        (["--run", "line:1:2:3", "--runs", "states"], 2, "contradict"),
        (["--runs", "windows"], 1, "needs --run"),
    ],
)
def test_bad_command_lines(
    fbm3w_sample: Sample,
    args: list[str],
    code: int,
    message: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert score(fbm3w_sample.bag, *args) == code
    assert message in one_line_error(capsys.readouterr().err)


def test_bad_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert score(tmp_path / "missing.bag") == 1
    one_line_error(capsys.readouterr().err)
    bad = tmp_path / "bad.yaml"
    bad.write_text("runs_specifications: [line\n", encoding="utf-8")
    mocap_only = _mocap_only_bag(tmp_path / "only.bag")
    assert score(mocap_only, "--config", bad) == 1
    assert "malformed" in one_line_error(capsys.readouterr().err)
    assert score(mocap_only, "--runs", "states") == 1
    assert "bmbox_state" in one_line_error(capsys.readouterr().err)
    empty = tmp_path / "empty.bag"
    with BagWriter(empty, "ros1") as bag:
        bag.write_string("/chatter", [1_448_020_800_000_000_000], "hello")
    assert score(empty) == 1
    assert "no end-effector poses" in one_line_error(capsys.readouterr().err)


def _mocap_only_bag(path: Path) -> Path:
    stream, _ = one_run(builtin_shapes()["line"](np.linspace(0, 1, 200)))
    with BagWriter(path, "ros1") as bag:
        bag.write_pose2d(
            "/fbm3w/robot_at_work/pose2d",
            stream.t_ns,
            stream.xyz[:, 0],
            stream.xyz[:, 1],
            np.zeros(len(stream)),
        )
    return path


@pytest.mark.slow
@pytest.mark.parametrize(
    ("window", "where"),
    [
        ("end + 5", "past the end"),  # the path window runs 5 s past the last message
        ("ref - 100", "before the start"),  # a reference before the first message
    ],
)
def test_window_outside_the_log_is_an_error(
    window: str, where: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 15 (4): a window cut by the log's end was scored from what was left."""

    log = generate(np.random.default_rng(4), ["line"], sigma=0.5e-3, approach=0.05)
    bag = write_bag(log, tmp_path / "run.bag")
    config = write_config(["line"], tmp_path / "fbm3w.yaml")
    (ref_a, ref_b), (pa, pb) = log.truth.ref_phase[0], log.truth.path[0]
    span = (log.t_ns[-1] - log.t_ns[0]) / 1e9
    ref, start, end = (ref_a + ref_b) / 2, pa, pb
    if window == "end + 5":
        end = span + 5
    else:
        ref = -100.0
    # inside the log: scored
    assert score(bag, "--config", config, f"--run=line:{(ref_a + ref_b) / 2}:{pa}:{pb}") == 0
    capsys.readouterr()
    assert score(bag, "--config", config, f"--run=line:{ref}:{start}:{end}") == 1
    captured = capsys.readouterr()
    line = one_line_error(captured.err)
    assert len([ln for ln in captured.err.splitlines() if ln.startswith("ertools:")]) == 1
    assert captured.out == ""  # no score printed
    assert f"reaches {where} of the log" in line
    assert f"reference {ref:.3f} s, path {start:.3f}-{end:.3f} s" in line
    assert f"the log covers 0-{span:.3f} s" in line
