"""Fault suite, core side: a refused step leaves the simulator bit-identical.

Each case feeds two simulators of one scene the same good commands and one of them a bad
one in between; the bad one must raise with a reason, and the next good command must give
both exactly the same output (the twin never saw the bad command). Scenes are time-stepped
(numerics.model: time_stepped forces the 1D model, where the domain can grow) unless a case
says it exercises the closed form.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from scenes import STANDARD_SOLID_FINGER

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.simulator import ContactSimulator

SCENE = STANDARD_SOLID_FINGER


def _twins(**extra: Any) -> tuple[ContactSimulator, ContactSimulator]:
    contact = SceneConfig.from_parameters({**SCENE, **extra}).contact("finger")
    return ContactSimulator(contact), ContactSimulator(contact)


def _pressed(sim: ContactSimulator) -> None:
    """A short loading history: the contact is in touch and its memory is loaded."""
    for k, depth in enumerate([-1e-6, 5e-6, 1.2e-5, 2.0e-5]):
        sim.step(0.01 * k, depth=depth)


def _assert_same(live: ContactSimulator, twin: ContactSimulator, what: str) -> None:
    assert live.time == twin.time and live.output == twin.output, what
    after_live = live.step(live.time + 0.01, depth=2.0e-5)
    after_twin = twin.step(twin.time + 0.01, depth=2.0e-5)
    assert after_live == after_twin, f"{what}: next good command differs: {after_live} vs {after_twin}"
    # And the hidden memory too: a hold lets it speak.
    assert live.advance(live.time + 0.5) == twin.advance(twin.time + 0.5), f"{what}: memory differs"


def test_a_depth_beyond_the_domain_is_refused_with_the_limit_and_changes_nothing() -> None:
    live, twin = _twins()
    _pressed(live)
    _pressed(twin)
    with pytest.raises(InputError) as refused:
        live.step(live.time + 0.01, depth=1e10)
    reason = str(refused.value)
    # Since 0.8.0 the depth limit (the largest domain's length, 1e3 m here) refuses it before
    # the domain would grow (its limit is a contact radius of 1e3 m, a depth of 2e8 m here).
    assert "largest domain" in reason and "at most 1e+03 m" in reason, reason
    _assert_same(live, twin, "depth 1e10 m")
    np.testing.assert_allclose(live.output.force, twin.output.force, rtol=0, atol=0)
    assert live.output.force > 1e-3, "a 20 um press on this sphere pushes with about 2 mN"


@pytest.mark.parametrize(
    "bad",
    [
        lambda s: s.step(s.time - 0.001, depth=1e-5),
        lambda s: s.step(s.time + 0.01, depth=float("nan")),
        lambda s: s.step(s.time + 0.01, force=1e12),
        lambda s: s.step_depths(np.array([s.time + 0.01, s.time + 0.02]), np.array([2.5e-5, 1e10])),
    ],
    ids=["time-backwards", "nan-depth", "unreachable-force", "step_depths-bad-last-row"],
)
def test_every_refused_step_leaves_the_state_bit_identical(bad: Callable[[ContactSimulator], Any]) -> None:
    live, twin = _twins()
    _pressed(live)
    _pressed(twin)
    with pytest.raises(InputError):
        bad(live)
    _assert_same(live, twin, "refused step")


def test_an_exception_inside_the_model_restores_the_state(monkeypatch: pytest.MonkeyPatch) -> None:
    """Whatever goes wrong mid-step (here: after the model advanced), nothing is half-applied."""
    live, twin = _twins()
    _pressed(live)
    _pressed(twin)
    real = live._model.advance

    def advance_then_fail(*args: Any) -> Any:
        real(*args)
        raise KeyboardInterrupt

    monkeypatch.setattr(live._model, "advance", advance_then_fail)
    with pytest.raises(KeyboardInterrupt):
        live.step(live.time + 0.01, depth=3e-5)
    with pytest.raises(KeyboardInterrupt):
        live.advance(live.time + 0.2)
    monkeypatch.undo()
    _assert_same(live, twin, "interrupted step")


@pytest.mark.parametrize(
    "other",
    [
        {"finger.numerics.preset": "balanced"},  # another grid
        {"finger.adhesion.work_of_adhesion": 0.5},
        {
            "finger.material.kelvin_shear_moduli": [2.0e5, 1.0e5],
            "finger.material.kelvin_viscosities": [2.0e3, 1e5],
        },
        {
            "finger.material.kelvin_shear_moduli": [],
            "finger.material.kelvin_viscosities": [],
            "finger.numerics.model": "auto",
        },
    ],
    ids=["numerics", "adhesion", "kelvin-2", "closed-form"],
)
def test_a_snapshot_of_another_contact_is_refused_and_changes_nothing(other: dict[str, Any]) -> None:
    """Found by an outside tester (benchmarks/outside_test_0.5.0/core_snapshot_mismatch.py): a
    snapshot restored into another contact's simulator ran the snapshot's memory under the other
    physics (or failed with a TypeError on the closed form)."""
    source, _ = _twins()
    _pressed(source)
    snapshot = source.snapshot()
    contact = SceneConfig.from_parameters({**SCENE, **other}).contact("finger")
    live, twin = ContactSimulator(contact), ContactSimulator(contact)
    _pressed(live)
    _pressed(twin)
    with pytest.raises(InputError, match="another contact"):
        live.restore(snapshot)
    _assert_same(live, twin, "a refused restore")
    # The same contact, in a new simulator: accepted, and it continues as the source does.
    same, _ = _twins()
    same.restore(snapshot)
    _assert_same(same, source, "a restore into the same contact")
