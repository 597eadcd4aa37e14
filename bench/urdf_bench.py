# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Side by side: joint_state_transformer's Levenberg-Marquardt against our closed form (issue 31).

HIT-Robotics' joint_state_transformer (the node ros/urdfdom#264 proposes)
completes a robot's joint states by Levenberg-Marquardt over the URDF's
constraints (its ``robot_model`` library, ``levenberg_marquardt.cpp``):
re-implemented here from its description, not its code, on the URDF's own
forward kinematics in NumPy (the library runs Pinocchio in C++):

- the residual stacks each closure's point gap (3 rows, its spherical and
  point constraints) and each mimic joint's ``q - multiplier q_leader -
  offset`` (its ``MimicJointConstraint``); the Jacobian is the geometric one
  (``w x (p - o)`` per revolute ancestor, ``w`` per prismatic one), filtered
  to the dependent joints;
- damped least squares ``step = J^T (J J^T + lambda I)^-1 h``, lambda from
  1e-3, x10 per outer iteration, /10 or x10 by the inner iteration's
  progress within [1e-9, 1e3]; a backtracking line search in ``1/10`` steps;
  ``ceil(sqrt(100))`` inner iterations, 100 in all; converged when the
  residual and the step are both below ``tol = 1e-5`` (its default);
- warm-started from the last message's state, as its node keeps it.

Each message sets the actuated joints (a smooth trajectory) and both
approaches answer every passive joint; we report the time per message and
the largest closure gap of each (the URDF's forward kinematics with the
answered joints), over the loops' size. Run:
``.venv/bin/python bench/urdf_bench.py [--messages N]``. Not a timed test.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
import time

import numpy as np

import mech_kinematics as mk
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.description import ClosureKind
from mech_kinematics.robot.writer import robot_urdf_from_scene

DATA = Path(__file__).resolve().parents[1] / 'test' / 'data' / 'urdf'
TOLERANCE = 1e-5
MAX_ITERATIONS = 100
LINE_SEARCH = 10


class LevenbergMarquardt:
    """joint_state_transformer's completion of joint states, on one robot."""

    def __init__(self, robot):
        d = robot.description
        self.d = d
        self.closures = [c for c in d.closures if c.kind is ClosureKind.PIN]
        names = set(robot.planar.joints) | set(robot.actuated)
        for j in d.joints.values():
            if j.mimic is not None and j.mimic.joint in names:
                names.add(j.name)
        self.names = [n for n in d.joints if n in names]
        self.index = {n: i for i, n in enumerate(self.names)}
        self.independent = np.array([n in robot.actuated for n in self.names])
        self.mimics = [(self.index[j.name], self.index[j.mimic.joint], j.mimic)
                       for j in d.joints.values() if j.mimic is not None and j.name in names
                       and j.mimic.joint in names]
        self.state = np.array([robot.reference.get(n, 0.0) for n in self.names])
        self.angular = np.array([d.joints[n].type.angular for n in self.names])

    def frames(self, q):
        """Return every link's frame and every joint's world axis and origin at ``q``."""
        values = {n: float(q[i]) for i, n in enumerate(self.names)}
        pose = self.d.pose(values)
        frames = self.d.transforms(pose)
        axes = {}
        for n in self.names:
            j = self.d.joints[n]
            t = frames[j.parent] @ j.origin
            axes[n] = (t[:3, :3] @ np.asarray(j.axis), t[:3, 3])
        return frames, axes

    def residual(self, q):
        """Return the constraints' residual at ``q``: closure gaps (m), mimic rules."""
        frames, _ = self.frames(q)
        rows = []
        for c in self.closures:
            rows.extend((frames[c.link_a] @ c.frame_a)[:3, 3]
                        - (frames[c.link_b] @ c.frame_b)[:3, 3])
        for i, leader, rule in self.mimics:
            rows.append(q[i] - rule.multiplier * q[leader] - rule.offset)
        return np.array(rows)

    def jacobian(self, q):
        """Return the residual's geometric Jacobian at ``q``."""
        frames, axes = self.frames(q)
        rows = []
        for c in self.closures:
            pa = (frames[c.link_a] @ c.frame_a)[:3, 3]
            pb = (frames[c.link_b] @ c.frame_b)[:3, 3]
            block = np.zeros((3, len(self.names)))
            for sign, link, p in ((1.0, c.link_a, pa), (-1.0, c.link_b, pb)):
                for j in self.d.chain(link):
                    if j.name not in self.index:
                        continue
                    w, o = axes[j.name]
                    column = np.cross(w, p - o) if j.type.angular else w
                    block[:, self.index[j.name]] += sign * column
            rows.extend(block)
        for i, leader, rule in self.mimics:
            row = np.zeros(len(self.names))
            row[i] = 1.0
            row[leader] -= rule.multiplier
            rows.append(row)
        return np.array(rows)

    def normalize(self, q):
        """Return ``q`` with its revolute joints wrapped to [-pi, pi)."""
        out = q.copy()
        out[self.angular] = np.remainder(out[self.angular] + math.pi, math.tau) - math.pi
        return out

    def solve(self, given):
        """Set the actuated joints, solve the rest by LM from the last state; return q, ok."""
        q = self.state.copy()
        for name, value in given.items():
            q[self.index[name]] = value
        filt = np.diag((~self.independent).astype(float))
        lam = 1e-3
        h = self.residual(q)
        step = np.full(len(q), 2 * TOLERANCE)
        inner_max = math.ceil(math.sqrt(MAX_ITERATIONS))
        outer = 0

        def converged():
            return h @ h < TOLERANCE ** 2 and step @ step < TOLERANCE ** 2

        while outer < MAX_ITERATIONS and not converged():
            lam *= 10
            previous = h @ h
            inner = 0
            while inner < inner_max and not converged():
                jf = self.jacobian(q) @ filt
                jjt = jf @ jf.T + lam * np.eye(len(h))
                step = jf.T @ np.linalg.solve(jjt, h)
                q = self.normalize(q - step)
                h = self.residual(q)
                last, best = h @ h, q.copy()
                mini = step / LINE_SEARCH
                for _ in range(LINE_SEARCH):
                    trial = self.normalize(best + mini)
                    ht = self.residual(trial)
                    if ht @ ht > last:
                        break
                    last, best, h = ht @ ht, trial, ht
                q = best
                inner += 1
                lam = max(lam / 10, 1e-9) if h @ h < previous else min(lam * 10, 1e3)
            outer += inner
        ok = converged()
        if ok:
            self.state = q
        return q, ok

    def gap(self, values):
        """Return the largest closure gap (m) with joint values ``values`` (name -> value)."""
        q = np.array([values[n] for n in self.names])
        frames, _ = self.frames(q)
        return max(float(np.linalg.norm((frames[c.link_a] @ c.frame_a)[:3, 3]
                                        - (frames[c.link_b] @ c.frame_b)[:3, 3]))
                   for c in self.closures)


