"""A benchmarking box's state log given alone (the 2015 layout: states in one file, the mocap
logger's poses in its own): the error says to give the mocap files too, not to pick a pose
topic among none."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from stderr_text import joined_lines

from ertools.cli.main import main

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "tests" / "io"))
from io_bagmaker import Spec, write  # noqa: E402

ITEMS = ROOT / "sample_bags" / "fbm1h" / "fbm1h.yaml"


def _state_log(tmp_path: Path, ns: str) -> Path:
    spec = Spec()
    for machine in ("BmBox", "RefBox", "Client"):
        state = spec.conn(f"/{ns}/{machine.lower()}_state", f"rockin_scoring/{machine}State")
        for i in range(5):
            spec.add(state, 1_448_020_800_000_000_000 + i * 100_000_000, state=0, payload="")
    return write(tmp_path / f"log_{ns}_2015-11-20-12-00-00_0.bag", "ros1", spec)


@pytest.mark.parametrize("ns", ["fbm2h", "fbm3w"])
def test_a_state_log_alone_asks_for_the_mocap_files(
    ns: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = _state_log(tmp_path, ns)
    assert main(["score", ns, str(bag)]) == 1
    (message,) = joined_lines(capsys.readouterr().err)
    assert message.startswith(f"ertools: error: {bag}: no ")
    assert "give the mocap logger's files too, as further BAGs" in message
    assert "choose one with" not in message


def test_fbm1_states_without_a_run_say_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """FBM1 finds its runs first: none (the box never left its first state) is one line, not
    an 'unexpected ValueError ... this is a bug'."""
    bag = _state_log(tmp_path, "fbm1h")
    assert main(["score", "fbm1h", str(bag), "--items", str(ITEMS)]) == 1
    (message,) = joined_lines(capsys.readouterr().err)
    assert message == (
        f"ertools: error: {bag}: /fbm1h/bmbox_state: no run found (the benchmarking box sent "
        "no goal in 5 state messages)"
    )
