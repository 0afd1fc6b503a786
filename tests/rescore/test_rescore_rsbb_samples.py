"""`ertools rescore` on a freshly written single-benchmark RSBB sample (hgmf, hnf, hopf, hpff,
hppf) lists no file as unused: the sample's answers sit beside its layout folder, as the
season's do, since a real competition's folder holds none. A stray file put into the same
layout is still listed, on stderr and in results.json."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from ertools.samples.__main__ import generate
from ertools.simulator.answers import answers_path
from tests.helpers.inprocess import run

pytestmark = pytest.mark.slow  # writes a sample and rescores it twice (~1-3 s)

NOT_A_LOG = "not a log, and no input of any execution names it"


def _rescore(folder: Path, out: Path) -> tuple[str, dict[str, Any]]:
    ran = run(["rescore", str(folder), "--out", str(out), "--no-reports", "-j", "1", "-q"])
    assert ran.code == 0, ran.stderr
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    return ran.stderr, doc


@pytest.mark.parametrize("name", ["hgmf", "hnf", "hopf", "hpff", "hppf"])
def test_a_sample_layout_has_no_unused_file_but_a_stray_one(tmp_path: Path, name: str) -> None:
    generate(tmp_path / "samples", [name])
    folder = tmp_path / "samples" / name
    err, doc = _rescore(folder, tmp_path / "out")
    assert NOT_A_LOG not in err
    assert [f["path"] for f in doc["files"] if f["place"] == "problem"] == []
    assert doc["problems"] == []
    assert answers_path(folder).is_file()  # the answers exist, beside the folder
    assert doc["executions"] and all(e["status"] == "scored" for e in doc["executions"])

    # the same layout with a file that is no log, beside a run bag: still said
    bag = min(folder.glob("rsbb_logs/*/*/run_*.bag"))
    stray = bag.with_name("notes.txt")
    stray.write_text("the referee's notes\n", encoding="utf-8")
    err, doc = _rescore(folder, tmp_path / "out_stray")
    assert f"ertools: warning: {stray}: {NOT_A_LOG}" in err.splitlines()
    problems = [f for f in doc["files"] if f["place"] == "problem"]
    assert problems == [
        {
            "path": stray.relative_to(folder).as_posix(),
            "place": "problem",
            "execution": None,
            "kind": "unused",
            "reason": NOT_A_LOG,
        }
    ]
    assert [(p["kind"], p["path"]) for p in doc["problems"]] == [("unused", str(stray))]
