"""The ``ertools`` command: the console script (pyproject.toml's ``[project.scripts]``) and
``python -m ertools``, both through ertools.launch (a Ctrl-C while the command's modules load is
one line, exit status 130)."""

import gc
import os
import sys

from ertools.launch import run

# NumPy's OpenBLAS starts a thread per core when NumPy is imported, which then spins waiting for
# work: on a 2-core machine ~60 ms of CPU and wall before a command reads its first byte
# (docs/performance.md, "Start-up"). No command multiplies matrices large enough to share.
BLAS_THREADS = "1"


# Net new container objects between two young-generation collections (Python's default: 700).
GC_THRESHOLD = 100_000


def _command() -> object:
    from ertools.cli.main import main  # lazy: inside run()'s Ctrl-C guard, NumPy: 150-250 ms

    return main()


def main() -> int:
    """The ``ertools`` console command."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)  # before NumPy's import
    # A cycle collection every 700 new objects ran 63 times in the hour's score (13 ms, 3 %),
    # over the imports' objects mostly: the data are NumPy arrays, which it never scans.
    gc.set_threshold(GC_THRESHOLD, 10, 10)
    code = run(_command, "ertools")
    # The process ends next. Python's exit runs full garbage collections over every object left
    # (modules, arrays' owners): 40 ms after an hour's score on this machine, to find cycles
    # the operating system frees anyway. Frozen objects are not scanned; finalisers of what
    # reference counting frees (open files, atexit) run as before (docs/performance.md, "Exit").
    gc.freeze()
    return code


if __name__ == "__main__":
    sys.exit(main())
