"""Cost of the simulator's step against a minimal stepper of the same model (issue 13).

Per element count N and Kelvin count K, on a standard-solid sphere driven through a 1 kHz
depth cycle that keeps the contact open and its edge moving, side by side in one run:

- the product's compiled kernel (`core._kernels._advance` on the row `ContactSimulator`
  built, looped in numba), `step_depths` per row, and `ContactSimulator.step` per call;
- `bench.reference_stepper.MinimalStepper` on the same grid from the same state, as one
  compiled run (`run`) and per call (`step`): the smallest correct program of the model, the
  baseline of the 2x target; its agreement with the product (pull-off and branch forces
  relative to the pull-off force, jump rows excluded) is stated beside its time;
- a bare compiled loop that only reads and writes the state arrays once per step: the
  memory floor no stepper reaches.

`step_costs` measures the other target: every step bounded (snap-in and pull-off rows
against the median step of the scene) and force control against depth control.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from viscoadh_ros.bench.accuracy import Case, cases, contact_config
from viscoadh_ros.bench.reference_stepper import MinimalStepper
from viscoadh_ros.bench.timing import interleaved_medians
from viscoadh_ros.core import _kernels
from viscoadh_ros.core import simulator as simulator_module
from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.core.simulator import ContactSimulator

STEP_S = 1e-3  # the node's command period at 1 kHz
STEP_TIMING_STEPS = 100
CYCLE_S = 2.0  # slow enough that the edge crosses about one element per step at 4096 elements
# The depth cycles between these multiples of the case's JKR depth scale: always in contact.
DEPTH_LOW, DEPTH_HIGH = 0.5, 2.0
#: Rows of the pull-off run that states the minimal stepper's agreement with the product.
AGREEMENT_ROWS = 400
#: 1 kHz rows held at the cycle's start before timing (several retardation times of the cases).
HOLD_STEPS = 1500


@numba.njit(cache=True)
def _bare_steps(wl, wsum, g_c, depth):  # pragma: no cover - compiled
    """The floor: per step, read and write every Kelvin elongation and sum once."""
    n, k_count = wl.shape
    for s in range(depth.shape[0]):
        d = depth[s]
        for i in range(n):
            u = d - g_c[i]
            total = 0.0
            for k in range(k_count):
                # A data-dependent update the compiler cannot drop or hoist out of the loop.
                value = 0.5 * wl[i, k] + 1e-3 * u
                wl[i, k] = value
                total += value
            wsum[i] = total + 1e-3 * u


# Not cached: numba's on-disk cache of a function does not notice a change to the functions it
# calls in another module, so a cached loop would go on timing the kernel it was first built with.
@numba.njit
def _kernel_steps(row_args, radius, depth, dt, max_substep, max_edge_move):  # pragma: no cover - compiled
    """The simulator's kernel over a depth history; returns the total number of substeps.

    row_args: `Row.kernel_args`, the tuple the public wrapper `_kernels.advance` passes.
    """
    out = row_args[-1]
    substeps = 0
    for s in range(1, depth.shape[0]):
        status = _kernels._advance(*row_args, radius, depth[s - 1], depth[s], dt, max_substep, max_edge_move)
        if status != _kernels.STATUS_OK:
            return -1
        radius = out[_kernels.OUT_RADIUS]
        substeps += int(out[_kernels.OUT_SUBSTEPS])
    return substeps


# Where a row's time goes (the measured cause beside a missed 2x target): each part of the
# kernel's row alone, over the same depth history on the same row, compiled loops (not cached,
# as `_kernel_steps`). The kernel computes these inside its step; timed alone they show which
# part is already beyond the minimal stepper's whole row.
@numba.njit
def _update_parts(wl, wsum, wb, bsum, diss, n_in, depth, dt, g_c, p, p_inv, lam, beta, coef, e_kelvin, dx):
    """The Kelvin update of every element per row (A and B states, damper work, the losses'
    sum and the memory peak), with the step's coefficients computed once (the kernel keeps
    them per step length)."""
    n = wl.shape[0]
    total = 0.0
    for s in range(1, depth.shape[0]):  # pragma: no cover - compiled
        lost, _ = _kernels._update_range(
            wl, wsum, wb, bsum, diss, 0, n, n_in, depth[s - 1], depth[s], (depth[s] - depth[s - 1]) / dt,
            g_c, p, p_inv, lam, beta, coef, e_kelvin, dx, 0.0, 0.0,
        )  # fmt: skip
        total += lost
    return total


@numba.njit
def _force_parts(radius, depth, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, buf, wb, p, p_inv, lam, beta):
    """The contact force (its memory integral) once per row at the row's edge."""
    total = 0.0
    for s in range(1, depth.shape[0]):  # pragma: no cover - compiled
        total += _kernels._force(
            radius, depth[s], wsum, bsum, dx, g_c, gf, gint, df, e0, kap, buf, wb, p, p_inv, lam, beta
        )
    return total


