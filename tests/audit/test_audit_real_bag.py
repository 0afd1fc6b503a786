"""The real 2015 FBM2@Home test log: it has no state topics (README of ../shared/real_bags)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from ertools.cli.main import main
from ertools.report.folder import write_report
from tests.helpers.fakes import FakeResult
from tests.helpers.stderr_text import error_messages

REAL = Path(__file__).resolve().parents[2] / ".." / "shared" / "real_bags"
BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"

pytestmark = pytest.mark.real


@pytest.fixture
def bag() -> Path:
    if not BAG.exists():
        pytest.skip("../shared/real_bags not present")
    return BAG


def test_audit_says_there_is_nothing_to_audit(
    bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["audit", str(bag)]) == 1
    err = error_messages(capsys.readouterr().err)
    assert len(err) == 1 and "no benchmark state topics" in err[0] and bag.name in err[0]
    assert "an FBM2@Home log without them scores with `ertools score fbm2h`" in err[0]


def test_report_of_the_real_bag_hashes_it_and_has_no_audit(bag: Path, tmp_path: Path) -> None:
    digest = hashlib.sha256()
    with bag.open("rb") as fh:  # read-only, as every input
        for block in iter(lambda: fh.read(1 << 16), b""):
            digest.update(block)
    result = FakeResult("fbm2h", {"position_accuracy": 0.1})
    write_report(result, tmp_path / "r", inputs=[bag], argv=[])
    meta = json.loads((tmp_path / "r" / "result.json").read_text())
    assert meta["inputs"][0]["sha256"] == digest.hexdigest()
    assert meta["inputs"][0]["size"] == 2943979  # the file as shipped (ls -l), byte for byte
    assert meta["audit"] is None  # no state topics: no audit section
