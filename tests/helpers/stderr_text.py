"""Reading ertools' stderr in tests: each error message is one line as printed
(``ertools.cli.text.error_text``); older helpers' indented continuations are joined here too."""

from __future__ import annotations


def joined_lines(err: str) -> list[str]:
    """The lines of ``err``, each error message on one: after an ``ertools: error:`` line, a
    line indented by two spaces is the next clause (joined with "; "), one indented by four
    the same clause wrapped (joined with a blank)."""
    out: list[str] = []
    in_error = False
    for line in err.splitlines():
        if in_error and line.startswith("    "):
            out[-1] += " " + line.strip()
        elif in_error and line.startswith("  "):
            out[-1] += "; " + line.strip()
        else:
            out.append(line)
            in_error = line.lstrip("\x1b[K").startswith("ertools: error:")
    return out


def error_messages(err: str) -> list[str]:
    """Each ``ertools: error:`` message of ``err``, on one line."""
    return [line for line in joined_lines(err) if line.startswith("ertools: error:")]
