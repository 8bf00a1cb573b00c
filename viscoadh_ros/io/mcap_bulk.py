"""Write a whole MCAP file from columns: message records and chunks built with numpy.

:func:`viscoadh_ros.io.mcap_log.write_mcap` adds one message at a time through the ``mcap``
package's ``Writer`` (about 30 us per message in Python, more than replay's whole budget);
:func:`write_columns` writes the same file from whole topics at once: the message records of
a topic (fixed size when its payloads are, as :func:`viscoadh_ros.io.cdr.encode_array` makes
them, or given as columns, :class:`viscoadh_ros.io.cdr.Messages`, serialised in place) are
numpy structured arrays put in log-time order and cut into chunks; topics on the same log
times (a state and its wrench per input) are built chunk by chunk into one reused block, so
the file is never held whole. The message indexes are numpy arrays too. Only the handful of
other records (header, schemas, channels, metadata, one ChunkIndex per chunk, the summary)
go through ``mcap``'s record classes.

The file follows what :class:`~viscoadh_ros.io.mcap_log.McapRecorder` writes (profile
``ros2``, ``ros2msg`` schemas, ``cdr`` channels with ``offered_qos_profiles``, the
``viscoadh`` metadata record, uncompressed chunks, a summary with statistics, chunk and
metadata indexes), so ``mcap``'s reader, ``rosbags`` and :class:`~viscoadh_ros.io.bag.Bag`
read it; schemas and channels sit in the data section before the first chunk and are repeated
in the summary. Message order: by log time; at equal times the k-th messages of the topics
before the (k+1)-th, topics in the given order (as ``write_mcap``).
"""

from __future__ import annotations

import functools
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
from viscoadh_ros.io import cdr
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
#: A Chunk record up to its compression name's bytes: opcode, record length, message start
#: and end time, uncompressed size, uncompressed CRC, compression name length (0: none).
_CHUNK_HEAD = struct.Struct("<BQQQQII")


def _as_rows(payloads: Any) -> NDArray[np.uint8] | None:
    """The payloads as an (n, L) uint8 array when they all have one length, else None."""
    if isinstance(payloads, cdr.Messages):
        return payloads.rows()
    if isinstance(payloads, np.ndarray):
        return payloads if payloads.ndim == 2 else None
    if not len(payloads):
        return np.zeros((0, 0), np.uint8)
    length = len(payloads[0])
    if any(len(p) != length for p in payloads):
        return None
    return np.frombuffer(b"".join(payloads), np.uint8).reshape(len(payloads), length)


def _fixed(payloads: Any) -> NDArray[np.uint8] | cdr.Messages | None:
    """Payloads of one length as they can be written in place (an (n, L) array or the
    messages' columns), else None."""
    return payloads if isinstance(payloads, cdr.Messages) else _as_rows(payloads)


def _size(payloads: NDArray[np.uint8] | cdr.Messages) -> int:
    return payloads.layout.itemsize if isinstance(payloads, cdr.Messages) else payloads.shape[1]


def _head_layout(length: int) -> np.dtype:
    """One message record with a payload of ``length`` bytes (no padding)."""
    return np.dtype(_MESSAGE_HEAD + [("data", f"V{length}")] if length else _MESSAGE_HEAD)


def _fill(
    records: np.ndarray,
    channel: int,
    log_ns: NDArray[np.int64],
    payloads: NDArray[np.uint8] | cdr.Messages,
    first: int = 0,
) -> None:
    """Write messages ``first`` to ``first + len(records)`` of a topic as message records (a
    zeroed structured array of :func:`_head_layout`) in place; messages given as columns
    are checked first (`cdr.Messages.check`)."""
    if isinstance(payloads, cdr.Messages):
        payloads.check()
    _fill_constant(records, channel, payloads)
    _fill_varying(records, log_ns, payloads, first)


def _fill_constant(records: np.ndarray, channel: int, payloads: NDArray[np.uint8] | cdr.Messages) -> None:
    """The bytes all the records of a topic share (see `_fill`)."""
    records["opcode"] = Opcode.MESSAGE
    records["length"] = _HEAD_SIZE - 9 + _size(payloads)
    records["channel"] = channel
    if isinstance(payloads, cdr.Messages):
        payloads.encode_constant(records["data"].view(payloads.layout))


