"""Recompute a benchmark score from its logs.

NAME is the benchmark; each has its own inputs, options and examples: `ertools score NAME
--help` (e.g. ertools score fbm3w run.bag --config configs/fbm3w.yaml). The score goes to
stdout (YAML, or --format json), notes and warnings to stderr.
"""

# The members and their options are generated from each benchmark's declared inputs (the
# registry, ertools.benchmarks.registry): a benchmark has no code of its own in the CLI.

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks import registry
from ertools.benchmarks.base import AnyBenchmark, Described, Input, Reported, offers
from ertools.cli.command import Command, Delegate
from ertools.cli.groups import add_group_arguments, run_group
from ertools.cli.options import deprecation_note
from ertools.cli.output import note
from ertools.cli.result_options import add_output_options
from ertools.errors import UsageError

GROUP_PROG = "ertools score"
# Number kinds -> argparse types (the values are checked again by make_options).
_TYPES: dict[str, Any] = {"float": float, "int": int, "path": Path, "paths": Path, "str": str}


def members() -> dict[str, Command]:
    """Every registered benchmark, as a member of the ``score`` group (this module), from the
    registry's lines: no benchmark is imported (every group module has this function)."""
    return {e.name: Command(__name__, e.summary, "") for e in registry.ENTRIES}


def _member(prog: str) -> str | None:
    """The benchmark a parser's prog names (``ertools score fbm3w`` -> ``fbm3w``)."""
    words = prog.split()
    if len(words) == 3 and words[:2] == GROUP_PROG.split():
        return words[2]
    return None


def describe(prog: str) -> tuple[str, str | None]:
    """The ``--help`` description and epilog: the group's, or the benchmark's."""
    name = _member(prog)
    if name is None:
        return (__doc__ or "").strip(), None
    bench = registry.get(name)
    if not isinstance(bench, Described):
        return registry.entry(name).summary, None
    return bench.description, bench.epilog


def add_arguments(parser: argparse.ArgumentParser) -> None:
    name = _member(parser.prog)
    if name is None:
        add_group_arguments(parser, members())
    else:
        add_benchmark_arguments(parser, name)


def _metavar(declared: Input) -> str | None:
    if declared.metavar:
        return declared.metavar
    if declared.kind in ("float", "int"):
        return declared.unit.upper() if declared.unit else "N"
    if declared.kind in ("path", "paths"):
        return "FILE"
    return None


def _help(declared: Input) -> str:
    text = declared.help
    formerly = [*declared.old_flags, *(f.option for f in declared.former)]
    if formerly:
        text += f" (formerly {', '.join(formerly)})"
    return text.replace("%", "%%")


def _old_dest(flag: str) -> str:
    """Where an old spelling's value goes: its own name, so that errors name it as typed."""
    return flag.lstrip("-").replace("-", "_")


def _add_input(target: Any, declared: Input) -> None:
    """One declared input as an argparse option (its values checked by make_options)."""
    kw: dict[str, Any] = {"dest": declared.name, "help": _help(declared), "default": None}
    if declared.kind == "flag":
        kw["action"] = "store_true"
    else:
        metavar = _metavar(declared)
        if metavar is not None:
            kw["metavar"] = metavar
        if declared.kind == "choice" and declared.with_file:
            kw["nargs"] = "+"
            kw.setdefault("metavar", "MODE")
        elif declared.kind == "choice":
            kw["choices"] = declared.choices
        else:
            kw["type"] = _TYPES[declared.kind]
        if declared.kind == "paths":
            kw["nargs"] = "+"
        if declared.repeat:
            kw["action"] = "append"
    target.add_argument(declared.option, **kw)
    for old in declared.old_flags:
        old_kw = {**kw, "dest": _old_dest(old), "help": argparse.SUPPRESS}
        target.add_argument(old, **old_kw)
    for former in declared.former:
        if former.value is None:
            former_kw = {**kw, "dest": former.name, "help": argparse.SUPPRESS}
        else:  # a former switch, standing for one value
            former_kw = {"dest": former.name, "action": "store_true", "default": None}
            former_kw["help"] = argparse.SUPPRESS
        target.add_argument(former.option, **former_kw)


