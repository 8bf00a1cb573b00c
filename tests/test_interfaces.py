"""The toolchain for real: viscoadh_msgs built into the venv, carried by rclpy, and the CLI.

Every custom message type is published and received and every custom service type served and
called through rclpy executors in one process; one message also crosses to a child process
(the ``ros_env`` path other tests rely on).
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")  # the ROS half of the suite; the core tests run without it
from viscoadh_msgs.msg import ContactState, IndentationCommand  # noqa: E402
from viscoadh_msgs.srv import PredictPullOff, SimulateHistory  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
TIMEOUT = 10.0  # s; generous for loaded CI machines, a pass takes milliseconds


def _indentation_command() -> IndentationCommand:
    msg = IndentationCommand()
    msg.header.frame_id = "finger"
    msg.header.stamp.sec = 12
    msg.header.stamp.nanosec = 345
    msg.mode = IndentationCommand.FORCE
    msg.depth = 1.25e-6
    msg.force = -3.5e-3
    return msg


def _contact_state() -> ContactState:
    msg = ContactState()
    msg.header.frame_id = "contact"
    msg.depth = 2.0e-6
    msg.force = -1.5e-3
    msg.contact_radius = 4.0e-5
    msg.phase = ContactState.DETACHING
    msg.edge_speed = -1.0e-4
    msg.effective_work_of_adhesion = 0.075
    msg.energy_input = 3.0e-9
    msg.energy_dissipated = 1.0e-9
    msg.scale_separation_ok = True
    msg.unstable = True
    msg.model = ContactState.MODEL_TIME_STEPPED
    msg.commands_received = 7
    msg.commands_rejected = 2
    return msg


def test_phase_constants_are_the_documented_values() -> None:
    expected = {"NO_CONTACT": 0, "INDENTING": 1, "STICKING": 2, "DETACHING": 3}
    for name, value in expected.items():
        assert getattr(ContactState, name) == value, f"ContactState.{name}"
    assert (IndentationCommand.DEPTH, IndentationCommand.FORCE) == (0, 1)
    assert (SimulateHistory.Request.DEPTH, SimulateHistory.Request.FORCE) == (0, 1)


@pytest.mark.parametrize(
    "msg_type, make",
    [(IndentationCommand, _indentation_command), (ContactState, _contact_state)],
    ids=["IndentationCommand", "ContactState"],
)
def test_message_round_trip(
    ros_context: Any, ros_executor: Any, spin_until: Any, msg_type: type, make: Any
) -> None:
    from rclpy.node import Node

    talker = Node("talker", context=ros_context)
    listener = Node("listener", context=ros_context)
    ros_executor.add_node(talker)
    ros_executor.add_node(listener)
    received: list[Any] = []
    listener.create_subscription(msg_type, "topic", received.append, 10)
    publisher = talker.create_publisher(msg_type, "topic", 10)
    sent = make()

    assert spin_until(ros_executor, lambda: publisher.get_subscription_count() > 0, TIMEOUT), (
        f"{msg_type.__name__}: subscriber not matched"
    )
    publisher.publish(sent)
    assert spin_until(ros_executor, lambda: bool(received), TIMEOUT), f"{msg_type.__name__}: nothing received"
    assert received[0] == sent, f"{msg_type.__name__}: received {received[0]} != sent {sent}"


def _serve_and_call(
    ros_context: Any, executor: Any, spin_until: Any, srv_type: type, handler: Any, request: Any
) -> Any:
    from rclpy.node import Node

    server = Node("server", context=ros_context)
    client_node = Node("client", context=ros_context)
    executor.add_node(server)
    executor.add_node(client_node)
    server.create_service(srv_type, "service", handler)
    client = client_node.create_client(srv_type, "service")
    assert spin_until(executor, client.service_is_ready, TIMEOUT), f"{srv_type.__name__}: service not found"
    future = client.call_async(request)
    assert spin_until(executor, future.done, TIMEOUT), f"{srv_type.__name__}: no response"
    return future.result()


def test_simulate_history_service_round_trip(ros_context: Any, ros_executor: Any, spin_until: Any) -> None:
    def handler(
        request: SimulateHistory.Request, response: SimulateHistory.Response
    ) -> SimulateHistory.Response:
        # Echo shapes and values back through every response field, so each one is carried.
        response.depth = [2.0 * d for d in request.depth]
        response.force = [t + 1.0 for t in request.time]
        response.contact_radius = [math.sqrt(abs(d)) for d in request.depth]
        response.phase = [SimulateHistory.Request.FORCE if request.mode else 0] * len(request.time)
        response.success = True
        response.message = f"{len(request.time)} samples"
        return response

    request = SimulateHistory.Request(
        mode=SimulateHistory.Request.FORCE,
        time=[0.0, 0.5, 1.0],
        depth=[0.0, 1e-6, 4e-6],
        force=[0.0, 1e-3, 2e-3],
    )
    response = _serve_and_call(ros_context, ros_executor, spin_until, SimulateHistory, handler, request)

    assert response.success and response.message == "3 samples", "SimulateHistory: status"
    assert list(response.depth) == [0.0, 2e-6, 8e-6], "SimulateHistory: depth"
    assert list(response.force) == [1.0, 1.5, 2.0], "SimulateHistory: force"
    assert list(response.contact_radius) == pytest.approx([0.0, 1e-3, 2e-3], rel=1e-12), (
        "SimulateHistory: radius"
    )
    assert list(response.phase) == [1, 1, 1], "SimulateHistory: phase"


def test_predict_pull_off_service_round_trip(ros_context: Any, ros_executor: Any, spin_until: Any) -> None:
    def handler(
        request: PredictPullOff.Request, response: PredictPullOff.Response
    ) -> PredictPullOff.Response:
        response.pull_off_force = -request.retract_speed * 10.0
        response.pull_off_depth = -request.retract_speed
        response.time_to_detach = 1.0 / request.retract_speed
        response.success = True
        response.message = "ok"
        return response

    request = PredictPullOff.Request(retract_speed=1e-4)
    response = _serve_and_call(ros_context, ros_executor, spin_until, PredictPullOff, handler, request)

    assert response.success and response.message == "ok", "PredictPullOff: status"
    assert (response.pull_off_force, response.pull_off_depth) == (-1e-3, -1e-4), (
        "PredictPullOff: force, depth"
    )
    assert response.time_to_detach == pytest.approx(1e4, rel=1e-12), "PredictPullOff: time_to_detach"


def test_message_reaches_a_child_process(
    ros_localhost_context: Any, ros_env: dict[str, str], spin_until: Any
) -> None:
    """A ContactState published by a child process arrives here: ros_env and LOCALHOST work."""
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    child_code = textwrap.dedent("""
        import sys, threading
        import rclpy
        from rclpy.executors import ExternalShutdownException
        from rclpy.node import Node
        from viscoadh_msgs.msg import ContactState
        rclpy.init()
        node = Node("child_talker")
        pub = node.create_publisher(ContactState, "child_state", 10)
        msg = ContactState(force=-0.25, phase=ContactState.STICKING)
        node.create_timer(0.05, lambda: pub.publish(msg))
        # Publish until the parent closes stdin (it has its message by then).
        threading.Thread(target=lambda: (sys.stdin.read(), rclpy.try_shutdown()), daemon=True).start()
        try:
            rclpy.spin(node)
        except ExternalShutdownException:
            pass
    """)
    child = subprocess.Popen([sys.executable, "-c", child_code], env=ros_env, stdin=subprocess.PIPE)
    executor = SingleThreadedExecutor(context=ros_localhost_context)
    listener = Node("parent_listener", context=ros_localhost_context)
    executor.add_node(listener)
    received: list[ContactState] = []
    listener.create_subscription(ContactState, "child_state", received.append, 10)
    try:
        assert spin_until(executor, lambda: bool(received), 20.0), "nothing received from the child process"
        assert (received[0].force, received[0].phase) == (-0.25, ContactState.STICKING), "child ContactState"
    finally:
        child.communicate(timeout=TIMEOUT)
        listener.destroy_node()
        executor.shutdown(timeout_sec=1.0)


def test_messages_import_with_no_ros_environment() -> None:
    code = (
        "from viscoadh_msgs.msg import ContactState, IndentationCommand; "
        "from viscoadh_msgs.srv import SimulateHistory, PredictPullOff; print(ContactState.DETACHING)"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env={}, cwd="/", capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, f"import with an empty environment failed:\n{done.stderr}"
    assert done.stdout.strip() == "3", "ContactState.DETACHING from a bare environment"


def test_cli_help_lists_every_verb() -> None:
    from viscoadh_ros.cli.main import VERBS

    done = subprocess.run(
        [str(BIN / "viscoadh"), "--help"], env={}, cwd="/", capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, f"viscoadh --help failed:\n{done.stderr}"
    for verb in VERBS:
        assert f"\n    {verb} " in done.stdout, f"verb {verb!r} missing from viscoadh --help"


@pytest.mark.parametrize("package_xml", ["package.xml", "msg_defs/package.xml"])
def test_package_xml_passes_catkin_pkg_validation(package_xml: str) -> None:
    """colcon and rosdep read package.xml through catkin_pkg, which is strict."""
    from catkin_pkg.package import parse_package

    package = parse_package(str(REPO / package_xml))
    package.validate()
    assert package.package_format == 3, f"{package_xml}: format"
