# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The specializer's constant propagation (issues 19 and 22): fewer operations, the same bits.

:func:`mech_kinematics.solver.specialize.propagate` folds what a scene's
generated code computes from constants. Every fold must give the value, the
type and the error the unfolded code gives for every input, signed zeros,
NaNs, infinities, ints, complex numbers and NumPy arrays included: the
property test runs random straight-line programs both ways.
"""

import ast
import math
import re

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.solver.base import Step
from mech_kinematics.solver.compiler import scene_plan
from mech_kinematics.solver.specialize import plan_body, propagate

SETTINGS = settings(max_examples=400, deadline=None, derandomize=True)


def _propagated(source, live=('out',), namespace=None):
    """Return the unparsed body of ``source`` after :func:`propagate`."""
    body = ast.parse(source).body
    return ast.unparse(ast.Module(propagate(body, namespace or {}, set(live)), []))


def _function(body, namespace, arguments='x'):
    """Return ``f(x)`` (or ``f(<arguments>)``) running ``body`` and returning its ``out``."""
    tree = ast.parse(f'def f({arguments}):\n    return out')
    tree.body[0].body[:0] = body
    exec(compile(ast.fix_missing_locations(tree), '<test>', 'exec'), namespace)  # noqa: S102
    return namespace['f']


def _facts(value):
    """Return what identifies ``value`` bit for bit: its type, and its bits or repr."""
    if isinstance(value, np.ndarray):
        return type(value), value.dtype, value.shape, value.tobytes()
    if isinstance(value, np.generic):
        return type(value), value.dtype, value.tobytes()
    if isinstance(value, float) and math.isnan(value):
        return float, 'nan'
    return type(value), repr(value)


def _run(function, x):
    """Return the facts of each value ``function(x)`` returns, or what it raised."""
    with np.errstate(all='ignore'):
        try:
            values = function(x)
        except (ArithmeticError, TypeError, ValueError) as error:
            return type(error), str(error)
    return [_facts(v) for v in values]


def test_constants_are_put_in_and_folded():
    """A local bound once to a constant is replaced where read; constant operations fold."""
    assert _propagated('a, b = (2.0, (1+0j))\n'
                       'c = a * 3.0 - b.real\n'
                       'out = x * c + abs(-b) + (a < 3.0)') == 'out = x * 5.0 + 1.0 + True'


def test_a_fold_that_raises_is_left_to_raise():
    """``1.0 / 0.0`` raises at run time: the division stays in place, and so does its binding."""
    assert _propagated('a = 1.0 / 0.0\nout = x') == 'a = 1.0 / 0.0\nout = x'


def test_a_signed_zero_folds_as_python_computes_it():
    """``-0.0 + 0.0`` is ``0.0`` in Python, and ``-(0.0)`` is ``-0.0``: the folds keep both."""
    assert _propagated('z = -0.0\nout = (x, z + 0.0, -(z + 0.0), z * -1.0)') == (
        'out = (x, 0.0, -0.0, 0.0)')


def test_bindings_read_twice_or_in_a_branch_are_not_constants():
    """A name bound twice, or only inside an if, keeps every read."""
    source = 'a = 1.0\nif x:\n    b = 2.0\na = 3.0\nout = a + b'
    assert _propagated(source) == source.replace('\n', '\n', 4)


def test_dead_bindings_go_only_where_nothing_is_lost():
    """A dead constant or name binding goes; a dead call, expression or live name stays."""
    source = ('k = 2.0\n'
              'y = x\n'
              'r = math.sqrt(x)\n'
              'np.cos(x, out=e.real)\n'
              'P = (k, x)\n'
              'out = x')
    assert _propagated(source, live=('out', 'P')) == (
        'r = math.sqrt(x)\nnp.cos(x, out=e.real)\nP = (2.0, x)\nout = x')


def test_a_tuple_binding_keeps_its_computed_entries():
    """``a, b = (1.0, f(x))``: the constant entry goes, the call stays."""
    assert _propagated('a, b = (1.0, f(x))\nout = a + b') == 'b = f(x)\nout = 1.0 + b'


def test_tuple_entries_are_read_from_locals():
    """``P[1]`` of ``P = (a, f(x), 1.0)`` reads the local computed first, in the same order."""
    assert _propagated('a = x.real\nP = (a, f(x), 1.0)\nQ = (0.0, 2.0)\n'
                       'out = (P[0], P[1], P[2], P[-1], P[5], Q[:1], Q[::0], P, P[1:], P[::2])'
                       ) == (
        'a = x.real\n_e0 = f(x)\nP = (a, _e0, 1.0)\n_e2 = P[5]\n_e3 = (0.0, 2.0)[::0]\n'
        '_e4 = (_e0, 1.0)\n_e5 = P[::2]\nout = (a, _e0, 1.0, 1.0, _e2, (0.0,), _e3, P, _e4, _e5)')


def test_an_unpacked_tuple_is_never_built():
    """``a, b = P`` of ``P = (f(x), g(x))`` reads the entries' locals; P is not built."""
    assert _propagated('P = (f(x), g(x))\nif x:\n    c = 1\nelse:\n    c = 2\n'
                       'a, b = P\nR = (a, c)\nd, e = R\nout = (b, a, e)') == (
        '_e0 = f(x)\n_e1 = g(x)\nif x:\n    c = 1\nelse:\n    c = 2\nout = (_e1, _e0, c)')


