"""Read ROS 2 recordings: one ``.mcap`` file or a rosbag2 folder (``metadata.yaml`` + ``*.mcap``).

Messages are deserialised with :func:`rclpy.serialization.deserialize_message` into the
installed message classes, or read in bulk as raw CDR (:meth:`Bag.raw`, :meth:`Bag.rows`) for
the fixed-layout decoders of :mod:`viscoadh_ros.io.cdr`. The file is walked here, record by
record with one ``struct`` call each (the summary is skipped: the ``mcap`` package's reader
parses every index entry as an object, which cost more than the messages). A chunk's message
records are located from the message index records that follow it, read as numpy arrays and
accepted only when they tile the chunk exactly (every record a message, each starting where
the one before ends); otherwise (no or partial indexes, a channel or schema record inside the
chunk, a damaged index) the chunk is walked record by record. The messages are then read as
columns (channel, log time, payload offset and size as numpy arrays; payloads of one length
as one (n, L) array). A file that was not finished (a recorder killed mid-run) has no footer: it is
read up to the last complete chunk; :class:`Bag` refuses it with a clear :class:`InputError`
unless ``recover=True``.
"""

from __future__ import annotations

import re
import struct
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from io import BytesIO
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Metadata, Schema
from mcap.stream_reader import get_chunk_data_stream
from numpy.typing import NDArray

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
class _Part:
    """Messages of one topic from one chunk (or one top-level message record): payload ``k``
    is ``buffer[starts[k] : starts[k] + sizes[k]]``."""

    buffer: NDArray[np.uint8]
    starts: NDArray[np.int64]
    sizes: NDArray[np.int64]
    log_ns: NDArray[np.int64]
    order: NDArray[np.int64]


@dataclass
class _Topic:
    type_name: str
    encoding: str
    parts: list[_Part] = field(default_factory=list)

    @property
    def count(self) -> int:
        return sum(p.starts.size for p in self.parts)

    def column(self, name: str) -> NDArray[np.int64]:
        values = [getattr(p, name) for p in self.parts]
        return np.concatenate(values) if values else np.empty(0, dtype=np.int64)

    def payloads(self) -> list[bytes]:
        return [
            p.buffer[s : s + z].tobytes()
            for p in self.parts
            for s, z in zip(p.starts.tolist(), p.sizes.tolist(), strict=True)
        ]


#: libyaml's safe loader when PyYAML was built with it (the same documents, ~10x faster than
#: the pure-Python one on a scene), else the pure-Python one.
_SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

_RECORD_TYPES = {Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel, Opcode.METADATA: Metadata}

#: Record header (opcode u8, length u64) and Message record fields before the payload
#: (channel id u16, sequence u32, log time u64, publish time u64), MCAP's little-endian layout.
_RECORD_HEADER = struct.Struct("<BQ")
_MESSAGE_FIELDS = struct.Struct("<HIQQ")
_CHUNK_FIELDS = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
_MAGIC = b"\x89MCAP0\r\n"


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
        # A folder whose recorder was killed has no metadata.yaml yet, or the files of a rotated
        # `.mcap` log put in one folder: take its files in the order of their numbers.
        files = _numbered_files(path, list(path.glob("*.mcap")))
    if not files:
        raise InputError(f"bag folder {str(path)!r} holds no .mcap file")
    return files


_NUMBERED = re.compile(r"(.+)_(\d+)\.mcap")


