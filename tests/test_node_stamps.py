"""The node on a simulated clock, as a controller meets it: every published state is stamped with
the time it describes, C/state stamps never go back, and the hold timer publishes nothing
extra while commands keep coming at its rate, whatever their stamps.

Outside tester (against 0.8.0, node in another process): with the clock run to 1.100 s under
the hold timer, a command stamped 1.095 s was applied at 1.100 s but answered stamped 1.095 s
(C/state stamps went back, and the state was labelled with a time it does not describe); with
commands every 10 ms stamped 10 ms ahead of the clock, the timer republished the state at the
same stamp with identical values for 59 of 120 commands (36 extra c0/state under hand
commands). The references are the core stepped directly on the times the node reports.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from test_node_live import SCENE, T0_NS
from viscoadh_msgs.msg import ContactState, HandCommand, HandState, IndentationCommand

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator
from viscoadh_ros.ros.conversions import ns_to_stamp, stamp_to_ns
from viscoadh_ros.ros.node import ViscoadhNode

TIMEOUT = 5.0
MS = 1_000_000
#: 50 Hz: the hold timer's period is 20 ms of the simulated clock.
PERIOD_NS = 20 * MS
IDS = ["elastic", "visco"]


def _reference(contact: str) -> ContactSimulator:
    return ContactSimulator(SceneConfig.from_parameters(SCENE).contact(contact))


def _outputs(state: Any, k: int | None = None) -> tuple[float, ...]:
    """depth, force, contact radius of a ContactState, or of row ``k`` of a HandState."""
    if k is None:
        return (state.depth, state.force, state.contact_radius)
    return (state.depth[k], state.force[k], state.contact_radius[k])


class _SimClockClient:
    """A controller on ``/clock``: a node on simulated time at 50 Hz, commands on C/indentation
    and hand/indentation, every C/state and hand/state collected in arrival order."""

    def __init__(self, context: Any, executor: Any, spin_until: Any) -> None:
        overrides = [Parameter(n, value=v) for n, v in SCENE.items()]
        overrides += [Parameter("use_sim_time", value=True), Parameter("publish_rate", value=50.0)]
        self.server = ViscoadhNode(context=context, parameter_overrides=overrides)
        executor.add_node(self.server)
        self.executor, self.spin_until = executor, spin_until
        self.node = Node("sim_clock_client", context=context)
        executor.add_node(self.node)
        self.clock = self.node.create_publisher(Clock, "/clock", 10)
        self.single = {
            i: self.node.create_publisher(IndentationCommand, f"{i}/indentation", 100) for i in IDS
        }
        self.hand = self.node.create_publisher(HandCommand, "hand/indentation", 100)
        self.states: dict[str, list[ContactState]] = {i: [] for i in IDS}
        self.hand_states: list[HandState] = []
        for i in IDS:
            self.node.create_subscription(ContactState, f"{i}/state", self.states[i].append, 1000)
        self.node.create_subscription(HandState, "hand/state", self.hand_states.append, 1000)
        server = self.server
        assert spin_until(
            executor,
            lambda: (
                self.hand.get_subscription_count() > 0
                and all(p.get_subscription_count() > 0 for p in self.single.values())
                and server.hand.state_pub.get_subscription_count() > 0
                and all(server.contacts[i].state_pub.get_subscription_count() > 0 for i in IDS)
            ),
            TIMEOUT,
        ), "the node's topics did not match"

    def tick(self, ns: int) -> None:
        """Move /clock to ``ns`` and give the hold timer the time to fire on it."""
        self.clock.publish(Clock(clock=ns_to_stamp(ns)))
        assert self.spin_until(self.executor, lambda: self.server.now_ns() == ns, TIMEOUT), "clock"
        deadline = time.monotonic() + 0.02
        self.spin_until(self.executor, lambda: time.monotonic() > deadline, 1.0)

    def send(self, contact: str, stamp_ns: int, depth: float) -> ContactState:
        """One command on C/indentation; the state that answers it (the next commands_received)."""
        got = self.states[contact]
        count = max((s.commands_received for s in got), default=0) + 1
        msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=depth)
        msg.header.stamp = ns_to_stamp(stamp_ns)
        self.single[contact].publish(msg)

        def answer() -> ContactState | None:
            return next((s for s in got if s.commands_received == count), None)

        assert self.spin_until(self.executor, lambda: answer() is not None, TIMEOUT), "no answer"
        return answer()

    def send_hand(self, stamp_ns: int, depths: list[float], ids: list[str]) -> HandState:
        """One hand command; its HandState."""
        before = len(self.hand_states)
        msg = HandCommand(mode=HandCommand.DEPTH, depth=depths, contact_ids=ids)
        msg.header.stamp = ns_to_stamp(stamp_ns)
        self.hand.publish(msg)
        assert self.spin_until(self.executor, lambda: len(self.hand_states) > before, TIMEOUT), "no answer"
        return self.hand_states[before]

    def settle(self) -> None:
        """Let whatever the node published arrive."""
        deadline = time.monotonic() + 0.2
        self.spin_until(self.executor, lambda: time.monotonic() > deadline, 1.0)


@pytest.fixture
def client(ros_context: Any, ros_executor: Any, spin_until: Any) -> _SimClockClient:
    return _SimClockClient(ros_context, ros_executor, spin_until)


def _stamps(states: list[Any]) -> list[int]:
    return [stamp_to_ns(s.header.stamp) for s in states]


def _hold_to_last_tick(client: _SimClockClient, contact: str) -> tuple[ContactSimulator, int]:
    """Press ``contact`` in at T0 and run the clock to T0 + 100 ms in 5 ms steps, so that the
    hold timer advances it; returns a reference stepped as the node stepped it (the command,
    then every hold tick at its stamp) and the last tick's stamp."""
    client.tick(T0_NS - 10 * MS)
    pressed = client.send(contact, T0_NS, 5e-6)
    assert stamp_to_ns(pressed.header.stamp) == T0_NS
    for k in range(1, 21):
        client.tick(T0_NS + 5 * MS * k)
    client.settle()
    ticks = [s for s in client.states[contact] if stamp_to_ns(s.header.stamp) > T0_NS]
    assert len(ticks) >= 2, "the hold timer did not advance the contact"
    reference = _reference(contact)
    reference.step(0.0, depth=5e-6)
    for state in ticks:
        held = reference.step((stamp_to_ns(state.header.stamp) - T0_NS) * 1e-9, depth=5e-6)
        assert _outputs(state) == (held.depth, held.force, held.contact_radius), "hold tick"
    return reference, stamp_to_ns(ticks[-1].header.stamp)


