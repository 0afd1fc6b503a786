"""The largest number of seconds ertools takes is written once (issue 37):
``ertools.timeutil.MAX_SECONDS``, which the command line, the API, the manifests, the configs
and every benchmark's number inputs read."""

from __future__ import annotations

import re

import pytest

from ertools.benchmarks.base import Input, resolve_values
from ertools.errors import UsageError
from ertools.timeutil import MAX_SECONDS, NS_PER_S
from tests.architecture.archscan import ROOT

LITERAL = re.compile(r"\b4\.6e9\b|\b4_600_000_000\b|\b4600000000\b")


def test_the_limit_is_written_once() -> None:
    found = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in sorted((ROOT / "ertools").rglob("*.py"))
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if LITERAL.search(line)
    ]
    assert len(found) == 1 and found[0].startswith("ertools/timeutil.py:"), found


def test_its_nanoseconds_fit_int64_twice() -> None:
    # a sum or difference of two such times still fits: 2 * 4.6e18 < 2**63 - 1 (9.22e18)
    assert 2 * int(MAX_SECONDS * NS_PER_S) < 2**63 - 1


def test_every_float_input_is_held_to_it() -> None:
    declared = (Input("offset", "float", "an offset", unit="s"),)
    assert resolve_values(declared, {"offset": MAX_SECONDS * 0.999})["offset"] < MAX_SECONDS
    with pytest.raises(UsageError) as refused:
        resolve_values(declared, {"offset": MAX_SECONDS})
    assert str(refused.value) == "--offset 4600000000.0: give a number smaller than 4.6e+09 in size"
