"""The convergence study in the suite (issue 10): the core at the default `balanced` preset
(numerics.model: time_stepped) against the independent element-wise reference
(tests/reference_stepper.py) in every regime of tests/convergence_cases.py.

The reference table (benchmarks/convergence_reference.json) is written by
``python benchmarks/convergence.py`` (minutes: the reference runs up to 256 000 elements);
`test_reference_table_is_reproduced_live` re-runs two of its entries here at a coarser level
and checks them against the table and against closed forms, so the table cannot drift from
the stepper that is said to make it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import convergence_cases as cc
import numpy as np
import pytest
import reference_stepper as rs

from viscoadh_ros.core.history import simulate_history

TABLE = json.loads(
    (Path(__file__).resolve().parents[1] / "benchmarks" / "convergence_reference.json").read_text()
)
#: What `balanced` promises (presets.py, docs/configuration.md): pull-off within 0.5 % of the
#: converged answer, each branch's force within 1 % of the pull-off force.
PULL_OFF_TOLERANCE, BRANCH_TOLERANCE = 5e-3, 1e-2


@pytest.mark.parametrize("case", cc.CASES, ids=[c.name for c in cc.CASES])
def test_balanced_meets_its_promise(case: cc.Case) -> None:
    entry = TABLE["cases"][case.name]
    times, depths = case.history()
    result = simulate_history(case.contact(), times, depth=depths)
    assert result.model == "time_stepped"
    err = cc.errors(case, result.force, result.contact_radius, result.energy_dissipated, entry)
    unc = entry["uncertainty"]
    assert err["pull_off"] < PULL_OFF_TOLERANCE, f"pull-off off by {err['pull_off']:.2%} ({unc})"
    assert err["indentation"] < BRANCH_TOLERANCE, f"indentation branch off by {err['indentation']:.2%}"
    assert err["retraction"] < BRANCH_TOLERANCE, f"retraction branch off by {err['retraction']:.2%}"
    # The reference's own dissipation is uncertain where the loss is a small difference of
    # large energies (the elastic deep press: 1 %); allow that plus 1 %.
    assert err["dissipated"] < 1e-2 + 2.0 * unc["dissipated"], (
        f"dissipated energy off by {err['dissipated']:.2%}"
    )


def test_reference_table_is_reproduced_live() -> None:
    """Two entries re-run at a quarter of the table's resolution: within the first-order
    distance such a run has from the table (4x its own uncertainty there), and the elastic
    one against JKR's -(3/2) pi R w (displacement control passes the force minimum)."""
    for name in ("elastic shallow", "partly relaxed"):
        case = next(c for c in cc.CASES if c.name == name)
        entry = TABLE["cases"][name]
        times, depths = case.history()
        coarse = rs.run(
            case.contact(),
            times,
            depths,
            length=case.length,
            elements=entry["elements"] // 4,
            substeps=max(entry["substeps"] // 4, 1),
        )
        err = cc.errors(case, coarse.force, coarse.radius, coarse.dissipated, entry)
        unc = entry["uncertainty"]
        for quantity in ("pull_off", "indentation", "retraction"):
            assert err[quantity] < 4.0 * 4.0 * unc[quantity] + 1e-4, f"{name} {quantity}: {err} vs {unc}"
    jkr = -1.5 * math.pi * cc.RADIUS * cc.WORK
    pull_off = min(TABLE["cases"]["elastic shallow"]["force"])
    assert abs(pull_off / jkr - 1.0) < 1e-3, f"reference pull-off {pull_off} vs JKR {jkr}"


def test_convergence_with_elements_is_second_order_in_the_partly_relaxed_regime() -> None:
    """The largest force error of the partly relaxed deep case against the reference falls
    by at least 3x per doubling of the elements from 80 to 320 (observed order ~1.7)."""
    case = next(c for c in cc.CASES if c.name == "partly relaxed deep")
    entry = TABLE["cases"][case.name]
    times, depths = case.history()
    errors = []
    for elements in (80, 160, 320):
        result = simulate_history(case.contact(elements=elements), times, depth=depths)
        err = cc.errors(case, result.force, result.contact_radius, result.energy_dissipated, entry)
        errors.append(max(err["pull_off"], err["indentation"], err["retraction"]))
    assert errors[1] < errors[0] / 3.0 and errors[2] < errors[1] / 3.0, f"errors {errors}"
    assert np.all(np.isfinite(errors))
