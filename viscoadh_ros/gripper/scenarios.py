"""The scenarios of `viscoadh gripper`, each a few runs of `run_cycle` and one figure.

- ``pick``: three presses of a 1.3 g part; on the built-in cell the one without a hold (too
  short) and the 10 um one (too shallow) fail, the one held long enough lifts the part.
- ``transport``: the same grip lifted gently and with a hard acceleration (the pads carry
  ``m (g + a)`` while it lasts).
- ``place``: pick, carry, lower into the fixture, latch (a weak and a strong one), retract:
  the release succeeds only if the pads' pull-off stays below the latch's holding force plus
  the part's weight.
- ``controller``: `plan_pick` chooses press depth and hold time from `predict_pull_off` so the
  pick holds with a safety factor; at the latch `choose_release_speed` asks the live pads for
  the retract speed whose pull-off the fixture can hold.
- ``weights``: parts of several masses for two grips, against the model's predicted capacity.

Each scenario is first planned (`plan`: its runs' labels, cells and motions, without
stepping anything) and then run (`run_planned`); `check` asks `check_stability` of every
planned run, so `viscoadh gripper` refuses a cell before it writes anything (0.10.0's outside
tester: a 2x2 cell passed ``pick``, wrote its figure and was refused at ``transport``, exit 2).
A run's label states its setting (press, hold, lift, latch, mass), never the outcome the
built-in cell is expected to give: another cell may give another one.

`Bank` is a factory ``cell -> PadBank`` (library or node path); each run gets a fresh bank.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

import numpy as np

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.history import predict_pull_off
from viscoadh_ros.core.simulator import ContactSimulator

from .config import Cell
from .cycle import GRAVITY, Trajectory, check_stability, longest_stable_timestep, run_cycle, timestep_text
from .motion import Motion
from .pads import LibraryPads, PadBank

SCENARIOS = ("pick", "transport", "place", "controller", "weights")
#: The controller's safety factor on the pick (pull-off against m (g + a)) and the release.
SAFETY_FACTOR = 1.5
#: Retract speeds the controller may release at, m/s (slowest first: the gentlest that works).
RELEASE_SPEEDS = (0.002, 0.01, 0.05, 0.2)

Bank = Callable[[Cell], PadBank]


def library_bank(cell: Cell) -> PadBank:
    """The fast path: the pads' simulators in this process."""
    return LibraryPads(cell.pad, cell.gripper.pad_count)


def with_mass(cell: Cell, mass: float) -> Cell:
    return replace(cell, gripper=cell.gripper.with_part_mass(mass))


@dataclass(frozen=True)
class Run:
    """One labelled run of a scenario."""

    label: str
    trajectory: Trajectory


#: Set by `viscoadh gripper --frames DIR`: a factory ``label -> frames callback`` for run_cycle.
FRAMES: Callable[[str], Callable] | None = None


def _run(label: str, cell: Cell, motion: Motion, bank: Bank, **kwargs) -> Run:
    if FRAMES is not None:
        kwargs["frames"] = FRAMES(label)
    pads = bank(cell)
    try:
        return Run(label, run_cycle(cell, motion, pads, **kwargs))
    finally:
        pads.close()


def predicted_pull_off(cell: Cell, motion: Motion) -> float:
    """Total pull-off force of the pads (N, < 0) the model predicts for ``motion``'s press:
    one pad pressed at the approach speed from the start height to ``press_depth`` into a
    rigid part, held ``hold_time``, then asked `predict_pull_off` at the speed the pads are
    pulled off at (`Motion.pad_retract_speed`: the peel's), times the number of pads. This is
    the plan before the run; the run's own prediction (`run_cycle`) asks the live pads after
    the press the servo really made. (The servo lags its reference by ``kv v / kp`` and the
    part sinks a little into the table: the planned press is a little off; the safety factor
    covers it.)"""
    simulator = ContactSimulator(cell.pad)
    start = cell.gripper.arm.start_height
    approach = (start + motion.press_depth) / motion.approach_speed
    samples = max(2, int(approach / cell.gripper.timestep) + 1)
    times = np.linspace(0.0, approach, samples)
    simulator.step_depths(times, -start + motion.approach_speed * times)
    if motion.hold_time > 0.0:
        simulator.step(approach + motion.hold_time, depth=motion.press_depth)
    single = predict_pull_off(simulator, motion.pad_retract_speed).pull_off_force
    return cell.gripper.pad_count * single


