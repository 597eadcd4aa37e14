# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Figures that docs/commands.md, robustness.md, bags.md, view.md, install.md quote.

- ``check_grid``: the time of ``check``'s study of the assembly region
  (:func:`mech_kinematics.geometry.region.region_from_scene`, 180 x 180 grid
  and both slices) on the packaged five-bar and excavator, ``--repeat`` runs
  each after one untimed run: ``[min, median, max]`` in ms;
- ``reindex``: a bag of 100,000 ``JointState`` messages written with
  ``BagWriter`` in 20 MCAP chunks, one byte flipped in the 11th chunk, and
  the same messages in sqlite3 with one leaf page of ``messages`` damaged
  (its page type byte) in the middle of the table: the file size, the time
  of ``reindex()`` (``[min, median, max]`` of ``--repeat`` repairs of fresh
  copies, s) and the messages it kept.

- ``recorder``: the node at 1 kHz recorded by three recorders (mcap, sqlite3,
  and an mcap *witness*; the default EventsExecutor): the CPU of the mcap and
  sqlite3 recorders over ``--record`` s (user + system over wall time, % of
  one core, from /proc, from 2 s after they subscribed), then both killed
  with ``kill -9``, the witness stopped normally 0.2 s later and the two bags
  reindexed (timed): of the state messages the witness received before the
  kill (from when both recorded), the share each reindexed bag holds, and how
  long before the kill its newest was received, and the share of those
  received at least 1 s before the kill; the witness's bag size per minute.

- ``viewer``: the default node (100 Hz) and ``view`` on a free port: after
  the first frame and 5 s of traces, 100 requests of ``/state`` one after
  another, their times (ms: median and 90th percentile) and the answer's size.

- ``tf2_build``: ``scripts/build_tf2_msgs.py --force`` (docs/install.md), the
  build of ``tf2_msgs`` into the running ``.venv``, ``[min, median, max]`` of
  ``--repeat`` runs, s.

``--data docs/report/data.json`` stores each section under its key (a report
keeps them); without it the figures are printed as JSON.

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/docs_bench.py [check_grid] [reindex] [recorder] [viewer] [tf2_build]
                               [--repeat 7]
                               [--record 10] [--data FILE]
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import datetime
import json
import os
from pathlib import Path
import random
import shutil
import signal
import sqlite3
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from typing import Any

#: Messages of the reindexed bag, and the MCAP chunks they fill.
MESSAGES = 100_000
CHUNKS = 20
T0 = 1_700_000_000_000_000_000     # ns, the receive time of message 0
DT = 1_000_000                     # ns between messages (1 kHz)
TYPE = 'sensor_msgs/msg/JointState'


def _spread(times: list[float]) -> list[float]:
    return [min(times), statistics.median(times), max(times)]


def _timed(call: Callable[[], Any]) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def check_grid(repeat: int) -> dict[str, Any]:
    """Return the times (ms) of ``region_from_scene`` on the packaged several-driver scenes."""
    import mech_kinematics as mk
    from mech_kinematics.geometry.region import GRID, region_from_scene

    out: dict[str, Any] = {'grid': GRID, 'repeat': repeat}
    for name in ('five_bar', 'excavator'):
        scene = mk.load_scene(name)
        region_from_scene(scene)
        out[name] = {'ms': _spread([1e3 * _timed(lambda s=scene: region_from_scene(s))
                                    for _ in range(repeat)])}
    return out


def _payloads() -> list[bytes]:
    """Return the messages: JointState, stamp i ns, one joint at i mrad (bytes patched)."""
    import numpy as np
    from rosbags.typesys import get_types_from_msg, get_typestore, Stores

    from mech_kinematics.tools import record

    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(record.message_definition(TYPE)[1], TYPE))
    header = store.types['std_msgs/msg/Header'](
        store.types['builtin_interfaces/msg/Time'](0, 0), 'mechanism')
    marker = 12345.678      # the position, found in the bytes
    msg = store.types[TYPE](header, ['crank'], np.array([marker]), np.zeros(1), np.zeros(1))
    template = bytearray(store.serialize_cdr(msg, TYPE))
    position = bytes(template).index(struct.pack('<d', marker))
    out = []
    for i in range(MESSAGES):
        struct.pack_into('<I', template, 8, i)
        struct.pack_into('<d', template, position, i * 1e-3)
        out.append(bytes(template))
    return out


