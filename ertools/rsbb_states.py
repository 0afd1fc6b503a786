"""The RSBB of the ERL @Home seasons 2017-19: state machines, messages, topics and frames.

Read from ``rockin-robot-challenge/rsbb`` at ``2bb8a41`` and its October 2017 rewrite
``Enri2077/rsbb`` (docs/rsbb.md gives the sources line by line). Pure data: the reader
(:mod:`ertools.rsbb`), the simulator (:mod:`ertools.simulator.rsbb`) and the benchmarks share it.
"""

from __future__ import annotations

import enum

from ertools.frozen_dataclass import frozen_dataclass

# ``rsbb_benchmarking_messages/BmBoxState`` keeps the seed's Listing 6 numbers: the 2015 enum,
# written once. The RSBB BmBox never enters COMPLETED_MANUAL_OPERATION or TRANSMITTING_SCORE,
# and it publishes its state at 10 Hz only (a transition is seen at the next tick).
from ertools.states import BmBoxState as BmBoxState  # noqa: PLC0414 (re-exported)


class RefBoxState(enum.IntEnum):
    """``rsbb_benchmarking_messages/RefBoxState``: one enumeration for three sub-machines.

    The benchmark sub-machine uses START, EXECUTING_BENCHMARK, END, STOP and GLOBAL_TIMEOUT;
    the goal sub-machine START, READY, TRANSMITTING_GOAL and EXECUTING_GOAL; the manual
    operation sub-machine START, READY and EXECUTING_MANUAL_OPERATION. The others are declared
    and never set by the RefBox.
    """

    START = 0
    EXECUTING_BENCHMARK = 1
    END = 2
    STOP = 3
    EMERGENCY_STOP = 4
    ERROR = 5
    GLOBAL_TIMEOUT = 6
    READY = 7
    TRANSMITTING_GOAL = 8
    EXECUTING_GOAL = 9
    GOAL_TIMEOUT = 10
    EXECUTING_MANUAL_OPERATION = 11
    NONE = 12


#: Benchmark states in which the BmBox considers the benchmark not running (its exception
#: states; EMERGENCY_STOP is not one of them, and END ends it by the BmBox's own END).
NOT_RUNNING_STATES = frozenset({RefBoxState.STOP, RefBoxState.ERROR, RefBoxState.GLOBAL_TIMEOUT})

#: The result file's ``benchmark_info.end_description`` for the RefBox benchmark state the
#: BmBox last knew (BenchmarkObjects.py ``get_end_description``); any other state gives
#: :data:`END_DESCRIPTION_OTHER`, and the file written at setup says :data:`END_DESCRIPTION_SETUP`.
END_DESCRIPTIONS: dict[RefBoxState, str] = {
    RefBoxState.END: "END: benchmark ended normally",
    RefBoxState.STOP: "STOP: benchmark stopped by referee",
    RefBoxState.EMERGENCY_STOP: "EMERGENCY_STOP: benchmark stopped due to emergency",
    RefBoxState.ERROR: "ERROR: benchmark terminated due to RefBox error",
    RefBoxState.GLOBAL_TIMEOUT: "GLOBAL_TIMEOUT: benchmark ended due to global timeout",
}
END_DESCRIPTION_OTHER = "still running or unknown reason"
END_DESCRIPTION_SETUP = "initialised"


# --- messages ---------------------------------------------------------------------------------

BMBOX_STATE_TYPE = "rsbb_benchmarking_messages/BmBoxState"
REFBOX_STATE_TYPE = "rsbb_benchmarking_messages/RefBoxState"
CORE_TO_GUI_TYPE = "roah_rsbb/CoreToGui"
ZONE_STATE_TYPE = "roah_rsbb/ZoneState"
ZONE_SCORE_GROUP_TYPE = "roah_rsbb/ZoneScoreGroup"
ROBOT_INFO_TYPE = "roah_rsbb/RobotInfo"

#: The fields of each RefBoxState sub-machine, in message order: (state field, payload field).
REFBOX_FIELDS: tuple[tuple[str, str], ...] = (
    ("benchmark_state", "benchmark_payload"),
    ("goal_execution_state", "goal_execution_payload"),
    ("manual_operation_state", "manual_operation_payload"),
)


