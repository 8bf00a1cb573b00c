"""The benchmark plan of `viscoadh bench`: which sizes each section runs at, quick or full."""

from __future__ import annotations

import datetime
import os
import platform
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

SECTIONS = ("kernel", "bound", "accuracy", "node", "replay", "batch", "gripper", "fit")
#: The results keys each section writes (the soak is asked for by --soak, not --sections); a
#: merge replaces exactly these.
SECTION_KEYS = {
    "kernel": ("kernel",),
    "bound": ("step_costs",),
    "accuracy": ("accuracy", "presets", "tolerance"),
    "node": ("node", "startup_s"),
    "replay": ("replay",),
    "batch": ("batch",),
    "gripper": ("gripper",),
    "fit": ("fit",),
    "soak": ("soak",),
}
#: Top-level keys that describe the run the report header names.
RUN_KEYS = ("command", "date", "machine", "quick")


@dataclass(frozen=True)
class Plan:
    """Sizes of one bench run. Quick keeps the whole run under about three minutes."""

    kernel_elements: tuple[int, ...]
    kernel_kelvin: tuple[int, ...]
    kernel_steps: int
    kernel_repeats: int
    accuracy_elements: tuple[int, ...]
    accuracy_rows: tuple[int, ...]
    accuracy_repeats: int
    reference_elements: int
    reference_rows: int
    node_contacts: int
    node_duration_s: float
    replay_seconds: float
    replay_repeats: int
    gripper_pads: tuple[int, ...]
    gripper_seconds: float
    gripper_repeats: int
    batch_bags: int = 12
    batch_seconds: float = 20.0
    batch_workers: tuple[int, ...] = (1, 2)
    fit_samples: int = 5000
    fit_starts: int = 4
    fit_kelvin_starts: int = 1
    accuracy_tolerances: tuple[float, ...] = (1e-2, 1e-3, 1e-4)
    #: A second, longer recording replayed in fresh processes (start-up against length).
    replay_long_seconds: float | None = 600.0


FULL = Plan(
    kernel_elements=(64, 128, 256, 512, 1024, 2048, 4096),
    kernel_kelvin=(0, 1, 4),
    kernel_steps=2000,
    kernel_repeats=7,
    accuracy_elements=(32, 64, 128, 256, 512),
    accuracy_rows=(251, 1001, 4001),
    accuracy_repeats=2,
    reference_elements=1024,
    reference_rows=4001,
    node_contacts=4,
    node_duration_s=30.0,
    replay_seconds=60.0,
    replay_repeats=3,
    gripper_pads=(1, 4, 16),
    gripper_seconds=0.6,
    gripper_repeats=3,
)
QUICK = Plan(
    kernel_elements=(64, 256, 1024, 4096),
    kernel_kelvin=(0, 1, 4),
    kernel_steps=200,
    kernel_repeats=3,
    accuracy_elements=(64, 256),
    accuracy_rows=(251, 1001),
    accuracy_repeats=1,
    reference_elements=512,
    reference_rows=2001,
    node_contacts=4,
    node_duration_s=5.0,
    replay_seconds=10.0,
    replay_repeats=1,
    batch_bags=4,
    batch_seconds=2.0,
    gripper_pads=(1, 4, 16),
    gripper_seconds=0.3,
    gripper_repeats=1,
    fit_samples=1000,
    fit_starts=2,
    fit_kelvin_starts=1,
    accuracy_tolerances=(1e-2, 1e-3),
    replay_long_seconds=60.0,
)


def machine_description() -> str:
    """CPU count, processor and Python of this machine, for the report header."""
    return (
        f"{os.cpu_count()} CPUs, {platform.processor() or platform.machine()}, "
        f"{platform.system()} {platform.release()}, Python {platform.python_version()}"
    )


