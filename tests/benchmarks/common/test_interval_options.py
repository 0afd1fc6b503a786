"""The interval options given nonsense (issue 28): ``--confidence``, ``--draws`` and ``--seed``
outside what they can mean are one ``ertools: error:`` line and exit 2 on every ``score``
command; a huge ``--draws`` is refused above its documented cap rather
than run for days with gigabytes of draws."""

from __future__ import annotations

from pathlib import Path

import pytest

import ertools
from ertools.benchmarks import registry
from ertools.benchmarks.common.inputs import MAX_DRAWS, MAX_SEED
from ertools.cli.main import main
from ertools.errors import UsageError
from tests.helpers.bagmaker import Spec, write
from tests.helpers.stderr_text import error_messages

ROOT = Path(__file__).resolve().parents[3]

SAMPLES = ROOT / "sample_bags"
FBM1 = [SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag", "--items"]
LOGS = {
    "fbm1h": [*FBM1, SAMPLES / "fbm1h" / "fbm1h.yaml"],
    "fbm1w": ["FBM1W_LOG", "--items", ROOT / "configs" / "fbm1w.yaml"],
    "fbm2h": [SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"],
    "fbm3w": [SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"],
    "trajectory": [SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag", SAMPLES / "robotlog"],
    "hnf": [SAMPLES / "hnf" / "rsbb_logs" / "HNF" / "simbot" / "run_1_2019-04-10-14-31-06.bag"],
    "hpff": [SAMPLES / "hpff" / "rsbb_logs" / "HPFF" / "simbot" / "run_1_2019-04-10-15-22-11.bag"],
    "hopf": [SAMPLES / "hopf" / "rsbb_logs" / "HOPF" / "simbot" / "run_1_2019-04-11-16-26-40.bag"],
    "hppf": [SAMPLES / "hppf" / "rsbb_logs" / "HPPF" / "simbot" / "run_1_2019-04-11-17-26-40.bag"],
}
# An RSBB benchmark refuses the values before it reads anything: any run bag will do.
RSBB_RUN = [SAMPLES / "hgmf" / "rsbb_logs" / "HGMF" / "simbot" / "run_1_2019-04-12-10-00-00.bag"]
# The benchmarks with intervals (the referee-scored ones have none: nothing is measured).
WITH_INTERVALS = [
    n for n in registry.names() if any(i.name == "confidence" for i in registry.get(n).inputs)
]
# option, value -> what the one line must say
NONSENSE = [
    ("--confidence", "0", "--confidence must be positive"),
    ("--confidence", "-0.5", "--confidence must be positive"),
    ("--confidence", "1", "--confidence must be < 1, got 1.0"),
    ("--confidence", "1.5", "--confidence must be < 1, got 1.5"),
    ("--confidence", "95", "--confidence must be < 1, got 95.0"),
    ("--confidence", "nan", "--confidence nan: give a finite number"),
    ("--draws", "-1", "--draws must be >= 0, got -1"),
    ("--draws", "1e3", "argument --draws: invalid int value: '1e3'"),
    ("--draws", str(10**9), f"--draws {10**9}: at most {MAX_DRAWS}"),
    ("--draws", str(MAX_DRAWS + 1), f"--draws {MAX_DRAWS + 1}: at most {MAX_DRAWS}"),
    ("--seed", "abc", "argument --seed: invalid int value: 'abc'"),
    ("--seed", "-1", "--seed must be >= 0, got -1"),
    # a whole number however long: refused for its size, not called fractional
    ("--seed", "9" * 23, f"--seed {'9' * 23}: at most {MAX_SEED}"),
]


def _fbm1w_log(tmp_path: Path) -> Path:
    """A small log with FBM1@Work's topics (the samples have none)."""
    spec = Spec()
    pose = spec.conn("/fbm1w/origin/pose", "geometry_msgs/PoseStamped")
    state = spec.conn("/fbm1w/bmbox_state", "rockin_scoring/BmBoxState")
    for i in range(5):
        t = 1_448_020_800_000_000_000 + i * 100_000_000
        spec.add(pose, t, stamp=t, frame="world", xyz=(0.0, 0.0, 0.0), q=(0.0, 0.0, 0.0, 1.0))
        spec.add(state, t, state=0, payload="")
    return write(tmp_path / "log_fbm1w.bag", "ros1", spec)


@pytest.mark.parametrize(("option", "value", "says"), NONSENSE, ids=lambda v: str(v)[:12])
@pytest.mark.parametrize("name", WITH_INTERVALS)
def test_nonsense_is_one_line_and_exit_2(
    name: str,
    option: str,
    value: str,
    says: str,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    args = [_fbm1w_log(tmp_path) if a == "FBM1W_LOG" else a for a in LOGS.get(name, RSBB_RUN)]
    assert main(["score", name, *map(str, args), option, value]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    (line,) = error_messages(err)
    assert line.startswith("ertools: error: ") and says in line, line
    assert line in err.splitlines(), err  # one line as printed, not joined from several


def test_the_cap_is_in_the_help(capsys: pytest.CaptureFixture[str]) -> None:
    for name in WITH_INTERVALS:
        assert main(["score", name, "--help"]) == 0
        assert f"at most {MAX_DRAWS}" in " ".join(capsys.readouterr().out.split())


@pytest.mark.slow
def test_the_largest_seed_is_taken() -> None:
    """The cap is the int64 a result carries: the largest seed scores (and the Python API
    refuses the next one as the CLI does)."""

    result = ertools.score("fbm3w", LOGS["fbm3w"], seed=MAX_SEED, draws=20)
    assert result.to_dict()["uncertainty"]["seed"] == MAX_SEED
    with pytest.raises(UsageError, match=f"at most {MAX_DRAWS}"):
        ertools.score("fbm3w", LOGS["fbm3w"], draws=MAX_DRAWS + 1)
