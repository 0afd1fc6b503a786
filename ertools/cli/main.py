"""``ertools`` entry point: lazy dispatch so that ``ertools --help`` answers instantly."""

from __future__ import annotations

import argparse
import errno
import math
import os
import re
import select
import sys

if __name__ == "__main__":
    # `python -m ertools.cli.main`: the module run under its own name, its imports included, inside
    # ertools.launch's guard (a Ctrl-C while they load: one line, exit 130)
    from ertools.launch import run as launch

    def _start() -> object:
        from ertools.cli.main import main  # lazy: in launch's Ctrl-C guard, 70 ms

        return main()

    sys.exit(launch(_start, "ertools"))

from collections.abc import Sequence
from pathlib import Path
from types import ModuleType
from typing import NoReturn

from ertools._version import __version__
from ertools.cli.command import Command, Delegate
from ertools.cli.text import error_text, one_line
from ertools.errors import ErtoolsError, UsageError
from ertools.progress import Bar, reporting

COMMANDS: dict[str, Command] = {
    "info": Command("ertools.cli.info", "describe bags like `rosbag info`", "ertools info run.bag"),
    "timeline": Command(
        "ertools.cli.timeline",
        "order bags from many machines by time; overlaps, gaps, GT pairing",
        "ertools timeline bags/ --plot timeline.png",
    ),
    "score": Command(
        "ertools.cli.score",
        "recompute a benchmark score ({benchmarks})",
        "ertools score fbm3w run.bag --config configs/fbm3w.yaml",
    ),
    "rescore": Command(
        "ertools.cli.rescore",
        "score a whole competition from a manifest; results.json, reports, in parallel",
        "ertools rescore logs/ --config competition.yaml --out results/",
    ),
    "export": Command(
        "ertools.cli.export",
        "poses as TUM, KITTI or CSV for evo and other tools; the robot/GT pair",
        "ertools export run.bag --topic /fbm3w/robot_at_work/pose -o poses.tum",
    ),
    "noise": Command(
        "ertools.cli.noise",
        "mocap noise statistics of a stationary marker set, suggested d_min",
        "ertools noise stationary.bag --topic /fbm3w/robot_at_work/pose",
    ),
    "acquire": Command(
        "ertools.cli.acquire",
        "offline acquisition of marker-to-robot transforms and FBM1 items",
        "ertools acquire transform run.bag --team homer",
    ),
    "audit": Command(
        "ertools.cli.audit",
        "reconstruct a benchmark from its state topics and check it",
        "ertools audit fbm2h.bag --report audit/",
    ),
    "report": Command(
        "ertools.cli.report",
        "combine several results into one HTML page",
        "ertools report results/*/score.json --report competition/",
    ),
    "record": Command(
        "ertools.cli.record",
        "record OptiTrack NatNet mocap data to MCAP, no ROS needed",
        "ertools record --config mocap.yaml --out-dir logs/",
    ),
    "monitor": Command(
        "ertools.cli.monitor",
        "watch the log being written and warn when it stops growing",
        "ertools monitor logs/ --bell",
    ),
    "clock": Command(
        "ertools.cli.clock",
        "query an NTP server and report the local clock offset",
        "ertools clock --server 192.168.1.1",
    ),
}


def _top_level_help() -> str:
    from ertools.benchmarks.registry import names  # lazy: the protocols, 10 ms: not --version

    width = max(len(name) for name in COMMANDS)
    lines = [
        "usage: ertools [-h] [-V] COMMAND [ARGS...]",
        "",
        "Re-score ERL / RoCKIn benchmarks from their logs, with no ROS installed.",
        "",
        "commands:",
    ]
    for name, cmd in COMMANDS.items():
        lines.append(f"  {name:<{width}}  {cmd.summary.format(benchmarks=', '.join(names()))}")
        lines.append(f"  {'':<{width}}    e.g. {cmd.example}")
    lines += [
        "",
        "`ertools COMMAND --help` shows a command's options with examples;",
        "`ertools -V` (--version) its version.",
        "Exit status: 0 success, 1 unusable data or config, 2 usage error.",
    ]
    return "\n".join(lines)


class _Parser(argparse.ArgumentParser):
    """argparse with the house error format: one ``ertools: error:`` line, exit status 2."""

    def error(self, message: str) -> NoReturn:
        # a required option with a hidden old spelling is a required group of one visible name
        one = re.fullmatch(r"one of the arguments (\S+) is required", message)
        if one is not None:
            message = f"the following arguments are required: {one.group(1)}"
        group_required: str | None = getattr(self, "group_required", None)
        usage = ""
        if group_required and message.startswith("the following arguments are required"):
            # a group given nothing (`ertools score`): the usage line, then what it needs
            message = f"the following arguments are required: {group_required}"
            usage = self.format_usage()
        self.exit(
            2, f"{usage}{error_text(f'{self.prog}: {message} (`{self.prog} --help` shows how)')}\n"
        )


