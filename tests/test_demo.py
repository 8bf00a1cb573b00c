"""`viscoadh demo`: the cycle plan, the summary arithmetic, and the whole job end to end."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.demo import (
    CyclePlan,
    _si,
    creep_time,
    loop_energy,
    plan_cycle,
    run_demo,
    sphere_reference,
)
from viscoadh_ros.io.bag import Bag

REPO = Path(__file__).resolve().parents[1]
DEFAULT_CONTACT = SceneConfig.from_yaml(default_scene_path()).contacts[0]


def test_schedule_hits_every_corner_of_the_cycle():
    plan = CyclePlan(
        start_depth=-1e-6, max_depth=4e-6, approach_speed=1e-5, hold_time=0.25,
        retract_speed=2e-5, end_depth=-6e-6, command_rate=200.0,
    )
    time, depth, last_hold = plan.schedule()
    assert np.all(np.diff(time) > 0), "time must increase"
    np.testing.assert_allclose(np.diff(time), 1 / 200.0, rtol=1e-6, err_msg="command period")
    t_in = 5e-6 / 1e-5
    np.testing.assert_allclose(
        [time[last_hold], depth[last_hold]], [t_in + 0.25, 4e-6], rtol=1e-12, err_msg="end of hold"
    )
    np.testing.assert_allclose(depth[-1], -6e-6, rtol=1e-12, err_msg="end of retraction")
    np.testing.assert_allclose(
        np.interp(t_in, time, depth), 4e-6, rtol=1e-12, err_msg="top of the approach"
    )
    speed = np.diff(depth[last_hold:]) / np.diff(time[last_hold:])
    np.testing.assert_allclose(speed, -2e-5, rtol=1e-9, err_msg="retract speed")


def test_plan_scales_with_the_scene():
    plan = plan_cycle(DEFAULT_CONTACT)
    _, _, d_c = sphere_reference(DEFAULT_CONTACT).scales
    creep = creep_time(DEFAULT_CONTACT)
    np.testing.assert_allclose(
        [plan.start_depth, plan.max_depth, plan.approach_speed],
        [-d_c, 4 * d_c, 5 * d_c / (40 * creep)],
        rtol=1e-12,
        err_msg="default scene plan",
    )


def test_loop_energy_is_the_enclosed_area():
    # A triangle loop in the force-depth plane, clockwise in (d, F): area 0.5 * 2 * 3.
    depth = np.array([0.0, 2.0, 2.0, 0.0])
    force = np.array([0.0, 0.0, 3.0, 0.0])
    np.testing.assert_allclose(loop_energy(depth, force), -3.0, rtol=1e-12, err_msg="triangle")
    # An elastic path in and out along the same line loses nothing.
    d = np.concatenate([np.linspace(0, 1, 50), np.linspace(1, 0, 50)])
    np.testing.assert_allclose(loop_energy(d, 7.0 * d), 0.0, atol=1e-12, err_msg="elastic")


@pytest.mark.parametrize(
    ("value", "text"),
    [(-1.2345e-3, "-1.234 mN"), (2.5e-8, "25 nN"), (0.0, "0 N"), (3.0, "3 N"), (4e-13, "0.4 pN")],
)
def test_si_prefixes(value, text):
    assert _si(value, "N") == text


def test_non_sphere_scene_is_refused_with_the_key(tmp_path):
    flat = SceneConfig.from_yaml(default_scene_path()).to_parameters()
    contact = flat["contacts"][0]
    flat[f"{contact}.indenter.shape"] = "cone"
    flat[f"{contact}.indenter.half_angle"] = 1.2
    scene = tmp_path / "cone.yaml"
    scene.write_text(_yaml(SceneConfig.from_parameters(flat)))
    result = subprocess.run(
        [sys.executable, "-m", "viscoadh_ros", "demo", "--scene", str(scene), "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=120, check=False,
    )
    assert result.returncode == 2, result.stderr
    assert result.stderr.count("\n") == 1 and "indenter.shape" in result.stderr, result.stderr
    assert not (tmp_path / "demo.mcap").exists()


def _yaml(scene: SceneConfig) -> str:
    import yaml

    return yaml.safe_dump(scene.to_dict(), sort_keys=False)


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    return out, run_demo(out_dir=out)


def _number(report: str, label: str) -> float:
    """The first value after ``label`` in the report, in SI units."""
    match = re.search(rf"{label}\s+(-?[\d.e+-]+) ([munp]?)", report)
    assert match, f"no {label!r} in:\n{report}"
    return float(match.group(1)) * {"": 1, "m": 1e-3, "u": 1e-6, "n": 1e-9, "p": 1e-12}[match.group(2)]


def test_demo_writes_log_and_figure(demo):
    out, report = demo
    assert (out / "demo.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", "figure is not a PNG"
    assert str((out / "demo.png").resolve()) in report and str((out / "demo.mcap").resolve()) in report
    bag = Bag(out / "demo.mcap")
    contact = DEFAULT_CONTACT.id
    topics = bag.topics
    for topic, type_name in [
        (f"/{contact}/indentation", "viscoadh_msgs/msg/IndentationCommand"),
        (f"/{contact}/state", "viscoadh_msgs/msg/ContactState"),
    ]:
        assert topics.get(topic) == type_name, f"{topic} missing from the log: {topics}"
        assert bag.message_count(topic) > 100, f"{topic} has too few messages"
    assert bag.scene() is not None, "the log must carry the scene"


def test_demo_shows_the_papers_effect(demo):
    _, report = demo
    reference = sphere_reference(DEFAULT_CONTACT)
    predicted = _number(report, "predicted")
    reached = _number(report, "reached")
    # The prediction is made from the end of the hold at the speed the driver then uses.
    np.testing.assert_allclose(reached, predicted, rtol=0.02, err_msg="pull-off predicted vs reached")
    assert reached < 0, "the release must pull"
    w_in = _number(report, "work of adhesion in")
    w_out = _number(report, "work of adhesion out")
    np.testing.assert_allclose(w_in, reference.work_indentation, rtol=0.05, err_msg="w_eff1 on approach")
    # The edge reaches the quasistatic w_eff2 only as the ramp slows: about 94 % with ramps of
    # 40 creep times (88 % with 20, 97 % with 80); the force, an integral, is closer.
    np.testing.assert_allclose(w_out, reference.work_detachment, rtol=0.1, err_msg="w_eff2 on release")
    np.testing.assert_allclose(
        reached, -1.5 * math.pi * reference.radius * reference.work_detachment,
        rtol=0.01, err_msg="pull-off vs -(3/2) pi R w_eff2",
    )
    lost = _number(report, "energy lost in cycle")
    f_c, _, d_c = reference.scales
    assert math.isfinite(lost) and lost > 0.01 * f_c * d_c, f"the cycle must lose energy ({lost} J)"


def test_node_in_process_runs_at_the_nodes_gil_switch_interval() -> None:
    """In-process, the node's live thread shares the GIL with the executor and the caller:
    node_in_process runs at the interval `viscoadh node` uses and restores the caller's."""
    from viscoadh_ros.demo import node_in_process
    from viscoadh_ros.ros.node import GIL_SWITCH_INTERVAL_S

    before = sys.getswitchinterval()
    with node_in_process(SceneConfig.from_yaml(default_scene_path())):
        assert sys.getswitchinterval() == pytest.approx(GIL_SWITCH_INTERVAL_S)
    assert sys.getswitchinterval() == before


