"""The error model of numerics.tolerance (core/presets.py ERROR_MODEL), measured.

    .venv/bin/python benchmarks/tolerance_model.py     # about a minute

For every case of tests/convergence_cases.py it runs the core (numerics.model: time_stepped)
at element counts 32..640 with the step control of `fast` (fine_factor 16, max_edge_cells 2)
and of `balanced` (32, 1) and prints the largest force error (pull-off, both branches,
relative to the pull-off force) against the independent reference table, with C = err N^p
for the regime's order; the elastic and glassy deep cases also against the elastic closed
form (exact) from 16 to 2048 elements. ERROR_MODEL's constants are the envelopes of these
C with a 20 % margin.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

import convergence_cases as cc  # noqa: E402
from scenes import one_contact  # noqa: E402

from viscoadh_ros.core.history import simulate_history  # noqa: E402

TABLE = json.loads((HERE / "convergence_reference.json").read_text())["cases"]
CONTROLS = {"fast step control": "fast", "balanced step control": "balanced"}


def force_error(case: cc.Case, run, reference: dict) -> float:
    err = cc.errors(case, run.force, run.contact_radius, run.energy_dissipated, reference)
    return max(err["pull_off"], err["indentation"], err["retraction"])


def main() -> None:
    for case in cc.CASES:
        times, depths = case.history()
        order = 1.3 if len(case.kelvin) > 1 else 2.0
        for label, preset in CONTROLS.items():
            cells = []
            for elements in (32, 48, 64, 96, 128, 192, 256, 384, 640):
                run = simulate_history(case.contact(preset=preset, elements=elements), times, depth=depths)
                error = force_error(case, run, TABLE[case.name])
                cells.append(f"{elements}: {error:.1e} (C {error * elements**order:.3g})")
            print(f"{case.name} [{case.regime}, {label}, p = {order}] " + ", ".join(cells), flush=True)
    for name in ("elastic shallow", "elastic deep", "glassy deep"):
        case = next(c for c in cc.CASES if c.name == name)
        times, depths = case.history()
        exact_contact = one_contact(
            case.indenter, glass_shear_modulus=cc.G0, work=cc.WORK, numerics={"model": "closed_form"}
        )
        exact = simulate_history(exact_contact, times, depth=depths)
        reference = {
            "force": exact.force,
            "radius": exact.contact_radius,
            "dissipated": exact.energy_dissipated,
        }
        cells = []
        for elements in (16, 32, 64, 128, 256, 512, 1024, 2048):
            run = simulate_history(case.contact(preset="fast", elements=elements), times, depth=depths)
            error = force_error(case, run, reference)
            cells.append(f"{elements}: {error:.1e} (C {error * elements**2:.3g})")
        print(f"{name} against the closed form [p = 2] " + ", ".join(cells), flush=True)


if __name__ == "__main__":
    main()
