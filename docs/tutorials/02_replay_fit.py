"""Tutorial 2, step 1: make a recorded experiment to replay and fit.

Stands in for a lab recording: an indenter position (geometry_msgs/PointStamped, z = depth,
m) and a load cell (geometry_msgs/WrenchStamped, force.z, N, > 0 compressive) at a fixed rate, for
two press-hold-pull cycles at different speeds, on a material whose parameters the
recording does not tell you. Writes OUT/experiment.mcap and OUT/truth.yaml (the answer, for
checking the fit). See docs/tutorials/02_replay_fit.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import yaml
from geometry_msgs.msg import PointStamped, WrenchStamped

from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.demo import creep_time
from viscoadh_ros.io.mcap_log import McapRecorder
from viscoadh_ros.plotting import JkrReference
from viscoadh_ros.ros.conversions import ns_to_stamp


def cycle(d_c: float, ramp: float, hold: float, dt: float) -> np.ndarray:
    """Depth samples (m), every `dt` s, of one press-hold-pull cycle: ramps of `ramp` s
    from -2 d_c to 4 d_c and back, a hold of `hold` s between them."""
    down = np.linspace(-2.0 * d_c, 4.0 * d_c, round(ramp / dt))
    return np.concatenate([down, np.full(round(hold / dt), 4.0 * d_c), down[::-1]])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("experiment"))
    parser.add_argument("--samples", type=int, default=100, help="samples per slow ramp")
    args = parser.parse_args()

    # The "true" material: the built-in scene with a stiffer, stickier pad.
    flat = SceneConfig.from_yaml(default_scene_path()).to_parameters()
    contact_id = flat["contacts"][0]
    flat[f"{contact_id}.material.glass_shear_modulus"] *= 1.5
    flat[f"{contact_id}.adhesion.work_of_adhesion"] *= 2.0
    truth = SceneConfig.from_parameters(flat)
    contact = truth.contact(contact_id)
    _, _, d_c = JkrReference.from_contact(contact).scales  # critical depth, m
    creep = creep_time(contact)  # the material's longest creep time, s

    # Two cycles, slow (ramps of 5 creep times) and fast (half a creep time), holds of one
    # creep time, and a pause of two between them.
    dt = 5.0 * creep / args.samples  # the recorder's sample period, s
    depth = np.concatenate([
        cycle(d_c, 5.0 * creep, creep, dt),
        np.full(round(2.0 * creep / dt), -2.0 * d_c),
        cycle(d_c, 0.5 * creep, creep, dt),
    ])
    time = np.arange(depth.size) * dt
    force = simulate_history(contact, time, depth=depth).force
    rng = np.random.default_rng(7)
    measured = force + rng.normal(0.0, 0.01 * np.max(np.abs(force)), force.size)

    args.out.mkdir(parents=True, exist_ok=True)
    # --8<-- [start:record]
    with McapRecorder(args.out / "experiment.mcap") as bag:
        for t, d, f in zip(time, depth, measured, strict=True):
            stamp_ns = round((1.0 + t) * 1e9)
            position = PointStamped()
            position.header.stamp = ns_to_stamp(stamp_ns)
            position.point.z = float(d)
            load = WrenchStamped()
            load.header.stamp = ns_to_stamp(stamp_ns)
            load.wrench.force.z = float(f)
            bag.record("/finger/position", position, stamp_ns)
            bag.record("/load_cell", load, stamp_ns)
    # --8<-- [end:record]
    (args.out / "truth.yaml").write_text(yaml.safe_dump(truth.to_dict(), sort_keys=False))
    print(f"wrote {args.out / 'experiment.mcap'}: {time.size} samples over {time[-1]:.3g} s")


if __name__ == "__main__":
    main()
