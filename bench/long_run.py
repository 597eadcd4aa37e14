# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One real run of kinematics_node on the system clock: its crank angle after minutes.

A script, not a test (it runs for ``--seconds``, ten minutes by default). It
starts ``kinematics_node`` at ``--rate`` Hz on ``--scene`` and subscribes to
``joint_states`` in this process (``raw=True``: every stamp is counted, the
bytes are kept once per ``--keep`` seconds of stamps and decoded at the end).

The exact crank angle at stamp ``s`` is ``a1 + omega * (s - s1)`` in 60-digit
arithmetic, from the first received message (stamp ``s1``, crank position
``a1``): the node's timebase makes the angle at ``s1`` within an ulp or two
of the truth, so the error measured at ``s`` is the growth since ``s1``. For
each kept message it compares the published crank position with that (wrapped
to (-pi, pi]) and every published joint position and velocity with
``mech_kinematics.solve`` at the exact angle rounded to a double. The result
(JSON) goes to stdout or ``--out``; the report copies it into its data file
(``report --long-run FILE``).

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/long_run.py [--seconds 600] [--rate 1000] [--out long_run.json]
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
from pathlib import Path
import random
import signal
import subprocess
import sys
import time

NS = 1_000_000_000
SCENE = 'khurmi_four_bar_ad150'


def _wrap(x: float) -> float:
    return math.remainder(x, 2.0 * math.pi)


def run(seconds: float, rate: float, scene_name: str, keep_s: float) -> dict[str, object]:
    """Run the node for ``seconds`` and return the measured figures."""
    import mpmath
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rclpy.serialization import deserialize_message
    from sensor_msgs.msg import JointState

    import mech_kinematics as mk
    from mech_kinematics.ros.cdr import stamp_from_cdr
    from mech_kinematics.ros.parameters import rate_default
    from mech_kinematics.scene import load_scene
    from mech_kinematics.units import rad_per_s_from_rpm

    scene = load_scene(scene_name)
    rpm = rate_default(scene.input)  # the node's default crank_speed_rpm
    namespace = f'/long_run_{os.getpid()}_{random.randrange(10 ** 6)}'
    rclpy.init()
    sub = rclpy.create_node('long_run_subscriber', namespace=namespace)
    stamps: list[int] = []
    kept: list[bytes] = []
    keep_ns = round(keep_s * NS)
    next_keep = [0]

    def on_state(data: bytes) -> None:
        stamp = stamp_from_cdr(data)
        stamps.append(stamp)
        if stamp >= next_keep[0]:
            kept.append(bytes(data))
            next_keep[0] = stamp + keep_ns if next_keep[0] else stamp + keep_ns

    sub.create_subscription(JointState, 'joint_states', on_state,
                            QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE),
                            raw=True)
    command = [sys.executable, '-m', 'mech_kinematics.kinematics_node', '--ros-args',
               '-r', f'__ns:={namespace}', '-p', f'scene:={scene_name}',
               '-p', f'rate_hz:={rate}', '--log-level', 'warn']
    started = datetime.datetime.now(datetime.timezone.utc)
    node = subprocess.Popen(command)
    try:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            rclpy.spin_once(sub, timeout_sec=0.1)
    finally:
        node.send_signal(signal.SIGINT)
        node.wait(timeout=20)
        sub.destroy_node()
        rclpy.try_shutdown()
    if not kept:
        msg = 'Expected joint_states from the node, got none: is the ROS environment set up?'
        raise RuntimeError(msg)
    messages = [deserialize_message(d, JointState) for d in kept]
    crank = scene.input.link
    first = messages[0]
    index = list(first.name).index(next(n for n in first.name if crank in n))
    s1 = stamp_from_cdr(kept[0])
    a1 = first.position[index]
    omega = scene.input.speed
    rows = []
    with mpmath.workdps(60):
        omega_mp = rad_per_s_from_rpm(mpmath.mpf(rpm), mpmath.pi)
        for data, msg in zip(kept, messages, strict=True):
            s = stamp_from_cdr(data)
            exact = mpmath.mpf(a1) + omega_mp * mpmath.mpf(s - s1) / NS
            two_pi = 2 * mpmath.pi
            exact_wrapped = exact - two_pi * mpmath.floor(exact / two_pi + mpmath.mpf(0.5))
            angle_error = abs(_wrap(float(mpmath.mpf(msg.position[index]) - exact_wrapped)))
            state = mk.solve(scene, float(exact_wrapped), omega, 0.0)
            names = list(msg.name)
            worst = 0.0
            for name, pos, vel in zip(names, msg.position, msg.velocity, strict=True):
                joint = state.joints[name]
                worst = max(worst, abs(_wrap(pos - joint.position)),
                            abs(vel - joint.velocity))
            rows.append({'t_s': (s - s1) / NS, 'angle_error_rad': angle_error,
                         'state_error': worst})
    period = round(NS / rate)
    owed = (stamps[-1] - stamps[0]) // period + 1
    return {
        'date': started.strftime('%Y-%m-%d'),
        'started_utc': started.strftime('%Y-%m-%dT%H:%M:%SZ'),
        'scene': scene_name, 'rate_hz': rate, 'crank_speed_rpm': rpm,
        'seconds': seconds, 'run_time_s': (stamps[-1] - stamps[0]) / NS,
        'turns': abs(rpm) * (stamps[-1] - stamps[0]) / NS / 60,
        'received': len(set(stamps)), 'owed': owed,
        'max_angle_error_rad': max(r['angle_error_rad'] for r in rows),
        'final_angle_error_rad': rows[-1]['angle_error_rad'],
        'max_state_error': max(r['state_error'] for r in rows),
        'keep_s': keep_s, 'samples': len(rows), 'rows': rows[:: max(1, len(rows) // 60)],
    }


def main(argv: list[str] | None = None) -> int:
    """Run the node once and print (or write) the measured figures as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=600.0)
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--scene', default=SCENE)
    parser.add_argument('--keep', type=float, default=1.0,
                        help='seconds of stamps between decoded messages')
    parser.add_argument('--out', type=Path)
    args = parser.parse_args(argv)
    result = run(args.seconds, args.rate, args.scene, args.keep)
    text = json.dumps(result, indent=1)
    if args.out:
        args.out.write_text(text + '\n')
    else:
        print(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
