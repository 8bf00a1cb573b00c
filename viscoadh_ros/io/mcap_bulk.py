"""Write a whole MCAP file from columns: message records and chunks built with numpy.

:func:`viscoadh_ros.io.mcap_log.write_mcap` adds one message at a time through the ``mcap``
package's ``Writer`` (about 30 us per message in Python, more than replay's whole budget);
:func:`write_columns` writes the same file from whole topics at once: the message records of
a topic (fixed size when its payloads are, as :func:`viscoadh_ros.io.cdr.encode_array` makes
them) are one numpy structured array, scattered in log-time order into one buffer that is cut
into chunks; the message indexes are numpy arrays too. Only the handful of other records
(header, schemas, channels, metadata, one Chunk/ChunkIndex per chunk, the summary) go through
``mcap``'s record classes.

The file follows what :class:`~viscoadh_ros.io.mcap_log.McapRecorder` writes (profile
``ros2``, ``ros2msg`` schemas, ``cdr`` channels with ``offered_qos_profiles``, the
``viscoadh`` metadata record, uncompressed chunks, a summary with statistics, chunk and
metadata indexes), so ``mcap``'s reader, ``rosbags`` and :class:`~viscoadh_ros.io.bag.Bag`
read it; schemas and channels sit in the data section before the first chunk and are repeated
in the summary. Message order: by log time; at equal times the k-th messages of the topics
before the (k+1)-th, topics in the given order (as ``write_mcap``).
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
)
from numpy.typing import NDArray

from viscoadh_ros import __version__
from viscoadh_ros.io.mcap_log import (
    METADATA_NAME,
    SCENE_KEY,
    VERSION_KEY,
    TopicData,
    TopicQos,
    plain,
    summary_and_footer,
)
from viscoadh_ros.io.ros_schemas import schema_text

_MAGIC = b"\x89MCAP0\r\n"
#: A message record before its payload: opcode, record length, channel id, sequence, log and
#: publish time (MCAP's little-endian layout, no padding).
_MESSAGE_HEAD = [
    ("opcode", "u1"),
    ("length", "<u8"),
    ("channel", "<u2"),
    ("sequence", "<u4"),
    ("log_time", "<u8"),
    ("publish_time", "<u8"),
]
_HEAD_SIZE = 31


def _as_rows(payloads: Sequence[bytes] | NDArray[np.uint8]) -> NDArray[np.uint8] | None:
    """The payloads as an (n, L) uint8 array when they all have one length, else None."""
    if isinstance(payloads, np.ndarray):
        return payloads if payloads.ndim == 2 else None
    if not len(payloads):
        return np.zeros((0, 0), np.uint8)
    length = len(payloads[0])
    if any(len(p) != length for p in payloads):
        return None
    return np.frombuffer(b"".join(payloads), np.uint8).reshape(len(payloads), length)


def _records(channel: int, log_ns: NDArray[np.int64], payloads: Any) -> tuple[NDArray[np.uint8], NDArray]:
    """``(bytes, sizes)``: the message records of one topic, concatenated, and each one's size."""
    rows = _as_rows(payloads)
    n = len(log_ns)
    if rows is not None:
        length = rows.shape[1]
        layout = np.dtype(_MESSAGE_HEAD + [("data", f"V{length}")] if length else _MESSAGE_HEAD)
        records = np.empty(n, layout)
        records["opcode"] = Opcode.MESSAGE
        records["length"] = _HEAD_SIZE - 9 + length
        records["channel"] = channel
        records["sequence"] = np.arange(n, dtype=np.uint32)
        records["log_time"] = log_ns
        records["publish_time"] = log_ns
        if length:
            records["data"] = rows.view(f"V{length}").reshape(n)
        return np.frombuffer(records.tobytes(), np.uint8), np.full(n, layout.itemsize, dtype=np.int64)
    # Payloads of several lengths: one small header per message, joined in one pass.
    heads = struct.Struct("<BQHIQQ")
    parts = []
    for k, (ns, data) in enumerate(zip(log_ns.tolist(), payloads, strict=True)):
        parts.append(heads.pack(Opcode.MESSAGE, _HEAD_SIZE - 9 + len(data), channel, k, ns, ns))
        parts.append(bytes(data))
    sizes = np.array([_HEAD_SIZE + len(p) for p in payloads], dtype=np.int64)
    return np.frombuffer(b"".join(parts), np.uint8), sizes


