"""The scene configuration: one schema, one loader, shared by the node, the CLI and the tests.

A scene is a ROS 2 parameters file::

    /**:
      ros__parameters:
        contacts: [finger]
        finger:
          indenter: {shape: sphere, radius: 0.002}
          material: {glass_shear_modulus: 1.0e6, kelvin_shear_moduli: [2.0e4], ...}
          adhesion: {work_of_adhesion: 0.05}
        publish_rate: 50.0

:meth:`SceneConfig.from_dict` accepts that mapping (any node name; of several node sections
those that apply to the node, ``/**`` and ``viscoadh``, merged in file order, as the node takes
them, else all of them), the bare ``ros__parameters`` mapping, or the flat dotted form
rclpy hands a node (``"finger.indenter.shape": "sphere"``). Everything funnels into
:meth:`SceneConfig.from_parameters`, the one validator: unknown keys (with the closest valid
key suggested), wrong types, out-of-range or non-finite values all raise
:class:`ConfigError` naming the full dotted key. Every key, its unit, default and range is
listed in ``docs/configuration.md``.

Notes on particular keys:

* Keys of other indenter shapes (``indenter.half_angle`` for a sphere) are accepted and
  ignored, so that a shape can be overridden on top of a base scene; they are not kept.
* The material is a Kelvin chain (``glass_shear_modulus`` + ``kelvin_*`` lists) OR a
  relaxation Prony series (``prony_long_term_modulus``, ``prony_moduli``, ``prony_times``),
  converted exactly to the chain (:func:`rheology.prony_to_creep`); giving both is an error.
  The config keeps the form it was given in, so it round-trips.
* K = 0 (elastic): omit ``kelvin_shear_moduli``/``kelvin_viscosities`` (or write ``[]`` in
  YAML read by this loader). ROS parameters cannot type an empty array by themselves (rclpy
  infers a byte array, and ROS params files reject ``[]``): :meth:`to_parameters` gives an
  empty ``list`` for such keys and the node declares them as ``DOUBLE_ARRAY``.
"""

from __future__ import annotations

import array
import difflib
import math
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from viscoadh_ros.core.errors import ConfigError, InputError
from viscoadh_ros.core.presets import TOLERANCE_RANGE, SceneHint, resolve_numerics
from viscoadh_ros.core.profiles import make_profile
from viscoadh_ros.core.rheology import CreepElement, prony_to_creep


@dataclass(frozen=True, kw_only=True)
class IndenterConfig:
    """Rigid axisymmetric indenter.

    shape: ``sphere | cone | flat_punch | power_law | table``.
    radius: sphere radius R or flat punch radius a0, m (> 0; sphere, flat_punch).
    half_angle: cone half-angle between axis and flank, rad, in (0, pi/2) (cone).
    coefficient: ``c`` of ``f = c r^n``, m^(1-n) (> 0; power_law).
    exponent: ``n`` of ``f = c r^n`` (> 0; power_law).
    table_radius: radii r_i, m, from 0, strictly increasing (table).
    table_height: gap heights f(r_i), m, from 0, non-decreasing (table).
    Fields that do not apply to the shape are 0 / empty.
    """

    shape: str
    radius: float = 0.0
    half_angle: float = 0.0
    coefficient: float = 0.0
    exponent: float = 0.0
    table_radius: tuple[float, ...] = ()
    table_height: tuple[float, ...] = ()


@dataclass(frozen=True, kw_only=True)
class MaterialConfig:
    """Viscoelastic half-space: glass spring ``G0`` in series with K Kelvin elements.

    glass_shear_modulus: ``G0``, instantaneous shear modulus, Pa (> 0).
    kelvin_shear_moduli: ``G_k``, Pa (> 0 each), K entries (K = 0: elastic).
    kelvin_viscosities: ``eta_k``, Pa s (> 0 each), K entries.
    poisson_ratio: ``nu`` in [0, 0.5], default 0.5 (incompressible); ``E* = 2 G/(1 - nu)``.
    prony_long_term_modulus, prony_moduli, prony_times: the relaxation Prony series
      ``G(t) = G_inf + sum g_i exp(-t/tau_i)`` (Pa, Pa, s) when the material was given that
      way (then the Kelvin fields hold its exact conversion); 0 / empty otherwise.
    """

    glass_shear_modulus: float
    kelvin_shear_moduli: tuple[float, ...] = ()
    kelvin_viscosities: tuple[float, ...] = ()
    poisson_ratio: float = 0.5
    prony_long_term_modulus: float = 0.0
    prony_moduli: tuple[float, ...] = ()
    prony_times: tuple[float, ...] = ()

    @property
    def given_as_prony(self) -> bool:
        """True if the scene gave this material as a relaxation Prony series."""
        return self.prony_long_term_modulus > 0.0


