"""Finding the FBM3@Work runs: from the state topics, from explicit windows, or from motion.

Every finder returns :class:`RunWindow` s: when the reference position is taken, and the
time window of the path. The scorer does the rest, identically for the three modes.

``states`` (seed 7.3.3, the 2015 node): per run the BmBox goes
``WAITING_MANUAL_OPERATION -> COMPLETED_MANUAL_OPERATION`` (reference = pose at completion)
``-> TRANSMITTING_GOAL`` (payload: the spec) ``-> EXECUTING_GOAL`` (path starts)
``-> WAITING_RESULT -> READY`` (path ends when WAITING_RESULT is left). A RefBox ``END`` with
payload ``timeout``/``halt``/``stop`` during a run ends it early: that run is reported with
that status and not scored, as the 2015 node skipped it.

``windows``: ``SPEC:REF_T:START_T:END_T`` or a YAML list; times are seconds from the bag's
first message, or epoch seconds when larger than 1e9.

``auto``: stationary at the reference, a short move, stationary at the start, the path,
stationary at the end. Each move between two stationary phases is a candidate path; the first
one (in order) whose end lands near the end of the expected target shape in the run frame built
from the two stationary phases before it is taken as the run's path (see :func:`find_auto`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.fbm3w_motion import (
    DEFAULT_MIN_STILL_S,
    DEFAULT_STILL_SPEED,
    Phase,
    stationary_phases,
)
from ertools.configs.fbm3w import Fbm3wConfig
from ertools.errors import ConfigError, SegmentationError
from ertools.io.model import BenchmarkStates
from ertools.states import BmBoxState, RefBoxState
from ertools.streams import PoseStream, StateStream
from ertools.timeutil import resolve_time

F64 = npt.NDArray[np.float64]

# RefBox END payloads that end a benchmark early, and the run status reported for them.
EARLY_END = {"timeout": "timeout", "halt": "stopped", "stop": "stopped", "stopped": "stopped"}
# Stationary samples kept at each side of an auto-detected path: the phase edges found from the
# smoothed speed are fuzzy by about half the smoothing window (0.1 s).
AUTO_EDGE_S = 0.2
# An auto candidate is the path when its end lies within this fraction of the target's extent
# from the target's end point t(1) (in the run frame), and its length within these ratios.
AUTO_END_TOLERANCE = 0.3
AUTO_LENGTH_RATIO = (0.6, 1.8)


@dataclass(frozen=True)
class RunWindow:
    """One run as found in the logs.

    Attributes:
        index: run number from 0.
        spec: the shape named for the run by the logs or the user (None: take the config's).
        ref_ns: time of the reference position (None: unknown).
        start_ns, end_ns: the path window (None for a run interrupted before its path).
        status: ``completed``, ``timeout``, ``stopped``, ``interrupted`` (benchmark ended
            before the path) or ``incomplete`` (log ends during the run).
        mode: ``states``, ``windows`` or ``auto``.
        note: how the times were found, for the referee.
    """

    index: int
    spec: str | None
    ref_ns: int | None
    start_ns: int | None
    end_ns: int | None
    status: str = "completed"
    mode: str = "states"
    note: str = ""

    @property
    def execution_time_s(self) -> float | None:
        if self.start_ns is None or self.end_ns is None:
            return None
        return (self.end_ns - self.start_ns) / 1e9


# --- states -------------------------------------------------------------------------------


def _early_end(refbox: StateStream | None) -> tuple[int, str] | None:
    """(time, status) of the first RefBox END with a timeout/stop payload, if any."""
    if refbox is None or len(refbox) == 0:
        return None
    ch = refbox.changes()
    for t, s, p in zip(ch.t_ns.tolist(), ch.state.tolist(), ch.payload, strict=True):
        if s == RefBoxState.END:
            word = p.strip().lower().split(maxsplit=1)[0] if p.strip() else ""
            if word in EARLY_END:
                return int(t), EARLY_END[word]
    return None


def find_states(states: BenchmarkStates) -> list[RunWindow]:
    """Runs from the BmBox transitions (see the module docstring).

    Raises:
        SegmentationError: no BmBox state topic, or no run in it.
    """
    bm = states.bmbox
    if bm is None or len(bm) == 0:
        raise SegmentationError(
            "no /fbm3w/bmbox_state messages: use --runs windows (--run SPEC:REF:START:END) "
            "or --runs auto"
        )
    early = _early_end(states.refbox)
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
        if start is None:
            status, end_ns = ("incomplete" if status == "incomplete" else "interrupted"), None
        elif early is not None and end_ns is not None and start <= early[0] <= end_ns + 1e9:
            # a RefBox END(timeout/stop) while the path was collected ended the run; the 2015
            # node then skipped its accuracy (``if benchmark.Timeout(): ... continue``)
            status = early[1]
            note = f"{note}; RefBox END ({early[1]})"
        ref = cur["ref"] if cur["ref"] is not None else last_ref
        if cur["ref"] is None and ref is not None:
            note += "; reference taken at the previous manual operation"
        runs.append(RunWindow(len(runs), cur["spec"], ref, start, end_ns, status, "states", note))
        cur = None

    def new_run() -> dict[str, Any]:
        return {"ref": None, "start": None, "spec": None}

    for i, (t, code) in enumerate(zip(times, codes, strict=True)):
        payload = ch.payload[i].strip()
        if code == BmBoxState.WAITING_MANUAL_OPERATION:
            close(t, "interrupted", "BmBox back to a manual operation")
            cur = new_run()
        elif code == BmBoxState.COMPLETED_MANUAL_OPERATION:
            cur = cur or new_run()
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
        close(int(bm.t_ns[-1]), "incomplete", "the BmBox log ends during the run")
    if not runs:
        raise SegmentationError(
            f"{bm.topic}: no run found (no EXECUTING_GOAL or manual operation in "
            f"{len(ch)} transitions); use --runs windows or --runs auto"
        )
    return runs


# --- windows ------------------------------------------------------------------------------


def _seconds(text: Any, where: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}: {text!r} is not a time in seconds") from None
    if not math.isfinite(value):
        raise ConfigError(f"{where}: {text!r} is not a finite time")
    return value


def parse_run_spec(text: str, index: int) -> tuple[str, float, float, float]:
    """``SPEC:REF_T:START_T:END_T`` -> (spec, ref, start, end) seconds, unresolved."""
    parts = text.split(":")
    if len(parts) != 4 or not parts[0].strip():
        raise ConfigError(f"--run {text!r}: expected SPEC:REF_T:START_T:END_T, e.g. line:2:5.5:31")
    where = f"--run {text!r}"
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
    specs: Sequence[tuple[str, float, float, float]], bag_start_ns: int
) -> list[RunWindow]:
    """Explicit runs; times resolved against the bag's first message (or epoch)."""
    runs = []
    for i, (spec, ref, start, end) in enumerate(specs):
        r, s, e = (resolve_time(v, bag_start_ns) for v in (ref, start, end))
        if e < s:
            raise ConfigError(f"run {i} ({spec}): END_T {end} is before START_T {start}")
        runs.append(
            RunWindow(i, spec, r, s, e, "completed", "windows", "given on the command line")
        )
    return runs


# --- auto ---------------------------------------------------------------------------------


def _mean_xy(poses: PoseStream, phase: Phase) -> F64:
    return np.asarray(poses.xyz[phase.first : phase.last + 1, :2].mean(axis=0))


def find_auto(
    poses: PoseStream,
    config: Fbm3wConfig,
    *,
    still_speed: float = DEFAULT_STILL_SPEED,
    min_still_s: float = DEFAULT_MIN_STILL_S,
) -> list[RunWindow]:
    """Runs from motion alone (see the module docstring).

    For run k (shape ``t`` = config spec k) every move j between stationary phases S_j and
    S_j+1 with a phase S_j-1 before it is a candidate: reference = mean of S_j-1, start =
    mean of S_j, end = mean of S_j+1. It is run k's path when, in the run frame of that
    reference and start, the end lies within 30% of the target's extent from t(1) and the
    move's length (smoothed) is 0.6 to 1.8 times the target's length. The approach move (a few
    cm) and the return move (ending behind the start) fail the end test.

    Raises:
        SegmentationError: fewer than three stationary phases, or no run recognised.
    """
    from ertools.benchmarks.fbm3w_path import run_frame

    xy = poses.xyz[:, :2]
    phases = stationary_phases(poses.t_ns, xy, speed=still_speed, min_duration_s=min_still_s)
    if len(phases) < 3:
        raise SegmentationError(
            f"{poses.source}: found {len(phases)} stationary phase(s) (still below "
            f"{still_speed * 1000:g} mm/s for {min_still_s:g} s); a run needs three (reference, "
            "start, end); use --runs windows"
        )
    runs: list[RunWindow] = []
    j = 1
    edge = round(AUTO_EDGE_S * 1e9)
    for k, spec in enumerate(config.runs_specifications):
        try:
            shape = config.shape(spec)
        except ConfigError:
            shape = None
        found = None
        while j + 1 < len(phases):
            ref_p, start_p, end_p = phases[j - 1], phases[j], phases[j + 1]
            ref_xy, start_xy, end_xy = (_mean_xy(poses, p) for p in (ref_p, start_p, end_p))
            move = xy[start_p.last : end_p.first + 1]
            length = float(np.sum(np.hypot(*np.diff(move, axis=0).T)))
            ok = False
            if shape is not None and np.hypot(*(start_xy - ref_xy)) > 0:
                frame = run_frame(ref_xy, start_xy)
                end_f = frame.to_frame(end_xy[None, :])[0]
                target_end = shape(1.0)[0]
                extent = float(np.max(np.ptp(shape.dense(), axis=0)))
                target_len = shape.length()
                ok = (
                    float(np.hypot(*(end_f - target_end))) <= AUTO_END_TOLERANCE * extent
                    and AUTO_LENGTH_RATIO[0] <= length / target_len <= AUTO_LENGTH_RATIO[1]
                )
            elif shape is None:
                ok = True  # unknown shape: take the next move; the run fails at scoring
            if ok:
                found = (ref_p, start_p, end_p)
                j += 2
                break
            j += 1
        if found is None:
            break
        ref_p, start_p, end_p = found
        start_ns = max(start_p.start_ns, start_p.end_ns - edge)
        end_ns = min(end_p.end_ns, end_p.start_ns + edge)
        ref_ns = (ref_p.start_ns + ref_p.end_ns) // 2
        runs.append(
            RunWindow(
                k,
                None,
                ref_ns,
                start_ns,
                end_ns,
                "completed",
                "auto",
                f"reference: middle of the stationary phase {_span(ref_p, poses)}; path: "
                f"{AUTO_EDGE_S:g} s of stillness each side of the move",
            )
        )
    if not runs:
        raise SegmentationError(
            f"{poses.source}: no move between stationary phases matches the first run's shape "
            f"({config.runs_specifications[0]}); use --runs windows"
        )
    return runs


def _span(phase: Phase, poses: PoseStream) -> str:
    t0 = poses.start_ns
    return f"{(phase.start_ns - t0) / 1e9:.2f}-{(phase.end_ns - t0) / 1e9:.2f} s"


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
