"""Numerics presets and overrides, and force control across the jump-in and pull-away."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.core.config import NumericsConfig
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.core.presets import PRESET_NAMES, preset, resolve_numerics
from viscoadh_ros.core.simulator import ContactSimulator


def test_presets_order_cost_and_overrides_apply() -> None:
    fast, balanced, accurate = (preset(name) for name in PRESET_NAMES)
    assert fast.elements < balanced.elements < accurate.elements
    assert fast.max_edge_cells >= balanced.max_edge_cells >= accurate.max_edge_cells > 0.0
    assert fast.force_tolerance > balanced.force_tolerance > accurate.force_tolerance
    assert resolve_numerics(NumericsConfig()) == balanced
    tuned = resolve_numerics(
        NumericsConfig(
            preset="fast",
            elements=77,
            max_substep=1e-3,
            force_tolerance=1e-7,
            domain_radius=2e-4,
            model="time_stepped",
        )
    )
    assert (tuned.elements, tuned.max_substep, tuned.force_tolerance, tuned.domain_radius, tuned.model) == (
        77,
        1e-3,
        1e-7,
        2e-4,
        "time_stepped",
    )
    assert tuned.fine_factor == fast.fine_factor


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("preset", "slow"),
        ("model", "exact"),
        ("elements", 2),
        ("elements", -1),
        ("force_tolerance", 2.0),
        ("max_substep", math.nan),
        ("domain_radius", -1.0),
    ],
)
def test_bad_numerics_name_the_key(field: str, value) -> None:
    with pytest.raises(ConfigError, match=f"numerics.{field}"):
        resolve_numerics(NumericsConfig(**{field: value}))


def contact(work: float, kelvin=()):
    return one_contact(
        {"shape": "sphere", "radius": 1e-3}, kelvin=kelvin, viscosities=[1e3] * len(kelvin), work=work
    )


@pytest.mark.parametrize("kelvin", [(), (1e5,)])
def test_force_control_jump_in_and_pull_away(kelvin) -> None:
    sim = ContactSimulator(contact(0.05, kelvin))
    sim.step(1e-3, depth=-1e-6)
    # Pulling while out of contact: no equilibrium, stays off, says so, no NaN.
    away = sim.step(2e-3, force=-1e-4)
    assert away.unstable and away.contact_radius == 0.0 and away.force == 0.0 and math.isfinite(away.depth)
    # Pushing: the indenter moves in, the adhesive contact snaps in (reported), then holds the force.
    jump = sim.step(3e-3, force=1e-4)
    assert jump.unstable and jump.contact_radius > 0.0, "snap-in not reported"
    np.testing.assert_allclose(jump.force, 1e-4, rtol=1e-5, err_msg=f"K={len(kelvin)} after jump-in")
    steady = sim.step(4e-3, force=1e-4)
    assert not steady.unstable
    np.testing.assert_allclose(steady.force, 1e-4, rtol=1e-5, err_msg=f"K={len(kelvin)} holding")
