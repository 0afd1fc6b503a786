"""The real 2015 bag (an FBM2@Home log) given to the FBM1 scorer: one clear line, exit 1."""

from __future__ import annotations

from pathlib import Path

import pytest

from ertools.cli.main import main
from tests.benchmarks.fbm1.fbm1_testkit import write_items
from tests.helpers.stderr_text import joined_lines

REAL = Path(__file__).resolve().parents[3] / ".." / "shared" / "real_bags"
BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"


@pytest.mark.real
def test_fbm2h_log_is_not_an_fbm1_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    if not BAG.exists():
        pytest.skip("../shared/real_bags not present")
    items = write_items(tmp_path / "items.yaml")
    code = main(["score", "fbm1h", str(BAG), "--items", str(items)])
    out, err = capsys.readouterr()
    assert code == 1 and out == ""  # another benchmark's log: unusable data (docs/cli.md)
    assert joined_lines(err) == [  # one message, wrapped where a long path makes it long
        f"ertools: error: {BAG}: this looks like an FBM2@Home log (topics /fbm2h/...): "
        "ertools score fbm2h"
    ]