def _numbered_files(folder: Path, files: list[Path]) -> list[Path]:
    """The files of a folder without ``metadata.yaml`` in log order: one log's
    ``<stem>_<i>.mcap`` files (a rotated log, a killed rosbag2 recorder's folder), by number,
    the numbers consecutive. InputError naming the files otherwise: a folder holding files of
    several logs, a file not numbered as the others, or a number missing (an outside tester's
    folders replayed with exit 0 and wrong forces: a rotated log without file 7, with a copy of
    file 1, and two sessions' logs together)."""
    if len(files) < 2:
        return files
    stems: dict[str, list[tuple[int, Path]]] = {}
    loose = []
    for file in files:
        match = _NUMBERED.fullmatch(file.name)
        if match is None:
            loose.append(file.name)
        else:
            stems.setdefault(match.group(1), []).append((int(match.group(2)), file))
    where = f"bag folder {str(folder)!r} (no metadata.yaml)"
    advice = "replay a folder that holds the files of one log, all of them"
    if loose:
        raise InputError(
            f"{where}: {', '.join(sorted(loose))} {'is' if len(loose) == 1 else 'are'} not numbered as "
            "the files of one rotated log (<stem>_0.mcap, <stem>_1.mcap, ...), so their place in the "
            f"log is unknown (a copy, or another recording?); {advice}"
        )
    if len(stems) > 1:
        logs = ", ".join(f"{stem}_*.mcap ({len(numbered)} files)" for stem, numbered in sorted(stems.items()))
        raise InputError(f"{where} holds the files of several logs: {logs}; {advice}")
    ((stem, numbered),) = stems.items()
    numbered.sort(key=lambda item: item[0])
    numbers = [n for n, _ in numbered]
    repeated = sorted({n for n in numbers if numbers.count(n) > 1})
    if repeated:
        names = [f.name for n, f in numbered if n == repeated[0]]
        raise InputError(f"{where}: {', '.join(names)} have the same number in the log; {advice}")
    missing = sorted(set(range(numbers[0], numbers[-1] + 1)) - set(numbers))
    if missing:
        names = ", ".join(f"{stem}_{n}.mcap" for n in missing[:5]) + (" ..." if len(missing) > 5 else "")
        raise InputError(
            f"{where}: the rotated log {stem}_*.mcap lacks {names} (it holds {stem}_{numbers[0]}.mcap "
            f"to {stem}_{numbers[-1]}.mcap): the commands in the missing file(s) would be left out "
            f"and the contact's history broken; {advice}"
        )
    return [f for _, f in numbered]


def _unaligned(buffer: NDArray[np.uint8], dtype: str) -> NDArray:
    """``buffer`` read as ``dtype`` numbers starting at every byte (a view, no copy): element k
    is the number whose first byte is ``buffer[k]``."""
    itemsize = np.dtype(dtype).itemsize
    return np.ndarray((max(buffer.size - itemsize + 1, 0),), dtype, buffer, 0, (1,))


def _message_indexes(data: bytes, position: int) -> list[tuple[int, int]]:
    """The (start, end) of the bodies of the complete message index records from
    ``position`` on (those that follow a chunk)."""
    found = []
    length = len(data)
    while position + _RECORD_HEADER.size <= length:
        opcode, size = _RECORD_HEADER.unpack_from(data, position)
        start = position + _RECORD_HEADER.size
        if opcode != Opcode.MESSAGE_INDEX or start + size > length:
            break
        found.append((start, start + size))
        position = start + size
    return found


