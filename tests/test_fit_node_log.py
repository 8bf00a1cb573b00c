"""`viscoadh fit` on the real node's log of a session with a runtime parameter change.

The node (in process, simulated clock, logging on) runs the standard-solid sphere through four
press-pull cycles: two with the work of adhesion 0.05 J/m^2 (a `C/reset` between them), then a
parameter change to 0.08 (a PARAMETERS event), two more cycles (a reset between them). After
each reset and the change the contact idles for 8 s of node clock, so the hold timer logs
states of the contact at rest. An outside tester fitted the cycles after the change only
(`--time-range`) and got "RMSE 0 N, r^2 1.000000", the work of adhesion NOT IDENTIFIED "(best
0.05)" and a scene saying 0.05: the fit ran the model with the logged 0.08 after the change
whatever its trial value, and counted those samples as fitted. Fitting the whole record gave
one value for two materials.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.msg import ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from scenes import STANDARD_SOLID_FINGER, call_service
from std_srvs.srv import Trigger

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.demo import _Driver, node_in_process
from viscoadh_ros.experiment import PARAMETERS, RESET, load_experiment
from viscoadh_ros.fitting import fit_bag
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.ros.conversions import ns_to_stamp

SCENE = SceneConfig.from_parameters(STANDARD_SOLID_FINGER)
#: Press to 20 um in 0.2 s, pull out to -30 um by 0.5 s, commands every 10 ms.
TIMES = np.arange(0.0, 0.5, 0.01)
DEPTHS = np.interp(TIMES, [0.0, 0.2, 0.5], [-1e-6, 20e-6, -30e-6])


@pytest.fixture(scope="module")
def node_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    log = tmp_path_factory.mktemp("fit_node_log") / "session.mcap"
    with node_in_process(
        SCENE,
        use_sim_time=True,
        **{"log.enabled": True, "log.path": str(log), "command.max_future_s": 30.0},
    ) as (context, executor):
        client = Node("fit_node_log_driver", context=context)
        driver = _Driver(client, "finger", timeout=10.0)
        clock = client.create_publisher(Clock, "/clock", 1)
        reset = client.create_client(Trigger, "finger/reset")
        parameters = client.create_client(SetParameters, "/viscoadh/set_parameters")
        executor.add_node(client)
        driver.wait_for_node()

        def move_clock(t: float) -> None:
            clock.publish(Clock(clock=ns_to_stamp(round(t * 1e9))))
            time.sleep(0.02)

        def cycle(start: float) -> None:
            for t, d in zip(TIMES, DEPTHS, strict=True):
                driver.command(start + t, d)
            for t in (0.6, 0.7, 0.8, 0.9, 1.0):  # out of touch until relaxed
                driver.command(start + t, DEPTHS[-1])

        def idle(start: float) -> None:
            """8 s of node clock with no command: the hold timer logs the contact at rest (once
            a second, more samples than the jump mask of the next snap-in covers)."""
            for t in np.arange(start, start + 8.0, 0.25):
                move_clock(float(t))

        move_clock(1.0)
        cycle(1.0)
        assert call_service(reset, Trigger.Request()).success
        idle(2.1)
        cycle(11.0)
        change = SetParameters.Request(
            parameters=[
                ParameterMsg(
                    name="finger.adhesion.work_of_adhesion",
                    value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=0.08),
                )
            ]
        )
        result = call_service(parameters, change).results[0]
        assert result.successful, result.reason
        idle(12.1)
        cycle(21.0)
        assert call_service(reset, Trigger.Request()).success
        idle(22.1)
        cycle(31.0)
    return log


def _change_time(log: Path) -> float:
    """The parameter change's time, s since the record's first input."""
    experiment = load_experiment(Bag(log), contact="finger")
    assert [r.kind for r in experiment.restarts] == [RESET, PARAMETERS, RESET]
    return float(experiment.time(np.array([experiment.restarts[1].ns]))[0])


def _at_rest(experiment: Any) -> np.ndarray:
    """The measured samples logged after a reset and before the next command."""
    (reset,) = experiment.restarts
    assert reset.kind == RESET
    next_command = experiment.input_order[experiment.input_order > reset.order].min()
    return (experiment.measured_order > reset.order) & (experiment.measured_order < next_command)


def test_a_fit_across_the_parameter_change_is_refused(node_log: Path, tmp_path: Path, capsys: Any) -> None:
    change = _change_time(node_log)
    out = tmp_path / "fit.yaml"
    assert main(["fit", str(node_log), "--free", "work_of_adhesion", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert "parameter change" in err and f"t = {change:.6g} s" in err and "--time-range" in err, err
    assert "work_of_adhesion 0.05 -> 0.08" in err, err
    assert not out.exists() and not list(tmp_path.iterdir())


def test_a_fit_after_the_change_fits_the_new_material(node_log: Path, tmp_path: Path, capsys: Any) -> None:
    """The tester's command: the cycles after the change only."""
    change = _change_time(node_log)
    out = tmp_path / "after.yaml"
    args = ["fit", str(node_log), "--free", "work_of_adhesion", "--time-range", f"{change + 0.01}", "100"]
    assert main([*args, "--no-report", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "NOT IDENTIFIED" not in printed, printed
    assert "parameter change" in printed, printed
    # Within 1 %: the log is noiseless and the fit's grid is not the node's (model error).
    fitted = SceneConfig.from_yaml(out).contact("finger")
    assert fitted.adhesion.work_of_adhesion == pytest.approx(0.08, rel=1e-2), fitted

    # What was fitted: the samples of the stretch after the change whose model depends on the
    # trial, not those of the contact at rest after the second reset.
    done = fit_bag(str(node_log), {"free": "work_of_adhesion", "time_range": [change + 0.01, 100.0]})
    experiment, result = done.experiment, done.result
    assert result.values["work_of_adhesion"] == pytest.approx(0.08, rel=1e-2)
    assert result.rmse > 0.0, "a fit never reports samples its trial cannot change"
    at_rest = _at_rest(experiment)
    assert at_rest.sum() >= 6, "the session logs the contact at rest"
    assert not np.any(result.used & at_rest)


def test_a_fit_before_the_change_fits_the_first_material(node_log: Path) -> None:
    """The other side: the scene the node started with, the cycles before the change."""
    change = _change_time(node_log)
    done = fit_bag(str(node_log), {"free": "work_of_adhesion", "time_range": [0.0, change - 0.01]})
    experiment, result = done.experiment, done.result
    assert result.values["work_of_adhesion"] == pytest.approx(0.05, rel=1e-2)
    at_rest = _at_rest(experiment)
    assert at_rest.sum() >= 6, "the session logs the contact at rest"
    assert not np.any(result.used & at_rest)
