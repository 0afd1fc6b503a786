"""Simulated RSBB runs (ERL @Home 2017-19): the bag and the result file a run left.

Given a timed :class:`RsbbScenario` (the manual operations, goals, stop, the script's tf
broadcasts and saves, the mocap bodies as :func:`ertools.simulator.mocap.simulate_mocap`
publishes them), :func:`write_rsbb_run` writes what the RSBB recorded (docs/rsbb.md):
``rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag`` with the RefBox state (at each change and at
10 Hz), the BmBox state (10 Hz only), ``/timeout``, the live score, ``/tf`` (mocap bodies under
``testbed_origin``, the static ``testbed_origin -> map``, the script's broadcasts), the bodies'
pose topics, the map and, with referee items, ``/core/to_gui``; and
``results/<CODE>/<team>/result_run_<n>_<date>.yaml``.

The scenario's scores are given, never computed here: the simulator knows no scoring code
(a benchmark's ``sample`` module, or a test's replay of the script, supplies them).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import (
    BMBOX_STATE_TOPIC,
    BMBOX_STATE_TYPE,
    CORE_TO_GUI_TOPIC,
    CORE_TO_GUI_TYPE,
    LIVE_SCORE_TOPIC,
    LOGS_DIR,
    MAP_FRAME,
    MOCAP_PARENT,
    MSG_DEFINITIONS,
    REFBOX_STATE_TOPIC,
    REFBOX_STATE_TYPE,
    RESULTS_DIR,
    STATE_PERIOD_NS,
    TIMEOUT_TOPIC,
    BmBoxState,
    RefBoxState,
    body_pose2d_topic,
    body_pose_topic,
)
from ertools.simulator.mocap import MocapPublished, simple_map
from ertools.simulator.packing import rosbags_name
from ertools.simulator.rsbb_scenario import (
    RsbbScenario,
    Save,
    live_score_text,
    local_time,
    result_object,
    result_time_text,
)
from ertools.simulator.writer import BagWriter

MS = 1_000_000
#: The mocap node's /tf copy of a pose: stamped this after the pose topic's header (its own
#: ``ros::Time::now()``) and recorded this after the pose message (what a script's tf listener
#: holds: a benchmark's sample computes its live score from these).
TF_STAMP_LAG_NS = 5_000
TF_RECORD_LAG_NS = 40_000
BMBOX_CALLER = "/rsbb/rsbb_bmbox"
CORE_CALLER = "/rsbb/roah_rsbb_core"
MOCAP_CALLER = "/rsbb/mocap_node"


@frozen_dataclass
class RunPaths:
    """The files one simulated run wrote."""

    bag: Path
    result: Path


# --- the state machines' messages ------------------------------------------------------------


def _refbox_changes(sc: RsbbScenario) -> list[tuple[int, tuple[int, str, int, str, int, str]]]:
    """(time, full RefBox state) at each change, as the RefBox published them."""
    out: list[tuple[int, tuple[int, str, int, str, int, str]]] = []
    state: list[Any] = [int(RefBoxState.START), "", int(RefBoxState.START), ""]
    state += [int(RefBoxState.START), ""]

    def put(t: int, **changes: Any) -> None:
        for key, value in changes.items():
            state[{"b": 0, "bp": 1, "g": 2, "gp": 3, "m": 4, "mp": 5}[key]] = value
        full = (
            int(state[0]),
            str(state[1]),
            int(state[2]),
            str(state[3]),
            int(state[4]),
            str(state[5]),
        )
        out.append((t, full))

    put(sc.t_connect_ns)
    if sc.t_start_ns is None:
        return out
    s = sc.t_start_ns
    put(s, b=RefBoxState.EXECUTING_BENCHMARK)
    put(s + 1, g=RefBoxState.READY)
    put(s + 2, m=RefBoxState.READY)
    events: list[tuple[int, dict[str, Any]]] = []
    for mo in sc.manual_operations:
        events.append(
            (mo.t_request_ns, {"m": RefBoxState.EXECUTING_MANUAL_OPERATION, "mp": mo.request})
        )
        if mo.t_done_ns is not None:
            events.append((mo.t_done_ns, {"m": RefBoxState.READY, "mp": mo.answer}))
    for g in sc.goals:
        events.append((g.t_request_ns, {"g": RefBoxState.TRANSMITTING_GOAL, "gp": ""}))
        if g.t_start_ns is not None:
            events.append((g.t_start_ns, {"g": RefBoxState.EXECUTING_GOAL, "gp": ""}))
        if g.t_end_ns is not None and g.outcome in ("result", "timeout"):
            payload = g.result if g.outcome == "result" else ""
            events.append((g.t_end_ns, {"g": RefBoxState.READY, "gp": payload}))
    if sc.t_end_ns is not None and sc.end is not None:
        kind = {
            "end": RefBoxState.END,
            "stop": RefBoxState.STOP,
            "global_timeout": RefBoxState.GLOBAL_TIMEOUT,
        }[sc.end]
        events.append((sc.t_end_ns, {"b": kind}))
    for t, changes in sorted(events, key=lambda e: e[0]):
        put(t, **{k: (int(v) if isinstance(v, RefBoxState) else v) for k, v in changes.items()})
    return out


def _bmbox_changes(sc: RsbbScenario) -> list[tuple[int, int, str]]:
    """(time, state, payload) of the BmBox's state machine (published at 10 Hz only)."""
    out = [
        (sc.t_setup_ns, int(BmBoxState.START), ""),
        (sc.t_setup_ns + 5 * MS, int(BmBoxState.WAITING_CLIENT), ""),
    ]
    if sc.t_start_ns is None:
        return out
    ready = int(BmBoxState.READY)
    out.append((sc.t_start_ns + 3 * MS, ready, ""))
    stop = sc.t_end_ns if sc.end in ("stop", "global_timeout") else None
    for mo in sc.manual_operations:
        out.append((mo.t_request_ns - 2 * MS, int(BmBoxState.WAITING_MANUAL_OPERATION), mo.request))
        done = mo.t_done_ns if mo.t_done_ns is not None else stop
        if done is not None:
            out.append((done + 1 * MS, ready, ""))
    for g in sc.goals:
        out.append((g.t_request_ns - 2 * MS, int(BmBoxState.TRANSMITTING_GOAL), g.request))
        end = g.t_end_ns if g.t_end_ns is not None else stop
        if g.t_start_ns is not None:
            out.append((g.t_start_ns + 1 * MS, int(BmBoxState.EXECUTING_GOAL), g.request))
            out.append((g.t_start_ns + 2 * MS, int(BmBoxState.WAITING_RESULT), ""))
        if end is not None:
            out.append((end + 1 * MS, ready, ""))
    if sc.end == "end" and sc.t_end_ns is not None:
        out.append((sc.t_end_ns + 5 * MS, int(BmBoxState.END), ""))
    out.append((sc.t_disconnect_ns, int(BmBoxState.END), ""))
    return sorted(out, key=lambda e: e[0])