def run(
    plan: Plan,
    *,
    sections: Sequence[str],
    soak_minutes: float | None,
    command: str,
    contacts: int | None = None,
    hand: bool = False,
    node_log: bool = False,
    progress: Callable[[str], None],
) -> dict[str, Any]:
    """Run the chosen sections (plus the soak when asked) and return the results dictionary.

    Besides the sections' keys (SECTION_KEYS) it holds the run's RUN_KEYS and ``runs``: for
    each section that ran, the same four, so a merge can tell which command measured what.
    """
    unknown = sorted(set(sections) - set(SECTIONS))
    if unknown:
        raise ValueError(f"sections: unknown {', '.join(unknown)} (known: {', '.join(SECTIONS)})")
    results: dict[str, Any] = {
        "command": command,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": machine_description(),
        "quick": plan is QUICK,
    }
    if "kernel" in sections:
        from viscoadh_ros.bench.kernel import kernel_table

        progress("kernel: compiling and timing")
        results["kernel"] = kernel_table(
            elements=plan.kernel_elements,
            kelvin=plan.kernel_kelvin,
            steps=plan.kernel_steps,
            repeats=plan.kernel_repeats,
        )
    if "bound" in sections:
        from viscoadh_ros.bench.kernel import step_costs

        progress("bound: per-step costs on the default scene")
        results["step_costs"] = step_costs(repeats=plan.kernel_repeats)
    if "accuracy" in sections:
        from viscoadh_ros.bench.accuracy import accuracy_grid, preset_table, reference_forces, tolerance_table
        from viscoadh_ros.core.presets import PRESET_NAMES

        progress("accuracy: reference runs")
        references = reference_forces(elements=plan.reference_elements, rows=plan.reference_rows)
        progress("accuracy: grid over elements and steps")
        results["accuracy"] = accuracy_grid(
            references=references,
            preset="balanced",
            elements=plan.accuracy_elements,
            rows=plan.accuracy_rows,
            repeats=plan.accuracy_repeats,
        )
        progress("accuracy: presets")
        results["presets"] = preset_table(
            references=references,
            presets=PRESET_NAMES,
            rows=plan.reference_rows,
            repeats=plan.accuracy_repeats,
        )
        progress("accuracy: tolerance mode")
        results["tolerance"] = tolerance_table(
            references=references,
            tolerances=plan.accuracy_tolerances,
            rows=plan.reference_rows,
            repeats=plan.accuracy_repeats,
        )
    if "node" in sections:
        from viscoadh_ros.bench.latency import node_benchmark

        count = contacts or plan.node_contacts
        progress(
            f"node: {plan.node_duration_s:g} s of 1 kHz commands on {count} contacts"
            f"{' by the hand topic' if hand else ''}{' with logging' if node_log else ''}, node then echo"
        )
        results["node"] = node_benchmark(
            contacts=count, duration_s=plan.node_duration_s, hand=hand, log=node_log
        )
        results["startup_s"] = results["node"]["startup_s"]
    if "replay" in sections:
        from viscoadh_ros.bench.replay_speed import replay_benchmark

        long_seconds = plan.replay_long_seconds
        long_text = f", fresh processes on {long_seconds:g} s too" if long_seconds else ""
        progress(f"replay: {plan.replay_seconds:g} s of 1 kHz commands{long_text}")
        results["replay"] = replay_benchmark(
            seconds=plan.replay_seconds, repeats=plan.replay_repeats, long_seconds=plan.replay_long_seconds
        )
    if "batch" in sections:
        from viscoadh_ros.bench.batch_throughput import batch_benchmark

        progress(f"batch: {plan.batch_bags} bags of {plan.batch_seconds:g} s, workers {plan.batch_workers}")
        results["batch"] = batch_benchmark(
            bags=plan.batch_bags, seconds=plan.batch_seconds, workers=plan.batch_workers
        )
    if "gripper" in sections:
        from viscoadh_ros.bench.gripper import gripper_benchmark

        progress(f"gripper: {plan.gripper_seconds:g} s of the MuJoCo cell, library then node")
        results["gripper"] = gripper_benchmark(
            pads=plan.gripper_pads, seconds=plan.gripper_seconds, repeats=plan.gripper_repeats
        )
    if "fit" in sections:
        from viscoadh_ros.bench.fit_speed import fit_benchmark

        progress(f"fit: {plan.fit_starts} + {plan.fit_kelvin_starts} fits, {plan.fit_samples} samples each")
        results["fit"] = fit_benchmark(
            samples=plan.fit_samples, starts=plan.fit_starts, kelvin_starts=plan.fit_kelvin_starts
        )
    if soak_minutes is not None:
        from viscoadh_ros.bench.soak import SOAK_CONTACTS, soak

        count = contacts or SOAK_CONTACTS
        progress(
            f"soak: {soak_minutes:g} min on {count} contacts{' by the hand topic' if hand else ''} "
            "with logging on, then the echo node as long"
        )
        results["soak"] = soak(minutes=soak_minutes, contacts=count, hand=hand)
    run_info = {key: results[key] for key in RUN_KEYS}
    # A section is known by its first results key (`bound` writes `step_costs`): 0.5.0-0.6.0
    # looked for the section's name, so a `bound` run was never listed and `merge` kept the
    # file's old `step_costs` (BENCHMARKS.md showed 2026-11-22's bound figures until 0.7.0).
    results["runs"] = {name: dict(run_info) for name, keys in SECTION_KEYS.items() if keys[0] in results}
    return results


def is_results(data: Any) -> bool:
    """Whether ``data`` (parsed JSON) looks like a results dictionary that can be merged into."""
    return isinstance(data, dict) and all(key in data for key in RUN_KEYS)


def merge(previous: dict[str, Any], new: dict[str, Any]) -> dict[str, Any]:
    """``previous`` results with every section that ``new`` ran replaced by ``new``'s.

    Sections ``new`` did not run keep their values and their ``runs`` entry (a file written
    before ``runs`` existed counts as one run, its top-level RUN_KEYS; ``previous`` must have
    them, see :func:`is_results`). The header's
    RUN_KEYS become ``new``'s when it ran every section of SECTIONS, else stay ``previous``'s.
    """
    base = {key: previous[key] for key in RUN_KEYS if key in previous}
    runs = {
        name: dict(previous.get("runs", {}).get(name, base))
        for name, keys in SECTION_KEYS.items()
        if keys[0] in previous
    }
    merged = {key: value for key, value in previous.items() if key != "runs"}
    for name in new["runs"]:
        for key in SECTION_KEYS[name]:
            merged.pop(key, None)
            if key in new:
                merged[key] = new[key]
    runs.update(new["runs"])
    if set(SECTIONS) <= set(new["runs"]):
        merged.update({key: new[key] for key in RUN_KEYS})
    merged["runs"] = {name: runs[name] for name in SECTION_KEYS if name in runs}
    return merged
