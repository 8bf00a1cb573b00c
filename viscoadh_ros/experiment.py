"""A recorded experiment (inputs + measured force) and the model run over it.

Used by ``viscoadh replay`` and ``viscoadh fit``: both read the same inputs from a bag and run
the same event loop, which is the node's own: a ``ContactSimulator.step`` at every input
stamp, a ``ContactSimulator.advance`` (hold the last control) at every measured-force stamp in
between. Replaying the node's own log therefore reproduces its published forces.

Inputs (the control): ``viscoadh_msgs/msg/IndentationCommand`` (DEPTH or FORCE mode),
``std_msgs/msg/Float64`` (depth, m), or the ``z`` of ``geometry_msgs/msg/PointStamped`` /
``PoseStamped`` (depth, m, > 0 presses in). Measured force: ``geometry_msgs/msg/WrenchStamped``
(``wrench.force.z``, N) or ``std_msgs/msg/Float64`` (N), taken as the model's sign
(> 0 compressive, pushing the indenter out; this is what the node publishes); ``flip_force``
negates it for load cells that read tension positive. Times: ``header.stamp`` when the message
has one (a zero stamp means "on receipt"), else the log time. Events of equal time run in the
order they were recorded: a node log holds a hold-timer state stamped at a command's stamp
before that command (the timer ran first) and the command's answer after it.
"""

from __future__ import annotations

import math
import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.io import cdr
from viscoadh_ros.io.bag import Bag

if TYPE_CHECKING:
    from viscoadh_ros.core.config import ContactConfig, SceneConfig
    from viscoadh_ros.core.simulator import StepOutput

COMMAND = "viscoadh_msgs/msg/IndentationCommand"
FLOAT64 = "std_msgs/msg/Float64"
POINT = "geometry_msgs/msg/PointStamped"
POSE = "geometry_msgs/msg/PoseStamped"
WRENCH = "geometry_msgs/msg/WrenchStamped"
INPUT_TYPES = (COMMAND, FLOAT64, POINT, POSE)
FORCE_TYPES = (WRENCH, FLOAT64)

DEPTH, FORCE = 0, 1  # input modes, equal to IndentationCommand.DEPTH / FORCE


@dataclass(frozen=True)
class Experiment:
    """Inputs and measured force of one contact on one time base.

    Times are integer ns on the recording's clock; ``time(ns)`` gives seconds since ``t0_ns``
    (the first input), which is the simulation time.
    """

    t0_ns: int
    input_ns: NDArray[np.int64]  # (n,) stamps of the inputs, non-decreasing
    input_order: NDArray[np.int64]  # (n,) positions of the inputs in the recording
    input_mode: NDArray[np.uint8]  # (n,) DEPTH or FORCE
    input_value: NDArray[np.float64]  # (n,) depth, m, or force, N
    measured_ns: NDArray[np.int64]  # (m,) stamps of the measured force (m may be 0)
    measured_force: NDArray[np.float64]  # (m,) N, > 0 compressive
    measured_order: NDArray[np.int64]  # (m,) positions of the force samples in the recording
    input_topic: str
    force_topic: str | None

    def time(self, ns: NDArray[np.int64]) -> NDArray[np.float64]:
        """Seconds since the first input."""
        return (np.asarray(ns, dtype=np.int64) - self.t0_ns) * 1e-9

    @property
    def duration(self) -> float:
        """Span of the record (inputs and measured force), s."""
        last = (
            self.input_ns[-1] if self.measured_ns.size == 0 else max(self.input_ns[-1], self.measured_ns[-1])
        )
        return (int(last) - self.t0_ns) * 1e-9


#: The fields each type contributes: the input's value (and mode), or the measured force.
_VALUE_FIELDS = {
    COMMAND: ("mode", "depth", "force"),
    FLOAT64: ("data",),
    POINT: ("point.z",),
    POSE: ("pose.position.z",),
    WRENCH: ("wrench.force.z",),
}


def _field(msg: Any, path: str) -> Any:
    for name in path.split("."):
        msg = getattr(msg, name)
    return msg


