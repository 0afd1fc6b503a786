"""A file cut short while mapped ends the process in one error line (``ertools.io.mapguard``);
a SIGBUS that is not about a watched map goes where it went before."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from ertools.io import mapguard

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(not mapguard.ACTIVE, reason="the guard is Linux-only")


def _run(script: str, *flags: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, *flags, "-c", script],
        capture_output=True,
        text=True,
        cwd=REPO,
        timeout=120,
        check=False,
    )


CUT = """
import mmap, os, sys
import numpy as np
from ertools.io import mapguard
path = sys.argv[1] if len(sys.argv) > 1 else {path!r}
with open(path, "rb") as f:
    mm = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
{watch}
os.truncate(path, 0)
print(int(np.frombuffer(mm, np.uint8).sum()))  # every page of the map is gone
"""


@pytest.mark.parametrize("flags", [(), ("-X", "faulthandler")], ids=["plain", "faulthandler"])
def test_a_watched_map_of_a_cut_file_ends_in_one_line(tmp_path: Path, flags: tuple[str]) -> None:
    path = tmp_path / "x.bag"
    path.write_bytes(b"\x01" * 300_000)
    done = _run(CUT.format(path=str(path), watch="mapguard.watch(mm, path)"), *flags)
    assert (done.returncode, done.stdout) == (1, "")
    assert done.stderr.splitlines() == [
        f"ertools: error: {path}: the file changed while it was read (cut short: copied over, "
        "truncated or still being written?); read it again once it is complete"
    ]


def test_an_unwatched_map_crashes_as_without_the_guard(tmp_path: Path) -> None:
    """The guard installed (a map watched once) but no map alive: the default action, the
    process killed by SIGBUS, as it would be with no guard at all."""
    path = tmp_path / "x.bag"
    path.write_bytes(b"\x01" * 300_000)
    script = CUT.format(
        path=str(path),
        watch="other = object()\nmapguard.watch(other, 'y')\nmapguard.unwatch(other)",
    )
    done = _run(script)
    assert done.returncode == -7  # SIGBUS
    assert "ertools: error" not in done.stderr


def test_a_sigbus_sent_while_no_map_is_alive_is_not_swallowed(tmp_path: Path) -> None:
    script = """
import signal
from ertools.io import mapguard
mapguard.watch(object(), "x")  # installs; the object is gone at once
mapguard.unwatch(object())
mapguard._LIVE.clear()
signal.raise_signal(signal.SIGBUS)
print("survived")
"""
    done = _run(script)
    assert done.returncode == -7 and "survived" not in done.stdout
