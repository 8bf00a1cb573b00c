"""The ``viscoadh`` node: a thin ROS 2 adapter over the contact simulator.

Per contact id ``C`` of the scene: subscribes ``C/indentation``, publishes ``C/state``,
``C/wrench`` (and ``C/marker`` when ``markers.enabled``), serves ``C/simulate_history``,
``C/predict_pull_off`` and ``C/reset``; node-wide it publishes ``/diagnostics`` at 1 Hz.
The full interface with units and sign conventions is in docs/ros_interface.md.

Threading: the live path (every contact's command subscription and hold timer, and the state
and wrench publishing they do) is served by the node's own thread on a raw rclpy wait set,
started at the end of construction and stopped by ``destroy_node``. Its entities are in a
callback group no executor runs (:class:`_LiveGroup`), so the executor the node is added to
(``main`` spins a MultiThreadedExecutor in the main thread) serves only the services, parameter
services, ``/clock`` and diagnostics: a 10^5-row ``simulate_history`` never queues a command,
and rclpy's executor (tens of microseconds of Python per callback, measured as the bottleneck
at 4 contacts x 1 kHz, see benchmarks/notes.md) is off the latency path. A per-contact lock
guards the simulator against the services and parameter changes, which run on executor threads.
"""

from __future__ import annotations

import contextlib
import gc
import math
import operator
import os
import sys
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import rclpy
import yaml
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from rcl_interfaces.msg import SetParametersResult
from rclpy.callback_groups import CallbackGroup, ReentrantCallbackGroup
from rclpy.clock import JumpThreshold, TimeJump
from rclpy.duration import Duration
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.exceptions import InvalidHandle
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.guard_condition import GuardCondition
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_policy_name_from_kind
from rclpy.serialization import deserialize_message
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Trigger
from viscoadh_msgs.msg import ContactEvent, ContactState, HandCommand, HandState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff, SimulateHistory
from visualization_msgs.msg import Marker

from viscoadh_ros.core._kernels import warm_up
from viscoadh_ros.core.config import NODE_NAME, ContactConfig, SceneConfig
from viscoadh_ros.core.errors import ConfigError, InputError
from viscoadh_ros.core.hand import ContactStepError, step_contacts
from viscoadh_ros.core.history import predict_pull_off, simulate_history
from viscoadh_ros.core.simulator import ContactSimulator, StepOutput
from viscoadh_ros.io import cdr
from viscoadh_ros.io.mcap_log import McapRecorder, TopicQos, plain
from viscoadh_ros.ros import conversions, diagnostics, markers, parameters

#: An idle contact (out of touch, relaxed) republishes its unchanging state at this period.
IDLE_PUBLISH_PERIOD_NS = 1_000_000_000
#: How long a stop (SIGINT, SIGTERM, `destroy_node`) waits for a step the live thread is in,
#: and then for the process to exit (a service call such as a long ``simulate_history`` on an
#: executor thread, which the interpreter's exit would wait for), s; past it the step or call
#: is abandoned (see `main`). Steps are bounded (numerics ranges, `presets.MAX_SUBSTEPS`), but
#: a legit large scene's step may take seconds, and a history any time.
STOP_WAIT_S = 2.0
#: Period of /diagnostics.
DIAGNOSTICS_PERIOD_S = 1.0
#: Minimum interval between two warnings of the same kind of rejection (throttled log), s.
WARN_THROTTLE_S = 1.0
_QOS_DEPTH = 10


def command_qos(depth: int) -> QoSProfile:
    """QoS of the command subscriptions (``C/indentation``, ``hand/indentation``): reliable,
    volatile, keep last ``depth`` (``command.queue_depth``).

    Reliable (the ROS default), so no command is lost while discovery completes; a best-effort
    publisher (sensor-data QoS) cannot match it and is warned about (see
    ``_Contact.on_incompatible_qos``). A best-effort subscription would match both, but it lost
    the first command of a child-process client whose publisher matched before the node's
    subscription did. The depth is how far the live thread may fall behind before the oldest
    waiting command is lost: 0.4.0's 10 (10 ms at 1 kHz) lost commands whenever the node
    stalled longer (a full collection, the machine's scheduler; see benchmarks/rounds).
    """
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE)


