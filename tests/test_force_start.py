"""Where the force search starts (0.5.0): from rest at the glass modulus' JKR contact
(`ContactSimulator._from_rest`), after converged force steps from their path extrapolated in
time (`_path_prediction`). Both change only the trials tried; the step must end where the
bracketing search from the held depth (the 0.4.0 search, kept as the fallback) ends, within
the force tolerance, in the same contact state.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from force_histories import decode, default_contact, finger_contact

from viscoadh_ros.core import reference
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.simulator import ContactSimulator, _path_prediction

GOLDEN = np.load(Path(__file__).with_name("force_control_golden.npz"))


class _Counting(ContactSimulator):
    """Counts the trial steps of the last `step`."""

    trials = 0

    def step(self, time, *, depth=None, force=None):
        self.trials = 0
        return super().step(time, depth=depth, force=force)

    def _trial(self, time, depth):
        self.trials += 1
        return super()._trial(time, depth)


class _Bracketing(ContactSimulator):
    """The reference: no start from rest, no extrapolated path (the held depth's bracketing
    search, or the linear secant after a converged step, as in 0.4.0)."""

    def _from_rest(self, residual, d0, target, stop):
        return None

    @staticmethod
    def _path_prediction(path, time, target, slope):
        return None


def _same_step(new, old, tolerance: float, scale: float, depth_scale: float) -> None:
    """The bounds of tests/test_force_search.py: force within twice the tolerance (floored at
    1e-6 of the force scale), depth within 100x the tolerance of the depth scale (two roots
    within the force tolerance may lie that far apart where F(d) steps as the edge crosses a
    cell), the same contact state and flag."""
    assert (new.contact_radius > 0.0) == (old.contact_radius > 0.0), (new, old)
    assert new.unstable == old.unstable, (new, old)
    bound = 2.0 * tolerance * max(abs(old.force), 1e-6 * scale)
    assert abs(new.force - old.force) <= bound, (new.force, old.force)
    assert abs(new.depth - old.depth) <= 100.0 * tolerance * depth_scale, (new.depth, old.depth)


def test_zero_force_from_rest_ends_where_main_ended_in_few_trials() -> None:
    """Row 0 of the bench's force history: a zero force from rest snaps the default sphere
    in. It ends where main's search ended (the golden file, 0.2.0): attached, flagged (the
    force jumped in), the same depth and radius; at the glass modulus' JKR zero-load radius
    to the creep of one step; in at most 5 trials (the bracketing search took 10)."""
    contact = default_contact()
    sim = _Counting(contact)
    out = sim.step(1e-3, force=0.0)
    assert out.contact_radius > 0.0 and out.unstable
    assert sim.trials <= 5, sim.trials
    golden = {key: GOLDEN[f"default_bench_sine/{key}"][0] for key in ("depth", "contact_radius", "force")}
    assert out.depth == pytest.approx(golden["depth"], rel=1e-6)
    assert out.contact_radius == pytest.approx(golden["contact_radius"], rel=1e-6)
    scale = float(np.max(np.abs(GOLDEN["default_bench_sine/force"])))
    assert abs(out.force - golden["force"]) <= sim.numerics.force_tolerance * 1e-6 * scale
    physics = sim.physics
    radius = contact.indenter.radius
    # JKR at zero load: 4 E a^3 / (3 R) = sqrt(8 pi w E a^3).
    w, e0 = physics.work_of_adhesion, physics.e0
    a_jkr = (3.0 * radius / (4.0 * e0) * math.sqrt(8.0 * math.pi * w * e0)) ** (2.0 / 3.0)
    assert out.contact_radius == pytest.approx(a_jkr, rel=5e-3)
    assert float(reference.jkr_force(a_jkr, radius, physics.e0, physics.work_of_adhesion)) == pytest.approx(
        0.0, abs=1e-12
    )


@pytest.mark.parametrize("target", [0.0, 2e-3, -1e-3, -2e-3, 0.05])
def test_force_from_rest_ends_where_the_bracketing_search_ends(target: float) -> None:
    """From rest, pressing, holding zero, pulling within the glass JKR pull-off (-1.18 mN:
    attached) and beyond it (-2 mN: no glass contact carries it, the bracketing search runs
    as before and the indenter stays off)."""
    contact = default_contact()
    new = ContactSimulator(contact).step(1e-3, force=target)
    old = _Bracketing(contact).step(1e-3, force=target)
    _same_step(new, old, ContactSimulator(contact).numerics.force_tolerance, 0.05, abs(old.depth))
    assert new.depth == pytest.approx(old.depth, rel=1e-6)
    assert new.contact_radius == pytest.approx(old.contact_radius, rel=1e-6)


def test_a_refused_force_command_then_a_good_one_from_rest() -> None:
    """Bad commands (NaN, infinite, time backwards) change nothing: the good one after them
    is the same step, bit for bit, as on a fresh simulator."""
    contact = default_contact()
    fresh = ContactSimulator(contact).step(1e-3, force=0.0)
    sim = ContactSimulator(contact)
    for bad in (math.nan, math.inf):
        with pytest.raises(InputError):
            sim.step(1e-3, force=bad)
    with pytest.raises(InputError):
        sim.step(-1.0, force=0.0)
    assert sim.step(1e-3, force=0.0) == fresh


def test_force_from_rest_after_a_reset_is_the_same_step() -> None:
    """After a history (press, pull-off, memory left) and a reset, a force step from rest is
    the same, bit for bit, as on a fresh simulator (the rows the search keeps are caches)."""
    contact = default_contact()
    commands = decode(GOLDEN["default_hold_pull/commands"])[:900]
    sim = ContactSimulator(contact)
    for kind, t, value in commands:
        try:
            sim.step(t, force=value) if kind == "force" else sim.advance(t)
        except InputError:
            pass
    sim.reset(10.0)
    again = [sim.step(10.0 + 1e-3 * k, force=f) for k, f in enumerate([0.0, 0.0, 1e-3, 2e-3], start=1)]
    twin = ContactSimulator(contact)
    twin.reset(10.0)
    first = [twin.step(10.0 + 1e-3 * k, force=f) for k, f in enumerate([0.0, 0.0, 1e-3, 2e-3], start=1)]
    assert again == first


@pytest.mark.parametrize("make", [default_contact, finger_contact], ids=["default", "finger"])
def test_force_steps_after_a_deep_press(make) -> None:
    """A deep press under depth control (beyond the first domain: it grew), then force
    control unloading, holding and pulling: every step where the reference search ends."""
    contact = make()
    new, old = ContactSimulator(contact), _Bracketing(contact)
    tolerance = new.numerics.force_tolerance
    t = 0.0
    for depth in np.linspace(0.0, 2e-4, 40):
        t += 1e-3
        a, b = new.step(t, depth=float(depth)), old.step(t, depth=float(depth))
        assert a == b
    peak = new.output.force
    targets = np.concatenate([np.linspace(peak, 0.0, 30), np.zeros(20), np.linspace(0.0, -0.2 * peak, 30)])
    for target in targets:
        t += 1e-3
        a, b = new.step(t, force=float(target)), old.step(t, force=float(target))
        _same_step(a, b, tolerance, abs(peak), 2e-4)


def test_path_prediction_extrapolates_a_polynomial_path() -> None:
    """Depth and force quadratic in time (slope 100 N/m): the extrapolated depth meets the
    target exactly, on equal and on unequal spacing; too few points or a time that does not
    move on give None."""

    def depth(t):
        return 1e-6 + 2e-5 * t - 3e-4 * t * t

    def force(t):
        return 100.0 * depth(t) - 1e-3 * t

    for times in ([1e-3, 2e-3, 3e-3, 4e-3], [1e-3, 2.5e-3, 3e-3, 4.2e-3], [1e-3, 2e-3, 3e-3]):
        path = tuple((t, depth(t), force(t)) for t in times)
        t = times[-1] + 1e-3
        target = force(t) + 5e-4
        predicted = _path_prediction(path, t, target, 100.0)
        assert predicted == pytest.approx(depth(t) + 5e-6, rel=1e-9)
    path = tuple((t, depth(t), force(t)) for t in (1e-3, 2e-3))
    assert _path_prediction(path, 3e-3, 0.0, 100.0) is None
    path = tuple((t, depth(t), force(t)) for t in (1e-3, 2e-3, 3e-3))
    assert _path_prediction(path, 3e-3, 0.0, 100.0) is None