@dataclass(frozen=True, kw_only=True)
class AdhesionConfig:
    """Adhesion. work_of_adhesion: ``w`` (Delta gamma), J/m^2 (>= 0; 0 = non-adhesive).
    interaction_range: range ``h`` of the adhesive interaction, m (> 0), for the
    scale-separation check of the energy criterion."""

    work_of_adhesion: float = 0.0
    interaction_range: float = 1e-9


@dataclass(frozen=True, kw_only=True)
class NumericsConfig:
    """Speed/accuracy knobs (see ``core/presets.py``); 0 means "from the preset".

    preset: ``fast | balanced | accurate``. model: ``auto | closed_form | time_stepped``.
    elements: MDR elements (int, 0 or >= 4). domain_radius: initial domain length, m.
    max_substep: longest internal substep, s. force_tolerance: relative force tolerance
    of force control (< 1). tolerance: the force error the numerics must meet, relative to
    the pull-off force (0 = the preset's numerics, else in (0, 1)); the element count and
    step control are then the cheapest the convergence study says meet it for the scene
    (``presets.numerics_for_tolerance``). time_scale: the shortest time over which the
    scene's loading changes, s (0 = unknown: the worst case of every regime); with it the
    tolerance mode recognises a relaxed or glassy body.

    ``scene`` is not a parameter: `ContactConfig` attaches what the tolerance mode reads of
    the contact's material and indenter (``presets.SceneHint``); it takes no part in
    equality, the schema or ``to_parameters``.
    """

    preset: str = "balanced"
    model: str = "auto"
    elements: int = 0
    domain_radius: float = 0.0
    max_substep: float = 0.0
    force_tolerance: float = 0.0
    tolerance: float = 0.0
    time_scale: float = 0.0
    scene: SceneHint | None = field(default=None, compare=False, repr=False, metadata={"schema": False})


@dataclass(frozen=True, kw_only=True)
class ContactConfig:
    """One simulated contact; ``id`` is a ROS name token and prefixes its keys and topics."""

    id: str
    indenter: IndenterConfig
    material: MaterialConfig
    adhesion: AdhesionConfig = AdhesionConfig()
    numerics: NumericsConfig = NumericsConfig()

    def __post_init__(self) -> None:
        # The tolerance mode resolves the numerics for this contact's material and indenter:
        # hand them to `resolve_numerics` with the numerics (a `replace` re-runs this).
        hint = SceneHint.of(self.indenter, self.material)
        if self.numerics.scene != hint:
            object.__setattr__(self, "numerics", replace(self.numerics, scene=hint))


@dataclass(frozen=True, kw_only=True)
class NodeConfig:
    """Node-wide settings (flat keys in brackets).

    publish_rate [publish_rate]: state publication rate between commands, Hz (0.1..10000).
    frame_id [frame_id]: frame of published states, wrenches and markers.
    markers_enabled [markers.enabled]: publish ``C/marker``.
    log_enabled [log.enabled], log_path [log.path]: MCAP logging and its file/folder.
    log_chunk_size [log.chunk_size]: MCAP chunk size, bytes (> 0).
    log_max_bytes [log.max_bytes]: rotate after this many bytes (0 = never).
    log_max_duration [log.max_duration]: rotate after this many seconds (0 = never; at most
      :data:`DURATION_MAX_S`).
    log_queue_size [log.queue_size]: bound of the writer queue, messages (> 0).
    command_max_future_s [command.max_future_s]: how far ahead of the node clock a command's
      ``header.stamp`` may be, s (0..:data:`DURATION_MAX_S`); a command stamped further ahead
      is rejected.
    command_queue_depth [command.queue_depth]: commands each command subscription
      (``C/indentation``, ``hand/indentation``) holds for the live thread, keep last
      (1..:data:`COMMAND_QUEUE_DEPTH_MAX`): a node that falls behind by more loses the oldest.
    """

    publish_rate: float = 50.0
    frame_id: str = "contact"
    markers_enabled: bool = False
    log_enabled: bool = False
    log_path: str = ""
    log_chunk_size: int = 256 * 1024
    log_max_bytes: int = 0
    log_max_duration: float = 0.0
    log_queue_size: int = 10000
    command_max_future_s: float = 1.0
    command_queue_depth: int = 100


