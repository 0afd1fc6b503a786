"""Reading ertools' stderr in tests: an error message longer than the CLI's line limit
continues on indented lines (``ertools.cli.main.error_text``); here it is one line again."""

from __future__ import annotations


def error_messages(err: str) -> list[str]:
    """Each ``ertools: error:`` message of ``err`` on one line: a detail line indented by two
    spaces is the next clause (joined with "; "), one indented by four the same clause
    wrapped (joined with a blank)."""
    out: list[str] = []
    for line in err.splitlines():
        if line.startswith("ertools: error:"):
            out.append(line)
        elif out and line.startswith("    "):
            out[-1] += " " + line.strip()
        elif out and line.startswith("  "):
            out[-1] += "; " + line.strip()
    return out


def one_error(err: str) -> str:
    """The one error message of ``err`` (asserts there is exactly one, and nothing else but
    ``ertools:`` lines around it)."""
    messages = error_messages(err)
    assert len(messages) == 1, err
    return messages[0]
