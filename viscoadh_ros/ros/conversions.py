"""Core results <-> ROS messages: the one place where the two meet.

Sign convention of the wrench (documented in docs/ros_interface.md): the force on the indenter
along +z of the contact frame, whose z axis points from the body out through the indenter. A
compressive contact force (``force > 0``) pushes the indenter out, so ``wrench.force.z = force``;
an adhesive pull (``force < 0``) points into the body. The model is axisymmetric and
frictionless: the other force components and the torque are zero.
"""

from __future__ import annotations

import array
import math
from typing import TYPE_CHECKING, Any

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import WrenchStamped
from viscoadh_msgs.msg import ContactState, IndentationCommand
from viscoadh_msgs.srv import SimulateHistory

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.io import cdr

if TYPE_CHECKING:
    from viscoadh_ros.core.history import HistoryResult
    from viscoadh_ros.core.simulator import StepOutput

#: ``ContactSimulator.model`` names -> ``ContactState.model`` codes.
MODEL_CODES: dict[str, int] = {
    "closed_form": ContactState.MODEL_CLOSED_FORM,
    "time_stepped": ContactState.MODEL_TIME_STEPPED,
}


def stamp_to_ns(stamp: Time) -> int:
    """A ``builtin_interfaces/Time`` as integer nanoseconds."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def ns_to_stamp(ns: int) -> Time:
    """Integer nanoseconds (>= 0) as a ``builtin_interfaces/Time``."""
    sec, nanosec = divmod(ns, 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def command_control(msg: IndentationCommand) -> dict[str, float]:
    """The keyword of ``ContactSimulator.step`` for a command: ``{"depth": d}`` or ``{"force": f}``.

    Raises InputError for an unknown mode or a non-finite value of the mode's field.
    """
    return control_of(msg.mode, msg.depth, msg.force)


def control_of(mode: int, depth: float, force: float) -> dict[str, float]:
    """:func:`command_control` of a command's ``mode``, ``depth`` and ``force`` fields."""
    if mode == IndentationCommand.DEPTH:
        name, value = "depth", depth
    elif mode == IndentationCommand.FORCE:
        name, value = "force", force
    else:
        raise InputError(
            f"mode must be DEPTH ({IndentationCommand.DEPTH}) or FORCE "
            f"({IndentationCommand.FORCE}) (got {mode})"
        )
    if not math.isfinite(value):
        raise InputError(f"{name} must be finite (got {value})")
    return {name: float(value)}


def describe_command(msg: IndentationCommand) -> str:
    """A command in a few words for a rejection reason: ``depth 1e+10 m``, ``force nan N``."""
    return describe(msg.mode, msg.depth, msg.force)


def describe(mode: int, depth: float, force: float) -> str:
    """:func:`describe_command` of a command's ``mode``, ``depth`` and ``force`` fields."""
    if mode == IndentationCommand.DEPTH:
        return f"depth {depth:g} m"
    if mode == IndentationCommand.FORCE:
        return f"force {force:g} N"
    return f"mode {mode}"


def contact_state(
    output: StepOutput,
    *,
    stamp_ns: int,
    frame_id: str,
    model: str,
    commands_received: int,
    commands_rejected: int,
) -> ContactState:
    """The ContactState message of one simulator output, stamped ``stamp_ns`` (node clock)."""
    msg = ContactState()
    msg.header.stamp = ns_to_stamp(stamp_ns)
    msg.header.frame_id = frame_id
    msg.depth = float(output.depth)
    msg.force = float(output.force)
    msg.contact_radius = float(output.contact_radius)
    # Phase is an IntEnum whose values equal the message constants (tested).
    msg.phase = int(output.phase)
    msg.edge_speed = float(output.edge_speed)
    msg.effective_work_of_adhesion = float(output.effective_work_of_adhesion)
    msg.energy_input = float(output.energy_input)
    msg.energy_dissipated = float(output.energy_dissipated)
    msg.scale_separation_ok = bool(output.scale_separation_ok)
    msg.unstable = bool(output.unstable)
    msg.model = MODEL_CODES[model]
    msg.commands_received = commands_received
    msg.commands_rejected = commands_rejected
    return msg