#: Largest ``command.queue_depth``: 100 s of commands at 1 kHz.
COMMAND_QUEUE_DEPTH_MAX = 100_000

# --- schema: flat key -> (section dataclass field, kind) ------------------------------------

_SECTIONS = {
    "indenter": IndenterConfig,
    "material": MaterialConfig,
    "adhesion": AdhesionConfig,
    "numerics": NumericsConfig,
}
_KIND_OF_TYPE = {"float": "float", "int": "int", "str": "str", "bool": "bool", "tuple[float, ...]": "floats"}


def _schema_fields(cls: type) -> list[Any]:
    """The fields of a section that are parameters (not the numerics' attached scene)."""
    return [f for f in fields(cls) if f.metadata.get("schema", True)]


def _kinds(cls: type) -> dict[str, str]:
    return {f.name: _KIND_OF_TYPE[str(f.type)] for f in _schema_fields(cls)}


#: contact-level keys, relative to ``<id>.``: "indenter.shape" -> "str", ...
CONTACT_KEYS: dict[str, str] = {
    f"{section}.{name}": kind for section, cls in _SECTIONS.items() for name, kind in _kinds(cls).items()
}
#: node-level keys: "publish_rate" -> "float", "markers.enabled" -> "bool", ...
NODE_KEYS: dict[str, str] = {
    name.replace("markers_", "markers.").replace("log_", "log.", 1).replace("command_", "command.", 1): kind
    for name, kind in _kinds(NodeConfig).items()
}
_SHAPE_KEYS = {
    "sphere": ("radius",),
    "cone": ("half_angle",),
    "flat_punch": ("radius",),
    "power_law": ("coefficient", "exponent"),
    "table": ("table_radius", "table_height"),
}
#: Longest duration a node setting in seconds may give (``log.max_duration``,
#: ``command.max_future_s``), s: about 31.7 years; the node holds them in integer nanoseconds
#: (1e300 s overflowed the conversion and stopped the node).
DURATION_MAX_S = 1e9

#: Physical range of every indenter, material and adhesion number, relative key -> (low, high,
#: unit), both ends included (lists: every element). Outside it the model would compute with
#: numbers no body has (G0 = 1e-300 Pa gives a contact radius of 1e98 m) or overflow (1e308 Pa);
#: docs/configuration.md lists the same ranges.
PHYSICAL_RANGES: dict[str, tuple[float, float, str]] = {
    "indenter.radius": (1e-9, 1e3, "m"),
    "indenter.half_angle": (1e-3, math.pi / 2 - 1e-3, "rad"),
    "indenter.coefficient": (1e-30, 1e30, "m^(1-n)"),
    "indenter.exponent": (0.1, 10.0, ""),
    "indenter.table_radius": (0.0, 1e3, "m"),
    "indenter.table_height": (0.0, 1e3, "m"),
    "material.glass_shear_modulus": (1.0, 1e12, "Pa"),
    "material.kelvin_shear_moduli": (1.0, 1e12, "Pa"),
    "material.kelvin_viscosities": (1e-6, 1e15, "Pa s"),
    "material.poisson_ratio": (0.0, 0.5, ""),
    "material.prony_long_term_modulus": (1.0, 1e12, "Pa"),
    "material.prony_moduli": (1.0, 1e12, "Pa"),
    "material.prony_times": (1e-9, 1e9, "s"),
    "adhesion.work_of_adhesion": (0.0, 1e3, "J/m^2"),
    "adhesion.interaction_range": (1e-12, 1e-3, "m"),
}
_KELVIN_KEYS = ("glass_shear_modulus", "kelvin_shear_moduli", "kelvin_viscosities")
_PRONY_KEYS = ("prony_long_term_modulus", "prony_moduli", "prony_times")
# A ROS name token; ids become topic namespaces. "__" is reserved by ROS.
_ID_PATTERN = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_NODE_ROOTS = {key.split(".")[0] for key in NODE_KEYS} | {"contacts"}


