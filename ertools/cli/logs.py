"""How a command shows what the library logs: one ``ertools: LEVEL: ...`` line on stderr,
below any progress bar. Apart from :mod:`ertools.cli.main` so that building a command's
parser does not import :mod:`logging`."""

from __future__ import annotations

import logging
import sys

from ertools.cli.text import printable
from ertools.progress import clear_current


def configure_logging(verbose: int) -> None:
    """Library warnings on stderr as the CLI's own notes: ``ertools: warning: ...``; ``-v``
    adds info, ``-vv`` debug."""
    level = logging.WARNING if verbose == 0 else logging.INFO if verbose == 1 else logging.DEBUG

    class _LowerLevel(logging.Formatter):
        # "ertools: warning: ..." like the CLI's own notes (cli/output.note), not "WARNING";
        # the record itself is left as is (other handlers may see it).
        def formatMessage(self, record: logging.LogRecord) -> str:  # noqa: N802 (logging's)
            record.message = printable(record.message)  # one line, whatever a path holds
            return super().formatMessage(record)

        def format(self, record: logging.LogRecord) -> str:
            text = super().format(record)
            head = f"ertools: {record.levelname}:"
            return text.replace(head, head.lower(), 1)

    class _BelowTheBar(logging.StreamHandler):  # type: ignore[type-arg]
        # a message logged while a progress bar is drawn starts on a line of its own
        def emit(self, record: logging.LogRecord) -> None:
            clear_current()
            super().emit(record)

    handler = _BelowTheBar(sys.stderr)
    handler.setFormatter(_LowerLevel("ertools: %(levelname)s: %(message)s"))
    root = logging.getLogger("ertools")
    root.handlers[:] = [handler]
    root.setLevel(level)
    root.propagate = False
