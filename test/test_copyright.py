# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Every Python source starts with the project's copyright and license header."""

from pathlib import Path
import re

import pytest

ROOT = Path(__file__).resolve().parent.parent
# The exact header (the year may become a range such as 2026-2027):
#   # Copyright 2026 mech_kinematics contributors
#   # SPDX-License-Identifier: Apache-2.0
# An optional shebang line may come first.  Empty files (e.g. a bare
# __init__.py) are exempt, as in ament_copyright.
HEADER = re.compile(
    r'\A(#![^\n]*\n)?'
    r'# Copyright 20\d\d(-20\d\d)? mech_kinematics contributors\n'
    r'# SPDX-License-Identifier: Apache-2\.0\n'
)


def _sources():
    files = [ROOT / 'setup.py']
    for folder in ('mech_kinematics', 'test', 'scripts', 'launch'):
        if (ROOT / folder).is_dir():
            files += sorted((ROOT / folder).rglob('*.py'))
    return files


@pytest.mark.linter
@pytest.mark.copyright
def test_copyright():
    """Each .py in mech_kinematics/, test/, scripts/, launch/ and setup.py carries the header."""
    sources = _sources()
    assert Path(__file__).resolve() in sources
    missing = [
        str(path.relative_to(ROOT)) for path in sources
        if path.stat().st_size and not HEADER.match(path.read_text(encoding='utf-8'))
    ]
    assert not missing, f'Missing or malformed copyright header in: {missing}'


@pytest.mark.linter
@pytest.mark.copyright
def test_copyright_pattern():
    """The header check accepts the exact header and rejects near misses."""
    good = ('# Copyright 2026 mech_kinematics contributors\n'
            '# SPDX-License-Identifier: Apache-2.0\n"""Doc."""\n')
    assert HEADER.match(good)
    assert HEADER.match('#!/usr/bin/env python3\n' + good)
    assert not HEADER.match('"""Doc."""\n' + good)
    assert not HEADER.match(good.replace('Apache-2.0', 'MIT'))
    assert not HEADER.match(good.replace('contributors', 'authors'))