#: Keys whose type errors also state the allowed values (the rest state them on range errors).
_ALLOWED = {"numerics.tolerance": TOLERANCE_RANGE}


def _coerce(key: str, kind: str, value: Any) -> Any:
    """``value`` converted to the schema kind, or ConfigError naming ``key``."""
    if kind == "float":
        allowed = next((f", {text}" for leaf, text in _ALLOWED.items() if key.endswith(f".{leaf}")), "")
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ConfigError(f"{key} must be a number{allowed} (got {value!r})")
        number = float(value)
        if not math.isfinite(number):
            raise ConfigError(f"{key} must be finite{allowed} (got {value!r})")
        return number
    if kind == "int":
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            return int(value)
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ConfigError(f"{key} must be an integer (got {value!r})")
        return int(value)
    if kind == "str":
        if not isinstance(value, str):
            raise ConfigError(f"{key} must be a string (got {value!r})")
        return value
    if kind == "bool":
        if not isinstance(value, (bool, np.bool_)):
            raise ConfigError(f"{key} must be true or false (got {value!r})")
        return bool(value)
    # "floats" (and "strings" for contacts): a sequence; rclpy hands array.array for arrays
    if isinstance(value, (bytes, bytearray)) and len(value) == 0:
        return ()  # rclpy types an untyped empty array as a byte array
    if not isinstance(value, (list, tuple, np.ndarray, array.array)):
        raise ConfigError(f"{key} must be a list (got {value!r})")
    item_kind = "str" if kind == "strings" else "float"
    return tuple(_coerce(f"{key}[{index}]", item_kind, item) for index, item in enumerate(value))


def _flatten(mapping: Mapping[str, Any], prefix: str, flat: dict[str, Any]) -> None:
    for key, value in mapping.items():
        if not isinstance(key, str):
            raise ConfigError(f"{prefix}{key!r}: keys must be strings")
        if isinstance(value, Mapping):
            _flatten(value, f"{prefix}{key}.", flat)
        else:
            flat[f"{prefix}{key}"] = value


#: The node's default name (`viscoadh node`), and the params-file section names that apply
#: to it.
NODE_NAME = "viscoadh"
_OWN_SECTIONS = frozenset({"/**", "**", "/*", "*", NODE_NAME, f"/{NODE_NAME}"})


def _unwrap(mapping: Mapping[str, Any]) -> dict[str, Any]:
    """The flat dotted parameters of a params-file mapping, a bare mapping or a flat one."""
    if not isinstance(mapping, Mapping):
        raise ConfigError(f"a scene must be a mapping (got {type(mapping).__name__})")
    wrapped = bool(mapping) and all(
        isinstance(value, Mapping) and set(value) == {"ros__parameters"} for value in mapping.values()
    )
    sections = [
        key for key, value in mapping.items() if isinstance(value, Mapping) and "ros__parameters" in value
    ]
    if sections and not wrapped:
        # A params file with something else beside its node sections: flattened as a bare
        # mapping, it was refused as "contacts is required" (0.8.0's outside tester).
        other = next(
            key for key in mapping if key not in sections or set(mapping[key]) != {"ros__parameters"}
        )
        raise ConfigError(
            f"{other!s}: not a node section; a parameters file holds only "
            f"'<node name>: {{ros__parameters: ...}}' sections (found {', '.join(map(str, sections))})"
        )
    flat: dict[str, Any] = {}
    if wrapped:
        # Several node sections: those the node (named `NODE_NAME` unless remapped) takes,
        # as ROS applies a params file; others are another node's (0.8.0's outside tester:
        # a second node's section was merged and refused as unknown parameters, while the
        # node ran the file). None of them: every section, in file order.
        applies = [name for name in mapping if str(name) in _OWN_SECTIONS]
        chosen = applies if len(mapping) > 1 and applies else list(mapping)
        for node_name in chosen:
            section = mapping[node_name]
            parameters = section["ros__parameters"]
            if not isinstance(parameters, Mapping):
                raise ConfigError(f"{node_name}.ros__parameters must be a mapping")
            _flatten(parameters, "", flat)
    else:
        _flatten(mapping, "", flat)
    return flat


