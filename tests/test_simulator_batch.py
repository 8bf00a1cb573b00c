"""The batch depth path (`ContactSimulator.step_depths`, `simulate_history(depth=...)`)
against row-by-row stepping: every output field within 1e-9 relative."""

from __future__ import annotations

import numpy as np
import pytest

from viscoadh_ros.core.config import SceneConfig, load_default_scene
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator


def _sphere(numerics: dict, kelvin: bool = True):
    material = {"glass_shear_modulus": 1e6}
    if kelvin:
        material.update(kelvin_shear_moduli=[5e4], kelvin_viscosities=[1.05e5])
    scene = SceneConfig.from_dict(
        {
            "contacts": ["c"],
            "c": {
                "indenter": {"shape": "sphere", "radius": 5e-3},
                "material": material,
                "adhesion": {"work_of_adhesion": 0.05},
                "numerics": numerics,
            },
        }
    )
    return scene.contact("c")


def _sine(rows: int, period: float = 0.6) -> tuple[np.ndarray, np.ndarray]:
    """Indent, pull off, stay out of contact with memory left, and touch again."""
    time = np.linspace(0.0, 1.5 * period, rows)
    return time, 60e-6 * np.sin(2.0 * np.pi * time / period) + 10e-6


CASES = {
    # Default scene: memory left out of contact, the idle test, first touch again.
    "default": (lambda: load_default_scene().contact("finger"), _sine(240)),
    # A domain far too small: the kernel asks to grow mid-history.
    "grows": (lambda: _sphere({"preset": "fast", "domain_radius": 1e-5}), _sine(120)),
    # Repeated stamps (dt = 0 rows) and a long stay above the surface (memory dropped).
    "repeats": (
        lambda: _sphere({"preset": "fast"}),
        (
            np.repeat(np.linspace(0.0, 3.0, 60), 2),
            np.repeat(np.concatenate([np.linspace(-5e-6, 30e-6, 20), np.full(40, -80e-6)]), 2),
        ),
    ),
    "closed_form": (lambda: _sphere({"preset": "fast"}, kelvin=False), _sine(80)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_step_depths_equals_stepping(case: str) -> None:
    make_contact, (time, depth) = CASES[case]
    stepped = ContactSimulator(make_contact())
    outputs = [stepped.step(float(t), depth=float(d)) for t, d in zip(time, depth, strict=True)]
    batched = ContactSimulator(make_contact())
    columns = batched.step_depths(time, depth)
    assert np.any(columns["contact_radius"] > 0.0), f"{case}: never in contact, the case tests nothing"
    for name in STEP_OUTPUT_FIELDS:
        expected = np.array([getattr(o, name) for o in outputs], dtype=np.float64)
        got = columns[name].astype(np.float64)
        scale = max(float(np.max(np.abs(expected))), 1e-300)
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9 * scale, err_msg=f"{case}: {name}")
    # The simulator ends where stepping ended: the next step agrees too.
    assert batched.output == outputs[-1], f"{case}: final output"
    after = (batched.step(time[-1] + 0.01, depth=2e-5), stepped.step(time[-1] + 0.01, depth=2e-5))
    np.testing.assert_allclose(after[0].force, after[1].force, rtol=1e-9, err_msg=f"{case}: step after")


def test_simulate_history_depth_is_the_batch() -> None:
    time, depth = _sine(50)
    result = simulate_history(_sphere({"preset": "fast"}), time, depth=depth)
    sim = ContactSimulator(_sphere({"preset": "fast"}))
    expected = [sim.step(float(t), depth=float(d)).force for t, d in zip(time, depth, strict=True)]
    np.testing.assert_allclose(result.force, expected, rtol=1e-9, err_msg="simulate_history force")


@pytest.mark.parametrize(
    ("time", "depth", "message"),
    [
        ([0.0, 1.0], [0.0, np.nan], "depth\\[1\\]"),
        ([0.0, np.inf], [0.0, 0.0], "time\\[1\\]"),
        ([1.0, 0.5], [0.0, 0.0], "time must not go backwards"),
        ([0.0, 1.0], [0.0], "one length"),
    ],
)
def test_step_depths_bad_input_changes_nothing(time, depth, message) -> None:
    sim = ContactSimulator(_sphere({"preset": "fast"}))
    sim.step(0.1, depth=1e-5)
    before = sim.output
    with pytest.raises(InputError, match=message):
        sim.step_depths(np.array(time) + 0.2, np.array(depth))
    assert sim.output == before


@pytest.mark.parametrize("kelvin", [False, True])
def test_phase_at_rest_of_a_batch_that_ends_out_of_contact(kelvin: bool) -> None:
    """An edge held at rest reads the same phase in a batch as step by step, also when the
    batch ends out of contact with its domain dropped (0.4.0, an outside tester: the batch took
    its at-rest threshold from the row left after it, none, and read the held edge INDENTING
    and DETACHING in turn). Time-stepped path (`model: time_stepped`), elastic and creeping."""
    contact = _sphere({"model": "time_stepped", "elements": 64}, kelvin=kelvin)
    times = np.arange(1, 41) * 1e-3
    depths = np.concatenate([[40e-6], np.full(19, 80e-6), np.full(20, -2e-3)])
    sim = ContactSimulator(contact)
    per_call = [sim.step(float(t), depth=float(d)).phase for t, d in zip(times, depths, strict=True)]
    batch = ContactSimulator(contact).step_depths(times, depths)
    assert [int(p) for p in per_call] == [int(p) for p in batch["phase"]]
    assert batch["contact_radius"][-1] == 0.0
