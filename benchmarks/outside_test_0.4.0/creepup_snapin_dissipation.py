# ruff: noqa: E501
"""Snap-in of a surface creeping back up to an indenter still pressed in (re-contact while
memory is left, no depth motion needed): fuzz10_sphere_K2 of scenes_fuzz.py, row 102 (dt = 0.47
s from no contact at d = +0.11 mm: the indenter was pulled up quickly, the depressed surface
creeps back and touches it inside the step; K = 2, retardation 1e-4 s and 1e3 s).
The same row cut into M sub-rows: energy dissipated over the row, force and radius at its end.
Run with main's venv and with c28c75b's (0.4.0 snap-in located in time vs halving).

usage: <venv>/bin/python repro/creepup_snapin_dissipation.py
"""

import numpy as np
from scenes import contact_of
from scenes_fuzz import scenes

from viscoadh_ros.core.simulator import ContactSimulator

name, sec, t, d = {s[0]: s for s in scenes()}["fuzz10_sphere_K2"]
row = 102
c = contact_of(sec)
print(f"row {row}: t {t[row - 1]:.6f} -> {t[row]:.6f} s, depth {d[row - 1]:+.4e} -> {d[row]:+.4e} m")
for m in (1, 2, 10, 100, 1000, 10000):
    sim = ContactSimulator(c)
    sim.step_depths(t[:row], d[:row])
    e0, w0 = sim.output.energy_dissipated, sim.output.energy_input
    s = np.arange(1, m + 1) / m
    cols = sim.step_depths(t[row - 1] + (t[row] - t[row - 1]) * s, d[row - 1] + (d[row] - d[row - 1]) * s)
    o = sim.output
    touch = np.flatnonzero(cols["contact_radius"] > 0)
    first = f"{cols['time'][touch[0]] - t[row - 1]:.4e}" if touch.size else "-"
    print(
        f"M={m:6d} dissipated over the row {o.energy_dissipated - e0:.4e} J  input {o.energy_input - w0:+.4e} J"
        f"  F={o.force:.6e} N a={o.contact_radius:.6e} m  first sub-row in contact ends at +{first} s"
    )
