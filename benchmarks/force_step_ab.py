"""Force-control steps before/after side by side (0.8.0's lean force path, issue 13).

    .venv/bin/python benchmarks/force_step_ab.py [--repeats R] ROOT [ROOT ...]

Each ROOT is a checkout; its core is run in its own process (``PYTHONPATH=ROOT``), the roots
in turn, R rounds, so the machine's drift falls on every root alike. Per round and root: the
wall time of each `step` call (`time.perf_counter`) on the bound section's histories (the
default scene's sine under depth control, the same forces commanded back under force
control, and the gripper's hold-and-pull forces), after one warm-up pass. Printed per root:
the median over rounds of each history's median, mean and p99 per step, and force / depth
control (mean and p99), the bound section's ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

_CHILD = r"""
import json, sys, time
import numpy as np
from viscoadh_ros.bench import kernel as K
from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.core.simulator import ContactSimulator

contact = SceneConfig.from_yaml(default_scene_path()).contacts[0]
times, depths = K._scene_history(K.SCENE_SECONDS)
forces = ContactSimulator(contact).step_depths(times, depths)["force"]
hold_times, hold_forces = K.hold_pull_forces()
clock = time.perf_counter

def costs(t, v, key):
    sim = ContactSimulator(contact)
    out = np.empty(t.size)
    for i in range(t.size):
        start = clock()
        sim.step(float(t[i]), **{key: float(v[i])})
        out[i] = clock() - start
    return out

result = {}
for name, t, v, key in (("depth", times, depths, "depth"), ("force", times, forces, "force"),
                        ("hold_pull", hold_times, hold_forces, "force")):
    costs(t, v, key)  # warm-up
    c = costs(t, v, key) * 1e6
    result[name] = {"median": float(np.median(c)), "mean": float(np.mean(c)),
                    "p99": float(np.percentile(c, 99.0)), "max": float(np.max(c))}
print(json.dumps(result))
"""


def _run(root: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(root))
    done = subprocess.run(
        [sys.executable, "-c", _CHILD], env=env, capture_output=True, text=True, check=True, cwd=root
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("roots", nargs="+", type=Path)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    runs: dict[Path, list[dict]] = {root: [] for root in args.roots}
    for _ in range(args.repeats):
        for root in args.roots:
            runs[root].append(_run(root))
    for root, results in runs.items():
        table = {
            name: {stat: float(np.median([r[name][stat] for r in results])) for stat in results[0][name]}
            for name in results[0]
        }
        print(f"{root}:")
        for name, stats in table.items():
            print(f"  {name:9s} " + "  ".join(f"{stat} {value:8.2f} us" for stat, value in stats.items()))
        for stat in ("mean", "p99"):
            print(f"  force / depth control {stat}: {table['force'][stat] / table['depth'][stat]:.2f}")


if __name__ == "__main__":
    main()
