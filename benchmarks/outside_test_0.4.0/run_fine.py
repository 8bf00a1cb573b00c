"""For every scene of a scene module: step_depths on the history and on the history with each
row cut into M sub-rows (read at the row ends). Saves both. usage: python run_fine.py MODULE M OUT.npz"""

import importlib
import sys

import numpy as np
from scenes import contact_of

from viscoadh_ros.core.simulator import ContactSimulator

mod, m, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
saved = {}
for name, sec, t, d in importlib.import_module(mod).scenes():
    c = contact_of(sec)
    coarse = ContactSimulator(c).step_depths(t, d)
    tt = np.concatenate(([0.0], t))
    dd = np.concatenate(([0.0], d))
    s = np.arange(1, m + 1) / m
    ft = (tt[:-1, None] + (tt[1:] - tt[:-1])[:, None] * s).ravel()
    fd = (dd[:-1, None] + (dd[1:] - dd[:-1])[:, None] * s).ravel()
    fine = ContactSimulator(c).step_depths(ft, fd)
    idx = np.arange(len(t)) * m + m - 1
    for f in ("force", "contact_radius", "energy_input", "energy_dissipated", "phase"):
        saved[f"{name}/{f}"] = np.asarray(coarse[f], float)
        saved[f"{name}/fine_{f}"] = np.asarray(fine[f], float)[idx]
    print(name, len(t), flush=True)
np.savez(path, **saved)
