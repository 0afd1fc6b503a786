"""Two rescorings at once in one process (issue 36, finding 16): ``ertools.rescore`` called from
two threads, each into its own folder with two workers, share the process's fork server
(ertools/competition/children.py); neither may close what the other still uses, nor see the other's
warnings in its rows.

The calls run in a script of their own (a library caller's process, as a notebook's): the first
holds a long execution, the second starts once the first's server is up and lasts longer, so
that the first ends while the second's scorers still work, in every round.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.rescore.rescore_competition import LOGS, OFFSETS, SCALE, expected_value, make_competition

pytestmark = pytest.mark.slow

HERE = Path(__file__).parent
ROUNDS = 3
# three rounds of a few seconds each; a hang would otherwise block the suite
TIMEOUT_S = 240

CALLER = """
import json, os, sys, threading, time
from pathlib import Path

sys.path.insert(0, sys.argv[1])
from ertools.benchmarks import registry

registry.ENTRIES = (registry.Entry("toy", "rescore_toy:TOY", "a toy benchmark"),)
import logging

import ertools
from ertools.competition import children

base, rounds, jobs = Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
logging.getLogger("ertools").addHandler(logging.NullHandler())
for r in range(rounds):
    results, errors = {}, []

    def go(name):
        try:
            doc = ertools.rescore(
                [], config=base / name / "competition.yaml", out=base / f"out-{name}-{r}",
                jobs=jobs, reports=False,
            )
            results[name] = {
                e["id"]: [e["status"], e["reason"], (e["score"] or {}).get("toy"), e["warnings"]]
                for e in doc["executions"]
            }
        except BaseException as err:
            errors.append(f"{name}: {type(err).__name__}: {err}")

    first = threading.Thread(target=go, args=("a",))
    first.start()
    # the first call under way (its folder locked; with workers, its fork server up)
    lock = base / f"out-a-{r}" / ".ertools.lock"
    while first.is_alive() and not (
        lock.exists() and (jobs == 1 or os.getpid() in children._servers)
    ):
        time.sleep(0.005)
    second = threading.Thread(target=go, args=("b",))
    second.start()
    first.join()
    second.join()
    print(json.dumps({"results": results, "errors": errors}), flush=True)
"""

SLOW_A = {"toy-alpha-20151120T120000": ("alpha", "2015-11-20T12:00:00Z", "1\nsleep\nwarn\n2\n")}
SLOW_B = {
    "toy-beta-20151120T120000": ("beta", "2015-11-20T12:00:00Z", "sleep\nsleep\nwarn\n3\n"),
    "toy-alpha-20151120T123000": ("alpha", "2015-11-20T12:30:00Z", "sleep\nsleep\n5\nmoment\n"),
}


WARNS = ("toy-alpha-20151120T120000", "toy-beta-20151120T120000")


def expected(extra: dict[str, tuple[str, str, str]]) -> dict[str, float]:
    """Each execution's value by hand: mean of its numbers x scale + its team's offset."""
    out = {ident: expected_value(ident) for ident in LOGS}
    for ident, (team, _, text) in extra.items():
        numbers = [float(w) for w in text.split() if w.replace(".", "").isdigit()]
        out[ident] = sum(numbers) / len(numbers) * SCALE + OFFSETS[team]
    return out


@pytest.mark.parametrize("jobs", [2, 1])
def test_two_threads_rescore_at_once(jobs: int, tmp_path: Path) -> None:
    """Every round: no error, every execution scored as by hand, and each row with its own
    warnings only (the ones its scorer logged, and the one of ``moment``)."""
    make_competition(tmp_path / "a", extra=SLOW_A)
    make_competition(tmp_path / "b", extra=SLOW_B)
    script = tmp_path / "caller.py"
    script.write_text(textwrap.dedent(CALLER))
    proc = subprocess.run(
        [sys.executable, str(script), str(HERE), str(tmp_path), str(ROUNDS), str(jobs)],
        env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    rounds = [json.loads(line) for line in proc.stdout.splitlines()]
    assert len(rounds) == ROUNDS
    want = {"a": expected(SLOW_A), "b": expected(SLOW_B)}
    for n, done in enumerate(rounds):
        assert done["errors"] == [], (n, done["errors"])
        for name in ("a", "b"):
            rows = done["results"][name]
            assert sorted(rows) == sorted(want[name]), (n, name)
            for ident, (status, reason, toy, warnings) in rows.items():
                assert status == "scored", (n, name, ident, reason)
                assert abs(toy["value"] - want[name][ident]) < 1e-12, (n, name, ident)
                # the warning of b's `moment` execution is b's, in that row only
                moment = any("not kept in the cache" in w for w in warnings)
                assert moment == (ident == "toy-alpha-20151120T123000"), (n, ident, warnings)
                logged = [w for w in warnings if w.startswith("toy warning")]
                log = f"{ident}.txt"
                assert logged == ([f"toy warning from {log}"] if ident in WARNS else []), (
                    n,
                    ident,
                    warnings,
                )
