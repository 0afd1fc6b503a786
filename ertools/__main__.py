"""The ``ertools`` command: the console script (pyproject.toml's ``[project.scripts]``) and
``python -m ertools``, both through ertools.launch (a Ctrl-C while the command's modules load is
one line, exit status 130)."""

import sys

from ertools.launch import run


def _command() -> object:
    from ertools.cli.main import main  # lazy: inside run()'s Ctrl-C guard, NumPy: 150-250 ms

    return main()


def main() -> int:
    """The ``ertools`` console command."""
    return run(_command, "ertools")


if __name__ == "__main__":
    sys.exit(main())
