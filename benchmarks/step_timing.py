"""Side-by-side step cost of two checkouts of the core (issue 10 asked: no slower than before).

    .venv/bin/python benchmarks/step_timing.py <checkout root>

Times `ContactSimulator.step` (row by row) and `step_depths` (one compiled loop) on a
4001-row sine press of a standard solid (K = 1) and a K = 3 chain, balanced preset, best of
3; run it alternately on the old and the new checkout (e.g. a `git archive` of main unpacked
under /tmp) and compare only ratios measured in one sitting.
"""

from __future__ import annotations

import sys
import time

import numpy as np

root = sys.argv[1]
sys.path.insert(0, root + "/tests")
sys.path.insert(0, root)

import viscoadh_ros  # noqa: E402

assert viscoadh_ros.__file__.startswith(root), viscoadh_ros.__file__

from scenes import one_contact  # noqa: E402

from viscoadh_ros.core import _kernels  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

_kernels.warm_up()
for kelvin, viscosities, name in (([1e5], [1.1e4], "K=1"), ([1e5, 2e5, 5e5], [1.1e4, 1e3, 1e5], "K=3")):
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        glass_shear_modulus=1e6,
        kelvin=kelvin,
        viscosities=viscosities,
        work=0.05,
        numerics={"model": "time_stepped"},
    )
    t = np.linspace(0.0, 1.0, 4001)
    d = 2e-5 * np.sin(np.pi * t) ** 2 - 2e-6
    best_step, best_batch = 1e9, 1e9
    for _ in range(3):
        sim = ContactSimulator(contact)
        start = time.perf_counter()
        for ti, di in zip(t, d, strict=True):
            sim.step(float(ti), depth=float(di))
        best_step = min(best_step, time.perf_counter() - start)
        sim = ContactSimulator(contact)
        start = time.perf_counter()
        sim.step_depths(t, d)
        best_batch = min(best_batch, time.perf_counter() - start)
    print(f"{name} step {best_step / t.size * 1e6:.1f} us/row  batch {best_batch / t.size * 1e6:.1f} us/row")
