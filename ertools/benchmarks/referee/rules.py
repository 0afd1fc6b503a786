"""The referee-scored benchmarks' rules: none. They report the items the referee entered and
rank them by the ERL rule; no deviation of theirs is printed (docs/rsbb.md)."""

from __future__ import annotations

from ertools.fidelity import Rule

RULES: tuple[Rule, ...] = ()
