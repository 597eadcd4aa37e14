# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``plot`` command: panels, labels and values, from a scene and from a bag.

The bags here are written without DDS: the node's own renderer
(:class:`mech_kinematics.ros.messages.TickMessages`, the bytes it publishes) and the
rosbags writer, with the definitions the recorder stores.
"""

import math
from pathlib import Path
import subprocess
import sys

from helpers import BOOM_CYLINDER, FIVE_BAR_TWO_CRANKS, forces_scene, SCENES
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.tools import plot, record as bag_recorder

REPO = Path(__file__).resolve().parents[2]
#: Values drawn are the solver's, untouched: exact up to float64 rounding of |v|.
RTOL = 1e-12
PNG_MAGIC = b'\x89PNG\r\n\x1a\n'
JOINT_PANELS = {'Joint angles', 'Joint angular velocities', 'Joint angular accelerations'}
POINT_PANELS = {'Point paths', 'Point speeds |v|', 'Point accelerations |a|'}
SLIDER_PANELS = {'Slider positions', 'Slider velocities', 'Slider accelerations'}
UNITS = ('[rad]', '[rad/s]', '[rad/s²]', '[m]', '[m/s]', '[m/s²]', '[s]', '[N]', '[N m]',
         '[N m; N for an actuator]')
TYPES = {'joint_states': 'sensor_msgs/msg/JointState',
         'joint_accelerations': 'trajectory_msgs/msg/JointTrajectory',
         'point_accelerations': 'trajectory_msgs/msg/MultiDOFJointTrajectory'}


def panels(fig):
    return {ax.get_title(): ax for ax in fig.axes}


def assert_png(path: Path) -> None:
    data = path.read_bytes()
    assert data.startswith(PNG_MAGIC), f'{path} is not a PNG'
    width, height = int.from_bytes(data[16:20], 'big'), int.from_bytes(data[20:24], 'big')
    assert width >= 800 and height >= 600


def assert_units_everywhere(fig) -> None:
    for ax in fig.axes:
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert label.endswith(UNITS), f'{ax.get_title()!r}: axis label {label!r} has no unit'


def bag_figure(bag, *, scene=None, x='time'):
    """Return the Figure ``plot_bag`` draws, unsaved (PNGs are checked where they matter)."""
    return plot.figure_from_motion(plot.motion_from_bag(bag, scene=scene), x=x)


def scene_figure(scene, *, samples=plot.DEFAULT_SAMPLES, x=None):
    """Return the Figure ``plot_scene`` draws, unsaved (PNGs are checked where they matter)."""
    x = x or ('angle' if scene.single_crank else 'time')
    return plot.figure_from_motion(plot.motion_from_scene(scene, samples=samples, x=x), x=x)


def lines(ax) -> dict:
    return {line.get_label(): line for line in ax.get_lines()
            if not line.get_label().startswith('_')}


def write_bag(path: Path, scene, angles, *, storage='mcap', topics=tuple(TYPES), dt=0.002,
              namespaces=('',), skip=(), scene_text=None, imus=False):
    """Write what the node would publish at ``angles`` (one tick per dt s) to a new bag.

    With ``scene_text``, also the node's latched ``scene`` topic holding it; with
    ``imus``, the scene's ``imu/NAME`` topics (the node's own bytes).
    """
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import get_typestore, Stores
    from rosbags.typesys.msg import get_types_from_msg

    from mech_kinematics.ros.messages import TickMessages

    ticks = TickMessages(scene.output_joints, scene.output_points, 'mechanism')
    store = get_typestore(Stores.EMPTY)
    definitions = {}
    for topic in topics:
        text = bag_recorder.message_definition(TYPES[topic])[1]
        store.register(get_types_from_msg(text, TYPES[topic]))
        definitions[topic] = text
    start = 1_700_000_000 * 10**9
    with Writer(path, version=8, storage_plugin=StoragePlugin[storage.upper()]) as writer:
        connections = {(ns, t): writer.add_connection(f'{ns}/{t}', TYPES[t],
                                                      msgdef=definitions[t],
                                                      rihs01=store.hash_rihs01(TYPES[t]))
                       for ns in namespaces for t in topics}
        if scene_text is not None:
            string = 'std_msgs/msg/String'
            text = bag_recorder.message_definition(string)[1]
            store.register(get_types_from_msg(text, string))
            connection = writer.add_connection('/scene', string, msgdef=text,
                                               rihs01=store.hash_rihs01(string))
            message = store.types[string](data=scene_text)
            writer.write(connection, start, store.serialize_cdr(message, string))
        sensors = {}
        if imus:
            from mech_kinematics.ros.imus import ImuMessages
            from mech_kinematics.ros.ticker import values_from_state

            imu_type = 'sensor_msgs/msg/Imu'
            text = bag_recorder.message_definition(imu_type)[1]
            store.register(get_types_from_msg(text, imu_type))
            sensors = {spec.name: writer.add_connection(f'/imu/{spec.name}', imu_type,
                                                        msgdef=text,
                                                        rihs01=store.hash_rihs01(imu_type))
                       for spec in scene.imus}
            imu_messages = ImuMessages(scene.imus, scene.output_joints, scene.output_points,
                                       'mechanism')
        for i, angle in enumerate(angles):
            if i in skip:
                continue
            stamp = start + round(i * dt * 1e9)
            state = mk.solve(scene, angle)
            rendered = dict(zip(TYPES, ticks.render(state, *divmod(stamp, 10**9)), strict=True))
            for (_, topic), connection in connections.items():
                writer.write(connection, stamp, rendered[topic])
            if sensors:
                values = values_from_state(state, scene.output_joints, scene.output_points)
                for connection, data in zip(sensors.values(), imu_messages.render_values(
                        values, *divmod(stamp, 10**9)), strict=True):
                    writer.write(connection, stamp, data)
    return path


def test_scene_plot_has_every_panel_with_units(tmp_path):
    """From a scene: joint and point panels, every axis labelled with a unit, a real PNG."""
    out = tmp_path / 'four_bar.png'
    fig = plot.plot_scene(mk.load_scene('khurmi_four_bar_ad150'), out)
    assert set(panels(fig)) == JOINT_PANELS | POINT_PANELS
    assert_units_everywhere(fig)
    assert_png(out)
    assert panels(fig)['Joint angular velocities'].get_xlabel() == 'crank angle θ [rad]'
    assert set(lines(panels(fig)['Joint angles'])) == {'crank', 'coupler', 'rocker'}
    # A, D are fixed: no speed line, a marker in the path panel.
    assert set(lines(panels(fig)['Point speeds |v|'])) == {'B', 'C'}


def test_scene_plot_values_are_the_solver_values(tmp_path):
    """The lines drawn are mk.solve over 0..2π: angular velocities and point speeds."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    fig = scene_figure(scene, samples=181)
    angle = np.linspace(0.0, 2 * math.pi, 181)
    state = mk.solve(scene, angle)
    rocker = lines(panels(fig)['Joint angular velocities'])['rocker']
    np.testing.assert_allclose(rocker.get_xdata(), angle, rtol=RTOL, atol=0)
    np.testing.assert_allclose(rocker.get_ydata(), state.joints['rocker'].velocity, rtol=RTOL,
                               atol=0)
    speed_c = lines(panels(fig)['Point speeds |v|'])['C'].get_ydata()
    np.testing.assert_allclose(speed_c, np.linalg.norm(state.points['C'].velocity, axis=1),
                               rtol=RTOL, atol=0)


