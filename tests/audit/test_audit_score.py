"""Live vs recomputed scores: alignment, tolerance and explanations on hand-made scores."""

from __future__ import annotations

import math

import pytest

from ertools.auditing.analyse import audit_states
from ertools.auditing.compare import attach, compare_scores, flatten
from ertools.states import BmBoxState as B
from ertools.states import Machine
from ertools.streams import Provenance
from tests.helpers.audit_streams import heartbeat
from tests.helpers.fakes import FakeResult

WRAP_DEV = "orientation errors are wrapped to [0, pi] (2015 used the unwrapped difference)"


def _fbm2h(orient1: float, dist0: float) -> FakeResult:
    return FakeResult(
        "fbm2h",
        {
            "position_accuracy": 0.2,
            "orientation_accuracy": 0.1,
            "details": {
                "segments_details": {
                    "0": {"dinstance_error": dist0, "orientation_error": 0.05},
                    "1": {"dinstance_error": 0.3, "orientation_error": orient1},
                }
            },
        },
        deviations=(WRAP_DEV,),
        provenance=Provenance(parameters=(("transform", "identity"), ("d_min", "0.001"))),
    )


def test_flatten_paths() -> None:
    assert flatten({"a": {"b": [1, {"c": 2}]}, "d": {}}) == {"a.b.0": 1, "a.b.1.c": 2, "d": {}}


def test_one_based_live_segments_are_aligned_and_differences_explained() -> None:
    # The 2015 node numbered segments from 1. Segment 2 (live) = segment 1 (ertools): its
    # unwrapped yaw difference was 2*pi - 0.4 rad, so 2015's atan2(sin, cos) gave -0.4.
    live = {
        "position_accuracy": 0.2,
        "orientation_accuracy": 0.1 + 5e-7,  # within the 1e-6 tolerance
        "details": {
            "segments_details": {
                1: {"dinstance_error": 0.1, "orientation_error": 0.05},
                2: {"dinstance_error": 0.3, "orientation_error": -0.4},
            }
        },
    }
    cmp = compare_scores(live, _fbm2h(0.4, 0.1 + 2e-3))
    by_key = {line.key: line for line in cmp.lines}
    assert any("numbers from 1" in n for n in cmp.notes)
    assert by_key["orientation_accuracy"].status == "same"
    seg1 = by_key["details.segments_details.1.orientation_error"]
    assert seg1.status == "differs"
    assert seg1.difference == pytest.approx(0.8, abs=1e-12)
    assert "negative of the recomputed" in seg1.explanation
    assert "ertools differs from 2015: " + WRAP_DEV in seg1.explanation
    assert "transform=identity" in seg1.explanation
    seg0 = by_key["details.segments_details.0.dinstance_error"]
    assert seg0.status == "differs" and seg0.difference == pytest.approx(2e-3, abs=1e-12)
    assert "interpolates" in seg0.explanation
    assert "d_min" not in seg0.explanation  # not a parameter of a waypoint error
    assert [line.key for line in cmp.differences] == [
        "details.segments_details.0.dinstance_error",
        "details.segments_details.1.orientation_error",
    ]
    assert cmp.same == 4


def test_keys_only_on_one_side() -> None:
    cmp = compare_scores({"position_accuracy": 0.2, "hits": 3}, _fbm2h(0.4, 0.1))
    status = {line.key: line.status for line in cmp.lines}
    assert status["hits"] == "only live"
    assert status["details.segments_details.1.dinstance_error"] == "only recomputed"
    assert status["position_accuracy"] == "same"


def test_no_live_score() -> None:
    cmp = compare_scores(None, _fbm2h(0.4, 0.1))
    assert cmp.lines == () and cmp.notes


def test_fbm3w_distance_error_names_d_min() -> None:
    rec = FakeResult(
        "fbm3w",
        {"best_distance_error": 0.0102, "runs_details": {"0": {"distance_error": 0.0102}}},
        provenance=Provenance(parameters=(("d_min", "0.001 m"), ("topic", "/fbm3w/x/pose2d"))),
        warnings=("d_min 1 mm is below the noise", "an unrelated warning"),
    )
    cmp = compare_scores(
        {"best_distance_error": 0.0131, "runs_details": {0: {"distance_error": 0.0131}}}, rec
    )
    line = cmp.differences[1]
    assert line.key == "runs_details.0.distance_error"
    assert "d_min=0.001 m" in line.explanation and "topic=/fbm3w/x/pose2d" in line.explanation
    assert "the scorer warned: d_min 1 mm is below the noise" in line.explanation
    assert "unrelated" not in line.explanation
    assert math.isclose(line.difference or 0.0, -0.0029, abs_tol=1e-12)


