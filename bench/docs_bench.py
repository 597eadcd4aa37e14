# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Figures that docs/commands.md and docs/robustness.md quote (a script, not a test).

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

``--data docs/report/data.json`` stores each section under its key (a report
keeps them); without it the figures are printed as JSON.

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/docs_bench.py [check_grid] [reindex] [--repeat 7] [--data FILE]
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import datetime
import json
import os
from pathlib import Path
import shutil
import sqlite3
import statistics
import struct
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


SECTIONS = {'check_grid': check_grid, 'reindex': reindex_repair}


def main(argv: list[str] | None = None) -> int:
    """Measure the sections asked for; store them in the data file or print them."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('sections', nargs='*', metavar='SECTION',
                        help=f'what to measure: {", ".join(SECTIONS)} (default: all)')
    parser.add_argument('--repeat', type=int, default=7, help='timed runs of each')
    parser.add_argument('--data', metavar='FILE',
                        help='store each section in this data file (docs/report/data.json)')
    args = parser.parse_args(argv)
    unknown = [name for name in args.sections if name not in SECTIONS]
    if unknown:
        parser.error(f'Expected sections among {", ".join(SECTIONS)}, got {", ".join(unknown)}')
    for name in args.sections or SECTIONS:
        section = SECTIONS[name](args.repeat)
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
