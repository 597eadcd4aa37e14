# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The errors of ``mech_kinematics.errors`` are built the way their signatures say (issue 33).

``AssemblyError(dyad, angle, reason, *, facts=None)`` carries its facts as
data; a call that passes one message instead raises a TypeError in place of
the refusal it meant (the URDF of a scene refused at every angle did). mypy
checks only the strict modules, so every construction in the package is read
here and bound to its class's signature.
"""

import ast
import functools
import inspect
from pathlib import Path

import pytest

from mech_kinematics import errors

PACKAGE = Path(errors.__file__).resolve().parent
#: The error classes of errors.py, by name.
CLASSES = {name: cls for name, cls in vars(errors).items()
           if inspect.isclass(cls) and issubclass(cls, Exception)
           and cls.__module__ == errors.__name__}


@functools.lru_cache(maxsize=None)
def constructions():
    """Return (file:line, class name, call) of every call of an error class in the package.

    The package is read once for the module's tests and their ids.
    """
    found = []
    for path in sorted(PACKAGE.rglob('*.py')):
        tree = ast.parse(path.read_text(encoding='utf-8'))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                func = node.func
                name = func.id if isinstance(func, ast.Name) else \
                    func.attr if isinstance(func, ast.Attribute) else None
                if name in CLASSES:
                    found.append((f'{path.relative_to(PACKAGE.parent)}:{node.lineno}', name,
                                  node))
    return tuple(found)


def test_the_package_builds_its_errors():
    """There are constructions to check (the scan finds the solver's own)."""
    found = {name for _, name, _ in constructions()}
    assert {'AssemblyError', 'UntrustedError', 'SceneError'} <= found


@pytest.mark.parametrize('where, name, call', list(constructions()),
                         ids=[where for where, _, _ in constructions()])
def test_every_error_is_built_with_the_arguments_of_its_signature(where, name, call):
    """Each call binds to ``__init__``: positional count and keyword names as declared."""
    if any(isinstance(arg, ast.Starred) for arg in call.args) or any(
            keyword.arg is None for keyword in call.keywords):
        pytest.skip('*args or **kwargs: not checked statically')
    signature = inspect.signature(CLASSES[name])
    try:
        signature.bind(*call.args, **{keyword.arg: keyword.value for keyword in call.keywords})
    except TypeError as error:
        pytest.fail(f'{where}: {name}{signature} cannot be called so: {error}')
