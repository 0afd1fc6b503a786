"""The leaderboards of ``results.json``: per benchmark, each team's best scored execution ranked
by the benchmark's own rule, with the rank stability of docs/uncertainty.md."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import Discovered, Ranking
from ertools.competition.site_text import TEAM_UNKNOWN
from ertools.report import ranks

#: A score's ``status`` when the referee disqualified the run (a disqualifying behaviour).
DISQUALIFIED = "disqualified"


def leaderboards(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Per benchmark (registry order), each team's best scored execution by the benchmark's
    own :class:`~ertools.benchmarks.base.Ranking`; equal values share a rank."""
    boards: list[dict[str, Any]] = []
    names = [n for n in registry.names() if any(r["benchmark"] == n for r in rows)]
    names += sorted({str(r["benchmark"]) for r in rows} - set(names))
    for name in names:
        bench = registry.get(name)
        if not isinstance(bench, Discovered):  # a manifest takes no other
            continue
        ranking = bench.ranking
        sign = 1.0 if ranking.lower_is_better else -1.0
        best: dict[str, Mapping[str, Any]] = {}
        unranked: list[dict[str, Any]] = []
        columns: list[dict[str, str]] = []

        for row in rows:
            if row["benchmark"] != name or row["status"] != "scored" or row["rank_value"] is None:
                continue
            # A run the referee disqualified is shown, never ranked (the ERL rule).
            if isinstance(row.get("score"), Mapping) and row["score"].get("status") == DISQUALIFIED:
                why = "; ".join(row["score"].get("disqualifying_behaviors") or []) or "disqualified"
                unranked.append(
                    {
                        "execution": row["id"],
                        "value": row["rank_value"],
                        "note": f"{row['team'] or TEAM_UNKNOWN}: disqualified ({why})",
                        **_cells(ranking, row, columns),
                    }
                )
                continue
            # A score that says its data cannot support it (validity, docs/uncertainty.md) is
            # never ranked, whatever number it carries.
            unscoreable = ranks.unscoreable_reason(row.get("score"))
            if unscoreable is not None:
                unranked.append(
                    {
                        "execution": row["id"],
                        "value": row["rank_value"],
                        "note": f"{row['team'] or TEAM_UNKNOWN}: unscoreable ({unscoreable})",
                        **_cells(ranking, row, columns),
                    }
                )
                continue
            if row["team"] is None:  # scored, but ranked only once the manifest names it
                unranked.append(
                    {
                        "execution": row["id"],
                        "value": row["rank_value"],
                        "note": TEAM_UNKNOWN,
                        **_cells(ranking, row, columns),
                    }
                )
                continue
            team = str(row["team"])
            if team not in best or sign * row["rank_value"] < sign * best[team]["rank_value"]:
                best[team] = row
        ordered = sorted(best.items(), key=lambda tr: (sign * tr[1]["rank_value"], tr[0]))
        by_id = {str(r["id"]): r for _, r in ordered}
        confidence = ranks.board_confidence(ranks.confidence_of(r.get("score")) for _, r in ordered)
        standings = ranks.stability(
            [
                ranks.Contender(
                    team,
                    float(row["rank_value"]),
                    _interval(row, ranking.text),
                    ranks.confidence_of(row.get("score")) or ranks.DEFAULT_CONFIDENCE,
                    str(row["id"]),
                )
                for team, row in ordered
            ],
            lower_is_better=ranking.lower_is_better,
            confidence=confidence,
        )
        board_rows: list[dict[str, Any]] = [
            {
                "rank": s.rank,
                "team": s.name,
                "value": s.score,
                "execution": s.ident,
                "interval": list(s.interval) if s.interval else None,
                "p_swap_next": s.p_swap_next,
                "rank_group": s.group,
                "tied_with": list(s.tied_with),
                "rank_note": s.note,
                **_cells(ranking, by_id[s.ident], columns),
            }
            for s in standings
        ]
        title = next(str(r["title"]) for r in rows if r["benchmark"] == name)
        boards.append(
            {
                "benchmark": name,
                "title": title,
                "rule": ranking.text,
                "lower_is_better": ranking.lower_is_better,
                "confidence": confidence,
                "rows": board_rows,
                "unranked": unranked,
                **({"columns": columns} if columns else {}),
            }
        )
    return boards


def _cells(
    ranking: Ranking, row: Mapping[str, Any], columns: list[dict[str, str]]
) -> dict[str, Any]:
    """A row's own columns (:attr:`Ranking.columns`); each new header is added to the
    board's ``columns`` (its meaning beside it)."""
    score = row.get("score")
    if ranking.columns is None or not isinstance(score, Mapping):
        return {}
    shown = list(ranking.columns(score))
    for header, _, what in shown:
        if all(c["header"] != header for c in columns):
            columns.append({"header": header, "description": what})
    return {"columns": {header: value for header, value, _ in shown}}


def _interval(row: Mapping[str, Any], rule: str) -> tuple[float, float] | None:
    """The confidence interval of an execution's ranked value, from its score."""
    score = row.get("score")
    key = ranks.ranked_key(score, row.get("rank_value"), rule)
    return ranks.interval_of(score, key)
