"""Cost per element of an ordinary in-contact 1 kHz step, two checkouts side by side in ONE
process (issue 13, "Kernel": the 0.4.0 round's `elem` work).

    .venv/bin/python benchmarks/element_ab.py <old checkout root> [--repeats 15] [--steps 400]
        [--cases 64,0 1024,1 ...] [--close]

The scene: the kernel section's standard solid (`bench.kernel`) with K Kelvin elements, pressed
to 1.5 JKR depth scales in 100 ms, then a slow sine (+-0.1 scale, period 2 s) at 1 kHz: one
substep per step, the edge moving less than an element (checked), in contact throughout. (The
kernel section's own cycle starts the K = 1 chain out of contact: its surface crept down and
lets go of the indenter on the way back, so its first rows time the first-touch search, not
the in-contact step.)

The old checkout's `viscoadh_ros/core` is copied into a temporary package (`_old_core`) with its
own numba cache. Per (N, K), interleaved, median of repeats: `ContactSimulator.step` per call
(old, new), the kernel `step` calls (`_advance_packed` with its journal, and for the new one
the kept force, as `_TimeStepped.advance` passes them) in a compiled loop (old, new),
`step_depths` over the same stretch (old, new) and the bench's `MinimalStepper.run` on the same
grid, in ns per element step (N elements, one step). Timed in the thread's CPU time, not wall
time: on a machine shared by several jobs (load 8-15 on 2 cores during the 0.4.0 round) wall
times swung 3x between neighbouring repeats, CPU time much less (cache sharing still moves
it). The outputs of both checkouts are compared: bit for bit (asserted), or with ``--close``
the largest difference of each output column relative to its largest value is printed.
"""

from __future__ import annotations

import argparse
import importlib
import math
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from viscoadh_ros.bench import kernel as bench_kernel
from viscoadh_ros.bench.accuracy import Case, cases, contact_config
from viscoadh_ros.bench.reference_stepper import MinimalStepper
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

STEP_S = bench_kernel.STEP_S
PRESS, AMPLITUDE, PERIOD = 1.5, 0.1, 2.0


def old_core(root: Path):
    target = Path(tempfile.mkdtemp(prefix="old_core_"))
    shutil.copytree(
        root / "viscoadh_ros" / "core", target / "_old_core", ignore=shutil.ignore_patterns("__pycache__")
    )
    sys.path.insert(0, str(target))
    module = importlib.import_module("_old_core.simulator")
    importlib.import_module("_old_core._kernels").warm_up()
    return module


def scene(simulator_class, elements: int, kelvin: int, steps: int):
    """A simulator pressed into contact and the (times, depths) of the in-contact stretch."""
    case = next(c for c in cases() if c.name == "standard_solid_pull_off")
    material = bench_kernel.kelvin_material(case, kelvin)
    contact = contact_config(
        Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": elements, "model": "time_stepped"},
    )
    sim = simulator_class(contact)
    for index, d in enumerate(np.linspace(0.0, PRESS, 101) * case.depth_scale):
        sim.step(index * STEP_S, depth=float(d))
    t = sim.time + STEP_S * np.arange(1, steps + 1)
    phase = 2.0 * math.pi * (t - sim.time) / PERIOD
    return sim, t, case.depth_scale * (PRESS + AMPLITUDE * np.sin(phase))


def interleaved_cpu_medians(runs: dict, *, repeats: int) -> dict[str, float]:
    """Median thread CPU time of each named run, s, the runs interleaved repeat by repeat."""
    samples: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.thread_time()
            run()
            samples[name].append(time.thread_time() - start)
    return {name: float(np.median(values)) for name, values in samples.items()}


def _packed_loop(advance_packed, kept: bool):
    """The kernel calls of `_TimeStepped.advance` over a depth history, compiled: journal on,
    and (``kept``) the force the call before ended with."""

    @numba.njit
    def loop(state, const, out, radius, depths, dt, max_substep, max_move):  # pragma: no cover
        force = math.nan
        for s in range(1, depths.shape[0]):
            d0, d1 = depths[s - 1], depths[s]
            if kept:
                advance_packed(state, const, True, radius, d0, d1, dt, max_substep, max_move, force)
            else:
                advance_packed(state, const, True, radius, d0, d1, dt, max_substep, max_move)
            radius = out[0]
            force = out[1]

    return loop


def _columns(outputs) -> np.ndarray:
    return np.array([[float(getattr(o, name)) for name in STEP_OUTPUT_FIELDS] for o in outputs])


