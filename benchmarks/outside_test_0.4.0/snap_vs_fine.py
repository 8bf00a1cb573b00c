# ruff: noqa: E501
"""Where new (0.4.0) and old (c28c75b) differ most, which is nearer a finer reference: the
same history with every row cut into M equal sub-rows (the kernel's own time discretisation
refined; same grid). Prints per scene, at the rows with the largest new-old force difference,
force new/old/fine and energy_input likewise; run with each venv and compare.

usage: <venv>/bin/python repro/snap_vs_fine.py SCENE [M] [rows...]
"""

import sys

import numpy as np
from scenes import contact_of, scenes

from viscoadh_ros.core.simulator import ContactSimulator

name = sys.argv[1]
m = int(sys.argv[2]) if len(sys.argv) > 2 else 100
sc = {s[0]: s for s in scenes()}[name]
_, sec, t, d = sc
c = contact_of(sec)
coarse = ContactSimulator(c).step_depths(t, d)
tt = np.concatenate(([0.0], t))
dd = np.concatenate(([0.0], d))
ft, fd = [], []
for i in range(len(t)):
    s = np.arange(1, m + 1) / m
    ft.append(tt[i] + (tt[i + 1] - tt[i]) * s)
    fd.append(dd[i] + (dd[i + 1] - dd[i]) * s)
ft, fd = np.concatenate(ft), np.concatenate(fd)
fine = ContactSimulator(c).step_depths(ft, fd)
idx = np.arange(len(t)) * m + m - 1
np.savez(
    f"/tmp/tester_fine_{name}.npz",
    **{f"coarse_{k}": v for k, v in coarse.items()},
    **{f"fine_{k}": fine[k][idx] for k in fine},
)
for f in ("force", "energy_input", "energy_dissipated", "contact_radius"):
    a, b = coarse[f], fine[f][idx]
    print(
        f"{f:18s} max|coarse-fine|/max|fine| = {np.max(np.abs(a - b)) / np.max(np.abs(b)):.3e}  row {int(np.argmax(np.abs(a - b)))}"
    )