def capacity(cell: Cell, motion: Motion) -> float:
    """Heaviest part (kg) the predicted pull-off lifts at the motion's lift acceleration."""
    return -predicted_pull_off(cell, motion) / (GRAVITY + motion.lift_acceleration)


def plan_pick(cell: Cell, base: Motion, *, safety: float = SAFETY_FACTOR) -> Motion:
    """The quickest press (shallowest, then shortest hold) of a small grid whose predicted
    pull-off carries ``safety`` times ``m (g + a)``; InputError (a ValueError) if none does."""
    need = safety * cell.gripper.part.mass * (GRAVITY + base.lift_acceleration)
    for hold in (0.0, 0.1, 0.2, 0.4, 0.8):
        for depth in (20e-6, 50e-6, 100e-6, 150e-6):
            motion = replace(base, press_depth=depth, hold_time=hold)
            if -predicted_pull_off(cell, motion) >= need:
                return motion
    raise InputError(
        f"no press of the grid holds a {cell.gripper.part.mass * 1e3:g} g part with safety {safety:g}"
    )


def choose_release_speed(cell: Cell, bank: PadBank, *, safety: float = SAFETY_FACTOR) -> tuple[float, dict]:
    """At the latch: the slowest of RELEASE_SPEEDS whose predicted total pull-off, times
    ``safety``, stays below the holding force plus the part's weight (else the fastest).
    Returns (speed m/s, {speed: predicted total pull-off N})."""
    hold = cell.gripper.fixture.holding_force + cell.gripper.part.mass * GRAVITY
    predictions = {v: float(bank.predict_pull_off(v).sum()) for v in RELEASE_SPEEDS}
    for speed in RELEASE_SPEEDS:
        if -predictions[speed] * safety <= hold:
            return speed, predictions
    return RELEASE_SPEEDS[-1], predictions


#: The scenarios' grips: a good press and two that fail (base part 1 g, built-in cell).
GOOD = Motion(press_depth=150e-6, hold_time=0.3)
SHORT = replace(GOOD, hold_time=0.0)
SHALLOW = replace(GOOD, press_depth=10e-6)


#: The pick scenario's part, kg: heavier than the built-in cell's 1 g, so that a grip without a
#: hold (measured boundary 1.05-1.1 g with the slow peel) fails while a held one (1.6 g) lifts it.
PICK_MASS = 1.3e-3


@dataclass(frozen=True)
class Planned:
    """One run of a scenario before it runs: its label (the setting, not an expected outcome),
    its cell and motion; ``release_controller``: the retract speed is chosen at the latch by
    `choose_release_speed` (the controller scenario)."""

    label: str
    cell: Cell
    motion: Motion
    release_controller: bool = False


def grip_text(motion: Motion) -> str:
    """The press of ``motion`` as a label: ``press 150 um, hold 0.3 s`` (or ``no hold``)."""
    hold = f"hold {motion.hold_time:g} s" if motion.hold_time > 0.0 else "no hold"
    return f"press {motion.press_depth * 1e6:g} um, {hold}"


def plan_pick_scenario(cell: Cell) -> list[Planned]:
    cell = with_mass(cell, PICK_MASS)
    return [Planned(grip_text(motion), cell, motion) for motion in (SHORT, SHALLOW, GOOD)]


def plan_transport(cell: Cell) -> list[Planned]:
    gentle = replace(GOOD, lift_acceleration=2.0, lift_height=0.02, carry_time=0.3)
    hard = replace(gentle, lift_acceleration=40.0, lift_speed=0.2)
    return [Planned(f"lift at {m.lift_acceleration:g} m/s^2", cell, m) for m in (gentle, hard)]


def with_holding_force(cell: Cell, force: float) -> Cell:
    fixture = replace(cell.gripper.fixture, holding_force=force)
    return replace(cell, gripper=replace(cell.gripper, fixture=fixture))


def plan_place(cell: Cell) -> list[Planned]:
    place = replace(GOOD, place=True, retract_speed=0.002)
    return [
        Planned(f"latch holds {force * 1e3:g} mN", with_holding_force(cell, force), place)
        for force in (0.002, 0.02)
    ]


