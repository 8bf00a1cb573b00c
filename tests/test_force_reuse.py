"""A step hands its kernel the force the step before ended with instead of integrating it
again (`_TimeStepped._force_at`, `_kernels._advance_packed`'s ``force_prev``; 0.4.0, issue 13:
a whole pass over the interior, a quarter of a K = 1 step in contact).

That force is only right on the memory it was computed on, so the model drops it (or, after a
rollback, puts back the one from the transaction's start) whenever anything but `advance`
writes the memory. Two proofs over random call sequences with every kind of call that moves
the state (depth and force steps, holds, refused calls, calls interrupted after the kernel ran,
a hand's undo after success, snapshot/restore, `step_depths`, reset):

- whenever the next step would use the kept force, it equals the force integrated afresh on
  the current memory, bit for bit;
- a simulator that reuses it and one made to integrate it every step give bit-equal outputs
  and memory, and the reuse really happens (most depth steps in contact take it).
"""

from __future__ import annotations

import math
from contextlib import contextmanager

import numpy as np
import pytest
from step_scenarios import depth_scale, scenes

from viscoadh_ros.core import _kernels, simulator
from viscoadh_ros.core.simulator import ContactSimulator

KINDS = ["depth"] * 14 + [
    "same_time",
    "force",
    "advance",
    "nan",
    "back",
    "snapshot",
    "restore",
    "rows",
    "undo",
    "interrupt",
    "reset",
]


class _Interrupt(BaseException):
    pass


@contextmanager
def _interrupted_after_the_kernel():
    """`step` raises after its kernel ran (the output record is its last work before it commits)."""
    real = simulator._object_new

    def interrupted(*args):
        raise _Interrupt

    simulator._object_new = interrupted
    try:
        yield
    finally:
        simulator._object_new = real


def _sequence(seed: int, scale: float) -> list[tuple[str, float, float]]:
    rng = np.random.default_rng(seed)
    calls, t = [], 0.0
    for _ in range(220):
        kind = str(rng.choice(KINDS))
        t += 0.0 if kind == "same_time" else float(rng.choice([1e-3, 1e-4, 5e-3]))
        if kind == "reset" and rng.uniform() < 0.7:
            kind = "depth"  # a rare event: most sequences keep their contact
        calls.append((kind, t, scale * float(rng.uniform(-0.6, 1.6))))
    return calls


def _bits(value) -> object:
    if isinstance(value, float):
        return value.hex()
    if isinstance(value, dict):
        return {key: _bits(v) for key, v in value.items()}
    if isinstance(value, np.ndarray):
        return value.tobytes()
    if hasattr(value, "__dataclass_fields__"):
        return tuple(_bits(getattr(value, name)) for name in value.__dataclass_fields__)
    return repr(value)


def _memory(sim: ContactSimulator) -> bytes:
    row = sim._model.row
    if row is None:
        return b""
    return row.wl.tobytes() + row.wb.tobytes() + row.wsum.tobytes() + row.bsum.tobytes()


def _kept_force_is_used(sim: ContactSimulator) -> bool:
    """Would the next step from the current state take the kept force (`advance`'s test)?"""
    model = sim._model
    known = model._force_at
    return (
        known is not None
        and known[0] is model.row
        and known[1] == model.radius
        and known[2] == sim._depth
        and sim._depth != 0.0
    )


def _call(sim: ContactSimulator, kind: str, t: float, value: float, state: dict) -> object:
    try:
        if kind in ("depth", "same_time"):
            return sim.step(t, depth=value)
        if kind == "force":
            return sim.step(t, force=value * 1e2)
        if kind == "advance":
            return sim.advance(t)
        if kind == "nan":
            return sim.step(t, depth=math.nan)
        if kind == "back":
            return sim.step(t - 1.0, depth=value)
        if kind == "snapshot":
            state["snapshot"] = sim.snapshot()
            return None
        if kind == "restore":
            if "snapshot" in state:
                sim.restore(state["snapshot"])
            return sim.output
        if kind == "rows":
            times = sim.time + 1e-3 * np.arange(1, 6)
            return sim.step_depths(times, np.linspace(sim.output.depth, value, 6)[1:])
        if kind == "undo":
            # A hand's sample: this contact stepped, a later one failed, this one is undone.
            token = sim._undo_token()
            sim.step(t, depth=value)
            sim._undo(token)
            return sim.output
        if kind == "interrupt":
            with _interrupted_after_the_kernel():
                try:
                    sim.step(t, depth=value)
                except _Interrupt:
                    return "interrupted"
            return "not interrupted"
        if kind == "reset":
            sim.reset(t)
            return sim.output
    except ValueError as error:
        return type(error).__name__ + str(error)
    raise AssertionError(kind)


SCENES = ["default", "standard_fast", "two_kelvin", "growing", "elastic_stepped", "punch"]


@pytest.mark.parametrize("name", SCENES)
@pytest.mark.parametrize("seed", [3, 4])
def test_the_kept_force_is_the_force_of_the_current_memory(name: str, seed: int) -> None:
    contact, scale = scenes()[name], depth_scale(name)
    reusing, integrating = ContactSimulator(contact), ContactSimulator(contact)
    states: tuple[dict, dict] = ({}, {})
    used = in_contact_steps = 0
    for kind, t, value in _sequence(seed, scale):
        if kind == "depth" and reusing.in_contact:
            in_contact_steps += 1
            used += _kept_force_is_used(reusing)
        integrating._model._force_at = None  # the reference integrates it every time
        got = _call(reusing, kind, t, value, states[0])
        want = _call(integrating, kind, t, value, states[1])
        assert _bits(got) == _bits(want), (kind, t, value)
        assert _memory(reusing) == _memory(integrating), (kind, t, value)
        assert _bits(reusing.output) == _bits(integrating.output)
        model = reusing._model
        if _kept_force_is_used(reusing):
            row, radius, depth, force = model._force_at
            fresh = _kernels.force(row, radius, depth)
            assert force.hex() == fresh.hex(), (kind, t, value)
    # Not a test that cannot fail: the reuse happens on most depth steps in contact (the others
    # follow a call that changed the memory otherwise).
    assert in_contact_steps > 20
    assert used >= 0.6 * in_contact_steps, (used, in_contact_steps)


def test_a_step_from_a_state_the_kernel_did_not_leave_integrates_the_force() -> None:
    """set_state, rewind, reset and step_depths drop the kept force; a rollback restores the
    transaction's own."""
    contact, scale = scenes()["standard_fast"], depth_scale("standard_fast")
    sim = ContactSimulator(contact)
    for k in range(1, 30):
        sim.step(k * 1e-3, depth=scale * 0.04 * k)
    model = sim._model
    assert _kept_force_is_used(sim)
    kept = model._force_at
    token = model.begin()
    model.rewind(model.get_state())
    assert model._force_at is None
    model.rollback(token)
    assert model._force_at is kept
    sim.restore(sim.snapshot())
    assert model._force_at is None
    sim.step(30e-3, depth=scale * 1.2)
    assert _kept_force_is_used(sim)
    sim.step_depths(np.array([31e-3, 32e-3]), np.array([scale, scale]))
    assert model._force_at is None
    sim.step(33e-3, depth=scale)
    sim.reset(0.0)
    assert model._force_at is None