@numba.njit
def _edge_parts(radius, depth, wsum, bsum, dx, g_c, gf, gmin, gmax, df, c_crit, reach, max_move):
    """The edge search once per row from the row's edge (limited to the kernel's edge move)."""
    total = 0.0
    for s in range(1, depth.shape[0]):  # pragma: no cover - compiled
        found, _, _ = _kernels._locate_edge(
            radius, depth[s], wsum, bsum, dx, g_c, gf, gmin, gmax, df, c_crit, reach, max_move
        )
        total += found
    return total


def _part_runs(
    row: _kernels.Row, radius: float, depth: npt.NDArray[np.float64], max_edge_move: float
) -> dict:
    """The timed parts of a row (see `_update_parts`): callables for `interleaved_medians`.
    The update writes the memory: each run starts from the row's memory as the caller left it
    (`measure_kernel` sets it before every kernel run)."""
    n_in = _kernels._interior_count(radius, row.dx, row.elements)
    runs: dict[str, Any] = {}
    if row.wl.shape[1]:
        coef = _kernels.coefficient_workspace(row.wl.shape[1])
        _kernels._substep_coefficients(row.lam, row.rate, STEP_S, coef)

        def run_update() -> None:
            _update_parts(
                row.wl, row.wsum, row.wb, row.bsum, row.diss, n_in, depth, STEP_S, row.g_c,
                row.p, row.p_inv, row.lam, row.beta, coef, row.e_kelvin, row.dx,
            )  # fmt: skip

        runs["part_update"] = run_update
    buf = np.empty(row.elements)

    def run_force() -> None:
        _force_parts(
            radius,
            depth,
            row.wsum,
            row.bsum,
            row.dx,
            row.g_c,
            row.gf,
            row.gint_kernel,
            row.df,
            row.e0,
            row.kap,
            buf,
            row.wb,
            row.p,
            row.p_inv,
            row.lam,
            row.beta,
        )

    def run_edge() -> None:
        _edge_parts(
            radius, depth, row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df,
            row.c_crit, row.reach, max_edge_move,
        )  # fmt: skip

    runs["part_force"] = run_force
    runs["part_edge"] = run_edge
    return runs


def kelvin_material(case: Case, kelvin: int) -> dict[str, Any]:
    """The case's material with `kelvin` Kelvin elements sharing its relaxed modulus.

    K = 0 is the elastic glass spring alone; for K > 1 the retardation times spread over a
    decade each side of the case's, so the chain is a genuine K-mode one.
    """
    material = dict(case.contact["material"])
    if kelvin == 0:
        return {"glass_shear_modulus": material["glass_shear_modulus"]}
    moduli = material["kelvin_shear_moduli"][0] * kelvin
    viscosity = material["kelvin_viscosities"][0] * kelvin
    spread = np.logspace(-1.0, 1.0, kelvin) if kelvin > 1 else np.ones(1)
    material["kelvin_shear_moduli"] = [moduli] * kelvin
    material["kelvin_viscosities"] = [float(viscosity * f) for f in spread]
    return material


def _cycle(case: Case, steps: int) -> npt.NDArray[np.float64]:
    t = np.arange(steps + 1) * STEP_S
    phase = 0.5 - 0.5 * np.cos(2.0 * math.pi * t / CYCLE_S)
    return case.depth_scale * (DEPTH_LOW + (DEPTH_HIGH - DEPTH_LOW) * phase)


