"""Background MCAP recorder (profile ``ros2``) that never blocks the live path.

Files follow what rosbag2 (Jazzy) writes, so ``ros2 bag``, the ``mcap`` reader and
``rosbags`` accept them: one ``pkg/msg/Type`` schema per type (``ros2msg`` text with all
dependencies), ``cdr`` payloads from :func:`rclpy.serialization.serialize_message`, channel
metadata ``offered_qos_profiles``. Every file also carries a metadata record
:data:`METADATA_NAME` with the scene (``SceneConfig.to_dict()`` as YAML) and the software
version, so one file alone is enough to replay the run: the scene in force when the file was
started (:meth:`McapRecorder.set_scene` after a runtime parameter change; the change itself is
a PARAMETERS event among the messages).

Crash safety: chunks are bounded (``chunk_size`` bytes) and each finished chunk is handed
to the operating system at once, so a process killed with SIGKILL leaves every message up
to the last finished chunk readable; :meth:`McapRecorder.close` finishes the file (summary
and footer). Rotation starts a new file, ``<stem>_<index>.mcap``, after ``max_bytes`` or
``max_duration``. A ``path`` without the ``.mcap`` suffix is a rosbag2-style folder that
gets a ``metadata.yaml`` on close.
"""

from __future__ import annotations

import datetime
import struct
import threading
import time
import zlib
from collections import Counter, deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import yaml
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)
from numpy.typing import NDArray

from viscoadh_ros import __version__
from viscoadh_ros.core.config import DURATION_MAX_S
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.io.ros_schemas import schema_text, type_name_of

#: Name of the MCAP metadata record holding the scene and the software version.
METADATA_NAME = "viscoadh"
#: Keys of that record.
SCENE_KEY = "scene_yaml"
VERSION_KEY = "software_version"
#: Name of the metadata record a recorder writes into each file it finishes: messages it
#: dropped (full queue) since it started, in total (:data:`DROPPED_KEY`) and per topic (YAML
#: mapping, :data:`DROPPED_TOPICS_KEY`), so a reader knows whether the log is complete (a
#: replay that counts commands must know). A file cut by SIGKILL has no such record.
LOG_RECORD_NAME = "viscoadh_log"
DROPPED_KEY = "messages_dropped"
DROPPED_TOPICS_KEY = "dropped_by_topic"

_MAGIC = b"\x89MCAP0\r\n"

# rmw's RMW_DURATION_INFINITE as rosbag2 Jazzy writes it ({sec, nsec} of INT64_MAX ns).
_INFINITE = {"sec": 9223372036, "nsec": 854775807}


def serialize_message(msg: Any) -> bytes:
    """``rclpy.serialization.serialize_message``, imported on first use (then this module's
    name is bound to it, so later calls go straight to rclpy): the readers and the columnar
    writer that import this module for its records and constants need no rclpy (~50-150 ms
    of a fresh process)."""
    from rclpy.serialization import serialize_message as serialize

    globals()["serialize_message"] = serialize
    return serialize(msg)


@dataclass(frozen=True)
class TopicQos:
    """Offered QoS of a recorded topic, written as rosbag2 Jazzy's ``offered_qos_profiles``."""

    depth: int = 10
    reliability: str = "reliable"
    durability: str = "volatile"

    def to_yaml(self) -> str:
        """The one-element profile list in rosbag2's (bag version 9) YAML form."""
        profile = {
            "history": "keep_last",
            "depth": self.depth,
            "reliability": self.reliability,
            "durability": self.durability,
            "deadline": dict(_INFINITE),
            "lifespan": dict(_INFINITE),
            "liveliness": "automatic",
            "liveliness_lease_duration": dict(_INFINITE),
            "avoid_ros_namespace_conventions": False,
        }
        return yaml.safe_dump([profile], sort_keys=False)


@dataclass
class _Item:
    topic: str | None  # None: not a message, the metadata (`data`) of the files started from here
    type_name: str
    # CDR bytes, or the message itself when the caller handed it over (serialised by the writer).
    data: Any
    stamp_ns: int


#: How long the writer thread sleeps when nothing is queued, s. It polls rather than waits on
#: a condition so that record() is one bounded append: notifying a condition (queue.Queue) cost
#: the live thread more than the append (~3 us per message at ~12k messages/s).
WRITER_POLL_S = 0.002


