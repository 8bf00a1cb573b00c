"""core.hand.step_contacts: several contacts as one sample, all or nothing.

The contacts are standard solids with adhesion (``auto`` picks the time-stepped 1D model).
"""

from __future__ import annotations

import pytest
from scenes import one_contact

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.hand import DEPTH, FORCE, ContactStepError, step_contacts
from viscoadh_ros.core.simulator import ContactSimulator


def _simulators(count: int) -> list[ContactSimulator]:
    return [
        ContactSimulator(
            one_contact(
                {"shape": "sphere", "radius": 0.005 * (1 + k)},
                kelvin=[1e5],
                viscosities=[1.1e4],
                work=0.05,
                numerics={"preset": "fast"},
            )
        )
        for k in range(count)
    ]


def test_outputs_equal_one_step_per_simulator() -> None:
    hand, alone = _simulators(3), _simulators(3)
    for t, depth in ((0.0, 1e-5), (1e-3, 3e-5), (2e-3, -1e-5)):
        outputs = step_contacts(hand, [t] * 3, DEPTH, [depth, depth / 2, depth / 3])
        assert outputs == [
            s.step(t, depth=d) for s, d in zip(alone, [depth, depth / 2, depth / 3], strict=True)
        ]
    force = step_contacts(hand, [3e-3] * 3, FORCE, [1e-3, 2e-3, 0.0])
    assert force == [s.step(3e-3, force=f) for s, f in zip(alone, [1e-3, 2e-3, 0.0], strict=True)]


def test_a_failing_contact_rolls_back_every_contact_before_it() -> None:
    sims = _simulators(3)
    step_contacts(sims, [0.0] * 3, DEPTH, [2e-5] * 3)
    before = [(s.time, s.output, s.snapshot().model_state[2].tobytes()) for s in sims]
    with pytest.raises(ContactStepError, match="largest domain") as raised:
        step_contacts(sims, [1e-3] * 3, DEPTH, [3e-5, 3e-5, 1e10])
    assert raised.value.index == 2
    assert [(s.time, s.output, s.snapshot().model_state[2].tobytes()) for s in sims] == before
    with pytest.raises(ContactStepError) as raised:
        step_contacts(sims, [1e-3, 1e-3, -1.0], DEPTH, [3e-5] * 3)
    assert raised.value.index == 2 and "backwards" in str(raised.value)
    assert [(s.time, s.output, s.snapshot().model_state[2].tobytes()) for s in sims] == before


def test_bad_shapes_and_modes_are_refused_before_any_step() -> None:
    sims = _simulators(2)
    with pytest.raises(InputError, match="one time and one value per simulator"):
        step_contacts(sims, [0.0], DEPTH, [1e-5, 1e-5])
    with pytest.raises(InputError, match="mode must be DEPTH"):
        step_contacts(sims, [0.0, 0.0], 5, [1e-5, 1e-5])
    assert all(s.time == 0.0 and not s.in_contact for s in sims)
