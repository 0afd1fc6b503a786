"""Team names: the rockin_logger log-name helper, the payload and transform sources, their
precedence, and ``--team`` / the default team stored by every scoring command."""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from ertools.benchmarks.common.teams import (
    parse_robot_log_name,
    read_payload_team,
    resolve_team,
    team_from_log_name,
    team_from_payloads,
    team_from_transform_name,
    with_team,
)
from ertools.cli.main import main
from ertools.samples.__main__ import generate
from ertools.simulator.writer import BagWriter
from ertools.states import Machine
from ertools.streams import Provenance
from ertools.timelines.build import benchmark_names

REPO = Path(__file__).resolve().parents[3]


def _sample_dir(name: str, tmp_factory: pytest.TempPathFactory) -> Path:
    """``sample_bags/<name>`` when shipped, else generated from the protocol into a temp dir."""
    shipped = REPO / "sample_bags" / name
    if shipped.is_dir() and any(shipped.glob("*.answers.yaml")):
        return shipped

    out = tmp_factory.mktemp(f"samples_{name}")
    generate(out, [name])
    return out / name


# --------------------------------------------------------------------------------------------
# The rockin_logger name helper: ${BENCHMARK}_${DATE}_${TEAMNAME}.bag


@pytest.mark.parametrize(
    ("name", "benchmark", "team"),
    [
        ("FBM2H_201511201200_homer.bag", "fbm2h", "homer"),
        ("FBMH2_201511201200_homer.bag", "fbm2h", "homer"),  # the logger's other spelling
        ("TBMH1_201511201200_b-it-bots.bag", "tbm1h", "b-it-bots"),
        ("fbm3w_20151120120000_team_x.bag.active", "fbm3w", "team_x"),  # still recording
        ("logs/usb/FBM1W_201511201200_SocRob.mcap", "fbm1w", "SocRob"),
        ("FBM2H_renamed.bag", "fbm2h", None),  # a benchmark, but no date_team part
    ],
)
def test_rockin_logger_names(name: str, benchmark: str, team: str | None) -> None:
    parsed = parse_robot_log_name(name)
    assert parsed is not None and parsed.benchmark == benchmark
    assert team_from_log_name(name) == team


@pytest.mark.parametrize(
    "name",
    [
        "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag",  # a mocap (GT) log names no team
        "robot.bag",
        "FBM9_201511201200_homer.bag",  # no arena letter
        "XBM2H_201511201200_homer.bag",
    ],
)
def test_names_the_logger_did_not_give(name: str) -> None:
    assert team_from_log_name(name) is None


def test_timeline_uses_the_same_helper() -> None:
    assert benchmark_names([], "FBMH2_201511201200_homer.bag") == ("fbm2h",)
    assert benchmark_names([], "robot.bag") == ()


def test_transform_names() -> None:
    assert team_from_transform_name("cfg/transform-simbot.yaml") == "simbot"
    assert team_from_transform_name("transform-identity.yaml") is None  # Listing 12
    assert team_from_transform_name("marker.yaml") is None


def test_payloads() -> None:
    # 10 Hz repeats, free text and a "timeout" END payload are no team; a mapping naming
    # an identity transform is none either; the first real name wins.
    payloads = ["", "timeout", "Place item 3 on the table", "robot_info: identity"] * 3
    assert team_from_payloads(payloads) is None
    assert team_from_payloads([*payloads, "team: tripod\nrun: 2", "team_name: other"]) == "tripod"
    assert team_from_payloads(["{robot_info: homer, x: 1}"]) == "homer"
    assert team_from_payloads(["team: [unclosed"]) is None  # not YAML: skipped, not fatal


def test_precedence() -> None:
    log = "FBM2H_201511201200_homer.bag"
    tr = "transform-simbot.yaml"
    full = resolve_team("b-it-bots", inputs=[log], payload_team="tripod", transform=tr)
    assert full is not None and (full.name, full.source) == ("b-it-bots", "explicit")
    payload = resolve_team(None, inputs=[log], payload_team="tripod", transform=tr)
    assert payload is not None and (payload.name, payload.source) == ("tripod", "payload")
    named = resolve_team("  ", inputs=["gt.bag", log], transform=tr)  # blank --team: no name
    assert named is not None and (named.name, named.source) == ("homer", "log name")
    by_tr = resolve_team(None, inputs=["gt.bag"], transform=tr)
    assert by_tr is not None and (by_tr.name, by_tr.source) == ("simbot", "transform")
    # The transform's robot_info is preferred to its file name.
    info = resolve_team(None, transform="t.yaml", transform_team="socrob")
    assert info is not None and info.name == "socrob"
    assert resolve_team(None, inputs=["gt.bag"], transform="transform-identity.yaml") is None


@dataclass(frozen=True)
class _Result:
    name: str
    provenance: Provenance = field(default_factory=Provenance)


