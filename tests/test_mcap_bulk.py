"""`write_columns` writes the same file whichever form the payloads take (the messages' columns
serialised in place, an (n, L) array, a list of bytes), and a file of empty topics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from viscoadh_ros.io import cdr, mcap_bulk
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.mcap_bulk import write_columns
from viscoadh_ros.io.mcap_log import TopicData


@pytest.mark.parametrize("n", [1, 5, 3000])
def test_payload_forms_write_the_same_bytes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, n: int) -> None:
    """Also the same bytes as the general path (every topic's records built whole, then put
    in log-time order), which side-by-side topics do not take."""
    rng = np.random.default_rng(n)
    stamps = 2_000_000_000 + 1_000_000 * np.arange(n)
    state = {
        "force": rng.normal(size=n),
        "phase": rng.integers(0, 4, n).astype(np.uint8),
        "scale_separation_ok": rng.random(n) < 0.5,
        "model": 1,
        "commands_received": np.arange(1, n + 1),
    }
    wrench = {"wrench.force.z": rng.normal(size=n)}
    forms = {
        "messages": lambda t, f, v: cdr.Messages(t, stamps, f, v),
        "rows": lambda t, f, v: cdr.encode_array(t, stamps, f, v),
        "bytes": lambda t, f, v: cdr.encode(t, stamps, f, v),
    }
    files = {}
    for form, make in forms.items():
        path = tmp_path / f"{form}.mcap"
        write_columns(
            path,
            [
                TopicData("/c/state", cdr.CONTACT_STATE, stamps, make(cdr.CONTACT_STATE, "frame", state)),
                TopicData("/c/wrench", cdr.WRENCH, stamps, make(cdr.WRENCH, "frame", wrench)),
            ],
            scene={"a": 1},
            chunk_size=4096,
        )
        files[form] = path.read_bytes()
    with monkeypatch.context() as patch:
        patch.setattr(mcap_bulk._SideBySide, "plan", staticmethod(lambda *args: None))
        for form, make in forms.items():
            path = tmp_path / f"{form}_general.mcap"
            write_columns(
                path,
                [
                    TopicData("/c/state", cdr.CONTACT_STATE, stamps, make(cdr.CONTACT_STATE, "frame", state)),
                    TopicData("/c/wrench", cdr.WRENCH, stamps, make(cdr.WRENCH, "frame", wrench)),
                ],
                scene={"a": 1},
                chunk_size=4096,
            )
            files[f"{form} general"] = path.read_bytes()
    assert len(set(files.values())) == 1, "one file whatever the form and path"
    bag = Bag(tmp_path / "messages.mcap")
    columns = cdr.decode(cdr.CONTACT_STATE, bag.rows("/c/state")[2])
    assert columns is not None
    np.testing.assert_array_equal(columns["force"], state["force"])
    np.testing.assert_array_equal(columns["scale_separation_ok"], state["scale_separation_ok"])


def test_messages_refuse_bad_columns_before_writing(tmp_path: Path) -> None:
    path = tmp_path / "bad.mcap"
    stamps = np.arange(3)
    with pytest.raises(KeyError, match="no field"):
        write_columns(
            path, [TopicData("/w", cdr.WRENCH, stamps, cdr.Messages(cdr.WRENCH, stamps, "f", {"x": 1}))]
        )
    with pytest.raises(ValueError, match=">= 0"):
        write_columns(
            path, [TopicData("/w", cdr.WRENCH, stamps, cdr.Messages(cdr.WRENCH, stamps - 5, "f", {}))]
        )
    assert not path.exists()


def test_empty_topics(tmp_path: Path) -> None:
    path = tmp_path / "empty.mcap"
    empty = np.zeros(0, np.int64)
    write_columns(
        path,
        [
            TopicData("/c/state", cdr.CONTACT_STATE, empty, cdr.Messages(cdr.CONTACT_STATE, empty, "f", {})),
            TopicData("/c/wrench", cdr.WRENCH, empty, cdr.encode_array(cdr.WRENCH, empty, "f", {})),
        ],
    )
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        assert list(reader.iter_messages()) == []
        assert {c.topic for c in reader.get_summary().channels.values()} == {"/c/state", "/c/wrench"}


def test_decode_only_the_fields_asked() -> None:
    stamps = 5_000_000_000 + np.arange(4)
    rows = cdr.encode_array(
        cdr.WRENCH, stamps, "f", {"wrench.force.z": np.arange(4.0), "wrench.torque.x": 2.0}
    )
    full = cdr.decode(cdr.WRENCH, rows)
    some = cdr.decode(cdr.WRENCH, rows, ["wrench.force.z"])
    assert full is not None and some is not None
    assert set(some) == {"wrench.force.z", "stamp_ns"}
    for name in some:
        np.testing.assert_array_equal(some[name], full[name])
    with pytest.raises(KeyError, match="no field"):
        cdr.decode(cdr.WRENCH, rows, ["wrench.force.w"])


def test_crc32_combine_equals_zlib() -> None:
    import random
    import zlib

    from viscoadh_ros.io.mcap_bulk import crc32_combine

    rng = random.Random(5)
    for first, second in [(0, 0), (0, 7), (7, 0), (1, 1), (100, 1000), (3, 1 << 20), (12345, 999_999)]:
        a, b = rng.randbytes(first), rng.randbytes(second)
        assert crc32_combine(zlib.crc32(a), zlib.crc32(b), second) == zlib.crc32(a + b)
        start = rng.randrange(1 << 32)  # a CRC running on from earlier bytes
        assert crc32_combine(zlib.crc32(a, start), zlib.crc32(b), second) == zlib.crc32(a + b, start)
    # A wrong length gives another CRC (the shift is not a no-op).
    a, b = rng.randbytes(50), rng.randbytes(60)
    assert crc32_combine(zlib.crc32(a), zlib.crc32(b), 61) != zlib.crc32(a + b)
