"""Where ertools declares its rules, read from the source: the catalogue
(:func:`ertools.fidelity.all_rules`) collects the ``Rule`` constants of the modules that
``RULE_MODULES`` lists, so a rule made anywhere else (in a function, a list, a module not
listed) would be missing from it, from the docs' table and from the checks on both.

The scanner takes the folder holding ``ertools/`` so that a test can plant a bad module in a
small tree and see it refused.
"""

from __future__ import annotations

import ast
from pathlib import Path


def _module_name(root: Path, path: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def listed_modules(root: Path) -> tuple[str, ...]:
    """``RULE_MODULES`` as ``ertools/fidelity.py`` under ``root`` writes it (a literal)."""
    tree = ast.parse((root / "ertools" / "fidelity.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.AnnAssign) and node.value is not None:
            target, value = node.target, node.value
        elif isinstance(node, ast.Assign) and len(node.targets) == 1:
            target, value = node.targets[0], node.value
        else:
            continue
        if isinstance(target, ast.Name) and target.id == "RULE_MODULES":
            return tuple(ast.literal_eval(value))
    raise AssertionError("ertools/fidelity.py has no literal RULE_MODULES")


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


def rule_declarations(root: Path) -> tuple[dict[str, tuple[str, ...]], set[str]]:
    """(module -> the names of its module-level ``Rule`` constants, problems): a ``Rule(...)``
    that is not the whole value of a module-level assignment, constants in a module
    ``RULE_MODULES`` does not list, and a listed module that declares none. Problems are
    stable strings, without line numbers."""
    listed = listed_modules(root)
    constants: dict[str, tuple[str, ...]] = {}
    problems: set[str] = set()
    for path in sorted((root / "ertools").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        tree = ast.parse(path.read_text(encoding="utf-8"))
        found = [c for c in (_constant(stmt) for stmt in tree.body) if c is not None]
        names = [name for name, _ in found]
        declared = {id(call) for _, call in found}
        for node in ast.walk(tree):
            if _is_rule_call(node) and id(node) not in declared:
                problems.add(f"{rel}: a Rule made in {_where(tree, node)}, not a module constant")
        module = _module_name(root, path)
        if names:
            constants[module] = tuple(names)
            if module not in listed:
                problems.add(f"{rel}: Rule constants in a module RULE_MODULES does not list")
    problems |= {
        f"RULE_MODULES lists {name}, which declares no Rule constant"
        for name in listed
        if name not in constants
    }
    return constants, problems
