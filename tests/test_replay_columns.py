"""`run_model` over a recorded stream equals `ContactSimulator.step_depths` over the same depth
history, bit for bit: replay adds no arithmetic of its own to the simulator's outputs, whether
each measured sample shares its command's stamp (the inputs' columns are taken whole) or falls
between commands (the depth is held to it, the columns gathered row by row)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from geometry_msgs.msg import WrenchStamped
from viscoadh_msgs.msg import IndentationCommand

from viscoadh_ros.bench.latency import bench_scene
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator
from viscoadh_ros.experiment import choose_contact, load_experiment, run_model
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.mcap_log import McapRecorder


def _record(path: Path, count: int, offset_ns: int) -> SceneConfig:
    """Depth commands every ms (a sine through contact and pull-off), a measured wrench
    ``offset_ns`` after each command's stamp."""
    scene_map, amplitude = bench_scene(1)
    scene = SceneConfig.from_dict(scene_map)
    with McapRecorder(path, scene=scene.to_dict(), queue_size=2 * count + 16) as recorder:
        for k in range(count):
            stamp = 1_000_000_000 + k * 1_000_000
            depth = amplitude * (1.2 * (0.5 - 0.5 * math.cos(2 * math.pi * k / 700)) - 0.2)
            command = IndentationCommand(mode=IndentationCommand.DEPTH, depth=depth)
            command.header.stamp.sec, command.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
            recorder.record("/c0/indentation", command, stamp)
            wrench = WrenchStamped()
            wrench.header.stamp.sec, wrench.header.stamp.nanosec = divmod(stamp + offset_ns, 1_000_000_000)
            recorder.record("/c0/wrench", wrench, stamp + offset_ns)
    return scene


@pytest.mark.parametrize("offset_ns", [0, 400_000])
def test_run_model_equals_step_depths(tmp_path: Path, offset_ns: int) -> None:
    path = tmp_path / "stream.mcap"
    scene = _record(path, 1500, offset_ns)
    experiment = load_experiment(Bag(path))
    contact = choose_contact(scene, None)
    run = run_model(contact, experiment)
    t_in = experiment.time(experiment.input_ns)
    d_in = experiment.input_value
    # The history the node steps through: every command, and every measured stamp after it
    # at the held depth (with offset 0 the sample reads the command's own step).
    t_meas = experiment.time(experiment.measured_ns)
    if offset_ns:
        times = np.ravel(np.column_stack([t_in, t_meas]))
        depths = np.repeat(d_in, 2)
        input_rows = np.arange(0, times.size, 2)
        measured_rows = input_rows + 1
    else:
        times, depths = t_in, d_in
        input_rows = measured_rows = np.arange(t_in.size)
    expected = ContactSimulator(contact).step_depths(times, depths)
    assert np.min(expected["force"]) < 0.0 < np.max(expected["force"]), "contact and pull-off"
    for name in STEP_OUTPUT_FIELDS:
        np.testing.assert_array_equal(run.input_columns[name], expected[name][input_rows], err_msg=name)
    np.testing.assert_array_equal(run.model_force, expected["force"][measured_rows])


def test_running_max_and_last_true_equal_the_accumulates() -> None:
    from viscoadh_ros.experiment import _last_true, _running_max

    rng = np.random.default_rng(11)
    for size in (0, 1, 2, 5, 200):
        for values in (np.sort(rng.normal(size=size)), rng.normal(size=size), np.zeros(size)):
            np.testing.assert_array_equal(_running_max(values), np.maximum.accumulate(values))
        ints = rng.integers(-5, 5, size)
        np.testing.assert_array_equal(_running_max(ints), np.maximum.accumulate(ints))
        for mask in (rng.random(size) < 0.3, np.zeros(size, bool), np.ones(size, bool)):
            expected = np.maximum.accumulate(np.where(mask, np.arange(size), -1)) if size else mask
            np.testing.assert_array_equal(_last_true(mask), expected)
