"""`viscoadh fit` end to end: a synthetic experiment with known parameters and noise, written as
a bag with real rclpy serialisation, is fitted back within the uncertainty the fit states."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from geometry_msgs.msg import PointStamped, WrenchStamped

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator
from viscoadh_ros.fitting import parameters_of, with_parameters
from viscoadh_ros.io.mcap_log import McapRecorder, plain
from viscoadh_ros.ros.conversions import ns_to_stamp

#: The material behind the synthetic record (standard solid, retardation time 10 ms).
TRUE = {"G0": 1.0e6, "G1": 2.0e5, "eta1": 2.0e3, "work_of_adhesion": 0.05}
#: Where the fit starts (the --scene file): every parameter off by 20 to 100 %.
START = {"G0": 1.6e6, "G1": 1.2e5, "eta1": 4.0e3, "work_of_adhesion": 0.03}
NOISE = 0.02  # standard deviation of the load-cell noise, fraction of max|F|
T0_NS = 5_000_000_000


def _scene(values: dict[str, float]) -> SceneConfig:
    return SceneConfig.from_parameters(
        {
            "contacts": ["probe"],
            "probe.indenter.shape": "sphere",
            "probe.indenter.radius": 0.01,
            "probe.material.glass_shear_modulus": values["G0"],
            "probe.material.kelvin_shear_moduli": [values["G1"]],
            "probe.material.kelvin_viscosities": [values["eta1"]],
            "probe.adhesion.work_of_adhesion": values["work_of_adhesion"],
            "probe.numerics.preset": "fast",
        }
    )


def _write_experiment(path: Path, *, retract_to: float = -30e-6) -> float:
    """Two indentations at different rates, a hold, and a retraction past pull-off, sampled at
    1 kHz: depth as PointStamped.point.z, load cell as WrenchStamped.wrench.force.z (+ noise)."""
    t = np.arange(0.0, 0.2, 1e-3)
    depth = np.interp(
        t, [0, 0.01, 0.03, 0.05, 0.08, 0.10, 0.2], [-1e-6, 10e-6, 10e-6, 3e-6, 20e-6, 20e-6, retract_to]
    )
    sim = ContactSimulator(_scene(TRUE).contacts[0])
    force = np.array([sim.step(float(ti), depth=float(di)).force for ti, di in zip(t, depth, strict=True)])
    sigma = NOISE * float(np.max(np.abs(force)))
    force += np.random.default_rng(7).normal(0.0, sigma, force.size)
    with McapRecorder(path) as recorder:
        for ti, di, fi in zip(t, depth, force, strict=True):
            stamp_ns = T0_NS + round(ti * 1e9)
            point = PointStamped()
            point.header.stamp = ns_to_stamp(stamp_ns)
            point.point.z = float(di)
            wrench = WrenchStamped()
            wrench.header.stamp = ns_to_stamp(stamp_ns)
            wrench.wrench.force.z = float(fi)
            # Log times a little after the stamps, as a recorder receiving them would have them.
            recorder.record("/probe/depth", point, stamp_ns + 300_000)
            recorder.record("/loadcell/wrench", wrench, stamp_ns + 400_000)
    assert recorder.error is None and recorder.dropped == 0, "the synthetic bag must be complete"
    return sigma


def _write_scene(path: Path, scene: SceneConfig) -> Path:
    path.write_text(yaml.safe_dump(plain(scene.to_dict()), sort_keys=False), encoding="utf-8")
    return path


def test_fit_recovers_known_parameters_within_stated_uncertainty(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    bag = tmp_path / "experiment.mcap"
    noise = _write_experiment(bag)
    start = _write_scene(tmp_path / "start.yaml", _scene(START))
    fitted_path = tmp_path / "fitted.yaml"
    code = main(
        ["fit", str(bag), "--scene", str(start), "--depth-topic", "/probe/depth", "-o", str(fitted_path)]
    )
    out = capsys.readouterr().out
    assert code == 0, f"fit failed: {out}"
    stated = {
        name: (float(value), float(sigma))
        for name, value, sigma in re.findall(r"^\s*(\w+) = (\S+) \+- (\S+) ", out, flags=re.MULTILINE)
    }
    assert set(stated) == set(TRUE), f"every free parameter is reported with an uncertainty: {out}"
    fitted = parameters_of(SceneConfig.from_yaml(fitted_path).contacts[0])
    for name, truth in TRUE.items():
        value, sigma = stated[name]
        np.testing.assert_allclose(fitted[name], value, rtol=1e-5, err_msg=f"{name}: written vs printed")
        assert sigma < 0.05 * truth, f"{name}: uncertainty {sigma:g} too large to mean anything"
        assert abs(value - truth) <= 3.0 * sigma, f"{name}: {value:g} +- {sigma:g}, truth {truth:g}"

    # The written scene is one replay accepts, and its force follows the record to the noise.
    summary = tmp_path / "summary.json"
    args = [
        "replay",
        str(bag),
        "--scene",
        str(fitted_path),
        "--depth-topic",
        "/probe/depth",
        "-o",
        str(tmp_path / "replay.mcap"),
        "--json",
        str(summary),
    ]
    assert main(args) == 0
    result = yaml.safe_load(summary.read_text())
    assert result["rmse_N"] < 1.5 * noise, f"replay of the fitted scene: {result}, noise {noise:g} N"


def test_fit_without_pull_off_refuses_work_of_adhesion(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    bag = tmp_path / "press_only.mcap"
    _write_experiment(bag, retract_to=5e-6)  # never pulled out: the force stays compressive
    start = _write_scene(tmp_path / "start.yaml", _scene(START))
    out = tmp_path / "fitted.yaml"
    code = main(["fit", str(bag), "--scene", str(start), "--depth-topic", "/probe/depth", "-o", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, f"one error line, exit 2: {err}"
    assert "work_of_adhesion cannot be identified" in err[0], err[0]
    assert not out.exists(), "nothing may be written"


def test_fitted_values_replace_a_prony_series() -> None:
    prony = SceneConfig.from_parameters(
        {
            "contacts": ["probe"],
            "probe.indenter.shape": "sphere",
            "probe.indenter.radius": 0.01,
            "probe.material.prony_long_term_modulus": 1.0e5,
            "probe.material.prony_moduli": [4.0e5],
            "probe.material.prony_times": [0.01],
        }
    ).contacts[0]
    fitted = with_parameters(prony, TRUE, kelvin=1)
    written = SceneConfig.from_dict(SceneConfig(contacts=(fitted,), node=_scene(TRUE).node).to_dict())
    np.testing.assert_allclose(
        [parameters_of(written.contacts[0])[n] for n in TRUE],
        list(TRUE.values()),
        rtol=1e-12,
        err_msg="a scene given as Prony series must be written with the fitted chain",
    )
