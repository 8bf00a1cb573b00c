"""`viscoadh replay`'s bulk output equals, message for message, what the node's conversions build."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from viscoadh_ros.bench.replay_speed import record_stream
from viscoadh_ros.cli.main import main
from viscoadh_ros.experiment import choose_contact, load_experiment, run_model
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.ros import conversions


def test_replay_output_equals_conversions(tmp_path: Path) -> None:
    bag_path, out = tmp_path / "stream.mcap", tmp_path / "out.mcap"
    scene = record_stream(bag_path, 0.12)
    assert main(["replay", str(bag_path), "-o", str(out)]) == 0
    experiment = load_experiment(Bag(bag_path))
    contact = choose_contact(scene, None)
    run = run_model(contact, experiment)
    frame = scene.node.frame_id
    replayed = Bag(out)
    states = list(replayed.messages([f"/{contact.id}/state"]))
    wrenches = list(replayed.messages([f"/{contact.id}/wrench"]))
    assert len(states) == len(wrenches) == experiment.input_ns.size
    for k, (stamp, output) in enumerate(zip(experiment.input_ns.tolist(), run.input_outputs, strict=True)):
        expected = conversions.contact_state(
            output,
            stamp_ns=stamp,
            frame_id=frame,
            model=run.model,
            commands_received=k + 1,
            commands_rejected=0,
        )
        assert states[k].msg == expected, f"state {k}"
        assert states[k].log_time_ns == wrenches[k].log_time_ns == stamp, f"log times of command {k}"
        assert wrenches[k].msg == conversions.wrench(output, stamp_ns=stamp, frame_id=frame), f"wrench {k}"
    # A state and its wrench are recorded together, in stamp order.
    orders = np.array([[s.order, w.order] for s, w in zip(states, wrenches, strict=True)])
    np.testing.assert_array_equal(orders[:, 1] - orders[:, 0], 1, err_msg="wrench right after its state")
