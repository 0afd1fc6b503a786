"""The one option vocabulary: builders every command uses for the same idea.

The same idea has one spelling in every command (docs/cli.md lists them):

- a pose source: ``--topic TOPIC`` or ``--tf PARENT:CHILD`` (``--robot-``/``--gt-`` prefixes
  where a command reads two): :func:`add_pose_source`, read back with :func:`pose_spec`;
- ``--time-source header|record``, one default (``header``) everywhere: :func:`add_time_source`;
- ``--format text|json|yaml|csv`` and ``--out/-o FILE``: :func:`add_output`;
- ``--report DIR`` for a report folder: :func:`add_report`;
- ``--plot FILE`` (the suffix picks the format, every figure in one file) and ``--plots DIR``
  (one file per figure): :func:`add_plots`, written by :func:`ertools.cli.emit.write_plots`;
- durations are plain names in seconds (metavar ``S``): ``--max-gap``, ``--still-min``,
  ``--clock-tolerance``; never a ``-s``/``-duration`` suffix, never milliseconds;
- an old spelling keeps working for one release and says so once on stderr
  (``ertools: note: --frame is deprecated, use --tf world:FRAME``): :func:`deprecated`;
- every usage error exits 2: values are checked by argparse ``type=`` functions
  (:func:`positive`, :func:`non_negative`, :func:`seconds`) at parse time.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.common.spec import (
    DEFAULT_PARENT,
    DEFAULT_TIME_SOURCE,
    TIME_SOURCES,
    PoseSpec,
    parse_tf,
)
from ertools.progress import clear_current

# The builders use the light ``common.spec`` (no numpy, no bag reader), so that every parser,
# ``--help`` included, builds without the readers.

FORMATS = ("text", "json", "yaml", "csv")
# Suffixes ``--plot FILE`` can write with matplotlib (html is the timeline's own page).
PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def deprecation_note(old: str, new: str) -> None:
    """The one stderr line an old spelling costs: ``ertools: note: OLD is deprecated, use NEW``."""

    clear_current()
    print(f"ertools: note: {old} is deprecated, use {new}", file=sys.stderr)


class _Deprecated(argparse.Action):
    """An old option spelling: stores like the new one (after ``convert``) and notes it."""

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str,
        *,
        new: str,
        convert: Callable[[Any], Any] | None = None,
        append: bool = False,
        **kwargs: Any,
    ) -> None:
        self.new = new
        self.convert = convert
        self.append = append
        super().__init__(option_strings, dest, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        deprecation_note(option_string or self.option_strings[0], self.new)
        value = self.const if self.nargs == 0 else values
        if self.convert is not None:
            try:
                value = self.convert(value)
            except (ValueError, TypeError) as err:
                parser.error(f"{option_string}: {err}")
        if self.append:
            value = [*(getattr(namespace, self.dest, None) or []), value]
        setattr(namespace, self.dest, value)


def deprecated(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    old: str,
    new: str,
    dest: str,
    *,
    flag: bool = False,
    const: Any = True,
    convert: Callable[[Any], Any] | None = None,
    append: bool = False,
    metavar: str | None = None,
) -> None:
    """Keep ``old`` working for one release as a hidden alias of ``new`` (stored in ``dest``).

    Args:
        flag: the old option takes no value (stores ``const``).
        convert: maps the old value to the new option's value (``--frame F`` -> ``("world", F)``).
        append: the new option is a list (``action="append"``).
    """
    parser.add_argument(
        old,
        dest=dest,
        action=_Deprecated,
        new=new,
        convert=convert,
        append=append,
        nargs=0 if flag else None,
        const=const if flag else None,
        metavar=metavar,
        default=argparse.SUPPRESS,
        help=argparse.SUPPRESS,
    )


# ---------------------------------------------------------------- value checks (exit 2)


def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number")
    return value


def finite(text: str) -> float:
    """A finite number, any sign (argparse ``type=``)."""
    return _number(text)


def positive(text: str) -> float:
    """A finite number > 0 (argparse ``type=``: a bad one is a usage error, exit 2)."""
    value = _number(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"{text}: must be > 0")
    return value


def non_negative(text: str) -> float:
    """A finite number >= 0 (argparse ``type=``)."""
    value = _number(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text}: must be >= 0")
    return value


def fraction(text: str) -> float:
    """A number in [0, 1] (argparse ``type=``)."""
    value = _number(text)
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"{text}: must be in [0, 1]")
    return value


# Durations are seconds: the same check, a name that says what the option holds.
seconds = non_negative
positive_seconds = positive


def positive_int(text: str) -> int:
    """An integer >= 1 (argparse ``type=``)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be >= 1")
    return value


def port(text: str) -> int:
    """A UDP/TCP port, 1 to 65535 (argparse ``type=``)."""
    value = positive_int(text)
    if value > 65535:
        raise argparse.ArgumentTypeError(f"{text}: a port is 1 to 65535")
    return value


