"""Soak: the node under 1 kHz commands on 8 contacts with MCAP logging on, for minutes.

Reports the node's memory growth (resident set, median of the last tenth of the run against
the first tenth after warm-up), the commands that got no state back, the p99 round trip of
the first and last windows and its drift, and how many commands the node's log holds.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from viscoadh_ros.bench.latency import bench_scene, measure_round_trips, write_scene

SOAK_CONTACTS = 8
SOAK_RATE_HZ = 1000.0
WARMUP_S = 2.0


def logged_commands(log_path: Path) -> int:
    """Number of IndentationCommand messages in the node's MCAP log (a file or a folder)."""
    from viscoadh_ros.io.bag import Bag

    bag = Bag(log_path, recover=True)
    return sum(bag.message_count(topic) for topic in bag.topics if topic.endswith("/indentation"))


def soak(
    *,
    minutes: float,
    contacts: int = SOAK_CONTACTS,
    rate_hz: float = SOAK_RATE_HZ,
    domain_id: int | None = None,
) -> dict[str, Any]:
    """The `soak` results section (see the module docstring); `domain_id` None picks one."""
    duration = minutes * 60.0
    with tempfile.TemporaryDirectory(prefix="viscoadh_soak_") as tmp:
        log_path = Path(tmp) / "soak.mcap"
        scene, amplitude = bench_scene(contacts, log_path=log_path)
        scene_path = write_scene(scene, Path(tmp) / "scene.yaml")
        trips = measure_round_trips(
            "node",
            contact_ids=scene["/**"]["ros__parameters"]["contacts"],
            duration_s=duration,
            rate_hz=rate_hz,
            depth_amplitude=amplitude,
            scene_path=scene_path,
            warmup_s=WARMUP_S,
            domain_id=domain_id,
        )
        logged = logged_commands(log_path)
    measured = trips.rss_time_s >= trips.startup_s + WARMUP_S
    rss = trips.rss_bytes[measured]
    tenth = max(1, rss.size // 10)
    first, last = float(np.median(rss[:tenth])), float(np.median(rss[-tenth:]))
    window = max(5.0, duration / 10.0)
    p99 = trips.window_p99_ms(window)
    return {
        "minutes": minutes,
        "contacts": contacts,
        "rate_hz": rate_hz,
        "commands_sent": int(trips.latency_s.size),
        "dropped": trips.dropped,
        "logged_commands": logged,
        "rss_start_mb": first / 1e6,
        "rss_end_mb": last / 1e6,
        "memory_growth": (last - first) / first,
        "window_s": window,
        "p99_first_window_ms": p99[0],
        "p99_last_window_ms": p99[-1],
        "p99_drift": (p99[-1] - p99[0]) / p99[0],
        "deadline_miss_fraction": trips.deadline_miss_fraction(1.0 / rate_hz),
    }
