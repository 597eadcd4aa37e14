# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Error bounds against the truth, and the refusal of what cannot be trusted (issues 10, 12).

Every value the solver returns carries an absolute error bound
(``State.error_bound``). These tests measure the actual error of every
returned value against the 50-digit reference of
``mech_kinematics.verify.reference`` (the exact answer for the scene's
doubles) and check that

- the bound is never below the actual error: over an extreme suite built
  here (a toggle, a folded toggle, a change point, a guide at grazing reach,
  a pin passing through and near a slotted lever's pivot, extreme ratios),
  1e-3, 1e-6 and 1e-9 rad from every singular position, on both sides; over
  extreme scales and speeds; and on hypothesis-generated mechanisms of every
  dyad type;
- in well-conditioned positions it is not more than 1e3 x (the actual error
  + 1 ulp of the value's kind's scale), so that good answers are not refused.
  "Well-conditioned" means the reference's condition number ``kappa`` of the
  state (``reference.condition``: the componentwise relative condition number
  in every input) is at most :data:`KAPPA_WELL` for every kind of value. A
  bound cannot be within an ulp of an exact answer, hence the ulp; and the
  bound counts the rounding of the inputs, which the reference does not, so
  it cannot beat ``kappa`` ulps;
- the two cases of issue 10 are refused with one clear line, and every
  packaged scene is answered over a full cycle wherever it assembles;
- issue 12 item 4: no NaN or inf, over 1e-300..1e300 m and 1e-6..1e6 rpm.
"""

from __future__ import annotations

import cmath
import contextlib
import dataclasses
import json
import math
import re
import subprocess
import sys
import warnings

from helpers import (actual_errors, assert_bounded, crank_scene_names, equilateral_chain,
                     first_order_spreads, ROOT)
from hypothesis import assume, given, HealthCheck, settings
from hypothesis import strategies as st
import mpmath
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.units import rad_per_s_from_rpm
from mech_kinematics.verify import reference as ref

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

#: Offsets from every singular position, rad (issue 10).
OFFSETS = (1e-3, 1e-6, 1e-9)
#: Positions whose condition number is at most this, for every kind of value,
#: are well-conditioned: there the bound is within TIGHTNESS of the truth.
KAPPA_WELL = 10.0
#: Largest bound / (actual error + 1 ulp of the kind's scale) where well-conditioned.
TIGHTNESS = 1e3
#: Lengths (m) and crank speeds (rpm) of issue 12's extreme-scale range.
SCALES = (1e-300, 1e-200, 1e-98, 1e-20, 1.0, 1e77, 1e78, 1e200, 1e300)
SPEEDS_RPM = (-1e6, -1.0, 1e-6, 1e6)

#: Random mechanisms are drawn freely and the ones that cannot assemble (and, for
#: the tightness test, the ill-conditioned ones) filtered out: more than half.
SETTINGS = settings(max_examples=300, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.filter_too_much])


# --- measuring the actual error ---------------------------------------------------


# --- the extreme suite ------------------------------------------------------------


def four_bar(name, a, b, c, d, angle=0.0, branch=1, speed=-4 * math.pi, scale=1.0):
    """Return a four-bar ABCD (ground A at 0, D at (d, 0)) with a coupler point E."""
    return mk.Scene(name, {'A': (0.0, 0.0), 'D': (d * scale, 0.0)},
                    mk.Crank('crank', 'A', 'B', a * scale, angle, speed, 0.0),
                    (mk.RRR('C', (mk.Link('coupler', 'B', b * scale),
                                  mk.Link('rocker', 'D', c * scale)), branch),),
                    (mk.CarriedPoint('E', 'coupler', 'B', 'C', (0.5 * b * scale,
                                                                0.3 * b * scale)),))


def slider_crank(name, crank, rod, offset=0.0, speed=10 * math.pi):
    """Return a slider-crank (guide along x, ``offset`` above the crank centre), a rod point."""
    return mk.Scene(name, {'O': (0.0, 0.0), 'E': (0.0, offset)},
                    mk.Crank('crank', 'O', 'B', crank, 0.0, speed, 0.0),
                    (mk.RRP('P', mk.Link('rod', 'B', rod), 'E', 0.0, 'piston', 1),),
                    (mk.CarriedPoint('M', 'rod', 'B', 'P', (0.5 * rod, 0.0)),))


def slotted_lever(name, pivot_height, crank=0.15, speed=4 * math.pi, ram=True):
    """Return a slotted lever about O = 0 driven by a crank about (0, pivot_height).

    The lever carries C, 0.7 m out; with ``ram`` an RRP ram runs from C to a
    guide along y = 0.1 (within reach while the lever stays near horizontal).
    """
    dyads = [mk.RPR('lever', 'O', 'B', 'block')]
    if ram:
        dyads.append(mk.RRP('R', mk.Link('ram_link', 'C', 0.3), 'G', 0.0, 'ram', 1))
    return mk.Scene(name, {'O': (0.0, 0.0), 'A': (0.0, pivot_height), 'G': (0.0, 0.1)},
                    mk.Crank('crank', 'A', 'B', crank, -1.0, speed, 1.0), tuple(dyads),
                    (mk.CarriedPoint('C', 'lever', 'O', 'B', (0.7, 0.0)),))


def distance_angle(a, d, distance):
    """Return the crank angle at which the crank tip is ``distance`` from D = (d, 0)."""
    with mpmath.workdps(60):
        a_, d_, r = (mpmath.mpf(x) for x in (a, d, distance))
        return mpmath.acos((a_ * a_ + d_ * d_ - r * r) / (2 * a_ * d_))


def near(singular, sides=(1, -1)):
    """Return the crank angles ``OFFSETS`` away from a singular crank angle (mpmath)."""
    with mpmath.workdps(60):
        return [float(singular + side * mpmath.mpf(offset))
                for offset in OFFSETS for side in sides]


def extreme_suite():
    """Return (label, scene, angles, speed) for every singular position of the suite."""
    toggle = four_bar('toggle', 0.05, 0.066, 0.056, 0.1)  # non-Grashof: |BD| reaches b + c
    extended = distance_angle(0.05, 0.1, 0.066 + 0.056)
    folded = four_bar('folded', 0.05, 0.1, 0.04, 0.1, angle=1.0)  # |BD| reaches b - c too
    inner = distance_angle(0.05, 0.1, 0.1 - 0.04)
    with mpmath.workdps(60):
        grazing = -mpmath.pi / 2
    return [
        ('extended toggle', toggle, near(extended, (-1,)) + near(-extended, (1,)), None),
        ('folded toggle', folded, near(inner, (1,)), None),
        ('change point', four_bar('change_point', 0.04, 0.1, 0.04, 0.1, angle=0.5),
         near(mpmath.mpf(0)), None),
        ('guide at grazing reach',
         slider_crank('grazing', 0.125, 0.1875, offset=0.0625), near(grazing), None),
        ('pin through the pivot', slotted_lever('through_pivot', 0.15), near(grazing), None),
        # Within 1e-6 rad the lever turns half a turn: no ram could follow it.
        ('pin near the pivot', slotted_lever('near_pivot', 0.15 * (1 + 1e-6), ram=False),
         near(grazing), None),
        ('rod/crank 1e6', slider_crank('long_rod', 0.1, 1e5), [math.pi / 2, 0.3], None),
        ('rod/crank 1.000001', slider_crank('short_rod', 0.1, 0.1000001),
         [math.pi / 2, -math.pi / 2, 0.7], None),
        ('crank/frame 1e-6', four_bar('tiny_crank', 1e-7, 0.15, 0.08, 0.1), [0.0, 2.0], None),
        ('1e5 rpm', four_bar('fast', 0.04, 0.15, 0.08, 0.15), [1.0, -2.0],
         rad_per_s_from_rpm(1e5)),
        ('1e-6 rpm', four_bar('slow', 0.04, 0.15, 0.08, 0.15), [1.0, -2.0],
         rad_per_s_from_rpm(1e-6)),
    ]


SUITE = extreme_suite()


@pytest.mark.parametrize(('label', 'scene', 'angles', 'speed'), SUITE,
                         ids=[case[0] for case in SUITE])
def test_bound_covers_the_actual_error_near_every_singular_position(
        label, scene, angles, speed):
    """At 1e-3, 1e-6 and 1e-9 rad from each singular position, no error exceeds its bound."""
    answered = 0
    for angle in angles:
        state, _ = assert_bounded(scene, angle, speed, 1.0)
        answered += state is not None
    assert answered, label  # something was checked


@pytest.mark.parametrize('size', SCALES)
@pytest.mark.parametrize('rpm', SPEEDS_RPM)
def test_full_scale_range_is_finite_and_bounded_or_refused(size, rpm):
    """1e-300..1e300 m and 1e-6..1e6 rpm: finite answers within their bounds, or refused.

    See issue 12 (an RRR above about 1e77 m overflowed, 1e-98 m claimed its
    circles do not meet).
    """
    scene = four_bar('scaled', 0.04, 0.15, 0.08, 0.15, angle=math.radians(60), scale=size)
    speed = rad_per_s_from_rpm(rpm)
    for angle in (math.radians(60), -2.5):
        try:
            state = mk.solve(scene, angle, speed, 0.5 * speed)
        except mk.UntrustedError as error:
            assert 'overflows' in error.reason, error
            assert error.bound == math.inf
            continue
        text = json.dumps(state.as_dict(), allow_nan=False)  # raises on NaN or inf
        assert 'error_bound' in text
        exact = ref.reference(scene, angle, speed, 0.5 * speed)
        for path, _, error, bound, _ in actual_errors(state, exact):
            assert error <= bound, (size, rpm, angle, path, error, bound)


def test_full_scale_range_answers_where_doubles_can():
    """Every size answers at 1 rpm; only states beyond the doubles' range are refused."""
    for size in SCALES:
        scene = four_bar('scaled', 0.04, 0.15, 0.08, 0.15, angle=1.0, scale=size)
        state = mk.solve(scene, 1.0, rad_per_s_from_rpm(1.0), 0.0)
        assert state.relative_error_bound < 1e-10, size
    # 1e300 m at 1e6 rpm accelerates at about 1e310 m/s^2.
    scene = four_bar('huge', 0.04, 0.15, 0.08, 0.15, angle=1.0, scale=1e300)
    with pytest.raises(mk.UntrustedError, match='overflows'):
        mk.solve(scene, 1.0, rad_per_s_from_rpm(1e6), 0.0)


@pytest.mark.parametrize('size', [1e-98, 1e-300, 1e78, 1e300])
def test_messages_at_extreme_scales_state_true_numbers(size):
    """A circles-do-not-meet message's own numbers violate the inequality it states (issue 12)."""
    scene = four_bar('scaled', 0.05, 0.066, 0.056, 0.1, angle=0.0, scale=size)
    with pytest.raises(mk.AssemblyError) as caught:
        mk.solve(scene, math.pi)  # |BD| = 0.15 > BC + CD = 0.122
    reason = caught.value.reason
    assert 'do not meet' in reason
    got = float(reason.rsplit('= ', 1)[1].split()[0])
    upper = float(reason.split('| < ')[2].split()[0])
    assert got > upper
    assert got == pytest.approx(0.15 * size, rel=1e-12)


def test_speed_of_1e160_rpm_is_refused_not_nan():
    """``solve --speed-rpm 1e160`` exits 2 with one line instead of printing NaN (issue 12)."""
    result = subprocess.run(
        [sys.executable, '-m', 'mech_kinematics', 'solve', 'khurmi_four_bar_ad150',
         '--speed-rpm', '1e160'], capture_output=True, text=True, check=False)
    assert result.returncode == 2
    assert result.stdout == ''
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('error: ') and 'overflows' in lines[0]


# --- the two cases of issue 10 ----------------------------------------------------------


#: Issue 10's slotted lever: its pivot O on the pin circle, the crank at 60 rpm.
PIN_THROUGH_PIVOT = mk.Scene(
    'pin_through_pivot', {'O': (0.0, 0.0), 'A': (0.0, 0.15)},
    mk.Crank('crank', 'A', 'B', 0.15, 0.0, 2 * math.pi, 0.0),
    (mk.RPR('lever', 'O', 'B', 'block'),))
#: Issue 10's Grashof change-point four-bar (a + d = b + c, a parallelogram), flat at 0.
CHANGE_POINT = four_bar('change_point', 0.04, 0.1, 0.04, 0.1, angle=0.5)


def test_pin_through_pivot_is_refused_not_answered_wrong():
    """1e-9 rad after the pin passes the pivot: refused, not omega 6.283 for 3.1416 (issue 10).

    Moving the crank's centre by one ulp changes the exact lever speed there to
    about -1160 or +1166 rad/s: no double answer can be trusted, and the bound
    says so.
    """
    angle = -math.pi / 2 + 1e-9
    with pytest.raises(mk.UntrustedError) as caught:
        mk.solve(PIN_THROUGH_PIVOT, angle)
    error = caught.value
    assert error.dyad == 'RPR lever'
    assert error.value.startswith('joints.lever.')
    assert error.bound > error.tolerance > 0
    assert '\n' not in str(error)
    # The answer given with no tolerance carries a bound that covers its error.
    state, exact = assert_bounded(PIN_THROUGH_PIVOT, angle)
    assert float(exact.joints['lever'][1]) == pytest.approx(math.pi, rel=1e-9)
    bound = state.error_bound.joints['lever'].velocity
    assert bound > 1e3  # rad/s: one ulp of the inputs moves the exact answer by ~1e3
    # Far enough from the pivot the same lever is answered, and exact to its bound.
    assert_bounded(PIN_THROUGH_PIVOT, -math.pi / 2 + 1e-2)
    mk.solve(PIN_THROUGH_PIVOT, -math.pi / 2 + 1e-2)


def test_change_point_near_flat_is_refused_not_answered_wrong():
    """1e-6 rad from a change point's flat position: refused with one line (issue 10)."""
    with pytest.raises(mk.UntrustedError) as caught:
        mk.solve(CHANGE_POINT, 1e-6)
    error = caught.value
    assert error.dyad == 'RRR C'
    assert error.value.split('.')[1] in ('C', 'E', 'coupler', 'rocker')
    assert error.bound > error.tolerance
    assert 'near-singularity measure of RRR C' in error.reason
    assert_bounded(CHANGE_POINT, 1e-6)
    # Rounding the inputs alone moves the exact accelerations by more than their size.
    exact = ref.reference(CHANGE_POINT, 1e-6)
    kappa = ref.condition(CHANGE_POINT, exact)
    assert kappa['angular acceleration'] * ref.mpmath.eps > 1


@pytest.mark.parametrize(('scene', 'angle', 'dyad'), [
    (PIN_THROUGH_PIVOT, -math.pi / 2 + 1e-9, 'RPR lever'), (CHANGE_POINT, 1e-6, 'RRR C')])
def test_issue_cases_refused_by_the_solve_command(tmp_path, scene, angle, dyad):
    """``solve`` exits 2 with one line naming the dyad, the value, its bound and the tolerance."""
    path = tmp_path / f'{scene.name}.yaml'
    path.write_text(json.dumps(scene_dict(scene)))  # JSON is YAML
    result = subprocess.run(
        [sys.executable, '-m', 'mech_kinematics', 'solve', str(path), '--angle-deg',
         repr(math.degrees(angle))], capture_output=True, text=True, check=False)
    assert result.returncode == 2, result.stdout
    assert result.stdout == ''
    line, = result.stderr.strip().splitlines()
    assert line.startswith(f'error: {dyad} cannot be solved')
    assert 'cannot be trusted' in line and 'error bound' in line and '1e-06 x' in line
    # A looser tolerance answers it, with the bounds in the JSON.
    result = subprocess.run(
        [sys.executable, '-m', 'mech_kinematics', 'solve', str(path), '--angle-deg',
         repr(math.degrees(angle)), '--max-error', 'inf'], capture_output=True, text=True,
        check=False)
    assert result.returncode == 0, result.stderr
    assert set(json.loads(result.stdout)['error_bound']) == {'joints', 'points'}


def scene_dict(scene):
    """Write ``scene`` (RRR, RRP, RPR, carried points) as a scene-file mapping in m and rad."""
    c = scene.input
    dyads = []
    for d in scene.dyads:
        if isinstance(d, mk.RRR):
            dyads.append({'type': 'RRR', 'point': d.point, 'branch': int(d.branch),
                          'links': [{'name': link.name, 'from': link.start,
                                     'length': link.length} for link in d.links]})
        elif isinstance(d, mk.RRP):
            dyads.append({'type': 'RRP', 'point': d.point, 'slider': d.slider,
                          'branch': int(d.branch),
                          'link': {'name': d.link.name, 'from': d.link.start,
                                   'length': d.link.length},
                          'guide': {'through': d.through, 'angle': d.guide_angle}})
        else:
            dyads.append({'type': 'RPR', 'link': d.link, 'center': d.center,
                          'through': d.through, 'slider': d.slider})
    return {'name': scene.name, 'units': {'length': 'm', 'angle': 'rad'},
            'ground': {n: [x, y] for n, (x, y) in scene.ground.items()},
            'input': {'link': c.link, 'center': c.center, 'point': c.point,
                      'length': c.length, 'angle': c.angle,
                      'speed_rpm': c.speed * 30 / math.pi, 'accel': c.accel},
            'dyads': dyads,
            'points': {p.name: {'link': p.link, 'origin': p.origin, 'xaxis': p.xaxis,
                                'local': list(p.local)} for p in scene.points}}


# --- random mechanisms of every dyad type -------------------------------------------

unit = st.floats(0.0, 1.0)
signs = st.sampled_from((1, -1))
angles = st.floats(-math.pi, math.pi)


def lerp(lo, hi, t):
    return lo + (hi - lo) * t


def build(name, ground, crank, dyads, points=()):
    """Return the Scene, rejecting the example if it cannot assemble at the crank angle."""
    try:
        return mk.Scene(name, {k: (z.real, z.imag) for k, z in ground.items()}, crank,
                        tuple(dyads), tuple(points))
    except mk.SceneError as error:
        assume('assemble' not in str(error))
        raise


@st.composite
def frames(draw):
    """Return (size m, origin, unit direction) of a drawn mechanism."""
    size = draw(st.sampled_from((1e-3, 0.2, 5.0)))
    origin = complex(draw(st.floats(-2, 2)), draw(st.floats(-2, 2))) * size
    return size, origin, cmath.exp(1j * draw(angles))


@st.composite
def four_bars(draw):
    """Draw a four-bar of any Grashof class with an (x, y) coupler point (RRR)."""
    size, origin, u = draw(frames())
    a, b, c = (lerp(0.1, 3.0, draw(unit)) * size for _ in range(3))
    point = mk.CarriedPoint('E', 'coupler', 'B', 'C', (lerp(-1, 1, draw(unit)) * b,
                                                       lerp(-1, 1, draw(unit)) * b))
    return build('four_bar', {'A': origin, 'D': origin + size * u},
                 mk.Crank('crank', 'A', 'B', a, draw(angles)),
                 [mk.RRR('C', (mk.Link('coupler', 'B', b), mk.Link('rocker', 'D', c)),
                         draw(signs))], [point])


@st.composite
def slider_cranks(draw):
    """Draw an offset slider-crank on a guide in any direction, with a rod point (RRP)."""
    size, origin, u = draw(frames())
    offset = lerp(-1.5, 1.5, draw(unit)) * size
    through = origin + complex(lerp(-3, 3, draw(unit)), 0) * size * u + 1j * offset * u
    rod = lerp(0.5, 5.0, draw(unit)) * size
    return build('slider_crank', {'A': origin, 'G': through},
                 mk.Crank('crank', 'A', 'B', size, draw(angles)),
                 [mk.RRP('P', mk.Link('rod', 'B', rod), 'G', cmath.phase(u), 'piston',
                         draw(signs))],
                 [mk.CarriedPoint('M', 'rod', 'P', 'B', (lerp(-0.5, 1.5, draw(unit)) * rod,
                                                         0.0))])


@st.composite
def slotted_levers(draw):
    """Draw a crank-and-slotted-lever or Whitworth quick return with its ram (RPR, RRP)."""
    size, origin, u = draw(frames())
    ratio = lerp(0.2, 0.8, draw(unit))
    centres, a = (ratio * size, size) if draw(st.booleans()) else (size, ratio * size)
    ground = {'O': origin, 'A': origin + centres * u,
              'G': origin + complex(lerp(-2, 2, draw(unit)), lerp(-2, 2, draw(unit))) * size}
    lever = lerp(0.5, 2.5, draw(unit)) * (a + centres)
    return build('slotted_lever', ground, mk.Crank('crank', 'A', 'B', a, draw(angles)),
                 [mk.RPR('lever', 'O', 'B', 'block'),
                  mk.RRP('R', mk.Link('ram_link', 'C', lerp(0.2, 3.0, draw(unit)) * size), 'G',
                         draw(angles), 'ram', draw(signs))],
                 [mk.CarriedPoint('C', 'lever', 'O', 'B', (lever, 0.0))])


@st.composite
def six_links(draw):
    """Draw a four-bar driving an RRR or RRP dyad from its coupler point."""
    base = draw(four_bars())
    size = math.dist(base.ground['A'], base.ground['D'])
    ground = {k: complex(*v) for k, v in base.ground.items()}
    ground['F'] = ground['A'] + complex(lerp(-2, 2, draw(unit)), lerp(-2, 2, draw(unit))) * size
    first = lerp(0.3, 3, draw(unit)) * size
    if draw(st.booleans()):
        second = mk.RRR('M', (mk.Link('link5', 'E', first),
                              mk.Link('link6', 'F', lerp(0.3, 3, draw(unit)) * size)),
                        draw(signs))
    else:
        second = mk.RRP('M', mk.Link('link5', 'E', first), 'F', draw(angles), 'slider6',
                        draw(signs))
    return build('six_link', ground, base.input, [*base.dyads, second], base.points)


mechanisms = st.one_of(four_bars(), slider_cranks(), slotted_levers(), six_links())
#: Crank motions: speed in +-[0.2, 200] rad/s, acceleration +-[0.1, 2] speed^2, or at rest.
motions = st.one_of(
    st.tuples(st.floats(0.2, 200.0).flatmap(lambda w: st.sampled_from((w, -w))),
              st.floats(0.1, 2.0).flatmap(lambda k: st.sampled_from((k, -k)))).map(
        lambda m: (m[0], m[1] * m[0] ** 2)),
    st.just((0.0, 0.0)), st.just((0.0, 1.0)))


@SETTINGS
@given(mechanisms, motions, angles)
def test_bound_covers_the_actual_error_of_random_mechanisms(scene, motion, angle):
    """On random mechanisms of every dyad type, no returned value's error exceeds its bound."""
    assert_bounded(scene, angle, *motion)


def minimum_measure(state):
    """Return the smallest near-singularity measure of the state's dyads (1 without dyads)."""
    return min(state.singularity.values(), default=1.0)


def assert_tight(scene, angle, speed=None, accel=None):
    """Assert bound <= TIGHTNESS * (error + ulp(scale)) for every value, if well-conditioned.

    Returns whether the position was well-conditioned (max kappa <= KAPPA_WELL).
    """
    try:
        state = mk.solve(scene, angle, speed, accel)
    except mk.AssemblyError:
        return False
    if minimum_measure(state) < 0.05:  # kappa is at least ~1 / measure there: skip its cost
        return False
    exact = ref.reference(scene, angle, speed, accel)
    if max(ref.condition(scene, exact).values()) > KAPPA_WELL:
        return False
    for path, _, error, bound, scale in actual_errors(state, exact):
        assert bound <= TIGHTNESS * (error + float(np.spacing(scale))), (
            scene.name, angle, path, error, bound, scale)
    return True


#: Packaged scenes whose condition number exceeds KAPPA_WELL at every angle tried.
NEVER_WELL_CONDITIONED = {
    'rocking_lever': 'kappa about 21 throughout',
    'jansen_leg': 'five dyads in a chain: kappa 23 to 187 at the eight angles',
}


@pytest.mark.parametrize('name', crank_scene_names())  # several drivers: test_solve_drivers
def test_bound_is_tight_on_the_packaged_scenes(name):
    """Where well-conditioned, a packaged scene's bounds are within 1e3 x (error + 1 ulp)."""
    scene = mk.load_scene(name)
    checked = [assert_tight(scene, scene.input.angle + turn)
               for turn in np.linspace(0, 2 * np.pi, 8, endpoint=False)]
    assert any(checked) or name in NEVER_WELL_CONDITIONED


@pytest.mark.parametrize('name', crank_scene_names())  # several drivers: test_solve_drivers
def test_bound_covers_the_actual_error_on_the_packaged_scenes(name):
    """At eight angles of a turn, no value of a packaged scene is off by more than its bound."""
    scene = mk.load_scene(name)
    answered = []
    for angle in scene.input.angle + np.linspace(0, 2 * np.pi, 8, endpoint=False):
        with contextlib.suppress(mk.AssemblyError):
            state = mk.solve(scene, angle, max_error=math.inf)
            if not all(e.engaged for e in state.intermittent.values()):
                continue  # the reference has no dwell: test_geneva checks locked wheels
        answered.append(assert_bounded(scene, angle)[0] is not None)
    assert sum(answered) >= 2, answered


@settings(SETTINGS, max_examples=100)
@given(mechanisms, motions, angles)
def test_bound_is_tight_where_well_conditioned(scene, motion, angle):
    """On random well-conditioned positions, bound <= 1e3 x (actual error + 1 ulp of scale)."""
    try:
        assume(assert_tight(scene, angle, *motion))
    except mk.AssemblyError:
        assume(False)


# --- the packaged scenes, both paths, the API --------------------------------------------


@pytest.mark.parametrize('name', crank_scene_names())  # several drivers: test_solve_drivers
def test_packaged_scenes_are_answered_wherever_they_assemble(name):
    """Over 3600 angles every packaged scene is answered except where it cannot assemble."""
    scene = mk.load_scene(name)
    theta = scene.input.angle + np.linspace(0, 2 * np.pi, 3600, endpoint=False)
    state = mk.solve(scene, theta)
    for lever, engagement in state.intermittent.items():
        # A Geneva wheel's acceleration jumps at the slot's mouth: the two samples
        # within rounding of an engagement instant are answered one-sided, the
        # other side in "jumps" (issue 19), and no others.
        instant = np.minimum(*(abs(np.remainder(theta - edge[0] + np.pi, 2 * np.pi) - np.pi)
                               for edge in (engagement.entry, engagement.exit)))
        jumped = ~np.isnan(state.jumps['joints'][lever]['acceleration'])
        np.testing.assert_array_equal(jumped, instant < 1e-12)
        assert jumped.sum() == 2 and state.valid[jumped].all()
    assert all(' (' not in key for key in state.failures), state.failures  # none untrusted
    assert np.nanmax(state.relative_error_bound) < 1e-10
    for index in np.flatnonzero(~state.valid)[::97]:  # refused: the reference agrees
        with pytest.raises(ref.NoAssembly):
            ref.reference(scene, float(theta[index]))


def assert_paths_agree(scene, theta, speed=None, accel=None, max_errors=(1e-3, 1e-6, 1e-9)):
    """Assert both paths give the same bounds, bit for bit, and refuse the same angles."""
    for max_error in max_errors:
        vector = mk.solve(scene, theta, speed, accel, max_error=max_error)
        vector_bounds = vector.error_bound.raw()
        for index, angle in enumerate(theta):
            try:
                single = mk.solve(scene, float(angle), speed, accel, max_error=max_error)
            except mk.AssemblyError as error:
                assert not vector.valid[index], (angle, error)
                assert any(key.startswith(error.dyad) and vector.failures[key][index]
                           for key in vector.failures)
                continue
            assert vector.valid[index], angle
            for got, table in zip(single.error_bound.raw(), vector_bounds, strict=True):
                for name, values in got.items():
                    assert tuple(values) == tuple(x[index] for x in table[name]), name


@pytest.mark.parametrize(('scene', 'singular'), [(CHANGE_POINT, 0.0),
                                                 (PIN_THROUGH_PIVOT, -math.pi / 2),
                                                 (SUITE[0][1], SUITE[0][2][0] + 1e-9)])
def test_single_angle_and_array_paths_give_the_same_bounds_and_refusals(scene, singular):
    """Near a singular position both paths give the same bits and refuse the same angles."""
    assert_paths_agree(scene, singular + np.concatenate([-np.logspace(-1, -12, 23), [0.0],
                                                         np.logspace(-12, -1, 23)]))


@settings(SETTINGS, max_examples=60)
@given(mechanisms, motions)
def test_paths_give_the_same_bounds_on_random_mechanisms(scene, motion):
    """On random mechanisms over a cycle, both paths' bounds and refusals are identical."""
    theta = scene.input.angle + np.linspace(-np.pi, np.pi, 24, endpoint=False)
    assert_paths_agree(scene, theta, *motion, max_errors=(1e-6, 1e-12))


def test_the_array_path_judges_with_each_angles_own_scales():
    """Angles whose bounds exceed the floors of the scales are judged with their own scales.

    The array path judges only those angles (``_judge``), with the norms of
    their values. At a tolerance that refuses about half of a coupler-point
    four-bar's assembled angles, its refusals are exactly where the state's
    relative bound exceeds the tolerance, as the single-angle path refuses,
    and some angles answered have a bound beyond the tolerance times the
    crank tip's speed (the floor): judged by the floor alone, they would be
    refused.
    """
    scene = mk.load_scene('four_bar_coupler_points')
    theta = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    everything = mk.solve(scene, theta, max_error=math.inf)
    relative = everything.relative_error_bound
    ordered = np.sort(relative[everything.valid])
    middle = len(ordered) // 2
    tol = float(np.sqrt(ordered[middle] * ordered[middle + 1]))  # between two samples
    state = mk.solve(scene, theta, max_error=tol)
    np.testing.assert_array_equal(state.valid, everything.valid & (relative <= tol))
    assert 0 < state.valid.sum() < everything.valid.sum()
    crank = scene.input
    rate = crank.speed ** 2 + abs(crank.accel)
    joints, points = everything.error_bound.raw()
    against_floors = np.fmax.reduce(
        [b[1] / (crank.length * abs(crank.speed)) for b in points.values()]
        + [b[2] / (crank.length * rate) for b in points.values()]
        + [b[1] / abs(crank.speed) for b in joints.values()]
        + [b[2] / rate for b in joints.values()])
    assert (state.valid & (against_floors > tol)).sum() > 20
    for index in range(0, len(theta), 7):
        try:
            mk.solve(scene, float(theta[index]), max_error=tol)
        except mk.AssemblyError:
            assert not state.valid[index]
        else:
            assert state.valid[index]


def test_refused_angles_name_the_reason_in_failures():
    """The array path marks untrusted angles invalid under '<dyad> (untrusted)'."""
    theta = np.array([0.3, 1e-6, -1e-6, 1e-2])
    state = mk.solve(CHANGE_POINT, theta)
    np.testing.assert_array_equal(state.valid, [True, False, False, True])
    np.testing.assert_array_equal(state.failures['RRR C (untrusted)'], [False, True, True, False])
    assert np.isnan(state.joints['rocker'].acceleration[1])
    assert np.isnan(state.error_bound.joints['rocker'].acceleration[1])
    assert np.isfinite(state.error_bound.points['C'].velocity[[0, 3]]).all()
    relative = state.relative_error_bound
    assert np.isnan(relative[1]) and relative[3] < 1e-6 < mk.solve(
        CHANGE_POINT, 1e-6, max_error=math.inf).relative_error_bound


def test_tolerance_decides_refusal_exactly():
    """A state is answered iff its largest relative bound is within max_error (to rounding)."""
    answered = mk.solve(CHANGE_POINT, 1e-3, max_error=math.inf)
    worst = answered.relative_error_bound
    assert 1e-12 < worst < 1e-3
    mk.solve(CHANGE_POINT, 1e-3, max_error=worst * (1 + 1e-12))
    assert mk.solve(CHANGE_POINT, np.array([1e-3]), max_error=worst * (1 + 1e-12)).valid.all()
    with pytest.raises(mk.UntrustedError) as caught:
        mk.solve(CHANGE_POINT, 1e-3, max_error=worst * (1 - 1e-9))
    assert not mk.solve(CHANGE_POINT, np.array([1e-3]), max_error=worst * (1 - 1e-9)).valid[0]
    assert caught.value.bound > caught.value.tolerance


@pytest.mark.parametrize('bad', [0.0, -1e-6, math.nan, '1e-6', None])
def test_max_error_must_be_a_positive_number(bad):
    """max_error of zero, negative, NaN or not a number is refused with a clear ValueError."""
    with pytest.raises(ValueError, match='max_error'):
        mk.solve(CHANGE_POINT, 0.3, max_error=bad)


def test_rounding_limit_is_refused_whatever_the_tolerance():
    """A guide within rounding of its reach is refused even with an infinite tolerance."""
    scene = slider_crank('grazing', 0.125, 0.1875, offset=0.0625)
    with pytest.raises(mk.UntrustedError) as caught:
        mk.solve(scene, -math.pi / 2 + 1e-9, max_error=math.inf)
    error = caught.value
    assert error.value == 'margin' and 'within rounding' in error.reason
    assert error.bound > 0 and error.tolerance < error.bound
    assert isinstance(error, mk.AssemblyError)  # the node's handler catches it as before


def test_error_bound_in_as_dict_and_records():
    """as_dict()['error_bound'] is shaped like joints and points, one number per value."""
    scene = mk.load_scene('quick_return')
    state = mk.solve(scene, 0.3)
    data = state.as_dict()
    bounds = data['error_bound']
    assert set(bounds['joints']) == set(data['joints'])
    assert set(bounds['points']) == set(data['points'])
    for group in ('joints', 'points'):
        for name, record in bounds[group].items():
            assert set(record) == {'position', 'velocity', 'acceleration'}
            for quantity, value in record.items():
                assert isinstance(value, float) and 0.0 <= value < 1e-9, (name, quantity)
                assert value == getattr(getattr(state.error_bound, group)[name], quantity)
    # A ground point is exact to its coordinates' rounding and does not move.
    assert bounds['points']['O'] == {'position': 0.0, 'velocity': 0.0, 'acceleration': 0.0}
    vector = mk.solve(scene, np.array([0.3, 0.4])).as_dict()['error_bound']
    assert vector['joints']['ram']['velocity'].shape == (2,)
    assert vector['joints']['ram']['velocity'][0] == bounds['joints']['ram']['velocity']


def test_scales_follow_their_definition():
    """position: size; angle: 1 rad; rates: the largest reported, floored by the crank's."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    state = mk.solve(scene, 1.0, -12.0, 5.0)
    scales = state.scales
    assert scales['position'] == 0.15 and scales['angle'] == 1.0
    speeds = [float(np.hypot(*p.velocity)) for p in state.points.values()]
    assert scales['velocity'] == max(speeds + [0.04 * 12.0])
    assert scales['angular velocity'] == max(abs(j.velocity) for j in state.joints.values())
    assert scales['angular acceleration'] == max(
        [abs(j.acceleration) for j in state.joints.values()] + [144.0 + 5.0])
    at_rest = mk.solve(scene, 1.0, 0.0, 0.0)
    assert at_rest.scales['velocity'] == 0.0
    assert at_rest.error_bound.points['C'].velocity == 0.0  # nothing moves: exact zeros


def test_state_built_without_init_equals_the_dataclass():
    """The solver's fast State construction gives what State(...) gives."""
    state = mk.solve(mk.load_scene('whitworth'), 0.5)
    fields = {f.name: getattr(state, f.name) for f in dataclasses.fields(mk.State)}
    assert mk.State(**fields) == state
    assert state.points['C'].position.shape == (2,)  # cached properties still work


def test_untrusted_error_is_one_clear_line():
    """The refusal names the dyad, the value, its bound and the tolerance on one line."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        with pytest.raises(mk.UntrustedError) as caught:
            mk.solve(CHANGE_POINT, 1e-6)
    error = caught.value
    text = str(error)
    assert '\n' not in text
    for part in (error.dyad, error.value.split('.')[1], f'{error.bound:.3g}', '1e-06 x'):
        assert part in text


@pytest.mark.parametrize('speed', [1e-160, 1e-300, 1e-320])
def test_tiny_speeds_are_answered_and_right(speed):
    """1e-160 and 1e-320 rad/s were refused ("at most 1e-06 x 0 m/s^2"); 0 was answered.

    Velocities are linear in the speed: each equals ``speed`` times the one at
    1 rad/s, within its error bound plus the float format's resolution (issue 21).
    """
    scene = mk.load_scene('khurmi_four_bar_ad150')
    unit = mk.solve(scene, 1.0, speed=1.0, accel=0.0)
    tiny = mk.solve(scene, 1.0, speed=speed, accel=0.0)
    bounds = tiny.error_bound
    for name, joint in tiny.joints.items():
        expected = speed * unit.joints[name].velocity
        assert abs(joint.velocity - expected) <= (bounds.joints[name].velocity
                                                  + 1e-9 * abs(expected) + 1e-322)
        assert joint.position == unit.joints[name].position


def _four_bar_yaml(crank: str, coupler: str, rocker: str, ground: str) -> str:
    return (f'name: huge\nunits: {{length: m, angle: deg}}\n'
            f'ground: {{A: [0, 0], D: [{ground}, 0]}}\n'
            f'input: {{link: crank, center: A, point: B, length: {crank}, angle: 60, '
            f'speed_rpm: 1}}\n'
            f'dyads:\n  - type: RRR\n    point: C\n    links:\n'
            f'      - {{name: coupler, from: B, length: {coupler}}}\n'
            f'      - {{name: rocker, from: D, length: {rocker}}}\n    branch: 1\n')


def test_lengths_near_the_largest_float_load_and_solve(tmp_path):
    """1e308 m lengths said "OverflowError: math range error" (issue 21): now they solve."""
    path = tmp_path / 'huge.yaml'
    path.write_text(_four_bar_yaml('0.4e308', '1.5e308', '0.8e308', '1.5e308'))
    scene = mk.load_scene(str(path))
    state = mk.solve(scene, 1.0, speed=1e-3, accel=0.0)
    b = state.points['B'].position
    assert b[0] == pytest.approx(0.4e308 * math.cos(1.0), rel=1e-15)
    assert b[1] == pytest.approx(0.4e308 * math.sin(1.0), rel=1e-15)
    normal = mk.solve(mk.load_scene('khurmi_four_bar_ad150'), 1.0, speed=1e-3, accel=0.0)
    for name, joint in state.joints.items():
        assert joint.position == pytest.approx(normal.joints[name].position, abs=1e-12)


def test_the_largest_float_as_a_length_is_named_as_it_is(tmp_path):
    """A crank of 1.7976931348623157e308 m is refused with a true reason, never an overflow."""
    path = tmp_path / 'max.yaml'
    path.write_text(_four_bar_yaml('1.7976931348623157e308', '150', '80', '150'))
    with pytest.raises(mk.SceneError) as raised:
        mk.load_scene(str(path))
    message = str(raised.value)
    assert 'cannot reach from B to D (1.79769e+308 m apart, more than 230 m)' in message
    assert 'inf' not in message and 'Overflow' not in message


def test_the_largest_float_in_rpm_is_a_finite_speed():
    """1.7976931348623157e308 rpm became inf rad/s ("got inf"); now 1.88e307 rad/s (issue 21).

    Values whose product with pi fits keep their bits (``rpm * pi / 30``).
    """
    from mech_kinematics.units import rad_per_s_from_rpm, rpm_from_rad_per_s

    largest = 1.7976931348623157e308
    assert rad_per_s_from_rpm(largest) == pytest.approx(largest / 30 * math.pi, rel=1e-15)
    assert rpm_from_rad_per_s(largest) == pytest.approx(largest / math.pi * 30, rel=1e-15)
    assert rad_per_s_from_rpm(-1e3) == -1e3 * math.pi / 30
    assert rpm_from_rad_per_s(2.5) == 2.5 * 30 / math.pi
    scene = mk.load_scene('khurmi_four_bar_ad150')
    with pytest.raises(mk.AssemblyError, match='the state overflows') as raised:
        mk.solve(scene, 1.0, rad_per_s_from_rpm(largest))
    assert 'inf' not in str(raised.value)


#: Well-conditioned positions of near-degenerate scenes (issue 19, "Loose bounds"): a
#: slider-crank whose rod is 1.000001 times its crank, at and near both dead centres, and
#: slotted levers whose pin passes 1e-3 and 1e-6 of the crank from the lever's pivot, at
#: positions away from that pass.
NEAR_DEGENERATE = [
    *((slider_crank('short_rod', 0.1, 0.1000001), angle)
      for angle in (0.0, 1e-3, math.pi - 1e-3, math.pi)),
    *((slotted_lever(f'near_pivot_{name}', 0.15 * (1 + h), ram=False), angle)
      for name, h in (('1e_3', 1e-3), ('1e_6', 1e-6))
      for angle in (math.pi / 2, 0.0, 2.5, math.pi)),
]


@pytest.mark.parametrize(('scene', 'angle'), NEAR_DEGENERATE,
                         ids=[f'{s.name}-{a:.6g}' for s, a in NEAR_DEGENERATE])
def test_bound_is_within_1e3_of_a_1_ulp_change_of_the_inputs_where_well_conditioned(scene,
                                                                                    angle):
    """Bound <= 1e3 x (what a 1-ulp change of the inputs moves the value + 1 ulp of its scale).

    Measured 33-204 (the slider-crank's rod acceleration at its dead centres is the
    largest). Without the ulp of the scale, a value that is nearly 0 at a dead centre
    (the piston's speed, the rod's angular acceleration) moves 1e4-1e7 times less than
    its bound: the norm-wise bounds do not see the inputs' errors cancel there
    (docs/accuracy.md, "Where the bounds are loose"). And never below the actual error.
    """
    state, exact = assert_bounded(scene, angle)
    assert state is not None
    assert max(ref.condition(scene, exact).values()) <= KAPPA_WELL
    spreads = first_order_spreads(scene, angle, exact=exact)
    worst = max(bound / (spreads[path] + float(np.spacing(scale)))
                for path, _, _, bound, scale in actual_errors(state, exact))
    assert worst <= TIGHTNESS, worst


def test_a_chain_of_equilateral_dyads_is_bounded_where_answered():
    """45 dyads: every value within its bound (against the 50-digit reference).

    45 used to be refused at the assembly check; from 17 on, on an acceleration bound.
    """
    scene = equilateral_chain(45)
    state, _ = assert_bounded(scene, 0.3)
    assert state is not None
    assert min(state.singularity.values()) == pytest.approx(math.sqrt(3) / 2, rel=1e-12)
    mk.solve(scene, 0.3)  # and answered at the default tolerance


def strip_truth(n, angle, speed, accel):
    """Return each pin of ``equilateral_chain(n)`` as (p, v, a), exact to 40 digits.

    The strip is one rigid body turning with the crank about A: its pins are the
    points of a triangular lattice, each the previous two's third vertex.
    """
    with mpmath.workdps(40):
        turn = mpmath.expj(angle)
        previous, current = mpmath.mpc(0), mpmath.mpc(1)
        sixth = mpmath.expj(mpmath.pi / 3)
        pins = []
        for k in range(n):
            side = sixth if k % 2 == 0 else mpmath.conj(sixth)
            previous, current = current, previous + (current - previous) * side
            p = turn * current
            pins.append((p, 1j * speed * p, (1j * accel - speed * speed) * p))
        return pins


def strip_errors(dyads):
    """Return the pins' largest actual error and bound over their kinds' scales, p / v / a.

    Each as text to two significant digits, as docs/robustness.md's table gives them;
    the truth is :func:`strip_truth`'s, every pin within its bound.
    """
    state = mk.solve(equilateral_chain(dyads), 0.3)
    _, bounds = state.error_bound.raw()
    errors, bounded = [0.0] * 3, [0.0] * 3
    for k, truth in enumerate(strip_truth(dyads, 0.3, 2.0, 0.5)):
        values = state.complex_points[f'P{k}']
        for index, (value, exact, bound) in enumerate(zip(values, truth, bounds[f'P{k}'],
                                                          strict=True)):
            error = float(abs(mpmath.mpc(value) - exact))
            assert error <= bound, (k, index, error, bound)
            errors[index] = max(errors[index], error)
            bounded[index] = max(bounded[index], float(bound))
    scales = [float(state.scales[kind]) for kind in ('position', 'velocity', 'acceleration')]
    return (' / '.join(f'{e / s:.2g}' for e, s in zip(errors, scales, strict=True)),
            ' / '.join(f'{b / s:.2g}' for b, s in zip(bounded, scales, strict=True)))


def test_the_long_chains_table_is_measured():
    """docs/robustness.md's table of strips gives what the solver answers, row by row."""
    text = (ROOT / 'docs' / 'robustness.md').read_text(encoding='utf-8')
    section = text[text.index('## Long chains'):]
    section = section[:section.index('\n## ')]
    rows = re.findall(r'^\| ([\d,]+) \| ([^|]+) \| ([^|]+) \|$', section, re.MULTILINE)
    assert [int(n.replace(',', '')) for n, _, _ in rows] == [5, 20, 45, 500, 2000]
    for dyads, actual, bound in rows:
        assert strip_errors(int(dyads.replace(',', ''))) == (actual.strip(), bound.strip())


@pytest.mark.parametrize('dyads', [500, 2000])
def test_long_chains_of_equilateral_dyads_are_answered_within_their_bounds(dyads):
    """500 and 2,000 dyads are answered (they were refused): every pin within its bound.

    Each dyad closes a rigid triangle on its predecessor's link, and its bounds carry
    that link's motion (docs/robustness.md, "Long chains"): they grow about as the
    square of the number of dyads, as the actual error does.
    """
    scene = equilateral_chain(dyads)
    state = mk.solve(scene, 0.3)
    _, bounds = state.error_bound.raw()
    worst = 0.0
    for k, truth in enumerate(strip_truth(dyads, 0.3, 2.0, 0.5)):
        values = state.complex_points[f'P{k}']
        for value, exact, bound in zip(values, truth, bounds[f'P{k}'], strict=True):
            error = float(abs(mpmath.mpc(value) - exact))
            assert error <= bound, (k, error, bound)
            worst = max(worst, float(bound) / max(error, 1e-300))
    far = bounds[f'P{dyads - 1}']
    assert far[0] < 1e-6 * dyads  # metres, the pin about dyads / 2 m from A
    for name, joint in state.joints.items():
        assert joint.velocity == pytest.approx(2.0, rel=1e-9), name
        assert joint.acceleration == pytest.approx(0.5, rel=1e-9), name


@pytest.mark.parametrize('size', [1e-300, 1e-200, 1e200, 1e300])
def test_strips_of_any_size_are_answered_alike(size):
    """A strip of 1e-300 m triangles built (its lengths' product underflowed: ZeroDivisionError).

    At every size the rigid triangles' bounds are those of the 1 m strip, to rounding.
    """
    unit = mk.solve(equilateral_chain(50), 0.3).relative_error_bound
    dyads, previous, current = [], 'A', 'B'
    for k in range(50):
        dyads.append(mk.RRR(f'P{k}', (mk.Link(f'a{k}', previous, size),
                                      mk.Link(f'b{k}', current, size)), 1 - 2 * (k % 2)))
        previous, current = current, f'P{k}'
    scene = mk.Scene('strip', {'A': (0.0, 0.0)},
                     mk.Crank('crank', 'A', 'B', size, 0.3, 2.0, 0.5), tuple(dyads))
    state = mk.solve(scene, 0.3)
    assert state.relative_error_bound == pytest.approx(unit, rel=0.05)
    assert state.joints['b49'].position == pytest.approx(0.3, abs=1e-13)


def four_bar_chain(n, angle=0.3):
    """Return ``n`` four-bars in series, each driven by the previous one's rocker tip.

    Dyad k joins the previous pin by a 1 m link to a 1 m rocker about its own ground
    pivot, 1 m to the right of that pin at ``angle``: every dyad's measure is 0.866.
    """
    ground, dyads = {'A': (0.0, 0.0)}, []
    previous, where, side = 'B', cmath.exp(1j * angle), 1
    for k in range(n):
        pivot = where + 1.0
        ground[f'G{k}'] = (pivot.real, pivot.imag)
        dyads.append(mk.RRR(f'P{k}', (mk.Link(f'a{k}', previous, 1.0),
                                      mk.Link(f'b{k}', f'G{k}', 1.0)), side))
        previous, where, side = f'P{k}', where + cmath.exp(1j * side * math.pi / 3), -side
    crank = mk.Crank('crank', 'A', 'B', 1.0, angle, 2.0, 0.5)
    return mk.Scene(f'four_bars{n}', ground, crank, tuple(dyads))


def test_a_chain_of_four_bars_is_bounded_and_answered_to_100():
    """40 four-bars in series within their bounds; 100 answered (from 21 on they were refused).

    A pin moves with its starts' errors through two maps of norm 1 / measure each:
    the bound adds the two starts' bounds over the measure once (it added the first
    start's again), so it grows 1.15 times a dyad here, where the actual error does
    not grow (docs/robustness.md, "Long chains").
    """
    state, _ = assert_bounded(four_bar_chain(40), 0.3)
    assert state is not None
    assert state.relative_error_bound < 1e-9
    assert mk.solve(four_bar_chain(100), 0.3).relative_error_bound < 1e-6


def truss_pairs(scene):
    """Return the pairs of points fixed on one link of ``scene``, by its generator's name."""
    return {'four_bar': [('B', 'C'), ('A', 'B'), ('D', 'C'), ('B', 'E'), ('E', 'C')],
            'slider_crank': [('B', 'P'), ('A', 'B'), ('P', 'M')],
            'slotted_lever': [('O', 'C'), ('A', 'B')],
            'six_link': [('B', 'E'), ('E', 'C'), ('E', 'M')]}[scene.name]


@st.composite
def trusses(draw):
    """Draw a mechanism with a strip of two rigid triangles on one of its links.

    The first RRR's starts are two points fixed on a link of the mechanism (its
    crank, coupler, rocker, rod, slotted lever, carried points among them); the
    second's are the first's start and pin, both on the first's second link.
    """
    base = draw(mechanisms)
    first, second = draw(st.sampled_from(truss_pairs(base)))
    try:
        points = mk.solve(base, base.input.angle, max_error=math.inf).complex_points
    except mk.AssemblyError:
        assume(False)
    d = abs(complex(points[first][0]) - complex(points[second][0]))
    assume(d > 0)
    l1 = lerp(0.4, 1.6, draw(unit)) * d
    l2 = lerp(abs(l1 - d), l1 + d, lerp(0.1, 0.9, draw(unit)))
    l3 = lerp(0.4, 1.6, draw(unit)) * l2
    l4 = lerp(abs(l3 - l2), l3 + l2, lerp(0.1, 0.9, draw(unit)))
    dyads = [*base.dyads,
             mk.RRR('T', (mk.Link('t1', first, l1), mk.Link('t2', second, l2)), draw(signs)),
             mk.RRR('S', (mk.Link('s1', second, l3), mk.Link('s2', 'T', l4)), draw(signs))]
    return build(base.name, {k: complex(*v) for k, v in base.ground.items()}, base.input,
                 dyads, base.points)


@settings(SETTINGS, max_examples=150)
@given(trusses(), motions, angles)
def test_bound_covers_the_actual_error_of_rigid_triangles_on_any_link(scene, motion, angle):
    """An RRR whose starts are fixed on one link is bounded as carried by it: never below."""
    assert_bounded(scene, angle, *motion)
