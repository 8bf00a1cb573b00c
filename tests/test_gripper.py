"""The MuJoCo gripper cell (viscoadh_ros.gripper): coupling, stability, picks, the two paths.

Model paths: the built-in cell's pad has a Kelvin element, so "auto" runs the time-stepped
model; the Hertz test forces ``numerics.model: time_stepped`` on an elastic pad.
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from viscoadh_ros.core.config import SceneConfig, default_scene_path, read_yaml
from viscoadh_ros.core.errors import ConfigError, InputError
from viscoadh_ros.core.reference import hertz_force
from viscoadh_ros.gripper.config import GripperConfig, cell_from_dict, default_cell_path, load_cell
from viscoadh_ros.gripper.cycle import run_cycle
from viscoadh_ros.gripper.motion import Motion
from viscoadh_ros.gripper.pads import LibraryPads, step_time
from viscoadh_ros.gripper.scenarios import CAPACITY_MARGIN, GOOD, SHORT, with_mass
from viscoadh_ros.gripper.scene import CellModel


@pytest.fixture(scope="module")
def cell():
    return load_cell(default_cell_path())


def raw_cell():
    return read_yaml(default_cell_path())


def test_adhesion_off_pad_resting_on_a_part_settles_at_the_hertz_depth():
    data = raw_cell()
    pad = data["/**"]["ros__parameters"]["pad"]
    pad["material"] = {"glass_shear_modulus": 3.0e5, "poisson_ratio": 0.5}
    pad["adhesion"] = {"work_of_adhesion": 0.0}
    pad["numerics"] = {"model": "time_stepped"}
    # A soft servo pressing from far below: an almost constant load on the part.
    data["gripper"]["arm"] = {"stiffness": 2.0, "damping": 40.0, "start_height": 1.0e-4}
    cell = cell_from_dict(data)
    world = CellModel(cell, latch_open_height=0.05)
    pads = LibraryPads(cell.pad, 1)
    dt_ns = round(cell.gripper.timestep * 1e9)
    m, d = world.model, world.data
    depths = []
    for step in range(2500):
        mujoco.mj_step1(m, d)
        geometry = world.pad_geometry()
        states = pads.step(step_time(step, dt_ns), geometry.depth)
        world.apply_pad_forces(geometry, states.force)
        world.set_controls(-0.05, latch_closed=False)
        mujoco.mj_step2(m, d)
        depths.append(geometry.depth[0])
    load = float(d.actuator_force[world.arm_actuator])  # the servo's push = what the pad carries
    e_star = 4.0 * 3.0e5
    radius = float(cell.pad.indenter.radius)
    expected = (3.0 * abs(load) / (4.0 * e_star * math.sqrt(radius))) ** (2.0 / 3.0)
    assert pads.simulators[0].model == "time_stepped"
    np.testing.assert_allclose(depths[-1], expected, rtol=0.01, err_msg="resting pad depth vs Hertz")
    np.testing.assert_allclose(float(hertz_force(depths[-1], radius, e_star)), abs(load), rtol=0.03)
    swing = np.ptp(depths[-500:])
    assert swing < 0.01 * expected, f"the resting pad still swings by {swing:.3g} m"


def test_a_lifted_part_hangs_without_a_growing_oscillation(cell):
    tr = run_cycle(cell, replace(GOOD, carry_time=0.6), LibraryPads(cell.pad, 1))
    assert tr.success, tr.outcome
    carry = tr.force[tr.segment == "carry", 0]
    first, last = np.ptp(carry[:500]), np.ptp(carry[-500:])
    assert last <= first, f"oscillation grew in the carry: {first:.3g} N -> {last:.3g} N"
    np.testing.assert_allclose(carry[-500:].mean(), -tr.part_mass * 9.81, rtol=0.05)


def _live_capacity(cell, motion):
    tr = run_cycle(cell, motion, LibraryPads(cell.pad, 1))
    return tr.predictions["pick_capacity_kg"]


@pytest.mark.parametrize("motion", [SHORT, GOOD], ids=["no hold", "hold 0.3 s"])
def test_lighter_than_the_live_prediction_is_lifted_and_heavier_than_the_margin_stays(cell, motion):
    # The live pads' prediction after the real press (a lower bound: a hanging part's contact
    # creeps stronger); the measured boundary lies within [1, CAPACITY_MARGIN] x capacity.
    limit = _live_capacity(cell, motion)
    light = run_cycle(with_mass(cell, 0.9 * limit), motion, LibraryPads(cell.pad, 1))
    assert light.success and light.pick_step is not None, light.outcome
    heavy_mass = 1.1 * CAPACITY_MARGIN * limit
    heavy = run_cycle(with_mass(cell, heavy_mass), motion, LibraryPads(cell.pad, 1))
    assert not heavy.success and heavy.pick_step is None, heavy.outcome


def test_with_a_peel_the_pad_carries_m_g_plus_a_and_without_it_a_jerk(cell):
    # Why the first prediction missed: lifting at once from the press, the arm already moves
    # when the pad's tension reaches the weight and jerks the part off the table.
    mass = 0.8e-3
    light = with_mass(cell, mass)
    load = mass * (9.81 + GOOD.lift_acceleration)
    peeled = run_cycle(light, GOOD, LibraryPads(cell.pad, 1))
    jerked = run_cycle(light, replace(GOOD, peel_speed=None), LibraryPads(cell.pad, 1))
    after = peeled.time >= peeled.starts["peel"]
    np.testing.assert_allclose(-peeled.force[after, 0].min(), load, rtol=0.03)
    after = jerked.time >= jerked.starts["lift"]
    assert -jerked.force[after, 0].min() > 1.5 * load


def test_a_part_that_rose_and_fell_back_is_not_said_to_have_stayed_on_the_table(cell):
    # The transport scenario's hard lift (40 m/s^2): the peel raised the part about 0.2 mm,
    # below the 0.5 mm that counts as a pick, then the pads let go. The outcome said "the pads
    # let go before the part left the table" (an outside tester, 0.9.0); it now says how far
    # the part rose and what counts as lifted.
    hard = replace(GOOD, lift_acceleration=40.0, lift_speed=0.2, lift_height=0.02, carry_time=0.3)
    tr = run_cycle(cell, hard, LibraryPads(cell.pad, 1))
    assert not tr.success and tr.pick_step is None
    rise = float(tr.part_rise.max())
    assert 0.0 < rise < 0.5e-3
    assert "left the table" not in tr.outcome
    assert f"rose {rise * 1e3:.3g} mm" in tr.outcome and "lifted 0.5 mm" in tr.outcome, tr.outcome


def test_a_pad_out_of_contact_exerts_exactly_zero_force(cell):
    tr = run_cycle(cell, SHORT, LibraryPads(cell.pad, 1), stop_after_release=True)
    apart = (tr.contact_radius[:, 0] == 0.0) & (tr.depth[:, 0] < 0.0)
    assert apart.sum() > 100
    assert np.all(tr.force[apart, 0] == 0.0)
    world = CellModel(cell, latch_open_height=0.05)
    mujoco.mj_step1(world.model, world.data)
    world.data.qfrc_applied[:] = 1.0
    world.apply_pad_forces(world.pad_geometry(), np.zeros(1))
    assert np.all(world.data.qfrc_applied == 0.0)


def test_library_and_node_paths_release_at_the_same_step(cell, ros_context):
    from viscoadh_ros.gripper.node_loop import NodePads

    motion = replace(SHORT, approach_speed=0.02)
    library = run_cycle(cell, motion, LibraryPads(cell.pad, 1), stop_after_release=True)
    with NodePads(cell) as bank:
        node = run_cycle(cell, motion, bank, stop_after_release=True)
    assert library.release_step is not None
    assert node.release_step == library.release_step
    np.testing.assert_array_equal(node.force, library.force)
    np.testing.assert_array_equal(node.part_rise, library.part_rise)


def test_a_time_step_too_long_for_the_part_is_refused(cell):
    light = with_mass(cell, 0.2e-3)
    with pytest.raises(InputError, match=r"gripper.timestep .* too long .*\(use gripper.timestep <="):
        run_cycle(light, GOOD, LibraryPads(cell.pad, 1))


@pytest.mark.parametrize(
    ("section", "value", "message"),
    [
        ("arm", {"stifness": 1.0}, r"gripper.arm.stifness: unknown key \(did you mean 'stiffness'\?\)"),
        ("part", {"mass": -1.0}, r"gripper.part.mass must be a finite number > 0"),
        ("pads", {"rows": 0}, r"gripper.pads.rows must be an integer from 1 to 8"),
        ("part", {"size": [0.01, 0.01, 0.005]}, r"gripper.part.size: the part .* is too small"),
    ],
)
def test_a_bad_gripper_key_is_one_clear_error(section, value, message):
    data = raw_cell()
    data["gripper"][section] = value
    with pytest.raises(ConfigError, match=message):
        cell_from_dict(data)


@pytest.mark.parametrize(
    ("written", "given"),
    [
        ("glass_shear_modulus: 3.0e+5", "glass_shear_modulus: 3.0e5"),
        ("timestep: 2.0e-4 ", "timestep: 2e-4 "),
    ],
)
def test_a_cell_file_reads_exponents_as_numbers_like_every_scene(tmp_path, written, given):
    # 0.10.0's outside tester: plain yaml.safe_load read 3.0e5 and 2e-4 as strings ("must be a
    # number (got '3.0e5')"), which every other verb, and ROS, read as numbers.
    text = default_cell_path().read_text()
    assert written in text
    file = tmp_path / "cell.yaml"
    file.write_text(text.replace(written, given))
    loaded = load_cell(file)
    assert loaded.pad.material.glass_shear_modulus == 3.0e5
    assert loaded.gripper.timestep == 2.0e-4
    assert loaded == load_cell(default_cell_path())


def test_a_scene_without_a_gripper_section_is_refused_for_that(tmp_path):
    # config/default.yaml is a valid scene with one sphere contact: it was refused for its
    # number 1.0e6 (the wrong reason) and, read as a scene, would have run on gripper defaults.
    with pytest.raises(ConfigError, match=r"default.yaml' has no 'gripper:' section"):
        load_cell(default_scene_path())
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "viscoadh_ros",
            "gripper",
            "--cell",
            str(default_scene_path()),
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 2
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("viscoadh gripper: error: gripper file ") and "no 'gripper:' section" in line
    assert not (tmp_path / "out").exists()


def test_an_empty_gripper_section_takes_the_defaults():
    data = raw_cell()
    data["gripper"] = None
    assert cell_from_dict(data).gripper == GripperConfig()


def test_a_non_adhesive_pad_is_plotted_without_a_warning(tmp_path):
    # Without adhesion the pads never pull: the force axis was limited to (0, 0), which
    # matplotlib warns about (an outside tester, 0.9.0).
    from viscoadh_ros.gripper.figures import plot_runs
    from viscoadh_ros.gripper.scenarios import Run

    data = raw_cell()
    data["/**"]["ros__parameters"]["pad"]["adhesion"]["work_of_adhesion"] = 0.0
    plain = cell_from_dict(data)
    tr = run_cycle(plain, SHORT, LibraryPads(plain.pad, 1))
    assert tr.force.min() >= 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert plot_runs([Run("no adhesion", tr)], tmp_path / "runs.png", title="t").exists()


def test_pad_scene_has_one_contact_per_pad(cell):
    many = replace(cell, gripper=cell.gripper.with_pads(2, 2))
    scene = many.pad_scene()
    assert scene.ids == ("pad_0", "pad_1", "pad_2", "pad_3")
    assert SceneConfig.from_dict(scene.to_dict()).contacts[3].material == cell.pad.material


def test_cli_bad_cell_is_one_line_and_exit_2(tmp_path):
    bad = tmp_path / "cell.yaml"
    text = default_cell_path().read_text().replace("stiffness: 2.0e+4", "stifness: 2.0e+4")
    bad.write_text(text)
    result = subprocess.run(
        [sys.executable, "-m", "viscoadh_ros", "gripper", "--cell", str(bad), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "viscoadh gripper: error: gripper.arm.stifness: unknown key (did you mean 'stiffness'?)"
    ]


def test_every_scenario_is_checked_before_anything_runs_or_is_written(tmp_path, monkeypatch, capsys):
    # 0.10.0's outside tester: 2x2 pads at 1.5e-4 s passed 'pick' (a 1.3 g part), which ran,
    # wrote its figure and printed its outcomes, then 'transport' (1 g) was refused: exit 2
    # after writing, where docs/cli.md says exit 2 writes nothing. No run may start now.
    import re

    from viscoadh_ros.cli.main import main
    from viscoadh_ros.gripper import scenarios

    def no_run(*args, **kwargs):
        raise AssertionError("a scenario ran before every scenario was checked")

    monkeypatch.setattr(scenarios, "run_cycle", no_run)
    file = tmp_path / "cell_15.yaml"
    file.write_text(default_cell_path().read_text().replace("timestep: 2.0e-4", "timestep: 1.5e-4"))
    out = tmp_path / "out"
    assert main(["gripper", "--cell", str(file), "--pads", "2x2", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and not out.exists()
    (line,) = captured.err.strip().splitlines()
    assert line.startswith(
        "viscoadh gripper: error: scenario transport (lift at 2 m/s^2): gripper.timestep 0.00015 s "
        "is too long for a 1 g part on 4 pad(s)"
    ), line
    # The step it suggests for all the refused runs is accepted by every scenario.
    suggested = float(re.search(r"gripper.timestep <= ([0-9.e-]+) s suits every one", line).group(1))
    cell = load_cell(file)
    cell = replace(cell, gripper=replace(cell.gripper.with_pads(2, 2), timestep=suggested))
    scenarios.check({name: scenarios.plan(name, cell) for name in scenarios.SCENARIOS})


def test_run_labels_state_the_setting_not_the_expected_outcome(cell, monkeypatch):
    # The same tester: with 2x2 pads the pick printed "press 150 um, no hold (too short):
    # picked and held"; the label said what the built-in cell's single pad gives.
    from viscoadh_ros.gripper import scenarios

    monkeypatch.setattr(scenarios, "run_cycle", lambda cell, motion, pads, **kwargs: motion)
    runs = scenarios.scenario_pick(cell, scenarios.library_bank)
    assert [run.label for run in runs] == [
        "press 150 um, no hold",
        "press 10 um, hold 0.3 s",
        "press 150 um, hold 0.3 s",
    ]
    assert [run.label for run in runs] == [scenarios.grip_text(run.trajectory) for run in runs]


def test_motion_rejects_a_negative_hold():
    with pytest.raises(InputError, match="hold_time must be a finite number >= 0"):
        Motion(hold_time=-1.0).validated()


def _frames_run(tmp_path, backend):
    env = {**__import__("os").environ, "MUJOCO_GL": backend}
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "viscoadh_ros",
            "gripper",
            "--scenario",
            "transport",
            "--frames",
            str(tmp_path / "frames"),
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        check=False,
        env=env,
    )


def test_frames_with_a_backend_that_is_not_offscreen_is_one_line_and_exit_2(tmp_path):
    result = _frames_run(tmp_path, "glfw")
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "viscoadh gripper: error: --frames: MUJOCO_GL='glfw': offscreen frames need 'egl' or 'osmesa'"
    ]
    assert not (tmp_path / "frames").exists()


def test_frames_are_written_or_the_missing_backend_is_named(tmp_path):
    # EGL works on this machine (frames written); where it does not, one line names it.
    result = _frames_run(tmp_path, "egl")
    if result.returncode == 0:
        frames = sorted((tmp_path / "frames" / "transport").glob("*/frame_*.png"))
        assert len(frames) > 5, result.stdout
        assert frames[0].read_bytes()[:4] == b"\x89PNG"
    else:
        assert result.returncode == 2, result.stderr
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith("viscoadh gripper: error: ") and "egl" in line
