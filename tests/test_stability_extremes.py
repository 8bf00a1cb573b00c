"""Numerical stability of the contact simulator at the extremes (hypothesis property tests).

Covered (the table in BENCHMARKS.md restates this): huge G0/G1 with tiny relaxation times and
coarse steps (no NaN, no oscillation, force between the relaxed and glass Hertz limits),
sudden depth jumps in and out of contact (no NaN, dissipation never negative nor decreasing),
force control at the JKR pull-off point (stable just above it, reported unstable just beyond,
never NaN), and convergence of the pull-off force with element refinement.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scenes import one_contact

from viscoadh_ros.core import reference
from viscoadh_ros.core.rheology import CreepElement
from viscoadh_ros.core.simulator import ContactSimulator, StepOutput

# Each example runs a short history; a few dozen examples per property keep the file fast.
EXAMPLES = settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True
)
FIELDS = ("depth", "force", "contact_radius", "edge_speed", "energy_input", "energy_dissipated")


def make_contact(
    *,
    radius: float,
    glass: float,
    kelvin: list[float],
    viscosities: list[float],
    work: float,
    elements: int = 0,
) -> Any:
    """A sphere contact through the one scene loader; elements 0 keeps the preset's count."""
    numerics: dict[str, Any] = {"model": "time_stepped"}
    if elements:
        numerics["elements"] = elements
    return one_contact(
        {"shape": "sphere", "radius": radius},
        glass_shear_modulus=glass,
        kelvin=kelvin,
        viscosities=viscosities,
        work=work,
        numerics=numerics,
    )


def run(contact: Any, time: np.ndarray, depth: np.ndarray) -> list[StepOutput]:
    simulator = ContactSimulator(contact)
    return [simulator.step(float(t), depth=float(d)) for t, d in zip(time, depth, strict=True)]


def assert_finite(outputs: list[StepOutput], case: str) -> None:
    for field in FIELDS:
        values = np.array([getattr(o, field) for o in outputs])
        assert np.all(np.isfinite(values)), f"{case}: {field} not finite: {values[~np.isfinite(values)][:3]}"


def hertz(depth: np.ndarray, radius: float, shear_modulus: float) -> np.ndarray:
    return reference.hertz_force(np.maximum(depth, 0.0), radius, 4.0 * shear_modulus)


@EXAMPLES
@given(
    log_ratio=st.floats(0.0, 6.0),  # G0/G1 from 1 to 1e6
    log_tau=st.floats(-6.0, 4.0),  # relaxation time 1e-6 .. 1e4 s
    log_dt=st.floats(-6.0, 0.0),  # step 1e-6 .. 1 s
    log_radius=st.floats(-6.0, 0.0),  # sphere radius 1e-6 .. 1 m
)
def test_ramp_hold_no_oscillation(log_ratio: float, log_tau: float, log_dt: float, log_radius: float) -> None:
    """Non-adhesive ramp then hold, any step against any relaxation time: the force rises
    monotonically on the ramp, relaxes monotonically on the hold, and stays between the relaxed
    and the glass Hertz forces (a scheme that is not L-stable rings or overshoots here)."""
    glass, radius, tau, dt = 1e6, 10.0**log_radius, 10.0**log_tau, 10.0**log_dt
    g1 = glass / 10.0**log_ratio
    case = f"G0/G1=1e{log_ratio:.2f} tau={tau:.2g} dt={dt:.2g} R={radius:.2g}"
    contact = make_contact(
        radius=radius, glass=glass, kelvin=[g1], viscosities=[tau * (glass + g1)], work=0.0
    )
    rows = 40
    time = np.arange(1, 2 * rows + 1) * dt
    depth = 1e-2 * radius * np.minimum(np.arange(1, 2 * rows + 1) / rows, 1.0)
    outputs = run(contact, time, depth)
    assert_finite(outputs, case)
    force = np.array([o.force for o in outputs])
    scale = float(hertz(depth[-1:], radius, glass)[0])
    # Edge chatter of a few 1e-9 relative is round-off, not ringing; a real oscillation is far larger.
    slack = 1e-6 * scale
    assert np.all(np.diff(force[:rows]) >= -slack), f"{case}: force falls during the ramp"
    assert np.all(np.diff(force[rows:]) <= slack), f"{case}: force rises during the hold"
    relaxed_shear = glass * g1 / (glass + g1)
    # 1% covers the discretisation of the contact edge at the preset's element count.
    assert np.all(force <= hertz(depth, radius, glass) * 1.01 + slack), f"{case}: above the glass limit"
    assert np.all(force >= hertz(depth, radius, relaxed_shear) * 0.99 - slack), f"{case}: below relaxed"