def test_a_command_stamped_before_a_hold_tick_is_answered_at_the_ticks_time(
    client: _SimClockClient,
) -> None:
    """The tester's reproducer: the command applies at the contact's time (the last tick's), and
    its state says so; C/state stamps never go back."""
    reference, last_tick = _hold_to_last_tick(client, "visco")
    late = last_tick - 5 * MS  # after the last command, before the last tick
    answer = client.send("visco", late, 8e-6)
    expected = reference.step((last_tick - T0_NS) * 1e-9, depth=8e-6)
    assert stamp_to_ns(answer.header.stamp) == last_tick, "stamped with the time it was applied at"
    assert _outputs(answer) == (expected.depth, expected.force, expected.contact_radius)
    client.tick(last_tick + 60 * MS)  # the timer holds the new depth from there
    client.settle()
    stamps = _stamps(client.states["visco"])
    assert stamps[-1] > last_tick, "the timer holds after the late command"
    assert np.all(np.diff(stamps) >= 0), np.diff(stamps)


def test_a_hand_command_stamped_before_a_hold_tick_is_answered_at_the_ticks_time(
    client: _SimClockClient,
) -> None:
    """The same through hand/indentation: every row of the HandState describes one time, the
    latest of the stamp and the listed contacts' times (here visco's last tick; elastic gets its
    first command there), and HandState carries it."""
    reference, last_tick = _hold_to_last_tick(client, "visco")
    state = client.send_hand(last_tick - 5 * MS, [8e-6, 3e-6], ["visco", "elastic"])
    assert stamp_to_ns(state.header.stamp) == last_tick
    visco = reference.step((last_tick - T0_NS) * 1e-9, depth=8e-6)
    elastic = _reference("elastic").step(0.0, depth=3e-6)
    assert _outputs(state, 0) == (visco.depth, visco.force, visco.contact_radius)
    assert _outputs(state, 1) == (elastic.depth, elastic.force, elastic.contact_radius)
    client.tick(last_tick + 60 * MS)
    client.settle()
    for contact in IDS:
        stamps = _stamps(client.states[contact])
        assert np.all(np.diff(stamps) >= 0), (contact, np.diff(stamps))
        assert stamps[-1] > last_tick, f"{contact}: the timer holds after the hand command"