def _agreement(contact: Any, row: _kernels.Row, minimal: MinimalStepper, scale: float) -> dict[str, float]:
    """How far the minimal stepper is from the product on one press and pull-off from rest
    (to the cycle's deepest point and out past pull-off, 1 kHz rows), the product on the same
    fixed grid (`numerics.domain_radius` = the row's length): the pull-off (most tensile
    force) relative difference, and the largest force difference relative to the product's
    pull-off force over the rows where neither jumps (both in contact or both out, and
    neither edge moved more than two elements in the row)."""
    numerics = replace(contact.numerics, domain_radius=row.length, elements=row.elements)
    product_sim = ContactSimulator(replace(contact, numerics=numerics))
    depths = scale * np.concatenate(
        [
            np.linspace(0.0, DEPTH_HIGH, AGREEMENT_ROWS // 4 + 1)[1:],
            np.linspace(DEPTH_HIGH, -2.0, AGREEMENT_ROWS)[1:],
        ]
    )
    times = STEP_S * np.arange(1, depths.size + 1)
    product = product_sim.step_depths(times, depths)
    minimal.set_state(depth=0.0, radius=0.0, memory=np.zeros_like(row.wl))
    radius_min = np.empty(depths.size)
    force_min = np.empty(depths.size)
    for index, d in enumerate(depths):
        force_min[index] = minimal.step(STEP_S, float(d))
        radius_min[index] = minimal.radius
    pull_off = float(np.min(product["force"]))
    r_p = np.concatenate(([0.0], product["contact_radius"]))
    r_m = np.concatenate(([0.0], radius_min))
    steady = (
        ((r_p[1:] > 0.0) == (r_m[1:] > 0.0))
        & (np.abs(np.diff(r_p)) <= 2.0 * row.dx)
        & (np.abs(np.diff(r_m)) <= 2.0 * row.dx)
    )
    diff = np.abs(product["force"] - force_min)[steady]
    return {
        "pull_off_rel_diff": abs(float(np.min(force_min)) - pull_off) / abs(pull_off),
        "max_force_diff_rel": float(np.max(diff, initial=0.0)) / abs(pull_off),
    }


def measure_kernel(elements: int, kelvin: int, *, steps: int, repeats: int) -> dict[str, Any]:
    """One row of the `kernel` results section (see the module docstring)."""
    case = next(c for c in cases() if c.name == "standard_solid_pull_off")
    material = kelvin_material(case, kelvin)
    contact = contact_config(
        Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": elements, "model": "time_stepped"},
    )
    depth = _cycle(case, steps)
    simulator = ContactSimulator(contact)
    # Press to the cycle's deepest point (the row is created and grown to fit the whole cycle),
    # come back to its start and hold there until the memory has relaxed: a body that creeps
    # (K >= 1) lets go of an indenter withdrawn faster than it recovers, so without the hold
    # the timed cycle would start out of contact and time the first-touch search and the
    # re-contact instead of ordinary in-contact steps (0.4.0: it did for K = 1).
    ramp = np.concatenate(
        [
            np.linspace(0.0, DEPTH_HIGH, 50),
            np.linspace(DEPTH_HIGH, DEPTH_LOW, 50),
            np.full(HOLD_STEPS, DEPTH_LOW),
        ]
    )
    for index, d in enumerate(ramp * case.depth_scale):
        simulator.step(index * STEP_S, depth=float(d))
    start = simulator.snapshot()
    model = simulator._model  # the benchmark times the private kernel on the simulator's own row
    row = model.row
    radius = model.radius
    numerics = simulator.numerics
    wl0, wb0 = row.memory()
    d_start = simulator.output.depth
    # The minimal stepper on the product's own grid, from the product's own state.
    minimal = MinimalStepper.on_grid_of(simulator)

    max_substep = float(numerics.max_substep)
    max_edge_move = float(numerics.max_edge_cells * row.dx)

    def run_kernel() -> int:
        row.set_memory(wl0, wb0)
        return _kernel_steps(row.kernel_args, radius, depth, STEP_S, max_substep, max_edge_move)

    def run_bare() -> None:
        _bare_steps(row.wl, row.wsum, row.g_c, depth)

    def run_minimal() -> None:
        minimal.set_state(depth=d_start, radius=radius, memory=wl0)
        minimal.run(STEP_S, depth[1:])

    t0 = simulator.time
    batch_times = t0 + STEP_S * np.arange(1, steps + 1)

    def run_batch() -> None:
        simulator.restore(start)
        simulator.step_depths(batch_times, depth[1:])

    simulator.restore(start)
    in_contact = float(np.mean(simulator.step_depths(batch_times, depth[1:])["contact_radius"] > 0.0))

    minimal.step(STEP_S, float(depth[0]))  # compiles the per-call entry point
    substeps = run_kernel()  # compiles (or loads the cache) outside the timing
    if substeps < 0:
        raise RuntimeError(f"kernel benchmark: the contact outgrew its domain at {elements} elements")
    run_bare()
    run_minimal()
    run_batch()
    row.set_memory(wl0, wb0)
    parts = _part_runs(row, radius, depth, max_edge_move)
    for run in parts.values():
        run()  # compiles outside the timing
    times = interleaved_medians(
        {"kernel": run_kernel, "bare": run_bare, "minimal": run_minimal, "batch": run_batch, **parts},
        repeats=repeats,
    )

    # Per call from Python, side by side: the whole `ContactSimulator.step` and the minimal
    # stepper's `step`, on a shorter stretch of the same cycle.
    step_count = min(steps, STEP_TIMING_STEPS)

    def run_steps() -> None:
        simulator.restore(start)
        for index in range(1, step_count + 1):
            simulator.step(t0 + index * STEP_S, depth=float(depth[index]))

    def run_minimal_steps() -> None:
        minimal.set_state(depth=d_start, radius=radius, memory=wl0)
        for index in range(1, step_count + 1):
            minimal.step(STEP_S, float(depth[index]))

    # The same stretch in one batch call each: what a call costs beyond its row is the
    # difference (the Python around the kernel and the compiled call, the journal).
    call_times = batch_times[:step_count]
    call_depths = depth[1 : step_count + 1]

    def run_steps_batch() -> None:
        simulator.restore(start)
        simulator.step_depths(call_times, call_depths)

    def run_minimal_steps_batch() -> None:
        minimal.set_state(depth=d_start, radius=radius, memory=wl0)
        minimal.run(STEP_S, call_depths)

    calls = interleaved_medians(
        {
            "step": run_steps,
            "minimal_step": run_minimal_steps,
            "step_batch": run_steps_batch,
            "minimal_step_batch": run_minimal_steps_batch,
        },
        repeats=max(1, repeats),
    )
    agreement = _agreement(contact, row, minimal, case.depth_scale)
    element_steps = row.elements * steps
    kernel_ns = times["kernel"] / element_steps * 1e9
    bare_ns = times["bare"] / element_steps * 1e9
    minimal_ns = times["minimal"] / element_steps * 1e9
    step_us = calls["step"] / step_count * 1e6
    minimal_step_us = calls["minimal_step"] / step_count * 1e6
    batch_us = times["batch"] / steps * 1e6
    minimal_run_us = times["minimal"] / steps * 1e6
    return {
        "elements": row.elements,
        "kelvin": kelvin,
        "ns_per_element_step": kernel_ns,
        "baseline_ns_per_element_step": bare_ns,
        "ratio": kernel_ns / bare_ns,
        "minimal_ns_per_element_step": minimal_ns,
        "kernel_vs_minimal": kernel_ns / minimal_ns,
        "substeps_per_step": substeps / steps,
        "in_contact": in_contact,
        "step_us": step_us,
        "minimal_step_us": minimal_step_us,
        "python_ratio": step_us / minimal_step_us,
        "batch_us": batch_us,
        "minimal_run_us": minimal_run_us,
        "batch_ratio": batch_us / minimal_run_us,
        # Where a batch row goes: each part of the kernel's row timed alone (`_part_runs`), us
        # per row; the rest (substeps beyond the first, retiming, outputs) is what is left.
        "part_update_us": times.get("part_update", 0.0) / steps * 1e6,
        "part_force_us": times["part_force"] / steps * 1e6,
        "part_edge_us": times["part_edge"] / steps * 1e6,
        # Per call beyond the row: `step()` less `step_depths` over the same stretch, and the
        # same for the minimal stepper (its `step` less its `run`), us per call.
        "call_overhead_us": (calls["step"] - calls["step_batch"]) / step_count * 1e6,
        "minimal_call_overhead_us": (calls["minimal_step"] - calls["minimal_step_batch"]) / step_count * 1e6,
        **agreement,
    }


def kernel_table(
    *, elements: Sequence[int], kelvin: Sequence[int], steps: int, repeats: int
) -> list[dict[str, Any]]:
    """The `kernel` results section: every element count at every Kelvin count."""
    return [measure_kernel(n, k, steps=steps, repeats=repeats) for k in kelvin for n in elements]


#: The bounded-step scene: the built-in default contact (balanced) pressed and pulled off
#: along a sine (snap-in, sticking, pull-off, out of contact with memory left) at 1 kHz.
SCENE_SECONDS = 3.0
SCENE_AMPLITUDE = 80e-6
SCENE_OFFSET = -10e-6


def _scene_history(seconds: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    t = STEP_S * np.arange(1, int(round(seconds / STEP_S)) + 1)
    return t, SCENE_AMPLITUDE * np.sin(2.0 * math.pi * t / seconds) + SCENE_OFFSET


def _per_step(simulator: ContactSimulator, times, values, key: str) -> npt.NDArray[np.float64]:
    """Wall time of each `step` call, s."""
    cost = np.empty(times.size)
    clock = time.perf_counter
    for index in range(times.size):
        start = clock()
        simulator.step(float(times[index]), **{key: float(values[index])})
        cost[index] = clock() - start
    return cost


def _row_work(contact: Any, times, values, key: str) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """What each `step` call did (the measured cause of a slow row): the model trials it ran
    (force control searches the depth, one trial per depth tried; a depth step is one) and the
    kernel substeps of those trials together, per row, on a fresh simulator. Counted at the
    compiled step every path calls (`simulator._STEP`: the lean depth and force paths and
    `_TimeStepped.advance`): a trial is a kernel call that stepped (one that stopped for a
    domain growth is not, its substeps count; one whose energies overflow, STATUS_OVERFLOW,
    stepped); a row with no call (idle above the surface) is one trial of no substep."""
    simulator = ContactSimulator(contact)  # loads the compiled step
    counted = [0, 0]
    kernel_step = simulator_module._STEP

    def counting_step(*args: Any) -> Any:
        result = kernel_step(*args)
        counted[0] += result[0] != _kernels.STATUS_GROW
        counted[1] += int(result[4])
        return result

    trials = np.zeros(times.size, dtype=np.int64)
    steps = np.zeros(times.size, dtype=np.int64)
    simulator_module._STEP = counting_step
    try:
        for index in range(times.size):
            counted[0] = counted[1] = 0
            simulator.step(float(times[index]), **{key: float(values[index])})
            trials[index], steps[index] = max(counted[0], 1), counted[1]
    finally:
        simulator_module._STEP = kernel_step
    return trials, steps


#: The large-N bounded-step scene: what `numerics.tolerance` 1e-4 picks for a two-mode standard
#: solid (8192 elements, `fast`'s step control; the outside tester's 0.5.0 case, whose first
#: step from rest took 500-1000x the median): a 5 mm sphere pressed from rest at 1 mm/s (the
#: first row touches: the snap-in, then the edge races across ~1000 elements per row), held,
#: pulled back at 1 mm/s to 20 um above the surface (the pull-off), held; 1 kHz.
LARGE_SCENE = {
    "indenter": {"shape": "sphere", "radius": 5.0e-3},
    "material": {
        "glass_shear_modulus": 1.0e6,
        "kelvin_shear_moduli": [5.0e4, 1.0e5],
        "kelvin_viscosities": [1.05e5, 1.0e6],
        "poisson_ratio": 0.5,
    },
    "adhesion": {"work_of_adhesion": 0.05, "interaction_range": 1e-9},
    "numerics": {"tolerance": 1e-4},
}
LARGE_SCENE_HOLD_ROWS = 30


def _large_scene_history() -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    press = STEP_S * np.arange(1, 21) * 1e-3
    pull = 20e-6 - STEP_S * np.arange(1, 41) * 1e-3
    hold = LARGE_SCENE_HOLD_ROWS
    depth = np.concatenate([press, np.full(hold, 20e-6), pull, np.full(hold, -20e-6)])
    return STEP_S * np.arange(1, depth.size + 1), depth


def _jump_rows(radius: npt.NDArray[np.float64]) -> tuple[int, int]:
    """The snap-in row (first in contact) and the pull-off row (first out of contact after it)."""
    snap_in = int(np.flatnonzero(radius > 0.0)[0])
    pull_off = int(np.flatnonzero((radius[:-1] > 0.0) & (radius[1:] <= 0.0))[0]) + 1
    return snap_in, pull_off


def large_scene_costs(*, repeats: int) -> dict[str, Any]:
    """Every step bounded at the largest element count `numerics.tolerance` picks (LARGE_SCENE):
    per row of its press-and-pull the median over `repeats` runs of `step` (depth control);
    the median, the largest row, the snap-in and pull-off rows and their ratios to the median."""
    contact = SceneConfig.from_dict({"contacts": ["c"], "c": LARGE_SCENE}).contact("c")
    times, depths = _large_scene_history()
    runs = []
    elements = 0
    for _ in range(repeats + 1):  # the first run loads the kernels
        simulator = ContactSimulator(contact)
        runs.append(_per_step(simulator, times, depths, "depth"))
        elements = simulator.numerics.elements
    radius = ContactSimulator(contact).step_depths(times, depths)["contact_radius"]
    cost = np.median(np.array(runs[1:]), axis=0)
    snap_in, pull_off = _jump_rows(radius)
    median = float(np.median(cost))
    worst = int(np.argmax(cost))
    _, substeps = _row_work(contact, times, depths, "depth")
    return {
        "max_row_substeps": int(substeps[worst]),
        "median_substeps": float(np.median(substeps)),
        "elements": int(elements),
        "rows": int(times.size),
        "median_us": median * 1e6,
        "max_us": float(cost[worst]) * 1e6,
        "max_row": worst,
        "max_over_median": float(cost[worst]) / median,
        "snap_in_row": snap_in,
        "snap_in_us": float(cost[snap_in]) * 1e6,
        "snap_in_over_median": float(cost[snap_in]) / median,
        "pull_off_row": pull_off,
        "pull_off_us": float(cost[pull_off]) * 1e6,
        "pull_off_over_median": float(cost[pull_off]) / median,
    }


#: The gripper's hold-and-pull history under force control (`hold_pull_forces`): the largest
#: force pressed, N, and the rows of each stage at 1 kHz.
HOLD_PULL_FORCE = 0.02
HOLD_PULL_RAMP, HOLD_PULL_HOLD, HOLD_PULL_PULL, HOLD_PULL_RETOUCH = 200, 200, 600, 200


def hold_pull_forces() -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """A gripper's force commands at 1 kHz (times s, forces N): press to HOLD_PULL_FORCE, hold
    it, pull on to -2.5x it (the contact lets go on the way and stays pulled while the
    surface creeps back towards the indenter), then touch again at half the press and hold."""
    f = HOLD_PULL_FORCE
    forces = np.concatenate(
        [
            np.linspace(0.0, f, HOLD_PULL_RAMP),
            np.full(HOLD_PULL_HOLD, f),
            np.linspace(f, -2.5 * f, HOLD_PULL_PULL),
            np.full(HOLD_PULL_RETOUCH, 0.5 * f),
        ]
    )
    return STEP_S * np.arange(1, forces.size + 1), forces


def step_costs(*, repeats: int, seconds: float = SCENE_SECONDS, large: bool = True) -> dict[str, Any]:
    """Every step bounded (issue 13): the per-step cost distribution of `step` on the default
    scene under depth control (the sine above, snap-in and pull-off included) and under force
    control (the forces the depth run produced, commanded back), per step the median over
    `repeats` runs (the sine's period is `seconds`); the snap-in and pull-off rows named.
    `hold_pull`: force control through a gripper's hold, pull-off and touch again
    (`hold_pull_forces`), its pull-off row and slowest row named; and, if `large`, the same
    under depth control on the large-N scene (``"large"``, `large_scene_costs`)."""
    contact = SceneConfig.from_yaml(default_scene_path()).contacts[0]
    times, depths = _scene_history(seconds)
    hold_times, hold_forces = hold_pull_forces()
    depth_runs, force_runs, hold_runs = [], [], []
    forces = radius = None
    hold_radius = np.zeros(0)
    for _ in range(repeats + 1):  # the first run loads the kernels
        simulator = ContactSimulator(contact)
        depth_runs.append(_per_step(simulator, times, depths, "depth"))
        if forces is None:
            reference = ContactSimulator(contact).step_depths(times, depths)
            forces, radius = reference["force"], reference["contact_radius"]
        force_runs.append(_per_step(ContactSimulator(contact), times, forces, "force"))
        simulator = ContactSimulator(contact)
        clock = time.perf_counter
        cost, hold_radius = np.empty(hold_times.size), np.empty(hold_times.size)
        for index in range(hold_times.size):
            start = clock()
            output = simulator.step(float(hold_times[index]), force=float(hold_forces[index]))
            cost[index] = clock() - start
            hold_radius[index] = output.contact_radius
        hold_runs.append(cost)
    depth_cost = np.median(np.array(depth_runs[1:]), axis=0)
    force_cost = np.median(np.array(force_runs[1:]), axis=0)
    hold_cost = np.median(np.array(hold_runs[1:]), axis=0)
    assert radius is not None
    snap_in, pull_off = _jump_rows(radius)
    summary: dict[str, Any] = {"rows": int(times.size), "snap_in_row": snap_in, "pull_off_row": pull_off}
    for name, cost in (("depth", depth_cost), ("force", force_cost), ("hold_pull", hold_cost)):
        median = float(np.median(cost))
        summary.update(
            {
                f"{name}_median_us": median * 1e6,
                f"{name}_mean_us": float(np.mean(cost)) * 1e6,
                f"{name}_p99_us": float(np.percentile(cost, 99.0)) * 1e6,
                f"{name}_max_us": float(np.max(cost)) * 1e6,
                f"{name}_max_over_median": float(np.max(cost)) / median,
            }
        )
    # The measured cause of a slow row: the trials and kernel substeps of the slowest row
    # against the median row's.
    for name, cost, key, values, at in (
        ("depth", depth_cost, "depth", depths, times),
        ("force", force_cost, "force", forces, times),
        ("hold_pull", hold_cost, "force", hold_forces, hold_times),
    ):
        trials, substeps = _row_work(contact, at, values, key)
        slowest = int(np.argmax(cost))
        # The row at the 99th percentile of cost (what sets the p99) and the share of rows by
        # their trials.
        p99_row = int(np.argsort(cost, kind="stable")[min(cost.size - 1, int(0.99 * cost.size))])
        summary.update(
            {
                f"{name}_slowest_row": slowest,
                f"{name}_slowest_trials": int(trials[slowest]),
                f"{name}_slowest_substeps": int(substeps[slowest]),
                f"{name}_median_trials": float(np.median(trials)),
                f"{name}_median_substeps": float(np.median(substeps)),
                f"{name}_p99_row_trials": int(trials[p99_row]),
                f"{name}_p99_row_substeps": int(substeps[p99_row]),
                f"{name}_rows_one_trial": float(np.mean(trials == 1)),
                f"{name}_rows_two_trials": float(np.mean(trials == 2)),
                f"{name}_rows_more_trials": float(np.mean(trials >= 3)),
            }
        )
    summary["snap_in_us"] = float(depth_cost[snap_in]) * 1e6
    summary["pull_off_us"] = float(depth_cost[pull_off]) * 1e6
    let_go = np.flatnonzero((hold_radius[:-1] > 0.0) & (hold_radius[1:] <= 0.0))
    summary["hold_pull_rows"] = int(hold_times.size)
    summary["hold_pull_pull_off_row"] = int(let_go[0]) + 1 if let_go.size else -1
    summary["hold_pull_slowest_row"] = int(np.argmax(hold_cost))
    summary["force_mean_ratio"] = summary["force_mean_us"] / summary["depth_mean_us"]
    summary["force_p99_ratio"] = summary["force_p99_us"] / summary["depth_p99_us"]
    if large:
        summary["large"] = large_scene_costs(repeats=repeats)
    return summary