def wrench(output: StepOutput, *, stamp_ns: int, frame_id: str) -> WrenchStamped:
    """The contact force on the indenter as a WrenchStamped (``force.z = force``, see above)."""
    msg = WrenchStamped()
    msg.header.stamp = ns_to_stamp(stamp_ns)
    msg.header.frame_id = frame_id
    msg.wrench.force.z = float(output.force)
    return msg


#: The simulator outputs a ContactState carries, in message order (the model code and the
#: command counters follow them); replay writes its columns in the same order.
STATE_OUTPUT_FIELDS = (
    "depth",
    "force",
    "contact_radius",
    "phase",
    "edge_speed",
    "effective_work_of_adhesion",
    "energy_input",
    "energy_dissipated",
    "scale_separation_ok",
    "unstable",
)


class LivePayloads:
    """The live path's ContactState and WrenchStamped for one ``frame_id`` as CDR payloads,
    equal to :func:`contact_state` and :func:`wrench` serialised.

    Per command the node publishes and logs these bytes (``Publisher.publish`` takes a payload
    as is): packing the values takes ~2 us, where building the message objects (17 fields
    through rosidl's property setters, nested headers) took ~17 us and publishing an object
    converts it to C and serialises it again.
    """

    _STATE_FIELDS = (*STATE_OUTPUT_FIELDS, "model", "commands_received", "commands_rejected")

    def __init__(self, frame_id: str) -> None:
        self.frame_id = frame_id
        self._state = cdr.Packer(cdr.CONTACT_STATE, frame_id)
        self._wrench = cdr.Packer(cdr.WRENCH, frame_id)
        # state() passes the values positionally: a change of the layout must not shift them.
        if self._state.fields != self._STATE_FIELDS:
            raise RuntimeError(f"ContactState layout changed: {self._state.fields}")

    def state(
        self,
        output: StepOutput,
        *,
        stamp_ns: int,
        model: str,
        commands_received: int,
        commands_rejected: int,
    ) -> bytes:
        """:func:`contact_state` of the same arguments, serialised."""
        return self._state.pack(
            stamp_ns,
            output.depth,
            output.force,
            output.contact_radius,
            output.phase,
            output.edge_speed,
            output.effective_work_of_adhesion,
            output.energy_input,
            output.energy_dissipated,
            output.scale_separation_ok,
            output.unstable,
            MODEL_CODES[model],
            commands_received,
            commands_rejected,
        )

    def wrench(self, output: StepOutput, *, stamp_ns: int) -> bytes:
        """:func:`wrench` of the same arguments, serialised (force and torque x, y, z)."""
        return self._wrench.pack(stamp_ns, 0.0, 0.0, output.force, 0.0, 0.0, 0.0)


def history_request(request: SimulateHistory.Request) -> dict[str, Any]:
    """Keyword arguments of ``simulate_history`` for a request: ``time`` and ``depth``/``force``.

    Only the mode is checked here; the core validates the arrays (finite, strictly increasing
    time, matching lengths) and names the offending one.
    """
    time = np.asarray(request.time, dtype=np.float64)
    if request.mode == SimulateHistory.Request.DEPTH:
        return {"time": time, "depth": np.asarray(request.depth, dtype=np.float64)}
    if request.mode == SimulateHistory.Request.FORCE:
        return {"time": time, "force": np.asarray(request.force, dtype=np.float64)}
    raise InputError(
        f"mode must be DEPTH ({SimulateHistory.Request.DEPTH}) or FORCE "
        f"({SimulateHistory.Request.FORCE}) (got {request.mode})"
    )


def _sequence(typecode: str, values: Any) -> array.array:
    """A message sequence field from an array: one buffer copy, no per-element Python loop."""
    dtype = np.float64 if typecode == "d" else np.uint8
    sequence = array.array(typecode)
    sequence.frombytes(np.ascontiguousarray(values, dtype=dtype).tobytes())
    return sequence


def history_response(result: HistoryResult, response: SimulateHistory.Response) -> SimulateHistory.Response:
    """Fill ``response`` from a history result (one value per request sample)."""
    response.depth = _sequence("d", result.depth)
    response.force = _sequence("d", result.force)
    response.contact_radius = _sequence("d", result.contact_radius)
    response.phase = _sequence("B", result.phase)
    response.success = True
    samples = len(response.force)
    response.message = f"{samples} sample{'' if samples == 1 else 's'}"
    return response
