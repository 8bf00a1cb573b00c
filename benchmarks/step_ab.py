"""Per-call cost of `ContactSimulator.step(t, depth=)` of two checkouts side by side, in ONE
process, against the bench's minimal stepper (issue 13, the Python step path).

    .venv/bin/python benchmarks/step_ab.py <old checkout root> [--repeats 30] [--hand 8,16]

The old checkout's `viscoadh_ros/core` is copied into a temporary package (`_old_core`), so both
simulators run in this interpreter on the same scene (the kernel section's standard solid,
pressed then cycled in contact at 1 kHz, `bench.kernel.measure_kernel`'s setup), interleaved
repeat by repeat (median of repeats): old step, new step, the minimal stepper's step, where
the new step's time goes (Python, dispatch, kernel), and the old/new
`core.hand.step_contacts` per contact. Only the ratios of one run mean anything
on a shared machine.
"""

from __future__ import annotations

import argparse
import importlib
import math
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from viscoadh_ros.bench.accuracy import Case, cases, contact_config
from viscoadh_ros.bench.kernel import DEPTH_HIGH, DEPTH_LOW, STEP_S, _cycle, _kernel_steps, kelvin_material
from viscoadh_ros.bench.reference_stepper import MinimalStepper
from viscoadh_ros.bench.timing import interleaved_medians
from viscoadh_ros.core import _kernels
from viscoadh_ros.core import hand as new_hand
from viscoadh_ros.core.simulator import ContactSimulator

CALLS = 100


def old_core(root: Path):
    """The old checkout's core as the package `_old_core` (a copy, so its numba cache and
    imports stay apart)."""
    target = Path(tempfile.mkdtemp(prefix="old_core_"))
    shutil.copytree(
        root / "viscoadh_ros" / "core", target / "_old_core", ignore=shutil.ignore_patterns("__pycache__")
    )
    sys.path.insert(0, str(target))
    simulator = importlib.import_module("_old_core.simulator")
    hand = importlib.import_module("_old_core.hand")
    importlib.import_module("_old_core._kernels").warm_up()
    return simulator, hand


def contact_for(elements: int, kelvin: int):
    case = next(c for c in cases() if c.name == "standard_solid_pull_off")
    material = kelvin_material(case, kelvin)
    contact = contact_config(
        Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": elements, "model": "time_stepped"},
    )
    return case, contact


def pressed(simulator_class, contact, scale: float):
    sim = simulator_class(contact)
    ramp = np.concatenate([np.linspace(0.0, DEPTH_HIGH, 50), np.linspace(DEPTH_HIGH, DEPTH_LOW, 50)])
    for index, d in enumerate(ramp * scale):
        sim.step(index * STEP_S, depth=float(d))
    return sim


def per_call(old_sim_module, elements: int, kelvin: int, repeats: int) -> dict[str, float]:
    case, contact = contact_for(elements, kelvin)
    depth = _cycle(case, CALLS)
    new = pressed(ContactSimulator, contact, case.depth_scale)
    old = pressed(old_sim_module.ContactSimulator, contact, case.depth_scale)
    new_start, old_start = new.snapshot(), old.snapshot()
    row = new._model.row
    minimal = MinimalStepper(
        g_centres=row.g_c,
        dx=row.dx,
        e0=new.physics.e0,
        e_kelvin=new._model.e_kelvin,
        eta_kelvin=new._model.e_kelvin / new._model.rate if new._model.e_kelvin.size else np.zeros(0),
        c_crit=new.physics.c_crit,
    )
    wl0 = row.memory()[0]
    d_start, radius = new.output.depth, new._model.radius
    t0 = new.time
    times = [t0 + i * STEP_S for i in range(1, CALLS + 1)]
    depths = [float(x) for x in depth[1:]]

    def run(sim, start):
        def steps() -> None:
            sim.restore(start)
            for t, d in zip(times, depths, strict=True):
                sim.step(t, depth=d)

        return steps

    def run_minimal() -> None:
        minimal.set_state(depth=d_start, radius=radius, memory=wl0)
        for d in depths:
            minimal.step(STEP_S, d)

    runs = {"old": run(old, old_start), "new": run(new, new_start), "minimal": run_minimal}
    for fn in runs.values():
        fn()
    # Same outputs on this stretch, bit for bit.
    run(old, old_start)()
    run(new, new_start)()
    assert old.output.force == new.output.force and old.output.contact_radius == new.output.contact_radius
    medians = interleaved_medians(runs, repeats=repeats)
    return {name: value / CALLS * 1e6 for name, value in medians.items()}


