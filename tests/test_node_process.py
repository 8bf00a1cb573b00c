"""`viscoadh node` as a child process, driven over DDS like a real controller.

The node runs from the venv's console script with a params file; the test publishes a slow
approach/retract cycle, reads the states, and calls every service. The node's forces must equal
the core's ``simulate_history`` on the same history (same core, same numbers).
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_srvs.srv import Trigger
from viscoadh_msgs.msg import ContactState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff, SimulateHistory

from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.ros.conversions import ns_to_stamp

VISCOADH = Path(sys.executable).parent / "viscoadh"
START_TIMEOUT = 30.0  # process start-up including numba's cache load, s
TIMEOUT = 5.0

SCENE = {
    "viscoadh": {
        "ros__parameters": {
            "contacts": ["finger"],
            "finger": {
                "indenter": {"shape": "sphere", "radius": 0.01},
                "material": {
                    "glass_shear_modulus": 1.0e6,
                    "kelvin_shear_moduli": [2.0e5],
                    "kelvin_viscosities": [2.0e3],
                },
                "adhesion": {"work_of_adhesion": 0.05},
                "numerics": {"preset": "fast"},
            },
            # The test stamps its commands 10 s ahead of the clock.
            "command": {"max_future_s": 30.0},
        }
    }
}


def run_node_process(tmp_path: Path, ros_env: dict[str, str]) -> Any:
    """`viscoadh node` on SCENE as a child process (output in ``tmp_path/node.log``), yielded
    and stopped afterwards; the body of the ``node_process`` fixtures."""
    params = tmp_path / "scene.yaml"
    params.write_text(yaml.safe_dump(SCENE))
    log = (tmp_path / "node.log").open("w")
    process = subprocess.Popen(
        [str(VISCOADH), "node", "--ros-args", "--params-file", str(params), "-p", "publish_rate:=2.0"],
        env=ros_env,
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    yield process
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=5.0)
    log.close()


@pytest.fixture
def node_process(tmp_path: Path, ros_env: dict[str, str]) -> Any:
    yield from run_node_process(tmp_path, ros_env)


class Controller:
    """The controller side of a node process's test: a client node on its own executor with a
    command publisher and the contact's states, up once the node answers (its idle heartbeat),
    calling services with the node's log in every failure message."""

    def __init__(self, context: Any, spin_until: Any, process: Any, log: Path, contact: str = "finger"):
        self.log = log
        self.executor = SingleThreadedExecutor(context=context)
        self.node = Node("controller", context=context)
        self.executor.add_node(self.node)
        self.states: list[ContactState] = []
        self.pub = self.node.create_publisher(IndentationCommand, f"{contact}/indentation", 10)
        self.node.create_subscription(ContactState, f"{contact}/state", self.states.append, 100)
        up = spin_until(
            self.executor,
            lambda: (
                (self.pub.get_subscription_count() > 0 and self.node.count_publishers(f"{contact}/state") > 0)
                or process.poll() is not None
            ),
            START_TIMEOUT,
        )
        assert up and process.poll() is None, log.read_text()
        # The node's state publisher may not have matched our subscription yet (discovery is not
        # symmetric; a reliable volatile writer drops what it published before): its idle
        # heartbeat (once per second) arriving proves it has.
        assert spin_until(self.executor, lambda: bool(self.states), START_TIMEOUT), "no idle heartbeat state"

    def call(self, srv_type: Any, name: str, request: Any) -> Any:
        service = self.node.create_client(srv_type, name)
        assert service.wait_for_service(timeout_sec=TIMEOUT), f"{name} not available\n{self.log.read_text()}"
        future = service.call_async(request)
        self.executor.spin_until_future_complete(future, timeout_sec=TIMEOUT)
        assert future.done(), f"{name} did not answer\n{self.log.read_text()}"
        return future.result()

    def close(self) -> None:
        self.executor.remove_node(self.node)
        self.node.destroy_node()
        self.executor.shutdown(timeout_sec=1.0)


def test_node_process_serves_a_controller_like_the_core(
    node_process: Any, ros_localhost_context: Any, spin_until: Any, tmp_path: Path
) -> None:
    controller = Controller(ros_localhost_context, spin_until, node_process, tmp_path / "node.log")
    executor, client, pub, states, call = (
        controller.executor,
        controller.node,
        controller.pub,
        controller.states,
        controller.call,
    )

    # Slow approach and retract, stamped 10 s ahead of the clock (see test_node_live).
    time = np.arange(0.0, 0.6, 0.01)
    depth = np.interp(time, [0.0, 0.3, 0.6], [-1e-6, 6e-6, -3e-6])
    t0 = client.get_clock().now().nanoseconds + 10 * 10**9
    forces = []
    for t, d in zip(time, depth, strict=True):
        msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=float(d))
        stamp = ns_to_stamp(t0 + round(t * 1e9))
        msg.header.stamp = stamp
        pub.publish(msg)
        # The answer carries the command's stamp (idle heartbeats carry the clock's).
        assert spin_until(executor, lambda s=stamp: states and states[-1].header.stamp == s, TIMEOUT), (
            f"no state at t={t}: {[(x.header.stamp, x.commands_received) for x in states[-3:]]}\n"
            + (tmp_path / "node.log").read_text()
        )
        forces.append(states[-1].force)

    history = call(
        SimulateHistory,
        "finger/simulate_history",
        SimulateHistory.Request(mode=0, time=time.tolist(), depth=depth.tolist()),
    )
    assert history.success, history.message
    contact = SceneConfig.from_yaml(tmp_path / "scene.yaml").contact("finger")
    expected = simulate_history(contact, time, depth=depth)
    np.testing.assert_allclose(
        forces, expected.force, rtol=1e-9, atol=1e-12, err_msg="live command path vs core simulate_history"
    )
    np.testing.assert_allclose(
        history.force, expected.force, rtol=1e-9, atol=1e-12, err_msg="simulate_history service vs core"
    )
    assert min(forces) < 0.0, "the cycle must reach the adhesive branch"

    bad = call(PredictPullOff, "finger/predict_pull_off", PredictPullOff.Request(retract_speed=-1.0))
    assert not bad.success and "retract_speed" in bad.message, bad.message
    reset = call(Trigger, "finger/reset", Trigger.Request())
    assert reset.success, reset.message
    msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=5e-6)
    before = len(states)
    pub.publish(msg)
    assert spin_until(executor, lambda: len(states) > before, TIMEOUT), "no state after reset"
    prediction = call(PredictPullOff, "finger/predict_pull_off", PredictPullOff.Request(retract_speed=1e-4))
    assert prediction.success, prediction.message
    assert prediction.pull_off_force < 0.0, "adhesive contact pulls off under tension"

    controller.close()
    node_process.send_signal(signal.SIGINT)
    assert node_process.wait(timeout=10.0) == 0, (tmp_path / "node.log").read_text()


def test_node_process_refuses_a_typo_in_the_scene(tmp_path: Path, ros_env: dict[str, str]) -> None:
    scene = yaml.safe_load(yaml.safe_dump(SCENE))
    scene["viscoadh"]["ros__parameters"]["finger"]["material"]["glass_shear_moduls"] = 1.0
    params = tmp_path / "typo.yaml"
    params.write_text(yaml.safe_dump(scene))
    done = subprocess.run(
        [str(VISCOADH), "node", "--ros-args", "--params-file", str(params)],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=60.0,
    )
    assert done.returncode == 2, done.stderr
    assert "glass_shear_moduls" in done.stderr and "Traceback" not in done.stderr, done.stderr