def _read_topic(bag: Bag, topic: str) -> tuple[NDArray[np.int64], NDArray[np.int64], dict[str, NDArray]]:
    """``(stamp_ns, order, columns)`` of ``topic``: the time of each message (header stamp, or
    the log time for a zero stamp or no header), its position in the recording, and the
    :data:`_VALUE_FIELDS` of its type as arrays. Fixed-layout CDR is read in bulk; anything
    else message by message through rclpy."""
    type_name = bag.topics[topic]
    log_ns, order, payloads = bag.raw(topic)
    columns = cdr.decode(type_name, payloads)
    if columns is None:
        messages = list(bag.messages([topic]))
        log_ns = np.array([m.log_time_ns for m in messages], dtype=np.int64)
        order = np.array([m.order for m in messages], dtype=np.int64)
        columns = {
            path: np.array([_field(m.msg, path) for m in messages]) for path in _VALUE_FIELDS[type_name]
        }
        if messages and hasattr(messages[0].msg, "header"):
            columns["stamp_ns"] = np.array(
                [m.msg.header.stamp.sec * 1_000_000_000 + m.msg.header.stamp.nanosec for m in messages],
                dtype=np.int64,
            )
    stamp_ns = columns.get("stamp_ns")
    # A zero stamp means "on receipt": the log time.
    stamps = log_ns if stamp_ns is None else np.where(stamp_ns != 0, stamp_ns, log_ns)
    return stamps, order, columns


def _inputs_of(topic: str, type_name: str, columns: dict[str, NDArray]) -> tuple[NDArray, NDArray]:
    """``(mode, value)`` of every input message: DEPTH/FORCE and the depth (m) or force (N)."""
    if type_name == COMMAND:
        mode = columns["mode"].astype(np.uint8)
        bad = np.flatnonzero((mode != DEPTH) & (mode != FORCE))
        if bad.size:
            raise InputError(f"{topic}: IndentationCommand with unknown mode {mode[bad[0]]}")
        return mode, np.where(mode == DEPTH, columns["depth"], columns["force"]).astype(np.float64)
    (path,) = _VALUE_FIELDS[type_name]
    value = columns[path].astype(np.float64)
    return np.full(value.size, DEPTH, dtype=np.uint8), value


def _pick(
    bag: Bag, given: str | None, default: str | None, types: tuple[str, ...], what: str, flag: str
) -> str | None:
    """The topic named by the user, else ``default`` if recorded, else the only one of ``types``."""
    if given:
        topic = bag.resolve(given)
    elif default and any(t == default or t.endswith("/" + default.strip("/")) for t in bag.topics):
        topic = bag.resolve(default)
    else:
        candidates = bag.topics_of_type(*types)
        if FLOAT64 in types and len(types) > 1:
            # A bare Float64 could be depth or force: never guess it.
            candidates = [t for t in candidates if bag.topics[t] != FLOAT64]
        if len(candidates) != 1:
            if not candidates:
                return None
            raise InputError(
                f"several {what} topics in {str(bag.path)!r} ({candidates}); choose one with {flag}"
            )
        topic = candidates[0]
    if bag.topics[topic] not in types:
        raise InputError(
            f"{what} topic {topic!r} has type {bag.topics[topic]!r}; expected one of {list(types)}"
        )
    return topic


def load_experiment(
    bag: Bag,
    *,
    input_topic: str | None = None,
    force_topic: str | None = None,
    contact: str | None = None,
    flip_force: bool = False,
) -> Experiment:
    """Read the inputs and the measured force of one contact from ``bag``.

    Without explicit topics: ``<contact>/indentation`` and ``<contact>/wrench`` when ``contact``
    is given and recorded, else the only input topic (IndentationCommand, PointStamped,
    PoseStamped) and the only WrenchStamped topic. A Float64 topic is used only when named.
    Raises InputError naming what is missing, ambiguous or of the wrong type.
    """
    inputs = _pick(
        bag,
        input_topic,
        f"{contact}/indentation" if contact else None,
        INPUT_TYPES,
        "input (depth)",
        "--depth-topic",
    )
    if inputs is None:
        raise InputError(
            f"no input topic in {str(bag.path)!r}: record IndentationCommand, PointStamped or "
            f"PoseStamped, or name a Float64 depth with --depth-topic (topics: {bag.topics})"
        )
    forces = _pick(
        bag, force_topic, f"{contact}/wrench" if contact else None, FORCE_TYPES, "force", "--force-topic"
    )
    if forces == inputs:
        raise InputError(f"the input and the force topic are both {inputs!r}")
    stamps, order, columns = _read_topic(bag, inputs)
    if stamps.size == 0:
        raise InputError(f"input topic {inputs!r} has no messages")
    mode, value = _inputs_of(inputs, bag.topics[inputs], columns)
    # By stamp; at equal stamps in recording order (see the module docstring).
    by_time = np.lexsort((order, stamps))
    input_ns, input_order, mode, value = stamps[by_time], order[by_time], mode[by_time], value[by_time]
    if not np.all(np.isfinite(value)):
        raise InputError(f"input topic {inputs!r} holds non-finite values")
    if forces:
        measured_ns, measured_order, columns = _read_topic(bag, forces)
        (path,) = _VALUE_FIELDS[bag.topics[forces]]
        force = columns[path].astype(np.float64) * (-1.0 if flip_force else 1.0)
        by_time = np.lexsort((measured_order, measured_ns))
        measured_ns, measured_order, force = measured_ns[by_time], measured_order[by_time], force[by_time]
    else:
        measured_ns = measured_order = np.empty(0, dtype=np.int64)
        force = np.empty(0)
    # Measured samples before the first input have no model to compare with.
    keep = measured_ns >= input_ns[0]
    if forces and not np.any(keep):
        raise InputError(
            f"empty time range: force topic {forces!r} ends before input topic {inputs!r} starts"
        )
    finite = np.isfinite(force[keep])
    if not np.all(finite):
        raise InputError(f"force topic {forces!r} holds non-finite values")
    return Experiment(
        t0_ns=int(input_ns[0]),
        input_ns=input_ns,
        input_order=input_order,
        input_mode=mode,
        input_value=value,
        measured_ns=measured_ns[keep],
        measured_force=force[keep],
        measured_order=measured_order[keep],
        input_topic=inputs,
        force_topic=forces,
    )


