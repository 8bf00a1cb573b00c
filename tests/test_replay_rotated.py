"""A rotated node log (``log.max_duration``) replayed file by file, as an outside tester did.

The real node (in process, simulated clock) runs two contacts through a press, a pull-off and
a second cycle after a reset, with rejected commands on c0, logging with
``log.max_duration: 1.0``: file 0 holds the start, file 1 the pull-off (the middle of each
contact's history: the contacts have received ~30 commands before it), file 2 starts with a
``C/reset`` of each contact. Replaying file 1 alone used to start a fresh contact halfway
through (c1: exit 0, an RMSE of tens of mN against the node's own wrench, no warning) or call
the log "incomplete" (c0, whose rejection events name commands by their index since the
node started); file 2 alone was refused the same way although the reset makes it exact. Both
forms of the log: one ``.mcap`` path (``<stem>_<i>.mcap``) and a rosbag2 folder.
"""

from __future__ import annotations

import json
import shutil
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from scenes import call_service, node_contacts_scene
from std_srvs.srv import Trigger
from viscoadh_msgs.msg import ContactEvent, IndentationCommand

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.demo import _Driver, node_in_process
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.ros.conversions import ns_to_stamp

SCENE = SceneConfig.from_parameters(node_contacts_scene(2))
CONTACTS = ("c0", "c1")


class _Session:
    """Drivers of both contacts, a raw publisher for refused commands, the reset services."""

    def __init__(self, client: Node) -> None:
        self.drivers = {c: _Driver(client, c, timeout=10.0) for c in CONTACTS}
        self.raw = client.create_publisher(IndentationCommand, "c0/indentation", 10)
        self.clock = client.create_publisher(Clock, "/clock", 1)
        self.resets = {c: client.create_client(Trigger, f"{c}/reset") for c in CONTACTS}
        self.events: list[ContactEvent] = []
        self.seen = threading.Condition()
        client.create_subscription(ContactEvent, "c0/events", self._on_event, 50)

    def _on_event(self, event: ContactEvent) -> None:
        with self.seen:
            self.events.append(event)
            self.seen.notify_all()

    def refused(self, t: float) -> None:
        """A NaN depth on c0 stamped ``t``, which the node rejects."""
        command = IndentationCommand(mode=IndentationCommand.DEPTH, depth=float("nan"))
        command.header.stamp = ns_to_stamp(round(t * 1e9))
        with self.seen:
            count = len(self.events)
            self.raw.publish(command)
            assert self.seen.wait_for(lambda: len(self.events) > count, 10.0), self.events
        assert self.events[-1].kind == ContactEvent.COMMAND_REJECTED

    def ramp(
        self, start: float, stop: float, d0: float, d1: float, *, refuse_at: float | None = None
    ) -> None:
        """Both contacts from ``d0`` to ``d1`` (m) over ``start`` .. ``stop`` s, every 10 ms."""
        for t in np.arange(start, stop + 1e-9, 0.01):
            if refuse_at is not None and t > refuse_at:
                self.refused(refuse_at)
                refuse_at = None
            depth = float(np.interp(t, [start, stop], [d0, d1]))
            for contact in CONTACTS:
                self.drivers[contact].command(float(t), depth)

    def move_clock(self, t: float) -> None:
        self.clock.publish(Clock(clock=ns_to_stamp(round(t * 1e9))))
        time.sleep(0.2)

    def reset(self, contact: str) -> None:
        assert call_service(self.resets[contact], Trigger.Request()).success


def _log(path: Path) -> None:
    """The node's rotated log of the session at ``path`` (a ``.mcap`` path or a folder)."""
    with node_in_process(
        SCENE,
        use_sim_time=True,
        **{"log.enabled": True, "log.path": str(path), "log.max_duration": 1.0},
    ) as (context, executor):
        client = Node("rotated_log_driver", context=context)
        session = _Session(client)
        executor.add_node(client)
        for driver in session.drivers.values():
            driver.wait_for_node()
        session.move_clock(1.0)
        # File 0: the press (a refused command on c0).
        session.ramp(1.0, 1.3, -1e-6, 20e-6, refuse_at=1.105)
        # File 1: the pull-off, then out of touch (a refused command on c0).
        session.ramp(2.0, 2.4, 20e-6, -30e-6, refuse_at=2.105)
        session.ramp(2.9, 2.9, -30e-6, -30e-6)
        # File 2: each contact reset, then a second cycle (a refused command on c0).
        session.move_clock(3.5)
        for contact in CONTACTS:
            session.reset(contact)
        session.ramp(3.5, 3.7, -1e-6, 20e-6, refuse_at=3.605)
        session.ramp(3.71, 3.9, 20e-6, -30e-6)


