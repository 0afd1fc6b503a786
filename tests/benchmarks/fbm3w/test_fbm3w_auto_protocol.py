"""``--runs auto`` on logs written from the protocol (protocol_logs.py), through the CLI.

Every shape of configs/fbm3w.yaml (the built-ins it names and its two example user shapes),
single- and multi-run logs, approach moves of 1-20 cm in any direction, still phases of
2-10 s, white mocap noise of 0.3-1.3 mm (sigma per axis, per frame at 120 Hz: 0.5-2.3 mm
from frame to frame), 1-4 dropouts of 50-300 ms, a robot's wobble and heading error. The
generator knows when each phase began and ended; the detector must find each path within
0.5 s and take its reference inside the reference phase, and its scores must be the
windows-mode scores.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ertools.cli.main import main
from tests.benchmarks.fbm3w.protocol_logs import (
    SHAPES,
    Log,
    by_arc_length,
    generate,
    shape_curve,
    write_bag,
    write_config,
)
from tests.helpers.stderr_text import error_messages

EDGE_TOLERANCE_S = 0.5


def _cli(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    # the windows and their scores are the subject, not the intervals (tests/intervals/):
    # no Monte Carlo draws (three quarters of each command's time otherwise)
    code = main(["score", "fbm3w", *map(str, args), "--draws", "0"])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _details(capsys: pytest.CaptureFixture[str], *args: object) -> list[dict[str, float]]:
    return _run(capsys, *args)[0]


def _run(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[list[dict[str, float]], str]:
    code, out, err = _cli(capsys, *args, "--format", "json")
    assert code == 0, err
    runs = json.loads(out)["runs_details"]
    return [runs[k] for k in sorted(runs, key=int)], err


def _cases() -> list[tuple[int, list[str]]]:
    """Seeded: each shape alone (twice) and first in two multi-run logs (2-4 runs)."""
    cases = []
    for i, shape in enumerate(SHAPES):
        rot = [*SHAPES[i:], *SHAPES[:i]]
        cases += [(100 + i, [shape]), (200 + i, [shape])]
        cases += [(300 + i, rot[: 2 + i % 3]), (400 + i, rot[: 4 - i % 3])]
    return cases


def _rel(log: Log, t_s: float) -> int:
    """Index of the first sample at or after ``t_s`` from the first pose."""
    return int(np.searchsorted(log.t_ns, log.t_ns[0] + round(t_s * 1e9), side="left"))


def _ref_index(log: Log, t_s: float) -> int:
    return int(np.searchsorted(log.t_ns, log.t_ns[0] + round(t_s * 1e9), side="right")) - 1


def _cut_bound(log: Log, k: int, run: dict[str, float]) -> float:
    """How far a window may move a run's noiseless score from the generator's window (m).

    0 (float rounding) when the window holds the whole motion: the still samples it adds at
    either end sit exactly on the start and end positions, so d_min keeps none of them, and
    the reference is the same point anywhere in its phase. When a window misses the first
    or last delta metres of the motion (the robot creeping below the noise), Eq. (1)
    changes by at most: the origin moves by delta_s (each error by <= delta_s), the x axis
    turns by <= delta_s / (baseline - delta_s) (a point r from the start moves by r times
    that), L shrinks by delta_s + delta_e, moving each target by <= that, and the dropped
    kept points (errors near 0) change the mean by less than the same.
    """
    pa, pb = log.truth.path[k]
    first = log.clean[_rel(log, pa)]
    last = log.clean[_ref_index(log, pb)]  # the last sample of the motion
    ref = log.clean[_ref_index(log, sum(log.truth.ref_phase[k]) / 2)]
    d_s = float(np.hypot(*(log.clean[_rel(log, run["start_time"])] - first)))
    d_e = float(np.hypot(*(log.clean[_ref_index(log, run["end_time"])] - last)))
    lo, hi = _rel(log, pa), _rel(log, pb)
    reach = float(np.max(np.hypot(*(log.clean[lo:hi] - first).T)))
    baseline = float(np.hypot(*(first - ref)))
    return 3 * (d_s + d_e) + reach * d_s / max(baseline - d_s, 1e-3) + 1e-9


@pytest.mark.slow
@pytest.mark.parametrize(("seed", "specs"), _cases())
def test_auto_finds_the_generated_runs(
    seed: int, specs: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(seed)
    log = generate(rng, specs)
    # the config may list more runs than the log holds (a benchmark cut short): a prefix
    listed = specs if seed % 2 else [*specs, "line"]
    _check(log, specs, listed, tmp_path, capsys, on_shape=True)


@pytest.mark.slow
def test_the_hardest_corner(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """1 cm approaches, the most noise (1.3 mm), the shortest still phases (2-2.5 s) and 4
    dropouts, in a 3-run log."""
    rng = np.random.default_rng(600)
    specs = ["hook", "semi", "line"]
    log = generate(rng, specs, sigma=1.3e-3, approach=0.01, still=(2.0, 2.5), dropouts=4)
    _check(log, specs, specs, tmp_path, capsys, on_shape=True)


@pytest.mark.slow
@pytest.mark.parametrize("pause", [0.8, 2.5])
def test_a_robot_pausing_halfway_along_its_path(
    pause: float, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A stop mid-path long enough to be a still phase splits the path in two moves: the run
    is the two joined (the window spans both)."""
    rng = np.random.default_rng(700 + round(pause * 10))
    specs = ["semi_ellipse", "hook", "spline"]
    log = generate(rng, specs, pause=pause)
    _check(log, specs, specs, tmp_path, capsys, on_shape=True)