def test_scene_with_sliders_adds_the_slider_column(tmp_path):
    """A mechanism with prismatic joints gets slider panels in metres."""
    fig = scene_figure(mk.load_scene('quick_return'), x='time')
    assert set(panels(fig)) == JOINT_PANELS | POINT_PANELS | SLIDER_PANELS
    assert_units_everywhere(fig)
    assert set(lines(panels(fig)['Slider positions'])) == {'block', 'ram'}
    assert panels(fig)['Slider velocities'].get_ylabel() == 'velocity [m/s]'
    assert panels(fig)['Slider velocities'].get_xlabel() == 'time [s]'


def test_scene_that_does_not_assemble_everywhere_leaves_gaps(tmp_path):
    """A triple rocker: angles that cannot be assembled are gaps (NaN), never made-up values."""
    scene = mk.load_scene('four_bar_coupler_points')
    fig = scene_figure(scene, samples=361)
    ydata = lines(panels(fig)['Joint angular velocities'])['rocker'].get_ydata()
    state = mk.solve(scene, np.linspace(0, 2 * math.pi, 361))
    assert np.isnan(ydata).sum() == (~state.valid).sum() > 0


def test_scene_plot_states_and_shades_where_it_does_not_assemble(tmp_path, capsys):
    """`plot --scene` prints the unassemblable ranges in one line and shades them (issue 11)."""
    out = tmp_path / 'fb.png'
    assert plot.main(['--scene', 'four_bar_coupler_points', '-o', str(out)]) == 0
    assert capsys.readouterr().out.splitlines()[0] == (
        'four_bar_coupler_points: does not assemble for crank angles 103.792..256.208 deg')
    motion = plot.motion_from_scene(mk.load_scene('four_bar_coupler_points'))
    fig = plot.figure_from_motion(motion, x='angle')
    assert fig._suptitle.get_text().endswith('does not assemble for crank angles '
                                             '103.792..256.208 deg')
    (start, end), = motion.gaps
    assert math.degrees(start) == pytest.approx(103.792, abs=1e-3)
    shaded = [patch for patch in panels(fig)['Joint angles'].patches]
    assert any(abs(p.get_x() - start) < 1e-12 and abs(p.get_width() - (end - start)) < 1e-12
               for p in shaded)


