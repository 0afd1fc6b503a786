"""``python -m ertools``: the ``ertools`` command, through ertools.launch as the console script
(a Ctrl-C while the command's modules load is one line, exit status 130)."""

import sys

from ertools.launch import main

sys.exit(main())
