"""`ContactSimulator.step` per call from Python, an old checkout's core against this one's, side
by side in one process (issue 13, kernel target "from Python"; 0.5.0 round `pycall`).

For each element count N and Kelvin count K: the `kernel` bench section's scene (the standard
solid pull-off case with K Kelvin elements, pressed, withdrawn to the cycle's start and held;
then 100 rows of its 1 kHz depth cycle, in contact, the edge moving), stepped by both cores'
`step(t, depth=d)` and by the bench's minimal stepper (`MinimalStepper.step`, this checkout's),
interleaved, median of the repeats, us per call; the outputs of the two cores compared field
by field (bit for bit). Then `core.hand.step_contacts` on 16 such contacts (N = 160, the
default numerics' count, K = 1) per contact, both cores, against 16 minimal steps.

    git worktree add /work/ab/<name>-base main
    .venv/bin/python benchmarks/pycall_ab.py /work/ab/<name>-base [repeats]
"""

from __future__ import annotations

import importlib
import math
import os
import sys

import ab_cores
import numpy as np

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
roots = {"old": os.path.abspath(sys.argv[1]), "new": here}
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 15
SIZES = [(n, k) for k in (0, 1, 4) for n in (64, 256, 1024, 4096)]
ROWS = 100
HAND = 16

cores = {}
for label, root in roots.items():
    cores[label] = ab_cores.load(root, rename_kernels=label == "old")
    # Imported now: the next `load` drops this core's modules from sys.modules.
    cores[label]["hand"] = importlib.import_module("viscoadh_ros.core.hand")
    assert cores[label]["hand"].__file__.startswith(root)
new_bench = cores["new"]["bench_kernel"]
interleaved_medians = new_bench.interleaved_medians
MinimalStepper = new_bench.MinimalStepper


def scene(core: dict, elements: int, kelvin: int):
    """The kernel section's start state (`bench.kernel.measure_kernel`) and its depth cycle."""
    bench = core["bench_kernel"]
    case = next(c for c in bench.cases() if c.name == "standard_solid_pull_off")
    material = bench.kelvin_material(case, kelvin)
    contact = bench.contact_config(
        bench.Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": elements, "model": "time_stepped"},
    )
    depth = [float(x) for x in bench._cycle(case, ROWS)]
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


def values(output) -> tuple:
    return tuple(
        int(v) if name == "phase" else v
        for name, v in zip(FIELDS, (getattr(output, f) for f in FIELDS), strict=True)
    )


FIELDS = cores["new"]["simulator"].STEP_OUTPUT_FIELDS


def stepper(sim, start, depth):
    t0 = sim.time

    def run() -> list:
        sim.restore(start)
        step = sim.step
        return [step(t0 + i * 1e-3, depth=depth[i]) for i in range(1, ROWS + 1)]

    return run


print(f"step() per call, us (median of {repeats} interleaved runs of {ROWS} rows)")
print("| N | K | old step | new step | minimal | old / minimal | new / minimal | old / new | outputs |")
print("|---|---|---|---|---|---|---|---|---|")
for elements, kelvin in SIZES:
    runs = {}
    results = {}
    minimal = None
    for label, core in cores.items():
        sim, start, depth = scene(core, elements, kelvin)
        runs[label] = stepper(sim, start, depth)
        results[label] = [values(o) for o in runs[label]()]
        if label == "new":
            model = sim._model
            radius, d_start = model.radius, sim._depth
            wl0 = model.row.wl.copy()
            minimal = MinimalStepper.on_grid_of(sim)

            def run_minimal(minimal=minimal, radius=radius, d_start=d_start, wl0=wl0, depth=depth) -> None:
                minimal.set_state(depth=d_start, radius=radius, memory=wl0)
                step = minimal.step
                for i in range(1, ROWS + 1):
                    step(1e-3, depth[i])

            runs["minimal"] = run_minimal
    same = all(
        a == b or all((x == y) or (math.isnan(x) and math.isnan(y)) for x, y in zip(a, b, strict=True))
        for a, b in zip(results["old"], results["new"], strict=True)
    )
    for run in runs.values():
        run()
    m = {key: value / ROWS * 1e6 for key, value in interleaved_medians(runs, repeats=repeats).items()}
    print(
        f"| {elements} | {kelvin} | {m['old']:.2f} | {m['new']:.2f} | {m['minimal']:.2f} | "
        f"{m['old'] / m['minimal']:.2f} | {m['new'] / m['minimal']:.2f} | {m['old'] / m['new']:.2f} | "
        f"{'bit-equal' if same else 'DIFFER'} |"
    )

# The hand topic: 16 contacts stepped as one sample (`core.hand.step_contacts`), per contact.
print()
print(f"core.hand.step_contacts, {HAND} contacts (N = 160, K = 1), us per contact")
hand_runs = {}
for label, core in cores.items():
    hand = core["hand"]
    sims, starts = [], []
    for _ in range(HAND):
        sim, start, depth = scene(core, 160, 1)
        sims.append(sim)
        starts.append(start)
    t0 = sims[0].time

    def run_hand(sims=sims, starts=starts, depth=depth, hand=hand, t0=t0) -> None:
        for sim, start in zip(sims, starts, strict=True):
            sim.restore(start)
        step_contacts = hand.step_contacts
        for i in range(1, ROWS + 1):
            t = t0 + i * 1e-3
            step_contacts(sims, [t] * HAND, hand.DEPTH, [depth[i]] * HAND)

    hand_runs[label] = run_hand
minimals = [MinimalStepper.on_grid_of(sim) for sim in sims]
memory = sims[0]._model.row.wl.copy()
radius, d_start = sims[0]._model.radius, sims[0]._depth


def run_minimal_hand() -> None:
    for minimal in minimals:
        minimal.set_state(depth=d_start, radius=radius, memory=memory)
    for i in range(1, ROWS + 1):
        for minimal in minimals:
            minimal.step(1e-3, depth[i])


hand_runs["minimal"] = run_minimal_hand
for run in hand_runs.values():
    run()
m = {
    key: value / (ROWS * HAND) * 1e6 for key, value in interleaved_medians(hand_runs, repeats=repeats).items()
}
print("| old | new | minimal | old / minimal | new / minimal | old / new |")
print("|---|---|---|---|---|---|")
print(
    f"| {m['old']:.2f} | {m['new']:.2f} | {m['minimal']:.2f} | {m['old'] / m['minimal']:.2f} | "
    f"{m['new'] / m['minimal']:.2f} | {m['old'] / m['new']:.2f} |"
)
