"""One measured job, run as its own process by run.py: prints JSON with the in-process time
(``inside_s``: the work itself, after the imports, which are timed apart as ``import_s``).

python bench/extract.py bytes PATH              read the file's bytes
python bench/extract.py ertools PATH TOPIC      ertools.io.reader.read_poses -> arrays
python bench/extract.py rosbags PATH TOPIC      rosbags AnyReader, one message at a time
python bench/extract.py inflate PATH            read and decompress every chunk, no decoding
python bench/extract.py sources PATH BODY       the GT's three pose sources of BODY (its pose
                                                topic, its pose2d topic by record time, its
                                                /tf frame) in one read (read_pose_sources)
python bench/extract.py each PATH BODY          the same three, one read_pose_source each
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path


def main() -> None:
    mode, path = sys.argv[1], Path(sys.argv[2])
    t_import = time.perf_counter()
    if mode == "ertools":
        from ertools.io.reader import read_poses
    elif mode == "rosbags":
        import numpy as np
        from rosbags.highlevel import AnyReader
    elif mode == "inflate":
        from ertools.io.bulk import load_all_chunks
        from ertools.io.files import open_bag
    elif mode in ("sources", "each"):
        from ertools.io.reader import PoseSource, read_pose_source

        body = sys.argv[3]
        sources = [
            PoseSource(topic=f"{body}/pose"),
            PoseSource(topic=f"{body}/pose2d", time_source="record"),
            PoseSource(frame=body.rsplit("/", 1)[-1]),
        ]
    t0 = time.perf_counter()
    if mode == "bytes":
        n = 0
        with path.open("rb") as f:
            while block := f.read(16 << 20):
                n += len(block)
    elif mode == "ertools":
        n = len(read_poses(path, sys.argv[3]))
    elif mode == "rosbags":
        rows = []
        with AnyReader([path]) as reader:
            conns = [c for c in reader.connections if c.topic == sys.argv[3]]
            for conn, _t, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                p, q = msg.pose.position, msg.pose.orientation
                stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
                rows.append((stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w))
        n = len(np.array(rows))
    elif mode == "inflate":
        with open_bag(path) as bag:
            n = load_all_chunks(bag)
    elif mode == "sources":
        from ertools.io.reader import read_pose_sources

        n = sum(len(s) for s in read_pose_sources(path, sources))
    elif mode == "each":
        streams = [read_pose_source(path, s) for s in sources]  # kept, as one read keeps them
        n = sum(len(s) for s in streams)
    else:
        raise SystemExit(f"unknown mode {mode}")
    done = time.perf_counter()
    print(json.dumps({"n": n, "inside_s": done - t0, "import_s": t0 - t_import}))


if __name__ == "__main__":
    main()