@EXAMPLES
@given(
    jumps=st.lists(st.floats(-1.0, 3.0), min_size=3, max_size=12),
    log_ratio=st.floats(0.0, 6.0),
    log_tau=st.floats(-6.0, 1.0),
    log_work=st.floats(-3.0, 1.0),  # work of adhesion 1e-3 .. 10 J/m^2
)
def test_depth_jumps_dissipation_never_negative(
    jumps: list[float], log_ratio: float, log_tau: float, log_work: float
) -> None:
    """Depth held piecewise constant with sudden jumps in and out of contact (adhesive, any
    rheology): outputs stay finite and the energy dissipated is never negative nor decreasing."""
    glass, radius, work = 1e6, 1e-3, 10.0**log_work
    g1, tau = glass / 10.0**log_ratio, 10.0**log_tau
    case = f"jumps={np.round(jumps, 2).tolist()} G0/G1=1e{log_ratio:.2f} tau={tau:.2g} w={work:.2g}"
    assert_dissipation_never_negative(
        make_contact(radius=radius, glass=glass, kelvin=[g1], viscosities=[tau * (glass + g1)], work=work),
        np.asarray(jumps),
        tau / 3.0,
        case,
    )


def assert_dissipation_never_negative(contact: Any, jumps: np.ndarray, step: float, case: str) -> None:
    """Hold each depth of `jumps` (in units of the larger of 1e-3 R and the glass JKR depth)
    for 10 steps of `step` s; dissipation must stay >= 0 and non-decreasing."""
    radius, glass = contact.indenter.radius, contact.material.glass_shear_modulus
    work = contact.adhesion.work_of_adhesion
    glass_only = CreepElement(glass_shear_modulus=glass)
    unit = max(1e-3 * radius, reference.figure4_scales(radius, work, glass_only).depth)
    depth = np.repeat(jumps * unit, 10)
    outputs = run(contact, np.arange(1, depth.size + 1) * step, depth)
    assert_finite(outputs, case)
    dissipated = np.array([o.energy_dissipated for o in outputs])
    scale = max(
        max(abs(o.energy_input) for o in outputs),
        work * math.pi * max(o.contact_radius for o in outputs) ** 2,
    )
    # The dissipation is a running sum of non-negative losses: only round-off may lower it.
    tol = 1e-9 * scale + 1e-300
    assert dissipated.min() >= -tol, f"{case}: dissipation {dissipated.min():.3g} J < 0 (scale {scale:.3g} J)"
    assert np.all(np.diff(dissipated) >= -tol), f"{case}: dissipation decreases"


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(
    log_creep=st.floats(-6.0, 8.0),  # creep time eta1/G1, 1e-6 .. 1e8 s
    log_history=st.floats(-3.0, 3.0),  # press-and-pull duration 1e-3 .. 1e3 s
    log_ratio=st.floats(0.0, 4.0),  # G0/G1 1 .. 1e4
    log_depth=st.floats(-0.3, 3.0),  # deepest point 0.5 .. 1000 d_c
)
def test_press_and_pull_in_every_regime(
    log_creep: float, log_history: float, log_ratio: float, log_depth: float
) -> None:
    """An adhesive sphere pressed to 0.5..1000 d_c and pulled off, for creep times from 1e-6 s
    to 1e8 s against histories of 1e-3 s to 1e3 s and G0/G1 up to 1e4 (time-stepped path,
    balanced): outputs finite, the contact lets go, the dissipation is >= 0 and never
    decreases, and the most tensile force lies between the glassy and the relaxed JKR
    pull-offs under displacement control (-(3/2) pi R w and -(3/2) pi R w_eff2), 2 % slack."""
    glass, radius, work = 1e6, 1e-3, 0.05
    g1 = glass / 10.0**log_ratio
    creep_time, duration = 10.0**log_creep, 10.0**log_history
    contact = make_contact(radius=radius, glass=glass, kelvin=[g1], viscosities=[creep_time * g1], work=work)
    element = CreepElement.from_config(contact.material)
    d_c = abs(reference.figure4_scales(radius, work, element).depth)
    d_glass = abs(reference.jkr_scales(radius, 4.0 * glass, work).depth)
    deepest = 10.0**log_depth * d_c
    depth = np.concatenate(
        [np.linspace(-0.5 * d_glass, deepest, 100), np.linspace(deepest, -3.0 * d_c, 201)[1:]]
    )
    case = f"creep {creep_time:.3g} s over {duration:.3g} s, G0/G1 1e{log_ratio:.2f}, {deepest / d_c:.3g} d_c"
    outputs = run(contact, np.linspace(duration / depth.size, duration, depth.size), depth)
    assert_finite(outputs, case)
    dissipated = np.array([o.energy_dissipated for o in outputs])
    assert dissipated.min() >= 0.0, case
    assert np.all(np.diff(dissipated) >= -1e-9 * dissipated.max()), f"{case}: dissipation decreases"
    assert outputs[-1].contact_radius == 0.0, f"{case}: still in contact at -3 d_c"
    pull_off = min(o.force for o in outputs)
    glassy = -1.5 * math.pi * radius * work
    relaxed = -1.5 * math.pi * radius * work * (glass + g1) / g1
    assert relaxed * 1.02 <= pull_off <= glassy * 0.98 or pull_off > glassy * 0.98, case
    assert pull_off >= relaxed * 1.02, (
        f"{case}: pull-off {pull_off:.4g} N beyond the relaxed JKR {relaxed:.4g} N"
    )


