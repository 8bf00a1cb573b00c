"""Runtime parameter changes the node must refuse without stopping, as a user meets them.

An outside tester (0.11.0) stopped a running node with one ``ros2 param set``: a
``numerics.model: closed_form`` on a body with memory passed the schema and failed when the
contact's simulator was built, and the error left the parameter callback for ``main``'s start-up
handler (exit 2, every contact gone). A ``command.max_future_s`` of 1e300 overflowed the
nanosecond conversion (exit 1), and ``log.max_duration: 1e300`` did at start-up. A refused change
left no trace. These tests drive the node in another process over DDS (the parameter service,
as ``ros2 param set`` does): a bad change, then the node still answering, then a good change.
"""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.msg import ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node
from rclpy.parameter import Parameter
from viscoadh_msgs.msg import ContactEvent, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff

from tests.test_node_process import SCENE, START_TIMEOUT, TIMEOUT, VISCOADH, Controller, run_node_process
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator
from viscoadh_ros.ros.conversions import ns_to_stamp
from viscoadh_ros.ros.node import ViscoadhNode


def _double(name: str, value: float) -> ParameterMsg:
    return ParameterMsg(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value)
    )


def _string(name: str, value: str) -> ParameterMsg:
    return ParameterMsg(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=value)
    )


@pytest.fixture
def node_process(tmp_path: Path, ros_env: dict[str, str]) -> Any:
    yield from run_node_process(tmp_path, ros_env)


def test_a_bad_runtime_change_is_refused_and_the_node_keeps_serving(
    node_process: Any, ros_localhost_context: Any, spin_until: Any, tmp_path: Path
) -> None:
    log = tmp_path / "node.log"
    controller = Controller(ros_localhost_context, spin_until, node_process, log)
    client, pub, states, call = controller.node, controller.pub, controller.states, controller.call
    events: list[ContactEvent] = []
    # C/events is transient local, keep last 10 (docs/ros_interface.md): late joiners see them.
    from viscoadh_ros.ros.node import EVENTS_QOS

    client.create_subscription(ContactEvent, "finger/events", events.append, EVENTS_QOS)
    executor = controller.executor

    def set_one(parameter: ParameterMsg) -> Any:
        return call(
            SetParameters, "/viscoadh/set_parameters", SetParameters.Request(parameters=[parameter])
        ).results[0]

    closed = set_one(_string("finger.numerics.model", "closed_form"))
    assert not closed.successful and "closed_form" in closed.reason, closed.reason
    assert node_process.poll() is None, "a refused change stopped the node:\n" + log.read_text()
    assert spin_until(
        executor, lambda: any(e.kind == ContactEvent.PARAMETERS_REFUSED for e in events), TIMEOUT
    ), f"no PARAMETERS_REFUSED event: {[(e.kind, e.reason) for e in events]}"
    refused = next(e for e in events if e.kind == ContactEvent.PARAMETERS_REFUSED)
    assert "closed_form" in refused.reason and refused.contact_id == "finger", refused

    for value in (1e300, float("inf")):
        future = set_one(_double("command.max_future_s", value))
        assert not future.successful and "max_future_s" in future.reason, future.reason
        assert node_process.poll() is None, f"max_future_s={value} stopped the node:\n" + log.read_text()

    # Nothing to pull off before any contact: not a success with zeros.
    idle = call(PredictPullOff, "finger/predict_pull_off", PredictPullOff.Request(retract_speed=1e-3))
    assert not idle.success and "not in contact" in idle.message, idle.message

    # The contact still runs its start-up physics: a press is answered with the core's force.
    t0 = client.get_clock().now().nanoseconds + 10 * 10**9
    msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=5e-6)
    msg.header.stamp = ns_to_stamp(t0)
    pub.publish(msg)
    assert spin_until(executor, lambda: states[-1].header.stamp == msg.header.stamp, TIMEOUT), log.read_text()
    contact = SceneConfig.from_dict(SCENE).contact("finger")
    expected = ContactSimulator(contact).step(0.0, depth=5e-6)
    np.testing.assert_allclose(
        states[-1].force, expected.force, rtol=1e-9, err_msg="the refused change moved the contact"
    )
    pressed = call(PredictPullOff, "finger/predict_pull_off", PredictPullOff.Request(retract_speed=1e-3))
    assert pressed.success and pressed.pull_off_force < 0.0, pressed.message

    # A good change after the bad ones applies.
    assert set_one(_double("command.max_future_s", 20.0)).successful
    assert node_process.poll() is None

    controller.close()
    node_process.send_signal(signal.SIGINT)
    assert node_process.wait(timeout=10.0) == 0, log.read_text()


@pytest.mark.parametrize("override", ["log.max_duration:=1e300", "command.max_future_s:=1e300"])
def test_a_duration_too_long_stops_start_up_with_one_line(
    override: str, tmp_path: Path, ros_env: dict[str, str]
) -> None:
    params = tmp_path / "scene.yaml"
    params.write_text(yaml.safe_dump(SCENE))
    result = subprocess.run(
        [
            str(VISCOADH),
            "node",
            "--ros-args",
            "--params-file",
            str(params),
            "-p",
            override,
            "-p",
            "log.enabled:=true",
            "-p",
            f"log.path:={tmp_path / 'log.mcap'}",
        ],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=START_TIMEOUT,
    )
    assert result.returncode == 2, result.stdout + result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    key = override.split(":=")[0]
    assert key in result.stderr and "1e+09" in result.stderr, result.stderr


