"""Force steps around a pull-off under force control (0.6.0): a pull held after the contact let
go re-touches at the held depth as the surface creeps back, and the search brackets the new
detachment around the last step's shift (`ContactSimulator._predicted_detachment`) instead of
golden-section and bisection steps over the whole pull; a push back in from the detached
state starts on the glass stiffness. Both change only the trials tried: every step must end
where the search without them ends (same contact state and flag, the force within the
tolerance, the detachment depth within the bisection's width), in fewer trials.
"""

from __future__ import annotations

import numpy as np
import pytest
from force_histories import apply, cases, default_contact, finger_contact
from scenes import one_contact

from viscoadh_ros.bench.kernel import hold_pull_forces
from viscoadh_ros.core import _kernels, simulator
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.simulator import ContactSimulator


class _Counting(ContactSimulator):
    """Counts the trial steps of each `step`: the compiled step's calls that stepped (every
    path calls it, the lean ones too; `bench.kernel._row_work` counts the same way), or one
    for a step that made none (idle above the surface)."""

    trials = 0

    def _counted(self, call):
        kernel_step = simulator._STEP
        counted = [0]

        def counting(*args):
            result = kernel_step(*args)
            counted[0] += result[0] == _kernels.STATUS_OK
            return result

        simulator._STEP = counting
        try:
            return call()
        finally:
            simulator._STEP = kernel_step
            self.trials = max(counted[0], 1)

    def step(self, time, *, depth=None, force=None):
        return self._counted(lambda: super(_Counting, self).step(time, depth=depth, force=force))

    def advance(self, time):
        # `advance` calls `step`, which counts.
        return super().advance(time)


class _Unpredicted(_Counting):
    """The reference: no bracket predicted from the last pull-off."""

    def _predicted_detachment(self, residual, trials, d0, shift, target):
        return None


def _run(cls, contact, commands):
    sim = cls(contact)
    outputs, trials = [], []
    for kind, t, value in commands:
        try:
            apply(sim, kind, t, value)
        except InputError:
            pass
        outputs.append(sim.output)
        trials.append(sim.trials)
    return sim, outputs, np.array(trials)


def _bench_hold_pull():
    times, forces = hold_pull_forces()
    return [("force", float(t), float(f)) for t, f in zip(times, forces, strict=True)]


HISTORIES = {
    "default_hold_pull": (default_contact, cases()["default_hold_pull"][1]),
    "finger_hold_pull": (finger_contact, cases()["finger_hold_pull"][1]),
    "bench_hold_pull": (default_contact, _bench_hold_pull()),
}


@pytest.mark.parametrize("name", list(HISTORIES))
def test_a_pull_after_a_pull_off_ends_where_the_unpredicted_search_ends(name: str) -> None:
    make, commands = HISTORIES[name]
    sim, new, new_trials = _run(_Counting, make(), commands)
    _, old, old_trials = _run(_Unpredicted, make(), commands)
    _assert_the_same_steps(sim, new, old)
    assert new_trials.sum() <= old_trials.sum()


def _assert_the_same_steps(sim, new, old) -> None:
    """Every step of `new` ends where the one of `old` does: the same contact state and
    `unstable` flag, the force within the tolerance, the depth within ten times it. The
    detachment is bisected to half the tolerance of the depth from another bracket: two such
    ends lie within the width apart (and the steps after them as close)."""
    tolerance = sim.numerics.force_tolerance
    depth_scale = max(abs(o.depth) for o in old)
    for index, (a, b) in enumerate(zip(new, old, strict=True)):
        assert (a.contact_radius > 0.0) == (b.contact_radius > 0.0), (index, a, b)
        assert a.unstable == b.unstable, (index, a, b)
        assert abs(a.force - b.force) <= 2.0 * tolerance * max(abs(b.force), 1e-6 * 0.02), (index, a, b)
        assert abs(a.depth - b.depth) <= 10.0 * tolerance * depth_scale, (index, a.depth, b.depth)