def _fill_varying(
    records: np.ndarray, log_ns: NDArray[np.int64], payloads: NDArray[np.uint8] | cdr.Messages, first: int
) -> None:
    """The bytes that differ between the records of a topic (see `_fill`)."""
    end, length = first + len(records), _size(payloads)
    records["sequence"] = np.arange(first, end, dtype=np.uint32)
    records["log_time"] = log_ns[first:end]
    records["publish_time"] = log_ns[first:end]
    if isinstance(payloads, cdr.Messages):
        payloads.encode_varying(records["data"].view(payloads.layout), first)
    elif length:
        records["data"] = payloads[first:end].view(f"V{length}").reshape(end - first)


def _records(channel: int, log_ns: NDArray[np.int64], payloads: Any) -> tuple[NDArray[np.uint8], NDArray]:
    """``(bytes, sizes)``: the message records of one topic, concatenated, and each one's size."""
    fixed = _fixed(payloads)
    n = len(log_ns)
    if fixed is not None:
        layout = _head_layout(_size(fixed))
        records = np.zeros(n, layout)
        _fill(records, channel, log_ns, fixed)
        return records.view(np.uint8), np.full(n, layout.itemsize, dtype=np.int64)
    # Payloads of several lengths: one small header per message, joined in one pass.
    heads = struct.Struct("<BQHIQQ")
    parts = []
    for k, (ns, data) in enumerate(zip(log_ns.tolist(), payloads, strict=True)):
        parts.append(heads.pack(Opcode.MESSAGE, _HEAD_SIZE - 9 + len(data), channel, k, ns, ns))
        parts.append(bytes(data))
    sizes = np.array([_HEAD_SIZE + len(p) for p in payloads], dtype=np.int64)
    return np.frombuffer(b"".join(parts), np.uint8), sizes


class _SideBySide:
    """Topics whose payloads all have one length, on the same non-decreasing log times (a
    state and its wrench per input): in file order the k-th records of the topics lie side by
    side, one structured row per k. A chunk's bytes are built when it is written, into one
    reused block of rows (filled and, for messages given as columns, serialised in place),
    so the file is never held whole and each row is written while it is in the cache."""

    def __init__(self, log_ns: NDArray[np.int64], fixed: list[NDArray[np.uint8] | cdr.Messages]) -> None:
        self.log_ns, self.fixed = log_ns, fixed
        layouts = [_head_layout(_size(f)) for f in fixed]
        offsets = np.cumsum([0] + [lay.itemsize for lay in layouts])
        self.names = [f"t{t}" for t in range(len(fixed))]
        self.row = np.dtype(
            {
                "names": self.names,
                "formats": layouts,
                "offsets": offsets[:-1].tolist(),
                "itemsize": int(offsets[-1]),
            }
        )
        n, count = log_ns.size, len(fixed)
        self.count = count
        self.sizes = np.tile(np.array([lay.itemsize for lay in layouts], dtype=np.int64), n)
        self.which = np.tile(np.arange(count), n)
        self.times = np.repeat(log_ns, count)
        self._block = np.empty(0, self.row)
        # One row of the bytes every row shares (record heads, encapsulations, frame ids,
        # scalar fields; padding zero): a chunk's block starts as copies of it.
        template = np.zeros(1, self.row)
        for t, (name, data) in enumerate(zip(self.names, fixed, strict=True)):
            _fill_constant(template[name], t + 1, data)
        self._template = template.view(np.uint8)

    @staticmethod
    def plan(log_ns: list[NDArray[np.int64]], payloads: list[Any]) -> _SideBySide | None:
        """The topics as side-by-side rows, or None when they are not like that."""
        n = log_ns[0].size
        if len(payloads) < 2 or n == 0:
            return None
        if not all(ns.shape == (n,) and np.array_equal(ns, log_ns[0]) for ns in log_ns[1:]):
            return None
        if np.any(np.diff(log_ns[0]) < 0):
            return None
        fixed = [_fixed(p) for p in payloads]
        if any(f is None for f in fixed):
            return None
        for f in fixed:
            if isinstance(f, cdr.Messages):
                f.check()  # before the file is opened
        return _SideBySide(log_ns[0], fixed)  # type: ignore[arg-type]

    def chunk(self, lo: int, hi: int, first: int, end: int) -> memoryview:
        """The bytes of records ``lo`` to ``hi`` (file-order indexes), stream offsets ``first``
        to ``end``; valid until the next call."""
        k0, k1 = lo // self.count, (hi - 1) // self.count + 1
        if self._block.size < k1 - k0:
            self._block = np.empty(k1 - k0, self.row)
        block = self._block[: k1 - k0]
        raw = block.view(np.uint8)
        raw.reshape(k1 - k0, self.row.itemsize)[:] = self._template
        for name, data in zip(self.names, self.fixed, strict=True):
            _fill_varying(block[name], self.log_ns, data, k0)
        offset = first - k0 * self.row.itemsize
        return memoryview(raw[offset : offset + end - first])


