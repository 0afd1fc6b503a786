"""What the progress bar costs a read (docs/performance.md, "Progress bars").

python bench/progress_overhead.py [FOLDER]

Writes an hour of the GT benchmark data (ROS1 uncompressed and lz4, MCAP zstd) into
FOLDER (default build/bench-progress/), then reads the pose topic with ``read_poses`` eleven
times each without a reporter and with a :class:`ertools.progress.Bar` drawing on a fake
terminal from the first byte (the worst case: no delay), and prints the best times.
"""

from __future__ import annotations

import io
import sys
import time
from pathlib import Path

from bagwrite import msgdef, typestore, write_mcap, write_ros1
from data import GT_TOPIC, T0, gt_topics

from ertools.io.reader import read_poses
from ertools.progress import Bar, reporting


class Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


class Counting(Bar):
    """The bar, counting its calls (one per group of chunks)."""

    calls = 0

    def advance(self, n: int) -> None:
        self.calls += 1
        super().advance(n)


def best(path: Path, repeats: int = 11) -> tuple[float, float, int, int]:
    """Best of ``repeats`` reads without and with a bar (alternated: same cache, same load)."""
    plain, drawn, draws, calls = [], [], 0, 0
    for _ in range(repeats):
        for bar in (False, True):
            out = Tty()
            reporter = Counting(out, delay_s=0.0) if bar else None
            t0 = time.perf_counter()
            with reporting(reporter):
                read_poses(path, GT_TOPIC)
            (drawn if bar else plain).append(time.perf_counter() - t0)
            if reporter is not None:
                draws, calls = out.getvalue().count("\r"), reporter.calls
    return min(plain), min(drawn), draws, calls


def main() -> None:
    folder = Path(sys.argv[1] if len(sys.argv) > 1 else "build/bench-progress")
    folder.mkdir(parents=True, exist_ok=True)
    files = {
        "ROS1": folder / "gt_hour.bag",
        "ROS1 lz4": folder / "gt_hour_lz4.bag",
        "MCAP zstd": folder / "gt_hour.mcap",
    }
    if not all(p.exists() for p in files.values()):
        topics = gt_topics(T0, 3600, seed=1)
        write_ros1(files["ROS1"], topics)
        write_ros1(files["ROS1 lz4"], topics, "lz4")
        topics2 = gt_topics(T0, 3600, seed=1, ros1=False)
        schemas = {t.msgtype: msgdef(typestore(False), t.msgtype, False)[0] for t in topics2}
        write_mcap(files["MCAP zstd"], topics2, schemas, "zstd")
    print("| file | MiB | no reporter s | bar drawn s | reports | redraws |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, path in files.items():
        read_poses(path, GT_TOPIC)  # page cache warm
        plain, drawn, draws, calls = best(path)
        mib = path.stat().st_size / 2**20
        print(f"| {name} | {mib:.0f} | {plain:.3f} | {drawn:.3f} | {calls} | {draws} |")


if __name__ == "__main__":
    main()
