"""Batch throughput: `viscoadh replay` over an archive of bags on a local Dask cluster, bags per
minute against the number of worker processes.

The archive is made here: ``bags`` node-style logs of ``seconds`` of 1 kHz depth commands each
(`replay_speed.record_stream`). Each worker count runs the whole verb once, as a user would
(``viscoadh replay 'archive/*.mcap' -o OUT --workers N``): the wall time includes starting the
cluster (its own line in the table), the workers' imports and the summary table. The 1-minute
load average before each run is recorded: workers scale only onto idle cores.
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from viscoadh_ros.bench.replay_speed import record_stream


def batch_benchmark(*, bags: int, seconds: float, workers: Sequence[int]) -> dict[str, Any]:
    """The `batch` results section: one row per worker count."""
    from viscoadh_ros.cli.main import main as cli_main

    rows = []
    with tempfile.TemporaryDirectory(prefix="viscoadh_bench_batch_") as tmp:
        archive = Path(tmp) / "archive"
        archive.mkdir()
        for k in range(bags):
            record_stream(archive / f"run_{k:03d}.mcap", seconds)
        for count in workers:
            out = Path(tmp) / f"out_{count}"
            load = os.getloadavg()[0]  # other processes on the machine: scaling needs idle cores
            started = time.perf_counter()
            with contextlib.redirect_stdout(io.StringIO()):
                status = cli_main(
                    ["replay", str(archive / "*.mcap"), "-o", str(out), "--workers", str(count)]
                )
            wall = time.perf_counter() - started
            if status != 0:
                raise RuntimeError(f"viscoadh replay (batch, {count} workers) exited with status {status}")
            rows.append(
                {
                    "workers": count,
                    "bags": bags,
                    "wall_s": wall,
                    "bags_per_minute": 60.0 * bags / wall,
                    "cluster_start_s": _cluster_start(count),
                    "load_average_1min": load,
                }
            )
    return {"bags": bags, "seconds_per_bag": seconds, "rows": rows}


def _cluster_start(workers: int) -> float:
    """Seconds to start and stop an empty LocalCluster of ``workers`` processes (the fixed cost
    inside each batch's wall time)."""
    from viscoadh_ros import batch

    started = time.perf_counter()
    client, cluster = batch.connect(workers, None)
    client.close()
    cluster.close()
    return time.perf_counter() - started
