"""`ertools info` states a median rate only with >= 10 messages over >= 1 s (issue 19).

A generated bag holds a 4-message /rosout burst (the sample bag's 2000 Hz line), a 120 Hz
pose topic over 2 s, a 1 Hz topic of 9 messages (8 s: too few), a 10 Hz topic of exactly 10
messages over 0.9 s (too short) and 11 over 1.0 s (enough), every expected value computed here
from the record times written.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ertools.cli.main import main
from tests.helpers.bagmaker import FORMATS, Spec, bag_name, write
from tests.helpers.scene import T0

FRAME = 8_333_333  # 120 Hz
MS = 1_000_000
S = 1_000_000_000


def burst_bag(path: Path, fmt: str) -> tuple[Path, dict[str, list[int]]]:
    times = {
        # the sample bag's burst: 0.5 ms, 199.6 ms and 0.1 ms apart (median 0.5 ms: "2000 Hz")
        "/rosout": [T0 + k for k in (0, 500_000, 200_100_000, 200_200_000)],
        "/pose": [T0 + i * FRAME for i in range(241)],  # 240 frames = 2.0 s at 120 Hz
        "/slow": [T0 + i * S for i in range(9)],  # 1 Hz, 8 s, 9 messages
        "/short": [T0 + i * 100 * MS for i in range(10)],  # 10 Hz, 10 messages, 0.9 s
        "/enough": [T0 + i * 100 * MS for i in range(11)],  # 10 Hz, 11 messages, 1.0 s
    }
    spec = Spec()
    for topic, ts in times.items():
        c = spec.conn(topic, "std_msgs/String")
        for t in ts:
            spec.add(c, t, data="x")
    spec.msgs.sort(key=lambda m: m[1])
    return write(path, fmt, spec), times


@pytest.mark.parametrize("fmt", FORMATS)
def test_rates_only_where_one_can_be_stated(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, fmt: str
) -> None:
    path, times = burst_bag(bag_name(tmp_path, fmt), fmt)
    assert main(["info", str(path), "--format", "json"]) == 0
    topics = {t["name"]: t for t in json.loads(capsys.readouterr().out)["bags"][0]["topics"]}
    for name, ts in times.items():
        assert topics[name]["count"] == len(ts)
        assert topics[name]["span_s"] == (ts[-1] - ts[0]) / 1e9
    # the burst's median interval is 0.5 ms: 2000 Hz, a rate it never had
    assert topics["/rosout"]["median_rate_hz"] is None
    assert topics["/slow"]["median_rate_hz"] is None  # 9 messages
    assert topics["/short"]["median_rate_hz"] is None  # 0.9 s
    assert topics["/enough"]["median_rate_hz"] == pytest.approx(10.0, rel=1e-15)
    assert topics["/pose"]["median_rate_hz"] == pytest.approx(1e9 / FRAME, rel=1e-15)

    assert main(["info", str(path)]) == 0
    rows = {
        x.split()[0]: x.split()[3:]
        for x in capsys.readouterr().out.splitlines()
        if x.startswith("  /")
    }
    assert rows["/rosout"] == ["4", "messages", "in", "0.2", "s"]  # 0.2002 s to 3 digits
    assert rows["/slow"] == ["9", "messages", "in", "8", "s"]
    assert rows["/short"] == ["10", "messages", "in", "0.9", "s"]
    assert rows["/enough"] == ["10", "Hz"]
    assert rows["/pose"] == ["120", "Hz"]
