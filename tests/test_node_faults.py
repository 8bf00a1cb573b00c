"""The node under faults, in-process (issue 11): a client node publishes as a controller would.

Each rejected command must leave the contact exactly as a twin simulator fed only the good
commands, say why on ``C/events`` (and in the MCAP log), and never lock the contact out. A new
or reset contact stays out of touch until a command brings it in.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from mcap.reader import make_reader
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from std_srvs.srv import Trigger
from test_node_live import SCENE, TIMEOUT, Client, _command
from viscoadh_msgs.msg import ContactEvent, ContactState, IndentationCommand

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.simulator import ContactSimulator
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.ros.node import ViscoadhNode

#: The test_node_live scene with the default tolerance for stamps ahead of the clock (1 s).
FAULT_SCENE = {k: v for k, v in SCENE.items() if k != "command.max_future_s"}


def _node(context: Any, executor: Any, scene: dict[str, Any] = FAULT_SCENE, **kwargs: Any) -> ViscoadhNode:
    overrides = [Parameter(name, value=value) for name, value in scene.items()]
    node = ViscoadhNode(context=context, parameter_overrides=overrides, **kwargs)
    executor.add_node(node)
    return node


class EventClient(Client):
    """A client that also listens to the contact's events (as a late joiner would)."""

    def __init__(
        self, *args: Any, contact: str = "elastic", ahead_ns: int = 300_000_000, **kwargs: Any
    ) -> None:
        super().__init__(*args, contact=contact, **kwargs)
        self.events: list[ContactEvent] = []
        self.node.create_subscription(ContactEvent, f"{contact}/events", self.events.append, 50)
        # Stamps ahead of the clock (by default within the default tolerance of 1 s): the hold
        # timer advances a contact only up to now.
        self.t0 = self.node.get_clock().now().nanoseconds + ahead_ns

    def rejected(self, index: int) -> ContactEvent:
        """Wait for the COMMAND_REJECTED event of command ``index``."""

        def event() -> ContactEvent | None:
            return next((e for e in self.events if e.command_index == index and e.kind == 1), None)

        assert self.spin_until(self.executor, lambda: event() is not None, TIMEOUT), f"no event {index}"
        return event()


def _twin(contact: str, scene: dict[str, Any] = FAULT_SCENE) -> ContactSimulator:
    return ContactSimulator(SceneConfig.from_parameters(scene).contact(contact))


@pytest.mark.parametrize(
    "future_ns, what",
    [(3600 * 10**9, "+1 h"), (None, "2038")],
)
def test_a_command_stamped_far_ahead_is_rejected_and_does_not_lock_the_contact(
    ros_context: Any, ros_executor: Any, spin_until: Any, future_ns: int | None, what: str
) -> None:
    node = _node(ros_context, ros_executor)
    client = EventClient(ros_context, ros_executor, spin_until)
    assert client.send(_command(client.t0, depth=5e-6)) is not None
    far = (2**31 - 1) * 10**9 if future_ns is None else node.now_ns() + future_ns
    assert client.send(_command(far, depth=8e-6), expect_state=False) is None, what
    event = client.rejected(1)
    assert "ahead of the node clock" in event.reason and "command.max_future_s" in event.reason, event.reason
    after = client.send(_command(client.t0 + 10_000_000, depth=6e-6))
    assert after is not None, f"{what}: a normal command after the far one must be accepted"
    twin = _twin("elastic")
    twin.step(0.0, depth=5e-6)
    expected = twin.step(0.01, depth=6e-6)
    assert after.force == pytest.approx(expected.force, rel=1e-12), what
    assert (after.commands_received, after.commands_rejected) == (2, 1)


