# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A robot described in URDF, solved under its own names and signs. See issue 31.

Every value is checked with the URDF's own forward kinematics, written once in
test/helpers.py apart from the package (``UrdfFk``): the joint values we answer
close every loop of the URDF within 1e-12 of the loop's size, and our
velocities and accelerations move the URDF's links so that the loops stay
closed (the gap of the pose extrapolated by ``h`` is O(h^3)).
"""

import math
import xml.etree.ElementTree as ET

from helpers import khurmi_urdf, UrdfFk
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.writer import robot_urdf_from_scene

#: A loop closes within this, over its size: the contract's exactness.
RTOL_CLOSURE = 1e-12
#: Round-tripped frames against the scene's own, over the mechanism's size (and rad).
RTOL_SAME = 1e-12
#: Step of the finite differences (s) and what O(h^2) allows at it (relative to the rate).
H = 1e-4
RTOL_DIFFERENCE = 1e-6
#: Scenes whose URDF form is refused, and why.
NO_URDF = {'geneva': 'intermittent'}
SCENES = [name for name in mk.scene_names() if name not in NO_URDF]


def test_the_four_bar_in_urdf_answers_the_scene_under_the_urdf_signs():
    """Khurmi's rocker pivot turns about -z: its joint is minus the rocker's absolute turn."""
    robot = load_robot(khurmi_urdf())
    scene = mk.load_scene('khurmi_four_bar_ad150')
    answer = robot.solve({'motor': 0.25}, {'motor': -12.566}, {'motor': 3.0})
    state = mk.solve(scene, math.pi / 3 + 0.25, -12.566, 3.0)
    rocker = state.joints['rocker']
    start = mk.solve(scene, math.pi / 3).joints['rocker'].position
    joint = answer.joints['rocker_pivot']
    assert joint.position == pytest.approx(-(rocker.position - start), abs=1e-13)
    assert joint.velocity == pytest.approx(-rocker.velocity, rel=1e-12)
    assert joint.acceleration == pytest.approx(-rocker.acceleration, rel=1e-12)
    coupler = state.joints['coupler']
    elbow = answer.joints['elbow']
    assert elbow.velocity == pytest.approx(coupler.velocity - (-12.566), rel=1e-12)
    assert list(answer.joints) == ['motor', 'elbow', 'rocker_pivot']


@pytest.mark.parametrize('form', ['constraint', 'closing frames'])
def test_every_closure_form_gives_the_same_joints_and_closes_the_urdf(form):
    """A <constraint> and closing_C_1/_2 frames (turned as they like) give the same joints."""
    text = khurmi_urdf(form)
    robot = load_robot(text)
    fk = UrdfFk(text)
    reference = load_robot(khurmi_urdf('constraint'))
    for angle in np.linspace(-1.0, 1.0, 9):
        answer = robot.solve({'motor': float(angle)})
        values = {n: j.position for n, j in answer.joints.items()}
        for name, value in reference.solve({'motor': float(angle)}).joints.items():
            assert values[name] == pytest.approx(value.position, abs=1e-14)
        for closure, gap in fk.gaps(values).items():
            assert gap <= RTOL_CLOSURE * fk.loop_size(closure)


def test_a_loop_closures_yaml_sidecar_is_read_with_its_independent_joints(tmp_path):
    """scikit-robot's sidecar: closures at a root-frame point, independent joints as drivers."""
    text = khurmi_urdf('constraint')
    root = ET.fromstring(text)
    root.remove(root.find('constraint'))
    root.remove(root.find('transmission'))
    urdf = tmp_path / 'khurmi.urdf'
    urdf.write_text(ET.tostring(root, encoding='unicode'))
    state = mk.solve(mk.load_scene('khurmi_four_bar_ad150'), math.pi / 3)
    c = state.complex_points['C'][0]
    sidecar = tmp_path / 'loop_closures.yaml'
    sidecar.write_text(f'closures:\n- link_a: coupler\n  link_b: rocker\n  point: [{c.real!r}, '
                       f'{c.imag!r}, 0.0]\n  axis: [0.0, 0.0, 1.0]\ndependent: [elbow, '
                       f'rocker_pivot]\nindependent: [motor]\n')
    robot = load_robot(urdf, sidecar)
    assert robot.actuated == ('motor',)
    fk = UrdfFk(urdf.read_text(), sidecar)
    answer = robot.solve({'motor': 0.7})
    values = {n: j.position for n, j in answer.joints.items()}
    assert max(fk.gaps(values).values()) <= RTOL_CLOSURE * 0.2
    expected = load_robot(khurmi_urdf()).solve({'motor': 0.7}).joints
    assert values['rocker_pivot'] == pytest.approx(expected['rocker_pivot'].position, abs=1e-13)


