"""The CLI's lines of text: control characters escaped, error messages on one line (or a few
indented ones when long). Light: every command module and the dispatcher use it."""

from __future__ import annotations

import textwrap

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


# The longest error line: what is wrong and where fits on it; the detail (frames found, the
# topics there, what to try) goes to further lines, indented, at the message's "; ".
MAX_ERROR_LINE = 200


def _clauses(text: str) -> list[str]:
    """``text`` split at each "; " outside brackets."""
    parts, depth, start = [], 0, 0
    for i, char in enumerate(text):
        depth += (char in "([{") - (char in ")]}")
        if depth == 0 and text.startswith("; ", i):
            parts.append(text[start:i])
            start = i + 2
    return [*parts, text[start:]]


def error_text(message: str) -> str:
    """``ertools: error: MESSAGE`` as printed: one line when it fits in
    :data:`MAX_ERROR_LINE` characters, else each further clause (after "; ") on a line of its
    own indented by two spaces, and a clause still too long wrapped at words onto lines
    indented by four."""
    first = f"ertools: error: {printable(one_line(message))}"
    if len(first) <= MAX_ERROR_LINE:
        return first
    clauses = _clauses(first)
    lines = [clauses[0], *(f"  {c}" for c in clauses[1:])]
    out: list[str] = []
    for line in lines:
        out += textwrap.wrap(
            line,
            MAX_ERROR_LINE,
            subsequent_indent="    ",  # deeper than a clause: the same clause goes on
            break_long_words=False,
            break_on_hyphens=False,
        ) or [line]
    return "\n".join(out)
