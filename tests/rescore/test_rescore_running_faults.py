"""`ertools rescore` when the files move under it (issue 36, "Faults while running"): a verdict
of the moment (a file missing for a moment, unreadable, a disk full) is never cached, and a file
replaced while it is scored never puts its new hash beside the old bytes' score.

The moments are chosen deterministically: the scoring is wrapped (``pipeline.run_jobs``) so that
a file is moved away just before its execution is scored and put back after, or a toy log
(tests/rescore/rescore_toy.py) does it to itself while it is read.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.main import main
from ertools.competition import pipeline
from ertools.competition.jobs import Job, run_job
from ertools.competition.memo import FileMemo
from ertools.errors import BagError, ConfigError, transient_error, watching
from ertools.io.formats import detect_format
from tests.rescore.rescore_competition import OFFSETS, SCALE, make_competition, use_toy_registry

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags" / "fbm3w"
FBM3W_BAG = SAMPLES / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def rescore(manifest: Path, out: Path, *extra: str) -> tuple[int, dict[str, Any], str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(
            ["rescore", "-q", "--config", str(manifest), "--out", str(out), "--jobs", "1", *extra]
        )
    doc: dict[str, Any] = json.loads((out / "results.json").read_text())
    return code, doc, err.getvalue()


@pytest.fixture
def fbm3w_day(tmp_path: Path) -> tuple[Path, Path]:
    """The sample FBM3@Work log copied, and a manifest listing it: (manifest, bag)."""
    day = tmp_path / "day"
    day.mkdir()
    bag = day / FBM3W_BAG.name
    shutil.copyfile(FBM3W_BAG, bag)
    shutil.copyfile(SAMPLES / "fbm3w.yaml", day / "fbm3w.yaml")
    manifest = day / "competition.yaml"
    manifest.write_text(
        "benchmarks:\n  fbm3w:\n    inputs: {config: fbm3w.yaml}\n"
        f"executions:\n  - {{benchmark: fbm3w, team: robotto, bags: [{bag.name}]}}\n"
    )
    return manifest, bag


def expected_fbm3w() -> tuple[float, float, int]:
    """The sample's truth (generated with it, not computed by ertools): best distance error,
    its tolerance, best run."""
    answers = yaml.safe_load(FBM3W_BAG.with_suffix(".answers.yaml").read_text())
    want = answers["expected"]
    return (
        float(want["best_distance_error"]),
        float(answers["tolerance"]["distance_error"]["abs"]),
        int(want["best_run"]),
    )


@contextlib.contextmanager
def around_scoring(monkeypatch: pytest.MonkeyPatch, before: Any, after: Any) -> Iterator[None]:
    """``before()`` once the executions are keyed, just before they are scored; ``after()``
    once scored, before the results are written."""
    real = pipeline.run_jobs

    def wrapped(*args: Any, **kwargs: Any) -> None:
        before()
        try:
            real(*args, **kwargs)
        finally:
            after()

    with monkeypatch.context() as m:
        m.setattr(pipeline, "run_jobs", wrapped)
        yield


# --- finding 1: a file missing for a moment -------------------------------------------------


@pytest.mark.slow
def test_a_log_missing_for_a_moment_is_not_cached(
    fbm3w_day: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The GT bag moved away while the day is scored and put back byte for byte (a USB key
    re-plugged): that run says so, and the next one, warm, scores it (it was not cached)."""
    manifest, bag = fbm3w_day
    away = bag.with_name("away.bag")
    out = tmp_path / "out"
    with around_scoring(monkeypatch, lambda: bag.rename(away), lambda: away.rename(bag)):
        code, doc, _ = rescore(manifest, out, "--no-reports")
    (row,) = doc["executions"]
    assert code == 1 and row["status"] == "unscoreable"
    assert "no such file" in row["reason"]
    code, doc, _ = rescore(manifest, out, "--no-reports")
    (row,) = doc["executions"]
    assert code == 0 and row["status"] == "scored" and not row["cached"], row["reason"]
    best, tolerance, best_run = expected_fbm3w()
    assert row["score"]["best_run"] == best_run
    assert abs(row["score"]["best_distance_error"] - best) <= tolerance
    code, doc, _ = rescore(manifest, out, "--no-reports")
    assert doc["executions"][0]["cached"] and doc["executions"][0]["status"] == "scored"


