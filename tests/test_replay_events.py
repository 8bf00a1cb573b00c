"""Replay of a node log that holds what a real session holds: rejected commands (a NaN, an
unknown mode, an older stamp), a `C/reset`, a runtime parameter change (work of adhesion
0.05 -> 0.2), a command stamped before a hold-timer tick it arrived after, and a stretch under
force control. The log is written here in the node's format (commands on receipt, then the
answer or the ContactEvent; hold-timer states; events on `C/events`) by `NodeRules`, which
applies the node's rules (ros/node.py `_Contact`) step by step with the public simulator; the
replay must reproduce every logged force to 1e-9 of the peak.

The scene is a standard-solid sphere with `numerics.model: time_stepped` (the 1D model)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scenes import STANDARD_SOLID_FINGER
from viscoadh_msgs.msg import ContactEvent, IndentationCommand

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import ContactConfig, SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator, StepOutput
from viscoadh_ros.experiment import load_experiment, run_model
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.mcap_log import McapRecorder, plain
from viscoadh_ros.ros import conversions

SCENE = SceneConfig.from_parameters(STANDARD_SOLID_FINGER)
MS = 1_000_000


class NodeRules:
    """One contact handled by the node's rules (ros/node.py ``_Contact.on_command``,
    ``on_timer``, ``_reset_locked``, ``replace_config_locked`` of the node that logs events:
    a contact with no command since start, reset or a parameter change is left at rest by the
    hold timer; a command stamped before the contact's last published state is applied, and
    answered, at that state's time; the timer publishes only past it), logging what the node
    logs."""

    def __init__(self, contact: ContactConfig, recorder: McapRecorder, *, events: bool = True) -> None:
        self.events = events  # False: a 0.1.0 node, which logged no events
        self.sim = ContactSimulator(contact)
        self.contact = contact
        self.rec = recorder
        self.epoch: int | None = None
        self.last_command: int | None = None
        self.time: int | None = None  # the stamp of the last published state since a restart
        self.hold: dict[str, float] = {}
        self.count = 0  # commands received since start
        self.rejected = 0
        self.forces: list[float] = []  # every published (logged) force, in order
        self.answers: list[int] = []  # the stamps of the accepted commands' states

    def _sim_time(self, ns: int) -> float:
        if self.epoch is None:
            self.epoch = ns
        return (ns - self.epoch) * 1e-9

    def _publish(self, output: StepOutput, stamp_ns: int, now_ns: int) -> None:
        wrench = conversions.wrench(output, stamp_ns=stamp_ns, frame_id="contact")
        self.rec.record("/finger/wrench", wrench, now_ns)
        self.forces.append(output.force)
        if self.last_command is not None:
            self.time = stamp_ns  # a rest heartbeat before the first command sets no time

    def _event(self, kind: int, now_ns: int, **fields: Any) -> None:
        if not self.events:
            return
        event = ContactEvent(contact_id="finger", kind=kind, **fields)
        event.header.stamp = conversions.ns_to_stamp(now_ns)
        self.rec.record("/finger/events", event, now_ns)

    def command(
        self, now_ns: int, stamp_ns: int, depth: float = 0.0, force: float = 0.0, mode: int = 0
    ) -> bool:
        msg = IndentationCommand(mode=mode, depth=depth, force=force)
        msg.header.stamp = conversions.ns_to_stamp(stamp_ns)
        self.rec.record("/finger/indentation", msg, now_ns)
        index, self.count = self.count, self.count + 1
        stamp = conversions.stamp_to_ns(msg.header.stamp) or now_ns
        try:
            control = conversions.command_control(msg)
            if self.last_command is not None and stamp < self.last_command:
                raise ValueError("header.stamp is older than the last command's")
            at = stamp if self.time is None else max(stamp, self.time)
            if self.last_command is None:
                self.sim.reset(time=0.0)
                self.epoch = at
            output = self.sim.step(self._sim_time(at), **control)
        except ValueError as error:
            self.rejected += 1
            self._event(
                ContactEvent.COMMAND_REJECTED,
                now_ns,
                command_index=index,
                command_stamp=msg.header.stamp,
                reason=f"command rejected: {error}",
            )
            return False
        self.hold, self.last_command = control, stamp
        self._publish(output, at, now_ns)
        self.answers.append(at)
        return True

    def tick(self, now_ns: int) -> None:
        if self.time is not None and now_ns <= self.time:
            return  # the last state already describes now or later
        # No command since start or reset: nothing to hold, the contact stays at rest.
        output = self.sim.output
        if self.last_command is not None:
            target = self._sim_time(now_ns)
            if target > self.sim.time:
                output = self.sim.step(target, **self.hold)
        self._publish(output, now_ns, now_ns)

    def reset(self, now_ns: int) -> None:
        self.sim.reset(time=0.0)
        self.epoch = self.last_command = self.time = None
        self.hold = {}
        self._event(ContactEvent.RESET, now_ns, reason="reset")

    def parameters(self, now_ns: int, contact: ContactConfig) -> None:
        assert self.sim.is_idle, "the node changes a contact's parameters only when idle"
        self.sim, self.contact = ContactSimulator(contact), contact
        self.epoch = self.last_command = self.time = None
        self.hold = {}
        scene = dataclasses.replace(SCENE, contacts=(contact,))
        self._event(
            ContactEvent.PARAMETERS,
            now_ns,
            reason="finger.adhesion.work_of_adhesion",
            contact_yaml=yaml.safe_dump(plain(scene.to_dict()), sort_keys=False),
        )


def _cycle(node: NodeRules, start_ns: int, *, pull_to: float = -30e-6) -> int:
    """Press to 20 um in 0.3 s, hold 0.1 s (hold-timer ticks), pull out to `pull_to` in 0.5 s;
    commands every 10 ms, received 1 ms after their stamp. Returns the last stamp."""
    times = np.concatenate([np.arange(0, 300, 10), np.arange(400, 910, 10)])
    depths = np.interp(times, [0, 300, 400, 900], [-1e-6, 20e-6, 20e-6, pull_to])
    for t, d in zip(times.tolist(), depths.tolist(), strict=True):
        stamp = start_ns + t * MS
        if t == 400:
            for tick in range(320, 400, 20):
                node.tick(start_ns + tick * MS)
        node.command(stamp + MS, stamp, depth=d)
    return start_ns + 900 * MS


def _session(path: Path, *, events: bool = True) -> tuple[list[float], dict[str, int], list[int]]:
    """The log of a session; returns the logged forces, the node's counts and the stamps of the
    accepted commands' states."""
    counts = {"rejected": 0, "accepted": 0}
    with McapRecorder(path, scene=SCENE.to_dict(), queue_size=100_000) as rec:
        node = NodeRules(SCENE.contact("finger"), rec, events=events)
        t = 1_000 * MS
        # Cycle 1 with refused commands in its loading: a NaN, an unknown mode, an older stamp
        # (a depth that would crush the sample if applied), then a command stamped before a
        # hold tick it arrives after (the node applies it at the tick's time).
        node.command(t + 1 * MS, t, depth=-1e-6)
        node.command(t + 6 * MS, t + 5 * MS, depth=float("nan"))
        node.command(t + 7 * MS, t + 6 * MS, depth=5e-6, mode=7)
        node.command(t + 11 * MS, t + 10 * MS, depth=1e-6)
        node.command(t + 12 * MS, t + 8 * MS, depth=50e-6)
        node.tick(t + 25 * MS)
        node.command(t + 26 * MS, t + 20 * MS, depth=2e-6)
        end = _cycle(node, t + 30 * MS)
        # A stretch under force control in contact, then depth again.
        node.command(end + 11 * MS, end + 10 * MS, depth=15e-6)
        for k in range(2, 6):
            node.command(end + (10 * k + 1) * MS, end + 10 * k * MS, force=5e-3, mode=1)
        node.tick(end + 65 * MS)
        node.command(end + 71 * MS, end + 70 * MS, depth=-30e-6)
        t = end + 100 * MS
        if events:
            node.reset(t)
            node.tick(t + 20 * MS)
            node.tick(t + 40 * MS)
            # The first command after the reset, stamped before the rest heartbeats it arrives
            # after: its history starts at its own stamp (a heartbeat describes no history).
            node.command(t + 41 * MS, t + 30 * MS, depth=-2e-6)
            # The same cycle again, then a parameter change once idle, ticks, a third cycle.
            end = _cycle(node, t + 100 * MS)
            t = end + 500 * MS
            node.tick(t)  # relaxed and out of touch by now
            stronger = dataclasses.replace(
                node.contact, adhesion=dataclasses.replace(node.contact.adhesion, work_of_adhesion=0.2)
            )
            node.parameters(t + 10 * MS, stronger)
            node.tick(t + 20 * MS)
            node.tick(t + 40 * MS)
            _cycle(node, t + 100 * MS, pull_to=-60e-6)
        counts = {"rejected": node.rejected, "accepted": node.count - node.rejected}
    return node.forces, counts, node.answers


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[float], dict[str, int], list[int]]:
    path = tmp_path_factory.mktemp("events") / "session.mcap"
    return path, *_session(path)


