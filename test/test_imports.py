# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""No import cycle among the package's modules, function-level imports included (issue 30).

``solve -> compiled -> tick -> solve`` was a cycle hidden in imports inside
functions, and ``rpr -> geneva -> rpr`` another: each module's imports are
read with ``ast`` (every ``import`` and ``from ... import`` anywhere in it,
relative ones resolved; those under ``if TYPE_CHECKING:`` run only for type
checkers and are left out), and the graph they make must have no cycle.
"""

import ast
import itertools
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / 'mech_kinematics'


def _module_name(root: Path, path: Path) -> str:
    """Return the dotted name of the module at ``path`` in the package at ``root``."""
    parts = list(path.relative_to(root.parent).with_suffix('').parts)
    return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)


def _type_checking(node: ast.If) -> bool:
    """Return whether ``node`` is ``if TYPE_CHECKING:`` (or ``typing.TYPE_CHECKING``)."""
    test = node.test
    return (isinstance(test, ast.Name) and test.id == 'TYPE_CHECKING') or (
        isinstance(test, ast.Attribute) and test.attr == 'TYPE_CHECKING')


def _imports(tree: ast.AST, name: str, package: bool, modules: set[str]) -> dict[str, int]:
    """Return the package's modules the module ``name`` imports, each with its first line.

    ``package``: whether the module is a package's ``__init__`` (its relative
    imports start from itself). ``from X import y`` imports the module
    ``X.y`` where there is one, else ``X``.
    """
    base = name if package else name.rpartition('.')[0]
    found: dict[str, int] = {}

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking(child):
                for stmt in child.orelse:
                    visit_one(stmt)
                continue
            visit_one(child)

    def visit_one(node: ast.AST) -> None:
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base.split('.')
                origin = '.'.join(parts[:len(parts) - node.level + 1]
                                  + ([node.module] if node.module else []))
            else:
                origin = node.module or ''
            targets = [f'{origin}.{alias.name}' if f'{origin}.{alias.name}' in modules
                       else origin for alias in node.names]
        for target in targets:
            if target in modules:
                found.setdefault(target, node.lineno)
        visit(node)

    visit(tree)
    return found


def import_graph(root: Path) -> dict[str, dict[str, tuple[str, int]]]:
    """Return, per module of the package at ``root``, the modules it imports: (file, line)."""
    paths = {_module_name(root, path): path for path in sorted(root.rglob('*.py'))}
    modules = set(paths)
    graph = {}
    for name, path in paths.items():
        tree = ast.parse(path.read_text(encoding='utf-8'))
        where = str(path.relative_to(root.parent))
        graph[name] = {target: (where, line) for target, line in _imports(
            tree, name, path.name == '__init__.py', modules).items()}
    return graph


def cycles(graph: dict[str, dict[str, tuple[str, int]]]) -> list[str]:
    """Return one line per cycle of ``graph`` (per strongly connected set): its modules in turn.

    Each edge names the import that makes it, e.g. ``a -> b (a.py:3) -> a (b.py:9)``.
    """
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def connect(v: str) -> None:    # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            members = []
            while True:
                w = stack.pop()
                members.append(w)
                if w == v:
                    break
            if len(members) > 1 or v in graph[v]:
                found.append(members)

    for v in sorted(graph):
        if v not in index:
            connect(v)
    lines = []
    for members in found:
        start = min(members)
        inside = set(members)
        # The shortest way back to the start, within the component (breadth first).
        previous: dict[str, str] = {}
        frontier = [start]
        while start not in previous:
            following = []
            for v in frontier:
                for w in sorted(graph[v]):
                    if w in inside and w not in previous:
                        previous[w] = v
                        following.append(w)
            frontier = following
        path = [start]
        while path[-1] != start or len(path) == 1:
            path.append(previous[path[-1]])
        path.reverse()
        steps = [f'{b} ({graph[a][b][0]}:{graph[a][b][1]})' for a, b in itertools.pairwise(path)]
        lines.append(' -> '.join([path[0], *steps]))
    return lines


def test_the_package_has_no_import_cycle():
    """No module of mech_kinematics imports, even inside a function, one that imports it back."""
    assert cycles(import_graph(PACKAGE)) == []


def test_a_cycle_through_a_function_level_import_is_named(tmp_path):
    """The check finds a cycle made by an import inside a function, and names each import."""
    root = tmp_path / 'pkg'
    (root / 'sub').mkdir(parents=True)
    (root / '__init__.py').write_text('')
    (root / 'sub' / '__init__.py').write_text('from .low import x\n')
    (root / 'sub' / 'low.py').write_text('x = 1\n\ndef f():\n    from ..top import y\n')
    (root / 'top.py').write_text('from .sub import low\ny = 2\n')
    assert cycles(import_graph(root)) == [
        'pkg.sub.low -> pkg.top (pkg/sub/low.py:4) -> pkg.sub.low (pkg/top.py:1)']


def test_an_import_for_type_checkers_alone_makes_no_cycle(tmp_path):
    """``if TYPE_CHECKING:`` imports are left out; its ``else`` branch is read."""
    root = tmp_path / 'pkg'
    root.mkdir()
    (root / '__init__.py').write_text('')
    (root / 'a.py').write_text('from . import b\n')
    (root / 'b.py').write_text('from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n'
                               '    from .a import x\n')
    assert cycles(import_graph(root)) == []
    (root / 'b.py').write_text('import typing\nif typing.TYPE_CHECKING:\n    pass\nelse:\n'
                               '    import pkg.a\n')
    assert cycles(import_graph(root)) == ['pkg.a -> pkg.b (pkg/a.py:1) -> pkg.a (pkg/b.py:5)']
