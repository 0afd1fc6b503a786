"""A recomputed RSBB score in the result file's ``score`` form, and compared with the scores the
run left: the last live score (``/rsbb/current_benchmark_result``) and the result file.

The BmBox dumped the score with PyYAML (keys sorted, block style); :func:`score_yaml` writes a
recomputed one the same way, so that the two can be read side by side. :func:`compare_scores`
flattens the three to dotted keys (``segment_2.distance_error``) and compares them leaf by
leaf: numbers within a tolerance, everything else (the ``"60.0%"`` strings, HNF's pose dumps,
booleans, nulls) exactly. The live score and the file should agree with each other (the
file is the last save); where they do not, the comparison says so (a script that died keeps
its last save in both, a run whose recorder stopped early has an older live score).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

import numpy as np
import yaml

from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.results import LiveScore, RsbbResult

#: Two numbers within this are the same score: 1 um, 1 urad, 1 us; above the round-off of a
#: YAML round trip, below every effect a deviation describes (the issue's tolerance where the
#: log records the lookups' moments).
SCORE_ABS_TOL = 1e-6


def plain(value: Any) -> Any:
    """``value`` with NumPy scalars and tuples made plain Python (for YAML and JSON)."""
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def score_yaml(score: Mapping[str, Any]) -> str:
    """The score as the BmBox dumped it into the result file (keys sorted, block style)."""
    return str(yaml.safe_dump(plain(score), default_flow_style=False))


def flatten(score: Any, prefix: str = "") -> dict[str, Any]:
    """Nested mappings as ``{"segment_1.distance_error": value}``; an empty mapping stays a
    leaf (``goal_2: {}`` is a score field of its own); lists stay whole leaves."""
    if not isinstance(score, Mapping) or (not score and prefix):
        return {prefix: score}
    out: dict[str, Any] = {}
    for key, value in score.items():
        out.update(flatten(value, f"{prefix}.{key}" if prefix else str(key)))
    return out


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


_FLOAT_IN_TEXT = re.compile(r"-?\d+\.\d+(?:[eE][-+]?\d+)?")


def _same_text(a: str, b: str, abs_tol: float) -> bool:
    """Texts that agree word for word, the decimal numbers in them (HNF's pose dumps hold each
    float's ``repr``) within ``abs_tol``."""
    if a == b:
        return True
    if _FLOAT_IN_TEXT.sub("#", a) != _FLOAT_IN_TEXT.sub("#", b):
        return False
    na = [float(x) for x in _FLOAT_IN_TEXT.findall(a)]
    nb = [float(x) for x in _FLOAT_IN_TEXT.findall(b)]
    return all(abs(x - y) <= abs_tol for x, y in zip(na, nb, strict=True))


def same_value(a: Any, b: Any, abs_tol: float = SCORE_ABS_TOL) -> bool:
    """Whether two score leaves agree: numbers within ``abs_tol`` (NaN equals NaN), lists
    element by element, texts word for word with their decimal numbers within ``abs_tol``
    (``"60.0%"`` is not ``"60.1%"``; a pose dump's last digit may differ), anything else
    exactly (type included: ``True`` is not ``1``)."""
    if _is_number(a) and _is_number(b):
        fa, fb = float(a), float(b)
        if math.isnan(fa) or math.isnan(fb):
            return math.isnan(fa) and math.isnan(fb)
        return fa == fb or abs(fa - fb) <= abs_tol
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(
            same_value(x, y, abs_tol) for x, y in zip(a, b, strict=True)
        )
    if isinstance(a, str) and isinstance(b, str):
        return _same_text(a, b, abs_tol)
    return type(a) is type(b) and bool(a == b)


@frozen_dataclass
class KeyComparison:
    """One score field in the recomputed, live and file scores.

    Attributes:
        key: the dotted key.
        recomputed, live, file: the values (None also when absent: see ``present``).
        present: which of the three hold the key, in that order.
        live_agrees, file_agrees: the recomputed value matches (None: either side lacks it,
            or there is no such score at all).
    """

    key: str
    recomputed: Any
    live: Any
    file: Any
    present: tuple[bool, bool, bool]
    live_agrees: bool | None
    file_agrees: bool | None

    def row(self) -> dict[str, Any]:
        """One row of the ``comparison`` table."""
        return {
            "key": self.key,
            "recomputed": _cell(self.recomputed, self.present[0]),
            "live": _cell(self.live, self.present[1]),
            "file": _cell(self.file, self.present[2]),
            "live_agrees": self.live_agrees,
            "file_agrees": self.file_agrees,
        }


def _cell(value: Any, present: bool) -> Any:
    if not present:
        return "(absent)"
    return value if isinstance(value, bool | int | float | str) or value is None else repr(value)


@frozen_dataclass
class ScoreComparison:
    """The recomputed score against the run's own.

    Attributes:
        keys: every key of any of the three, in the recomputed order then the others'.
        live_t_ns: the record time of the live score compared (the last that parsed), or None
            when the bag has none.
        live_form: ``"2019"`` (with a ``SCORE SUMMARY``), ``"2017"`` (one dump), or None.
        file: the result file compared, or None.
        live_file_differ: keys where the live score and the file disagree with each other.
        abs_tol: the tolerance on numbers.
    """

    keys: tuple[KeyComparison, ...]
    live_t_ns: int | None
    live_form: str | None
    file: str | None
    live_file_differ: tuple[str, ...]
    abs_tol: float

    def differing(self, against: str) -> tuple[KeyComparison, ...]:
        """The keys where the recomputed score differs from ``"live"`` or ``"file"`` (a key one
        side lacks counts)."""
        index = 1 if against == "live" else 2
        return tuple(
            k
            for k in self.keys
            if (k.live_agrees if index == 1 else k.file_agrees) is False
            or (k.present[0] != k.present[index])
        )

    def summary(self) -> list[str]:
        """A few lines for stderr: each score compared, and the first differences."""
        out: list[str] = []
        n = sum(k.present[0] for k in self.keys)
        for against, here in (("live", self.live_t_ns is not None), ("file", self.file)):
            name = (
                "live score (/rsbb/current_benchmark_result)"
                if against == "live"
                else f"result file ({self.file})"
            )
            if not here:
                out.append(
                    f"{name}: none to compare with"
                    if against == "live"
                    else "no result file: nothing to compare with"
                )
                continue
            diff = self.differing(against)
            if not diff:
                out.append(f"{name}: all {n} fields the same (numbers to {self.abs_tol:g})")
                continue
            shown = ", ".join(_describe(k, against) for k in diff[:4])
            more = f" and {len(diff) - 4} more" if len(diff) > 4 else ""
            out.append(f"{name}: {len(diff)} of {len(self.keys)} fields differ: {shown}{more}")
        if self.live_file_differ:
            out.append(
                "the live score and the result file disagree on "
                + ", ".join(self.live_file_differ[:4])
                + (" ..." if len(self.live_file_differ) > 4 else "")
                + " (the file holds the last save)"
            )
        return out

    def rows(self) -> list[dict[str, Any]]:
        """The ``comparison`` table: one row per key."""
        return [k.row() for k in self.keys]

    def to_dict(self) -> dict[str, Any]:
        """Counts and differing keys, for a JSON result."""
        return {
            "live_time_ns": self.live_t_ns,
            "live_form": self.live_form,
            "file": self.file,
            "abs_tol": self.abs_tol,
            "differ_from_live": [k.key for k in self.differing("live")]
            if self.live_t_ns is not None
            else None,
            "differ_from_file": [k.key for k in self.differing("file")] if self.file else None,
            "live_file_differ": list(self.live_file_differ),
        }


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 24 else text[:21] + "..."


def _describe(k: KeyComparison, against: str) -> str:
    index = 1 if against == "live" else 2
    theirs = k.live if index == 1 else k.file
    if not k.present[0]:
        return f"{k.key} (only there)"
    if not k.present[index]:
        return f"{k.key} (not there)"
    return f"{k.key} {_short(k.recomputed)} vs {_short(theirs)}"


def last_live_score(live: tuple[LiveScore, ...]) -> LiveScore | None:
    """The last live score message that parsed, or None."""
    for message in reversed(live):
        if message.result is not None:
            return message
    return None


def _score_of(result: Mapping[str, Any] | None) -> dict[str, Any] | None:
    if result is None:
        return None
    score = result.get("score")
    return dict(score) if isinstance(score, Mapping) else {}


def compare_scores(
    recomputed: Mapping[str, Any],
    live: tuple[LiveScore, ...] | LiveScore | None,
    file: RsbbResult | None,
    *,
    abs_tol: float = SCORE_ABS_TOL,
) -> ScoreComparison:
    """The recomputed score (result-file form) against the last live score and the file."""
    message = last_live_score(live) if isinstance(live, tuple) else live
    live_score = _score_of(message.result) if message is not None else None
    file_score = dict(file.score) if file is not None else None
    flat_r = flatten(plain(recomputed)) if recomputed else {}
    flat_l = flatten(live_score) if live_score else {}
    flat_f = flatten(file_score) if file_score else {}
    order = list(flat_r) + [k for k in flat_l if k not in flat_r]
    order += [k for k in flat_f if k not in flat_r and k not in flat_l]
    keys = []
    for key in order:
        present = (key in flat_r, key in flat_l, key in flat_f)
        r, v_l, v_f = flat_r.get(key), flat_l.get(key), flat_f.get(key)
        keys.append(
            KeyComparison(
                key,
                r,
                v_l,
                v_f,
                present,
                same_value(r, v_l, abs_tol) if present[0] and present[1] else None,
                same_value(r, v_f, abs_tol) if present[0] and present[2] else None,
            )
        )
    both = live_score is not None and file_score is not None
    live_file = tuple(
        k
        for k in dict.fromkeys([*flat_l, *flat_f])
        if both
        and (k not in flat_l or k not in flat_f or not same_value(flat_l[k], flat_f[k], abs_tol))
    )
    return ScoreComparison(
        tuple(keys),
        None if message is None else message.t_ns,
        None if message is None else ("2019" if message.summary_form else "2017"),
        None if file is None else file.path,
        live_file,
        abs_tol,
    )
