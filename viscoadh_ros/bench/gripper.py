"""Real-time factor of the MuJoCo gripper cell (`viscoadh gripper`), library and node path.

The scene: the built-in cell (config/gripper_cell.yaml) with 1, 4 and 16 pads (1x1, 2x2, 4x4),
a part of 1 g per pad (the default time step resolves a part of about 0.5 g per pad pressed
150 um, `cycle.stability_number`; a 16-pad array on a 1 g part would need a step 4 times
shorter), grown by `GripperConfig.with_pads` to carry the array. The run is the start of the
standard pick (`scenarios.GOOD`): approach, touch, press and hold, ``seconds`` of simulated
time, so every pad is in contact for most of it. Per pad count the library path (`LibraryPads`)
and the node path (`NodePads`: the in-process node over DDS, lockstep on /clock) run the same
`run_cycle` alternately, ``repeats`` times each; the real-time factor is simulated time over
the median wall time (above 1: faster than real time). The node's start-up is not timed.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import replace
from typing import Any

#: Part mass per pad, kg (see the module docstring: stability at the default time step).
MASS_PER_PAD = 1.0e-3


def bench_cell(rows: int, columns: int):
    """The built-in cell with a rows x columns pad array and a part of MASS_PER_PAD per pad."""
    from viscoadh_ros.gripper.config import default_cell_path, load_cell

    cell = load_cell(default_cell_path())
    gripper = cell.gripper.with_pads(rows, columns)
    return replace(cell, gripper=gripper.with_part_mass(MASS_PER_PAD * rows * columns))


def gripper_benchmark(*, pads: tuple[int, ...], seconds: float, repeats: int) -> list[dict[str, Any]]:
    """One row per pad count (each a square number: n x n pads): pads, simulated seconds,
    physics steps, and for each path its median wall time (s) and real-time factor."""
    from viscoadh_ros.gripper.cycle import run_cycle
    from viscoadh_ros.gripper.node_loop import NodePads
    from viscoadh_ros.gripper.pads import LibraryPads
    from viscoadh_ros.gripper.scenarios import GOOD

    rows_out = []
    for count in pads:
        side = math.isqrt(count)
        if side * side != count:
            raise ValueError(f"gripper bench: {count} pads is not a square array")
        cell = bench_cell(side, side)
        walls: dict[str, list[float]] = {"library": [], "node": []}
        steps = 0
        for _ in range(repeats):
            for path in ("library", "node"):
                # A fresh bank per run (a node's contacts cannot go back in time); the node's
                # start-up happens before the clock starts.
                bank = LibraryPads(cell.pad, count) if path == "library" else NodePads(cell)
                try:
                    begin = time.perf_counter()
                    trajectory = run_cycle(cell, GOOD, bank, duration=seconds)
                    walls[path].append(time.perf_counter() - begin)
                finally:
                    bank.close()
                steps = trajectory.time.size
        simulated = steps * cell.gripper.timestep
        row: dict[str, Any] = {
            "pads": count,
            "part_mass_kg": cell.gripper.part.mass,
            "sim_s": simulated,
            "steps": steps,
        }
        for path, values in walls.items():
            wall = statistics.median(values)
            row[f"{path}_wall_s"] = wall
            row[f"{path}_rtf"] = simulated / wall
        rows_out.append(row)
    return rows_out
