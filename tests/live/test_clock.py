"""The SNTP clock check against a fake server on 127.0.0.1 with a known offset."""

from __future__ import annotations

import json
import re

import pytest
import yaml

from ertools.cli.main import main
from ertools.errors import ClockError
from ertools.live.clock import ns_to_ntp, ntp_to_ns, query_sntp
from tests.live.live_helpers import fake_sntp_server, free_udp_port

pytestmark = pytest.mark.xdist_group("timing")


@pytest.mark.parametrize("offset", [2.5, -0.25, 0.0])
def test_offset_is_measured_within_half_the_delay(offset: float) -> None:
    with fake_sntp_server(offset) as port:
        check = query_sntp("127.0.0.1", port, timeout_s=2.0)
    # SNTP's error bound: the true offset lies within delay/2 of the estimate (the server
    # stamps with exactly local + offset); 2 us more for the NTP fraction rounding.
    assert abs(check.offset_s - offset) <= check.delay_s / 2 + 2e-6
    assert 0 <= check.delay_s < 1.0
    assert check.stratum == 2
    assert check.within(abs(offset) + check.delay_s) and (offset == 0 or not check.within(0.01))


def test_ntp_timestamp_conversion_round_trips() -> None:
    t = 1_445_609_740_123_456_789  # 2015-10-23, the real bag's day
    back = ntp_to_ns(*ns_to_ntp(t))
    assert abs(back - t) <= 1  # 2**-32 s = 0.23 ns resolution, floor twice


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"stratum": 0}, "kiss-o'-death"),
        ({"leap": 3}, "not synchronised"),
        ({"echo": False}, "originate mismatch"),
    ],
)
def test_bad_replies_are_clock_errors(kwargs: dict[str, int], message: str) -> None:
    with fake_sntp_server(0.0, **kwargs) as port, pytest.raises(ClockError, match=message):
        query_sntp("127.0.0.1", port, timeout_s=2.0)


def test_cli_within_and_outside_tolerance(capsys: pytest.CaptureFixture[str]) -> None:
    with fake_sntp_server(0.2) as port:
        ok = main(["clock", "--server", "127.0.0.1", "--port", str(port), "--tolerance", "0.5"])
        out_ok = capsys.readouterr().out
        bad = main(["clock", "--server", "127.0.0.1", "--port", str(port), "--tolerance", "0.05"])
        out_bad = capsys.readouterr().out
    assert ok == 0 and out_ok.startswith("ok: offset +")
    assert bad == 1 and out_bad.startswith("outside tolerance: offset +")
    for out in (out_ok, out_bad):
        match = re.search(r"offset ([+-][0-9.]+) s, delay ([0-9.]+) s", out)
        assert match is not None, out
        offset, delay = float(match[1]), float(match[2])
        # Within delay/2 of the truth, plus the 6-decimal printing (5e-7 each).
        assert abs(offset - 0.2) <= delay / 2 + 2e-6


@pytest.mark.slow
def test_cli_unreachable_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    port = free_udp_port()  # nobody listens there
    code = main(["clock", "--server", "127.0.0.1", "--port", str(port), "--timeout", "0.3"])
    err = capsys.readouterr().err.strip()
    assert code == 1
    assert err.count("\n") == 0 and "unreachable" in err and err.startswith("ertools: error:")


def test_cli_json_and_yaml_give_the_numbers(capsys: pytest.CaptureFixture[str]) -> None:
    with fake_sntp_server(-0.25) as port:
        base = ["clock", "--server", "127.0.0.1", "--port", str(port), "--tolerance", "0.5"]
        assert main([*base, "--format", "json"]) == 0
        data = json.loads(capsys.readouterr().out)
        assert main([*base, "--format", "yaml", "--tolerance", "0.01"]) == 1
        outside = yaml.safe_load(capsys.readouterr().out)
    for got in (data, outside):
        assert abs(got["offset"] - -0.25) <= got["delay"] / 2 + 2e-6  # SNTP's bound
        assert got["stratum"] == 2 and got["port"] == port
    assert data["within_tolerance"] is True and data["tolerance"] == 0.5
    assert outside["within_tolerance"] is False and outside["tolerance"] == 0.01
