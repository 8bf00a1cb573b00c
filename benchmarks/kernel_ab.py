"""Side-by-side per-step cost of two checkouts on the default scene (issue 13's before/after).

    .venv/bin/python benchmarks/kernel_ab.py <checkout root>

Drives the built-in default contact (balanced, N = 160, K = 1) through a 3 s, 80 um sine at
1 kHz (snap-in, sticking, pull-off, out of contact with memory left) with `step(depth=)`,
then `step_depths`, then `step(force=)` on the forces of the depth run; prints median, mean,
p99 and max per step and the worst rows. Run it alternately on the old and the new checkout
(e.g. a `git archive` of main unpacked under /tmp) and compare only ratios from one sitting.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

root = sys.argv[1]
sys.path.insert(0, root)

import viscoadh_ros  # noqa: E402

assert viscoadh_ros.__file__.startswith(root), viscoadh_ros.__file__

from viscoadh_ros.core import _kernels  # noqa: E402
from viscoadh_ros.core.config import SceneConfig  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

_kernels.warm_up()
contact = SceneConfig.from_yaml(root + "/config/default.yaml").contact("finger")
t = np.arange(1, 3001) * 1e-3
d = 80e-6 * np.sin(2 * math.pi * t / 3.0) - 10e-6


def per_step(key: str, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    sim = ContactSimulator(contact)
    sim.step(0.0, depth=-20e-6)
    cost, force = np.empty(t.size), np.empty(t.size)
    for i in range(t.size):
        start = time.perf_counter()
        out = sim.step(float(t[i]), **{key: float(values[i])})
        cost[i] = time.perf_counter() - start
        force[i] = out.force
    return cost, force


per_step("depth", d)  # loads the kernels
cost, force = per_step("depth", d)
median = np.median(cost)
print(
    f"depth: median {median * 1e6:.1f} us mean {cost.mean() * 1e6:.1f} p99 "
    f"{np.percentile(cost, 99) * 1e6:.1f} max {cost.max() * 1e6:.0f} us; max/median {cost.max() / median:.0f}"
)
print("  worst rows", [(int(i), round(cost[i] * 1e6)) for i in np.argsort(cost)[-5:]])
sim = ContactSimulator(contact)
sim.step(0.0, depth=-20e-6)
start = time.perf_counter()
columns = sim.step_depths(t, d)
print(f"step_depths: {(time.perf_counter() - start) / t.size * 1e6:.2f} us/row")
force_cost, _ = per_step("force", force)
print(
    f"force: median {np.median(force_cost) * 1e6:.1f} us mean {force_cost.mean() * 1e6:.1f} p99 "
    f"{np.percentile(force_cost, 99) * 1e6:.1f} max {force_cost.max() * 1e6:.0f} us; "
    f"mean/depth mean {force_cost.mean() / cost.mean():.1f}"
)
