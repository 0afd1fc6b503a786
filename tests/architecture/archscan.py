"""The source of ertools read as data for the architecture tests (issue 37): its import graph
counting every import, hidden imports, function-level imports, root-package imports, benchmark
modules outside their package, repeated runs of lines and dotted references in prose.

Every scanner takes the folder holding ``ertools/`` so that a test can plant a fault in a copy
and see it found. Each returns offenders as stable strings (no line numbers), which the tests
compare with their ratchet allowlists.
"""

from __future__ import annotations

import ast
import re
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def module_name(root: Path, path: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules(root: Path) -> dict[str, Path]:
    """Every module of the package under ``root``: dotted name -> file."""
    return {module_name(root, p): p for p in sorted((root / "ertools").rglob("*.py"))}


def _parse(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    """ids of the nodes under an ``if TYPE_CHECKING:`` block (annotations only)."""
    return {
        id(node)
        for block in ast.walk(tree)
        if isinstance(block, ast.If) and "TYPE_CHECKING" in ast.unparse(block.test)
        for stmt in block.body
        for node in ast.walk(stmt)
    }


def _imported(
    node: ast.Import | ast.ImportFrom, here: list[str], files: dict[str, Path]
) -> list[str]:
    """The modules an import statement names (a name imported from a package that is a
    submodule counts as that submodule)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if node.level:
        base = ".".join([*here[: len(here) - node.level + 1], node.module or ""]).strip(".")
    else:
        base = node.module or ""
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in files else base for a in node.names]


def module_graph(root: Path) -> dict[str, set[str]]:
    """Every ertools -> ertools import edge: top level, under TYPE_CHECKING, in functions."""
    files = modules(root)
    graph: dict[str, set[str]] = {}
    for mod, path in files.items():
        here = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
        edges = set()
        for node in ast.walk(_parse(path)):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            for target in _imported(node, here, files):
                while target and target not in files:  # `import a.b.c`, c a name in a.b
                    target = target.rpartition(".")[0]
                if target.startswith("ertools") and target != mod:
                    edges.add(target)
        graph[mod] = edges
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan's, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp: list[str] = []
                while not comp or comp[-1] != v:
                    comp.append(stack.pop())
                    on.discard(comp[-1])
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


# The one place allowed to import a module by its name in a string (plan37 §4), and the one
# module allowed a module-level __getattr__ (the public API's names, PEP 562).
IMPORT_MODULE_ALLOWED = frozenset({"ertools/benchmarks/registry.py"})
GETATTR_ALLOWED = frozenset({"ertools/__init__.py"})


def hidden_imports(root: Path) -> set[str]:
    """``file: what`` for every dependency the import contracts cannot see: a submodule
    reached as an attribute without an import of it in that file, a module ``__getattr__``
    (but the root's), a module class swapped, an ``import_module`` (but the registry's)."""
    files = modules(root)
    problems: set[str] = set()
    for path in files.values():
        rel = path.relative_to(root).as_posix()
        tree = _parse(path)
        typing_only = _type_checking_nodes(tree)
        imported: set[str] = set()
        aliases: dict[str, str] = {}  # local name -> module it names
        for node in ast.walk(tree):
            if id(node) in typing_only:
                continue
            if isinstance(node, ast.Import):
                for a in node.names:
                    parts = a.name.split(".")  # `import a.b.c` imports a, a.b and a.b.c
                    imported.update(".".join(parts[:k]) for k in range(1, len(parts) + 1))
                    if a.asname:
                        aliases[a.asname] = a.name
                    else:
                        aliases[a.name.partition(".")[0]] = a.name.partition(".")[0]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                for a in node.names:
                    full = f"{node.module}.{a.name}"
                    imported.add(full if full in files else node.module)
                    if full in files:
                        aliases[a.asname or a.name] = full
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute):
                problems |= _reached(node, aliases, imported, files, rel)
                if node.attr == "__class__" and isinstance(node.ctx, ast.Store):
                    problems.add(f"{rel}: module class swapped")
            if (
                isinstance(node, ast.FunctionDef)
                and node.name == "__getattr__"
                and node.col_offset == 0
                and rel not in GETATTR_ALLOWED
            ):
                problems.add(f"{rel}: module __getattr__")
            if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == "__getattr__" for t in node.targets
            ):
                problems.add(f"{rel}: module __getattr__ assigned")
            named = node.id if isinstance(node, ast.Name) else getattr(node, "attr", None)
            if named == "import_module" and rel not in IMPORT_MODULE_ALLOWED:
                problems.add(f"{rel}: import_module outside the registry")
    return problems


def _reached(
    node: ast.Attribute,
    aliases: dict[str, str],
    imported: set[str],
    files: dict[str, Path],
    rel: str,
) -> set[str]:
    chain = []
    cur: ast.expr = node
    while isinstance(cur, ast.Attribute):
        chain.append(cur.attr)
        cur = cur.value
    if not (isinstance(cur, ast.Name) and cur.id in aliases):
        return set()
    base = aliases[cur.id]
    for attr in reversed(chain):
        nxt = f"{base}.{attr}"
        if nxt not in files:
            return set()
        if nxt not in imported:
            return {f"{rel}: {nxt} reached as an attribute"}
        base = nxt
    return set()


# `# lazy: <reason>` on the import's own (first) line, the reason naming the cost avoided, as
# measured (`300 ms`, `1.2 s`), or `optional` (an extra that may not be installed).
LAZY = re.compile(r"#\s*lazy:.*(\b\d+(\.\d+)? ?(ms|s)\b|\boptional\b)")


def function_imports(path: Path) -> Iterator[tuple[int, str, str]]:
    """(line, imported module, text of its first line) of every import inside a function,
    those under ``if TYPE_CHECKING:`` aside."""
    source = path.read_text(encoding="utf-8")
    lines = source.splitlines()
    tree = ast.parse(source)
    typing_only = _type_checking_nodes(tree)
    seen: set[int] = set()
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Import | ast.ImportFrom) and id(node) not in typing_only:
                if id(node) in seen:  # a nested function's import, met through its parent
                    continue
                seen.add(id(node))
                if isinstance(node, ast.Import):
                    module = node.names[0].name
                else:
                    module = "." * node.level + (node.module or "")
                yield node.lineno, module, lines[node.lineno - 1]


def unexplained_lazy_imports(root: Path) -> set[str]:
    """``file: module`` (`` xN`` when N imports of it) of every function-level import
    without ``# lazy: <reason>`` on its line, the reason naming a measured cost or ``optional``
    (the reason on the line above does not count: a formatter moves it away)."""
    counts: dict[str, int] = defaultdict(int)
    for path in sorted((root / "ertools").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        for _line, module, text in function_imports(path):
            if not LAZY.search(text):
                counts[f"{rel}: {module}"] += 1
    return {k if n == 1 else f"{k} x{n}" for k, n in counts.items()}


def root_imports(root: Path) -> set[str]:
    """Modules below the public API that import the root package: ``import ertools`` or
    ``from ertools import ...`` (``ertools/__init__.py`` aside)."""
    out = set()
    for path in sorted((root / "ertools").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        if rel == "ertools/__init__.py":
            continue
        for node in ast.walk(_parse(path)):
            if isinstance(node, ast.Import) and any(a.name == "ertools" for a in node.names):
                out.add(rel)
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module == "ertools":
                out.add(rel)
    return out


def facade_packages(root: Path) -> set[str]:
    """Package ``__init__.py`` files (the root's aside) that import anything: a package that
    re-exports its modules hides which one a user depends on (the contracts see the package)."""
    out = set()
    for path in sorted((root / "ertools").rglob("__init__.py")):
        rel = path.relative_to(root).as_posix()
        if rel != "ertools/__init__.py" and any(
            isinstance(node, ast.Import | ast.ImportFrom) for node in ast.walk(_parse(path))
        ):
            out.add(rel)
    return out


SHARED_BENCHMARK_FOLDERS = frozenset({"common", "__pycache__"})
# Names that mean one benchmark besides its package's: the registry's names and the sample
# folders and configuration files that belong to one.
BENCHMARK_WORDS = frozenset(
    {"fbm1h", "fbm1w", "robotlog", "stationary", "shapes", "goal", "timing"}
)


def outside_benchmark_modules(root: Path) -> set[str]:
    """``file: why`` of every benchmark module outside ``benchmarks/<name>/``: named after a
    benchmark, or importing a benchmark package's modules, anywhere but that package, the
    registry and the CLI's command modules (which may import what their command runs). The
    sample competition (``samples/competition*.py``) may import the benchmarks' ``sample``
    modules: it schedules the simulated executions of named benchmarks (data, not a
    dispatch)."""
    bench = root / "ertools" / "benchmarks"
    packages = sorted(
        p.name for p in bench.iterdir() if p.is_dir() and p.name not in SHARED_BENCHMARK_FOLDERS
    )
    names = set(packages) | BENCHMARK_WORDS
    word = re.compile(r"(^|_)(" + "|".join(sorted(names, key=len, reverse=True)) + r")(_|$)")
    own = re.compile(r"ertools\.benchmarks\.(" + "|".join(packages) + r")\b")
    competition = re.compile(r"ertools/samples/competition\w*\.py$")
    out = set()
    for path in sorted((root / "ertools").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        parts = rel.split("/")
        if parts[1] == "benchmarks" and len(parts) > 3 and parts[2] in packages:
            continue
        if rel == "ertools/benchmarks/registry.py" or parts[1] == "cli":
            continue
        if word.search(path.stem):
            out.add(f"{rel}: named after a benchmark")
        for node in ast.walk(_parse(path)):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                mods = [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                mods = [a.name for a in node.names]
            else:
                continue
            for m in mods:
                if (found := own.match(m)) is None:
                    continue
                if competition.match(rel) and m.startswith(f"{found.group(0)}.sample"):
                    continue
                out.add(f"{rel}: imports ertools.benchmarks.{found.group(1)}")
    return out


# The shared modules of the RSBB layer: they read each benchmark's facts through its package
# (config, declaration) or the registry, never by its code.
RSBB_SHARED = ("ertools/rsbb/", "ertools/competition/", "ertools/samples/")
RSBB_TABLE = "ertools/rsbb_states.py"


def registered_codes(root: Path) -> frozenset[str]:
    """The registry's names in capitals (``HNF``: an RSBB benchmark's code), read from the
    ``Entry("name", ...)`` lines of ``ertools/benchmarks/registry.py``."""
    tree = _parse(root / "ertools" / "benchmarks" / "registry.py")
    return frozenset(
        node.args[0].value.upper()
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id == "Entry"
        and node.args
        and isinstance(node.args[0], ast.Constant)
        and isinstance(node.args[0].value, str)
    )


def _chosen_by(node: ast.AST) -> list[ast.AST]:
    """The expressions ``node`` picks a case by: a comparison's operands (and the elements of
    a tuple, list or set among them), a subscript's key, a dict's keys, a match value."""
    if isinstance(node, ast.Compare):
        operands = [node.left, *node.comparators]
        return operands + [
            e for o in operands if isinstance(o, ast.Tuple | ast.List | ast.Set) for e in o.elts
        ]
    if isinstance(node, ast.Subscript):
        return [node.slice]
    if isinstance(node, ast.Dict):
        return [k for k in node.keys if k is not None]
    if isinstance(node, ast.MatchValue):
        return [node.value]
    return []


def benchmark_codes_in_shared(root: Path) -> set[str]:
    """``file:line: why`` of every registered benchmark's code (the registry's name in
    capitals) a shared RSBB module names: in ``ertools/rsbb/``, ``competition/`` and
    ``samples/`` any string literal of one; in ``rsbb_states.py``, whose table is the RSBB's
    own description (every code it knows: code, name, scripted), one chosen by (compared,
    a subscript's or a dict's key, a match case)."""
    codes = registered_codes(root)
    out = set()
    for path in sorted((root / "ertools").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        if rel == RSBB_TABLE:
            candidates = [c for n in ast.walk(_parse(path)) for c in _chosen_by(n)]
            why = "chooses by the code"
        elif rel.startswith(RSBB_SHARED):
            candidates = list(ast.walk(_parse(path)))
            why = "names the code"
        else:
            continue
        for node in candidates:
            if isinstance(node, ast.Constant) and node.value in codes:
                out.add(f"{rel}:{node.lineno}: {why} {node.value!r}")
    return out


_PUNCTUATION = re.compile(r"^[\[\](){},:]*$")


def _significant(path: Path) -> list[tuple[int, str]]:
    """(line number, text with white space folded) of the lines that are not blank, a
    comment, an import (or its continuation) or lone punctuation."""
    out, in_import = [], False
    for no, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        line = " ".join(raw.split())
        if in_import:
            in_import = not line.startswith(")")
            continue
        if line.startswith("import ") or (line.startswith("from ") and " import " in line):
            in_import = line.endswith("(")
            continue
        if not line or line.startswith("#") or _PUNCTUATION.match(line):
            continue
        out.append((no, line))
    return out


def repeats(root: Path, n: int = 10) -> dict[str, str]:
    """Runs of ``n`` or more identical significant lines found in two places or more:
    ``"fileA ~ fileB"`` -> ``"fileA:a-b ~ fileB:c-d"`` (one entry per pair of files)."""
    seen: dict[tuple[str, ...], list[tuple[str, int, int]]] = defaultdict(list)
    for path in sorted((root / "ertools").rglob("*.py")):
        lines = _significant(path)
        rel = path.relative_to(root).as_posix()
        for i in range(len(lines) - n + 1):
            window = tuple(text for _, text in lines[i : i + n])
            seen[window].append((rel, lines[i][0], lines[i + n - 1][0]))
    out: dict[str, str] = {}
    for places in sorted(tuple(p) for p in seen.values() if len(p) > 1):
        key = " ~ ".join(sorted({p[0] for p in places}))
        out.setdefault(key, " ~ ".join(f"{r}:{a}-{b}" for r, a, b in places))
    return out


# A dotted name in prose or code: `ertools.report.folder`, `ertools.api.score`.
DOTTED = re.compile(r"(?<![\w./-])ertools(?:\.[A-Za-z_]\w*)+")


def dotted_references(paths: list[Path], root: Path) -> Iterator[tuple[str, str]]:
    """(file, reference) of every dotted ``ertools.…`` name in ``paths``."""
    for path in paths:
        rel = path.relative_to(root).as_posix()
        for match in DOTTED.finditer(path.read_text(encoding="utf-8")):
            yield rel, match.group(0)


def ratchet(found: set[str], allowed: frozenset[str], what: str) -> None:
    """Fail on an offender missing from ``allowed`` (a new one) and on an entry of
    ``allowed`` that is no longer an offender (fixed: it must leave the list, so the list
    only shrinks)."""
    new, fixed = sorted(found - allowed), sorted(allowed - found)
    message = []
    if new:
        message += [f"new {what} (fix them; the allowlist only shrinks):", *new]
    if fixed:
        message += [f"fixed {what}: remove them from the allowlist:", *fixed]
    assert not message, "\n".join(message)


def plant(root: Path, files: dict[str, str]) -> Path:
    """A small package tree under ``root`` (``ertools/...`` paths -> source)."""
    for rel, text in files.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root