@pytest.mark.slow_cases("line", "semi", "semi_ellipse", "spline")
@pytest.mark.parametrize("spec", SHAPES)
def test_a_shape_turned_from_the_approach_is_found(
    spec: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The robot draws the shape 57-126 degrees off the reference -> start direction: the
    2015 frame scores it badly, but it is still the run (matched after the best rotation)."""
    rng = np.random.default_rng(500 + SHAPES.index(spec))
    turn = float(rng.uniform(1.0, 2.2) * rng.choice([-1.0, 1.0]))
    log = generate(rng, [spec], turn=turn)
    _check(log, [spec], [spec], tmp_path, capsys, on_shape=False)


def _check(
    log: Log,
    specs: list[str],
    listed: list[str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    *,
    on_shape: bool,
) -> None:
    bag = write_bag(log, tmp_path / "run.bag")
    config = write_config(listed, tmp_path / "fbm3w.yaml")
    # d_min above the noise (3 epsilon, epsilon = sigma * sqrt(pi), the mean distance
    # between two frames of white noise), as `ertools noise` suggests
    d_min = 3 * log.truth.sigma * math.sqrt(math.pi)
    common = ("--config", config, "--d-min", f"{d_min:.6f}")
    auto, err = _run(capsys, bag, *common, "--runs", "auto")
    truth = log.truth
    if len(listed) > len(specs):
        end = truth.path[-1][1]
        said = next(ln for ln in err.splitlines() if "--runs auto found" in ln)
        assert f"found {len(specs)} of the {len(listed)} runs" in said
        assert f"matches run {len(specs)}'s shape 'line'" in said
        # the time is the detected end of the last path, within the 0.5 s of the edges
        at = float(said.split(" after ")[1].split(" s ")[0])
        assert at == pytest.approx(end, abs=EDGE_TOLERANCE_S)
    else:
        assert "--runs auto found" not in err
    assert [r["spec"] for r in auto] == specs
    for k, run in enumerate(auto):
        path_a, path_b = truth.path[k]
        assert run["start_time"] == pytest.approx(path_a, abs=EDGE_TOLERANCE_S), k
        assert run["end_time"] == pytest.approx(path_b, abs=EDGE_TOLERANCE_S), k
        ref_a, ref_b = truth.ref_phase[k]
        assert ref_a < run["reference_time"] < ref_b, k
    # the same windows given by hand score the same, to the last digit
    given = [
        f"--run={r['spec']}:{r['reference_time']!r}:{r['start_time']!r}:{r['end_time']!r}"
        for r in auto
    ]
    same = _details(capsys, bag, *common, "--runs", "windows", *given)
    assert [r["distance_error"] for r in same] == [r["distance_error"] for r in auto]
    # the generator's own windows (reference: the middle of its reference phase), on the
    # noiseless twin: any motion the detected window left out, or a reference outside the
    # reference phase, changes the score; still samples do not
    clean = write_bag(log, tmp_path / "clean.bag", clean=True)
    mine = [
        f"--run={s}:{(ra + rb) / 2!r}:{pa!r}:{pb!r}"
        for s, (ra, rb), (pa, pb) in zip(specs, truth.ref_phase, truth.path, strict=True)
    ]
    config_2015 = ("--config", config)  # the 2015 d_min: nothing to filter
    # one command, the generator's windows then the detected ones
    both = _details(capsys, clean, *config_2015, "--runs", "windows", *mine, *given)
    gen, found = both[: len(mine)], both[len(mine) :]
    for k, (f, g) in enumerate(zip(found, gen, strict=True)):
        bound = _cut_bound(log, k, auto[k])
        assert abs(f["distance_error"] - g["distance_error"]) <= bound, (k, bound)
    # the runs are the shapes: noiseless, each is within the wobble (<= 4 mm per axis), the
    # heading error (<= 4 degrees over the shape's reach) and the gap between the shape's own
    # parameter and its arc length (the 2015 formula's floor, 8.4 mm for the sine) of its
    # target
    u = np.linspace(0.0, 1.0, 2001)
    for k, run in enumerate(gen if on_shape else []):
        by_arc, _ = by_arc_length(specs[k], u)
        reach = float(np.max(np.hypot(*by_arc.T)))
        gap = float(np.max(np.hypot(*(shape_curve(specs[k], u) - by_arc).T)))
        assert run["distance_error"] < 0.004 * math.sqrt(2) + math.radians(4) * reach + gap


def test_the_users_semicircle(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 15: still ~6 s, a 3 cm approach, still ~4 s, ~10 cm of shape over ~14 s, still
    until the log ends; windows mode scored it, auto mode refused it."""
    rng = np.random.default_rng(15)
    log = generate(
        rng, ["semi"], sigma=0.5e-3, approach=0.03, still=(4.0, 6.0), path_s=14.0, dropouts=2
    )
    bag = write_bag(log, tmp_path / "semicircle.bag")
    config = write_config(["semi"], tmp_path / "fbm3w.yaml")
    (auto,) = _details(capsys, bag, "--config", config, "--runs", "auto")
    (pa, pb), (ra, rb) = log.truth.path[0], log.truth.ref_phase[0]
    assert auto["start_time"] == pytest.approx(pa, abs=EDGE_TOLERANCE_S)
    assert auto["end_time"] == pytest.approx(pb, abs=EDGE_TOLERANCE_S)
    assert ra < auto["reference_time"] < rb
    run = f"--run=semi:{auto['reference_time']!r}:{auto['start_time']!r}:{auto['end_time']!r}"
    (windows,) = _details(capsys, bag, "--config", config, run)
    assert windows["distance_error"] == auto["distance_error"]


def test_a_log_without_an_end_phase_says_what_it_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The log stops during the path: the error names the still phases and the missing end."""
    rng = np.random.default_rng(7)
    log = generate(rng, ["line"], sigma=0.5e-3, approach=0.05, still=(3.0, 3.0), dropouts=0)
    cut = _rel(log, (log.truth.path[0][0] + log.truth.path[0][1]) / 2)
    short = Log(log.t_ns[:cut], log.xy[:cut], log.truth, log.clean[:cut])
    bag = write_bag(short, tmp_path / "cut.bag")
    config = write_config(["line"], tmp_path / "fbm3w.yaml")
    code, _, err = _cli(capsys, bag, "--config", config, "--runs", "auto")
    assert code == 1
    lines = error_messages(err)
    assert len(lines) == 1 and "Traceback" not in err
    line = lines[0]
    assert "found 2 still phase(s)" in line
    ref_a, ref_b = log.truth.ref_phase[0]
    start_a, start_b = log.truth.start_phase[0]
    # the two phases found, with their times from the first pose: reference and start
    listed = line.split("still phase(s) (")[1].split(";")[0].replace(" s", "").split(", ")
    found = [tuple(float(v) for v in span.split("-")) for span in listed]
    expected = [(ref_a, ref_b), (start_a, start_b)]
    assert np.allclose(found, expected, atol=EDGE_TOLERANCE_S), (found, expected)
    assert "no end phase: the log ends during a move" in line
    last = (short.t_ns[-1] - short.t_ns[0]) / 1e9
    assert f"last pose at {last:.2f} s" in line


def test_no_move_matches_the_shape(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A line drawn where the config says semi_ellipse: the error lists the moves and how far
    each is from the shape."""
    rng = np.random.default_rng(8)
    log = generate(rng, ["line"], sigma=0.5e-3, approach=0.05, still=(3.0, 3.0), dropouts=0)
    bag = write_bag(log, tmp_path / "line.bag")
    config = write_config(["semi_ellipse"], tmp_path / "fbm3w.yaml")
    code, _, err = _cli(capsys, bag, "--config", config, "--runs", "auto")
    assert code == 1
    line = error_messages(err)[0]
    assert "matches run 0's shape 'semi_ellipse'" in line
    assert "still phases 0.00-" in line
    pa, pb = log.truth.path[0]
    # the path move is listed with its times (edges within the 0.5 s of the detector)
    assert "off the shape by" in line
    assert "no still phase before it for the reference" in line  # the approach (move 0)
    assert line.count(" cm") == 2
    assert abs(float(line.split("moves ")[1].split(";")[1].split("-")[0]) - pa) < 0.5
    assert pb > pa
