"""Who ran a benchmark: the team name of a result, and where it was found.

A result names its team from, in this order (the first that gives one wins):

1. ``explicit``: the ``--team NAME`` the referee gave;
2. ``payload``: a benchmark state message whose payload is a YAML mapping with a ``team``,
   ``team_name`` or ``robot_info`` key (the 2015 manual's listings put no team in a payload,
   but a RefBox or BmBox that does is taken at its word);
3. ``log name``: a robot log named by the 2015 rockin_logger,
   ``${BENCHMARK}_${DATE}_${TEAMNAME}.bag`` (``FBM2H_201511201200_homer.bag`` -> ``homer``);
4. ``transform``: the FBM2H marker-to-robot transform, named ``transform-<team>.yaml`` by the
   2015 acquisition node (seed 7.2.4), whose ``robot_info`` is the team (``identity`` is no team).

Only :func:`read_payload_team` and :func:`with_team` read files (the logs' state topics);
the rest works on names and texts.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Literal

from ertools.errors import ErtoolsError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.reader import read_benchmark_states

TeamSource = Literal["explicit", "payload", "log name", "transform", "RSBB layout"]

# What each source is, as reports print it ("homer (from --team)").
SOURCE_TEXT: dict[str, str] = {
    "explicit": "--team",
    "payload": "a state payload",
    "log name": "the log's file name",
    "transform": "the FBM2H transform",
    "RSBB layout": "the RSBB folder rsbb_logs/<CODE>/<team>/",
}

# rockin_logger (2015) named robot logs ${BENCHMARK}_${DATE}_${TEAMNAME}.bag, the benchmark
# written FBM2H or FBMH2 (TBMH1...) and the date %Y%m%d%H%M. The date and team are optional
# here so that a log renamed to just ``FBM2H_<something>`` still gives its benchmark.
ROBOT_LOG_RE = re.compile(
    r"^(?P<kind>[FT]BM)(?:(?P<n>\d)(?P<hw>[HW])|(?P<hw2>[HW])(?P<n2>\d))_"
    r"(?:(?P<date>\d{8,14})_(?P<team>.+))?",
    re.IGNORECASE,
)
_LOG_SUFFIXES = (".bag.active", ".bag", ".mcap", ".db3")
_NAMESPACE_RE = re.compile(r"^[ft]bm\d[hw]$")
_TRANSFORM_RE = re.compile(r"^transform-(?P<team>.+)\.ya?ml$")
# Payload keys that name a team (robot_info: the transform file's key, Listing 11).
PAYLOAD_KEYS = ("team", "team_name", "robot_info")
# Transforms that belong to no team: the identity of Listing 12.
NO_TEAM = frozenset({"", "identity"})


@frozen_dataclass
class RobotLogName:
    """What a rockin_logger file name says: the benchmark (``fbm2h``) and, when the name has
    them, the date digits and the team."""

    benchmark: str
    date: str | None
    team: str | None


def _stem(path: str | Path) -> str:
    name = Path(path).name
    for suffix in _LOG_SUFFIXES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return name


def parse_robot_log_name(path: str | Path) -> RobotLogName | None:
    """The rockin_logger fields of a file name, or None for a name it did not give."""
    match = ROBOT_LOG_RE.match(_stem(path))
    if match is None:
        return None
    number = match.group("n") or match.group("n2")
    arena = match.group("hw") or match.group("hw2")
    team = match.group("team")
    return RobotLogName(
        benchmark=f"{match.group('kind')}{number}{arena}".lower(),
        date=match.group("date"),
        team=team or None,
    )


def team_from_log_name(path: str | Path) -> str | None:
    """The team of a robot log named by the 2015 rockin_logger, else None.

    ``FBM2H_201511201200_homer.bag`` -> ``homer``; ``TBMH1_201511201200_b-it-bots.bag`` ->
    ``b-it-bots``; ``log_fbm2h_mocap_2015-11-20-12-00-00_0.bag`` (a mocap log) -> None.
    """
    parsed = parse_robot_log_name(path)
    return None if parsed is None else parsed.team


def team_from_transform_name(path: str | Path) -> str | None:
    """``transform-homer.yaml`` -> ``homer``; the identity transform and other names -> None."""
    match = _TRANSFORM_RE.match(Path(path).name)
    if match is None or match.group("team") in NO_TEAM:
        return None
    return match.group("team")


def team_from_payloads(payloads: Iterable[str]) -> str | None:
    """The first team a state payload names (a YAML mapping with a :data:`PAYLOAD_KEYS` key).

    Payloads that are not YAML mappings (``timeout``, a free-text operation) are skipped;
    scanning stops at the first name found.
    """
    import yaml  # lazy: PyYAML, 10-20 ms, only for the payloads of state topics

    from ertools.yamlin import load as load_yaml  # lazy: PyYAML 10-20 ms, payloads only

    for text in dict.fromkeys(payloads):  # 10 Hz state topics repeat each payload
        if ":" not in text or not any(k in text for k in PAYLOAD_KEYS):
            continue
        try:
            data = load_yaml(text, duplicates=[])  # a name: read as the 2015 nodes did
        except yaml.YAMLError:
            continue
        if not isinstance(data, dict):
            continue
        for key in PAYLOAD_KEYS:
            value = data.get(key)
            if isinstance(value, str | int) and str(value).strip() not in NO_TEAM:
                return str(value).strip()
    return None


@frozen_dataclass
class Team:
    """A result's team and where the name came from."""

    name: str
    source: TeamSource


