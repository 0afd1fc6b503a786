"""``--rules 2015/2016/2017`` on every path of the FBM1 nodes, against their loops run as written.

The nodes (``node_fbm1.py``, each ported statement by statement from its commit, over the
BmBox replayed from the log, ``tests/helpers/bmbox2015.py``): ``scripts/fbm1h`` at e373be0
(RoCKIn 2015 Lisbon, ``--rules 2015``), ``scripts/fbm1w`` at 7628309 (RoCKIn 2015 Lisbon,
``--rules 2015``), ``scripts/fbm1h`` at 40ba68b (the Lisbon 2016 second local competition,
``--rules 2016``) and at 89dfa75 (the Lisbon 2017 major tournament, ``--rules 2017``).

The logs are generated with the samples' writer, one per path: a normal benchmark of 10
runs; a RefBox timeout at the 10th run (the loop ends by its count) and at the 7th (the node goes
on: its next manual operation waits until the log ends); a RefBox stop while the robot works and
one during the manual operation; the seed's bare ``timeout`` / ``halt`` (no string BmBox.py
compares: the BmBox waits on for the robot); an END payload no 2015 code knew; the log cut
inside every phase of a run. The rule for a cut (issue 23): the benchmark stopped there. Each
node's logs carry its item broadcasts where it made them (2015: after the answer; 2016-17:
after the placement). ertools' ``--rules`` must equal the replay to 1e-12 (relative), field
for field; the default must score every one of these logs (exit 0, numbers, the deviations
said).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from ertools.cli.main import main
from ertools.simulator.mocap import MocapNoise, publish_mocap, simulate_mocap
from ertools.simulator.statemachine import Transition, publish_states
from ertools.simulator.writer import BagWriter
from ertools.states import BmBoxState, ClientState, Machine, RefBoxState
from tests.benchmarks.fbm1.node_fbm1 import VERSIONS, fbm1_node
from tests.benchmarks.fbm1.test_fbm1_nodes import read_log, tf_lookup

pytestmark = pytest.mark.slow

S = 1_000_000_000
MS = 1_000_000
T0 = 1_448_020_000 * S
REL = 1e-12
NS = "fbm1h"
BENCHMARK_RUNS = 10  # scripts/fbm1h line 13
RUN_S = 4  # one run every 4 s, from 3 s on
RATE_HZ = 60  # enough for the node's interpolated lookup; keeps the logs small

ITEMS = [
    {
        "class": "mug",
        "id": k + 1,
        "instance": f"mug{k + 1}",
        "rot": [0.0, 0.0, math.sin(0.1 * k), math.cos(0.1 * k)],
        "trans": [0.01 * k, -0.02, 0.001],
    }
    for k in range(BENCHMARK_RUNS)
]


# ----------------------------------------------------------------------------- the logs


@dataclass(frozen=True)
class Case:
    """One path: what happens in each run (the last one's outcome ends the benchmark unless
    it is an answer), and where the log is cut (run, phase) if it is."""

    outcomes: tuple[str, ...]
    cut: tuple[int, str] | None = None
    end_payload: str = ""


# Seconds into a run: the manual operation, the referee's confirmation, the goal, the robot's
# acknowledgement, the wait, the answer, the BmBox back to READY.
# The node sleeps 1 s after each answer (lines 119, 121): the next manual operation comes later.
WMO, PLACED, CMO, TG, CLIENT_EG, EG, WR, ANSWER, DONE = (
    0.0,
    1.0,
    1.02,
    1.5,
    1.55,
    1.6,
    1.7,
    2.8,
    2.9,
)
# Where each phase of a run is cut (seconds into the run): inside its state.
CUT_AT = {"WMO": 0.5, "CMO": 1.2, "TG": 1.52, "EG": 1.65, "WR": 2.5, "READY": 3.4}
ANSWERS = [  # dx, dy (m), dtheta (deg), class right, instance right
    (0.01, -0.02, 8.0, True, True),
    (0.02, 0.01, -4.0, True, False),
    (0.72, 0.96, 3.0, True, True),  # 1.2 m off: unclipped in 2015
    (0.0, 0.03, 190.0, False, False),  # theta across +-180: one wrap
    (-0.01, 0.0, 550.0, True, True),  # one wrap is not enough
]


def _board(k: int) -> tuple[float, float, float]:
    """The board in the table frame during run k (x, y, yaw rad); it drifts 2 mm/s."""
    return 0.3 + 0.02 * k, 0.2 + 0.01 * (k % 3), -2.9 + 0.6 * k


def write_case(
    path: Path, case: Case, ns: str = NS, named_while: str = "both", node: str = "2015"
) -> Path:
    """The log of ``case``: state topics, 60 Hz mocap of table and board (pose topics and /tf,
    as the 2015 mocap node), the node's item broadcasts on /tf (``node`` 2015: after the answer;
    2016 or 2017: after the placement). At @Work (``ns="fbm1w"``) the RefBox names the item
    (its payload while it executes the manual operation and the goal), the BmBox's manual
    operation has none; ``named_while="goal"``: only in the EXECUTING_GOAL that confirms the
    placement (what ``ManualOperation()`` returned to the 2015 node)."""

    def at(k: int, s: float) -> int:
        return T0 + round((3 + RUN_S * k + s) * S)

    tr = [
        Transition(T0 + S // 2, Machine.BMBOX, BmBoxState.START),
        Transition(T0 + S // 2, Machine.REFBOX, RefBoxState.START),
        Transition(T0 + S // 2, Machine.CLIENT, ClientState.START),
        Transition(T0 + 1 * S, Machine.BMBOX, BmBoxState.WAITING_CLIENT),
        Transition(T0 + 1 * S + S // 2, Machine.CLIENT, ClientState.READY),
        Transition(T0 + 1 * S + S // 2 + 10 * MS, Machine.REFBOX, RefBoxState.READY),
        Transition(T0 + 2 * S, Machine.BMBOX, BmBoxState.READY),
        Transition(T0 + 2 * S + S // 2, Machine.CLIENT, ClientState.WAITING_GOAL),
    ]
    casts: list[tuple[int, dict[str, Any]]] = []
    cut_ns = None if case.cut is None else at(case.cut[0], CUT_AT[case.cut[1]])
    rng = np.random.default_rng(len(case.outcomes) * 31 + len(tr))
    table_xyz, r_t = np.array([1.0, 2.0, 0.7]), Rotation.from_euler("z", 0.3)
    n_runs = len(case.outcomes)
    end_s = 3 + RUN_S * n_runs + 2
    t = T0 + np.arange(0, end_s * RATE_HZ) * (S // RATE_HZ)
    secs = (t - T0) / S
    rel = np.tile([-0.5, -0.5, 0.0, 0.0], (t.size, 1))  # the board off the table between runs

    for k, outcome in enumerate(case.outcomes):
        bx, by, byaw = _board(k)
        on = (secs >= 3 + RUN_S * k + 0.3) & (secs < 3 + RUN_S * (k + 1) - 0.2)
        rel[on] = [bx, by, 0.02, byaw]
        rel[on, 0] += 0.002 * (secs[on] - 3 - RUN_S * k)
        item = ITEMS[(3 * k + 1) % BENCHMARK_RUNS]
        payload = f"Place item {item['id']} ({item['instance']}) on the table"
        named = item["instance"] if ns == "fbm1w" else ""
        tr += [
            Transition(
                at(k, WMO),
                Machine.BMBOX,
                BmBoxState.WAITING_MANUAL_OPERATION,
                "" if ns == "fbm1w" else payload,
            ),
            Transition(
                at(k, 0.05),
                Machine.REFBOX,
                RefBoxState.EXECUTING_MANUAL_OPERATION,
                "" if named_while == "goal" else named,
            ),
        ]
        if outcome == "stop-manual":
            tr += [
                Transition(at(k, 0.8), Machine.REFBOX, RefBoxState.END, case.end_payload),
                Transition(at(k, 0.82), Machine.BMBOX, BmBoxState.READY),
            ]
            break
        tr += [
            Transition(at(k, PLACED), Machine.REFBOX, RefBoxState.EXECUTING_GOAL, named),
            Transition(at(k, CMO), Machine.BMBOX, BmBoxState.COMPLETED_MANUAL_OPERATION),
            Transition(at(k, TG), Machine.BMBOX, BmBoxState.TRANSMITTING_GOAL),
            Transition(at(k, CLIENT_EG), Machine.CLIENT, ClientState.EXECUTING_GOAL),
            Transition(at(k, EG), Machine.BMBOX, BmBoxState.EXECUTING_GOAL),
            Transition(at(k, WR), Machine.BMBOX, BmBoxState.WAITING_RESULT),
        ]
        if node != "2015":
            casts.append((at(k, CMO) + 7 * MS, item))
        if outcome in ("timeout", "stop", "timeout-wait"):
            tr += [
                Transition(at(k, 2.4), Machine.REFBOX, RefBoxState.END, case.end_payload),
                Transition(at(k, 2.4) + 30 * MS, Machine.CLIENT, ClientState.END),
                Transition(at(k, 2.4) + 50 * MS, Machine.BMBOX, BmBoxState.READY),
            ]
            if outcome == "timeout-wait":
                # The node goes on (Running() is true): its next manual operation waits for a
                # RefBox that has ended, until the log ends.
                nxt = ITEMS[(3 * (k + 1) + 1) % BENCHMARK_RUNS]
                text = f"Place item {nxt['id']} ({nxt['instance']}) on the table"
                tr.append(
                    Transition(
                        at(k + 1, WMO),
                        Machine.BMBOX,
                        BmBoxState.WAITING_MANUAL_OPERATION,
                        "" if ns == "fbm1w" else text,
                    )
                )
                cut_ns = at(k + 1, CUT_AT["WMO"])
            break
        if outcome == "unknown":  # an END the BmBox did not understand: it waits on
            tr.append(Transition(at(k, 2.4), Machine.REFBOX, RefBoxState.END, case.end_payload))
        dx, dy, dth, c_ok, i_ok = ANSWERS[k % len(ANSWERS)]
        m = (
            np.linalg.inv(_matrix(table_xyz, r_t.as_quat()))
            @ _matrix(_world(table_xyz, r_t, bx + 0.002 * 2, by), _quat(r_t, byaw))
            @ _matrix(item["trans"], item["rot"])
        )
        answer = {
            "item_class": item["class"] if c_ok else "plate",
            "item_instance": item["instance"] if i_ok else "plate1",
            "x": round(float(m[0, 3] + dx), 4),
            "y": round(float(m[1, 3] + dy), 4),
            "theta": round(math.degrees(math.atan2(m[1, 0], m[0, 0])) + dth, 2),
        }
        text = yaml.safe_dump(answer, default_flow_style=True).strip()
        tr += [
            Transition(at(k, ANSWER), Machine.CLIENT, ClientState.COMPLETED_GOAL, text),
            Transition(at(k, DONE), Machine.BMBOX, BmBoxState.READY),
            Transition(at(k, DONE) + 40 * MS, Machine.CLIENT, ClientState.WAITING_GOAL),
        ]
        if node == "2015":
            casts.append((at(k, DONE) + 7 * MS, item))
    last = max(x.t_ns for x in tr)
    if cut_ns is None:
        tr += [
            Transition(last + S // 2, Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE, "{}"),
            Transition(last + S, Machine.BMBOX, BmBoxState.END),
        ]
    keep = t <= (cut_ns if cut_ns is not None else t[-1])
    xyz_w = np.array([_world(table_xyz, r_t, x, y) for x, y in rel[:, :2]])
    xyz_w[:, 2] += rel[:, 2]
    q_w = (r_t * Rotation.from_euler("z", rel[:, 3:4])).as_quat()
    with BagWriter(path, "ros1") as bag:
        for body, xyz, q in (
            ("origin", np.tile(table_xyz, (t.size, 1)), np.tile(r_t.as_quat(), (t.size, 1))),
            ("ref_board", xyz_w, q_w),
        ):
            pub = simulate_mocap(t[keep], xyz[keep], q[keep], rng=rng, noise=MocapNoise())
            publish_mocap(bag, ns, body, pub)
        publish_states(bag, ns, sorted(tr, key=lambda x: x.t_ns), end_ns=cut_ns)
        for t_cast, item in casts:
            if cut_ns is None or t_cast <= cut_ns:
                bag.write_tf(
                    np.array([t_cast + 300_000]),
                    np.array([t_cast]),
                    "ref_board",
                    "item",
                    np.array([item["trans"]], dtype=float),
                    np.array([item["rot"]], dtype=float),
                    callerid=f"/{ns}/benchmark",
                )
    return path


def _world(table_xyz: np.ndarray, r_t: Rotation, x: float, y: float) -> np.ndarray:
    return np.asarray(r_t.apply([x, y, 0.0]) + table_xyz)


def _quat(r_t: Rotation, yaw: float) -> np.ndarray:
    return np.asarray((r_t * Rotation.from_euler("z", yaw)).as_quat())


def _matrix(p: Any, q: Any) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(q).as_matrix()
    m[:3, 3] = p
    return m


# ----------------------------------------------------------------------------- the paths

FULL = ("answer",) * BENCHMARK_RUNS
CASES: dict[str, Case] = {
    "normal": Case(FULL),
    "timeout": Case(("answer",) * 9 + ("timeout",), end_payload="reason: timeout"),
    # The seed's bare words (6.2.3) are neither string BmBox.py compares: its BmBox waited on
    # for the robot, as for any END it did not know (lines 49-55).
    "timeout-seed-form": Case(("answer",) * 9 + ("unknown",), end_payload="timeout"),
    "timeout-then-waits": Case(("answer",) * 6 + ("timeout-wait",), end_payload="reason: timeout"),
    "stop-during-goal": Case(("answer",) * 5 + ("stop",), end_payload="reason: stop"),
    "halt-seed-form": Case(("answer",) * 9 + ("unknown",), end_payload="halt"),
    "stop-during-manual-operation": Case(
        ("answer",) * 5 + ("stop-manual",), end_payload="reason: stop"
    ),
    "unknown-end-payload": Case(("answer",) * 9 + ("unknown",), end_payload="reason: finished"),
    **{
        f"cut-in-{phase}": Case(("answer",) * 6, cut=(5 if phase != "READY" else 4, phase))
        for phase in ("WMO", "CMO", "TG", "EG", "WR", "READY")
    },
}
# scripts/fbm1w has no run cap (``while benchmark.Running():``): its benchmark ends when the
# RefBox stops it, the last run counted while waiting for its manual operation. After a RefBox
# timeout, or an END it did not know, it waits for the next manual operation until the log
# ends; the 10th run is not the last for it, so those cases end at the 7th run here.
CASES_1W = {
    name: Case((*FULL, "stop-manual"), end_payload="reason: stop") if name == "normal" else case
    for name, case in CASES.items()
    if name == "timeout-then-waits" or not name.startswith(("timeout", "unknown", "halt"))
}
# Under --rules 2015 these END payloads are none of the two strings: warned about.
UNKNOWN_2015 = ("unknown-end-payload", "timeout-seed-form", "halt-seed-form")
# (node version of node_fbm1.VERSIONS, case): every case at every version of each script.
PATHS = [(v, n) for v in ("2015", "2016", "2017") for n in CASES] + [("2015w", n) for n in CASES_1W]


def _score(
    bag: Path, items: Path, args: list[str], capsys: Any, ns: str = NS
) -> tuple[dict[str, Any], str]:
    # the replayed node's numbers are the subject, not the intervals: no Monte Carlo draws
    argv = ["score", ns, str(bag), "--items", str(items), "--format", "json", "--draws", "0"]
    code = main([*argv, *args])
    out, err = capsys.readouterr()
    assert code == 0, err
    data: dict[str, Any] = json.loads(out)
    return data, err


def _close(got: float, want: float) -> bool:
    return got == pytest.approx(want, rel=REL, abs=1e-15)


def _run_node(bag: Path, version: str) -> dict[str, Any]:
    ns = VERSIONS[version][0]
    log = read_log(bag, ns)
    return fbm1_node(
        log.states, ITEMS, log.item_stamps, lambda item, t: tf_lookup(log, item, t), version
    )


@pytest.mark.parametrize(("version", "name"), PATHS)
def test_rules_are_the_node_on_every_path(
    version: str, name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ns = VERSIONS[version][0]
    case = (CASES_1W if ns == "fbm1w" else CASES)[name]
    bag = write_case(tmp_path / f"{name}.bag", case, ns, node=version.rstrip("w"))
    items = tmp_path / "items.yaml"
    items.write_text(yaml.safe_dump({"items": ITEMS}), encoding="utf-8")
    node = _run_node(bag, version)
    data, err = _score(bag, items, ["--rules", version.rstrip("w")], capsys, ns)
    for key, want in node["score"].items():
        assert _close(data[key], want), (key, data[key], want)
    assert len(data["runs"]) == len(node["runs"]), "every run the node counted, no other"
    for index, want in node["runs"].items():
        got = data["runs"][str(index)]
        status = {"aborted": "aborted", "no_answer": "no_answer", "scored": "scored"}
        assert got["status"] == status[want["status"]], index
        if want["status"] != "scored":
            assert not got.get("pose_score"), index
            continue
        gt = got["ground_truth"]
        for a, b in zip((gt["x"], gt["y"], gt["theta"]), want["gt"], strict=True):
            assert _close(a, b), index
        e = got["error"]
        for a, b in zip((e["x"], e["y"], e["theta"]), want["err"], strict=True):
            assert _close(a, b), index
        assert (got["class_correct"], got["instance_correct"]) == (
            want["class_ok"],
            want["instance_ok"],
        )
        assert _close(got["pose_score"], want["pose_score"]), index
        assert _close(got["execution_time"], want["execution_time"]), index
    # What the output says on these paths.
    assert ("stopped there" in err) is node["cut"], err
    assert ("none of the forms" in err) is (name in UNKNOWN_2015), err
    if name in UNKNOWN_2015:
        assert f"RefBox END with payload {case.end_payload!r}" in err

    # The default scores every log the node scored, and says where it differs.
    default, err = _score(bag, items, [], capsys, ns)
    for key in ("class_accuracy", "instance_accuracy", "pose_score", "execution_time"):
        assert isinstance(default[key], float), key
    assert "differs from 2015" in err


def test_the_paths_give_the_numbers_issue_23_names(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Stopped after run 6's goal, cut there, and cut before its goal: one rule for the three
    (the node counts run 6 in ``runs`` in each: 6 runs, the same accuracies)."""
    items = tmp_path / "items.yaml"
    items.write_text(yaml.safe_dump({"items": ITEMS}), encoding="utf-8")
    got = {}
    for name in ("stop-during-goal", "cut-in-WR", "cut-in-WMO"):
        bag = write_case(tmp_path / f"{name}.bag", CASES[name])
        node = _run_node(bag, "2015")
        assert len(node["runs"]) == 6, name
        got[name] = node["score"]
        data, _ = _score(bag, items, ["--rules", "2015"], capsys)
        assert data["class_accuracy"] == pytest.approx(node["score"]["class_accuracy"], rel=REL)
        assert data["runs"]["6"]["status"] == ("aborted" if name == "cut-in-WMO" else "no_answer")
    # 4 of the 5 answered runs have the right class (ANSWERS[3] is wrong), 3 the right
    # instance: over the 6 runs the node counted, in all three logs.
    for score in got.values():
        assert score["class_accuracy"] == pytest.approx(4 / 6, rel=REL)
        assert score["instance_accuracy"] == pytest.approx(3 / 6, rel=REL)
        # the pose score too, over 6 (the mocap noise differs between the logs: 1e-5)
        assert score["pose_score"] == pytest.approx(got["stop-during-goal"]["pose_score"], abs=1e-4)


def test_fbm1w_item_is_what_manual_operation_returned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """scripts/fbm1w took the item from ``ManualOperation()``'s return: the RefBox payload when
    the BmBox left the manual operation. A RefBox that names it only then is read there."""
    items = tmp_path / "items.yaml"
    items.write_text(yaml.safe_dump({"items": ITEMS}), encoding="utf-8")
    bag = write_case(tmp_path / "w.bag", CASES_1W["normal"], "fbm1w", named_while="goal")
    node = _run_node(bag, "2015w")
    data, _ = _score(bag, items, ["--rules", "2015"], capsys, "fbm1w")
    assert [r["status"] for r in data["runs"].values()] == ["scored"] * 10 + ["aborted"]
    for key, want in node["score"].items():
        assert _close(data[key], want), key
