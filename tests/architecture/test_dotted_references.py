"""Every dotted ``ertools.…`` name in the package, the docs and the README names something
that exists (issue 37): a module, or an attribute of one. A rename that leaves a stale name in
prose fails here, where a reader would otherwise follow it to nothing."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

from tests.architecture.archscan import ROOT, dotted_references, modules, ratchet

# Names in the ertools namespace that are data, not Python: the Foxglove schemas
# (`ertools.Fbm3wRun`: capitalised, as no module is) and the MCAP metadata records of
# `ertools live` (docs/live.md).
NOT_PYTHON = re.compile(r"ertools\.[A-Z]\w*|ertools\.(recorder|clock)(\.stats)?")

# Stale names today: the list only shrinks.
ALLOWED: frozenset[str] = frozenset()


def texts(root: Path) -> list[Path]:
    docs = [p for p in sorted((root / "docs").rglob("*")) if p.suffix in {".md", ".py"}]
    return [*sorted((root / "ertools").rglob("*.py")), *docs, root / "README.md"]


def resolves(reference: str, names: dict[str, Path]) -> bool:
    """Whether ``reference`` is a module, or attributes of the longest module it starts with
    (a dataclass's field without a default counts: it is documented as an attribute)."""
    parts = reference.split(".")
    for k in range(len(parts), 0, -1):
        module = ".".join(parts[:k])
        if module not in names:
            continue
        obj: object = importlib.import_module(module)
        for attr in parts[k:]:
            fields = getattr(obj, "__dataclass_fields__", {})
            if attr in fields and not hasattr(obj, attr):
                return attr == parts[-1]
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def stale(root: Path) -> set[str]:
    names = modules(root)
    return {
        f"{where}: {reference}"
        for where, reference in dotted_references(texts(root), root)
        if not NOT_PYTHON.fullmatch(reference) and not resolves(reference, names)
    }


def test_no_new_stale_dotted_name() -> None:
    ratchet(stale(ROOT), ALLOWED, "dotted names that name nothing")


def test_a_stale_name_is_found() -> None:
    names = modules(ROOT)
    assert resolves("ertools.errors.ErtoolsError", names)
    assert resolves("ertools.io", names)
    assert not resolves("ertools.errors.NoSuchError", names)
    assert not resolves("ertools.no_such_module", names)
    assert not resolves("ertools.errors.ErtoolsError.no_such_method", names)