def _prefixed(contact_id: str, error: ValueError) -> ConfigError:
    """An InputError/ConfigError of a section validator, re-raised with the contact id."""
    return ConfigError(f"{contact_id}.{error}")


def _unknown_key(key: str, valid: list[str]) -> ConfigError:
    close = difflib.get_close_matches(key, valid, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return ConfigError(f"unknown parameter {key!r}{hint}")


def _bound_text(bound: float, *, upper: bool) -> str:
    """``bound`` with the fewest significant digits, at least 6, that do not print it outside
    the range it closes (an upper bound never above itself, a lower one never below), so the
    printed bound is itself accepted: at 6 digits pi/2 - 0.001 printed as 1.5698, which is
    above it and was refused at its own printed value."""
    for digits in range(6, 17):
        text = f"{bound:.{digits}g}"
        if (float(text) <= bound) if upper else (float(text) >= bound):
            return text
    return f"{bound:.17g}"  # 17 significant digits give every float back exactly


def _number_text(number: float) -> str:
    """``number`` with the fewest significant digits, at least 6, that give it back exactly,
    so a refused value just beyond a bound never prints as a number inside the range."""
    for digits in range(6, 17):
        text = f"{number:.{digits}g}"
        if float(text) == number:
            return text
    return f"{number:.17g}"


def range_text(key: str) -> str:
    """``[low, high]`` of the :data:`PHYSICAL_RANGES` entry ``key`` (relative, e.g.
    ``"indenter.half_angle"``) as the errors and docs/configuration.md print it: both printed
    bounds are inside the range (see :func:`_bound_text`)."""
    low, high, _ = PHYSICAL_RANGES[key]
    return f"[{_bound_text(low, upper=False)}, {_bound_text(high, upper=True)}]"


def _check_range(key: str, value: Any) -> None:
    """ConfigError naming ``key`` and its :data:`PHYSICAL_RANGES` entry if ``value`` (or an
    element of it) lies outside."""
    relative = key.split(".", 1)[1]
    low, high, unit = PHYSICAL_RANGES[relative]
    values = value if isinstance(value, tuple) else (value,)
    for index, number in enumerate(values):
        if not low <= number <= high:
            name = f"{key}[{index}]" if isinstance(value, tuple) else key
            raise ConfigError(
                f"{name} must be in {range_text(relative)}{' ' + unit if unit else ''} "
                f"(got {_number_text(number)})"
            )


def _build_contact(contact_id: str, given: dict[str, Any]) -> ContactConfig:
    """A validated ContactConfig from its coerced relative keys (``"indenter.radius"``...)."""
    used = {f"indenter.{name}" for name in _SHAPE_KEYS.get(given.get("indenter.shape"), ())}
    for key, value in given.items():
        # Keys of other indenter shapes are ignored (see the module docstring), so not checked.
        if key in PHYSICAL_RANGES and (key in used or not key.startswith("indenter.")):
            _check_range(f"{contact_id}.{key}", value)

    def section(name: str) -> dict[str, Any]:
        return {k.split(".", 1)[1]: v for k, v in given.items() if k.startswith(f"{name}.")}

    indenter = section("indenter")
    if "shape" not in indenter:
        raise ConfigError(f"{contact_id}.indenter.shape is required (one of {', '.join(_SHAPE_KEYS)})")
    shape = indenter["shape"]
    if shape not in _SHAPE_KEYS:
        raise ConfigError(
            f"{contact_id}.indenter.shape must be one of {', '.join(_SHAPE_KEYS)} (got {shape!r})"
        )
    for name in _SHAPE_KEYS[shape]:
        if name not in indenter:
            raise ConfigError(f"{contact_id}.indenter.{name} is required for shape {shape!r}")
    indenter_config = IndenterConfig(shape=shape, **{name: indenter[name] for name in _SHAPE_KEYS[shape]})

    material = section("material")
    kelvin = [name for name in _KELVIN_KEYS if name in material]
    prony = [name for name in _PRONY_KEYS if name in material]
    if kelvin and prony:
        raise ConfigError(
            f"{contact_id}.material: give either the Kelvin chain ({', '.join(_KELVIN_KEYS)}) or the Prony "
            f"series ({', '.join(_PRONY_KEYS)}), not both (got {contact_id}.material.{kelvin[0]} and "
            f"{contact_id}.material.{prony[0]})"
        )
    poisson = material.get("poisson_ratio", 0.5)
    try:
        if prony:
            if "prony_long_term_modulus" not in material:
                raise ConfigError("material.prony_long_term_modulus is required with a Prony series")
            element = prony_to_creep(
                material["prony_long_term_modulus"],
                material.get("prony_moduli", ()),
                material.get("prony_times", ()),
                poisson_ratio=poisson,
            )
        else:
            if "glass_shear_modulus" not in material:
                raise ConfigError("material.glass_shear_modulus is required (or give a Prony series)")
            element = CreepElement(
                glass_shear_modulus=material["glass_shear_modulus"],
                kelvin_shear_moduli=np.array(material.get("kelvin_shear_moduli", ()), dtype=np.float64),
                kelvin_viscosities=np.array(material.get("kelvin_viscosities", ()), dtype=np.float64),
                poisson_ratio=poisson,
            )
        make_profile(indenter_config)
        adhesion = AdhesionConfig(**section("adhesion"))
        if adhesion.work_of_adhesion < 0.0:
            raise InputError(f"adhesion.work_of_adhesion must be >= 0 (got {adhesion.work_of_adhesion!r})")
        if adhesion.interaction_range <= 0.0:
            raise InputError(f"adhesion.interaction_range must be > 0 (got {adhesion.interaction_range!r})")
        numerics = NumericsConfig(**section("numerics"))
        resolve_numerics(replace(numerics, scene=SceneHint.of(indenter_config, element)))
    except (InputError, ConfigError) as error:
        raise _prefixed(contact_id, error) from None
    material_config = MaterialConfig(
        glass_shear_modulus=element.glass_shear_modulus,
        kelvin_shear_moduli=tuple(float(v) for v in element.kelvin_shear_moduli),
        kelvin_viscosities=tuple(float(v) for v in element.kelvin_viscosities),
        poisson_ratio=element.poisson_ratio,
        prony_long_term_modulus=material.get("prony_long_term_modulus", 0.0),
        prony_moduli=material.get("prony_moduli", ()),
        prony_times=material.get("prony_times", ()),
    )
    return ContactConfig(
        id=contact_id,
        indenter=indenter_config,
        material=material_config,
        adhesion=adhesion,
        numerics=numerics,
    )


#: The node's hold-timer rate, Hz: the range its ROS parameter descriptor declares (ros/parameters.py);
#: a scene file is checked against the same (0.8.0 took any rate > 0 from a file: 1e9 Hz would
#: spin a timer every nanosecond).
PUBLISH_RATE_MIN, PUBLISH_RATE_MAX = 0.1, 10_000.0


def _build_node(given: dict[str, Any]) -> NodeConfig:
    node = NodeConfig(**{key.replace(".", "_"): value for key, value in given.items()})
    checks = [
        (
            "publish_rate",
            PUBLISH_RATE_MIN <= node.publish_rate <= PUBLISH_RATE_MAX,
            f"in [{PUBLISH_RATE_MIN:g}, {PUBLISH_RATE_MAX:g}] Hz",
        ),
        ("log.chunk_size", node.log_chunk_size > 0, "> 0"),
        ("log.max_bytes", node.log_max_bytes >= 0, ">= 0"),
        ("log.max_duration", 0.0 <= node.log_max_duration <= DURATION_MAX_S, f"in [0, {DURATION_MAX_S:g}] s"),
        ("log.queue_size", node.log_queue_size > 0, "> 0"),
        (
            "command.max_future_s",
            0.0 <= node.command_max_future_s <= DURATION_MAX_S,
            f"in [0, {DURATION_MAX_S:g}] s",
        ),
        (
            "command.queue_depth",
            1 <= node.command_queue_depth <= COMMAND_QUEUE_DEPTH_MAX,
            f"in 1..{COMMAND_QUEUE_DEPTH_MAX}",
        ),
    ]
    for key, ok, bound in checks:
        if not ok:
            raise ConfigError(f"{key} must be {bound} (got {getattr(node, key.replace('.', '_'))!r})")
    if node.log_enabled and not node.log_path:
        raise ConfigError("log.path must be set when log.enabled is true")
    return node


class _RosYamlLoader(yaml.SafeLoader):
    """PyYAML's safe loader, reading floats the way ROS 2 params files do: YAML 1.1 makes
    ``1.0e6`` (no exponent sign) and ``1e-9`` strings, the ROS parser reads them as doubles."""


_RosYamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"^[-+]?(?:[0-9][0-9_]*\.[0-9_]*|\.[0-9_]+|[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)$|^[-+]?(?:[0-9][0-9_]*\.[0-9_]*|\.[0-9_]+)$|^[-+]?\.(?:inf|Inf|INF)$|^\.(?:nan|NaN|NAN)$"
    ),
    list("-+0123456789."),
)


