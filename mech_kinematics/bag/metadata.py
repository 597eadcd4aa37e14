# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What a rosbag2 bag says about itself: its topics and its ``metadata.yaml``.

A bag directory holds one storage file (``.mcap`` or ``.db3``) and
``metadata.yaml``. The storage file carries, per topic, what rosbag2 calls its
topic metadata (name, type, serialization format, offered QoS profiles, type
hash) and the message definitions; ``metadata.yaml`` repeats that with the
message counts and the time range. rosbags and ``ros2 bag`` refuse a bag
without ``metadata.yaml``; both storages of this package hold everything needed
to rebuild it (:func:`mech_kinematics.bag.writer.reindex`).

The offered QoS profiles are stored as YAML text in the format of the bag
version: integers for the policies in version 8 (readable by Humble), names in
version 9 (rosbag2#1895). rosbags' own ``dump_qos_v8`` and ``dump_qos_v9`` write
them, so that a bag of this package and a bag of rosbags say the same thing.
rosbags is imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
import os
from pathlib import Path
from typing import Any

import yaml

from ..errors import MechKinematicsError

__all__ = [
    'BAG_VERSIONS', 'BagError', 'BagInfo', 'METADATA_FILE', 'Topic', 'bag_version_of_qos',
    'bagfile_information', 'metadata_text', 'parse_qos', 'qos_text', 'ros_distro',
    'stored_version', 'type_hash_from_definition', 'write_metadata_yaml',
]

BAG_VERSIONS = (8, 9)
METADATA_FILE = 'metadata.yaml'
_DELIMITER = '=' * 80 + '\n'


class BagError(MechKinematicsError):
    """A bag cannot be written, closed or rebuilt (the message says which file and why)."""


@dataclass(frozen=True)
class Topic:
    """One topic of a bag, as rosbag2's ``TopicMetadata`` and message definition describe it.

    Attributes
    ----------
    id : int
        The storage's id of the topic (the MCAP channel id, the sqlite3 ``topics.id``), >= 1.
    name : str
        Absolute topic name, e.g. ``/joint_states``.
    type : str
        Type name, e.g. ``sensor_msgs/msg/JointState``.
    definition : str
        Full message definition, the type's text then its dependencies' (rosbag2_cpp
        ``LocalMessageDefinitionSource``).
    encoding : str
        Format of ``definition``: ``'ros2msg'`` or ``'ros2idl'``.
    type_hash : str
        ``RIHS01_`` followed by 64 hexadecimal digits.
    qos : tuple
        Offered QoS profiles of the publishers (``rosbags.interfaces.Qos``).
    serialization_format : str
        ``'cdr'``.
    """

    id: int
    name: str
    type: str
    definition: str
    encoding: str
    type_hash: str
    qos: tuple[Any, ...] = ()
    serialization_format: str = 'cdr'


@dataclass(frozen=True)
class BagInfo:
    """A closed bag: its topics, what its storage holds, and how it was closed.

    Attributes
    ----------
    path : Path
        The bag directory.
    storage : str
        ``'mcap'`` or ``'sqlite3'`` (rosbag2's storage identifier).
    version : int
        Bag format version, 8 or 9.
    file : str
        Name of the storage file inside ``path``.
    topics : tuple of Topic
        In id order.
    counts : Mapping[int, int]
        Messages readable from the storage, by topic id.
    start, end : int
        Receive times of the first and last message, ns since the epoch (0 if none).
    notes : tuple of str
        What recovery did to the storage (dropped an incomplete tail, rolled back a
        transaction, ...); empty after a normal close.
    """

    path: Path
    storage: str
    version: int
    file: str
    topics: tuple[Topic, ...]
    counts: Mapping[int, int]
    start: int = 0
    end: int = 0
    notes: tuple[str, ...] = field(default=())

    @property
    def message_count(self) -> int:
        """Messages in the bag, all topics."""
        return sum(self.counts.get(t.id, 0) for t in self.topics)

    def count(self, name: str) -> int:
        """Messages of the topic called ``name`` (0 if the bag has no such topic)."""
        return sum(self.counts.get(t.id, 0) for t in self.topics if t.name == name)


def qos_text(profiles: Sequence[Any], version: int) -> str:
    """Return the offered QoS ``profiles`` as the storage of a version-``version`` bag holds them.

    Version 8: rosbags' ``dump_qos_v8`` (a YAML list, policies as integers).
    Version 9: the YAML of rosbags' ``dump_qos_v9`` (policies by name).
    """
    from rosbags.rosbag2.metadata import dump_qos_v8, dump_qos_v9

    if version >= 9:
        dumped = dump_qos_v9(list(profiles))
        return yaml.safe_dump(dumped, default_flow_style=False, sort_keys=False).strip() \
            if dumped else ''
    return dump_qos_v8(list(profiles))


def parse_qos(text: str) -> tuple[Any, ...]:
    """Return the QoS profiles stored as ``text`` (either version's format)."""
    from rosbags.rosbag2.metadata import parse_qos as rosbags_parse_qos

    return tuple(rosbags_parse_qos(text))


def bag_version_of_qos(texts: Sequence[str]) -> int | None:
    """Return the bag version whose QoS format ``texts`` use, or None if none tells.

    Version 8 stores the policies as integers, version 9 by name.
    """
    for text in texts:
        try:
            profiles = yaml.safe_load(text) if text else None
        except yaml.YAMLError:
            continue
        if isinstance(profiles, list) and profiles and isinstance(profiles[0], dict):
            reliability = profiles[0].get('reliability')
            if isinstance(reliability, str):
                return 9
            if isinstance(reliability, int):
                return 8
    return None


def stored_version(text: str) -> int | None:
    """Return the bag version of rosbag2 metadata stored in a storage file, None if unknown."""
    try:
        info = yaml.safe_load(text)
    except yaml.YAMLError:
        return None
    version = info.get('version') if isinstance(info, dict) else None
    return version if isinstance(version, int) else None


def type_hash_from_definition(type_name: str, definition: str, encoding: str) -> str:
    """Return the RIHS01 hash of ``type_name`` computed from its stored definition.

    For storages that do not keep the hash (bags written by rosbags' mcap writer);
    rosbags computes it the same way when it checks a bag.
    """
    from rosbags.typesys import get_types_from_idl, get_types_from_msg, get_typestore, Stores

    types: dict[str, Any] = {}
    if encoding == 'ros2msg':
        types.update(get_types_from_msg(definition, type_name))
    else:
        for section in definition.split(_DELIMITER)[1:]:
            _, idl = section.split('\n', 1)
            types.update(get_types_from_idl(idl))
    store = get_typestore(Stores.EMPTY)
    store.register(types)
    return str(store.hash_rihs01(type_name))


def ros_distro() -> str:
    """Return the ROS distribution, as rosbag2 records it (``ROS_DISTRO``, empty if unset)."""
    return os.environ.get('ROS_DISTRO', '')


def bagfile_information(info: BagInfo) -> dict[str, Any]:
    """Return the ``rosbag2_bagfile_information`` mapping of ``metadata.yaml`` for ``info``."""
    from rosbags.rosbag2.metadata import dump_qos_v8, dump_qos_v9

    dump_qos = dump_qos_v9 if info.version >= 9 else dump_qos_v8
    start = info.start if info.message_count else 0
    duration = max(0, info.end - info.start) if info.message_count else 0
    count = info.message_count
    return {
        'version': info.version,
        'storage_identifier': info.storage,
        'duration': {'nanoseconds': duration},
        'starting_time': {'nanoseconds_since_epoch': start},
        'message_count': count,
        'topics_with_message_count': [
            {
                'topic_metadata': {
                    'name': topic.name,
                    'type': topic.type,
                    'serialization_format': topic.serialization_format,
                    'offered_qos_profiles': dump_qos(list(topic.qos)),
                    'type_description_hash': topic.type_hash,
                },
                'message_count': info.counts.get(topic.id, 0),
            }
            for topic in info.topics
        ],
        'compression_format': '',
        'compression_mode': '',
        'relative_file_paths': [info.file],
        'files': [{
            'path': info.file,
            'starting_time': {'nanoseconds_since_epoch': start},
            'duration': {'nanoseconds': duration},
            'message_count': count,
        }],
        'custom_data': None,
        'ros_distro': ros_distro(),
    }


class _Dumper(yaml.SafeDumper):
    """Safe YAML with multi-line strings (version 8's QoS profiles) as literal blocks."""


def _represent_str(dumper: yaml.SafeDumper, text: str) -> Any:
    style = '|' if '\n' in text else None
    return dumper.represent_scalar('tag:yaml.org,2002:str', text, style=style)


_Dumper.add_representer(str, _represent_str)


def metadata_text(info: BagInfo) -> str:
    """Return :func:`bagfile_information` as YAML (what the storages embed)."""
    return yaml.dump(bagfile_information(info), Dumper=_Dumper, default_flow_style=False,
                     sort_keys=False)


def write_metadata_yaml(info: BagInfo) -> Path:
    """Write ``metadata.yaml`` of ``info`` atomically (a synced temporary file, renamed).

    Raises
    ------
    OSError
        If it cannot be written (the previous ``metadata.yaml``, if any, is left as it was).
    """
    text = yaml.dump({'rosbag2_bagfile_information': bagfile_information(info)},
                     Dumper=_Dumper, default_flow_style=False, sort_keys=False)
    target = info.path / METADATA_FILE
    tmp = target.with_name(METADATA_FILE + '.tmp')
    try:
        with open(tmp, 'w', encoding='utf-8') as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(tmp, target)
    except OSError:
        tmp.unlink(missing_ok=True)
        raise
    return target
