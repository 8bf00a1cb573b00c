"""Synthetic recorded experiments with known material for the fit tests.

A record is made by an INDEPENDENT model run (`simulate_history` at the ``accurate`` preset,
a finer grid sized by the simulator itself, not the fit's grid) plus seeded Gaussian
load-cell noise, and written as a bag with real rclpy serialisation: the depth as
PointStamped.point.z on ``/probe/depth``, the load cell as WrenchStamped.wrench.force.z on
``/loadcell/wrench``, both stamped by the rig's clock.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from geometry_msgs.msg import PointStamped, WrenchStamped

from viscoadh_ros.bench.fit_speed import probe_scene
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.io.mcap_log import McapRecorder, plain
from viscoadh_ros.ros.conversions import ns_to_stamp

#: A standard solid (retardation time eta1/G1 = 10 ms) on a 10 mm sphere.
TRUE = {"G0": 1.0e6, "G1": 2.0e5, "eta1": 2.0e3, "work_of_adhesion": 0.05}
T0_NS = 5_000_000_000
DEPTH_TOPIC = "/probe/depth"


def scene(values: dict[str, float], *, preset: str = "fast", kelvin: int = 1) -> SceneConfig:
    """A one-contact scene ("probe", sphere R = 10 mm) with ``values`` (names as fitting's):
    the bench's own record scene, so tests and bench fit the same experiment."""
    return probe_scene(values, preset=preset, kelvin=kelvin)


def standard_history(samples: int = 200, *, retract_to: float = -30e-6) -> tuple[np.ndarray, np.ndarray]:
    """(time s, depth m): a fast press to 10 um, a hold, a partial unload, a slower press to
    20 um, a hold and a retraction past pull-off, over 0.2 s in ``samples`` samples."""
    t = np.linspace(0.0, 0.2, samples, endpoint=False)
    depth = np.interp(
        t, [0, 0.01, 0.03, 0.05, 0.08, 0.10, 0.2], [-1e-6, 10e-6, 10e-6, 3e-6, 20e-6, 20e-6, retract_to]
    )
    return t, depth


def true_force(
    values: dict[str, float], time: np.ndarray, depth: np.ndarray, *, kelvin: int = 1
) -> np.ndarray:
    """The noiseless force (N) of the independent model run (``accurate`` preset)."""
    contact = scene(values, preset="accurate", kelvin=kelvin).contacts[0]
    return simulate_history(contact, time, depth=depth).force


def write_record(
    path: Path,
    time: np.ndarray,
    depth: np.ndarray,
    force: np.ndarray,
    *,
    noise: float,
    seed: int,
) -> float:
    """Write ``force`` plus Gaussian noise of ``noise`` x max|force| (seeded) as a bag;
    returns the noise's standard deviation, N."""
    sigma = noise * float(np.max(np.abs(force)))
    measured = force + np.random.default_rng(seed).normal(0.0, sigma, force.size)
    with McapRecorder(path) as recorder:
        for ti, di, fi in zip(time, depth, measured, strict=True):
            stamp_ns = T0_NS + round(ti * 1e9)
            point = PointStamped()
            point.header.stamp = ns_to_stamp(stamp_ns)
            point.point.z = float(di)
            wrench = WrenchStamped()
            wrench.header.stamp = ns_to_stamp(stamp_ns)
            wrench.wrench.force.z = float(fi)
            # Log times a little after the stamps, as a recorder receiving them would have them.
            recorder.record(DEPTH_TOPIC, point, stamp_ns + 300_000)
            recorder.record("/loadcell/wrench", wrench, stamp_ns + 400_000)
    assert recorder.error is None and recorder.dropped == 0, "the synthetic bag must be complete"
    return sigma


def write_scene(path: Path, values: dict[str, float], *, preset: str = "fast", kelvin: int = 1) -> Path:
    """A start scene file with ``values``."""
    path.write_text(
        yaml.safe_dump(plain(scene(values, preset=preset, kelvin=kelvin).to_dict()), sort_keys=False),
        encoding="utf-8",
    )
    return path