def test_payload_team_read_from_a_bag(tmp_path: Path) -> None:
    bag = tmp_path / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
    t = 1_447_999_200_000_000_000 + 100_000_000 * __import__("numpy").arange(5)
    with BagWriter(bag, "ros1") as w:
        w.write_state(Machine.REFBOX, "/fbm3w/refbox_state", t, 1, "team: tripod\nrun: 1")
        w.write_state(Machine.BMBOX, "/fbm3w/bmbox_state", t, 1, "")
    assert read_payload_team([bag], "fbm3w") == "tripod"
    assert read_payload_team([bag], "fbm2h") is None  # no state topics of that benchmark
    result = with_team(_Result("fbm3w"), None, [bag])
    assert (result.provenance.team, result.provenance.team_source) == ("tripod", "payload")
    # --team beats the payload; a result with no team found is unchanged.
    result = with_team(_Result("fbm3w"), "b-it-bots", [bag])
    assert (result.provenance.team, result.provenance.team_source) == ("b-it-bots", "explicit")
    assert with_team(_Result("trajectory"), None, [bag]) == _Result("trajectory")


# --------------------------------------------------------------------------------------------
# Every scoring command: --team stored, else the log's rockin_logger name


@dataclass(frozen=True)
class Case:
    command: str
    sample: str
    bag_glob: str
    extra: tuple[str, ...]  # file names in the sample folder, or options
    logger_name: str  # the benchmark as the rockin_logger wrote it in file names


CASES = [
    Case("fbm1h", "fbm1h", "log_fbm1h_*.bag", ("--items", "@fbm1h.yaml"), "FBM1H"),
    Case("fbm2h", "fbm2h", "log_fbm2h_*.bag", (), "FBMH2"),
    Case("fbm3w", "fbm3w", "log_fbm3w_*.bag", ("--config", "@fbm3w.yaml"), "FBM3W"),
    Case("trajectory", "robotlog", "FBM2H_*.bag", ("@log_fbm2h_mocap_*.bag",), "FBM2H"),
]


def _argv(case: Case, folder: Path, bag: Path) -> list[str]:
    extra: list[str] = []
    for a in case.extra:
        extra += [str(p) for p in sorted(folder.glob(a[1:]))] if a.startswith("@") else [a]
    return ["score", case.command, str(bag), *extra]


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[c.command for c in CASES])
def test_scoring_commands_store_the_team(
    case: Case,
    tmp_path: Path,
    tmp_path_factory: pytest.TempPathFactory,
    capsys: pytest.CaptureFixture[str],
) -> None:
    folder = _sample_dir(case.sample, tmp_path_factory)
    (source,) = folder.glob(case.bag_glob)
    # The log as the 2015 rockin_logger would have named it, for a team this test chooses.
    team = "robo_team-7"
    bag = tmp_path / f"{case.logger_name}_201511201200_{team}.bag"
    shutil.copyfile(source, bag)
    assert team_from_log_name(bag) == team
    argv = _argv(case, folder, bag)

    assert main([*argv, "--report", str(tmp_path / "default")]) == 0, capsys.readouterr().err
    meta = json.loads((tmp_path / "default" / "result.json").read_text())
    assert (meta["team"], meta["team_source"]) == (team, "log name")

    assert main([*argv, "--team", "b-it-bots", "--report", str(tmp_path / "given")]) == 0
    meta = json.loads((tmp_path / "given" / "result.json").read_text())
    assert (meta["team"], meta["team_source"]) == ("b-it-bots", "explicit")
    assert "b-it-bots (from --team)" in (tmp_path / "given" / "index.html").read_text()
    capsys.readouterr()


@pytest.mark.slow
def test_fbm2h_team_alone_keeps_the_identity_transform(
    tmp_path: Path, tmp_path_factory: pytest.TempPathFactory, capsys: pytest.CaptureFixture[str]
) -> None:
    """--team without --transforms only names the team; --transforms still needs it."""
    folder = _sample_dir("fbm2h", tmp_path_factory)
    (bag,) = folder.glob("log_fbm2h_*.bag")
    main(["score", "fbm2h", str(bag), "--team", "simbot", "--report", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert "identity marker-to-robot transform" in err
    assert json.loads((tmp_path / "r" / "result.json").read_text())["team"] == "simbot"
    # No --team, a mocap log's name: the transform file names the team (its robot_info).
    (transform,) = folder.glob("transform-*.yaml")
    expected = transform.name.removeprefix("transform-").removesuffix(".yaml")
    t_report = tmp_path / "t"
    assert (
        main(["score", "fbm2h", str(bag), "--transform", str(transform), "--report", str(t_report)])
        == 0
    )
    meta = json.loads((t_report / "result.json").read_text())
    assert (meta["team"], meta["team_source"]) == (expected, "transform")
    capsys.readouterr()
    code = main(["score", "fbm2h", str(bag), "--transforms", str(folder)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--transforms DIR needs --team NAME" in err[0]
