# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A publish that never returns ends the process, exit status 1 (ros/watchdog.py, issue 42).

Fast DDS's shared-memory transport blocked the node's tick thread for good on
a killed reader's port (Fast-DDS#6485) in 3 of 26 runs beside CPU hogs. Here
a stand-in publisher blocks inside the tick thread's publish of a real
:class:`~mech_kinematics.ros.tick_thread.TickThread` in a process of its
own: once with the GIL released (an event waited on), once with it held (a
C ``sleep`` called through ``ctypes.PyDLL``, as rclpy's ``publish`` holds it).
"""

import subprocess
import sys
import textwrap

import pytest

from mech_kinematics.ros.watchdog import PublishWatch, PublishWatchdog, stuck_line

#: The stand-in node: one crank at 1 kHz on a TickThread, its joint_states publish blocking.
SCRIPT = textwrap.dedent("""
    import ctypes, sys, threading
    import mech_kinematics as mk
    from mech_kinematics.ros.diagnostics import TickStats
    from mech_kinematics.ros.driver import TickDriver
    from mech_kinematics.ros.tick_thread import TickThread
    from mech_kinematics.ros.timebase import CrankTimebase
    from mech_kinematics.ros.watchdog import PublishWatch, PublishWatchdog

    HOW, BOUND_S = sys.argv[1], float(sys.argv[2])


    class Clock:
        ros_time_is_active = False


    class Logger:
        def warning(self, text, **_):
            print(text, file=sys.stderr, flush=True)

        fatal = warning


    class Solver:
        max_error, jumps_at = 1e-6, None

        def solve(self, angle, speed, accel, tol, turns):
            return [angle], 1.0


    def block(_message):
        if HOW == 'gil':      # held, as rclpy's publish holds it
            ctypes.PyDLL(None).sleep(60)
        else:
            threading.Event().wait(60)


    class Publishing:
        def __init__(self, watch):
            self.count = 0
            self.publish = watch.wrap(watch.slot(), 'joint_states', block)

        def tick(self, values, stamp, sec, nanosec):
            self.count += 1
            if self.count == 5:
                self.publish(values)


    watch = PublishWatch()
    watchdog = PublishWatchdog(watch, BOUND_S, Logger().fatal)
    driver = TickDriver(1_000_000, 100_000_000)
    driver.add_drive('crank', CrankTimebase, angle=0.0, speed_rpm=60.0, accel=0.0,
                     max_speed_rpm=1000.0)
    ticks = TickThread(Clock(), driver, TickStats(mk.NEAR_SINGULAR), Logger(),
                       lambda: None, lambda: False)
    watchdog.start()
    ticks.start(Solver(), Publishing(watch), None)
    threading.Event().wait(120)
    print('the watchdog did not end the process', file=sys.stderr)
    sys.exit(3)
""")


def _run(how, bound_s=0.3):
    return subprocess.run([sys.executable, '-c', SCRIPT, how, str(bound_s)],
                          capture_output=True, text=True, timeout=100)


def test_a_publish_stuck_without_the_gil_is_one_line_naming_the_topic_and_status_1():
    """The watchdog's thread sees the stamp older than the bound: one line, exit status 1."""
    done = _run('released')
    assert done.returncode == 1, done.stderr
    [line] = done.stderr.splitlines()
    assert line.startswith('a publish on joint_states has not returned for ')
    assert line.endswith(' s (the Fast DDS shared-memory hang of a killed reader, '
                         'docs/robustness.md?): exiting with status 1 for a supervisor to '
                         'restart the node')


def test_a_publish_stuck_with_the_gil_held_ends_the_process_naming_the_topic():
    """No Python runs: faulthandler's timer, no longer re-armed, dumps the stacks and exits 1."""
    done = _run('gil')
    assert done.returncode == 1, done.stderr
    lines = done.stderr.splitlines()
    assert lines[0].startswith('Timeout (0:00:'), done.stderr
    # The stuck thread's stack: the publisher (here the stand-in's `block`; rclpy's own
    # `publish` in a node), called by the watched publish, named for its topic.
    stuck = [i for i, text in enumerate(lines) if text.endswith('in publish on joint_states')]
    assert stuck and lines[stuck[0] - 1].endswith(' in block'), done.stderr
    assert lines[stuck[0] - 2].endswith('(most recent call first):'), done.stderr


def test_a_publish_within_the_bound_is_no_stuck_one():
    """A slot stamped within the bound, or cleared, is not stuck; one beyond it names its topic."""
    watch = PublishWatch()
    slot = watch.slot()
    seen = []
    watch.wrap(slot, 'joint_states', lambda m: seen.append((m, slot.since_ns, slot.topic)))('m')
    [(message, since, topic)] = seen
    assert (message, topic) == ('m', 'joint_states') and since > 0 and slot.since_ns == 0
    assert watch.stuck(10 ** 12, 10 ** 9) is None
    slot.since_ns, slot.topic = 5 * 10 ** 9, 'tf'
    assert watch.stuck(6 * 10 ** 9, 10 ** 9) is None
    assert watch.stuck(6 * 10 ** 9 + 1, 10 ** 9) == ('tf', 10 ** 9 + 1)
    assert stuck_line('tf', 2_500_000_000).startswith('a publish on tf has not returned for '
                                                      '2.5 s')


def test_a_bound_of_0_starts_no_watchdog():
    """publish_timeout_s 0: off."""
    watchdog = PublishWatchdog(PublishWatch(), 0.0, print, exit=pytest.fail)
    watchdog.start()
    assert watchdog._thread is None
    watchdog.stop()


def test_the_bound_is_a_read_only_parameter_with_a_range():
    """publish_timeout_s: 2 s by default, 0 (off) to 3600 s, set at start only."""
    from mech_kinematics.ros.node_parameters import description
    from mech_kinematics.ros.parameters import spec

    p = spec('publish_timeout_s')
    assert (p.kind, p.default, p.low, p.high, p.unit, p.read_only) == (
        'double', 2.0, 0.0, 3600.0, 's', True)
    assert description(p).endswith('0: off [s, 0 to 3600]')