def test_a_missing_file_is_a_transient_error(tmp_path: Path) -> None:
    """Classified where it is raised: a missing file, and every ertools error made while an
    operating-system error is handled; a verdict on the bytes is not."""
    with pytest.raises(BagError) as missing:
        detect_format(tmp_path / "gone.bag")
    assert transient_error(missing.value)
    (tmp_path / "text.bag").write_text("hello\n")
    with pytest.raises(BagError) as not_a_bag:
        detect_format(tmp_path / "text.bag")
    assert not transient_error(not_a_bag.value)
    try:
        open(tmp_path / "none", "rb")  # noqa: SIM115 - the error, not the file, is wanted
    except OSError:
        # as `raise ConfigError(...) from None` and a plain raise inside the handler do
        made = ConfigError("cannot read it")
    assert made.transient
    bz2_damage = OSError("Invalid data stream")  # bz2's verdict on bytes: no errno
    try:
        raise bz2_damage
    except OSError:
        assert not BagError("corrupt bz2 chunk").transient


@pytest.mark.slow
def test_a_problem_of_the_moment_met_and_handled_is_not_cached(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A scorer that skips a file it could not find at that moment still scores: its row says
    so, and it is scored again by the next run (the same bytes may give another score)."""
    use_toy_registry(monkeypatch)
    comp = make_competition(
        tmp_path / "comp",
        extra={"toy-alpha-20151120T120000": ("alpha", "2015-11-20T12:00:00Z", "3\nmoment\n5\n")},
    )
    out = tmp_path / "out"
    _, doc, _ = rescore(comp.manifest, out, "--no-reports")
    rows = {r["id"]: r for r in doc["executions"]}
    row = rows["toy-alpha-20151120T120000"]
    assert row["status"] == "scored"
    assert row["score"]["toy"]["value"] == pytest.approx((3 + 5) / 2 * SCALE + OFFSETS["alpha"])
    assert any("not kept in the cache" in w for w in row["warnings"])
    _, doc, _ = rescore(comp.manifest, out, "--no-reports")
    cached = {r["id"]: r["cached"] for r in doc["executions"]}
    assert not cached["toy-alpha-20151120T120000"]
    assert sum(cached.values()) == len(cached) - 1  # the others came from the cache


def test_an_unwritable_report_folder_is_not_cached(tmp_path: Path) -> None:
    """A problem of the machine (the report folder cannot be made) is the outcome's, marked."""
    log = tmp_path / "log.txt"
    log.write_text("1\n2\n")
    blocker = tmp_path / "file"
    blocker.write_text("")
    job = Job(
        "toy-1",
        "toy",
        "tests.rescore.rescore_toy:TOY",
        None,
        (str(log),),
        report_dir=str(blocker / "report"),
    )
    outcome = run_job(job)
    assert outcome.status == "unscoreable" and outcome.machine, outcome


def test_the_memo_keeps_no_fact_learnt_at_a_bad_moment(tmp_path: Path) -> None:
    """Discovery's memo (cache/files.json) does not remember what was computed while a
    transient error was met, nor a fact of a file that changed while it was read."""
    log = tmp_path / "log.bag"
    log.write_bytes(b"x" * 10)
    memo = FileMemo(tmp_path / "files.json")

    def flaky() -> str:
        with contextlib.suppress(BagError):
            detect_format(tmp_path / "gone.bag")
        return "team-of-the-moment"

    assert memo.get(log, "team:fbm2h", flaky) == "team-of-the-moment"
    assert memo.get(log, "team:fbm2h", lambda: "homer") == "homer"
    assert memo.get(log, "team:fbm2h", lambda: "other") == "homer"  # remembered since

    def rewrites() -> str:
        log.write_bytes(b"y" * 20)
        return "old"

    assert memo.get(log, "clock", rewrites) == "old"
    assert memo.get(log, "clock", lambda: "new") == "new"


def test_watching_sees_errors_handled_inside() -> None:
    with watching() as met:
        with contextlib.suppress(BagError):
            detect_format("/nonexistent/ertools/x.bag")
        with contextlib.suppress(BagError):
            raise BagError("a verdict on bytes")
    assert len(met) == 1 and "no such file" in str(met[0])


# --- finding 2: a file replaced while it is scored ------------------------------------------


@pytest.mark.slow
def test_a_log_replaced_after_it_was_scored_keeps_the_scored_hash(
    fbm3w_day: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bag replaced by other bytes once scored, before the results are written: the
    results put the scored bytes' hash beside their score, not the new file's; the next run
    scores the new file."""
    manifest, bag = fbm3w_day
    scored_sha = sha256(bag)
    other = tmp_path / "other.bag"
    other.write_bytes(bag.read_bytes() + b"\0" * 64)  # other bytes, still a bag's head
    out = tmp_path / "out"
    with around_scoring(monkeypatch, lambda: None, lambda: other.replace(bag)):
        code, doc, _ = rescore(manifest, out, "--no-reports")
    (row,) = doc["executions"]
    assert code == 0 and row["status"] == "scored"
    recorded = {i["path"]: i["sha256"] for i in doc["inputs"]}
    assert recorded[str(bag)] == scored_sha != sha256(bag)
    _, doc, _ = rescore(manifest, out, "--no-reports")
    assert not doc["executions"][0]["cached"]
    assert {i["path"]: i["sha256"] for i in doc["inputs"]}[str(bag)] == sha256(bag)


def test_a_log_replaced_while_it_is_read_is_no_score(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A toy log replaced by another file in the middle of its reading: no score from the
    mix, nothing cached; the next run scores the new file."""
    use_toy_registry(monkeypatch)
    ident = "toy-beta-20151120T120000"
    comp = make_competition(
        tmp_path / "comp", extra={ident: ("beta", "2015-11-20T12:00:00Z", "1\nreplace\n")}
    )
    out = tmp_path / "out"
    _, doc, _ = rescore(comp.manifest, out, "--no-reports")
    row = {r["id"]: r for r in doc["executions"]}[ident]
    assert row["status"] == "failed" and "changed or went while it was scored" in row["reason"]
    _, doc, _ = rescore(comp.manifest, out, "--no-reports")
    row = {r["id"]: r for r in doc["executions"]}[ident]
    assert row["status"] == "scored" and not row["cached"]
    assert row["score"]["toy"]["value"] == pytest.approx(100 * SCALE + OFFSETS["beta"])


# --- finding 9: one execution listed many times ---------------------------------------------

ALIASED = """\
version: 1
benchmarks:
  toy:
    inputs: {{scale: 2.0}}
    teams:
      alpha: {{transform: configs/transform-alpha.yaml}}
executions:
  - &one {{benchmark: toy, team: alpha, bags: [logs/a.txt], start: 2015-11-20T09:00:00Z}}
{copies}  - {{benchmark: toy, team: alpha, bags: [logs/b.txt], start: 2015-11-20T10:00:00Z}}
  - {{benchmark: toy, team: alpha, bags: [logs/../logs/a.txt], start: 2015-11-20T09:00:00Z}}
"""


def aliased_day(root: Path, copies: int) -> Path:
    """One execution listed ``copies`` more times as YAML aliases, once more as a copy (its
    path spelt another way), and a different one."""
    (root / "logs").mkdir(parents=True)
    (root / "configs").mkdir()
    (root / "configs" / "transform-alpha.yaml").write_text("offset: 0.25\n")
    (root / "logs" / "a.txt").write_text("1\n2\n")
    (root / "logs" / "b.txt").write_text("4\n")
    manifest = root / "competition.yaml"
    manifest.write_text(ALIASED.format(copies="  - *one\n" * copies))
    return manifest


def test_check_names_an_execution_listed_twice(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    use_toy_registry(monkeypatch)
    manifest = aliased_day(tmp_path, copies=3)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["rescore", "--check", "--config", str(manifest)])
    lines = err.getvalue().splitlines()
    assert code == 0
    # the three aliases (executions[1..3]) and the copy (executions[5]); not the other one
    assert lines[0] == (
        f"ertools: warning: {manifest}: executions[1], executions[2], executions[3], "
        "executions[5]: the same execution as executions[0] (listed 4 more times: same "
        "benchmark, team, logs, time and inputs); scored once"
    )
    assert "2 listed executions" in lines[-1] and len(lines) == 2


@pytest.mark.slow
def test_an_execution_listed_many_times_is_scored_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """1,000 aliases of one execution: one job, one row, and a problem naming the copies."""
    use_toy_registry(monkeypatch)
    manifest = aliased_day(tmp_path, copies=1000)
    scored: list[str] = []
    real = pipeline.run_jobs

    def counting(jobs: Any, **kwargs: Any) -> None:
        scored.extend(job.id for job in jobs)
        real(jobs, **kwargs)

    monkeypatch.setattr(pipeline, "run_jobs", counting)
    code, doc, err = rescore(manifest, tmp_path / "out", "--no-reports")
    assert code == 0
    assert len(scored) == 2 == len(doc["executions"])
    values = sorted(r["score"]["toy"]["value"] for r in doc["executions"])
    assert values == pytest.approx([1.5 * SCALE + 0.25, 4 * SCALE + 0.25])
    dupes = [p for p in doc["problems"] if p["kind"] == "duplicate-execution"]
    assert len(dupes) == 1 and "1001 more times" in dupes[0]["message"]
    assert "the same execution as executions[0]" in err


def test_the_same_bytes_listed_twice_are_scored_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two listed executions whose logs are byte-identical copies (same team, inputs, time):
    one cache key, scored once; both rows scored, the second saying whose score it shares."""
    use_toy_registry(monkeypatch)
    manifest = aliased_day(tmp_path, copies=0)
    shutil.copyfile(tmp_path / "logs" / "a.txt", tmp_path / "logs" / "copy.txt")
    text = manifest.read_text().replace("logs/../logs/a.txt", "logs/copy.txt")
    manifest.write_text(text)
    scored: list[str] = []
    real = pipeline.run_jobs

    def counting(jobs: Any, **kwargs: Any) -> None:
        scored.extend(job.id for job in jobs)
        real(jobs, **kwargs)

    monkeypatch.setattr(pipeline, "run_jobs", counting)
    code, doc, _ = rescore(manifest, tmp_path / "out", "--no-reports")
    assert code == 0 and len(scored) == 2 and len(doc["executions"]) == 3
    rows = [r for r in doc["executions"] if r["bags"][0].endswith(("a.txt", "copy.txt"))]
    assert [r["status"] for r in rows] == ["scored", "scored"]
    assert rows[0]["score"] == rows[1]["score"]
    assert any(f"scored once, as {rows[0]['id']}" in w for w in rows[1]["warnings"])


def test_check_names_one_log_listed_for_two_teams(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    use_toy_registry(monkeypatch)
    manifest = aliased_day(tmp_path, copies=0)
    (tmp_path / "configs" / "transform-beta.yaml").write_text("offset: 1\n")
    text = manifest.read_text().replace(
        "      alpha: {transform: configs/transform-alpha.yaml}\n",
        "      alpha: {transform: configs/transform-alpha.yaml}\n"
        "      beta: {transform: configs/transform-beta.yaml}\n",
    )
    text += "  - {benchmark: toy, team: beta, bags: [logs/a.txt], start: 2015-11-20T09:00:00Z}\n"
    manifest.write_text(text)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert main(["rescore", "--check", "--config", str(manifest)]) == 0
    assert (
        "executions[3]: the logs and time of executions[0] for another team (beta, there "
        "alpha): both are scored; remove the wrong one"
    ) in err.getvalue()