def test_touch_at_zero_depth_huge_glass_ratio() -> None:
    """Touching at zero depth and holding, G0/G1 = 1e4: dissipation must stay >= 0."""
    glass = 1e6
    contact = make_contact(radius=1e-3, glass=glass, kelvin=[glass / 1e4], viscosities=[glass], work=1.0)
    assert_dissipation_never_negative(contact, np.zeros(3), 1.0 / 3.0, "G0/G1=1e4 touch at d=0")


def _creep(contact: Any) -> CreepElement:
    return CreepElement.from_config(contact.material)


@settings(max_examples=10, deadline=None, derandomize=True)
@given(log_work=st.floats(-3.0, 0.0), log_radius=st.floats(-4.0, -1.0), margin=st.floats(2e-2, 5e-2))
def test_force_control_at_pull_off(log_work: float, log_radius: float, margin: float) -> None:
    """Elastic JKR under force control, pulled to just above and just beyond the pull-off force
    `-(3/2) pi R w` (margins above the preset's 0.5% pull-off accuracy): the first holds contact
    and is stable, the second is reported unstable and leaves contact; never NaN."""
    glass, radius, work = 1e6, 10.0**log_radius, 10.0**log_work
    case = f"w={work:.3g} R={radius:.3g} margin={margin:.3g}"
    contact = make_contact(radius=radius, glass=glass, kelvin=[], viscosities=[], work=work)
    pull_off = reference.jkr_pull_off_force_control(radius, 4.0 * glass, work).force
    for factor, expect_contact in ((1.0 - margin, True), (1.0 + margin, False)):
        simulator = ContactSimulator(contact)
        d_c = reference.figure4_scales(radius, work, _creep(contact)).depth
        simulator.step(1e-3, depth=d_c)  # touch and snap in under displacement control
        targets = np.linspace(simulator.output.force, factor * pull_off, 8)
        outputs = [simulator.step(2e-3 + i * 1e-3, force=float(f)) for i, f in enumerate(targets)]
        assert_finite(outputs, f"{case} factor={factor:.4f}")
        last = outputs[-1]
        if expect_contact:
            assert last.contact_radius > 0.0 and not last.unstable, f"{case}: lost contact above pull-off"
            np.testing.assert_allclose(last.force, factor * pull_off, rtol=1e-4, err_msg=case)
        else:
            assert any(o.unstable for o in outputs), f"{case}: pull-off beyond the limit not reported"
            assert last.contact_radius == 0.0, f"{case}: still in contact beyond the pull-off force"