def test_re_touch_rows_take_few_trials() -> None:
    """The default hold-pull history holds a pull after the pull-off while the surface creeps
    back (~80 rows that touch at the held depth and let go again): 27-28 trials each before
    (golden section and bisection over the whole pull), now at most 16 (the first rows after
    a hold, whose last shift is no guide) and mostly 5-6."""
    make, commands = HISTORIES["default_hold_pull"]
    _, outputs, trials = _run(_Counting, make(), commands)
    _, _, old_trials = _run(_Unpredicted, make(), commands)
    pulled = np.array(
        [
            kind == "force" and value < 0.0 and out.contact_radius == 0.0 and out.unstable
            for (kind, _, value), out in zip(commands, outputs, strict=True)
        ]
    )
    retouch = pulled & (old_trials >= 20)
    assert retouch.sum() >= 50
    assert np.max(trials[retouch][2:]) <= 16, trials[retouch]
    assert np.median(trials[retouch]) <= 7, trials[retouch]


def test_a_push_back_in_after_a_pull_off_meets_its_target() -> None:
    """The bench's gripper history: press, hold, pull until it lets go, pulled on, touch
    again at half the press: the touch-again row ends attached at its target in at most 5
    trials (7 before, one of them 3x past the root), and the hold after it stays there."""
    make, commands = HISTORIES["bench_hold_pull"]
    sim, outputs, trials = _run(_Counting, make(), commands)
    forces = np.array([value for _, _, value in commands])
    touch = int(np.flatnonzero(np.diff(forces) > 0.01)[0]) + 1
    assert outputs[touch - 1].contact_radius == 0.0
    assert trials[touch] <= 5, trials[touch]
    tolerance = sim.numerics.force_tolerance
    for out, target in zip(outputs[touch:], forces[touch:], strict=True):
        assert out.contact_radius > 0.0
        assert abs(out.force - target) <= tolerance * target, out


def _closed_form_sphere():
    return one_contact({"shape": "sphere", "radius": 5e-3}, work=0.05)


def _closed_form_cone():
    return one_contact({"shape": "cone", "half_angle": 1.3}, work=0.05)


@pytest.mark.parametrize(
    "make",
    [default_contact, _closed_form_sphere, _closed_form_cone],
    ids=["time_stepped", "closed_form_sphere", "closed_form_cone"],
)
def test_a_hard_pull_lets_go_where_a_gentle_one_does(make) -> None:
    """Pulled from a pressed contact with forces no attached depth reaches, from 3x its
    adhesive force to -1e308 N, the contact lets go at the same depth (the detachment
    bisected to the tolerance of where it holds, not of the force pulled or of the far
    detached trial), every output finite, and it can be pushed back in. Before 0.8.0, -1e100 N
    published a depth of -1e71 m and an energy of 1e136 J (-1e200 N: NaN), after which a push
    was refused as beyond the domain, and the let-go depth moved with the force (-1.23 um at
    -1 N, -4.7 um at -1e6 N). The closed forms (elastic, no domain) likewise: -1e100 N let go
    at -1.9e53 m, and the next push was refused (outside tester, 0.8.0)."""
    contact = make()
    assert ContactSimulator(contact).model == ("time_stepped" if make is default_contact else "closed_form")
    pulls = (-0.05, -1.0, -1e3, -1e6, -1e100, -1e200, -1e308)
    outputs, pushed = [], []
    held = 0.0
    for pull in pulls:
        sim = ContactSimulator(contact)
        sim.step(1e-3, force=0.02)
        held = sim.step(2e-3, force=0.02).depth
        out = sim.step(3e-3, force=pull)
        outputs.append(out)
        pushed.append(sim.step(4e-3, force=0.02))
    tolerance = ContactSimulator(contact).numerics.force_tolerance
    depth = outputs[0].depth
    for pull, out, back in zip(pulls, outputs, pushed, strict=True):
        assert out.contact_radius == 0.0 and out.unstable and out.force == 0.0, pull
        values = [
            getattr(out, name) for name in out.__dataclass_fields__ if isinstance(getattr(out, name), float)
        ]
        assert all(np.isfinite(values)), (pull, out)
        # Bisected to half the tolerance of the held depth: within its whole tolerance.
        assert abs(out.depth - depth) <= tolerance * abs(held), (pull, out.depth, depth)
        assert back.contact_radius > 0.0 and abs(back.force - 0.02) <= 2.0 * tolerance * 0.02, (pull, back)