#: ``C/events`` keeps its last events for late joiners (a recorder started after the node).
EVENTS_QOS = QoSProfile(
    depth=100, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
_NS_PER_S = 1_000_000_000
#: GIL switch interval of the node process, s (CPython's default is 5 ms): how long the live
#: thread, woken by a command, may wait for a service thread that holds the GIL in Python code.
GIL_SWITCH_INTERVAL_S = 1e-4
_COMMAND_TYPE = "viscoadh_msgs/msg/IndentationCommand"
#: The live thread serves the command subscriptions' QoS events (an incompatible publisher) in
#: one wait per this period, ns (see ``_LiveLoop._run``).
EVENTS_PERIOD_NS = 200_000_000


def _seconds(ns: int) -> str:
    """A node-clock time in ns as seconds with all nine decimals, exactly (a float's 16 digits
    change the last nanoseconds of a 2026 stamp, and users compare these with their stamps)."""
    sign = "-" if ns < 0 else ""
    whole, frac = divmod(abs(ns), _NS_PER_S)
    return f"{sign}{whole}.{frac:09d}"


class Recorder(Protocol):
    """What the node hands every message it receives and publishes to (MCAP logging)."""

    def record(self, topic: str, msg: Any, stamp_ns: int, *, handed_over: bool = False) -> bool:
        """Queue ``msg`` seen on ``topic`` at log time ``stamp_ns`` (node clock); never blocks.
        ``handed_over``: the caller never changes ``msg`` again, so the recorder may serialise
        it later on its own thread. False when the message was dropped (full queue)."""

    def record_cdr(self, topic: str, type_name: str, payload: bytes, stamp_ns: int) -> bool:
        """:meth:`record` for an already serialised ``type_name`` message."""

    def set_scene(self, scene: Mapping[str, Any] | None) -> None:
        """The scene in force from now on, for the files started after what was recorded."""

    def close(self) -> None:
        """Finish the log."""

    @property
    def dropped(self) -> int:
        """Messages dropped so far (full queue or failed writer)."""

    @property
    def written(self) -> int:
        """Messages written so far."""

    @property
    def error(self) -> BaseException | None:
        """Why the writer stopped, if it did."""


class _Contact:
    """The live state and ROS endpoints of one contact id."""

    def __init__(self, node: ViscoadhNode, config: ContactConfig) -> None:
        self.node = node
        self.id = config.id
        self.config = config
        self.simulator = ContactSimulator(config)
        self.lock = threading.Lock()
        self.counters = diagnostics.ContactCounters()
        # Simulation time is node-clock time minus an epoch (integer ns) set by the first event
        # after start or reset, so float seconds keep sub-microsecond resolution.
        self.epoch_ns: int | None = None
        self.last_command_ns: int | None = None
        self.last_clock_ns: int | None = None
        self.last_publish_ns: int | None = None
        # Node clock when the last accepted command (C/indentation or hand) was received: the
        # hold timer stays out of the way while commands keep coming (see :meth:`on_timer`).
        self.last_received_ns: int | None = None
        # The contact's time, node-clock ns: the time the last state it published (C/state, or
        # its row of a hand/state) describes and is stamped with, since start or the last
        # restart (reset, parameter change, clock jump back). It never goes back: a command
        # stamped before it is applied at it (see :meth:`_applied_ns`).
        self.time_ns: int | None = None
        # Commands received on C/indentation since start (accepted or not): the next one's index.
        self.commands_seen = 0
        # The last accepted control ({"depth": d} or {"force": f}); the hold timer keeps it, so
        # a contact under force control creeps at constant force between commands.
        self.hold: dict[str, float] = {}

        live = node.live_group
        self.state_pub = node.create_publisher(ContactState, f"{self.id}/state", _QOS_DEPTH)
        self.wrench_pub = node.create_publisher(WrenchStamped, f"{self.id}/wrench", _QOS_DEPTH)
        self.marker_pub = node.create_publisher(Marker, f"{self.id}/marker", _QOS_DEPTH)
        self.subscription = node.create_subscription(
            IndentationCommand,
            f"{self.id}/indentation",
            self.on_command,
            node.command_qos,
            callback_group=live,
            event_callbacks=SubscriptionEventCallbacks(incompatible_qos=self.on_incompatible_qos),
        )
        # The subscription's QoS events (an incompatible publisher) stay in the live group and
        # are served by the live thread's own wait set (`_LiveLoop._run`), not by the services'
        # executor: with Fast DDS an event of a subscription wakes a wait set that holds it at
        # every message the subscription receives, and the executor rebuilt its wait set in
        # Python at each wake (0.4.0: 60 % of a core and the GIL at 16 contacts x 1 kHz).
        self.events_pub = node.create_publisher(ContactEvent, f"{self.id}/events", EVENTS_QOS)
        self.timer = node.create_timer(1.0 / node.scene.node.publish_rate, self.on_timer, callback_group=live)
        # Resolved names, read per message for the log (rclpy's topic_name asks rcl each time).
        self.command_topic = self.subscription.topic_name
        self.state_topic = self.state_pub.topic_name
        self.wrench_topic = self.wrench_pub.topic_name
        self.events_topic = self.events_pub.topic_name
        services = node.services_group
        node.create_service(
            SimulateHistory,
            f"{self.id}/simulate_history",
            self.on_simulate_history,
            callback_group=services,
        )
        node.create_service(
            PredictPullOff,
            f"{self.id}/predict_pull_off",
            self.on_predict_pull_off,
            callback_group=services,
        )
        node.create_service(Trigger, f"{self.id}/reset", self.on_reset, callback_group=services)

    # --- clock -------------------------------------------------------------------------------

    def _sim_time(self, ns: int) -> float:
        """Simulation time, s, of node-clock time ``ns``; -inf before the first command since
        start or reset (the contact is then at rest and nothing moves it)."""
        if self.last_command_ns is None:
            return -math.inf
        return (ns - self.epoch_ns) * 1e-9

    def _reset_locked(self) -> None:
        """Back to a contact that has received no command: at rest, out of touch. The hold
        timer does not step it until a command brings it in (see :meth:`on_timer`)."""
        self.simulator.reset(time=0.0)
        self.epoch_ns = None
        self.last_command_ns = None
        self.last_publish_ns = None
        self.last_received_ns = None
        self.time_ns = None
        self.hold = {}

    def _check_clock_locked(self, now_ns: int) -> None:
        """Reset the contact when the node clock went backwards (a looping bag, a clock reset).

        ROS time jumps are also caught by the node's jump handler (a timer on ROS time does not
        fire after a backward jump); this check covers a system clock set back.
        """
        if self.last_clock_ns is not None and now_ns < self.last_clock_ns:
            self.clock_jumped_locked((self.last_clock_ns - now_ns) * 1e-9)
        self.last_clock_ns = now_ns

    def clock_jumped_locked(self, back_s: float) -> None:
        """Reset after the clock went back by ``back_s`` seconds, with a warning."""
        reason = f"clock jumped back by {back_s:.3f} s; contact reset"
        self.node.get_logger().warning(f"{self.id}: {reason}")
        self._reset_locked()
        self.last_clock_ns = None
        self.event_locked(ContactEvent.RESET, self.node.now_ns(), reason=reason)

    def event_locked(
        self,
        kind: int,
        now_ns: int,
        *,
        reason: str,
        index: int = 0,
        stamp: Any = None,
        contact_yaml: str = "",
    ) -> None:
        """Publish a ContactEvent on ``C/events`` and log it (caller holds the lock, so the
        log keeps the contact's events and commands in the order they took effect)."""
        event = ContactEvent(kind=kind, contact_id=self.id, command_index=index, reason=reason)
        event.header.stamp = conversions.ns_to_stamp(now_ns)
        event.header.frame_id = self.node.frame_id
        if stamp is not None:
            event.command_stamp = stamp
        event.contact_yaml = contact_yaml
        self.events_pub.publish(event)
        self.node.record(self.events_topic, event, now_ns)

    def on_incompatible_qos(self, event: Any) -> None:
        """A publisher on ``C/indentation`` whose QoS cannot match: its commands never arrive."""
        policy = qos_policy_name_from_kind(event.last_policy_kind)
        reason = (
            f"a publisher on {self.command_topic} offers a QoS incompatible with the node's (last "
            f"incompatible policy: {policy}); its commands are not received. The node subscribes "
            f"reliable, volatile, keep last {self.node.command_qos.depth}: publish reliable (not best "
            "effort / sensor-data QoS)"
        )
        with self.lock:
            self.counters.incompatible_publishers = event.total_count
            self.counters.last_rejection = reason
            self.counters.rejections_in_window += 1
        self.node.get_logger().warning(f"{self.id}: {reason}")

    # --- live path ---------------------------------------------------------------------------

    def on_command(self, msg: IndentationCommand) -> None:
        """Handle a command message object (see :meth:`handle_command`)."""
        stamp = msg.header.stamp
        self.handle_command(stamp.sec, stamp.nanosec, msg.mode, msg.depth, msg.force, msg)

    def on_raw_command(self, payload: bytes) -> None:
        """Handle a command as taken off the subscription, serialised: read with ``struct``
        (rclpy's message object costs ~15 us per take) and logged as received."""
        fields = cdr.parse_command(payload)
        if fields is None:  # not the usual little-endian layout: let rclpy read it
            self.on_command(deserialize_message(payload, IndentationCommand))
            return
        self.handle_command(*fields, payload)

    def handle_command(
        self, sec: int, nanosec: int, mode: int, depth: float, force: float, received: Any
    ) -> None:
        """Step to the command's stamp (or the contact's time when later, see
        :meth:`_applied_ns`) and publish the state stamped with that time, or reject it
        (the contact unchanged, a COMMAND_REJECTED event with the reason). ``received``: the
        command as it came, a message object or its CDR payload, for the log."""
        with self.lock:
            now_ns = self.node.now_ns()
            if isinstance(received, bytes):
                self.node.record_cdr(self.command_topic, _COMMAND_TYPE, received, now_ns)
            else:
                self.node.record(self.command_topic, received, now_ns)
            index = self.commands_seen
            self.commands_seen = index + 1
            self._check_clock_locked(now_ns)
            try:
                stamp_ns = self._command_stamp_locked(sec, nanosec, now_ns)
                control = conversions.control_of(mode, depth, force)
                at_ns = self._applied_ns(stamp_ns)
                # The first command since start or reset: nothing says where the indenter was
                # before, so the contact's history starts at rest at this time (the way
                # simulate_history starts at its first sample). Nothing changes until the step
                # succeeded (the simulator's step is a transaction).
                epoch_ns = at_ns if self.last_command_ns is None else self.epoch_ns
                target = (at_ns - epoch_ns) * 1e-9
                started = time.perf_counter()
                output = self.simulator.step(target, **control)
                self.counters.steps.add(time.perf_counter() - started)
            except ValueError as error:
                reason = f"command rejected ({conversions.describe(mode, depth, force)}): {error}"
                self._reject_locked(reason, command=True)
                self.event_locked(
                    ContactEvent.COMMAND_REJECTED,
                    now_ns,
                    reason=reason,
                    index=index,
                    stamp=Time(sec=sec, nanosec=nanosec),
                )
                return
            self.accepted_locked(epoch_ns, stamp_ns, at_ns, now_ns, control)
            state = self._state_locked(output, at_ns)
        self._publish(state, output, at_ns, now_ns)

    def _applied_ns(self, stamp_ns: int) -> int:
        """When a command stamped ``stamp_ns`` applies: at its stamp, or at the contact's time
        when that is later (a hold tick or a command already published a state stamped after
        it), so the contact's time and the stamps of its states never go back within a history.
        The first command since start or a restart starts a history at its own stamp (rest
        heartbeats before it describe none). Its state is stamped with this time."""
        return stamp_ns if self.time_ns is None else max(stamp_ns, self.time_ns)

    def accepted_locked(
        self,
        epoch_ns: int,
        stamp_ns: int,
        at_ns: int,
        now_ns: int,
        control: dict[str, float],
        *,
        count: bool = True,
    ) -> None:
        """Book an accepted command stamped ``stamp_ns``, applied at ``at_ns`` (see
        :meth:`_applied_ns`); ``count``: it came on ``C/indentation`` (a hand command counts on
        the hand's counters instead)."""
        if count:
            self.counters.commands_received += 1
        self.epoch_ns = epoch_ns
        self.hold = control
        self.last_command_ns = stamp_ns
        self.time_ns = at_ns
        self.last_publish_ns = now_ns
        self.last_received_ns = now_ns

    def _command_stamp_locked(self, sec: int, nanosec: int, now_ns: int) -> int:
        """The command's stamp, ns on the node clock (zero: ``now_ns``); InputError for a stamp
        that is malformed, too far ahead of the node clock, or older than the last command's."""
        if sec < 0 or nanosec >= _NS_PER_S:
            raise InputError(
                f"header.stamp must have sec >= 0 and nanosec < 1000000000 (got sec {sec}, nanosec {nanosec})"
            )
        stamp_ns = sec * _NS_PER_S + nanosec or now_ns
        if stamp_ns - now_ns > self.node.max_future_ns:
            raise InputError(
                f"header.stamp {_seconds(stamp_ns)} s is {(stamp_ns - now_ns) * 1e-9:.3f} s ahead of the "
                f"node clock ({_seconds(now_ns)} s); command.max_future_s allows "
                f"{self.node.max_future_ns * 1e-9:g} s"
            )
        if self.last_command_ns is not None and stamp_ns < self.last_command_ns:
            raise InputError(
                f"header.stamp {_seconds(stamp_ns)} s is older than the last "
                f"command's {_seconds(self.last_command_ns)} s"
            )
        return stamp_ns

    def on_timer(self) -> None:
        """Between commands: advance the contact to now (hold, relaxation) and publish."""
        with self.lock:
            # Read under the lock: a command handled on another thread (in-process callers)
            # between the read and the lock would look like the clock going back.
            now_ns = self.node.now_ns()
            self._check_clock_locked(now_ns)
            period = self.timer.timer_period_ns
            if self.last_received_ns is not None and now_ns - self.last_received_ns < period * 3 // 2:
                # Commands keep coming at the timer's rate (one came within the last period and
                # a half: half a period for jitter), whatever their stamps: each publishes its own
                # state. A hold state between two would be extra, and would take the contact's
                # time past the next command's stamp (applied late: a hold, then a jump). 0.8.0
                # let the timer in half a period after a command, so at the timer's rate it put
                # a hold state between two commands at every tick of the wrong phase.
                return
            if self.last_publish_ns is not None:
                since = now_ns - self.last_publish_ns
                # A tick that catches up on a late one publishes nothing new.
                if since < period // 2:
                    return
                if self.simulator.is_idle and since < IDLE_PUBLISH_PERIOD_NS:
                    return
            if self.time_ns is not None and now_ns <= self.time_ns:
                # The contact's last state already describes now, or a later time (a command
                # stamped ahead of the clock, within command.max_future_s): a state stamped now
                # would repeat it or make the state stamps go back.
                return
            # No command since start or reset: the contact is out of touch and there is nothing
            # to hold (holding depth 0 would touch the surface, and an adhesive contact snaps in).
            target = self._sim_time(now_ns)
            output = self.simulator.output
            if target > self.simulator.time:
                started = time.perf_counter()
                try:
                    output = self.simulator.step(target, **self.hold)
                except ValueError as error:
                    # Holding an accepted control rarely fails (a held force that creep makes
                    # unreachable); the step changed nothing, the contact waits for a command.
                    # Nothing is published: the contact is still at the time of its last state,
                    # and that state stamped now would claim a time it does not describe.
                    self.node.get_logger().warning(
                        f"{self.id}: hold failed, state kept: {error}", throttle_duration_sec=WARN_THROTTLE_S
                    )
                    self.counters.steps.add(time.perf_counter() - started)
                    return
                self.counters.steps.add(time.perf_counter() - started)
            self.last_publish_ns = now_ns
            if self.last_command_ns is not None:
                # A rest heartbeat before the first command describes no history: the first
                # command starts one at its own stamp (tests/test_node_faults.py).
                self.time_ns = now_ns
            state = self._state_locked(output, now_ns)
        self._publish(state, output, now_ns, now_ns)
        if self.node.markers_enabled and self.marker_pub.get_subscription_count() > 0:
            for marker in markers.contact_markers(
                output,
                self.config.indenter,
                contact_id=self.id,
                stamp_ns=now_ns,
                frame_id=self.node.frame_id,
            ):
                self.marker_pub.publish(marker)

    def _state_locked(self, output: StepOutput, stamp_ns: int) -> bytes:
        """The ContactState at ``stamp_ns`` as its CDR payload (see LivePayloads)."""
        return self.node.payloads.state(
            output,
            stamp_ns=stamp_ns,
            model=self.simulator.model,
            commands_received=self.counters.commands_received,
            commands_rejected=self.counters.commands_rejected,
        )

    def _publish(self, state: bytes, output: StepOutput, stamp_ns: int, now_ns: int) -> None:
        """Publish the state (a CDR payload), and the wrench when it has subscribers; log what
        is published.

        The wrench costs a payload and a publish per command: skipped while nobody reads it,
        except that an MCAP log keeps it for replays.
        """
        node = self.node
        self.state_pub.publish(state)
        node.record_cdr(self.state_topic, cdr.CONTACT_STATE, state, now_ns)
        listened = self.wrench_pub.get_subscription_count() > 0
        if listened or node.logging:
            wrench = node.payloads.wrench(output, stamp_ns=stamp_ns)
            if listened:
                self.wrench_pub.publish(wrench)
            node.record_cdr(self.wrench_topic, cdr.WRENCH, wrench, now_ns)

    def _reject_locked(self, reason: str, *, command: bool) -> None:
        self.counters.reject(reason, command=command)
        self.node.get_logger().warning(f"{self.id}: {reason}", throttle_duration_sec=WARN_THROTTLE_S)

    # --- services ----------------------------------------------------------------------------

    def on_simulate_history(
        self, request: SimulateHistory.Request, response: SimulateHistory.Response
    ) -> SimulateHistory.Response:
        """Run a whole history from a fresh state of this contact; the live state is untouched."""
        config = self.config
        try:
            result = simulate_history(config, **conversions.history_request(request))
        except ValueError as error:
            return self._fail(response, f"simulate_history rejected: {error}")
        return conversions.history_response(result, response)

    def on_predict_pull_off(
        self, request: PredictPullOff.Request, response: PredictPullOff.Response
    ) -> PredictPullOff.Response:
        """Pull-off if the indenter retracted now at ``retract_speed``, from a copy of the live
        state held to now."""
        now_ns = self.node.now_ns()
        with self.lock:
            snapshot = self.simulator.snapshot()
            config = self.config
            now_s = self._sim_time(now_ns)
        try:
            speed = _retract_speed(request.retract_speed)
            copy = ContactSimulator(config)
            copy.restore(snapshot)
            if now_s > copy.time:
                copy.advance(now_s)
            in_contact = copy.in_contact
            prediction = predict_pull_off(copy, speed)
        except ValueError as error:
            return self._fail(response, f"predict_pull_off rejected: {error}")
        response.pull_off_force = float(prediction.pull_off_force)
        response.pull_off_depth = float(prediction.pull_off_depth)
        response.time_to_detach = float(prediction.time_to_detach)
        # A pull-off was found only if the contact was touching and let go within the run's
        # range; otherwise the core's message says which (nothing to pull off, or the values up
        # to where the run stopped).
        response.success = bool(in_contact and prediction.detached)
        response.message = prediction.message
        return response

    def on_reset(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        """Forget the contact's history: fresh, relaxed, out of touch."""
        with self.lock:
            self._reset_locked()
            self.event_locked(ContactEvent.RESET, self.node.now_ns(), reason=f"{self.id}/reset called")
        response.success = True
        response.message = f"contact '{self.id}' reset"
        return response

    def _fail(self, response: Any, reason: str) -> Any:
        with self.lock:
            self._reject_locked(reason, command=False)
        response.success = False
        response.message = reason
        return response

    # --- reconfiguration and diagnostics -----------------------------------------------------

    def replace_config_locked(
        self, config: ContactConfig, simulator: ContactSimulator, scene: SceneConfig
    ) -> None:
        """Use ``config`` and its fresh ``simulator`` (built before any contact changed, so a
        scene that cannot be simulated changes nothing) from now on, a contact that has received
        no command (caller holds the lock and checked the contact is idle); a PARAMETERS event
        carries the new contact."""
        self.config = config
        self.simulator = simulator
        self._reset_locked()
        contact_scene = SceneConfig(contacts=(config,), node=scene.node)
        self.event_locked(
            ContactEvent.PARAMETERS,
            self.node.now_ns(),
            reason="parameters changed: contact restarted with the new physics",
            contact_yaml=yaml.safe_dump(plain(contact_scene.to_dict()), sort_keys=False),
        )

    def take_commands(self) -> None:
        """Handle every command waiting on the subscription (live thread)."""
        take = self.subscription.handle.take_message
        while (taken := take(IndentationCommand, True)) is not None:
            self.on_raw_command(taken[0])

    def set_publish_rate(self, rate: float) -> None:
        """Run the hold timer at ``rate`` Hz from now on."""
        self.timer.timer_period_ns = int(1e9 / rate)

    def status(self) -> Any:
        with self.lock:
            return diagnostics.contact_status(
                self.id,
                self.counters,
                node_name=self.node.get_fully_qualified_name(),
                model=self.simulator.model,
                validity=self.simulator.model_validity,
                in_contact=self.simulator.in_contact,
            )


class _Hand:
    """The hand topics: ``hand/indentation`` (HandCommand: several contacts in one sample),
    answered with one ``hand/state`` (HandState) and logged as one record each; a rejected hand
    command changes no contact and publishes one ContactEvent on ``hand/events``.

    The rules are those of ``C/indentation`` (docs/ros_interface.md), applied to every contact
    of the sample before any is stepped: mode, one finite value per contact, known ids each
    once, a stamp neither malformed, nor too far ahead, nor older than any listed contact's last
    command (from either topic). The steps are one :func:`~viscoadh_ros.core.hand.step_contacts`
    call, all or nothing. A contact's own ``C/state`` does not repeat what ``hand/state`` says;
    its hold timer takes over when hand commands stop.
    """

    def __init__(self, node: ViscoadhNode) -> None:
        self.node = node
        self.commands_seen = 0
        self.commands_received = 0
        self.commands_rejected = 0
        self.last_rejection = ""
        self._rejected_reported = 0  # commands_rejected at the last /diagnostics status
        self._qos_problems = 0  # incompatible publishers noticed since the last status
        self._order = list(node.contacts)
        self._by_id = sorted(node.contacts.values(), key=_contact_id)
        self.state_pub = node.create_publisher(HandState, "hand/state", _QOS_DEPTH)
        self.events_pub = node.create_publisher(ContactEvent, "hand/events", EVENTS_QOS)
        self.subscription = node.create_subscription(
            HandCommand,
            "hand/indentation",
            self.on_command,
            node.command_qos,
            callback_group=node.live_group,
            event_callbacks=SubscriptionEventCallbacks(incompatible_qos=self.on_incompatible_qos),
        )
        # As for C/indentation: the QoS events are served by the live thread.
        self.command_topic = self.subscription.topic_name
        self.state_topic = self.state_pub.topic_name
        self.events_topic = self.events_pub.topic_name

    def status(self, node_name: str) -> Any:
        """The ``<node>: hand`` diagnostic status (WARN after a rejection since the last one)."""
        with self.node.hand_lock:
            window = self.commands_rejected - self._rejected_reported + self._qos_problems
            self._rejected_reported = self.commands_rejected
            self._qos_problems = 0
            return diagnostics.hand_status(
                node_name=node_name,
                received=self.commands_received,
                rejected=self.commands_rejected,
                rejected_in_window=window,
                last_rejection=self.last_rejection,
            )

    def on_incompatible_qos(self, event: Any) -> None:
        """A publisher on ``hand/indentation`` whose QoS cannot match: warn, naming the policy."""
        policy = qos_policy_name_from_kind(event.last_policy_kind)
        self.last_rejection = (
            f"a publisher on {self.command_topic} offers a QoS incompatible with the node's (last "
            f"incompatible policy: {policy}); its commands are not received. Publish reliable."
        )
        self._qos_problems += 1
        self.node.get_logger().warning(self.last_rejection)

    def take_commands(self) -> None:
        """Handle every hand command waiting on the subscription (live thread), taken
        serialised: read with ``struct`` (rclpy's message object costs ~14 us per take at 16
        contacts) and logged as received (the writer thread need not serialise it again)."""
        take = self.subscription.handle.take_message
        while (taken := take(HandCommand, True)) is not None:
            self.on_raw_command(taken[0])

    def on_raw_command(self, payload: bytes) -> None:
        """Handle a serialised hand command (see :meth:`handle_command`)."""
        fields = cdr.parse_hand_command(payload)
        if fields is None:  # not the usual little-endian layout: let rclpy read it
            self.on_command(deserialize_message(payload, HandCommand))
            return
        self.handle_command(*fields, payload)

    def _contacts(self, ids: Any) -> list[_Contact]:
        """The contacts a command names, in its order (empty: all, in the scene's order)."""
        contacts = self.node.contacts
        if not ids:
            return [contacts[i] for i in self._order]
        chosen = []
        seen: set[str] = set()
        for k, contact_id in enumerate(ids):
            if contact_id not in contacts:
                raise _HandError(
                    f"contact_ids[{k}] '{contact_id}' is not a contact of this node "
                    f"(contacts: {', '.join(self._order)})",
                    contact_id,
                )
            if contact_id in seen:
                raise _HandError(f"contact_ids[{k}] '{contact_id}' is listed twice", contact_id)
            seen.add(contact_id)
            chosen.append(contacts[contact_id])
        return chosen

    def on_command(self, msg: HandCommand) -> None:
        """Handle a hand command message object (see :meth:`handle_command`)."""
        stamp = msg.header.stamp
        self.handle_command(stamp.sec, stamp.nanosec, msg.contact_ids, msg.mode, msg.depth, msg.force, msg)

    def handle_command(
        self,
        sec: int,
        nanosec: int,
        ids: Sequence[str],
        mode: int,
        depth: Sequence[float],
        force: Sequence[float],
        received: Any,
    ) -> None:
        """Step every contact of the command to its stamp (or the latest of their times when
        later) and publish one HandState stamped with that time, or reject it (no contact
        changes, one ContactEvent on ``hand/events`` with the reason). ``received``: the command
        as it came, a message object or its CDR payload, for the log."""
        node = self.node
        try:
            contacts = self._contacts(ids)
        except _HandError as error:
            with node.hand_lock:
                now_ns = node.now_ns()
                self._record(received, now_ns)
                index = self.commands_seen
                self.commands_seen = index + 1
                self._reject(str(error), error.contact_id, index, Time(sec=sec, nanosec=nanosec), now_ns)
            return
        # Sorted, as the parameter callback takes several contacts' locks.
        locked = self._by_id if not ids else sorted(contacts, key=_contact_id)
        with node.hand_lock:
            for contact in locked:
                contact.lock.acquire()
            try:
                self._handle_locked(contacts, sec, nanosec, mode, depth, force, received)
            finally:
                for contact in reversed(locked):
                    contact.lock.release()

    def _record(self, received: Any, now_ns: int) -> None:
        """Log a hand command as it came (a CDR payload or a message object)."""
        if isinstance(received, bytes):
            self.node.record_cdr(self.command_topic, cdr.HAND_COMMAND, received, now_ns)
        else:
            self.node.record(self.command_topic, received, now_ns)

    def _handle_locked(
        self,
        contacts: list[_Contact],
        sec: int,
        nanosec: int,
        mode: int,
        depth: Sequence[float],
        force: Sequence[float],
        received: Any,
    ) -> None:
        """:meth:`handle_command` with the hand's and the contacts' locks held."""
        node = self.node
        now_ns = node.now_ns()
        self._record(received, now_ns)
        index = self.commands_seen
        self.commands_seen = index + 1
        for contact in contacts:
            contact._check_clock_locked(now_ns)
        culprit = ""
        try:
            values = self._values(mode, depth, force, contacts)
            stamp_ns = 0
            for contact in contacts:
                culprit = contact.id
                stamp_ns = contact._command_stamp_locked(sec, nanosec, now_ns)
            culprit = ""
            # One time for the whole sample: the stamp, or the latest of the contacts' times
            # when one is later (see _Contact._applied_ns), so HandState's one stamp is the time
            # every row describes and no contact's time goes back.
            at_ns = max(contact._applied_ns(stamp_ns) for contact in contacts)
            epochs = [at_ns if c.last_command_ns is None else c.epoch_ns for c in contacts]
            targets = [(at_ns - epoch_ns) * 1e-9 for epoch_ns in epochs]
            started = time.perf_counter()
            outputs = step_contacts([c.simulator for c in contacts], targets, mode, values)
            spent = (time.perf_counter() - started) / len(contacts)
        except _HandError as error:
            self._reject(str(error), error.contact_id, index, Time(sec=sec, nanosec=nanosec), now_ns)
            return
        except ContactStepError as error:
            culprit = contacts[error.index].id
            reason = f"contact '{culprit}': {error}"
            self._reject(reason, culprit, index, Time(sec=sec, nanosec=nanosec), now_ns)
            return
        except ValueError as error:
            reason = f"contact '{culprit}': {error}" if culprit else str(error)
            self._reject(reason, culprit, index, Time(sec=sec, nanosec=nanosec), now_ns)
            return
        key = "depth" if mode == HandCommand.DEPTH else "force"
        for contact, epoch_ns, value in zip(contacts, epochs, values, strict=True):
            contact.counters.steps.add(spent)
            contact.accepted_locked(epoch_ns, stamp_ns, at_ns, now_ns, {key: float(value)}, count=False)
        self.commands_received += 1
        payload = cdr.pack_hand_state(
            at_ns,
            node.frame_id,
            [c.id for c in contacts],
            _hand_columns(outputs, [c.simulator.model for c in contacts]),
            self.commands_received,
            self.commands_rejected,
        )
        self.state_pub.publish(payload)
        node.record_cdr(self.state_topic, cdr.HAND_STATE, payload, now_ns)

    @staticmethod
    def _values(mode: int, depth: Sequence[float], force: Sequence[float], contacts: list[_Contact]) -> Any:
        """The mode's values, one finite number per contact; _HandError otherwise."""
        count = len(contacts)
        if mode == HandCommand.DEPTH:
            name, values, other_name, other = "depth", depth, "force", force
        elif mode == HandCommand.FORCE:
            name, values, other_name, other = "force", force, "depth", depth
        else:
            raise _HandError(
                f"mode must be DEPTH ({HandCommand.DEPTH}) or FORCE ({HandCommand.FORCE}) (got {mode})"
            )
        if len(values) != count:
            raise _HandError(f"{name} has {len(values)} values for {count} contacts")
        if len(other) not in (0, count):
            raise _HandError(f"{other_name} has {len(other)} values for {count} contacts (give 0 or {count})")
        for k, value in enumerate(values):
            if not math.isfinite(value):
                raise _HandError(
                    f"{name}[{k}] (contact '{contacts[k].id}') must be finite (got {value})", contacts[k].id
                )
        return values

    def _reject(self, reason: str, contact_id: str, index: int, stamp: Any, now_ns: int) -> None:
        """Count, warn about and publish (and log) a rejected hand command."""
        node = self.node
        reason = f"hand command rejected: {reason}"
        self.commands_rejected += 1
        self.last_rejection = reason
        node.get_logger().warning(reason, throttle_duration_sec=WARN_THROTTLE_S)
        event = ContactEvent(
            kind=ContactEvent.COMMAND_REJECTED, contact_id=contact_id, command_index=index, reason=reason
        )
        event.header.stamp = conversions.ns_to_stamp(now_ns)
        event.header.frame_id = node.frame_id
        event.command_stamp = stamp
        self.events_pub.publish(event)
        node.record(self.events_topic, event, now_ns)


class _HandError(InputError):
    """A hand command refused before any step; ``contact_id``: the contact it names, or ""."""

    def __init__(self, message: str, contact_id: str = "") -> None:
        super().__init__(message)
        self.contact_id = contact_id


def _hand_columns(outputs: list[StepOutput], models: list[str]) -> dict[str, Any]:
    """HandState's per-contact arrays from the step outputs."""
    rows = [_STATE_OUTPUTS(output) for output in outputs]
    columns: dict[str, Any] = dict(zip(conversions.STATE_OUTPUT_FIELDS, zip(*rows, strict=True), strict=True))
    columns["model"] = [conversions.MODEL_CODES[m] for m in models]
    return columns


_contact_id = operator.attrgetter("id")
#: The StepOutput fields a HandState carries, as a tuple per output.
_STATE_OUTPUTS = operator.attrgetter(*conversions.STATE_OUTPUT_FIELDS)


class _LiveGroup(CallbackGroup):
    """Callback group of the live path's entities: never run by an executor (the executors
    leave out of their wait sets every entity whose group cannot execute), only by
    :class:`_LiveLoop`."""

    def can_execute(self, entity: Any) -> bool:
        return False

    def beginning_execution(self, entity: Any) -> bool:
        return False

    def ending_execution(self, entity: Any) -> None:
        return None


class _LiveLoop:
    """The node's live thread: one raw wait set over every contact's command subscription and
    hold timer, the node's ``/clock`` subscription (under ``use_sim_time``) and a guard
    condition that stops it.

    ``/clock`` is served here, before the commands taken in the same wake-up, so a command
    received after a clock tick is handled on that tick's time, as on one executor; left to
    the executor thread, the tick would race the command.

    No executor: rclpy's Python executor builds a wait set, tasks and coroutines for every
    callback; taking each message straight off its subscription costs a few microseconds. The
    wait releases the GIL, so the thread costs nothing while no command arrives.
    """

    def __init__(self, node: ViscoadhNode) -> None:
        self._node = node
        self._contacts = list(node.contacts.values())
        self._wake = GuardCondition(None, None, context=node.context)
        self._stopping = False
        self._wake_destroyed = False
        self.error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="viscoadh-live", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self, timeout: float | None = None) -> bool:
        """Stop the thread and wait for it, at most ``timeout`` s (None: until it stops);
        False when it is still running (inside a step: the kernels release the GIL, so the
        caller goes on; the thread ends at its next use of a destroyed entity, and is a daemon,
        so it does not hold the process). Idempotent."""
        self._stopping = True
        if self._thread.is_alive():
            if not self._wake_destroyed:
                self._wake.trigger()
            self._thread.join(timeout)
            if self._thread.is_alive():
                return False  # its wait set may still hold the guard condition: kept
        if not self._wake_destroyed:
            self._wake_destroyed = True
            self._wake.destroy()
        return True

    def _clock_subscription(self) -> Any:
        """The node's ``/clock`` subscription, if ``use_sim_time`` made one, moved to this thread
        (executors skip it from now on). rclpy creates and destroys it on the executor thread
        when ``use_sim_time`` changes, so it is looked up on every wake-up."""
        for subscription in self._node.subscriptions:
            if subscription.msg_type is Clock:
                subscription.callback_group = self._node.live_group
                return subscription
        return None

    def _run(self) -> None:
        contacts = self._contacts
        hand = self._node.hand
        # The command subscriptions' QoS event handlers (an incompatible publisher): served here.
        events = list(hand.subscription.event_handlers)
        for contact in contacts:
            events.extend(contact.subscription.event_handlers)
        wait_set = _rclpy.WaitSet(
            len(contacts) + 2, 1, len(contacts), 0, 0, len(events), self._node.context.handle
        )
        events_due = 0  # time.monotonic_ns() from which the next wait holds the QoS events
        try:
            while not self._stopping:
                wait_set.clear_entities()
                with contextlib.ExitStack() as in_use:
                    clock = self._clock_subscription()
                    if clock is not None:
                        try:
                            # Held while in the wait set: the executor thread may destroy it.
                            in_use.enter_context(clock.handle)
                            wait_set.add_subscription(clock.handle)
                        except InvalidHandle:
                            clock = None
                    wait_set.add_subscription(hand.subscription.handle)
                    for contact in contacts:
                        wait_set.add_subscription(contact.subscription.handle)
                        wait_set.add_timer(contact.timer.handle)
                    # The QoS events (an incompatible publisher, rare) join one wait in
                    # EVENTS_PERIOD_NS: putting 17 handlers in the wait set and asking each
                    # whether it is ready cost ~90 us of the ~150 us a wake-up took (at 16
                    # contacts), at every command. An event waits at most that long.
                    until_events = events_due - time.monotonic_ns()
                    with_events = until_events <= 0
                    if with_events:
                        for handler in events:
                            in_use.enter_context(handler)
                            handler.add_to_wait_set(wait_set)
                    wait_set.add_guard_condition(self._wake.handle)
                    wait_set.wait(-1 if with_events else until_events)
                    if self._stopping:
                        return
                    if with_events:
                        events_due = time.monotonic_ns() + EVENTS_PERIOD_NS
                        for handler in events:
                            if handler.is_ready(wait_set):
                                status = handler.take_data()
                                if status:
                                    handler.callback(status)
                    ready = wait_set.get_ready_entities("subscription")
                    if clock is not None and clock.handle.pointer in ready:
                        while (taken := clock.handle.take_message(Clock, clock.raw)) is not None:
                            clock.callback(taken[0])
                if hand.subscription.handle.pointer in ready:
                    hand.take_commands()
                for contact in contacts:
                    if contact.subscription.handle.pointer in ready:
                        contact.take_commands()
                ready = wait_set.get_ready_entities("timer")
                for contact in contacts:
                    if contact.timer.handle.pointer in ready:
                        contact.timer.handle.call_timer()
                        contact.on_timer()
        except BaseException as error:
            # Not a bad command (those are rejected in on_command): a bug or a dead context.
            # Record it so main() stops the node rather than serve services without a live path.
            # rclpy's SIGINT/SIGTERM handler shuts the context down under a running thread: a
            # publish or wait that fails then is the end of the run, not an error.
            if not self._stopping and self._node.context.ok():
                self.error = error
                self._node.get_logger().fatal(f"live thread stopped: {error!r}")
                raise


class ViscoadhNode(Node):
    """The ``viscoadh`` node. Keyword arguments go to :class:`rclpy.node.Node` (``context``,
    ``parameter_overrides``, ``namespace``, ...), except ``freeze``: when true, the objects
    alive once the node is built are frozen (:func:`freeze_start_up_objects`) before its live
    thread starts; for the one node of a process, as :func:`main` makes it.

    Raises ConfigError (naming the key) when the scene in the parameters is invalid.
    """

    def __init__(self, *, freeze: bool = False, **kwargs: Any) -> None:
        started = time.perf_counter()
        super().__init__(NODE_NAME, automatically_declare_parameters_from_overrides=True, **kwargs)
        self.scene: SceneConfig = parameters.scene_from_node(self)
        parameters.declare_scene(self, self.scene)
        self.frame_id = self.scene.node.frame_id
        self.payloads = conversions.LivePayloads(self.frame_id)
        self.markers_enabled = self.scene.node.markers_enabled
        self.max_future_ns = round(self.scene.node.command_max_future_s * _NS_PER_S)
        self.command_qos = command_qos(self.scene.node.command_queue_depth)
        # MCAP logging; None while logging is off. Opened before the endpoints exist, so the
        # log holds every command received and every state and wrench published.
        events_qos = TopicQos(depth=EVENTS_QOS.depth, durability="transient_local")
        events_topics = [f"{c.id}/events" for c in self.scene.contacts] + ["hand/events"]
        self._recorder: Recorder | None = _open_recorder(
            self.scene, {self.resolve_topic_name(topic): events_qos for topic in events_topics}
        )
        # Compile/load every numba kernel before the first command can arrive (~0.2 s).
        warm_up()
        warmed = time.perf_counter()
        self.services_group = ReentrantCallbackGroup()
        self.live_group = _LiveGroup()
        self.contacts = {c.id: _Contact(self, c) for c in self.scene.contacts}
        # Held around a hand command (and nothing else): the hand's counters and event order.
        self.hand_lock = threading.Lock()
        self.hand = _Hand(self)
        self._jump_handler = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-1)),
            post_callback=self._on_clock_jump,
        )
        self._parameter_lock = threading.Lock()
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, "/diagnostics", _QOS_DEPTH)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics)
        self._live = _LiveLoop(self)
        if freeze:
            # Before the live thread starts: the collection holds the GIL for 0.1-0.5 s (1e6
            # objects, a loaded machine), which would stop the first commands.
            freeze_start_up_objects()
        self._live.start()
        self.get_logger().info(
            f"ready in {time.perf_counter() - started:.3f} s (numba warm-up "
            f"{warmed - started:.3f} s); contacts: "
            + ", ".join(f"{c.id} [{c.simulator.model}]" for c in self.contacts.values())
        )

    @property
    def logging(self) -> bool:
        """Whether an MCAP log is being written."""
        return self._recorder is not None

    @property
    def live_error(self) -> BaseException | None:
        """The exception that stopped the live thread, if one did (the node is then broken)."""
        return self._live.error

    def now_ns(self) -> int:
        """Node clock (ROS time under ``use_sim_time``), ns: read off the rcl clock directly
        (``Clock.now()`` builds and validates a Time object, ~5 us on the live path)."""
        handle = self.get_clock().handle
        with handle:
            return handle.get_now().nanoseconds

    def _on_clock_jump(self, jump: TimeJump) -> None:
        """ROS time went back (``/clock`` of a looping bag): reset every contact."""
        for contact in self.contacts.values():
            with contact.lock:
                contact.clock_jumped_locked(-jump.delta.nanoseconds * 1e-9)

    def record(self, topic: str, msg: Any, stamp_ns: int) -> None:
        """Hand a received or published message to the recorder, if logging is on.

        The live path builds (or takes) a fresh message object per command and never changes it
        after publishing it, so the message is handed over: serialised on the recorder's thread,
        not on the live one.
        """
        if self._recorder is not None:
            self._recorder.record(topic, msg, stamp_ns, handed_over=True)

    def record_cdr(self, topic: str, type_name: str, payload: bytes, stamp_ns: int) -> None:
        """Hand a published payload (CDR of a ``type_name`` message) to the recorder, if on."""
        if self._recorder is not None:
            self._recorder.record_cdr(topic, type_name, payload, stamp_ns)

    def _publish_diagnostics(self) -> None:
        statuses = [contact.status() for contact in self.contacts.values()]
        hand = self.hand
        if hand.commands_seen or hand.last_rejection:
            statuses.append(hand.status(self.get_fully_qualified_name()))
        if self._recorder is not None:
            statuses.append(
                diagnostics.log_status(
                    node_name=self.get_fully_qualified_name(),
                    written=self._recorder.written,
                    dropped=self._recorder.dropped,
                    error=self._recorder.error,
                )
            )
        self.diagnostics_pub.publish(diagnostics.diagnostic_array(statuses, stamp_ns=self.now_ns()))

    def _on_set_parameters(self, changed: list[Parameter]) -> SetParametersResult:
        """Validate a runtime change through the scene schema and apply it, or refuse it.

        Node-level ``publish_rate``, ``frame_id`` and ``markers.enabled`` apply at once. A
        contact's physics can change only while that contact is out of touch and relaxed
        (``is_idle``): its simulator is replaced, which would otherwise discard a live state.
        """
        ids = tuple(self.contacts)
        flat = self.scene.to_parameters()
        touched: set[str] = set()
        for parameter in changed:
            owner = parameters.classify_change(parameter.name, ids)
            if owner is None:
                return self._refuse_change(parameters.not_a_scene_parameter(parameter.name), touched)
            if owner == "" and parameter.name not in parameters.RUNTIME_NODE_PARAMETERS:
                return self._refuse_change(f"{parameter.name} cannot change while the node runs", touched)
            if owner:
                touched.add(owner)
            flat[parameter.name] = parameter.value
        try:
            scene = SceneConfig.from_parameters(flat)
            # Every touched contact's simulator is built before any contact changes: a scene the
            # schema accepts may still be one the model cannot run (numerics.model closed_form
            # on a body with memory), and that must refuse the change, not stop the node.
            simulators = {cid: ContactSimulator(scene.contact(cid)) for cid in sorted(touched)}
        except (ConfigError, InputError) as error:
            return self._refuse_change(str(error), touched)
        with self._parameter_lock, contextlib.ExitStack() as stack:
            for contact_id in sorted(touched):
                stack.enter_context(self.contacts[contact_id].lock)
            for contact_id in sorted(touched):
                if not self.contacts[contact_id].simulator.is_idle:
                    return self._refuse_change(
                        f"contact '{contact_id}' is in contact or still relaxing; change its "
                        "parameters when it is out of touch and relaxed (or after "
                        f"{contact_id}/reset)",
                        touched,
                        locked=True,
                    )
            for contact_id in touched:
                self.contacts[contact_id].replace_config_locked(
                    scene.contact(contact_id), simulators[contact_id], scene
                )
            if self._recorder is not None:
                # After the PARAMETERS events and before the touched contacts' next commands (their
                # locks are held): a file the recorder starts from here on names the new scene.
                self._recorder.set_scene(scene.to_dict())
        if scene.node.publish_rate != self.scene.node.publish_rate:
            for contact in self.contacts.values():
                contact.set_publish_rate(scene.node.publish_rate)
        self.frame_id = scene.node.frame_id
        if self.payloads.frame_id != self.frame_id:
            self.payloads = conversions.LivePayloads(self.frame_id)
        self.markers_enabled = scene.node.markers_enabled
        self.max_future_ns = round(scene.node.command_max_future_s * _NS_PER_S)
        self.scene = scene
        return SetParametersResult(successful=True)

    def _refuse_change(self, reason: str, touched: set[str], *, locked: bool = False) -> SetParametersResult:
        """Refuse a runtime parameter change: nothing changes. The refusal is answered to the
        caller, warned on the node's log and, for each contact the change named, published and
        logged as a PARAMETERS_REFUSED event (``locked``: the caller holds those contacts' locks)."""
        self.get_logger().warning(f"parameter change refused: {reason}")
        now_ns = self.now_ns()
        for contact_id in sorted(touched):
            contact = self.contacts[contact_id]
            with contextlib.nullcontext() if locked else contact.lock:
                contact.event_locked(
                    ContactEvent.PARAMETERS_REFUSED, now_ns, reason=f"parameter change refused: {reason}"
                )
        return SetParametersResult(successful=False, reason=reason)

    def destroy_node(self) -> None:
        # Stop the live thread first: it uses the subscriptions, timers and publishers. A step
        # still running after STOP_WAIT_S is abandoned (its answer is never published).
        if not self._live.stop(STOP_WAIT_S):
            self.get_logger().warning(
                f"the live thread was still in a step {STOP_WAIT_S:g} s after the stop: not waiting for it"
            )
        if self._recorder is not None:
            self._recorder.close()
            self._recorder = None
        super().destroy_node()