def test_attach_to_audit() -> None:
    score = "position_accuracy: 0.25\n"
    bm = heartbeat(
        Machine.BMBOX,
        [
            (0.0, B.START, ""),
            (0.5, B.WAITING_CLIENT, ""),
            (1.0, B.READY, ""),
            (1.5, B.TRANSMITTING_SCORE, score),
            (2.0, B.END, ""),
        ],
        2.0,
    )
    rec = FakeResult("fbm2h", {"position_accuracy": 0.2}, failures=("segment 3: no GT",))
    audit = attach(audit_states(bm), rec)
    assert audit.recomputed is rec
    assert audit.comparison is not None and len(audit.comparison.differences) == 1
    assert audit.failures == ("segment 3: no GT",)
    assert audit.findings == 1
    assert audit.tables()["score_comparison"][0]["live"] == 0.25
    assert audit.to_dict()["recomputed"]["position_accuracy"] == 0.2


def test_top_level_segments_are_renested() -> None:
    # The 2015 FBM2 node wrote segments_details at the top level, numbered from 1.
    live = {"segments_details": {1: {"dinstance_error": 0.1}, 2: {"dinstance_error": 0.3}}}
    cmp = compare_scores(live, _fbm2h(0.4, 0.1))
    status = {line.key: line.status for line in cmp.lines}
    assert status["details.segments_details.0.dinstance_error"] == "same"
    assert status["details.segments_details.1.dinstance_error"] == "same"
    assert any("top level" in n for n in cmp.notes) and any("from 1" in n for n in cmp.notes)


def test_no_common_key_shows_the_payload_beside_the_headline() -> None:
    cmp = compare_scores({"score": "see the answers file"}, _fbm2h(0.4, 0.1))
    assert [(x.key, x.status) for x in cmp.lines] == [
        ("position_accuracy", "only recomputed"),
        ("orientation_accuracy", "only recomputed"),
        ("score", "only live"),
    ]
    assert any("no key in common" in n for n in cmp.notes)


def test_rules_2015_tell_deviations_from_data() -> None:
    # Segment 1's orientation: the 2015 rules give the live -0.4 back (a deliberate deviation);
    # segment 0's distance: the 2015 rules still give 0.102, not the live 0.1 (the data).
    live = {
        "details": {
            "segments_details": {
                "0": {"dinstance_error": 0.1, "orientation_error": 0.05},
                "1": {"dinstance_error": 0.3, "orientation_error": -0.4},
            }
        }
    }
    as_2015 = _fbm2h(-0.4 + 1e-5, 0.102)  # 1e-5 rad of noise: within the 0.1 % reproduction
    cmp = compare_scores(live, _fbm2h(0.4, 0.102), as_2015=as_2015)
    by_key = {line.key: line for line in cmp.lines}
    orient = by_key["details.segments_details.1.orientation_error"].explanation
    assert orient.startswith("recomputed with the 2015 rules: -0.39999, the live value")
    dist = by_key["details.segments_details.0.dinstance_error"].explanation
    assert dist.startswith("recomputed with the 2015 rules: 0.102, still not the live value")


def test_rules_2015_timing_band() -> None:
    # 0.1003 vs the live 0.1: 0.3 %, beyond the 0.1 % reproduction but within the 1 % the live
    # node's few-ms-later read explains; 0.1015 (1.5 %) is not.
    live = {"details": {"segments_details": {"0": {"dinstance_error": 0.1}}}}
    key = "details.segments_details.0.dinstance_error"
    near = compare_scores(live, _fbm2h(0.0, 0.1003), as_2015=_fbm2h(0.0, 0.1003))
    assert "a few ms after the logged moment" in {x.key: x for x in near.lines}[key].explanation
    far = compare_scores(live, _fbm2h(0.0, 0.1015), as_2015=_fbm2h(0.0, 0.1015))
    assert "still not the live value" in {x.key: x for x in far.lines}[key].explanation


def test_segments_straight_under_details_are_found() -> None:
    # The early 2015 FBM2 node: score['details'] = segments_detail, numbered from 1.
    live = {"details": {1: {"dinstance_error": 0.1}, 2: {"dinstance_error": 0.3}}}
    cmp = compare_scores(live, _fbm2h(0.4, 0.1))
    status = {line.key: line.status for line in cmp.lines}
    assert status["details.segments_details.0.dinstance_error"] == "same"
    assert status["details.segments_details.1.dinstance_error"] == "same"
    assert "only live" not in status.values()