def _sample(changes: Sequence[tuple[int, Any]], ticks: np.ndarray) -> list[Any]:
    """The value in force at each tick (the last change at or before it)."""
    times = np.array([c[0] for c in changes], dtype=np.int64)
    idx = np.searchsorted(times, ticks, side="right") - 1
    return [changes[int(i)][1] for i in idx]


# --- the bag ------------------------------------------------------------------------------------


def register_types(bag: BagWriter) -> None:
    """Add the RSBB message types to the writer's type store (once per store)."""
    from rosbags.typesys import get_types_from_msg  # lazy: rosbags, 100 ms

    missing = {
        n: d for n, d in MSG_DEFINITIONS.items() if rosbags_name(n) not in bag.typestore.types
    }
    types: dict[str, Any] = {}
    for name, text in missing.items():
        types.update(get_types_from_msg(text, rosbags_name(name)))
    if types:
        bag.typestore.register(types)


def _write_states(bag: BagWriter, sc: RsbbScenario) -> None:
    refbox = _refbox_changes(sc)
    beats = np.arange(
        sc.t_connect_ns + 50 * MS, sc.t_disconnect_ns, STATE_PERIOD_NS, dtype=np.int64
    )
    times = np.concatenate([np.array([t for t, _ in refbox], np.int64), beats])
    values = [v for _, v in refbox] + _sample(refbox, beats)
    order = np.argsort(times, kind="stable")
    conn = bag.connection(
        REFBOX_STATE_TOPIC, REFBOX_STATE_TYPE, callerid=CORE_CALLER, latching=True
    )
    cls = bag.msgclass(REFBOX_STATE_TYPE)
    bag.write_many(
        conn,
        times[order],
        [
            cls(
                benchmark_state=v[0],
                benchmark_payload=v[1],
                goal_execution_state=v[2],
                goal_execution_payload=v[3],
                manual_operation_state=v[4],
                manual_operation_payload=v[5],
            )
            for v in (values[i] for i in order.tolist())
        ],
    )
    bmbox = _bmbox_changes(sc)
    ticks = np.arange(sc.t_setup_ns + 7 * MS, sc.t_disconnect_ns, STATE_PERIOD_NS, dtype=np.int64)
    sampled = _sample([(t, (s, p)) for t, s, p in bmbox], ticks)
    conn = bag.connection(BMBOX_STATE_TOPIC, BMBOX_STATE_TYPE, callerid=BMBOX_CALLER)
    cls = bag.msgclass(BMBOX_STATE_TYPE)
    bag.write_many(conn, ticks, [cls(state=s, payload=p) for s, p in sampled])


