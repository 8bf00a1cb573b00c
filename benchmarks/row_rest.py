"""Where a batch row's fixed rest goes (issue 13, 0.11.0 `rest`): instructions per row of
`_advance_rows` on the kernel section's state (`bench.kernel.measure_kernel`: pressed, held,
then 400 rows of its cycle, in contact), counted by callgrind.

    PYTHONPATH=ROOT valgrind --tool=callgrind --trace-children=yes --instr-atstart=no \\
        --collect-atstart=no --callgrind-out-file=OUT.%p \\
        .venv/bin/python benchmarks/row_rest.py N,K REPEATS CGCTL_SO [--map FILE]

(``--trace-children``: the venv's bootstrap re-executes Python.) ``CGCTL_SO``: a shared
library with ``cg_on()`` (start instrumentation, zero, collect) and ``cg_off(name)`` (stop
collecting, dump) built from valgrind/callgrind.h's client requests; ``-`` to run without.
Two dumps: ``empty`` (REPEATS calls of `_advance_rows` from Python that step no row: the
dispatch, the first force, the memory reset) and ``full`` (REPEATS calls over the 400 rows);
instructions per row = (full - empty) / (REPEATS 400). Whichever checkout is on PYTHONPATH
is counted (an old one the same way). ``--map FILE``: the address of every function of
`_advance_rows`'s compiled library, to read callgrind's anonymous JIT addresses by.
"""

from __future__ import annotations

import ctypes
import sys

import numpy as np

from viscoadh_ros.bench import kernel as bench_kernel
from viscoadh_ros.bench.accuracy import Case, cases, contact_config
from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator

STEP_S = 1e-3
ROWS = 400


def bench_state(n: int, k: int):
    """The simulator `measure_kernel` times from, and its cycle's times and depths."""
    case = next(c for c in cases() if c.name == "standard_solid_pull_off")
    material = bench_kernel.kelvin_material(case, k)
    contact = contact_config(
        Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": n, "model": "time_stepped"},
    )
    sim = ContactSimulator(contact)
    ramp = np.concatenate(
        [
            np.linspace(0.0, bench_kernel.DEPTH_HIGH, 50),
            np.linspace(bench_kernel.DEPTH_HIGH, bench_kernel.DEPTH_LOW, 50),
            np.full(bench_kernel.HOLD_STEPS, bench_kernel.DEPTH_LOW),
        ]
    )
    for index, d in enumerate(ramp * case.depth_scale):
        sim.step(index * STEP_S, depth=float(d))
    depth = bench_kernel._cycle(case, ROWS)
    times = sim.time + STEP_S * np.arange(1, ROWS + 1)
    return sim, times, depth[1:]


def _write_map(path: str) -> None:
    """`_advance_rows`'s object code from its cache file to ``path``.o, and the address of
    each function defined in it (``nm``) in this process to ``path`` (address, name)."""
    import subprocess

    dispatcher = _kernels._advance_rows
    cache_file = dispatcher._cache._cache_file
    # The entry compiled for this process's CPU (under valgrind numba sees another CPU, without
    # AVX-512, and compiles and caches the kernels for it).
    magic = dispatcher.targetctx.codegen().magic_tuple()
    (obj,) = [
        cache_file._load_data(entry)[0][2][0]
        for key, entry in cache_file._load_index().items()
        if magic in key
    ]
    with open(path + ".o", "wb") as fh:
        fh.write(obj)
    names = subprocess.run(["nm", "--defined-only", path + ".o"], capture_output=True, text=True).stdout
    (cres,) = _kernels._advance_rows.overloads.values()
    with open(path, "w") as fh:
        for line in names.splitlines():
            value, kind, name = line.split(maxsplit=2)
            if kind in "tTW":
                fh.write(f"{cres.library.get_pointer_to_function(name):#x} {int(value, 16):#x} {name}\n")


def main() -> None:
    argv = sys.argv[1:]
    map_file = None
    if "--map" in argv:
        at = argv.index("--map")
        map_file = argv[at + 1]
        del argv[at : at + 2]
    n, k = (int(v) for v in argv[0].split(","))
    repeats = int(argv[1])
    ctl = None if argv[2] == "-" else ctypes.CDLL(argv[2])
    sim, times, depths = bench_state(n, k)
    row, radius = sim._model.row, sim._model.radius
    wl0, wb0 = row.memory()
    ms = float(sim.numerics.max_substep)
    mm = float(sim.numerics.max_edge_cells * row.dx)
    t0, d0 = sim.time, sim.output.depth
    peak = float(np.max(np.abs(row.wsum), initial=0.0))
    backup, backup_b = np.empty_like(row.wl), np.empty_like(row.wl)
    args = row.kernel_args
    rows = np.zeros((times.size, _kernels.ROW_SIZE))

    def run(first):
        row.set_memory(wl0, wb0)
        i, status = _kernels._advance_rows(
            *args, backup, backup_b, radius, t0, d0, peak, times, depths, first, ms, mm, 0.0, rows
        )
        assert i == times.size and status == 0, (i, status)

    run(0)
    run(times.size)
    if map_file:
        _write_map(map_file)
    for phase, first in (("empty", times.size), ("full", 0)):
        if ctl:
            ctl.cg_on()
        for _ in range(repeats):
            run(first)
        if ctl:
            ctl.cg_off(phase.encode())
    substeps = rows[:, _kernels.OUT_SUBSTEPS].sum() / times.size
    checksum = float(np.nansum(rows[:, : _kernels.OUT_SIZE]))
    print(f"N={n} K={k} substeps {substeps:.3f} checksum {checksum:.17g}")


if __name__ == "__main__":
    main()
