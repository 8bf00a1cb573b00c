"""Convergence study of the time-stepped core against an independent reference (issue 10).

    .venv/bin/python benchmarks/convergence.py            # reference table + study (minutes)
    .venv/bin/python benchmarks/convergence.py --study    # study only, from the stored table

For every case of tests/convergence_cases.py it runs the element-wise reference stepper
(tests/reference_stepper.py) at REFINE times the case's base resolution and half that, keeps
the order-1 Richardson extrapolation per row as the reference (benchmarks/
convergence_reference.json; ``uncertainty`` = its distance to the finest run, relative to the
pull-off force), then runs the core at each preset and at 80..640 elements (balanced
otherwise) and writes the errors and their observed order to benchmarks/convergence.md.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

import convergence_cases as cc  # noqa: E402
import reference_stepper as rs  # noqa: E402

from viscoadh_ros.core.history import simulate_history  # noqa: E402

TABLE = HERE / "convergence_reference.json"
REPORT = HERE / "convergence.md"
#: Reference resolution: elements and substeps times the case's base (finest level).
REFINE_ELEMENTS, REFINE_SUBSTEPS = 16, 4
ORDER_ELEMENTS = (80, 160, 320, 640)
QUANTITIES = ("pull_off", "indentation", "retraction", "dissipated")


def _round(values: np.ndarray) -> list[float]:
    return [float(f"{v:.9g}") for v in values]


def build_table() -> dict:
    table = {}
    for case in cc.CASES:
        times, depths = case.history()
        start = time.perf_counter()
        fine, extrapolated = rs.converged(
            case.contact(),
            times,
            depths,
            length=case.length,
            elements=case.elements * REFINE_ELEMENTS // 2,
            substeps=case.substeps * REFINE_SUBSTEPS // 2,
        )
        entry = {
            "force": _round(extrapolated.force),
            "radius": _round(fine.radius),
            "dissipated": _round(extrapolated.dissipated),
            "elements": fine.elements,
            "substeps": fine.substeps,
        }
        finest = {"force": fine.force, "radius": fine.radius, "dissipated": fine.dissipated}
        own = cc.errors(case, fine.force, fine.radius, fine.dissipated, entry)
        entry["uncertainty"] = {k: float(f"{v:.3g}") for k, v in own.items()}
        del finest
        table[case.name] = entry
        print(f"reference {case.name}: {time.perf_counter() - start:.1f} s, uncertainty {own}", flush=True)
    TABLE.write_text(json.dumps({"command": "python benchmarks/convergence.py", "cases": table}) + "\n")
    return table


def study(table: dict) -> str:
    lines = [
        "| case | regime | reference uncertainty | fast | balanced | accurate | order (80..640 el.) |",
        "|---|---|---|---|---|---|---|",
    ]
    worst = {p: dict.fromkeys(QUANTITIES, 0.0) for p in ("fast", "balanced", "accurate")}
    for case in cc.CASES:
        entry = table[case.name]
        times, depths = case.history()
        cells = []
        for preset in ("fast", "balanced", "accurate"):
            run = simulate_history(case.contact(preset=preset), times, depth=depths)
            err = cc.errors(case, run.force, run.contact_radius, run.energy_dissipated, entry)
            for q in QUANTITIES:
                worst[preset][q] = max(worst[preset][q], err[q])
            cells.append(" / ".join(f"{err[q]:.1e}" for q in QUANTITIES))
        series = []
        for elements in ORDER_ELEMENTS:
            run = simulate_history(case.contact(elements=elements), times, depth=depths)
            err = cc.errors(case, run.force, run.contact_radius, run.energy_dissipated, entry)
            series.append(max(err["pull_off"], err["indentation"], err["retraction"]))
        orders = [
            math.log2(a / b) if a > 0 and b > 0 else float("nan")
            for a, b in zip(series, series[1:], strict=False)
        ]
        unc = entry["uncertainty"]
        lines.append(
            f"| {case.name} | {case.regime} | {' / '.join(f'{unc[q]:.0e}' for q in QUANTITIES)} | "
            + " | ".join(cells)
            + f" | {' '.join(f'{e:.1e}' for e in series)} (order {' '.join(f'{o:.1f}' for o in orders)}) |"
        )
        print(lines[-1], flush=True)
    lines.append("")
    lines.append(
        "Worst case over all regimes (pull-off / indentation branch / retraction branch / dissipated):"
    )
    lines.append("")
    for preset, values in worst.items():
        lines.append(f"- {preset}: " + " / ".join(f"{values[q]:.1e}" for q in QUANTITIES))
    return "\n".join(lines) + "\n"


def main() -> None:
    if "--study" in sys.argv:
        table = json.loads(TABLE.read_text())["cases"]
    else:
        table = build_table()
    report = study(table)
    REPORT.write_text(
        "Written by `python benchmarks/convergence.py` (the reference table, minutes) or "
        "`python benchmarks/convergence.py --study` (the study from the stored table). Cases: "
        "`tests/convergence_cases.py` (1001-row press and pull, sphere R = 1 mm, G0 = 1 MPa, "
        "G1 = 0.1 MPa, w = 0.05 J/m^2); reference: `tests/reference_stepper.py` (binary "
        "elements, criterion at centres, expm chain update) at up to 256 000 elements, order-1 "
        "Richardson. Each cell: pull-off (relative) / indentation branch / retraction branch "
        "(largest force error over the branch's rows relative to the pull-off force) / "
        "dissipated energy at the end (relative). The reference's own uncertainty (its distance "
        "to its finest run) is the floor of what the table can show; the order column is the "
        "largest of the three force errors at 80, 160, 320, 640 elements.\n\n" + report
    )
    print(report)


if __name__ == "__main__":
    main()
