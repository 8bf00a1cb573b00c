"""The large-N scene's racing rows side by side (0.10.0 round `race`): an old checkout's core
and this checkout's in one process, interleaved, per row the median over the repeats, for the
snap-in row, the rows where the edge races on while pressed, and the pull-off row (the
`bound_scenes_ab.py` large scene: `bench.kernel.LARGE_SCENE`, 8192 elements, K = 2, depth
control). Prints each core's median row, the listed rows, their ratios to the median, and
whether the outputs (force, radius) are equal bit for bit.

    .venv/bin/python benchmarks/race_rows_ab.py /work/ab/base [repeats] [rows]
"""

from __future__ import annotations

import os
import sys
import time

import ab_cores
import numpy as np

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
roots = {"old": os.path.abspath(sys.argv[1]), "new": here}
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
rows = [int(r) for r in sys.argv[3].split(",")] if len(sys.argv) > 3 else [0, 1, 2, 6, 8, 63, 64]
cores = {}
for label, root in roots.items():
    core = ab_cores.load(root, rename_kernels=label == "old")
    config, bench = core["config"], core["bench_kernel"]
    large = config.SceneConfig.from_dict({"contacts": ["c"], "c": bench.LARGE_SCENE}).contact("c")
    cores[label] = (core["simulator"], large)
bench = ab_cores.load(here, rename_kernels=False)["bench_kernel"]
times, depths = bench._large_scene_history()
costs = {label: [] for label in cores}
outputs = {}
clock = time.perf_counter
for run in range(repeats + 1):  # run 0 loads the kernels
    for label, (module, contact) in cores.items():
        sim = module.ContactSimulator(contact)
        cost = np.empty(times.size)
        out = np.empty((times.size, 2))
        for index in range(times.size):
            start = clock()
            step = sim.step(float(times[index]), depth=float(depths[index]))
            cost[index] = clock() - start
            out[index] = step.force, step.contact_radius
        if run:
            costs[label].append(cost)
        outputs[label] = out
median = {label: np.median(np.array(runs), axis=0) * 1e6 for label, runs in costs.items()}
print(f"large scene, per row the median of {repeats} interleaved runs, us (ratio to the scene's median row)")
print("| row | " + " | ".join(cores) + " |")
print("|---|" + "---|" * len(cores))
print("| median | " + " | ".join(f"{np.median(median[label]):.1f}" for label in cores) + " |")
for row in rows:
    cells = []
    for label in cores:
        m = np.median(median[label])
        cells.append(f"{median[label][row]:.0f} ({median[label][row] / m:.1f}x)")
    print(f"| {row} | " + " | ".join(cells) + " |")
equal = np.array_equal(outputs["old"].view(np.int64), outputs["new"].view(np.int64))
print("outputs (force, radius) equal bit for bit:", equal)