def write_columns(
    path: str | Path,
    topics: Sequence[TopicData],
    *,
    scene: Mapping[str, Any] | None = None,
    chunk_size: int = 1024 * 1024,
) -> None:
    """Write a finished MCAP file of whole topics at once (see the module docstring).

    ``TopicData.payloads`` may be a list of CDR payloads, an (n, L) uint8 array of n
    payloads of L bytes (:func:`viscoadh_ros.io.cdr.encode_array`), or a
    :class:`viscoadh_ros.io.cdr.Messages` (the columns of n messages, serialised straight
    into the file's records: the fast case).
    """
    for data in topics:
        if len(data.log_ns) != len(data.payloads):
            raise ValueError(f"{data.topic}: {len(data.log_ns)} log times for {len(data.payloads)} messages")
    log_ns = [np.asarray(d.log_ns, dtype=np.int64) for d in topics]
    if any(np.any(ns < 0) for ns in log_ns):
        raise ValueError("log times must be >= 0 ns")
    # Every topic's records in log-time order (ties as write_mcap breaks them): built chunk by
    # chunk for side-by-side topics, else in one buffer.
    plan = _SideBySide.plan(log_ns, [d.payloads for d in topics]) if topics else None
    if plan is not None:
        sizes, which, times = plan.sizes, plan.which, plan.times
        chunk_bytes = plan.chunk
    else:
        built = [
            _records(t + 1, ns, d.payloads) for t, (ns, d) in enumerate(zip(log_ns, topics, strict=True))
        ]
        stream, sizes, which, times = _ordered(log_ns, built)

        def chunk_bytes(lo: int, hi: int, first: int, end: int) -> memoryview:
            return memoryview(stream[first:end])

    starts = np.cumsum(sizes) - sizes  # of each message record in the ordered stream

    builder = RecordBuilder()
    head = bytearray(_MAGIC)
    Header(profile="ros2", library=f"viscoadh_ros {__version__}").write(builder)
    metadata_offset = len(head) + builder.count
    Metadata(name=METADATA_NAME, metadata=_metadata(scene)).write(builder)
    metadata_length = len(head) + builder.count - metadata_offset
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
    head += builder.end()

    # Chunks: consecutive messages up to about chunk_size bytes each. The records are written
    # to the file straight from `stream` (no copy per chunk); the message indexes of all
    # chunks are one array sorted by (chunk, channel), cut into one record per pair.
    chunk_of = starts // max(int(chunk_size), 1)
    firsts = (
        np.concatenate(([0], np.flatnonzero(np.diff(chunk_of)) + 1)) if sizes.size else np.zeros(0, np.int64)
    )
    lasts = np.concatenate((firsts[1:], [sizes.size])) if sizes.size else firsts
    chunk = np.repeat(np.arange(firsts.size), lasts - firsts)
    entries = np.empty(sizes.size, [("log_time", "<u8"), ("offset", "<u8")])
    entries["log_time"] = times
    entries["offset"] = starts - starts[firsts][chunk]
    count = len(topics)
    by_channel = np.argsort(chunk * count + which, kind="stable")
    entries = entries[by_channel]
    pair_counts = np.bincount(chunk * count + which, minlength=firsts.size * count).reshape(
        firsts.size, count
    )
    pair_ends = np.cumsum(pair_counts.reshape(-1)).reshape(firsts.size, count)
    start_times = np.minimum.reduceat(times, firsts) if sizes.size else firsts
    end_times = np.maximum.reduceat(times, firsts) if sizes.size else firsts
    chunk_indexes = []
    path = Path(path)
    try:
        with open(path, "wb") as out:
            out.write(head)
            position, crc = len(head), zlib.crc32(head)
            for c, (lo, hi) in enumerate(zip(firsts.tolist(), lasts.tolist(), strict=True)):
                first, end = int(starts[lo]), int(starts[hi - 1] + sizes[hi - 1])
                data = chunk_bytes(lo, hi, first, end)
                data_crc = zlib.crc32(data)
                chunk_head = _CHUNK_HEAD.pack(
                    Opcode.CHUNK,
                    40 + len(data),
                    int(start_times[c]),
                    int(end_times[c]),
                    len(data),
                    data_crc,
                    0,
                ) + struct.pack("<Q", len(data))
                chunk_start = position
                indexes = bytearray()
                offsets: dict[int, int] = {}
                index_start = position + len(chunk_head) + len(data)
                for t in np.flatnonzero(pair_counts[c]).tolist():
                    body = entries[pair_ends[c, t] - pair_counts[c, t] : pair_ends[c, t]].tobytes()
                    offsets[t + 1] = index_start + len(indexes)
                    indexes += struct.pack("<BQHI", Opcode.MESSAGE_INDEX, 2 + 4 + len(body), t + 1, len(body))
                    indexes += body
                for piece in (chunk_head, data, indexes):
                    out.write(piece)
                # The data section's CRC runs on through the chunk; over its records it
                # follows from their own CRC (one pass over the records, not two).
                crc = zlib.crc32(chunk_head, crc)
                crc = crc32_combine(crc, data_crc, len(data))
                crc = zlib.crc32(indexes, crc)
                position = index_start + len(indexes)
                chunk_indexes.append(
                    ChunkIndex(
                        message_start_time=int(start_times[c]),
                        message_end_time=int(end_times[c]),
                        chunk_start_offset=chunk_start,
                        chunk_length=index_start - chunk_start,
                        message_index_offsets=offsets,
                        message_index_length=len(indexes),
                        compression="",
                        compressed_size=len(data),
                        uncompressed_size=len(data),
                    )
                )
            DataEnd(data_section_crc=crc).write(builder)
            tail = builder.end()
            position += len(tail)
            sections = (
                (Opcode.SCHEMA, list(schemas.values())),
                (Opcode.CHANNEL, channels),
                (
                    Opcode.STATISTICS,
                    [_statistics(which, times, len(schemas), len(channels), len(chunk_indexes))],
                ),
                (Opcode.CHUNK_INDEX, chunk_indexes),
                (
                    Opcode.METADATA_INDEX,
                    [MetadataIndex(offset=metadata_offset, length=metadata_length, name=METADATA_NAME)],
                ),
            )
            out.write(tail + summary_and_footer(builder, position, sections))
    except BaseException:
        path.unlink(missing_ok=True)  # never leave a half-written file
        raise


