"""Which snap-in partition is nearer the converged answer where main's and 0.4.0's differ most
(0.4.0 `snap`): run once under each checkout (separate processes: each its own kernels).

- the cone step scene's re-contact row (tests/step_scenarios.py, t = 0.256 s): the force of
  one step against the same step cut into 10, 100 and 1000 sub-steps (each with its own,
  finer jump resolution), from the same state;
- the random-memory rows of the kernel golden (K = 3 with a mode relaxing at 1e7 / s) whose
  force moved most: the one-call force against 100 and 1000 calls over the same interval.

    .venv/bin/python benchmarks/snap_reference.py <checkout root>
"""

from __future__ import annotations

import copy
import sys

import numpy as np

root = sys.argv[1]
sys.path.insert(0, root + "/tests")
sys.path.insert(0, root)
import viscoadh_ros  # noqa: E402

assert viscoadh_ros.__file__.startswith(root), viscoadh_ros.__file__
import step_scenarios  # noqa: E402
from kernel_golden import _contact, sphere_indenter  # noqa: E402

from viscoadh_ros.core import _kernels  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

_kernels.warm_up()
ROW_TIME = 0.256


def step(sim, time, depth):
    if abs(time - ROW_TIME) < 1e-12:
        t0, d0 = sim.time, sim._depth
        for pieces in (10, 100, 1000):
            ref = copy.deepcopy(sim)
            for t in np.linspace(t0, time, pieces + 1)[1:]:
                out = ref.step(float(t), depth=float(d0 + (depth - d0) * (t - t0) / (time - t0)))
            print(f"cone t = {time}: {pieces} sub-steps force {out.force:.6e} N")
        out = sim.step(time, depth=depth)
        print(f"cone t = {time}: one step force {out.force:.6e} N")
        return out
    return sim.step(time, depth=depth)


step_scenarios.run_scene(step_scenarios.scenes()["cone"], step_scenarios.depth_scale("cone"), step)

# The kernel golden's random rows (tests/kernel_golden.py: random_rows, K = 3).
picks = {False: (0, 52, 55), True: (67, 68, 70)}
for smooth, wanted in picks.items():
    contact = _contact(sphere_indenter(), (2e5, 5e4, 1e6), (1e2, 1e4, 1e-1), 0.05, {"elements": 48})
    model = ContactSimulator(contact)._model
    index = 0
    for seed in range(8):
        rng = np.random.default_rng(seed)
        n, k = 48, 3
        if smooth:
            x = np.linspace(0.0, 1.0, n)[:, None]
            memory = 2e-6 * (
                rng.normal(size=(1, k)) + rng.normal(size=(1, k)) * x + rng.normal(size=(1, k)) * x**2
            )
        else:
            memory = rng.normal(scale=2e-6, size=(n, k))
        unit = rng.uniform(size=(n, k)) * model.steady
        row = model._build_row(2e-4, memory, unit)
        for _ in range(10):
            a = float(rng.choice([0.0, rng.uniform(0.0, 0.9) * row.length]))
            d0 = float(rng.uniform(-3e-6, 1.5e-5))
            d1 = float(rng.uniform(-3e-6, 1.5e-5))
            dt = float(rng.choice([0.0, 1e-4, 1e-3, 1e-2]))
            move = float(rng.choice([0.5, 1.0, 2.0])) * row.dx
            if index in wanted:
                refs = []
                for pieces in (100, 1000):
                    ref = row.with_memory(row.wl.copy(), row.wb.copy())
                    radius = a
                    for p in range(pieces):
                        da = d0 + (d1 - d0) * p / pieces
                        db = d0 + (d1 - d0) * (p + 1) / pieces
                        _, out = _kernels.advance(
                            ref, radius, da, db, dt / pieces, max_substep=0.0, max_edge_move=move
                        )
                        radius = out[_kernels.OUT_RADIUS]
                    refs.append(out[_kernels.OUT_FORCE])
            status, out = _kernels.advance(row, a, d0, d1, dt, max_substep=0.0, max_edge_move=move)
            if index in wanted:
                name = "smooth" if smooth else "rough"
                print(
                    f"random_k3_{name} row {index} (dt {dt:g} s): one call {out[_kernels.OUT_FORCE]:.6e}, "
                    f"100 calls {refs[0]:.6e}, 1000 calls {refs[1]:.6e} N"
                )
            if status != _kernels.STATUS_OK:
                row.set_memory(memory, unit)
            index += 1