def non_negative_int(text: str) -> int:
    """An integer >= 0 (argparse ``type=``: a count)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text}: must be >= 0")
    return value


def seconds_or_auto(text: str) -> str | float:
    """Seconds (any sign: a clock offset) or ``auto`` (argparse ``type=``)."""
    if text == "auto":
        return text
    try:
        return _number(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"{text!r}: give seconds or 'auto'") from None


def tf_pair(text: str) -> tuple[str, str]:
    """``PARENT:CHILD`` (argparse ``type=``)."""
    try:
        return parse_tf(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


# ---------------------------------------------------------------- pose source and time


def _dest(prefix: str, name: str) -> str:
    return (prefix + name).replace("-", "_")


def add_pose_source(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    prefix: str = "",
    *,
    what: str = "poses",
    default: str = "",
    old_frame: Sequence[str] = (),
    old_topic: Sequence[str] = (),
) -> None:
    """``--[PREFIX]topic TOPIC`` or ``--[PREFIX]tf PARENT:CHILD`` (one of them, exit 2 if both).

    Args:
        prefix: ``robot-`` or ``gt-`` where a command reads two sources.
        what: what the poses are, for the help text.
        default: the help's "default ..." text (what is read when neither is given).
        old_frame: old spellings of a bare tf child frame (``--frame FRAME`` becomes
            ``--tf world:FRAME`` with a deprecation note).
        old_topic: old spellings of the topic (``--robot-topic`` where the new name differs).
    """
    which = parser.add_mutually_exclusive_group()
    tail = f" (default: {default})" if default else ""
    which.add_argument(
        f"--{prefix}topic",
        dest=_dest(prefix, "topic"),
        metavar="TOPIC",
        help=f"{what}: a pose topic (PoseStamped, Pose2D, Odometry, ...){tail}",
    )
    which.add_argument(
        f"--{prefix}tf",
        dest=_dest(prefix, "tf"),
        type=tf_pair,
        metavar="PARENT:CHILD",
        help=f"{what}: the /tf pose of CHILD in PARENT instead (e.g. world:robot_at_work)",
    )
    for old in old_frame:
        deprecated(
            which,
            old,
            f"--{prefix}tf {DEFAULT_PARENT}:FRAME",
            _dest(prefix, "tf"),
            convert=lambda frame: (DEFAULT_PARENT, frame),
            metavar="FRAME",
        )
    for old in old_topic:
        deprecated(which, old, f"--{prefix}topic", _dest(prefix, "topic"), metavar="TOPIC")


def add_time_source(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    prefix: str = "",
    *,
    old: Sequence[str] = (),
) -> None:
    """``--[PREFIX]time-source header|record``, default ``header`` in every command.

    ``header`` is the message stamp (the mocap's clock); a type without a header
    (``geometry_msgs/Pose2D``) falls back on the record time with a warning on stderr.
    """
    parser.add_argument(
        f"--{prefix}time-source",
        dest=_dest(prefix, "time_source"),
        choices=TIME_SOURCES,
        default=None,  # None: not given (the default applies; see pose_spec)
        help=f"pose time: the message's header stamp (default {DEFAULT_TIME_SOURCE}; Pose2D has "
        "none and falls back on the record time, with a warning) or the bag's record time",
    )
    for spelling in old:
        deprecated(
            parser,
            spelling,
            f"--{prefix}time-source",
            _dest(prefix, "time_source"),
            convert=_time_source_value,
            metavar="{header,record}",
        )


def _time_source_value(text: str) -> str:
    if text not in TIME_SOURCES:
        raise ValueError(f"{text!r}: choose header or record")
    return text


def time_source(args: argparse.Namespace, prefix: str = "") -> str:
    """The time source asked for, the common default when none was."""
    value = getattr(args, _dest(prefix, "time_source"), None)
    return str(value) if value is not None else DEFAULT_TIME_SOURCE


def pose_spec(
    args: argparse.Namespace, prefix: str = "", *, time_prefix: str | None = None
) -> PoseSpec:
    """The :class:`PoseSpec` of ``--[PREFIX]topic``/``--[PREFIX]tf`` and the time source.

    ``time_prefix`` names the time-source option's prefix when it differs from ``prefix``
    (default: the same; a command with one ``--time-source`` for two sources passes ``""``).
    """

    tp = prefix if time_prefix is None else time_prefix
    given = getattr(args, _dest(tp, "time_source"), None)
    return PoseSpec(
        topic=getattr(args, _dest(prefix, "topic"), None),
        tf=getattr(args, _dest(prefix, "tf"), None),
        time_source=given if given is not None else DEFAULT_TIME_SOURCE,
        time_source_given=given is not None,
    )


# ---------------------------------------------------------------- outputs


def _format_value(aliases: Mapping[str, str]) -> Callable[[str], str]:
    def value(text: str) -> str:
        if text in aliases:
            deprecation_note(f"--format {text}", f"--format {aliases[text]}")
            return aliases[text]
        return text

    return value


def add_output(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    formats: Sequence[str] = FORMATS,
    default: str | None = None,
    *,
    aliases: Mapping[str, str] | None = None,
    out: bool = True,
    out_help: str = "write the output to FILE instead of stdout",
) -> None:
    """``--format`` (``formats``, first one the default unless ``default``) and ``--out/-o FILE``.

    ``aliases`` maps old format names to new ones (``table`` -> ``text``); ``--output`` is the
    old spelling of ``--out``.
    """
    chosen = default or formats[0]
    parser.add_argument(
        "--format",
        choices=tuple(formats),
        default=chosen,
        type=_format_value(aliases or {}),
        help=f"output format on stdout or --out (default {chosen})",
    )
    if out:
        parser.add_argument("-o", "--out", dest="out", type=Path, metavar="FILE", help=out_help)
        deprecated(parser, "--output", "--out", "out", convert=Path, metavar="FILE")


def add_report(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    help: str = "",
    *,
    required: bool = False,
    old: Sequence[str] = (),
) -> None:
    """``--report DIR``: a self-contained report folder (``old``: former spellings)."""
    # required with old spellings: a required group of the new and the old options, so that
    # either satisfies argparse and a missing one is its usage error (exit 2, with --help)
    where = parser.add_mutually_exclusive_group(required=True) if required else parser
    where.add_argument(
        "--report",
        type=Path,
        metavar="DIR",
        help=help or "write a self-contained report folder (index.html, data files, figures)",
    )
    for spelling in old:
        deprecated(where, spelling, "--report", "report", convert=Path, metavar="DIR")


def plot_file(
    suffixes: Sequence[str] = PLOT_SUFFIXES, *, folder: bool = False
) -> Callable[[str], Path]:
    """argparse ``type=`` for ``--plot FILE``: the suffix must say the format (exit 2 if not);
    ``folder``: the command has ``--plots DIR`` too (the message says so)."""

    def value(text: str) -> Path:
        path = Path(text)
        if path.suffix.lower() not in suffixes:
            raise argparse.ArgumentTypeError(
                f"{text}: the suffix picks the format; give one of {', '.join(suffixes)}"
                + (" (--plots DIR writes one file per figure)" if folder else "")
            )
        return path

    return value


class _PlotOrOldFolder(argparse.Action):
    """``--plot FILE``; a value without a plot suffix is the old ``--plot DIR`` (a folder):
    it still works, as ``--plots DIR``, with a deprecation note (never a folder named like a
    file: ``--plot fig.png`` writes the file ``fig.png``)."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: Any) -> None:
        self.suffixes: tuple[str, ...] = tuple(kwargs.pop("suffixes"))
        self.folder_dest: str | None = kwargs.pop("folder_dest")
        super().__init__(option_strings, dest, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        text = str(values)
        path = Path(text)
        if path.suffix.lower() in self.suffixes:
            setattr(namespace, self.dest, path)
            return
        looks_like_folder = text.endswith(("/", "\\")) or path.suffix == "" or path.is_dir()
        if self.folder_dest is not None and looks_like_folder:
            deprecation_note(f"--plot {text} (a folder)", f"--plots {text}")
            setattr(namespace, self.folder_dest, path)
            return
        parser.error(
            f"argument --plot: {text}: the suffix picks the format; give one of "
            f"{', '.join(self.suffixes)}"
            + (" (--plots DIR writes one file per figure)" if self.folder_dest else "")
        )


def add_plots(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    *,
    folder: bool = True,
    suffixes: Sequence[str] = PLOT_SUFFIXES,
    what: str = "the figures",
) -> None:
    """``--plot FILE`` (every figure in one file; its suffix picks png/svg/pdf) and, with
    ``folder``, ``--plots DIR`` (one file per figure)."""
    parser.add_argument(
        "--plot",
        action=_PlotOrOldFolder,
        suffixes=suffixes,
        folder_dest="plots" if folder else None,
        metavar="FILE",
        help=f"write {what} to FILE; its suffix ({', '.join(suffixes)}) picks the format",
    )
    if folder:
        parser.add_argument(
            "--plots",
            type=Path,
            metavar="DIR",
            help="write one file per figure (PNG) into DIR",
        )


def add_out_dir(
    parser: argparse.ArgumentParser | argparse._ActionsContainer,
    help: str,
    *,
    old: Sequence[str] = (),
    default: Path | None = None,
    required: bool = False,
) -> None:
    """``--out-dir DIR``: a folder of several data files (not a report)."""
    where = parser.add_mutually_exclusive_group(required=True) if required else parser
    where.add_argument("--out-dir", type=Path, metavar="DIR", default=default, help=help)
    for spelling in old:
        deprecated(where, spelling, "--out-dir", "out_dir", convert=Path, metavar="DIR")
