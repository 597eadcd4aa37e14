# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Build script for the mech_kinematics ament_python package."""

from glob import glob
import os

from setuptools import find_packages
from setuptools import setup

package_name = 'mech_kinematics'


def _files(pattern):
    """Return the regular files matching ``pattern``, sorted."""
    return sorted(path for path in glob(pattern) if os.path.isfile(path))


# The shipped scenes live in config/scenes/ at the repo root (never copied into
# the source tree).  They are installed twice: under share/mech_kinematics/ for
# ROS (data_files below), and inside the Python package as mech_kinematics/scenes/
# by mapping a data-only sub-package onto config/scenes/, so that a wheel or a
# colcon install also has them next to the code.  An editable install does not
# materialise that copy; the code then finds config/scenes/ next to the package.
_scenes_package = (
    {package_name + '.scenes': 'config/scenes'} if os.path.isdir('config/scenes') else {}
)

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'test.*']) + list(_scenes_package),
    package_dir=_scenes_package,
    # The printed textbook answers (mech_kinematics/data/, read by mech_kinematics.textbook).
    package_data={package_name + '.data': ['*.yaml'],
                  **{name: ['*.yaml'] for name in _scenes_package}},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', _files('config/*')),
        ('share/' + package_name + '/config/scenes', _files('config/scenes/*')),
        ('share/' + package_name + '/launch', _files('launch/*.launch.*')),
    ],
    python_requires='>=3.10',
    install_requires=['setuptools'],
    zip_safe=False,
    maintainer='mech_kinematics contributors',
    maintainer_email='mech_kinematics@example.com',
    description=('Exact kinematics of planar mechanisms: an analytic solver, a ROS 2 node '
                 'and tools'),
    license='Apache-2.0',
    entry_points={
        # Installed to lib/mech_kinematics (setup.cfg), so each runs as
        # `ros2 run mech_kinematics NAME`; in .venv/bin after `make install`.
        'console_scripts': [
            'kinematics_node = mech_kinematics.kinematics_node:main',
            # Every tool of `python -m mech_kinematics` (mech_kinematics/__main__.py
            # TOOLS) but `run`, make run's wrapper: NAME = mech_kinematics.tools.NAME:main.
            # test/test_packaging.py fails when a tool has no line here.
            'solve = mech_kinematics.tools.solve:main',
            'record = mech_kinematics.tools.record:main',
            'plot = mech_kinematics.tools.plot:main',
            'diagram = mech_kinematics.tools.diagram:main',
            'report = mech_kinematics.tools.report:main',
            'bench = mech_kinematics.tools.bench:main',
            'reindex = mech_kinematics.tools.reindex:main',
            'check = mech_kinematics.tools.check:main',
            'urdf = mech_kinematics.tools.urdf:main',
            'urdf2scene = mech_kinematics.tools.urdf2scene:main',
            'view = mech_kinematics.tools.view:main',
        ],
    },
)