def _open_recorder(scene: SceneConfig, qos: dict[str, TopicQos]) -> McapRecorder | None:
    """The MCAP recorder the scene's ``log.*`` parameters ask for (None when logging is off);
    ``qos``: offered QoS of the topics that differ from the default (``C/events``).

    The whole scene goes into the file's metadata record, so the log alone replays the run.
    """
    node = scene.node
    if not node.log_enabled:
        return None
    return McapRecorder(
        node.log_path,
        scene=scene.to_dict(),
        chunk_size=node.log_chunk_size,
        max_bytes=node.log_max_bytes,
        max_duration=node.log_max_duration,
        queue_size=node.log_queue_size,
        qos=qos,
    )


#: Retract speeds predict_pull_off accepts, m/s: slower, the retraction would not reach
#: pull-off in a representable time; faster, nothing physical retracts.
RETRACT_SPEED_RANGE = (1e-12, 1e3)


def _retract_speed(value: float) -> float:
    """``retract_speed`` as a float in :data:`RETRACT_SPEED_RANGE`, else InputError."""
    low, high = RETRACT_SPEED_RANGE
    speed = float(value)
    if not low <= speed <= high:
        raise InputError(f"retract_speed must be in [{low:g}, {high:g}] m/s (got {speed:g})")
    return speed


