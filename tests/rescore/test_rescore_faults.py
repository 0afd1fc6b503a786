"""`ertools rescore` under faults (issue 25): a killed command leaves no worker behind, outputs
are whole or absent, two runs into one folder take turns, CSV cells never become formulas.

Kill points are chosen deterministically: a toy log holding the word ``hold`` makes its
scorer write its pid and wait for ever (tests/rescore/rescore_toy.py), and the test kills when
that file appears; a write is killed from inside, by the hook it goes through.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from ertools import atomic
from ertools.cli.main import main
from ertools.competition import cache
from ertools.csvsafe import spreadsheet_safe
from tests.rescore.rescore_competition import (
    LOGS,
    expected_value,
    make_competition,
    use_toy_registry,
)

HERE = Path(__file__).parent
TOY_MAIN = HERE / "toy_main.py"
TOY_RESCORE = (sys.executable, str(TOY_MAIN), "rescore", "-q", "--no-reports", "--config")
# long enough for a loaded 2-core machine; a passing test never waits this long
DEADLINE_S = 60.0


@pytest.fixture(autouse=True)
def _toy(monkeypatch: pytest.MonkeyPatch) -> None:
    use_toy_registry(monkeypatch)


def wait_for(condition: Callable[[], bool], what: str) -> None:
    """Poll ``condition`` until it holds (a condition, not a guessed delay)."""
    end = time.monotonic() + DEADLINE_S
    while not condition():
        if time.monotonic() > end:
            raise AssertionError(f"{what}: not after {DEADLINE_S} s")
        time.sleep(0.05)


def alive(pid: int) -> bool:
    """A process that exists and is not a zombie waiting to be reaped."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "\nState:\tZ" not in status


HOLD = {
    "toy-alpha-20151120T110000": ("alpha", "2015-11-20T11:00:00Z", "hold\n"),
    "toy-beta-20151120T113000": ("beta", "2015-11-20T11:30:00Z", "hold\n"),
}


def ppid(pid: int) -> int:
    status = Path(f"/proc/{pid}/status").read_text()
    return int(status.split("\nPPid:\t", 1)[1].split("\n", 1)[0])


def cmdline(pid: int) -> str:
    return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()


def descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (children, their children...), from /proc."""
    children: dict[int, list[int]] = {}
    for status in Path("/proc").glob("[0-9]*/status"):
        try:
            ppid = int(status.read_text().split("\nPPid:\t", 1)[1].split("\n", 1)[0])
        except (OSError, IndexError, ValueError):
            continue
        children.setdefault(ppid, []).append(int(status.parent.name))
    out, stack = [], [pid]
    while stack:
        for child in children.get(stack.pop(), []):
            out.append(child)
            stack.append(child)
    return out


def _dask_or_skip() -> None:
    pytest.importorskip("distributed", reason="needs the dask extra: pip install -e '.[dask]'")


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("parallel", [["--jobs", "2"], ["--jobs", "2", "--scheduler", "local"]])
def test_workers_end_when_the_command_is_killed(parallel: list[str], tmp_path: Path) -> None:
    """kill -9 of `rescore --jobs 2` (local workers, or a Dask LocalCluster) while both
    executions are being scored: every process it started ends too. What it started: one fork
    server, a fork of the command (it had one thread then: ertools/competition/children.py), and
    the two scorers, the server's children."""
    if "--scheduler" in parallel:
        _dask_or_skip()
    comp = make_competition(tmp_path / "comp", extra=HOLD)
    pid_files = [comp.log(ident).with_name(comp.log(ident).name + ".pid") for ident in HOLD]
    proc = subprocess.Popen(
        [*TOY_RESCORE, str(comp.manifest), "--out", str(tmp_path / "out"), *parallel],
        env={
            **os.environ,
            "PYTHONPATH": os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]),
        },
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    tree: list[int] = []
    try:
        wait_for(
            lambda: all(p.is_file() and p.read_text().endswith("\n") for p in pid_files),
            "both executions being scored",
        )
        scorers = [int(p.read_text()) for p in pid_files]
        tree = descendants(proc.pid)
        assert len(set(scorers)) == 2 and set(scorers) <= set(tree)
        servers = [pid for pid in tree if ppid(pid) == proc.pid]
        assert len(servers) == 1, f"one server below the command: {tree}"
        assert {ppid(pid) for pid in scorers} == set(servers)
        assert cmdline(servers[0]) == cmdline(proc.pid)  # a fork, not a fresh interpreter
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        wait_for(lambda: not any(alive(p) for p in tree), "every process ending with rescore")
    finally:
        proc.kill()
        proc.wait()
        for p in tree:  # only if the test failed: leave nothing behind
            if alive(p):
                os.kill(p, signal.SIGKILL)


