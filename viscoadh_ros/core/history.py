"""Whole loading histories and "what if I retract now" on top of `ContactSimulator`.

`simulate_history` runs a sampled depth or force history from a fresh state (the depth is
linear between samples); `predict_pull_off` retracts a copy of a live contact at constant
speed and reports where it lets go. Both only drive the simulator; they hold no physics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import InputError, require_positive
from .simulator import STEP_OUTPUT_FIELDS, ContactSimulator, StepOutput

FloatArray = NDArray[np.float64]

#: Output steps per characteristic depth range of the retraction in `predict_pull_off`.
PULL_OFF_STEPS = 400
#: The retraction gives up after this many characteristic depth ranges.
PULL_OFF_RANGES = 50
#: Rows per step across the two steps around the let-go (or the largest pull), looked at again.
PULL_OFF_REFINE = 16
#: The let-go is bracketed to this fraction of the time retracted (the zoom stops there) ...
PULL_OFF_TIME_TOLERANCE = 1e-6
#: ... or after this many zoom levels (each narrows the bracket 16 times: enough for any range
#: of doubles; 8 left a very glassy pad's branch, G0/G1 = 1e12, unresolved: 0 N, 0.9.0).
PULL_OFF_LEVELS = 64
#: The rows around the largest pull are looked at again until it moves by less than this.
PULL_OFF_FORCE_TOLERANCE = 1e-6


@dataclass(frozen=True)
class HistoryResult:
    """One value per input sample for every `StepOutput` field (arrays of shape (n,)).

    time, depth, contact_radius, edge_speed: s, m, m, m/s; force: N; phase: uint8 (`Phase`
    values); effective_work_of_adhesion: J/m^2; energy_input, energy_dissipated: J;
    scale_separation_ok, unstable: bool. ``model`` names the model path used.
    """

    time: FloatArray
    depth: FloatArray
    force: FloatArray
    contact_radius: FloatArray
    phase: NDArray[np.uint8]
    edge_speed: FloatArray
    effective_work_of_adhesion: FloatArray
    energy_input: FloatArray
    energy_dissipated: FloatArray
    scale_separation_ok: NDArray[np.bool_]
    unstable: NDArray[np.bool_]
    model: str

    def columns(self) -> dict[str, np.ndarray]:
        """The output columns in CSV order: time, depth, force, contact_radius, phase, then
        the other StepOutput fields."""
        return {name: getattr(self, name) for name in STEP_OUTPUT_FIELDS}

    @classmethod
    def from_outputs(cls, outputs: list[StepOutput], model: str) -> HistoryResult:
        dtypes = {"phase": np.uint8, "scale_separation_ok": np.bool_, "unstable": np.bool_}
        arrays = {
            name: np.array([getattr(o, name) for o in outputs], dtype=dtypes.get(name, np.float64))
            for name in STEP_OUTPUT_FIELDS
        }
        return cls(**arrays, model=model)


def _history_array(name: str, values: ArrayLike) -> FloatArray:
    # Numbers only: numpy turns booleans and numeric text into floats (True -> 1 m,
    # "0.001" -> 0.001 N), which `step` refuses since 0.8.0 (`errors.require_finite`).
    if isinstance(values, np.ndarray):
        if values.dtype.kind not in "iufO" and values.size:
            kind = "booleans" if values.dtype.kind == "b" else f"{values.dtype.name} values"
            raise InputError(f"{name} must be a sequence of numbers (got {kind})")
        items = values.reshape(-1) if values.dtype.kind == "O" else ()
    else:
        items = values if isinstance(values, (list, tuple)) else ()
    for index, item in enumerate(items):
        if isinstance(item, (str, bytes, bool, np.bool_)):
            raise InputError(f"{name}[{index}] must be a number (got {item!r})")
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a sequence of numbers") from None
    if array.ndim != 1:
        raise InputError(f"{name} must be one-dimensional (got shape {array.shape})")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise InputError(f"{name}[{int(bad[0])}] must be finite (got {float(array[bad[0]])!r})")
    return array


def simulate_history(
    contact: Any, time: ArrayLike, *, depth: ArrayLike | None = None, force: ArrayLike | None = None
) -> HistoryResult:
    """Run a history from a fresh, undeformed state of `contact` (a ContactConfig).

    time: sample times, s, shape (n,), n >= 1, strictly increasing. Exactly one of
    depth (m, > 0 presses in; displacement control) or force (N, > 0 compressive; force
    control), shape (n,). The contact rests at depth 0 until the first sample, reached
    instantly. Everything is validated before anything is computed.
    """
    if (depth is None) == (force is None):
        raise InputError("simulate_history needs exactly one of depth or force")
    times = _history_array("time", time)
    control_name = "depth" if depth is not None else "force"
    control = _history_array(control_name, depth if depth is not None else force)
    if times.size == 0:
        raise InputError("time must have at least one sample")
    if control.size != times.size:
        raise InputError(f"{control_name} has {_samples(control.size)} but time has {_samples(times.size)}")
    steps = np.flatnonzero(np.diff(times) <= 0.0)
    if steps.size:
        i = int(steps[0]) + 1
        raise InputError(
            f"time must be strictly increasing "
            f"(time[{i}] = {float(times[i])!r} after {float(times[i - 1])!r})"
        )
    simulator = ContactSimulator(contact)
    simulator.reset(float(times[0]))
    if depth is not None:
        # All rows in one compiled loop on the time-stepped path (same outputs as stepping).
        return HistoryResult(**simulator.step_depths(times, control), model=simulator.model)
    outputs = [simulator.step(float(t), force=float(c)) for t, c in zip(times, control, strict=True)]
    return HistoryResult.from_outputs(outputs, simulator.model)


@dataclass(frozen=True)
class PullOffPrediction:
    """Outcome of a constant-speed retraction from the current state.

    pull_off_force: the most tensile force reached, N (0 if never tensile); pull_off_depth:
    the depth where it was reached (never tensile: where the contact let go), m;
    time_to_detach: from the start of the retraction to full detachment, s (the time the
    retraction ran if it did not detach); detached: whether
    the contact let go; message: what happened, including a limit that stopped the run.
    """

    pull_off_force: float
    pull_off_depth: float
    time_to_detach: float
    detached: bool
    message: str


def predict_pull_off(simulator: ContactSimulator, retract_speed: float) -> PullOffPrediction:
    """Retract `simulator`'s contact from its current depth at `retract_speed` (m/s, > 0)
    until it has fully detached, on a snapshot: the live state is restored afterwards.

    The depth step is 1/PULL_OFF_STEPS of a characteristic range (current depth plus the
    profile height at the edge plus the glass critical elongation scaled to the relaxed
    modulus); the run stops after PULL_OFF_RANGES such ranges and says so. That range can be
    far wider than the adhesive branch (a deep press, a glassy body: E0*/E_r* >> 1), so one
    step may cross the whole branch; the let-go is therefore bracketed and the bracket
    zoomed: the same path (the depth is linear in time between rows whatever their spacing)
    is stepped again from the row before the last attached one, PULL_OFF_REFINE rows per
    step, until the first detached row is known to PULL_OFF_TIME_TOLERANCE of the time
    retracted (`time_to_detach` is that row's time). The largest pull is the most tensile
    force of every row run; the rows around it are then looked at again, PULL_OFF_REFINE
    times finer, from the same rows before it, until it settles.
    """
    speed = require_positive("retract_speed", retract_speed)
    start = simulator.snapshot()
    out = simulator.output
    if not simulator.in_contact:
        return PullOffPrediction(0.0, out.depth, 0.0, True, "not in contact: nothing to pull off")
    physics = simulator.physics
    radius = out.contact_radius
    edge_height = float(physics.profile.g(radius))
    critical = physics.c_crit * math.sqrt(radius) * physics.e0 / physics.e_relaxed
    span = abs(out.depth) + edge_height + critical
    if not span > 0.0:
        span = radius
    dt = span / PULL_OFF_STEPS / speed
    t0, d0 = simulator.time, out.depth
    # The largest pull: force, depth, time after t0 (-1: none yet) and the level of rows it
    # came from (`levels`: each level's starting snapshot, its time and its row spacing).
    best = [min(out.force, 0.0), out.depth, -1.0, 0]
    levels: list[tuple[Any, float, float]] = [(start, 0.0, dt)]

    def rows_from(level: int, count: int) -> int:
        """The first `count` rows of level `level`; the first detached row's index (1-based),
        0 if none."""
        origin, ta, h = levels[level]
        simulator.restore(origin)
        for k in range(1, count + 1):
            t = ta + k * h
            step = simulator.step(t0 + t, depth=d0 - speed * t)
            if step.force < best[0]:
                best[:] = [step.force, step.depth, t, level]
            if not simulator.in_contact:
                return k
        return 0

    def level_after(level: int, rows: int, refine: int) -> int:
        """A new level: from `rows` rows of `level` on, rows `refine` times finer."""
        origin, ta, h = levels[level]
        if rows:
            rows_from(level, rows)
            origin = simulator.snapshot()
        levels.append((origin, ta + rows * h, h / refine))
        return len(levels) - 1

    detached = False
    elapsed = 0.0
    try:
        first = rows_from(0, PULL_OFF_STEPS * PULL_OFF_RANGES)
        elapsed = simulator.time - t0
        if first:
            detached = True
            # The let-go lies within the last two rows: zoom in from the row before the last
            # attached one, rows PULL_OFF_REFINE times finer, until the first detached row is
            # known closely enough.
            level, count = 0, first
            for _ in range(PULL_OFF_LEVELS):
                level = level_after(level, max(count - 2, 0), PULL_OFF_REFINE)
                count = rows_from(level, 4 * PULL_OFF_REFINE)
                if not count:
                    # The finer rows hold on a little longer than the coarser ones let go:
                    # keep the bracket found so far.
                    break
                _, ta, h = levels[level]
                elapsed = ta + count * h
                if h <= PULL_OFF_TIME_TOLERANCE * elapsed:
                    break
        settled, current = 0, best[3]
        for _ in range(PULL_OFF_LEVELS):
            # The rows around the largest pull again, PULL_OFF_REFINE times finer, until two
            # levels in a row move it by less than PULL_OFF_FORCE_TOLERANCE of itself: a smooth
            # minimum settles at once; the cusp at a fast let-go, which a row steps past (0.9 %
            # of the pull-off at 1 d_c, 10 mm/s), can hide from one finer level: after a deep
            # press on a power law retracted at 1 m/s, rows 16x finer found the same force and
            # rows 256x finer 1.9 % more (an outside tester, 0.9.0).
            if not best[2] > 0.0:
                break
            before = best[0]
            # Each level finer than the last, around the largest pull so far (which may have
            # come from a coarser level), from the rows before it on the last level.
            _, ta, h = levels[current]
            k = int(round((best[2] - ta) / h))
            current = level_after(current, max(k - 1, 0), PULL_OFF_REFINE)
            rows_from(current, 2 * PULL_OFF_REFINE)
            settled = settled + 1 if abs(best[0] - before) <= PULL_OFF_FORCE_TOLERANCE * abs(best[0]) else 0
            if settled == 2:
                break
    finally:
        simulator.restore(start)
    if detached and not best[0] < 0.0:
        # Never tensile (no adhesion): nothing was pulled, and the depth that matters is where
        # the contact let go (the start depth was reported: a second outside tester, 0.12.0).
        best[1] = d0 - speed * elapsed
    if detached:
        message = f"detached after {elapsed:.6g} s of retraction at {speed:g} m/s"
    else:
        message = (
            f"still in contact after retracting {speed * elapsed:.6g} m "
            f"({PULL_OFF_RANGES} characteristic depth ranges); the values are up to there"
        )
    return PullOffPrediction(best[0], best[1], elapsed, detached, message)


def _samples(count: int) -> str:
    """``"1 sample"``, ``"3 samples"``."""
    return f"{count} sample{'' if count == 1 else 's'}"
