"""``python tests/rescore/toy_main.py rescore ...``: the ertools command line with the toy
benchmark as the only one registered, for the tests that run rescore as a process of its own
(to kill it, or to run two at once)."""

from __future__ import annotations

import sys

from ertools.benchmarks import registry
from ertools.cli.main import main

if __name__ == "__main__":
    # run as a script, whose folder (tests/rescore, rescore_toy's) heads sys.path
    registry.ENTRIES = (registry.Entry("toy", "rescore_toy:TOY", "a toy benchmark"),)
    raise SystemExit(main(sys.argv[1:]))
