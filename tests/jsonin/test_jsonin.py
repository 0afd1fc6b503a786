"""ertools.jsonin: JSON with a key given twice refused, naming both lines (issue 36)."""

from __future__ import annotations

import json

import pytest

from ertools import jsonin


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ('{"a": 1,\n "a": 2}', "duplicate key 'a' at line 2 (first at line 1)"),
        # the same key in two objects is no duplicate; inside one nested object it is
        (
            '{"a": {"k": 1},\n "b": {"k": 2,\n "k": 3}}',
            "duplicate key 'k' at line 3 (first at line 2)",
        ),
        # a key and a string value spelled alike, escapes and brackets inside strings
        (
            '{"v": "x\\\\", "w": "[{", "x": ["v", {"v": 1}],\n"v": 0}',
            "duplicate key 'v' at line 2 (first at line 1)",
        ),
        ('[{"q\\"": 1, "q\\"": 2}]', "duplicate key 'q\"' at line 1 (first at line 1)"),
    ],
)
def test_a_key_given_twice_is_named_with_its_lines(text: str, said: str) -> None:
    assert json.loads(text)  # the json module reads each, keeping the last value silently
    with pytest.raises(jsonin.DuplicateKeyError) as caught:
        jsonin.loads(text)
    assert str(caught.value) == said


def test_json_without_duplicates_reads_as_the_json_module_reads_it() -> None:
    text = '{"a": [1, 2.5, null, true], "b": {"a": "}"}, "c": "\\u00e9"}'
    assert jsonin.loads(text) == json.loads(text)