#: CRC-32 (zlib's, reflected polynomial) arithmetic modulo P for `crc32_combine`, after zlib's
#: crc32.c: polynomials as 32-bit words, x^0 in the top bit.
_CRC_POLY = 0xEDB88320


def _multmodp(a: int, b: int) -> int:
    """a(x) b(x) modulo P."""
    m, p = 1 << 31, 0
    while True:
        if a & m:
            p ^= b
            if not a & (m - 1):
                return p
        m >>= 1
        b = (b >> 1) ^ _CRC_POLY if b & 1 else b >> 1


def _x2n_table() -> list[int]:
    """x^(2^k) modulo P for k = 0..31."""
    table, p = [], 1 << 30  # x^1
    for _ in range(32):
        table.append(p)
        p = _multmodp(p, p)
    return table


_X2N = _x2n_table()


@functools.lru_cache(maxsize=64)
def _shift_bytes(length: int) -> int:
    """x^(8 length) modulo P: the factor that moves a CRC past ``length`` zero bytes."""
    p, k = 1 << 31, 3  # x^0; 2^3 bits a byte
    while length:
        if length & 1:
            p = _multmodp(_X2N[k & 31], p)
        length >>= 1
        k += 1
    return p


def crc32_combine(crc1: int, crc2: int, length2: int) -> int:
    """``zlib.crc32(A + B)`` from ``crc1 = zlib.crc32(A)``, ``crc2 = zlib.crc32(B)`` and
    ``length2 = len(B)`` (zlib's ``crc32_combine``, which Python's zlib does not expose):
    a few microseconds, where running the CRC over B again costs ~0.3 ms per MB."""
    return _multmodp(_shift_bytes(length2), crc1) ^ crc2


def _ordered(
    log_ns: list[NDArray[np.int64]], built: list[tuple[NDArray[np.uint8], NDArray[np.int64]]]
) -> tuple[NDArray[np.uint8], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """``(stream, sizes, topic, log time)``: the records of all topics in file order, and each
    record's size, topic index and log time in that order."""
    if not built:
        empty = np.zeros(0, np.int64)
        return np.zeros(0, np.uint8), empty, empty, empty
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
