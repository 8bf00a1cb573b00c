"""The node's parameters: read the scene from them, declare them with descriptors.

The scene schema and its validation live in :mod:`viscoadh_ros.core.config` (one schema, one
loader). This module only adapts it to ROS 2 parameters:

* :func:`scene_from_node` reads the flat dotted overrides rclpy hands the node (from
  ``--ros-args --params-file FILE`` and ``-p name:=value``) and builds a
  :class:`~viscoadh_ros.core.config.SceneConfig` with ``SceneConfig.from_parameters``. Without a
  ``contacts`` override the built-in scene (``default_scene_path()``) is the base and the
  overrides are applied on top of it.
* :func:`declare_scene` declares every parameter of the effective scene with a
  :class:`ParameterDescriptor` (units in the description, ranges, ``read_only`` where a change at
  runtime cannot be applied safely), so ``ros2 param list/describe/get`` show the whole scene.
* :func:`classify_change` tells the node which part of the scene a runtime change touches.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
)
from rclpy.node import Node
from rclpy.parameter import Parameter

from viscoadh_ros.core.config import (
    COMMAND_QUEUE_DEPTH_MAX,
    CONTACT_KEYS,
    DURATION_MAX_S,
    NODE_KEYS,
    PHYSICAL_RANGES,
    PUBLISH_RATE_MAX,
    PUBLISH_RATE_MIN,
    SceneConfig,
    load_default_scene,
    read_yaml,
)
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.core.presets import DOMAIN_RADIUS_RANGE, ELEMENTS_MAX, MAX_SUBSTEPS

#: Parameters every rclpy node declares itself; they are not part of the scene.
_RCLPY_PARAMETERS = frozenset({"use_sim_time", "start_type_description_service"})
#: rclpy's QoS override parameters (``qos_overrides./topic.publisher.depth`` ...).
_RCLPY_PREFIXES = ("qos_overrides.",)

#: Node-level parameters that the node applies at runtime without touching any contact.
RUNTIME_NODE_PARAMETERS = frozenset({"publish_rate", "frame_id", "markers.enabled", "command.max_future_s"})

_INF = math.inf


@dataclass(frozen=True)
class _Spec:
    """How one parameter is described to ROS tools."""

    description: str
    low: float | None = None
    high: float | None = None
    read_only: bool = False


# Per-contact parameters, keyed by the name after ``<contact id>.``. Changing any of them
# replaces the contact's simulator, which the node allows only while the contact is out of
# touch and relaxed (checked at runtime, so not read_only). The indenter, material and adhesion
# numbers take their ranges from the loader's `PHYSICAL_RANGES` (`descriptor`), not from here.
_CONTACT_SPECS: dict[str, _Spec] = {
    "indenter.shape": _Spec("Indenter shape: sphere | cone | flat_punch | power_law | table."),
    "indenter.radius": _Spec("Sphere radius or flat punch radius, m (> 0)."),
    "indenter.half_angle": _Spec("Cone half-angle between axis and flank, rad (0 < angle < pi/2)."),
    "indenter.coefficient": _Spec("Power-law profile coefficient c in f = c r^n, m^(1-n) (> 0)."),
    "indenter.exponent": _Spec("Power-law profile exponent n (> 0)."),
    "indenter.table_radius": _Spec("Tabulated profile: radii r, m (strictly increasing, from 0)."),
    "indenter.table_height": _Spec(
        "Tabulated profile: gap heights f(r), m (same length as table_radius, f(0) = 0)."
    ),
    "material.glass_shear_modulus": _Spec(
        "Instantaneous (glass) shear modulus G0 of the body, Pa (> 0)."
    ),
    "material.kelvin_shear_moduli": _Spec(
        "Shear moduli G_k of the Kelvin elements in series with the glass spring, Pa (> 0 each)."
    ),
    "material.kelvin_viscosities": _Spec(
        "Viscosities eta_k of the Kelvin elements, Pa s (> 0 each, one per modulus)."
    ),
    "material.poisson_ratio": _Spec(
        "Poisson ratio nu of the body; E* = 2 G / (1 - nu). Default 0.5 (incompressible)."
    ),
    "material.prony_long_term_modulus": _Spec(
        "Relaxation Prony series: long-term shear modulus G_inf, Pa (converted exactly to the Kelvin chain)."
    ),
    "material.prony_moduli": _Spec("Relaxation Prony series: moduli G_i, Pa (> 0 each)."),
    "material.prony_times": _Spec("Relaxation Prony series: relaxation times tau_i, s (> 0)."),
    "adhesion.work_of_adhesion": _Spec("Work of adhesion dgamma, J/m^2 (>= 0; 0 = non-adhesive)."),
    "adhesion.interaction_range": _Spec(
        "Range h of the adhesive interaction, m (> 0); used for the scale-separation check."
    ),
    "numerics.preset": _Spec("Numerics preset: fast | balanced | accurate."),
    "numerics.model": _Spec(
        "Model path: auto (cheapest exact path for the scene) | closed_form | time_stepped."
    ),
    "numerics.elements": _Spec(
        f"Number of MDR elements of the time-stepped model (0 = from the preset, else 4..{ELEMENTS_MAX}).",
        low=0,
        high=ELEMENTS_MAX,
    ),
    "numerics.domain_radius": _Spec(
        "Initial length of the element row, m (0 = from the scene, else "
        f"{DOMAIN_RADIUS_RANGE[0]:g}..{DOMAIN_RADIUS_RANGE[1]:g}; grows with the contact).",
        low=0.0,
        high=DOMAIN_RADIUS_RANGE[1],
    ),
    "numerics.max_substep": _Spec(
        f"Longest internal time substep, s (0 = none); a step longer than {MAX_SUBSTEPS} of them "
        "is refused.",
        low=0.0,
        high=_INF,
    ),
    "numerics.force_tolerance": _Spec(
        "Relative force tolerance of force control (0 = from the preset, < 1).",
        low=0.0,
        high=1.0,
    ),
    "numerics.tolerance": _Spec(
        "Force error the numerics must meet, relative to the pull-off force (0 = the preset's "
        "numerics, else in (0, 1)): the cheapest element count the convergence study says meets it.",
        low=0.0,
        high=1.0,
    ),
    "numerics.time_scale": _Spec(
        "Shortest time over which the loading changes, s (0 = unknown); lets numerics.tolerance "
        "recognise a glassy body.",
        low=0.0,
        high=_INF,
    ),
}

_NODE_SPECS: dict[str, _Spec] = {
    "contacts": _Spec(
        "Ids of the simulated contacts; each id C gets C/indentation, C/state, C/wrench and "
        "services under C/. Fixed at start-up.",
        read_only=True,
    ),
    "publish_rate": _Spec(
        "Rate of the state published between commands (hold, relaxation), Hz.",
        low=PUBLISH_RATE_MIN,
        high=PUBLISH_RATE_MAX,
    ),
    "frame_id": _Spec(
        "frame_id of published states, wrenches and markers: the contact frame, z from the body "
        "out through the indenter."
    ),
    "markers.enabled": _Spec("Publish C/marker (contact disc and indenter) for RViz/Foxglove."),
    "command.max_future_s": _Spec(
        "How far ahead of the node clock a command's header.stamp may be, s; a command stamped "
        "further ahead is rejected (it would move the contact's time).",
        low=0.0,
        high=DURATION_MAX_S,
    ),
    "command.queue_depth": _Spec(
        "Commands each command subscription (C/indentation, hand/indentation) holds for the "
        "live thread, keep last: a node that falls behind by more loses the oldest. Fixed at "
        "start-up.",
        low=1,
        high=COMMAND_QUEUE_DEPTH_MAX,
        read_only=True,
    ),
    "log.enabled": _Spec("Record commands, states and wrenches to MCAP.", read_only=True),
    "log.path": _Spec("MCAP file or folder for the log.", read_only=True),
    "log.chunk_size": _Spec("MCAP chunk size, bytes.", low=1, high=2**31 - 1, read_only=True),
    "log.max_bytes": _Spec(
        "Rotate the log file after this many bytes (0 = never).",
        low=0,
        high=2**62,
        read_only=True,
    ),
    "log.max_duration": _Spec(
        "Rotate the log file after this many seconds (0 = never), s.",
        low=0.0,
        high=DURATION_MAX_S,
        read_only=True,
    ),
    "log.queue_size": _Spec(
        "Bound of the log writer's queue, messages (full queue drops).",
        low=1,
        high=2**31 - 1,
        read_only=True,
    ),
}


def is_scene_parameter(name: str) -> bool:
    """True for a parameter name that belongs to the scene (not one of rclpy's own)."""
    return name not in _RCLPY_PARAMETERS and not name.startswith(_RCLPY_PREFIXES)


def not_a_scene_parameter(name: str) -> str:
    """Why a runtime change of ``name`` (not part of the scene) is refused."""
    if name == "use_sim_time":
        return (
            "use_sim_time is fixed at start-up: start the node with -p use_sim_time:=true "
            "(a contact's time comes from its commands' stamps on the clock it started with)"
        )
    if name in _RCLPY_PARAMETERS or name.startswith(_RCLPY_PREFIXES):
        return f"{name} is one of rclpy's own parameters, fixed at start-up"
    return f"{name} is not a parameter of this node (see docs/ros_interface.md, Parameters)"


def node_overrides(node: Node) -> dict[str, Any]:
    """The scene parameters given to ``node`` as overrides (params file, ``-p``), flat dotted.

    The node must be created with ``automatically_declare_parameters_from_overrides=True``:
    that is rclpy's public way to see the overrides before knowing their names.
    """
    names = [n for n in node.list_parameters([], 0).names if is_scene_parameter(n)]
    return {p.name: p.value for p in node.get_parameters(names)}


def load_scene(overrides: Mapping[str, Any]) -> SceneConfig:
    """Build the scene from flat dotted overrides (raises ``ConfigError`` naming a bad key).

    Without a ``contacts`` override the built-in scene is the base, so ``-p publish_rate:=100``
    alone runs the default scene at 100 Hz.
    """
    flat: dict[str, Any] = {}
    if "contacts" not in overrides:
        flat.update(load_default_scene().to_parameters())
    flat.update(overrides)
    return SceneConfig.from_parameters(flat)


def scene_from_node(node: Node) -> SceneConfig:
    """The scene the node was started with (see :func:`load_scene`)."""
    return load_scene(node_overrides(node))


def spec_for(name: str) -> _Spec | None:
    """The descriptor spec of a flat scene parameter name, None if the name has none."""
    if name in _NODE_SPECS:
        return _NODE_SPECS[name]
    _, _, leaf = name.partition(".")
    return _CONTACT_SPECS.get(leaf)


def _kind(name: str) -> str:
    """The schema kind of a flat name (``float|int|str|bool|floats|strings``)."""
    if name == "contacts":
        return "strings"
    if name in NODE_KEYS:
        return NODE_KEYS[name]
    _, _, leaf = name.partition(".")
    return CONTACT_KEYS[leaf]


_ROS_TYPES = {
    "float": (Parameter.Type.DOUBLE, float),
    "int": (Parameter.Type.INTEGER, int),
    "str": (Parameter.Type.STRING, str),
    "bool": (Parameter.Type.BOOL, bool),
    "floats": (Parameter.Type.DOUBLE_ARRAY, lambda v: [float(x) for x in v]),
    "strings": (Parameter.Type.STRING_ARRAY, lambda v: [str(x) for x in v]),
}


def ros_parameter(name: str, value: Any) -> Parameter:
    """A Parameter of the schema's type for a validated scene value (``to_parameters()``).

    The type comes from the schema, not the value: rclpy would call ``[]`` a byte array and a
    whole-number modulus an integer.
    """
    parameter_type, convert = _ROS_TYPES[_kind(name)]
    return Parameter(name, parameter_type, convert(value))


def descriptor(name: str, parameter_type: int) -> ParameterDescriptor:
    """The ParameterDescriptor for a flat scene parameter: description, range, read_only."""
    spec = spec_for(name) or _Spec(f"Scene parameter {name} (see docs/ros_interface.md).")
    low, high, description = spec.low, spec.high, spec.description
    _, _, leaf = name.partition(".")
    if name not in _NODE_SPECS and leaf in PHYSICAL_RANGES:
        # An indenter, material or adhesion number: the loader's range (both ends included),
        # the one a change is checked against.
        low, high, unit = PHYSICAL_RANGES[leaf]
        description += f" Allowed: [{low:g}, {high:g}]" + (f" {unit}" if unit else "") + "."
    desc = ParameterDescriptor(
        name=name,
        type=parameter_type,
        description=description,
        read_only=spec.read_only,
    )
    if low is not None and parameter_type == ParameterType.PARAMETER_DOUBLE:
        desc.floating_point_range = [
            FloatingPointRange(from_value=float(low), to_value=float(high), step=0.0)
        ]
    elif low is not None and parameter_type == ParameterType.PARAMETER_INTEGER:
        desc.integer_range = [IntegerRange(from_value=int(low), to_value=int(high), step=0)]
    return desc


def declare_scene(node: Node, scene: SceneConfig) -> None:
    """Declare every parameter of ``scene`` on ``node`` with its descriptor and typed value.

    Overrides were auto-declared untyped and without descriptors; they are re-declared here,
    statically typed, with the validated value of the scene (``ignore_override``: the scene
    already holds them). rclpy infers BYTE_ARRAY from ``[]``, so an empty list is declared by
    its type and then set.
    """
    empty = []
    for name, value in scene.to_parameters().items():
        parameter = ros_parameter(name, value)
        if node.has_parameter(name):
            node.undeclare_parameter(name)
        is_empty = isinstance(parameter.value, list) and not parameter.value
        node.declare_parameter(
            name,
            parameter.type_ if is_empty else parameter.value,
            descriptor(name, parameter.type_.value),
            ignore_override=True,
        )
        if is_empty:
            empty.append(parameter)
    node.set_parameters(empty)


def classify_change(name: str, contact_ids: tuple[str, ...]) -> str | None:
    """The contact id a parameter belongs to, ``""`` for a node-level one, None if unknown."""
    head, _, _ = name.partition(".")
    if head in contact_ids:
        return head
    if name in _NODE_SPECS or name.startswith("log."):
        return ""
    return None


def check_params_files(args: list[str]) -> None:
    """Read every ``--params-file FILE`` of the ROS arguments ``args`` before rclpy does, so a
    missing or unparsable file is one ConfigError line naming it (rcl's own error is a
    traceback). The scene inside is validated later, by the node, like any parameters."""
    for flag, value in zip(args, args[1:], strict=False):
        if flag == "--params-file":
            data = read_yaml(value, what="params file")
            if not isinstance(data, Mapping):
                raise ConfigError(
                    f"params file {value!r} must hold a mapping ({{node name or /**: "
                    f"{{ros__parameters: ...}}}}), got {type(data).__name__}"
                )
