"""The pads through the ``viscoadh`` node: the node-in-the-loop `PadBank`.

`NodePads` starts the node in this process (`viscoadh_ros.demo.node_in_process`, DDS traffic
kept inside the process) on a scene with one contact per pad (`Cell.pad_scene`), on simulated
time (``use_sim_time``; this bank publishes ``/clock`` from MuJoCo's clock). Each physics step
runs in lockstep, as a user's controller would:

1. publish one ``IndentationCommand`` (DEPTH) per pad on ``pad_i/indentation``, stamped with
   the step's time (``CLOCK_START_NS + k dt_ns``);
2. wait for every pad's ``ContactState`` with that stamp on ``pad_i/state``;
3. publish ``/clock`` = that stamp (after the answers: the node's hold timer then never
   advances a contact past a command it has not seen).

The node steps the same core with the same times and depths as `LibraryPads`, and CDR carries
float64 unchanged, so the two paths give the same trajectory. ``predict_pull_off`` calls each
pad's ``pad_i/predict_pull_off`` service (the node holds the copy to its clock's now, which is
the last step's time).
"""

from __future__ import annotations

import contextlib
import threading
import time as wallclock

import numpy as np
from numpy.typing import NDArray
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from viscoadh_msgs.msg import ContactState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff

from viscoadh_ros.demo import node_in_process
from viscoadh_ros.ros.conversions import ns_to_stamp, stamp_to_ns

from .config import Cell, pad_ids
from .pads import PadStates

#: Where the simulated clock starts, ns (a zero stamp would mean "now" to the node).
CLOCK_START_NS = 1_000_000_000
#: Wall-clock seconds to wait for any one answer of the node (a loaded machine only slows the
#: run down; the lockstep keeps it the same).
ANSWER_TIMEOUT_S = 30.0
#: The node's own publish timer, Hz: silent while commands come every physics step.
NODE_PUBLISH_RATE = 20.0


class NodePads:
    """Every pad of ``cell`` as a contact of an in-process ``viscoadh`` node, over DDS."""

    def __init__(self, cell: Cell) -> None:
        self.count = cell.gripper.pad_count
        self.ids = pad_ids(self.count)
        self._stack = contextlib.ExitStack()
        self._node: Node | None = None
        try:
            context, executor = self._stack.enter_context(
                node_in_process(cell.pad_scene(), use_sim_time=True, publish_rate=NODE_PUBLISH_RATE)
            )
            # Destroyed by node_in_process once its spinner has stopped (destroying it here,
            # while the spinner may be waiting on its entities, raised InvalidHandle there).
            self._node = Node("viscoadh_gripper_cell", context=context)
            executor.add_node(self._node)
            self._setup()
        except BaseException:
            self._stack.close()
            raise

    def _setup(self) -> None:
        node = self._node
        self._clock_pub = node.create_publisher(
            Clock, "/clock", QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
        )
        self._clock = Clock()
        self._commands = [node.create_publisher(IndentationCommand, f"{i}/indentation", 10) for i in self.ids]
        self._messages = [IndentationCommand(mode=IndentationCommand.DEPTH) for _ in self.ids]
        for index, pad_id in enumerate(self.ids):
            node.create_subscription(
                ContactState, f"{pad_id}/state", lambda msg, i=index: self._on_state(i, msg), 10
            )
        self._predict = [node.create_client(PredictPullOff, f"{i}/predict_pull_off") for i in self.ids]
        self._answer = threading.Condition()
        self._waiting_for = -1
        self._received = [None] * self.count
        self._missing = 0
        self._states = PadStates(
            np.zeros(self.count), np.zeros(self.count), np.zeros(self.count, dtype=np.uint8)
        )
        deadline = wallclock.monotonic() + ANSWER_TIMEOUT_S
        while (
            not all(p.get_subscription_count() > 0 for p in self._commands)
            or self._clock_pub.get_subscription_count() == 0
        ):
            if wallclock.monotonic() > deadline:
                raise RuntimeError("the viscoadh node did not subscribe to the pads' command topics")
            wallclock.sleep(0.01)
        for client in self._predict:
            if not client.wait_for_service(timeout_sec=max(0.0, deadline - wallclock.monotonic())):
                raise RuntimeError("the viscoadh node's predict_pull_off services did not come up")

    def _on_state(self, index: int, msg: ContactState) -> None:
        with self._answer:
            if stamp_to_ns(msg.header.stamp) == self._waiting_for and self._received[index] is None:
                self._received[index] = msg
                self._missing -= 1
                if self._missing == 0:
                    self._answer.notify()

    def step(self, time: float, depths: NDArray[np.float64]) -> PadStates:
        stamp_ns = CLOCK_START_NS + round(time * 1e9)
        stamp = ns_to_stamp(stamp_ns)
        with self._answer:
            self._waiting_for, self._missing = stamp_ns, self.count
            self._received = [None] * self.count
            for publisher, message, depth in zip(self._commands, self._messages, depths, strict=True):
                message.header.stamp = stamp
                message.depth = float(depth)
                publisher.publish(message)
            if not self._answer.wait_for(lambda: self._missing == 0, ANSWER_TIMEOUT_S):
                raise RuntimeError(f"the viscoadh node did not answer every pad at t = {time:.6f} s")
        self._clock.clock = stamp
        self._clock_pub.publish(self._clock)
        states = self._states
        for i, msg in enumerate(self._received):
            states.force[i] = msg.force
            states.contact_radius[i] = msg.contact_radius
            states.phase[i] = msg.phase
        return states

    def predict_pull_off(self, retract_speed: float) -> NDArray[np.float64]:
        forces = np.zeros(self.count)
        for i, client in enumerate(self._predict):
            done = threading.Event()
            future = client.call_async(PredictPullOff.Request(retract_speed=float(retract_speed)))
            future.add_done_callback(lambda _, done=done: done.set())
            if not done.wait(ANSWER_TIMEOUT_S) or future.result() is None:
                raise RuntimeError(f"{self.ids[i]}/predict_pull_off did not answer")
            answer = future.result()
            if not answer.success:
                raise RuntimeError(f"{self.ids[i]}/predict_pull_off failed: {answer.message}")
            forces[i] = answer.pull_off_force
        return forces

    def close(self) -> None:
        """Stop the node and its executor (idempotent)."""
        self._stack.close()

    def __enter__(self) -> NodePads:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