@pytest.mark.parametrize("work", [0.01, 0.1, 1.0])
def test_pull_off_converges_with_refinement(work: float) -> None:
    """Elastic JKR pull-off on the time-stepped path: the error against `-(3/2) pi R w` falls as
    the element count doubles, reaching 1% by 256 elements."""
    glass, radius = 1e6, 1e-3
    d_c = reference.figure4_scales(
        radius, work, _creep(make_contact(radius=radius, glass=glass, kelvin=[], viscosities=[], work=work))
    ).depth
    time = np.linspace(0.0, 1.0, 801)
    depth = np.interp(time, [0.0, 0.5, 1.0], [-0.5 * d_c, 2.0 * d_c, -3.0 * d_c])
    exact = reference.jkr_pull_off_force_control(radius, 4.0 * glass, work).force
    errors = []
    for elements in (16, 32, 64, 128, 256):
        contact = make_contact(
            radius=radius, glass=glass, kelvin=[], viscosities=[], work=work, elements=elements
        )
        force = min(o.force for o in run(contact, time, depth))
        errors.append(abs(force - exact) / abs(exact))
    case = f"w={work} errors={np.round(errors, 5).tolist()}"
    assert errors[-1] < 0.5 * errors[0], f"{case}: no convergence with refinement"
    assert errors[-1] < 1e-2, f"{case}: not within 1% at 256 elements"


def _frozen(sim: ContactSimulator) -> tuple:
    """What a refused step must leave as it was: outputs, memo and the memory's bits."""
    row = getattr(sim._model, "row", None)
    memory = b"" if row is None else row.wl.tobytes() + row.wb.tobytes() + row.wsum.tobytes()
    return (sim.time, sim.output, sim._energy_input, sim._held_force, sim._force_memo, memory)


def _standard_solid() -> Any:
    return one_contact({"shape": "sphere", "radius": 0.005}, kelvin=[1e5], viscosities=[1.1e4], work=0.05)


def _punch() -> Any:
    return one_contact(
        {"shape": "flat_punch", "radius": 5e-4},
        kelvin=[1e5],
        viscosities=[1e4],
        work=0.05,
        numerics={"preset": "fast"},
    )


@pytest.mark.parametrize(
    "bad",
    [
        # Text and booleans are not numbers, though float() takes them (outside tester, 0.8.0).
        {"time": 2e-3, "force": "0.001"},
        {"time": 2e-3, "force": b"0.001"},
        {"time": 2e-3, "force": True},
        {"time": "2e-3", "depth": 1e-5},
        {"time": 2e-3, "depth": np.bool_(True)},
        # A time step the substep control halved to zero (ZeroDivisionError before 0.8.0):
        # only near time 0 can a step be that short.
        {"time": 1e-310, "force": 0.001},
        {"time": 1e-310, "depth": 1e-5},
    ],
)
def test_a_refused_command_changes_nothing_and_the_next_one_steps(bad: dict[str, Any]) -> None:
    """Bad input, on the lean and the general paths alike: an InputError (a ValueError) that
    says what is wrong, the state as before, and the next good command steps as if the bad one
    never came."""
    from viscoadh_ros.core.errors import InputError

    contact = _standard_solid()
    sim, reference_sim = ContactSimulator(contact), ContactSimulator(contact)
    for force in (1e-3, 1.2e-3, 1.1e-3):  # jumps at time 0
        sim.step(0.0, force=force)
        reference_sim.step(0.0, force=force)
    before = _frozen(sim)
    time = bad.pop("time")
    with pytest.raises(InputError, match="must be a number|shorter than the shortest"):
        sim.step(time, **bad)
    assert _frozen(sim) == before
    for k in range(4, 8):
        assert sim.step(k * 1e-3 / 3, force=1.5e-3) == reference_sim.step(k * 1e-3 / 3, force=1.5e-3)


def test_a_time_step_below_the_shortest_is_refused_by_step_depths_too() -> None:
    from viscoadh_ros.core.errors import InputError
    from viscoadh_ros.core.simulator import MIN_TIME_STEP

    sim = ContactSimulator(_standard_solid())
    sim.step(0.0, depth=1e-5)
    before = _frozen(sim)
    times = np.array([0.0, 1e-310, 3e-3])
    with pytest.raises(InputError, match=r"time\[1\].*shorter than the shortest"):
        sim.step_depths(times, np.full(3, 1e-5))
    assert _frozen(sim) == before
    # At the shortest step and at a repeated time (a jump) it steps.
    out = sim.step_depths(np.array([0.0, MIN_TIME_STEP, 2.0 * MIN_TIME_STEP]), np.array([1e-5, 2e-5, 2e-5]))
    assert np.all(np.isfinite(out["energy_input"])) and np.all(np.isfinite(out["edge_speed"]))