@pytest.mark.slow
def test_a_second_rescore_into_the_same_folder_waits_for_the_first(tmp_path: Path) -> None:
    """Two rescores into one --out take turns: the second says who it waits for, then writes
    results identical to a run alone."""
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    with atomic.folder_lock(out):  # the first run, as far as the second can tell
        proc = subprocess.Popen(
            [*TOY_RESCORE, str(comp.manifest), "--out", str(out), "--jobs", "1"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert proc.stderr is not None
        first = proc.stderr.readline()  # blocks until the second run reports the wait
        assert "being written by another ertools rescore" in first
        assert f"process {os.getpid()}" in first
        assert not (out / "results.json").exists()  # it waited before writing anything
    rest = proc.stderr.read()
    assert proc.wait() == 0, rest
    rows = json.loads((out / "results.json").read_text())["executions"]
    assert {r["id"]: r["rank_value"] for r in rows} == {i: expected_value(i) for i in LOGS}


def test_a_write_interrupted_before_its_rename_leaves_the_previous_results(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    argv = ["rescore", "--config", str(comp.manifest), "--out", str(out), "--jobs", "1"]
    assert main(argv) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert {"results.json", "results.csv", "index.html"} <= set(before)

    def killed(*_: object) -> None:
        raise KeyboardInterrupt  # as a Ctrl-C between the write and the rename would

    monkeypatch.setattr(atomic.os, "replace", killed)
    assert main([*argv, "--no-cache"]) == 130
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert after == before  # whole previous files, and no temporary left


def test_a_process_killed_inside_a_write_leaves_the_old_file_whole(tmp_path: Path) -> None:
    """SIGKILL at the chosen phase (after the data, before the rename): the target keeps its
    old content; nothing half-written has its name."""
    target = tmp_path / "results.json"
    target.write_text('{"old": true}\n')
    script = textwrap.dedent(
        f"""
        import os, signal
        from pathlib import Path
        from ertools import atomic
        def die(fd):
            os.kill(os.getpid(), signal.SIGKILL)
        atomic.os.fsync = die
        atomic.write_text(Path({str(target)!r}), "x" * 1_000_000)
        """
    )
    proc = subprocess.run([sys.executable, "-c", script], check=False)
    assert proc.returncode == -signal.SIGKILL
    assert target.read_text() == '{"old": true}\n'
    leftovers = [p.name for p in tmp_path.iterdir() if p != target]
    assert len(leftovers) == 1 and leftovers[0].startswith(".results.json.")


@pytest.mark.slow
def test_concurrent_writers_of_one_file_never_collide(tmp_path: Path) -> None:
    """Two processes rewriting results.json and results.csv 200 times each: every write
    succeeds and every read finds one whole file (the old shared `results.tmp` raced)."""
    script = textwrap.dedent(
        f"""
        import sys
        from pathlib import Path
        from ertools import atomic
        out = Path({str(tmp_path)!r})
        tag = sys.argv[1]
        for i in range(200):
            atomic.write_text(out / "results.json", '{{"by": "' + tag + '", "i": %d}}' % i)
            atomic.write_text(out / "results.csv", "by,i\\n" + tag + ",%d\\n" % i)
        """
    )
    procs = [subprocess.Popen([sys.executable, "-c", script, tag]) for tag in "ab"]
    reads = 0
    while any(p.poll() is None for p in procs) or reads == 0:
        for name in ("results.json", "results.csv"):
            path = tmp_path / name
            if path.exists():
                text = path.read_text()
                if name == "results.json":
                    assert json.loads(text)["by"] in "ab"
                else:
                    assert text.startswith("by,i\n") and text.count("\n") == 2
                reads += 1
    assert [p.wait() for p in procs] == [0, 0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.csv", "results.json"]


def test_csv_cells_that_look_like_formulas_are_text(tmp_path: Path) -> None:
    """A team named =HYPERLINK(...) reaches results.csv as text: a leading apostrophe."""
    team = '=HYPERLINK("http://evil.example/","x")'
    extra = {"toy-evil-20151120T120000": (f"'{team}'", "2015-11-20T12:00:00Z", "1\n")}
    comp = make_competition(tmp_path / "comp", extra=extra)
    text = comp.manifest.read_text()  # the team takes alpha's offset file
    comp.manifest.write_text(
        text.replace(
            "    teams:\n",
            f"    teams:\n      '{team}':\n        transform: configs/transform-alpha.yaml\n",
        )
    )
    out = tmp_path / "out"
    assert main(["rescore", "--config", str(comp.manifest), "--out", str(out), "-j", "1"]) == 0
    rows = list(csv.DictReader(io.StringIO((out / "results.csv").read_text())))
    evil = next(r for r in rows if "HYPERLINK" in r["team"])
    assert evil["team"] == "'" + team
    assert float(evil["rank_value"]) == 1.0 * 2.0 + 0.25  # scored, alpha's offset
    doc = json.loads((out / "results.json").read_text())
    assert any(r["team"] == team for r in doc["executions"])  # the data itself is unchanged
    scored = next(r for r in rows if r["id"] == "toy-alpha-20151120T091000")
    assert float(scored["rank_value"]) == expected_value("toy-alpha-20151120T091000")


@pytest.mark.parametrize(
    ("cell", "expected"),
    [
        ("=1+1", "'=1+1"),
        ("+1+cmd|' /C calc'!A0", "'+1+cmd|' /C calc'!A0"),
        ("+1", "+1"),
        ("-2+3", "'-2+3"),
        ("@SUM(A1)", "'@SUM(A1)"),
        ("\tx", "'\tx"),
        ("\rx", "'\rx"),
        ("alpha", "alpha"),
        ("", ""),
        ("-0.5", "-0.5"),  # a number as text: a spreadsheet reads it as the number
        ("-1e3", "-1e3"),
        ("-inf", "'-inf"),
        (" -1", " -1"),
        (-0.5, -0.5),  # a number stays a number
        (None, None),
    ],
)
def test_spreadsheet_safe(cell: object, expected: object) -> None:
    assert spreadsheet_safe(cell) == expected


# ------------------------------------------------------------------------------------------
# The cache trusts nothing it finds


def entries(out: Path) -> list[Path]:
    return sorted((out / "cache" / "outcomes").glob("*.json"))


def entry_of(out: Path, ident: str) -> Path:
    for path in entries(out):
        if json.loads(path.read_text())["outcome"]["report"].endswith(f"/{ident}/index.html"):
            return path
    raise AssertionError(ident)


FIRST = "toy-alpha-20151120T091000"


def edit(field: str, value: Any, *, keep_checksum: bool = False) -> Callable[[Path], None]:
    def damage(out: Path) -> None:
        path = entry_of(out, FIRST)
        entry = json.loads(path.read_text())
        entry["outcome"][field] = value
        if keep_checksum:  # a forger who recomputes the checksum (it is not signed)
            material = {k: v for k, v in entry.items() if k != "checksum"}
            entry["checksum"] = hashlib.sha256(
                json.dumps(material, sort_keys=True).encode()
            ).hexdigest()
        path.write_text(json.dumps(entry))

    return damage


@pytest.mark.parametrize(
    ("damage", "why"),
    [
        (edit("rank_value", 1e-9), "checksum mismatch"),  # a hand edit
        (edit("status", "bogus", keep_checksum=True), "invalid status"),
        (edit("report", 123, keep_checksum=True), "invalid report"),
        (edit("rank_value", "abc", keep_checksum=True), "invalid rank_value"),
        (edit("warnings", [1, 2], keep_checksum=True), "invalid warnings"),
        (lambda out: entry_of(out, FIRST).write_text("{not json"), "not JSON"),
        (lambda out: entry_of(out, FIRST).write_text('{"rank_value": NaN}'), "cache version"),
        (
            lambda out: (out / "executions" / FIRST / "score.json").write_text('{"x"'),
            "report file score.json has changed",
        ),
        (
            lambda out: (out / "executions" / FIRST / "score.yaml").unlink(),
            "report file score.yaml is missing",
        ),
    ],
)
def test_a_cache_entry_that_is_not_right_is_scored_again(
    damage: Callable[[Path], None], why: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    argv = ["rescore", "--config", str(comp.manifest), "--out", str(out), "--jobs", "1"]
    assert main(argv) == 0
    report = out / "executions" / FIRST
    files = {p.relative_to(report): p.read_bytes() for p in report.rglob("*") if p.is_file()}
    capsys.readouterr()
    damage(out)
    assert main(argv) == 0
    err = capsys.readouterr().err
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    # by hand: the values of the toy competition, whatever the damage
    assert {i: r["rank_value"] for i, r in rows.items()} == {i: expected_value(i) for i in LOGS}
    assert [i for i, r in rows.items() if not r["cached"]] == [FIRST]
    warnings = [line for line in err.splitlines() if "cache entr" in line]
    assert len(warnings) == 1 and "1 cache entry not used, scored again" in warnings[0]
    assert why in warnings[0], warnings[0]
    assert "this is a bug" not in err
    # the report folder written again: the same files (result.json has its own time stamp)
    again = {p.relative_to(report) for p in report.rglob("*") if p.is_file()}
    assert again == set(files)
    assert (report / "score.json").read_bytes() == files[Path("score.json")]
    # and the third run takes everything from the cache again
    assert main(argv) == 0
    doc = json.loads((out / "results.json").read_text())
    assert all(r["cached"] for r in doc["executions"])
    assert "cache entr" not in capsys.readouterr().err


def test_a_damaged_hash_memo_costs_the_hashing_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    argv = ["rescore", "--config", str(comp.manifest), "--out", str(out), "--jobs", "1"]
    assert main(argv) == 0
    memo = out / "cache" / "hashes.json"
    rows = json.loads(memo.read_text())
    first = next(iter(rows))
    rows[first] = "bogus"
    rows["/elsewhere"] = [1, 2]
    memo.write_text(json.dumps(rows))
    assert main(argv) == 0
    doc = json.loads((out / "results.json").read_text())
    assert all(r["cached"] for r in doc["executions"])  # the file hashed again: same key
    assert "this is a bug" not in capsys.readouterr().err


def test_a_machine_error_is_not_cached(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A report folder that cannot be written makes its execution unscoreable this time, and
    is not remembered: once the folder can be written, it is scored."""
    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    argv = ["rescore", "--config", str(comp.manifest), "--out", str(out), "--jobs", "1"]
    (out / "executions").mkdir(parents=True)
    (out / "executions" / FIRST).write_text("a file where the report folder goes")
    assert main(argv) == 1
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    assert rows[FIRST]["status"] == "unscoreable"
    assert "cannot write the report folder" in rows[FIRST]["reason"]
    (out / "executions" / FIRST).unlink()
    assert main(argv) == 0
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    assert rows[FIRST]["status"] == "scored" and not rows[FIRST]["cached"]
    assert rows[FIRST]["rank_value"] == expected_value(FIRST)
    assert capsys.readouterr().err.count("0 unscoreable") == 1


def test_report_files_are_read_again_only_when_their_stamp_changed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A warm rerun checks the report folders from the stamps remembered in hashes.json (no
    file read); a file rewritten with the same size (a new inode and time, as any write
    gives) is read, found changed, and its execution scored again."""

    comp = make_competition(tmp_path / "comp")
    out = tmp_path / "out"
    argv = ["rescore", "--config", str(comp.manifest), "--out", str(out), "--jobs", "1"]
    assert main(argv) == 0
    read: list[str] = []
    real = cache._sha256_file

    def counted(path: Path) -> str:
        read.append(path.name)
        return real(path)

    monkeypatch.setattr(cache, "_sha256_file", counted)
    assert main(argv) == 0
    assert read == []  # every report file known by its stamp
    score = out / "executions" / FIRST / "score.json"
    text = score.read_bytes()
    flipped = text.replace(b"4.25", b"9.25", 1)  # same size, other content
    assert flipped != text and len(flipped) == len(text)
    score.unlink()  # a new file, as an editor or a copy writes it
    score.write_bytes(flipped)
    capsys.readouterr()
    assert main(argv) == 0
    assert "report file score.json has changed" in capsys.readouterr().err
    rows = {r["id"]: r for r in json.loads((out / "results.json").read_text())["executions"]}
    assert [i for i, r in rows.items() if not r["cached"]] == [FIRST]
    assert score.read_bytes() == text  # written again by the scorer
