"""Where ertools declares its rules, read from the source: the catalogue
(:func:`ertools.benchmarks.catalogue.rules`) is each benchmark's ``rules``, its package's
``RULES`` tuple, so a rule made anywhere else (in a function, a class, a list) or left out of
its module's ``RULES`` would be missing from it, from the docs' table and from the checks on
both.

The scanner takes the folder holding ``ertools/`` so that a test can plant a bad module in a
small tree and see it refused.
"""

from __future__ import annotations

import ast
from pathlib import Path


def _module_name(root: Path, path: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_rule_call(node: ast.AST) -> bool:
    if not isinstance(node, ast.Call):
        return False
    func = node.func
    return (isinstance(func, ast.Name) and func.id == "Rule") or (
        isinstance(func, ast.Attribute) and func.attr == "Rule"
    )


def _constant(stmt: ast.stmt) -> tuple[str, ast.expr] | None:
    """The name and call of a module-level ``NAME = Rule(...)`` (or ``NAME: Rule = ...``)."""
    if isinstance(stmt, ast.Assign) and len(stmt.targets) == 1:
        target, value = stmt.targets[0], stmt.value
    elif isinstance(stmt, ast.AnnAssign) and stmt.value is not None:
        target, value = stmt.target, stmt.value
    else:
        return None
    return (target.id, value) if isinstance(target, ast.Name) and _is_rule_call(value) else None


def _where(tree: ast.Module, call: ast.AST) -> str:
    """The innermost function or class holding ``call``, or the module's statement."""
    found = "an expression at module level"
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and any(
            inner is call for inner in ast.walk(node)
        ):
            kind = "class" if isinstance(node, ast.ClassDef) else "function"
            found = f"{kind} {node.name}"  # walk is breadth first: the last hit is innermost
    return found


def _listed(tree: ast.Module) -> tuple[str, ...] | None:
    """The names a module-level ``RULES = (A, B)`` (or ``RULES: ... = (...)``) lists; None
    when the module has no such tuple of names."""
    for stmt in tree.body:
        if isinstance(stmt, ast.Assign) and len(stmt.targets) == 1:
            target, value = stmt.targets[0], stmt.value
        elif isinstance(stmt, ast.AnnAssign) and stmt.value is not None:
            target, value = stmt.target, stmt.value
        else:
            continue
        if isinstance(target, ast.Name) and target.id == "RULES" and isinstance(value, ast.Tuple):
            return tuple(e.id for e in value.elts if isinstance(e, ast.Name))
    return None


def rule_declarations(root: Path) -> tuple[dict[str, tuple[str, ...]], set[str]]:
    """(module -> the names of its module-level ``Rule`` constants, problems): a ``Rule(...)``
    that is not the whole value of a module-level assignment, a module whose constants its
    ``RULES`` tuple does not list (or lists in another order), and a ``RULES`` naming what is
    not one of its constants. Problems are stable strings, without line numbers."""
    constants: dict[str, tuple[str, ...]] = {}
    problems: set[str] = set()
    for path in sorted((root / "ertools").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        tree = ast.parse(path.read_text(encoding="utf-8"))
        found = [c for c in (_constant(stmt) for stmt in tree.body) if c is not None]
        names = tuple(name for name, _ in found)
        declared = {id(call) for _, call in found}
        for node in ast.walk(tree):
            if _is_rule_call(node) and id(node) not in declared:
                problems.add(f"{rel}: a Rule made in {_where(tree, node)}, not a module constant")
        if not names:
            continue
        constants[_module_name(root, path)] = names
        listed = _listed(tree)
        if listed is None:
            problems.add(f"{rel}: Rule constants and no RULES tuple listing them")
            continue
        missing = [n for n in names if n not in listed]
        if missing:
            problems.add(f"{rel}: RULES leaves out {', '.join(missing)}")
        strange = [n for n in listed if n not in names]
        if strange:
            problems.add(f"{rel}: RULES lists {', '.join(strange)}, not a Rule constant here")
        if not missing and not strange and listed != names:
            problems.add(f"{rel}: RULES lists its constants in another order than declared")
    return constants, problems