def test_ground_tuples_of_numbers_are_constants():
    """A ``_ground_*`` tuple of Python numbers is unpacked into constants; others are not."""
    namespace = {'_ground_P': ((1 + 0j), 0.5), '_ground_Q': (np.float64(1.0), 0.5)}
    assert _propagated('P = _ground_P\np, e = P\nQ = _ground_Q\nout = p + e + Q[1]',
                       live=('out', 'P', 'Q'), namespace=namespace) == (
        'P = ((1+0j), 0.5)\nQ = _ground_Q\nout = (1.5+0j) + Q[1]')


#: (program, vector, its ``out`` line after the identities): each rule at its edge.
IDENTITIES = [
    # A complex number times 1.0 is a complex multiplication: a signed zero can flip.
    ('z = complex(x.real, x.imag)\nout = [z * 1.0, 1.0 * z, z / 1.0, z * 1]', False,
     'out = [z * 1.0, 1.0 * z, z / 1.0, z * 1]'),
    ('f = x.real * 0.5\nout = [f * 1.0, 1 * f, f / 1.0, f - 0.0, f - 0, f * 1.0 * 1.0]', False,
     'out = [f, f, f, f, f, f]'),
    # z + -0.0 adds 0.0 to the imaginary part (-0.0 + 0.0 is 0.0); z - -0.0 adds 0.0.
    ('z = complex(x.real, x.imag)\nout = [z - 0.0, z - 0j, z + -0.0, z - -0.0, z - -0j]', False,
     'out = [z, z, z + -0.0, z - -0.0, z - (-0-0j)]'),
    ('f = x.real * 0.5\nout = [f - 0j, f + 0.0, 0.0 + f, 0.0 * f, f * -1.0]', False,
     'out = [f - 0j, f + 0.0, 0.0 + f, 0.0 * f, f * -1.0]'),
    # x.real and abs(x) may be ints: 1.0 * 3 is a float.
    ('r = x.real\nn = abs(x) * 2\nout = [r * 1.0, r - 0.0, n * 1.0, n / 2 * 1.0]', False,
     'out = [r * 1.0, r - 0.0, n * 1.0, n / 2]'),
    ('c = math.sqrt(abs(x.real))\nout = [c * 1.0, abs(c) * 1.0]', False, 'out = [c, abs(c)]'),
    # Arrays: an operand left bound to a second name would share its array.
    ('f = x.real * 0.5\ng = (f * 1.0) * 1.0\n'
     'out = [f * 1.0 + 2.0, g, -(f * 1.0), (f + 1.0) * 1.0]', True,
     'out = [f + 2.0, g, -f, f + 1.0]'),
]


@pytest.mark.parametrize(('source', 'vector', 'line'), IDENTITIES)
def test_identities_are_removed_only_where_exact(source, vector, line):
    """Each identity goes where it is the same bits for every input, and stays elsewhere."""
    body = propagate(ast.parse(source).body, {'math': math}, {'out'}, vector)
    assert ast.unparse(body[-1]) == line
    before = _function(ast.parse(source).body, {'math': math})
    after = _function(body, {'math': math})
    for x in ARGUMENTS:
        assert _run(after, x) == _run(before, x), (source, x)


