"""Every step bounded, side by side: the bench's bounded-step scene (the default contact, a
3000-row sine at 1 kHz, depth control, then force control on the forces the depth run
produced) stepped by an old checkout's core and this checkout's core in one process,
interleaved, per step the median over the repeats. Reports the largest difference of the
forces and contact radii (relative to each one's largest value; 0: bit for bit).

    mkdir /tmp/old_core && git -C /work/main archive main | tar -x -C /tmp/old_core
    .venv/bin/python benchmarks/bound_ab.py /tmp/old_core [repeats]
"""

from __future__ import annotations

import os
import sys
import time

import ab_cores
import numpy as np

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
roots = {"old": os.path.abspath(sys.argv[1]), "new": here}
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 7
cores = {}
for label, root in roots.items():
    # The old core's kernels under their own module name (ab_cores says why).
    core = ab_cores.load(root, rename_kernels=label == "old")
    contact = core["config"].SceneConfig.from_yaml(core["config"].default_scene_path()).contacts[0]
    cores[label] = (core["simulator"], contact)
_scene_history = core["bench_kernel"]._scene_history

times, depths = _scene_history(3.0)
modes = ("depth", "force")
costs: dict[tuple[str, str], list[np.ndarray]] = {(label, m): [] for label in cores for m in modes}
outputs = {}
clock = time.perf_counter
forces = {}
for label, (module, contact) in cores.items():
    forces[label] = module.ContactSimulator(contact).step_depths(times, depths)["force"]
for run in range(repeats + 1):  # run 0 loads the kernels
    for label, (module, contact) in cores.items():
        for mode in modes:
            sim = module.ContactSimulator(contact)
            command = depths if mode == "depth" else forces[label]
            cost = np.empty(times.size)
            values = np.empty((times.size, 2))
            for index in range(times.size):
                start = clock()
                out = sim.step(float(times[index]), **{mode: float(command[index])})
                cost[index] = clock() - start
                values[index] = out.force, out.contact_radius
            if run:
                costs[(label, mode)].append(cost)
            outputs[(label, mode)] = values

median = {key: np.median(np.array(runs), axis=0) for key, runs in costs.items()}
old_d, new_d = outputs[("old", "depth")], outputs[("new", "depth")]
radius = old_d[:, 1]
snap_in = int(np.flatnonzero(radius > 0.0)[0])
pull_off = int(np.flatnonzero((radius[:-1] > 0.0) & (radius[1:] <= 0.0))[0]) + 1
print(f"{times.size} rows, per step the median of {repeats} interleaved runs")
for mode in modes:
    a, b = outputs[("old", mode)], outputs[("new", mode)]
    diff = [float(np.max(np.abs(a[:, c] - b[:, c])) / np.max(np.abs(a[:, c]))) for c in range(2)]
    print(
        f"{mode} control: largest |new - old| over the largest value: force {diff[0]:.2g}, "
        f"radius {diff[1]:.2g}"
    )
print("| per step | old | new | new/old |")
print("|---|---|---|---|")


def line(name, pick, mode="depth"):
    old, new = pick(median[("old", mode)]), pick(median[("new", mode)])
    print(f"| {name} | {old:.1f} | {new:.1f} | {new / old:.2f} |")


line("depth median, us", lambda c: np.median(c) * 1e6)
line("depth p99, us", lambda c: np.percentile(c, 99.0) * 1e6)
line("depth max, us", lambda c: c.max() * 1e6)
line("depth max / median", lambda c: c.max() / np.median(c))
line(f"snap-in row {snap_in}, us", lambda c: c[snap_in] * 1e6)
line(f"pull-off row {pull_off}, us", lambda c: c[pull_off] * 1e6)
line("force median, us", lambda c: np.median(c) * 1e6, "force")
line("force mean, us", lambda c: np.mean(c) * 1e6, "force")
line("force p99, us", lambda c: np.percentile(c, 99.0) * 1e6, "force")
line("force max, us", lambda c: c.max() * 1e6, "force")
for label in cores:
    d, f = median[(label, "depth")], median[(label, "force")]
    print(
        f"{label}: force/depth mean {np.mean(f) / np.mean(d):.2f}x, p99 "
        f"{np.percentile(f, 99.0) / np.percentile(d, 99.0):.2f}x"
    )
for (label, mode), cost in median.items():
    worst = np.argsort(cost)[::-1][:5]
    rows = ", ".join(f"{int(i)}: {cost[i] * 1e6:.0f} us" for i in worst)
    print(f"{label} {mode}: worst rows {rows}")
