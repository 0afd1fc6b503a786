"""Every dotted ``ertools.…`` name in the package (its docstrings and comments included), the
docs and the README names something that exists (issue 37): a module, or an attribute of one;
and every path ``ertools/…`` names a file or folder (a ``*`` matching one at least). A rename
that leaves a stale name in prose fails here, where a reader would otherwise follow it to
nothing."""

from __future__ import annotations

import glob
import importlib
import re
from pathlib import Path

from tests.architecture.archscan import ROOT, dotted_references, modules, ratchet

# Names in the ertools namespace that are data, not Python: the Foxglove schemas
# (`ertools.Fbm3wRun`: capitalised, as no module is) and the MCAP metadata records of
# `ertools live` (docs/live.md).
NOT_PYTHON = re.compile(r"ertools\.[A-Z]\w*|ertools\.(recorder|clock)(\.stats)?")

# A path in prose: `ertools/report/folder.py`, `ertools/benchmarks/`, `ertools/report/plots_*.py`.
PATH = re.compile(r"(?<![\w./-])ertools/[\w*./-]*[\w*]")

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


def stale_paths(root: Path) -> set[str]:
    """``file: path`` of every ``ertools/…`` path in the package, docs and README that names no
    file or folder under ``root``."""
    out = set()
    for path in texts(root):
        for match in PATH.finditer(path.read_text(encoding="utf-8")):
            named = match.group(0).rstrip(".")
            if not glob.glob(glob.escape(str(root)) + "/" + named):
                out.add(f"{path.relative_to(root).as_posix()}: {named}")
    return out


def test_no_stale_path() -> None:
    assert not stale_paths(ROOT), "paths that name nothing:\n" + "\n".join(
        sorted(stale_paths(ROOT))
    )


def test_a_stale_path_in_a_docstring_is_found(tmp_path: Path) -> None:
    (tmp_path / "docs").mkdir()
    (tmp_path / "README.md").write_text("see `ertools/a.py` and `ertools/b_*.py`.\n")
    package = tmp_path / "ertools"
    package.mkdir()
    (package / "a.py").write_text(
        '"""Moved to ertools/gone/c.py; see ertools/ and ertools/a.py."""\n'
    )
    (package / "b_1.py").write_text("")
    assert stale_paths(tmp_path) == {"ertools/a.py: ertools/gone/c.py"}