def plain(value: Any) -> Any:
    """Mappings and tuples as plain dicts and lists, so ``yaml.safe_dump`` takes them."""
    if isinstance(value, Mapping):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def _metadata(scene: Mapping[str, Any] | None) -> dict[str, str]:
    """The :data:`METADATA_NAME` record: the scene as YAML and the software version."""
    return {
        SCENE_KEY: yaml.safe_dump(plain(scene), sort_keys=False) if scene is not None else "",
        VERSION_KEY: __version__,
    }


@dataclass(frozen=True)
class TopicData:
    """Every message of one topic for :func:`write_mcap`: ``log_ns`` (n,) int ns, ``payloads``
    the n CDR messages of ``type_name``."""

    topic: str
    type_name: str
    log_ns: NDArray[np.int64]
    payloads: Sequence[bytes]


def write_mcap(
    path: str | Path,
    topics: Sequence[TopicData],
    *,
    scene: Mapping[str, Any] | None = None,
    chunk_size: int = 1024 * 1024,
) -> None:
    """Write a finished MCAP file (same format as :class:`McapRecorder`) of whole topics at once,
    on the calling thread: for offline output, where nothing may be dropped and no live path
    waits. Messages go in log-time order; at equal times the k-th messages of the topics
    before the (k+1)-th, topics in the given order (so a state and its wrench stay together).
    """
    for data in topics:
        if len(data.log_ns) != len(data.payloads):
            raise ValueError(f"{data.topic}: {len(data.log_ns)} log times for {len(data.payloads)} messages")
    which = np.concatenate([np.full(len(d.payloads), t, dtype=np.int64) for t, d in enumerate(topics)])
    index = np.concatenate([np.arange(len(d.payloads), dtype=np.int64) for d in topics])
    log_ns = np.concatenate([np.asarray(d.log_ns, dtype=np.int64) for d in topics])
    order = np.lexsort((which, index, log_ns))
    file = _File(Path(path), chunk_size=chunk_size, metadata=_metadata(scene))
    try:
        channels = [file.channel(d.topic, d.type_name, TopicQos()) for d in topics]
        payloads = [d.payloads for d in topics]
        add = file.add
        for t, k, ns in zip(
            which[order].tolist(), index[order].tolist(), log_ns[order].tolist(), strict=True
        ):
            add(channels[t], ns, bytes(payloads[t][k]), k)
    finally:
        file.finish()


