# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Reading each closure form against reading a loop_closures.yaml of the same loops (issue 43).

For each fixture of ``test/robot/test_closure_forms.py`` the same robot's
closures are also written as a scikit-robot ``loop_closures.yaml`` (each
closure's point and axis in the root frame at the zero pose; a weld as the
pin at its origin, which reads the same way), and both are timed:

- ``file``: :func:`~mech_kinematics.robot.description.read_closure_file`
  alone (the form inside a URDF: the URDF's read with the elements less the
  same URDF's read without them);
- ``whole``: :func:`~mech_kinematics.robot.description.read_description`
  of the URDF and its closures.

Each figure is the median of ``--repeat`` runs (ms) after one untimed run,
and the ratio form / loop_closures.yaml. Run: ``.venv/bin/python
bench/closure_forms.py [--repeat 200]``. Not a timed test.
"""

from __future__ import annotations

import argparse
from functools import partial
import json
from pathlib import Path
import statistics
import tempfile
import time

from lxml import etree
import numpy as np

from mech_kinematics.robot.description import read_closure_file, read_description

DATA = Path(__file__).resolve().parents[1] / 'test' / 'data' / 'urdf'
#: name -> (URDF, closure file or None: the closures inside the URDF).
FORMS = {
    'constraint file': ('robotiq_2f_85.urdf', 'robotiq_2f_85.constraints.xml'),
    'robot.yaml': ('gepetto_5bar_linkage.urdf', 'gepetto_5bar_linkage.robot.yaml'),
    'robot_data.yaml': ('fusion2urdf_assem1_exact.urdf',
                        'fusion2urdf_assem1_exact.robot_data.yaml'),
    '<loop_joint>': ('robotiq_2f_85.loop_joint.urdf', None),
    '<loop>': ('robotiq_2f_85.loop.urdf', None),
}


def _median_ms(call, repeat: int) -> float:
    call()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def _loop_closures_yaml(urdf: Path, closures: Path | None, folder: Path) -> Path:
    """Write the robot's closures as a loop_closures.yaml; return its path."""
    description = read_description(urdf, closures)
    zero = description.transforms({})
    lines = ['closures:']
    for c in description.closures:
        frame = zero[c.link_a] @ c.frame_a
        axis = frame[:3, :3] @ np.asarray(c.axis_a if c.axis_a is not None else (0, 0, 1))
        point = ', '.join(repr(float(v)) for v in frame[:3, 3])
        lines.append(f'- {{link_a: {c.link_a}, link_b: {c.link_b}, point: [{point}], '
                     f'axis: [{", ".join(repr(float(v)) for v in axis)}]}}')
    path = folder / f'{urdf.stem}.loop_closures.yaml'
    path.write_text('\n'.join(lines) + '\n')
    return path


def main() -> None:
    """Print the figures as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--repeat', type=int, default=200)
    args = parser.parse_args()
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, (urdf_name, closures_name) in FORMS.items():
            urdf = DATA / urdf_name
            closures = None if closures_name is None else DATA / closures_name
            sidecar = _loop_closures_yaml(urdf, closures, folder)
            if closures is None:    # the elements inside: the URDF without them and a sidecar
                plain = folder / f'{urdf.stem}.plain.urdf'
                root = etree.fromstring(urdf.read_bytes())
                for element in [*root.findall('loop_joint'), *root.findall('loop')]:
                    root.remove(element)
                plain.write_bytes(etree.tostring(root))
                with_form = _median_ms(partial(read_description, urdf), args.repeat)
                bare = _median_ms(partial(read_description, plain), args.repeat)
                base = _median_ms(partial(read_description, plain, sidecar), args.repeat)
                form_file = with_form - bare
                yaml_file = base - bare
                whole, whole_yaml = with_form, base
            else:
                description = read_description(urdf)
                form_file = _median_ms(partial(read_closure_file, closures, description),
                                       args.repeat)
                yaml_file = _median_ms(partial(read_closure_file, sidecar, description),
                                       args.repeat)
                whole = _median_ms(partial(read_description, urdf, closures), args.repeat)
                whole_yaml = _median_ms(partial(read_description, urdf, sidecar), args.repeat)
            out[name] = {'file_ms': round(form_file, 3),
                         'loop_closures_yaml_ms': round(yaml_file, 3),
                         'file_ratio': round(form_file / yaml_file, 2),
                         'whole_ms': round(whole, 3), 'whole_loop_closures_yaml_ms':
                         round(whole_yaml, 3), 'whole_ratio': round(whole / whole_yaml, 2)}
    print(json.dumps(out, indent=1))


if __name__ == '__main__':
    main()
