"""The bounded-step scenes side by side: an old checkout's core and this checkout's core in
one process, interleaved, per row the median over the repeats: the bench's depth sine and
the force control on its forces (default scene), the gripper's hold-and-pull under force
control, and the large-N press and pull (8192 elements, depth control). Reports each scene's
median, largest row and their ratio, and the largest output differences: forces relative to
the scene's pull-off force (the adhesive force scale), radii to the largest radius, depths to
the largest depth. ``AB_ROWS=59,60,61`` also prints those rows of the depth scene.

    git worktree add --detach /tmp/old_core <commit>
    .venv/bin/python benchmarks/bound_scenes_ab.py /tmp/old_core [repeats]

Beware (0.9.0): the rows that build a domain (the snap-in and the rows after it, ~80 us) run
10-30 us slower in whichever core steps second in an iteration, also with the roles swapped
(benchmarks/rounds/0.9.0-lead.md): compare those rows both ways round before reading a change
into them.
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
cores = {}
for label, root in roots.items():
    core = ab_cores.load(root, rename_kernels=label == "old")
    config, bench = core["config"], core["bench_kernel"]
    default = config.SceneConfig.from_yaml(config.default_scene_path()).contacts[0]
    large = config.SceneConfig.from_dict({"contacts": ["c"], "c": bench.LARGE_SCENE}).contact("c")
    cores[label] = (core["simulator"], default, large, bench)

bench = cores["new"][3]
times, depths = bench._scene_history(bench.SCENE_SECONDS)
hold_times, hold_forces = bench.hold_pull_forces()
large_times, large_depths = bench._large_scene_history()
scenes = {}
for label, (module, default, large, _) in cores.items():
    forces = module.ContactSimulator(default).step_depths(times, depths)["force"]
    scenes[label] = {
        "depth": (default, times, depths, "depth"),
        "force": (default, times, forces, "force"),
        "hold_pull": (default, hold_times, hold_forces, "force"),
        "large": (large, large_times, large_depths, "depth"),
    }
names = ("depth", "force", "hold_pull", "large")
costs: dict[tuple[str, str], list[np.ndarray]] = {(label, name): [] for label in cores for name in names}
outputs = {}
clock = time.perf_counter
for run in range(repeats + 1):  # run 0 loads the kernels
    for name in names:
        for label, (module, *_rest) in cores.items():
            contact, at, values, key = scenes[label][name]
            sim = module.ContactSimulator(contact)
            cost = np.empty(at.size)
            rows = np.empty((at.size, 3))
            for index in range(at.size):
                start = clock()
                out = sim.step(float(at[index]), **{key: float(values[index])})
                cost[index] = clock() - start
                rows[index] = out.force, out.contact_radius, out.depth
            if run:
                costs[(label, name)].append(cost)
            outputs[(label, name)] = rows

median = {key: np.median(np.array(runs), axis=0) for key, runs in costs.items()}


def relative(a: np.ndarray, b: np.ndarray, scale: float) -> float:
    return float(np.max(np.abs(a - b)) / scale)


print(f"per row the median of {repeats} interleaved runs")
print(
    "| scene | median us (old, new) | max us (old, new) | max / median (old, new) "
    "| max dF / pull-off | max da / a_max | max d(depth) / depth_max |"
)
print("|---|---|---|---|---|---|---|")
for name in names:
    old, new = median[("old", name)], median[("new", name)]
    a, b = outputs[("old", name)], outputs[("new", name)]
    df = relative(a[:, 0], b[:, 0], abs(np.min(a[:, 0])))
    da = relative(a[:, 1], b[:, 1], np.max(np.abs(a[:, 1])))
    dd = relative(a[:, 2], b[:, 2], np.max(np.abs(a[:, 2])))
    print(
        f"| {name} | {np.median(old) * 1e6:.2f}, {np.median(new) * 1e6:.2f} "
        f"| {old.max() * 1e6:.0f} (row {int(old.argmax())}), {new.max() * 1e6:.0f} (row {int(new.argmax())}) "
        f"| {old.max() / np.median(old):.1f}, {new.max() / np.median(new):.1f} "
        f"| {df:.2g} | {da:.2g} | {dd:.2g} |"
    )
for label in cores:
    d, f = median[(label, "depth")], median[(label, "force")]
    mean = np.mean(f) / np.mean(d)
    p99 = np.percentile(f, 99.0) / np.percentile(d, 99.0)
    print(f"{label}: force/depth mean {mean:.2f}x, p99 {p99:.2f}x")
for row in [int(r) for r in os.environ.get("AB_ROWS", "").split(",") if r]:
    old, new = median[("old", "depth")][row], median[("new", "depth")][row]
    print(f"depth row {row}: old {old * 1e6:.1f} us, new {new * 1e6:.1f} us")