def test_a_loop_anywhere_in_space_with_out_of_plane_offsets_gives_the_same_joints():
    """The four-bar hung on a tilted, shifted base, its coupler 7 mm out of the plane."""
    flat = load_robot(khurmi_urdf()).solve({'motor': 0.4}, {'motor': 2.0})
    text = khurmi_urdf(dz=0.007).replace(
        '<link name="frame"/>', '<link name="world"/><link name="frame"/><joint name="mount" '
        'type="fixed"><parent link="world"/><child link="frame"/><origin xyz="1 -2 0.5" '
        'rpy="0.4 -1.1 2.3"/></joint>')
    robot = load_robot(text)
    answer = robot.solve({'motor': 0.4}, {'motor': 2.0})
    for name, joint in flat.joints.items():
        assert answer.joints[name].position == pytest.approx(joint.position, abs=1e-13)
        assert answer.joints[name].velocity == pytest.approx(joint.velocity, abs=1e-12)
    fk = UrdfFk(text)
    values = {n: j.position for n, j in answer.joints.items()}
    assert max(fk.gaps(values).values()) <= RTOL_CLOSURE * fk.loop_size('pin_C')


def _taylor_gap(fk, answer, h):
    """Return the largest closure gap (m) of the pose moved by ``h`` s along our rates."""
    values = {n: j.position + h * j.velocity + 0.5 * h * h * j.acceleration
              for n, j in answer.joints.items()}
    return max(fk.gaps(values).values())


@pytest.mark.parametrize('name', SCENES)
def test_every_packaged_scene_round_trips_through_its_urdf(name):
    """Read back, `urdf --robot` puts every body's link where the scene puts the body.

    At drivers moved from their start, the URDF's forward kinematics with the
    joints we answer puts each link at its body's angle, and each of the
    body's points (fixed in the link at the zero pose, the scene's start)
    where the scene puts it, within 1e-12 of the size; every loop closes.
    """
    from mech_kinematics.geometry.instant_centres import full_scene
    scene = mk.load_scene(name)
    full = full_scene(scene)
    text = robot_urdf_from_scene(scene, frame_id='base', prefix='r')
    robot = load_robot(text)
    fk = UrdfFk(text)
    graph = scene.graph

    def solve_scene(values):
        return mk.solve(full, values[0] if len(values) == 1 else values)

    def angle_of(state, frame):
        return frame.angle if frame.angle_of is None else state.joints[frame.angle_of].position

    start = solve_scene([d.start for d in scene.drivers])
    zero = fk.transforms({})
    local = {}
    for body, frame in graph.frames():
        link = zero[f'r/{body}']
        origin = complex(link[0, 3], link[1, 3])
        turn = complex(math.cos(angle_of(start, frame)), -math.sin(angle_of(start, frame)))
        local[body] = {p: (start.complex_points[p][0] - origin) * turn
                       for p in graph.bodies[body].points}
    size = max(abs(p) for p, _, _ in start.complex_points.values())
    rng = np.random.default_rng(31)
    checked = 0
    for _ in range(12):
        steps = {d.name: (rng.uniform(-0.5, 0.5) if d.joint_type.angular
                          else rng.uniform(-0.1, 0.1) * d.start) for d in scene.drivers}
        try:
            state = solve_scene([d.start + steps[d.name] for d in scene.drivers])
        except mk.AssemblyError:
            continue
        urdf = {d.name: d.reference + steps[d.name] / d.sigma for d in robot.planar.drivers}
        # Rates up to 2 rad/s, or 2 m/s (at most 2 sizes a second: the Taylor bound's rates).
        speeds = {d.name: float(rng.uniform(-2, 2)) * (1.0 if d.type.angular else min(size, 1.0))
                  for d in robot.planar.drivers}
        answer = robot.solve(urdf, speeds)
        values = {n: j.position for n, j in answer.joints.items()}
        frames = fk.transforms(values)
        for body, frame in graph.frames():
            link = frames[f'r/{body}']
            theta = math.atan2(link[1, 0], link[0, 0])
            assert math.remainder(theta - angle_of(state, frame), math.tau) == pytest.approx(
                0.0, abs=RTOL_SAME)
            origin = complex(link[0, 3], link[1, 3])
            for point, z in local[body].items():
                placed = origin + z * complex(math.cos(theta), math.sin(theta))
                assert abs(placed - state.complex_points[point][0]) <= RTOL_SAME * size
        for closure, gap in fk.gaps(values).items():
            assert gap <= RTOL_CLOSURE * fk.loop_size(closure)
        # Our rates keep the URDF's loops closed: the extrapolated pose's gap is O(h^3).
        assert _taylor_gap(fk, answer, H) <= 1e3 * H ** 3 * size
        checked += 1
    assert checked >= 3


