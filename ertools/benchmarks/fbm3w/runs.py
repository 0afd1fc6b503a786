"""Finding the FBM3@Work runs: from the state topics, from explicit windows, or from motion.

Every finder returns :class:`RunWindow` s: when the reference position is taken, and the
time window of the path. The scorer does the rest, identically for the three modes.

``states`` (seed 7.3.3, the 2015 node): per run the BmBox goes
``WAITING_MANUAL_OPERATION -> COMPLETED_MANUAL_OPERATION`` (reference = the pose when it left
WAITING_MANUAL_OPERATION, READY on a RefBox END too: the node's ``ManualOperation()`` returned)
``-> TRANSMITTING_GOAL`` (payload: the spec) ``-> EXECUTING_GOAL`` (path starts)
``-> WAITING_RESULT -> READY`` (path ends when WAITING_RESULT is left). A RefBox ``END`` during
a run ends it early when its payload is a timeout or a stop (``reason: timeout`` /
``reason: stop``, the 2015 BmBox's strings; by default the seed's ``timeout`` / ``halt`` too, not
under ``--exact-end-payloads``: :func:`ertools.states.end_reason`): that run is reported as
``timeout`` or ``stopped``. Another END payload is warned about once, with its file and time,
and read as the 2015 BmBox read it (neither). A log that ends inside a run is that run stopped there
(:mod:`ertools.benchmarks.common.ending`), said in a warning.

``windows``: ``SPEC:REF_T:START_T:END_T`` or a YAML list; times are seconds from the bag's
first message, or epoch seconds when larger than 1e9.

``auto``: from motion alone (:mod:`ertools.benchmarks.fbm3w.auto_runs`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ertools.benchmarks.common.ending import (
    RefBoxEnd,
    cut_warning,
    end_payload_warnings,
    log_cut,
    refbox_ends,
)
from ertools.benchmarks.fbm3w.settings import Fbm3wConfig
from ertools.configs._yaml import show
from ertools.errors import ConfigError, SegmentationError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.model import BenchmarkStates
from ertools.states import BmBoxState, EndReason, end_reason
from ertools.streams import StateStream
from ertools.timeutil import MAX_SECONDS, ns_to_s, resolve_time

# What a RefBox END payload does to the run it ends (ertools.states.end_reason).
EARLY_END = {EndReason.TIMEOUT: "timeout", EndReason.STOP: "stopped"}
# A RefBox END this long after the BmBox left WAITING_RESULT still ended that run: the BmBox
# left because of it, and the recorder may write the two machines' messages out of order.
END_SLACK_NS = 1_000_000_000


@frozen_dataclass
class RunWindow:
    """One run as found in the logs.

    Attributes:
        index: run number from 0.
        spec: the shape named for the run by the logs or the user (None: take the config's).
        ref_ns: time of the reference position (None: unknown).
        start_ns, end_ns: the path window (None for a run interrupted before its path).
        status: ``completed``, ``timeout``, ``stopped`` (by the RefBox, or the log ends
            during the path: stopped there) or ``interrupted`` (benchmark ended before the path).
        mode: ``states``, ``windows`` or ``auto``.
        note: how the times were found, for the referee.
        warnings: what the state log said about this run that the referee must know (an END
            payload no 2015 code knew, the log ending inside the run).
    """

    index: int
    spec: str | None
    ref_ns: int | None
    start_ns: int | None
    end_ns: int | None
    status: str = "completed"
    mode: str = "states"
    note: str = ""
    warnings: tuple[str, ...] = ()

    @property
    def execution_time_s(self) -> float | None:
        if self.start_ns is None or self.end_ns is None:
            return None
        return ns_to_s(self.end_ns - self.start_ns)


# --- states -------------------------------------------------------------------------------


def find_states(states: BenchmarkStates, *, exact_2015: bool = False) -> list[RunWindow]:
    """Runs from the BmBox transitions (see the module docstring).

    ``exact_2015``: RefBox END payloads read as the 2015 BmBox did (``--exact-end-payloads``).

    Raises:
        SegmentationError: no BmBox state topic, or no run in it.
    """
    bm = states.bmbox
    if bm is None or len(bm) == 0:
        raise SegmentationError(
            "no /fbm3w/bmbox_state messages: use --runs windows (--run SPEC:REF:START:END) "
            "or --runs auto"
        )
    ends = refbox_ends(states.refbox, exact_2015=exact_2015)
    t0 = int(bm.t_ns[0])
    ch = bm.changes()
    times = ch.t_ns.tolist()
    codes = ch.state.tolist()
    runs: list[RunWindow] = []
    cur: dict[str, Any] | None = None
    last_ref: int | None = None

    def close(end_ns: int | None, status: str, note: str) -> None:
        nonlocal cur
        if cur is None:
            return
        start = cur["start"]
        said: list[str] = []
        index = len(runs)
        if start is None:
            if status == "cut" and end_ns is not None:
                said.append(cut_warning(end_ns, bm, t0, f"run {index}", "its path had not started"))
            status, end_ns = "interrupted", None
        elif end_ns is not None:
            # The BmBox's Timeout()/Running() read the last RefBox payload when WaitResult
            # returned: the last END of the run decides; an unknown payload is neither.
            known = _early_ends(start, end_ns)
            if known:
                status = EARLY_END[known[-1].reason]
                note = f"{note}; RefBox END {known[-1].payload!r}"
            elif status == "cut":
                status = "stopped"
                said.append(
                    cut_warning(
                        end_ns,
                        bm,
                        t0,
                        f"run {index}",
                        f"run {index} is not scored, and its time counts as a stopped run's",
                    )
                )
        ref = cur["ref"] if cur["ref"] is not None else last_ref
        if cur["ref"] is None and ref is not None:
            note += "; reference taken at the previous manual operation"
        runs.append(
            RunWindow(index, cur["spec"], ref, start, end_ns, status, "states", note, tuple(said))
        )
        cur = None

    def _early_ends(start: int, end: int) -> list[RefBoxEnd]:
        if exact_2015:
            # As Timeout() and Running() read it when WaitResult returned: the payload of the
            # last RefBox message then, whatever its state (BmBox.py 34-35, 114-126).
            payload = _payload_at(states.refbox, end)
            reason = end_reason(payload, exact_2015=True)
            return [RefBoxEnd(end, payload, reason)] if reason.ends_early else []
        return [e for e in ends if start <= e.t_ns <= end + END_SLACK_NS and e.reason.ends_early]

    def new_run() -> dict[str, Any]:
        return {"ref": None, "start": None, "spec": None}

    prev = None
    for i, (t, code) in enumerate(zip(times, codes, strict=True)):
        payload = ch.payload[i].strip()
        if prev == BmBoxState.WAITING_MANUAL_OPERATION and cur is not None:
            # ManualOperation() returned (to COMPLETED_MANUAL_OPERATION, or READY on a RefBox
            # END, BmBox.py 40-44) and the node took its reference then (scripts/fbm3w 206-208).
            cur["ref"] = last_ref = t
        prev = code
        if code == BmBoxState.WAITING_MANUAL_OPERATION:
            close(t, "interrupted", "BmBox back to a manual operation")
            cur = new_run()
        elif code == BmBoxState.COMPLETED_MANUAL_OPERATION:
            cur = cur or new_run()
            if cur["ref"] is None:
                cur["ref"] = last_ref = t
        elif code == BmBoxState.TRANSMITTING_GOAL:
            if cur is not None and cur["start"] is not None:
                close(t, "interrupted", "")
            cur = cur or new_run()
            cur["spec"] = payload or None
        elif code == BmBoxState.EXECUTING_GOAL:
            cur = cur or new_run()
            if cur["start"] is None:
                cur["start"] = t
        elif code == BmBoxState.WAITING_RESULT or cur is None:
            continue
        elif cur["start"] is not None:
            # the path ends as WAITING_RESULT (or EXECUTING_GOAL) is left
            normal = code in (BmBoxState.READY, BmBoxState.TRANSMITTING_SCORE)
            close(
                t,
                "completed" if normal else "stopped",
                "BmBox EXECUTING_GOAL to leaving WAITING_RESULT",
            )
        elif code in (BmBoxState.END, BmBoxState.TRANSMITTING_SCORE):
            close(t, "interrupted", "the benchmark ended before the path")
    if cur is not None:
        close(int(bm.t_ns[-1]), "cut", "the BmBox log ends during the run")
    elif runs and (cut := log_cut(bm, states.refbox, exact_2015=exact_2015)) is not None:
        # Between runs: nothing is lost, but the log is not the whole benchmark.
        said = cut_warning(cut, bm, t0, "the benchmark", "no run was open")
        runs[-1] = replace(runs[-1], warnings=(*runs[-1].warnings, said))
    if not runs:
        raise SegmentationError(
            f"{bm.topic}: no run found (no EXECUTING_GOAL or manual operation in "
            f"{len(ch)} transitions); use --runs windows or --runs auto"
        )
    unknown = end_payload_warnings(states.refbox, t0, exact_2015=exact_2015)
    if unknown:
        runs[0] = replace(runs[0], warnings=(*unknown, *runs[0].warnings))
    return runs


def _payload_at(stream: StateStream | None, t_ns: int) -> str:
    """The payload of the last message of ``stream`` recorded at or before ``t_ns``."""
    if stream is None or len(stream) == 0:
        return ""
    i = int(np.searchsorted(stream.t_ns, t_ns, side="right")) - 1
    return stream.payload[i] if i >= 0 else ""


# --- windows ------------------------------------------------------------------------------


def _seconds(text: Any, where: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError, OverflowError):  # a 400-digit integer overflows float()
        raise ConfigError(f"{where}: {show(text)} is not a time in seconds") from None
    if not math.isfinite(value):
        raise ConfigError(f"{where}: {show(text)} is not a finite time")
    if abs(value) > MAX_SECONDS:  # its nanoseconds would not fit int64
        raise ConfigError(f"{where}: {show(text)} s is out of range (at most {MAX_SECONDS:g} s)")
    return value


def parse_run_spec(text: str, index: int) -> tuple[str, float, float, float]:
    """``SPEC:REF_T:START_T:END_T`` -> (spec, ref, start, end) seconds, unresolved."""
    parts = text.split(":")
    if len(parts) != 4 or not parts[0].strip():
        raise ConfigError(
            f"--run {show(text)}: expected SPEC:REF_T:START_T:END_T, e.g. line:2:5.5:31"
        )
    where = f"--run {show(text)}"
    return (
        parts[0].strip(),
        _seconds(parts[1], where),
        _seconds(parts[2], where),
        _seconds(parts[3], where),
    )


def parse_runs_file(data: Any, source: str) -> list[tuple[str, float, float, float]]:
    """A YAML list (or ``{runs: [...]}``) of ``{spec, reference, start, end}`` mappings."""
    if isinstance(data, dict) and "runs" in data:
        data = data["runs"]
    if not isinstance(data, list) or not data:
        raise ConfigError("expected a list of {spec, reference, start, end}", path=source)
    out = []
    for i, item in enumerate(data):
        where = f"{source}: run {i}"
        if not isinstance(item, dict):
            raise ConfigError(f"{where}: expected a mapping {{spec, reference, start, end}}")
        missing = [k for k in ("spec", "reference", "start", "end") if k not in item]
        if missing:
            raise ConfigError(f"{where}: missing key(s) {', '.join(missing)}")
        out.append(
            (
                str(item["spec"]),
                _seconds(item["reference"], where),
                _seconds(item["start"], where),
                _seconds(item["end"], where),
            )
        )
    return out


def find_windows(
    specs: Sequence[tuple[str, float, float, float]],
    bag_start_ns: int,
    bag_end_ns: int | None = None,
) -> list[RunWindow]:
    """Explicit runs; times resolved against the bag's first message (or epoch).

    Raises:
        ConfigError: END_T before START_T, or (``bag_end_ns`` given) a time outside the log:
            a window cut by the end of the log would be scored on the part left, a wrong
            score that looks right.
    """
    runs = []
    for i, (spec, ref, start, end) in enumerate(specs):
        r, s, e = (resolve_time(v, bag_start_ns) for v in (ref, start, end))
        if e < s:
            raise ConfigError(f"run {i} ({spec}): END_T {end} is before START_T {start}")
        if bag_end_ns is not None and (min(r, s) < bag_start_ns or max(r, e) > bag_end_ns):
            span = (bag_end_ns - bag_start_ns) / 1e9
            rel = [(v - bag_start_ns) / 1e9 for v in (r, s, e)]
            where = "before the start" if min(r, s) < bag_start_ns else "past the end"
            raise ConfigError(
                f"run {i} ({spec}): the window reaches {where} of the log (reference "
                f"{rel[0]:.3f} s, path {rel[1]:.3f}-{rel[2]:.3f} s from the first message; "
                f"the log covers 0-{span:.3f} s): check the times (seconds from the log start, "
                "or epoch seconds)"
            )
        runs.append(
            RunWindow(i, spec, r, s, e, "completed", "windows", "given on the command line")
        )
    return runs


# --- the specs ----------------------------------------------------------------------------


def with_specs(runs: list[RunWindow], config: Fbm3wConfig) -> tuple[list[RunWindow], list[str]]:
    """Each run's spec from the config (Listing 14 order); warnings where the logs disagree.

    The config wins (it is what the 2015 node scored with); a run beyond the config's list
    keeps the spec the logs gave, or None (it then fails).
    """
    warnings = []
    out = []
    specs = config.runs_specifications
    for run in runs:
        if run.mode == "windows":
            out.append(run)
            continue
        cfg = specs[run.index] if run.index < len(specs) else None
        if cfg is not None and run.spec is not None and run.spec != cfg:
            warnings.append(
                f"run {run.index}: the BmBox goal says {run.spec!r}, the config says {cfg!r}; "
                f"scored as {cfg!r} (pass the config the benchmark ran with)"
            )
        out.append(replace(run, spec=cfg if cfg is not None else run.spec))
    if len(runs) > len(specs) and any(r.mode != "windows" for r in runs):
        warnings.append(
            f"the logs hold {len(runs)} runs, the config specifies {len(specs)}; the extra runs "
            "use the spec the BmBox published"
        )
    return out, warnings
