# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The YAML 1.2 reader of scene files: a hardened PyYAML loader, bounded and strict.

:func:`read_scene_yaml` parses text with :class:`SceneLoader` (on libyaml's
parser where PyYAML has it), not with ``yaml.safe_load``: YAML 1.2 scalars,
no duplicate or non-text keys, and every resource bounded, so that any text
gives plain data or one :class:`~mech_kinematics.errors.SceneError` naming the
line and column. :mod:`mech_kinematics.scene` reads the scene's keys from
what it returns.

YAML dialect
------------
Plain scalars resolve by the YAML 1.2 core schema: ``1.5e2``, ``1e-3`` and
``-1E+3`` are floats, ``0o17`` and ``0x1F`` integers, ``true``/``false``
booleans, ``~``/``null``/empty null. A plain scalar that YAML 1.1 (the
dialect of ``yaml.safe_load`` and ROS tools) reads as a boolean or number
and YAML 1.2 reads otherwise is refused rather than guessed at, so a file
this loader accepts means the same to both: ``on``/``off``/``yes``/``no``
(quote them), ``1_000``, ``1:30`` (base 60), ``0b101`` and numbers with a
leading zero such as ``017`` (octal in 1.1, decimal in 1.2). Merge keys
(``<<``) are refused; anchors and aliases are fine. Only the standard tags
``!!str``, ``!!int``, ``!!float``, ``!!bool``, ``!!null``, ``!!seq`` and
``!!map`` are accepted.

