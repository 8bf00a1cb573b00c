"""Core <-> message conversions: constants agree, every field is carried, signs are kept."""

from __future__ import annotations

import dataclasses
import math

import pytest
from geometry_msgs.msg import WrenchStamped
from rclpy.serialization import deserialize_message
from viscoadh_msgs.msg import ContactState, IndentationCommand

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.simulator import Phase, StepOutput
from viscoadh_ros.ros import conversions


@pytest.mark.parametrize("phase", list(Phase))
def test_phase_values_equal_the_message_constants(phase: Phase) -> None:
    assert getattr(ContactState, phase.name) == phase.value, phase.name


def test_model_codes_cover_both_model_paths() -> None:
    assert conversions.MODEL_CODES == {
        "closed_form": ContactState.MODEL_CLOSED_FORM,
        "time_stepped": ContactState.MODEL_TIME_STEPPED,
    }


#: A detaching, tensile, unstable step: every field non-default and signed where it can be.
OUTPUT = StepOutput(
    time=1.5,
    depth=-2e-6,
    force=-3e-3,
    contact_radius=4e-5,
    phase=Phase.DETACHING,
    edge_speed=-1e-4,
    effective_work_of_adhesion=0.3,
    energy_input=1e-9,
    energy_dissipated=2e-10,
    scale_separation_ok=False,
    unstable=True,
)


def test_step_output_fields_are_all_carried_with_their_sign() -> None:
    output = OUTPUT
    state = conversions.contact_state(
        output,
        stamp_ns=3_000_000_007,
        frame_id="tip",
        model="time_stepped",
        commands_received=5,
        commands_rejected=2,
    )
    for field in dataclasses.fields(StepOutput):
        if field.name != "time":
            assert getattr(state, field.name) == getattr(output, field.name), field.name
    assert (state.header.stamp.sec, state.header.stamp.nanosec) == (3, 7)
    assert state.header.frame_id == "tip" and state.model == ContactState.MODEL_TIME_STEPPED
    assert (state.commands_received, state.commands_rejected) == (5, 2)
    wrench = conversions.wrench(output, stamp_ns=3_000_000_007, frame_id="tip")
    # Adhesive pull: the force on the indenter points into the body, -z of the contact frame.
    assert wrench.wrench.force.z == -3e-3
    assert (wrench.wrench.force.x, wrench.wrench.force.y, wrench.wrench.torque.z) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    "msg, match",
    [
        (IndentationCommand(mode=3, depth=1e-6), "mode"),
        (IndentationCommand(mode=IndentationCommand.DEPTH, depth=math.nan), "depth"),
        (IndentationCommand(mode=IndentationCommand.FORCE, force=math.inf), "force"),
    ],
)
def test_bad_command_names_the_field(msg: IndentationCommand, match: str) -> None:
    with pytest.raises(InputError, match=match):
        conversions.command_control(msg)


def test_command_selects_the_control_of_its_mode() -> None:
    msg = IndentationCommand(mode=IndentationCommand.FORCE, depth=math.nan, force=-1e-3)
    assert conversions.command_control(msg) == {"force": -1e-3}, "depth is unused in FORCE mode"


@pytest.mark.parametrize("frame_id", ["", "a", "tip", "contact_frame"])
def test_live_payloads_read_back_as_the_messages(frame_id: str) -> None:
    """The node publishes and logs these bytes: they must deserialise to exactly the messages
    contact_state/wrench build, whatever the frame id's length does to the CDR alignment."""
    output = OUTPUT
    stamp_ns = 1_795_352_880_799_998_059
    common = {"model": "closed_form", "commands_received": 70_000, "commands_rejected": 3}
    payloads = conversions.LivePayloads(frame_id)
    state = deserialize_message(payloads.state(output, stamp_ns=stamp_ns, **common), ContactState)
    expected = conversions.contact_state(output, stamp_ns=stamp_ns, frame_id=frame_id, **common)
    assert state == expected, f"frame {frame_id!r}: {state} != {expected}"
    wrench = deserialize_message(payloads.wrench(output, stamp_ns=stamp_ns), WrenchStamped)
    expected_wrench = conversions.wrench(output, stamp_ns=stamp_ns, frame_id=frame_id)
    assert wrench == expected_wrench, f"frame {frame_id!r}: {wrench} != {expected_wrench}"
