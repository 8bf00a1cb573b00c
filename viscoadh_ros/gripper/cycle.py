"""One pick (and place) in the MuJoCo cell with the pads stepped by a `PadBank`.

Per physics step k, at ``t_k = k dt`` (integer nanoseconds, `pads.step_time`):

1. ``mj_step1``: positions and velocities of step k, kinematics, MuJoCo's own collisions.
2. the pad geometry (depth, normal, point) from MuJoCo's geoms;
3. ``bank.step(t_k, depths)``: every pad's contact to ``t_k`` (the depth is linear in time
   between two steps, as the core integrates a sampled history);
4. the pad forces on the arm and the part, the servo references;
5. ``mj_step2``: MuJoCo integrates to step k + 1 (semi-implicit Euler, ``implicitfast``).

The coupling is explicit (the pad force of step k acts over step k). It is stable when the
pads' contact stiffness against the part's mass resolves in time: `stability_number` is
``omega dt`` with ``omega = sqrt(n k / m)``, ``k = 2 E0* a`` the stiffness of one pad at the
deepest press (glass modulus: what a fast oscillation meets) and ``a = sqrt(R d)``. `run_cycle`
refuses a run above `STABILITY_LIMIT` with the longest time step that would do; tests check
that a part resting under a pad settles without a growing oscillation at the default step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.rheology import CreepElement

from .config import Cell
from .motion import ArmProgram, Motion
from .pads import PadBank, step_time
from .scene import LATCH_CLEARANCE, CellModel

#: The part counts as lifted (or pulled out of the fixture) above this rise, m.
LIFT_THRESHOLD = 0.5e-3
#: Largest accepted ``omega dt`` of the pads-on-part oscillation (semi-implicit Euler is
#: stable below 2; 0.5 keeps about 12 steps per period and the phase error small).
STABILITY_LIMIT = 0.5
GRAVITY = 9.81


def contact_stiffness(cell: Cell, depth: float) -> float:
    """Instant (glass-modulus) normal stiffness of one pad at ``depth`` (m), N/m: ``2 E0* a``
    with the Hertz radius ``a = sqrt(R d)``."""
    e0 = CreepElement.from_config(cell.pad.material).glass_modulus_star
    return 2.0 * e0 * math.sqrt(float(cell.pad.indenter.radius) * max(depth, 0.0))


def stability_number(cell: Cell, depth: float) -> float:
    """``omega dt`` of the part on all pads pressed ``depth`` (m) deep (see the module doc)."""
    g = cell.gripper
    omega = math.sqrt(g.pad_count * contact_stiffness(cell, depth) / g.part.mass)
    return omega * g.timestep


def _deepest(motion: Motion) -> float:
    return max(motion.press_depth, motion.place_depth if motion.place else 0.0)


def longest_stable_timestep(cell: Cell, motion: Motion) -> float:
    """The longest ``gripper.timestep`` (s) `check_stability` accepts for ``motion``."""
    return cell.gripper.timestep * STABILITY_LIMIT / stability_number(cell, _deepest(motion))


def timestep_text(seconds: float) -> str:
    """``seconds`` rounded DOWN to 3 significant digits, as text: a time step suggested as
    ``<= 0.000146 s`` is then accepted (``:.3g`` alone may round above the bound)."""
    scale = 10.0 ** (math.floor(math.log10(seconds)) - 2)
    return f"{math.floor(seconds / scale) * scale:.3g}"


def check_stability(cell: Cell, motion: Motion) -> None:
    """InputError (with the longest stable time step) when the explicit coupling would not
    resolve the pads-on-part oscillation at the motion's deepest press."""
    depth = _deepest(motion)
    number = stability_number(cell, depth)
    if number > STABILITY_LIMIT:
        longest = longest_stable_timestep(cell, motion)
        raise InputError(
            f"gripper.timestep {cell.gripper.timestep:g} s is too long for a "
            f"{cell.gripper.part.mass * 1e3:g} g part on {cell.gripper.pad_count} pad(s) pressed "
            f"{depth * 1e6:g} um: omega*dt = {number:.2f} > {STABILITY_LIMIT} "
            f"(use gripper.timestep <= {timestep_text(longest)} s, a heavier part or a shallower press)"
        )


