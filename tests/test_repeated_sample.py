"""A repeated sample (the same instant, the same command) changes nothing.

A rig or a bag that records every message twice (or a controller that republishes its last
command) steps the model twice at one instant with one depth or force. An outside tester
(0.10.0) found that the second, zero-length step moved the contact: the time-stepped kernel's
zero-time branch searched the edge again without a motion limit, re-attached elements the
receding edge had just released and published a force 0.8 % of the pull-off force deeper; a
repeated force command was solved again from the solved state and landed ~1e-10 m elsewhere.

Path exercised: the time-stepped model (a K = 1 standard solid; asserted), `fast` and
`balanced`, through `step_depths` (the compiled batch), `step` (the lean depth path and
the force-control search). The times come from integer nanosecond stamps, as a node log's do
(with float times the edge happened to sit where the second search left it alone).
"""

from __future__ import annotations

import numpy as np
import pytest

from viscoadh_ros.bench.fit_speed import probe_scene
from viscoadh_ros.core.simulator import ContactSimulator, _TimeStepped

TRUE = {"G0": 1.0e6, "G1": 2.0e5, "eta1": 2.0e3, "work_of_adhesion": 0.05}


def _history(samples: int = 250) -> tuple[np.ndarray, np.ndarray]:
    """A press, hold, partial unload, second press and a retraction past pull-off, the times
    from integer nanosecond stamps (`tests/fit_records.standard_history`'s shape)."""
    t = np.linspace(0.0, 0.2, samples, endpoint=False)
    depth = np.interp(
        t, [0, 0.01, 0.03, 0.05, 0.08, 0.10, 0.2], [-1e-6, 10e-6, 10e-6, 3e-6, 20e-6, 20e-6, -30e-6]
    )
    ns = 5_000_000_000 + np.round(t * 1e9).astype(np.int64)
    return (ns - ns[0]) * 1e-9, depth


def _simulator(preset: str) -> ContactSimulator:
    simulator = ContactSimulator(probe_scene(TRUE, preset=preset).contacts[0])
    assert isinstance(simulator._model, _TimeStepped)  # not a closed form
    return simulator


@pytest.mark.parametrize("preset", ["fast", "balanced"])
def test_every_row_twice_in_a_batch_equals_every_row_once(preset: str) -> None:
    t, d = _history()
    once = _simulator(preset).step_depths(t, d)
    twice = _simulator(preset).step_depths(np.repeat(t, 2), np.repeat(d, 2))
    pull_off = -float(np.min(once["force"]))
    assert pull_off > 0.0
    names = ("force", "contact_radius", "phase", "edge_speed", "energy_input", "energy_dissipated")
    for name in names + ("effective_work_of_adhesion", "scale_separation_ok"):
        # The repeated row publishes what the first did, and the rows after it are unchanged.
        np.testing.assert_array_equal(twice[name][0::2], once[name], err_msg=name)
        np.testing.assert_array_equal(twice[name][1::2], once[name], err_msg=name)


def test_a_repeated_depth_command_returns_the_same_step() -> None:
    t, d = _history()
    single = _simulator("fast")
    doubled = _simulator("fast")
    for ti, di in zip(t, d, strict=True):
        want = single.step(float(ti), depth=float(di))
        first = doubled.step(float(ti), depth=float(di))
        again = doubled.step(float(ti), depth=float(di))
        assert first == want
        assert again == want
    # The batch path publishes the same for the same repeated samples.
    batch = _simulator("fast").step_depths(np.repeat(t, 2), np.repeat(d, 2))
    assert batch["phase"][-1] == int(doubled.output.phase)
    assert batch["edge_speed"][-1] == doubled.output.edge_speed


