"""Side-by-side A/B of several kernel modules on the batch path (`step_depths`, `_advance_rows`),
interleaved in ONE process, with the minimal stepper beside them (issue 13, 0.5.0 `kern`).

    .venv/bin/python benchmarks/rows_ab.py [--repeats R] [--close] ROOT [ROOT ...] -- SCENE [SCENE ...]

Each ROOT is a checkout whose ``viscoadh_ros/core/_kernels.py`` is loaded under its own module
name (`ab_cores.renamed_kernels`; this checkout too, so every side pays the same loader), the
first is the reference. SCENE is one of

- ``replay``: `step_depths` over the replay bench's 1 kHz history (`bench.replay_speed`: the
  default numerics' rate-dependent solid, N = 160, K = 1; out of contact, snap-in, sticking,
  pull-off) from a fresh simulator, the simulator module pointed at each kernel module in turn
  (`simulator._kernels`); 4 s (two cycles);
- ``bench:N,K``: `_advance_rows` on the kernel section's state (`bench.kernel.measure_kernel`:
  pressed, held until the memory relaxed, then 400 rows of its cycle, in contact);
- ``contact:N,K``: `_advance_rows` on `element_ab.py`'s scene (pressed to 1.5 JKR scales, a slow
  sine, one substep per row, in contact).

Per scene: us per row of each module and of `MinimalStepper.run` on the same grid and history
(the 2x target's baseline), median thread CPU time of interleaved repeats, and each module's
ratio to the reference and to the minimal stepper. Outputs: every module's rows must equal the
reference's bit for bit (asserted), or with ``--close`` the largest difference of each output
column relative to that column's largest value is printed (the force also relative to the
pull-off force, the quantity that matters).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ab_cores import renamed_kernels  # noqa: E402
from element_ab import scene as contact_scene  # noqa: E402

from viscoadh_ros.bench import kernel as bench_kernel  # noqa: E402
from viscoadh_ros.bench.accuracy import Case, cases, contact_config  # noqa: E402
from viscoadh_ros.bench.latency import bench_scene  # noqa: E402
from viscoadh_ros.bench.reference_stepper import MinimalStepper  # noqa: E402
from viscoadh_ros.core import simulator as simulator_module  # noqa: E402
from viscoadh_ros.core.config import SceneConfig  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

STEP_S = 1e-3
REPLAY_SECONDS = 4.0


def _cpu_medians(runs: dict, repeats: int) -> dict[str, float]:
    samples: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.thread_time()
            run()
            samples[name].append(time.thread_time() - start)
    return {name: float(np.median(v)) for name, v in samples.items()}


def _rows_caller(advance_rows):
    @numba.njit
    def call(row_args, backup, backup_b, radius, t0, d0, peak, times, depths, ms, mm, out):
        return advance_rows(
            *row_args, backup, backup_b, radius, t0, d0, peak, times, depths, 0, ms, mm, 0.0, out
        )

    return call


def _with_kernels(module, run):
    """`run` with the simulator module on `module`'s kernels, its per-call step entry
    (`simulator._STEP`, bound once from the kernels of the first model built) included: left
    bound to the first module, a later scene's `step()` calls ran that module's kernel on
    another module's row buffers (0.7.0: their constant layouts differ), and the scenes built
    after a `replay` scene started from a garbage state."""

    def wrapped():
        saved = simulator_module._kernels, simulator_module._STEP
        simulator_module._kernels = module
        simulator_module._STEP = None
        try:
            return run()
        finally:
            simulator_module._kernels, simulator_module._STEP = saved

    return wrapped


def replay_scene(modules: dict, repeats: int):
    """`step_depths` over the replay bench's history from a fresh simulator, per module."""
    scene_map, amplitude = bench_scene(1)
    contact = SceneConfig.from_dict(scene_map).contacts[0]
    count = int(round(REPLAY_SECONDS / STEP_S))
    index = np.arange(count)
    phase = 0.5 - 0.5 * np.cos(2.0 * math.pi * index * STEP_S / 2.0)
    depths = amplitude * (1.2 * phase - 0.2)
    times = 1.0 + index * STEP_S
    results = {}

    def stepper(module):
        def run():
            return ContactSimulator(contact).step_depths(times, depths)

        return _with_kernels(module, run)

    runs = {name: stepper(module) for name, module in modules.items()}
    for name, run in runs.items():
        results[name] = run()
    reference = ContactSimulator(contact)
    reference.step_depths(times, depths)
    minimal = MinimalStepper.on_grid_of(reference)

    def run_minimal():
        minimal.set_state(depth=0.0, radius=0.0, memory=np.zeros_like(reference._model.row.wl))
        minimal.run(STEP_S, depths)

    runs["minimal"] = run_minimal
    run_minimal()
    columns = {
        name: np.column_stack([np.asarray(value, dtype=np.float64) for key, value in sorted(res.items())])
        for name, res in results.items()
    }
    keys = sorted(next(iter(results.values())).keys())
    in_contact = float(np.mean(next(iter(results.values()))["contact_radius"] > 0.0))
    pull_off = abs(float(np.min(next(iter(results.values()))["force"])))
    model = reference._model
    label = f"replay N={model.row.elements} K={model.e_kelvin.size} in contact {in_contact:.2f}"
    return label, runs, columns, keys, count, pull_off