def freeze_start_up_objects() -> None:
    """Collect once, then move every object alive after start-up out of the collector's reach
    (``gc.freeze``): rclpy, numba, numpy and the node's own objects (~10^5-10^6) are never
    garbage, yet each full collection walked them all, stopping the live thread for 84-425 ms
    (0.4.0 under 16 contacts x 1 kHz on the loaded bench machine: about one a minute, measured
    with ``gc.callbacks``, while the command queue held 10 ms of commands). The collector still
    runs, over what the node creates afterwards. Called once per process, by the node
    :func:`main` builds, before its live thread starts (a process that makes many nodes, such
    as the test suite, must not freeze their leftovers)."""
    gc.collect()
    gc.freeze()


def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or shutdown (console script ``viscoadh_node``).

    The node's own thread serves the live path; the main thread spins a MultiThreadedExecutor
    for services, parameters and diagnostics. Returns 0, 2 with one error line when the scene
    in the parameters is invalid, 1 when the live thread failed.
    """
    # A command should not wait up to CPython's default 5 ms for a busy service thread.
    sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    try:
        parameters.check_params_files(list(args or []))
        rclpy.init(args=args)
    except ConfigError as error:
        print(f"viscoadh node: error: {error}", file=sys.stderr, flush=True)
        return 2
    except _rclpy.RCLError as error:
        detail = " ".join(str(error).split())
        print(f"viscoadh node: error: ROS arguments rejected: {detail}", file=sys.stderr, flush=True)
        return 2
    node = None
    code = 0
    try:
        node = ViscoadhNode(freeze=True)
        executor = MultiThreadedExecutor()
        executor.add_node(node)
        while rclpy.ok() and node.live_error is None:
            try:
                executor.spin_once(timeout_sec=0.5)
            except Exception:
                # SIGINT/SIGTERM shut the context down between the check and the wait.
                if rclpy.ok():
                    raise
                break
        if node.live_error is not None:
            print(f"viscoadh node: error: live path failed: {node.live_error!r}", file=sys.stderr, flush=True)
            code = 1
    except ConfigError as error:
        print(f"viscoadh node: error: {error}", file=sys.stderr, flush=True)
        code = 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            logger = node.get_logger()
            node.destroy_node()
            logger.info("finished")
        rclpy.try_shutdown()
        _exit_after(STOP_WAIT_S, code)
    return code


def _exit_after(seconds: float, code: int) -> None:
    """End the process with ``code`` if it has not exited ``seconds`` from now. The
    interpreter's exit waits for the executor's threads, and a service call (a long
    ``simulate_history``) may run for minutes: SIGTERM must still stop the node (0.10.0's
    outside tester needed kill -9). A daemon timer: a process that exits in time never sees
    it. Only for `main`, whose process ends when it returns."""

    def abandon() -> None:
        busy = sorted(
            t.name
            for t in threading.enumerate()
            if t not in (threading.current_thread(), threading.main_thread()) and not t.daemon
        )
        print(
            f"viscoadh node: still busy {seconds:g} s after the stop ({', '.join(busy) or 'exit'}): "
            "exiting without waiting for it",
            file=sys.stderr,
            flush=True,
        )
        sys.stdout.flush()
        os._exit(code)

    timer = threading.Timer(seconds, abandon)
    timer.daemon = True
    timer.start()
