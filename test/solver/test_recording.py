# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The recording value (:mod:`mech_kinematics.solver.recording`), issue 45.

A function written from a recorded run must compute what the run computed,
by Python's own arithmetic: every value bit for bit where no identity is
taken (the operations are the same, in the same order), up to the sign of a
zero where a sum with an exact zero or a product by zero or one is left out,
and never a finite answer where a factor left out was not finite. A decision
the run took on a value is a guard: another instant that would decide
otherwise is handed back (``False``; arrays: out of the mask).
"""

from __future__ import annotations

import math
import struct

from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from mech_kinematics.solver.recording import Recorder, Unrecordable

FUNCTIONS = {'biggest': (max, np.fmax, '{1} if {1} > {0} else {0}')}
SETTINGS = settings(max_examples=200, deadline=None)

#: Doubles that are neither 0 nor 1 in magnitude (no identity applies to them).
PLAIN = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6,
                  max_value=1e6).filter(lambda x: abs(x) not in (0.0, 1.0))
#: One step of a program: an operation, two operands (indices of values so far or a
#: constant) and whether the constant comes first.
STEP = st.tuples(st.sampled_from(['+', '-', '*', '/', 'neg', 'abs', 'max']),
                 st.integers(0, 30), st.integers(0, 30), st.booleans())


def _run(program, values, constants):
    """Run a program over ``values`` (numbers or Recs) and ``constants``; return every value."""
    values = list(values)
    for (op, i, j, constant_first), constant in zip(program, constants, strict=True):
        a = values[i % len(values)]
        b = constant if j % 3 == 0 else values[j % len(values)]
        if constant_first:
            a, b = b, a
        if op == '+':
            values.append(a + b)
        elif op == '-':
            values.append(a - b)
        elif op == '*':
            values.append(a * b)
        elif op == '/':
            values.append(a / b)
        elif op == 'neg':
            values.append(-a if j % 2 else -(-a))
        elif op == 'abs':
            values.append(abs(a))
        else:
            values.append(_biggest(a, b))
    return tuple(values)


_biggest = max


def _bits(x):
    return struct.pack('<d', x)


def _record(program, inputs, constants, vector=False):
    """Return the function written from a run of ``program`` at ``inputs``, and that run."""
    global _biggest
    recorder = Recorder(vector, FUNCTIONS)
    state = recorder.reader('state', list(inputs))
    _biggest = recorder.function('biggest')
    try:
        recorded = _run(program, [state[i] for i in range(len(inputs))], constants)
    finally:
        _biggest = max
    return recorder.written(recorded, 'f', '<test>'), recorder


@SETTINGS
@given(program=st.lists(STEP, min_size=1, max_size=25), data=st.data(),
       inputs=st.lists(PLAIN, min_size=1, max_size=4))
def test_a_written_function_computes_what_the_run_computed_bit_for_bit(program, data, inputs):
    """Without identities, a program written out gives every value's bits at other inputs."""
    constants = data.draw(st.lists(PLAIN, min_size=len(program), max_size=len(program)))
    others = data.draw(st.lists(PLAIN, min_size=len(inputs), max_size=len(inputs)))
    try:
        _run(program, inputs, constants)
        want = _run(program, others, constants)
    except (ZeroDivisionError, OverflowError):
        return
    function, recorder = _record(program, inputs, constants)
    got = function(others, 0.0)
    if got is False:   # a factor left out by a zero was not finite there
        assert recorder.identities
        return
    assert len(got) == len(want)
    for a, b in zip(got, want, strict=True):
        if recorder.identities:     # a constant the program made 0 or 1: up to a zero's sign
            assert a == b or (math.isnan(a) and math.isnan(b))
        else:
            assert _bits(a) == _bits(b) or (math.isnan(a) and math.isnan(b))


@SETTINGS
@given(program=st.lists(STEP, min_size=1, max_size=25), data=st.data(),
       inputs=st.lists(PLAIN, min_size=1, max_size=4))
def test_an_array_written_out_computes_each_instants_values(program, data, inputs):
    """The array path of the same run gives what the run gives on the arrays, instant by instant.

    The run on arrays (NumPy's operations, ``numpy.fmax`` for max) is the
    general array path; the function is written from one instant's run.
    """
    global _biggest
    constants = data.draw(st.lists(PLAIN, min_size=len(program), max_size=len(program)))
    rows = data.draw(st.lists(st.lists(PLAIN, min_size=len(inputs), max_size=len(inputs)),
                              min_size=1, max_size=5))
    try:
        _run(program, inputs, constants)
    except (ZeroDivisionError, OverflowError):
        return
    columns = [np.array(column) for column in zip(*rows, strict=True)]
    _biggest = np.fmax
    try:
        with np.errstate(all='ignore'):
            wants = _run(program, columns, constants)
    finally:
        _biggest = max
    with np.errstate(all='ignore'):    # the recorded run's numbers are NumPy's here
        function, recorder = _record(program, inputs, constants, vector=True)
        got, ok = function(columns, 0.0)
    ok = np.broadcast_to(ok, (len(rows),))
    for value, expected in zip(got, wants, strict=True):
        a = np.broadcast_to(value, (len(rows),))[ok]
        b = np.broadcast_to(expected, (len(rows),))[ok]
        if recorder.identities:     # a constant the program made 0 or 1: up to a zero's sign
            np.testing.assert_array_equal(a, b)
        else:
            assert a.tobytes() == b.astype(a.dtype).tobytes() or \
                np.array_equal(a, b, equal_nan=True) and not np.any(a == 0)


