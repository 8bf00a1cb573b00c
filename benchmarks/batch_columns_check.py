"""`_kernels._batch_columns` (0.11.0 `rest`) against the numpy expressions `step_depths` used
before it, bit for bit (asserted), on the kernel section's states and tests/test_simulator_batch
cases; with ``--time N,K ...`` also both timed, interleaved, thread CPU time per 400-row call.

    PYTHONPATH=. .venv/bin/python benchmarks/batch_columns_check.py [--time 64,0 1024,1]
"""

import math
import sys

import numpy as np

here = __import__("pathlib").Path(__file__).resolve().parent
sys.path.insert(0, str(here))
sys.path.insert(0, str(here.parent / "tests"))
import test_simulator_batch as tsb  # noqa: E402
from row_rest import bench_state  # noqa: E402

from viscoadh_ros.core import _kernels  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator, Phase  # noqa: E402


def old_cols(sim, t, d, radius, work, gaps, rest, steps):
    physics = sim.physics
    r0 = np.concatenate(([sim._output.contact_radius], radius[:-1]))
    dt = steps
    energy_input = np.cumsum(np.concatenate(([sim._energy_input], work)))[1:]
    g = gaps[:, 2]
    tol = 1e-9 * (np.abs(d) + physics.c_crit * np.sqrt(radius) + g)
    pinned = np.where(
        gaps[:, 0] >= -tol, Phase.INDENTING, np.where(gaps[:, 1] <= tol, Phase.DETACHING, Phase.STICKING)
    )
    phase = np.where(
        radius <= 0.0,
        Phase.NO_CONTACT,
        np.where(radius > r0 + rest, Phase.INDENTING, np.where(radius < r0 - rest, Phase.DETACHING, pinned)),
    ).astype(np.uint8)
    moving = dt > 0.0
    edge_speed = np.where(moving, (radius - r0) / np.where(moving, dt, 1.0), 0.0)
    u = d - g
    in_contact = radius > 0.0
    effective = np.where(
        in_contact & (u < 0.0),
        physics.e_relaxed * u * u / (2.0 * math.pi * np.where(in_contact, radius, 1.0)),
        0.0,
    )
    v_c1, v_c2 = physics.critical_speeds
    ok = (edge_speed == 0.0) | (np.abs(edge_speed) >= np.where(edge_speed > 0.0, v_c1, v_c2))
    return phase, edge_speed, effective, energy_input, ok


def new_cols(sim, d, steps, radius, gaps, rest, work, force, dissipated):
    """`_kernels._batch_columns` as `step_depths` calls it from ``sim``'s state, with no
    repeated sample before the first row (the histories have none)."""
    p = sim.physics
    v1, v2 = p.critical_speeds
    return _kernels._batch_columns(
        d,
        steps,
        radius,
        gaps,
        rest,
        work,
        sim._output.contact_radius,
        sim._energy_input,
        p.c_crit,
        p.e_relaxed,
        v1,
        v2,
        force,
        dissipated,
        np.zeros(6),
    )


def check(label, sim, t, d):
    t = np.ascontiguousarray(t, dtype=np.float64)
    d = np.ascontiguousarray(d, dtype=np.float64)
    steps = np.diff(t, prepend=sim._time)
    radius, force, work, dissipated, gaps, rest = sim._model.advance_rows(sim, t, d)
    old = old_cols(sim, t, d, radius, work, gaps, rest, steps)
    new = new_cols(sim, d, steps, radius, gaps, rest, work, force, dissipated)
    # Since the repeated-sample fix (0.11.0), a row that repeats the row before (no time, the
    # same depth, not at rest) takes that row's columns, where the old expressions recomputed
    # them: compared on the other rows only.
    prev_d = np.concatenate(([np.nan], d[:-1]))
    at_rest = (radius == 0.0) & (force == 0.0) & (new[3] == 0.0) & (dissipated == 0.0)
    prev_rest = np.concatenate(([True], at_rest))[:-1]
    keep = ~((steps == 0.0) & (d == prev_d) & ~prev_rest)
    for name, a, b in zip(("phase", "edge_speed", "effective", "energy", "ok"), old, new, strict=False):
        assert a.dtype == b.dtype and a.shape == b.shape, (label, name, a.dtype, b.dtype)
        assert np.array_equal(a[keep].view(np.uint8), b[keep].view(np.uint8)), (label, name)
    print(label, "equal", len(t), "rows, phases", np.bincount(new[0], minlength=4))


def timed(nk):
    import time

    n, k = (int(v) for v in nk.split(","))
    sim, t, d = bench_state(n, k)
    start = sim.snapshot()
    steps = np.diff(t, prepend=sim._time)
    radius, force, work, dissipated, gaps, rest = sim._model.advance_rows(sim, t, d)
    sim.restore(start)

    def old():
        old_cols(sim, t, d, radius, work, gaps, rest, steps)

    def new():
        new_cols(sim, d, steps, radius, gaps, rest, work, force, dissipated)

    def batch():
        sim.restore(start)
        sim.step_depths(t, d)

    runs = dict(old=old, new=new, batch=batch)
    for r in runs.values():
        r()
    S = {x: [] for x in runs}
    for _ in range(101):
        for x, r in runs.items():
            s0 = time.thread_time()
            r()
            S[x].append(time.thread_time() - s0)
    m = {x: float(np.median(v)) * 1e6 for x, v in S.items()}
    print(
        f"{nk}: columns old {m['old']:.1f} us, new {m['new']:.1f} us per 400-row call; "
        f"step_depths+restore (new) {m['batch']:.1f} us = {m['batch'] / 400:.3f} us/row; "
        f"saved {(m['old'] - m['new']) / 400:.3f} us/row"
    )


if __name__ == "__main__":
    for nk in ("64,0", "1024,1", "256,4"):
        n, k = (int(v) for v in nk.split(","))
        sim, times, depths = bench_state(n, k)
        check(f"bench {nk}", sim, times, depths)
    for case, (make, (t, d)) in sorted(tsb.CASES.items()):
        sim = ContactSimulator(make())
        if hasattr(sim._model, "advance_rows"):
            # a prefix stepped first, so r0 and the energy before are not zero
            for ti, di in zip(t[:5], d[:5], strict=False):
                sim.step(float(ti), depth=float(di))
            check(f"case {case}", sim, t[5:], d[5:])
    if "--time" in sys.argv:
        for spec in sys.argv[sys.argv.index("--time") + 1 :]:
            timed(spec)
