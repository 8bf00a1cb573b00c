"""A node log with a runtime parameter change, replayed (and fitted, plotted) with a scene of
the user's, as an outside tester did.

The real node (in process, simulated clock) logs to a rotated ``.mcap`` path
(``log.max_duration``): a press-pull cycle of the standard-solid finger (w = 0.05 J/m^2), a
change of the work of adhesion to 0.2 (a PARAMETERS event), a second cycle. Replayed with
``--scene`` of a candidate material (G0 doubled), replay used to switch to the logged material
at the change, silently: bit for bit the node's own answer after it (model pull-off = measured).
It now runs the candidate throughout with the parameters the change set applied on top, and
says so. The files the recorder starts after the change store the new scene (they stored the
start-up one, and `viscoadh plot` drew the w = 0.05 reference over data at w = 0.2).
"""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.msg import ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from scenes import STANDARD_SOLID_FINGER, call_service

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.demo import _Driver, node_in_process
from viscoadh_ros.experiment import PARAMETERS, load_experiment, materials, run_model, stretch
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.mcap_log import plain
from viscoadh_ros.ros.conversions import ns_to_stamp

SCENE = SceneConfig.from_parameters(STANDARD_SOLID_FINGER)
#: Press to 20 um in 0.2 s, pull out to -30 um by 0.5 s, commands every 10 ms.
TIMES = np.arange(0.0, 0.5, 0.01)
DEPTHS = np.interp(TIMES, [0.0, 0.2, 0.5], [-1e-6, 20e-6, -30e-6])


@pytest.fixture(scope="module")
def log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of the rotated log's files (``session_<i>.mcap``)."""
    folder = tmp_path_factory.mktemp("parameters_log")
    params = {
        "log.enabled": True,
        "log.path": str(folder / "session.mcap"),
        "log.max_duration": 0.4,
        "command.max_future_s": 30.0,
    }
    with node_in_process(SCENE, use_sim_time=True, **params) as (context, executor):
        client = Node("parameters_log_driver", context=context)
        driver = _Driver(client, "finger", timeout=10.0)
        clock = client.create_publisher(Clock, "/clock", 1)
        parameters = client.create_client(SetParameters, "/viscoadh/set_parameters")
        executor.add_node(client)
        driver.wait_for_node()
        clock.publish(Clock(clock=ns_to_stamp(1_000_000_000)))
        time.sleep(0.1)

        def cycle(start: float) -> None:
            for t, d in zip(TIMES, DEPTHS, strict=True):
                driver.command(start + t, d)
            driver.command(start + 1.0, DEPTHS[-1])  # out of touch and relaxed

        cycle(1.0)
        value = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=0.2)
        change = SetParameters.Request(
            parameters=[ParameterMsg(name="finger.adhesion.work_of_adhesion", value=value)]
        )
        result = call_service(parameters, change).results[0]
        assert result.successful, result.reason
        time.sleep(0.1)
        cycle(3.0)
    files = sorted(folder.glob("session_*.mcap"), key=lambda f: int(f.stem.split("_")[1]))
    assert len(files) >= 4, files
    return folder


def _scene_file(tmp_path: Path, name: str, **changes: Any) -> Path:
    """The logged scene with ``changes`` (flat keys) as a YAML file."""
    flat = {**SCENE.to_parameters(), **changes}
    path = tmp_path / name
    path.write_text(yaml.safe_dump(plain(SceneConfig.from_parameters(flat).to_dict()), sort_keys=False))
    return path


def _replay(log: Path, tmp_path: Path, *extra: str) -> dict[str, Any]:
    summary = tmp_path / "summary.json"
    assert main(["replay", str(log), "-o", str(tmp_path / "out.mcap"), "--json", str(summary), *extra]) == 0
    return json.loads(summary.read_text())


