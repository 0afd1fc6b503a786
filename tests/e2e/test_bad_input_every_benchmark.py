"""End to end: every registered benchmark's sample, spoiled the ways a referee spoils it.

For each benchmark of the registry: its sample log cut in half (in a copy of its sample
folder, where its side files are found), another benchmark's log, a text file named ``.bag``,
and, where the benchmark needs a side file it cannot do without, the log alone in a folder.
docs/cli.md (Exit status) says what each must give: one ``ertools: error:`` line on stderr,
exit 1 (the data is unusable; the command line is fine), no traceback. The other stderr lines
allowed are ertools' own notes (``found in the RSBB layout``...).
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import pytest

from ertools.benchmarks import registry
from ertools.cli.main import main

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"
UNUSABLE = 1  # docs/cli.md: "1 unusable data or config (a bag, a YAML file)"


@dataclass(frozen=True)
class Sample:
    """A benchmark's sample: its folder under sample_bags/, its log in it, the extra
    arguments (paths relative to the folder: a copy's are its own)."""

    folder: str
    log: str
    extra: tuple[str, ...] = ()


_FBM1H = Sample("fbm1h", "log_fbm1h_2015-11-20-12-00-00_0.bag", ("--items", "fbm1h.yaml"))
SAMPLE = {
    "fbm1h": _FBM1H,
    "fbm1w": _FBM1H,  # the fbm1 package's one sample (registry.scenarios): FBM1@Home's
    "fbm2h": Sample("fbm2h", "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
    "fbm3w": Sample("fbm3w", "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"),
    "trajectory": Sample("robotlog", "FBM2H_201511201200_homer.bag", (".",)),
    "noise": Sample("stationary", "log_fbm3w_noise_2015-11-20-09-00-00_0.bag"),
    "hnf": Sample("hnf", "rsbb_logs/HNF/simbot/run_1_2019-04-10-14-31-06.bag"),
    "hpff": Sample("hpff", "rsbb_logs/HPFF/simbot/run_1_2019-04-10-15-22-11.bag"),
    "hopf": Sample("hopf", "rsbb_logs/HOPF/simbot/run_1_2019-04-11-16-26-40.bag"),
    "hppf": Sample("hppf", "rsbb_logs/HPPF/simbot/run_1_2019-04-11-17-26-40.bag"),
    "hgmf": Sample("hgmf", "rsbb_logs/HGMF/simbot/run_1_2019-04-12-10-00-00.bag"),
    "hgtkmh": Sample("season2019", "rsbb_logs/HGTKMH/simbot/run_1_2019-04-13-12-00-00.bag"),
    "hwv": Sample("season2019", "rsbb_logs/HWV/simbot/run_1_2019-04-13-13-00-00.bag"),
    "hcfgac": Sample("season2019", "rsbb_logs/HCFGAC/simbot/run_1_2019-04-13-14-00-00.bag"),
    "stb": Sample("season2019", "rsbb_logs/STB/simbot/run_1_2019-04-13-15-00-00.bag"),
}
# Another benchmark's log for each, and the command the message must point to (None: the
# benchmark cannot tell whose log it is, it says what it lacks).
WRONG: dict[str, tuple[str, str | None]] = {
    "fbm1h": ("fbm2h", "ertools score fbm2h"),
    "fbm1w": ("fbm3w", "ertools score fbm3w"),
    "fbm2h": ("fbm3w", "ertools score fbm3w"),
    "fbm3w": ("fbm1h", "ertools score fbm1h"),
    "trajectory": ("hnf", None),
    "noise": ("fbm1h", None),
    "hnf": ("hpff", "ertools score hpff"),
    "hpff": ("hnf", "ertools score hnf"),
    "hopf": ("hnf", "ertools score hnf"),
    "hppf": ("hopf", "ertools score hopf"),
    "hgmf": ("hpff", "ertools score hpff"),
    "hgtkmh": ("hwv", "ertools score hwv"),
    "hwv": ("stb", "ertools score stb"),
    "hcfgac": ("hgmf", "ertools score hgmf"),
    "stb": ("hcfgac", "ertools score hcfgac"),
}
# The side file a benchmark cannot score without, and the option the message must name.
NEEDED = {"hnf": "--transform", "hpff": "--transform", "hopf": "--items", "hgmf": "--config"}


def test_every_registered_benchmark_has_a_case() -> None:
    assert set(SAMPLE) == set(WRONG) == set(registry.names())


def _copy(sample: Sample, tmp_path: Path) -> Path:
    """A copy of the sample's folder (its side files found in it as in the original)."""
    out = tmp_path / sample.folder
    shutil.copytree(SAMPLES / sample.folder, out)
    return out


def _args(sample: Sample, folder: Path) -> list[str]:
    return [a if a.startswith("-") else str(folder / a) for a in sample.extra]


def _one_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``argv``; the one ``ertools: error:`` line, after checking the exit status, that
    nothing else on stderr is a foreign line (a wrapped detail, a traceback)."""
    capsys.readouterr()
    code = main(argv)
    err = capsys.readouterr().err
    lines = err.splitlines()
    errors = [ln for ln in lines if ln.startswith("ertools: error:")]
    assert len(errors) == 1, err
    assert all(ln.startswith("ertools: ") for ln in lines), err
    assert "Traceback" not in err and "unexpected" not in errors[0], err
    assert code == UNUSABLE, err
    return errors[0]


@pytest.mark.parametrize("name", list(SAMPLE))
def test_a_truncated_log(name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sample = SAMPLE[name]
    folder = _copy(sample, tmp_path)
    log = folder / sample.log
    data = log.read_bytes()
    log.write_bytes(data[: len(data) // 2])
    line = _one_error(["score", name, str(log), *_args(sample, folder)], capsys)
    assert str(log) in line and "truncated" in line, line


@pytest.mark.parametrize("name", list(SAMPLE))
def test_another_benchmarks_log(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    other, hint = WRONG[name]
    log = SAMPLES / SAMPLE[other].folder / SAMPLE[other].log
    extra = _args(SAMPLE[name], SAMPLES / SAMPLE[name].folder)
    line = _one_error(["score", name, str(log), *extra], capsys)
    assert hint is None or line.endswith(hint) or hint in line, line
    # out of its folder, the RSBB run is told by its live score (or its lack of what is asked)
    alone = tmp_path / f"{other}.bag"
    shutil.copyfile(log, alone)
    line = _one_error(["score", name, str(alone), *extra], capsys)
    assert str(alone) in line or (hint is not None and hint in line), line


@pytest.mark.parametrize("name", list(SAMPLE))
def test_a_text_file_is_said_to_be_no_bag(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = tmp_path / "notes.bag"
    text.write_text("the referee's notes, saved under the wrong name\n", encoding="utf-8")
    extra = _args(SAMPLE[name], SAMPLES / SAMPLE[name].folder)
    line = _one_error(["score", name, str(text), *extra], capsys)
    # before any side file is looked for (hgmf asked for HGMF.yaml first); trajectory also
    # reads a text trajectory, and says the file is neither
    assert line.startswith(f"ertools: error: {text}: not a ROS1 bag") or (
        name == "trajectory" and line.startswith(f"ertools: error: {text}: not a bag, and")
    ), line


@pytest.mark.parametrize("name", list(NEEDED))
def test_a_side_file_nowhere(name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sample = SAMPLE[name]
    log = tmp_path / Path(sample.log).name
    shutil.copyfile(SAMPLES / sample.folder / sample.log, log)  # no layout, no result file
    line = _one_error(["score", name, str(log)], capsys)
    assert f"give {NEEDED[name]}" in line, line
