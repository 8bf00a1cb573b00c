"""The snap-in and pull-off rows of the bench's bounded-step scene, old core against this one,
side by side in one process: each core steps the scene (default contact, 3000-row sine at
1 kHz, depth control) up to the row, then the row's `step` is timed from a copy of that
simulator (`copy.deepcopy`, the row created for the snap-in as the first contact creates it)
and the row's compiled `_kernels.advance` alone on a copy of its row, the cores interleaved,
per core the median of the repeats; the substeps each took and the force each gave.

    mkdir /tmp/old_core && git -C /work/main archive main | tar -x -C /tmp/old_core
    .venv/bin/python benchmarks/snap_ab.py /tmp/old_core [repeats]
"""

from __future__ import annotations

import copy
import os
import sys
import time

import ab_cores
import numpy as np

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
roots = {"old": os.path.abspath(sys.argv[1]), "new": here}
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 41
cores = {}
for label, root in roots.items():
    # The old core's kernels under their own module name (ab_cores says why).
    core = ab_cores.load(root, rename_kernels=label == "old")
    contact = core["config"].SceneConfig.from_yaml(core["config"].default_scene_path()).contacts[0]
    cores[label] = (core["simulator"], core["kernels"], contact)
_scene_history = core["bench_kernel"]._scene_history

times, depths = _scene_history(3.0)
radius = cores["old"][0].ContactSimulator(cores["old"][2]).step_depths(times, depths)["contact_radius"]
rows = {
    "snap-in": int(np.flatnonzero(radius > 0.0)[0]),
    "pull-off": int(np.flatnonzero((radius[:-1] > 0.0) & (radius[1:] <= 0.0))[0]) + 1,
}
clock = time.perf_counter
print(f"per core the median of {repeats} interleaved repeats, us")
print("| row | what | old | new | new/old | substeps old -> new | force old, new (N) |")
print("|---|---|---|---|---|---|---|")
for name, index in rows.items():
    before = {}
    for label, (module, _, contact) in cores.items():
        sim = module.ContactSimulator(contact)
        for i in range(index):
            sim.step(float(times[i]), depth=float(depths[i]))
        before[label] = sim
    step_cost = {label: [] for label in cores}
    kernel_cost = {label: [] for label in cores}
    result = {}
    for _ in range(repeats):
        for label, (_, kernels, _) in cores.items():
            sim = copy.deepcopy(before[label])
            start = clock()
            out = sim.step(float(times[index]), depth=float(depths[index]))
            step_cost[label].append(clock() - start)
            model = before[label]._model
            template = model.row if model.row is not None else model._template
            row = template.with_memory(template.wl.copy(), template.wb.copy())
            start = clock()
            kernels.advance(
                row,
                model.radius,
                float(depths[index - 1]),
                float(depths[index]),
                float(times[index] - times[index - 1]),
                max_substep=model._max_substep,
                max_edge_move=model._max_edge_cells * row.dx,
            )
            kernel_cost[label].append(clock() - start)
            result[label] = (int(row.out[kernels.OUT_SUBSTEPS]), out.force)
    for what, cost in (("`step`", step_cost), ("`_kernels.advance`", kernel_cost)):
        old, new = np.median(cost["old"]) * 1e6, np.median(cost["new"]) * 1e6
        subs = f"{result['old'][0]} -> {result['new'][0]}"
        forces = f"{result['old'][1]:.9g}, {result['new'][1]:.9g}"
        print(f"| {name} {index} | {what} | {old:.1f} | {new:.1f} | {new / old:.2f} | {subs} | {forces} |")