@pytest.mark.parametrize('zero', [0.0, -0.0, 0, 0j])
def test_a_sum_with_zero_and_a_product_by_one_are_the_other_operand(zero):
    """``x + 0``, ``x - 0``, ``0 + x``, ``x * 1``, ``x / 1``: no operation, the value itself."""
    recorder = Recorder(False, {})
    x = recorder.reader('state', [2.5])[0]
    if isinstance(zero, complex):     # a complex zero would make a real x complex: kept
        assert (x + zero).name != x.name
        return
    for same in (x + zero, zero + x, x - zero, x * 1.0, 1.0 * x, x / 1.0, x * 1):
        assert same is x
    assert (-1.0 * x).value == -2.5 and (zero - x).value == -2.5


def test_a_product_by_zero_is_zero_where_the_other_factor_is_finite():
    """``0.0 * x`` is left out, and the function defers where ``x`` is not finite."""
    recorder = Recorder(False, {})
    state = recorder.reader('state', [2.5, 4.0])
    x, y = state[0], state[1]
    result = (y + 0.0 * x, y * 2.0)
    function = recorder.written(result, 'f', '<test>')
    assert ' 0.0 * ' not in function.source
    assert function([7.0, 3.0], 0.0) == (3.0, 6.0)
    for bad in (math.inf, -math.inf, math.nan):
        assert function([bad, 3.0], 0.0) is False
    vector = Recorder(True, {})
    state = vector.reader('state', [2.5, 4.0])
    function = vector.written((state[1] + 0.0 * state[0],), 'f', '<test>')
    with np.errstate(all='ignore'):
        (value,), ok = function([np.array([1.0, np.inf, 2.0]), np.array([5.0, 5.0, 5.0])],
                                0.0)
    np.testing.assert_array_equal(ok, [True, False, True])
    np.testing.assert_array_equal(value, [5.0, 5.0, 5.0])


def test_a_decision_on_a_value_is_a_guard():
    """``if x > 1`` taken while recording: another value that decides otherwise is handed back."""
    recorder = Recorder(False, {})
    x = recorder.reader('state', [2.0])[0]
    result = x * 3.0 if x > 1.0 else -x
    function = recorder.written(result, 'f', '<test>')
    assert function([5.0], 0.0) == 15.0
    assert function([0.5], 0.0) is False
    vector = Recorder(True, {})
    x = vector.reader('state', [2.0])[0]
    function = vector.written(x * 3.0 if x > 1.0 else -x, 'f', '<test>')
    value, ok = function([np.array([5.0, 0.5, 1.5])], 0.0)
    np.testing.assert_array_equal(ok, [True, False, True])
    np.testing.assert_array_equal(value[ok], [15.0, 4.5])


def test_the_same_operation_and_each_read_are_written_once():
    """A repeated operation on the same values, and a repeated read, are one statement."""
    recorder = Recorder(False, {})
    state = recorder.reader('state', {'p': [1.5, 2.5]})
    a, b = state['p'][0], state['p'][1]
    assert state['p'][0] is a      # the reader's children are remembered
    result = (abs(a * b), abs(a * b), -(-a))
    function = recorder.written(result, 'f', '<test>')
    assert function.source.count('abs(') == 1 and function.source.count("['p']") == 1
    assert result[2] is a
    assert function({'p': [3.0, -2.0]}, 0.0) == (6.0, 6.0, 3.0)


def test_what_cannot_be_recorded_is_refused_by_name():
    """A recorded value turned into a number (math.cos, float) raises Unrecordable."""
    recorder = Recorder(False, {})
    x = recorder.reader('state', [0.5])[0]
    with pytest.raises(Unrecordable, match=r'turned into a number outside the recorded'):
        math.cos(x)
    with pytest.raises(Unrecordable):
        float(x)
    with pytest.raises(TypeError):
        hash(x)
    with pytest.raises(Unrecordable, match='holds a object'):
        recorder.written(object(), 'f', '<test>')


def test_a_named_function_is_the_targets_own_and_folds_on_constants():
    """``biggest`` is written as max's test for one instant and as numpy.fmax for arrays."""
    recorder = Recorder(False, FUNCTIONS)
    biggest = recorder.function('biggest')
    assert biggest(2.0, 3.0) == 3.0     # constants: computed now
    x = recorder.reader('state', [1.0])[0]
    function = recorder.written(biggest(x, 2.0), 'f', '<test>')
    assert 'biggest' not in function.source
    assert function([5.0], 0.0) == 5.0 and function([-1.0], 0.0) == 2.0
    assert math.isnan(function([math.nan], 0.0))     # max(nan, 2.0) is nan, as here
    vector = Recorder(True, FUNCTIONS)
    x = vector.reader('state', [1.0])[0]
    function = vector.written(vector.function('biggest')(x, 2.0), 'f', '<test>')
    value, _ = function([np.array([5.0, np.nan])], 0.0)
    np.testing.assert_array_equal(value, np.fmax([5.0, np.nan], 2.0))