def robots():
    """Yield (name, robot, trajectory of the actuated joints) for the bench."""
    for name in ('robotiq_2f_85', 'robotiq_2f_140'):
        robot = load_robot(DATA / f'{name}.urdf', DATA / f'{name}.loop_closures.yaml')
        yield name, robot, lambda t: {'finger_joint': 0.35 + 0.3 * math.sin(t)}
    five = load_robot(robot_urdf_from_scene(mk.load_scene('five_bar')))
    yield 'five_bar (urdf --robot)', five, lambda t: {
        'left_crank': 0.4 * math.sin(t), 'right_crank': 0.4 * math.sin(1.3 * t)}


def main(argv=None):
    """Run the side-by-side bench and print one line per robot."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--messages', type=int, default=500)
    args = parser.parse_args(argv)
    print(f'{"robot":26s} {"LM us/msg":>10s} {"LM gap/size":>12s} {"LM failed":>9s} '
          f'{"ours us/msg":>11s} {"ours gap/size":>13s}')
    for name, robot, trajectory in robots():
        lm = LevenbergMarquardt(robot)
        size = max(m['size'] for m in robot.planar.mechanisms)
        times = np.linspace(0.0, 2 * math.pi, args.messages)
        lm_gap = our_gap = 0.0
        failed = 0
        start = time.perf_counter()
        answers = []
        for t in times:
            q, ok = lm.solve(trajectory(t))
            failed += not ok
            answers.append(q)
        lm_time = (time.perf_counter() - start) / len(times)
        for q in answers:
            lm_gap = max(lm_gap, lm.gap(dict(zip(lm.names, q, strict=True))))
        start = time.perf_counter()
        ours = [robot.solve(trajectory(t)) for t in times]
        our_time = (time.perf_counter() - start) / len(times)
        for answer in ours:
            values = {n: float(j.position) for n, j in answer.joints.items()}
            our_gap = max(our_gap, lm.gap(values))
        print(f'{name:26s} {lm_time * 1e6:10.0f} {lm_gap / size:12.2e} {failed:9d} '
              f'{our_time * 1e6:11.0f} {our_gap / size:13.2e}')


if __name__ == '__main__':
    main()
