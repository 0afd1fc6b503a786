"""FBM1 validity: a board whose tracking is lost (Motive repeating its last pose) around the
ground truth. Lost before the placement, the repeated pose is where the board was before, not
where it stands: the run is unscoreable. Lost after it, the board stood still: scored, the
repeats counted."""

from __future__ import annotations

import numpy as np

from ertools.benchmarks.fbm1.config import Fbm1Options, ScoreRules
from ertools.benchmarks.fbm1.pipeline import score_fbm1
from ertools.benchmarks.fbm1.runs import runs_from_states
from ertools.configs._yaml import parse_yaml
from ertools.configs.items import parse_items
from ertools.states import Machine
from ertools.streams import PoseStream
from tests.benchmarks.fbm1.fbm1_testkit import (
    ITEMS_YAML,
    T0,
    RunSpec,
    S,
    bodies,
    run_start_s,
    state_streams,
)

GOOD = RunSpec(
    "Place item 3 (b2) on the table",
    "{item_class: b, item_instance: b2, x: 0.35, y: 0.25, theta: 0}",
    (0.3, 0.2, 0.03),
    0.0,
)


def _noisy(body: PoseStream, seed: int) -> PoseStream:
    """The body with 0.1 mm of mocap noise: no two real measurements repeat."""
    xyz = body.xyz + np.random.default_rng(seed).normal(0.0, 1e-4, body.xyz.shape)
    return PoseStream(body.t_ns, xyz, body.quat_xyzw, "world", body.child_frame_id, body.source)


def _frozen(board: PoseStream, from_s: float, to_s: float) -> PoseStream:
    """The board's pose at ``from_s`` repeated until ``to_s`` (tracking lost)."""
    secs = (board.t_ns - T0) / S
    idx = np.flatnonzero((secs >= from_s) & (secs < to_s))
    xyz, quat = board.xyz.copy(), board.quat_xyzw.copy()
    xyz[idx] = xyz[idx[0]]
    quat[idx] = quat[idx[0]]
    return PoseStream(board.t_ns, xyz, quat, "world", "ref_board", board.source)


def _score(board_from_to: tuple[float, float], options: Fbm1Options | None = None):  # type: ignore[no-untyped-def]
    runs = [GOOD]
    streams = state_streams(runs)
    found = runs_from_states(
        streams[Machine.BMBOX], streams[Machine.REFBOX], streams[Machine.CLIENT]
    )
    origin, board = bodies(runs)
    origin, board = _noisy(origin, 1), _noisy(board, 2)
    b = run_start_s(0)
    board = _frozen(board, b + board_from_to[0], b + board_from_to[1])
    items = parse_items(parse_yaml(ITEMS_YAML), "items.yaml")
    return origin, board, score_fbm1(origin, board, found, items, options, t0_ns=T0)


def test_lost_before_the_placement_is_unscoreable() -> None:
    # frozen from 0.5 s (the board still beside the table) to 5.0 s, inside the run: placed at
    # 1.0 s unseen, seen on the table again after the goal (4.0 s)
    _, _, result = _score((0.5, 5.0))
    (run,) = result.runs
    assert run.status == "unscoreable"
    assert run.pose_score is None and run.errors is None
    assert run.unscoreable_reason is not None
    assert run.unscoreable_reason.startswith("no valid ref_board pose within 0.5 s of the")
    assert "moved while unseen" in run.unscoreable_reason
    assert result.failures == (f"run 1: unscoreable: {run.unscoreable_reason}",)
    assert result.nothing_scored  # no run counted: the CLI prints the failure, exit 1
    assert any("[fbm1.unscoreable]" in d for d in result.deviations)
    d = run.to_dict(T0)
    assert d["status"] == "unscoreable" and d["unscoreable_reason"] == run.unscoreable_reason
    # as the 2015 node (its rules set --score-unscoreable): scored from the pose it had, with
    # a warning
    assert Fbm1Options.for_rules("fbm1h", "2015").rules.score_unscoreable
    legacy_rules = Fbm1Options(rules=ScoreRules(score_unscoreable=True))
    _, _, legacy = _score((0.5, 5.0), legacy_rules)
    assert legacy.runs[0].status == "scored"
    assert any(
        "2015 scored this run from a ground truth that was not measured then" in w
        for w in legacy.warnings
    )


def test_seen_again_only_after_the_run_is_given_the_benefit() -> None:
    # frozen beside the table until 9.0 s, after the result (6.0 s): the board may have been
    # moved on purpose then; nothing while the robot looked shows that it moved
    _, _, result = _score((0.5, 9.0))
    assert result.runs[0].status == "scored"
    assert result.runs[0].validity is not None
    assert result.runs[0].validity.invalid_samples["tracking_lost"] > 0


def test_lost_after_the_placement_is_scored_and_counted() -> None:
    # frozen from 2.0 s to 9.0 s: the board stood where it was last seen
    origin, board, result = _score((2.0, 9.0))
    (run,) = result.runs
    assert run.status == "scored" and run.unscoreable_reason is None
    gt = run.gt
    assert gt is not None and run.validity is not None
    b = run_start_s(0)
    secs = (board.t_ns - T0) / S
    frozen_from = int(board.t_ns[secs >= b + 2.0][0])  # the last measurement, then repeated

    def inside(t: np.ndarray) -> np.ndarray:
        return (t >= gt.start_ns) & (t <= gt.end_ns)

    tb, to = board.t_ns, origin.t_ns
    # every board sample after the first frozen one repeats it
    repeats = int(np.sum(inside(tb) & (tb > frozen_from) & (secs < b + 9.0)))
    assert repeats > 100
    samples = int(np.sum(inside(tb))) + int(np.sum(inside(to)))
    assert run.validity.invalid_samples == {"tracking_lost": repeats}
    assert run.validity.valid_fraction == (samples - repeats) / samples
    lines = result.validity_lines()
    assert lines[0].startswith("validity: run 1 ground truth ")
