# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Golden values: the answers printed in the course notes, at the accuracy they deserve.

The entries are package data, ``mech_kinematics/data/textbook_answers.yaml``,
read through :mod:`mech_kinematics.textbook`, with their source, their
tolerance (0.5 % for numbers the text computes, 5 % for values measured on a
drawing, 10 % for squares and products of measured values; for the forces, what
the book's approximate piston acceleration deserves) and, for known-bad printed
numbers and the forces' answers, the exact value beside them. The loader's own
checks follow.
"""

from __future__ import annotations

import math
import subprocess
import sys
from typing import Any

from helpers import start_positions
import mpmath
import pytest

import mech_kinematics as mk
from mech_kinematics import textbook
from mech_kinematics.textbook import TextbookAnswer

#: Agreement of the solver with an entry's stored exact (50-digit) value.
RTOL_EXACT = 1e-12
#: How many answers the seeds print (every one is kept), and the forces' four (issue 32).
N_ANSWERS = 66

ANSWERS = textbook.textbook_answers()

_STATES: dict[str, dict[str, Any]] = {}


def _state(scene_name: str) -> dict[str, Any]:
    if scene_name not in _STATES:
        scene = mk.load_scene(scene_name)
        _STATES[scene_name] = mk.solve(scene, start_positions(scene)).as_dict()
    return _STATES[scene_name]


def _id(entry: TextbookAnswer) -> str:
    return f"{entry.scene}:{entry.quantity.split(' ')[0]}"


@pytest.mark.parametrize('entry', [e for e in ANSWERS if not e.discrepancy], ids=_id)
def test_printed_answer_within_drawing_accuracy(entry: TextbookAnswer) -> None:
    """The solver's value is within the printed answer's stated tolerance."""
    got = entry.evaluate(_state(entry.scene))
    assert entry.within_tolerance(got), (entry.quantity, got, entry.printed)
    if entry.exact is not None:
        assert math.isclose(got, entry.exact, rel_tol=RTOL_EXACT, abs_tol=1e-15)


@pytest.mark.parametrize('entry', [e for e in ANSWERS if e.discrepancy], ids=_id)
def test_documented_discrepancy_keeps_the_exact_value(entry: TextbookAnswer) -> None:
    """A printed answer known to be off: the solver gives the exact value, not the book's."""
    got = entry.evaluate(_state(entry.scene))
    assert entry.exact is not None
    assert math.isclose(got, entry.exact, rel_tol=RTOL_EXACT)
    miss = abs(entry.printed - got) / abs(got)
    assert miss > mk.NEAR_SINGULAR, 'no longer a discrepancy: move it to the tight tests'
    assert miss <= entry.rel_tol, 'the documented tolerance no longer covers the miss'


def test_every_seed_scene_has_answers() -> None:
    """Each scene taken from the seeds' worked problems is checked against printed numbers."""
    covered = {entry.scene for entry in ANSWERS}
    assert covered >= {'khurmi_four_bar_ad150', 'slider_crank_150_600', 'steam_engine_500_2000',
                       'quick_return', 'geneva', 'rocking_lever', 'piston_300',
                       'four_bar_coupler_points', 'khurmi_engine_15_7',
                       'singh_petrol_engine_13_15'}


def test_every_printed_answer_is_kept_with_its_source() -> None:
    """All 66 printed answers load, each citing its seed and, where known, its book."""
    assert len(ANSWERS) == N_ANSWERS
    assert len({(e.scene, e.quantity) for e in ANSWERS}) == N_ANSWERS
    for entry in ANSWERS:
        assert entry.source.startswith(('seed 00', 'not in the seed text')), entry.source
    books = ('Khurmi & Gupta', 'Beer & Johnston', 'Dunn', 'Rattan', 'V. P. Singh', 'Hibbeler')
    assert all(any(book in e.source for book in books) for e in ANSWERS)
    example = textbook.find_answer('quick_return', "alpha_lever = a^t_B'O / B'O = 6.4 / 0.52")
    assert 'Example 8.10' in example.source and example.printed == 12.3
    assert example.rel_tol == 0.10 and example.kind == 'derived from measured'
    assert 'Khurmi prints' in (example.note or '')


#: The engines of the forces' answers (issue 32): crank and rod (m), the crank's angle from
#: the dead centre toward the piston (deg), rpm, reciprocating mass (kg), gas load toward the
#: crank (N, as pressure x area), gravity along the stroke away from the crank (m/s^2).
ENGINES = {
    'khurmi_engine_15_7': ('0.3', '1.2', 60, 250, '250', ('0.35e6', '0.5'), '0'),
    'singh_petrol_engine_13_15': ('0.1', '0.35', 30, 1800, '1.6', ('750e3', '0.15'), '-9.81'),
}


def _engine(r, rod, theta, rpm, mass, gas, g):
    """Return a slider-crank's statics at 50 digits, the rod and crank massless.

    (rod thrust, push along the stroke, turning moment on the crank, the crank pin's
    tangential force), from the piston's exact acceleration (its position
    differentiated twice) and the rod's line; none of the package's formulas.
    """
    with mpmath.workdps(50):
        r, rod, mass, g = (mpmath.mpf(v) for v in (r, rod, mass, g))
        load = mpmath.mpf(gas[0]) * mpmath.pi / 4 * mpmath.mpf(gas[1]) ** 2
        angle, omega = mpmath.radians(theta), 2 * mpmath.pi * rpm / 60

        def stroke(t):
            return r * mpmath.cos(t) + mpmath.sqrt(rod ** 2 - (r * mpmath.sin(t)) ** 2)

        accel = mpmath.diff(stroke, angle, 2) * omega ** 2
        push = mass * accel + load - mass * g          # on the piston from the rod
        pin = mpmath.mpc(r * mpmath.cos(angle), r * mpmath.sin(angle))
        along = (stroke(angle) - pin) / abs(stroke(angle) - pin)
        thrust = push / along.real
        on_crank = -thrust * along
        moment = pin.real * on_crank.imag - pin.imag * on_crank.real
        return {'thrust': abs(thrust), 'push': push, 'moment': moment, 'tangential': moment / r}


#: Each force answer's quantity (its first word) -> the closed form's value.
CLOSED_FORM = {'F_Q,': 'thrust', 'F_T,': 'tangential', 'T,': 'moment', 'F_P,': 'push'}


@pytest.mark.parametrize('entry', [e for e in ANSWERS if e.scene in ENGINES], ids=_id)
def test_a_force_answers_exact_value_is_the_closed_form(entry: TextbookAnswer) -> None:
    """The forces' stored exact values are a slider-crank's statics solved at 50 digits."""
    want = _engine(*ENGINES[entry.scene])[CLOSED_FORM[entry.quantity.split(' ')[0]]]
    assert entry.exact is not None
    assert abs(entry.exact - want) <= 1e-15 * abs(want)
    assert abs(entry.printed - float(want)) <= entry.rel_tol * abs(float(want))


def test_degrees_answer_converts_the_radians() -> None:
    """An answer printed in degrees is the joint angle in radians, converted (Geneva beta)."""
    beta = textbook.find_answer('geneva', 'beta, angle of the slot from the line of centres, '
                                          'degrees')
    assert beta.unit == 'deg'
    radians = _state('geneva')['joints']['wheel']['position']
    expected = math.degrees(abs(radians))
    assert beta.evaluate(_state('geneva')) == pytest.approx(expected, rel=1e-15)


def test_find_answer_names_what_is_missing() -> None:
    """Asking for an answer the data does not hold raises KeyError naming scene and quantity."""
    with pytest.raises(KeyError, match="'geneva'.*'no such quantity'"):
        textbook.find_answer('geneva', 'no such quantity')


_GOOD = """
answers:
  - scene: geneva
    source: seed 000
    quantity: q
    accessor: {joint: wheel, field: velocity, mode: signed}
    printed: -4.08
    unit: rad/s
    rel_tol: 0.005
    kind: computed
"""


def test_load_answers_reads_the_format(tmp_path) -> None:
    """A minimal file in the packaged format loads into a TextbookAnswer."""
    path = tmp_path / 'answers.yaml'
    path.write_text(_GOOD)
    (answer,) = textbook.load_answers(path)
    assert answer == TextbookAnswer('geneva', 'seed 000', 'q',
                                    textbook.JointValue('wheel', 'velocity', 'signed'), -4.08,
                                    'rad/s', 0.005, 'computed')


@pytest.mark.parametrize(('old', 'new', 'match'), [
    pytest.param('field: velocity', 'field: speed',
                 r'answers\[0\]\.accessor\.field: expected one of', id='field'),
    pytest.param('mode: signed', 'mode: cubed',
                 r'answers\[0\]\.accessor\.mode: expected abs or signed', id='mode'),
    pytest.param('{joint: wheel, field: velocity, mode: signed}', '{link: wheel}',
                 r'answers\[0\]\.accessor: expected keys', id='accessor'),
    pytest.param('printed: -4.08', 'printed: .nan',
                 r'answers\[0\]\.printed: expected a finite number', id='printed'),
    pytest.param('rel_tol: 0.005', 'rel_tol: 5',
                 r'answers\[0\]\.rel_tol: expected a relative tolerance', id='rel_tol'),
    pytest.param('kind: computed', 'kind: guessed', r'answers\[0\]\.kind: expected one of',
                 id='kind'),
    pytest.param('kind: computed', 'kind: computed\n    discrepancy: true',
                 r'answers\[0\]\.exact: expected the exact value', id='discrepancy'),
    pytest.param('unit: rad/s', 'unit: rad/s\n    page: 12',
                 r'answers\[0\]: expected keys among', id='unknown-key'),
    pytest.param('answers:', 'answer:', 'expected a non-empty list under "answers"',
                 id='no-answers'),
    pytest.param('printed: -4.08', 'printed: [', 'invalid YAML', id='yaml'),
])
def test_load_answers_refuses_a_bad_file(tmp_path, old, new, match) -> None:
    """A malformed answers file is one ValueError naming the file, the entry and the key."""
    path = tmp_path / 'answers.yaml'
    assert old in _GOOD
    path.write_text(_GOOD.replace(old, new))
    with pytest.raises(ValueError, match=match) as info:
        textbook.load_answers(path)
    assert str(info.value).startswith(str(path))


@pytest.mark.parametrize(('accessor', 'match'), [
    pytest.param('{effort: crank, factor: 1, mode: twice}', r'accessor\.mode: expected abs or',
                 id='effort-mode'),
    pytest.param('{reaction: C, field: force, component: z, mode: abs}',
                 r'accessor\.component: expected one of x, y, norm', id='component'),
    pytest.param('{reaction: C, field: moment, component: x, mode: abs}',
                 r'accessor\.component: expected none for a moment', id='moment-component'),
    pytest.param('{reaction: C, field: torque, mode: abs}', r'accessor\.field: expected force',
                 id='field'),
])
def test_a_bad_force_accessor_is_named(tmp_path, accessor, match) -> None:
    """An effort or reaction accessor with a bad mode, component or field is one line."""
    path = tmp_path / 'answers.yaml'
    path.write_text(_GOOD.replace('{joint: wheel, field: velocity, mode: signed}', accessor))
    with pytest.raises(ValueError, match=match):
        textbook.load_answers(path)


def test_force_accessors_read_state_dicts() -> None:
    """An effort is scaled and signed; a reaction's component, length or scalar field is read."""
    state = {'efforts': {'crank': -2.0},
             'reactions': {'C': {'force': [3.0, -4.0]}, 'ram': {'normal': -7.0, 'moment': 1.5}}}
    assert textbook.EffortValue('crank', -0.5, 'signed').value(state) == 1.0
    assert textbook.EffortValue('crank', 1.0, 'abs').value(state) == 2.0
    assert textbook.ReactionValue('C', 'force', 'norm', 'abs').value(state) == 5.0
    assert textbook.ReactionValue('C', 'force', 'y', 'signed').value(state) == -4.0
    assert textbook.ReactionValue('C', 'force', 'y', 'abs').value(state) == 4.0
    assert textbook.ReactionValue('ram', 'normal', None, 'signed').value(state) == -7.0


def test_loader_is_pure() -> None:
    """Loading the answers imports neither ROS, matplotlib, SciPy nor mpmath."""
    code = ('import sys; from mech_kinematics.textbook import textbook_answers; '
            'assert len(textbook_answers()) > 0; '
            "heavy = {'rclpy', 'matplotlib', 'scipy', 'mpmath'} & set(sys.modules); "
            'assert not heavy, heavy')
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)
