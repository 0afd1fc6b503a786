"""Execution discovery (ertools.competition.discover) on the sample competition and by hand.

The competition's answers.json says, from the generator's own bookkeeping (which file it
wrote for which execution, when), what a correct discovery finds: every execution with its
benchmark log, span, GT hour files, robot log and team, and the problems planted.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import pytest

from ertools.competition.discover import Discovery, _gt_only, discover
from ertools.io.formats import Unreadable
from ertools.samples.competition_schedule import NO_ROBOT_LOG, TRUNCATED
from ertools.timelines.build import build_timeline
from ertools.timelines.model import BagEntry, Pairing
from ertools.timelines.scan import scan
from tests.helpers.summaries import Summary, Topic

pytestmark = pytest.mark.slow

S = 1_000_000_000
T0 = 1_448_013_600 * S  # 2015-11-20 10:00:00 UTC


# --- the sample competition ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def day(sample_competition: Path) -> tuple[Discovery, dict[str, Any]]:
    root = sample_competition
    answers = json.loads((root / "answers.json").read_text())
    found = discover(scan([root]))

    def rel(p: str) -> str:
        return str(Path(p).relative_to(root))

    # paths relative to the folder, as answers.json gives them
    executions = tuple(
        dataclasses.replace(
            e,
            bmbox_log=rel(e.bmbox_log),
            gt_files=tuple(rel(g) for g in e.gt_files),
            robot_log=None if e.robot_log is None else rel(e.robot_log),
        )
        for e in found.executions
    )
    problems = tuple(dataclasses.replace(p, path=rel(p.path)) for p in found.problems)
    return Discovery(executions, problems), answers


def test_every_execution_found_with_its_files(day: tuple[Discovery, dict[str, Any]]) -> None:
    found, answers = day
    by_log = {e.bmbox_log: e for e in found.executions}
    assert sorted(by_log) == sorted(e["bmbox_log"] for e in answers["executions"])
    for want in answers["executions"]:
        got = by_log[want["bmbox_log"]]
        assert got.benchmark == want["benchmark"] and got.namespace == want["namespace"]
        assert got.start_ns == want["start_ns"], want["id"]
        if want["truncated"]:
            assert got.end_ns < want["end_ns"]  # readable up to the cut
        else:
            assert got.end_ns == want["end_ns"], want["id"]
        assert list(got.gt_files) == want["gt_files"], want["id"]
        assert got.robot_log == want["robot_log"], want["id"]
        if want["robot_log"] is not None:
            assert (got.team, got.team_source) == (want["team"], "log name"), want["id"]
            assert got.id == want["id"]
        else:
            assert got.team is None and got.team_source is None
            # a problem of the day; not a note of its row, which says "team unknown"
            assert (got.bmbox_log, "no-team") in {(p.path, p.kind) for p in found.problems}
            assert not any("no team" in p for p in got.problems)


def test_planted_problems_are_found(day: tuple[Discovery, dict[str, Any]]) -> None:
    found, answers = day
    kinds = {(p.path, p.kind) for p in found.problems}
    want = {p["kind"]: p for p in answers["problems"]}
    assert (want["truncated"]["path"], "truncated") in kinds
    assert (want["active"]["path"], "active") in kinds
    assert (want["duplicate"]["path"], "duplicate") in kinds
    assert (want["clock-offset"]["path"], "clock-offset") in kinds
    assert (want["unpaired"]["path"], "unpaired") in kinds
    assert (want["no-team"]["path"], "no-team") in kinds
    (no_robot,) = [e for e in answers["executions"] if e["id"] == NO_ROBOT_LOG]
    assert want["no-team"]["path"] == no_robot["bmbox_log"]
    # nothing else is wrong with the day: one problem line per planted problem (the truncated
    # log has two lines, index and last record), no GT or pairing problems
    assert {k for _, k in kinds} == {
        "truncated",
        "active",
        "duplicate",
        "clock-offset",
        "unpaired",
        "no-team",
    }
    # the clock line gives the offset the answers know (header - record = 3.998 s)
    (clock,) = [p for p in found.problems if p.kind == "clock-offset"]
    assert f"{-want['clock-offset']['offset_s'] + 0.002:+.3f} s" in clock.message
    # execution-level lines carry their files' problems
    (trunc,) = [e for e in found.executions if e.id == TRUNCATED]
    assert any("truncated" in p for p in trunc.problems)


# --- by hand --------------------------------------------------------------------------------------

POSE = "geometry_msgs/PoseStamped"
STATE = "rockin_scoring/BmBoxState"


def gt(path: str, a: float, b: float, ns: str = "fbm2h") -> Summary:
    return Summary(path, T0 + round(a * S), T0 + round(b * S), (Topic(f"/{ns}/body/pose", POSE),))


def bench(path: str, a: float, b: float, ns: str = "fbm2h") -> Summary:
    return Summary(
        path, T0 + round(a * S), T0 + round(b * S), (Topic(f"/{ns}/bmbox_state", STATE),)
    )


def robot(path: str, a: float, b: float) -> Summary:
    return Summary(path, T0 + round(a * S), T0 + round(b * S), (Topic("/rockin/x/pose", POSE),))


def test_each_robot_log_goes_to_the_execution_it_overlaps_most() -> None:
    # Two FBM2H runs back to back; team A's logger ran 0-70 s (run 1: 10-60 s), team B's
    # 55-130 s (run 2: 65-120 s): B's log overlaps run 1 by 5 s and run 2 by 55 s.
    tl = build_timeline(
        [
            gt("gt/log_mocap_2015-11-20-09-59-58_0.bag", -2, 200),
            bench("bm/log_fbm2h_2015-11-20-10-00-10_0.bag", 10, 60),
            bench("bm/log_fbm2h_2015-11-20-10-01-05_0.bag", 65, 120),
            robot("r/FBM2H_201511201000_alpha.bag", 0, 70),
            robot("r/FBM2H_201511201000_beta.bag", 55, 130),
        ]
    )
    found = discover(tl)
    assert [(e.team, e.robot_log) for e in found.executions] == [
        ("alpha", "r/FBM2H_201511201000_alpha.bag"),
        ("beta", "r/FBM2H_201511201000_beta.bag"),
    ]
    assert [e.id for e in found.executions] == [
        "fbm2h-alpha-20151120T100010",
        "fbm2h-beta-20151120T100105",
    ]
    assert found.problems == ()


def test_payload_team_wins_and_other_benchmarks_robot_logs_do_not_pair() -> None:
    log = "bm/log_fbm2h_2015-11-20-10-00-10_0.bag"
    tl = build_timeline(
        [
            gt("gt/log_mocap_2015-11-20-09-59-58_0.bag", -2, 200),
            bench(log, 10, 60),
            robot("r/FBM2H_201511201000_alpha.bag", 0, 70),
            robot("r/FBM3W_201511201000_gamma.bag", 5, 65),  # another arena's robot
        ]
    )
    found = discover(tl, payload_teams={log: "delta"})
    (e,) = found.executions
    assert (e.team, e.team_source, e.robot_log) == (
        "delta",
        "payload",
        "r/FBM2H_201511201000_alpha.bag",
    )
    assert [(p.path, p.kind) for p in found.problems] == [
        ("r/FBM3W_201511201000_gamma.bag", "unpaired")
    ]


def test_two_robot_logs_on_one_execution_is_ambiguous() -> None:
    tl = build_timeline(
        [
            gt("gt/log_mocap_2015-11-20-09-59-58_0.bag", -2, 200),
            bench("bm/log_fbm2h_2015-11-20-10-00-10_0.bag", 10, 60),
            robot("r/FBM2H_201511201000_alpha.bag", 0, 70),  # covers all 50 s
            robot("r/FBM2H_201511201000_beta.bag", 30, 80),  # 30 s
        ]
    )
    (e,) = discover(tl).executions
    assert e.team == "alpha"
    assert any("several robot logs" in p and "beta" in p for p in e.problems)


def test_gt_coverage_and_missing_gt() -> None:
    # GT covers 10-40 s of a 10-60 s run: 60 %; a second run at 300-320 s has no GT at all.
    tl = build_timeline(
        [
            gt("gt/log_mocap_2015-11-20-10-00-00_0.bag", 0, 40),
            bench("bm/log_fbm2h_2015-11-20-10-00-10_0.bag", 10, 60),
            bench("bm/log_fbm2h_2015-11-20-10-05-00_0.bag", 300, 320),
        ]
    )
    found = discover(tl)
    first, second = found.executions
    assert first.gt_files == ("gt/log_mocap_2015-11-20-10-00-00_0.bag",)
    assert any("GT covers 60.0 %" in p for p in first.problems)
    assert second.gt_files == ()
    kinds = [(p.path, p.kind) for p in found.problems]
    assert ("bm/log_fbm2h_2015-11-20-10-00-10_0.bag", "partial-gt") in kinds
    assert ("bm/log_fbm2h_2015-11-20-10-05-00_0.bag", "no-gt") in kinds
    assert sum(k == "no-team" for _, k in kinds) == 2


def test_copies_and_lost_benchmark_logs() -> None:
    log = bench("bm/log_fbm3w_2015-11-20-10-00-10_0.bag", 10, 60, ns="fbm3w")
    copy = Summary("usb_stick/" + Path(log.path).name, log.start_ns, log.end_ns, log.topics)
    tl = build_timeline(
        [gt("gt/log_mocap_2015-11-20-09-59-58_0.bag", -2, 200, ns="fbm3w"), log, copy],
        unreadable=[Unreadable("bm/log_fbm3w_2015-11-20-11-37-15_0.bag", "not a bag")],
    )
    found = discover(tl)
    # the first by path is the original (the timeline decides); the copy is no execution
    assert [e.bmbox_log for e in found.executions] == [log.path]
    by_kind = {p.kind: p for p in found.problems if p.kind in ("duplicate", "unreadable")}
    assert by_kind["duplicate"].path == copy.path
    lost = [p for p in found.problems if "execution is missing" in p.message]
    assert len(lost) == 1 and "fbm3w execution started 2015-11-20 11:37:15" in lost[0].message


def test_gt_recordings_alone_are_candidate_executions() -> None:
    """The GT recordings no benchmark log overlaps: one candidate per recording (its split
    files in order); the uncovered tail of a recording that covers a benchmark log, a
    recording naming no benchmark and a still marker set's recording are problems."""

    def gt(path: str, start: int, benchmarks: tuple[str, ...] = ("fbm3w",)) -> BagEntry:
        return BagEntry(path, "ros1", start, start + 10, "gt", "gt", benchmarks=benchmarks)

    entries = [
        gt("work/log_fbm3w_mocap_2015-11-20-10-00-00_1.bag", 10),  # listed out of order
        gt("work/log_fbm3w_mocap_2015-11-20-10-00-00_0.bag", 0),
        gt("home/log_fbm2h_mocap_2015-11-20-11-00-00_0.bag", 100, ("fbm2h",)),
        gt("home/log_fbm2h_mocap_2015-11-20-11-00-00_1.bag", 110, ("fbm2h",)),
        gt("odd/log_mocap_2015-11-20-12-00-00_0.bag", 200, ()),
        gt("still/log_fbm3w_static_2015-11-20-13-00-00_0.bag", 300),
    ]
    covering = Pairing("bm/log_fbm2h_0.bag", "benchmark", (entries[2].path,), 100.0, ())
    recordings, problems = _gt_only(entries, (covering,))
    assert [[f.path for f in r] for r in recordings] == [
        [
            "work/log_fbm3w_mocap_2015-11-20-10-00-00_0.bag",
            "work/log_fbm3w_mocap_2015-11-20-10-00-00_1.bag",
        ]
    ]
    assert {(p.path, p.kind) for p in problems} == {
        ("home/log_fbm2h_mocap_2015-11-20-11-00-00_1.bag", "gt-only"),
        ("odd/log_mocap_2015-11-20-12-00-00_0.bag", "gt-only"),
        ("still/log_fbm3w_static_2015-11-20-13-00-00_0.bag", "gt-only"),
    }
    (still,) = [p for p in problems if p.path.startswith("still/")]
    assert "noise recording" in still.message