def _indexed_starts(
    data: bytes, buffer: NDArray[np.uint8], indexes: list[tuple[int, int]]
) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
    """``(starts, lengths)``: the offsets of a chunk's message records (``buffer``: its
    records) from its message indexes (bodies at ``indexes`` in ``data``), in record order,
    and each record's length field; None unless those records tile the chunk exactly: the
    first at 0, each next one where the one before ends, the last ending at the chunk's end,
    every one a message record (then the walk finds the same)."""
    offsets = []
    for start, end in indexes:
        if end - start < 6:
            return None
        (entries,) = struct.unpack_from("<I", data, start + 2)
        if entries % 16 or 6 + entries != end - start:
            return None
        offsets.append(np.frombuffer(data, "<u8", entries // 8, start + 6)[1::2])
    if not offsets:
        return None
    found = np.concatenate(offsets)
    if found.size == 0 or np.any(found > buffer.size):
        return None
    starts = np.sort(found.astype(np.int64), kind="stable")  # runs per channel: merged fast
    if starts[0] != 0 or starts[-1] + _RECORD_HEADER.size + _MESSAGE_FIELDS.size > buffer.size:
        return None
    if np.any(buffer[starts] != Opcode.MESSAGE):
        return None
    lengths = _unaligned(buffer, "<u8")[starts + 1].astype(np.int64)
    ends = starts + _RECORD_HEADER.size + lengths
    if ends[-1] != buffer.size or np.any(ends[:-1] != starts[1:]):
        return None
    return starts, lengths


class Bag:
    """All messages of a recording, read once into memory (raw CDR, decoded on demand).

    Args:
        path: An ``.mcap`` file or a rosbag2 folder.
        recover: Accept unfinished (truncated) files, keeping the messages of every complete
            chunk. Otherwise such a file raises :class:`InputError`.
    """

    #: Locate a chunk's messages from its message indexes when they tile it (else walk it);
    #: False walks every chunk (the reference the tests compare the indexed reading with).
    use_indexes = True

    def __init__(self, path: str | Path, *, recover: bool = False) -> None:
        self.path = Path(path)
        self.files = _bag_files(self.path)
        #: The metadata records by name; a key in several files keeps the first file's value
        #: (the scene the record starts with: a rotated log's later files store the scene in
        #: force when each was started, `file_metadata`).
        self.metadata: dict[str, dict[str, str]] = {}
        #: Each file's own metadata records, in the order of `files`.
        self.file_metadata: list[dict[str, dict[str, str]]] = []
        #: The position in the recording (``order``) of each file's first message.
        self.file_starts: list[int] = []
        self.truncated: list[Path] = []
        self._topics: dict[str, _Topic] = {}
        self._records = 0
        for file in self.files:
            self.file_starts.append(self._records)
            self.file_metadata.append({})
            self._read_file(file, recover)
            for name, record in self.file_metadata[-1].items():
                merged = self.metadata.setdefault(name, {})
                for key, value in record.items():
                    merged.setdefault(key, value)
        if self.truncated and self._records == 0:
            names = ", ".join(repr(str(f)) for f in self.truncated)
            raise InputError(
                f"nothing to recover from {names}: the file ends or is damaged before its first "
                "complete chunk, so no message in it can be read"
            )

    def _read_file(self, file: Path, recover: bool) -> None:
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        data = file.read_bytes()
        if not data.startswith(_MAGIC):
            raise InputError(f"{str(file)!r} is not an MCAP file")
        # Message records of uncompressed chunks (and outside chunks) lie in ``data`` itself:
        # their file offsets are gathered chunk by chunk and added as columns in one pass
        # (`_flush`) before anything that could change what they mean (a channel or schema
        # record) and at the end.
        self._buffer = np.frombuffer(data, np.uint8)
        # (file offsets of message records, their length fields when already read, else None)
        self._pending: list[tuple[NDArray[np.int64], NDArray[np.int64] | None]] = []
        finished = False
        try:
            position, length = len(_MAGIC), len(data)
            while position < length and not finished:
                if position + _RECORD_HEADER.size > length:
                    raise McapError("the file ends inside a record header")
                opcode, size = _RECORD_HEADER.unpack_from(data, position)
                start = position + _RECORD_HEADER.size
                position = start + size
                if position > length:
                    raise McapError(f"a record of {size} bytes overruns the file")
                if opcode == Opcode.CHUNK:
                    indexes = _message_indexes(data, position) if self.use_indexes else []
                    self._read_chunk(data, start, position, indexes, channels, schemas)
                elif opcode == Opcode.MESSAGE:
                    self._pending.append((np.array([start - _RECORD_HEADER.size]), None))
                elif opcode in _RECORD_TYPES:
                    if opcode != Opcode.METADATA:
                        self._flush(channels, schemas)
                    record = _RECORD_TYPES[opcode].read(ReadDataStream(BytesIO(data[start:position])))
                    if opcode == Opcode.SCHEMA:
                        schemas[record.id] = record
                    elif opcode == Opcode.CHANNEL:
                        channels[record.id] = record
                    else:
                        self.file_metadata[-1].setdefault(record.name, {}).update(record.metadata)
                elif opcode == Opcode.FOOTER:
                    finished = True
            self._flush(channels, schemas)
            if not finished:
                raise McapError("the file ends before its footer")
        except (McapError, struct.error, ValueError, EOFError) as exc:
            if not recover:
                raise InputError(
                    f"{str(file)!r} is truncated or damaged ({type(exc).__name__}: {exc}); "
                    "pass --recover to use the messages up to its last complete chunk"
                ) from None
            try:  # the complete chunks before the damage
                self._flush(channels, schemas)
            except McapError:
                pass
        self._pending = []
        if not finished:
            self.truncated.append(file)

    def _read_chunk(
        self,
        data: bytes,
        start: int,
        end: int,
        indexes: list[tuple[int, int]],
        channels: dict[int, Channel],
        schemas: dict[int, Schema],
    ) -> None:
        """The records of one chunk (CRC-checked; decompressed by ``mcap`` if compressed);
        ``indexes``: the (start, end) of the bodies of the message index records after it."""
        _, _, uncompressed, crc, name_length = _CHUNK_FIELDS.unpack_from(data, start)
        at = start + _CHUNK_FIELDS.size
        compression = data[at : at + name_length].decode()
        (size,) = struct.unpack_from("<Q", data, at + name_length)
        body_start = at + name_length + 8
        if body_start + size > end:
            raise McapError("chunk records overrun the chunk")
        if compression:
            self._flush(channels, schemas)
            chunk = Chunk.read(ReadDataStream(BytesIO(data[start:end])))
            stream, length = get_chunk_data_stream(chunk, validate_crc=True)
            records: bytes | memoryview = stream.read(length)
        else:
            records = memoryview(data)[body_start : body_start + size]
            if crc and zlib.crc32(records) != crc:
                raise McapError("chunk CRC mismatch")
            if len(records) != uncompressed:
                raise McapError("chunk size differs from its uncompressed size")
        buffer = np.frombuffer(records, np.uint8)
        located = _indexed_starts(data, buffer, indexes) if indexes else None
        if located is not None:
            self._messages(compression, body_start, buffer, located[0], channels, schemas, located[1])
            return
        length = len(records)
        found: list[int] = []  # starts of the message records
        position = 0
        unpack = _RECORD_HEADER.unpack_from
        while position < length:
            opcode, size = unpack(records, position)
            if opcode == Opcode.MESSAGE:
                found.append(position)
            elif opcode in (Opcode.CHANNEL, Opcode.SCHEMA):
                if found:  # the messages before it, on channels already known
                    self._messages(compression, body_start, buffer, np.array(found), channels, schemas)
                    found = []
                self._flush(channels, schemas)
                body = ReadDataStream(BytesIO(records[position + 9 : position + 9 + size]))
                if opcode == Opcode.CHANNEL:
                    channel = Channel.read(body)
                    channels[channel.id] = channel
                else:
                    schema = Schema.read(body)
                    schemas[schema.id] = schema
            position += _RECORD_HEADER.size + size
            if position > length:
                raise McapError(f"chunk record of {size} bytes overruns its chunk")
        if found:
            self._messages(compression, body_start, buffer, np.array(found), channels, schemas)

    def _messages(
        self,
        compression: str,
        body_start: int,
        buffer: NDArray[np.uint8],
        starts: NDArray[np.int64],
        channels: dict[int, Channel],
        schemas: dict[int, Schema],
        lengths: NDArray[np.int64] | None = None,
    ) -> None:
        """Message records at ``starts`` of a chunk's records ``buffer`` (``lengths``: their
        length fields, when read already): added now from a decompressed buffer, else kept as
        file offsets for `_flush`."""
        if compression:
            self._add_messages(buffer, starts, channels, schemas, lengths)
        else:
            self._pending.append((starts + body_start, lengths))

    def _flush(self, channels: dict[int, Channel], schemas: dict[int, Schema]) -> None:
        """Add the pending message records of the file in one pass; when that fails (a bad
        record or channel), chunk by chunk, so those before the bad one are kept."""
        batch, self._pending = self._pending, []
        if not batch:
            return
        starts = np.concatenate([s for s, _ in batch])
        known = [n for _, n in batch]
        lengths = None if any(n is None for n in known) else np.concatenate(known)
        try:
            self._add_messages(self._buffer, starts, channels, schemas, lengths)
        except McapError:
            for part_starts, part_lengths in batch:
                self._add_messages(self._buffer, part_starts, channels, schemas, part_lengths)

    def _add_messages(
        self,
        buffer: NDArray[np.uint8],
        starts: NDArray[np.int64],
        channels: dict[int, Channel],
        schemas: dict[int, Schema],
        lengths: NDArray[np.int64] | None = None,
    ) -> None:
        """Message records at ``starts`` of ``buffer``, as columns per topic, in order
        (``lengths``: their length fields when read already, else read here)."""
        # Every record lies whole in ``buffer`` (its caller checked its length), so the
        # fields after the opcode are read as unaligned numbers at the records' offsets.
        record_size = _unaligned(buffer, "<u8")[starts + 1].astype(np.int64) if lengths is None else lengths
        if np.any(record_size < _MESSAGE_FIELDS.size):
            raise McapError("a message record shorter than its fields")
        channel_id = _unaligned(buffer, "<u2")[starts + 9]
        # The channels present, ascending (a count per id: no sort of the records).
        ids = np.flatnonzero(np.bincount(channel_id)).tolist() if channel_id.size else []
        unknown = [cid for cid in ids if cid not in channels]
        if unknown:  # before anything is added
            raise McapError(f"message on channel {unknown[0]}, which is not defined before it")
        log_ns = _unaligned(buffer, "<u8")[starts + 15].astype(np.int64)
        order = self._records + np.arange(starts.size, dtype=np.int64)
        self._records += starts.size
        payload_start = starts + _RECORD_HEADER.size + _MESSAGE_FIELDS.size
        payload_size = record_size - _MESSAGE_FIELDS.size
        for cid in ids:
            mine = channel_id == cid if len(ids) > 1 else slice(None)
            self._topic(cid, channels, schemas).parts.append(
                _Part(buffer, payload_start[mine], payload_size[mine], log_ns[mine], order[mine])
            )

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

    @property
    def topics(self) -> dict[str, str]:
        """Topic name -> ``pkg/msg/Type`` of every topic with messages."""
        return {name: t.type_name for name, t in self._topics.items()}

    def message_count(self, topic: str) -> int:
        """Number of messages recorded on ``topic`` (its exact recorded name). A topic with no
        message in the file raises InputError naming the recorded topics (a misspelt name
        must not read as an empty topic)."""
        info = self._topics.get(topic)
        if info is None:
            raise InputError(
                f"topic {topic!r} has no message in {str(self.path)!r} (topics: {sorted(self._topics)})"
            )
        return info.count

    def _cdr(self, topic: str) -> _Topic:
        info = self._topics[topic]
        if info.encoding != "cdr":
            raise InputError(f"topic {topic!r} has message encoding {info.encoding!r}, not cdr")
        return info

    def raw(self, topic: str) -> tuple[NDArray[np.int64], NDArray[np.int64], list[bytes]]:
        """``(log_ns, order, payloads)`` of ``topic`` in recording order: log times (ns) and
        positions in the recording, shape (n,), and the n CDR payloads, undecoded."""
        info = self._cdr(topic)
        return info.column("log_ns"), info.column("order"), info.payloads()

    def rows(self, topic: str) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.uint8] | None]:
        """:meth:`raw` as columns: the payloads as one (n, L) uint8 array when they all have
        one length L (a fixed-layout type with one frame id), else None."""
        info = self._cdr(topic)
        sizes = info.column("sizes")
        if sizes.size == 0 or np.any(sizes != sizes[0]):
            return info.column("log_ns"), info.column("order"), None
        width = int(sizes[0])
        # Each part's payloads gathered as one L-byte item per message (an unaligned view of
        # its buffer), straight into the (n, L) array.
        rows = np.empty((sizes.size, width), np.uint8)
        items = rows.view(f"V{width}").reshape(sizes.size) if width else None
        done = 0
        for part in info.parts:
            count = part.starts.size
            if items is not None:
                items[done : done + count] = _unaligned(part.buffer, f"V{width}")[part.starts]
            done += count
        return info.column("log_ns"), info.column("order"), rows

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
            log_ns, order = topic.column("log_ns").tolist(), topic.column("order").tolist()
            streams.extend(
                (t, k, name, cls, data) for t, k, data in zip(log_ns, order, topic.payloads(), strict=True)
            )
        streams.sort(key=lambda item: (item[0], item[1]))
        # rclpy only here: reading a replay's columns needs none (~50-150 ms of a fresh process).
        from rclpy.serialization import deserialize_message

        for log_time, order, name, cls, data in streams:
            try:
                msg = deserialize_message(data, cls)
            except Exception as exc:  # noqa: BLE001 - rclpy raises plain exceptions on bad CDR
                raise InputError(
                    f"topic {name!r}: message at {log_time} ns does not decode ({exc})"
                ) from None
            yield RecordedMessage(name, self._topics[name].type_name, log_time, msg, order)

    def file_of(self, order: NDArray[np.int64]) -> NDArray[np.intp]:
        """The index in `files` of the file holding each message at positions ``order``."""
        return np.searchsorted(np.asarray(self.file_starts), order, side="right") - 1

    def scene(self, file: int | None = None) -> dict[str, Any] | None:
        """The scene stored by our recorder (``SceneConfig.to_dict()`` form), if any: the one
        the record starts with (its first file's), or file ``file``'s (the scene in force when
        the recorder started that file)."""
        metadata = self.metadata if file is None else self.file_metadata[file]
        text = metadata.get(METADATA_NAME, {}).get(SCENE_KEY, "")
        if not text:
            return None
        try:
            scene = yaml.load(text, Loader=_SAFE_LOADER)
        except yaml.YAMLError as exc:
            raise InputError(f"{str(self.path)!r}: the stored scene is not valid YAML ({exc})") from None
        return scene if isinstance(scene, dict) else None

    @property
    def software_version(self) -> str | None:
        """Version of viscoadh_ros that wrote the recording, if ours."""
        return self.metadata.get(METADATA_NAME, {}).get(VERSION_KEY)