@dataclass
class Trajectory:
    """A recorded run, one row per physics step (SI units).

    time (n,) s; arm_height, arm_reference (n,) m (pad-tip plane above the part's resting top);
    part_rise (n,) m; latch_height (n,) m; depth, force, contact_radius (n, pads) m, N, m;
    segment (n,) names of the motion segments; starts: segment -> start time, s;
    pick_step: first step the part was lifted (None: never); release_step: first step after
    the hold began with every pad out of touch (None: never); outcome: one line;
    success: whether the run did what it was for (held it, or released it into the fixture);
    predictions: what the controller asked (name -> value), for the figures.
    """

    time: NDArray[np.float64]
    arm_height: NDArray[np.float64]
    arm_reference: NDArray[np.float64]
    part_rise: NDArray[np.float64]
    latch_height: NDArray[np.float64]
    depth: NDArray[np.float64]
    force: NDArray[np.float64]
    contact_radius: NDArray[np.float64]
    segment: NDArray[np.str_]
    starts: dict[str, float]
    part_mass: float
    pad_count: int
    place: bool
    pick_step: int | None = None
    release_step: int | None = None
    outcome: str = ""
    success: bool = False
    predictions: dict[str, float] = field(default_factory=dict)

    @property
    def pick_time(self) -> float | None:
        return None if self.pick_step is None else float(self.time[self.pick_step])

    @property
    def release_time(self) -> float | None:
        return None if self.release_step is None else float(self.time[self.release_step])


def run_cycle(
    cell: Cell,
    motion: Motion,
    bank: PadBank,
    *,
    choose_retract_speed: Callable[[PadBank], float] | None = None,
    stop_after_release: bool = False,
    duration: float | None = None,
    frames: Callable[[mujoco.MjModel, mujoco.MjData, float], None] | None = None,
) -> Trajectory:
    """Run ``motion`` in a fresh MuJoCo model of ``cell`` with ``bank`` stepping the pads.

    The pick's prediction (``predictions["pick_pull_off"]``, N, and ``["pick_capacity_kg"]``):
    when the press really ends (the first step after the hold at which the pads' summed depth
    falls: the servo lags its reference, so without a hold the arm still presses into the
    peel), the live pads are asked `PadBank.predict_pull_off` at the speed they are then pulled
    at (`Motion.pad_retract_speed`); the heaviest part that pull-off lifts is the pull-off over
    ``g + lift_acceleration`` (the peak load of a lift with a peel, measured within 2 %).
    It is a lower bound: docs/gripper.md gives the measured boundary against it.

    ``choose_retract_speed(bank)`` is called once when the retraction of a place starts (if
    ``motion.retract_speed`` is None). ``stop_after_release``: end 20 steps after the release
    (tests). ``duration``: end after this much simulated time, s (the bench). ``frames(model, data, t)``:
    called every step after the forces are applied (`render.FrameRecorder`). InputError for a
    motion the coupling cannot resolve (`check_stability`).
    """
    check_stability(cell, motion)
    if bank.count != cell.gripper.pad_count:
        raise InputError(f"the bank has {bank.count} pads, the cell {cell.gripper.pad_count}")
    world = CellModel(cell, latch_open_height=motion.lift_height + LATCH_CLEARANCE)
    program = ArmProgram(
        motion,
        start_height=cell.gripper.arm.start_height,
        latch_time=cell.gripper.fixture.latch_time,
        choose_retract_speed=None if choose_retract_speed is None else lambda: choose_retract_speed(bank),
    )
    dt_ns = round(cell.gripper.timestep * 1e9)
    m, d = world.model, world.data
    rows: dict[str, list] = {
        k: [] for k in ("time", "arm", "ref", "rise", "latch", "depth", "force", "radius", "seg")
    }
    step = 0
    stop_at: int | None = None
    previous_depth = -math.inf
    pick_prediction: float | None = None
    while True:
        t = step_time(step, dt_ns)
        if t > program.duration or (stop_at is not None and step >= stop_at):
            break
        if duration is not None and t > duration:
            break
        mujoco.mj_step1(m, d)
        geometry = world.pad_geometry()
        if pick_prediction is None and t >= program.starts["peel"]:
            deepest = float(geometry.depth.sum())
            if deepest < previous_depth:  # the press really ended at the last step
                pick_prediction = float(bank.predict_pull_off(motion.pad_retract_speed).sum())
            previous_depth = deepest
        states = bank.step(t, geometry.depth)
        world.apply_pad_forces(geometry, states.force)
        reference = program.arm_height(t)
        world.set_controls(reference, latch_closed=program.latch_fraction(t))
        if frames is not None:
            frames(m, d, t)
        rows["time"].append(t)
        rows["arm"].append(world.arm_height)
        rows["ref"].append(reference)
        rows["rise"].append(world.part_rise)
        rows["latch"].append(world.latch_height)
        rows["depth"].append(geometry.depth.copy())
        rows["force"].append(states.force.copy())
        rows["radius"].append(states.contact_radius.copy())
        rows["seg"].append(program.segment(t))
        if (
            stop_after_release
            and stop_at is None
            and t >= program.starts["peel"]
            and not states.contact_radius.any()
        ):
            stop_at = step + 20
        mujoco.mj_step2(m, d)
        step += 1
    trajectory = Trajectory(
        time=np.array(rows["time"]),
        arm_height=np.array(rows["arm"]),
        arm_reference=np.array(rows["ref"]),
        part_rise=np.array(rows["rise"]),
        latch_height=np.array(rows["latch"]),
        depth=np.array(rows["depth"]).reshape(-1, bank.count),
        force=np.array(rows["force"]).reshape(-1, bank.count),
        contact_radius=np.array(rows["radius"]).reshape(-1, bank.count),
        segment=np.array(rows["seg"]),
        starts=dict(program.starts),
        part_mass=cell.gripper.part.mass,
        pad_count=bank.count,
        place=motion.place,
    )
    if pick_prediction is not None:
        trajectory.predictions["pick_pull_off"] = pick_prediction
        trajectory.predictions["pick_capacity_kg"] = -pick_prediction / (GRAVITY + motion.lift_acceleration)
    if program.retract_speed is not None:
        trajectory.predictions["retract_speed"] = float(program.retract_speed)
    judge(trajectory)
    return trajectory


