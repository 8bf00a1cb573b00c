"""Read ROS 2 recordings: one ``.mcap`` file or a rosbag2 folder (``metadata.yaml`` + ``*.mcap``).

Messages are deserialised with :func:`rclpy.serialization.deserialize_message` into the
installed message classes, or read in bulk as raw CDR (:meth:`Bag.raw`) for the fixed-layout
decoders of :mod:`viscoadh_ros.io.cdr`. Chunks are split into records here (one ``struct`` call
per record) rather than by the ``mcap`` package's record objects, which cost several times
more per message. A file that was not finished (a recorder killed mid-run) has no
summary: it is read record by record up to the last complete chunk; :class:`Bag` refuses
it with a clear :class:`InputError` unless ``recover=True``.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from io import BytesIO
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from mcap.data_stream import ReadDataStream
from mcap.exceptions import InvalidMagic, McapError
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Footer, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, get_chunk_data_stream
from numpy.typing import NDArray
from rclpy.serialization import deserialize_message

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.io.mcap_log import METADATA_NAME, SCENE_KEY, VERSION_KEY
from viscoadh_ros.io.ros_schemas import message_class


@dataclass(frozen=True)
class RecordedMessage:
    """One deserialised message: ``log_time_ns`` is the recorder's clock, ns; ``order`` its
    position in the recording (files in order, records in file order), which breaks ties of
    equal times the way the recorder saw them."""

    topic: str
    type_name: str
    log_time_ns: int
    msg: Any
    order: int


@dataclass
class _Topic:
    type_name: str
    encoding: str
    log_ns: list[int] = field(default_factory=list)  # log time of each message, ns
    order: list[int] = field(default_factory=list)  # position in the recording
    data: list[bytes] = field(default_factory=list)  # CDR payloads


#: Record header (opcode u8, length u64) and Message record fields before the payload
#: (channel id u16, sequence u32, log time u64, publish time u64), MCAP's little-endian layout.
_RECORD_HEADER = struct.Struct("<BQ")
_MESSAGE_FIELDS = struct.Struct("<HIQQ")


def _bag_files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    if not path.is_dir():
        raise InputError(f"bag {str(path)!r} does not exist")
    meta = path / "metadata.yaml"
    if meta.is_file():
        try:
            info = yaml.safe_load(meta.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
            names = list(info["relative_file_paths"])
        except (yaml.YAMLError, KeyError, TypeError) as exc:
            raise InputError(f"bag folder {str(path)!r}: unreadable metadata.yaml ({exc})") from None
        storage = info.get("storage_identifier", "mcap")
        if storage != "mcap":
            raise InputError(f"bag folder {str(path)!r} uses storage {storage!r}; only mcap is read")
        files = [path / name for name in names]
        missing = [str(f) for f in files if not f.is_file()]
        if missing:
            raise InputError(
                f"bag folder {str(path)!r}: files listed in metadata.yaml are missing: {missing}"
            )
    else:
        # A folder whose recorder was killed has no metadata.yaml yet: take its files in order.
        files = sorted(path.glob("*.mcap"), key=lambda f: (len(f.name), f.name))
    if not files:
        raise InputError(f"bag folder {str(path)!r} holds no .mcap file")
    return files


class Bag:
    """All messages of a recording, read once into memory (raw CDR, decoded on demand).

    Args:
        path: An ``.mcap`` file or a rosbag2 folder.
        recover: Accept unfinished (truncated) files, keeping the messages of every complete
            chunk. Otherwise such a file raises :class:`InputError`.
    """

    def __init__(self, path: str | Path, *, recover: bool = False) -> None:
        self.path = Path(path)
        self.files = _bag_files(self.path)
        self.metadata: dict[str, dict[str, str]] = {}
        self.truncated: list[Path] = []
        self._topics: dict[str, _Topic] = {}
        self._records = 0
        for file in self.files:
            self._read_file(file, recover)

    def _read_file(self, file: Path, recover: bool) -> None:
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        finished = False
        with open(file, "rb") as stream:
            try:
                for record in StreamReader(stream, emit_chunks=True, validate_crcs=True).records:
                    if isinstance(record, Chunk):
                        self._read_chunk(record, channels, schemas)
                    elif isinstance(record, Schema):
                        schemas[record.id] = record
                    elif isinstance(record, Channel):
                        channels[record.id] = record
                    elif isinstance(record, Message):
                        self._add(record, channels, schemas)
                    elif isinstance(record, Metadata):
                        self.metadata.setdefault(record.name, {}).update(record.metadata)
                    elif isinstance(record, Footer):
                        finished = True
            except InvalidMagic:
                if not finished:
                    raise InputError(f"{str(file)!r} is not an MCAP file") from None
            except (McapError, struct.error, ValueError, EOFError) as exc:
                if not recover:
                    raise InputError(
                        f"{str(file)!r} is truncated or damaged ({type(exc).__name__}: {exc}); "
                        "pass --recover to use the messages up to its last complete chunk"
                    ) from None
        if not finished:
            self.truncated.append(file)

    def _read_chunk(self, chunk: Chunk, channels: dict[int, Channel], schemas: dict[int, Schema]) -> None:
        """The records of one chunk (decompressed and CRC-checked by ``mcap``), in order."""
        stream, length = get_chunk_data_stream(chunk, validate_crc=True)
        data = memoryview(stream.read(length)) if length else memoryview(b"")
        topics: dict[int, _Topic] = {}  # channel id -> topic, for this chunk's messages
        position = 0
        while position < length:
            opcode, size = _RECORD_HEADER.unpack_from(data, position)
            start = position + _RECORD_HEADER.size
            position = start + size
            if position > length:
                raise McapError(f"chunk record of {size} bytes overruns its chunk")
            if opcode == Opcode.MESSAGE:
                channel_id, _, log_time, _ = _MESSAGE_FIELDS.unpack_from(data, start)
                topic = topics.get(channel_id)
                if topic is None:
                    topic = topics[channel_id] = self._topic(channel_id, channels, schemas)
                topic.log_ns.append(log_time)
                topic.order.append(self._records)
                topic.data.append(bytes(data[start + _MESSAGE_FIELDS.size : position]))
                self._records += 1
            elif opcode in (Opcode.CHANNEL, Opcode.SCHEMA):
                body = ReadDataStream(BytesIO(data[start:position]))
                if opcode == Opcode.CHANNEL:
                    channel = Channel.read(body)
                    channels[channel.id] = channel
                else:
                    schema = Schema.read(body)
                    schemas[schema.id] = schema

    def _topic(self, channel_id: int, channels: dict[int, Channel], schemas: dict[int, Schema]) -> _Topic:
        """The topic of a channel, created on its first message."""
        channel = channels.get(channel_id)
        if channel is None:
            raise McapError(f"message on channel {channel_id}, which is not defined before it")
        topic = self._topics.get(channel.topic)
        if topic is None:
            schema = schemas.get(channel.schema_id)
            type_name = schema.name if schema is not None else ""
            topic = self._topics[channel.topic] = _Topic(type_name, channel.message_encoding)
        return topic

    def _add(self, record: Message, channels: dict[int, Channel], schemas: dict[int, Schema]) -> None:
        topic = self._topic(record.channel_id, channels, schemas)
        topic.log_ns.append(record.log_time)
        topic.order.append(self._records)
        topic.data.append(record.data)
        self._records += 1

    @property
    def topics(self) -> dict[str, str]:
        """Topic name -> ``pkg/msg/Type`` of every topic with messages."""
        return {name: t.type_name for name, t in self._topics.items()}

    def message_count(self, topic: str) -> int:
        """Number of messages recorded on ``topic``."""
        return len(self._topics[topic].data)

    def raw(self, topic: str) -> tuple[NDArray[np.int64], NDArray[np.int64], list[bytes]]:
        """``(log_ns, order, payloads)`` of ``topic`` in recording order: log times (ns) and
        positions in the recording, shape (n,), and the n CDR payloads, undecoded."""
        info = self._topics[topic]
        if info.encoding != "cdr":
            raise InputError(f"topic {topic!r} has message encoding {info.encoding!r}, not cdr")
        return np.array(info.log_ns, dtype=np.int64), np.array(info.order, dtype=np.int64), info.data

    def resolve(self, name: str) -> str:
        """The recorded topic called ``name``, also matched without its namespace prefix.

        ``finger/wrench`` finds ``/finger/wrench``; ``wrench`` finds it too when unique.
        """
        if name in self._topics:
            return name
        wanted = "/" + name.strip("/")
        matches = [t for t in self._topics if t == wanted or t.endswith(wanted)]
        if len(matches) == 1:
            return matches[0]
        if not matches:
            raise InputError(f"topic {name!r} is not in {str(self.path)!r} (topics: {sorted(self._topics)})")
        raise InputError(f"topic {name!r} is ambiguous in {str(self.path)!r}: {sorted(matches)}")

    def topics_of_type(self, *type_names: str) -> list[str]:
        """Topics whose type is one of ``type_names``, sorted."""
        return sorted(t for t, info in self._topics.items() if info.type_name in type_names)

    def messages(self, topics: Iterable[str]) -> Iterator[RecordedMessage]:
        """Decoded messages of ``topics`` in log-time order (recording order for equal times)."""
        streams = []
        for name in topics:
            topic = self._topics[name]
            if topic.encoding != "cdr":
                raise InputError(f"topic {name!r} has message encoding {topic.encoding!r}, not cdr")
            cls = message_class(topic.type_name)
            streams.extend(
                (t, order, name, cls, data)
                for t, order, data in zip(topic.log_ns, topic.order, topic.data, strict=True)
            )
        streams.sort(key=lambda item: (item[0], item[1]))
        for log_time, order, name, cls, data in streams:
            try:
                msg = deserialize_message(data, cls)
            except Exception as exc:  # noqa: BLE001 - rclpy raises plain exceptions on bad CDR
                raise InputError(
                    f"topic {name!r}: message at {log_time} ns does not decode ({exc})"
                ) from None
            yield RecordedMessage(name, self._topics[name].type_name, log_time, msg, order)

    def scene(self) -> dict[str, Any] | None:
        """The scene stored by our recorder (``SceneConfig.to_dict()`` form), if any."""
        text = self.metadata.get(METADATA_NAME, {}).get(SCENE_KEY, "")
        if not text:
            return None
        try:
            scene = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise InputError(f"{str(self.path)!r}: the stored scene is not valid YAML ({exc})") from None
        return scene if isinstance(scene, dict) else None

    @property
    def software_version(self) -> str | None:
        """Version of viscoadh_ros that wrote the recording, if ours."""
        return self.metadata.get(METADATA_NAME, {}).get(VERSION_KEY)
