"""The catalogue of rules where the rulebook, the 2015 nodes and ertools' defaults differ.

Every ``differs from 2015:`` line ertools prints is a :class:`Deviation` made from a
:class:`Rule` declared as a module-level constant next to the code that applies it, so a
referee who reads the line can find the rule (its key), what the 2015 node did and the option
that brings the 2015 behaviour back. Beside them, each benchmark's ``VERSIONS`` lists the
versions of its node files (:class:`NodeVersion`: commit, date, the competition it served, what
moved a score, the option that reproduces it). ``docs/fidelity.md``'s two tables are generated
from this catalogue (``python -m ertools.fidelity``) and a test keeps them in step: a rule or
version that is added, removed or reworded changes the docs in the same commit.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    # `python -m ertools.fidelity`: the module run under its own name, its imports included, inside
    # ertools.launch's guard (a Ctrl-C while they load: one line, exit 130)
    # (the benchmark modules' Rule class is that module's, not __main__'s)
    from ertools.launch import run as launch

    def _start() -> object:
        from ertools.fidelity import main  # lazy: in launch's Ctrl-C guard, 10 ms

        return main()

    sys.exit(launch(_start, "python -m ertools.fidelity"))

import importlib
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from ertools.atomic import write_text

# Modules that declare Rule constants; the catalogue is what these hold, in this order.
RULE_MODULES: tuple[str, ...] = (
    "ertools.benchmarks.fbm1.rules",
    "ertools.benchmarks.fbm2h.rules",
    "ertools.benchmarks.fbm3w.rules",
    "ertools.benchmarks.trajectory.rules",
    "ertools.benchmarks.common.ending",
    "ertools.benchmarks.hnf.rules",
    "ertools.benchmarks.hpff.rules",
    "ertools.benchmarks.hopf.rules",
    "ertools.benchmarks.hppf.rules",
    "ertools.benchmarks.hgmf.rules",
)


@dataclass(frozen=True)
class Rule:
    """One rule on which the rulebook, the 2015 node and ertools' default may disagree.

    Attributes:
        key: ``<benchmark>.<short-name>``, unique; printed with every deviation.
        benchmark: the benchmark name (``fbm3w``...), or ``all``.
        title: a short name of the rule.
        rulebook: what the rulebook / seed manual says (with the section).
        node_2015: what the 2015 node did, with the file it did it in.
        ertools: what ertools does by default, and why.
        option: the command-line option that restores 2015; empty where none can (then
            ``ertools`` says why).
        season: the original the rule differs from: ``2015`` (the RoCKIn nodes, whose
            behaviour ``node_2015`` describes) or ``2019``/``2017`` (an RSBB script of the ERL
            @Home seasons, described in ``node_2015`` likewise).
    """

    key: str
    benchmark: str
    title: str
    rulebook: str
    node_2015: str
    ertools: str
    option: str
    season: str = "2015"

    def deviation(self, detail: str) -> Deviation:
        """The line to print for one result: ``detail`` says what differs in this result."""
        return Deviation(self, detail)


@dataclass(frozen=True)
class NodeVersion:
    """One version of a node file of rockin-robot-challenge/benchmark_and_scoring_fbm: a row of
    the version table (``docs/fidelity.md``), read at its commit.

    Attributes:
        file: the file in that repository (``scripts/fbm2h``, ``src/rockin_scoring/BmBox.py``).
        commit: the short commit hash.
        date: the commit date (YYYY-MM-DD).
        event: the competition it served (RoCKIn 2015 Lisbon, the Lisbon 2016 second local,
            the Lisbon 2017 major tournament), or ``development``.
        changes: every change since the file's previous row that moves a score.
        restores: the option reproducing it, or ``not restorable:`` and why.
    """

    file: str
    commit: str
    date: str
    event: str
    changes: str
    restores: str


class Deviation(str):
    """A ``differs from 2015`` text that knows its :class:`Rule`.

    A ``str`` so that everything that prints, joins, compares or serialises deviations treats
    it as the text it is; ``rule`` ties it to the catalogue.
    """

    rule: Rule
    detail: str

    def __new__(cls, rule: Rule, detail: str) -> Deviation:
        text = detail
        if rule.option and rule.option not in detail:
            text += f"; {rule.option} restores {rule.season}"
        self = super().__new__(cls, f"{text} [{rule.key}]")
        self.rule = rule
        self.detail = detail
        return self

    def __reduce__(self) -> tuple[type[Deviation], tuple[Rule, str]]:
        return (Deviation, (self.rule, self.detail))


def differs_line(deviation: str) -> str:
    """The line printed for a deviation: ``differs from 2015: ...`` (or the season its rule
    names, ``differs from 2019: ...`` for the RSBB benchmarks)."""
    rule = getattr(deviation, "rule", None)
    season = rule.season if isinstance(rule, Rule) else "2015"
    return f"differs from {season}: {deviation}"


def all_rules() -> tuple[Rule, ...]:
    """Every Rule constant of :data:`RULE_MODULES`, in module then definition order.

    Raises:
        ValueError: two rules share a key (a programming error, caught by the tests).
    """
    rules: list[Rule] = []
    for name in RULE_MODULES:
        module = importlib.import_module(name)
        rules.extend(v for v in vars(module).values() if isinstance(v, Rule))
    keys = [r.key for r in rules]
    dupes = sorted({k for k in keys if keys.count(k) > 1})
    if dupes:
        raise ValueError(f"rule keys declared twice: {', '.join(dupes)}")
    return tuple(rules)


# Modules that declare the node versions (a ``VERSIONS`` tuple): the BmBox first.
VERSION_MODULES: tuple[str, ...] = (
    "ertools.benchmarks.common.ending",
    "ertools.benchmarks.fbm1.rules",
    "ertools.benchmarks.fbm2h.rules",
    "ertools.benchmarks.fbm3w.rules",
    "ertools.benchmarks.hnf.rules",
    "ertools.benchmarks.hpff.rules",
    "ertools.benchmarks.hopf.rules",
    "ertools.benchmarks.hppf.rules",
    "ertools.benchmarks.hgmf.rules",
)


def all_versions() -> tuple[NodeVersion, ...]:
    """The ``VERSIONS`` of the modules of :data:`VERSION_MODULES`, in that order."""
    out: list[NodeVersion] = []
    for name in VERSION_MODULES:
        out.extend(getattr(importlib.import_module(name), "VERSIONS", ()))
    return tuple(out)


def version_table(versions: Iterable[NodeVersion]) -> str:
    """The node versions as a Markdown table."""
    head = "| file | commit | date | served | changes since the row above | restored by |"
    lines = [head, "|" + "---|" * head.count(" | ") + "---|"]
    for v in versions:
        cells = (f"`{v.file}`", f"`{v.commit}`", v.date, v.event, v.changes, v.restores)
        lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown_table(rules: Iterable[Rule], *, full: bool) -> str:
    """The rules as a Markdown table: ``full`` adds the rulebook and the 2015 sources."""
    if full:
        head = "| key | rule | rulebook | 2015 node | ertools default | restores 2015 |"
    else:
        head = "| benchmark | rule | ertools | 2015 | restores 2015 |"
    lines = [head, "|" + "---|" * head.count(" | ") + "---|"]
    for r in rules:
        option = f"`{r.option}`" if r.option else "-"
        cells: tuple[str, ...]
        if full:
            cells = (f"`{r.key}`", r.title, r.rulebook, r.node_2015, r.ertools, option)
        else:
            cells = (r.benchmark, r.title, r.ertools, r.node_2015, option)
        lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


BEGIN = "<!-- fidelity-table:begin (generated by `python -m ertools.fidelity`; do not edit) -->"
END = "<!-- fidelity-table:end -->"
VERSIONS_BEGIN = (
    "<!-- version-table:begin (generated by `python -m ertools.fidelity`; do not edit) -->"
)
VERSIONS_END = "<!-- version-table:end -->"


def replace_table(document: str, table: str, begin: str = BEGIN, end: str = END) -> str:
    """``document`` with the text between the markers ``begin`` and ``end`` replaced by
    ``table``.

    Raises:
        ValueError: the markers are missing.
    """
    start, stop = document.find(begin), document.find(end)
    if start < 0 or stop < start:
        raise ValueError("the generated-table markers are missing")
    return document[: start + len(begin)] + "\n" + table + document[stop:]


def main(argv: list[str] | None = None) -> int:
    """``python -m ertools.fidelity [--write]``: print or rewrite the generated tables."""

    args = sys.argv[1:] if argv is None else argv
    # The README links docs/fidelity.md and keeps no table of its own (a summary only).
    path = Path("docs/fidelity.md")
    tables = (
        (markdown_table(all_rules(), full=True), BEGIN, END),
        (version_table(all_versions()), VERSIONS_BEGIN, VERSIONS_END),
    )
    if "--write" not in args:
        for table, _, _ in tables:
            print(f"## {path}\n\n{table}")
        return 0
    text = path.read_text(encoding="utf-8")
    for table, begin, end in tables:
        text = replace_table(text, table, begin, end)
    write_text(path, text)
    print(f"wrote the version and rule tables of {path}")
    return 0
