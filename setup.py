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
    ],
    python_requires='>=3.10',
    install_requires=['setuptools'],
    zip_safe=False,
    maintainer='mech_kinematics contributors',
    maintainer_email='mech_kinematics@example.com',
    description='Planar linkage kinematics (four-bar, slider-crank) as a ROS 2 node',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'kinematics_node = mech_kinematics.kinematics_node:main',
            'reindex = mech_kinematics.tools.reindex:main',
        ],
    },
)