def test_a_geneva_wheel_has_no_urdf_form_and_says_why(capsys):
    """An intermittent slot cannot be a URDF joint: urdf --robot refuses in one line."""
    assert cli_main(['urdf', 'geneva', '--robot']) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'intermittent' in err


@pytest.mark.parametrize('name', ['khurmi_four_bar_ad150', 'excavator', 'quick_return',
                                  'scotch_yoke', 'five_bar'])
def test_passive_rates_match_central_differences_of_the_positions(name):
    """Each joint's velocity and acceleration against central differences (h = 1e-4 s).

    The actuated joints move as p + v t + a t^2 / 2; the differences of the
    positions we answer at t = -h, 0, h match our rates to O(h^2).
    """
    robot = load_robot(robot_urdf_from_scene(mk.load_scene(name)))
    rng = np.random.default_rng(7)
    for _ in range(3):
        p = {n: robot.start(n) + rng.uniform(-0.2, 0.2) * (1 if robot.joint_type(n).angular
                                                           else 0.05) for n in robot.actuated}
        v = {n: rng.uniform(-1, 1) for n in robot.actuated}
        a = {n: rng.uniform(-1, 1) for n in robot.actuated}
        try:
            now, before, after = (robot.solve({n: p[n] + t * v[n] + 0.5 * t * t * a[n]
                                               for n in p},
                                              {n: v[n] + t * a[n] for n in p}, a)
                                  for t in (0.0, -H, H))
        except mk.AssemblyError:
            continue
        for joint in now.joints:
            q = [s.joints[joint].position for s in (before, now, after)]
            if robot.joint_type(joint).angular:
                q = np.unwrap(q)
            velocity = (q[2] - q[0]) / (2 * H)
            acceleration = (q[2] - 2 * q[1] + q[0]) / H ** 2
            motion = now.joints[joint]
            scale = 1 + abs(motion.velocity) + abs(motion.acceleration)
            assert velocity == pytest.approx(motion.velocity, abs=RTOL_DIFFERENCE * scale)
            assert acceleration == pytest.approx(motion.acceleration, abs=1e-3 * scale)


def test_solve_prints_the_urdf_joints_under_their_names(tmp_path, capsys):
    """`solve ROBOT.urdf --input motor=30 --speed motor=60` prints Robot.solve's joints."""
    import json
    path = tmp_path / 'khurmi.urdf'
    path.write_text(khurmi_urdf())
    assert cli_main(['solve', str(path), '--input', 'motor=30', '--speed', 'motor=60',
                     '--accel', 'motor=2']) == 0
    data = json.loads(capsys.readouterr().out)
    answer = load_robot(str(path)).solve({'motor': math.radians(30)},
                                         {'motor': 60 * math.pi / 30}, {'motor': 2.0})
    assert set(data['joints']) == {'motor', 'elbow', 'rocker_pivot'}
    for name, joint in answer.joints.items():
        assert data['joints'][name]['position'] == joint.position
        assert data['joints'][name]['velocity'] == joint.velocity
    assert set(data['error_bound']['joints']) == set(data['joints'])
    assert cli_main(['solve', str(path), '--input', 'elbow=3']) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and "'elbow'" in err


def test_urdf2scene_writes_a_scene_that_solves_as_the_robot(tmp_path, capsys):
    """The written scene loads and its links turn as the robot's joints say."""
    path = tmp_path / 'khurmi.urdf'
    path.write_text(khurmi_urdf())
    out = tmp_path / 'khurmi.yaml'
    assert cli_main(['urdf2scene', str(path), '-o', str(out)]) == 0
    scene = mk.load_scene(out)
    robot = load_robot(str(path))
    state = mk.solve(scene, scene.input.angle + 0.3)
    answer = robot.solve({'motor': 0.3})
    item = robot.planar.joints['rocker_pivot']
    assert answer.joints['rocker_pivot'].position == pytest.approx(
        item.reference + item.sigma * (state.joints['rocker'].position - item.child_ref),
        abs=1e-14)
    assert 'rocker_pivot' in out.read_text()


