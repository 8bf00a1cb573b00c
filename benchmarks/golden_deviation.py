"""How far this checkout's golden files are from an old checkout's (0.4.0 `snap`: the snap-in
located in time directly moved the bits from a snap-in on): per kernel-golden scene the
largest difference of each output over its largest value, the random-memory rows likewise,
and per step-golden scene the worst field.

    .venv/bin/python benchmarks/golden_deviation.py /tmp/old_core
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

here = Path(__file__).resolve().parent.parent
old_root = Path(sys.argv[1])
sys.path.insert(0, str(here / "tests"))
from step_scenarios import STEP_OUTPUT_FIELDS  # noqa: E402


def rel(a: np.ndarray, b: np.ndarray) -> float:
    if a.size == 0:
        return 0.0
    top = np.nanmax(np.abs(a))
    return float(np.nanmax(np.abs(a - b)) / top) if top > 0 else 0.0


old = np.load(old_root / "tests/data/kernel_golden.npz")
new = np.load(here / "tests/data/kernel_golden.npz")
print("| scene | force | radius | energy in | dissipated | memory wl | memory wb | forced depth |")
print("|---|---|---|---|---|---|---|---|")
for scene in sorted({key.split("/")[0] for key in old.files if "/" in key}):
    a, b = old[scene + "/step"], new[scene + "/step"]
    values = [rel(a[:, c], b[:, c]) for c in range(4)]
    if scene + "/memory" in old.files:
        ma, mb = old[scene + "/memory"], new[scene + "/memory"]
        half = ma.size // 2
        values += [rel(ma[:half], mb[:half]), rel(ma[half:], mb[half:])]
    else:
        values += [0.0, 0.0]
    values.append(rel(old[scene + "/forced"][:, 0], new[scene + "/forced"][:, 0]))
    print(f"| {scene} | " + " | ".join(f"{v:.1e}" for v in values) + " |")
print()
print("| random rows | force | radius | work | motion codes equal |")
print("|---|---|---|---|---|")
for key in sorted(k for k in old.files if k.startswith("random_") and k.endswith("_out")):
    a, b = old[key], new[key]
    col = {name: 1 + index for index, name in enumerate(("radius", "force", "work", "motion"))}
    print(
        f"| {key} | {rel(a[:, col['force']], b[:, col['force']]):.1e} | "
        f"{rel(a[:, col['radius']], b[:, col['radius']]):.1e} | "
        f"{rel(a[:, col['work']], b[:, col['work']]):.1e} | "
        f"{np.array_equal(a[:, col['motion']], b[:, col['motion']])} |"
    )
print()
old = np.load(old_root / "tests/data/step_golden.npz")
new = np.load(here / "tests/data/step_golden.npz")
print("| step scene | worst field: largest difference / its largest value |")
print("|---|---|")
for key in sorted(old.files):
    a, b = old[key][:, :-1], new[key][:, :-1]
    worst = max(
        (
            (rel(a[:, c], b[:, c]), name)
            for c, name in enumerate(STEP_OUTPUT_FIELDS)
            if np.nanmax(np.abs(a[:, c])) > 0
        ),
        default=(0.0, "-"),
    )
    print(f"| {key} | {worst[1]} {worst[0]:.1e} |")
