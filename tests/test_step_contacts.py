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


def _full_state(sim: ContactSimulator) -> tuple:
    state = sim.snapshot().model_state
    memory = b"" if state[2] is None else state[2].tobytes() + state[3].tobytes()
    return (
        sim.time,
        sim.output,
        sim._energy_input,
        sim._held_force,
        sim._force_memo,
        state[0],
        state[1],
        state[4],
        memory,
    )


@pytest.mark.parametrize("mode", [DEPTH, FORCE])
def test_undone_contacts_go_on_exactly_as_if_the_sample_never_came(mode: int) -> None:
    """The contacts stepped before a failing one are undone from their step's journal (no
    snapshot): their whole state is back bit for bit, and they go on like contacts that never
    saw the sample, also when the undone step grew the domain or searched a force."""
    sims, alone = _simulators(3), _simulators(3)
    for t, depth in ((0.0, 1e-5), (1e-3, 3e-5), (2e-3, 4e-5)):
        step_contacts(sims, [t] * 3, DEPTH, [depth, depth / 2, depth / 3])
        for s, d in zip(alone, [depth, depth / 2, depth / 3], strict=True):
            s.step(t, depth=d)
    before = [_full_state(s) for s in sims]
    values = [9e-5, 2e-5, 3e-5] if mode == DEPTH else [5e-2, 1e-3, 0.0]
    with pytest.raises(ContactStepError) as raised:
        step_contacts(sims, [3e-3, 3e-3, 1e-3], mode, values)
    assert raised.value.index == 2
    assert [_full_state(s) for s in sims] == before
    for t, value in ((4e-3, 2e-5), (5e-3, -1e-5), (6e-3, 5e-5)):
        assert step_contacts(sims, [t] * 3, DEPTH, [value] * 3) == [s.step(t, depth=value) for s in alone]
    for t, value in ((7e-3, 1e-3), (8e-3, 2e-3), (9e-3, 1e-3)):
        assert step_contacts(sims, [t] * 3, FORCE, [value] * 3) == [s.step(t, force=value) for s in alone]
    assert [_full_state(s)[8] for s in sims] == [_full_state(s)[8] for s in alone]


def test_a_simulator_listed_twice_is_refused() -> None:
    sims = _simulators(2)
    with pytest.raises(InputError, match="each simulator once"):
        step_contacts([sims[0], sims[1], sims[0]], [0.0] * 3, DEPTH, [1e-5] * 3)
    assert all(s.time == 0.0 and not s.in_contact for s in sims)


def test_contacts_on_the_lean_force_path_are_undone_too() -> None:
    """Contacts held under force control take the lean force step (one frame, the predicted
    root); when a later contact of the sample fails, they are undone from that step's journal
    bit for bit and go on like contacts that never saw the sample."""
    sims, alone = _simulators(3), _simulators(3)
    forces = [2e-3, 1e-3, 5e-4]
    for k in range(1, 13):
        t, scale = k * 1e-3, 0.5 + 0.05 * k
        values = [scale * f for f in forces]
        step_contacts(sims, [t] * 3, FORCE, values)
        for s, v in zip(alone, values, strict=True):
            s.step(t, force=v)
    before = [_full_state(s) for s in sims]
    general = [0]
    for s in sims:
        transaction = s._step_transaction

        def counted(*args, _transaction=transaction):
            general[0] += 1
            return _transaction(*args)

        s._step_transaction = counted  # type: ignore[method-assign]
    with pytest.raises(ContactStepError) as raised:
        step_contacts(sims, [13e-3, 13e-3, 5e-3], FORCE, [1.2 * f for f in forces])
    assert raised.value.index == 2
    # The first two took the lean path (only the failing one's refusal went the general way).
    assert general[0] == 1
    assert [_full_state(s) for s in sims] == before
    for k in range(13, 20):
        t, values = k * 1e-3, [(1.8 - 0.05 * k) * f for f in forces]
        assert step_contacts(sims, [t] * 3, FORCE, values) == [
            s.step(t, force=v) for s, v in zip(alone, values, strict=True)
        ]
    assert [_full_state(s)[8] for s in sims] == [_full_state(s)[8] for s in alone]