#: Constants a fold meets: signed zeros, units, infinities, NaN, ints, complex numbers.
CONSTANTS = st.sampled_from([0.0, -0.0, 1.0, -1.0, 2.0, 0.5, 1e308, math.inf, -math.inf,
                             math.nan, 0, 1, 2, 0j, -0j, complex(-0.0, 0.0), 1 + 0j,
                             1j, complex(0.0, -0.0), complex(math.inf, 0.0), True])
#: Arguments of every type the generated code is called with, and more.
ARGUMENTS = [0.0, -0.0, 1.5, -2.0, math.inf, -math.inf, math.nan, 0, 3, True,
             complex(-0.0, -0.0), complex(0.0, -0.0), complex(1.5, -0.0), complex(-2.0, 0.0),
             complex(math.inf, -0.0), complex(math.nan, 1.0), np.float64(-0.0),
             np.array(-0.0), np.array(complex(-1.0, -0.0)),
             np.array([0.0, -0.0, 1.0, -math.inf, math.nan]),
             np.array([complex(-0.0, -0.0), complex(-1.0, 0.0), complex(math.inf, -0.0)]),
             np.array([1, -2]), np.array([0.5, -0.0], dtype=np.float32)]


def _literal(value):
    """Return source giving ``value``: a literal, or constants the propagation folds into it."""
    if isinstance(value, complex):
        return f'(-(-({_literal(value.real)}) - {_literal(value.imag)}j))'
    if isinstance(value, float) and not math.isfinite(value):
        return '(1e309 - 1e309)' if math.isnan(value) else '-1e309' if value < 0 else '1e309'
    return repr(value)


@st.composite
def programs(draw):
    """Return the source of a random straight-line program of ``x`` ending in ``out``."""
    names = ['x']
    lines = []

    def expression(depth):
        choice = draw(st.integers(0, 9 if depth < 3 else 1))
        if choice == 0:
            return _literal(draw(CONSTANTS))
        if choice == 1:
            return draw(st.sampled_from(names))
        if choice == 2:
            return f'-({expression(depth + 1)})'
        if choice == 3:
            return f'abs({expression(depth + 1)})'
        if choice == 4:
            return f'({expression(depth + 1)}).{draw(st.sampled_from(["real", "imag"]))}'
        if choice == 5:
            return f'complex(({expression(depth + 1)}).real, ({expression(depth + 1)}).real)'
        op = draw(st.sampled_from(['+', '-', '*', '/', '<']))
        return f'({expression(depth + 1)} {op} {expression(depth + 1)})'

    tuples = []
    for index in range(draw(st.integers(1, 6))):
        if tuples and draw(st.booleans()):
            lines.append(f'v{index} = {draw(st.sampled_from(tuples))}[{draw(st.integers(-2, 1))}]')
            names.append(f'v{index}')
        if draw(st.booleans()):
            lines.append(f't{index} = ({expression(0)}, {expression(0)})')
            tuples.append(f't{index}')
        if draw(st.booleans()):
            lines.append(f'v{index}, w{index} = ({expression(0)}, {expression(0)})')
            names += [f'v{index}', f'w{index}']
        else:
            lines.append(f'v{index} = {expression(0)}')
            names.append(f'v{index}')
    lines.append(f'out = ({", ".join(draw(st.lists(st.sampled_from(names), min_size=1)))},)')
    return '\n'.join(lines)


@SETTINGS
@given(source=programs())
def test_propagation_keeps_every_bit_type_and_error(source):
    """A random program of constants and ``x`` gives the same results before and after.

    Each program is propagated for both paths (single-angle and vector), drawn
    once: a test a path ran the same derandomized programs.
    """
    before = _function(ast.parse(source).body, {})
    expected = [_run(before, x) for x in ARGUMENTS]
    for vector in (False, True):
        after = _function(propagate(ast.parse(source).body, {}, {'out'}, vector), {})
        for x, facts in zip(ARGUMENTS, expected, strict=True):
            assert _run(after, x) == facts, (source, vector, x)