@pytest.mark.parametrize(
    "inward, outward, loop, lost, expected",
    [
        # The default (viscoelastic) scene's numbers: the paper's effect and energy still stored.
        (2.381e-3, 5e-2, 3.414e-6, 2.667e-6, ["weak on the way in", "strong on the way out", "still stored"]),
        # An elastic scene (the outside tester's --scene config/examples/elastic.yaml): the same
        # work both ways, and the loop's area is what was dissipated.
        (44e-3, 44e-3, 1.85e-9, 1.855e-9, ["about the same both ways", "nothing is left stored"]),
    ],
)
def test_the_report_commentary_follows_the_numbers(inward, outward, loop, lost, expected):
    from viscoadh_ros.demo import DemoSummary, format_summary

    summary = DemoSummary(
        predicted_pull_off=-1e-3,
        reached_pull_off=-1e-3,
        approach_work_of_adhesion=inward,
        release_work_of_adhesion=outward,
        reference=sphere_reference(DEFAULT_CONTACT),
        loop_energy=loop,
        dissipated_energy=lost,
        simulated_time=1.0,
        wall_time=1.0,
        commands=10,
    )
    report = format_summary(summary, {})
    for text in expected:
        assert text in report, report
    if "weak on the way in" not in expected:
        assert "weak on the way in" not in report and "still stored" not in report, report