class _File:
    """One open MCAP file with its channels; the writer thread is its only user.

    Messages are packed into the open chunk by hand (one ``struct`` call and a copy of the
    payload each, ~1-2 us) rather than through ``mcap``'s ``Writer.add_message`` (~6 us of
    Python per message, which the node's writer thread spent competing with the live thread
    for the GIL); every other record goes through ``mcap``'s record classes. The layout is the
    one ``mcap``'s writer makes: header, the ``viscoadh`` metadata, schemas and channels as they
    appear (before the chunk holding their first message), uncompressed chunks each followed by
    its message indexes, then data end, a summary (schemas, channels, statistics, chunk and
    metadata indexes, summary offsets), footer and magic.
    """

    _HEAD = struct.Struct("<BQHIQQ")  # Message record up to its payload (opcode .. publish time)

    def __init__(self, path: Path, *, chunk_size: int, metadata: dict[str, str]) -> None:
        self.path = path
        self.stream: IO[bytes] = open(path, "wb")  # noqa: SIM115 - closed in finish()
        self._chunk_size = chunk_size
        self._builder = RecordBuilder()
        self._crc = 0
        self._offset = 0
        self._emit(_MAGIC)
        Header(profile="ros2", library=f"viscoadh_ros {__version__}").write(self._builder)
        self._emit(self._builder.end())
        self._metadata_indexes: list[MetadataIndex] = []
        self._add_metadata(METADATA_NAME, metadata)
        self.stream.flush()
        self._schemas: dict[str, Schema] = {}
        self._channel_records: list[Channel] = []
        self.channels: dict[str, int] = {}
        self.topic_types: dict[str, str] = {}
        self.counts: Counter[str] = Counter()
        self._channel_counts: Counter[int] = Counter()
        self.first_ns: int | None = None
        self.last_ns = 0
        self._chunk_indexes: list[ChunkIndex] = []
        # The open chunk: its records, and per channel the (log time, offset) of its messages.
        self._chunk = bytearray()
        self._index: dict[int, list[int]] = {}
        self._chunk_start_ns = 0
        self._chunk_end_ns = 0

    def _emit(self, data: bytes | bytearray) -> None:
        self.stream.write(data)
        self._crc = zlib.crc32(data, self._crc)
        self._offset += len(data)

    def _add_metadata(self, name: str, metadata: dict[str, str]) -> None:
        start = self._offset
        Metadata(name=name, metadata=metadata).write(self._builder)
        self._emit(self._builder.end())
        self._metadata_indexes.append(MetadataIndex(offset=start, length=self._offset - start, name=name))

    def channel(self, topic: str, type_name: str, qos: TopicQos) -> int:
        """The channel id of ``topic``, registered (with its schema) on first use."""
        channel = self.channels.get(topic)
        if channel is None:
            schema = self._schemas.get(type_name)
            if schema is None:
                schema = Schema(
                    id=len(self._schemas) + 1,
                    name=type_name,
                    encoding="ros2msg",
                    data=schema_text(type_name).encode(),
                )
                self._schemas[type_name] = schema
                schema.write(self._builder)
            channel = len(self._channel_records) + 1
            record = Channel(
                id=channel,
                topic=topic,
                message_encoding="cdr",
                schema_id=schema.id,
                metadata={"offered_qos_profiles": qos.to_yaml()},
            )
            record.write(self._builder)
            self._emit(self._builder.end())
            self._channel_records.append(record)
            self.channels[topic] = channel
            self.topic_types[topic] = type_name
        return channel

    def add(self, channel: int, stamp_ns: int, data: bytes, sequence: int) -> None:
        """Append one message to the open chunk; finish the chunk once it holds chunk_size."""
        chunk = self._chunk
        if not chunk:
            self._chunk_start_ns = self._chunk_end_ns = stamp_ns
        elif stamp_ns < self._chunk_start_ns:
            self._chunk_start_ns = stamp_ns
        elif stamp_ns > self._chunk_end_ns:
            self._chunk_end_ns = stamp_ns
        entries = self._index.get(channel)
        if entries is None:
            entries = self._index[channel] = []
        entries += (stamp_ns, len(chunk))
        chunk += self._HEAD.pack(Opcode.MESSAGE, 22 + len(data), channel, sequence, stamp_ns, stamp_ns)
        chunk += data
        self._channel_counts[channel] += 1
        if len(chunk) >= self._chunk_size:
            self._finish_chunk()

    def _finish_chunk(self) -> None:
        """Write the open chunk and its message indexes, and hand them to the operating system
        at once, so a SIGKILL cannot take them with the userspace buffer."""
        data = bytes(self._chunk)
        if not data:
            return
        chunk = Chunk(
            compression="",
            data=data,
            message_start_time=self._chunk_start_ns,
            message_end_time=self._chunk_end_ns,
            uncompressed_crc=zlib.crc32(data),
            uncompressed_size=len(data),
        )
        chunk_start = self._offset
        chunk.write(self._builder)
        self._emit(self._builder.end())
        index_start = self._offset
        offsets: dict[int, int] = {}
        parts = []
        position = index_start
        for channel, entries in self._index.items():
            body = np.asarray(entries, dtype="<u8").tobytes()
            offsets[channel] = position
            record = struct.pack("<BQHI", Opcode.MESSAGE_INDEX, 2 + 4 + len(body), channel, len(body)) + body
            parts.append(record)
            position += len(record)
        self._emit(b"".join(parts))
        self._chunk_indexes.append(
            ChunkIndex(
                message_start_time=chunk.message_start_time,
                message_end_time=chunk.message_end_time,
                chunk_start_offset=chunk_start,
                chunk_length=index_start - chunk_start,
                message_index_offsets=offsets,
                message_index_length=self._offset - index_start,
                compression="",
                compressed_size=len(data),
                uncompressed_size=len(data),
            )
        )
        self._chunk = bytearray()
        self._index = {}
        self.stream.flush()

    def write(self, item: _Item, qos: TopicQos) -> None:
        channel = self.channel(item.topic, item.type_name, qos)
        data = item.data if isinstance(item.data, bytes) else serialize_message(item.data)
        topic = item.topic
        self.add(channel, item.stamp_ns, data, self.counts[topic])
        self.counts[topic] += 1
        stamp_ns = item.stamp_ns
        if self.first_ns is None or stamp_ns < self.first_ns:
            self.first_ns = stamp_ns
        if stamp_ns > self.last_ns:
            self.last_ns = stamp_ns

    @property
    def size(self) -> int:
        """Bytes the file holds so far, the open chunk and its message indexes included (an
        index entry is 16 B per message, each index record 15 B besides)."""
        entries = sum(len(e) for e in self._index.values())  # two numbers per message
        return self._offset + len(self._chunk) + 8 * entries + 15 * len(self._index)

    def finish(self, log_record: dict[str, str] | None = None) -> None:
        self._finish_chunk()
        if log_record is not None:
            self._add_metadata(LOG_RECORD_NAME, log_record)
        builder = self._builder
        DataEnd(data_section_crc=self._crc).write(builder)
        self._emit(builder.end())
        summary_start = self._offset
        counts = self._channel_counts
        times = [(c.message_start_time, c.message_end_time) for c in self._chunk_indexes]
        statistics = Statistics(
            message_count=sum(counts.values()),
            schema_count=len(self._schemas),
            channel_count=len(self._channel_records),
            attachment_count=0,
            metadata_count=len(self._metadata_indexes),
            chunk_count=len(self._chunk_indexes),
            message_start_time=min((t[0] for t in times), default=0),
            message_end_time=max((t[1] for t in times), default=0),
            channel_message_counts={c.id: counts[c.id] for c in self._channel_records},
        )
        sections = (
            (Opcode.SCHEMA, list(self._schemas.values())),
            (Opcode.CHANNEL, self._channel_records),
            (Opcode.STATISTICS, [statistics]),
            (Opcode.CHUNK_INDEX, self._chunk_indexes),
            (Opcode.METADATA_INDEX, self._metadata_indexes),
        )
        self.stream.write(summary_and_footer(builder, summary_start, sections))
        self.stream.close()


