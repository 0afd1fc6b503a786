"""The robot's FBM1 answers: the Client's COMPLETED_GOAL payload, or a ``--results`` file.

A payload is a YAML mapping ``{item_class, item_instance, x, y, theta}``: x and y in metres in
the table (``origin``) frame, theta in **degrees** (the 2015 node converted it with pi/180 and
the 2015 robots answered in degrees, although the seed's 7.1 says radians).
"""

from __future__ import annotations

import contextlib
import math
from typing import Any

from ertools.configs._yaml import parse_payload
from ertools.errors import ConfigError, ScoringError
from ertools.frozen_dataclass import frozen_dataclass

ANSWER_FIELDS = ("item_class", "item_instance", "x", "y", "theta")


@frozen_dataclass
class Answer:
    """One robot answer.

    Attributes:
        item_class: the class the robot named.
        item_instance: the instance the robot named.
        x: metres, table frame.
        y: metres, table frame.
        theta_deg: degrees, table frame (as sent).
        source: ``client payload`` or the results file.
    """

    item_class: str
    item_instance: str
    x: float
    y: float
    theta_deg: float
    source: str = "client payload"


def answer_from_mapping(data: Any, where: str, source: str) -> Answer:
    """Validate an answer mapping; ScoringError names ``where`` (the run) and what is wrong."""
    if not isinstance(data, dict):
        raise ScoringError(f"{where}: answer is not a YAML mapping: {_short(data)}")
    missing = [f for f in ANSWER_FIELDS if f not in data or data[f] is None]
    if missing:
        raise ScoringError(f"{where}: answer lacks {', '.join(missing)} ({source})")
    numbers: dict[str, float] = {}
    for key in ("x", "y", "theta"):
        value = data[key]
        if isinstance(value, str):
            # YAML 1.1 reads "1e-3" (no dot) as text; a robot meant a number.
            with contextlib.suppress(ValueError):
                value = float(value)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ScoringError(f"{where}: answer {key}={data[key]!r} is not a number ({source})")
        if not math.isfinite(value):
            raise ScoringError(f"{where}: answer {key} is {value} ({source})")
        numbers[key] = float(value)
    names = []
    for key in ("item_class", "item_instance"):
        value = data[key]
        if isinstance(value, dict | list):
            raise ScoringError(f"{where}: answer {key} is not a name: {_short(value)} ({source})")
        names.append(str(value))
    return Answer(names[0], names[1], numbers["x"], numbers["y"], numbers["theta"], source)


def parse_answer_payload(payload: str, where: str) -> Answer:
    """The Client's COMPLETED_GOAL payload (YAML text) as an Answer."""
    try:
        data = parse_payload(payload, source="client payload", what=f"answer YAML of {where}")
    except ConfigError as err:
        raise ScoringError(
            f"{where}: answer payload is not YAML ({err}): {_short(payload)}"
        ) from err
    return answer_from_mapping(data, where, "client payload")


@frozen_dataclass
class ResultsFile:
    """Answers kept outside the log: by run index (1-based) and/or by item id."""

    by_run: dict[int, Any]
    by_item: dict[int, Any]
    source: str


def parse_results(data: Any, source: str) -> ResultsFile:
    """``--results`` file: a list of answers each with ``run`` or ``item``/``id``.

    A mapping from run index to answer is accepted too. Answers are validated only when a
    run uses them, so one bad entry fails one run.
    """
    if isinstance(data, dict) and "results" in data:
        data = data["results"]
    by_run: dict[int, Any] = {}
    by_item: dict[int, Any] = {}
    if isinstance(data, dict):
        for key, value in data.items():
            try:
                by_run[int(key)] = value
            except (TypeError, ValueError):
                raise ConfigError(f"results: key {key!r} is not a run index", path=source) from None
        return ResultsFile(by_run, by_item, source)
    if not isinstance(data, list):
        raise ConfigError("results: expected a list of answers", path=source)
    for k, entry in enumerate(data):
        if not isinstance(entry, dict):
            raise ConfigError(f"results[{k}]: expected a mapping", path=source)
        run = entry.get("run")
        item = entry.get("item", entry.get("id"))
        if run is None and item is None:
            raise ConfigError(f"results[{k}]: give 'run' (1-based) or 'item' (id)", path=source)
        for what, value, table in (("run", run, by_run), ("item", item, by_item)):
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, int):
                raise ConfigError(f"results[{k}]: {what} must be an integer", path=source)
            if value in table:
                raise ConfigError(f"results[{k}]: {what} {value} given twice", path=source)
            table[value] = entry
    return ResultsFile(by_run, by_item, source)


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value) if not isinstance(value, str) else repr(value.strip())
    return text if len(text) <= limit else text[: limit - 3] + "..."
