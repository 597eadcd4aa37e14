# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Rebuild a bag's ``metadata.yaml`` from its storage file: ``python -m mech_kinematics reindex``.

The counterpart of ``ros2 bag reindex`` for the bags of ``record`` (and of
rosbags and rosbag2: one ``.mcap`` or ``.db3`` file). After the recorder was
killed, its bag has no ``metadata.yaml`` and rosbags and ``ros2 bag`` refuse
it; this makes it readable, with every message that reached the file (all
but those not flushed yet: the last half second of the recording, more on a
slow disk), by
:func:`mech_kinematics.bag.reindex`:

- MCAP: the file is scanned and every intact chunk kept, also those after a
  damaged one (or after a summary with more data after it). Unless the file
  was closed normally and is whole, the kept chunks are copied to a new file
  with their message indexes and a summary, which takes the file's name; the
  original is kept as ``NAME.damaged``. The storage file is never cut or
  changed in place;
- sqlite3: opening the database for writing rolls back the transaction that
  was cut, then the tables are checked and counted; if pages are unreadable,
  every readable row is copied to a new database and the original is kept as
  ``NAME.damaged``.

Each note printed says what was dropped (offsets or row ids) and why.

A bag whose storage file another process locks (a recording still running)
or holds open is refused with one line naming the process, and nothing is
written (:mod:`mech_kinematics.bag.lock`). If the repaired file cannot be
written whole (a full disk, a read-only directory), the storage file is left
as it was.

Topics, types, message definitions, type hashes, offered QoS, message counts,
time range, storage identifier and bag version are taken from the storage
file. Running it on a bag that is already whole (closed normally, or
reindexed) writes nothing but the same metadata.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import sys
from typing import Any

from .cli import run_tool

__all__ = ['add_parser', 'main', '_handle']

REINDEX_HELP = """\
Rebuild metadata.yaml of the bag directory BAG from its storage file (.mcap or
.db3), as `ros2 bag reindex` does, e.g. after the recorder was killed: the
bag becomes readable by rosbags, `ros2 bag` and Foxglove with every message
that reached the file. A storage file is never cut or repaired in place: an
MCAP file that needs a summary, and damage (a changed byte in a chunk, an
unreadable database page), are written whole to a new file that takes its
name, with every intact chunk or readable row, and the original is kept
beside it as NAME.damaged; an sqlite3 database has its interrupted
transaction rolled back by SQLite. A bag that is already whole is left as it
is. A bag that another process locks or holds open (a recording still
running) is refused, exit status 2. Each note says what was dropped and why.
The bag version is --bag-version if given, else the one stored in the bag,
else the one its QoS profiles are written in, else 8.
"""


def _print_result(info: Any) -> None:
    seconds = (info.end - info.start) / 1e9 if info.message_count else 0.0
    print(f'reindexed {info.path} ({info.storage}, bag version {info.version}): '
          f'{info.message_count} messages over {seconds:.1f} s')
    for note in info.notes:
        print(f'  {note}')
    width = max([len(t.name) for t in info.topics] + [5])
    type_width = max([len(t.type) for t in info.topics] + [4])
    print(f'{"topic":<{width}}  {"type":<{type_width}}  {"messages":>9}')
    for topic in info.topics:
        print(f'{topic.name:<{width}}  {topic.type:<{type_width}}  '
              f'{info.counts.get(topic.id, 0):>9}')


def _handle(args: argparse.Namespace) -> int:
    """Handle ``reindex``: rebuild the metadata, print what the bag holds; return the status."""
    from ..bag import BagError, reindex

    try:
        info = reindex(args.bag, version=args.bag_version)
    except BagError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    _print_result(info)
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``reindex`` subcommand on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'reindex', help="rebuild a bag's metadata.yaml from its storage (after a crash)",
        description=REINDEX_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('bag', metavar='BAG', help='the bag directory')
    parser.add_argument('--bag-version', type=int, choices=(8, 9), default=None,
                        help='rosbag2 format version of the metadata (default: as stored, '
                             'else as the QoS profiles are written, else 8)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``reindex``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
