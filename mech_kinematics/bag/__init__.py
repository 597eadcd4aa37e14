# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""rosbag2 bags that survive their writer: writing, recovery and ``metadata.yaml``.

- :mod:`.metadata`: a bag's topics (:class:`Topic`), what a closed bag holds
  (:class:`BagInfo`) and its ``metadata.yaml``;
- :mod:`.storage_mcap`, :mod:`.storage_sqlite3`: the two storage files, each
  flushed a chunk or a transaction at a time, and recovered after a crash;
- :mod:`.writer`: :class:`BagWriter` and :func:`reindex`;
- :mod:`.queued`: :class:`QueuedWriter`, a writer written by a thread of its
  own, so that receiving never waits on the disk (its queue bounded:
  what overflows it is dropped and counted).

The files are those rosbag2 and rosbags write (MCAP ``ros2`` profile, sqlite3
schema version 4): rosbags, ``ros2 bag`` and Foxglove read them. Only the
standard library and PyYAML are imported here; rosbags, for its QoS and
type-hash helpers, inside the functions that use it.
"""

from .metadata import BAG_VERSIONS, BagError, BagInfo, Topic
from .queued import MAX_QUEUE_BYTES, QueuedWriter
from .writer import (BagWriter, check_new_bag, check_options, DEFAULT_VERSION, FLUSH_INTERVAL_S,
                     reindex, STORAGES)

__all__ = ['BAG_VERSIONS', 'BagError', 'BagInfo', 'BagWriter', 'DEFAULT_VERSION',
           'FLUSH_INTERVAL_S', 'MAX_QUEUE_BYTES', 'QueuedWriter', 'STORAGES', 'Topic',
           'check_new_bag', 'check_options', 'reindex']
