"""The vocabulary of the rules where the rulebook, the 2015 nodes and ertools' defaults differ.

Every ``differs from 2015:`` line ertools prints is a :class:`Deviation` made from a
:class:`Rule` declared as a module-level constant next to the code that applies it, so a
referee who reads the line can find the rule (its key), what the 2015 node did and the option
that brings the 2015 behaviour back. Beside them, each benchmark's ``VERSIONS`` lists the
versions of its node files (:class:`NodeVersion`: commit, date, the competition it served, what
moved a score, the option that reproduces it). The catalogue of them all comes from the
registry (:mod:`ertools.benchmarks.catalogue`, which generates ``docs/fidelity.md``'s two
tables with the functions here).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


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


_GENERATED = "(generated by `python -m ertools.benchmarks.catalogue`; do not edit)"
BEGIN = f"<!-- fidelity-table:begin {_GENERATED} -->"
END = "<!-- fidelity-table:end -->"
VERSIONS_BEGIN = f"<!-- version-table:begin {_GENERATED} -->"
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
