"""Varied depth-control step sequences, recorded field by field (the step path's golden).

`record(stepper_name)` runs every scene's sequence on fresh simulators and returns one float64
array per scene: a row per public call (the 11 `StepOutput` fields, phase as its value, flags
0/1; a refused call records the simulator's state after it: time, the output's force and a
memory digest, so "nothing changed" is compared too) and the memory digest after each call.
The golden `data/step_golden.npz` was written from the 0.2.0 step path (main at fecbb5f) by
``python tests/step_scenarios.py tests/data/step_golden.npz`` and is compared bit for bit by
tests/test_step_lean.py; it was written again in 0.4.0 when the snap-in out of contact came to
be located in time directly (`_kernels._touch_time`: another substep partition, so other bits
from a snap-in on; the round file benchmarks/rounds/0.4.0-snap.md states by how much), and in
0.8.0 for the punch scene from its refused 1e10 m command on (the punch took that depth before:
a flat punch's contact radius is fixed, so no domain limit refused it; the depth limit now
does; the rows before it are the 0.4.0 golden's), and in 0.9.0 from the kernel that locates
every let-go in time and takes a small contact's let-go loss on the fine profile (the cone
scene's energy dissipated moved by 4.8e-4 of its largest value; every other field of every
scene by at most 9e-14 of its largest value: `benchmarks/golden_deviation.py`), and in 0.10.0
from the kernel whose edge loses no adhesion energy where it moves continuously
(`_kernels._adhesion_loss`: only energy_dissipated moved, by at most 4.1e-3 of its largest
value on the elastic scene and 4e-4 on the others; every other field bit for bit), and in
0.11.0 where a repeated sample (the same depth at the same time, row 161) is the step before
it as it was: the 0.10.0 step searched the edge again (an outside tester's finding); the rows
from it on moved by at most 2.1e-5 of each field's largest value (two_kelvin's force), 1e-6
on the other scenes, and the refused calls after it record the repeated row's phase; and again
after 0.11.0 from the kernel whose force is continuous as the edge crosses an element centre
where the memory behind the edge is relaxed (`_kernels._edge_piece`, `_relaxed_share`): against
the 0.11.0 file the elastic, punch, default and two_kelvin scenes bit for bit, the others' force
(and energy_input) by at most 1.6e-6 of its largest value (cone; growing 9.7e-8, loose_range and
standard_fast 1.9e-9), every radius and the memory digests bit for bit. Force
control is kept out (its search is tuned separately); the scenes cover snap-in, sticking,
pull-off, out of contact with memory, re-contact, depth jumps at one time, domain growth,
refused calls mid-way (bad numbers, time going back, a contact the domain cannot represent),
reset, snapshot/restore into the same and another simulator, `advance` and `step_depths`
between steps.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from scenes import one_contact  # noqa: E402

from viscoadh_ros.core.config import SceneConfig, default_scene_path  # noqa: E402
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator  # noqa: E402


def scenes() -> dict[str, object]:
    """Scene name -> ContactConfig."""
    standard = {"kelvin": [1e5], "viscosities": [1.1e4], "work": 0.05}
    return {
        "default": SceneConfig.from_yaml(default_scene_path()).contacts[0],
        "elastic_stepped": one_contact(
            {"shape": "sphere", "radius": 0.005},
            work=0.05,
            numerics={"elements": 64, "model": "time_stepped"},
        ),
        "standard_fast": one_contact(
            {"shape": "sphere", "radius": 0.01}, **standard, numerics={"preset": "fast"}
        ),
        "two_kelvin": one_contact(
            {"shape": "sphere", "radius": 0.004},
            kelvin=[2e5, 5e4],
            viscosities=[2e3, 4e4],
            work=0.08,
            numerics={"elements": 96},
        ),
        # A domain much smaller than the contact: it grows several times on the way in.
        "growing": one_contact(
            {"shape": "sphere", "radius": 0.01},
            **standard,
            numerics={"elements": 48, "domain_radius": 2e-5},
        ),
        "cone": one_contact(
            {"shape": "cone", "half_angle": 1.3},
            kelvin=[3e5],
            viscosities=[3e3],
            work=0.03,
            numerics={"preset": "fast"},
        ),
        # A long interaction range: the edge is often slower than the criterion's critical
        # speeds (scale_separation_ok false, advancing and receding thresholds apart).
        "loose_range": SceneConfig.from_dict(
            {
                "contacts": ["c"],
                "c": {
                    "indenter": {"shape": "sphere", "radius": 0.01},
                    "material": {
                        "glass_shear_modulus": 1e6,
                        "kelvin_shear_moduli": [1e5],
                        "kelvin_viscosities": [1.1e4],
                    },
                    "adhesion": {"work_of_adhesion": 0.05, "interaction_range": 3e-6},
                    "numerics": {"preset": "fast"},
                },
            }
        ).contact("c"),
        "punch": one_contact(
            {"shape": "flat_punch", "radius": 5e-4},
            kelvin=[1e5],
            viscosities=[1e4],
            work=0.05,
            numerics={"preset": "fast"},
        ),
    }


def _digest(sim: ContactSimulator) -> float:
    """A number that changes with any bit of the model's memory (sum of the state's bytes as
    integers, weighted by position), 0 without a row."""
    state = sim.snapshot().model_state
    if not isinstance(state, tuple) or state[2] is None:
        return 0.0
    raw = np.frombuffer(state[2].tobytes() + state[3].tobytes(), dtype=np.uint8).astype(np.float64)
    return float(np.dot(raw, np.arange(1, raw.size + 1) % 9973)) + float(state[0]) * 1e6


def _row(sim: ContactSimulator, output) -> list[float]:
    values = [float(getattr(output, name)) for name in STEP_OUTPUT_FIELDS]
    return [*values, _digest(sim)]


def _sequence(scale: float) -> list[tuple[str, float, float]]:
    """(kind, time, value) calls for a scene whose depth scale is `scale` (m)."""
    calls: list[tuple[str, float, float]] = []
    t = 0.0
    # Approach from above, snap-in, press, hold with creep, pull off, out of contact with memory.
    for k in range(1, 161):
        t = k * 1e-3
        calls.append(("depth", t, scale * (1.6 * math.sin(2.0 * math.pi * k / 160.0) - 0.3)))
    calls.append(("depth", t, scale * 0.4))  # a jump in depth at the same time (dt = 0)
    calls.append(("depth", t, scale * 0.4))  # the same command again
    calls.append(("nan", t + 1e-3, math.nan))  # refused: nothing changes
    calls.append(("back", t - 1.0, scale))  # refused: time going back
    calls.append(("huge", t + 1e-3, 1e10))  # refused: beyond the representable domain
    calls.append(("advance", t + 5e-3, 0.0))
    t += 5e-3
    calls.append(("snapshot", t, 0.0))
    for k in range(1, 41):
        t += 2e-3
        calls.append(("depth", t, scale * (0.4 - 0.06 * k)))
    calls.append(("restore", t, 0.0))  # back to the snapshot, then go another way
    for k in range(1, 21):
        calls.append(("depth_after_restore", k * 3e-3, scale * (0.4 + 0.05 * k)))
    calls.append(("rows", 0.0, 0.0))  # step_depths over 30 rows
    for k in range(1, 31):
        calls.append(("depth_after_rows", k * 1e-3, scale * (0.2 * math.cos(k / 3.0) - 0.05 * k)))
    calls.append(("foreign", 0.0, 0.0))  # restore the snapshot into a fresh simulator and go on
    for k in range(1, 21):
        calls.append(("depth_after_restore", k * 2e-3, scale * (0.3 - 0.08 * k)))
    calls.append(("reset", 0.0, 0.0))
    for k in range(1, 41):
        calls.append(("depth", k * 1e-3, scale * (0.05 * k - 0.3)))
    return calls


def depth_scale(name: str) -> float:
    return {
        "default": 40e-6,
        "elastic_stepped": 20e-6,
        "standard_fast": 30e-6,
        "two_kelvin": 25e-6,
        "growing": 30e-6,
        "cone": 20e-6,
        "loose_range": 30e-6,
        "punch": 2e-6,
    }[name]


def run_scene(contact, scale: float, step: Callable[..., object] | None = None) -> np.ndarray:
    """The rows of one scene's sequence. `step(sim, time, depth)` makes a depth step (default:
    ``sim.step(time, depth=depth)``)."""
    if step is None:

        def step(sim, time, depth):
            return sim.step(time, depth=depth)

    sim = ContactSimulator(contact)
    rows: list[list[float]] = []
    snapshot = None
    base = 0.0  # start of the relative times ("depth_after_*")
    for kind, t, value in _sequence(scale):
        if kind in ("depth", "depth_after_restore", "depth_after_rows"):
            rows.append(_row(sim, step(sim, t if kind == "depth" else base + t, value)))
        elif kind in ("nan", "back", "huge"):
            try:
                output = step(sim, t, value)
            except ValueError:
                output = sim.output  # refused (since 0.8.0 on every scene, the punch's too)
            rows.append(_row(sim, output))
        elif kind == "advance":
            rows.append(_row(sim, sim.advance(t)))
        elif kind == "snapshot":
            snapshot = sim.snapshot()
        elif kind == "restore":
            assert snapshot is not None
            sim.restore(snapshot)
            rows.append(_row(sim, sim.output))
        elif kind == "rows":
            t0 = sim.time
            times = t0 + 1e-3 * np.arange(1, 31)
            depths = scale * np.linspace(0.5, -0.2, 30)
            columns = sim.step_depths(times, depths)
            rows.append([float(columns[name][-1]) for name in STEP_OUTPUT_FIELDS] + [_digest(sim)])
        elif kind == "foreign":
            assert snapshot is not None
            other = ContactSimulator(contact)
            other.restore(snapshot)
            sim = other
            rows.append(_row(sim, sim.output))
        elif kind == "reset":
            sim.reset(0.0)
            rows.append(_row(sim, sim.output))
        # Relative times after a restore/rows/foreign call continue from the simulator's time.
        if kind in ("restore", "rows", "foreign"):
            base = sim.time
    return np.array(rows, dtype=np.float64)


def record(step: Callable[..., object] | None = None) -> dict[str, np.ndarray]:
    return {name: run_scene(contact, depth_scale(name), step) for name, contact in scenes().items()}


if __name__ == "__main__":
    out = Path(sys.argv[1])
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out, **record())
    print(f"wrote {out}")
