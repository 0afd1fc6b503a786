"""The MCAP specification's own reader-conformance suite, through the CLI and the Python API.

Every ``.mcap`` of ``../shared/mcap_conformance`` sits beside a ``.json`` listing the records a
conforming reader must find (written by the specification's authors, not by ertools). The
expected messages (count, per-topic counts, first and last log time, per-topic log times) are
computed here from those records alone and must come out exactly, with exit status 0: every
file is a valid, complete MCAP file in one of the layouts the specification allows.

The suite is looked for in ``../shared/mcap_conformance`` (or ``$ERTOOLS_MCAP_CONFORMANCE``).
Without it the tests skip and say why; in CI (``CI`` set) they fail instead.
"""

from __future__ import annotations

import json
import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from ertools.cli.main import main
from ertools.io.files import open_bag
from ertools.io.summary import record_times
from ertools.io.summary import summary as bag_summary

SUITE = Path(
    os.environ.get("ERTOOLS_MCAP_CONFORMANCE")
    or Path(__file__).resolve().parents[2].parent / "shared" / "mcap_conformance"
)
FILES = sorted(SUITE.glob("*/*.mcap")) if SUITE.is_dir() else []
# The suite as copied from foxglove/mcap tests/conformance/data (see its README).
SUITE_SIZE = 416


@dataclass(frozen=True)
class Expected:
    count: int
    per_topic: dict[str, list[int]]  # topic -> sorted log times of its messages
    indexed: bool  # the summary's indexes cover every message (see ``expected``)

    @property
    def first(self) -> int:
        return min(t[0] for t in self.per_topic.values())

    @property
    def last(self) -> int:
        return max(t[-1] for t in self.per_topic.values())


def expected(mcap: Path) -> Expected:
    """The messages the suite's ``.json`` says a reader finds in ``mcap``."""
    doc = json.loads(mcap.with_suffix(".json").read_text())
    topic_of: dict[int, str] = {}
    schemaless = True
    summary = False
    messages: list[tuple[int, int]] = []
    for record in doc["records"]:
        fields = dict(record["fields"])
        if record["type"] == "Channel":
            topic_of[int(fields["id"])] = fields["topic"]
            schemaless &= fields["schema_id"] == "0"
        elif record["type"] == "Message":
            messages.append((int(fields["channel_id"]), int(fields["log_time"])))
        elif record["type"] == "Footer":
            summary = fields["summary_start"] != "0"
    per_topic: dict[str, list[int]] = {}
    for cid, t in messages:
        per_topic.setdefault(topic_of[cid], []).append(t)
    # The writer's options (the suite's variant features): ch chunked, chx chunk indexes,
    # mx message indexes, rch/rsh channels/schemas repeated in the summary. The indexes
    # answer alone when every message is in an indexed chunk with message indexes and the
    # summary names its channel (and schema).
    features = set(doc["meta"]["variant"]["features"])
    # Padded message indexes are counted record by record: a padded index and one whose
    # array length was damaged to fewer entries are the same bytes (found by fuzzing).
    covers = (
        {"ch", "chx", "mx", "rch"} <= features
        and ("rsh" in features or schemaless)
        and "pad" not in features
    )
    indexed = summary and (not messages or covers)
    return Expected(len(messages), {k: sorted(v) for k, v in per_topic.items()}, indexed)


def _need_suite() -> None:
    why = f"the MCAP conformance suite is not at {SUITE}"
    if os.environ.get("CI"):
        pytest.fail(f"{why} (CI must run it)")
    pytest.skip(why)


PARAMS = FILES or [None]
IDS = [f"{p.parent.name}/{p.stem}" for p in FILES] or ["suite-absent"]


def test_suite_is_whole() -> None:
    if not FILES:
        _need_suite()
    assert len(FILES) == SUITE_SIZE
    assert all(p.with_suffix(".json").is_file() for p in FILES)
    # both paths are exercised: files the indexes answer for, and files read record by record
    kinds = Counter(expected(p).indexed for p in FILES)
    assert kinds[True] > 0 and kinds[False] > 0


@pytest.mark.parametrize("path", PARAMS, ids=IDS)
def test_cli_info(path: Path | None, capsys: pytest.CaptureFixture[str]) -> None:
    if path is None:
        _need_suite()
        return
    want = expected(path)
    code = main(["info", "--format", "json", str(path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert err == ""
    data = json.loads(out)
    assert data["problems"] == []
    (bag,) = data["bags"]
    assert bag["messages"] == want.count
    counts = {t["name"]: t["count"] for t in bag["topics"] if t["count"]}
    assert counts == {k: len(v) for k, v in want.per_topic.items()}
    if want.count:
        # the suite's times are a few nanoseconds: float seconds hold them exactly enough
        # that rounding back to integer nanoseconds is exact
        assert round(bag["start"] * 1e9) == want.first
        assert round(bag["end"] * 1e9) == want.last
        for t in bag["topics"]:
            if t["count"]:
                assert round(t["first"] * 1e9) == want.per_topic[t["name"]][0]
                assert round(t["last"] * 1e9) == want.per_topic[t["name"]][-1]
    assert bag["index"] in ("summary+message-indexes", "summary", "scan")
    # the indexes are used exactly when the file has the ones that cover every message
    assert (bag["index"] != "scan") == want.indexed


@pytest.mark.parametrize("path", PARAMS, ids=IDS)
def test_api_summary_and_messages(path: Path | None) -> None:
    if path is None:
        _need_suite()
        return
    want = expected(path)
    counts = {k: len(v) for k, v in want.per_topic.items()}
    for exact in (False, True):
        s = bag_summary(path, exact=exact)
        assert s.problems == ()
        assert s.message_count == want.count
        assert {t.name: t.count for t in s.topics if t.count} == counts
        if want.count:
            assert (s.start_ns, s.end_ns) == (want.first, want.last)
    for t in bag_summary(path, exact=True).topics:
        if t.count:
            mine = want.per_topic[t.name]
            assert (t.first_ns, t.last_ns) == (mine[0], mine[-1])
    times = record_times(path)
    assert {k: v.tolist() for k, v in times.items() if len(v)} == want.per_topic
    # the message read: every message of every channel, in log-time order
    with open_bag(path) as bag:
        got = [(c.topic, t) for c, t, _data in bag.raw(bag.connections)]
    assert Counter(topic for topic, _t in got) == Counter(counts)
    t_read = np.array([t for _topic, t in got], dtype=np.int64)
    assert np.all(np.diff(t_read) >= 0)
    for topic, ts in want.per_topic.items():
        assert [t for name, t in got if name == topic] == ts
