"""Bulk CDR (io/cdr.py) against rclpy's serialisation, over random messages of every type."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from viscoadh_ros.io import cdr
from viscoadh_ros.io.ros_schemas import message_class

FRAMES = ["", "a", "contact", "abcdefg", "x" * 13]


def _random_fields(type_name: str, n: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
    fields = {}
    for name, fmt in cdr._FIELDS[type_name][1]:
        if fmt == "?":
            fields[name] = rng.random(n) < 0.5
        elif fmt == "<f8":
            fields[name] = rng.normal(size=n) * 10.0 ** rng.integers(-12, 12, size=n)
        else:
            fields[name] = rng.integers(0, 256 if fmt == "u1" else 2**32, size=n)
    return fields


def _message(type_name: str, stamp_ns: int, frame: str, fields: dict[str, Any], k: int) -> Any:
    msg = message_class(type_name)()
    if cdr._FIELDS[type_name][0]:
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
        msg.header.frame_id = frame
    for path, fmt in cdr._FIELDS[type_name][1]:
        *parents, name = path.split(".")
        target = msg
        for parent in parents:
            target = getattr(target, parent)
        value = fields[path][k]
        setattr(target, name, bool(value) if fmt == "?" else float(value) if fmt == "<f8" else int(value))
    return msg


@pytest.mark.parametrize("type_name", sorted(cdr.TYPES))
@pytest.mark.parametrize("frame", FRAMES)
def test_bulk_cdr_matches_rclpy(type_name: str, frame: str) -> None:
    rng = np.random.default_rng(len(frame) + 7 * len(type_name))
    n = 6
    fields = _random_fields(type_name, n, rng)
    stamps = rng.integers(0, 2**31 * 10**9, size=n)
    ours = cdr.encode(type_name, stamps, frame, fields)
    theirs = []
    for k in range(n):
        msg = _message(type_name, int(stamps[k]), frame, fields, k)
        reference = serialize_message(msg)
        theirs.append(reference)
        case = f"{type_name} frame {frame!r} message {k}"
        assert len(ours[k]) == len(reference), case
        assert deserialize_message(ours[k], type(msg)) == msg, f"rclpy reads our bytes: {case}"
    # rclpy leaves its alignment padding uninitialised: compare what it decodes to, both ways.
    decoded = cdr.decode(type_name, theirs)
    assert decoded is not None, f"{type_name} frame {frame!r} read in bulk"
    for path, values in fields.items():
        np.testing.assert_array_equal(decoded[path], values, err_msg=f"{type_name} {path} frame {frame!r}")
    if cdr._FIELDS[type_name][0]:
        np.testing.assert_array_equal(decoded["stamp_ns"], stamps, err_msg=f"{type_name} stamps")


@pytest.mark.parametrize("type_name", sorted(cdr.TYPES))
@pytest.mark.parametrize("frame", FRAMES)
def test_packer_matches_bulk_encode(type_name: str, frame: str) -> None:
    """One message at a time (the node's live path) gives the bulk encoder's bytes exactly."""
    rng = np.random.default_rng(3 + len(frame) + 5 * len(type_name))
    n = 4
    fields = _random_fields(type_name, n, rng)
    stamps = rng.integers(0, 2**31 * 10**9, size=n)
    packer = cdr.Packer(type_name, frame)
    assert packer.fields == tuple(fields), f"{type_name}: field order"
    for k, bulk in enumerate(cdr.encode(type_name, stamps, frame, fields)):
        values = [fields[name][k].item() for name in packer.fields]
        assert packer.pack(int(stamps[k]), *values) == bulk, f"{type_name} frame {frame!r} message {k}"


def test_bulk_decode_declines_what_it_cannot_read() -> None:
    wrench = "geometry_msgs/msg/WrenchStamped"
    short, long = (cdr.encode(wrench, [0], frame, {}) for frame in ("a", "abcdefghij"))
    assert cdr.decode(wrench, short + long) is None, "frame ids of different lengths"
    assert cdr.decode("std_msgs/msg/String", [b"\x00\x01\x00\x00"]) is None, "a type without a layout"
    big_endian = [b"\x00\x00\x00\x00" + short[0][4:]]
    assert cdr.decode(wrench, big_endian) is None, "big-endian CDR"
    assert cdr.decode(wrench, [short[0][:-8]]) is None, "truncated payload"
    with pytest.raises(KeyError, match="no field 'wrench.force.w'"):
        cdr.encode(wrench, [0], "a", {"wrench.force.w": 1.0})


def test_experiment_reads_mixed_frames_through_rclpy(tmp_path: Any) -> None:
    """Frame ids of different lengths in one topic cannot be read in bulk: the rclpy fallback
    gives the same experiment (log time for a zero stamp)."""
    from geometry_msgs.msg import PointStamped, WrenchStamped

    from viscoadh_ros.experiment import load_experiment
    from viscoadh_ros.io.bag import Bag
    from viscoadh_ros.io.mcap_log import McapRecorder

    path = tmp_path / "mixed.mcap"
    with McapRecorder(path) as recorder:
        for k in range(4):
            point, wrench = PointStamped(), WrenchStamped()
            point.header.stamp.sec = wrench.header.stamp.sec = 10 + k
            point.header.frame_id, wrench.header.frame_id = "a" * (k + 1), "b" * (3 - k)
            point.point.z, wrench.wrench.force.z = 1e-6 * k, -0.5 * k
            if k == 3:
                wrench.header.stamp.sec = 0  # "on receipt": the log time
            recorder.record("/p", point, (10 + k) * 1_000_000_000)
            recorder.record("/w", wrench, (10 + k) * 1_000_000_000 + 5)
    experiment = load_experiment(Bag(path))
    np.testing.assert_array_equal(experiment.input_value, 1e-6 * np.arange(4), err_msg="depths")
    np.testing.assert_array_equal(experiment.measured_force, -0.5 * np.arange(4), err_msg="forces")
    np.testing.assert_array_equal(
        experiment.measured_ns, [10e9, 11e9, 12e9, 13e9 + 5], err_msg="header stamps, else log time"
    )


@pytest.mark.parametrize("frame_id", ["", "a", "abc", "abcd", "hand_frame_01"])
def test_parse_command_reads_what_rclpy_serialises(frame_id: str) -> None:
    """The live path's raw command reader gives rclpy's fields for every frame_id padding."""
    from rclpy.serialization import serialize_message
    from viscoadh_msgs.msg import IndentationCommand

    msg = IndentationCommand(mode=IndentationCommand.FORCE, depth=-1.5e-4, force=float("nan"))
    msg.header.stamp.sec, msg.header.stamp.nanosec = 1_700_000_000, 999_999_999
    msg.header.frame_id = frame_id
    sec, nanosec, mode, depth, force = cdr.parse_command(serialize_message(msg))
    assert (sec, nanosec, mode, depth) == (1_700_000_000, 999_999_999, IndentationCommand.FORCE, -1.5e-4)
    assert math.isnan(force)


def test_parse_command_leaves_other_layouts_to_rclpy() -> None:
    from rclpy.serialization import serialize_message
    from viscoadh_msgs.msg import IndentationCommand

    payload = serialize_message(IndentationCommand(depth=1.0))
    assert cdr.parse_command(b"\x00\x00\x00\x00" + payload[4:]) is None, "big endian"
    assert cdr.parse_command(payload[:-1]) is None, "cut"
    assert cdr.parse_command(payload + b"\x00" * 8) is None, "longer than the layout"


@pytest.mark.parametrize("count", [0, 1, 3, 16])
@pytest.mark.parametrize("frame_id", ["", "ab", "hand"])
def test_hand_state_payload_is_what_rclpy_serialises(count: int, frame_id: str) -> None:
    from viscoadh_msgs.msg import HandState

    rng = np.random.default_rng(count)
    ids = [f"finger_{'x' * k}" for k in range(count)]
    columns = {}
    for name, code in cdr.HAND_STATE_ARRAYS:
        if code == "?":
            columns[name] = (rng.random(count) < 0.5).tolist()
        elif code == "B":
            columns[name] = rng.integers(0, 4, size=count).tolist()
        else:
            columns[name] = (rng.normal(size=count) * 1e-3).tolist()
    payload = cdr.pack_hand_state(1_234_567_890_123, frame_id, ids, columns, 7, 2)
    msg = HandState(contact_ids=ids, commands_received=7, commands_rejected=2, **columns)
    msg.header.stamp.sec, msg.header.stamp.nanosec = 1234, 567_890_123
    msg.header.frame_id = frame_id
    # Same fields (not the same bytes: rclpy leaves alignment padding uninitialised, and for
    # empty arrays its buffer carries uninitialised bytes after the message).
    back = deserialize_message(payload, HandState)
    assert back == msg
    assert list(back.contact_ids) == ids and list(back.force) == columns["force"]