def write_columns(
    path: str | Path,
    topics: Sequence[TopicData],
    *,
    scene: Mapping[str, Any] | None = None,
    chunk_size: int = 1024 * 1024,
) -> None:
    """Write a finished MCAP file of whole topics at once (see the module docstring).

    ``TopicData.payloads`` may be a list of CDR payloads or an (n, L) uint8 array of n
    payloads of L bytes (:func:`viscoadh_ros.io.cdr.encode_array`), the fast case.
    """
    for data in topics:
        if len(data.log_ns) != len(data.payloads):
            raise ValueError(f"{data.topic}: {len(data.log_ns)} log times for {len(data.payloads)} messages")
    log_ns = [np.asarray(d.log_ns, dtype=np.int64) for d in topics]
    if any(np.any(ns < 0) for ns in log_ns):
        raise ValueError("log times must be >= 0 ns")
    # Every topic's records, then one buffer in log-time order (ties as write_mcap breaks them).
    built = [_records(t + 1, ns, d.payloads) for t, (ns, d) in enumerate(zip(log_ns, topics, strict=True))]
    stream, sizes, which, times = _ordered(log_ns, built)
    starts = np.cumsum(sizes) - sizes  # of each message record in the ordered stream

    builder = RecordBuilder()
    out = bytearray(_MAGIC)
    Header(profile="ros2", library=f"viscoadh_ros {__version__}").write(builder)
    metadata_offset = len(out) + builder.count
    Metadata(name=METADATA_NAME, metadata=_metadata(scene)).write(builder)
    metadata_length = len(out) + builder.count - metadata_offset
    schemas: dict[str, Schema] = {}
    channels: list[Channel] = []
    qos = TopicQos().to_yaml()
    for t, data in enumerate(topics):
        if data.type_name not in schemas:
            schema = Schema(
                id=len(schemas) + 1,
                name=data.type_name,
                encoding="ros2msg",
                data=schema_text(data.type_name).encode(),
            )
            schemas[data.type_name] = schema
            schema.write(builder)
        channel = Channel(
            id=t + 1,
            topic=data.topic,
            message_encoding="cdr",
            schema_id=schemas[data.type_name].id,
            metadata={"offered_qos_profiles": qos},
        )
        channels.append(channel)
        channel.write(builder)
    out += builder.end()

    # Chunks: consecutive messages up to about chunk_size bytes each.
    chunk_of = starts // max(int(chunk_size), 1)
    bounds = np.flatnonzero(np.diff(chunk_of)) + 1
    chunk_indexes = []
    for lo, hi in zip(np.concatenate(([0], bounds)), np.concatenate((bounds, [sizes.size])), strict=True):
        if hi <= lo:
            continue
        first, end = int(starts[lo]), int(starts[hi - 1] + sizes[hi - 1])
        data = stream[first:end].tobytes()
        chunk = Chunk(
            compression="",
            data=data,
            message_start_time=int(times[lo:hi].min()),
            message_end_time=int(times[lo:hi].max()),
            uncompressed_crc=zlib.crc32(data),
            uncompressed_size=len(data),
        )
        chunk_start = len(out)
        chunk.write(builder)
        out += builder.end()
        index_start = len(out)
        offsets: dict[int, int] = {}
        for t in np.unique(which[lo:hi]).tolist():
            mine = np.flatnonzero(which[lo:hi] == t) + lo
            entries = np.empty(mine.size, [("log_time", "<u8"), ("offset", "<u8")])
            entries["log_time"] = times[mine]
            entries["offset"] = starts[mine] - first
            body = entries.tobytes()
            offsets[t + 1] = len(out)
            out += struct.pack("<BQHI", Opcode.MESSAGE_INDEX, 2 + 4 + len(body), t + 1, len(body)) + body
        chunk_indexes.append(
            ChunkIndex(
                message_start_time=chunk.message_start_time,
                message_end_time=chunk.message_end_time,
                chunk_start_offset=chunk_start,
                chunk_length=index_start - chunk_start,
                message_index_offsets=offsets,
                message_index_length=len(out) - index_start,
                compression="",
                compressed_size=len(data),
                uncompressed_size=len(data),
            )
        )
    DataEnd(data_section_crc=zlib.crc32(out)).write(builder)
    out += builder.end()

    sections = (
        (Opcode.SCHEMA, list(schemas.values())),
        (Opcode.CHANNEL, channels),
        (Opcode.STATISTICS, [_statistics(which, times, len(schemas), len(channels), len(chunk_indexes))]),
        (Opcode.CHUNK_INDEX, chunk_indexes),
        (
            Opcode.METADATA_INDEX,
            [MetadataIndex(offset=metadata_offset, length=metadata_length, name=METADATA_NAME)],
        ),
    )
    out += summary_and_footer(builder, len(out), sections)
    Path(path).write_bytes(out)


