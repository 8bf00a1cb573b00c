"""Worst step against the median step when a contact is pressed at 1 kHz from rest, by element
count. Issue 13 ("every step bounded"): no step, snap-in included, above 20x the median step of
its scene; docs/concepts.md: "the cost of a step grows about linearly with N". The node runs
every contact's steps on one live thread, so one slow step delays every contact.
History: 1 kHz, 20 ms ramp from 0 to 20 um (the first step touches: snap-in), 100 ms hold.
Numerics: what numerics.tolerance picks (1e-3, 1e-4) and the presets. Warm run first."""

import sys
import time

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

import viscoadh_ros.core._kernels as _k  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

K2 = {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4, 1e5], "kelvin_viscosities": [1.05e5, 1e6]}
CASES = (
    ("K=1 balanced", None, {"preset": "balanced"}),
    ("K=1 accurate", None, {"preset": "accurate"}),
    ("K=1 tol 1e-3", None, {"tolerance": 1e-3}),
    ("K=2 tol 1e-3", K2, {"tolerance": 1e-3}),
    ("K=2 tol 3e-4", K2, {"tolerance": 3e-4}),
    ("K=2 tol 1e-4", K2, {"tolerance": 1e-4}),
)
t = np.arange(1, 121) * 1e-3
d = np.minimum(t * 1e-3, 20e-6)

_k.warm_up()
for rep in (0, 1):
    for label, mat, num in CASES:
        c = contact(material=mat, numerics=num) if mat else contact(numerics=num)
        s = ContactSimulator(c)
        cost = []
        for ti, di in zip(t, d):
            w = time.perf_counter()
            s.step(float(ti), depth=float(di))
            cost.append(time.perf_counter() - w)
        cost = np.array(cost)
        med = float(np.median(cost))
        i = int(np.argmax(cost))
        if rep:
            print(
                f"{label:14s} N={s.numerics.elements:5d}: worst step {cost[i] * 1e3:7.2f} ms at row {i} "
                f"= {cost[i] / med:6.0f}x the median {med * 1e3:.3f} ms",
                flush=True,
            )