def _own_row(module, row):
    """`row` rebuilt by `module`'s own `Row` (its state layout: 0.10.0 aliases wsum and bsum to
    wl and wb at K = 1, and a module run on another layout's views measures the wrong loops:
    the old loops on aliased views lost their vectorisation, ~1.5-2x per row). The same
    numbers: geometry, chain and memory copied."""
    keys = ("dx", "g_c", "gf", "gint", "df", "reach", "p", "p_inv", "lam", "beta", "rate", "e_kelvin")
    values = {key: getattr(row, key) for key in keys}
    values = {key: value.copy() if isinstance(value, np.ndarray) else value for key, value in values.items()}
    wl, wb = row.memory()
    own = module.Row(**values, steady=row.steady.copy(), e0=row.e0, c_crit=row.c_crit, wl=wl, wb=wb)
    own.coef[...] = row.coef
    return own


def _rows_scene(sim: ContactSimulator, times, depths, modules: dict):
    model = sim._model
    row, radius = model.row, model.radius
    wl0, wb0 = row.memory()
    ms = float(sim.numerics.max_substep)
    mm = float(sim.numerics.max_edge_cells * row.dx)
    t0, d0 = sim.time, sim.output.depth
    peak = float(np.max(np.abs(row.wsum), initial=0.0))
    backup, backup_b = np.empty_like(row.wl), np.empty_like(row.wl)
    count = times.size
    outs = {}
    runs = {}
    for name, module in modules.items():
        call = _rows_caller(module._advance_rows)
        own = _own_row(module, row)
        args = tuple(getattr(own, key) for key in module.Row._build_kernel_args.__code__.co_names)
        rows = np.zeros((count, module.ROW_SIZE))
        outs[name] = rows

        def run(call=call, args=args, rows=rows, own=own):
            own.set_memory(wl0, wb0)
            i, status = call(args, backup, backup_b, radius, t0, d0, peak, times, depths, ms, mm, rows)
            assert i == count and status == 0, (i, status)

        runs[name] = run
    minimal = MinimalStepper.on_grid_of(sim)

    def run_minimal():
        minimal.set_state(depth=d0, radius=radius, memory=wl0)
        minimal.run(STEP_S, depths)

    runs["minimal"] = run_minimal
    for run in runs.values():
        run()
    row.set_memory(wl0, wb0)
    keys = [
        "radius",
        "force",
        "work",
        "motion",
        "substeps",
        "dissipated",
        "memory",
        "gap_out",
        "gap_in",
        "g_edge",
    ]
    pull_off = abs(float(np.min(outs[next(iter(outs))][:, 1])))
    in_contact = float(np.mean(outs[next(iter(outs))][:, 0] > 0.0))
    return runs, outs, keys, in_contact, pull_off


