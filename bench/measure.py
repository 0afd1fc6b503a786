"""Run one command and report its wall time, CPU time and peak RSS as JSON (used by run.py).

A process's peak RSS (``ru_maxrss``) includes the memory of whatever it was forked from until
it execs, so run.py (large, after generating data) must not fork the measured commands
itself: it starts this small launcher, which imports nothing heavy, and this launcher forks
the command and reads its ``os.wait4`` resource usage.

    python bench/measure.py CMD [ARGS...]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time


def main() -> int:
    argv = sys.argv[1:]
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE)
    out = proc.stdout.read() if proc.stdout else b""
    _pid, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    code = os.waitstatus_to_exitcode(status)
    lines = out.decode(errors="replace").strip().splitlines()
    print(
        json.dumps(
            {
                "wall_s": wall,
                "maxrss_kib": usage.ru_maxrss,
                "cpu_s": usage.ru_utime + usage.ru_stime,
                "exit": code,
                "last_line": lines[-1] if lines else "",
            }
        )
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
