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
has one (a zero stamp means "on receipt"), else the log time.

Two orders of events:

- A **node log** (IndentationCommand inputs in a file written by viscoadh's recorder, which
  stores the software version, or in any recording that holds the contact's ``C/events``)
  runs in recording order, which is the order the node
  handled things in: it logs each command on receipt, before its answer, and its hold-timer
  states as it publishes them. A command stamped before a state the node already published
  for the contact since its history began (a hold tick's) runs at that state's time, as the node
  applied (and stamped) it. The node's verdicts are applied as the node made them: a
  command refused by the node (a ``COMMAND_REJECTED`` ``ContactEvent`` on ``C/events`` naming
  its index among the commands received; or, in logs without events, what the node always
  refuses: an unknown mode, a non-finite value, a stamp older than the last accepted command's)
  is skipped; a ``RESET`` or ``PARAMETERS`` event restarts the contact at its place in the
  log (fresh state, at rest until the next accepted command; PARAMETERS with the contact
  configuration it carries), and the next accepted command starts a new time base, as in the
  node; a ``PARAMETERS_REFUSED`` event (a runtime change the node refused) changes nothing.
- Any other recording runs by stamp; at equal stamps in recording order.

A record must hold the contact's history from its start: when the contact's logged
ContactStates (``C/state``) count commands the node received before the record's first one
(a later file of a rotated log, a recording started late), and no RESET or PARAMETERS event
comes before that command, :func:`load_experiment` refuses it (a fresh contact there is not
the node's). After such a restart the record replays exactly; the events' command indexes and
the counters then count from the node's start.
"""

from __future__ import annotations

import dataclasses
import math
import re
import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
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
EVENT = "viscoadh_msgs/msg/ContactEvent"
INPUT_TYPES = (COMMAND, FLOAT64, POINT, POSE)
FORCE_TYPES = (WRENCH, FLOAT64)

DEPTH, FORCE = 0, 1  # input modes, equal to IndentationCommand.DEPTH / FORCE
COMMAND_REJECTED, RESET, PARAMETERS, PARAMETERS_REFUSED = 1, 2, 3, 4  # ContactEvent.kind


@dataclass(frozen=True)
class Restart:
    """A RESET or PARAMETERS event of a node log: the contact restarts from a fresh state
    (PARAMETERS: with ``contact_yaml``, the scene YAML holding the changed contact)."""

    kind: int  # RESET or PARAMETERS
    ns: int  # the event's stamp (node clock), ns
    order: int  # position in the recording
    contact_yaml: str = ""


@dataclass(frozen=True)
class Experiment:
    """Inputs and measured force of one contact on one time base.

    Times are integer ns on the recording's clock; ``time(ns)`` gives seconds since ``t0_ns``
    (the first input). The inputs are the accepted ones, in the order they run (see the module
    docstring); ``rejected_index`` lists the commands skipped as the node refused them.
    """

    t0_ns: int
    #: (n,) stamps of the accepted inputs, in run order; in a node log the time the node applied
    #: each at (its stamp, or the contact's time when later: see ``_applied_ns``).
    input_ns: NDArray[np.int64]
    input_order: NDArray[np.int64]  # (n,) positions of the inputs in the recording
    input_mode: NDArray[np.uint8]  # (n,) DEPTH or FORCE
    input_value: NDArray[np.float64]  # (n,) depth, m, or force, N
    measured_ns: NDArray[np.int64]  # (m,) stamps of the measured force (m may be 0)
    measured_force: NDArray[np.float64]  # (m,) N, > 0 compressive
    measured_order: NDArray[np.int64]  # (m,) positions of the force samples in the recording
    input_topic: str
    force_topic: str | None
    #: True for a node log: events run in recording order (else by stamp).
    by_arrival: bool = False
    #: (n,) index of each accepted input among all inputs received (0-based).
    input_index: NDArray[np.int64] | None = None
    #: (r,) indexes of the commands skipped as refused by the node, and why.
    rejected_index: NDArray[np.int64] = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    rejected_reason: tuple[str, ...] = ()
    restarts: tuple[Restart, ...] = ()  # RESET / PARAMETERS events, in recording order
    events_topic: str | None = None
    #: Commands the contact had received (accepted and rejected) before the record's first
    #: one, and how many of them the node rejected: a record that starts with a reset of a
    #: contact the node had driven before (the node counts commands since it started).
    commands_before: int = 0
    rejected_before: int = 0

    def select(self, inputs: Any, measured: Any, **changes: Any) -> Experiment:
        """This record with only the inputs ``inputs`` and the measured samples ``measured``
        (masks or index arrays over each), and the fields in ``changes`` replaced."""
        return dataclasses.replace(
            self,
            input_ns=self.input_ns[inputs],
            input_order=self.input_order[inputs],
            input_mode=self.input_mode[inputs],
            input_value=self.input_value[inputs],
            input_index=None if self.input_index is None else self.input_index[inputs],
            measured_ns=self.measured_ns[measured],
            measured_force=self.measured_force[measured],
            measured_order=self.measured_order[measured],
            **changes,
        )

    def time(self, ns: NDArray[np.int64]) -> NDArray[np.float64]:
        """Seconds since the first input."""
        return (np.asarray(ns, dtype=np.int64) - self.t0_ns) * 1e-9

    @property
    def duration(self) -> float:
        """Span of the record (inputs and measured force), s."""
        last = (
            int(self.input_ns.max())
            if self.measured_ns.size == 0
            else max(int(self.input_ns.max()), int(self.measured_ns.max()))
        )
        return (last - self.t0_ns) * 1e-9

    @property
    def counters(self) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """``(commands_received, commands_rejected)`` at each accepted input, as the node's
        ContactState counts them since it started (accepted so far including this one; refused
        so far)."""
        index = self.input_index if self.input_index is not None else np.arange(self.input_ns.size)
        accepted_before = self.commands_before - self.rejected_before
        received = accepted_before + np.arange(1, self.input_ns.size + 1)
        rejected = self.rejected_before + np.searchsorted(np.sort(self.rejected_index), index)
        return received, rejected.astype(np.int64)


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


def _read_topic(
    bag: Bag, topic: str, fields: tuple[str, ...] | None = None
) -> tuple[NDArray[np.int64], NDArray[np.int64], dict[str, NDArray]]:
    """``(stamp_ns, order, columns)`` of ``topic``: the time of each message (header stamp, or
    the log time for a zero stamp or no header), its position in the recording, and the
    ``fields`` (default: the :data:`_VALUE_FIELDS` of its type) as arrays. Fixed-layout CDR
    is read in bulk; anything else message by message through rclpy."""
    type_name = bag.topics[topic]
    fields = _VALUE_FIELDS[type_name] if fields is None else fields
    log_ns, order, rows = bag.rows(topic)
    columns = None if rows is None else cdr.decode(type_name, rows, fields)
    if columns is None:
        messages = list(bag.messages([topic]))
        log_ns = np.array([m.log_time_ns for m in messages], dtype=np.int64)
        order = np.array([m.order for m in messages], dtype=np.int64)
        columns = {path: np.array([_field(m.msg, path) for m in messages]) for path in fields}
        if messages and hasattr(messages[0].msg, "header"):
            columns["stamp_ns"] = np.array(
                [m.msg.header.stamp.sec * 1_000_000_000 + m.msg.header.stamp.nanosec for m in messages],
                dtype=np.int64,
            )
    stamp_ns = columns.get("stamp_ns")
    # A zero stamp means "on receipt": the log time.
    stamps = log_ns if stamp_ns is None else np.where(stamp_ns != 0, stamp_ns, log_ns)
    return stamps, order, columns


def _inputs_of(type_name: str, columns: dict[str, NDArray]) -> tuple[NDArray, NDArray]:
    """``(mode, value)`` of every input message: DEPTH/FORCE (or an IndentationCommand's own,
    possibly unknown, mode) and the depth (m) or force (N)."""
    if type_name == COMMAND:
        mode = columns["mode"].astype(np.uint8)
        return mode, np.where(mode == FORCE, columns["force"], columns["depth"]).astype(np.float64)
    (path,) = _VALUE_FIELDS[type_name]
    value = columns[path].astype(np.float64)
    return np.full(value.size, DEPTH, dtype=np.uint8), value


def _pick(
    bag: Bag, given: str | None, default: str | None, types: tuple[str, ...], what: str, flag: str
) -> str | None:
    """The topic named by the user, else ``default`` (the contact's topic), which must then be
    recorded, else the only one of ``types``; None when there is none of ``types`` (and, for
    the force, none at all)."""
    candidates = bag.topics_of_type(*types)
    if FLOAT64 in types and len(types) > 1:
        # A bare Float64 could be depth or force: never guess it.
        candidates = [t for t in candidates if bag.topics[t] != FLOAT64]
    if given:
        topic = bag.resolve(given)
    elif default:
        # The contact's own topic, or nothing: never another contact's (no silent fallback).
        if not any(t == default or t.endswith("/" + default.strip("/")) for t in bag.topics):
            if not candidates and what == "force":
                return None
            raise InputError(
                f"no topic {default!r} in {str(bag.path)!r} ({what} topics found: {candidates}); "
                f"check --contact or name the topic with {flag}"
            )
        topic = bag.resolve(default)
    else:
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
    is given (an error naming the recorded topics when absent: never another contact's), else
    the only input topic (IndentationCommand, PointStamped, PoseStamped) and the only
    WrenchStamped topic. A Float64 topic is used only when named. In a node log, the events of
    the input's contact (``<namespace>/events`` beside ``<namespace>/indentation``) are read
    too (see the module docstring). Raises InputError naming what is missing, ambiguous, of
    the wrong type or inconsistent.
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
    mode, value = _inputs_of(bag.topics[inputs], columns)
    # A node's log: written by our recorder, or holding the contact's events.
    by_arrival = bag.topics[inputs] == COMMAND and (
        bag.software_version is not None or _events_topic(inputs) in bag.topics
    )
    events_topic, restarts = None, ()
    # What the node had counted before the record (a record that starts mid-history).
    counts = _state_counts(bag, inputs) if bag.topics[inputs] == COMMAND else None
    if by_arrival and counts is not None:
        _refuse_broken_sequence(bag, inputs, order, counts)
    earlier, shown_by = _commands_before(counts, order)
    rejected_before = 0
    if by_arrival:
        _refuse_hand_driven(bag, inputs)
        events_topic, restarts, rejections = _node_events(bag, inputs)
        _refuse_mid_history(bag, inputs, order, earlier, restarts)
        refused = _refused_commands(events_topic, inputs, rejections, stamps, order, columns, earlier)
        keep, index, rejected, reasons = _node_verdicts(stamps, order, mode, value, refused, restarts)
        if not keep.any():
            raise InputError(f"input topic {inputs!r}: the node refused every command ({reasons[0]})")
        if earlier and counts is not None:
            # Of the earlier commands, those the node rejected: the state's count less the
            # rejections recorded before it.
            logged = int(np.count_nonzero(~keep & (order < counts.order[shown_by])))
            rejected_before = min(max(int(counts.rejected[shown_by]) - logged, 0), earlier)
        # Recording order is the order the node handled them in.
        run = np.argsort(order, kind="stable")
        run = run[keep[run]]
        index = index[run]
        # The node applies a command stamped before the contact's last published state at that
        # state's time (and stamps its answer so): run each input at the time the node did.
        stamps = stamps.copy()
        stamps[run] = _applied_ns(bag, inputs, stamps[run], order[run], restarts, counts)
    else:
        _refuse_mid_history(bag, inputs, order, earlier, ())
        bad = np.flatnonzero((mode != DEPTH) & (mode != FORCE))
        if bad.size:
            raise InputError(f"{inputs}: IndentationCommand with unknown mode {mode[bad[0]]}")
        if not np.all(np.isfinite(value)):
            raise InputError(f"input topic {inputs!r} holds non-finite values")
        # By stamp; at equal stamps in recording order (see the module docstring).
        run = np.lexsort((order, stamps))
        index = np.arange(run.size)
        rejected, reasons = np.empty(0, dtype=np.int64), ()
    input_ns, input_order, mode, value = stamps[run], order[run], mode[run], value[run]
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
    if by_arrival:
        keep = measured_order > input_order[0]
    else:
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
        by_arrival=by_arrival,
        input_index=index.astype(np.int64),
        rejected_index=rejected,
        rejected_reason=reasons,
        restarts=restarts,
        events_topic=events_topic,
        commands_before=earlier,
        rejected_before=rejected_before,
    )


def _refuse_hand_driven(bag: Bag, inputs: str) -> None:
    """An InputError when a HandCommand in ``bag`` commands the contact of ``inputs``
    (``<ns>/C/indentation``), by name or as every contact (an empty ``contact_ids``): the node
    stepped it from ``hand/indentation`` too, which replay does not read yet
    (docs/recording_and_replay.md), so a replay from ``inputs`` alone would leave those
    commands out and compare a wrong model silently (an outside tester's log: exit 0, an RMSE
    of 82 uN where the node's own answers give 0)."""
    topics = bag.topics_of_type(cdr.HAND_COMMAND)
    if not topics:
        return
    path = inputs.strip("/").split("/")
    if len(path) < 2:
        return
    contact = path[-2]
    for topic in topics:
        count = sum(cdr.hand_command_steps(payload, contact) for payload in bag.raw(topic)[2])
        if count:
            raise InputError(
                f"contact {contact!r} was also stepped by hand commands ({count} on {topic!r}): replay "
                f"reads a contact's commands from {inputs!r} only and would leave those out "
                "(replaying a hand-driven contact is not supported yet; docs/recording_and_replay.md)"
            )


def _events_topic(inputs: str) -> str:
    """``C/events`` beside ``C/indentation``."""
    return inputs.rsplit("/", 1)[0] + "/events"


def _contact_of(inputs: str) -> str:
    """The contact a node log's input topic belongs to, for messages: ``finger`` of
    ``/finger/indentation`` (the topic itself when it has no namespace)."""
    parts = inputs.strip("/").split("/")
    return parts[-2] if len(parts) > 1 else inputs


@dataclass(frozen=True)
class _StateCounts:
    """The counters of a contact's logged ContactStates (``C/state``): how many commands the
    node had accepted and rejected on ``C/indentation`` since it started, at each state."""

    order: NDArray[np.int64]  # positions of the states in the recording
    received: NDArray[np.int64]  # commands_received (accepted)
    rejected: NDArray[np.int64]  # commands_rejected
    stamp_ns: NDArray[np.int64]  # header stamps as published (the time each state describes)


def _state_counts(bag: Bag, inputs: str) -> _StateCounts | None:
    """The counters of the ContactStates beside ``inputs`` (``C/state``), None when the
    recording holds none."""
    topic = inputs.rsplit("/", 1)[0] + "/state"
    if bag.topics.get(topic) != cdr.CONTACT_STATE:
        return None
    _, order, columns = _read_topic(bag, topic, ("commands_received", "commands_rejected"))
    if order.size == 0:
        return None
    return _StateCounts(
        order.astype(np.int64),
        columns["commands_received"].astype(np.int64),
        columns["commands_rejected"].astype(np.int64),
        columns["stamp_ns"].astype(np.int64),
    )


def _commands_before(counts: _StateCounts | None, order: NDArray[np.int64]) -> tuple[int, int]:
    """``(commands, state)``: how many commands (accepted and rejected) the contact had
    received before the first one the recording holds (``order``: the commands' positions),
    and which state shows it; (0, -1) without states.

    Each state counts every command the node handled up to it; the recording holds those
    recorded before it: the difference is what came before the recording. Our recorder logs
    a command before its answer, so it is the same at every state; another recorder (rosbag2)
    may take a state before the command it answers, so the least over the states is taken."""
    if counts is None:
        return 0, -1
    logged = np.searchsorted(np.sort(order), counts.order)
    ahead = counts.received + counts.rejected - logged
    state = int(np.argmin(ahead))
    return max(int(ahead[state]), 0), state


def _refuse_broken_sequence(bag: Bag, inputs: str, order: NDArray[np.int64], counts: _StateCounts) -> None:
    """An InputError naming the file when the files of a log (several files, written by our
    recorder) do not hold one history of the contact in order: each ContactState counts the
    commands the node received since it started, so the commands counted and not recorded
    before it (`_commands_before`) are the same in every file of one log. More in a later
    file: a file between is missing (or its recorder dropped commands); fewer: a file is
    repeated (a copy), or comes from another run of the node (its counters start again at 1).
    An outside tester's folders (a rotated log with file 7 left out, a copy of file 1, two
    sessions' logs) replayed with exit 0 and wrong forces. A recording by another recorder
    (``ros2 bag``) may take a state before the command it answers, so it is not checked."""
    if len(bag.files) < 2 or bag.software_version is None:
        return
    logged = np.searchsorted(np.sort(order), counts.order)
    ahead = counts.received + counts.rejected - logged
    files = bag.file_of(counts.order)
    contact = _contact_of(inputs)
    last: tuple[int, int] | None = None
    for file in np.unique(files).tolist():
        here = int(ahead[files == file].min())
        if last is not None and here != last[1]:
            name, before = bag.files[file].name, bag.files[last[0]].name
            if here > last[1]:
                what = (
                    f"count {here - last[1]} commands on {inputs!r} that the files before it do not hold: "
                    f"a file between {before} and {name} is missing (or the recorder dropped commands)"
                )
            else:
                what = (
                    f"count {last[1] - here} fewer commands on {inputs!r} than the files before it hold: "
                    f"{name} repeats an earlier file (a copy) or comes from another run of the node "
                    "(whose counters start again at 1)"
                )
            raise InputError(
                f"contact {contact!r}: {str(bag.path)!r} is not one history of the contact: the "
                f"ContactState counters in {name} {what}; replay the files of one run of the node, "
                "all of them, in one folder"
            )
        last = (file, here)


def _refuse_mid_history(
    bag: Bag, inputs: str, order: NDArray[np.int64], earlier: int, restarts: tuple[Restart, ...]
) -> None:
    """An InputError when the record starts in the middle of the contact's history: the node
    had received ``earlier`` commands before the first one recorded, and no RESET or
    PARAMETERS event comes before that command. A replay would start a fresh contact there,
    where the node's was pressed in, creeping or adhering (an outside tester's second file of
    a rotated log: exit 0, an RMSE of 23 mN against the node's own forces). After a restart
    the earlier history no longer matters: such a record replays exactly."""
    if earlier <= 0 or (restarts and restarts[0].order < int(np.min(order))):
        return
    contact = _contact_of(inputs)
    raise InputError(
        f"contact {contact!r}: {str(bag.path)!r} starts in the middle of the contact's history: the "
        f"node had received {earlier} commands on {inputs!r} before the first one recorded here (its "
        "ContactState counters say so) and no reset or parameter change of the contact comes "
        "before that command, so a replay from rest there would not be the node's contact; "
        + _whole_log_hint(bag.path)
    )


def _whole_log_hint(path: Path) -> str:
    """What to replay instead of ``path``, a record that starts mid-history."""
    if path.is_file():
        if (path.parent / "metadata.yaml").is_file():
            return f"replay the whole rosbag2 folder {str(path.parent)!r} instead (this is one of its files)"
        rotated = re.fullmatch(r"(.+)_(\d+)\.mcap", path.name)
        if rotated and int(rotated.group(2)) > 0:
            stem = rotated.group(1)
            return (
                f"replay the whole log instead: put {stem}_0.mcap, {stem}_1.mcap, ... (a rotated log; "
                f"this is file {rotated.group(2)}) in one folder and replay the folder (its files are "
                "read in order)"
            )
    return (
        "replay the whole log instead (the earlier files of a rotated log with this one, in one folder), "
        "or a recording that starts before the contact's first command or with a reset of it (a "
        "recorder that dropped messages leaves commands out too)"
    )


@dataclass(frozen=True)
class _Rejection:
    """A COMMAND_REJECTED event: the command's index since the node started, its stamp."""

    index: int
    stamp_ns: int
    log_ns: int
    reason: str


def _node_events(bag: Bag, inputs: str) -> tuple[str | None, tuple[Restart, ...], list[_Rejection]]:
    """``(events topic, restarts, rejections)`` from the ContactEvents logged beside ``inputs``."""
    topic = _events_topic(inputs)
    if topic not in bag.topics:
        return None, (), []
    if bag.topics[topic] != EVENT:
        raise InputError(f"events topic {topic!r} has type {bag.topics[topic]!r}; expected {EVENT!r}")
    restarts: list[Restart] = []
    rejections: list[_Rejection] = []
    for message in bag.messages([topic]):
        event = message.msg
        if event.kind == COMMAND_REJECTED:
            stamp = event.command_stamp.sec * 1_000_000_000 + event.command_stamp.nanosec
            reason = event.reason or "rejected by the node"
            rejections.append(_Rejection(int(event.command_index), stamp, message.log_time_ns, reason))
        elif event.kind in (RESET, PARAMETERS):
            if event.kind == PARAMETERS and not event.contact_yaml:
                raise InputError(f"{topic}: PARAMETERS event at {message.log_time_ns} ns has no contact_yaml")
            stamp = event.header.stamp.sec * 1_000_000_000 + event.header.stamp.nanosec
            restarts.append(
                Restart(int(event.kind), stamp or message.log_time_ns, message.order, event.contact_yaml)
            )
        elif event.kind != PARAMETERS_REFUSED:  # a refused change changed nothing
            raise InputError(f"{topic}: event of unknown kind {event.kind} at {message.log_time_ns} ns")
    return topic, tuple(sorted(restarts, key=lambda r: r.order)), rejections


def _refused_commands(
    topic: str | None,
    inputs: str,
    rejections: list[_Rejection],
    stamps: NDArray[np.int64],
    order: NDArray[np.int64],
    columns: dict[str, NDArray],
    earlier: int,
) -> dict[int, str]:
    """``{k: reason}``: the commands the events reject, by their index ``k`` among those the
    recording holds (the event's index since the node started, less the ``earlier`` commands
    before the recording); an event that names a command the recording does not hold is an
    error."""
    # Commands in recording order: the node counts them in the order it received them.
    received = np.argsort(order, kind="stable")
    raw_stamp = columns.get("stamp_ns", stamps)[received]
    refused: dict[int, str] = {}
    for rejection in rejections:
        k = rejection.index - earlier
        if not 0 <= k < received.size or int(raw_stamp[k]) != rejection.stamp_ns:
            raise InputError(
                f"{topic}: the event at {rejection.log_ns} ns rejects command {rejection.index} stamped "
                f"{rejection.stamp_ns} ns, which {inputs!r} does not hold (it has {received.size} commands"
                + (f" after {earlier} earlier ones" if earlier else "")
                + "); the log is incomplete (a recorder that dropped messages, or a later file of a "
                "rotated log without the contact's states)"
            )
        refused[k] = rejection.reason
    return refused


def _applied_ns(
    bag: Bag,
    inputs: str,
    stamps: NDArray[np.int64],
    order: NDArray[np.int64],
    restarts: tuple[Restart, ...],
    counts: _StateCounts | None,
) -> NDArray[np.int64]:
    """The time the node applied each accepted command at (``stamps``, ``order``: the accepted
    commands in recording order): its stamp, or the contact's time when that is later, the
    stamp of the last state it published (``C/state``, else ``C/wrench``, beside ``inputs``)
    or of a command it applied, since the last restart before it (ros/node.py
    ``_Contact._applied_ns``). The stamps as they are when the log holds neither topic.
    ``counts``: the states' counters and stamps when `_state_counts` read them already."""
    base = inputs.rsplit("/", 1)[0]
    published = next((t for t in (base + "/state", base + "/wrench") if t in bag.topics), None)
    if published is None:
        return stamps
    if counts is not None and published == base + "/state":
        state_ns, state_order = counts.stamp_ns, counts.order
    else:
        # The header stamps as published (`_read_topic`'s own stamps put the log time for a
        # zero one).
        _, state_order, columns = _read_topic(bag, published, ())
        state_ns = columns.get("stamp_ns", np.zeros(0, np.int64))
    values = np.concatenate([stamps, state_ns])
    orders = np.concatenate([order, state_order])
    is_command = np.arange(values.size) < stamps.size
    by_order = np.argsort(orders, kind="stable")
    values, orders, is_command = values[by_order], orders[by_order], is_command[by_order]
    # A restart (reset, parameter change, clock jump back) forgets the contact's time, and the
    # rest heartbeats before its first command describe no history (the node does not count
    # them: the first command starts one at its own stamp).
    segment = np.searchsorted(np.array([r.order for r in restarts], dtype=np.int64), orders)
    running = np.empty_like(values)
    for seg in np.unique(segment).tolist():
        mine = np.flatnonzero(segment == seg)  # contiguous: sorted by order
        mine_values = values[mine].copy()
        commands = np.flatnonzero(is_command[mine])
        first = int(commands[0]) if commands.size else mine.size
        mine_values[:first] = np.iinfo(np.int64).min
        running[mine] = np.maximum.accumulate(mine_values)
    applied = np.empty_like(running)
    applied[by_order] = running
    return applied[: stamps.size]


def _node_verdicts(
    stamps: NDArray[np.int64],
    order: NDArray[np.int64],
    mode: NDArray[np.uint8],
    value: NDArray[np.float64],
    refused: dict[int, str],
    restarts: tuple[Restart, ...],
) -> tuple[NDArray[np.bool_], NDArray[np.int64], NDArray[np.int64], tuple[str, ...]]:
    """The node's verdict on every command, by position in ``stamps`` (the topic's recording
    order): ``(accepted mask, index among the commands received, rejected indexes, reasons)``.

    Refused: what the events name, and what the node always refuses (unknown mode, non-finite
    value, a stamp older than the last accepted command's since the last restart)."""
    received = np.argsort(order, kind="stable")  # k-th command received -> position
    index = np.empty(order.size, dtype=np.int64)
    index[received] = np.arange(order.size)
    reasons: dict[int, str] = {}
    for k, reason in refused.items():
        reasons[int(received[k])] = reason
    for pos in np.flatnonzero((mode != DEPTH) & (mode != FORCE)).tolist():
        reasons.setdefault(pos, f"mode must be DEPTH (0) or FORCE (1) (got {mode[pos]})")
    for pos in np.flatnonzero(~np.isfinite(value)).tolist():
        reasons.setdefault(pos, f"{'force' if mode[pos] == FORCE else 'depth'} must be finite")
    # Older stamps, per stretch between restarts: the last accepted stamp is the running
    # maximum of the candidates before (a candidate refused for its stamp is below it).
    segment = np.searchsorted(np.array([r.order for r in restarts], dtype=np.int64), order)
    refused_so_far = np.zeros(order.size, dtype=np.bool_)
    refused_so_far[list(reasons)] = True
    received_segment = segment[received]
    received_open = ~refused_so_far[received]
    for seg in np.unique(segment).tolist():
        # This stretch's commands not refused yet, in the order received.
        candidates = received[(received_segment == seg) & received_open]
        if candidates.size < 2:
            continue
        last = _running_max(stamps[candidates])
        older = np.flatnonzero(stamps[candidates][1:] < last[:-1]) + 1
        for j in older.tolist():
            p = int(candidates[j])
            reasons[p] = f"header.stamp {stamps[p]} ns is older than the last command's {last[j - 1]} ns"
    keep = np.ones(order.size, dtype=np.bool_)
    keep[list(reasons)] = False
    rejected_positions = sorted(reasons, key=lambda p: index[p])
    return (
        keep,
        index,
        index[np.array(rejected_positions, dtype=np.int64)] if reasons else np.empty(0, dtype=np.int64),
        tuple(reasons[p] for p in rejected_positions),
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
    model: str  # ContactSimulator.model of the first input: "closed_form" or "time_stepped"
    #: (n,) the model each input ran with when a PARAMETERS event changed it, else None
    #: (every input ran with ``model``).
    input_model: NDArray[np.str_] | None = None

    @property
    def input_outputs(self) -> list[StepOutput]:
        """One StepOutput per input (built from `input_columns`)."""
        from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, Phase, StepOutput

        columns = [self.input_columns[name].tolist() for name in STEP_OUTPUT_FIELDS]
        phase = STEP_OUTPUT_FIELDS.index("phase")
        columns[phase] = [Phase(p) for p in columns[phase]]
        return [StepOutput(*values) for values in zip(*columns, strict=True)]


def changed_contact(restart: Restart, contact_id: str) -> ContactConfig:
    """The configuration a PARAMETERS event carries for ``contact_id``."""
    import yaml

    from viscoadh_ros.core.config import SceneConfig

    try:
        scene = SceneConfig.from_dict(yaml.safe_load(restart.contact_yaml))
    except (yaml.YAMLError, ValueError) as exc:
        raise InputError(f"PARAMETERS event at {restart.ns} ns: unusable contact_yaml ({exc})") from None
    ids = [c.id for c in scene.contacts]
    if contact_id not in ids:
        if len(ids) != 1:
            raise InputError(f"PARAMETERS event at {restart.ns} ns holds contacts {ids}, not {contact_id!r}")
        contact_id = ids[0]
    return scene.contact(contact_id)


@dataclass(frozen=True)
class Material:
    """The contact a stretch of a record runs with: from the record's start (``ns`` None) or
    from a PARAMETERS event (its stamp ``ns``), with what that event changed."""

    contact: ContactConfig
    ns: int | None = None
    #: The parameters the logged change set (relative keys, ``"adhesion.work_of_adhesion"``):
    #: ``(before, after)`` as the node ran them.
    changed: dict[str, tuple[Any, Any]] = field(default_factory=dict)
    #: Of those, the values the user's scene held that the change replaced where they differed
    #: from the node's before the change.
    replaced: dict[str, Any] = field(default_factory=dict)
    given: bool = False  # True: the change applied to the user's scene; False: the node's contact
    order: int | None = None  # the event's position in the recording (None: the record's start)

    def _at(self, experiment: Experiment) -> float:
        """Record time of the change, s (0 for the record's start; < 0 before its first input)."""
        return 0.0 if self.ns is None else float(experiment.time(np.array([self.ns]))[0])

    def describe(self, experiment: Experiment, start: str) -> str:
        """``t = 4.07 s on: <what>``; ``start``: what the record starts with."""
        at = self._at(experiment)
        if self.ns is None:
            return f"t = {at:.6g} s on: {start}"
        change = ", ".join(f"{k} {_value_text(a)} -> {_value_text(b)}" for k, (a, b) in self.changed.items())
        change = f"the logged parameter change {change or '(nothing of this contact)'}"
        # A change made before the record's first input (in recording order: after a reset the
        # stamps may start over) has a negative record time (an outside tester read
        # "t = -0.073 s" as a fault): say what it means.
        first = int(experiment.input_order[0]) if experiment.input_order.size else None
        early = first is not None and self.order is not None and self.order < first
        before = " (before the first input)" if early else ""
        text = f"t = {at:.6g} s{before} on: " + (
            f"{change} applied to the --scene contact" if self.given else f"the node's contact after {change}"
        )
        if self.replaced:
            text += (
                " (replacing the scene's "
                + ", ".join(f"{k} {_value_text(v)}" for k, v in self.replaced.items())
                + ")"
            )
        return text

    def as_dict(self, experiment: Experiment) -> dict[str, Any]:
        """JSON-ready: ``from_s``, ``changed`` ``{key: [before, after]}``, ``replaced``."""
        return {
            "from_s": self._at(experiment),
            "changed": {k: [a, b] for k, (a, b) in self.changed.items()},
            "replaced": dict(self.replaced),
        }


def _value_text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value_text(v) for v in value) + "]"
    return str(value)


def _contact_parameters(contact: ContactConfig) -> dict[str, Any]:
    """The contact's parameters with keys relative to it (``"adhesion.work_of_adhesion"``)."""
    from viscoadh_ros.core.config import SceneConfig

    prefix = contact.id + "."
    flat = SceneConfig(contacts=(contact,)).to_parameters()
    return {k[len(prefix) :]: v for k, v in flat.items() if k.startswith(prefix)}


def materials(
    experiment: Experiment, contact: ContactConfig, *, logged: ContactConfig | None, given: bool
) -> list[Material]:
    """The contact each stretch of ``experiment`` runs with: ``contact`` from the start, then
    one per PARAMETERS event, in order.

    ``given`` False (``contact`` is the log's own): each event's contact as logged, the node's.
    ``given`` True (a scene the user gave, e.g. a candidate material): the parameters the
    event changed (its contact against the node's before it: ``logged``, the contact the log
    stores for its start, for the first event, the previous event's for the others) are set
    on the user's contact, everything else stays the user's; a log that stores no scene has
    ``contact`` stand for the node's start (``logged`` None). InputError when a change cannot
    apply to the user's contact (say, a Kelvin chain of another length)."""
    from viscoadh_ros.core.config import SceneConfig
    from viscoadh_ros.core.errors import ConfigError

    found = [Material(contact)]
    node_before = logged if logged is not None else contact
    current = contact
    for restart in experiment.restarts:
        if restart.kind != PARAMETERS:
            continue
        node_after = changed_contact(restart, contact.id)
        old, new = _contact_parameters(node_before), _contact_parameters(node_after)
        changed = {k: (old.get(k), v) for k, v in new.items() if old.get(k) != v}
        removed = [k for k in old if k not in new]
        if not given:
            current = dataclasses.replace(node_after, id=contact.id)
            replaced: dict[str, Any] = {}
        else:
            mine = _contact_parameters(current)
            replaced = {k: mine[k] for k in changed if k in mine and mine[k] != old.get(k)}
            updated = {k: v for k, v in mine.items() if k not in removed}
            updated.update({k: after for k, (_, after) in changed.items()})
            try:
                current = SceneConfig.from_parameters(
                    {"contacts": [contact.id], **{f"{contact.id}.{k}": v for k, v in updated.items()}}
                ).contact(contact.id)
            except (ConfigError, ValueError) as exc:
                at = float(experiment.time(np.array([restart.ns]))[0])
                raise InputError(
                    f"the logged parameter change at t = {at:.6g} s ({', '.join(changed) or 'nothing'}) "
                    f"cannot apply to the --scene contact {contact.id!r}: {exc}"
                ) from None
        found.append(Material(current, restart.ns, changed, replaced, given, restart.order))
        node_before = node_after
    return found


def run_model(
    contact: ContactConfig,
    experiment: Experiment,
    *,
    progress: Callable[[int], Any] | None = None,
    parameters: bool = True,
    changes: list[ContactConfig] | None = None,
) -> ModelRun:
    """Run ``contact``'s model over ``experiment`` from a fresh state (the node's event loop).

    Every event under depth control (a depth input, or a measured stamp while a depth is
    held: `ContactSimulator.advance` then steps to that time holding the depth) runs in one
    `ContactSimulator.step_depths` call per stretch between force inputs; force inputs and
    the stamps they hold run event by event. A node log's restarts (RESET, PARAMETERS) start
    a fresh simulator where they were logged, and the next input a new time base, as the node
    does; ``parameters=False`` keeps ``contact`` through PARAMETERS events (a fit's trial);
    ``changes``: the contact each PARAMETERS event restarts with, in order (default: the one
    the event carries; `materials`). ``progress(k)`` is called with the number of events done
    since the last call.
    """
    from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS

    n, m = experiment.input_ns.size, experiment.measured_ns.size
    restarts = experiment.restarts
    kind, index, stamps = _run_order(experiment)

    columns = {name: np.empty(n, dtype=dtype) for name, dtype in _column_dtypes(STEP_OUTPUT_FIELDS).items()}
    ran: list[tuple[NDArray[np.int64], str]] = []  # (inputs, the model they ran with) per piece
    model_force = np.empty(m)
    started = wallclock.perf_counter()
    # Pieces between restarts; each: measured samples before its first input (the node's hold
    # timer on a fresh contact), then the inputs and samples from its first input on.
    cuts = np.flatnonzero(kind == 2)
    # The k-th PARAMETERS event of the record restarts with changes[k].
    rank = {i: k for k, i in enumerate(i for i, r in enumerate(restarts) if r.kind == PARAMETERS)}
    if changes is not None and len(changes) != len(rank):
        raise ValueError(f"{len(changes)} contacts for the record's {len(rank)} parameter changes")
    for lo, hi in zip(np.concatenate(([0], cuts + 1)), np.concatenate((cuts, [kind.size])), strict=True):
        if lo > 0 and parameters and restarts[int(index[lo - 1])].kind == PARAMETERS:
            at = int(index[lo - 1])
            contact = changed_contact(restarts[at], contact.id) if changes is None else changes[rank[at]]
        inputs = np.flatnonzero(kind[lo:hi] == 0)
        first = lo + int(inputs[0]) if inputs.size else hi
        if first > lo:
            _at_rest(contact, index[lo:first], model_force)
        if first < hi:
            model = _run_piece(
                contact,
                experiment,
                stamps[first:hi],
                kind[first:hi] == 0,
                index[first:hi],
                columns,
                model_force,
            )
            ran.append((index[first:hi][kind[first:hi] == 0], model))
        if progress is not None:
            progress(int(hi - lo))
    wall_time = wallclock.perf_counter() - started
    # The model per input only when it changed (a 16-character string per input costs more
    # than the rest of the bookkeeping).
    input_model = None
    if len({model for _, model in ran}) > 1:
        input_model = np.empty(n, dtype="<U16")
        for inputs, model in ran:
            input_model[inputs] = model
    return ModelRun(columns, model_force, wall_time, ran[0][1], input_model)


def _run_order(experiment: Experiment) -> tuple[NDArray[np.int8], NDArray[np.int64], NDArray[np.int64]]:
    """``(kind, index, stamp_ns)`` of every event in the order the model runs them: kind 0 an
    input, 1 a measured sample, 2 a restart; index its position among those of its kind."""
    n, m, r = experiment.input_ns.size, experiment.measured_ns.size, len(experiment.restarts)
    restarts = experiment.restarts
    kind = np.concatenate([np.zeros(n, np.int8), np.ones(m, np.int8), np.full(r, 2, np.int8)])
    index = np.concatenate([np.arange(n), np.arange(m), np.arange(r)])
    stamps = np.concatenate(
        [experiment.input_ns, experiment.measured_ns, np.array([x.ns for x in restarts], dtype=np.int64)]
    )
    orders = np.concatenate(
        [experiment.input_order, experiment.measured_order, np.array([x.order for x in restarts], np.int64)]
    )
    if experiment.by_arrival:
        sequence = np.argsort(orders, kind="stable")
    else:
        # By stamp; at equal stamps in recording order (see the module docstring).
        sequence = np.lexsort((orders, stamps))
    return kind[sequence], index[sequence], stamps[sequence]


def at_rest(experiment: Experiment) -> NDArray[np.bool_]:
    """(m,) True for the measured samples the model takes from a contact at rest: after a
    restart (RESET, PARAMETERS) and before the next input, the node's hold timer publishes the
    fresh contact's output (:func:`_at_rest`), whatever its material."""
    kind, index, _ = _run_order(experiment)
    last_input, last_restart = _last_true(kind == 0), _last_true(kind == 2)
    resting = np.zeros(experiment.measured_ns.size, dtype=np.bool_)
    measured = kind == 1
    resting[index[measured]] = last_restart[measured] > last_input[measured]
    return resting


def stretch(experiment: Experiment, after: int | None, before: int | None) -> Experiment:
    """The part of a node log recorded after position ``after`` and before ``before`` (None:
    from its start, to its end), cut at restarts so it runs as the whole record runs there:
    the inputs between them, the measured samples from the first of those inputs on (those
    before it are the contact at rest), the restarts between. ``t0_ns`` stays the record's, so
    times still count from its first input; ``rejected_index`` and ``commands_before`` stay
    too (they count the commands received, not the inputs run). InputError when no input is
    left."""
    low = -1 if after is None else after
    high = np.iinfo(np.int64).max if before is None else before
    inputs = (experiment.input_order > low) & (experiment.input_order < high)
    if not inputs.any():
        raise InputError(f"{experiment.input_topic}: no input between the record's restarts there")
    measured = experiment.measured_order < high
    if experiment.by_arrival:
        measured &= experiment.measured_order > int(experiment.input_order[inputs].min())
    else:
        measured &= experiment.measured_ns >= int(experiment.input_ns[inputs].min())
    restarts = tuple(r for r in experiment.restarts if low < r.order < high)
    return experiment.select(inputs, measured, restarts=restarts)


def _at_rest(contact: ContactConfig, index: NDArray[np.int64], model_force: NDArray[np.float64]) -> None:
    """Measured samples after a restart, before the next accepted command: the node's hold
    timer leaves a contact that has had no command since start or reset alone (nothing to hold;
    holding depth 0 would touch the surface), so it publishes the fresh contact's output."""
    from viscoadh_ros.core.simulator import ContactSimulator

    model_force[index] = ContactSimulator(contact).output.force


def _run_piece(
    contact: ContactConfig,
    experiment: Experiment,
    stamps: NDArray[np.int64],
    is_input: NDArray[np.bool_],
    index: NDArray[np.int64],
    columns: dict[str, NDArray],
    model_force: NDArray[np.float64],
) -> str:
    """Inputs and measured samples from a fresh simulator whose time base starts at the first
    (an input) stamp, as the node's first command after start or a restart; returns the model."""
    from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

    times = (stamps - stamps[0]) * 1e-9
    # The control each event runs under: an input's own, a measured stamp the last input's
    # (the first event is an input).
    last_input = _last_true(is_input)
    held_mode = experiment.input_mode[index[last_input]]
    held_value = experiment.input_value[index[last_input]]
    sim = ContactSimulator(contact)
    # Stretches of consecutive events of one control mode.
    bounds = np.flatnonzero(np.diff(held_mode.astype(np.int8))) + 1
    for lo, hi in zip(np.concatenate(([0], bounds)), np.concatenate((bounds, [times.size])), strict=True):
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
    return sim.model


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
    # The node steps to max(stamp, the contact's time): a command stamped before a hold tick
    # it arrived after runs at the tick's time.
    times = _running_max(np.maximum(times, sim.time))
    previous = np.concatenate(([sim.time], times[:-1]))
    steps = is_input | (times > previous)
    result = sim.step_depths(times[steps], depth[steps])
    # Each event's force: its own step's, or the last step's before it (the count of steps
    # so far less one is that step's row; -1 before the first).
    last_step = np.cumsum(steps) - 1
    force = np.where(last_step >= 0, result["force"][np.maximum(last_step, 0)], before)
    measured = ~is_input
    model_force[index[measured]] = force[measured]
    inputs = index[is_input]
    input_rows = last_step[is_input]
    count = inputs.size
    if count and int(np.count_nonzero(steps)) == count and np.all(np.diff(inputs) == 1):
        # Every step is an input's (no measured stamp advanced time on its own, the usual
        # case) and the inputs are consecutive: whole columns, no gather and scatter per field.
        at = slice(int(inputs[0]), int(inputs[0]) + count)
        for name, values in result.items():
            if count == columns[name].size and values.dtype == columns[name].dtype:
                columns[name] = values  # the whole column: step_depths' own array, no copy
            else:
                columns[name][at] = values
    else:
        for name, values in result.items():
            columns[name][inputs] = values[input_rows]


def _running_max(values: NDArray) -> NDArray:
    """``np.maximum.accumulate(values)`` (1-D), skipped when ``values`` never decrease (then
    it is ``values`` itself): numpy's accumulate costs ~10 ns per element, 10x a diff."""
    if values.size > 1 and np.any(values[1:] < values[:-1]):
        return np.maximum.accumulate(values)
    return values


def _last_true(mask: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Per position, the index of the last True of ``mask`` at or before it, -1 before the
    first: ``np.maximum.accumulate(np.where(mask, np.arange(mask.size), -1))`` by a cumulative
    count (numpy's accumulate costs ~10 ns per element, 10x a cumsum)."""
    where = np.flatnonzero(mask)
    if where.size == 0:
        return np.full(mask.size, -1, dtype=np.int64)
    seen = np.cumsum(mask) - 1
    return np.where(seen >= 0, where[np.maximum(seen, 0)], -1)


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
