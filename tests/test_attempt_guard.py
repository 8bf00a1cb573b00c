"""A step whose edge sweeps a fine row completes with the certified numerics (0.4.0).

An outside tester found that a fast pull-off in one 1 ms step on a 1024-element row (what
`numerics.tolerance` picks for tolerances near 1e-4) ran out of the kernel's 2000 substep
attempts (one accepted and one rejected attempt per element the edge crosses), crossed the
rest of the release in one substep and dissipated ten times the work put in. The guard now
grows with the row. Time-stepped path (`model: time_stepped`), standard solid, sphere.
"""

from __future__ import annotations

import numpy as np

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator


def _contact(elements: int):
    section = {
        "indenter": {"shape": "sphere", "radius": 5e-3},
        "material": {
            "glass_shear_modulus": 1e6,
            "kelvin_shear_moduli": [5e4],
            "kelvin_viscosities": [1.05e5],
        },
        "adhesion": {"work_of_adhesion": 0.05},
        "numerics": {"model": "time_stepped", "elements": elements},
    }
    return SceneConfig.from_dict({"contacts": ["c"], "c": section}).contact("c")


def test_a_pull_off_across_a_fine_row_in_one_step_keeps_the_energy_balance() -> None:
    contact = _contact(1024)
    times = np.array([1e-3, 2e-3, 3e-3])
    depths = np.array([6e-5, 1.23e-4, -8.2e-5])
    one = ContactSimulator(contact)
    for t, d in zip(times, depths, strict=True):
        out = one.step(float(t), depth=float(d))
    assert out.contact_radius == 0.0
    # The same release cut into 100 rows.
    fine = ContactSimulator(contact)
    fine.step_depths(times[:2], depths[:2])
    rows = np.arange(1, 101)
    cols = fine.step_depths(2e-3 + rows * 1e-5, depths[1] + (depths[2] - depths[1]) * rows / 100)
    # Out of contact nothing is stored in the glass springs: what went in is at most what the
    # dampers and the adhesion hysteresis took plus the Kelvin energy still held.
    assert out.energy_dissipated <= out.energy_input * (1.0 + 1e-9)
    np.testing.assert_allclose(out.energy_dissipated, cols["energy_dissipated"][-1], rtol=0.01)
    np.testing.assert_allclose(out.energy_input, cols["energy_input"][-1], rtol=0.01)
