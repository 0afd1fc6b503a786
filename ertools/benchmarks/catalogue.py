"""The catalogue of every rule where ertools differs from the original nodes and of every node
version it reproduces, from the registry: each benchmark's ``rules`` and the ``VERSIONS`` its
package's ``rules`` module declares, with the 2015 BmBox's own (``common.ending``: every 2015
node imported it). ``docs/fidelity.md``'s two tables are generated from it
(``python -m ertools.benchmarks.catalogue [--write]``) and a test keeps them in step: a rule or
version added, removed or reworded changes the docs in the same commit.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    # `python -m ertools.benchmarks.catalogue`: the module run under its own name, its imports
    # included, inside ertools.launch's guard (a Ctrl-C while they load: one line, exit 130)
    # (the rules are the benchmark modules' objects, not copies made under __main__)
    from ertools.launch import run as launch

    def _start() -> object:
        from ertools.benchmarks.catalogue import main  # lazy: in launch's Ctrl-C guard, 300 ms

        return main()

    sys.exit(launch(_start, "python -m ertools.benchmarks.catalogue"))

from pathlib import Path

from ertools.atomic import write_text
from ertools.benchmarks import registry
from ertools.benchmarks.common import ending
from ertools.fidelity import (
    BEGIN,
    END,
    VERSIONS_BEGIN,
    VERSIONS_END,
    Rule,
    markdown_table,
    replace_table,
    version_table,
)
from ertools.node_versions import NodeVersion

#: The 2015 BmBox's: its rules and the versions of its files (``BmBox.py``, ``FSM.py``).
SHARED_RULES: tuple[Rule, ...] = ending.RULES
SHARED_VERSIONS: tuple[NodeVersion, ...] = ending.VERSIONS


def rules() -> tuple[Rule, ...]:
    """Every benchmark's ``rules`` in the registry's order (a package's once: fbm1h and fbm1w
    share fbm1's), the BmBox's after those of the 2015 nodes (season ``2015``) and before
    those of the RSBB seasons.

    Raises:
        ValueError: two rules share a key (a programming error, caught by the tests).
    """
    own: list[Rule] = []
    for name in registry.names():
        own.extend(r for r in registry.get(name).rules if not any(r is o for o in own))
    cut = next((i for i, r in enumerate(own) if r.season != "2015"), len(own))
    found = (*own[:cut], *SHARED_RULES, *own[cut:])
    keys = [r.key for r in found]
    dupes = sorted({k for k in keys if keys.count(k) > 1})
    if dupes:
        raise ValueError(f"rule keys declared twice: {', '.join(dupes)}")
    return found


def versions() -> tuple[NodeVersion, ...]:
    """The BmBox's versions, then the ``VERSIONS`` of each benchmark package's ``rules``
    module, in the registry's order (a package's once)."""
    found: list[NodeVersion] = list(SHARED_VERSIONS)
    seen: set[str] = set()
    for name in registry.names():
        module = registry.package_module(name, "rules")
        if module is None or module.__name__ in seen:
            continue
        seen.add(module.__name__)
        declared: tuple[NodeVersion, ...] = getattr(module, "VERSIONS", ())
        found.extend(declared)
    return tuple(found)


def main(argv: list[str] | None = None) -> int:
    """``python -m ertools.benchmarks.catalogue [--write]``: print or rewrite the generated
    tables of ``docs/fidelity.md`` (run from the repository's root)."""
    args = sys.argv[1:] if argv is None else argv
    # The README links docs/fidelity.md and keeps no table of its own (a summary only).
    path = Path("docs/fidelity.md")
    tables = (
        (markdown_table(rules(), full=True), BEGIN, END),
        (version_table(versions()), VERSIONS_BEGIN, VERSIONS_END),
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
