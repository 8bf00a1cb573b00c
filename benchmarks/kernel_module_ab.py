"""In-process A/B of two versions of the compiled kernel module on the kernel bench's scenario.

    .venv/bin/python benchmarks/kernel_module_ab.py [--close] [--steps S] <old checkout root> N,K [N,K ...]

Loads ``viscoadh_ros/core/_kernels.py`` of the old checkout as a separate module beside this
checkout's, builds the `viscoadh bench --sections kernel` state for each (N, K) (standard
solid pressed to the cycle's deepest point and back, then 400 rows of the 1 kHz cycle, or S
rows: ``--steps 100`` is the stretch `viscoadh bench` times per call from Python, with its K = 1
snap-in and re-contact), and times, interleaved and median of 7 (31 at N <= 256), per row:
`_advance` row by row in a compiled loop (old, new), `_advance_rows` (old, new) and
`MinimalStepper.run`. The rows of both `_advance_rows` must be equal bit for bit (asserted),
so the script also proves the new kernel's outputs on these scenes. With ``--close`` (a change
meant to move the outputs at the rounding level, e.g. the 0.3.0 edge root finder) the largest
difference of each output slot, relative to that slot's largest value (the edge gaps: the
radius's), is printed instead.
Only ratios from one sitting count (shared machine).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numba
import numpy as np

from viscoadh_ros.bench import kernel as bench_kernel
from viscoadh_ros.bench.accuracy import Case, cases, contact_config
from viscoadh_ros.bench.reference_stepper import MinimalStepper
from viscoadh_ros.core import _kernels as new
from viscoadh_ros.core.simulator import ContactSimulator

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ab_cores import renamed_kernels  # noqa: E402

STEPS = 400


def _setup(elements: int, kelvin: int) -> tuple[ContactSimulator, np.ndarray]:
    """The bench's kernel state (`bench.kernel.measure_kernel`) and its depth cycle."""
    case = next(c for c in cases() if c.name == "standard_solid_pull_off")
    material = bench_kernel.kelvin_material(case, kelvin)
    contact = contact_config(
        Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": elements, "model": "time_stepped"},
    )
    sim = ContactSimulator(contact)
    ramp = np.concatenate(
        [
            np.linspace(0.0, bench_kernel.DEPTH_HIGH, 50),
            np.linspace(bench_kernel.DEPTH_HIGH, bench_kernel.DEPTH_LOW, 50),
        ]
    )
    for index, d in enumerate(ramp * case.depth_scale):
        sim.step(index * bench_kernel.STEP_S, depth=float(d))
    return sim, bench_kernel._cycle(case, STEPS)


def _loop(advance):
    @numba.njit
    def loop(row_args, radius, depth, dt, max_substep, max_edge_move):  # pragma: no cover - compiled
        out = row_args[-1]
        for s in range(1, depth.shape[0]):
            advance(*row_args, radius, depth[s - 1], depth[s], dt, max_substep, max_edge_move)
            radius = out[0]

    return loop


def _rows(advance_rows):
    @numba.njit
    def rows(
        row_args, backup, backup_b, radius, d0, times, depths, max_substep, max_edge_move, out
    ):  # pragma: no cover
        return advance_rows(
            *row_args,
            backup,
            backup_b,
            radius,
            0.0,
            d0,
            1.0,
            times,
            depths,
            0,
            max_substep,
            max_edge_move,
            0.0,
            out,
        )

    return rows


def _old_args(old, row) -> tuple:
    """The old kernel's row arguments: this row's arrays by the old `Row._build_kernel_args`'s
    names (attributes the old row did not have are not passed)."""
    return tuple(getattr(row, name) for name in old.Row._build_kernel_args.__code__.co_names)


