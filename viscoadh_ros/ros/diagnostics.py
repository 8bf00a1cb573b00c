"""/diagnostics for the node: per contact step time, command counters, model, validity.

``diagnostic_updater`` is not on PyPI, so the node builds its ``DiagnosticArray`` here: one
``DiagnosticStatus`` per contact, named ``<node's fully qualified name>: <id>`` (two nodes in
different namespaces stay apart on the one ``/diagnostics`` topic), published at about 1 Hz.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from viscoadh_ros.core.simulator import ModelValidity
from viscoadh_ros.ros.conversions import ns_to_stamp


@dataclass
class StepTimer:
    """Wall time of the simulator steps over the current diagnostics window, s."""

    count: int = 0
    total: float = 0.0
    maximum: float = 0.0

    def add(self, seconds: float) -> None:
        """Account one step that took ``seconds``."""
        self.count += 1
        self.total += seconds
        self.maximum = max(self.maximum, seconds)

    def take(self) -> tuple[int, float, float]:
        """(steps, mean s, max s) of the window, and start a new window."""
        window = (
            self.count,
            self.total / self.count if self.count else 0.0,
            self.maximum,
        )
        self.count, self.total, self.maximum = 0, 0.0, 0.0
        return window


@dataclass
class ContactCounters:
    """What one contact has seen since start; updated under the contact's lock."""

    commands_received: int = 0
    commands_rejected: int = 0
    requests_rejected: int = 0
    #: Publishers on C/indentation whose QoS does not match the node's (never heard).
    incompatible_publishers: int = 0
    rejections_in_window: int = 0
    last_rejection: str = ""
    steps: StepTimer = field(default_factory=StepTimer)

    def reject(self, reason: str, *, command: bool) -> None:
        """Count one rejected command (``command=True``) or service request."""
        if command:
            self.commands_rejected += 1
        else:
            self.requests_rejected += 1
        self.rejections_in_window += 1
        self.last_rejection = reason


def contact_status(
    contact_id: str,
    counters: ContactCounters,
    *,
    node_name: str,
    model: str,
    validity: ModelValidity,
    in_contact: bool,
) -> DiagnosticStatus:
    """The status of one contact; takes (and resets) the step-time and rejection windows.

    Level WARN when the current state lies outside the model's validity (flank slope at the
    contact edge beyond the small-slope limit, no scale separation of the energy criterion, or
    a contact the grid does not resolve: `ContactSimulator.model_validity`) or something was
    rejected since the last report, else OK.
    """
    steps, mean, maximum = counters.steps.take()
    problems = []
    if not validity.ok:
        problems.append(f"outside the model's validity: {validity.message}")
    if counters.rejections_in_window:
        problems.append(f"{counters.rejections_in_window} rejected (last: {counters.last_rejection})")
    counters.rejections_in_window = 0
    values = {
        "model": model,
        "in_contact": str(in_contact),
        "scale_separation_ok": str(validity.scale_separation_ok),
        "small_slope_ok": str(validity.small_slope_ok),
        "resolution_ok": str(validity.resolution_ok),
        "edge_slope": f"{validity.edge_slope:.3g}",
        "steps_in_window": str(steps),
        "step_time_mean_us": f"{mean * 1e6:.1f}",
        "step_time_max_us": f"{maximum * 1e6:.1f}",
        "commands_received": str(counters.commands_received),
        "commands_rejected": str(counters.commands_rejected),
        "requests_rejected": str(counters.requests_rejected),
        "incompatible_publishers": str(counters.incompatible_publishers),
        "last_rejection": counters.last_rejection,
    }
    return DiagnosticStatus(
        level=DiagnosticStatus.WARN if problems else DiagnosticStatus.OK,
        name=f"{node_name}: {contact_id}",
        hardware_id=contact_id,
        message="; ".join(problems) if problems else "OK",
        values=[KeyValue(key=k, value=v) for k, v in values.items()],
    )


def diagnostic_array(statuses: list[DiagnosticStatus], *, stamp_ns: int) -> DiagnosticArray:
    """The /diagnostics message holding ``statuses``, stamped on the node clock."""
    msg = DiagnosticArray(status=statuses)
    msg.header.stamp = ns_to_stamp(stamp_ns)
    return msg


def log_status(
    *, node_name: str, written: int, dropped: int, error: BaseException | None
) -> DiagnosticStatus:
    """The status of the MCAP log (``<node name>: log``): ERROR when the writer stopped, WARN once
    a message was dropped (the log is then incomplete for good), else OK."""
    if error is not None:
        level, message = DiagnosticStatus.ERROR, f"log writer stopped: {error}"
    elif dropped:
        level, message = DiagnosticStatus.WARN, f"{dropped} messages dropped (writer queue full)"
    else:
        level, message = DiagnosticStatus.OK, "OK"
    values = {"messages_written": str(written), "messages_dropped": str(dropped)}
    return DiagnosticStatus(
        level=level,
        name=f"{node_name}: log",
        hardware_id="mcap",
        message=message,
        values=[KeyValue(key=k, value=v) for k, v in values.items()],
    )


def hand_status(
    *, node_name: str, received: int, rejected: int, rejected_in_window: int, last_rejection: str
) -> DiagnosticStatus:
    """The status of the hand topics (``<node name>: hand``): WARN when a hand command was
    rejected (or a publisher's QoS could not match) since the last status, else OK."""
    values = {
        "commands_received": str(received),
        "commands_rejected": str(rejected),
        "last_rejection": last_rejection,
    }
    return DiagnosticStatus(
        level=DiagnosticStatus.WARN if rejected_in_window else DiagnosticStatus.OK,
        name=f"{node_name}: hand",
        hardware_id="hand",
        message=f"{rejected_in_window} hand command(s) rejected: {last_rejection}"
        if rejected_in_window
        else "OK",
        values=[KeyValue(key=k, value=v) for k, v in values.items()],
    )