@frozen_dataclass
class MessageSpec:
    """A ROS1 message definition as data: constants (type, name, value), then fields."""

    constants: tuple[tuple[str, str, int], ...]
    fields: tuple[tuple[str, str], ...]

    def text(self) -> str:
        """The ``.msg`` text (constants, a blank line, fields), as rosbags parses it."""
        consts = "".join(f"{t} {n} = {v}\n" for t, n, v in self.constants)
        body = "".join(f"{t} {n}\n" for t, n in self.fields)
        return f"{consts}\n{body}" if consts else body


def _enum_constants(enum_type: type[enum.IntEnum]) -> tuple[tuple[str, str, int], ...]:
    return tuple(("uint8", m.name, int(m.value)) for m in enum_type)


MESSAGES: dict[str, MessageSpec] = {
    BMBOX_STATE_TYPE: MessageSpec(
        _enum_constants(BmBoxState), (("uint8", "state"), ("string", "payload"))
    ),
    REFBOX_STATE_TYPE: MessageSpec(
        _enum_constants(RefBoxState),
        tuple(
            field
            for state, payload in REFBOX_FIELDS
            for field in (("uint8", state), ("string", payload))
        ),
    ),
    ZONE_SCORE_GROUP_TYPE: MessageSpec(
        (("uint8", "SCORING_BOOL", 0), ("uint8", "SCORING_UINT", 1)),
        (
            ("string", "group_name"),
            ("uint8[]", "types"),
            ("string[]", "descriptions"),
            ("int32[]", "current_values"),
        ),
    ),
    ROBOT_INFO_TYPE: MessageSpec(
        (), (("string", "team"), ("string", "robot"), ("duration", "skew"), ("time", "beacon"))
    ),
    ZONE_STATE_TYPE: MessageSpec(
        (),
        (
            ("string", "zone"),
            ("string", "name"),
            ("string", "desc"),
            ("string", "code"),
            ("duration", "timeout"),
            ("string", "team"),
            ("uint8", "round"),
            ("uint8", "run"),
            ("time", "schedule"),
            ("duration", "timer"),
            ("string", "state"),
            ("string", "benchmark_state"),
            ("string", "goal_state"),
            ("string", "manual_operation_state"),
            ("string", "bmscript_state"),
            ("string", "robot_state"),
            ("string", "manual_operation"),
            ("bool", "run_selector_enabled"),
            ("bool", "connect_enabled"),
            ("bool", "disconnect_enabled"),
            ("bool", "start_enabled"),
            ("bool", "stop_enabled"),
            ("bool", "prev_enabled"),
            ("bool", "next_enabled"),
            ("bool", "omf"),
            ("uint8[]", "omf_switches"),
            ("uint8", "omf_damaged"),
            ("bool", "omf_complete"),
            ("string", "log"),
            ("string", "online_data"),
            ("ZoneScoreGroup[]", "scoring"),
        ),
    ),
    CORE_TO_GUI_TYPE: MessageSpec(
        (("uint8", "RED", 0), ("uint8", "YELLOW", 1), ("uint8", "NEUTRAL", 2)),
        (
            ("time", "clock"),
            ("string", "status"),
            ("string", "addr"),
            ("string", "port"),
            ("RobotInfo[]", "active_robots"),
            ("string[]", "benchmarking_robots"),
            ("ZoneState[]", "zones"),
            ("string", "bm_server_status"),
            ("uint8", "bm_server_status_color"),
            ("string", "record_server_status"),
            ("uint8", "record_server_status_color"),
            ("time", "tablet_last_beacon"),
            ("bool", "tablet_display_map"),
            ("time", "tablet_call_time"),
            ("time", "tablet_position_time"),
            ("float64", "tablet_position_x"),
            ("float64", "tablet_position_y"),
        ),
    ),
}

#: Each type's ``.msg`` text (nested roah_rsbb types are referred to by their short names,
#: as in their package).
MSG_DEFINITIONS: dict[str, str] = {name: spec.text() for name, spec in MESSAGES.items()}


