"""Scenes whose outputs pin the compiled step bit for bit (issue 13, windowed substep trials).

`tests/test_kernel_golden.py` runs every scene here and compares with
`tests/data/kernel_golden.npz`, written by the 0.2.0 kernel (main before the windowed trials),
then again by the 0.4.0 kernel whose snap-in out of contact is located in time directly
(`_kernels._touch_time`: a new substep partition around the touch changes the bits from a
snap-in on; benchmarks/rounds/0.4.0-snap.md states by how much against the 0.2.0 file), and
by the 0.9.0 kernel, which locates a let-go in time even when the edge moves less than the
edge limit on its way to no contact, and takes the loss of a let-go from a contact at most
`_kernels.FOLD_FINE_CELLS` elements wide on the fine profile (`_kernels._fold_energy`): against
the 0.8.0 file one random-memory row moved (K = 1 rough memory: force 7.7e-5, radius 8.8e-5,
work 3.2e-4 of their largest values), every other output by at most 1.5e-13 (rounding the
0.8.0 file already differed by, within `golden_tolerance.RELATIVE`), and by the 0.10.0 kernel,
whose edge loses no adhesion energy where it moves continuously (`_kernels._adhesion_loss`):
against the 0.9.0 file only the dissipated energy moved, by at most 8.7e-4 of its largest value
(k0_cycles; every other output and the memory bit for bit, `benchmarks/golden_deviation.py`), and
by the kernel after 0.11.0 whose force is continuous as the edge crosses an element centre
where the memory behind the edge is relaxed (the last interior element blended in, scaled by
element L-1's relaxation: `_kernels._edge_piece`, `_relaxed_share`): against the 0.11.0 file
(`benchmarks/golden_deviation.py`) only the force and what is computed from it moved (energy
input, the forced depths): every radius, motion code and the memory bit for bit, the K = 0,
punch and fast-edge scenes bit for bit (to 1e-15); the force by at most 3.3e-3 of its largest
value (k1_regrowth; 1.7e-4 k1_jumps_dt0, 9.9e-4 the rough K = 1 random-memory rows, below 5e-5
the others), the energy input by at most 4.6e-4 (work 2.0e-3 on the rough K = 1 rows), the
forced depths by 1.8e-3 (k1_regrowth)::

    .venv/bin/python tests/kernel_golden.py <checkout root of the reference> tests/data/kernel_golden.npz

Each scene is driven through `ContactSimulator.step_depths` (the batch kernel), through
`step(depth=)` row by row, through `step(force=)` on the forces of the depth run (the force
search), and directly through `_kernels.advance` on rows with random memory (rough and smooth)
from random radii and depths: together K = 0/1/2/4, snap-in, pull-off, fast edges racing
across many elements, regrowth of the domain, a flat punch (the reach), out of contact with
memory left (the first touch of a ring), zero-length steps, a substep cap and the three
presets. Every float output is compared exactly (`np.array_equal`).

The file pins the kernel, not the force search or the Python step around it: a change that is
meant to move those outputs (e.g. a new force-control solver) regenerates the file from a
checkout with that change and the kernel the file was written by, so the kernel stays pinned.
"""

from __future__ import annotations

import math
import sys
from typing import Any

import numpy as np

STEP_S = 1e-3


def _contact(indenter: dict[str, Any], kelvin, viscosities, work: float, numerics: dict[str, Any]):
    from viscoadh_ros.core.config import SceneConfig

    material: dict[str, Any] = {"glass_shear_modulus": 1.0e6}
    if len(kelvin):
        material.update(kelvin_shear_moduli=list(kelvin), kelvin_viscosities=list(viscosities))
    section = {
        "indenter": dict(indenter),
        "material": material,
        "adhesion": {"work_of_adhesion": work},
        "numerics": dict(numerics, model="time_stepped"),
    }
    return SceneConfig.from_dict({"contacts": ["c"], "c": section}).contact("c")


def _sine(seconds: float, amplitude: float, offset: float, rows: int, period: float) -> tuple:
    t = np.linspace(seconds / rows, seconds, rows)
    return t, amplitude * np.sin(2.0 * math.pi * t / period) + offset


