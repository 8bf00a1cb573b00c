"""`ContactSimulator.step(t, depth=...)` per call from Python: an old checkout's core against this
one's and the bench's minimal reference stepper, side by side in one process (issue 13, kernel
target "from Python"; 0.12.0 round `percall`).

For each element count N and Kelvin count K: the `kernel` bench section's scene
(`bench.kernel.measure_kernel`: the standard solid pull-off case with K Kelvin elements, pressed,
withdrawn to the cycle's start and held; then 100 rows of its 1 kHz depth cycle, in contact, the
edge moving), stepped by both cores' `step(t, depth=d)` (a restore, then the 100 calls, as the
bench's `run_steps`) and by `MinimalStepper.step` (this checkout's, from the same state, as the
bench's `run_minimal_steps`), the three interleaved repeat by repeat; median of the repeats, us
per call. The two cores' outputs are compared field by field on every timed row (bit for bit:
floats by their bits, so a -0.0 against 0.0 counts as a difference).

    git worktree add --detach /work/ab/<name>-base main
    PYTHONPATH=. .venv/bin/python benchmarks/percall_ab.py [--new-first] /work/ab/<name>-base \
        [repeats] [N,K ...]

(default repeats 21; default scenes N = 64, 256, 1024, 2048, 4096 at K = 0, 1, 4). An A/A run
(the same checkout as old and new) shows the noise of a sitting. Where each core's compiled code
lands in memory moves a K = 4 step at N >= 1024 by up to ~4 % either way, and it follows the
order the cores are loaded in (0.12.0 `percall`: the same two kernels read 1.02-1.04 and
0.97 the other way round): `--new-first` loads this checkout's core first; run both orders.
"""

from __future__ import annotations

import os
import struct
import sys

import ab_cores
import numpy as np

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
argv = [arg for arg in sys.argv[1:] if arg != "--new-first"]
roots = {"old": os.path.abspath(argv[0]), "new": here}
if "--new-first" in sys.argv:
    roots = {"new": here, "old": roots["old"]}
repeats = int(argv[1]) if len(argv) > 1 else 21
if len(argv) > 2:
    SIZES = [tuple(int(x) for x in arg.split(",")) for arg in argv[2:]]
else:
    SIZES = [(n, k) for k in (0, 1, 4) for n in (64, 256, 1024, 2048, 4096)]
ROWS = 100  # `bench.kernel.STEP_TIMING_STEPS`

cores = {}
for label, root in roots.items():
    cores[label] = ab_cores.load(root, rename_kernels=label == "old")
cores = {"old": cores["old"], "new": cores["new"]}  # run and print in this order either way
new_bench = cores["new"]["bench_kernel"]
interleaved_medians = new_bench.interleaved_medians
MinimalStepper = new_bench.MinimalStepper
FIELDS = cores["new"]["simulator"].STEP_OUTPUT_FIELDS


def scene(core: dict, elements: int, kelvin: int):
    """The kernel section's start state (`bench.kernel.measure_kernel`) and its depth cycle."""
    bench = core["bench_kernel"]
    case = next(c for c in bench.cases() if c.name == "standard_solid_pull_off")
    material = bench.kelvin_material(case, kelvin)
    contact = bench.contact_config(
        bench.Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": elements, "model": "time_stepped"},
    )
    depth = bench._cycle(case, ROWS)
    sim = core["simulator"].ContactSimulator(contact)
    ramp = np.concatenate(
        [
            np.linspace(0.0, bench.DEPTH_HIGH, 50),
            np.linspace(bench.DEPTH_HIGH, bench.DEPTH_LOW, 50),
            np.full(bench.HOLD_STEPS, bench.DEPTH_LOW),
        ]
    )
    for index, d in enumerate(ramp * case.depth_scale):
        sim.step(index * bench.STEP_S, depth=float(d))
    return sim, sim.snapshot(), depth


def bits(output) -> tuple:
    """The output's fields, floats as their IEEE bits."""
    return tuple(
        struct.pack("<d", v) if type(v) is float else (type(v).__name__, int(v))
        for v in (getattr(output, name) for name in FIELDS)
    )


def stepper(sim, start, depth):
    """The bench's `run_steps`: restore, then ROWS calls of `step`."""
    t0 = sim.time

    def run() -> list:
        sim.restore(start)
        return [sim.step(t0 + index * 1e-3, depth=float(depth[index])) for index in range(1, ROWS + 1)]

    return run


def minimal_stepper(sim, depth):
    """The bench's `run_minimal_steps` on `sim`'s grid from its state."""
    minimal = MinimalStepper.on_grid_of(sim)
    radius, d_start, wl0 = sim._model.radius, sim._depth, sim._model.row.wl.copy()

    def run() -> None:
        minimal.set_state(depth=d_start, radius=radius, memory=wl0)
        for index in range(1, ROWS + 1):
            minimal.step(1e-3, float(depth[index]))

    return run


print(
    f"step(t, depth=) per call, us (median of {repeats} interleaved runs of {ROWS} calls, restore included)"
)
print("| N | K | old step | new step | minimal | old / minimal | new / minimal | new / old | outputs |")
print("|---|---|---|---|---|---|---|---|---|")
for elements, kelvin in SIZES:
    runs = {}
    results = {}
    for label, core in cores.items():
        sim, start, depth = scene(core, elements, kelvin)
        runs[label] = stepper(sim, start, depth)
        results[label] = [bits(o) for o in runs[label]()]
        if label == "new":
            runs["minimal"] = minimal_stepper(sim, depth)
    same = results["old"] == results["new"]
    for run in runs.values():
        run()
    m = {key: value / ROWS * 1e6 for key, value in interleaved_medians(runs, repeats=repeats).items()}
    print(
        f"| {elements} | {kelvin} | {m['old']:.3f} | {m['new']:.3f} | {m['minimal']:.3f} | "
        f"{m['old'] / m['minimal']:.3f} | {m['new'] / m['minimal']:.3f} | {m['new'] / m['old']:.3f} | "
        f"{'bit-equal' if same else 'DIFFER'} |",
        flush=True,
    )