def measure(old_module, elements: int, kelvin: int, steps: int, repeats: int, close: bool) -> dict:
    new, times, depths = scene(ContactSimulator, elements, kelvin, steps)
    old, _, _ = scene(old_module.ContactSimulator, elements, kelvin, steps)
    starts = {"new": new.snapshot(), "old": old.snapshot()}
    sims = {"new": new, "old": old}
    t_list, d_list = [float(x) for x in times], [float(x) for x in depths]
    minimal = MinimalStepper.on_grid_of(new)
    row = new._model.row
    wl0 = row.memory()[0]
    d_start, radius = new.output.depth, new._model.radius

    def per_call(key: str):
        sim, start = sims[key], starts[key]

        def run() -> list:
            sim.restore(start)
            return [sim.step(t, depth=d) for t, d in zip(t_list, d_list, strict=True)]

        return run

    def batch(key: str):
        sim, start = sims[key], starts[key]

        def run():
            sim.restore(start)
            return sim.step_depths(times, depths)

        return run

    def run_minimal() -> None:
        minimal.set_state(depth=d_start, radius=radius, memory=wl0)
        minimal.run(STEP_S, depths)

    history = np.concatenate(([d_start], depths))
    max_substep = float(new.numerics.max_substep)
    max_move = float(new.numerics.max_edge_cells * row.dx)
    old_row = old._model.row
    wb0 = row.memory()[1]
    kernels = {"new": sys.modules["viscoadh_ros.core._kernels"], "old": sys.modules["_old_core._kernels"]}
    kept = "force_prev" in kernels["new"]._advance_packed.py_func.__code__.co_varnames
    old_kept = "force_prev" in kernels["old"]._advance_packed.py_func.__code__.co_varnames
    loops = {
        "new": _packed_loop(kernels["new"]._advance_packed, kept),
        "old": _packed_loop(kernels["old"]._advance_packed, old_kept),
    }

    def kernel(key: str):
        target = row if key == "new" else old_row

        def run() -> None:
            target.set_memory(wl0, wb0)
            buffers = target._state, target._const, target.out
            loops[key](*buffers, radius, history, STEP_S, max_substep, max_move)

        return run

    runs = {
        "old step": per_call("old"),
        "new step": per_call("new"),
        "old kernel": kernel("old"),
        "new kernel": kernel("new"),
        "old rows": batch("old"),
        "new rows": batch("new"),
        "minimal": run_minimal,
    }
    results = {key: run() for key, run in runs.items()}
    radii = np.array([o.contact_radius for o in results["new step"]])
    substeps = new._model.substeps
    dx = row.dx
    moved = float(np.max(np.abs(np.diff(np.concatenate(([radius], radii))))) / dx)
    assert np.all(radii > 0.0), "left the contact"
    differ = {}
    for kind in ("step", "rows"):
        if kind == "step":
            a, b = _columns(results["old step"]), _columns(results["new step"])
        else:
            a = np.column_stack([results["old rows"][name].astype(float) for name in STEP_OUTPUT_FIELDS])
            b = np.column_stack([results["new rows"][name].astype(float) for name in STEP_OUTPUT_FIELDS])
        if close:
            scale = np.maximum(np.max(np.abs(a), axis=0), 1e-300)
            differ[kind] = float(np.max(np.abs(a - b) / scale))
        else:
            assert np.array_equal(a, b), f"the {kind} outputs differ"
            differ[kind] = 0.0
    medians = interleaved_cpu_medians(runs, repeats=repeats)
    per_element = {key: value / (steps * elements) * 1e9 for key, value in medians.items()}
    per_element.update(moved=moved, substeps=substeps, differ=differ)
    return per_element


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--steps", type=int, default=400)
    default = ["64,0", "1024,0", "4096,0", "64,1", "256,1", "1024,1", "4096,1", "64,4", "1024,4", "4096,4"]
    parser.add_argument("--cases", nargs="+", default=default)
    parser.add_argument("--close", action="store_true")
    args = parser.parse_args()
    old_module = old_core(args.old.resolve())
    print(
        f"ns per element step (median of {args.repeats} interleaved repeats of {args.steps} "
        "in-contact 1 kHz steps)"
    )
    print(
        "| N | K | step() old | new | old/new | kernel call old | new | old/new | step_depths old | new "
        "| old/new | minimal run | rows new/minimal | edge move (cells) | outputs |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for spec in args.cases:
        elements, kelvin = (int(v) for v in spec.split(","))
        r = measure(old_module, elements, kelvin, args.steps, args.repeats, args.close)
        note = "bit-equal" if not args.close else f"<= {max(r['differ'].values()):.1e} of each column"
        step, rows = (r["old step"], r["new step"]), (r["old rows"], r["new rows"])
        kernel = r["old kernel"], r["new kernel"]
        print(
            f"| {elements} | {kelvin} | {step[0]:.2f} | {step[1]:.2f} | {step[0] / step[1]:.2f} "
            f"| {kernel[0]:.2f} | {kernel[1]:.2f} | {kernel[0] / kernel[1]:.2f} "
            f"| {rows[0]:.2f} | {rows[1]:.2f} | {rows[0] / rows[1]:.2f} | {r['minimal']:.2f} "
            f"| {rows[1] / r['minimal']:.2f} | {r['moved']:.3f} | {note} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
