"""Cost of the simulator's compiled step against the physical floor of this machine.

The floor is a bare compiled loop that reads and writes the same state arrays as the kernel
(the Kelvin elongations `wl` (N, K) and their sums `wsum` (N,), with the profile `g_c` (N,))
once per step and does nothing else. The kernel is `core._kernels._advance` on a row built by
`ContactSimulator` itself for a standard-solid sphere, driven through a 1 kHz depth cycle that
keeps the contact open and its edge moving. Both run as compiled loops over the steps, so the
numbers compare the kernels and not Python's call overhead; the whole `ContactSimulator.step`
(Python included) is reported beside them as `step_us`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from viscoadh_ros.bench.accuracy import Case, cases, contact_config
from viscoadh_ros.bench.timing import interleaved_medians, median_seconds
from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator

STEP_S = 1e-3  # the node's command period at 1 kHz
STEP_TIMING_STEPS = 100
CYCLE_S = 2.0  # slow enough that the edge crosses about one element per step at 4096 elements
# The depth cycles between these multiples of the case's JKR depth scale: always in contact.
DEPTH_LOW, DEPTH_HIGH = 0.5, 2.0


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


@numba.njit(cache=True)
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


def measure_kernel(elements: int, kelvin: int, *, steps: int, repeats: int) -> dict[str, Any]:
    """One row of the `kernel` results section (see the module docstring)."""
    case = next(c for c in cases() if c.name == "standard_solid_pull_off")
    contact = contact_config(
        Case(
            case.name,
            dict(case.contact, material=kelvin_material(case, kelvin)),
            case.cycle_time,
            case.closed_form,
        ),
        {"elements": elements},
    )
    depth = _cycle(case, steps)
    simulator = ContactSimulator(contact)
    # Press to the cycle's deepest point (the row is created and grown to fit the whole cycle),
    # then come back to its start.
    ramp = np.concatenate([np.linspace(0.0, DEPTH_HIGH, 50), np.linspace(DEPTH_HIGH, DEPTH_LOW, 50)])
    for index, d in enumerate(ramp * case.depth_scale):
        simulator.step(index * STEP_S, depth=float(d))
    start = simulator.snapshot()
    model = simulator._model  # the benchmark times the private kernel on the simulator's own row
    row = model.row
    radius = model.radius
    numerics = simulator.numerics
    wl0, wb0 = row.memory()

    max_substep = float(numerics.max_substep)
    max_edge_move = float(numerics.max_edge_cells * row.dx)

    def run_kernel() -> int:
        row.set_memory(wl0, wb0)
        return _kernel_steps(row.kernel_args, radius, depth, STEP_S, max_substep, max_edge_move)

    def run_bare() -> None:
        _bare_steps(row.wl, row.wsum, row.g_c, depth)

    substeps = run_kernel()  # compiles (or loads the cache) outside the timing
    if substeps < 0:
        raise RuntimeError(f"kernel benchmark: the contact outgrew its domain at {elements} elements")
    run_bare()
    times = interleaved_medians({"kernel": run_kernel, "bare": run_bare}, repeats=repeats)

    # The whole Python step (validation, kernel, outputs) on a shorter stretch of the same cycle:
    # it costs far more than the kernel, and its per-step cost is what a node pays.
    step_count = min(steps, STEP_TIMING_STEPS)
    t0 = simulator.time

    def run_steps() -> None:
        simulator.restore(start)
        for index in range(1, step_count + 1):
            simulator.step(t0 + index * STEP_S, depth=float(depth[index]))

    step_s = median_seconds(run_steps, repeats=max(1, repeats // 2))
    element_steps = row.elements * steps
    kernel_ns = times["kernel"] / element_steps * 1e9
    bare_ns = times["bare"] / element_steps * 1e9
    return {
        "elements": row.elements,
        "kelvin": kelvin,
        "ns_per_element_step": kernel_ns,
        "baseline_ns_per_element_step": bare_ns,
        "ratio": kernel_ns / bare_ns,
        "substeps_per_step": substeps / steps,
        "step_us": step_s / step_count * 1e6,
    }


def kernel_table(
    *, elements: Sequence[int], kelvin: Sequence[int], steps: int, repeats: int
) -> list[dict[str, Any]]:
    """The `kernel` results section: every element count at every Kelvin count."""
    return [measure_kernel(n, k, steps=steps, repeats=repeats) for k in kelvin for n in elements]