class _Bisected(_Counting):
    """The reference for the detachment search aimed by let-go depths (0.10.0): the model
    says nothing of where a trial let go, so `_detachment` bisects (as before 0.10.0)."""

    def _detachment(self, *args):
        model = self._model
        model.let_go_depth = None  # shadows the method: `_detachment` then bisects
        try:
            return super()._detachment(*args)
        finally:
            del model.let_go_depth


def test_a_step_that_lets_go_says_where_along_its_path() -> None:
    """The kernel's let-go depth (`_kernels.OUT_LET_GO`, `_TimeStepped.let_go_depth`): after
    a step that let go it lies on the step's path (between the held depth and the depth
    published, the trial's own); after one that held on, or never touched, NaN."""
    make, commands = HISTORIES["bench_hold_pull"]
    sim = ContactSimulator(make())
    let_goes = 0
    for kind, t, value in commands:
        before = sim.output
        out = apply(sim, kind, t, value)
        jump = sim._model.let_go_depth()
        if before.contact_radius > 0.0 and out.contact_radius == 0.0:
            let_goes += 1
            assert out.depth <= jump <= before.depth, (t, out.depth, jump, before.depth)
        elif out.contact_radius > 0.0 or before.contact_radius == 0.0:
            assert np.isnan(jump), (t, jump)
    assert let_goes == 1


@pytest.mark.parametrize("name", list(HISTORIES))
def test_the_aimed_detachment_ends_where_the_bisection_ends(name: str) -> None:
    """The detachment search aims its trials at the fold the let-go depths of the trials that
    let go predict (`ContactSimulator._detachment`): every step ends where the bisection ends
    (same contact state and flag, the force within the tolerance, the let-go depth within the
    width both bisect to, and the steps after it as close), and the step that pulls off takes
    fewer trials (bench: 36 -> 24; benchmarks/rounds/0.10.0-holdpull.md)."""
    make, commands = HISTORIES[name]
    sim, new, new_trials = _run(_Counting, make(), commands)
    _, old, old_trials = _run(_Bisected, make(), commands)
    _assert_the_same_steps(sim, new, old)
    assert new_trials.max() < old_trials.max(), (new_trials.max(), old_trials.max())
    assert new_trials.sum() < old_trials.sum()


def test_a_push_back_from_a_pull_held_at_zero_depth_takes_few_trials() -> None:
    """An outside tester (0.10.0): a sphere pulled at -1000 N past its pull-off and held there
    while the surface creeps back (it touches at a held depth of ~1e-21 m and lets go again),
    then pushed back: the push-back's first row (-800 N) ran the dip's golden section onto an
    attached trial at ~1e-21 m, every interior trial detached, down to 1e-10 of that depth:
    98 trials (0.9.0: 6). The section now also stops on the attached values it knows at its
    ends and at its best trial (`ContactSimulator._search_dip`)."""
    sim = _Counting(
        one_contact(
            {"shape": "sphere", "radius": 1e-3},
            kelvin=[2e5],
            viscosities=[1.2e3],
            work=0.05,
            numerics={"model": "time_stepped", "tolerance": 1e-2},
        )
    )
    press, pull, dt = 2e-3, -1e3, 1e-3
    forces = (
        [press * i / 20 for i in range(1, 21)]
        + [press] * 20
        + [press + (pull - press) * i / 20 for i in range(1, 21)]
        + [pull] * 200
        + [pull + (press - pull) * i / 20 for i in range(1, 21)]
        + [press] * 20
    )
    trials = []
    for i, force in enumerate(forces):
        out = sim.step((i + 1) * dt, force=force)
        trials.append(sim.trials)
    push_back = 260
    assert sim.output.contact_radius > 0.0 and abs(out.force - press) <= 1e-2 * press
    assert max(trials[push_back : push_back + 5]) <= 12, trials[push_back : push_back + 5]
    assert max(trials) <= 40, max(trials)