def scenes() -> dict[str, tuple[Any, np.ndarray, np.ndarray]]:
    """name -> (contact, times s, depths m)."""
    from viscoadh_ros.core.config import SceneConfig, default_scene_path

    sphere = {"shape": "sphere", "radius": 1e-3}
    out: dict[str, tuple[Any, np.ndarray, np.ndarray]] = {}
    default = SceneConfig.from_yaml(default_scene_path()).contacts[0]
    # The bench's bounded-step scene: snap-in, sticking, pull-off, out of contact with memory.
    out["default_sine"] = (default, *_sine(3.0, 80e-6, -10e-6, 3000, 3.0))
    # Elastic (K = 0) with adhesion: snap-in and the fold, both ways, twice.
    out["k0_cycles"] = (
        _contact(sphere, (), (), 0.05, {"preset": "fast"}),
        *_sine(0.6, 6e-6, 1e-6, 600, 0.3),
    )
    # K = 1, fast press and pull at 1 kHz: the edge races across many elements per step.
    out["k1_fast_edge"] = (
        _contact(sphere, (1e5,), (1e3,), 0.05, {"preset": "balanced", "elements": 400}),
        *_sine(0.2, 3e-5, -8e-6, 200, 0.1),
    )
    # K = 2 and K = 4 chains spanning decades, accurate and fast presets.
    out["k2_accurate"] = (
        _contact(sphere, (1e5, 3e5), (1e2, 1e4), 0.05, {"preset": "accurate"}),
        *_sine(0.5, 2.5e-5, -8e-6, 500, 0.25),
    )
    out["k4_fast"] = (
        _contact(sphere, (2e5, 2e5, 2e5, 2e5), (2e1, 2e2, 2e3, 2e4), 0.08, {"preset": "fast"}),
        *_sine(0.4, 3e-5, -1e-5, 400, 0.2),
    )
    # A small first domain pressed deep: the row regrows several times (memory remapped).
    out["k1_regrowth"] = (
        _contact(sphere, (1e5,), (1e3,), 0.01, {"preset": "fast", "domain_radius": 2e-5}),
        np.linspace(1e-3, 0.3, 300),
        np.concatenate([np.linspace(0.0, 4e-5, 150), np.linspace(4e-5, -1e-5, 150)]),
    )
    # Flat punch (the domain ends at the reach), K = 1, with a substep cap.
    out["k1_punch_substeps"] = (
        _contact(
            {"shape": "flat_punch", "radius": 5e-4},
            (1e5,),
            (2e2,),
            0.05,
            {"preset": "fast", "max_substep": 2.5e-4},
        ),
        *_sine(0.3, 4e-6, -1e-6, 300, 0.15),
    )
    # Zero-length rows (repeated times: depth jumps) in contact and across snap-in / pull-off.
    t, d = _sine(0.2, 1e-5, 1e-6, 100, 0.1)
    t = np.repeat(t, 2)
    d = np.repeat(d, 2)
    d[1::2] += 1.5e-6 * np.cos(np.arange(d.size // 2))
    out["k1_jumps_dt0"] = (_contact(sphere, (1e5,), (1e3,), 0.05, {"preset": "fast"}), t, d)
    return out


def run_scene(contact: Any, times: np.ndarray, depths: np.ndarray) -> dict[str, np.ndarray]:
    """Every float output of the scene through the three simulator paths."""
    from viscoadh_ros.core.simulator import ContactSimulator

    fields = ("force", "contact_radius", "energy_input", "energy_dissipated", "edge_speed", "phase")
    result: dict[str, np.ndarray] = {}
    batch = ContactSimulator(contact).step_depths(times, depths)
    for name in fields:
        result[f"batch_{name}"] = np.asarray(batch[name], dtype=np.float64)
    sim = ContactSimulator(contact)
    rows = []
    substeps = []
    for ti, di in zip(times, depths, strict=True):
        o = sim.step(float(ti), depth=float(di))
        rows.append([float(getattr(o, name)) for name in fields])
        substeps.append(getattr(sim._model, "substeps", 0))
    result["step"] = np.array(rows)
    result["substeps"] = np.array(substeps, dtype=np.float64)
    model = sim._model
    if getattr(model, "row", None) is not None:
        result["memory"] = np.concatenate([model.row.wl.ravel(), model.row.wb.ravel()])
    # Force control on the forces of the depth run (every 5th row, fewer searches).
    sim = ContactSimulator(contact)
    forced = []
    for ti, fi in zip(times[4::5], np.asarray(batch["force"])[4::5], strict=True):
        try:
            o = sim.step(float(ti), force=float(fi))
            forced.append([float(getattr(o, name)) for name in ("depth", *fields)])
        except ValueError:
            forced.append([math.nan] * (len(fields) + 1))
    result["forced"] = np.array(forced)
    return result


def random_rows() -> dict[str, np.ndarray]:
    """`_kernels.advance` on rows with random memory (rough and smooth), random radii, depths
    and step lengths: the outputs and the memory after each call."""
    from viscoadh_ros.core import _kernels
    from viscoadh_ros.core.simulator import ContactSimulator

    result: dict[str, np.ndarray] = {}
    chains = {
        "k0": ((), ()),
        "k1": ((1e5,), (1e3,)),
        "k3": ((2e5, 5e4, 1e6), (1e2, 1e4, 1e-1)),
    }
    for name, (kelvin, viscosities) in chains.items():
        for smooth in (False, True):
            contact = _contact(sphere_indenter(), kelvin, viscosities, 0.05, {"elements": 48})
            sim = ContactSimulator(contact)
            model = sim._model
            k = len(kelvin)
            outs = []
            mems = []
            for seed in range(8):
                rng = np.random.default_rng(seed)
                n = 48
                if smooth:
                    x = np.linspace(0.0, 1.0, n)[:, None]
                    memory = 2e-6 * (
                        rng.normal(size=(1, k)) + rng.normal(size=(1, k)) * x + rng.normal(size=(1, k)) * x**2
                    )
                else:
                    memory = rng.normal(scale=2e-6, size=(n, k))
                unit = rng.uniform(size=(n, k)) * model.steady
                row = model._build_row(2e-4, memory, unit)
                for _ in range(10):
                    a = float(rng.choice([0.0, rng.uniform(0.0, 0.9) * row.length]))
                    d0 = float(rng.uniform(-3e-6, 1.5e-5))
                    d1 = float(rng.uniform(-3e-6, 1.5e-5))
                    dt = float(rng.choice([0.0, 1e-4, 1e-3, 1e-2]))
                    cells = float(rng.choice([0.5, 1.0, 2.0]))
                    status, out = _kernels.advance(
                        row, a, d0, d1, dt, max_substep=0.0, max_edge_move=cells * row.dx
                    )
                    # The slots the file's kernel wrote (OUT_LET_GO is 0.10.0's, after them).
                    outs.append([float(status), *out[: _kernels.OUT_LET_GO].tolist()])
                    mems.append(np.concatenate([row.wl.ravel(), row.wb.ravel()]))
                    if status != _kernels.STATUS_OK:
                        row.set_memory(memory, unit)
            result[f"random_{name}_{'smooth' if smooth else 'rough'}_out"] = np.array(outs)
            result[f"random_{name}_{'smooth' if smooth else 'rough'}_memory"] = np.array(mems)
    return result


def sphere_indenter() -> dict[str, Any]:
    return {"shape": "sphere", "radius": 1e-3}


def compute() -> dict[str, np.ndarray]:
    """Every array the golden file holds, keyed ``<scene>/<output>``."""
    from viscoadh_ros.core import _kernels

    _kernels.warm_up()
    result: dict[str, np.ndarray] = {}
    for name, (contact, times, depths) in scenes().items():
        for key, value in run_scene(contact, times, depths).items():
            result[f"{name}/{key}"] = value
    result.update(random_rows())
    return result


if __name__ == "__main__":
    root, target = sys.argv[1], sys.argv[2]
    sys.path.insert(0, root)
    import viscoadh_ros

    assert viscoadh_ros.__file__.startswith(root), viscoadh_ros.__file__
    arrays = compute()
    np.savez_compressed(target, **arrays)
    print(f"{len(arrays)} arrays, {sum(a.size for a in arrays.values())} values -> {target}")