def test_replay_with_a_candidate_scene_applies_the_logged_change_on_top(
    log: Path, tmp_path: Path, capsys: Any
) -> None:
    candidate = _scene_file(tmp_path, "candidate.yaml", **{"finger.material.glass_shear_modulus": 2.0e6})
    summary = _replay(log, tmp_path, "--scene", str(candidate))
    printed = capsys.readouterr().out
    # Each stretch says what it ran with.
    assert f"material t = 0 s on: 'finger' of --scene {str(candidate)!r}" in printed, printed
    assert (
        "the logged parameter change adhesion.work_of_adhesion 0.05 -> 0.2 applied to the --scene contact"
        in printed
    ), printed
    assert summary["materials"][1]["changed"] == {"adhesion.work_of_adhesion": [0.05, 0.2]}, summary
    # After the change: the candidate (G0 = 2 MPa) with w = 0.2, not the node's G0 = 1 MPa.
    experiment = load_experiment(Bag(log))
    (change,) = [r for r in experiment.restarts if r.kind == PARAMETERS]
    contact = SceneConfig.from_yaml(candidate).contact("finger")
    after = dataclasses.replace(contact, adhesion=dataclasses.replace(contact.adhesion, work_of_adhesion=0.2))
    expected = run_model(after, stretch(experiment, change.order, None), parameters=False).model_force.min()
    assert summary["model_pull_off_force_N"] == pytest.approx(float(expected), rel=1e-12), summary
    measured = summary["measured_pull_off_force_N"]
    assert abs(summary["model_pull_off_force_N"] - measured) > 1e-3 * abs(measured), summary
    assert summary["max_error_N"] > 1e-3 * abs(measured), "the candidate is not the node's material"

    # With the logged scene, and without --scene: the node's material throughout, exactly.
    (tmp_path / "same").mkdir()
    summary = _replay(log, tmp_path / "same", "--scene", str(_scene_file(tmp_path, "same.yaml")))
    assert summary["max_error_N"] == 0.0, summary
    (tmp_path / "logged").mkdir()
    summary = _replay(log, tmp_path / "logged")
    assert summary["max_error_N"] == 0.0 and summary["materials"][1]["replaced"] == {}, summary
    assert "the node's contact after the logged parameter change" in capsys.readouterr().out


def test_a_scene_value_the_change_replaces_is_named(log: Path, tmp_path: Path, capsys: Any) -> None:
    """A candidate with its own work of adhesion: the change sets the node's new value (the
    experiment changed it), and the output names the candidate's value it replaced."""
    candidate = _scene_file(tmp_path, "w.yaml", **{"finger.adhesion.work_of_adhesion": 0.1})
    summary = _replay(log, tmp_path, "--scene", str(candidate))
    assert summary["materials"][1]["replaced"] == {"adhesion.work_of_adhesion": 0.1}, summary
    assert "(replacing the scene's adhesion.work_of_adhesion 0.1)" in capsys.readouterr().out


def test_a_change_that_cannot_apply_to_the_scene_is_refused(log: Path, tmp_path: Path, capsys: Any) -> None:
    """A scene whose material form takes the change (a Prony series, the change touching the
    adhesion only) replays; a logged change of the Kelvin chain cannot apply to a chain of
    another length: the replay is refused, naming the change, nothing written."""
    flat = {k: v for k, v in SCENE.to_parameters().items() if ".material." not in k}
    flat["finger.material.prony_long_term_modulus"] = 1.0e5
    flat["finger.material.prony_moduli"] = [1.0e5]
    flat["finger.material.prony_times"] = [0.01]
    prony = tmp_path / "prony.yaml"
    prony.write_text(yaml.safe_dump(plain(SceneConfig.from_parameters(flat).to_dict()), sort_keys=False))
    summary = _replay(log, tmp_path, "--scene", str(prony))
    assert summary["materials"][1]["changed"] == {"adhesion.work_of_adhesion": [0.05, 0.2]}, summary

    experiment = load_experiment(Bag(log))
    (change,) = [r for r in experiment.restarts if r.kind == PARAMETERS]
    logged = SCENE.contact("finger")
    stiffer = dataclasses.replace(logged.material, kelvin_shear_moduli=(3.0e5,))
    scene = dataclasses.replace(SCENE, contacts=(dataclasses.replace(logged, material=stiffer),))
    edited = dataclasses.replace(change, contact_yaml=yaml.safe_dump(plain(scene.to_dict())))
    record = dataclasses.replace(
        experiment, restarts=tuple(edited if r == change else r for r in experiment.restarts)
    )
    two = _scene_file(
        tmp_path,
        "k2.yaml",
        **{
            "finger.material.kelvin_shear_moduli": [2.0e5, 1.0e5],
            "finger.material.kelvin_viscosities": [2e3, 1e4],
        },
    )
    user = SceneConfig.from_yaml(two).contact("finger")
    with pytest.raises(
        InputError, match=r"logged parameter change at t = .* \(material.kelvin_shear_moduli\)"
    ):
        materials(record, user, logged=logged, given=True)
    # The node's own contact takes it, as logged.
    (_, after) = materials(record, logged, logged=None, given=False)
    assert after.contact.material.kelvin_shear_moduli == (3.0e5,)
    assert after.changed == {"material.kelvin_shear_moduli": ([2.0e5], [3.0e5])}


def test_files_started_after_the_change_store_the_new_scene(log: Path) -> None:
    files = sorted(log.glob("session_*.mcap"), key=lambda f: int(f.stem.split("_")[1]))
    whole = Bag(log)
    (change,) = [r for r in load_experiment(whole).restarts if r.kind == PARAMETERS]
    stored = []
    for k, file in enumerate(files):
        w = SceneConfig.from_dict(Bag(file).scene()).contact("finger").adhesion.work_of_adhesion
        stored.append(w)
        assert w == (0.2 if whole.file_starts[k] > change.order else 0.05), (file.name, w)
    assert stored[0] == 0.05 and stored[-1] == 0.2, stored
    # The log as a whole starts with the start-up scene.
    assert SceneConfig.from_dict(whole.scene()).contact("finger").adhesion.work_of_adhesion == 0.05