def add_benchmark_arguments(parser: argparse.ArgumentParser, name: str) -> None:
    """BAG... and every declared input of ``name``, grouped as declared, then the output
    options shared by every benchmark."""
    bench = registry.get(name)
    parser.set_defaults(benchmark=name)
    # A `with_file` choice takes words (`--reached timing FILE`): given before the bags it
    # swallows them, so none is required here and run() takes them back (see _bags).
    swallows = any(i.with_file for i in bench.inputs)
    metavar, bags_help = _bags_metavar(bench)
    if isinstance(metavar, str):
        parser.add_argument(
            "bags",
            nargs="*" if swallows else "+",
            type=Path,
            metavar=metavar,
            help=bags_help,
        )
    else:  # the first bag, then any number of others (ROBOT_BAG [GT_PATH ...])
        first, rest = metavar
        parser.add_argument("bags", type=Path, metavar=first, help=bags_help)
        parser.add_argument("more_bags", type=Path, nargs="*", metavar=rest)
    groups: dict[str, Any] = {}
    for declared in bench.inputs:
        target: Any = parser
        if declared.group:
            if declared.group not in groups:
                groups[declared.group] = parser.add_argument_group(declared.group)
            target = groups[declared.group]
        _add_input(target, declared)
    names = {i.name for i in bench.inputs}
    # a benchmark without figures or Foxglove content (the referee-scored ones) offers neither
    add_output_options(
        parser,
        plot=offers(bench, "figures"),
        foxglove=offers(bench, "foxglove"),
        team="team" not in names,
    )


def _bags_metavar(bench: AnyBenchmark) -> tuple[str | tuple[str, str], str]:
    """The placeholder of the log arguments and their help (:class:`Described`'s)."""
    if isinstance(bench, Described):
        return bench.bags_metavar, bench.bags_help
    return Described.bags_metavar, Described.bags_help


def _values(bench: AnyBenchmark, args: argparse.Namespace) -> dict[str, Any]:
    """The values given, by input name; an old spelling is said on stderr."""
    values: dict[str, Any] = {}
    for declared in bench.inputs:
        value = getattr(args, declared.name)
        for old in declared.old_flags:
            old_value = getattr(args, _old_dest(old))
            if old_value is None or old_value is False:
                continue
            # A bare frame of the old spellings is the child of the mocap frame.
            frame = " world:FRAME" if declared.metavar == "PARENT:CHILD" else ""
            deprecation_note(old, declared.option + frame)
            if not value:
                value = old_value
        for former in declared.former:
            old_value = getattr(args, former.name)
            if old_value is None or old_value is False:
                continue
            new_value = former.new_value(old_value)
            given = "" if former.value is not None else f" {old_value}"
            deprecation_note(former.option + given, f"{declared.option} {new_value}")
            if not value:
                value = new_value
        if declared.kind == "flag" and not value:
            value = None  # not given: make_options applies the default
        values[declared.name] = value
    return values


def _bags(bench: AnyBenchmark, values: dict[str, Any], bags: Sequence[Path]) -> list[Path]:
    """The bags, taken back from a ``with_file`` choice that swallowed them when it came
    first (``--reached timing FILE log.bag``)."""
    out = list(bags)
    for declared in bench.inputs:
        words = values.get(declared.name)
        if not declared.with_file or not words or out:
            continue
        need = 2 if words[0] in declared.with_file else 1
        if len(words) > need:
            out = [Path(w) for w in words[need:]]
            values[declared.name] = words[:need]
    if not out:
        metavar, _ = _bags_metavar(bench)
        first = metavar if isinstance(metavar, str) else metavar[0]
        raise UsageError(
            f"give at least one {first} (the log file); `ertools score {bench.name} --help` "
            "shows how"
        )
    return out


def run(args: argparse.Namespace) -> int | Delegate:
    name: str | None = getattr(args, "benchmark", None)
    if name is None:
        return run_group("score", members(), args)
    bench = registry.get(name)
    values = _values(bench, args)
    given = args.bags if isinstance(args.bags, list) else [args.bags, *args.more_bags]
    bags = _bags(bench, values, given)
    args.bags = bags
    from ertools.benchmarks.document import all_failed  # lazy: NumPy, the scorer, 250 ms
    from ertools.benchmarks.scoring import score_execution  # lazy: 250 ms
    from ertools.cli.emit import emit_result  # lazy: the report, 300 ms

    scored = score_execution(bench, bags, values)  # what ertools.score calls
    result = scored.result
    inputs = list(bags)
    if isinstance(bench, Reported):
        if not all_failed(result):  # nothing scored: only the errors (emit_result)
            for line in bench.notes(result):
                note(line)
        inputs = bench.input_files(bags, scored.options, result)
    return emit_result(result, args, inputs)
