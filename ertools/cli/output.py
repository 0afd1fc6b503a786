"""How every command writes: results on stdout (or ``--out``), notes on stderr, below any
progress bar. Light on purpose: every command imports it."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from ertools.cli.text import error_text, printable
from ertools.progress import clear_current


def write_text(text: str, output: Path | None) -> None:
    """Text to ``output`` (a file) or stdout (below any progress bar: stdout and stderr may
    be the same terminal)."""
    if output is None:
        clear_current()
        sys.stdout.write(text if text.endswith("\n") else text + "\n")
    else:
        from ertools.atomic import write_text as write_file  # lazy: tempfile, 2 ms: --out only

        output.parent.mkdir(parents=True, exist_ok=True)
        write_file(output, text if text.endswith("\n") else text + "\n")
        note(f"wrote {output}")


def note(message: str) -> None:
    """A human note on stderr (stdout stays parseable), below any progress bar; an
    ``error: ...`` note as every error is printed (:func:`ertools.cli.text.error_text`)."""

    clear_current()
    if message.startswith("error: "):
        print(error_text(message.removeprefix("error: ")), file=sys.stderr)
    else:
        print(f"ertools: {printable(message)}", file=sys.stderr)


def dump_json(data: Any) -> str:
    """``data`` as indented JSON (NumPy values as plain numbers, NaN as null)."""
    from ertools.serialize import json_text  # lazy: NumPy, 60 ms; not for --help

    return json_text(data)