@pytest.mark.parametrize("hand", [False, True], ids=["C/indentation", "hand/indentation"])
@pytest.mark.parametrize(
    "ahead_ns", [PERIOD_NS, 0, -5 * MS], ids=["a period ahead", "at the clock", "5 ms behind"]
)
def test_commands_at_the_timers_rate_get_no_hold_states_between_them_whatever_their_stamps(
    client: _SimClockClient, hand: bool, ahead_ns: int
) -> None:
    """Commands every timer period (20 ms of /clock), each sent once the clock reached the
    previous sample's time and stamped ``ahead_ns`` from the clock: every C/state is a command's
    answer (0.8.0 republished a period-ahead stream's states at the same stamps; at or behind
    the clock its timer put a hold state between two commands and applied the next one late, a
    hold then a jump instead of the ramp), the answers are those of the core stepped on the
    samples, and once the commands stop the timer holds."""
    depths = np.interp(np.arange(30), [0, 15, 29], [-1e-6, 8e-6, 2e-6])
    start = T0_NS + 10 * PERIOD_NS
    client.tick(start - PERIOD_NS)
    references = {i: _reference(i) for i in IDS}
    for k, depth in enumerate(depths.tolist()):
        clock = start + k * PERIOD_NS
        client.tick(clock)
        stamp = clock + ahead_ns
        expected = {i: references[i].step(k * PERIOD_NS * 1e-9, depth=depth) for i in IDS}
        if hand:
            state = client.send_hand(stamp, [depth, depth], IDS)
            assert stamp_to_ns(state.header.stamp) == stamp, k
            for j, i in enumerate(IDS):
                assert _outputs(state, j) == _outputs(expected[i], None), (k, i)
        else:
            state = client.send("visco", stamp, depth)
            assert stamp_to_ns(state.header.stamp) == stamp, k
            assert _outputs(state) == _outputs(expected["visco"], None), k
    client.settle()
    # Every C/state from the first command on is a command's answer, one per command (hand
    # commands are answered on hand/state only).
    first = start + ahead_ns
    for i in IDS if hand else ["visco"]:
        during = [s.commands_received for s in client.states[i] if stamp_to_ns(s.header.stamp) >= first]
        assert during == ([] if hand else list(range(1, depths.size + 1))), f"{i}: hold states {during}"
    # The commands stopped: the timer takes over.
    last = start + (depths.size - 1) * PERIOD_NS
    client.tick(last + 4 * PERIOD_NS)
    client.settle()
    for i in IDS if hand else ["visco"]:
        stamps = _stamps(client.states[i])
        assert stamps[-1] == last + 4 * PERIOD_NS, f"{i}: no hold state after the commands"
        assert np.all(np.diff(stamps) >= 0), (i, np.diff(stamps))
