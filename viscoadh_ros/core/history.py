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
#: Rows per output step across the two steps around the largest pull, looked at again.
PULL_OFF_REFINE = 16


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
    the depth where it was reached, m; time_to_detach: from the start of the retraction to
    full detachment, s (the time the retraction ran if it did not detach); detached: whether
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
    modulus); the run stops after PULL_OFF_RANGES such ranges and says so.
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
    best_force, best_depth = min(out.force, 0.0), out.depth
    best = 0
    detached = False
    try:
        for i in range(1, PULL_OFF_STEPS * PULL_OFF_RANGES + 1):
            step = simulator.step(t0 + i * dt, depth=d0 - speed * i * dt)
            if step.force < best_force:
                best_force, best_depth, best = step.force, step.depth, i
            if not simulator.in_contact:
                detached = True
                break
        elapsed = simulator.time - t0
        if best > 0:
            # The largest pull lies within a step of the best sample; at a fast retraction it
            # is the last row before the jump, a cusp a coarse row steps past (0.9 % of the
            # pull-off at 1 d_c, 10 mm/s). The same path again to the row before it, then
            # PULL_OFF_REFINE rows per step across the two steps around it.
            simulator.restore(start)
            for i in range(1, best):
                simulator.step(t0 + i * dt, depth=d0 - speed * i * dt)
            for k in range((best - 1) * PULL_OFF_REFINE + 1, (best + 1) * PULL_OFF_REFINE + 1):
                t = k * dt / PULL_OFF_REFINE
                step = simulator.step(t0 + t, depth=d0 - speed * t)
                if step.force < best_force:
                    best_force, best_depth = step.force, step.depth
                if not simulator.in_contact:
                    break
    finally:
        simulator.restore(start)
    if detached:
        message = f"detached after {elapsed:.6g} s of retraction at {speed:g} m/s"
    else:
        message = (
            f"still in contact after retracting {speed * elapsed:.6g} m "
            f"({PULL_OFF_RANGES} characteristic depth ranges); the values are up to there"
        )
    return PullOffPrediction(best_force, best_depth, elapsed, detached, message)


def _samples(count: int) -> str:
    """``"1 sample"``, ``"3 samples"``."""
    return f"{count} sample{'' if count == 1 else 's'}"
