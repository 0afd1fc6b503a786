"""Numbers that are not numbers (issue 25, item 8): a 400-digit integer, 1e300, .nan, .inf and
YAML nested thousands deep, in every file ertools reads a number from. Each is one
``ertools: error:`` line naming the file and the key, exit status 1, never an OverflowError or
RecursionError "this is a bug"."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from ertools.benchmarks.fbm3w.shapes import compile_expression
from ertools.cli.main import main
from ertools.configs._yaml import parse_yaml
from ertools.errors import ConfigError
from ertools.yamlin import MAX_DEPTH
from tests.helpers.stderr_text import error_messages

ROOT = Path(__file__).resolve().parents[2]
FBM2H = ROOT / "sample_bags" / "fbm2h"
FBM2H_BAG = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM2H_GOAL = FBM2H / "fbm2h_goal.yaml"
FBM2H_TIMING = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0_reached_waypoint_timing.yaml"
FBM2H_TRANSFORM = FBM2H / "transform-simbot.yaml"
FBM2H_SCORE = ("score", "fbm2h", str(FBM2H_BAG))
FBM3W_BAG = ROOT / "sample_bags" / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM3W_CONFIG = ROOT / "sample_bags" / "fbm3w" / "fbm3w.yaml"
FBM1H = ROOT / "sample_bags" / "fbm1h"
FBM1H_BAG = FBM1H / "log_fbm1h_2015-11-20-12-00-00_0.bag"
FBM1H_ITEMS = FBM1H / "fbm1h.yaml"

HUGE = "1" * 400
# YAML 1.1 (PyYAML) reads 1e300 as text; 1.0e+300 is its spelling of the number
HOSTILE = {"huge": HUGE, "1e300": "1.0e+300", "nan": ".nan", "inf": "-.inf"}


def first(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


# file kind -> (the original, how to plant a number in it, the key the message must name,
# the command scoring with it)
Plant = Callable[[str, str], str]
CASES: dict[str, tuple[Path, Plant, str, Callable[[Path], list[str]]]] = {
    "goal": (
        FBM2H_GOAL,
        lambda t, v: first(t, "[1.6, 0.4", f"[{v}, 0.4"),
        "goal.waypoints[0]",
        lambda f: ([*FBM2H_SCORE, "--goal", str(f), "--transform", str(FBM2H_TRANSFORM)]),
    ),
    "timing": (
        FBM2H_TIMING,
        lambda t, v: first(t, "10.100000000", v),
        "p1",
        lambda f: ([*FBM2H_SCORE, "--reached", "timing", str(f), "--goal", str(FBM2H_GOAL)]),
    ),
    "transform": (
        FBM2H_TRANSFORM,
        lambda t, v: first(t, "[0.12,", f"[{v},"),
        "marker_to_robot_transform",
        lambda f: ["score", "fbm2h", str(FBM2H_BAG), "--transform", str(f)],
    ),
    "d_min": (
        FBM3W_CONFIG,
        lambda t, v: first(t, "d_min: 0.00033", f"d_min: {v}"),
        "d_min",
        lambda f: ["score", "fbm3w", str(FBM3W_BAG), "--config", str(f)],
    ),
    "items": (
        FBM1H_ITEMS,
        lambda t, v: first(t, "trans: [0.05651563768871693,", f"trans: [{v},"),
        "trans",
        lambda f: ["score", "fbm1h", str(FBM1H_BAG), "--items", str(f)],
    ),
}


@pytest.mark.parametrize("value", list(HOSTILE))
@pytest.mark.parametrize("kind", list(CASES))
def test_a_hostile_number_is_one_line_naming_file_and_key(
    kind: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    original, plant, key, command = CASES[kind]
    path = tmp_path / f"hostile-{kind}.yaml"
    path.write_text(plant(original.read_text(), HOSTILE[value]))
    code = main(command(path))
    err = capsys.readouterr().err
    lines = error_messages(err)
    assert code == 1, err
    assert len(lines) == 1, err
    assert "this is a bug" not in err and "Traceback" not in err
    assert str(path) in lines[0] and key in lines[0], lines[0]
    assert HUGE not in err  # 400 digits are not repeated back: their size is said
    assert re.search(r"too large|not a finite|out of range|larger than", lines[0]), lines[0]


@pytest.mark.slow
def test_deep_nesting_is_refused_with_a_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "deep.yaml"
    path.write_text("goal: " + "[" * 5000 + "]" * 5000 + "\n")
    code = main(["score", "fbm2h", str(FBM2H_BAG), "--goal", str(path)])
    err = capsys.readouterr().err
    assert code == 1
    assert "this is a bug" not in err
    assert (
        f"{path}: malformed goal list at line 1, column 70: nested more than 64 levels deep" in err
    )


def test_sixty_four_levels_are_still_read(tmp_path: Path) -> None:
    data = parse_yaml("[" * (MAX_DEPTH - 1) + "1" + "]" * (MAX_DEPTH - 1))
    for _ in range(MAX_DEPTH - 1):
        data = data[0]
    assert data == 1


def test_timing_read_as_epoch_seconds_far_away_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """1e12 s (epoch seconds in the year 33658): finite, but its nanoseconds overflow int64."""
    path = tmp_path / "timing.yaml"
    path.write_text(first(FBM2H_TIMING.read_text(), "10.100000000", "1.0e+12"))
    code = main([*FBM2H_SCORE, "--reached", "timing", str(path), "--goal", str(FBM2H_GOAL)])
    err = capsys.readouterr().err
    assert code == 1 and "this is a bug" not in err
    assert "p1: 1000000000000.0 s is out of range" in err


@pytest.mark.parametrize("spec", [f"line:{HUGE}:3:7", "line:1e300:3:7", "line:2:nan:7"])
def test_a_run_given_on_the_command_line(spec: str, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["score", "fbm3w", str(FBM3W_BAG), "--run", spec])
    err = capsys.readouterr().err
    assert code in (1, 2) and "this is a bug" not in err and HUGE not in err
    assert err.count("ertools: error:") == 1


def test_a_shape_constant_too_large_for_a_float() -> None:
    """A 300-digit constant fits the expression's 400 characters but not a float."""

    with pytest.raises(ConfigError, match=r"shapes.odd.x: .*constant 1111.*too large"):
        compile_expression("1" * 300 + " * l", where="shapes.odd.x")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("benchmarks:\n  fbm3w:\n    inputs: {d_min: .nan}\n", "benchmarks.fbm3w.inputs.d_min: "),
        ("benchmarks:\n  fbm3w:\n    inputs: {d_min: .inf}\n", "benchmarks.fbm3w.inputs.d_min: "),
        (f"benchmarks:\n  fbm3w:\n    inputs: {{d_min: {HUGE}}}\n", "d_min: 11111111111"),
        ("benchmarks:\n  fbm3w:\n    inputs: {d_min: -0.5}\n", "d_min: -0.5 must be >= 0 m"),
        # the intervals' cap (--draws at most 100000): days of draws refused before scoring
        ("benchmarks:\n  fbm3w:\n    inputs: {draws: 1000000000}\n", "draws: 1000000000: at most"),
        # a level of 1.5 passed --check, then made every execution unscoreable
        ("benchmarks:\n  fbm3w:\n    inputs: {confidence: 1.5}\n", "confidence: 1.5 must be < 1"),
        ("executions:\n- {benchmark: fbm3w, team: a, bags: [BAG], start: 1.0e+300}\n", "start"),
        ("executions:\n- {benchmark: fbm3w, team: a, bags: [BAG], start: .nan}\n", "start"),
        (f"executions:\n- {{benchmark: fbm3w, team: a, bags: [BAG], end: {HUGE}}}\n", "end"),
        (f"version: {HUGE}\n", "version: 1111"),
        ("title: " + "[" * 3000 + "]" * 3000 + "\n", "nested more than 64 levels deep"),
    ],
)
def test_a_manifest_number_fails_check_not_the_rescore(
    text: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`rescore --check` refuses what would abort the whole rescore (.nan d_min) or overflow
    (a start in 1e300 epoch seconds), naming the manifest and the key."""
    manifest = tmp_path / "competition.yaml"
    manifest.write_text(
        "version: 1\n" * ("version" not in text) + text.replace("BAG", str(FBM3W_BAG))
    )
    code = main(["rescore", "--config", str(manifest), "--check"])
    err = capsys.readouterr().err
    assert code == 1, err
    assert "this is a bug" not in err and HUGE not in err
    assert any(str(manifest) in line and message in line for line in err.splitlines()), err


@pytest.mark.parametrize(
    ("x", "code", "said"),
    [
        ("1.0e+308", 1, "goal.waypoints[0][0]: 1e+308 is out of range"),
        # by hand: 5000 - 2.33 (the GT's largest x) and 31.6 - 2.33
        ("5000.0", 1, "goal.waypoints[0] (5000, 0.4) lies 4997.7 m outside"),
        ("31.6", 0, "goal.waypoints[0] (31.6, 0.4) lies 29.3 m outside the area the GT covers"),
        ("1.6", 0, None),  # the sample's own goal: nothing said
    ],
)
def test_a_goal_far_outside_the_arena(
    x: str, code: int, said: str | None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The GT of the sample covers x -1.02..2.33 m, y -0.53..2.59 m (its marker path): a
    waypoint 29 m beyond is warned, one 5 km beyond refused (issue 25, item 9)."""
    path = tmp_path / "goal.yaml"
    path.write_text(first(FBM2H_GOAL.read_text(), "[1.6, 0.4", f"[{x}, 0.4"))
    assert main([*FBM2H_SCORE, "--goal", str(path), "--transform", str(FBM2H_TRANSFORM)]) == code
    err = capsys.readouterr().err
    assert "this is a bug" not in err
    if said is None:
        assert "outside the area" not in err
    else:
        assert said in err


def test_a_billion_laughs_file_is_read_in_its_own_size(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ten lists, each nine aliases of the previous one: a billion paths to walk when every
    number is checked, ten objects when each is checked once (the test would time out)."""
    lines = ["a: &a [1, 1, 1, 1, 1, 1, 1, 1, .nan]"]
    for prev, name in zip("abcdefghi", "bcdefghij", strict=True):
        lines.append(f"{name}: &{name} [{', '.join([f'*{prev}'] * 9)}]")
    path = tmp_path / "goal.yaml"
    path.write_text("\n".join(lines) + "\n")
    code = main([*FBM2H_SCORE, "--goal", str(path)])
    err = capsys.readouterr().err
    assert code == 1 and "this is a bug" not in err
    assert ": nan is not a finite number" in err  # found through whichever alias came first
