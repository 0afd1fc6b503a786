"""The CLI's lines of text: control characters escaped, every error message on one line.
Light: every command module and the dispatcher use it."""

from __future__ import annotations

# Control characters as escapes: a file name holding a newline (or an escape sequence) must
# not start a line of its own in a command's output, nor drive the terminal.
_CONTROL = {c: f"\\x{c:02x}" for c in (*range(0x20), 0x7F, *range(0x80, 0xA0))} | {
    0x09: "\\t",
    0x0A: "\\n",
    0x0D: "\\r",
    0x2028: "\\u2028",
    0x2029: "\\u2029",
}


def printable(text: str) -> str:
    """``text`` with its control characters escaped as Python writes them (``\\n``)."""
    return text.translate(_CONTROL)


def one_line(message: str) -> str:
    """The message on one line: wrapped third-party texts (a YAML parser's) span several."""
    return " ".join(message.split())


def error_text(message: str) -> str:
    """``ertools: error: MESSAGE`` as printed: always one line (a line-oriented reader, a log
    grep, a test, counts one error per line), however long; a third-party text's newlines (a
    YAML parser's) are folded into it. The message's clauses stay joined with "; "."""
    return f"ertools: error: {printable(one_line(message))}"
