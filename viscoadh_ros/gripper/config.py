"""The gripper cell file: an ordinary scene (the pad's contact) plus a ``gripper:`` section.

One YAML file holds both parts::

    /**:
      ros__parameters:          # the ordinary scene, loaded by core/config.py (SceneConfig)
        contacts: [pad]         # ONE contact: the pad; every pad of the gripper is a copy
        pad: {indenter: {shape: sphere, radius: ...}, material: {...}, adhesion: {...}}
    gripper:                    # the MuJoCo cell, loaded here (GripperConfig)
      timestep: 2.0e-4
      pads: {rows: 1, columns: 1, pitch: 0.025}
      arm: {mass: 0.2, stiffness: 2.0e4, damping: 200.0, start_height: 1.0e-3}
      part: {mass: 1.0e-3, size: [0.05, 0.05, 0.006]}
      fixture: {holding_force: 0.02, latch_stiffness: 50.0, latch_time: 0.05}

Every key of the ``gripper`` section, its unit and range is in docs/gripper.md; an unknown or
bad key raises one ``ConfigError`` naming it (``gripper.arm.stifness: unknown key (did you
mean 'stiffness'?)``). The pad contact must be a sphere (a soft hemispherical pad) so that a
pad maps onto the core's rigid-sphere-on-half-space model (see docs/gripper.md).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

from viscoadh_ros.core.config import ContactConfig, SceneConfig, read_yaml
from viscoadh_ros.core.errors import ConfigError

#: Top-level key of the cell section in a gripper file.
SECTION = "gripper"


@dataclass(frozen=True)
class PadsConfig:
    """The pad array under the arm: ``rows`` x ``columns`` pads, ``pitch`` m apart (centre to
    centre), centred on the arm axis."""

    rows: int = 1
    columns: int = 1
    pitch: float = 0.025


@dataclass(frozen=True)
class ArmConfig:
    """The arm: one vertical slide joint under a position servo, gravity compensated.

    mass: kg of the moving arm; stiffness: N/m servo gain kp; damping: N s/m servo gain kv;
    start_height: m of the pad tips above the part's top face at t = 0 (> 0: out of touch).
    """

    mass: float = 0.2
    stiffness: float = 2.0e4
    damping: float = 200.0
    start_height: float = 1.0e-3


@dataclass(frozen=True)
class PartConfig:
    """The part: a rigid box resting on the table under the gripper.

    mass: kg; size: full edge lengths (x, y, z), m.
    """

    mass: float = 1.0e-3
    size: tuple[float, float, float] = (0.05, 0.05, 0.006)


@dataclass(frozen=True)
class FixtureConfig:
    """The place fixture: a latch that comes down on the part's two x-edges and holds it.

    holding_force: N the latch presses down with at most (its actuator's force limit: pulled
    up harder than that plus the part's weight, the part lifts out); latch_stiffness: N/m of
    the latch servo (it is driven 10 holding-force lengths below the rim, so it saturates at
    the holding force once on the part); latch_time: s the latch takes to close.
    """

    holding_force: float = 0.02
    latch_stiffness: float = 50.0
    latch_time: float = 0.05


@dataclass(frozen=True)
class GripperConfig:
    """The MuJoCo side of the cell. timestep: s, MuJoCo's physics step; each pad's contact is
    stepped once per physics step (see docs/gripper.md on the choice)."""

    timestep: float = 2.0e-4
    pads: PadsConfig = PadsConfig()
    arm: ArmConfig = ArmConfig()
    part: PartConfig = PartConfig()
    fixture: FixtureConfig = FixtureConfig()

    @property
    def pad_count(self) -> int:
        return self.pads.rows * self.pads.columns

    def with_part_mass(self, mass: float) -> GripperConfig:
        """A copy with another part mass, kg (> 0)."""
        _positive("gripper.part.mass", mass)
        return replace(self, part=replace(self.part, mass=float(mass)))

    def with_pads(self, rows: int, columns: int) -> GripperConfig:
        """A copy with another pad array (the part grows to carry it, see `fit_part`)."""
        return fit_part(replace(self, pads=replace(self.pads, rows=int(rows), columns=int(columns))))


@dataclass(frozen=True)
class Cell:
    """A loaded gripper file: the pad's contact (a ContactConfig with a sphere indenter) and
    the MuJoCo cell."""

    pad: ContactConfig
    gripper: GripperConfig

    def pad_scene(self) -> SceneConfig:
        """The scene the node runs in the node-in-the-loop path: one contact per pad,
        ``pad_0`` .. ``pad_<n-1>``, each a copy of the pad contact."""
        parameters = SceneConfig(contacts=(self.pad,)).to_parameters()
        prefix = f"{self.pad.id}."
        per_pad = {k[len(prefix) :]: v for k, v in parameters.items() if k.startswith(prefix)}
        flat: dict[str, Any] = {
            k: v for k, v in parameters.items() if k != "contacts" and not k.startswith(prefix)
        }
        ids = pad_ids(self.gripper.pad_count)
        flat["contacts"] = list(ids)
        for pad_id in ids:
            flat.update({f"{pad_id}.{k}": v for k, v in per_pad.items()})
        return SceneConfig.from_parameters(flat)


def pad_ids(count: int) -> tuple[str, ...]:
    """Contact ids of the pads, in pad order."""
    return tuple(f"pad_{i}" for i in range(count))


_SECTIONS: dict[str, type] = {
    "pads": PadsConfig,
    "arm": ArmConfig,
    "part": PartConfig,
    "fixture": FixtureConfig,
}
_INTEGER_KEYS = {"pads.rows", "pads.columns"}


def _positive(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{key} must be a number (got {value!r})")
    number = float(value)
    if not math.isfinite(number) or number <= 0.0:
        raise ConfigError(f"{key} must be a finite number > 0 (got {value!r})")
    return number


def _unknown(key: str, given: str, valid: list[str]) -> ConfigError:
    close = difflib.get_close_matches(given, valid, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else f" (known: {', '.join(valid)})"
    return ConfigError(f"{key}: unknown key{hint}")


def _value(key: str, name: str, value: Any) -> Any:
    """One validated leaf value of the gripper section."""
    if name in _INTEGER_KEYS:
        if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 8:
            raise ConfigError(f"{key} must be an integer from 1 to 8 (got {value!r})")
        return value
    if name == "part.size":
        if not isinstance(value, (list, tuple)) or len(value) != 3:
            raise ConfigError(f"{key} must be a list of 3 edge lengths in m (got {value!r})")
        return tuple(_positive(f"{key}[{i}]", v) for i, v in enumerate(value))
    return _positive(key, value)


def gripper_from_dict(mapping: Any) -> GripperConfig:
    """A validated GripperConfig from the ``gripper`` section (a mapping; missing keys keep
    their defaults). ConfigError naming the first bad key."""
    if mapping is None:
        mapping = {}
    if not isinstance(mapping, Mapping):
        raise ConfigError(f"{SECTION} must be a mapping (got {type(mapping).__name__})")
    top = {f.name for f in fields(GripperConfig)}
    built: dict[str, Any] = {}
    for name, value in mapping.items():
        key = f"{SECTION}.{name}"
        if name not in top:
            raise _unknown(key, str(name), sorted(top))
        if name == "timestep":
            built[name] = _positive(key, value)
            continue
        if not isinstance(value, Mapping):
            raise ConfigError(f"{key} must be a mapping (got {value!r})")
        section_type = _SECTIONS[name]
        valid = [f.name for f in fields(section_type)]
        leaves = {}
        for leaf, leaf_value in value.items():
            if leaf not in valid:
                raise _unknown(f"{key}.{leaf}", str(leaf), valid)
            leaves[leaf] = _value(f"{key}.{leaf}", f"{name}.{leaf}", leaf_value)
        built[name] = section_type(**leaves)
    config = GripperConfig(**built)
    if config.timestep > 5.0e-3:
        raise ConfigError(f"{SECTION}.timestep must be <= 5e-3 s (got {config.timestep!r})")
    return check_layout(config)


def fit_part(config: GripperConfig) -> GripperConfig:
    """A copy whose part is at least large enough in x and y for the pad array and the
    latch bars (see `check_layout`)."""
    need_x, need_y = _needed_footprint(config)
    sx, sy, sz = config.part.size
    return replace(config, part=replace(config.part, size=(max(sx, need_x), max(sy, need_y), sz)))


#: Width of each latch bar over the part's x-edges, m, and the free margin around a pad, m.
LATCH_WIDTH = 0.006
PAD_MARGIN = 0.004


def _needed_footprint(config: GripperConfig) -> tuple[float, float]:
    span_x = (config.pads.columns - 1) * config.pads.pitch
    span_y = (config.pads.rows - 1) * config.pads.pitch
    return span_x + 2.0 * (PAD_MARGIN + LATCH_WIDTH), span_y + 2.0 * PAD_MARGIN


def check_layout(config: GripperConfig) -> GripperConfig:
    """ConfigError unless every pad lands on the part's top face clear of the latch bars."""
    need_x, need_y = _needed_footprint(config)
    sx, sy, _ = config.part.size
    if sx < need_x - 1e-12 or sy < need_y - 1e-12:
        raise ConfigError(
            f"{SECTION}.part.size: the part ({sx:g} x {sy:g} m) is too small for "
            f"{config.pads.rows} x {config.pads.columns} pads at pitch {config.pads.pitch:g} m "
            f"and the latch bars (needs at least {need_x:g} x {need_y:g} m)"
        )
    return config


def load_cell(path: str | Path) -> Cell:
    """Load a gripper file: its scene (exactly one contact, a sphere: the pad) through
    core/config.py, its ``gripper`` section here. ConfigError naming the bad key.

    The file is read by the scene loader (`read_yaml`, as ROS 2 reads params files), so
    ``3.0e5`` and ``2e-4`` are numbers here as in every other scene (0.10.0's outside tester:
    plain ``yaml.safe_load`` read them as strings and refused them as "not a number")."""
    file = Path(path)
    return cell_from_dict(read_yaml(file, what="gripper file"), source=f"gripper file {str(file)!r}")


def cell_from_dict(data: Any, *, source: str = "the gripper mapping") -> Cell:
    """The Cell of a gripper file's mapping (see the module docstring); ``source`` names it
    in the error of a missing ``gripper`` section."""
    if not isinstance(data, Mapping):
        raise ConfigError("a gripper file must hold a mapping (the scene plus a 'gripper' section)")
    if SECTION not in data:
        # Checked before the scene: a plain scene (config/default.yaml) is a valid scene, so
        # without this it ran on every gripper default (or failed on a scene key instead).
        raise ConfigError(
            f"{source} has no '{SECTION}:' section: a gripper file is a scene with one pad "
            f"contact plus a '{SECTION}:' section (every key in it optional; '{SECTION}: {{}}' "
            "takes the defaults; see docs/gripper.md)"
        )
    scene_part = {k: v for k, v in data.items() if k != SECTION}
    scene = SceneConfig.from_dict(scene_part)
    if len(scene.contacts) != 1:
        raise ConfigError(
            f"contacts: a gripper file describes ONE pad contact (copied for every pad); got "
            f"{len(scene.contacts)} ({', '.join(scene.ids)})"
        )
    pad = scene.contacts[0]
    if pad.indenter.shape != "sphere":
        raise ConfigError(
            f"{pad.id}.indenter.shape must be 'sphere' for a gripper pad (a soft hemispherical "
            f"pad of that radius); got {pad.indenter.shape!r}"
        )
    return Cell(pad=pad, gripper=gripper_from_dict(data.get(SECTION)))


def default_cell_path() -> Path:
    """The built-in cell, config/gripper_cell.yaml (source tree, then the install prefix)."""
    from viscoadh_ros.core.config import default_scene_path

    return default_scene_path().with_name("gripper_cell.yaml")