def measure(old, elements: int, kelvin: int, close: bool = False) -> dict[str, float]:
    """us per row of each run (see the module docstring); asserts the batch rows are equal
    (`close`: returns the largest relative difference of the rows as ``"rows differ"``)."""
    sim, depth = _setup(elements, kelvin)
    model = sim._model
    row, radius = model.row, model.radius
    wl0, wb0 = row.memory()
    max_substep = float(sim.numerics.max_substep)
    max_move = float(sim.numerics.max_edge_cells * row.dx)
    args = {"old": _old_args(old, row), "new": row.kernel_args}
    loops = {"old": _loop(old._advance), "new": _loop(new._advance)}
    batches = {"old": _rows(old._advance_rows), "new": _rows(new._advance_rows)}
    times = 1e-3 * np.arange(1, STEPS + 1)
    out = {key: np.zeros((STEPS, new.ROW_SIZE)) for key in batches}
    backup, backup_b = np.empty_like(row.wl), np.empty_like(row.wl)
    eta = model.e_kelvin / model.rate if model.e_kelvin.size else np.zeros(0)
    minimal = MinimalStepper(
        g_centres=row.g_c,
        dx=row.dx,
        e0=sim.physics.e0,
        e_kelvin=model.e_kelvin,
        eta_kelvin=eta,
        c_crit=sim.physics.c_crit,
    )
    d0 = float(depth[0])

    def stepwise(key: str):
        def run() -> None:
            row.set_memory(wl0, wb0)
            loops[key](args[key], radius, depth, 1e-3, max_substep, max_move)

        return run

    def batch(key: str):
        def run() -> None:
            row.set_memory(wl0, wb0)
            batches[key](
                args[key], backup, backup_b, radius, d0, times, depth[1:], max_substep, max_move, out[key]
            )

        return run

    def run_minimal() -> None:
        minimal.set_state(depth=d0, radius=radius, memory=wl0)
        minimal.run(1e-3, depth[1:])

    runs = {
        "old step": stepwise("old"),
        "new step": stepwise("new"),
        "old rows": batch("old"),
        "new rows": batch("new"),
        "minimal": run_minimal,
    }
    for run in runs.values():
        run()
    differ = 0.0
    if close:
        scale = np.maximum(np.max(np.abs(out["old"]), axis=0), 1e-300)
        # The criterion gaps at the edge are h at a root (rounding noise): on the radius's scale.
        for gap in (new.ROW_GAP_OUTSIDE, new.ROW_GAP_INSIDE):
            scale[gap] = scale[new.OUT_RADIUS]
        by_slot = np.max(np.abs(out["old"] - out["new"]) / scale, axis=0)
        # The motion and substep counts are codes (a new substep partition changes the count):
        # printed per slot below, not in the headline figure.
        values = [slot for slot in range(by_slot.size) if slot not in (new.OUT_MOTION, new.OUT_SUBSTEPS)]
        differ = float(np.max(by_slot[values]))
        print(
            "  largest relative difference per output slot: "
            + ", ".join(f"{slot}: {value:.1e}" for slot, value in enumerate(by_slot)),
            flush=True,
        )
    else:
        assert np.array_equal(out["old"], out["new"]), "the kernels' rows differ"
    samples: dict[str, list[float]] = {key: [] for key in runs}
    # Short runs (small N) are the most exposed to a shared machine's preemptions: more repeats.
    for _ in range(7 if elements > 256 else 31):
        for key, run in runs.items():
            start = time.perf_counter()
            run()
            samples[key].append(time.perf_counter() - start)
    result = {key: float(np.median(v)) / STEPS * 1e6 for key, v in samples.items()}
    result["rows differ"] = differ
    return result


def main() -> None:
    args = sys.argv[1:]
    close = "--close" in args
    args = [a for a in args if a != "--close"]
    if "--steps" in args:
        at = args.index("--steps")
        global STEPS
        STEPS = int(args[at + 1])
        del args[at : at + 2]
    # Under its own module name: loaded in place it would share the new kernels' compiled symbols
    # (seen with the 0.3.0 edge root finder: "old" rows equal to the new ones).
    old = renamed_kernels(args[0])
    for spec in args[1:]:
        elements, kelvin = (int(v) for v in spec.split(","))
        us = measure(old, elements, kelvin, close)
        step, rows, minimal = (
            (us["old step"], us["new step"]),
            (us["old rows"], us["new rows"]),
            us["minimal"],
        )
        print(
            f"N={elements:5d} K={kelvin}  us/row: _advance old {step[0]:8.2f} new {step[1]:7.2f} "
            f"(x{step[0] / step[1]:.2f}) | _advance_rows old {rows[0]:8.2f} new {rows[1]:7.2f} "
            f"(x{rows[0] / rows[1]:.2f}) | minimal {minimal:6.2f}: rows/minimal old "
            f"{rows[0] / minimal:.2f} new {rows[1] / minimal:.2f}  "
            + (f"(values differ by <= {us['rows differ']:.1e} of each slot)" if close else "(rows equal)"),
            flush=True,
        )


if __name__ == "__main__":
    main()
