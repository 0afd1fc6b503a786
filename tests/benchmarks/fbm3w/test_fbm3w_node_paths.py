"""``--2015`` on every path of the RoCKIn 2015 FBM3@Work node, against its loop run as written.

The node is ``scripts/fbm3w`` at 50b173b (2015-11-30), ported statement by statement in
``node_fbm3w.py`` over the BmBox replayed from the log (``tests/helpers/bmbox2015.py``). It differs
from the versions before it on these paths: 7942ea2 (2015-11-30) scores and times a run the
RefBox timed out and goes on with the next run (before it: time added, no score, ``continue``
with the same run number); 7942ea2 also replaced the 0.30/0.10 line and the semi-ellipse
spline by the line and sine of Listing 15 (``node_fbm3w.TARGETS``).

The logs are generated with the samples' writer, one per path: normal; a RefBox timeout
during the last run's path, during an earlier one (the node then waits for the next manual
operation until the log ends) and during a manual operation (the BmBox back to READY by
BmBox.py 43-44: the node takes its reference there and runs the goal); a stop during a path
and during a manual operation; an END payload no 2015 code knew and the seed's bare
``timeout`` / ``halt`` (to the 2015 BmBox no known string: it waited on for the robot); the
log cut inside every phase of a run (the benchmark stopped there: issue 23). ertools'
``--2015`` must equal the replay to 1e-12 (relative), field for field; the default must score
every one of them and say where it differs.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from ertools.cli.main import main
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState
from tests.benchmarks.fbm3w.node_fbm3w import SPECS, fbm3w_node
from tests.benchmarks.fbm3w.test_fbm3w_2015 import _track

pytestmark = pytest.mark.slow

S = 1_000_000_000
MS = 1_000_000
T0 = 1_448_020_800 * S
REL = 1e-12
TOPIC = "/fbm3w/robot_at_work/pose2d"


# ----------------------------------------------------------------------------- the logs


@dataclass(frozen=True)
class Case:
    """What happens in run ``run`` at ``phase``: a RefBox END (payload) or the log cut there;
    None: the five runs end normally. ``after`` a timeout: ``score`` (the node sends its score:
    the last run), ``wait`` (the node asks for the next manual operation, which never comes,
    until the log ends) or ``go on`` (a timeout during the manual operation: the run goes on)."""

    run: int | None = None
    phase: str = ""
    end_payload: str | None = None  # None: a cut
    after: str = "score"


# Seconds into a run (each 12 s): the manual operation, its confirmation, the goal, the path
# (3 s to 3 + path_s), the answer, READY.
WMO, CONFIRM, CMO, TG, CLIENT_EG, EG, WR, ANSWER, DONE = (
    0,
    1.0,
    1.02,
    1.5,
    1.55,
    3.0,
    3.05,
    8.9,
    9.0,
)
# Where a phase is ended: inside its state.
AT = {"WMO": 0.5, "CMO": 1.2, "TG": 1.52, "EG": 3.02, "WR": 5.0, "READY": 10.5}


def write_case(path: Path, case: Case) -> tuple[list[int], list[tuple[float, float]]]:
    """The log of ``case``: 120 Hz pose2d of the end effector, the three state topics."""
    rng = np.random.default_rng(23)
    tr = [
        Transition(T0, Machine.BMBOX, BmBoxState.START),
        Transition(T0, Machine.REFBOX, RefBoxState.START),
        Transition(T0, Machine.CLIENT, ClientState.START),
        Transition(T0 + S // 10, Machine.BMBOX, BmBoxState.WAITING_CLIENT),
        Transition(T0 + S // 5, Machine.CLIENT, ClientState.READY),
        Transition(T0 + S // 4, Machine.REFBOX, RefBoxState.READY),
        Transition(T0 + S * 3 // 10, Machine.BMBOX, BmBoxState.READY),
    ]
    ts, xys = [], []
    cut_ns = None
    for k, spec in enumerate(SPECS):
        t0 = 1.0 + 12.0 * k

        def at(s: float, t0: float = t0) -> int:
            return T0 + round((t0 + s) * S)

        ends_here = case.run == k
        reach = 0.6 if ends_here and case.phase == "WR" else 1.0
        t, xy = _track(
            t0, spec, reach=reach, path_s=4.0 + k % 2, offset=0.001 * (k + 1),
            origin=(0.4 + 0.2 * k, -0.3), yaw=0.4 * k - 1.0, rng=rng,
        )  # fmt: skip
        ts.append(t)
        xys.append(xy)
        tr += [
            Transition(at(WMO), Machine.BMBOX, BmBoxState.WAITING_MANUAL_OPERATION),
            Transition(at(0.05), Machine.REFBOX, RefBoxState.EXECUTING_MANUAL_OPERATION),
        ]
        if ends_here and case.end_payload is None:
            cut_ns = at(AT[case.phase])
        payload = case.end_payload
        if ends_here and payload is not None and case.phase == "WMO":
            # BmBox.py 43-44: any RefBox END moves it out of WAITING_MANUAL_OPERATION.
            tr += [
                Transition(at(AT["WMO"]), Machine.REFBOX, RefBoxState.END, payload),
                Transition(at(AT["WMO"] + 0.02), Machine.BMBOX, BmBoxState.READY),
            ]
            if case.after != "go on":
                break
        else:
            tr += [
                Transition(at(CONFIRM), Machine.REFBOX, RefBoxState.EXECUTING_GOAL),
                Transition(at(CMO), Machine.BMBOX, BmBoxState.COMPLETED_MANUAL_OPERATION),
            ]
        tr += [
            Transition(at(TG), Machine.BMBOX, BmBoxState.TRANSMITTING_GOAL, spec),
            Transition(at(CLIENT_EG), Machine.CLIENT, ClientState.EXECUTING_GOAL),
            Transition(at(EG), Machine.BMBOX, BmBoxState.EXECUTING_GOAL),
        ]
        if ends_here and payload is not None and case.phase == "EG":
            # The timeout reaches the BmBox before the node's own WAITING_RESULT (BmBox.py
            # 49-50 from EXECUTING_GOAL): WaitResult() returns at once.
            tr += [
                Transition(at(AT["EG"]), Machine.REFBOX, RefBoxState.END, payload),
                Transition(at(AT["EG"] + 0.01), Machine.CLIENT, ClientState.END),
                Transition(at(AT["EG"] + 0.02), Machine.BMBOX, BmBoxState.READY),
            ]
            break
        tr.append(Transition(at(WR), Machine.BMBOX, BmBoxState.WAITING_RESULT))
        if ends_here and payload is not None and case.phase == "WR":
            tr.append(Transition(at(AT["WR"]), Machine.REFBOX, RefBoxState.END, payload))
            if payload in ("reason: timeout", "reason: stop"):
                tr += [
                    Transition(at(AT["WR"] + 0.02), Machine.CLIENT, ClientState.END),
                    Transition(at(AT["WR"] + 0.05), Machine.BMBOX, BmBoxState.READY),
                ]
                if case.after == "wait":
                    # The RefBox published its END once: the next manual operation waits.
                    wmo = BmBoxState.WAITING_MANUAL_OPERATION
                    tr.append(Transition(at(12.0), Machine.BMBOX, wmo))
                    cut_ns = at(12.5)
                break
            # Not a string the BmBox compared (the seed's bare words neither): it waited on for
            # the robot (BmBox.py lines 49-55).
        tr += [
            Transition(at(ANSWER), Machine.CLIENT, ClientState.COMPLETED_GOAL, "done"),
            Transition(at(DONE), Machine.BMBOX, BmBoxState.READY),
            Transition(at(DONE + 0.05), Machine.CLIENT, ClientState.WAITING_GOAL),
        ]
    last = max(x.t_ns for x in tr)
    if cut_ns is None:
        tr += [
            Transition(last + S // 4, Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE, "{}"),
            Transition(last + S // 2, Machine.BMBOX, BmBoxState.END),
        ]
    t_ns = T0 + np.round(np.concatenate(ts) * S).astype(np.int64)
    xy_all = np.vstack(xys)
    keep = t_ns <= (cut_ns if cut_ns is not None else t_ns[-1])
    with BagWriter(path, "ros1") as bag:
        bag.write_pose2d(TOPIC, t_ns[keep], xy_all[keep, 0], xy_all[keep, 1], np.zeros(keep.sum()))
        publish_states(bag, "fbm3w", sorted(tr, key=lambda x: x.t_ns), end_ns=cut_ns)
    return t_ns[keep].tolist(), [tuple(p) for p in xy_all[keep].tolist()]


def _states(bag: Path) -> dict[str, list[tuple[int, int, str]]]:
    out: dict[str, list[tuple[int, int, str]]] = {"bmbox": [], "refbox": []}
    with AnyReader([bag]) as reader:
        for machine, rows in out.items():
            conns = [c for c in reader.connections if c.topic == f"/fbm3w/{machine}_state"]
            for c, t, raw in reader.messages(connections=conns):
                m = reader.deserialize(raw, c.msgtype)
                rows.append((t, int(m.state), str(m.payload)))
    return out


CASES: dict[str, Case] = {
    "normal": Case(),
    "timeout": Case(4, "WR", "reason: timeout"),
    "timeout-then-waits": Case(2, "WR", "reason: timeout", after="wait"),
    "timeout-before-waiting-result": Case(4, "EG", "reason: timeout"),
    "timeout-during-manual-operation": Case(3, "WMO", "reason: timeout", after="go on"),
    "timeout-seed-form": Case(4, "WR", "timeout"),
    "stop-during-path": Case(2, "WR", "reason: stop"),
    "halt-seed-form": Case(2, "WR", "halt"),
    "stop-during-manual-operation": Case(2, "WMO", "reason: stop"),
    "unknown-end-payload": Case(4, "WR", "reason: finished"),
    **{f"cut-in-{p}": Case(2, p) for p in ("WMO", "CMO", "TG", "EG", "WR")},
    "cut-in-READY": Case(1, "READY"),
}
# What the node does on each path, read from its source by hand: the runs it scores (and
# times), whether the log's end stopped it.
BY_HAND = {
    "normal": ([0, 1, 2, 3, 4], False),
    "timeout": ([0, 1, 2, 3, 4], False),
    "timeout-then-waits": ([0, 1, 2], True),
    "timeout-before-waiting-result": ([0, 1, 2, 3, 4], False),
    "timeout-during-manual-operation": ([0, 1, 2, 3, 4], False),
    "timeout-seed-form": ([0, 1, 2, 3, 4], False),
    "stop-during-path": ([0, 1], False),
    "halt-seed-form": ([0, 1, 2, 3, 4], False),
    "stop-during-manual-operation": ([0, 1], False),
    "unknown-end-payload": ([0, 1, 2, 3, 4], False),
    **{f"cut-in-{p}": ([0, 1], True) for p in ("WMO", "CMO", "TG", "EG", "WR")},
    "cut-in-READY": ([0, 1], True),
}


def _score(bag: Path, args: list[str], capsys: Any) -> tuple[dict[str, Any], str]:
    # the replayed node's numbers are the subject, not the intervals: no Monte Carlo draws
    code = main(["score", "fbm3w", str(bag), "--format", "json", "--draws", "0", *args])
    out, err = capsys.readouterr()
    assert code == 0, err
    data: dict[str, Any] = json.loads(out)
    return data, err


def _close(got: float, want: float) -> bool:
    return got == pytest.approx(want, rel=REL, abs=1e-15)


def _node(name: str, tmp_path: Path) -> tuple[Path, dict[str, Any]]:
    bag = tmp_path / f"{name}.bag"
    t, xy = write_case(bag, CASES[name])
    states = _states(bag)
    return bag, fbm3w_node(states["bmbox"], states["refbox"], t, xy)


@pytest.mark.parametrize("name", list(CASES))
def test_the_port_follows_the_source(name: str, tmp_path: Path) -> None:
    """The replay's outcome on each path is the one read from the source by hand."""
    _, node = _node(name, tmp_path)
    scored, cut = BY_HAND[name]
    runs = node["runs_details"]
    assert [k for k, r in runs.items() if "distance_error" in r] == scored
    assert [k for k, r in runs.items() if "execution_time" in r] == scored
    assert node["cut"] is cut
    if name.startswith("timeout") and name != "timeout-seed-form":
        run = CASES[name].run
        assert runs[run]["timeout"] and "distance_error" in runs[run]


