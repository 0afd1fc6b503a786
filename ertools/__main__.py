"""The ``ertools`` command: the console script (pyproject.toml's ``[project.scripts]``) and
``python -m ertools``, both through ertools.launch (a Ctrl-C while the command's modules load is
one line, exit status 130)."""

import os
import sys

from ertools.launch import run

# NumPy's OpenBLAS starts a thread per core when NumPy is imported, which then spins waiting for
# work: on a 2-core machine ~60 ms of CPU and wall before a command reads its first byte
# (docs/performance.md, "Start-up"). No command multiplies matrices large enough to share.
BLAS_THREADS = "1"


def _command() -> object:
    from ertools.cli.main import main  # lazy: inside run()'s Ctrl-C guard, NumPy: 150-250 ms

    return main()


def main() -> int:
    """The ``ertools`` console command."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)  # before NumPy's import
    return run(_command, "ertools")


if __name__ == "__main__":
    sys.exit(main())