@pytest.fixture(scope="module", params=["file", "folder"])
def rotated(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, list[Path]]:
    """(form, the log's files in order)."""
    folder = tmp_path_factory.mktemp(f"rotated_{request.param}")
    if request.param == "file":
        _log(folder / "session.mcap")
        files = sorted(folder.glob("session_*.mcap"))
    else:
        _log(folder / "session")
        files = sorted((folder / "session").glob("session_*.mcap"))
    assert [f.name for f in files] == ["session_0.mcap", "session_1.mcap", "session_2.mcap"], files
    return request.param, files


def _replay(bag: Path, contact: str, tmp_path: Path) -> tuple[int, dict[str, Any]]:
    """Exit code and summary of `viscoadh replay BAG --contact C` (written beside tmp_path)."""
    summary, out = tmp_path / f"{bag.stem}_{contact}.json", tmp_path / f"{bag.stem}_{contact}.mcap"
    code = main(["replay", str(bag), "--contact", contact, "-o", str(out), "--json", str(summary)])
    return code, json.loads(summary.read_text()) if code == 0 else {}


def _peak(bag: Path, contact: str) -> float:
    return max(abs(m.msg.wrench.force.z) for m in Bag(bag).messages([f"/{contact}/wrench"]))


def test_a_file_from_the_middle_of_the_history_is_refused(
    rotated: tuple[str, list[Path]], tmp_path: Path, capsys: Any
) -> None:
    form, files = rotated
    middle = files[1]
    for contact in ("c1", "c0"):  # c1: no event in the file; c0: rejections named by node-wide index
        code, _ = _replay(middle, contact, tmp_path)
        err = capsys.readouterr().err
        assert code == 2, (contact, err)
        assert f"contact '{contact}'" in err and "middle of the contact's history" in err, err
        assert "incomplete" not in err, err
        if form == "folder":
            assert f"replay the whole rosbag2 folder {str(middle.parent)!r}" in err, err
        else:
            assert "session_0.mcap" in err and "one folder" in err, err
        assert len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / f"{middle.stem}_{contact}.mcap").exists()
    fit = ["fit", str(middle), "--contact", "c1", "--free", "work_of_adhesion", "--no-report"]
    assert main([*fit, "-o", str(tmp_path / "fit.yaml")]) == 2
    err = capsys.readouterr().err
    assert "contact 'c1'" in err and "middle of the contact's history" in err, err
    assert not (tmp_path / "fit.yaml").exists()


def test_the_first_file_and_a_file_that_starts_with_a_reset_replay_alone(
    rotated: tuple[str, list[Path]], tmp_path: Path
) -> None:
    _, files = rotated
    for contact in CONTACTS:
        code, summary = _replay(files[0], contact, tmp_path)
        assert code == 0 and summary["max_error_N"] <= 1e-9 * _peak(files[0], contact), summary
        code, summary = _replay(files[2], contact, tmp_path)
        assert code == 0, contact
        assert summary["max_error_N"] <= 1e-9 * _peak(files[2], contact), summary
        assert summary["resets"] == 1, summary
    assert summary["commands_rejected"] == 0, summary
    code, summary = _replay(files[2], "c0", tmp_path)
    assert summary["commands_rejected"] == 1, summary
    # The replayed states carry the node's counters (since the node started, not the file).
    logged = list(Bag(files[2]).messages(["/c0/state"]))[-1].msg
    replayed = list(Bag(tmp_path / "session_2_c0.mcap").messages(["/c0/state"]))[-1].msg
    assert (replayed.commands_received, replayed.commands_rejected) == (
        logged.commands_received,
        logged.commands_rejected,
    )
    assert logged.commands_rejected == 3


