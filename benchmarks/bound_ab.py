"""Every step bounded, side by side: the bench's bounded-step scene (the default contact, a
3000-row sine at 1 kHz, depth control) stepped by an old checkout's core and this checkout's
core in one process, interleaved, per step the median over the repeats; asserts both give
the same forces and contact radii bit for bit.

    mkdir /tmp/old_core && git -C /work/main archive main | tar -x -C /tmp/old_core
    .venv/bin/python benchmarks/bound_ab.py /tmp/old_core [repeats]
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
roots = {"old": os.path.abspath(sys.argv[1]), "new": here}
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 7
cores = {}
for label, root in roots.items():
    for key in [key for key in sys.modules if key.startswith("viscoadh_ros")]:
        del sys.modules[key]
    sys.path.insert(0, root)
    from viscoadh_ros.bench.kernel import _scene_history
    from viscoadh_ros.core import _kernels, simulator
    from viscoadh_ros.core.config import SceneConfig, default_scene_path

    assert _kernels.__file__.startswith(root), _kernels.__file__
    _kernels.warm_up()
    cores[label] = (simulator, SceneConfig.from_yaml(default_scene_path()).contacts[0])
    sys.path.remove(root)

times, depths = _scene_history(3.0)
costs: dict[str, list[np.ndarray]] = {label: [] for label in cores}
outputs = {}
clock = time.perf_counter
for run in range(repeats + 1):  # run 0 loads the kernels
    for label, (module, contact) in cores.items():
        sim = module.ContactSimulator(contact)
        cost = np.empty(times.size)
        values = np.empty((times.size, 2))
        for index in range(times.size):
            start = clock()
            out = sim.step(float(times[index]), depth=float(depths[index]))
            cost[index] = clock() - start
            values[index] = out.force, out.contact_radius
        if run:
            costs[label].append(cost)
        outputs[label] = values
assert outputs["old"].tobytes() == outputs["new"].tobytes(), "the outputs differ"

median = {label: np.median(np.array(runs), axis=0) for label, runs in costs.items()}
print(f"{times.size} rows, per step the median of {repeats} interleaved runs; outputs bit-equal")
print("| per step | old | new | new/old |")
print("|---|---|---|---|")


def line(name, pick):
    old, new = pick(median["old"]), pick(median["new"])
    print(f"| {name} | {old:.1f} | {new:.1f} | {new / old:.2f} |")


line("median, us", lambda c: np.median(c) * 1e6)
line("p99, us", lambda c: np.percentile(c, 99.0) * 1e6)
line("max, us", lambda c: c.max() * 1e6)
line("max / median", lambda c: c.max() / np.median(c))
for label, cost in median.items():
    worst = np.argsort(cost)[::-1][:5]
    rows = ", ".join(f"{int(i)}: {cost[i] * 1e6:.0f} us" for i in worst)
    print(f"{label}: worst rows {rows}")