# --- topics, frames, bodies -------------------------------------------------------------------

NAMESPACE = "/rsbb"
BMBOX_STATE_TOPIC = "/rsbb/bmbox/bmbox_state"
REFBOX_STATE_TOPIC = "/rsbb/bmbox/refbox_state"
LIVE_SCORE_TOPIC = "/rsbb/current_benchmark_result"
TIMEOUT_TOPIC = "/timeout"
CORE_TO_GUI_TOPIC = "/core/to_gui"
CORE_TO_PUBLIC_TOPIC = "/core/to_public"
MAP_TOPIC = "/rsbb/map"
MAP_METADATA_TOPIC = "/rsbb/map_metadata"

#: The BmBox's and the RefBox's heartbeat period.
STATE_PERIOD_NS = 100_000_000

#: The mocap node's parent frame (the root of the tf tree) and its rigid bodies, by OptiTrack id.
MOCAP_PARENT = "testbed_origin"
MOCAP_BODIES: dict[int, str] = {
    3: "robot_markerset",
    4: "table_origin",
    5: "positioner_origin",
    6: "actor_markerset",
}
#: The static ``testbed_origin -> map`` that tf's static_transform_publisher re-sends on /tf.
MAP_FRAME = "map"


def body_pose_topic(body: str) -> str:
    """``/rsbb/<body>/pose`` (PoseStamped, frame ``testbed_origin``)."""
    return f"{NAMESPACE}/{body}/pose"


def body_pose2d_topic(body: str) -> str:
    """``/rsbb/<body>/pose2d`` (Pose2D)."""
    return f"{NAMESPACE}/{body}/pose2d"


@frozen_dataclass
class ScriptFrame:
    """A frame a benchmark script broadcasts on /tf at each successful lookup.

    Attributes:
        child: the broadcast frame, spelt as the script spells it (leading slash).
        parent: the mocap body it hangs from.
        reference: the frame the script looks the child up in.
        attempts: the helper's ``max_failed_attempts`` (None: until the benchmark stops).
        timeout_s: each wait's timeout.
    """

    child: str
    parent: str
    reference: str
    attempts: int | None
    timeout_s: float


@frozen_dataclass
class Benchmark:
    """One benchmark of ``benchmarks_description.yaml`` (2bb8a41); what is its own (the frames
    its script broadcasts, its mocap bodies, its seasons) is in its package's ``config``.

    Attributes:
        code: the RSBB code (folder names, result files).
        name: the description's name.
        scripted: whether a BmBox script scores it (a result file exists).
    """

    code: str
    name: str
    scripted: bool


BENCHMARKS: dict[str, Benchmark] = {
    b.code: b
    for b in (
        Benchmark("HOPF", "Functionality Benchmark 1: Object Perception Functionality", True),
        Benchmark("HNF", "Functionality Benchmark 2: Navigation Functionality", True),
        Benchmark("HSUF", "Functionality Benchmark 3: Speech Understanding Functionality", False),
        Benchmark("HPPF", "Functionality Benchmark 4: People Perception Functionality", True),
        Benchmark("HPFF", "Functionality Benchmark 5: Person Following Functionality", True),
        Benchmark(
            "HGMF", "Functionality Benchmark 6: Grasping and Manipulation Functionality", True
        ),
        Benchmark("HGTKMH", "Task Benchmark 1: Getting to know my home", False),
        Benchmark("HWV", "Task Benchmark 2: Welcoming visitors", False),
        Benchmark("HCFGAC", "Task Benchmark 3: Catering for Granny Annie's Comfort", False),
        Benchmark("STB", "Test Benchmark: Simple Test Benchmark", True),
    )
}

# --- file names -------------------------------------------------------------------------------

#: strftime of the result file's dates (BenchmarkObjects.py): local time and zone.
RESULT_TIME_FORMAT = "%Y-%m-%d_%H:%M:%S_%Z(%z)"
#: strftime of the date rosbag record appends to the bag prefix (local time).
BAG_TIME_FORMAT = "%Y-%m-%d-%H-%M-%S"
LOGS_DIR = "rsbb_logs"
RESULTS_DIR = "results"
