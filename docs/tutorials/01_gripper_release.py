"""Tutorial 1: a gripper finger that asks `predict_pull_off` before it lets go.

Run:  .venv/bin/python docs/tutorials/01_gripper_release.py
      (starts the viscoadh node in this process; with --external it talks to a node you
      started yourself with `viscoadh node`). See docs/tutorials/01_gripper_release.md.
"""

from __future__ import annotations

import argparse
import threading
from pathlib import Path

import rclpy
from rclpy.node import Node
from viscoadh_msgs.msg import ContactState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.demo import creep_time, node_in_process
from viscoadh_ros.plotting import JkrReference


# --8<-- [start:controller]
class GripperFinger(Node):
    """Press, hold, ask how hard letting go will pull, then release at a chosen speed.

    Depths in m, speeds in m/s, forces in N, times in s (node clock).
    """

    RATE_HZ = 200.0  # command rate, like a real finger controller

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

    def run(**node_kwargs) -> None:
        node = GripperFinger(**finger, **node_kwargs)
        executor = rclpy.executors.MultiThreadedExecutor(context=node.context)
        executor.add_node(node)
        while not node.done.is_set() and node.context.ok():
            executor.spin_once(timeout_sec=0.1)
        print("predicted pull-off force per release speed:")
        for speed, force in sorted(node.predictions.items()):
            print(f"  {speed:10.3e} m/s -> {force:11.4e} N")
        print(f"released at {node.release_speed:.3e} m/s; most tensile force read "
              f"{node.most_tensile:.4e} N (predicted {node.predictions[node.release_speed]:.4e} N)")
        node.destroy_node()

    if args.external:
        rclpy.init()
        try:
            run()
        finally:
            rclpy.try_shutdown()
    else:
        with node_in_process(scene) as (context, _executor):
            run(context=context)


if __name__ == "__main__":
    main()
