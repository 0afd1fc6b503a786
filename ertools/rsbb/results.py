"""RSBB result files and live scores (docs/rsbb.md, "The result file", "Saving and the live score").

The BmBox wrote both with Python 2 PyYAML: the file with ``yaml.dump`` (so a Python 2
``unicode`` string carries ``!!python/unicode`` and a tuple ``!!python/tuple``), the live
topic with ``yaml.safe_dump``. They are read with a safe loader that turns those tags into
plain strings and lists; any other Python tag is refused, nothing is ever constructed.
"""

from __future__ import annotations

import re
from datetime import datetime, timedelta, timezone
from pathlib import Path
from typing import Any

import yaml

from ertools.errors import ConfigError
from ertools.frozen_dataclass import frozen_dataclass

#: The line that separates the 2019 live score's result from its totals.
SUMMARY_MARK = "\n\nSCORE SUMMARY:\n"
LIVE_WHERE = "/rsbb/current_benchmark_result"


class RsbbLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that also reads Python 2 PyYAML's ``!!python/unicode``,
    ``!!python/str`` (as strings) and ``!!python/tuple`` (as a list)."""


def _as_str(loader: yaml.SafeLoader, node: yaml.Node) -> str:
    if not isinstance(node, yaml.ScalarNode):
        raise yaml.constructor.ConstructorError(
            None, None, f"{node.tag} must tag a scalar", node.start_mark
        )
    return str(loader.construct_scalar(node))


def _as_list(loader: yaml.SafeLoader, node: yaml.Node) -> list[Any]:
    if not isinstance(node, yaml.SequenceNode):
        raise yaml.constructor.ConstructorError(
            None, None, "!!python/tuple must tag a sequence", node.start_mark
        )
    return list(loader.construct_sequence(node, deep=True))


RsbbLoader.add_constructor("tag:yaml.org,2002:python/unicode", _as_str)
RsbbLoader.add_constructor("tag:yaml.org,2002:python/str", _as_str)
RsbbLoader.add_constructor("tag:yaml.org,2002:python/tuple", _as_list)


def load_rsbb_yaml(text: str, where: str) -> Any:
    """Parse RSBB YAML text with :class:`RsbbLoader`.

    Raises:
        ConfigError: not YAML, or a Python tag other than the three above.
    """
    try:
        return yaml.load(text, Loader=RsbbLoader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = f" (line {mark.line + 1})" if mark is not None else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ConfigError(f"{where}: not readable RSBB YAML{line}: {problem}") from err


@frozen_dataclass
class RsbbResult:
    """One ``result_run_<n>_<date>.yaml``.

    Attributes:
        path: the file.
        code, team, run: ``benchmark_info``'s benchmark code, team and run.
        start_time, end_time: ``benchmark_info``'s local times as written (``end_time`` None
            in the file written at setup).
        end_description: why the benchmark ended, as the BmBox last knew it.
        params: the benchmark config the script ran with (``None`` when it had none).
        score: the script's score mapping (``{}`` when empty).
        referee_score: the referee items (a list of mappings) or None.
    """

    path: str
    code: str
    team: str
    run: int
    start_time: str
    end_time: str | None
    end_description: str
    params: Any
    score: dict[str, Any]
    referee_score: list[dict[str, Any]] | None


def _result_from(data: Any, where: str) -> RsbbResult:
    if not isinstance(data, dict) or not isinstance(data.get("benchmark_info"), dict):
        raise ConfigError(f"{where}: not an RSBB result file (no benchmark_info mapping)")
    info = data["benchmark_info"]
    missing = [k for k in ("benchmark_code", "team", "run") if k not in info]
    if missing:
        raise ConfigError(f"{where}: benchmark_info lacks {', '.join(missing)}")
    run = info["run"]
    if not isinstance(run, int) or isinstance(run, bool):
        raise ConfigError(f"{where}: benchmark_info.run is {run!r}, not an integer")
    score = data.get("score")
    if score is None:
        score = {}
    if not isinstance(score, dict):
        raise ConfigError(f"{where}: score is a {type(score).__name__}, not a mapping")
    referee = data.get("referee_score")
    if referee is not None and not (
        isinstance(referee, list) and all(isinstance(i, dict) for i in referee)
    ):
        raise ConfigError(f"{where}: referee_score is not a list of items")
    params = info.get("params")
    return RsbbResult(
        path=where,
        code=str(info["benchmark_code"]),
        team=str(info["team"]),
        run=run,
        start_time=str(info.get("start_time", "")),
        end_time=None if info.get("end_time") is None else str(info["end_time"]),
        end_description=str(info.get("end_description", "")),
        params=None if params == "None" else params,
        score=score,
        referee_score=referee,
    )


def load_result(path: str | Path) -> RsbbResult:
    """Read a result file.

    Raises:
        ConfigError: unreadable, not YAML, or not the result layout.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{p}: cannot read the result file ({err})") from err
    return _result_from(load_rsbb_yaml(text, str(p)), str(p))


@frozen_dataclass
class LiveScore:
    """One ``/rsbb/current_benchmark_result`` message.

    Attributes:
        t_ns: record time.
        text: the message as published.
        result: the parsed result (``benchmark_info``, ``score``, ``referee_score``), the
            2019 summary merged back into ``score``; None when the text is not YAML.
        summary_form: True for the 2019 form (a ``SCORE SUMMARY`` section).
    """

    t_ns: int
    text: str
    result: dict[str, Any] | None
    summary_form: bool


def parse_live_score(t_ns: int, text: str) -> LiveScore:
    """A live score message in either season's form; ``result`` None if it does not parse."""
    summary_form = SUMMARY_MARK in text
    head, _, tail = text.partition(SUMMARY_MARK) if summary_form else (text, "", "")
    try:
        result = load_rsbb_yaml(head, LIVE_WHERE)
        summary = load_rsbb_yaml(tail, LIVE_WHERE) if summary_form else None
    except ConfigError:
        return LiveScore(t_ns, text, None, summary_form)
    if not isinstance(result, dict) or (summary is not None and not isinstance(summary, dict)):
        return LiveScore(t_ns, text, None, summary_form)
    if summary:
        score = result.get("score")
        result["score"] = {**(score if isinstance(score, dict) else {}), **summary}
    return LiveScore(t_ns, text, result, summary_form)


_RESULT_TIME = re.compile(
    r"^(\d{4}-\d{2}-\d{2})_(\d{2}:\d{2}:\d{2})_([^()]*)\(([+-])(\d{2})(\d{2})\)$"
)


def parse_result_time(text: str) -> datetime | None:
    """A result file's date (``2017-12-14_20:37:46_WET(+0000)``) as an aware datetime."""
    m = _RESULT_TIME.match(text.strip())
    if m is None:
        return None
    try:
        local = datetime.fromisoformat(f"{m.group(1)}T{m.group(2)}")
    except ValueError:
        return None
    sign = 1 if m.group(4) == "+" else -1
    offset = timedelta(hours=int(m.group(5)), minutes=int(m.group(6))) * sign
    return local.replace(tzinfo=timezone(offset))
