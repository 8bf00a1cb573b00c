"""`viscoadh replay`'s bulk output equals, message for message, what the node's conversions build."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from viscoadh_ros.bench.replay_speed import record_stream
from viscoadh_ros.cli.main import main
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.experiment import choose_contact, load_experiment, run_model
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.ros import conversions


def test_replay_output_equals_conversions(tmp_path: Path) -> None:
    bag_path, out = tmp_path / "stream.mcap", tmp_path / "out.mcap"
    scene = record_stream(bag_path, 0.12)
    assert main(["replay", str(bag_path), "-o", str(out)]) == 0
    experiment = load_experiment(Bag(bag_path))
    contact = choose_contact(scene, None)
    run = run_model(contact, experiment)
    frame = scene.node.frame_id
    replayed = Bag(out)
    states = list(replayed.messages([f"/{contact.id}/state"]))
    wrenches = list(replayed.messages([f"/{contact.id}/wrench"]))
    assert len(states) == len(wrenches) == experiment.input_ns.size
    for k, (stamp, output) in enumerate(zip(experiment.input_ns.tolist(), run.input_outputs, strict=True)):
        expected = conversions.contact_state(
            output,
            stamp_ns=stamp,
            frame_id=frame,
            model=run.model,
            commands_received=k + 1,
            commands_rejected=0,
        )
        assert states[k].msg == expected, f"state {k}"
        assert states[k].log_time_ns == wrenches[k].log_time_ns == stamp, f"log times of command {k}"
        assert wrenches[k].msg == conversions.wrench(output, stamp_ns=stamp, frame_id=frame), f"wrench {k}"
    # A state and its wrench are recorded together, in stamp order.
    orders = np.array([[s.order, w.order] for s, w in zip(states, wrenches, strict=True)])
    np.testing.assert_array_equal(orders[:, 1] - orders[:, 0], 1, err_msg="wrench right after its state")


def _read_all(path: Path) -> dict[str, Any]:
    """Every message of ``path`` through the mcap reader (indexed and streamed), rosbags and
    our Bag: (topic, log time, sequence, payload) lists that must agree."""
    from mcap.reader import NonSeekingReader, make_reader
    from rosbags.highlevel import AnyReader

    with open(path, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None and reader.get_header().profile == "ros2"
        indexed = [(c.topic, m.log_time, m.sequence, m.data) for _, c, m in reader.iter_messages()]
        metadata = {r.name: r.metadata for r in reader.iter_metadata()}
    with open(path, "rb") as stream:
        streamed = [
            (c.topic, m.log_time, m.sequence, m.data)
            for _, c, m in NonSeekingReader(stream, validate_crcs=True).iter_messages()
        ]
    with AnyReader([path]) as reader:
        forces = [
            reader.deserialize(raw, c.msgtype).wrench.force.z
            for c, _, raw in reader.messages()
            if c.msgtype == "geometry_msgs/msg/WrenchStamped"
        ]
    bag = Bag(path)
    ours = sorted((m.topic, m.log_time_ns) for m in bag.messages(bag.topics))
    return {
        "indexed": indexed,
        "streamed": streamed,
        "rosbags_forces": forces,
        "bag": ours,
        "counts": dict(summary.statistics.channel_message_counts),
        "chunks": len(summary.chunk_indexes),
        "metadata": metadata,
        "scene": bag.scene(),
    }


def test_columnar_writer_reads_as_the_record_writer(tmp_path: Path) -> None:
    """`io.mcap_bulk.write_columns` (replay's writer) against `io.mcap_log.write_mcap` (one
    add_message per record): the same messages in the same order through every reader,
    several chunks, payloads of one length (arrays) and of several (frame ids that differ)."""
    from viscoadh_ros.io import cdr
    from viscoadh_ros.io.mcap_bulk import write_columns
    from viscoadh_ros.io.mcap_log import TopicData, write_mcap

    n = 300
    stamps = 1_000_000_000 + 1_000_000 * np.arange(n)
    stamps[50:60] = stamps[50]  # equal log times across topics: ties as write_mcap breaks them
    state = {"force": np.linspace(-1, 1, n), "phase": np.arange(n) % 4, "commands_received": np.arange(n)}
    mixed = cdr.encode(cdr.WRENCH, stamps[:7], "a", {"wrench.force.z": 1.0}) + cdr.encode(
        cdr.WRENCH, stamps[7:11], "longer_frame", {"wrench.force.z": 2.0}
    )
    topics = [
        TopicData(
            "/c/state", cdr.CONTACT_STATE, stamps, cdr.encode_array(cdr.CONTACT_STATE, stamps, "f", state)
        ),
        TopicData(
            "/c/wrench", cdr.WRENCH, stamps, cdr.encode(cdr.WRENCH, stamps, "f", {"wrench.force.z": 3.0})
        ),
        TopicData("/d/wrench", cdr.WRENCH, stamps[:11][::-1].copy(), mixed),
    ]
    scene = {"contacts": ["c"]}
    reference, columnar = tmp_path / "reference.mcap", tmp_path / "columnar.mcap"
    write_mcap(reference, topics, scene=scene, chunk_size=4096)
    write_columns(columnar, topics, scene=scene, chunk_size=4096)
    expected, got = _read_all(reference), _read_all(columnar)
    assert got["chunks"] > 3, "several chunks"
    for key in ("indexed", "streamed", "rosbags_forces", "bag", "counts", "metadata", "scene"):
        assert got[key] == expected[key], key
    assert len(got["indexed"]) == 2 * n + 11
    assert _check_indexes(columnar) == _check_indexes(reference) == 2 * n + 11


def _check_indexes(path: Path) -> int:
    """Every message index entry points at a message of its channel and log time, and every
    chunk index at its chunk and message indexes; returns the number of entries checked."""
    import struct

    from mcap.reader import make_reader
    from mcap.records import Chunk, MessageIndex
    from mcap.stream_reader import StreamReader

    data = path.read_bytes()
    checked = 0
    chunk = None
    with open(path, "rb") as stream:
        for record in StreamReader(stream, emit_chunks=True).records:
            if isinstance(record, Chunk):
                chunk = record
            elif isinstance(record, MessageIndex):
                for log_time, offset in record.records:
                    opcode, _, channel, _, log = struct.unpack_from("<BQHIQ", chunk.data, offset)
                    assert (opcode, channel, log) == (0x05, record.channel_id, log_time)
                    checked += 1
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    for index in summary.chunk_indexes:
        assert data[index.chunk_start_offset] == 0x06
        for channel, offset in index.message_index_offsets.items():
            assert data[offset] == 0x07 and struct.unpack_from("<H", data, offset + 9)[0] == channel
    return checked


@pytest.mark.parametrize("layout", ["chunked", "zstd", "lz4", "unchunked"])
def test_bag_reads_every_layout_of_the_mcap_writer(tmp_path: Path, layout: str) -> None:
    """Bag's own record walk against the mcap reader: compressed chunks, messages outside
    chunks, a channel defined between messages, payloads of several lengths; then a cut file
    is refused, and read up to its last complete chunk with recover."""
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer

    from viscoadh_ros.io import cdr
    from viscoadh_ros.io.ros_schemas import schema_text

    path = tmp_path / f"{layout}.mcap"
    compression = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4}.get(layout, CompressionType.NONE)
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=2048, compression=compression, use_chunking=layout != "unchunked")
        writer.start(profile="ros2")
        schema = writer.register_schema(cdr.WRENCH, "ros2msg", schema_text(cdr.WRENCH).encode())
        first = writer.register_channel("/a/wrench", "cdr", schema)
        for k in range(150):
            if k == 70:
                second = writer.register_channel("/b/wrench", "cdr", schema)
            frame = "f" * (1 + 8 * (k % 3))
            (payload,) = cdr.encode(cdr.WRENCH, [k * 1000], frame, {"wrench.force.z": float(k)})
            channel = first if k < 70 or k % 2 else second
            writer.add_message(channel, log_time=k * 1000, publish_time=k * 1000, data=payload, sequence=k)
        writer.finish()
    with open(path, "rb") as stream:
        expected = sorted((c.topic, m.log_time, m.data) for _, c, m in make_reader(stream).iter_messages())
    bag = Bag(path)
    got = sorted(
        (topic, t, data)
        for topic in bag.topics
        for t, data in zip(bag.raw(topic)[0].tolist(), bag.raw(topic)[2], strict=True)
    )
    assert got == expected and len(got) == 150
    assert bag.rows("/a/wrench")[2] is None, "frame ids of three lengths: no (n, L) array"

    data = path.read_bytes()
    path.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(InputError, match="truncated or damaged"):
        Bag(path)
    recovered = Bag(path, recover=True)
    assert recovered.truncated == [path]
    if layout != "unchunked":
        assert 0 < sum(recovered.message_count(t) for t in recovered.topics) < 150