def plan_controller(cell: Cell) -> list[Planned]:
    motion = replace(plan_pick(cell, Motion(place=True, retract_speed=None)), place=True, retract_speed=None)
    return [Planned(f"planned: {grip_text(motion)}", cell, motion, release_controller=True)]


#: Part masses of the weights scenario, kg.
WEIGHTS = (0.6e-3, 0.9e-3, 1.2e-3, 1.5e-3, 1.8e-3)
#: The measured pick boundary lies between 1 and this many times the predicted capacity
#: (`run_cycle`'s live prediction; docs/gripper.md: a hanging part's contact creeps stronger).
CAPACITY_MARGIN = 1.35


def plan_weights(cell: Cell) -> list[Planned]:
    return [
        Planned(f"{label}|{mass * 1e3:g} g", with_mass(cell, mass), motion)
        for label, motion in (("no hold", SHORT), ("hold 0.3 s", GOOD))
        for mass in WEIGHTS
    ]


PLANS: dict[str, Callable[[Cell], list[Planned]]] = {
    "pick": plan_pick_scenario,
    "transport": plan_transport,
    "place": plan_place,
    "controller": plan_controller,
    "weights": plan_weights,
}


def plan(name: str, cell: Cell) -> list[Planned]:
    """The runs of scenario ``name`` on ``cell``, not yet run (InputError if the controller
    finds no press that holds the part)."""
    return PLANS[name](cell)


def check(planned: Mapping[str, list[Planned]]) -> None:
    """InputError unless every planned run (scenario name -> its runs) passes the checks
    `run_cycle` makes before it steps (`check_stability`). The error names the first refused
    scenario and run; with more refused, how many and the time step that suits them all."""
    refused = []
    for name, runs in planned.items():
        for run in runs:
            try:
                check_stability(run.cell, run.motion)
            except InputError as error:
                refused.append((name, run, error))
    if not refused:
        return
    name, run, error = refused[0]
    text = f"scenario {name} ({run.label.replace('|', ', ')}): {error}"
    if len(refused) > 1:
        longest = min(longest_stable_timestep(r.cell, r.motion) for _, r, _ in refused)
        where = ", ".join(dict.fromkeys(n for n, _, _ in refused))
        text += (
            f"; {len(refused) - 1} more run(s) refused too ({where}); "
            f"gripper.timestep <= {timestep_text(longest)} s suits every one"
        )
    raise InputError(text)


def run_planned(planned: Planned, bank: Bank) -> Run:
    """Run one planned run on a fresh bank."""
    if not planned.release_controller:
        return _run(planned.label, planned.cell, planned.motion, bank)
    cell, motion = planned.cell, planned.motion
    asked: dict = {}

    def decide(pads: PadBank) -> float:
        speed, predictions = choose_release_speed(cell, pads)
        asked.update(predictions)
        return speed

    run = _run(planned.label, cell, motion, bank, choose_retract_speed=decide)
    run.trajectory.predictions["pick_pull_off"] = predicted_pull_off(cell, motion)
    for speed, force in asked.items():
        run.trajectory.predictions[f"release_pull_off@{speed:g}"] = force
    return run


def run_scenario(name: str, cell: Cell, bank: Bank) -> list[Run]:
    """Plan, check and run scenario ``name``."""
    planned = plan(name, cell)
    check({name: planned})
    return [run_planned(run, bank) for run in planned]


def scenario_pick(cell: Cell, bank: Bank) -> list[Run]:
    return run_scenario("pick", cell, bank)


def scenario_transport(cell: Cell, bank: Bank) -> list[Run]:
    return run_scenario("transport", cell, bank)


def scenario_place(cell: Cell, bank: Bank) -> list[Run]:
    return run_scenario("place", cell, bank)


def scenario_controller(cell: Cell, bank: Bank) -> list[Run]:
    return run_scenario("controller", cell, bank)


def scenario_weights(cell: Cell, bank: Bank) -> list[Run]:
    return run_scenario("weights", cell, bank)


RUNNERS: dict[str, Callable[[Cell, Bank], list[Run]]] = {
    "pick": scenario_pick,
    "transport": scenario_transport,
    "place": scenario_place,
    "controller": scenario_controller,
    "weights": scenario_weights,
}
