"""Tutorial 1: a gripper finger that asks `predict_pull_off` before it lets go.

Run:  .venv/bin/python docs/tutorials/01_gripper_release.py
      (starts the viscoadh node in this process on a simulated clock that this script drives;
      with --external it talks to a node you started yourself with `viscoadh node`, in real
      time). See docs/tutorials/01_gripper_release.md.
"""

from __future__ import annotations

import argparse
import threading
import time
from collections.abc import Callable
from pathlib import Path

import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from viscoadh_msgs.msg import ContactState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.demo import creep_time, node_in_process
from viscoadh_ros.plotting import JkrReference
from viscoadh_ros.ros.conversions import ns_to_stamp

#: Where the simulated clock starts, ns (a zero stamp would mean "now" to the node).
CLOCK_START_NS = 1_000_000_000
#: How long the simulated clock waits for any one answer, s of wall time (a loaded machine
#: only makes the run slower, never different).
ANSWER_TIMEOUT_S = 30.0


# --8<-- [start:controller]
class GripperFinger(Node):
    """Press, hold, ask how hard letting go will pull, then release at a chosen speed.

    Depths in m, speeds in m/s, forces in N, times in s (node clock).
    """

    RATE_HZ = 1000.0  # command rate, like a real finger controller

    def __init__(self, *, contact: str, grip_depth: float, speed: float, hold: float,
                 release_speeds: list[float], max_pull: float, **kwargs) -> None:
        super().__init__("gripper_finger", **kwargs)
        self.grip_depth, self.speed, self.hold = grip_depth, speed, hold
        self.release_speeds, self.max_pull = release_speeds, max_pull
        self.commands = self.create_publisher(IndentationCommand, f"{contact}/indentation", 10)
        self.create_subscription(ContactState, f"{contact}/state", self.on_state, 10)
        self.predict = self.create_client(PredictPullOff, f"{contact}/predict_pull_off")
        self.phase = "press"
        self.depth = -grip_depth / 4.0  # start just above the object
        self.release_speed = 0.0
        self.predictions: dict[float, float] = {}  # retract speed -> predicted pull-off force
        self.most_tensile = 0.0  # most tensile force read during the release
        self.done = threading.Event()
        self.timer = self.create_timer(1.0 / self.RATE_HZ, self.tick)

    def tick(self) -> None:
        """Advance the finger one period and publish where it is."""
        step = 1.0 / self.RATE_HZ
        if self.phase == "press":
            self.depth = min(self.depth + self.speed * step, self.grip_depth)
            if self.depth == self.grip_depth:
                self.phase, self.hold_until = "hold", self.now() + self.hold
        elif self.phase == "hold" and self.now() >= self.hold_until:
            self.phase = "ask"
            self.ask()
        elif self.phase == "release":
            self.depth -= self.release_speed * step
        command = IndentationCommand(mode=IndentationCommand.DEPTH, depth=self.depth)
        command.header.stamp = self.get_clock().now().to_msg()
        self.commands.publish(command)

    def ask(self) -> None:
        """Ask the model about every candidate speed before moving (the finger keeps holding)."""
        for speed in self.release_speeds:
            future = self.predict.call_async(PredictPullOff.Request(retract_speed=speed))
            future.add_done_callback(lambda f, v=speed: self.on_prediction(v, f.result()))

    def on_prediction(self, speed: float, answer: PredictPullOff.Response) -> None:
        if not answer.success:
            self.get_logger().error(f"predict_pull_off({speed:g} m/s) failed: {answer.message}")
            return
        self.predictions[speed] = answer.pull_off_force
        if len(self.predictions) < len(self.release_speeds):
            return
        # The fastest release that pulls no harder than the arm may pull; if none does,
        # the gentlest one (and say so).
        allowed = [v for v, f in self.predictions.items() if -f <= self.max_pull]
        if allowed:
            self.release_speed = max(allowed)
        else:
            self.release_speed = max(self.predictions, key=self.predictions.get)
            self.get_logger().warning("every release speed pulls harder than max_pull")
        self.phase = "release"

    def on_state(self, state: ContactState) -> None:
        if self.phase != "release":
            return
        self.most_tensile = min(self.most_tensile, state.force)
        if state.phase == ContactState.NO_CONTACT:
            self.phase = "released"
            self.done.set()

    def now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9
# --8<-- [end:controller]


