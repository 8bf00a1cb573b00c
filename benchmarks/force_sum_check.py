"""How far a checkout's outputs are from another's on scenes that stress the contact force (0.7.0:
the force's memory integral in its sum form, `_kernels._fill_force_weights`), as a user meets
them: per scene every StepOutput field, the force's difference over the scene's pull-off force
(the quantity that matters, never the peak compressive force), the others over their largest
value, and the rows whose codes (phase, flags) differ.

    .venv/bin/python benchmarks/force_sum_check.py run <checkout root> <out.npz>
    .venv/bin/python benchmarks/force_sum_check.py compare <old.npz> <new.npz>

Run each checkout in its own process (``run``), then ``compare``. Scenes: the default scene's
bench sine under depth control (per call and in batch); force control along an analytic sine of
force and the gripper's hold-pull history; a slowly relaxing pad (retardation 100 s) pressed to
100x its adhesion depth (the domain grows), held and pulled off, at K = 1, 2 and 4; the large-N
scene (8192 elements, `numerics.tolerance` 1e-4); a zero force and small tensions commanded from
rest.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np


def _scenes():
    from viscoadh_ros.bench import kernel as bk
    from viscoadh_ros.core.config import SceneConfig, default_scene_path

    default = SceneConfig.from_yaml(default_scene_path()).contacts[0]
    times, depths = bk._scene_history(3.0)
    hold_t, hold_f = bk.hold_pull_forces()
    t_force = 1e-3 * np.arange(1, 2001)
    sine_force = 0.02 * np.sin(2.0 * math.pi * t_force / 2.0) - 0.004
    yield "default_depth_calls", default, times, depths, "depth", False
    yield "default_depth_batch", default, times, depths, "depth", True
    yield "default_force_sine", default, t_force, sine_force, "force", False
    yield "default_hold_pull", default, hold_t, hold_f, "force", False
    for k in (1, 2, 4):
        material = {
            "glass_shear_modulus": 1.0e6,
            "kelvin_shear_moduli": [2.0e4 * k] * k,
            "kelvin_viscosities": [2.0e6 * k * 10.0**j for j in range(k)],
            "poisson_ratio": 0.5,
        }
        contact = SceneConfig.from_dict(
            {
                "contacts": ["c"],
                "c": {
                    "indenter": {"shape": "sphere", "radius": 5.0e-3},
                    "material": material,
                    "adhesion": {"work_of_adhesion": 0.05},
                },
            }
        ).contact("c")
        t = 1e-3 * np.arange(1, 1601)
        # Press at 1 mm/s to 400 um (about 100x the adhesion depth), hold, pull back to 50 um above.
        d = np.minimum(1e-3 * t, 4e-4)
        d = np.where(t > 0.8, np.maximum(4e-4 - 1e-3 * (t - 0.8), -5e-5), d)
        yield f"slow_pad_deep_k{k}", contact, t, d, "depth", True
    large = SceneConfig.from_dict({"contacts": ["c"], "c": bk.LARGE_SCENE}).contact("c")
    lt, ld = bk._large_scene_history()
    yield "large_n_depth", large, lt, ld, "depth", True
    t0 = 1e-3 * np.arange(1, 301)
    f0 = np.concatenate([np.zeros(100), np.linspace(0.0, -0.002, 100), np.full(100, -0.001)])
    yield "zero_force_from_rest", default, t0, f0, "force", False


def run(root: str, out: str) -> None:
    sys.path.insert(0, root)
    import viscoadh_ros

    assert viscoadh_ros.__file__.startswith(str(Path(root).resolve())), viscoadh_ros.__file__
    from viscoadh_ros.core.errors import InputError
    from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

    arrays = {}
    for name, contact, times, values, kind, batch in _scenes():
        sim = ContactSimulator(contact)
        if batch:
            columns = sim.step_depths(times, values)
            for field in STEP_OUTPUT_FIELDS:
                arrays[f"{name}/{field}"] = np.asarray(columns[field], dtype=float)
            continue
        rows = []
        for t, v in zip(times, values, strict=True):
            try:
                output = sim.step(float(t), **{kind: float(v)})
            except InputError:
                output = sim.output
            rows.append([float(getattr(output, field)) for field in STEP_OUTPUT_FIELDS])
        for index, field in enumerate(STEP_OUTPUT_FIELDS):
            arrays[f"{name}/{field}"] = np.array([row[index] for row in rows])
    np.savez(out, **arrays)


def compare(old_path: str, new_path: str) -> None:
    old, new = np.load(old_path), np.load(new_path)
    scenes = sorted({key.split("/")[0] for key in old.files})
    print("| scene | rows | max dF / pull-off | worst other field (diff / its max) | code rows differing |")
    print("|---|---|---|---|---|")
    for scene in scenes:
        force_old, force_new = old[f"{scene}/force"], new[f"{scene}/force"]
        pull_off = max(abs(float(np.min(force_old))), 1e-300)
        d_force = float(np.max(np.abs(force_new - force_old))) / pull_off
        worst, worst_field = 0.0, "-"
        codes = 0
        for key in old.files:
            if not key.startswith(scene + "/") or key.endswith("/force"):
                continue
            field = key.split("/", 1)[1]
            a, b = old[key], new[key]
            if field in ("phase", "scale_separation_ok", "unstable"):
                codes += int(np.count_nonzero(a != b))
                continue
            top = float(np.max(np.abs(a)))
            diff = float(np.max(np.abs(a - b))) / top if top > 0 else 0.0
            if diff > worst:
                worst, worst_field = diff, field
        print(f"| {scene} | {force_old.size} | {d_force:.2g} | {worst_field} {worst:.2g} | {codes} |")


if __name__ == "__main__":
    if sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3])
    else:
        compare(sys.argv[2], sys.argv[3])