@pytest.mark.parametrize("control", ["force", "depth"])
def test_a_push_whose_energy_overflows_is_refused(control: str) -> None:
    """A flat punch's contact radius is fixed, so no domain limit refused an absurd push:
    1e154 N (or the depth it reaches) overflowed the energies to inf and the step was taken
    (outside tester, 0.8.0). The depth limit refuses such pushes now (the test above); behind
    it, every publish path refuses a step whose energy is not finite (here with the depth
    limit lifted), and changes nothing; a finite step is kept."""
    from viscoadh_ros.core.errors import InputError

    sim = ContactSimulator(_punch())
    sim._depth_limit = math.inf
    sim.step(1e-3, force=1e-3)
    before = _frozen(sim)
    with pytest.raises(InputError, match="energy is not finite"):
        sim.step(2e-3, **{control: 1e200})
    assert _frozen(sim) == before
    with pytest.raises(InputError, match="energy is not finite"):
        sim.step_depths(np.array([2e-3]), np.array([1e200]))
    assert _frozen(sim) == before
    out = sim.step(2e-3, force=2e-3)
    assert all(math.isfinite(getattr(out, name)) for name in FIELDS)


@pytest.mark.parametrize(
    "contact, command",
    [
        # A flat punch's contact radius is fixed: 1e15 N reached 1.9e11 m, and the next 0.01 N
        # was answered with 0.13 N (the memory's rounding at that scale).
        (_punch, {"force": 1e15}),
        (_punch, {"depth": 1e10}),
        # The closed form (elastic sphere) has no domain at all: 1e10 m was taken and 1e50 N
        # answered with 5.9e49 N (outside tester, 0.8.0).
        (lambda: one_contact({"shape": "sphere", "radius": 5e-3}, work=0.05), {"depth": 1e10}),
        (lambda: one_contact({"shape": "sphere", "radius": 5e-3}, work=0.05), {"force": 1e50}),
    ],
    ids=["punch_force", "punch_depth", "closed_form_depth", "closed_form_force"],
)
def test_a_depth_beyond_the_largest_domain_is_refused_on_every_model(contact: Any, command: dict) -> None:
    """|depth| may not pass the largest domain a time-stepped contact of the scene can reach
    (`ContactSimulator._depth_limit`, 1e3 m here), whatever the model: the step is refused (naming the
    limit), changes nothing, and the contact goes on as one that never saw it."""
    from viscoadh_ros.core.errors import InputError

    sim, reference_sim = ContactSimulator(contact()), ContactSimulator(contact())
    for k in range(1, 4):
        sim.step(k * 1e-3, force=1e-2)
        reference_sim.step(k * 1e-3, force=1e-2)
    before = _frozen(sim)
    with pytest.raises(InputError, match="beyond the scene.s range.*largest domain"):
        sim.step(4e-3, **command)
    assert _frozen(sim) == before
    for k in range(4, 8):
        assert sim.step(k * 1e-3, force=1e-2 * (k - 2)) == reference_sim.step(k * 1e-3, force=1e-2 * (k - 2))


@pytest.mark.parametrize(
    "values, words",
    [
        ([1e-6, True], "depth[1] must be a number (got True)"),
        (["1e-6", "2e-6"], "depth[0] must be a number (got '1e-6')"),
        (np.array([True, False]), "depth must be a sequence of numbers (got booleans)"),
        (np.array(["1e-6", "2e-6"]), "depth must be a sequence of numbers"),
    ],
)
def test_simulate_history_takes_numbers_only(values: Any, words: str) -> None:
    """Booleans and numeric text became 1 m or 0.001 N through numpy (0.8.0's outside tester),
    though `step` refuses them: refused before anything runs, like `step`."""
    from viscoadh_ros.core.errors import InputError
    from viscoadh_ros.core.history import simulate_history

    with pytest.raises(InputError) as refused:
        simulate_history(_standard_solid(), [0.0, 1e-3], depth=values)
    assert words in str(refused.value)
    # The same numbers as numbers run.
    result = simulate_history(_standard_solid(), [0.0, 1e-3], depth=[1e-6, 2e-6])
    assert np.all(np.isfinite(result.force))