def resolve_team(
    explicit: str | None = None,
    *,
    inputs: Iterable[str | Path] = (),
    payload_team: str | None = None,
    transform: str | Path | None = None,
    transform_team: str | None = None,
) -> Team | None:
    """The team by precedence: ``--team`` > payload > log name > transform; None if none.

    Args:
        explicit: the ``--team`` value.
        inputs: the logs scored (their names are searched, the first rockin_logger name wins).
        payload_team: the name :func:`team_from_payloads` found in the state payloads.
        transform: the FBM2H transform file (its ``transform-<team>.yaml`` name).
        transform_team: the transform's ``robot_info`` (preferred to its file name).
    """
    if explicit is not None and explicit.strip():
        return Team(explicit.strip(), "explicit")
    if payload_team:
        return Team(payload_team, "payload")
    for path in inputs:
        team = team_from_log_name(path)
        if team:
            return Team(team, "log name")
    if transform_team and transform_team.strip() not in NO_TEAM:
        return Team(transform_team.strip(), "transform")
    if transform is not None:
        team = team_from_transform_name(transform)
        if team:
            return Team(team, "transform")
    return None


def read_payload_team(paths: Iterable[str | Path], namespace: str) -> str | None:
    """The team the state payloads of ``namespace`` (``fbm2h``...) in ``paths`` name, or None
    (no state topics, unreadable logs: the name is then looked for elsewhere)."""

    plist = [Path(p) for p in paths]
    if not plist or not namespace:
        return None
    try:
        states = read_benchmark_states(plist, namespace)
    except (ErtoolsError, OSError):
        return None
    streams = (states.refbox, states.bmbox, states.client)  # the RefBox first: it names teams
    return team_from_payloads(p for s in streams if s is not None for p in s.payload)


def with_team(result: Any, explicit: str | None, inputs: Iterable[str | Path]) -> Any:
    """``result`` (a frozen result dataclass) with ``provenance.team``/``team_source`` set by
    :func:`resolve_team` from ``explicit``, the logs' payloads and names and, for FBM2H, the
    transform used. A result with no team found is returned unchanged."""

    logs = [Path(p) for p in inputs if Path(p).suffix.lower() not in (".yaml", ".yml")]
    payload_team = None
    if not (explicit and explicit.strip()):
        name = str(getattr(result, "name", ""))
        # Only the benchmarks with state topics (/fbm1h/..., /fbm3w/...) have payloads.
        if _NAMESPACE_RE.match(name):
            payload_team = read_payload_team(logs, name)
    transform = getattr(result, "transform", None)  # FBM2H: the MarkerTransform used
    team = resolve_team(
        explicit,
        inputs=logs,
        payload_team=payload_team,
        transform=getattr(transform, "source", None) or None,
        transform_team=getattr(transform, "robot_info", None),
    )
    provenance = getattr(result, "provenance", None)
    if team is None or provenance is None or not dataclasses.is_dataclass(result):
        return result
    new_provenance = dataclasses.replace(provenance, team=team.name, team_source=team.source)
    return dataclasses.replace(result, provenance=new_provenance)  # type: ignore[type-var]


__all__ = [
    "PAYLOAD_KEYS",
    "ROBOT_LOG_RE",
    "SOURCE_TEXT",
    "RobotLogName",
    "Team",
    "TeamSource",
    "parse_robot_log_name",
    "read_payload_team",
    "resolve_team",
    "team_from_log_name",
    "team_from_payloads",
    "team_from_transform_name",
    "with_team",
]
