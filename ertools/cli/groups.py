"""Command groups (``score``, ``acquire``): a second level of lazy dispatch."""

from __future__ import annotations

import argparse
import sys

from ertools.cli.command import Command, Delegate


def add_group_arguments(parser: argparse.ArgumentParser, members: dict[str, Command]) -> None:
    """The group's parser takes the member name and leaves the rest to the member's parser.

    Its usage line names everything a member needs (``ertools score NAME BAG... [OPTIONS]``):
    the group alone prints it above its one error line."""
    parser.epilog = members_epilog(members)
    names = "{" + ",".join(members) + "}"
    parser.usage = f"%(prog)s [-h] [-v] [-q] {names} BAG... [OPTIONS]"
    # the error of a group given no member: what to give, not argparse's hidden ARGS
    parser.group_required = f"NAME ({', '.join(members)}), then its BAG... and options"  # type: ignore[attr-defined]
    parser.add_argument(
        "member", choices=list(members), metavar="NAME", help="one of the members below"
    )
    parser.add_argument("rest", nargs=argparse.REMAINDER, metavar="ARGS", help=argparse.SUPPRESS)


def members_epilog(members: dict[str, Command]) -> str:
    """The ``--help`` list of a group's members, each with its summary and an example (when
    it has one: a benchmark's are in its own ``--help``)."""
    lines = ["members:"]
    width = max(len(n) for n in members)
    for name, cmd in members.items():
        lines.append(f"  {name:<{width}}  {cmd.summary}")
        if cmd.example:
            lines.append(f"  {'':<{width}}    e.g. {cmd.example}")
    return "\n".join(lines)


def _member_words(argv: list[str] | None, member: str, rest: list[str]) -> list[str]:
    """The words after the member's name as given: argparse's REMAINDER drops a ``--`` right
    after the name (``score fbm3w -- -h.bag`` then read ``-h`` as --help). A ``--`` before the
    name made every later word a name or a bag: it is passed on too."""
    if argv is None:
        return rest
    for i, word in enumerate(argv):
        if word == member:
            before = argv[:i]
            return (["--"] if "--" in before else []) + argv[i + 1 :]
        if word == "--" or word.startswith("-"):
            continue  # the group's own options (-v, -q, --debug) come before the name
        break
    return rest


def run_group(group: str, members: dict[str, Command], args: argparse.Namespace) -> int | Delegate:
    """The member to run, its own parser on the remaining arguments (the dispatcher runs it)."""

    extra = ["-v"] * args.verbose + (["--debug"] if args.debug else [])
    extra += ["--quiet"] if args.quiet else []
    member: str = args.member
    rest: list[str] = _member_words(getattr(args, "argv", None), member, list(args.rest))
    if member not in members:  # argparse checked already; keeps mypy honest
        print(f"ertools: error: unknown {group} {member!r}", file=sys.stderr)
        return 2
    return Delegate(f"ertools {group} {member}", members[member].module, extra + rest)