def test_replay_reproduces_rejections_reset_and_parameter_change(
    session: tuple[Path, list[float], dict[str, int], list[int]], tmp_path: Path
) -> None:
    path, forces, counts, answers = session
    summary_path, out = tmp_path / "summary.json", tmp_path / "out.mcap"
    assert main(["replay", str(path), "-o", str(out), "--json", str(summary_path)]) == 0
    summary = json.loads(summary_path.read_text())
    peak = max(abs(f) for f in forces)
    assert summary["samples"] == len(forces), "every logged force"
    assert summary["max_error_N"] <= 1e-9 * peak, summary
    assert counts["rejected"] == 3, "the session refuses a NaN, an unknown mode, an older stamp"
    assert summary["commands_rejected"] == 3 and summary["restarts"] == 2, summary
    # The change matters: the third cycle pulls off harder than the first (w x4).
    pulls = [min(forces[: len(forces) // 3]), min(forces)]
    assert pulls[1] < 1.5 * pulls[0] < 0.0, pulls
    assert summary["model_pull_off_force_N"] == pytest.approx(summary["measured_pull_off_force_N"], rel=1e-9)

    # Each event matters: without the parameter change, or with the inputs in stamp order
    # (the 0.1.0 replay), the forces diverge.
    experiment = load_experiment(Bag(path))
    contact = SCENE.contact("finger")
    for label, run in {
        "parameter change ignored": run_model(contact, experiment, parameters=False),
        "stamp order": run_model(contact, dataclasses.replace(experiment, by_arrival=False, restarts=())),
    }.items():
        error = np.max(np.abs(run.model_force - experiment.measured_force))
        assert error > 1e-3 * peak, f"{label}: the session does not exercise it ({error} N)"

    # OUT holds one state per accepted command, with the node's counters.
    states = [m.msg for m in Bag(out).messages(["/finger/state"])]
    assert len(states) == counts["accepted"]
    assert [s.commands_received for s in states] == list(range(1, counts["accepted"] + 1))
    assert states[0].commands_rejected == 0 and states[-1].commands_rejected == counts["rejected"]
    assert states[3].commands_rejected == 3, "NaN, unknown mode and older stamp before the 4th"
    # ... stamped as the node stamped its answers: a command stamped before a hold tick it
    # arrived after, at the tick's time (the 0.8.0 replay used its stamp).
    stamps = [conversions.stamp_to_ns(s.header.stamp) for s in states]
    assert stamps == answers


def test_log_without_events_still_replays(tmp_path: Path) -> None:
    """A 0.1.0 log has no events: what the node always refuses (NaN, unknown mode, an older
    stamp) is recognised without them."""
    path = tmp_path / "old.mcap"
    forces, _, _ = _session(path, events=False)
    summary_path = tmp_path / "summary.json"
    assert main(["replay", str(path), "-o", str(tmp_path / "o.mcap"), "--json", str(summary_path)]) == 0
    summary = json.loads(summary_path.read_text())
    assert summary["max_error_N"] <= 1e-9 * max(abs(f) for f in forces), summary
    assert summary["commands_rejected"] == 3 and summary["restarts"] == 0, summary


def test_event_naming_a_command_the_log_lacks_is_an_error(tmp_path: Path, capsys: Any) -> None:
    path = tmp_path / "bad.mcap"
    with McapRecorder(path, scene=SCENE.to_dict()) as rec:
        node = NodeRules(SCENE.contact("finger"), rec)
        for k in range(3):
            node.command((k + 1) * 10 * MS, (k + 1) * 10 * MS, depth=1e-6 * k)
        event = ContactEvent(contact_id="finger", kind=ContactEvent.COMMAND_REJECTED, command_index=7)
        rec.record("/finger/events", event, 50 * MS)
    assert main(["replay", str(path), "-o", str(tmp_path / "o.mcap")]) == 2
    err = capsys.readouterr().err
    assert "rejects command 7" in err and "incomplete" in err, err


def test_recording_by_another_recorder_with_events_replays_by_the_node_rules(
    session: tuple[Path, list[float], dict[str, int], list[int]], tmp_path: Path
) -> None:
    """The same session copied by a plain MCAP writer (what `ros2 bag record` makes: no
    viscoadh metadata, so the scene comes from --scene): its `finger/events` make it a node
    log all the same."""
    from mcap.reader import make_reader
    from mcap.writer import Writer

    path, forces, _, _ = session
    copy, scene_file = tmp_path / "rosbag.mcap", tmp_path / "scene.yaml"
    with open(path, "rb") as source, open(copy, "wb") as target:
        reader, writer = make_reader(source), Writer(target)
        writer.start(profile="ros2")
        channels: dict[int, int] = {}
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if channel.id not in channels:
                schema_id = writer.register_schema(schema.name, schema.encoding, schema.data)
                channels[channel.id] = writer.register_channel(channel.topic, "cdr", schema_id)
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time)
        writer.finish()
    assert Bag(copy).software_version is None and Bag(copy).scene() is None
    scene_file.write_text(yaml.safe_dump(plain(SCENE.to_dict()), sort_keys=False))
    summary_path = tmp_path / "summary.json"
    args = ["replay", str(copy), "--scene", str(scene_file), "-o", str(tmp_path / "o.mcap")]
    assert main([*args, "--json", str(summary_path)]) == 0
    summary = json.loads(summary_path.read_text())
    assert summary["max_error_N"] <= 1e-9 * max(abs(f) for f in forces), summary
    assert summary["commands_rejected"] == 3 and summary["restarts"] == 2, summary


def test_replay_output_keeps_the_run_order_when_stamps_go_back_across_a_restart(tmp_path: Path) -> None:
    """After a reset the next command may carry an earlier stamp (a new time origin): the node
    log keeps recording order, and the replay's output must too. It was written in stamp order,
    so the two histories' rows alternated in the file (a third outside tester, after a clock
    jump back)."""
    path, out = tmp_path / "back.mcap", tmp_path / "out.mcap"
    with McapRecorder(path, scene=SCENE.to_dict(), queue_size=100_000) as rec:
        node = NodeRules(SCENE.contact("finger"), rec)
        end = _cycle(node, 2_000 * MS)
        node.reset(end + 10 * MS)
        _cycle(node, 1_000 * MS)  # stamped before the first cycle: stamps go back once
    assert main(["replay", str(path), "-o", str(out)]) == 0
    states = [m.msg for m in Bag(out).messages(["/finger/state"])]
    assert [s.commands_received for s in states] == list(range(1, len(node.answers) + 1))
    assert [conversions.stamp_to_ns(s.header.stamp) for s in states] == node.answers
