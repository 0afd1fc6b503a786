"""A goal's result string read as the RSBB scripts read it (``ertools.rsbb.answers``): the
cases written by hand from what PyYAML and Python's ``float`` do with them."""

from __future__ import annotations

from typing import Any

import pytest

from ertools.rsbb.answers import is_number, parse_answer


@pytest.mark.parametrize(
    ("text", "data", "problem"),
    [
        ("{x: 1, y: 2.5, class: a}", {"x": 1, "y": 2.5, "class": "a"}, None),
        ("", None, "the result is empty"),
        ("[1, 2]", [1, 2], "the result is a list, not a mapping"),
        ("just words", "just words", "the result is a str, not a mapping"),
        ("{x: [1", None, "the result is not YAML"),
    ],
)
def test_an_answer_is_a_mapping_or_says_why_not(text: str, data: Any, problem: str | None) -> None:
    assert parse_answer(text) == (data, problem)


@pytest.mark.parametrize(
    ("value", "number"),
    [(1, True), (-0.5, True), (float("nan"), True), (True, True), ("1.0", False), (None, False)],
)
def test_a_number_is_what_float_takes(value: Any, number: bool) -> None:
    assert is_number(value) is number


def test_an_int_beyond_a_float_is_no_number() -> None:
    # float(10**400) raises OverflowError: the script's %.2f died on it
    assert not is_number(10**400)
    assert is_number(10**300)