def _code(scene, vector):
    """Return the generated code of ``scene`` on one path, and its table entries' locals."""
    plan = scene_plan(mk.load_scene(scene))
    names = {}
    return ast.unparse(ast.Module(plan_body(plan, names, {}, vector=vector), [])), names


@pytest.mark.parametrize('vector', [False, True])
def test_the_yoke_keeps_no_constant_tuple_or_binding(vector):
    """The Scotch yoke's code binds no tuple of constants and no local to a bare constant."""
    code, names = _code('scotch_yoke', vector)
    assert '= ((1+0j), (6.123233995736766e-17+1j), 1.0, 1.0)' not in code
    live = set(names.values())
    for stmt in ast.parse(code).body:
        if not isinstance(stmt, ast.Assign) or {
                n.id for n in ast.walk(stmt.targets[0]) if isinstance(n, ast.Name)} <= live:
            continue        # a table entry the caller reads, a ground point's constants
        assert not isinstance(stmt.value, ast.Constant), ast.unparse(stmt)
        assert not (isinstance(stmt.value, ast.Tuple)
                    and any(isinstance(e, ast.Constant) for e in stmt.value.elts)), (
            ast.unparse(stmt))


@pytest.mark.parametrize('scene', ['scotch_yoke', 'khurmi_four_bar_ad150',
                                   'slider_crank_150_600'])
def test_single_angle_code_multiplies_by_no_one(scene):
    """The single-angle code holds no ``* 1.0``, ``1.0 *`` or ``- 0j`` (the yoke had 14)."""
    code, _ = _code(scene, False)
    assert not re.findall(r'(?<![\d.e-])1\.0 \*|\* 1\.0(?!\d)|- 0j', code), code


def test_array_operations_take_zero_d_constants_with_the_same_bits():
    """On the array path, a constant meeting an array of the angles becomes a 0-d array."""
    source = ('e = np.empty(np.shape(theta), dtype=np.complex128)\n'
              'np.cos(theta, out=e.real)\n'
              'np.sin(theta, out=e.imag)\n'
              'r = 0.05 * e\n'
              'w = abs(omega)\n'
              'd = np.hypot(r.real, r.imag)\n'
              'out = [r, 1j * omega * r, 2.5e-17 * w, (0.3 + d) / 2.0, 1j - r, w * 0.5, '
              'omega * 2.0, r.imag * -0.0, 1 * d, d > 0.04, 0.04 <= d, w > 0.5, d == 0.05]')
    namespace = {'np': np}
    body = propagate(ast.parse(source).body, namespace, {'out'}, vector=True)
    zero_d = {name for name, value in namespace.items() if isinstance(value, np.ndarray)}
    assert {namespace[name].item() for name in zero_d} == {0.05, 0.3, 2.0, 1j, -0.0, 0.04}
    assert all(namespace[name].ndim == 0 and not namespace[name].flags.writeable
               for name in zero_d)
    shown = re.sub(r'_z\d+', lambda m: f'Z({namespace[m.group()].item()!r})',
                   ast.unparse(body))
    # The operations on an array call NumPy's functions (_Ufuncs); those on scalars stay.
    assert '\nr = _np_multiply(Z(0.05), e)\n' in shown
    assert shown.splitlines()[-1] == (
        'out = [r, _np_multiply(1j * omega, r), 2.5e-17 * w, '
        '_np_true_divide(_np_add(Z(0.3), d), Z(2.0)), _np_subtract(Z(1j), r), w * 0.5, '
        'omega * 2.0, _np_multiply(r.imag, Z(-0.0)), _np_multiply(1, d), '
        '_np_greater(d, Z(0.04)), _np_less_equal(Z(0.04), d), w > 0.5, d == 0.05]')
    before = _function(ast.parse(source).body, {'np': np}, 'theta, omega')
    after = _function(body, namespace, 'theta, omega')
    theta = np.array([0.0, -0.0, 1.0, 2.5, -7.0])
    for omega in (np.array(3.0), np.array(-0.0), np.float64(2.0), np.linspace(-1.0, 1.0, 5)):
        assert [_facts(v) for v in after(theta, omega)] == [
            _facts(v) for v in before(theta, omega)], omega


# --- helpers a kernel calls, written out in place (issue 30) -----------------------------