def choose_contact(scene: SceneConfig, contact: str | None, input_topic: str | None = None) -> ContactConfig:
    """The contact of ``scene`` to run: the one named, the only one, or the one whose id is the
    namespace of ``input_topic`` (``/finger/indentation`` -> ``finger``)."""
    ids = [c.id for c in scene.contacts]
    if contact is None and len(ids) == 1:
        contact = ids[0]
    if contact is None and input_topic:
        parts = input_topic.strip("/").split("/")
        contact = next((p for p in reversed(parts[:-1]) if p in ids), None)
    if contact is None:
        raise InputError(f"the scene has contacts {ids}; choose one with --contact")
    if contact not in ids:
        raise InputError(f"contact {contact!r} is not in the scene (contacts: {ids})")
    return scene.contact(contact)


@dataclass(frozen=True)
class ModelRun:
    """The model over an experiment: outputs at the inputs, force at the measured stamps."""

    input_columns: dict[str, NDArray]  # StepOutput field -> (n,) one value per input
    model_force: NDArray[np.float64]  # (m,) N, at Experiment.measured_ns
    wall_time: float  # s spent simulating
    model: str  # ContactSimulator.model: "closed_form" or "time_stepped"

    @property
    def input_outputs(self) -> list[StepOutput]:
        """One StepOutput per input (built from `input_columns`)."""
        from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, Phase, StepOutput

        columns = [self.input_columns[name].tolist() for name in STEP_OUTPUT_FIELDS]
        phase = STEP_OUTPUT_FIELDS.index("phase")
        columns[phase] = [Phase(p) for p in columns[phase]]
        return [StepOutput(*values) for values in zip(*columns, strict=True)]