def test_a_fit_after_the_change_with_a_scene_holds_what_the_change_set(log: Path, tmp_path: Path) -> None:
    """`fit --scene` of the stretch after the change starts from the scene with the change's
    parameters set, as replay runs it: the held work of adhesion is the node's 0.2 there (it
    held the scene's 0.05, and G0 came out to fit the wrong adhesion)."""
    from viscoadh_ros.fitting import fit_bag

    experiment = load_experiment(Bag(log))
    (change,) = [r for r in experiment.restarts if r.kind == PARAMETERS]
    after = float(experiment.time(np.array([change.ns]))[0]) + 0.01
    candidate = _scene_file(tmp_path, "candidate.yaml", **{"finger.material.glass_shear_modulus": 2.0e6})
    done = fit_bag(str(log), {"scene": str(candidate), "free": "G0", "time_range": [after, 100.0]})
    assert done.changed_at is not None
    assert done.result.contact.adhesion.work_of_adhesion == 0.2
    # Within 2 %: the log is noiseless, and the fit's grid (11136 elements) gives back G0 = 1e6
    # to 1e-6 from the same log recorded at 8192 elements; what moves G0 is the node's own grid
    # (`fast`, 64 elements) in the record. Measured (benchmarks/rounds/0.11.0-centre.md, session
    # 12): 0.11.0's record, whose force dipped at each element-centre crossing, +0.43 %; the same
    # with the 12 rows the centre-crossing blend moves set to 8192 elements' force +1.82 %, with
    # all its other rows so set instead -1.36 % (the dips offset the rest: the old 1 % bound held
    # by that); with the blend +1.40 %. The bound is that grid's error, not the fit's; the held
    # work of adhesion is checked above.
    assert done.result.values["G0"] == pytest.approx(1.0e6, rel=2e-2), done.result.values


def test_plot_draws_the_reference_of_the_scene_in_force(
    log: Path, tmp_path: Path, capsys: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`viscoadh plot` of the whole log (a change in it) and of its last file (recorded after
    the change): the reference is the w = 0.2 contact's, and a change in the record is said;
    the loops break at the change (no line from one material's history into the other's)."""
    from viscoadh_ros.cli import plot
    from viscoadh_ros.plotting import JkrReference

    drawn: list[float] = []
    original = JkrReference.from_contact

    def spy(contact: Any) -> Any:
        drawn.append(contact.adhesion.work_of_adhesion)
        return original(contact)

    monkeypatch.setattr(JkrReference, "from_contact", spy)
    last = max(log.glob("session_*.mcap"), key=lambda f: int(f.stem.split("_")[1]))
    assert main(["plot", str(last), "-o", str(tmp_path / "last.png")]) == 0
    assert drawn == [0.2] and "note" not in capsys.readouterr().out
    assert main(["plot", str(log), "-o", str(tmp_path / "whole.png")]) == 0
    printed = capsys.readouterr().out
    assert drawn == [0.2, 0.2], drawn
    assert "parameters change in the record (1 PARAMETERS event(s))" in printed and "at its end" in printed
    assert (tmp_path / "whole.png").stat().st_size > 0

    import argparse

    curves, _, _ = plot._mcap_curves(argparse.Namespace(input=log, recover=False, contact=None))
    assert int(np.count_nonzero(np.isnan(curves[0].depth))) == 1, "one break, at the change"


def test_a_reader_that_stops_early_ends_the_cli_quietly(log: Path, tmp_path: Path) -> None:
    """`viscoadh replay ... | head` ended in a BrokenPipeError traceback: now exit 141 (as
    SIGPIPE), nothing on stderr, and the outputs written before the summary is printed."""
    import os
    import subprocess
    import sys

    import viscoadh_ros

    root = str(Path(viscoadh_ros.__file__).resolve().parents[1])
    out, summary = tmp_path / "out.mcap", tmp_path / "summary.json"
    command = [
        sys.executable,
        "-m",
        "viscoadh_ros",
        "replay",
        str(log),
        "-o",
        str(out),
        "--json",
        str(summary),
    ]
    env = {**os.environ, "PYTHONPATH": root}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    process.stdout.close()  # the reader is gone before the summary is printed
    _, err = process.communicate(timeout=120)
    assert process.returncode == 141, err.decode()
    assert err.decode() == ""
    assert out.stat().st_size > 0 and json.loads(summary.read_text())["max_error_N"] == 0.0
