"""Background MCAP recorder (profile ``ros2``) that never blocks the live path.

Files follow what rosbag2 (Jazzy) writes, so ``ros2 bag``, the ``mcap`` reader and
``rosbags`` accept them: one ``pkg/msg/Type`` schema per type (``ros2msg`` text with all
dependencies), ``cdr`` payloads from :func:`rclpy.serialization.serialize_message`, channel
metadata ``offered_qos_profiles``. Every file also carries a metadata record
:data:`METADATA_NAME` with the scene (``SceneConfig.to_dict()`` as YAML) and the software
version, so one file alone is enough to replay the run.

Crash safety: chunks are bounded (``chunk_size`` bytes) and each finished chunk is handed
to the operating system at once, so a process killed with SIGKILL leaves every message up
to the last finished chunk readable; :meth:`McapRecorder.close` finishes the file (summary
and footer). Rotation starts a new file, ``<stem>_<index>.mcap``, after ``max_bytes`` or
``max_duration``. A ``path`` without the ``.mcap`` suffix is a rosbag2-style folder that
gets a ``metadata.yaml`` on close.
"""

from __future__ import annotations

import datetime
import threading
import time
from collections import Counter, deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import yaml
from mcap.writer import CompressionType, Writer
from numpy.typing import NDArray
from rclpy.serialization import serialize_message

from viscoadh_ros import __version__
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

#: Bytes a message adds to a file besides its payload: the Message record's header (opcode,
#: length, channel, sequence, two times: 31 B) and its MessageIndex entry (16 B).
_MESSAGE_OVERHEAD = 31 + 16

# rmw's RMW_DURATION_INFINITE as rosbag2 Jazzy writes it ({sec, nsec} of INT64_MAX ns).
_INFINITE = {"sec": 9223372036, "nsec": 854775807}


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
    topic: str
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
        add = file.writer.add_message
        for t, k, ns in zip(
            which[order].tolist(), index[order].tolist(), log_ns[order].tolist(), strict=True
        ):
            add(channels[t], log_time=ns, publish_time=ns, data=payloads[t][k], sequence=k)
    finally:
        file.finish()


class _File:
    """One open MCAP file with its channels; the writer thread is its only user."""

    def __init__(self, path: Path, *, chunk_size: int, metadata: dict[str, str]) -> None:
        self.path = path
        self.stream: IO[bytes] = open(path, "wb")  # noqa: SIM115 - closed in finish()
        self.writer = Writer(self.stream, chunk_size=chunk_size, compression=CompressionType.NONE)
        self.writer.start(profile="ros2", library=f"viscoadh_ros {__version__}")
        self.writer.add_metadata(METADATA_NAME, metadata)
        self.stream.flush()
        self.schemas: dict[str, int] = {}
        self.channels: dict[str, int] = {}
        self.topic_types: dict[str, str] = {}
        self.counts: Counter[str] = Counter()
        self.first_ns: int | None = None
        self.last_ns = 0
        self.position = self.stream.tell()
        # Bytes of messages in the writer's open chunk, not yet in the stream.
        self.pending = 0

    def channel(self, topic: str, type_name: str, qos: TopicQos) -> int:
        """The channel id of ``topic``, registered (with its schema) on first use."""
        channel = self.channels.get(topic)
        if channel is None:
            schema = self.schemas.get(type_name)
            if schema is None:
                schema = self.writer.register_schema(type_name, "ros2msg", schema_text(type_name).encode())
                self.schemas[type_name] = schema
            channel = self.writer.register_channel(
                topic, "cdr", schema, {"offered_qos_profiles": qos.to_yaml()}
            )
            self.channels[topic] = channel
            self.topic_types[topic] = type_name
        return channel

    def write(self, item: _Item, qos: TopicQos) -> None:
        channel = self.channel(item.topic, item.type_name, qos)
        data = item.data if isinstance(item.data, bytes) else serialize_message(item.data)
        self.writer.add_message(
            channel,
            log_time=item.stamp_ns,
            publish_time=item.stamp_ns,
            data=data,
            sequence=self.counts[item.topic],
        )
        self.counts[item.topic] += 1
        self.first_ns = item.stamp_ns if self.first_ns is None else min(self.first_ns, item.stamp_ns)
        self.last_ns = max(self.last_ns, item.stamp_ns)
        # The writer just closed a chunk if the logical position moved: hand it to the OS now
        # so a SIGKILL cannot take it with the userspace buffer.
        position = self.stream.tell()
        if position != self.position:
            self.stream.flush()
            self.position = position
            self.pending = 0
        else:
            self.pending += len(data) + _MESSAGE_OVERHEAD

    @property
    def size(self) -> int:
        """Bytes the file holds so far, the open chunk included (it is still in the writer)."""
        return self.stream.tell() + self.pending

    def finish(self, log_record: dict[str, str] | None = None) -> None:
        if log_record is not None:
            self.writer.add_metadata(LOG_RECORD_NAME, log_record)
        self.writer.finish()
        self.stream.close()


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
        scene: ``SceneConfig.to_dict()`` of the run (stored as YAML in every file).
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
        if not max_duration >= 0.0 or max_duration == float("inf"):
            raise ConfigError(f"log.max_duration must be finite and >= 0 s (got {max_duration!r})")
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
            "custom_data": {SCENE_KEY: self._metadata[SCENE_KEY], VERSION_KEY: __version__},
            "ros_distro": "jazzy",
        }
        text = yaml.safe_dump({"rosbag2_bagfile_information": info}, sort_keys=False)
        (self._folder / "metadata.yaml").write_text(text, encoding="utf-8")
