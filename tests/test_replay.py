"""The node's own MCAP log, end to end: the node runs in-process with logging on and is driven
through an indent-hold-retract cycle on simulated time; its log is read with the mcap reader,
rosbags and rclpy, replayed by `viscoadh replay` (which must reproduce the node's forces) and
plotted by `viscoadh plot`."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import WrenchStamped
from mcap.reader import make_reader
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from rosgraph_msgs.msg import Clock
from viscoadh_msgs.msg import ContactState, IndentationCommand

from viscoadh_ros import __version__
from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.demo import _Driver, node_in_process
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.mcap_log import METADATA_NAME, SCENE_KEY, VERSION_KEY
from viscoadh_ros.ros.conversions import ns_to_stamp, stamp_to_ns

#: A standard-solid sphere (time-stepped model); the hold timer runs at its default 50 Hz, so
#: the log holds timer states between the commands too.
SCENE = SceneConfig.from_parameters(
    {
        "contacts": ["finger"],
        "finger.indenter.shape": "sphere",
        "finger.indenter.radius": 0.01,
        "finger.material.glass_shear_modulus": 1.0e6,
        "finger.material.kelvin_shear_moduli": [2.0e5],
        "finger.material.kelvin_viscosities": [2.0e3],
        "finger.adhesion.work_of_adhesion": 0.05,
        "finger.numerics.preset": "fast",
    }
)
START_S = 1.0  # simulated clock at the first command, s
#: Commands every 10 ms: press to 20 um in 0.3 s, hold 0.1 s, pull out to -30 um in 0.5 s,
#: then two idle commands 0.6 s apart so /diagnostics (1 Hz on the node clock) comes due.
TIMES = np.concatenate([np.arange(0.0, 0.3, 0.01), [0.4], np.arange(0.41, 0.9, 0.01), [1.5, 2.1]])
#: During the hold the clock alone moves on, so the node's hold timer publishes the relaxation.
HOLD_TICKS = np.arange(0.32, 0.4, 0.02)
DEPTHS = np.interp(TIMES, [0.0, 0.3, 0.4, 0.9], [-1e-6, 20e-6, 20e-6, -30e-6])


@dataclass
class NodeRun:
    log: Path
    answers: list[ContactState]  # the state the node answered each command with
    diagnostics: list[DiagnosticArray]


@pytest.fixture(scope="module")
def node_run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[NodeRun]:
    log = tmp_path_factory.mktemp("node") / "run.mcap"
    diagnostics: list[DiagnosticArray] = []
    with node_in_process(
        SCENE,
        use_sim_time=True,
        # The driver moves /clock after each answer; the next command may reach the node before
        # that clock (two topics, no order between them): at the first step, 1.0 -> 1.01 s on a
        # clock still at 0, 1.01 s ahead, was refused under the default 1 s (a CI failure).
        **{"log.enabled": True, "log.path": str(log), "command.max_future_s": 30.0},
    ) as (
        context,
        executor,
    ):
        client = Node("log_test_driver", context=context)
        client.create_subscription(DiagnosticArray, "/diagnostics", diagnostics.append, 10)
        executor.add_node(client)
        driver = _Driver(client, "finger", timeout=10.0)
        driver.wait_for_node()
        clock = client.create_publisher(Clock, "/clock", 1)
        answers = []
        for t, d in zip(TIMES, DEPTHS, strict=True):
            if np.isclose(t, 0.4):  # the end of the hold
                for tick in HOLD_TICKS:
                    clock.publish(Clock(clock=ns_to_stamp(round((START_S + tick) * 1e9))))
                    time.sleep(0.05)  # wall time for the node's timer to fire on the new clock
            answers.append(driver.command(START_S + t, d))
        # /diagnostics runs on the executor thread, the answers on the node's live thread: wait
        # for the diagnostics of the last clock period before the node is stopped.
        last_period_ns = int(START_S + TIMES[-1]) * 10**9
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline and not any(
            stamp_to_ns(array.header.stamp) >= last_period_ns for array in diagnostics
        ):
            time.sleep(0.01)
    yield NodeRun(log, answers, diagnostics)


def _messages(path: Path) -> dict[str, list[tuple[int, bytes]]]:
    """Topic -> [(log time ns, CDR bytes)] with the plain mcap reader; the file must be finished."""
    topics: dict[str, list[tuple[int, bytes]]] = {}
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        assert reader.get_header().profile == "ros2"
        assert reader.get_summary() is not None, "destroying the node must finish the log"
        for _, channel, message in reader.iter_messages(log_time_order=False):
            topics.setdefault(channel.topic, []).append((message.log_time, message.data))
    return topics


def test_node_log_holds_every_command_state_and_wrench(node_run: NodeRun) -> None:
    topics = _messages(node_run.log)
    assert set(topics) == {"/finger/indentation", "/finger/state", "/finger/wrench"}
    commands = [deserialize_message(data, IndentationCommand) for _, data in topics["/finger/indentation"]]
    np.testing.assert_allclose([c.depth for c in commands], DEPTHS, rtol=0, atol=0, err_msg="commands logged")
    # Log times are the node's clock (simulated here, not wall time): a command is logged no
    # later than its stamp's /clock tick, and never earlier than the one before it. (The node
    # may see a /clock tick after the next command under load: topics are not ordered.)
    stamps = [stamp_to_ns(c.header.stamp) for c in commands]
    log_times = [log_ns for log_ns, _ in topics["/finger/indentation"]]
    for k, log_ns in enumerate(log_times):
        earliest = log_times[k - 1] if k else 0
        assert earliest <= log_ns <= stamps[k], f"command {k}: log time {log_ns} ns off the node clock"

    states = [deserialize_message(data, ContactState) for _, data in topics["/finger/state"]]
    wrenches = [deserialize_message(data, WrenchStamped) for _, data in topics["/finger/wrench"]]
    assert len(states) == len(wrenches) > len(commands), "hold-timer states are logged as well as answers"
    np.testing.assert_array_equal(
        [w.wrench.force.z for w in wrenches], [s.force for s in states], err_msg="wrench z = state force"
    )
    logged = {(stamp_to_ns(s.header.stamp), s.force, s.contact_radius) for s in states}
    for k, answer in enumerate(node_run.answers):
        key = (stamp_to_ns(answer.header.stamp), answer.force, answer.contact_radius)
        assert key in logged, f"the state answering command {k} is not in the log"
    assert min(s.force for s in states) < 0.0, "the cycle must pull off (tensile force logged)"


def test_node_log_read_by_rosbags_and_bag(node_run: NodeRun) -> None:
    from rosbags.highlevel import AnyReader

    with AnyReader([node_run.log]) as reader:
        connections = {c.topic: c for c in reader.connections}
        assert connections["/finger/state"].msgtype == "viscoadh_msgs/msg/ContactState"
        forces = [
            reader.deserialize(raw, connection.msgtype).force
            for connection, _, raw in reader.messages(connections=[connections["/finger/state"]])
        ]
    bag = Bag(node_run.log)
    ours = [m.msg.force for m in bag.messages(["/finger/state"])]
    np.testing.assert_array_equal(forces, ours, err_msg="rosbags and rclpy decode the same states")

    # The metadata record: scene and version, enough to replay the log alone.
    with open(node_run.log, "rb") as stream:
        records = {m.name: m.metadata for m in make_reader(stream).iter_metadata()}
    assert records[METADATA_NAME][VERSION_KEY] == __version__
    stored = SceneConfig.from_dict(yaml.safe_load(records[METADATA_NAME][SCENE_KEY]))
    assert stored.contacts == SCENE.contacts, "the stored scene is the node's scene"
    assert stored.node.log_enabled, "the stored scene is the one the node ran (logging on)"


def test_log_status_in_diagnostics(node_run: NodeRun) -> None:
    statuses = [s for array in node_run.diagnostics for s in array.status if s.name == "/viscoadh: log"]
    assert statuses, "a logging node reports its log on /diagnostics"
    values: dict[str, Any] = {kv.key: kv.value for kv in statuses[-1].values}
    assert statuses[-1].level == DiagnosticStatus.OK, statuses[-1].message
    assert values["messages_dropped"] == "0" and int(values["messages_written"]) > 0, values


def test_replay_of_node_log_reproduces_its_forces(node_run: NodeRun, tmp_path: Path, capsys: Any) -> None:
    out = tmp_path / "replayed.mcap"
    summary_path = tmp_path / "summary.json"
    # No --scene: the scene comes from the log's metadata record.
    assert main(["replay", str(node_run.log), "-o", str(out), "--json", str(summary_path)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads(summary_path.read_text())
    assert set(summary) == {
        "bag",
        "contact",
        "input_topic",
        "force_topic",
        "output",
        "samples",
        "rmse_N",
        "max_error_N",
        "measured_pull_off_force_N",
        "model_pull_off_force_N",
        "replay_speed_x_real_time",
        "commands",
        "commands_rejected",
        "resets",
        "parameter_changes",
        "restarts",
        "materials",
    }
    # One stretch, one material: the record's own (no parameter change), no line printed.
    assert summary["materials"] == [{"from_s": 0.0, "changed": {}, "replaced": {}}]
    assert "material t =" not in printed
    assert summary["contact"] == "finger" and summary["force_topic"] == "/finger/wrench"
    logged = Bag(node_run.log)
    assert summary["samples"] == logged.message_count("/finger/wrench")
    peak = max(abs(m.msg.wrench.force.z) for m in logged.messages(["/finger/wrench"]))
    assert summary["max_error_N"] <= 1e-9 * peak, f"replay must reproduce the node's forces: {summary}"
    assert summary["measured_pull_off_force_N"] == pytest.approx(summary["model_pull_off_force_N"], rel=1e-9)
    assert summary["replay_speed_x_real_time"] > 0.0 and "x real time" in printed

    # OUT: the model's states and wrenches on the input stamps, readable by the same reader.
    replayed = Bag(out)
    states = [m.msg for m in replayed.messages(["/finger/state"])]
    assert len(states) == len(TIMES) == replayed.message_count("/finger/wrench")
    np.testing.assert_allclose(
        [s.force for s in states],
        [a.force for a in node_run.answers],
        rtol=1e-9,
        atol=1e-15,
        err_msg="replayed state at each command = the node's answer",
    )


@pytest.mark.parametrize("normalised", [False, True], ids=["SI", "figure4"])
def test_plot_from_node_log(node_run: NodeRun, tmp_path: Path, normalised: bool) -> None:
    figure = tmp_path / "loop.svg"
    args = ["plot", str(node_run.log), "-o", str(figure)] + (["--normalised"] if normalised else [])
    assert main(args) == 0
    text = figure.read_text()
    assert "<svg" in text and len(text) > 5000, "an SVG figure with the loop and its reference"
