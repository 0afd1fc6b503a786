"""What a rescore remembers of each log between runs (ertools.competition.memo): a warm rerun
reads no log to discover the executions, finds what it found the first time, and reads again
exactly the logs that changed."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from ertools.competition import found as found_module
from ertools.competition.found import find
from ertools.competition.memo import FileMemo


def test_a_fact_is_computed_once_per_version_of_the_file(tmp_path: Path) -> None:
    log = tmp_path / "a.bag"
    log.write_bytes(b"first")
    store = tmp_path / "memo.json"
    calls: list[str] = []

    def compute() -> str:
        calls.append(log.read_text())
        return log.read_text().upper()

    memo = FileMemo(store)
    assert memo.get(log, "fact", compute) == "FIRST"
    assert memo.get(log, "fact", compute) == "FIRST"
    memo.save()
    assert calls == ["first"]
    again = FileMemo(store)
    assert again.get(log, "fact", compute) == "FIRST"  # from the store: not computed
    assert calls == ["first"]
    log.write_bytes(b"second!")  # another size: another file
    assert again.get(log, "fact", compute) == "SECOND!"
    assert calls == ["first", "second!"]
    # a value that is not of the fact's shape is computed again
    assert again.get(log, "fact", compute, lambda v: v == "never") == "SECOND!"
    assert len(calls) == 3
    # --no-cache: nothing taken from the store, the store rewritten
    again.save()
    fresh = FileMemo(store, load=False)
    assert fresh.get(log, "fact", compute) == "SECOND!" and len(calls) == 4


@pytest.mark.parametrize(
    "text",
    [
        "{not json",
        json.dumps({"memo": 1, "ertools": "0.0.0-other", "files": {}}),
        json.dumps({"memo": 1, "files": {"x": {"stamp": "bogus", "fact": 1}}}),
    ],
)
def test_a_damaged_or_foreign_memo_costs_the_reading_only(tmp_path: Path, text: str) -> None:
    log = tmp_path / "a.bag"
    log.write_bytes(b"x")
    store = tmp_path / "memo.json"
    store.write_text(text)
    assert FileMemo(store).get(log, "fact", lambda: 42) == 42


def _counting(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    counts = {"clock": 0, "team": 0}
    clock, team = found_module.clock_check, found_module.read_payload_team

    def counted_clock(s: Any) -> Any:
        counts["clock"] += 1
        return clock(s)

    def counted_team(paths: Any, ns: str) -> Any:
        counts["team"] += 1
        return team(paths, ns)

    monkeypatch.setattr(found_module, "clock_check", counted_clock)
    monkeypatch.setattr(found_module, "read_payload_team", counted_team)
    return counts


@pytest.mark.slow
def test_a_warm_discovery_reads_no_log_and_finds_the_same(
    sample_competition: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    counts = _counting(monkeypatch)
    store = tmp_path / "files.json"
    plain = find([sample_competition])
    read = dict(counts)
    assert read["clock"] > 0 and read["team"] > 0
    memo = FileMemo(store)
    first = find([sample_competition], memo=memo)
    memo.save()
    assert counts == {k: 2 * v for k, v in read.items()}  # computed, as without a memo
    counts.update(clock=0, team=0)
    warm = find([sample_competition], memo=FileMemo(store))
    assert counts == {"clock": 0, "team": 0}
    for got in (first, warm):
        assert got.timeline == plain.timeline
        assert got.discovery == plain.discovery
        assert got.scorings == plain.scorings

    # one benchmark log seen as changed (its stamp no longer the file's): it alone is read
    rows = json.loads(store.read_text())
    changed = next(k for k, v in rows["files"].items() if any(f.startswith("team:") for f in v))
    rows["files"][changed]["stamp"][0] += 1
    store.write_text(json.dumps(rows))
    again = find([sample_competition], memo=FileMemo(store))
    assert counts["team"] == sum(f.startswith("team:") for f in rows["files"][changed])
    assert counts["clock"] == ("clock" in rows["files"][changed])
    assert again.discovery == plain.discovery
