"""One measured job, run as its own process by run.py: prints JSON with the in-process time.

python benchmarks/extract.py bytes PATH              read the file's bytes
python benchmarks/extract.py ertools PATH TOPIC      ertools.io.read_poses -> arrays
python benchmarks/extract.py rosbags PATH TOPIC      rosbags AnyReader, one message at a time
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path


def main() -> None:
    mode, path = sys.argv[1], Path(sys.argv[2])
    t0 = time.perf_counter()
    if mode == "bytes":
        n = 0
        with path.open("rb") as f:
            while block := f.read(16 << 20):
                n += len(block)
    elif mode == "ertools":
        from ertools.io import read_poses

        n = len(read_poses(path, sys.argv[3]))
    elif mode == "rosbags":
        import numpy as np
        from rosbags.highlevel import AnyReader

        rows = []
        with AnyReader([path]) as reader:
            conns = [c for c in reader.connections if c.topic == sys.argv[3]]
            for conn, _t, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                p, q = msg.pose.position, msg.pose.orientation
                stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
                rows.append((stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w))
        n = len(np.array(rows))
    else:
        raise SystemExit(f"unknown mode {mode}")
    print(json.dumps({"n": n, "inside_s": time.perf_counter() - t0}))


if __name__ == "__main__":
    main()
