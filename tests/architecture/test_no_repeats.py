"""No run of 10 or more significant lines written twice inside ertools/ (issue 37): one rule
in one place. Significant: not blank, a comment, an import or lone punctuation; white space
folded. Exact copies only; copies with other names need a tool by hand (docs/qa.md)."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, plant, ratchet, repeats

# Pairs of files sharing a run today: none, and none may come back.
ALLOWED: frozenset[str] = frozenset()


def test_no_new_repeated_run() -> None:
    found = repeats(ROOT)
    ratchet(set(found), ALLOWED, "runs of 10+ lines repeated (" + "; ".join(found.values()) + ")")


def test_a_repeat_is_found_across_files_and_layouts(tmp_path: Path) -> None:
    body = "".join(f"    x{i} = {i}\n" for i in range(10))
    spaced = "".join(f"    x{i}  =  {i}\n\n    # note\n" for i in range(10))
    nine = "".join(f"    x{i} = {i}\n" for i in range(9))
    root = plant(
        tmp_path,
        {
            "ertools/a.py": f"import os\ndef f():\n{body}",
            "ertools/b.py": f"from sys import (\n    argv,\n)\ndef g():\n{spaced}",
            "ertools/c.py": f"def h():\n{nine}    y = 1\n",
        },
    )
    assert repeats(root) == {"ertools/a.py ~ ertools/b.py": "ertools/a.py:3-12 ~ ertools/b.py:5-32"}


def test_a_repeat_inside_one_file_is_found(tmp_path: Path) -> None:
    # two functions of one module with the same 10-line body (as auditing/model.py's
    # to_dict and tables had): one file, two places
    body = "".join(f"    x{i} = {i}\n" for i in range(10))
    root = plant(tmp_path, {"ertools/a.py": f"def f():\n{body}def g():\n    y = 0\n{body}"})
    assert repeats(root) == {"ertools/a.py": "ertools/a.py:2-11 ~ ertools/a.py:14-23"}
