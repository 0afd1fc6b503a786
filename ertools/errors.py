"""The error hierarchy.

Every error a user can cause (a bad file, a bad config, a run that cannot be found, a score
that cannot be computed) is an :class:`ErtoolsError`. Its message is one line that says what is
wrong, where (file, topic, time) and, where possible, what to do. The CLI prints it on stderr
and exits with status 1; anything else escaping the library is a bug.
"""

from __future__ import annotations

from pathlib import Path

# The longest path a message shows whole: a folder deeper than the system's path limit (4096
# bytes on Linux) would make a line thousands of characters long. A path has no spaces to
# wrap at: this one leaves room in the 200 characters of an error's first line.
MAX_SHOWN = 160


def shown(path: str | Path) -> str:
    """``path`` for a message: whole up to :data:`MAX_SHOWN` characters, else its start and
    end around "..." with its length said (about 120 characters)."""
    text = str(path)
    if len(text) <= MAX_SHOWN:
        return text
    return f"{text[:40]}...{text[-60:]} ({len(text)} characters)"


class ErtoolsError(Exception):
    """Root of every error ertools raises on purpose."""

    exit_code = 1

    def __init__(self, message: str, *, path: str | Path | None = None) -> None:
        self.path = str(path) if path is not None else None
        self.message = message
        super().__init__(f"{shown(self.path)}: {message}" if self.path else message)


class BagError(ErtoolsError):
    """A bag or MCAP file that is missing, unreadable, truncated or lacks what was asked."""


class TopicError(BagError):
    """A topic or tf frame that is not in the file, or has the wrong type."""


class ConfigError(ErtoolsError):
    """A YAML config or command-line value that is malformed or inconsistent."""


class SegmentationError(ErtoolsError):
    """Runs, segments or windows that cannot be found in the logs."""


class ScoringError(ErtoolsError):
    """A score that cannot be computed from the data found (too few samples, NaN poses...)."""


class ClockError(ErtoolsError):
    """Clocks that disagree more than allowed, or logs that do not overlap in time."""


class UsageError(ErtoolsError):
    """A command line that cannot be acted on; the CLI exits with status 2."""

    exit_code = 2
