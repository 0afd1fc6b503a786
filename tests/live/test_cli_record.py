"""`ertools record` from the command line: the --simulate demo, usage and config errors."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from ertools.cli.main import main
from ertools.live.tail import is_finished, read_complete
from tests.helpers.stderr_text import error_messages

pytestmark = pytest.mark.xdist_group("timing")


@pytest.mark.slow
def test_simulate_demo_records_and_summarises(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["record", "--simulate", "--out-dir", str(tmp_path), "--duration", "1.5",
         "--health", "0.5", "--namespace", "/fbm2h"]
    )  # fmt: skip
    captured = capsys.readouterr()
    assert code == 0, captured.err
    summary = yaml.safe_load(captured.out)
    (path,) = (Path(p) for p in summary["files"])
    assert path.parent == tmp_path and path.name.startswith("log_fbm2h_mocap_")
    assert is_finished(path)
    # 120 Hz for 1.5 s is at most 180 frames; the sender starts after the recorder, and a
    # loaded machine may lose a few tenths of a second: at least half must be there.
    assert 90 <= summary["frames"] <= 181
    assert summary["natnet_version"] == "4.1" and summary["dropped"] == 0
    messages = read_complete(path).messages
    for name in ("robot_at_home", "origin", "ref_board"):
        written = summary["bodies"][name]["written"]
        assert written > 0
        assert sum(m.topic == f"/fbm2h/{name}/pose" for m in messages) == written
    assert "record: health: " in captured.err


def test_usage_and_config_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["record", "--out-dir", str(tmp_path)]) == 2
    assert "--config is required" in capsys.readouterr().err
    bad = tmp_path / "bad.yaml"
    bad.write_text("rigid_bodies:\n'3':\n  pose: robot_at_home/pose\n")
    assert main(["record", "--config", str(bad), "--out-dir", str(tmp_path)]) == 1
    err = error_messages(capsys.readouterr().err)
    assert len(err) == 1 and "indent them under rigid_bodies" in err[0]
    good = Path(__file__).resolve().parents[2] / "configs" / "mocap_home.yaml"
    code = main(
        ["record", "--config", str(good), "--out-dir", str(tmp_path), "--natnet-version", "x"]
    )
    assert code == 2 and "MAJOR.MINOR" in capsys.readouterr().err
    code = main(["record", "--config", str(good), "--out-dir", str(tmp_path), "--split", "0"])
    assert code == 2 and "must be > 0" in capsys.readouterr().err  # a usage error, at parse time
    assert not list(tmp_path.glob("*.mcap"))  # nothing written on a refused command line
