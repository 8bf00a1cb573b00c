# ruff: noqa: E501
"""Transaction invariants through the public API on racing/snap-in scenes (K = 1, 2, 4):
(1) snapshot at row i, run on, restore, run the same commands again: bit-equal outputs;
(2) a rejected command (NaN depth, time backwards, inf force, both depth and force) changes
nothing: the run with a bad command injected before every 7th row equals the clean run;
(3) force control: a run of step(t, force=) equals itself after snapshot/restore mid-way;
every output finite, energy_dissipated >= 0 and non-decreasing.

usage: .venv/bin/python repro/invariants.py
"""

import math
import sys

import numpy as np
from scenes import CHAINS, CONE, SPHERE, contact_of, cycle, section

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

dc = 41e-6
problems = []


def vec(o):
    return tuple(float(getattr(o, f)) for f in STEP_OUTPUT_FIELDS)


def check_out(name, outs):
    arr = np.array(outs)
    if not np.all(np.isfinite(arr)):
        problems.append(f"{name}: non-finite output")
    dis = arr[:, STEP_OUTPUT_FIELDS.index("energy_dissipated")]
    if np.any(dis < 0) or np.any(np.diff(dis) < 0):
        problems.append(f"{name}: energy_dissipated decreases (min step {np.min(np.diff(dis)):.3g})")


def depth_scene(name, sec, t, d):
    c = contact_of(sec)
    clean = ContactSimulator(c)
    ref = [vec(clean.step(float(a), depth=float(b))) for a, b in zip(t, d, strict=False)]
    check_out(name, ref)
    # (1) snapshot / restore at several rows
    for cut in (len(t) // 5, len(t) // 2, 4 * len(t) // 5):
        sim = ContactSimulator(c)
        for a, b in zip(t[:cut], d[:cut], strict=False):
            sim.step(float(a), depth=float(b))
        snap = sim.snapshot()
        for a, b in zip(t[cut:], d[cut:], strict=False):
            sim.step(float(a), depth=float(b))
        sim.restore(snap)
        again = [vec(sim.step(float(a), depth=float(b))) for a, b in zip(t[cut:], d[cut:], strict=False)]
        if again != ref[cut:]:
            problems.append(f"{name}: restore at row {cut} differs")
        # a fresh simulator restored from the snapshot
        other = ContactSimulator(c)
        other.restore(snap)
        again = [vec(other.step(float(a), depth=float(b))) for a, b in zip(t[cut:], d[cut:], strict=False)]
        if again != ref[cut:]:
            problems.append(f"{name}: restore into another simulator at row {cut} differs")
    # (2) rejected commands
    sim = ContactSimulator(c)
    got = []
    for i, (a, b) in enumerate(zip(t, d, strict=False)):
        if i % 7 == 3:
            for bad in (
                dict(depth=math.nan),
                dict(depth=math.inf),
                dict(force=math.nan),
                dict(depth=1e-6, force=0.0),
            ):
                try:
                    sim.step(float(a), **bad)
                    problems.append(f"{name}: bad command {bad} accepted")
                except (InputError, ValueError):
                    pass
            try:
                sim.step(sim.time - 1e-3, depth=float(b))
                problems.append(f"{name}: time backwards accepted")
            except (InputError, ValueError):
                pass
            try:
                sim.step_depths(np.array([float(a), float(a) - 1.0]), np.array([b, b]))
                problems.append(f"{name}: step_depths backwards accepted")
            except (InputError, ValueError):
                pass
            try:
                sim.step_depths(np.array([float(a)]), np.array([math.nan]))
                problems.append(f"{name}: step_depths NaN accepted")
            except (InputError, ValueError):
                pass
        got.append(vec(sim.step(float(a), depth=float(b))))
    if got != ref:
        i = next(k for k in range(len(ref)) if got[k] != ref[k])
        problems.append(f"{name}: bad commands changed the run from row {i}")
    # (4) step_depths in chunks equals step per call
    sim = ContactSimulator(c)
    cols = []
    for lo in range(0, len(t), 97):
        out = sim.step_depths(t[lo : lo + 97], d[lo : lo + 97])
        cols.append(np.column_stack([np.asarray(out[f], dtype=float) for f in STEP_OUTPUT_FIELDS]))
    cols = np.vstack(cols)
    diff = np.flatnonzero(np.any(cols != np.array(ref), axis=1))
    if diff.size:
        fields = [STEP_OUTPUT_FIELDS[j] for j in np.flatnonzero(np.any(cols != np.array(ref), axis=0))]
        problems.append(
            f"{name}: step_depths in chunks != step per call on {diff.size} rows (fields {fields}, first {diff[0]})"
        )


def force_scene(name, sec, t, f):
    c = contact_of(sec)
    sim = ContactSimulator(c)
    ref = []
    for a, b in zip(t, f, strict=False):
        ref.append(vec(sim.step(float(a), force=float(b))))
    check_out(name, ref)
    cut = len(t) // 2
    sim = ContactSimulator(c)
    for a, b in zip(t[:cut], f[:cut], strict=False):
        sim.step(float(a), force=float(b))
    snap = sim.snapshot()
    sim.step(float(t[cut]), depth=1e-4)
    sim.restore(snap)
    again = [vec(sim.step(float(a), force=float(b))) for a, b in zip(t[cut:], f[cut:], strict=False)]
    if again != ref[cut:]:
        problems.append(f"{name}: force control after restore differs")


def main():
    for k in (1, 2, 4):
        t, d = cycle(3 * dc, 1e-1, 0.05, 1e-1, 2 * dc, 1e-3)
        depth_scene(f"sphere_K{k}_fast", section(SPHERE, *CHAINS[k]), t, d)
        t, d = cycle(3 * dc, 3e-3, 1.0, 3e-3, 2 * dc, 1e-2)
        depth_scene(f"sphere_K{k}_slow", section(SPHERE, *CHAINS[k]), t, d)
        t, d = cycle(3 * dc, 1e-2, 0.5, 1e-2, 2 * dc, 1e-3)
        depth_scene(f"cone_K{k}", section(CONE, *CHAINS[k]), t, d)
    t, d = cycle(3 * dc, 1e-2, 0.5, 1e-2, 2 * dc, 1e-3)
    depth_scene("sphere_K0", section(SPHERE, *CHAINS[0]), t, d)
    for k in (1, 4):
        t = np.arange(1, 400) * 5e-3
        f = 5e-3 * np.sin(2 * np.pi * t / 1.0) - 1e-3
        force_scene(f"force_K{k}", section(SPHERE, *CHAINS[k]), t, f)
    print("\n".join(problems) if problems else "all invariants held")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
