"""Is the replay fit's G0 shift the model's error or the record's grid (round 0.11.0-centre,
session 12)? tests/test_replay_parameters.py fits G0 (from a 2 MPa candidate, w held at the
logged change's 0.2) to the node's log of the standard-solid finger (`fast`, 64 elements); the
fit runs on its own grid (`fitting.fit_grid`, `polish_elements`: 11136 elements here).

    PYTHONPATH=<checkout> python benchmarks/centre_fit_grid.py make <folder> [elements]
        the test's log (the node in process): the finger at its own numerics, or at
        ``numerics.elements`` = elements (e.g. 8192: the reference record)
    PYTHONPATH=<checkout> python benchmarks/centre_fit_grid.py fit <folder> [elements]
        the test's fit of that log; with elements, the fit's grids forced to that many
    PYTHONPATH=<checkout> python benchmarks/centre_fit_grid.py rows <folder> <base.npz> <other.npz> <which>
        the fit of the log with some rows of its stretch after the change replaced, by
        `benchmarks/centre_accuracy.py`'s outputs for the finger's w = 0.2 cycle (equal to the
        log's force to 1e-15): ``which`` = moved (the rows <other> moved against <base> set to
        8192 elements' force), unmoved (every other contact row so set), all, or other (the
        moved rows set to <other>'s force)

Prints the fitted G0 and the grids the fit ran. PYTHONPATH picks the kernel (the node's and the
fit's both). Seconds per fit.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from scenes import STANDARD_SOLID_FINGER  # noqa: E402

from viscoadh_ros.core.config import SceneConfig  # noqa: E402

TIMES = np.arange(0.0, 0.5, 0.01)
DEPTHS = np.interp(TIMES, [0.0, 0.2, 0.5], [-1e-6, 20e-6, -30e-6])
#: The second cycle (after the change) starts at this time of the record (its first input is 0).
SECOND_CYCLE = 2.0


def make(folder: Path, elements: int | None) -> None:
    """tests/test_replay_parameters.py's `log` fixture."""
    from rcl_interfaces.msg import Parameter as ParameterMsg
    from rcl_interfaces.msg import ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParameters
    from rclpy.node import Node
    from rosgraph_msgs.msg import Clock
    from scenes import call_service

    from viscoadh_ros.demo import _Driver, node_in_process
    from viscoadh_ros.ros.conversions import ns_to_stamp

    flat = dict(STANDARD_SOLID_FINGER)
    if elements:
        flat["finger.numerics.elements"] = elements
    folder.mkdir(parents=True, exist_ok=True)
    params = {
        "log.enabled": True,
        "log.path": str(folder / "session.mcap"),
        "log.max_duration": 0.4,
        "command.max_future_s": 30.0,
    }
    with node_in_process(SceneConfig.from_parameters(flat), use_sim_time=True, **params) as (
        context,
        executor,
    ):
        client = Node("parameters_log_driver", context=context)
        driver = _Driver(client, "finger", timeout=60.0)
        clock = client.create_publisher(Clock, "/clock", 1)
        parameters = client.create_client(SetParameters, "/viscoadh/set_parameters")
        executor.add_node(client)
        driver.wait_for_node()
        clock.publish(Clock(clock=ns_to_stamp(1_000_000_000)))
        time.sleep(0.1)

        def cycle(start: float) -> None:
            for t, d in zip(TIMES, DEPTHS, strict=True):
                driver.command(start + t, d)
            driver.command(start + 1.0, DEPTHS[-1])

        cycle(1.0)
        value = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=0.2)
        change = SetParameters.Request(
            parameters=[ParameterMsg(name="finger.adhesion.work_of_adhesion", value=value)]
        )
        result = call_service(parameters, change).results[0]
        assert result.successful, result.reason
        time.sleep(0.1)
        cycle(3.0)
    print("log", folder, sorted(p.name for p in folder.glob("*.mcap")))


def fit(folder: Path, elements: int | None) -> None:
    """tests/test_replay_parameters.py::test_a_fit_after_the_change_with_a_scene_holds_what_the_change_set."""
    from viscoadh_ros import fitting
    from viscoadh_ros.experiment import PARAMETERS, load_experiment
    from viscoadh_ros.io.bag import Bag
    from viscoadh_ros.io.mcap_log import plain

    grids = []
    fit_grid, polish = fitting.fit_grid, fitting.polish_elements

    def forced_grid(*args, **kwargs):
        domain, n = fit_grid(*args, **kwargs)
        grids.append(("coarse", n))
        return (domain, elements) if elements else (domain, n)

    def forced_polish(*args, **kwargs):
        n = elements or polish(*args, **kwargs)
        grids.append(("polish", n))
        return n

    fitting.fit_grid, fitting.polish_elements = forced_grid, forced_polish
    base = SceneConfig.from_parameters(STANDARD_SOLID_FINGER)
    flat = {**base.to_parameters(), "finger.material.glass_shear_modulus": 2.0e6}
    candidate = folder / "candidate.yaml"
    candidate.write_text(yaml.safe_dump(plain(SceneConfig.from_parameters(flat).to_dict()), sort_keys=False))
    experiment = load_experiment(Bag(folder))
    (change,) = [r for r in experiment.restarts if r.kind == PARAMETERS]
    after = float(experiment.time(np.array([change.ns]))[0]) + 0.01
    done = fitting.fit_bag(str(folder), {"scene": str(candidate), "free": "G0", "time_range": [after, 100.0]})
    g0 = done.result.values["G0"]
    print(
        f"G0 = {g0:.6e} ({g0 / 1e6 - 1.0:+.4%}), sigma {done.result.uncertainty['G0']:.2e},"
        f" w {done.result.contact.adhesion.work_of_adhesion}, grids {grids}",
        flush=True,
    )


def rows(folder: Path, base_npz: str, other_npz: str, which: str) -> None:
    import viscoadh_ros.experiment as ex

    scene = "finger_node_log_cycle_w02"
    base, other = np.load(base_npz), np.load(other_npz)
    ref, own, alt = base[f"{scene}/ref"], base[f"{scene}/own"], other[f"{scene}/own"]
    p = float(base[f"{scene}/p"])
    moved = np.abs(alt - own) > 1e-12 * p
    contact = base[f"{scene}/a_ref"] > 0.0
    pick = {"moved": moved, "unmoved": contact & ~moved, "all": contact, "other": moved}[which]
    load = ex.load_experiment

    def replaced(*args, **kwargs):
        e = load(*args, **kwargs)
        t, f = e.time(e.measured_ns), e.measured_force.copy()
        for i in np.flatnonzero(pick):
            j = int(np.argmin(np.abs(t - (SECOND_CYCLE + TIMES[i]))))
            assert abs(f[j] - own[i]) <= 1e-12 * p, "the log is not <base>'s force"
            f[j] = alt[i] if which == "other" else ref[i]
        return dataclasses.replace(e, measured_force=f)

    ex.load_experiment = replaced
    print(f"{which}: {int(pick.sum())} rows replaced", end="; ")
    fit(folder, None)


if __name__ == "__main__":
    what, where = sys.argv[1], Path(sys.argv[2])
    if what == "rows":
        rows(where, *sys.argv[3:6])
    else:
        {"make": make, "fit": fit}[what](where, int(sys.argv[3]) if len(sys.argv) > 3 else None)