def test_geneva_acceleration_jumps_are_not_smeared(tmp_path):
    """The wheel's acceleration line breaks where the pin enters and leaves a slot (issue 11)."""
    motion = plot.motion_from_scene(mk.load_scene('geneva'), samples=700)  # no sample on a mouth
    assert motion.jumps.sum() == 2  # entry and exit, once each per turn
    assert np.isfinite(motion.joints['wheel'][2]).all()
    fig = plot.figure_from_motion(motion, x='angle')
    y = lines(panels(fig)['Joint angular accelerations'])['wheel'].get_ydata()
    finite = np.isfinite(y)
    # no segment joins a locked sample (0) to an engaged one (|alpha| near 100 rad/s^2)
    for a, b in zip(y[:-1][finite[:-1] & finite[1:]], y[1:][finite[:-1] & finite[1:]],
                    strict=True):
        assert (a == 0.0) == (b == 0.0) or abs(a - b) < 1.0


@pytest.mark.parametrize('storage', bag_recorder.STORAGES)
def test_bag_plot_shows_the_recorded_values(tmp_path, storage):
    """From a bag of the node's bytes (mcap and sqlite3): panels, time axis and the values."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    angles = scene.input.angle + scene.input.speed * 0.002 * np.arange(200)
    bag = write_bag(tmp_path / 'bag', scene, angles, storage=storage)
    out = tmp_path / 'bag.png'
    assert plot.main([str(bag), '-o', str(out), '--scene', scene.name]) == 0
    assert_png(out)
    fig = bag_figure(bag, scene=scene)
    assert set(panels(fig)) == JOINT_PANELS | POINT_PANELS
    assert_units_everywhere(fig)
    accel = lines(panels(fig)['Joint angular accelerations'])['coupler']
    np.testing.assert_allclose(accel.get_xdata(), 0.002 * np.arange(200), rtol=0, atol=1e-9)
    expected = [mk.solve(scene, a).joints['coupler'].acceleration for a in angles]
    np.testing.assert_allclose(accel.get_ydata(), expected, rtol=RTOL, atol=0)


def test_bag_plot_finds_the_scene_from_diagnostics_or_warns(tmp_path):
    """Without --scene and without diagnostics in the bag, joints are plotted as revolute."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    bag = write_bag(tmp_path / 'bag', scene, np.linspace(0, 1, 20), namespaces=('/robot',))
    motion = plot.motion_from_bag(bag, scene=scene, namespace='/robot')
    assert len(motion.time) == 20
    with pytest.warns(UserWarning, match='no scene given'):
        motion = plot.motion_from_bag(bag)
    assert motion.joint_types == dict.fromkeys(scene.output_joints, 'revolute')


def test_bag_plot_takes_the_scene_stored_in_the_bag(tmp_path, capsys):
    """A bag with the node's scene topic and no diagnostics tells a slider from a revolute.

    Without it, the command says so in one `warning:` line, not Python's
    UserWarning format (issue 20).
    """
    scene = mk.load_scene('slider_crank_150_600')
    angles = np.linspace(0, 1, 20)
    stored = write_bag(tmp_path / 'stored', scene, angles,
                       scene_text=mk.scene.scene_text('slider_crank_150_600'))
    motion = plot.motion_from_bag(stored)
    assert motion.joint_types == {'crank': 'revolute', 'rod': 'revolute',
                                  'piston': 'prismatic'}
    assert motion.title.startswith('slider_crank_150_600: recording stored')
    assert plot.main([str(stored), '-o', str(tmp_path / 's.png')]) == 0
    assert 'warning' not in capsys.readouterr().err
    bare = write_bag(tmp_path / 'bare', scene, angles)
    assert plot.main([str(bare), '-o', str(tmp_path / 'b.png')]) == 0
    err = capsys.readouterr().err
    assert err.startswith('warning: ') and err.count('\n') == 1 and 'UserWarning' not in err
    assert 'no scene given' in err


def test_ticks_missing_from_a_bag_leave_a_gap_not_a_line(tmp_path):
    """Ticks the node did not publish are a break in every line, paths included."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    angles = scene.input.angle + scene.input.speed * 0.002 * np.arange(300)
    bag = write_bag(tmp_path / 'gap', scene, angles, skip=range(100, 140))
    fig = bag_figure(bag, scene=scene)
    for title in ('Joint angular velocities', 'Point paths'):
        for line in lines(panels(fig)[title]).values():
            y = np.asarray(line.get_ydata(), dtype=float)
            assert np.isnan(y).sum() == 1 and len(y) == 260 + 1, title


def test_bag_with_joint_states_only_has_no_acceleration_lines(tmp_path):
    """A bag with only joint_states plots angles and velocities, and says 'no data' for α."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    bag = write_bag(tmp_path / 'js', scene, np.linspace(0, 1, 20), topics=('joint_states',))
    fig = bag_figure(bag, scene=scene, x='angle')
    assert set(lines(panels(fig)['Joint angular velocities'])) == {'crank', 'coupler', 'rocker'}
    assert not lines(panels(fig)['Joint angular accelerations'])
    assert not lines(panels(fig)['Point speeds |v|'])