def test_limits_are_reported_not_refused():
    """A joint past its <limit> is answered and listed under limits."""
    text = khurmi_urdf().replace('<limit lower="-3" upper="3"', '<limit lower="-0.1" upper="0.1"')
    answer = load_robot(text).solve({'motor': 0.5})
    assert 'elbow' in answer.limits
    assert answer.limits['elbow']['position'] == answer.joints['elbow'].position


def test_mimic_joints_follow_their_rule_outside_and_are_checked_inside_a_loop():
    """A mimic outside the loops follows its leader; one inside strays and is reported."""
    extra = ('<link name="flag"/><joint name="flag_joint" type="revolute"><parent '
             'link="rocker"/><child link="flag"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" '
             'effort="1" velocity="1"/><mimic joint="rocker_pivot" multiplier="2" '
             'offset="0.1"/></joint>')
    text = khurmi_urdf().replace('</robot>', extra + '</robot>').replace(
        '<axis xyz="0 0 -1"/>', '<axis xyz="0 0 -1"/><mimic joint="motor" multiplier="-1"/>')
    answer = load_robot(text).solve({'motor': 0.3}, {'motor': 1.0})
    rocker = answer.joints['rocker_pivot']
    flag = answer.joints['flag_joint']
    assert flag.position == 2 * rocker.position + 0.1
    assert flag.velocity == 2 * rocker.velocity
    stray = answer.mimic['rocker_pivot']
    assert stray['leader'] == 'motor'
    assert stray['stray'] == pytest.approx(rocker.position - (-0.3), abs=1e-15)
    assert abs(stray['stray']) > 1e-3


def test_a_mimic_of_the_motor_drives_a_second_loop():
    """Two four-bars; the second's crank mimics the first's motor: it is that loop's input."""
    text = khurmi_urdf()
    twin = text.split('<robot name="khurmi">')[1].split('<transmission')[0]
    for old in ('crank', 'coupler', 'rocker', 'motor', 'elbow', 'pin_C'):
        twin = twin.replace(f'"{old}', f'"{old}2')
    twin = twin.replace('<link name="frame"/>', '').replace(
        '<axis xyz="0 0 1"/>\n    <limit lower="-3.2"',
        '<axis xyz="0 0 1"/><mimic joint="motor" multiplier="0.5" offset="0"/>\n'
        '    <limit lower="-3.2"', 1)
    both = text.replace('</robot>', twin + '</robot>')
    answer = load_robot(both).solve({'motor': 0.6}, {'motor': 1.0})
    assert answer.joints['motor2'].position == 0.3
    alone = load_robot(text).solve({'motor': 0.3}, {'motor': 0.5})
    assert answer.joints['rocker2_pivot'].position == pytest.approx(
        alone.joints['rocker_pivot'].position, abs=1e-14)
    assert answer.joints['rocker2_pivot'].velocity == pytest.approx(
        alone.joints['rocker_pivot'].velocity, abs=1e-13)


def test_an_array_of_positions_solves_many_instants():
    """Arrays of the actuated joints' values give arrays of every joint (Robot.solve)."""
    robot = load_robot(khurmi_urdf())
    angles = np.linspace(-0.5, 0.5, 5)
    many = robot.solve({'motor': angles})
    for k, angle in enumerate(angles):
        one = robot.solve({'motor': float(angle)})
        for name, joint in one.joints.items():
            assert many.joints[name].position[k] == pytest.approx(joint.position, abs=1e-15)


def test_a_bad_input_is_one_line(tmp_path, capsys):
    """A missing actuated joint list, an unknown closure link: one line each, exit 2."""
    path = tmp_path / 'bare.urdf'
    path.write_text(khurmi_urdf().split('<transmission')[0] + '</robot>')
    assert cli_main(['solve', str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert 'motor, elbow, rocker_pivot' in err
    with pytest.raises(UrdfError, match="'nowhere'"):
        load_robot(khurmi_urdf().replace('<child link="rocker"/><child_origin',
                                         '<child link="nowhere"/><child_origin'))