def test_a_change_of_two_contacts_is_all_or_nothing(ros_context: Any) -> None:
    """Two contacts in one atomic request, the second's physics unbuildable: neither changes
    (the contacts were replaced one by one and the second's error left the first changed)."""
    from tests.test_node_live import SCENE as TWO

    node = ViscoadhNode(
        context=ros_context, parameter_overrides=[Parameter(n, value=v) for n, v in TWO.items()]
    )
    try:
        elastic = node.contacts["elastic"].simulator
        result = node.set_parameters_atomically(
            [
                Parameter("elastic.material.glass_shear_modulus", value=2.0e6),
                Parameter("visco.numerics.model", value="closed_form"),
            ]
        )
        assert not result.successful and "closed_form" in result.reason, result.reason
        assert node.contacts["elastic"].simulator is elastic, "the first contact changed"
        assert node.get_parameter("elastic.material.glass_shear_modulus").value == 1.0e6
        assert node.get_parameter("visco.numerics.model").value == "auto"
        assert node.set_parameters_atomically(
            [Parameter("elastic.material.glass_shear_modulus", value=2.0e6)]
        ).successful
        assert node.contacts["elastic"].simulator is not elastic
    finally:
        node.destroy_node()


def test_use_sim_time_at_runtime_is_refused_saying_how_to_set_it(ros_context: Any) -> None:
    from tests.test_node_live import SCENE as TWO

    node = ViscoadhNode(
        context=ros_context, parameter_overrides=[Parameter(n, value=v) for n, v in TWO.items()]
    )
    try:
        result = node.set_parameters([Parameter("use_sim_time", value=True)])[0]
        assert not result.successful and "use_sim_time:=true" in result.reason, result.reason
    finally:
        node.destroy_node()


def test_a_log_with_refused_changes_replays_exactly(tmp_path: Path) -> None:
    """Refused changes in a node log (mid-contact; a model the body cannot run) are events the
    replay skips: it reproduces the node exactly and counts only the applied change."""
    import json
    import time as wallclock

    from rosgraph_msgs.msg import Clock
    from scenes import STANDARD_SOLID_FINGER, call_service

    from viscoadh_ros.cli.main import main
    from viscoadh_ros.demo import _Driver, node_in_process
    from viscoadh_ros.io.bag import Bag

    scene = SceneConfig.from_parameters(STANDARD_SOLID_FINGER)
    log = tmp_path / "session.mcap"
    times = np.arange(0.0, 0.5, 0.01)
    depths = np.interp(times, [0.0, 0.2, 0.5], [-1e-6, 20e-6, -30e-6])
    params = {"log.enabled": True, "log.path": str(log), "command.max_future_s": 30.0}
    with node_in_process(scene, use_sim_time=True, **params) as (context, executor):
        client = Node("refusals_log_driver", context=context)
        driver = _Driver(client, "finger", timeout=10.0)
        clock = client.create_publisher(Clock, "/clock", 1)
        service = client.create_client(SetParameters, "/viscoadh/set_parameters")
        executor.add_node(client)
        driver.wait_for_node()
        clock.publish(Clock(clock=ns_to_stamp(1_000_000_000)))
        wallclock.sleep(0.1)

        def change(parameter: ParameterMsg) -> Any:
            return call_service(service, SetParameters.Request(parameters=[parameter])).results[0]

        for t, d in zip(times[:20], depths[:20], strict=True):
            driver.command(1.0 + t, d)
        # In contact: refused (the contact is pressed).
        assert not change(_double("finger.adhesion.work_of_adhesion", 0.2)).successful
        for t, d in zip(times[20:], depths[20:], strict=True):
            driver.command(1.0 + t, d)
        driver.command(2.0, depths[-1])  # out of touch and relaxed
        refused = change(_string("finger.numerics.model", "closed_form"))
        assert not refused.successful and "closed_form" in refused.reason, refused.reason
        assert change(_double("finger.adhesion.work_of_adhesion", 0.2)).successful
        wallclock.sleep(0.1)
        for t, d in zip(times, depths, strict=True):
            driver.command(3.0 + t, d)
    bag = Bag(log)
    kinds = [m.msg.kind for m in bag.messages(["/finger/events"])]
    assert kinds == [
        ContactEvent.PARAMETERS_REFUSED,
        ContactEvent.PARAMETERS_REFUSED,
        ContactEvent.PARAMETERS,
    ], kinds
    summary = tmp_path / "summary.json"
    assert main(["replay", str(log), "-o", str(tmp_path / "out.mcap"), "--json", str(summary)]) == 0
    result = json.loads(summary.read_text())
    assert result["max_error_N"] == 0.0 and result["parameter_changes"] == 1, result
