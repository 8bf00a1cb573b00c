"""Where a `step_depths` row goes beyond the kernel (issue 13, 0.11.0 `rest`): on the kernel
section's state (`row_rest.bench_state`), interleaved in one process, thread CPU time, us a row
of 400: `simulator.restore` + `step_depths` (the bench's batch column), `restore` alone, and
`_advance_rows` alone, and `MinimalStepper.run` over the same rows from the same state (the
bench's baseline); "python" is the batch less the kernel.

    PYTHONPATH=. .venv/bin/python benchmarks/step_depths_split.py 64,0 1024,0 64,1 1024,1
"""

import sys
import time

import numpy as np

sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
from row_rest import bench_state

from viscoadh_ros.bench.reference_stepper import MinimalStepper
from viscoadh_ros.core import _kernels


def split(nk: str) -> None:
    n, k = (int(v) for v in nk.split(","))
    sim, times, depths = bench_state(n, k)
    start = sim.snapshot()
    row, radius = sim._model.row, sim._model.radius
    wl0, wb0 = row.memory()
    ms = float(sim.numerics.max_substep)
    mm = float(sim.numerics.max_edge_cells * row.dx)
    t0, d0 = sim.time, sim.output.depth
    peak = float(np.max(np.abs(row.wsum), initial=0.0))
    bk, bkb = np.empty_like(row.wl), np.empty_like(row.wl)
    rows = np.zeros((times.size, _kernels.ROW_SIZE))

    def batch():
        sim.restore(start)
        sim.step_depths(times, depths)

    def restore():
        sim.restore(start)

    def kernel():
        row.set_memory(wl0, wb0)
        _kernels._advance_rows(
            *row.kernel_args, bk, bkb, radius, t0, d0, peak, times, depths, 0, ms, mm, 0.0, rows
        )

    minimal_stepper = MinimalStepper.on_grid_of(sim)

    def minimal():
        minimal_stepper.set_state(depth=d0, radius=radius, memory=wl0)
        minimal_stepper.run(1e-3, depths)

    runs = {"batch": batch, "restore": restore, "kernel": kernel, "minimal": minimal}
    for r in runs.values():
        r()
    samples = {name: [] for name in runs}
    for _ in range(41):
        for name, r in runs.items():
            s = time.thread_time()
            r()
            samples[name].append(time.thread_time() - s)
    med = {name: float(np.median(v)) * 1e6 / times.size for name, v in samples.items()}
    print(
        nk,
        " ".join(f"{k} {v:.3f}" for k, v in med.items()),
        f"python {med['batch'] - med['kernel']:.3f} us/row",
        f"batch/minimal {med['batch'] / med['minimal']:.2f}",
        f"kernel/minimal {med['kernel'] / med['minimal']:.2f}",
    )


if __name__ == "__main__":
    for spec in sys.argv[1:]:
        split(spec)
