"""The one option vocabulary (docs/cli.md): every command spells the same idea the same way,
old spellings still work with one deprecation line, every usage error exits 2, and
``--plot FILE`` writes a file while ``--plots DIR`` writes a folder. On the sample bags."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

import pytest
import yaml

from ertools.benchmarks.common.sources import (
    PoseSpec,
    choose_source,
    pose_source,
    read_source,
    tf,
    time_source_fallback,
    topic,
)
from ertools.benchmarks.common.spec import parse_tf
from ertools.cli.main import build_parser, main
from ertools.cli.options import pose_spec, time_source
from ertools.errors import TopicError, UsageError
from tests.helpers import svg_figure
from tests.helpers.stderr_text import error_messages

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
STATIONARY = SAMPLES / "stationary" / "log_fbm3w_noise_2015-11-20-09-00-00_0.bag"
FBM3 = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM1 = SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag"
PNG = b"\x89PNG\r\n\x1a\n"


def run(capsys: pytest.CaptureFixture[str], *argv: object) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def parse(command: str, *argv: str) -> dict[str, object]:
    module = {"acquire transform": "acquire_transform", "acquire items": "acquire_items"}
    name = module.get(command, command)
    parser, _ = build_parser(f"ertools {command}", f"ertools.cli.{name}")
    return vars(parser.parse_args(list(argv)))


# ---------------------------------------------------------------- the common spellings


@pytest.mark.parametrize(
    ("command", "argv", "expected"),
    [
        (
            "info",
            ("b.bag", "--format", "yaml", "-o", "i.yaml"),
            {"format": "yaml", "out": "i.yaml"},
        ),
        ("info", ("b.bag", "--out", "i.txt"), {"format": "text", "out": "i.txt"}),
        ("timeline", ("d", "--format", "yaml", "--plot", "t.html"), {"format": "yaml"}),
        ("timeline", ("d", "--format", "csv", "--out", "t.csv"), {"out": "t.csv"}),
        (
            "noise",
            ("b.bag", "--tf", "world:robot_at_work", "--time-source", "record", "--format", "yaml"),
            {"tf": ("world", "robot_at_work"), "time_source": "record", "format": "yaml"},
        ),
        ("noise", ("b.bag", "--topic", "/p", "--plots", "figs"), {"topic": "/p", "plots": "figs"}),
        (
            "export",
            ("b.bag", "--tf", "map:base", "--time-source", "header", "-o", "p.tum"),
            {"tf": ("map", "base"), "time_source": "header", "out": "p.tum"},
        ),
        (
            "export",
            ("r.bag", "g/", "--out-dir", "evo", "--robot-time-source", "record"),
            {"out_dir": "evo", "robot_time_source": "record"},
        ),
        (
            "audit",
            ("b.bag", "--format", "json", "--out", "a.json", "--plot", "a.svg"),
            {"format": "json", "out": "a.json", "plot": "a.svg"},
        ),
        ("audit", ("b.bag",), {"format": "yaml"}),  # a result: YAML by default, as `score`
        (
            "acquire transform",
            ("b.bag", "--team", "homer", "--tf", "world:homer", "--out-dir", "t"),
            {"tf": ("world", "homer"), "out_dir": "t"},
        ),
        (
            "acquire items",
            ("b.bag", "--items", "v.yaml", "--origin-tf", "world:o", "--ref-board-topic", "/rb"),
            {"origin_tf": ("world", "o"), "ref_board_topic": "/rb"},
        ),
        (
            "acquire items",
            ("b.bag", "--items", "v.yaml", "--still-min", "3", "-o", "m.yaml"),
            {"still_min": 3.0, "out": "m.yaml"},
        ),
        ("record", ("--simulate", "--out-dir", "logs"), {"out_dir": "logs"}),
        ("report", ("r/", "--report", "c"), {"report": "c"}),
        ("clock", ("--server", "h", "--format", "json", "-o", "c.json"), {"format": "json"}),
    ],
)
def test_each_command_accepts_the_common_spellings(
    command: str,
    argv: tuple[str, ...],
    expected: dict[str, object],
    capsys: pytest.CaptureFixture[str],
) -> None:
    got = parse(command, *argv)
    for key, value in expected.items():
        shown = str(got[key]) if isinstance(got[key], Path) else got[key]
        assert shown == value, (key, got)
    assert "deprecated" not in capsys.readouterr().err


def test_time_source_has_one_default_everywhere() -> None:
    """Not given, it is None in the namespace and ``header`` in every pose spec."""

    for command, argv in (
        ("noise", ("b.bag",)),
        ("export", ("b.bag", "--topic", "/p")),
        ("acquire transform", ("b.bag", "--team", "t")),
        ("acquire items", ("b.bag", "--items", "v.yaml")),
    ):
        ns = argparse.Namespace(**parse(command, *argv))
        assert time_source(ns) == "header"
        assert pose_spec(ns, time_prefix="").time_source == "header"
        assert not pose_spec(ns, time_prefix="").time_source_given


# ---------------------------------------------------------------- old spellings


def test_old_frame_spelling_gives_the_same_result_with_one_note(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code_new, out_new, err_new = run(
        capsys, "noise", STATIONARY, "--tf", "world:robot_at_work", "--format", "json"
    )
    code_old, out_old, err_old = run(
        capsys, "noise", STATIONARY, "--frame", "robot_at_work", "--format", "json"
    )
    assert code_new == code_old == 0
    assert out_new == out_old
    assert json.loads(out_new)["samples"] > 1000  # the 51 s at 120 Hz of the stationary bag
    notes = [line for line in err_old.splitlines() if "deprecated" in line]
    assert notes == ["ertools: note: --frame is deprecated, use --tf world:FRAME"]
    assert "deprecated" not in err_new


def test_old_table_and_output_spellings(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = run(capsys, "info", FBM3, "--format", "table", "--output", tmp_path / "old.txt")
    assert code == 0
    assert err.splitlines()[:2] == [
        "ertools: note: --format table is deprecated, use --format text",
        "ertools: note: --output is deprecated, use --out",
    ]
    code, _, err = run(capsys, "info", FBM3, "-o", tmp_path / "new.txt")
    assert code == 0 and "deprecated" not in err
    assert (tmp_path / "old.txt").read_text() == (tmp_path / "new.txt").read_text()
    assert "/fbm3w/robot_at_work/pose2d" in (tmp_path / "new.txt").read_text()


@pytest.mark.parametrize(
    ("command", "old", "new", "note"),
    [
        (
            "acquire transform",
            ("b.bag", "--team", "t", "--tf-frame", "homer"),
            {"tf": ("world", "homer")},
            "--tf-frame is deprecated, use --tf world:FRAME",
        ),
        (
            "acquire transform",
            ("b.bag", "--team", "t", "--out", "dir"),
            {"out_dir": Path("dir")},
            "--out is deprecated, use --out-dir",
        ),
        (
            "acquire items",
            ("b.bag", "--items", "v.yaml", "--min-still", "2.5"),
            {"still_min": 2.5},
            "--min-still is deprecated, use --still-min",
        ),
        (
            "export",
            ("r.bag", "--out-dir", "e", "--robot-time", "record"),
            {"robot_time_source": "record"},
            "--robot-time is deprecated, use --robot-time-source",
        ),
        ("record", ("--simulate", "--out", "logs"), {"out_dir": Path("logs")}, "use --out-dir"),
        (
            "report",
            ("r/", "--out", "c"),
            {"report": Path("c")},
            "--out is deprecated, use --report",
        ),
        ("timeline", ("d", "--output", "t.csv"), {"out": Path("t.csv")}, "use --out"),
    ],
)
def test_old_spellings_parse_to_the_new_ones_with_one_note(
    command: str,
    old: tuple[str, ...],
    new: dict[str, object],
    note: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    got = parse(command, *old)
    for key, value in new.items():
        assert got[key] == value
    notes = [line for line in capsys.readouterr().err.splitlines() if line]
    assert len(notes) == 1 and notes[0].startswith("ertools: note: ") and note in notes[0]


# ---------------------------------------------------------------- usage errors exit 2


@pytest.mark.parametrize(
    "argv",
    [
        ("noise", str(STATIONARY), "--tf", "robot_at_work"),  # no PARENT:
        ("noise", str(STATIONARY), "--topic", "/a", "--tf", "world:b"),  # two sources
        ("noise", str(STATIONARY), "--frame", "b", "--tf", "world:b"),  # old + new source
        ("noise", str(STATIONARY), "--bin", "-0.001"),
        ("noise", str(STATIONARY), "--time-source", "wall"),
        ("noise", str(STATIONARY), "--plot", "hist.jpg"),
        ("info", str(FBM3), "--format", "xml"),
        ("timeline", str(SAMPLES), "--plot", "day.jpg"),
        ("timeline", str(SAMPLES), "--clock-tolerance", "-1"),
        ("audit", str(FBM3), "--max-silence", "0"),
        ("audit", str(FBM3), "--d-min", "-0.001"),
        ("audit", str(FBM3), "--hits", "-1"),
        ("export", str(FBM3), "--tf", "world:robot_at_work", "--time-source", "record"),
        ("export", str(FBM3), "--max-gap", "0"),
        ("acquire", "items", str(FBM1), "--items", "x.yaml", "--still-min", "0"),
        ("acquire", "transform", str(FBM3), "--team", "t", "--duration", "-5"),
        ("clock", "--server", "localhost", "--port", "70000"),
        ("clock", "--server", "localhost", "--timeout", "0"),
        ("monitor", str(SAMPLES), "--interval", "0"),
        ("monitor", str(SAMPLES), "--drop-fraction", "2"),
        ("record", "--simulate"),  # no --out-dir
        ("record", "--simulate", "--out-dir", "x", "--split", "0"),
        ("report", str(SAMPLES)),  # no --report
        ("score", "fbm3w", str(FBM3), "--plot", "fig.txt"),
    ],
)
def test_every_usage_error_exits_2_with_one_line(
    argv: tuple[str, ...],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(tmp_path)  # nothing may be written; if it were, not into the repository
    code, out, err = run(capsys, *argv)
    assert code == 2, err
    assert out == ""
    # one error line (an old spelling before it adds its deprecation note, nothing else)
    lines = [line for line in err.splitlines() if not line.startswith("ertools: note: ")]
    assert len(error_messages(err)) == 1 and lines[0].startswith("ertools: error: "), err
    assert all(line.startswith("  ") for line in lines[1:]), err  # its detail, if any
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- --plot FILE and --plots DIR


@pytest.mark.slow
def test_plot_file_is_a_file_and_plots_dir_a_folder(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    fig = tmp_path / "fig.png"
    folder = tmp_path / "figs"
    code, out, err = run(capsys, "score", "fbm3w", FBM3, "--plot", fig, "--plots", f"{folder}/")
    assert code == 0, err
    assert fig.is_file() and fig.read_bytes()[:8] == PNG  # not a folder named fig.png
    written = sorted(folder.iterdir())
    assert written and all(p.suffix == ".png" and p.read_bytes()[:8] == PNG for p in written)
    # One file per figure in the folder; every figure stacked in the one file: its height in
    # pixels is the sum of the figures' heights (inches at 110 dpi), each panel as tall as
    # in its own file.
    heights = [_png_size(p)[1] for p in written]
    assert len(written) >= 2
    assert abs(_png_size(fig)[1] - sum(heights)) <= 2 * len(written)
    assert yaml.safe_load(out)["best_distance_error"] > 0


@pytest.mark.slow
def test_plot_suffix_picks_the_format(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    for name, magic in (("h.svg", b"<?xml"), ("h.pdf", b"%PDF")):
        code, _, err = run(capsys, "noise", STATIONARY, "--plot", tmp_path / name)
        assert code == 0, err
        assert (tmp_path / name).is_file() and (tmp_path / name).read_bytes().startswith(magic)
    # The SVG is ertools' own chart (no matplotlib): the histogram, its axes and its lines.
    fig = svg_figure.read(tmp_path / "h.svg")
    assert fig.texts("title")[0].startswith("Mocap noise (")
    assert fig.texts("xlabel") == ["distance between consecutive measurements (mm)"]
    labels = fig.labels()
    assert labels[0].endswith("lost)") and labels[1].startswith("epsilon ")
    assert fig.series(labels[0]).findall("s:rect", svg_figure.NS)  # the histogram's bars


@pytest.mark.slow
def test_old_plot_folder_still_writes_a_folder_with_a_note(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code, _, err = run(capsys, "noise", STATIONARY, "--plot", f"{tmp_path / 'old'}/")
    assert code == 0
    assert [p.name for p in (tmp_path / "old").iterdir()] == ["noise.png"]
    assert f"ertools: note: --plot {tmp_path / 'old'}/ (a folder) is deprecated" in err


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


# ---------------------------------------------------------------- the one pose-source chooser

PRESENT = {
    "/fbm3w/robot_at_work/pose": "geometry_msgs/PoseStamped",
    "/fbm3w/robot_at_work/pose2d": "geometry_msgs/Pose2D",
    "/tf": "tf2_msgs/TFMessage",
}
DEFAULTS = (topic("/fbm3w/robot_at_work/pose2d"), topic("/fbm3w/robot_at_work/pose"), tf("x"))


def test_chooser_uses_the_given_source_else_the_first_default_present(
    caplog: pytest.LogCaptureFixture,
) -> None:
    given = PoseSpec(topic="/fbm3w/robot_at_work/pose", time_source="record")
    assert choose_source(["b.bag"], given, DEFAULTS, present=PRESENT) == given
    assert choose_source(["b.bag"], PoseSpec(tf=("a", "b")), DEFAULTS, present=PRESENT).tf == (
        "a",
        "b",
    )
    with caplog.at_level(logging.WARNING):
        first = choose_source(["b.bag"], PoseSpec(), DEFAULTS, present=PRESENT)
    assert first.topic == "/fbm3w/robot_at_work/pose2d" and caplog.records == []
    # the first default absent: the next one, with a warning naming both
    no_pose2d = {k: v for k, v in PRESENT.items() if not k.endswith("pose2d")}
    with caplog.at_level(logging.WARNING):
        second = choose_source(
            ["b.bag"], PoseSpec(time_source="record"), DEFAULTS, present=no_pose2d
        )
    assert second == PoseSpec(topic="/fbm3w/robot_at_work/pose", time_source="record")
    assert "/fbm3w/robot_at_work/pose2d absent" in caplog.text
    only_tf = {"/tf": "tf2_msgs/TFMessage"}
    assert choose_source(["b.bag"], PoseSpec(), DEFAULTS, present=only_tf).tf == ("world", "x")


def test_chooser_refuses_with_the_topics_there_are() -> None:
    with pytest.raises(TopicError, match=r"/nope: no such topic \(pose topics there: /a, /b\)"):
        choose_source(
            ["b.bag"],
            PoseSpec(topic="/nope"),
            present={"/a": "geometry_msgs/PoseStamped", "/b": "nav_msgs/Odometry"},
        )
    present = {"/a": "geometry_msgs/PoseStamped", "/b": "nav_msgs/Odometry"}
    with pytest.raises(TopicError, match="--topic TOPIC or --tf PARENT:CHILD"):
        choose_source(["b.bag"], PoseSpec(), DEFAULTS, present=present)
    one = {"/a": "geometry_msgs/PoseStamped"}
    assert (
        choose_source(["b.bag"], PoseSpec(), DEFAULTS, present=one, only_topic=True).topic == "/a"
    )


def test_spec_and_tf_text_checks() -> None:
    assert parse_tf("world:robot_at_work") == ("world", "robot_at_work")
    for bad in ("robot", ":robot", "world:", "a:b:c"):
        with pytest.raises(ValueError):
            parse_tf(bad)
    with pytest.raises(UsageError):
        PoseSpec(topic="/a", tf=("w", "b"))
    io_source = pose_source(PoseSpec(tf=("map", "base")))
    assert (io_source.topic, io_source.parent, io_source.frame) == (None, "map", "base")


def test_time_source_fallback_is_said(
    caplog: pytest.LogCaptureFixture, capsys: pytest.CaptureFixture[str]
) -> None:
    pose2d = PoseSpec(topic="/fbm3w/robot_at_work/pose2d")
    assert "no header stamp" in str(time_source_fallback(pose2d, PRESENT))
    assert time_source_fallback(PoseSpec(topic="/fbm3w/robot_at_work/pose"), PRESENT) is None
    record = PoseSpec(topic="/fbm3w/robot_at_work/pose2d", time_source="record")
    assert time_source_fallback(record, PRESENT) is None
    # asked for on the command line: a warning on stderr; the poses are the record-timed ones
    code, out, err = run(
        capsys, "noise", STATIONARY, "--topic", "/fbm3w/robot_at_work/pose2d", "--format", "json"
    )
    assert code == 0
    assert (
        "ertools: warning: /fbm3w/robot_at_work/pose2d is geometry_msgs/Pose2D, which has no "
        "header stamp" in err
    )
    # the command's own default topic: quiet (the 2015 setup), same numbers
    code, out_default, err_default = run(capsys, "noise", STATIONARY, "--format", "json")
    assert code == 0 and "no header stamp" not in err_default
    assert out == out_default
    header = read_source([STATIONARY], PoseSpec(topic="/fbm3w/robot_at_work/pose2d"))
    record_poses = read_source(
        [STATIONARY], PoseSpec(topic="/fbm3w/robot_at_work/pose2d", time_source="record")
    )
    assert (header.t_ns == record_poses.t_ns).all()


def test_timeline_yaml_holds_what_its_json_holds(capsys: pytest.CaptureFixture[str]) -> None:
    bags = SAMPLES / "fbm3w"
    code, out_json, _ = run(capsys, "timeline", bags, "--format", "json", "--no-clock-check")
    assert code == 0
    code, out_yaml, _ = run(capsys, "timeline", bags, "--format", "yaml", "--no-clock-check")
    assert code == 0
    from_json, from_yaml = json.loads(out_json), yaml.safe_load(out_yaml)
    assert from_yaml.keys() == from_json.keys() == {"bags", "sessions", "problems"}
    assert [b["path"] for b in from_yaml["bags"]] == [b["path"] for b in from_json["bags"]]
    # epoch seconds: YAML rounds floats to 9 decimals (1 ns), below a float's step at 1.4e9 s
    # (2.4e-7 s), so the values agree to the nanosecond
    for a, b in zip(from_yaml["bags"], from_json["bags"], strict=True):
        assert a["start"] == pytest.approx(b["start"], abs=1e-9)
        assert a["duration"] == pytest.approx(b["duration"], abs=1e-9)
