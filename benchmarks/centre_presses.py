"""Two presses through element centres (round 0.11.0-centre, session 12), per preset:

1. The outside tester's slow press (tests/test_centre_crossing.py: G0/G_inf = 11, tau = 1 ms,
   rows of 1 s to 30 relaxed d_c, then one row swept through several centres): the largest
   force jump at a centre, bisected to the crossing, and the largest |F - F_8192| / P along the
   sweep (P the analytic pull-off force).
2. A press of 50 creep times: a 1 mm sphere, G0 = 1 GPa, one Kelvin element with G0/G_inf = 11
   and tau = eta / (G0 + G1) = 1 ms, w = 0.01 J/m^2, pressed from -0.5 to 10 relaxed d_c in 50
   eta / G1 (5000 rows) and pulled to -3 d_c in as long, under depth control: |F - F_8192| / P
   on the press rows (P: the 8192-element pull-off force, `accurate` numerics), its largest,
   where (a / dx, v tau / dx there), its RMS, and the largest just past a centre (a / dx within
   0.05 of it) and just before. A reconstruction of the tester's "press of 50 retardation
   times towards 10 d_c" (its script was not kept): v tau ~ 0.15-0.35 dx at `balanced` to
   `accurate`, as there, not its exact numbers.

    PYTHONPATH=<checkout> python benchmarks/centre_presses.py

PYTHONPATH picks the kernel; the tests' helpers are this file's checkout's. A few seconds.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import test_centre_crossing as slow  # noqa: E402
from scenes import one_contact  # noqa: E402

from viscoadh_ros.core import reference  # noqa: E402
from viscoadh_ros.core.history import simulate_history  # noqa: E402
from viscoadh_ros.core.rheology import CreepElement  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

PRESETS = ({"preset": "fast"}, {"preset": "balanced"}, {"preset": "accurate"})


def slow_press() -> None:
    sim = slow.pressed({"elements": 8192})
    snapshot = sim.snapshot()
    ref = np.array([slow.next_row(sim, snapshot, d).force for d in slow.SWEEP])
    for numerics in PRESETS:
        sim = slow.pressed(numerics)
        snapshot = sim.snapshot()
        dx = sim._model.row.length / sim.numerics.elements
        outs = [slow.next_row(sim, snapshot, d) for d in slow.SWEEP]
        errors = np.abs(np.array([o.force for o in outs]) - ref) / slow.PULL_OFF
        cells = np.floor(np.array([o.contact_radius for o in outs]) / dx - 0.5)
        jumps = []
        for j in np.flatnonzero(np.diff(cells) > 0):
            lo, hi = slow.SWEEP[j], slow.SWEEP[j + 1]
            centre = (cells[j] + 1.5) * dx
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if slow.next_row(sim, snapshot, mid).contact_radius < centre:
                    lo = mid
                else:
                    hi = mid
            before, after = slow.next_row(sim, snapshot, lo), slow.next_row(sim, snapshot, hi)
            jumps.append(abs(after.force - before.force) / slow.PULL_OFF)
        print(
            f"slow press {numerics['preset']:9s} {sim.numerics.elements:4d} elements: {len(jumps)} crossings,"
            f" largest jump {max(jumps):.3e}, along the sweep largest {errors.max():.3e}"
            f" RMS {np.sqrt(np.mean(errors**2)):.3e}",
            flush=True,
        )


def creep_press(ratio: float = 11.0, half: int = 5000) -> None:
    g0, tau = 1e9, 1e-3
    g1 = g0 / (ratio - 1.0)

    def body(**numerics):
        return one_contact(
            {"shape": "sphere", "radius": 1e-3},
            glass_shear_modulus=g0,
            kelvin=[g1],
            viscosities=[tau * (g0 + g1)],
            work=0.01,
            numerics={"model": "time_stepped", **numerics},
        )

    unit = abs(reference.figure4_scales(1e-3, 0.01, CreepElement.from_config(body().material)).depth)
    depths = unit * np.concatenate([np.linspace(-0.5, 10.0, half), np.linspace(10.0, -3.0, half + 1)])
    times = np.linspace(0.0, 100.0 * tau * ratio, 2 * half + 1)
    ref = simulate_history(body(preset="accurate", elements=8192), times, depth=depths)
    p = -ref.force.min()
    press = np.arange(times.size) < half
    for numerics in (*PRESETS, {"tolerance": 3e-3}):
        contact = body(**numerics)
        sim = ContactSimulator(contact)
        forces, radii, dxs = [], [], []
        for t, d in zip(times, depths, strict=True):
            out = sim.step(float(t), depth=float(d))
            forces.append(out.force)
            radii.append(out.contact_radius)
            row = sim._model.row
            dxs.append(row.length / row.elements if row is not None else np.nan)
        forces, radii, dxs = np.array(forces), np.array(radii), np.array(dxs)
        both = press & (radii > 0.0) & (ref.contact_radius > 0.0)
        err = np.where(both, np.abs(forces - ref.force) / p, 0.0)
        i = int(np.argmax(err))
        speed = (radii[i] - radii[i - 1]) / (times[1] - times[0])
        frac = np.mod(radii / dxs - 0.5, 1.0)
        label = numerics.get("preset", f"tol {numerics.get('tolerance')}")
        past, ahead = err[both & (frac < 0.05)].max(), err[both & (frac > 0.95)].max()
        print(
            f"creep press {label:9s} {sim.numerics.elements:4d} elements: largest {err.max():.3e}"
            f" (a/dx {radii[i] / dxs[i]:.3f}, v tau/dx {speed * tau / dxs[i]:.3f}),"
            f" RMS {np.sqrt(np.mean(err[both] ** 2)):.3e},"
            f" just past a centre {past:.3e}, just before {ahead:.3e}",
            flush=True,
        )


if __name__ == "__main__":
    slow_press()
    creep_press()