def read_yaml(path: str | Path, *, what: str = "scene file") -> Any:
    """The YAML document in ``path``, read as ROS 2 reads params files; ConfigError (one line,
    naming the file) when it cannot be read or parsed. A byte-order mark is accepted."""
    file = Path(path)
    try:
        text = file.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else str(error)
        raise ConfigError(f"cannot read {what} {str(file)!r}: {reason}") from None
    try:
        return yaml.load(text, Loader=_RosYamlLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as error:
        detail = " ".join(str(error).split())
        raise ConfigError(f"{what} {str(file)!r} is not valid YAML: {detail}") from None


@dataclass(frozen=True, kw_only=True)
class SceneConfig:
    """A validated scene: the contacts (in the order of ``contacts``) and the node settings."""

    contacts: tuple[ContactConfig, ...]
    node: NodeConfig = NodeConfig()

    @classmethod
    def from_parameters(cls, flat: Mapping[str, Any]) -> SceneConfig:
        """From flat dotted parameters (``{"contacts": [...], "finger.indenter.shape": ...}``).
        Raises :class:`ConfigError` naming the first bad key."""
        if "contacts" not in flat:
            raise ConfigError("contacts is required: the list of contact ids, e.g. contacts: [finger]")
        ids = _coerce("contacts", "strings", flat["contacts"])
        if not ids:
            raise ConfigError("contacts must list at least one contact id")
        for index, contact_id in enumerate(ids):
            if not _ID_PATTERN.match(contact_id) or "__" in contact_id:
                raise ConfigError(
                    f"contacts[{index}] must be a ROS name token: a letter, then letters, digits or "
                    f"single underscores (got {contact_id!r})"
                )
            if contact_id in _NODE_ROOTS:
                raise ConfigError(f"contacts[{index}] {contact_id!r} is reserved for a node-level parameter")
        duplicates = sorted({c for c in ids if ids.count(c) > 1})
        if duplicates:
            raise ConfigError(f"contacts lists {duplicates[0]!r} more than once")
        valid = ["contacts", *NODE_KEYS, *(f"{c}.{key}" for c in ids for key in CONTACT_KEYS)]
        per_contact: dict[str, dict[str, Any]] = {c: {} for c in ids}
        node: dict[str, Any] = {}
        for key, value in flat.items():
            if key == "contacts":
                continue
            if key in NODE_KEYS:
                node[key] = _coerce(key, NODE_KEYS[key], value)
                continue
            head, _, leaf = key.partition(".")
            if head in per_contact and leaf in CONTACT_KEYS:
                per_contact[head][leaf] = _coerce(key, CONTACT_KEYS[leaf], value)
            elif leaf in CONTACT_KEYS:
                raise ConfigError(
                    f"{key}: contact {head!r} is not listed in contacts ({', '.join(ids)}); add it there or "
                    "remove its section"
                )
            else:
                raise _unknown_key(key, valid)
        contacts = tuple(_build_contact(c, per_contact[c]) for c in ids)
        return cls(contacts=contacts, node=_build_node(node))

    @classmethod
    def from_dict(cls, mapping: Mapping[str, Any]) -> SceneConfig:
        """From a ROS params mapping ``{node: {"ros__parameters": {...}}}``, the bare
        ``ros__parameters`` mapping, or the flat dotted form."""
        return cls.from_parameters(_unwrap(mapping))

    @classmethod
    def from_yaml(cls, path: str | Path) -> SceneConfig:
        """From a ROS 2 parameters YAML file (or a bare/flat mapping in YAML)."""
        file = Path(path)
        data = read_yaml(file)
        if not isinstance(data, Mapping):
            raise ConfigError(f"scene file {str(file)!r} must hold a mapping of parameters")
        return cls.from_dict(data)

    def to_parameters(self) -> dict[str, Any]:
        """Flat dotted parameters of ROS-parameter-compatible types (float, int, bool, str,
        list of float, list of str); lists may be empty (K = 0: declare them as DOUBLE_ARRAY).
        Only the keys of each contact's indenter shape and material form are given."""
        flat: dict[str, Any] = {"contacts": [c.id for c in self.contacts]}
        for contact in self.contacts:
            prefix = f"{contact.id}."
            flat[f"{prefix}indenter.shape"] = contact.indenter.shape
            for name in _SHAPE_KEYS[contact.indenter.shape]:
                flat[f"{prefix}indenter.{name}"] = _plain(getattr(contact.indenter, name))
            material = contact.material
            for name in (_PRONY_KEYS if material.given_as_prony else _KELVIN_KEYS) + ("poisson_ratio",):
                flat[f"{prefix}material.{name}"] = _plain(getattr(material, name))
            for section in ("adhesion", "numerics"):
                for item in _schema_fields(_SECTIONS[section]):
                    flat[f"{prefix}{section}.{item.name}"] = _plain(
                        getattr(getattr(contact, section), item.name)
                    )
        for key in NODE_KEYS:
            flat[key] = getattr(self.node, key.replace(".", "_"))
        return flat

    def to_dict(self) -> dict[str, Any]:
        """Nested ROS params mapping ``{"/**": {"ros__parameters": {...}}}`` (plain Python
        types, ready for ``yaml.safe_dump``); ``from_dict(to_dict())`` gives back this scene."""
        nested: dict[str, Any] = {}
        for key, value in self.to_parameters().items():
            *parents, leaf = key.split(".")
            target = nested
            for parent in parents:
                target = target.setdefault(parent, {})
            target[leaf] = value
        return {"/**": {"ros__parameters": nested}}

    def contact(self, contact_id: str) -> ContactConfig:
        """The contact with this id (ConfigError listing the ids if there is none)."""
        for contact in self.contacts:
            if contact.id == contact_id:
                return contact
        raise ConfigError(f"no contact {contact_id!r} in the scene (contacts: {', '.join(self.ids)})")

    @property
    def ids(self) -> tuple[str, ...]:
        """Contact ids in order."""
        return tuple(c.id for c in self.contacts)


def _plain(value: Any) -> Any:
    return [float(v) for v in value] if isinstance(value, tuple) else value


def default_scene_path() -> Path:
    """Path of the built-in scene ``config/default.yaml``: the source tree first, then
    ``sys.prefix/share/viscoadh_ros/config``, then the ament index (if importable)."""
    candidates = [
        Path(__file__).resolve().parents[2] / "config" / "default.yaml",
        Path(sys.prefix) / "share" / "viscoadh_ros" / "config" / "default.yaml",
    ]
    try:
        from ament_index_python.packages import get_package_share_directory

        candidates.append(Path(get_package_share_directory("viscoadh_ros")) / "config" / "default.yaml")
    except Exception:  # noqa: BLE001 - not installed, or the package is not in the index
        pass
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise ConfigError(f"built-in scene default.yaml not found (looked in {', '.join(map(str, candidates))})")


def load_default_scene() -> SceneConfig:
    """The built-in scene (:func:`default_scene_path`)."""
    return SceneConfig.from_yaml(default_scene_path())