def test_errors_are_reported_not_raised(tmp_path, capsys):
    """No source, a missing bag, two namespaces, no such topics or scene: exit 2, a reason."""
    assert plot.main(['-o', str(tmp_path / 'x.png')]) == 2
    assert 'Expected a BAG or --scene' in capsys.readouterr().err
    assert plot.main([str(tmp_path / 'nothing'), '-o', str(tmp_path / 'x.png')]) == 2
    assert 'does not exist' in capsys.readouterr().err
    scene = mk.load_scene('khurmi_four_bar_ad150')
    bag = write_bag(tmp_path / 'bag', scene, [1.0, 1.1], namespaces=('/left', '/right'))
    assert plot.main([str(bag), '-o', str(tmp_path / 'x.png')]) == 2
    assert 'pass --namespace' in capsys.readouterr().err
    assert plot.main([str(bag), '--namespace', '/nowhere', '-o', str(tmp_path / 'x.png')]) == 2
    assert "Expected the node's joint_accelerations" in capsys.readouterr().err
    assert plot.main(['--scene', 'no_such_scene', '-o', str(tmp_path / 'x.png')]) == 2
    assert 'no_such_scene' in capsys.readouterr().err
    assert not (tmp_path / 'x.png').exists()


def test_importing_the_commands_pulls_in_neither_matplotlib_nor_rclpy():
    """The command modules import matplotlib, rosbags and rclpy only when they run."""
    code = ('import sys, mech_kinematics.tools.plot, mech_kinematics.tools.record; '
            'heavy = {"matplotlib", "rclpy", "rosbags"} & set(sys.modules); '
            'assert not heavy, heavy')
    subprocess.run([sys.executable, '-c', code], check=True, cwd=REPO)


def test_output_without_an_image_suffix_is_refused(tmp_path, capsys):
    """``-o NAME`` would have written NAME.png and said "wrote NAME": refused, nothing written."""
    assert plot.main(['--scene', 'khurmi_four_bar_ad150', '-o', str(tmp_path / 'NAME')]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert f'got "{tmp_path / "NAME"}" without one; e.g. -o {tmp_path / "NAME.png"}' in err
    assert plot.main(['--scene', 'khurmi_four_bar_ad150', '-o', str(tmp_path / 'a.txt')]) == 2
    assert 'whose suffix is not one' in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_samples_beyond_the_bound_are_refused_at_once(tmp_path, capsys):
    """``--samples 1000000000`` allocated until the kernel killed it: now one line, exit 2."""
    out = tmp_path / 'x.png'
    assert plot.main(['--scene', 'khurmi_four_bar_ad150', '--samples', '1000000000',
                      '-o', str(out)]) == 2
    assert capsys.readouterr().err == (f'error: Expected --samples from 2 to {plot.MAX_SAMPLES}, '
                                       f'got 1000000000; a figure shows no more\n')
    assert plot.main(['--scene', 'khurmi_four_bar_ad150', '--samples', str(plot.MAX_SAMPLES),
                      '-o', str(out)]) == 0
    assert_png(out)


def test_bag_whose_metadata_is_a_fifo_is_refused_not_hung(tmp_path):
    """A FIFO named metadata.yaml made ``plot`` hang: now one line naming it, at once."""
    import os

    scene = mk.load_scene('khurmi_four_bar_ad150')
    bag = write_bag(tmp_path / 'bag', scene, [1.0, 1.1])
    (bag / 'metadata.yaml').unlink()
    os.mkfifo(bag / 'metadata.yaml')
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics', 'plot', str(bag), '-o',
                             str(tmp_path / 'x.png')], cwd=REPO, capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 2
    assert result.stderr == (f'error: Expected "{bag / "metadata.yaml"}" to be a regular file, '
                             f'got a FIFO; replace it with the file itself\n')