def judge(trajectory: Trajectory) -> None:
    """Fill in pick_step, release_step, outcome and success from the recorded rows."""
    tr = trajectory
    lifted = tr.part_rise > LIFT_THRESHOLD
    tr.pick_step = int(np.argmax(lifted)) if lifted.any() else None
    after_hold = tr.time >= tr.starts["peel"]
    free = ~tr.contact_radius.any(axis=1) & after_hold
    tr.release_step = int(np.argmax(free)) if free.any() else None
    released = tr.release_step is not None
    if not tr.place:
        if tr.pick_step is None:
            rise = float(tr.part_rise.max()) if tr.part_rise.size else 0.0
            if rise > 0.0:
                where = f"the part rose {rise * 1e3:.3g} mm"
            else:
                where = "the part never left the table"
            lift = f"{LIFT_THRESHOLD * 1e3:g} mm"
            tr.outcome = f"not picked: the pads let go before the part was lifted {lift} ({where})"
            tr.success = False
        elif released:
            tr.outcome = f"dropped in transport at t = {tr.release_time:.4f} s"
            tr.success = False
        else:
            tr.outcome, tr.success = "picked and held", True
        return
    in_retract = tr.time >= tr.starts["retract"]
    retract_start = int(np.argmax(in_retract)) if in_retract.any() else tr.time.size
    if tr.pick_step is None or tr.pick_step >= retract_start:
        tr.outcome, tr.success = "not picked: nothing to place", False
        return
    if released and tr.release_step < retract_start:
        tr.outcome, tr.success = f"dropped before the place at t = {tr.release_time:.4f} s", False
        return
    pulled_out = bool((tr.part_rise[in_retract] > LIFT_THRESHOLD).any())
    if pulled_out:
        tr.outcome, tr.success = "release failed: the pads pulled the part out of the fixture", False
    elif released:
        tr.outcome, tr.success = f"placed: released into the fixture at t = {tr.release_time:.4f} s", True
    else:
        tr.outcome, tr.success = "release failed: the pads still hold the part", False