def test_a_repeated_force_command_returns_the_same_step() -> None:
    t, d = _history()
    forces = _simulator("fast").step_depths(t, d)["force"]
    single = _simulator("fast")
    doubled = _simulator("fast")
    for ti, fi in zip(t, forces, strict=True):
        want = single.step(float(ti), force=float(fi))
        first = doubled.step(float(ti), force=float(fi))
        again = doubled.step(float(ti), force=float(fi))
        assert first == want
        assert again == want
    # A held force re-asked at its own instant (`advance`) is the same step too.
    assert doubled.advance(doubled.time) == doubled.output


def test_a_zero_time_jump_to_another_depth_still_moves_the_contact() -> None:
    """The identity is for the same depth only: a depth jump at one instant is a real step."""
    t, d = _history()
    simulator = _simulator("fast")
    simulator.step_depths(t[:60], d[:60])
    before = simulator.output
    assert before.contact_radius > 0.0
    after = simulator.step(float(t[59]), depth=before.depth + 10e-6)
    assert after.contact_radius > before.contact_radius
    assert after.force > before.force


@pytest.mark.parametrize("preset", ["fast", "balanced"])
def test_a_contact_at_rest_commanded_to_its_own_depth_snaps_in(preset: str) -> None:
    """Not a repeat: a fresh (or reset) contact rests at depth 0 without contact, and a first
    command to depth 0 at its reset time snaps an adhesive contact in (docs/ros_interface.md;
    the outside tester's check of this round's first version of the fix, which answered 0 N).
    Then the same command again is a repeat. `step` and `step_depths` alike."""
    stepped = _simulator(preset)
    first = stepped.step(0.0, depth=0.0)
    assert first.contact_radius > 0.0 and first.force < 0.0
    assert stepped.step(0.0, depth=0.0) == first
    batch = _simulator(preset).step_depths(np.zeros(2), np.zeros(2))
    assert batch["force"][0] == batch["force"][1] == first.force
    assert batch["contact_radius"][1] == first.contact_radius
    stepped.reset(0.0)
    assert stepped.step(0.0, depth=0.0).force == first.force


def _elastic_closed_form() -> ContactSimulator:
    from viscoadh_ros.core.config import SceneConfig

    scene = {
        "contacts": ["c"],
        "c": {
            "indenter": {"shape": "sphere", "radius": 0.01},
            "material": {"glass_shear_modulus": 1.0e6, "poisson_ratio": 0.5},
            "adhesion": {"work_of_adhesion": 0.05},
        },
    }
    simulator = ContactSimulator(SceneConfig.from_dict(scene).contact("c"))
    assert not isinstance(simulator._model, _TimeStepped)  # `model: auto` took the closed form
    return simulator


def test_a_repeated_sample_on_the_closed_form_and_from_any_number_type() -> None:
    """The closed form (an elastic body, `model: auto`) and the general `step` path (times
    that are ints or numpy scalars, which the lean path leaves to it) repeat a step too, and
    `step_depths` (which runs the closed form row by row) agrees with `step` on every field
    (the second tester: phase INDENTING against DETACHING, edge speed 0 on a repeated row)."""
    t, d = _history()
    batch = _elastic_closed_form().step_depths(np.repeat(t, 2), np.repeat(d, 2))
    stepped = _elastic_closed_form()
    for index, (ti, di) in enumerate(zip(t, d, strict=True)):
        first = stepped.step(float(ti), depth=float(di))
        assert stepped.step(float(ti), depth=float(di)) == first
        for name in ("force", "contact_radius", "phase", "edge_speed", "scale_separation_ok"):
            want = getattr(first, name)
            assert batch[name][2 * index] == want and batch[name][2 * index + 1] == want, (index, name)
    for make in (_elastic_closed_form, lambda: _simulator("fast")):
        simulator = make()
        for index, di in enumerate(d[:120]):
            first = simulator.step(index + 1, depth=float(di))  # whole seconds, an int time
            assert simulator.step(np.int64(index + 1), depth=np.float64(di)) == first
            assert simulator.step(index + 1, depth=float(di)) == first