def test_bag_without_metadata_or_with_a_damaged_chunk_says_to_reindex(tmp_path, capsys):
    """No metadata.yaml (recorder killed), or a chunk checksum mismatch: the line says reindex."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    bag = write_bag(tmp_path / 'bag', scene, [1.0, 1.1])
    (bag / 'metadata.yaml').rename(tmp_path / 'metadata.yaml')
    assert plot.main([str(bag), '-o', str(tmp_path / 'x.png')]) == 2
    err = capsys.readouterr().err
    assert err == (f'error: Expected a bag directory with a metadata.yaml, got "{bag}" without '
                   f'one (was its recorder killed?); run `python -m mech_kinematics reindex '
                   f'{bag}` to rebuild it\n')
    (tmp_path / 'metadata.yaml').rename(bag / 'metadata.yaml')
    ours = copied_by_the_recorders_writer(bag, tmp_path / 'ours')   # chunks with a CRC
    storage = ours / 'ours.mcap'
    data = bytearray(storage.read_bytes())
    data[data.index(b'coupler') + 2] ^= 0xFF      # inside the first message of the chunk
    storage.write_bytes(bytes(data))
    bag = ours
    assert plot.main([str(bag), '-o', str(tmp_path / 'x.png')]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'Chunk checksum mismatch' in err
    assert err.endswith(f'run `python -m mech_kinematics reindex {bag}` to keep every intact '
                        f'message\n')
    assert not (tmp_path / 'x.png').exists()


def copied_by_the_recorders_writer(bag: Path, destination: Path) -> Path:
    """Copy every message of ``bag`` into a new bag written by ``record``'s BagWriter.

    No flush by time (an hour's interval): one chunk, on a loaded machine too. A
    copy taking over the recorder's half second was split into chunks there, and
    the byte the test damages fell in a small chunk of a topic that plot does not
    read (the reader skips it by its index), so plot drew the rest and answered 0
    (seen once in a suite beside CPU hogs; with a flush at every write, each time).
    """
    from rosbags.highlevel import AnyReader

    from mech_kinematics.bag import BagWriter
    from mech_kinematics.bag.metadata import type_hash_from_definition

    writer = BagWriter(destination, storage='mcap', flush_interval=3600.0)
    writer.open()
    with AnyReader([bag]) as reader:
        topics = {}
        for c in reader.connections:
            encoding, text = bag_recorder.message_definition(c.msgtype)
            topics[c.id] = writer.add_topic(c.topic, c.msgtype, definition=text,
                                            encoding=encoding,
                                            type_hash=type_hash_from_definition(c.msgtype, text,
                                                                                encoding))
        for c, timestamp, raw in reader.messages():
            writer.write(topics[c.id], timestamp, bytes(raw))
    writer.close()
    return destination


# --- several drivers (issue 18): along the drivers' path ------------------------------

#: The five-bar's cranks turning together (60 deg apart: |BD| stays below 0.22 m).
TOGETHER = FIVE_BAR_TWO_CRANKS.replace('speed_rpm: -10', 'speed_rpm: 10')
#: The boom's cylinder retracting toward its shortest stroke (2000 mm, reached at 12 s).
RETRACTING = BOOM_CYLINDER.replace('speed: 0.05', 'speed: -0.05')


def test_several_drivers_are_plotted_along_their_path_in_time(tmp_path):
    """Each driver from its start at its speed for the quickest's period; the solver's values."""
    scene = mk.parse_scene(yaml.safe_load(TOGETHER))
    fig = plot.plot_scene(scene, tmp_path / 'five.png', samples=61)
    assert_png(tmp_path / 'five.png')
    assert fig._suptitle.get_text().startswith(
        'five: solver, every driver from its start at its speed (left 10 rpm, right 10 rpm) '
        'for 6 s (left turning once)')
    time = np.linspace(0.0, 6.0, 61)
    omega = 2 * math.pi / 6
    state = mk.solve(scene, [math.radians(120) + omega * time, math.radians(60) + omega * time],
                     [omega, omega], [0.0, 0.0])
    ldist = lines(panels(fig)['Joint angular velocities'])['ldist']
    np.testing.assert_allclose(ldist.get_xdata(), time, rtol=RTOL, atol=0)
    np.testing.assert_allclose(ldist.get_ydata(), state.joints['ldist'].velocity, rtol=RTOL,
                               atol=0)
    assert set(lines(panels(fig)['Joint angles'])) == {'left', 'right', 'ldist', 'rdist'}


def test_an_actuator_runs_to_the_end_of_its_stroke(tmp_path):
    """The retracting cylinder is plotted for 12 s, to its shortest length, in the slider panel."""
    scene = mk.parse_scene(yaml.safe_load(RETRACTING))
    motion = plot.motion_from_scene(scene, samples=25, x='time')
    assert motion.time[-1] == pytest.approx(12.0, rel=1e-14)
    assert 'for 12 s (cyl reaching the end of its stroke)' in motion.title
    position, velocity, _ = motion.joints['cyl']
    np.testing.assert_allclose(position, 2.6 - 0.05 * motion.time, rtol=1e-15, atol=1e-15)
    assert np.all(velocity == -0.05)


def test_a_path_leaving_the_region_is_refused_saying_where(tmp_path, capsys):
    """The cranks turning apart straighten the distal links at 0.31 s: one line, exit 2."""
    path = tmp_path / 'five.yaml'
    path.write_text(FIVE_BAR_TWO_CRANKS)
    out = tmp_path / 'five.png'
    assert plot.main(['--scene', str(path), '-o', str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: Expected the drivers' path of five to stay where it "
                          'assembles, got it leaving at t = 0.316667 s (left = 139 deg, right '
                          '= 41 deg): the circles about B (radius 0.14 m) and D (radius 0.14 '
                          'm) do not meet')
    assert err.rstrip().endswith('plot less with --duration SECONDS (at most 0.308333 s)')
    assert len(err.strip().splitlines()) == 1 and not out.exists()
    assert plot.main(['--scene', str(path), '-o', str(out), '--duration', '0.3']) == 0
    assert_png(out)


@pytest.mark.parametrize(('args', 'match'), [
    (['--x', 'angle'], 'Expected --x time for five, which has several drivers'),
    (['--speed-rpm', '5'], 'Expected no --speed-rpm or --accel for five'),
])
def test_options_that_mean_one_crank_are_refused(tmp_path, capsys, args, match):
    """--x angle and --speed-rpm have no meaning with several drivers: one line, exit 2."""
    path = tmp_path / 'five.yaml'
    path.write_text(TOGETHER)
    assert plot.main(['--scene', str(path), '-o', str(tmp_path / 'p.png'), *args]) == 2
    assert match in capsys.readouterr().err


def test_duration_with_one_crank_is_refused(tmp_path, capsys):
    """--duration is for several drivers: one line, exit 2."""
    assert plot.main(['--scene', 'khurmi_four_bar_ad150', '-o', str(tmp_path / 'p.png'),
                      '--duration', '1']) == 2
    assert 'Expected --duration and --speed NAME=VALUE only for a scene with several' in (
        capsys.readouterr().err)


def test_bag_of_a_scene_with_several_drivers_plots_against_time_only(tmp_path, capsys):
    """A five-bar recording: each driver's joint against time; --x angle is refused (exit 2)."""
    scene = mk.parse_scene(yaml.safe_load(TOGETHER))
    positions = [[math.radians(120) + 0.01 * i, math.radians(60) + 0.01 * i] for i in range(50)]
    bag = write_bag(tmp_path / 'five', scene, positions, scene_text=TOGETHER)
    fig = plot.plot_bag(bag, tmp_path / 'five.png')
    left = lines(panels(fig)['Joint angles'])['left']
    np.testing.assert_allclose(left.get_ydata(), [p[0] for p in positions], rtol=1e-15)
    assert plot.main([str(bag), '-o', str(tmp_path / 'a.png'), '--x', 'angle']) == 2
    assert ('Expected a recording of a scene driven by one crank to plot against crank angle, '
            'got five, with several drivers or an actuator: use --x time') in (
        capsys.readouterr().err)


def test_packaged_excavator_plotted_at_given_cylinder_speeds(tmp_path, capsys):
    """Its cylinders rest by default: refused saying so; --speed moves them to a stroke's end."""
    out = tmp_path / 'excavator.png'
    assert plot.main(['--scene', 'excavator', '-o', str(out)]) == 2
    assert capsys.readouterr().err == (
        'error: Expected a driver of excavator that turns or reaches the end of its stroke at '
        'its speed and acceleration, got none: give --speed NAME=VALUE or --duration SECONDS\n')
    scene = mk.load_scene('excavator')
    motion = plot.motion_from_scene(scene, samples=31, x='time',
                                    speeds={'boom_cyl': 0.1, 'stick_cyl': -0.05})
    # boom_cyl reaches 3.3 m from 2.6 m in 7 s; stick_cyl 2.5 m from 3.0 m only in 10 s
    assert motion.time[-1] == pytest.approx(7.0, rel=1e-14)
    assert 'for 7 s (boom_cyl reaching the end of its stroke)' in motion.title
    np.testing.assert_allclose(motion.joints['stick_cyl'][0], 3.0 - 0.05 * motion.time,
                               rtol=1e-15)
    assert plot.main(['--scene', 'excavator', '-o', str(out), '--speed', 'boom_cyl=0.1',
                      '--speed', 'stick_cyl=-0.05']) == 0
    assert_png(out)
    assert plot.main(['--scene', 'excavator', '-o', str(out), '--speed', 'arm=1']) == 2
    assert ('Expected --speed NAME=VALUE with NAME one of the drivers (boom_cyl, stick_cyl), '
            "got 'arm'") in capsys.readouterr().err


def test_packaged_five_bar_plots_both_cranks_turning_together(tmp_path):
    """five_bar's cranks at 30 rpm CCW, 30 deg apart: one 2 s turn, |BD| as the closed form."""
    motion = plot.motion_from_scene(mk.load_scene('five_bar'), samples=41, x='time')
    assert motion.time[-1] == pytest.approx(2.0, rel=1e-14)
    b, d = motion.points['B'][0], motion.points['D'][0]
    bd = np.hypot(*(b - d).T)
    # B - D = 0.12 e^(i left) (1 - e^(-i 30 deg)) - 0.1 m: |BD| within 0.1 -+ 0.24 sin 15 deg
    half = 0.24 * math.sin(math.radians(15))
    assert bd.min() >= 0.1 - half - 1e-12 and bd.max() <= 0.1 + half + 1e-12
    assert bd.max() - bd.min() == pytest.approx(2 * half, rel=1e-2)


# --- a recording of a node driven from a topic (issue 33) -------------------------------


def topic_driven_bag(path: Path, scene, positions, *, velocities: bool) -> Path:
    """Write what a topic-driven node publishes, with the project's bag writer (``record``'s).

    Its messages carry no accelerations (empty arrays, as the contract says),
    and no velocities either when the input messages had none.
    """
    from mech_kinematics.bag import BagWriter
    from mech_kinematics.bag.metadata import type_hash_from_definition
    from mech_kinematics.ros.messages import TickMessages

    ticks = TickMessages(scene.output_joints, scene.output_points, 'mechanism',
                         velocities=velocities, accelerations=False)
    writer = BagWriter(path, storage='mcap')
    writer.open()
    ids = {}
    for topic, msgtype in TYPES.items():
        encoding, text = bag_recorder.message_definition(msgtype)
        ids[topic] = writer.add_topic(f'/{topic}', msgtype, definition=text, encoding=encoding,
                                      type_hash=type_hash_from_definition(msgtype, text,
                                                                          encoding))
    start = 1_700_000_000 * 10**9
    for i, x in enumerate(positions):
        stamp = start + i * 10**7    # 100 Hz
        for topic, data in zip(TYPES, ticks.render(mk.solve(scene, x), *divmod(stamp, 10**9)),
                               strict=True):
            writer.write(ids[topic], stamp, data)
    writer.close()
    return path


@pytest.mark.parametrize('velocities', [True, False])
def test_a_bag_without_accelerations_plots_what_is_there_and_says_what_is_not(
        tmp_path, capsys, velocities):
    """Issue 33: `plot` on a topic-driven recording failed with "unexpected IndexError".

    Positions (and velocities when recorded) are drawn, the solver's values;
    each panel of what is not in the recording says so, and so does one
    warning line.
    """
    scene = mk.load_scene('boom')
    lengths = 1.9 + 0.004 * np.arange(60)
    bag = topic_driven_bag(tmp_path / 'topic', scene, lengths, velocities=velocities)
    with pytest.warns(UserWarning) as caught:
        fig = bag_figure(bag, scene=scene)
    missing = 'velocities or accelerations' if not velocities else 'accelerations'
    assert [str(w.message) for w in caught] == [
        f'{bag}: no {missing} in the recording (empty in every message, as a node driven from a '
        f'topic publishes them): their panels say so']
    boom = lines(panels(fig)['Joint angles'])['boom']
    np.testing.assert_allclose(boom.get_ydata(), [mk.solve(scene, x).joints['boom'].position
                                                  for x in lengths], rtol=RTOL, atol=0)
    cylinder = lines(panels(fig)['Slider positions'])['lift_cyl']
    np.testing.assert_array_equal(cylinder.get_ydata(), lengths)
    empty = ['Joint angular accelerations', 'Point accelerations |a|', 'Slider accelerations']
    if velocities:
        speed = lines(panels(fig)['Point speeds |v|'])['T']
        expected = [math.hypot(*mk.solve(scene, x).points['T'].velocity) for x in lengths]
        np.testing.assert_allclose(speed.get_ydata(), expected, rtol=RTOL, atol=0)
    else:
        empty += ['Joint angular velocities', 'Point speeds |v|', 'Slider velocities']
        assert 'T' in lines(panels(fig)['Point paths'])  # a moving point, from its path alone
    for title in empty:
        ax = panels(fig)[title]
        assert not lines(ax), title
        assert [t.get_text() for t in ax.texts] == ['not in the recording'], title
    out = tmp_path / 'cli.png'
    assert plot.main([str(bag), '-o', str(out), '--scene', 'boom']) == 0
    assert_png(out)
    assert capsys.readouterr().err == (
        f'warning: {bag}: no {missing} in the recording (empty in every message, as a node '
        f'driven from a topic publishes them): their panels say so\n')


# --- forces (issue 32): the turning-moment diagram and what the joints carry ------------

FORCE_PANELS = {'Turning moment (driver efforts)', 'Joint reactions |F|',
                'Shaking force on the frame |F|'}


def test_a_scene_with_forces_gets_its_turning_moment_and_reactions(tmp_path):
    """The engine: efforts, |F| of every pin and the shaking force are the solver's; the mean."""
    from mech_kinematics.geometry.turning import turning_moment_from_scene

    scene = forces_scene('engine')
    fig = plot.plot_scene(scene, tmp_path / 'engine.png', samples=181)
    assert_png(tmp_path / 'engine.png')
    found = panels(fig)
    assert set(found) >= FORCE_PANELS
    assert_units_everywhere(fig)
    angles = np.linspace(0.0, 2.0 * math.pi, 181)
    state = mk.solve(scene, angles)
    drawn = lines(found['Turning moment (driver efforts)'])
    np.testing.assert_array_equal(drawn['crank'].get_ydata(), state.forces.efforts['crank'])
    mean = turning_moment_from_scene(scene).mean
    (label,) = [name for name in drawn if name.startswith('crank mean')]
    assert label == f'crank mean {mean:.4g} N m'
    np.testing.assert_array_equal(drawn[label].get_ydata(), [mean, mean])
    reactions = lines(found['Joint reactions |F|'])
    assert set(reactions) == {'crank at O', 'B', 'P', 'piston at P (normal)'}
    np.testing.assert_array_equal(reactions['B'].get_ydata(),
                                  np.abs(state.forces.reactions['B'].force))
    np.testing.assert_array_equal(reactions['piston at P (normal)'].get_ydata(),
                                  np.abs(state.forces.reactions['piston'].normal))
    np.testing.assert_array_equal(lines(found['Shaking force on the frame |F|'])['shaking']
                                  .get_ydata(), np.abs(state.forces.shaking_force))


def test_several_drivers_plot_their_efforts_along_their_path(tmp_path):
    """The five-bar with masses, against time: both efforts, no mean line (no one turn)."""
    scene = forces_scene('five_bar_masses')
    fig = scene_figure(scene, samples=101)
    drawn = lines(panels(fig)['Turning moment (driver efforts)'])
    assert set(drawn) == {'left_crank', 'right_crank'}
    assert panels(fig)['Turning moment (driver efforts)'].get_xlabel() == 'time [s]'


def test_no_forces_no_forces_column(tmp_path):
    """A scene without masses, gravity or loads draws what it drew before, nothing more."""
    fig = scene_figure(mk.load_scene('khurmi_four_bar_ad150'), samples=91)
    assert not FORCE_PANELS & set(panels(fig))
    assert plot.motion_from_scene(mk.load_scene('khurmi_four_bar_ad150'), samples=5).forces \
        is None


def test_a_crank_that_cannot_turn_has_no_mean_line_and_says_why(tmp_path):
    """The four-bar with masses, its crank made longer than its rocker: gaps, and the reason."""
    data = yaml.safe_load((REPO / 'test' / 'data' / 'forces' / 'four_bar_masses.yaml')
                          .read_text())
    data['input']['length'] = 100
    scene = mk.parse_scene(data)
    motion = plot.motion_from_scene(scene, samples=181)
    assert motion.forces.means == {}
    assert motion.forces.note.startswith('no mean line: Expected four_bar_masses to turn')
    efforts = motion.forces.efforts['crank']
    assert np.isnan(efforts).any() and np.isfinite(efforts).any()
    fig = plot.figure_from_motion(motion, x='angle')
    texts = [t.get_text() for t in panels(fig)['Turning moment (driver efforts)'].texts]
    assert any(t.startswith('no mean line') for t in texts)


def _engine(tmp_path, gravity, masses=None):
    """Return the packaged engine with ``gravity`` (and ``masses``, kg by body, if given)."""
    data = yaml.safe_load((SCENES / 'engine.yaml').read_text())
    data['gravity'] = gravity
    for body, mass in (masses or {}).items():
        data['masses'][body]['mass'] = mass
    path = tmp_path / 'engine.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


def test_gravity_whose_forces_overflow_is_one_line(tmp_path, capsys):
    """Issue 42: gravity [1e308, 1e308] was "unexpected OverflowError"; now the scene's line."""
    path = _engine(tmp_path, [1e308, 1e308])
    out = tmp_path / 'e.png'
    assert plot.main(['--scene', str(path), '-o', str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (f'error: {path}: gravity: expected [gx, gy] whose weight on the moving '
                   'bodies (24 kg) is a finite force (at most 1.798e+308 N), got [1e+308, '
                   '1e+308] m/s^2\n')
    assert not out.exists()


def test_forces_too_large_to_draw_are_one_line_without_warnings(tmp_path, capsys):
    """Finite forces of 1e306 N and more: one line, exit 2, no matplotlib warnings.

    The engine with 0.6 kg in all under gravity [1.2e308, 1.2e308]: the weights (1e308 N)
    are finite, the forces answered; matplotlib's ticks overflowed on them (eight
    RuntimeWarnings, then "unexpected ValueError: arange: cannot compute length").
    """
    path = _engine(tmp_path, [1.2e308, 1.2e308], {'crank': 0.2, 'rod': 0.16, 'piston': 0.24})
    out = tmp_path / 'e.png'
    assert plot.main(['--scene', str(path), '-o', str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith('error: Expected values a plot can draw (at most 1e+300 in '
                          'magnitude), got '), err
    assert err.rstrip().endswith('(smaller forces or speeds plot)'), err
    assert err.count('\n') == 1 and not out.exists()
