"""`make fuzz`: mutate ROS1 and MCAP seed files and judge ertools' readers on every mutant.

    .venv/bin/python fuzz/run.py [--cases N] [--seed S] [--jobs J] [--timeout SEC]
    .venv/bin/python fuzz/run.py --seed S --case K [--keep FILE]   # one case, in full

Case K of seed S is fully determined by (S, K): its seed file is ``SEED_NAMES[K % 10]`` and
its mutation is drawn from ``numpy.random.default_rng([S, K])``. Every case runs in a worker
process that the parent watches: a case that gives no verdict within ``--timeout`` seconds
(default 20; a case takes ~50 ms) is a hang, its worker is killed and a new one takes the
next case. A watchdog process rather than SIGALRM, because an alarm cannot interrupt a long
call inside C code (a decompressor, a huge allocation) and would miss exactly those hangs.
Workers also run with a 3 GiB address-space limit, so an absurd length that makes a reader
allocate fails with MemoryError (a traceback, reported) instead of swapping the machine.

The last line is the summary, e.g.
``fuzz: 10000 cases, 9000 agreements (800 partial reads), 1000 clear refusals,
0 disagreements, 0 tracebacks, 0 hangs (seed 1)``; the exit status is 1 when any case is a
disagreement, a traceback or a hang.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import select
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from fuzz.seeds import SEEDS, suffix  # noqa: E402

SEED_NAMES = tuple(SEEDS)
CLI_EVERY = 25  # one case in CLI_EVERY also runs `ertools info` and `ertools noise`


def _applied(
    seed_data: bytes, edits: list[tuple[int, bytes]], which: set[int], workdir: Path, name: str
) -> Path:
    """The seed file with only the changes ``which`` (indices into ``edits``) applied,
    written to ``workdir``."""
    data = bytearray(seed_data)
    for k, (at, new) in enumerate(edits):
        if k in which:
            data[at : at + len(new)] = new
    path = workdir / f"part{suffix(name)}"
    path.write_bytes(bytes(data))
    return path


def _disagrees(parts: dict[str, tuple[str, str]]) -> bool:
    return any(v == "disagree" for v, _ in parts.values())


def _evidence(name: str, path: Path, summary: Any) -> str:
    """Evidence that the official reader read damaged bytes of ``path`` as sound (an MCAP
    CRC fails; a ROS1 index contradicts the bag's intact records, ``summary`` the undamaged
    file's); '' when there is none."""
    from fuzz.judge import mcap_crc_evidence, ros1_index_evidence

    if name.startswith("mcap"):
        return mcap_crc_evidence(path)
    return ros1_index_evidence(path, summary)


def run_case(seed: int, index: int, workdir: Path, keep: Path | None = None) -> dict[str, Any]:
    """Mutate, read with both readers, judge. Returns the verdict record of the case."""
    import numpy as np

    from fuzz.judge import (
        PARTS,
        cli_check,
        ertools_answer,
        judge_part,
        misread,
        misread_but_for,
        official_answer,
        worst,
    )
    from fuzz.mutate import mutate
    from fuzz.seeds import seed_bytes

    name = SEED_NAMES[index % len(SEED_NAMES)]
    rng = np.random.default_rng([seed, index])
    seed_data = seed_bytes(name)
    mutant = mutate(seed_data, rng)
    path = keep or workdir / f"case{suffix(name)}"
    path.write_bytes(mutant.data)
    truth = _truth(name, workdir)
    ert = ertools_answer(path)
    off = official_answer(path)
    parts = {p: judge_part(p, ert[p], off[p], [truth[p]]) for p in PARTS}
    several = len(mutant.edits) > 1 and _disagrees(parts)
    alone: list[dict[str, Any]] = []
    left_out: list[dict[str, Any]] = []
    if several:
        # several changes: also accept what the official reader reads with each one alone,
        # and with each one left out (one byte breaks the official reader, others change a
        # pose both would read)
        for k in range(len(mutant.edits)):
            alone.append(official_answer(_applied(seed_data, mutant.edits, {k}, workdir, name)))
            rest = set(range(len(mutant.edits))) - {k}
            left_out.append(official_answer(_applied(seed_data, mutant.edits, rest, workdir, name)))
        parts = {
            p: judge_part(
                p, ert[p], off[p], [truth[p], *(a[p] for a in alone), *(w[p] for w in left_out)]
            )
            for p in PARTS
        }
    if _disagrees(parts):
        # the official reader read damaged bytes as sound and ertools gave the undamaged answer
        evidence = _evidence(name, path, truth["summary"])
        parts = {p: misread(p, parts[p], ert[p], truth[p], evidence) for p in PARTS}
    if several and _disagrees(parts):
        # one change damaged what the official reader trusts (shown on the file with that
        # change alone), another the bytes of a message: ertools' answer is the official
        # reader's without the first
        for k, (at, _new) in enumerate(mutant.edits):
            if not _disagrees(parts):
                break
            single = _applied(seed_data, mutant.edits, {k}, workdir, name)
            shown = _evidence(name, single, truth["summary"])
            if not shown:
                continue
            parts = {
                p: misread_but_for(
                    p, parts[p], ert[p], truth[p], alone[k][p], left_out[k][p], shown, at
                )
                for p in PARTS
            }
    verdict = worst([v for v, _ in parts.values()])
    owner = ""
    if verdict == "disagree":
        owner = owner_of(name, mutant, dict(parts), ert, truth, off)
    cli = cli_check(path) if index % CLI_EVERY == 0 else ""
    if cli:
        verdict = "traceback" if "unexpected" in cli or "Traceback" in cli else "disagree"
    return {
        "index": index,
        "seed_file": name,
        "mutation": mutant.what,
        "verdict": verdict,
        "parts": {p: v for p, (v, _d) in parts.items()},
        "details": {p: d for p, (v, d) in parts.items() if v not in ("agree",)},
        "cli": cli,
        "owner": owner,
    }


# Disagreements that the concurrent reader work covers (issue 17): MCAP layouts the spec
# allows (files without message indexes, channels whose schema is only in the data section)
# and index-versus-record checks (an index that disagrees with the records it indexes).
ROS1_INDEX_FIELDS = ("index_data.", "chunk_info.", "connection.", "bag_header.", "chunk.message.")
MCAP_INDEX_FIELDS = ("message_index.", "chunk_index.", "statistics.", "summary_offset.", "footer.")


def owner_of(
    name: str,
    mutant: Any,
    parts: dict[str, tuple[str, str]],
    ert: Any,
    truth: Any,
    off_answers: Any,
) -> str:
    """Which work a disagreement belongs to: ``mcap-layout``, ``ros1-index``, ``mcap-index``
    (the index and the records disagree; ertools answered from the index) or ``fuzz`` (none:
    a reader bug to fix here)."""
    if name == "mcap-lz4-nomsgindex":
        return "mcap-layout"
    details = " ".join(d for v, d in parts.values() if v == "disagree")
    if "KeyError" in details and "official failed" in details and "', 0" not in details:
        # the official reader fails on a channel whose schema id is not in the summary
        return "mcap-layout"
    if name.startswith("ros1") and "official failed (AssertionError" in details:
        # rosbags asserts that each record's time is its index entry's; ertools does not yet
        return "ros1-index"
    from fuzz.mutate import layout
    from fuzz.seeds import seed_bytes

    what = mutant.what
    sites = [what.split(" field ", 1)[1].split(" at ")[0]] if " field " in what else []
    if what.startswith("random bytes"):  # the fields the changed bytes fell in
        lay = layout(seed_bytes(name))
        for at, _new in mutant.edits:
            sites += [x.name for x in lay.sites if x.offset <= at < x.offset + x.length]
    if name.startswith("ros1") and any(x.startswith(ROS1_INDEX_FIELDS) for x in sites):
        return "ros1-index"
    if name.startswith("mcap") and any(x.startswith(MCAP_INDEX_FIELDS) for x in sites):
        return "mcap-index"
    # ertools gave exactly the undamaged file's answer where it disagrees: it read the file
    # through its index, while the official reader lost records to the damage
    same_as_truth = all(
        v != "disagree"
        or (not isinstance(ert[p], str) and ert[p].ok and _equal(p, ert[p].value, truth[p]))
        for p, (v, _d) in parts.items()
    )
    # or the official reader lost records on the way (a linear read stops at a damaged
    # record) that ertools read through the index: its answer holds all the official one
    off_within = all(
        v != "disagree" or _official_within(p, ert[p], off_answers[p])
        for p, (v, _d) in parts.items()
    )
    if same_as_truth or off_within:
        return f"{name.split('-', maxsplit=1)[0]}-index"
    return "fuzz"


def _official_within(part: str, ert: Any, off: Any) -> bool:
    from fuzz.judge import _rows_within, _summary_within

    if isinstance(ert, str) or not ert.ok or not off.ok:
        return False
    if part == "summary":
        return set(off.value) == set(ert.value) and _summary_within(off.value, ert.value)
    return len(off.value[0]) < len(ert.value[0]) and _rows_within(off.value, ert.value)


def _equal(part: str, value: Any, truth: Any) -> bool:
    from fuzz.judge import _same_rows

    if not truth.ok:
        return False
    return bool(value == truth.value) if part == "summary" else _same_rows(value, truth.value)


_TRUTH: dict[str, Any] = {}


def _truth(name: str, workdir: Path) -> Any:
    """The official answer on the undamaged seed file (what a partial read must stay within)."""
    from fuzz.judge import official_answer
    from fuzz.seeds import seed_bytes

    if name not in _TRUTH:
        path = workdir / f"seed{suffix(name)}"
        path.write_bytes(seed_bytes(name))
        _TRUTH[name] = official_answer(path)
        path.unlink()
    return _TRUTH[name]


def worker() -> None:
    """Read case indices on stdin, answer one JSON line each on stdout."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
    logging.disable(logging.CRITICAL)  # readers warn about damage; the verdict is what counts
    out = sys.stdout
    sys.stdout = sys.stderr  # stray prints must not break the protocol
    with tempfile.TemporaryDirectory(prefix="ertools-fuzz-") as tmp:
        for line in sys.stdin:
            seed, index = map(int, line.split())
            if os.environ.get("ERTOOLS_FUZZ_STALL") == str(index):
                time.sleep(3600)  # the watchdog's own test: this case hangs
            try:
                rec = run_case(seed, index, Path(tmp))
            except Exception as err:  # the harness itself failed: report, do not hide
                rec = {"index": index, "verdict": "traceback", "harness": repr(err)}
            out.write(json.dumps(rec) + "\n")
            out.flush()


@dataclass
class Worker:
    proc: subprocess.Popen[str]
    index: int | None = None
    started: float = 0.0
    warm: bool = False  # past its first case (whose start-up imports get extra time)


def _spawn() -> Worker:
    proc = subprocess.Popen(
        [sys.executable, str(Path(__file__).resolve()), "--worker"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        bufsize=1,
    )
    return Worker(proc)


def run_cases(
    seed: int, indices: list[int], jobs: int = 2, timeout: float = 20.0, progress: bool = False
) -> list[dict[str, Any]]:
    """Verdict records of the given cases, run in ``jobs`` watched worker processes."""
    todo = list(reversed(indices))
    results: list[dict[str, Any]] = []
    workers = [_spawn() for _ in range(max(1, min(jobs, len(indices))))]
    start_up = 60.0  # the first case of a worker also imports rosbags, mcap, NumPy
    try:
        while todo or any(w.index is not None for w in workers):
            for w in workers:
                if w.index is None and todo:
                    w.index = todo.pop()
                    w.started = time.monotonic()
                    assert w.proc.stdin is not None
                    w.proc.stdin.write(f"{seed} {w.index}\n")
                    w.proc.stdin.flush()
            busy = [w for w in workers if w.index is not None]
            ready, _, _ = select.select([w.proc.stdout for w in busy], [], [], 0.5)
            now = time.monotonic()
            for i, w in enumerate(workers):
                if w.index is None:
                    continue
                assert w.proc.stdout is not None
                if w.proc.stdout in ready:
                    line = w.proc.stdout.readline()
                    if line:
                        results.append(json.loads(line))
                        w.index = None
                        w.warm = True
                        if progress and len(results) % 500 == 0:
                            print(f"fuzz: {len(results)} cases done", file=sys.stderr)
                        continue
                    # the worker died (a crash in C code, or killed by the memory limit)
                    results.append(
                        {"index": w.index, "verdict": "traceback", "harness": "worker died"}
                    )
                elif now - w.started < timeout + (0 if w.warm else start_up):
                    continue
                else:
                    results.append(
                        {
                            "index": w.index,
                            "verdict": "hang",
                            "harness": f"no verdict in {timeout} s",
                        }
                    )
                w.proc.kill()
                w.proc.wait()
                workers[i] = _spawn()
    finally:
        for w in workers:
            w.proc.kill()
            w.proc.wait()
    return sorted(results, key=lambda r: r["index"])


def summary_line(results: list[dict[str, Any]], seed: int) -> str:
    c = Counter(r["verdict"] for r in results)
    return (
        f"fuzz: {len(results)} cases, {c['agree'] + c['salvaged']} agreements "
        f"({c['salvaged']} partial reads of files the official reader refuses), "
        f"{c['refused']} clear refusals, {c['misread']} official misreads (damaged bytes the "
        f"official reader took as sound, ertools the undamaged answer), "
        f"{c['disagree']} disagreements, "
        f"{c['traceback']} tracebacks, {c['hang']} hangs (seed {seed})"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds per case before a hang")
    ap.add_argument("--case", type=int, help="run this one case in this process and show it")
    ap.add_argument("--keep", type=Path, help="with --case: write the mutant here")
    ap.add_argument("--json", type=Path, help="write every case's verdict record here")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker()
        return 0
    if args.case is not None:
        with tempfile.TemporaryDirectory(prefix="ertools-fuzz-") as tmp:
            rec = run_case(args.seed, args.case, Path(tmp), args.keep)
        print(json.dumps(rec, indent=2))
        return 0 if rec["verdict"] in ("agree", "salvaged", "refused", "misread") else 1
    print(f"fuzz: {args.cases} cases, seed {args.seed}, {args.jobs} workers", file=sys.stderr)
    t0 = time.monotonic()
    results = run_cases(args.seed, list(range(args.cases)), args.jobs, args.timeout, True)
    bad = [r for r in results if r["verdict"] in ("disagree", "traceback", "hang")]
    for r in bad:
        print(json.dumps(r), file=sys.stderr)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    owners = Counter(r.get("owner", "") for r in results if r["verdict"] == "disagree")
    if owners:
        print(f"fuzz: disagreements by owner: {dict(owners)}", file=sys.stderr)
    by_seed = Counter((r.get("seed_file", "?"), r["verdict"]) for r in results)
    for name in SEED_NAMES:
        row = ", ".join(
            f"{v} {by_seed[(name, v)]}"
            for v in ("agree", "salvaged", "refused", "misread", "disagree", "traceback")
            if by_seed[(name, v)]
        )
        print(f"  {name}: {row}", file=sys.stderr)
    print(
        f"fuzz: {time.monotonic() - t0:.0f} s; reproduce a case: "
        f"python fuzz/run.py --seed {args.seed} --case K",
        file=sys.stderr,
    )
    print(summary_line(results, args.seed))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