def bench_rows_scene(spec: str, modules: dict):
    n, k = (int(v) for v in spec.split(","))
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
    depth = bench_kernel._cycle(case, 400)
    times = sim.time + STEP_S * np.arange(1, 401)
    runs, outs, keys, in_contact, pull_off = _rows_scene(sim, times, depth[1:], modules)
    return f"bench N={n} K={k} in contact {in_contact:.2f}", runs, outs, keys, times.size, pull_off


def contact_rows_scene(spec: str, modules: dict):
    n, k = (int(v) for v in spec.split(","))
    sim, times, depths = contact_scene(ContactSimulator, n, k, 400)
    runs, outs, keys, in_contact, pull_off = _rows_scene(sim, times, depths, modules)
    return f"contact N={n} K={k} in contact {in_contact:.2f}", runs, outs, keys, times.size, pull_off


def compare(outs: dict, keys: list[str], close: bool, pull_off: float) -> str:
    names = list(outs)
    ref = outs[names[0]]
    notes = []
    for name in names[1:]:
        got = outs[name]
        if np.array_equal(ref, got, equal_nan=True):
            notes.append(f"{name}: equal")
            continue
        if not close:
            raise AssertionError(f"{name}'s rows differ from {names[0]}'s")
        scale = np.maximum(np.nanmax(np.abs(ref), axis=0), 1e-300)
        diff = np.nanmax(np.abs(ref - got), axis=0)
        parts = [f"{key} {d / s:.1e}" for key, d, s in zip(keys, diff, scale, strict=True) if d > 0]
        force = keys.index("force")
        parts.append(f"force/pull-off {diff[force] / max(pull_off, 1e-300):.1e}")
        notes.append(f"{name}: " + ", ".join(parts))
    return "; ".join(notes)


def main() -> None:
    argv = sys.argv[1:]
    repeats = 21
    close = "--close" in argv
    argv = [a for a in argv if a != "--close"]
    if "--repeats" in argv:
        at = argv.index("--repeats")
        repeats = int(argv[at + 1])
        del argv[at : at + 2]
    split = argv.index("--")
    roots, scenes = argv[:split], argv[split + 1 :]
    modules = {}
    for index, root in enumerate(roots):
        modules[f"{chr(ord('A') + index)}"] = renamed_kernels(root)
        print(f"{chr(ord('A') + index)} = {root}", flush=True)
    for module in modules.values():
        module.warm_up()
    for spec in scenes:
        kind, _, rest = spec.partition(":")
        if kind == "replay":
            label, runs, outs, keys, count, pull_off = replay_scene(modules, repeats)
        elif kind == "bench":
            label, runs, outs, keys, count, pull_off = bench_rows_scene(rest, modules)
        elif kind == "contact":
            label, runs, outs, keys, count, pull_off = contact_rows_scene(rest, modules)
        else:
            raise SystemExit(f"unknown scene {spec!r}")
        note = compare(outs, keys, close, pull_off)
        med = _cpu_medians(runs, repeats)
        us = {name: value / count * 1e6 for name, value in med.items()}
        first = next(iter(modules))
        cells = [f"{name} {us[name]:.3f}" for name in modules]
        ratios = [f"{first}/{name} {us[first] / us[name]:.3f}" for name in list(modules)[1:]]
        to_min = [f"{name}/min {us[name] / us['minimal']:.2f}" for name in modules]
        print(
            f"{label}: us/row "
            + ", ".join(cells)
            + f", minimal {us['minimal']:.3f} | "
            + ", ".join(ratios)
            + " | "
            + ", ".join(to_min)
            + f" | {note}",
            flush=True,
        )


if __name__ == "__main__":
    main()
