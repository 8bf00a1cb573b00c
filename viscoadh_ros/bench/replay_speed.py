"""Replay speed: `viscoadh replay` over a recorded 1 kHz command stream, and where the time goes.

The recording is made here with the project's own MCAP writer: the node's log format, one
contact of the bench scene (default numerics), an `IndentationCommand` and a measured
`WrenchStamped` per millisecond, the scene stored in the file. The whole `viscoadh replay` run
is timed (realtime factor = recorded duration / wall time), and beside it its stages with the
same public functions the verb uses: decode (open the bag, read the experiment), simulate
(`run_model`), encode and compare (the rest of the verb: building and writing the output MCAP
and the force comparison).
"""

from __future__ import annotations

import contextlib
import io
import math
import tempfile
from pathlib import Path
from typing import Any

from viscoadh_ros.bench.latency import bench_scene
from viscoadh_ros.bench.timing import interleaved_medians
from viscoadh_ros.core.config import SceneConfig

RATE_HZ = 1000.0
CYCLE_S = 2.0  # the latency client's depth cycle, so replay sees the same motion as the node


def record_stream(path: Path, seconds: float) -> SceneConfig:
    """Write a node-style MCAP log of `seconds` of 1 kHz depth commands and measured wrenches.

    The measured force is zero (any force serves for timing); returns the scene.
    """
    from geometry_msgs.msg import WrenchStamped
    from viscoadh_msgs.msg import IndentationCommand

    from viscoadh_ros.io.mcap_log import McapRecorder

    scene_map, amplitude = bench_scene(1)
    scene = SceneConfig.from_dict(scene_map)
    contact_id = scene.contacts[0].id
    count = max(2, round(seconds * RATE_HZ))
    recorder = McapRecorder(path, scene=scene.to_dict(), queue_size=2 * count + 16)
    for index in range(count):
        stamp_ns = 1_000_000_000 + index * 1_000_000
        sec, nanosec = divmod(stamp_ns, 1_000_000_000)
        phase = 0.5 - 0.5 * math.cos(2.0 * math.pi * index / RATE_HZ / CYCLE_S)
        command = IndentationCommand(mode=IndentationCommand.DEPTH, depth=amplitude * (1.2 * phase - 0.2))
        command.header.stamp.sec, command.header.stamp.nanosec = sec, nanosec
        wrench = WrenchStamped()
        wrench.header.stamp = command.header.stamp
        wrench.wrench.force.z = 0.0
        recorder.record(f"/{contact_id}/indentation", command, stamp_ns)
        recorder.record(f"/{contact_id}/wrench", wrench, stamp_ns)
    recorder.close()
    if recorder.error is not None or recorder.dropped:
        raise RuntimeError(
            f"recording the replay input failed: {recorder.error!r}, {recorder.dropped} dropped"
        )
    return scene


def replay_benchmark(*, seconds: float, repeats: int) -> dict[str, Any]:
    """The `replay` results section: realtime factor and the share of decode/simulate/encode."""
    from viscoadh_ros.cli.main import main as cli_main
    from viscoadh_ros.experiment import choose_contact, load_experiment, run_model
    from viscoadh_ros.io.bag import Bag

    with tempfile.TemporaryDirectory(prefix="viscoadh_bench_") as tmp:
        bag_path = Path(tmp) / "stream.mcap"
        scene = record_stream(bag_path, seconds)
        out_path = Path(tmp) / "replayed.mcap"
        experiment = load_experiment(Bag(bag_path))
        contact = choose_contact(scene, None)

        def whole() -> None:
            with contextlib.redirect_stdout(io.StringIO()):
                status = cli_main(["replay", str(bag_path), "-o", str(out_path)])
            if status != 0:
                raise RuntimeError(f"viscoadh replay exited with status {status}")

        whole()  # imports and compiled code loaded once, outside the timing
        times = interleaved_medians(
            {
                "total": whole,
                "decode": lambda: load_experiment(Bag(bag_path)),
                "simulate": lambda: run_model(contact, experiment),
            },
            repeats=repeats,
        )
    duration = float(experiment.duration)
    # The stages are timed apart from the whole run, so noise can make them add up to a little
    # more than it: shares are of their sum, with encode the non-negative remainder.
    stages = {
        "decode": times["decode"],
        "simulate": times["simulate"],
        "encode and compare": max(0.0, times["total"] - times["decode"] - times["simulate"]),
    }
    stage_sum = sum(stages.values())
    return {
        "commands": int(experiment.input_ns.size),
        "recorded_s": duration,
        "wall_s": times["total"],
        "realtime_factor": duration / times["total"],
        "simulate_realtime_factor": duration / times["simulate"],
        "us_per_command": times["total"] / experiment.input_ns.size * 1e6,
        "time_share": {stage: seconds / stage_sum for stage, seconds in stages.items()},
    }
