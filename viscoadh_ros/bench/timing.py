"""Small timing helpers shared by the benchmarks: median of repeats and latency percentiles."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np


def median_seconds(run: Callable[[], object], *, repeats: int) -> float:
    """Median wall time of `repeats` calls of `run`, s.

    The median, not the minimum or the mean, because on a shared machine a few repeats are hit by
    other work and the median ignores them while still describing a typical run.
    """
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        samples.append(time.perf_counter() - start)
    return float(np.median(samples))


def interleaved_medians(runs: dict[str, Callable[[], object]], *, repeats: int) -> dict[str, float]:
    """Median wall time of each named run, s, with the runs interleaved repeat by repeat.

    Interleaving puts a burst of load from elsewhere on the machine onto all runs alike, so
    their ratio stays meaningful on a shared machine where absolute times drift.
    """
    samples = interleaved_samples(runs, repeats=repeats)
    return {name: float(np.median(values)) for name, values in samples.items()}


def interleaved_samples(runs: dict[str, Callable[[], object]], *, repeats: int) -> dict[str, list[float]]:
    """Every wall time of each named run, s, the runs interleaved repeat by repeat (see
    :func:`interleaved_medians`), for a caller that pairs them with what it measured inside."""
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    samples: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.perf_counter()
            run()
            samples[name].append(time.perf_counter() - start)
    return samples


def latency_summary(latencies_s: Sequence[float], *, prefix: str) -> dict[str, float]:
    """p50/p99/p99.9 of round-trip times given in seconds, reported in ms as `<prefix>_p50_ms`...

    An empty sample raises: reporting zeros would hide a run in which nothing came back.
    """
    if len(latencies_s) == 0:
        raise ValueError(f"no round trips measured for {prefix!r}")
    ms = np.asarray(latencies_s, dtype=np.float64) * 1e3
    p50, p99, p999 = np.percentile(ms, [50.0, 99.0, 99.9])
    return {
        f"{prefix}_p50_ms": float(p50),
        f"{prefix}_p99_ms": float(p99),
        f"{prefix}_p999_ms": float(p999),
    }