def test_the_whole_log_replays_exactly(rotated: tuple[str, list[Path]], tmp_path: Path) -> None:
    form, files = rotated
    if form == "folder":
        whole = files[0].parent
    else:  # what the refusal advises: the files of the rotated log in one folder
        whole = tmp_path / "session"
        whole.mkdir()
        for file in files:
            shutil.copy(file, whole / file.name)
    for contact in CONTACTS:
        code, summary = _replay(whole, contact, tmp_path)
        assert code == 0, contact
        peak = max(_peak(f, contact) for f in files)
        assert summary["max_error_N"] <= 1e-9 * peak, summary
        assert summary["commands_rejected"] == (3 if contact == "c0" else 0), summary


def _folder(tmp_path: Path, name: str, files: dict[str, Path]) -> Path:
    """A folder (no metadata.yaml) holding ``files`` under the names given."""
    folder = tmp_path / name
    folder.mkdir()
    for target, source in files.items():
        shutil.copy(source, folder / target)
    return folder


def _refused(bag: Path, tmp_path: Path, capsys: Any) -> str:
    """The one-line error of replaying (and fitting) ``bag``, which must be refused."""
    for contact in CONTACTS:
        code, _ = _replay(bag, contact, tmp_path)
        err = capsys.readouterr().err
        assert code == 2, (contact, err)
        assert len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / f"{bag.stem}_{contact}.mcap").exists()
    fit = ["fit", str(bag), "--contact", "c1", "--free", "work_of_adhesion", "--no-report"]
    assert main([*fit, "-o", str(tmp_path / "fit.yaml")]) == 2
    assert not (tmp_path / "fit.yaml").exists()
    assert capsys.readouterr().err == err.replace("viscoadh replay:", "viscoadh fit:", 1)
    return err


def test_a_folder_with_a_file_missing_is_refused(
    rotated: tuple[str, list[Path]], tmp_path: Path, capsys: Any
) -> None:
    """An outside tester's rotated log with one file left out replayed with exit 0 and a
    model pull-off of -13.9 mN against the node's -31.5 mN."""
    _, files = rotated
    gap = _folder(tmp_path, "gap", {"session_0.mcap": files[0], "session_2.mcap": files[2]})
    err = _refused(gap, tmp_path, capsys)
    assert "lacks session_1.mcap" in err and "no metadata.yaml" in err, err
    # The same with the files renumbered: the counters in the later file show the commands
    # missing.
    renamed = _folder(tmp_path, "renamed", {"session_0.mcap": files[0], "session_1.mcap": files[2]})
    err = _refused(renamed, tmp_path, capsys)
    assert "not one history of the contact" in err and "ContactState counters in session_1.mcap" in err, err
    assert "missing" in err, err


def test_a_folder_with_a_repeated_file_or_another_run_is_refused(
    rotated: tuple[str, list[Path]], tmp_path: Path, capsys: Any
) -> None:
    """A copy of file 1 beside the log, and two logs in one folder, replayed with exit 0 (the
    tester's run: "skipped 63 the node rejected", though the node rejected none)."""
    _, files = rotated
    whole = {f.name: f for f in files}
    copy = _folder(tmp_path, "copy", {**whole, "session_1_copy.mcap": files[1]})
    err = _refused(copy, tmp_path, capsys)
    assert "session_1_copy.mcap is not numbered" in err, err
    two = _folder(tmp_path, "two", {**whole, **{f"other_{k}.mcap": f for k, f in enumerate(files)}})
    err = _refused(two, tmp_path, capsys)
    assert "several logs" in err and "other_*.mcap (3 files)" in err and "session_*.mcap" in err, err
    # Named as the log's next file: the counters say what it is. A copy of file 1, and the
    # start of another run of the node (file 0 again: its counters start at 1).
    for label, source in (("repeat", files[1]), ("restart", files[0])):
        extra = _folder(tmp_path, label, {**whole, "session_3.mcap": source})
        err = _refused(extra, tmp_path, capsys)
        assert "ContactState counters in session_3.mcap" in err and "fewer commands" in err, err
        assert "another run of the node" in err, err