def split(elements: int, kelvin: int, repeats: int) -> dict[str, float]:
    """Where the new step's time goes, us per call: the whole `step`, the packed kernel call
    from Python alone (`_advance_packed`, journal included) and the kernel looped in compiled
    code (`bench.kernel._kernel_steps`: no dispatch)."""
    case, contact = contact_for(elements, kelvin)
    depth = _cycle(case, CALLS)
    sim = pressed(ContactSimulator, contact, case.depth_scale)
    start = sim.snapshot()
    row = sim._model.row
    wl0, wb0 = row.memory()
    radius = sim._model.radius
    times = [sim.time + i * STEP_S for i in range(1, CALLS + 1)]
    depths = [float(x) for x in depth[1:]]
    max_substep = sim.numerics.max_substep
    max_edge_move = sim.numerics.max_edge_cells * row.dx

    def steps() -> None:
        sim.restore(start)
        for t, d in zip(times, depths, strict=True):
            sim.step(t, depth=d)

    def packed() -> None:
        row.set_memory(wl0, wb0)
        a, previous, out, force = radius, float(depth[0]), row.out, math.nan
        for d in depths:
            _kernels._advance_packed(
                row._state, row._const, True, a, previous, d, STEP_S, max_substep, max_edge_move, force
            )
            a, previous, force = float(out[0]), d, float(out[1])

    def compiled() -> None:
        row.set_memory(wl0, wb0)
        _kernel_steps(row.kernel_args, radius, depth, STEP_S, max_substep, max_edge_move)

    runs = {"step": steps, "packed": packed, "compiled": compiled}
    for fn in runs.values():
        fn()
    medians = interleaved_medians(runs, repeats=repeats)
    return {name: value / CALLS * 1e6 for name, value in medians.items()}


def per_hand(old_sim_module, old_hand, count: int, repeats: int) -> dict[str, float]:
    """`step_contacts` on `count` default-scene-like contacts (N = 160, K = 1), per contact."""
    case, contact = contact_for(160, 1)
    depth = _cycle(case, CALLS)
    hands = {}
    for name, cls, module in (
        ("old", old_sim_module.ContactSimulator, old_hand),
        ("new", ContactSimulator, new_hand),
    ):
        sims = [pressed(cls, contact, case.depth_scale * (1.0 + 0.01 * k)) for k in range(count)]
        hands[name] = (sims, [s.snapshot() for s in sims], module)
    t0 = hands["new"][0][0].time

    def run(name):
        sims, starts, module = hands[name]

        def steps() -> None:
            for sim, start in zip(sims, starts, strict=True):
                sim.restore(start)
            for i in range(1, CALLS + 1):
                module.step_contacts(sims, [t0 + i * STEP_S] * count, module.DEPTH, [float(depth[i])] * count)

        return steps

    runs = {f"hand_{name}": run(name) for name in hands}
    for fn in runs.values():
        fn()
    medians = interleaved_medians(runs, repeats=repeats)
    return {name: value / CALLS / count * 1e6 for name, value in medians.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--elements", default="64,160,256")
    parser.add_argument("--kelvin", default="0,1")
    parser.add_argument("--hand", default="8,16")
    args = parser.parse_args()
    old_sim, old_hand = old_core(args.old.resolve())
    print(f"per step(t, depth=) call, us (median of {args.repeats} interleaved repeats of {CALLS} calls)")
    print("| N | K | old step | new step | minimal step | old/new | new/minimal |")
    print("|---|---|---|---|---|---|---|")
    for kelvin in (int(k) for k in args.kelvin.split(",")):
        for elements in (int(n) for n in args.elements.split(",")):
            r = per_call(old_sim, elements, kelvin, args.repeats)
            print(
                f"| {elements} | {kelvin} | {r['old']:.2f} | {r['new']:.2f} | {r['minimal']:.2f} | "
                f"{r['old'] / r['new']:.2f} | {r['new'] / r['minimal']:.2f} |"
            )
    print("\nwhere the new step's time goes, us per call (same stretch)")
    print("| N | K | step() | packed kernel call | kernel in a compiled loop | Python | dispatch |")
    print("|---|---|---|---|---|---|---|")
    for kelvin in (int(k) for k in args.kelvin.split(",")):
        for elements in (int(n) for n in args.elements.split(",")):
            r = split(elements, kelvin, args.repeats)
            print(
                f"| {elements} | {kelvin} | {r['step']:.2f} | {r['packed']:.2f} | {r['compiled']:.2f} | "
                f"{r['step'] - r['packed']:.2f} | {r['packed'] - r['compiled']:.2f} |"
            )
    if args.hand:
        print("\nstep_contacts per contact, us (N = 160, K = 1, in contact)")
        print("| contacts | old | new | old/new |")
        print("|---|---|---|---|")
        for count in (int(c) for c in args.hand.split(",")):
            r = per_hand(old_sim, old_hand, count, max(3, args.repeats // 3))
            old, new = r["hand_old"], r["hand_new"]
            print(f"| {count} | {old:.2f} | {new:.2f} | {old / new:.2f} |")


if __name__ == "__main__":
    main()
