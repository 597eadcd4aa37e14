# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A recording value: the general path's own operations, run once and written out.

The forces of an instant (:meth:`.forces.Dynamics._forces`) are stated once,
in plain Python over floats and complex numbers. To write them out as one
straight-line function per scene, that same code is run once on a
:class:`Recorder`'s values instead of numbers (as Pinocchio's code generation
runs its own algorithms on a recording scalar): a :class:`Rec` carries the
number the general path would hold *and* the name of a local of the function
being written, and every arithmetic operation on it (``+ - * /``, unary
minus, ``abs``, ``.real``, ``.imag``, comparisons, ``& | ^``) computes the
number and appends the same operation to the function. Whatever does not
depend on the instant (the graph's structure, the masses, the constants) is
computed while recording and enters the function as a constant: the loops,
dictionaries and structural zeros of the general path leave no trace.

Where the general path decides by a value (``if``, ``not``, ``and``, partial
pivoting's ``max`` of magnitudes: anything that asks a :class:`Rec` for its
truth), the recorder answers with the recorded instant's truth and writes a
*guard*: the written function checks it holds and otherwise returns
``False`` (one instant: the caller asks another function or the general
path), or leaves the instant out of the mask it returns (arrays). So the
function runs the general path's operations, in its order, on the values
it is given, wherever the general path would take the branches recorded:
the same bits, NaN and bounds included, up to the sign of a zero where an
identity left an operation out (a sum with an exact zero, a product by an
exact zero or one: :meth:`Recorder.identity`; the function checks that the
factors it left out are finite).

What the general path computes by another function on arrays than on one
instant (``max`` and ``numpy.fmax``, ``cmath``-like ``expi``) is a named
function (:meth:`Recorder.function`) that the recorder writes as a call to
the target's own (the function for one instant or for arrays); its value
on constants is folded with it. A :class:`Rec` refuses what it cannot
record (``float()``, ``math.cos``): :class:`Unrecordable`, which the caller
reports as why the path is not written out; it has no hash.

Inputs are read through :meth:`Recorder.reader`: attribute and item reads of
the state, each written once at its first use as a local of the function
(``P = state.complex_points``, ``B = P['B']``, ``x = B[0]``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
import dataclasses
import math
import operator
import re
from typing import Any

import numpy as np

__all__ = ['Rec', 'Recorder', 'Unrecordable']

#: The numbers a state's leaf may hold (read as inputs).
_NUMBERS = (float, int, complex, np.floating, np.complexfloating, np.integer, np.bool_)


#: A local of a written function (how a value's name is found in an expression).
_NAME = re.compile(r'\bv\d+\b')
#: How deep values read once are written into one expression (Python's parser nests 200).
_DEPTH = 12


class Unrecordable(TypeError):
    """An operation a :class:`Rec` cannot record (a conversion to a number, a hash)."""


class Rec:
    """A recorded value: the number the general path holds and the local that will hold it."""

    __slots__ = ('_recorder', 'name', 'value')
    #: NumPy hands every operation with a Rec back to Python's (then to this class's).
    __array_ufunc__ = None
    __hash__ = None     # type: ignore[assignment]

    def __init__(self, recorder: Recorder, name: str, value: Any) -> None:
        self._recorder = recorder
        self.name = name
        self.value = value

    def __repr__(self) -> str:
        return f'Rec({self.name}={self.value!r})'

    def _binary(self, symbol: str, other: Any, reflected: bool = False) -> Any:
        function = _BINARY[symbol]
        if isinstance(other, Rec):
            a, b, ta, tb = self.value, other.value, self.name, other.name
            deps: tuple[str, ...] = (self.name, other.name)
        elif isinstance(other, _NUMBERS):
            same = self._recorder.identity(symbol, self, other, reflected)
            if same is not None:
                return same
            a, b, ta, tb = self.value, other, self.name, self._recorder.const(other)
            deps = (self.name,)
        else:
            return NotImplemented
        if reflected:
            a, b, ta, tb = b, a, tb, ta
        return self._recorder.let(f'{ta} {symbol} {tb}', function(a, b), deps)

    def __add__(self, other: Any) -> Any:
        return self._binary('+', other)

    def __radd__(self, other: Any) -> Any:
        return self._binary('+', other, True)

    def __sub__(self, other: Any) -> Any:
        return self._binary('-', other)

    def __rsub__(self, other: Any) -> Any:
        return self._binary('-', other, True)

    def __mul__(self, other: Any) -> Any:
        return self._binary('*', other)

    def __rmul__(self, other: Any) -> Any:
        return self._binary('*', other, True)

    def __truediv__(self, other: Any) -> Any:
        return self._binary('/', other)

    def __rtruediv__(self, other: Any) -> Any:
        return self._binary('/', other, True)

    def __and__(self, other: Any) -> Any:
        return self._binary('&', other)

    def __rand__(self, other: Any) -> Any:
        return self._binary('&', other, True)

    def __or__(self, other: Any) -> Any:
        return self._binary('|', other)

    def __ror__(self, other: Any) -> Any:
        return self._binary('|', other, True)

    def __xor__(self, other: Any) -> Any:
        return self._binary('^', other)

    def __rxor__(self, other: Any) -> Any:
        return self._binary('^', other, True)

    def __lt__(self, other: Any) -> Any:
        return self._binary('<', other)

    def __le__(self, other: Any) -> Any:
        return self._binary('<=', other)

    def __gt__(self, other: Any) -> Any:
        return self._binary('>', other)

    def __ge__(self, other: Any) -> Any:
        return self._binary('>=', other)

    def __eq__(self, other: Any) -> Any:  # type: ignore[override]
        return self._binary('==', other)

    def __ne__(self, other: Any) -> Any:  # type: ignore[override]
        return self._binary('!=', other)

    def __neg__(self) -> Rec:
        negated = self._recorder.negated.get(self.name)
        if negated is not None:     # -(-x) is x, bit for bit
            return negated
        result = self._recorder.let(f'-{self.name}', -self.value, (self.name,))
        self._recorder.negated[result.name] = self
        return result

    def __abs__(self) -> Rec:
        return self._recorder.let(f'abs({self.name})', abs(self.value), (self.name,))

    @property
    def real(self) -> Rec:
        """The real part, recorded."""
        return self._recorder.let(f'{self.name}.real', self.value.real, (self.name,))

    @property
    def imag(self) -> Rec:
        """The imaginary part, recorded."""
        return self._recorder.let(f'{self.name}.imag', self.value.imag, (self.name,))

    def __bool__(self) -> bool:
        truth = bool(self.value)
        self._recorder.guard(self.name, truth)
        return truth

    def _refuse(self, *_: Any) -> Any:
        raise Unrecordable(f'a recorded value ({self.name}) was turned into a number outside '
                           f'the recorded operations')

    __float__ = __complex__ = __int__ = __index__ = _refuse


_BINARY: dict[str, Callable[[Any, Any], Any]] = {
    '+': operator.add, '-': operator.sub, '*': operator.mul, '/': operator.truediv,
    '&': operator.and_, '|': operator.or_, '^': operator.xor, '<': operator.lt,
    '<=': operator.le, '>': operator.gt, '>=': operator.ge, '==': operator.eq,
    '!=': operator.ne}


class _Reader:
    """The state read through the recorder: each attribute or item read once, as a local."""

    __slots__ = ('_recorder', '_text', '_value', '_name', '_children')

    def __init__(self, recorder: Recorder, text: str, value: Any, name: str | None = None
                 ) -> None:
        self._recorder = recorder
        self._text = text       # how the parent's local reads it
        self._value = value
        self._name = name       # its own local, once a child is read
        self._children: dict[str, Any] = {}

    def _child(self, suffix: str, value: Any) -> Any:
        child = self._children.get(suffix)
        if child is not None:
            return child
        if self._name is None:
            self._name = self._recorder.let(self._text, None, ()).name
            self._recorder.keep(self._name)
        if isinstance(value, _NUMBERS):
            child = self._recorder.let(f'{self._name}{suffix}', value, (self._name,))
        elif value is None or isinstance(value, str):
            child = value
        else:
            child = _Reader(self._recorder, f'{self._name}{suffix}', value)
        self._children[suffix] = child
        return child

    def __getitem__(self, key: Any) -> Any:
        return self._child(f'[{key!r}]', self._value[key])

    def __getattr__(self, name: str) -> Any:
        if name.startswith('__'):
            raise AttributeError(name)
        return self._child(f'.{name}', getattr(self._value, name))

    def __contains__(self, key: Any) -> bool:
        return key in self._value

    def __len__(self) -> int:
        return len(self._value)


class Recorder:
    """The function being written: its statements, guards, constants and named functions.

    Parameters
    ----------
    vector : bool
        Write the array path: a guard narrows the mask ``ok`` the function
        returns beside its value, instead of returning ``False``.
    functions : mapping of str to (callable, callable, str or None)
        The named functions (:meth:`function`): each for one instant and for
        arrays, and how one instant's is written in place (a format of its
        arguments, ``'{1} if {1} > {0} else {0}'`` for ``max``), or None.
    names : mapping of str to object, optional
        What those formats call (``cos`` and ``sin``, say).
    """

    def __init__(self, vector: bool,
                 functions: dict[str, tuple[Callable[..., Any], Callable[..., Any],
                                            str | None]],
                 names: dict[str, Any] | None = None) -> None:
        self.vector = vector
        # (target or None for a guard, expression, operands or truth)
        self._lines: list[tuple[str | None, str, Any]] = []
        self._namespace: dict[str, Any] = {}
        self._constants: dict[tuple[str, str], str] = {}
        self._count = 0
        self._kept: set[str] = set()
        self._finite: dict[str, None] = {}  # operands an identity took as finite
        self._same: dict[str, Rec] = {}     # each expression's value, recorded once
        #: How many arithmetic operations an identity left out (:meth:`identity`).
        self.identities = 0
        #: The value each negation negates (``-(-x)`` is ``x``).
        self.negated: dict[str, Rec] = {}
        self._functions = {name: entry[1 if vector else 0] for name, entry in functions.items()}
        self._inline = {name: entry[2] for name, entry in functions.items()
                        if entry[2] is not None and not vector}
        self._namespace.update(self._functions, **(names or {}))

    # --- recording -------------------------------------------------------------------

    def const(self, value: Any) -> str:
        """Return how the function writes a constant (a literal, or a name it holds)."""
        kind = type(value)
        if kind is bool or (kind is int and value >= 0):
            return repr(value)
        if kind is float and math.isfinite(value) and math.copysign(1.0, value) > 0:
            return repr(value)
        key = (kind.__name__, repr(value))
        name = self._constants.get(key)
        if name is None:
            name = self._constants[key] = f'K{len(self._constants)}'
            self._namespace[name] = value
        return name

    def let(self, expression: str, value: Any, operands: Sequence[str]) -> Rec:
        """Return a new value: a local bound to ``expression`` (of the locals ``operands``)."""
        same = self._same.get(expression)
        if same is not None:    # the same operation on the same values: the same bits
            return same
        name = f'v{self._count}'
        self._count += 1
        self._lines.append((name, expression, tuple(operands)))
        result = self._same[expression] = Rec(self, name, value)
        return result

    def identity(self, symbol: str, value: Rec, constant: Any, reflected: bool) -> Any:
        """Return what ``value symbol constant`` is without an operation, or None.

        A sum with an exact zero is the other term, a product by an exact
        zero that zero, a product by one the other factor: exact (``x - 0.0``,
        ``x * 1.0`` of a real) or up to the sign of a zero where the other
        operand is finite, which the function checks once, at its end, of
        every operand a product by zero or a complex one's left out (a sum of
        them all, finite: a NaN or an infinity in any makes it defer).
        """
        if type(constant) is bool:     # True & x, False | x: x, of a truth
            truth = isinstance(value.value, (bool, np.bool_))
            return value if truth and ((symbol == '&' and constant)
                                       or (symbol == '|' and not constant)) else None
        if symbol not in '+-*/':
            return None
        same = self._identity(symbol, value, constant, reflected)
        if same is not None:
            self.identities += 1
        return same

    def _identity(self, symbol: str, value: Rec, constant: Any, reflected: bool) -> Any:
        real = not isinstance(value.value, (complex, np.complexfloating))
        if isinstance(constant, (complex, np.complexfloating)):
            if constant.imag != 0.0 or real:     # a complex result from a real: its type
                return None
            constant = constant.real
        if symbol == '+' or (symbol == '-' and not reflected):
            return value if constant == 0 else None
        if symbol == '-':
            return -value if constant == 0 else None
        if symbol == '/':
            return value if constant == 1 and not reflected and real else None
        if constant == 0:
            self._finite[value.name] = None
            return _BINARY[symbol](constant, value.value) if reflected else \
                _BINARY[symbol](value.value, constant)
        if constant == 1:
            if not real:
                self._finite[value.name] = None
            return value
        if constant == -1 and real:
            return -value
        return None

    def keep(self, name: str) -> None:
        """Keep a local whatever reads it (a reader's, read by its children's text)."""
        self._kept.add(name)

    def guard(self, name: str, truth: bool) -> None:
        """Write that the local ``name`` must have the recorded instant's truth."""
        self._lines.append((None, name, truth))

    def function(self, name: str) -> Callable[..., Any]:
        """Return the named function recorded: a call where an argument is recorded.

        On constants alone it is computed now, by the target's own function.
        """
        target = self._functions[name]

        def recorded(*args: Any) -> Any:
            if not any(isinstance(a, Rec) for a in args):
                return target(*args)
            values = [a.value if isinstance(a, Rec) else a for a in args]
            texts = [a.name if isinstance(a, Rec) else self.const(a) for a in args]
            operands = [a.name for a in args if isinstance(a, Rec)]
            inline = self._inline.get(name)
            text = f'{name}({", ".join(texts)})' if inline is None else inline.format(*texts)
            return self.let(text, target(*values), operands)

        return recorded

    def reader(self, name: str, value: Any) -> Any:
        """Return the function's parameter ``name`` (whose value is now ``value``), read lazily."""
        return _Reader(self, name, value, name)

    def parameter(self, name: str, value: Any) -> Rec:
        """Return the function's parameter ``name`` as a recorded value."""
        return Rec(self, name, value)

    # --- writing ---------------------------------------------------------------------

    def _built(self, value: Any, tail: list[str], used: set[str]) -> str:
        """Return the expression that builds ``value`` (writing its objects into ``tail``)."""
        if isinstance(value, Rec):
            used.add(value.name)
            return value.name
        if value is None or isinstance(value, str):
            return repr(value)
        if isinstance(value, _NUMBERS):
            return self.const(value)
        if isinstance(value, dict):
            items = [f'{self._built(k, tail, used)}: {self._built(v, tail, used)}'
                     for k, v in value.items()]
            return '{' + ', '.join(items) + '}'
        if isinstance(value, (tuple, list)):
            items = [self._built(v, tail, used) for v in value]
            text = ', '.join(items) + (',' if len(items) == 1 and isinstance(value, tuple)
                                       else '')
            return f'({text})' if isinstance(value, tuple) else f'[{text}]'
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            fields = ', '.join(f'{f.name}={self._built(getattr(value, f.name), tail, used)}'
                               for f in dataclasses.fields(value))
            name = f'o{len(tail)}'
            tail.append(f'{name} = new({self.const(type(value))})')
            tail.append(f'{name}.__dict__.update({fields})')
            return name
        raise Unrecordable(f'an answer holds a {type(value).__name__}, which is not written out')

    def source(self, result: Any, label: str) -> tuple[str, dict[str, Any]]:
        """Return the function's source (``label(state, max_error)``) and its namespace.

        ``result``: what the recorded run returned, with recorded values in it.
        Statements nothing reads (neither the result nor a guard) are left out.
        """
        tail: list[str] = []
        used: set[str] = set(self._kept) | set(self._finite)
        answer = self._built(result, tail, used)
        fixed = set(used)   # read by the answer, a reader's child or the finite test
        if self._finite:
            total = ' + '.join(self._finite)
            tail.insert(0, f'finite = {total}')
            tail.insert(1, 'ok = ok & (finite - finite == 0)' if self.vector
                        else 'if not finite - finite == 0: return False')
        for target, expression, operands in reversed(self._lines):
            if target is None:
                used.add(expression)
            elif target in used:
                used.update(operands)
        # A value read once (by one statement or one guard) is written where it is read, so
        # that its temporary goes at once (arrays: in the cache); consecutive guards are one
        # test. Python computes ``a + (b * c)`` as ``t = b * c; a + t``: the same bits.
        reads: dict[str, int] = {}
        for target, expression, _ in self._lines:
            if target is None:
                reads[expression] = reads.get(expression, 0) + 1
            elif target in used:
                for name in _NAME.findall(expression):
                    reads[name] = reads.get(name, 0) + 1
        once = {target for target, _, _ in self._lines if target is not None
                and target in used and reads.get(target) == 1 and target not in fixed}
        texts: dict[str, tuple[str, int]] = {}     # inlined value -> (text, depth)
        body: list[str] = ['ok = True'] if self.vector else []
        tests: list[str] = []
        for target, expression, operands in self._lines:
            if target is None:
                test = f'({texts.pop(expression, (expression, 0))[0]})'
                if self.vector:
                    body.append(f'ok = ok & ({test} {"!=" if operands else "=="} 0)')
                else:
                    tests.append(test if operands else f'not {test}')
                continue
            if target not in used:
                continue
            if tests:
                body.append(f'if not ({" and ".join(tests)}): return False')
                tests = []
            depth = 0
            for name in dict.fromkeys(operands):
                if name in texts:
                    text, inner = texts.pop(name)
                    expression = re.sub(rf'\b{name}\b', f'({text})', expression)
                    depth = max(depth, inner)
            if target in once and depth < _DEPTH:
                texts[target] = (expression, depth + 1)
            else:
                body.append(f'{target} = {expression}')
        if tests:
            body.append(f'if not ({" and ".join(tests)}): return False')
        body += tail
        body.append(f'return ({answer}, ok)' if self.vector else f'return {answer}')
        source = f'def {label}(state, max_error):\n' + ''.join(f'    {line}\n' for line in body)
        namespace = dict(self._namespace, new=object.__new__)
        return source, namespace

    def written(self, result: Any, label: str, filename: str) -> Callable[..., Any]:
        """Return the function :meth:`source` writes, compiled (its source on ``.source``)."""
        source, namespace = self.source(result, label)
        exec(compile(source, filename, 'exec'), namespace)  # noqa: S102
        function = namespace[label]
        function.source = source
        return function  # type: ignore[no-any-return]