def summary_and_footer(
    builder: RecordBuilder, summary_start: int, sections: Sequence[tuple[int, list]]
) -> bytes:
    """The bytes that end an MCAP file whose summary section starts at file offset
    ``summary_start``: each non-empty ``(opcode, records)`` group of ``sections``, the summary
    offsets of the groups, the footer with the summary's CRC, and the closing magic. ``builder``
    must be empty; both writers (`_File` and `mcap_bulk.write_columns`) end their files here."""
    groups = []
    for opcode, records in sections:
        if not records:
            continue
        group_start = summary_start + builder.count
        for record in records:
            record.write(builder)
        groups.append(
            SummaryOffset(
                group_opcode=opcode,
                group_start=group_start,
                group_length=summary_start + builder.count - group_start,
            )
        )
    offset_start = summary_start + builder.count
    for group in groups:
        group.write(builder)
    summary = builder.end()
    footer_head = struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, offset_start)
    crc = zlib.crc32(footer_head, zlib.crc32(summary))
    Footer(summary_start=summary_start, summary_offset_start=offset_start, summary_crc=crc).write(builder)
    return summary + builder.end() + _MAGIC


class McapRecorder:
    """Record ROS 2 messages to MCAP from a background thread.

    ``record()`` serialises the message (so later changes to the object do not leak into the
    log), or with ``handed_over=True`` queues the object itself for the writer thread to
    serialise (off the caller's thread), and puts it on a bounded queue; when the queue is
    full the message is dropped and :attr:`dropped` counts it. The writer thread owns the
    files. Record from one thread at a time, and not while :meth:`close` runs (the queue is a
    plain deque the writer polls).

    Args:
        path: ``*.mcap`` file, or a folder (rosbag2 layout) for any other name.
        scene: ``SceneConfig.to_dict()`` of the run (stored as YAML in every file; :meth:`set_scene`
            changes it for the files started later).
        chunk_size: Target chunk size, bytes (> 0): the most a SIGKILL can lose.
        max_bytes: Start a new file after this many bytes (0 = never).
        max_duration: Start a new file after this many seconds of log time (0 = never).
        queue_size: Messages that may wait for the writer (> 0).
        qos: Offered QoS written per topic (default: reliable, volatile, depth 10).
    """

    def __init__(
        self,
        path: str | Path,
        *,
        scene: Mapping[str, Any] | None = None,
        chunk_size: int = 256 * 1024,
        max_bytes: int = 0,
        max_duration: float = 0.0,
        queue_size: int = 10000,
        qos: Mapping[str, TopicQos] | None = None,
    ) -> None:
        for name, value in (("chunk_size", chunk_size), ("queue_size", queue_size)):
            if not isinstance(value, int) or value <= 0:
                raise ConfigError(f"log.{name} must be an integer > 0 (got {value!r})")
        if not isinstance(max_bytes, int) or max_bytes < 0:
            raise ConfigError(f"log.max_bytes must be an integer >= 0 (got {max_bytes!r})")
        if not 0.0 <= max_duration <= DURATION_MAX_S:
            raise ConfigError(f"log.max_duration must be in [0, {DURATION_MAX_S:g}] s (got {max_duration!r})")
        path = (
            Path(path) if str(path) else Path(datetime.datetime.now().strftime("viscoadh_%Y_%m_%d-%H_%M_%S"))
        )
        self._folder = None if path.suffix == ".mcap" else path
        self._stem = self._folder / self._folder.name if self._folder is not None else path.with_suffix("")
        self._rotating = max_bytes > 0 or max_duration > 0.0
        self._chunk_size = chunk_size
        self._max_bytes = max_bytes
        self._max_duration_ns = int(max_duration * 1e9)
        self._qos = dict(qos or {})
        self._metadata = _metadata(scene)
        self._start_metadata = self._metadata  # metadata.yaml's: the scene the log starts with
        self._queue_size = queue_size
        self._pending: deque[_Item] = deque()
        self._dropped = 0
        self._dropped_by_topic: Counter[str] = Counter()
        self._written = 0
        self._closed = False
        self._error: BaseException | None = None
        self._finished: list[_File] = []
        # The first file is opened here, so an unwritable path fails at start, not silently
        # in the writer thread.
        try:
            self._stem.parent.mkdir(parents=True, exist_ok=True)
            self._file: _File | None = _File(
                self._next_path(), chunk_size=chunk_size, metadata=self._metadata
            )
        except OSError as exc:
            raise ConfigError(f"log.path {str(path)!r} cannot be written ({exc.strerror or exc})") from None
        self._types: dict[type, str] = {}
        self._thread = threading.Thread(target=self._run, name="viscoadh-mcap", daemon=True)
        self._thread.start()

    @property
    def dropped(self) -> int:
        """Messages dropped because the queue was full (or the writer failed)."""
        return self._dropped

    @property
    def written(self) -> int:
        """Messages written to a file so far."""
        return self._written

    @property
    def paths(self) -> list[Path]:
        """Files written so far, in order (the open one last)."""
        files = list(self._finished) + ([self._file] if self._file is not None else [])
        return [f.path for f in files]

    @property
    def error(self) -> BaseException | None:
        """The exception that stopped the writer thread, if any (recording then drops)."""
        return self._error

    def record(self, topic: str, msg: Any, stamp_ns: int, *, handed_over: bool = False) -> bool:
        """Queue ``msg`` for ``topic`` with log time ``stamp_ns`` (node clock, ns).

        ``handed_over=True``: the caller gives ``msg`` away and never changes it again (e.g. a
        message built for one publish); it is serialised on the writer thread, which saves the
        caller ~5-15 us per message. Otherwise it is serialised here, so later changes to the
        object do not leak into the log.

        Never blocks. Returns False (and counts a drop) when the queue is full, the writer
        failed or the recorder is closed.
        """
        cls = type(msg)
        type_name = self._types.get(cls)
        if type_name is None:
            type_name = self._types[cls] = type_name_of(cls)
        return self._put(
            _Item(topic, type_name, msg if handed_over else serialize_message(msg), int(stamp_ns))
        )

    def record_cdr(self, topic: str, type_name: str, payload: bytes, stamp_ns: int) -> bool:
        """:meth:`record` for a message already serialised: ``payload`` is the CDR of a
        ``type_name`` (``pkg/msg/Type``) message. Never blocks; False when dropped."""
        return self._put(_Item(topic, type_name, payload, int(stamp_ns)))

    def set_scene(self, scene: Mapping[str, Any] | None) -> None:
        """The scene in force from now on (a runtime parameter change): the files started after
        the messages recorded so far store it, so each file names the scene in force when it
        started (events in it carry later changes). Queued in order with the messages, never
        dropped (a full queue would otherwise leave the later files naming a stale scene)."""
        if not self._closed and self._error is None:
            self._pending.append(_Item(None, "", _metadata(scene), 0))

    def _put(self, item: _Item) -> bool:
        if self._closed or self._error is not None or len(self._pending) >= self._queue_size:
            self._dropped += 1
            self._dropped_by_topic[item.topic] += 1
            return False
        self._pending.append(item)
        return True

    def close(self, timeout: float = 10.0) -> None:
        """Write what is queued, finish the file(s) and stop the thread. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._thread.join(timeout)
        # Left when the writer failed or timed out: count them rather than lose them silently.
        self._dropped += len(self._pending)
        self._pending.clear()

    def __enter__(self) -> McapRecorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _next_path(self) -> Path:
        if not self._rotating and self._folder is None:
            return self._stem.with_suffix(".mcap")
        return self._stem.parent / f"{self._stem.name}_{len(self._finished)}.mcap"

    def _rotate_if_due(self, stamp_ns: int) -> None:
        current = self._file
        if current is None or not self._rotating:
            return
        too_big = self._max_bytes and current.size >= self._max_bytes
        too_long = (
            self._max_duration_ns
            and current.first_ns is not None
            and stamp_ns - current.first_ns >= self._max_duration_ns
        )
        if too_big or too_long:
            current.finish(self._log_record())
            self._finished.append(current)
            self._file = None

    def _run(self) -> None:
        try:
            pending = self._pending
            while True:
                try:
                    item = pending.popleft()
                except IndexError:
                    # record() refuses once closed, so closed and empty means all is written.
                    if self._closed and not pending:
                        break
                    time.sleep(WRITER_POLL_S)
                    continue
                if item.topic is None:
                    self._metadata = item.data
                    continue
                self._rotate_if_due(item.stamp_ns)
                if self._file is None:
                    self._file = _File(
                        self._next_path(), chunk_size=self._chunk_size, metadata=self._metadata
                    )
                self._file.write(item, self._qos.get(item.topic, TopicQos()))
                self._written += 1
            if self._file is not None:
                self._file.finish(self._log_record())
                self._finished.append(self._file)
                self._file = None
            if self._folder is not None:
                self._write_bag_metadata()
        except BaseException as exc:  # noqa: BLE001 - reported via .error, never into the node
            self._error = exc

    def _log_record(self) -> dict[str, str]:
        """The :data:`LOG_RECORD_NAME` record: drops so far (the writer thread reads the
        counter the recording thread updates; a copy that races an update is retried)."""
        while True:
            try:
                by_topic = dict(self._dropped_by_topic)
                break
            except RuntimeError:  # changed size during the copy
                continue
        return {DROPPED_KEY: str(self._dropped), DROPPED_TOPICS_KEY: yaml.safe_dump(by_topic)}

    def _write_bag_metadata(self) -> None:
        """rosbag2's ``metadata.yaml`` (version 9) so ``ros2 bag`` and rosbags open the folder."""
        topics: dict[str, tuple[str, int]] = {}
        files = []
        for f in self._finished:
            for topic, count in f.counts.items():
                type_name = f.topic_types[topic]
                old = topics.get(topic, (type_name, 0))
                topics[topic] = (type_name, old[1] + count)
            first = f.first_ns or 0
            files.append(
                {
                    "path": f.path.name,
                    "starting_time": {"nanoseconds_since_epoch": first},
                    "duration": {"nanoseconds": f.last_ns - first},
                    "message_count": sum(f.counts.values()),
                }
            )
        starts = [f.first_ns for f in self._finished if f.first_ns is not None]
        start = min(starts) if starts else 0
        end = max((f.last_ns for f in self._finished), default=0)
        info = {
            "version": 9,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": max(end - start, 0)},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": sum(count for _, count in topics.values()),
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": topic,
                        "type": type_name,
                        "serialization_format": "cdr",
                        "offered_qos_profiles": self._qos.get(topic, TopicQos()).to_yaml(),
                        "type_description_hash": "",
                    },
                    "message_count": count,
                }
                for topic, (type_name, count) in topics.items()
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [f.path.name for f in self._finished],
            "files": files,
            "custom_data": {SCENE_KEY: self._start_metadata[SCENE_KEY], VERSION_KEY: __version__},
            "ros_distro": "jazzy",
        }
        text = yaml.safe_dump({"rosbag2_bagfile_information": info}, sort_keys=False)
        (self._folder / "metadata.yaml").write_text(text, encoding="utf-8")
