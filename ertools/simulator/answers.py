"""The answers file written beside every simulated log, and the conventions of the logs: file
names, the 2015 epoch, windows and tolerances.

Answers file ``<log stem>.answers.yaml`` (``<name>.bag`` -> ``<name>.answers.yaml``; a rosbag2
directory ``<name>/`` -> ``<name>.answers.yaml`` beside it), top-level keys in this order:

``benchmark``
    ``fbm1h``, ``fbm1w``, ``fbm2h``, ``fbm3w``, or a non-benchmark kind (``stationary``,
    ``robotlog``, ``timeline``).
``bag``
    The log's file name(s) relative to the answers file (a string or a list).
``generator``
    ``scenario``, ``seed`` and ``parameters`` (noise sigma, rates, latency, losses...).
``truth``
    What the simulation knows: run/segment windows as ``{start: <epoch s>, end: <epoch s>,
    start_ns: <int>, end_ns: <int>}`` (:func:`window`), true poses, items, offsets...
``expected``
    The values a correct scorer must report (per run/segment/item and totals).
``tolerance``
    For each expected key (or group), ``{abs: <number>, why: <one line>}``.

Numbers are plain YAML floats/ints (``to_plain`` converts NumPy values); times are given in
epoch seconds *and* int64 ns so tests can compare either.

A folder laid out as an organiser's (the RSBB's ``rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag``)
holds no answers: ``ertools rescore`` of it would list a file in it as not a log. Its runs'
answers are one file beside it, ``<folder>.answers.yaml`` (:func:`answers_path` of the folder,
:func:`write_layout_answers`), top-level keys ``benchmark``, ``bag`` (every run bag, relative
to the folder), ``generator`` (``scenario``, ``seed``) and ``runs``: per run bag (the same
relative path) its ``parameters``, ``truth``, ``expected`` and ``tolerance``.
:func:`read_answers` reads a log's answers in the first shape wherever they are.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ertools.atomic import write_text
from ertools.frozen_dataclass import frozen_dataclass

# A Friday at the Lisbon 2015 RoCKIn competition (2015-11-20 10:00:00 UTC): the default
# start of simulated logs.
EPOCH_2015 = 1_448_013_600 * 1_000_000_000


def log_name(kind: str, start_ns: int, *, index: int = 0, suffix: str = ".bag") -> str:
    """The 2015 logger's file name: ``log_<kind>_<YYYY-mm-dd-HH-MM-SS>_<index><suffix>`` (UTC).

    E.g. ``log_name("fbm3w_mocap", EPOCH_2015)`` -> ``log_fbm3w_mocap_2015-11-20-10-00-00_0.bag``.
    """

    stamp = dt.datetime.fromtimestamp(start_ns // 1_000_000_000, tz=dt.UTC)
    return f"log_{kind}_{stamp:%Y-%m-%d-%H-%M-%S}_{index}{suffix}"


def answers_path(log: Path) -> Path:
    """``x.bag`` / ``x.mcap`` / rosbag2 dir ``x`` -> ``x.answers.yaml`` in the same folder."""
    name = log.name
    for suffix in (".bag.active", ".bag", ".mcap"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
            break
    return log.with_name(f"{name}.answers.yaml")


def window(start_ns: int, end_ns: int) -> dict[str, Any]:
    """A time window for ``truth``: epoch seconds and ns."""
    return {
        "start": int(start_ns) / 1e9,
        "end": int(end_ns) / 1e9,
        "start_ns": int(start_ns),
        "end_ns": int(end_ns),
    }


def tol(abs_: float, why: str) -> dict[str, Any]:
    """A tolerance entry: ``{abs: ..., why: ...}``."""
    return {"abs": float(abs_), "why": why}


def given_tol(tolerance: Mapping[str, Any], key: str) -> dict[str, Any]:
    """The tolerance entry ``tolerance[key]`` (an answers file's), as :func:`tol` makes one."""
    return tol(tolerance[key]["abs"], tolerance[key]["why"])


def to_plain(value: Any) -> Any:
    """NumPy scalars/arrays, tuples and Paths -> plain YAML-safe Python values."""
    if isinstance(value, Mapping):
        return {str(k): to_plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return to_plain(value.tolist())
    if isinstance(value, (list, tuple)):
        return [to_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return value.name
    if isinstance(value, float):
        return float(value)
    return value


def write_answers(
    log: Path | Sequence[Path],
    *,
    benchmark: str,
    scenario: str,
    seed: int,
    parameters: Mapping[str, Any],
    truth: Mapping[str, Any],
    expected: Mapping[str, Any],
    tolerance: Mapping[str, Any],
) -> Path:
    """Write ``<log stem>.answers.yaml`` beside ``log`` (the first log when several).

    Key order is fixed (the convention above) and mapping order is kept, so the file is
    byte-identical for identical inputs.
    """

    logs = [log] if isinstance(log, Path) else list(log)
    if not logs:
        raise ValueError("write_answers needs at least one log path")
    doc = {
        "benchmark": benchmark,
        "bag": logs[0].name if len(logs) == 1 else [p.name for p in logs],
        "generator": {"scenario": scenario, "seed": int(seed), "parameters": to_plain(parameters)},
        "truth": to_plain(truth),
        "expected": to_plain(expected),
        "tolerance": to_plain(tolerance),
    }
    return _dump(doc, answers_path(logs[0]))


@frozen_dataclass
class RunAnswers:
    """One run's answers in a layout's answers file (:func:`write_layout_answers`)."""

    bag: Path
    parameters: Mapping[str, Any]
    truth: Mapping[str, Any]
    expected: Mapping[str, Any]
    tolerance: Mapping[str, Any]


def write_layout_answers(
    folder: Path, runs: Sequence[RunAnswers], *, benchmark: str, scenario: str, seed: int
) -> Path:
    """Write the answers of the runs laid out under ``folder`` beside it, as
    ``<folder>.answers.yaml`` (:func:`answers_path` of ``folder``), byte-identical for
    identical inputs; each run bag must lie under ``folder``."""

    if not runs:
        raise ValueError("write_layout_answers needs at least one run")
    # relative to the folder, not to the answers file: the samples' generator writes into a
    # folder of a temporary name that is renamed afterwards
    bags = [run.bag.relative_to(folder).as_posix() for run in runs]
    doc = {
        "benchmark": benchmark,
        "bag": bags,
        "generator": {"scenario": scenario, "seed": int(seed)},
        "runs": {
            bag: {
                "parameters": to_plain(run.parameters),
                "truth": to_plain(run.truth),
                "expected": to_plain(run.expected),
                "tolerance": to_plain(run.tolerance),
            }
            for bag, run in zip(bags, runs, strict=True)
        },
    }
    return _dump(doc, answers_path(folder))


def _dump(doc: Mapping[str, Any], out: Path) -> Path:
    """``doc`` as YAML at ``out``, keys in the order given, written whole (temp + rename)."""
    return write_text(out, yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=100))


def read_answers(log: Path) -> dict[str, Any]:
    """The answers of ``log``: its own answers file beside it, else its run's in the answers
    file beside the folder that holds it (:func:`write_layout_answers`), in a log's shape
    (``bag`` relative to that folder).

    Raises:
        FileNotFoundError: no answers file names ``log``.
    """

    own = answers_path(log)
    if own.is_file():
        doc: dict[str, Any] = yaml.safe_load(own.read_text(encoding="utf-8"))
        return doc
    for folder in log.parents:
        if not folder.name:  # "." or "/": nothing beside it
            break
        beside = answers_path(folder)
        if not beside.is_file():
            continue
        layout = yaml.safe_load(beside.read_text(encoding="utf-8"))
        bag = log.relative_to(folder).as_posix()
        run = layout.get("runs", {}).get(bag)
        if run is None:
            continue
        return {
            "benchmark": layout["benchmark"],
            "bag": bag,
            "generator": {**layout["generator"], "parameters": run["parameters"]},
            "truth": run["truth"],
            "expected": run["expected"],
            "tolerance": run["tolerance"],
        }
    raise FileNotFoundError(f"{log}: no answers file beside it or beside a folder holding it")