def _columns() -> int:
    """The terminal's width as :func:`shutil.get_terminal_size` gives it (``COLUMNS``, else
    stdout's terminal, else 80)."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns > 0:
        return columns
    try:
        return os.get_terminal_size(sys.__stdout__.fileno()).columns or 80  # type: ignore[union-attr]
    except (AttributeError, ValueError, OSError):
        return 80


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """argparse's formatter of descriptions as written, its width taken as argparse takes it
    but without importing shutil: argparse imports it (with bz2, lzma and zlib, ~2 ms) for
    every option added, and no scoring command needs it."""

    def __init__(
        self,
        prog: str,
        indent_increment: int = 2,
        max_help_position: int = 24,
        width: int | None = None,
    ) -> None:
        width = _columns() - 2 if width is None else width
        super().__init__(prog, indent_increment, max_help_position, width)


def command_module(name: str) -> ModuleType:
    """The module of a command (a :class:`Command`'s ``module``), imported now: each command
    imports only what it runs, and ``ertools --help`` nothing of them."""
    match name:
        case "ertools.cli.info":
            from ertools.cli import info  # lazy: only this command, 270 ms

            return info
        case "ertools.cli.timeline":
            from ertools.cli import timeline  # lazy: only this command, 260 ms

            return timeline
        case "ertools.cli.score":
            from ertools.cli import score  # lazy: only this command, 600 ms

            return score
        case "ertools.cli.rescore":
            from ertools.cli import rescore  # lazy: only this command, 1350 ms

            return rescore
        case "ertools.cli.export":
            from ertools.cli import export  # lazy: only this command, 500 ms

            return export
        case "ertools.cli.noise":
            from ertools.cli import noise  # lazy: only this command, 1150 ms

            return noise
        case "ertools.cli.acquire":
            from ertools.cli import acquire  # lazy: only this command, 1 ms

            return acquire
        case "ertools.cli.audit":
            from ertools.cli import audit  # lazy: only this command, 570 ms

            return audit
        case "ertools.cli.report":
            from ertools.cli import report  # lazy: only this command, 320 ms

            return report
        case "ertools.cli.record":
            from ertools.cli import record  # lazy: only this command, 280 ms

            return record
        case "ertools.cli.monitor":
            from ertools.cli import monitor  # lazy: only this command, 220 ms

            return monitor
        case "ertools.cli.clock":
            from ertools.cli import clock  # lazy: only this command, 285 ms

            return clock
        case "ertools.cli.acquire_transform":
            from ertools.cli import acquire_transform  # lazy: only this command, 870 ms

            return acquire_transform
        case "ertools.cli.acquire_items":
            from ertools.cli import acquire_items  # lazy: only this command, 830 ms

            return acquire_items
    raise UsageError(f"no command module {name!r}")


def build_parser(prog: str, module_name: str) -> tuple[argparse.ArgumentParser, object]:
    """The parser of one command module (imported only now)."""
    module = command_module(module_name)
    description = (module.__doc__ or "").strip()
    epilog = getattr(module, "EPILOG", None)
    describe = getattr(module, "describe", None)
    if describe is not None:  # one module serving several commands (`score NAME`)
        description, epilog = describe(prog)
    parser = _Parser(
        prog=prog,
        description=description,
        epilog=epilog,
        formatter_class=_Formatter,
    )
    parser.add_argument(
        "-v", "--verbose", action="count", default=0, help="more detail on stderr (-vv: debug)"
    )
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an unexpected error"
    )
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="no progress bar (one is shown on a terminal's stderr for work that lasts)",
    )
    module.add_arguments(parser)
    return parser, module


# Options naming what a command writes; every other path option or argument is an input.
OUTPUT_OPTIONS = {
    "output": "-o/--output",
    "report": "--report",
    "plot": "--plot",
    "plots": "--plots",
    "out": "--out",
    "out_dir": "--out-dir",
    "foxglove": "--foxglove",
}


def _refuse_overwriting_inputs(args: argparse.Namespace) -> None:
    """A UsageError when an output path is one of the inputs (`-o run.bag`)."""

    inputs: list[Path] = []
    for name, value in vars(args).items():
        if name in OUTPUT_OPTIONS:
            continue
        for v in value if isinstance(value, list | tuple) else [value]:
            if isinstance(v, Path) and v.exists():
                inputs.append(v)  # files, and folders read as a whole (`report DIR --out DIR`)
    for name, flag in OUTPUT_OPTIONS.items():
        out = getattr(args, name, None)
        if not isinstance(out, Path) or not out.exists():
            continue
        for p in inputs:
            if os.path.samefile(p, out):
                raise UsageError(
                    f"{flag} {out}: that is an input; ertools never overwrites its inputs"
                )


def _check_numbers(args: argparse.Namespace) -> None:
    """A UsageError for a NaN, infinite or absurdly large number option (`--max-gap nan`)."""
    from ertools.timeutil import MAX_SECONDS  # lazy: datetime, 3 ms: not for --version

    for name, value in vars(args).items():
        for v in value if isinstance(value, list | tuple) else [value]:
            if isinstance(v, float) and not (math.isfinite(v) and abs(v) < MAX_SECONDS):
                flag = "--" + name.replace("_", "-")
                raise UsageError(
                    f"{flag} {v}: give a finite number smaller than {MAX_SECONDS:g} in size"
                )


def run_command(prog: str, module_name: str, argv: Sequence[str]) -> int:
    """Parse ``argv`` for one command module and run it, mapping errors to exit codes."""

    parser, module = build_parser(prog, module_name)
    try:
        args = parser.parse_args(list(argv))
    except SystemExit as stop:  # --help (0) or a usage error (2), already printed
        return stop.code if isinstance(stop.code, int) else 2
    # The command as run, for report provenance (sys.argv is wrong when called in-process).
    args.command_line = [*prog.split(), *argv]
    args.argv = list(argv)  # a group hands its member the words after the member's name
    from ertools.cli.logs import configure_logging  # lazy: logging, ~5 ms: not for a parser

    configure_logging(args.verbose)
    bar = _progress_bar(args)
    try:
        _check_numbers(args)
        _refuse_overwriting_inputs(args)
        try:
            with reporting(bar):
                code: int | Delegate = module.run(args)  # type: ignore[attr-defined]
        finally:  # wiped before any error line below, which would otherwise follow the bar
            if bar is not None:
                bar.close()
    except ErtoolsError as err:
        print(error_text(str(err)), file=sys.stderr)
        return err.exit_code
    except KeyboardInterrupt:
        print("ertools: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError as err:
        if not _stdout_closed():  # a pipe of ertools' own, not the reader of stdout: a bug
            return _unexpected(err, args)
        _silence_stdout()
        return 0
    except OSError as err:  # mostly an output path that cannot be written (-o, --plot...)
        if args.debug:
            raise
        where = f"{err.filename}: " if err.filename else _writing(err, args)
        print(
            one_line(f"ertools: error: {where}{err.strerror or err}: cannot read or write there"),
            file=sys.stderr,
        )
        return 1
    except Exception as err:  # a bug: still one line unless --debug
        return _unexpected(err, args)
    if isinstance(code, Delegate):  # a group's member: parsed and run as a command itself
        return run_command(code.prog, code.module, code.argv)
    return code


# A full disk or quota, a file too large: a write's errors, which name no file.
_WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})


def _writing(err: OSError, args: argparse.Namespace) -> str:
    """``writing OUT: `` for a write error naming no file (a writer not through
    :mod:`ertools.atomic`, which names its own): the outputs the command was given, else
    stdout; "" for any other error."""
    if err.errno not in _WRITE_ERRNOS:
        return ""
    outs = [str(v) for name in OUTPUT_OPTIONS if isinstance(v := getattr(args, name, None), Path)]
    return f"writing {', '.join(outs) or 'stdout'}: "


def _unexpected(err: Exception, args: argparse.Namespace) -> int:
    """A bug: one line and exit 1; with --debug, ``err`` raised again (its traceback).

    A group member's own --debug re-raises through the group's run_command, whose parser left
    --debug in the member's arguments: the mark keeps the traceback."""
    if args.debug or getattr(err, "ertools_debug", False):
        err.ertools_debug = True  # type: ignore[attr-defined]
        raise err
    print(
        f"ertools: error: unexpected {type(err).__name__}: {one_line(str(err))} "
        "(this is a bug in ertools; re-run with --debug for the traceback)",
        file=sys.stderr,
    )
    return 1


def _progress_bar(args: argparse.Namespace) -> Bar | None:
    """The command's progress bar (``args.progress``): only on a terminal and without
    ``--quiet``; None otherwise, so nothing reports at all."""

    args.progress = None
    if getattr(args, "quiet", False) or not sys.stderr.isatty():
        return None
    bar = Bar(sys.stderr)
    args.progress = bar
    return bar


def main(argv: Sequence[str] | None = None) -> int:
    """Console entry point."""
    try:
        code = _main(argv)
        sys.stdout.flush()  # here, not at exit, where a closed pipe is a traceback
    except BrokenPipeError:
        # `ertools --help | head -1`: the reader has all it wants; say nothing more, and
        # point stdout at nothing so that Python's own flush at exit does not complain
        _silence_stdout()
        return 0
    return code


def _stdout_closed() -> bool:
    """Whether stdout's reader has gone (``ertools ... | head -1``): its pipe then polls as an
    error. Where that cannot be asked, assumed."""
    try:
        poll = select.poll()
        poll.register(sys.stdout.fileno(), select.POLLOUT)
        events = poll.poll(0)
    except (AttributeError, OSError, ValueError):  # no poll, stdout replaced in-process
        return True
    return any(mask & (select.POLLERR | select.POLLHUP) for _, mask in events)


def _silence_stdout() -> None:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout replaced in-process (tests)
        pass


def _main(argv: Sequence[str] | None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help"):
        print(_top_level_help())
        return 0 if args else 2
    if args[0] in ("-V", "--version"):
        print(f"ertools {__version__}")
        return 0
    name = args[0]
    if name not in COMMANDS:
        print(
            f"ertools: error: unknown command {name!r}; choose from {', '.join(COMMANDS)}",
            file=sys.stderr,
        )
        return 2
    return run_command(f"ertools {name}", COMMANDS[name].module, args[1:])