def _write_bag(path: Path, storage: str, payloads: list[bytes]) -> Path:
    from mech_kinematics.bag import BagWriter
    from mech_kinematics.bag.metadata import type_hash_from_definition
    from mech_kinematics.tools import record

    writer = BagWriter(path, storage=storage, flush_interval=3600.0, flush_bytes=1 << 40)
    writer.open()
    encoding, text = record.message_definition(TYPE)
    topic = writer.add_topic('/js', TYPE, definition=text, encoding=encoding,
                             type_hash=type_hash_from_definition(TYPE, text, encoding))
    for i, data in enumerate(payloads):
        writer.write(topic, T0 + i * DT, data)
        if (i + 1) % (MESSAGES // CHUNKS) == 0:
            writer.flush()      # one MCAP chunk, one sqlite3 transaction
    writer.close()
    return path


def _leaf_pages(db: bytes, root: int) -> list[int]:
    """Return the leaf pages of the table b-tree at page ``root`` of database ``db``, in order."""
    page_size = int.from_bytes(db[16:18], 'big')
    start = (root - 1) * page_size
    head = start + (100 if root == 1 else 0)
    if db[head] == 0x0D:
        return [root]
    cells = int.from_bytes(db[head + 3:head + 5], 'big')
    children = []
    for i in range(cells):
        cell = start + int.from_bytes(db[head + 12 + 2 * i:head + 14 + 2 * i], 'big')
        children.append(int.from_bytes(db[cell:cell + 4], 'big'))
    children.append(int.from_bytes(db[head + 8:head + 12], 'big'))
    return [leaf for child in children for leaf in _leaf_pages(db, child)]


def _damage(bag: Path, storage: str) -> tuple[Path, bytes]:
    """Return the storage file of ``bag`` and its bytes with one byte flipped."""
    from mech_kinematics.bag import storage_mcap

    if storage == 'mcap':
        file = bag / f'{bag.name}.mcap'
        chunks = storage_mcap.RecoveredMcap(file).chunks
        assert len(chunks) == CHUNKS, len(chunks)
        offset = chunks[10].offset + chunks[10].length - 10     # a message's data
    else:
        file = bag / f'{bag.name}.db3'
        with sqlite3.connect(file) as conn:
            (root,) = conn.execute('SELECT rootpage FROM sqlite_master WHERE name = ?',
                                   ('messages',)).fetchone()
        data = file.read_bytes()
        leaves = _leaf_pages(data, root)
        offset = (leaves[len(leaves) // 2] - 1) * int.from_bytes(data[16:18], 'big')
    damaged = bytearray(file.read_bytes())
    damaged[offset] ^= 0xFF
    return file, bytes(damaged)


def reindex_repair(repeat: int) -> dict[str, Any]:
    """Return the size, repair time and messages kept of a damaged bag in each storage."""
    from mech_kinematics.bag import reindex

    payloads = _payloads()
    out: dict[str, Any] = {'messages': MESSAGES, 'chunks': CHUNKS, 'repeat': repeat}
    with tempfile.TemporaryDirectory() as tmp:
        for storage in ('mcap', 'sqlite3'):
            source = _write_bag(Path(tmp) / f'source_{storage}', storage, payloads)
            file, damaged = _damage(source, storage)
            times, kept = [], set()
            for run in range(repeat):
                bag = Path(tmp) / f'bag_{storage}_{run}'
                bag.mkdir()
                (bag / f'{bag.name}{file.suffix}').write_bytes(damaged)
                times.append(_timed(lambda b=bag, k=kept: k.add(reindex(b).count('/js'))))
                shutil.rmtree(bag)
            assert len(kept) == 1, kept
            out[storage] = {'mb': file.stat().st_size / 1e6, 's': _spread(times),
                            'kept': kept.pop()}
            out[storage]['dropped'] = MESSAGES - out[storage]['kept']
    return out


NS = 1_000_000_000
STATE_TOPICS = ('/joint_states', '/joint_accelerations', '/point_accelerations')


def _cpu_seconds(pid: int) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _wait_for(file: Path, text: str, process: subprocess.Popen, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while text not in file.read_text():
        if process.poll() is not None or time.monotonic() > deadline:
            raise RuntimeError(f'no {text!r} from {file.name}:\n{file.read_text()}')
        time.sleep(0.05)


def _ros_env() -> dict[str, str]:
    env = dict(os.environ, ROS_DOMAIN_ID=str(random.SystemRandom().randint(101, 200)),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    repo = str(Path(__file__).resolve().parents[1])
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [repo, env.get('PYTHONPATH')]))
    return env


def _received(bag: Path) -> dict[str, dict[int, int]]:
    """Return topic -> {header stamp: receive time} of the state topics of ``bag``, ns."""
    from rosbags.highlevel import AnyReader

    from mech_kinematics.ros.cdr import stamp_from_cdr

    out: dict[str, dict[int, int]] = {topic: {} for topic in STATE_TOPICS}
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic in out]
        for connection, timestamp, raw in reader.messages(connections=connections):
            out[connection.topic][stamp_from_cdr(raw)] = timestamp
    return out


def recorder(record_s: float = 10.0) -> dict[str, Any]:
    """Return the recorders' CPU at 1 kHz and what kill -9 and reindex leave of their bags."""
    from mech_kinematics.bag import reindex

    env = _ros_env()
    out: dict[str, Any] = {'rate_hz': 1000.0, 'record_s': record_s}
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        processes: dict[str, subprocess.Popen] = {}
        logs: dict[str, Path] = {}

        def start(name: str, *argv: str) -> None:
            logs[name] = tmp / f'{name}.log'
            with open(logs[name], 'w') as log:
                processes[name] = subprocess.Popen([sys.executable, *argv], env=env, stdout=log,
                                                   stderr=subprocess.STDOUT, cwd=tmp)

        try:
            for name, storage in (('mcap', 'mcap'), ('sqlite3', 'sqlite3'), ('witness', 'mcap')):
                start(name, '-m', 'mech_kinematics', 'record', '-o', str(tmp / name),
                      '--storage', storage, '--progress', '0')
            for name in ('mcap', 'sqlite3', 'witness'):
                _wait_for(logs[name], 'recording to', processes[name])
            start('node', '-m', 'mech_kinematics.kinematics_node', '--ros-args',
                  '-p', 'rate_hz:=1000.0', '--log-level', 'warn')
            for name in ('mcap', 'sqlite3', 'witness'):
                _wait_for(logs[name], 'subscribed to /diagnostics', processes[name])
            time.sleep(2.0)
            killed = ('mcap', 'sqlite3')
            cpu0 = {n: _cpu_seconds(processes[n].pid) for n in killed}
            wall0 = time.monotonic()
            time.sleep(record_s)
            cpu1 = {n: _cpu_seconds(processes[n].pid) for n in killed}
            wall = time.monotonic() - wall0
            kill_ns = time.time_ns()
            for name in killed:
                processes[name].kill()
            for name in killed:
                processes[name].wait(timeout=10)
            time.sleep(0.2)     # the witness gets what was on the way at the kill
            processes['witness'].send_signal(signal.SIGINT)
            processes['witness'].wait(timeout=30)
        finally:
            for process in processes.values():
                if process.poll() is None:
                    process.send_signal(signal.SIGINT)
                    try:
                        process.wait(timeout=15)
                    except subprocess.TimeoutExpired:
                        process.kill()
                        process.wait()
        witness = _received(tmp / 'witness')
        first, last = (min(min(v.values()) for v in witness.values()),
                       max(max(v.values()) for v in witness.values()))
        size = sum(f.stat().st_size for f in (tmp / 'witness').iterdir())
        out['witness_mb_per_minute'] = size / 1e6 * 60 * NS / (last - first)
        for name in killed:
            start_s = time.perf_counter()
            reindex(tmp / name)
            reindex_s = time.perf_counter() - start_s
            got = _received(tmp / name)
            recovered = owed = old_kept = old = 0
            for topic in STATE_TOPICS:
                begin = max(min(got[topic]), min(witness[topic]))     # both recording
                window = {s for s, t in witness[topic].items() if s >= begin and t <= kill_ns}
                recovered += len(window & set(got[topic]))
                owed += len(window)
                older = {s for s in window if witness[topic][s] <= kill_ns - NS}
                old_kept += len(older & set(got[topic]))
                old += len(older)
            newest = max(max(v.values()) for v in got.values())
            out[name] = {'cpu_pct': 100 * (cpu1[name] - cpu0[name]) / wall,
                         'recovered_pct': 100 * recovered / owed, 'owed': owed,
                         'older_than_1s_pct': 100 * old_kept / old,
                         'newest_ms': (kill_ns - newest) / 1e6, 'reindex_s': reindex_s,
                         'mb': sum(f.stat().st_size for f in (tmp / name).iterdir()
                                   if f.suffix in ('.mcap', '.db3')) / 1e6}
    return out


def viewer(requests: int = 100) -> dict[str, Any]:
    """Return the times (ms) and size (kB) of ``/state`` from ``view`` beside the default node."""
    import re
    import urllib.request

    env = _ros_env()
    with tempfile.TemporaryDirectory() as tmp_name:
        log = Path(tmp_name) / 'view.log'
        with open(log, 'w') as out:
            node = subprocess.Popen([sys.executable, '-m', 'mech_kinematics.kinematics_node',
                                     '--ros-args', '--log-level', 'warn'], env=env,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            view = subprocess.Popen([sys.executable, '-m', 'mech_kinematics', 'view', '--port',
                                     '0'], env=env, stdout=out, stderr=subprocess.STDOUT)
        try:
            _wait_for(log, '(Ctrl-C stops it)', view)
            url = re.search(r'(http://\S+/)', log.read_text()).group(1)    # type: ignore
            # /state answers the page's token only (docs/view.md, The door).
            token = re.search(r'name="view-token" content="([^"]+)"', urllib.request.urlopen(
                url).read().decode()).group(1)    # type: ignore
            state = urllib.request.Request(url + 'state', headers={'X-View-Token': token})
            deadline = time.monotonic() + 30
            while json.loads(urllib.request.urlopen(state).read())['frame'] is None:
                if time.monotonic() > deadline:
                    raise RuntimeError('no frame from view within 30 s')
                time.sleep(0.1)
            time.sleep(5.0)     # the traces fill
            times, sizes = [], []
            for _ in range(requests):
                start = time.perf_counter()
                sizes.append(len(urllib.request.urlopen(state).read()))
                times.append(1e3 * (time.perf_counter() - start))
        finally:
            for process in (view, node):
                process.send_signal(signal.SIGINT)
                try:
                    process.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
    deciles = statistics.quantiles(times, n=10)
    return {'requests': requests, 'median_ms': statistics.median(times), 'p90_ms': deciles[-1],
            'kb': statistics.median(sizes) / 1e3}


def tf2_build(repeat: int) -> dict[str, Any]:
    """Return the times (s) of rebuilding tf2_msgs into this Python's virtualenv."""
    script = Path(__file__).resolve().parents[1] / 'scripts' / 'build_tf2_msgs.py'
    return {'repeat': repeat, 's': _spread([_timed(lambda: subprocess.run(
        [sys.executable, str(script), '--force'], check=True)) for _ in range(repeat)])}


#: name -> the measurement, of the command line's arguments.
SECTIONS: dict[str, Callable[[argparse.Namespace], dict[str, Any]]] = {
    'check_grid': lambda args: check_grid(args.repeat),
    'reindex': lambda args: reindex_repair(args.repeat),
    'recorder': lambda args: recorder(args.record),
    'viewer': lambda args: viewer(),
    'tf2_build': lambda args: tf2_build(args.repeat)}


def main(argv: list[str] | None = None) -> int:
    """Measure the sections asked for; store them in the data file or print them."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('sections', nargs='*', metavar='SECTION',
                        help=f'what to measure: {", ".join(SECTIONS)} (default: all)')
    parser.add_argument('--repeat', type=int, default=7, help='timed runs of each')
    parser.add_argument('--record', type=float, default=10.0,
                        help='recorder: seconds of the CPU measurement before kill -9')
    parser.add_argument('--data', metavar='FILE',
                        help='store each section in this data file (docs/report/data.json)')
    args = parser.parse_args(argv)
    unknown = [name for name in args.sections if name not in SECTIONS]
    if unknown:
        parser.error(f'Expected sections among {", ".join(SECTIONS)}, got {", ".join(unknown)}')
    for name in args.sections or SECTIONS:
        section = SECTIONS[name](args)
        section.update(date=datetime.date.today().isoformat(), cpus=os.cpu_count(),
                       load=os.getloadavg()[0])
        if args.data:
            from mech_kinematics.tools.report.data import store_section
            store_section(args.data, name, section)
            print(f'stored under {name} in {args.data}', file=sys.stderr)
        else:
            print(json.dumps({name: section}, indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