class LockstepClock(Node):
    """The simulated world's ``/clock`` for the in-process run, in lockstep with the finger.

    Moves ROS time (``use_sim_time`` in the finger and the node) one finger period at a time,
    and only once the node has answered the finger's command of the current period and the
    finger is not waiting for ``predict_pull_off`` answers. The finger then executes exactly
    the motion it plans, and the node sees the same commands at the same stamps on any machine,
    however loaded: the run is reproducible, not a race against the wall clock.
    """

    def __init__(self, contact: str, period: float, **kwargs) -> None:
        super().__init__("gripper_world_clock", **kwargs)
        self.period_ns = round(period * 1e9)
        self.publisher = self.create_publisher(
            Clock, "/clock", QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
        )
        self.states = self.create_subscription(ContactState, f"{contact}/state", self.on_state, 10)
        self.answered = threading.Condition()
        self.commands_answered = 0

    def on_state(self, state: ContactState) -> None:
        with self.answered:
            self.commands_answered = max(self.commands_answered, state.commands_received)
            self.answered.notify()

    def drive(self, finger: GripperFinger) -> None:
        """Tick until the finger has let go (RuntimeError if the node or finger stops answering)."""
        self.wait_until(
            lambda: self.publisher.get_subscription_count() >= 2  # the finger's and the node's
            and finger.commands.get_subscription_count() > 0
            and self.states.get_publisher_count() > 0
            and finger.predict.service_is_ready(),
            "the viscoadh node and the finger did not come up",
        )
        stamp_ns, ticks = CLOCK_START_NS, 0
        while not finger.done.is_set():
            self.publisher.publish(Clock(clock=ns_to_stamp(stamp_ns)))
            ticks += 1  # each period, the finger's timer sends one command
            self.wait_until(
                lambda ticks=ticks: self.commands_answered >= ticks and finger.phase != "ask",
                f"no answer to the finger's command at t = {stamp_ns * 1e-9:.3f} s",
            )
            stamp_ns += self.period_ns

    def wait_until(self, condition: Callable[[], bool], what: str) -> None:
        deadline = time.monotonic() + ANSWER_TIMEOUT_S
        with self.answered:
            # Woken by every state; service answers and discovery are polled every 10 ms.
            while not condition():
                if time.monotonic() > deadline:
                    raise RuntimeError(f"{what} within {ANSWER_TIMEOUT_S:g} s")
                self.answered.wait(0.01)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=Path(__file__).with_name("gripper_scene.yaml"))
    parser.add_argument("--external", action="store_true", help="use a running `viscoadh node`")
    args = parser.parse_args()

    # --8<-- [start:setup]
    scene = SceneConfig.from_yaml(args.scene)
    contact = scene.contacts[0]
    reference = JkrReference.from_contact(contact)  # the paper's quasistatic JKR branches
    slow_pull_off, _, d_c = reference.scales  # (3/2) pi R w_eff2 (N), critical depth (m)
    creep = creep_time(contact)  # the material's longest creep time, s
    finger = {
        "contact": contact.id,
        "grip_depth": 4.0 * d_c,
        "speed": 5.0 * d_c / (0.5 * creep),  # a quick grasp: half a creep time
        "hold": 0.5 * creep,
        "release_speeds": [0.5 * d_c / creep, 5.0 * d_c / creep, 50.0 * d_c / creep],
        "max_pull": 1.2 * slow_pull_off,  # what the arm may pull without losing the object
    }
    # --8<-- [end:setup]

    def report(node: GripperFinger) -> None:
        print("predicted pull-off force per release speed:")
        for speed, force in sorted(node.predictions.items()):
            print(f"  {speed:10.3e} m/s -> {force:11.4e} N")
        print(f"released at {node.release_speed:.3e} m/s; most tensile force read "
              f"{node.most_tensile:.4e} N (predicted {node.predictions[node.release_speed]:.4e} N)")

    if args.external:
        # Real time: the finger's timer runs on the wall clock, as on a robot.
        rclpy.init()
        try:
            node = GripperFinger(**finger)
            executor = MultiThreadedExecutor(context=node.context)
            executor.add_node(node)
            while not node.done.is_set() and node.context.ok():
                executor.spin_once(timeout_sec=0.1)
            report(node)
            node.destroy_node()
        finally:
            rclpy.try_shutdown()
        return
    # In process: simulated time. The node's own publish timer (20 Hz here) stays silent while
    # the finger commands every millisecond, so between two commands nothing but the commands moves
    # the contact.
    with node_in_process(scene, use_sim_time=True, publish_rate=20.0) as (context, _executor):
        sim_time = [Parameter("use_sim_time", value=True)]
        node = GripperFinger(**finger, context=context, parameter_overrides=sim_time)
        world = LockstepClock(contact.id, 1.0 / GripperFinger.RATE_HZ, context=context)
        executor = MultiThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(world)
        spinner = threading.Thread(target=executor.spin, daemon=True)
        spinner.start()
        try:
            world.drive(node)
        finally:
            executor.shutdown(timeout_sec=5.0)
            spinner.join(timeout=5.0)
            world.destroy_node()
            node.destroy_node()
        report(node)


if __name__ == "__main__":
    main()