def _write_events(bag: BagWriter, sc: RsbbScenario) -> None:
    stamps = [
        g.t_end_ns - 2 * MS for g in sc.goals if g.outcome == "timeout" and g.t_end_ns is not None
    ]
    if sc.end == "global_timeout" and sc.t_end_ns is not None:
        stamps.append(sc.t_end_ns + 1 * MS)
    if stamps:
        conn = bag.connection(TIMEOUT_TOPIC, "std_msgs/Empty", callerid=CORE_CALLER)
        cls = bag.msgclass("std_msgs/Empty")
        bag.write_many(conn, sorted(stamps), [cls() for _ in stamps])
    if sc.saves:
        texts = [live_score_text(result_object(sc, s.score, s.t_ns), sc.season) for s in sc.saves]
        conn = bag.connection(
            LIVE_SCORE_TOPIC, "std_msgs/String", callerid=BMBOX_CALLER, latching=True
        )
        cls = bag.msgclass("std_msgs/String")
        bag.write_many(conn, [s.t_ns + 1 * MS for s in sc.saves], [cls(data=t) for t in texts])


def _write_tf(bag: BagWriter, sc: RsbbScenario) -> None:
    for body in sc.bodies:
        pub = body.published
        keep = (pub.t_record_ns >= sc.t_record_ns) & (
            pub.t_record_ns <= sc.t_disconnect_ns + 50 * MS
        )
        pub = _take(pub, np.flatnonzero(keep))
        if body.record_topics:
            bag.write_pose_stamped(
                body_pose_topic(body.name),
                pub.t_record_ns,
                pub.t_header_ns,
                MOCAP_PARENT,
                pub.xyz,
                pub.quat_xyzw,
                callerid=MOCAP_CALLER,
            )
            bag.write_pose2d(
                body_pose2d_topic(body.name),
                pub.t_record_ns + 20_000,
                pub.xyz[:, 0],
                pub.xyz[:, 1],
                pub.yaw,
                callerid=MOCAP_CALLER,
            )
        bag.write_tf(
            pub.t_record_ns + TF_RECORD_LAG_NS,
            pub.t_header_ns + TF_STAMP_LAG_NS,
            MOCAP_PARENT,
            body.name,
            pub.xyz,
            pub.quat_xyzw,
            callerid=MOCAP_CALLER,
        )
    # tf's static_transform_publisher: every 100 ms, stamped one period ahead.
    t = np.arange(sc.t_record_ns + 30 * MS, sc.t_disconnect_ns, STATE_PERIOD_NS, dtype=np.int64)
    bag.write_tf(
        t,
        t + STATE_PERIOD_NS,
        MOCAP_PARENT,
        MAP_FRAME,
        np.zeros(3),
        np.array([0.0, 0.0, 0.0, 1.0]),
        callerid="/rsbb/testbed_map_bc",
    )
    for b in sc.broadcasts:
        bag.write_tf(
            b.t_ns + 1 * MS,
            b.t_ns,
            b.parent,
            b.child,
            np.asarray(b.xyz, dtype=np.float64),
            np.asarray(b.quat_xyzw, dtype=np.float64),
            callerid=BMBOX_CALLER,
        )