def _ordered(
    log_ns: list[NDArray[np.int64]], built: list[tuple[NDArray[np.uint8], NDArray[np.int64]]]
) -> tuple[NDArray[np.uint8], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """``(stream, sizes, topic, log time)``: the records of all topics in file order, and each
    record's size, topic index and log time in that order."""
    if not built:
        empty = np.zeros(0, np.int64)
        return np.zeros(0, np.uint8), empty, empty, empty
    n = log_ns[0].size
    shared = all(ns.shape == (n,) and np.array_equal(ns, log_ns[0]) for ns in log_ns)
    fixed = all(b.size == sizes.sum() and (n == 0 or np.all(sizes == sizes[0])) for b, sizes in built)
    if len(built) > 1 and shared and fixed and np.all(np.diff(log_ns[0]) >= 0):
        # Topics on the same non-decreasing log times (a state and its wrench per input): the
        # order is the k-th message of each topic in turn, i.e. the topics' rows side by side.
        count = len(built)
        stream = np.concatenate([b.reshape(n, -1) for b, _ in built], axis=1).reshape(-1)
        sizes = np.tile(np.array([s[0] for _, s in built], dtype=np.int64), n)
        return stream, sizes, np.tile(np.arange(count), n), np.repeat(log_ns[0], count)
    which = np.concatenate([np.full(len(ns), t, dtype=np.int64) for t, ns in enumerate(log_ns)])
    index = np.concatenate([np.arange(len(ns), dtype=np.int64) for ns in log_ns])
    times = np.concatenate(log_ns)
    order = np.lexsort((which, index, times))
    sizes = np.concatenate([s for _, s in built])
    sources = np.concatenate([np.cumsum(s) - s for _, s in built])  # start within its topic's bytes
    base = np.cumsum([0] + [len(b) for b, _ in built])[:-1]
    sources = (sources + np.repeat(base, [len(s) for _, s in built]))[order]
    everything = np.concatenate([b for b, _ in built])
    sizes, which, times = sizes[order], which[order], times[order]
    if sizes.size and np.all(sizes == sizes[0]):
        # One record size: reorder whole rows.
        return (
            everything.reshape(-1, int(sizes[0]))[sources // int(sizes[0])].reshape(-1),
            sizes,
            which,
            times,
        )
    starts = np.cumsum(sizes) - sizes
    return everything[np.repeat(sources - starts, sizes) + np.arange(int(sizes.sum()))], sizes, which, times


def _statistics(which: NDArray, times: NDArray, schemas: int, channels: int, chunks: int) -> Statistics:
    counts = np.bincount(which, minlength=channels) if which.size else np.zeros(channels, np.int64)
    return Statistics(
        message_count=int(which.size),
        schema_count=schemas,
        channel_count=channels,
        attachment_count=0,
        metadata_count=1,
        chunk_count=chunks,
        message_start_time=int(times.min()) if times.size else 0,
        message_end_time=int(times.max()) if times.size else 0,
        channel_message_counts={t + 1: int(c) for t, c in enumerate(counts.tolist())},
    )


def _metadata(scene: Mapping[str, Any] | None) -> dict[str, str]:
    """The viscoadh metadata record, as the recorder writes it."""
    return {
        SCENE_KEY: yaml.safe_dump(plain(scene), sort_keys=False) if scene is not None else "",
        VERSION_KEY: __version__,
    }