def test_a_tension_beyond_the_pull_off_lets_go_and_is_not_a_rejection(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """docs/ros_interface.md: a force the contact cannot hold in tension is accepted and lets
    the indenter go (force 0, NO_CONTACT, unstable), with no COMMAND_REJECTED event; while it
    is off every tension is answered the same way; a compressive force touches again. The
    answers equal the core's on the same commands (outside tester: 0.5.0's docs promised a
    rejection)."""
    _node(ros_context, ros_executor, {**FAULT_SCENE, "command.max_future_s": 30.0})
    client = EventClient(ros_context, ros_executor, spin_until, contact="visco", ahead_ns=10 * 10**9)
    twin = _twin("visco")
    forces = [1e-3, -10.0, -1e-3, 1e-3]
    states = []
    for k, force in enumerate(forces):
        states.append(
            client.send(_command(client.t0 + k * 10_000_000, force=force, mode=IndentationCommand.FORCE))
        )
        expected = twin.step(k * 0.01, force=force)
        assert states[-1] is not None, f"command {k} ({force} N) was not answered"
        # Within the force search's tolerance, not bit for bit: on the re-touch the node's
        # answer and the core's differ in the last bits (5e-18 N of 1 mN when written).
        assert states[-1].force == pytest.approx(expected.force, rel=1e-9, abs=1e-12), k
        assert (states[-1].phase, states[-1].unstable) == (int(expected.phase), expected.unstable), k
    touched, pulled, still_off, again = states
    assert touched.phase != ContactState.NO_CONTACT and touched.force == pytest.approx(1e-3, rel=1e-3)
    for off in (pulled, still_off):
        assert (off.force, off.contact_radius, off.phase, off.unstable) == (
            0.0,
            0.0,
            ContactState.NO_CONTACT,
            True,
        )
    assert again.phase != ContactState.NO_CONTACT and again.force == pytest.approx(1e-3, rel=1e-3)
    assert again.commands_rejected == 0
    assert not [e for e in client.events if e.kind == ContactEvent.COMMAND_REJECTED]


def test_the_future_tolerance_changes_at_runtime(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    node = _node(ros_context, ros_executor)
    client = EventClient(ros_context, ros_executor, spin_until)
    ahead = node.now_ns() + 3 * 10**9
    assert client.send(_command(ahead, depth=1e-6), expect_state=False) is None, "3 s ahead > 1 s"
    assert node.set_parameters([Parameter("command.max_future_s", value=10.0)])[0].successful
    assert client.send(_command(ahead, depth=1e-6)) is not None, "3 s ahead <= 10 s"


@pytest.mark.parametrize(
    "sec, nanosec", [(-(2**31), 0), (-1, 999_999_999), (5, 1_000_000_000), (5, 2**32 - 1)]
)
def test_a_malformed_stamp_is_rejected(
    ros_context: Any, ros_executor: Any, spin_until: Any, sec: int, nanosec: int
) -> None:
    _node(ros_context, ros_executor)
    client = EventClient(ros_context, ros_executor, spin_until)
    msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=1e-6)
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    assert client.send(msg, expect_state=False) is None
    assert "sec >= 0 and nanosec < 1000000000" in client.rejected(0).reason
    assert client.send(_command(client.t0, depth=1e-6)) is not None, "the contact is not locked"


def test_a_refused_huge_depth_leaves_the_contact_as_its_twin(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """Time-stepped contact (a standard solid): 1e10 m cannot be represented by its domain.
    Stamps 10 s ahead, so the hold timer never relaxes it between the commands."""
    _node(ros_context, ros_executor, {**FAULT_SCENE, "command.max_future_s": 30.0})
    client = EventClient(ros_context, ros_executor, spin_until, contact="visco", ahead_ns=10 * 10**9)
    twin = _twin("visco")
    depths = [5e-6, 1.2e-5, 2e-5]
    for k, depth in enumerate(depths):
        client.send(_command(client.t0 + k * 10_000_000, depth=depth))
        twin.step(k * 0.01, depth=depth)
    assert client.send(_command(client.t0 + 30_000_000, depth=1e10), expect_state=False) is None
    reason = client.rejected(3).reason
    assert "largest domain" in reason and "at most" in reason, reason  # the depth limit (0.8.0)
    after = client.send(_command(client.t0 + 40_000_000, depth=2e-5))
    expected = twin.step(0.04, depth=2e-5)
    assert after.force == expected.force and after.phase == int(expected.phase), (
        f"{after.force} N after the refused command, the twin {expected.force} N"
    )
    assert after.force > 1e-3, "a 20 um press pushes with about 2 mN"


def test_new_and_reset_contacts_stay_out_of_touch_and_take_parameters(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """Depth 0 touches the surface, but no command yet is no contact: the hold timer (here
    100 Hz; the idle heartbeat comes once per second) must not bring the contact in."""
    node = _node(ros_context, ros_executor, {**FAULT_SCENE, "publish_rate": 100.0})
    client = EventClient(ros_context, ros_executor, spin_until)

    def quiet_for(seconds: float) -> list[ContactState]:
        start = len(client.states)
        deadline = time.monotonic() + seconds
        spin_until(ros_executor, lambda: time.monotonic() > deadline, seconds + 1.0)
        return client.states[start:]

    heartbeats = quiet_for(1.5)
    assert heartbeats, "an idle contact still publishes its heartbeat"
    assert all(s.phase == ContactState.NO_CONTACT and s.force == 0.0 for s in heartbeats), [
        (s.phase, s.force) for s in heartbeats
    ]
    assert len(heartbeats) <= 3, f"an idle contact publishes once per second, not {len(heartbeats)}"
    softer = Parameter("elastic.material.glass_shear_modulus", value=5.0e5)
    assert node.set_parameters([softer])[0].successful, "parameters change on a new contact"

    assert client.send(_command(client.t0, depth=5e-6)).phase != ContactState.NO_CONTACT
    assert client.call(client.reset, Trigger.Request()).success
    after_reset = quiet_for(1.5)
    assert all(s.phase == ContactState.NO_CONTACT and s.force == 0.0 for s in after_reset), [
        (s.phase, s.force) for s in after_reset
    ]
    stiffer = Parameter("elastic.material.glass_shear_modulus", value=2.0e6)
    result = node.set_parameters([stiffer])[0]
    assert result.successful, f"parameters change after a reset: {result.reason}"


def test_diagnostics_of_two_namespaced_nodes_are_told_apart(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    from rclpy.node import Node

    _node(ros_context, ros_executor, namespace="left")
    _node(ros_context, ros_executor, namespace="right")
    probe = Node("probe", context=ros_context)
    ros_executor.add_node(probe)
    names: set[str] = set()
    probe.create_subscription(
        DiagnosticArray, "/diagnostics", lambda a: names.update(s.name for s in a.status), 10
    )
    expected = {f"/{ns}/viscoadh: {c}" for ns in ("left", "right") for c in ("elastic", "visco")}
    assert spin_until(ros_executor, lambda: expected <= names, 4.0), names


def test_a_best_effort_command_publisher_is_warned_about_naming_the_qos(
    ros_context: Any, ros_executor: Any, spin_until: Any, capfd: pytest.CaptureFixture[str]
) -> None:
    """Documented choice: commands are reliable; a sensor-data publisher gets a warning."""
    from rclpy.node import Node

    node = _node(ros_context, ros_executor)
    controller = Node("sensor_data_controller", context=ros_context)
    ros_executor.add_node(controller)
    controller.create_publisher(IndentationCommand, "elastic/indentation", qos_profile_sensor_data)
    counters = node.contacts["elastic"].counters
    assert spin_until(ros_executor, lambda: counters.incompatible_publishers == 1, 3.0), (
        "the incompatible publisher was not noticed"
    )
    assert "RELIABILITY" in counters.last_rejection, counters.last_rejection
    assert "RELIABILITY" in capfd.readouterr().err, "the warning must be logged"


def test_events_log_every_rejection_reset_and_parameter_change_in_order(
    ros_context: Any, ros_executor: Any, spin_until: Any, tmp_path: Path
) -> None:
    log = tmp_path / "run.mcap"
    node = _node(ros_context, ros_executor, {**FAULT_SCENE, "log.enabled": True, "log.path": str(log)})
    client = EventClient(ros_context, ros_executor, spin_until)
    t0 = client.t0
    client.send(_command(t0, depth=5e-6))
    bad = _command(t0 + 10_000_000, depth=math.nan)
    client.send(bad, expect_state=False)
    client.send(_command(t0 + 20_000_000, depth=4e-6))
    client.send(_command(t0 + 30_000_000, depth=1e-6, mode=7), expect_state=False)
    nan_event, mode_event = client.rejected(1), client.rejected(3)
    assert nan_event.command_stamp == bad.header.stamp and "depth must be finite" in nan_event.reason
    assert "mode" in mode_event.reason and mode_event.contact_id == "elastic"
    assert client.call(client.reset, Trigger.Request()).success
    changed = Parameter("elastic.adhesion.work_of_adhesion", value=0.2)
    assert node.set_parameters([changed])[0].successful
    client.send(_command(t0 + 40_000_000, depth=5e-6))
    assert spin_until(ros_executor, lambda: len(client.events) == 4, TIMEOUT), client.events
    kinds = [e.kind for e in client.events]
    assert kinds == [ContactEvent.COMMAND_REJECTED] * 2 + [ContactEvent.RESET, ContactEvent.PARAMETERS]
    stored = SceneConfig.from_dict(yaml.safe_load(client.events[-1].contact_yaml))
    assert stored.contacts == (SceneConfig.from_parameters(node.scene.to_parameters()).contact("elastic"),)
    assert stored.contacts[0].adhesion.work_of_adhesion == 0.2

    ros_executor.remove_node(node)
    node.destroy_node()
    with open(log, "rb") as stream:
        summary = make_reader(stream).get_summary()
    schema = next(s for s in summary.schemas.values() if s.name == "viscoadh_msgs/msg/ContactEvent")
    assert "MSG: builtin_interfaces/Time" in schema.data.decode(), "the schema carries its dependencies"
    channel = next(c for c in summary.channels.values() if c.topic == "/elastic/events")
    assert yaml.safe_load(channel.metadata["offered_qos_profiles"])[0]["durability"] == "transient_local"
    bag = Bag(log)
    sequence = [
        (m.topic, getattr(m.msg, "kind", None))
        for m in bag.messages(["/elastic/indentation", "/elastic/events"])
    ]
    assert sequence == [
        ("/elastic/indentation", None),
        ("/elastic/indentation", None),
        ("/elastic/events", ContactEvent.COMMAND_REJECTED),
        ("/elastic/indentation", None),
        ("/elastic/indentation", None),
        ("/elastic/events", ContactEvent.COMMAND_REJECTED),
        ("/elastic/events", ContactEvent.RESET),
        ("/elastic/events", ContactEvent.PARAMETERS),
        ("/elastic/indentation", None),
    ], "the log keeps every command and event in the order they took effect"
    forces = [m.msg.force for m in bag.messages(["/elastic/state"]) if m.msg.commands_received == 3]
    expected = ContactSimulator(stored.contacts[0]).step(0.0, depth=5e-6).force
    np.testing.assert_allclose(forces[-1], expected, rtol=1e-12, err_msg="after the change")


def test_a_rejection_reason_prints_the_stamps_to_the_nanosecond(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """The reason gives both stamps digit for digit (a float printed a 2026 stamp's last
    nanoseconds wrong: ...045717001 for ...045717063)."""
    _node(ros_context, ros_executor)
    client = EventClient(ros_context, ros_executor, spin_until)
    last = client.t0 - client.t0 % 10**9 + 125_717_163
    older = last - 80_000_100
    assert client.send(_command(last, depth=1e-6)) is not None
    assert client.send(_command(older, depth=2e-6), expect_state=False) is None
    reason = client.rejected(1).reason
    for ns in (older, last):
        assert f"{ns // 10**9}.{ns % 10**9:09d} s" in reason, reason


def test_state_stamps_never_go_back_after_a_command_stamped_ahead(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """A command stamped 0.4 s ahead (within command.max_future_s) is answered with its stamp;
    the hold timer (50 Hz here) must not then publish states stamped now, behind it."""
    _node(ros_context, ros_executor, {**FAULT_SCENE, "publish_rate": 50.0})
    client = EventClient(ros_context, ros_executor, spin_until, ahead_ns=400_000_000)
    assert client.send(_command(client.t0, depth=5e-6)) is not None
    deadline = time.monotonic() + 0.6
    spin_until(client.executor, lambda: time.monotonic() > deadline, 2.0)
    stamps = [s.header.stamp.sec * 10**9 + s.header.stamp.nanosec for s in client.states]
    assert len(stamps) >= 2, "the timer published after the clock caught up"
    assert np.all(np.diff(stamps) >= 0), np.diff(stamps)


def test_diagnostics_warn_when_a_press_leaves_the_models_validity(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """A press so deep that the sphere's flank at the contact edge is steep (depth 0.5 R: slope
    ~0.7 > 0.3) is still answered, but /diagnostics says the state is outside the small-slope
    assumption; a shallow press is OK. (Elastic sphere: closed-form path.)"""
    from rclpy.node import Node

    _node(ros_context, ros_executor)
    client = EventClient(ros_context, ros_executor, spin_until)
    probe = Node("probe", context=ros_context)
    ros_executor.add_node(probe)
    statuses: list[Any] = []
    probe.create_subscription(
        DiagnosticArray,
        "/diagnostics",
        lambda a: statuses.extend(s for s in a.status if s.name.endswith(": elastic")),
        10,
    )

    def latest() -> dict[str, str]:
        return {kv.key: kv.value for kv in statuses[-1].values} if statuses else {}

    assert client.send(_command(client.t0, depth=5e-6)) is not None
    statuses.clear()
    assert spin_until(ros_executor, lambda: latest().get("in_contact") == "True", 4.0)
    ok = statuses[-1]
    assert latest()["small_slope_ok"] == "True" and ok.level == DiagnosticStatus.OK, ok.message
    # Stamped ahead of the clock again: waiting for /diagnostics can outlast the first stamp,
    # and a command stamped before a hold tick is answered at the tick's time (send matches the
    # answer by the command's stamp).
    later = max(client.t0 + 10_000_000, client.node.get_clock().now().nanoseconds + 300_000_000)
    assert client.send(_command(later, depth=5e-3)) is not None
    statuses.clear()
    assert spin_until(ros_executor, lambda: bool(statuses), 4.0)
    status = statuses[-1]
    assert latest()["small_slope_ok"] == "False" and status.level == DiagnosticStatus.WARN, status.message
    assert "flank slope" in status.message and "small slopes" in status.message, status.message


def test_a_hold_that_fails_keeps_the_state_and_the_timer_and_the_next_command_is_served(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """Issue 11's untested path: the hold timer's step fails (a held force that creep makes
    unreachable; injected here, since no scene reaches it on cue). The contact keeps its state,
    the timer keeps trying and publishes nothing meanwhile (its last state stands: the kept
    state stamped now would claim a time it does not describe; the first version of this test
    wanted it republished), and the next command is served from the kept state."""
    node = _node(ros_context, ros_executor, {**FAULT_SCENE, "publish_rate": 100.0})
    client = EventClient(ros_context, ros_executor, spin_until, contact="visco", ahead_ns=0)
    # 50 ms ahead of the clock: a rest heartbeat or a hold tick published between reading the
    # clock and the node receiving the command would have it answered at that state's time.
    now = client.node.get_clock().now().nanoseconds + 50_000_000
    pressed = client.send(_command(now, depth=5e-6))
    assert pressed is not None
    held = client.send(_command(now + 1_000_000, mode=IndentationCommand.FORCE, force=pressed.force))
    assert held is not None
    contact = node.contacts["visco"]
    real_step = contact.simulator.step
    failed: list[float] = []

    def hold_fails(time: float, **control: float) -> Any:
        if "force" in control:  # the held force: out of reach from now on
            failed.append(time)
            raise InputError(f"injected: force {control['force']!r} N cannot be reached")
        return real_step(time, **control)

    with contact.lock:
        contact.simulator.step = hold_fails  # the instance's step: the hold timer's calls fail
        kept = contact.simulator.snapshot()

    def sim_time(state: ContactState) -> float:
        return (state.header.stamp.sec * 10**9 + state.header.stamp.nanosec - contact.epoch_ns) * 1e-9

    try:
        assert spin_until(client.executor, lambda: len(failed) >= 3, TIMEOUT), "the timer stopped"
        spin_until(client.executor, lambda: False, 0.1)  # anything published would arrive by now
        published = [s for s in client.states if sim_time(s) >= failed[0]]
        assert not published, "a state stamped after the contact's time while the hold fails"
        assert contact.simulator.snapshot().time == kept.time
        assert all(e.kind != 1 for e in client.events), "a failed hold is not a rejected command"
        # The next command is served from the kept state, exactly as a twin restored to it.
        twin = _twin("visco")
        twin.restore(kept)
        later = client.node.get_clock().now().nanoseconds
        answer = client.send(_command(later, depth=4e-6))
        assert answer is not None
        expected = twin.step((later - contact.epoch_ns) * 1e-9, depth=4e-6)
        assert (answer.depth, answer.force, answer.contact_radius) == (
            expected.depth,
            expected.force,
            expected.contact_radius,
        )
    finally:
        with contact.lock:
            del contact.simulator.step


def test_a_max_substep_too_fine_for_a_step_rejects_the_command_and_the_node_keeps_serving(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """0.10.0's outside tester: `max_substep: 1e-12` set at runtime on the idle contact (accepted:
    the scene alone cannot know the steps), then two commands 10 ms apart: the second never got
    an answer, the other contact and the services stopped answering and SIGTERM could not stop
    the node (one step of 1e10 substeps). Now the second command is rejected naming the fix,
    the contact kept as its twin, and the node serves everything else. Numbers outside a
    numerics range are refused as parameters, as from a scene file."""
    node = _node(ros_context, ros_executor)
    bad = node.set_parameters([Parameter("visco.numerics.elements", value=100_000_000)])[0]
    assert not bad.successful
    bad = node.set_parameters([Parameter("visco.numerics.domain_radius", value=1e300)])[0]
    assert not bad.successful
    fine = node.set_parameters([Parameter("visco.numerics.max_substep", value=1e-12)])[0]
    assert fine.successful, fine.reason
    client = EventClient(ros_context, ros_executor, spin_until, contact="visco")
    fine_scene = SceneConfig.from_parameters({**FAULT_SCENE, "visco.numerics.max_substep": 1e-12})
    twin = ContactSimulator(fine_scene.contact("visco"))
    first = client.send(_command(client.t0, depth=5e-6))
    assert first is not None and first.force == twin.step(0.0, depth=5e-6).force
    assert client.send(_command(client.t0 + 10_000_000, depth=6e-6), expect_state=False) is None
    reason = client.rejected(1).reason
    assert "numerics.max_substep" in reason and "at least 1e-06 s" in reason, reason
    # Steps of at most 10000 substeps (10 ns here) are served, from the kept state.
    after = client.send(_command(client.t0 + 5, depth=5.0e-6 + 1e-12))
    assert after is not None and after.force == twin.step(5 * 1e-9, depth=5.0e-6 + 1e-12).force
    other = EventClient(ros_context, ros_executor, spin_until, contact="elastic")
    assert other.send(_command(other.t0, depth=5e-6)) is not None, "the other contact answers"
    assert client.call(client.reset, Trigger.Request()).success, "the services answer"


def test_a_stop_does_not_wait_for_a_step_that_runs_on(
    ros_context: Any, ros_executor: Any, spin_until: Any
) -> None:
    """SIGINT/SIGTERM end in `destroy_node`, which stopped the live thread and waited for it: a
    step that did not end (0.10.0's max_substep 1e-12) kept the node running until kill -9.
    Steps are bounded now, but a large scene's may take seconds: the stop waits at most
    STOP_WAIT_S for it (the step, blocked here on cue, then ends on its own)."""
    from viscoadh_ros.ros import node as node_module

    node = _node(ros_context, ros_executor)
    client = EventClient(ros_context, ros_executor, spin_until, contact="visco")
    contact = node.contacts["visco"]
    real_step = contact.simulator.step
    entered, release = node_module.threading.Event(), node_module.threading.Event()

    def long_step(time: float, **control: float) -> Any:
        entered.set()
        release.wait(60.0)
        return real_step(time, **control)

    contact.simulator.step = long_step
    try:
        client.pub.publish(_command(client.t0, depth=5e-6))
        assert spin_until(ros_executor, entered.is_set, TIMEOUT), "the command reached no step"
        assert not node._live.stop(0.0), "the live thread is in the step"
        ros_executor.remove_node(node)
        node.destroy_node()  # returns though the step runs on
        assert node._live._thread.is_alive()
    finally:
        release.set()
    node._live._thread.join(60.0)
    assert not node._live._thread.is_alive(), "the step ended and the thread with it"
    assert node._live.error is None, "a stop is not a live-path failure"
