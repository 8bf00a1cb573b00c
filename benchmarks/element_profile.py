"""Where an in-contact step's kernel time goes: each sub-kernel timed alone in a compiled loop.

    .venv/bin/python benchmarks/element_profile.py [N,K ...]

On `element_ab.py`'s scene (in contact, one substep per 1 kHz step): `_advance` (integrates the
start force itself), `_advance_from` (given it), `_advance_packed` with its journal and the
kept force (what `step()` calls), and alone: `_force`, the journal copy, `_update_range` over
the whole row, `_locate_edge`, `_edge_outputs`. us per step and ns per element, median of
repeats (wall time: run it on a quiet machine, or read only the proportions).
"""

import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from element_ab import scene  # noqa: E402

from viscoadh_ros.core import _kernels as K  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402


def _setup(n, k):
    sim, _, depth = scene(ContactSimulator, n, k, 400)
    return sim, np.concatenate(([sim.output.depth], depth))


@numba.njit
def loop_advance(args, radius, depth, dt, ms, mm):
    out = args[-1]
    for s in range(1, depth.shape[0]):
        K._advance(*args, radius, depth[s - 1], depth[s], dt, ms, mm)
        radius = out[0]


@numba.njit
def loop_advance_from(args, radius, depth, dt, ms, mm):
    out = args[-1]
    fp = K._force(
        radius,
        depth[0],
        args[1],
        args[3],
        args[8],
        args[9],
        args[10],
        args[11],
        args[14],
        args[15],
        args[23],
        args[6],
        args[2],
        args[18],
        args[19],
        args[20],
        args[21],
    )
    for s in range(1, depth.shape[0]):
        K._advance_from(*args, radius, depth[s - 1], depth[s], dt, ms, mm, fp, args[0][:0], args[2][:0])
        radius = out[0]
        fp = out[1]


@numba.njit
def loop_packed(state, const, radius, depth, dt, ms, mm, out):
    fp = np.nan
    for s in range(1, depth.shape[0]):
        K._advance_packed(state, const, True, radius, depth[s - 1], depth[s], dt, ms, mm, fp)
        radius = out[0]
        fp = out[1]


@numba.njit
def loop_force(args, radius, depth):
    t = 0.0
    for s in range(1, depth.shape[0]):
        t += K._force(
            radius,
            depth[s],
            args[1],
            args[3],
            args[8],
            args[9],
            args[10],
            args[11],
            args[14],
            args[15],
            args[23],
            args[6],
            args[2],
            args[18],
            args[19],
            args[20],
            args[21],
        )
    return t


@numba.njit
def loop_copy(args, txn, txn_b, depth):
    for _ in range(1, depth.shape[0]):
        K._copy_state(args[0], args[2], txn, txn_b)


@numba.njit
def loop_update(args, radius, depth, dt):
    wl, wsum, wb, bsum, diss, coef, dx, g_c = (
        args[0],
        args[1],
        args[2],
        args[3],
        args[6],
        args[7],
        args[8],
        args[9],
    )
    n = wl.shape[0]
    n_in = K._interior_count(radius, dx, n)
    K._substep_coefficients(args[20], args[22], dt, coef)
    t = 0.0
    for s in range(1, depth.shape[0]):
        tt, pk = K._update_range(
            wl,
            wsum,
            wb,
            bsum,
            diss,
            0,
            n,
            n_in,
            depth[s - 1],
            depth[s],
            (depth[s] - depth[s - 1]) / dt,
            g_c,
            args[18],
            args[19],
            args[20],
            args[21],
            coef,
            args[24],
            dx,
            0.0,
            0.0,
        )
        t += tt
    return t


@numba.njit
def loop_locate(args, radius, depth, mm):
    t = 0.0
    for s in range(1, depth.shape[0]):
        a, m, g = K._locate_edge(
            radius,
            depth[s],
            args[1],
            args[3],
            args[8],
            args[9],
            args[10],
            args[12],
            args[13],
            args[14],
            args[16],
            args[17],
            mm,
        )
        t += a
    return t


@numba.njit
def loop_edge_out(args, radius, depth):
    for s in range(1, depth.shape[0]):
        K._edge_outputs(
            radius, depth[s], args[1], args[3], args[8], args[9], args[10], args[14], args[16], args[-1]
        )


def profile(n: int, k: int) -> None:
    sim, depth = _setup(n, k)
    row = sim._model.row
    radius = sim._model.radius
    wl0, wb0 = row.memory()
    ms = float(sim.numerics.max_substep)
    mm = float(sim.numerics.max_edge_cells * row.dx)
    args = row.kernel_args
    txn, txn_b = row.txn, row.txn_b
    n_in = K._interior_count(radius, row.dx, n)
    runs = {
        "advance": lambda: loop_advance(args, radius, depth, 1e-3, ms, mm),
        "advance_from": lambda: loop_advance_from(args, radius, depth, 1e-3, ms, mm),
        "packed+journal": lambda: loop_packed(row._state, row._const, radius, depth, 1e-3, ms, mm, row.out),
        "force": lambda: loop_force(args, radius, depth),
        "journal copy": lambda: loop_copy(args, txn, txn_b, depth),
        "update_range": lambda: loop_update(args, radius, depth, 1e-3),
        "locate_edge": lambda: loop_locate(args, radius, depth, mm),
        "edge_outputs": lambda: loop_edge_out(args, radius, depth),
    }
    samples = {key: [] for key in runs}
    for run in runs.values():
        row.set_memory(wl0, wb0)
        run()
    reps = 15 if n > 256 else 41
    for _ in range(reps):
        for key, run in runs.items():
            row.set_memory(wl0, wb0)
            t0 = time.perf_counter()
            run()
            samples[key].append(time.perf_counter() - t0)
    steps = depth.shape[0] - 1
    # substeps of the run
    print(f"N={n} K={k} n_in={n_in} radius/dx={radius / row.dx:.1f}")
    for key, v in samples.items():
        t = float(np.median(v)) / steps
        print(f"   {key:16s} {t * 1e6:8.3f} us/step {t / n * 1e9:7.2f} ns/elem")


def main() -> None:
    for spec in sys.argv[1:] or ["64,1", "1024,1", "4096,1"]:
        n, k = (int(v) for v in spec.split(","))
        profile(n, k)


if __name__ == "__main__":
    main()