def _take(pub: MocapPublished, idx: np.ndarray) -> MocapPublished:
    """The recorded part of a body's messages (the recorder runs from connect to disconnect)."""
    return MocapPublished(
        pub.frame_index[idx],
        pub.t_frame_ns[idx],
        pub.t_header_ns[idx],
        pub.t_record_ns[idx],
        pub.xyz[idx],
        pub.quat_xyzw[idx],
        pub.truth_xyz[idx],
        pub.truth_quat_xyzw[idx],
        pub.noise_xyz[idx],
        pub.repeated[idx],
        pub.dropped,
    )


@frozen_dataclass
class ZoneView:
    """What the RefBox's GUI showed of a run's zone at one tick: its state text, its start and
    stop buttons (stop enabled: the benchmark executing), its timer and the items' values (in
    the order of the items given to :func:`write_gui`)."""

    state: str = ""
    stop_enabled: bool = False
    start_enabled: bool = False
    timer_ns: int = 0
    values: tuple[int, ...] | None = None  # None: the items' own (final) values


def write_gui(
    bag: BagWriter,
    ticks: np.ndarray,
    code: str,
    team: str,
    run: int,
    items: Sequence[dict[str, Any]],
    views: Sequence[ZoneView],
) -> None:
    """``/core/to_gui`` at ``ticks`` (10 Hz), one zone: the run's, as ``views`` (one a tick)
    show it, with the referee items (``group_name``, ``desc``, ``type``, ``current_value``)."""
    zgroup = bag.msgclass("roah_rsbb/ZoneScoreGroup")
    time_cls = bag.msgclass("builtin_interfaces/Time")
    dur_cls = bag.msgclass("builtin_interfaces/Duration")
    zone_cls = bag.msgclass("roah_rsbb/ZoneState")
    gui = bag.msgclass(CORE_TO_GUI_TYPE)
    zero_t, zero_d = time_cls(sec=0, nanosec=0), dur_cls(sec=0, nanosec=0)
    final = tuple(int(i["current_value"]) for i in items)

    def scoring(values: tuple[int, ...]) -> list[Any]:
        groups: dict[str, list[tuple[dict[str, Any], int]]] = {}
        for item, value in zip(items, values, strict=True):
            groups.setdefault(str(item["group_name"]), []).append((item, value))
        return [
            zgroup(
                group_name=name,
                types=np.array([0 if i["type"] == "bool" else 1 for i, _ in rows], np.uint8),
                descriptions=[str(i["desc"]) for i, _ in rows],
                current_values=np.array([v for _, v in rows], np.int32),
            )
            for name, rows in groups.items()
        ]

    def zone(view: ZoneView) -> Any:
        secs, nsecs = divmod(int(view.timer_ns), 1_000_000_000)
        return zone_cls(
            zone=f"Zone {team}",
            name=code,
            desc="",
            code=code,
            timeout=zero_d,
            team=team,
            round=1,
            run=run,
            schedule=zero_t,
            timer=dur_cls(sec=secs, nanosec=nsecs),
            state=view.state,
            benchmark_state="",
            goal_state="",
            manual_operation_state="",
            bmscript_state="",
            robot_state="",
            manual_operation="",
            run_selector_enabled=False,
            connect_enabled=False,
            disconnect_enabled=True,
            start_enabled=view.start_enabled,
            stop_enabled=view.stop_enabled,
            prev_enabled=False,
            next_enabled=False,
            omf=False,
            omf_switches=np.zeros(0, np.uint8),
            omf_damaged=0,
            omf_complete=False,
            log="",
            online_data="",
            scoring=scoring(final if view.values is None else view.values),
        )

    zones: dict[ZoneView, Any] = {}  # a view repeats for many ticks: one message object each

    def zone_of(view: ZoneView) -> Any:
        if view not in zones:
            zones[view] = zone(view)
        return zones[view]

    msgs = [
        gui(
            clock=time_cls(sec=int(t // 1_000_000_000), nanosec=int(t % 1_000_000_000)),
            status="",
            addr="",
            port="",
            active_robots=[],
            benchmarking_robots=[team],
            zones=[zone_of(view)],
            bm_server_status="",
            bm_server_status_color=2,
            record_server_status="",
            record_server_status_color=2,
            tablet_last_beacon=zero_t,
            tablet_display_map=False,
            tablet_call_time=zero_t,
            tablet_position_time=zero_t,
            tablet_position_x=0.0,
            tablet_position_y=0.0,
        )
        for t, view in zip(ticks.tolist(), views, strict=True)
    ]
    conn = bag.connection(CORE_TO_GUI_TOPIC, CORE_TO_GUI_TYPE, callerid=CORE_CALLER, latching=True)
    bag.write_many(conn, ticks, msgs)


def _write_gui(bag: BagWriter, sc: RsbbScenario) -> None:
    """``/core/to_gui`` at 10 Hz with the run's zone and its referee items (final values)."""
    if sc.referee_score is None:
        return
    ticks = np.arange(sc.t_record_ns + 60 * MS, sc.t_disconnect_ns, STATE_PERIOD_NS, dtype=np.int64)
    items = [dict(i) for i in sc.referee_score]
    write_gui(bag, ticks, sc.code, sc.team, sc.run, items, [ZoneView()] * len(ticks))


def _check(sc: RsbbScenario) -> None:
    if sc.season not in ("2017", "2019"):
        raise UsageError(f"season {sc.season!r}: use '2017' or '2019'")
    if sc.end is not None and sc.end not in ("end", "stop", "global_timeout"):
        raise UsageError(f"end {sc.end!r}: use 'end', 'stop' or 'global_timeout'")
    if (sc.end is None) != (sc.t_end_ns is None):
        raise UsageError("give both t_end_ns and end, or neither")
    if sc.t_disconnect_ns <= sc.t_record_ns:
        raise UsageError("the disconnect must come after the recording started")
    for g in sc.goals:
        if g.outcome not in ("result", "timeout"):
            raise UsageError(f"goal outcome {g.outcome!r}: use 'result' or 'timeout'")


def write_rsbb_run(
    root: str | Path, sc: RsbbScenario, *, compression: str | None = None
) -> RunPaths:
    """Write the run's bag and result file under ``root`` in the RSBB's layout.

    Raises:
        UsageError: an inconsistent scenario, or a file that exists already.
    """
    _check(sc)
    base = Path(root)
    bag_name = f"run_{sc.run}_{local_time(sc, sc.t_record_ns).strftime('%Y-%m-%d-%H-%M-%S')}.bag"
    bag_path = base / LOGS_DIR / sc.code / sc.team / bag_name
    result_path = (
        base
        / RESULTS_DIR
        / sc.code
        / sc.team
        / f"result_run_{sc.run}_{result_time_text(sc, sc.t_setup_ns)}.yaml"
    )
    if result_path.exists():
        raise UsageError(f"{result_path} exists already; the simulator never overwrites")
    with BagWriter(bag_path, "ros1", compression=compression) as bag:
        register_types(bag)
        _write_states(bag, sc)
        _write_events(bag, sc)
        _write_tf(bag, sc)
        _write_gui(bag, sc)
        bag.write_map(
            "rsbb", sc.t_record_ns + 200 * MS, sc.t_connect_ns - 60_000 * MS, simple_map()
        )
    last = sc.saves[-1] if sc.saves else Save(sc.t_disconnect_ns, {})
    final = result_object(sc, last.score, sc.t_disconnect_ns)
    result_path.parent.mkdir(parents=True, exist_ok=True)
    result_path.write_text(yaml.dump(final, default_flow_style=False), encoding="utf-8")
    return RunPaths(bag_path, result_path)
