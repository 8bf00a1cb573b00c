"""`Bag` locates a chunk's messages from its message indexes; it must read exactly what the
record-by-record walk reads (`Bag.use_indexes = False`), on every layout, and fall back to the
walk whenever the indexes do not tile the chunk."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from viscoadh_ros.bench.replay_speed import record_stream
from viscoadh_ros.io import bag as bag_module
from viscoadh_ros.io import cdr
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.mcap_log import McapRecorder


def _contents(path: Path, *, indexed: bool, recover: bool = False) -> dict[str, Any]:
    """Everything a Bag exposes about ``path`` (raw payloads, columns, metadata)."""
    saved = Bag.use_indexes
    Bag.use_indexes = indexed
    try:
        bag = Bag(path, recover=recover)
    finally:
        Bag.use_indexes = saved
    topics = {}
    for topic in bag.topics:
        log_ns, order, payloads = bag.raw(topic)
        _, _, rows = bag.rows(topic)
        topics[topic] = (log_ns.tolist(), order.tolist(), payloads, None if rows is None else rows.tolist())
    return {
        "topics": bag.topics,
        "messages": topics,
        "metadata": bag.metadata,
        "truncated": bag.truncated,
    }


def _count_indexed(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """Record, per chunk read, whether its indexes were used."""
    used: list[bool] = []
    original = bag_module._indexed_starts

    def spy(*args: Any) -> Any:
        starts = original(*args)
        used.append(starts is not None)
        return starts

    monkeypatch.setattr(bag_module, "_indexed_starts", spy)
    return used


def test_recorder_log_is_read_from_its_indexes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "stream.mcap"
    record_stream(path, 3.0)
    used = _count_indexed(monkeypatch)
    indexed = _contents(path, indexed=True)
    assert used and all(used), "every chunk of our recorder's log tiles from its indexes"
    assert indexed == _contents(path, indexed=False)
    assert sum(len(m[0]) for m in indexed["messages"].values()) == 6000


def test_columnar_output_is_read_from_its_indexes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from viscoadh_ros.io.mcap_bulk import write_columns
    from viscoadh_ros.io.mcap_log import TopicData

    n = 2000
    stamps = 1_000_000_000 + 1_000_000 * np.arange(n)
    stamps[100:120] = stamps[100]
    state = {"force": np.linspace(-1, 1, n), "phase": np.arange(n) % 4}
    path = tmp_path / "columns.mcap"
    write_columns(
        path,
        [
            TopicData(
                "/c/state", cdr.CONTACT_STATE, stamps, cdr.encode_array(cdr.CONTACT_STATE, stamps, "f", state)
            ),
            TopicData(
                "/c/wrench", cdr.WRENCH, stamps[::2], cdr.encode_array(cdr.WRENCH, stamps[::2], "ff", {})
            ),
        ],
        chunk_size=8192,
    )
    used = _count_indexed(monkeypatch)
    assert _contents(path, indexed=True) == _contents(path, indexed=False)
    assert len(used) > 5 and all(used)


@pytest.mark.parametrize("layout", ["chunked", "zstd", "unchunked"])
def test_mcap_writer_layouts_read_alike(tmp_path: Path, layout: str) -> None:
    """mcap's own Writer puts a channel defined mid-run inside a chunk: that chunk is walked."""
    from mcap.writer import CompressionType, Writer

    from viscoadh_ros.io.ros_schemas import schema_text

    path = tmp_path / f"{layout}.mcap"
    compression = CompressionType.ZSTD if layout == "zstd" else CompressionType.NONE
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=2048, compression=compression, use_chunking=layout != "unchunked")
        writer.start(profile="ros2")
        schema = writer.register_schema(cdr.WRENCH, "ros2msg", schema_text(cdr.WRENCH).encode())
        first = writer.register_channel("/a/wrench", "cdr", schema)
        for k in range(300):
            if k == 70:
                second = writer.register_channel("/b/wrench", "cdr", schema)
            frame = "f" * (1 + 8 * (k % 3)) if k < 200 else "g"
            (payload,) = cdr.encode(cdr.WRENCH, [k * 1000], frame, {"wrench.force.z": float(k)})
            channel = first if k < 70 or k % 2 else second
            writer.add_message(channel, log_time=k * 1000, publish_time=k * 1000, data=payload, sequence=k)
        writer.finish()
    assert _contents(path, indexed=True) == _contents(path, indexed=False)
    # Cut mid-file: the complete chunks, alike.
    data = path.read_bytes()
    path.write_bytes(data[: len(data) * 2 // 3])
    assert _contents(path, indexed=True, recover=True) == _contents(path, indexed=False, recover=True)


def _chunk_index_records(data: bytes) -> list[tuple[int, int]]:
    """(start, end) of each message index record's entries in ``data``."""
    found, position = [], 8
    while position + 9 <= len(data):
        opcode, size = struct.unpack_from("<BQ", data, position)
        if opcode == 0x07:
            found.append((position + 9 + 6, position + 9 + size))
        if opcode == 0x02:  # footer
            break
        position += 9 + size
    return found


@pytest.mark.parametrize("damage", ["offset", "drop_entry", "duplicate", "length"])
def test_damaged_indexes_fall_back_to_the_walk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, damage: str
) -> None:
    """An index entry that points elsewhere, one missing, one twice, a bad length: the chunk
    is walked, and the messages are the walk's."""
    path = tmp_path / "stream.mcap"
    record_stream(path, 0.5)
    data = bytearray(path.read_bytes())
    start, end = _chunk_index_records(bytes(data))[0]
    assert end - start >= 32
    if damage == "offset":
        struct.pack_into("<Q", data, start + 8, struct.unpack_from("<Q", data, start + 8)[0] + 3)
    elif damage == "drop_entry":
        # The record without its last entry (lengths fixed up; Bag reads no summary offsets).
        struct.pack_into("<Q", data, start - 14, struct.unpack_from("<Q", data, start - 14)[0] - 16)
        struct.pack_into("<I", data, start - 4, end - start - 16)
        del data[end - 16 : end]
    elif damage == "duplicate":
        data[start + 24 : start + 32] = data[start + 8 : start + 16]
    else:
        struct.pack_into("<I", data, start - 4, end - start - 16 + 3)
    path.write_bytes(bytes(data))
    used = _count_indexed(monkeypatch)
    assert _contents(path, indexed=True) == _contents(path, indexed=False)
    assert used[0] is False, "the damaged chunk is walked"


@pytest.mark.parametrize("damage", ["channel", "crc"])
def test_a_bad_chunk_keeps_the_chunks_before_it(tmp_path: Path, damage: str) -> None:
    """A message on an undefined channel (CRC fixed up), or a CRC mismatch, in the third
    chunk: refused without recover; with it, the messages of the first two chunks."""
    from viscoadh_ros.core.errors import InputError

    path = tmp_path / "stream.mcap"
    record_stream(path, 10.0)
    data = bytearray(path.read_bytes())
    chunks, position = [], 8
    while True:
        opcode, size = struct.unpack_from("<BQ", data, position)
        if opcode == 0x06:
            chunks.append(position)
        if opcode == 0x02:
            break
        position += 9 + size
    assert len(chunks) >= 3
    head = chunks[2] + 9 + 8 + 8 + 8  # the chunk's uncompressed CRC
    records = head + 4 + 4 + 8  # no compression name; records length; first message record
    length = struct.unpack_from("<Q", data, head + 8)[0]
    if damage == "channel":
        struct.pack_into("<H", data, records + 9, 99)
        struct.pack_into("<I", data, head, zlib.crc32(bytes(data[records : records + length])))
    else:
        data[records + 40] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match="truncated or damaged"):
        Bag(path)
    kept = _contents(path, indexed=True, recover=True)
    assert kept == _contents(path, indexed=False, recover=True)
    count = sum(len(m[0]) for m in kept["messages"].values())
    assert 0 < count < 20000 and kept["truncated"] == [path]


def test_recover_with_nothing_recoverable_says_so(tmp_path: Path) -> None:
    """A file cut inside its first chunk: --recover has no message to give, and says that
    (an outside tester saw "no input topic", which sent them looking for a topic problem)."""
    from geometry_msgs.msg import PointStamped

    from viscoadh_ros.cli.main import main
    from viscoadh_ros.core.errors import InputError

    whole = tmp_path / "whole.mcap"
    with McapRecorder(whole) as recorder:
        for i in range(50):
            point = PointStamped()
            point.point.z = i * 1e-7
            recorder.record("/probe/depth", point, 1_000_000_000 + i * 1_000_000)
    data = whole.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: 8 + (len(data) - 8) // 10])  # the magic and a tenth of the records
    with pytest.raises(InputError, match="nothing to recover"):
        Bag(cut, recover=True)
    with pytest.raises(InputError, match="truncated or damaged"):
        Bag(cut)
    assert main(["replay", str(cut), "-o", str(tmp_path / "out.mcap"), "--recover"]) != 0