class _Tip:
    """A driver for the helpers' tests: its tip at ``theta + 0j`` (no bounds)."""

    label = 'input tip'
    tip = 'A'

    def run(self, ctx, theta, omega, alpha):
        ctx.points[self.tip] = (theta + 0j, omega + 0j, alpha + 0j, 0.0, 0.0, 0.0)


class _Helped(Step):
    """A step whose kernel calls helpers: one rebinds a parameter and calls another."""

    label = 'helped Q'
    start = 'A'
    point = 'Q'

    def run(self, ctx):
        p, v, a, ep, ev, ea = ctx.points[self.start]
        w = v * 3.0
        q, bound = self.shift(ctx, p * 2.0 - 1.0, w.real)
        self.record(ctx, q)
        ctx.points[self.point] = (q, w, a, bound, ev, ea)

    def shift(self, ctx, z, bound):
        bound = bound + 1.0
        w = np.hypot(z.real, z.imag) if ctx.vector else abs(z)
        scaled = self.scale(ctx, w)
        return z + scaled, bound * scaled

    def scale(self, ctx, w):
        return w * 0.5 + 0.25

    def record(self, ctx, q):
        ctx.measures[self.point] = q.imag - q.real


class _HelpedPlan:
    """The plan of a tip and a :class:`_Helped` step, as the compiler's ``ScenePlan``."""

    ground = {}
    crank = _Tip()
    drivers = (crank,)
    steps = (_Helped(),)


@pytest.mark.parametrize('vector', [False, True])
def test_helpers_are_written_out_with_the_same_bits(vector):
    """A kernel's helpers (nested, a parameter rebound, none returned) compile to run's bits."""
    from mech_kinematics.solver.context import _Context

    names, namespace = {}, {'np': np}
    body = plan_body(_HelpedPlan, names, namespace, vector=vector)
    code = ast.unparse(ast.Module(body, []))
    assert not re.findall(r'self|shift\(|scale\(|record\(', code), code
    entries = ', '.join(f'{key!r}: {local}' for key, local in names.items())
    function = _function([*body, *ast.parse(f'out = {{{entries}}}').body], namespace,
                         'theta, omega, alpha, turns, ctx')
    theta = (np.array([0.0, -0.0, 0.5, 2.5, -7.0, np.nan]) if vector else 0.75)
    ctx = _Context(theta, vector)
    _Tip().run(ctx, theta, 1.5, -0.25)
    _Helped().run(ctx)
    got = function(theta, 1.5, -0.25, 0, _Context(theta, vector))
    assert _facts(got['P_Q']) == _facts(ctx.points['Q'])
    assert _facts(got['M_Q']) == _facts(ctx.measures['Q'])


def test_the_two_rrr_kinds_share_one_kernel_written_out():
    """The RRR kinds (and the fold, through the actuated one) call _meet; the code calls none."""
    import inspect

    from mech_kinematics.solver.fold import _FoldStep
    from mech_kinematics.solver.rrr import _ActuatedRRRStep, _RRRStep

    for kernel in (_RRRStep.run, _ActuatedRRRStep._actuated):
        assert 'self._meet(ctx, ' in inspect.getsource(kernel), kernel
    for kernel in (_ActuatedRRRStep.run, _FoldStep.run):
        assert 'self._actuated(ctx)' in inspect.getsource(kernel), kernel
    for scene in ('khurmi_four_bar_ad150', 'excavator'):
        code, _ = _code(scene, False)
        assert '_meet' not in code and 'self' not in code, scene


def test_a_helper_outside_the_kernel_subset_is_named(monkeypatch):
    """A helper returning before its end is not compiled: the reason names the step and helper."""
    from mech_kinematics.solver.compiler import compile_scene, NotCompiled, SINGLE
    from mech_kinematics.solver.rrr import _RRRStep

    def _meet(self, ctx, d, dist, l1, l2, lsum, inputs, lengths):
        if ctx.vector:
            return d, d, dist, dist, dist
        return d, d, dist, dist, dist

    monkeypatch.setattr(_RRRStep, '_meet', _meet)
    assert compile_scene(mk.load_scene('khurmi_four_bar_ad150'), SINGLE) == NotCompiled(
        'step RRR C: helper _meet uses `return` before its end (not in the kernel subset)')