@pytest.mark.parametrize("name", list(CASES))
def test_2015_is_the_node_on_every_path(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, node = _node(name, tmp_path)
    data, err = _score(bag, ["--2015"], capsys)
    assert data["best_run"] == node["best_run"]
    assert _close(data["best_distance_error"], node["best_distance_error"])
    assert _close(data["execution_time"], node["execution_time"])
    scored = {int(k): r for k, r in data["runs_details"].items() if r["distance_error"] is not None}
    want = {k: r for k, r in node["runs_details"].items() if "distance_error" in r}
    assert set(scored) == set(want), "the runs the node scored, no other"
    for k, r in want.items():
        assert _close(scored[k]["distance_error"], r["distance_error"]), k
        assert _close(scored[k]["execution_time"], r["execution_time"]), k
    assert ("stopped there" in err) is node["cut"], err
    if name == "timeout-before-waiting-result":
        # One kept pose: scripts/fbm3w divides an empty sum by N = 1; the best run.
        assert data["runs_details"]["4"]["distance_error"] == 0.0 and data["best_run"] == 4
        assert "2015 scored it error_sum / N = 0.0 over its one kept pose" in err
    unknown_2015 = ("unknown-end-payload", "timeout-seed-form", "halt-seed-form")
    assert ("none of the forms" in err) is (name in unknown_2015), err

    # The default scores every log the node scored; where it differs, it says so.
    default, err = _score(bag, [], capsys)
    assert isinstance(default["execution_time"], float)
    assert default["best_run"] is not None
    if name != "normal":
        assert "differs from 2015" in err


def test_issue_23_stopped_and_cut_runs_add_no_time_in_2015(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Item 5: a run stopped with the exact 2015 payload is neither scored nor timed under
    --2015 (its time counted in the default, said); item 6: a log ending inside a run is that
    run stopped there: the same numbers."""
    got = {}
    for name in ("stop-during-path", "cut-in-WR"):
        bag = tmp_path / f"{name}.bag"
        write_case(bag, CASES[name])
        got[name], _ = _score(bag, ["--2015"], capsys)
        default, err = _score(bag, [], capsys)
        run2 = default["runs_details"]["2"]
        assert run2["status"] == "stopped" and run2["distance_error"] is None
        assert _close(
            default["execution_time"], got[name]["execution_time"] + run2["execution_time"]
        )
        assert "[fbm3w.stopped-runs]" in err
    # Runs 0 and 1 complete in both (4 s and 5 s paths: EXECUTING_GOAL to READY is 6 s each).
    for data in got.values():
        assert _close(data["execution_time"], 12.0)
        assert set(data["runs_details"]) == {"0", "1", "2"}


def test_rules_2015_is_2015(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--rules 2015`` is ``--2015``, the spelling FBM1 and FBM2@Home share."""
    bag, node = _node("timeout-then-waits", tmp_path)
    flag, _ = _score(bag, ["--2015"], capsys)
    rules, _ = _score(bag, ["--rules", "2015"], capsys)
    assert rules == flag and _close(rules["execution_time"], node["execution_time"])
    assert main(["score", "fbm3w", str(bag), "--rules", "2015", "--arc-length"]) == 2
    assert "contradict" in capsys.readouterr().err
