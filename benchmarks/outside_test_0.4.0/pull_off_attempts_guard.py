# ruff: noqa: E501
"""A fast pull-off in one 1 ms step on a fine row (elements 4096): the edge has to recede over
~all elements, one substep per element crossed, and the `_MAX_ATTEMPTS = 2000` guard drops the
motion limit mid-step; the rest of the release is one substep. Energy dissipated then jumps far
beyond the work put in (energy_dissipated > energy_input, impossible: stored energy >= 0, no
contact left) and far from the same history with the step cut into 100 rows. Same on c28c75b
(pre-existing). Elements 1024 (under the guard) for comparison.

usage: .venv/bin/python repro/pull_off_attempts_guard.py
"""

import numpy as np
from scenes import CHAINS, SPHERE, contact_of, section

from viscoadh_ros.core.simulator import ContactSimulator

for n in (1024, 4096):
    c = contact_of(section(SPHERE, *CHAINS[1], numerics={"elements": n}))
    t = np.array([1e-3, 2e-3, 3e-3])
    d = np.array([6e-5, 1.23e-4, -8.2e-5])
    sim = ContactSimulator(c)
    for a, b in zip(t, d, strict=False):
        o = sim.step(float(a), depth=float(b))
        print(
            f"N={n:5d} t={a:.0e} d={b:+.2e} F={o.force:+.4e} a={o.contact_radius:.3e} substeps={sim._model.substeps:5d}"
            f" input={o.energy_input:.4e} dissipated={o.energy_dissipated:.4e}"
        )
    # the same pull cut into 100 rows
    fine = ContactSimulator(c)
    fine.step_depths(t[:2], d[:2])
    tt = 2e-3 + np.arange(1, 101) * 1e-5
    dd = d[1] + (d[2] - d[1]) * np.arange(1, 101) / 100
    cols = fine.step_depths(tt, dd)
    print(
        f"N={n:5d} same pull in 100 rows: input={cols['energy_input'][-1]:.4e} dissipated={cols['energy_dissipated'][-1]:.4e}"
        f" (one-step dissipated / input = {o.energy_dissipated / o.energy_input:.1f})"
    )