Limits
------
:data:`MAX_YAML_NODES` (counted with aliases expanded, so a "billion laughs"
text is refused), :data:`MAX_DEPTH` and :data:`MAX_INTEGER_DIGITS`; each is
named in its refusal.
"""

from __future__ import annotations

from collections.abc import Callable
import math
import re
import reprlib
from typing import Any, NoReturn

import yaml
from yaml.events import (AliasEvent, DocumentEndEvent, DocumentStartEvent, MappingEndEvent,
                         MappingStartEvent, ScalarEvent, SequenceEndEvent, SequenceStartEvent,
                         StreamEndEvent, StreamStartEvent)

from .errors import SceneError

__all__ = ['MAX_DEPTH', 'MAX_INTEGER_DIGITS', 'MAX_YAML_NODES', 'SceneLoader', 'read_scene_yaml']

#: Most YAML nodes (scalars, lists, mappings) a scene file may hold, counted
#: with every alias expanded; a scene at all the count limits has about 370,000.
MAX_YAML_NODES = 500_000
#: Deepest nesting of lists and mappings (a scene needs 5).
MAX_DEPTH = 32
#: Most digits in an integer: every accepted integer converts to a finite
#: float (a double reaches 1.8e308).
MAX_INTEGER_DIGITS = 300

# --- the YAML reader -------------------------------------------------------------------

_TAG = 'tag:yaml.org,2002:'
_NULLS = frozenset(('', '~', 'null', 'Null', 'NULL'))
_BOOLS = {'true': True, 'True': True, 'TRUE': True,
          'false': False, 'False': False, 'FALSE': False}
# The YAML 1.2 core schema's numbers (https://yaml.org/spec/1.2.2/#1032-tag-resolution).
_INT = re.compile(r'[-+]?[0-9]+\Z')
_INT_BASE = re.compile(r'0(?:o[0-7]+|x[0-9a-fA-F]+)\Z')
_FLOAT = re.compile(r'[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?\Z')
_INF = re.compile(r'[-+]?\.(?:inf|Inf|INF)\Z')
_NAN = re.compile(r'\.(?:nan|NaN|NAN)\Z')
_LEADING_ZERO = re.compile(r'[-+]?0[0-9]')
_NUMBER_START = frozenset('0123456789+-.')
# How YAML 1.1 (PyYAML's resolver) reads a plain scalar, to refuse the ones it
# reads as a boolean, a number or a merge key while YAML 1.2 reads them otherwise.
_YAML11 = yaml.resolver.Resolver.yaml_implicit_resolvers
_YAML11_ONLY = {
    f'{_TAG}bool': 'a boolean in YAML 1.1, text in 1.2: write true or false, or quote it',
    f'{_TAG}int': 'a number in YAML 1.1 only (digit separators, base 60 or 0b): write it '
                  'in decimal, or quote it',
    f'{_TAG}float': 'a number in YAML 1.1 only (digit separators or base 60): write it in '
                    'decimal, or quote it',
    f'{_TAG}merge': 'a YAML 1.1 merge key: write the keys out',
}
_INTEGER_BOUND = 10 ** MAX_INTEGER_DIGITS
_NO_KEY = object()
_BRIEF = reprlib.Repr()
_BRIEF.maxstring = _BRIEF.maxother = 60
_BRIEF.maxlist = _BRIEF.maxdict = 4
_BRIEF.maxlevel = 2


def _join(where: str, key: str) -> str:
    """Return the key path ``where`` followed by ``key`` (``a.b``, ``a[0]``)."""
    if not where or not key:
        return where or key
    return f'{where}{key}' if key.startswith('[') else f'{where}.{key}'


def _brief(value: Any) -> str:
    """Return ``repr(value)``, shortened for a one-line message."""
    return _BRIEF.repr(value)


def _at(mark: Any) -> str:
    return f'line {mark.line + 1}, column {mark.column + 1}'


def _tag_name(tag: str) -> str:
    return f'!!{tag[len(_TAG):]}' if tag.startswith(_TAG) else tag


class _Frame:
    """An open list or mapping while a document is built."""

    __slots__ = ('value', 'anchor', 'start', 'key', 'key_mark', 'marks', 'depth')

    def __init__(self, value: Any, anchor: str | None, start: int) -> None:
        self.value = value
        self.anchor = anchor
        self.start = start  # node count when it opened
        self.key: Any = _NO_KEY  # a mapping's pending key
        self.key_mark: Any = None
        self.marks: dict[str, Any] = {}  # a mapping's keys -> where each was given
        self.depth = 1  # of the subtree so far, with aliases expanded


class _SceneBuilder:
    """Build one YAML document from parser events: YAML 1.2 scalars, bounded, iterative.

    Mixed into a PyYAML loader in place of its composer, constructor and
    resolver (which build a node graph first, resolve YAML 1.1 and recurse per
    nesting level). Aliases share the anchored object, as PyYAML's do; the
    node count and depth are those of the document with every alias expanded.
    """

    get_event: Callable[[], Any]

    def get_single_data(self) -> Any:
        """Return the one document of the stream (``None`` if there is none)."""
        self._nodes = 0
        self._anchors: dict[str, tuple[Any, int, int]] = {}  # -> (value, nodes, depth)
        self._open: set[str] = set()
        self._stack: list[_Frame] = []
        self._root: Any = None
        self._plains: dict[str, Any] = {}  # plain scalars resolved so far, by text
        documents = 0
        get_event = self.get_event
        while True:
            event = get_event()
            kind = type(event)
            if kind is ScalarEvent:
                self._scalar(event)
            elif kind is MappingStartEvent or kind is SequenceStartEvent:
                self._start(event, {} if kind is MappingStartEvent else [])
            elif kind is MappingEndEvent or kind is SequenceEndEvent:
                self._end(event)
            elif kind is AliasEvent:
                self._alias(event)
            elif kind is DocumentStartEvent:
                documents += 1
                if documents > 1:
                    self._fail(event, 'expected a single document in the stream, got more')
            elif kind is StreamEndEvent:
                return self._root
            elif kind is not DocumentEndEvent and kind is not StreamStartEvent:
                self._fail(event, f'unexpected YAML event {kind.__name__}')

    # -- events --

    def _scalar(self, event: Any) -> None:
        self._count(1, event)
        if event.tag is None and event.implicit[0]:
            value = self._plains.get(event.value, _NO_KEY)
            if value is _NO_KEY:
                value = self._plains[event.value] = self._plain(event, event.value)
        else:
            value = self._resolve(event)
        if event.anchor is not None:
            self._check_anchor(event)
            self._anchors[event.anchor] = (value, 1, 0)
        self._add(value, event, 0)

    def _start(self, event: Any, value: Any) -> None:
        frame = self._stack[-1] if self._stack else None
        if frame is not None and isinstance(frame.value, dict) and frame.key is _NO_KEY:
            kind = 'mapping' if isinstance(value, dict) else 'list'
            self._fail(event, f'expected a text key, got a {kind}')
        tag = event.tag
        expected = f'{_TAG}map' if isinstance(value, dict) else f'{_TAG}seq'
        if tag is not None and tag != '!' and tag != expected:
            self._fail(event, f'expected a standard tag, got {_tag_name(tag)}')
        if len(self._stack) >= MAX_DEPTH:
            self._fail(event, f'expected lists and mappings nested at most {MAX_DEPTH} deep '
                              f'(MAX_DEPTH), got deeper')
        self._count(1, event)
        if event.anchor is not None:
            self._check_anchor(event)
            self._open.add(event.anchor)
        self._stack.append(_Frame(value, event.anchor, self._nodes - 1))

    def _end(self, event: Any) -> None:
        frame = self._stack.pop()
        nodes = self._nodes - frame.start
        if frame.anchor is not None:
            self._open.discard(frame.anchor)
            self._anchors[frame.anchor] = (frame.value, nodes, frame.depth)
        self._add(frame.value, event, frame.depth)

    def _alias(self, event: Any) -> None:
        name = event.anchor
        if name in self._open:
            self._fail(event, f'expected an alias to a complete node, got *{name} inside '
                              f'&{name} (a recursive alias)')
        if name not in self._anchors:
            self._fail(event, f'expected an alias to an anchor defined before it, got '
                              f'undefined *{name}')
        value, nodes, depth = self._anchors[name]
        if len(self._stack) + depth > MAX_DEPTH:
            self._fail(event, f'expected lists and mappings nested at most {MAX_DEPTH} deep '
                              f'(MAX_DEPTH), got deeper through alias *{name}')
        self._count(nodes, event)
        self._add(value, event, depth)

    # -- helpers --

    def _add(self, value: Any, event: Any, depth: int) -> None:
        if not self._stack:
            self._root = value
            return
        frame = self._stack[-1]
        if depth >= frame.depth:
            frame.depth = depth + 1
        container = frame.value
        if type(container) is list:
            container.append(value)
            return
        if frame.key is _NO_KEY:
            if type(value) is not str:
                written = event.value if type(event) is ScalarEvent else value
                self._fail(event, f'expected a text key, got {_kind_of(value)} '
                                  f'{_brief(written)}', ' (quote it if it is a name)')
            previous = frame.marks.get(value)
            if previous is not None:
                self._fail(event, f'expected each key once, got {_brief(value)} again',
                           f' (first at {_at(previous)})')
            frame.key, frame.key_mark = value, event.start_mark
            return
        frame.marks[frame.key] = frame.key_mark
        container[frame.key] = value
        frame.key = _NO_KEY

    def _count(self, nodes: int, event: Any) -> None:
        self._nodes += nodes
        if self._nodes > MAX_YAML_NODES:  # a bound on the document with aliases expanded
            self._fail(event, f'expected at most {MAX_YAML_NODES} YAML nodes with aliases '
                              f'expanded (MAX_YAML_NODES), got more')

    def _check_anchor(self, event: Any) -> None:
        if event.anchor in self._anchors or event.anchor in self._open:
            self._fail(event, f'expected each anchor once, got &{event.anchor} again')

    def _resolve(self, event: Any) -> Any:
        text = event.value
        tag = event.tag
        if tag is None:
            return self._plain(event, text) if event.implicit[0] else text
        if tag == '!' or tag == f'{_TAG}str':
            return text
        value = self._plain(event, text)
        if tag == f'{_TAG}null' and value is None or tag == f'{_TAG}bool' and \
                isinstance(value, bool):
            return value
        if tag == f'{_TAG}int' and type(value) is int:
            return value
        if tag == f'{_TAG}float' and type(value) in (int, float):
            return float(value)
        if tag in (f'{_TAG}null', f'{_TAG}bool', f'{_TAG}int', f'{_TAG}float'):
            self._fail(event, f'expected a {_tag_name(tag)[2:]} after {_tag_name(tag)}, '
                              f'got {_brief(text)}')
        self._fail(event, f'expected a standard tag, got {_tag_name(tag)}')

    def _plain(self, event: Any, text: str) -> Any:
        """Resolve a plain scalar by the YAML 1.2 core schema."""
        if text in _NULLS:
            return None
        if text in _BOOLS:
            return _BOOLS[text]
        if text[0] in _NUMBER_START:
            if _INT.match(text):
                if _LEADING_ZERO.match(text):
                    self._fail(event, f'expected a number without a leading zero, got '
                                      f'{_brief(text)}', ' (octal in YAML 1.1, decimal in 1.2)')
                return self._integer(event, text, text.lstrip('+-'), 10)
            if _INT_BASE.match(text):
                return self._integer(event, text[2:], text[2:], 8 if text[1] == 'o' else 16)
            if _FLOAT.match(text):
                return float(text)
            if _INF.match(text):
                return -math.inf if text[0] == '-' else math.inf
            if _NAN.match(text):
                return math.nan
        for tag, regexp in _YAML11.get(text[0], ()):
            if regexp.match(text):
                if tag in _YAML11_ONLY:
                    self._fail(event, f'expected a value that YAML 1.1 and 1.2 read alike, '
                                      f'got {_brief(text)}', f' ({_YAML11_ONLY[tag]})')
                break
        return text

    def _integer(self, event: Any, text: str, digits: str, base: int) -> int:
        value = int(text, base) if len(digits) <= MAX_INTEGER_DIGITS else None
        if value is None or abs(value) >= _INTEGER_BOUND:
            self._fail(event, f'expected an integer of at most {MAX_INTEGER_DIGITS} decimal '
                              f'digits (MAX_INTEGER_DIGITS), got {_brief(text)}')
        return value

    def _fail(self, event: Any, problem: str, note: str = '') -> NoReturn:
        raise SceneError(f'{self._where()}: {problem} at {_at(event.start_mark)}{note}')

    def _where(self) -> str:
        """Return the key path of the node being read, e.g. ``dyads[2].links``."""
        path = ''
        for frame in self._stack:
            if type(frame.value) is list:
                path += f'[{len(frame.value)}]'
            elif frame.key is not _NO_KEY:
                path = _join(path, _BRIEF.repr_str(frame.key, 0)[1:-1])
        if len(path) > 80:
            path = f'{path[:60]}...{path[-16:]}'
        return path or 'scene'


def _kind_of(value: Any) -> str:
    return {type(None): 'null', bool: 'a boolean', int: 'a number',
            float: 'a number'}.get(type(value), type(value).__name__)


class SceneLoader(_SceneBuilder, yaml.SafeLoader):
    """A PyYAML safe loader that reads scene files: YAML 1.2 scalars, bounded, strict.

    ``yaml.load(text, Loader=SceneLoader)`` returns plain dicts, lists,
    strings, numbers, booleans and ``None`` and raises :class:`SceneError`
    (naming the key path, the line and the column) for a duplicate key, a key
    that is not text, a YAML 1.1-only scalar, an unsupported tag or a node
    beyond the limits; malformed YAML raises ``yaml.YAMLError`` as usual.
    """


if getattr(yaml, '__with_libyaml__', False):
    class CSceneLoader(_SceneBuilder, yaml.CSafeLoader):
        """:class:`SceneLoader` on libyaml's parser (the same results, faster)."""

    _FAST_LOADER: type = CSceneLoader
else:  # pragma: no cover - PyYAML built without libyaml
    _FAST_LOADER = SceneLoader


def read_scene_yaml(text: str) -> Any:
    """Parse the text of a scene file with the scene loader's YAML dialect and limits.

    Raises
    ------
    SceneError
        For YAML that is malformed, ambiguous between YAML 1.1 and 1.2, or
        beyond a limit, naming the line and column.
    """
    try:
        return yaml.load(text, Loader=_FAST_LOADER)  # noqa: S506 - a safe loader
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark
        at = f' at line {mark.line + 1}, column {mark.column + 1}' if mark else ''
        problem = ' '.join((error.problem or str(error)).split())
        raise SceneError(f'invalid YAML{at}: {problem}') from None
    except yaml.reader.ReaderError as error:
        character = error.character
        what = f'#x{character:04x}' if isinstance(character, int) else repr(character)
        msg = f'invalid YAML: {error.reason} {what} at offset {error.position}'
        raise SceneError(msg) from None
    except yaml.YAMLError as error:
        raise SceneError(f'invalid YAML: {" ".join(str(error).split())}') from None