def run_model(
    contact: ContactConfig,
    experiment: Experiment,
    *,
    progress: Callable[[int], Any] | None = None,
) -> ModelRun:
    """Run ``contact``'s model over ``experiment`` from a fresh state (the node's event loop).

    Every event under depth control (a depth input, or a measured stamp while a depth is
    held: `ContactSimulator.advance` then steps to that time holding the depth) runs in one
    `ContactSimulator.step_depths` call per stretch between force inputs; force inputs and
    the stamps they hold run event by event. ``progress(k)`` is called with the number of
    events done since the last call.
    """
    from viscoadh_ros.core.simulator import (
        STEP_OUTPUT_FIELDS,
        ContactSimulator,  # numba: loaded only to simulate
    )

    n, m = experiment.input_ns.size, experiment.measured_ns.size
    stamps = np.concatenate([experiment.input_ns, experiment.measured_ns])
    is_input = np.concatenate([np.ones(n, np.bool_), np.zeros(m, np.bool_)])
    index = np.concatenate([np.arange(n), np.arange(m)])
    # By stamp; at equal stamps in recording order (see the module docstring).
    order = np.lexsort((np.concatenate([experiment.input_order, experiment.measured_order]), stamps))
    times, is_input, index = experiment.time(stamps)[order], is_input[order], index[order]
    # The control each event runs under: an input's own, a measured stamp the last input's
    # (depth 0 before the first input: a fresh simulator holds its depth).
    last_input = np.maximum.accumulate(np.where(is_input, np.arange(order.size), -1))
    seen = last_input >= 0
    held_mode = np.full(order.size, DEPTH, dtype=np.uint8)
    held_mode[seen] = experiment.input_mode[index[last_input[seen]]]
    held_value = np.zeros(order.size)
    held_value[seen] = experiment.input_value[index[last_input[seen]]]
    sim = ContactSimulator(contact)
    columns = {name: np.empty(n, dtype=dtype) for name, dtype in _column_dtypes(STEP_OUTPUT_FIELDS).items()}
    model_force = np.empty(m)
    started = wallclock.perf_counter()
    # Stretches of consecutive events of one control mode.
    bounds = np.flatnonzero(np.diff(held_mode.astype(np.int8))) + 1
    for lo, hi in zip(np.concatenate(([0], bounds)), np.concatenate((bounds, [order.size])), strict=True):
        if held_mode[lo] == DEPTH:
            _depth_stretch(
                sim, times[lo:hi], is_input[lo:hi], index[lo:hi], held_value[lo:hi], columns, model_force
            )
        else:
            for k in range(lo, hi):
                t, i = max(float(times[k]), sim.time), int(index[k])
                if is_input[k]:
                    output = sim.step(t, force=float(experiment.input_value[i]))
                    for name in STEP_OUTPUT_FIELDS:
                        columns[name][i] = getattr(output, name)
                else:
                    model_force[i] = (sim.advance(t) if t > sim.time else sim.output).force
        if progress is not None:
            progress(int(hi - lo))
    return ModelRun(columns, model_force, wallclock.perf_counter() - started, sim.model)


def _column_dtypes(names: tuple[str, ...]) -> dict[str, type]:
    special = {"phase": np.uint8, "scale_separation_ok": np.bool_, "unstable": np.bool_}
    return {name: special.get(name, np.float64) for name in names}


def _depth_stretch(
    sim: Any,
    times: NDArray[np.float64],
    is_input: NDArray[np.bool_],
    index: NDArray[np.int64],
    depth: NDArray[np.float64],
    columns: dict[str, NDArray],
    model_force: NDArray[np.float64],
) -> None:
    """Run events under depth control in one `step_depths` call: every input steps; a
    measured stamp steps to its time holding the depth when time has passed (`advance`),
    else reads the last output. Writes the inputs' columns and the measured forces."""
    before = sim.output.force
    times = np.maximum(times, sim.time)
    previous = np.concatenate(([sim.time], times[:-1]))
    steps = is_input | (times > previous)
    result = sim.step_depths(times[steps], depth[steps])
    # Each event's force: its own step's, or the last step's before it.
    last_step = np.maximum.accumulate(np.where(steps, np.cumsum(steps) - 1, -1))
    force = np.where(last_step >= 0, result["force"][np.maximum(last_step, 0)], before)
    measured = ~is_input
    model_force[index[measured]] = force[measured]
    inputs = index[is_input]
    input_rows = (np.cumsum(steps) - 1)[is_input]
    for name, values in result.items():
        columns[name][inputs] = values[input_rows]


@dataclass(frozen=True)
class Comparison:
    """Model vs measured force (N) and replay speed."""

    samples: int
    rmse: float
    max_error: float
    measured_pull_off: float | None  # most tensile measured force, N (None: never < 0)
    model_pull_off: float | None
    speed: float  # record duration / wall time (multiples of real time)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary with units in the keys."""
        return {
            "samples": self.samples,
            "rmse_N": self.rmse,
            "max_error_N": self.max_error,
            "measured_pull_off_force_N": self.measured_pull_off,
            "model_pull_off_force_N": self.model_pull_off,
            "replay_speed_x_real_time": self.speed,
        }


def _pull_off(force: NDArray[np.float64]) -> float | None:
    low = float(np.min(force)) if force.size else 0.0
    return low if low < 0.0 else None


def compare(experiment: Experiment, run: ModelRun) -> Comparison:
    """Errors of ``run`` against ``experiment``'s measured force."""
    if experiment.measured_force.size == 0:
        raise InputError("no measured force to compare with")
    error = run.model_force - experiment.measured_force
    return Comparison(
        samples=int(error.size),
        rmse=float(np.sqrt(np.mean(error**2))),
        max_error=float(np.max(np.abs(error))),
        measured_pull_off=_pull_off(experiment.measured_force),
        model_pull_off=_pull_off(run.model_force),
        speed=experiment.duration / run.wall_time if run.wall_time > 0 else math.inf,
    )
