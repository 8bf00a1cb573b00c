"""The scene schema and loader: forms, round trips, exact Prony conversion, errors naming the key."""

import array
import copy
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from viscoadh_ros.core.config import (
    CONTACT_KEYS,
    NODE_KEYS,
    PHYSICAL_RANGES,
    SceneConfig,
    _check_range,
    default_scene_path,
    load_default_scene,
    range_text,
)
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.core.rheology import prony_to_creep

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "config" / "examples").glob("*.yaml"))

BARE = {
    "contacts": ["finger"],
    "finger": {
        "indenter": {"shape": "sphere", "radius": 2e-3},
        "material": {
            "glass_shear_modulus": 1e6,
            "kelvin_shear_moduli": [1e4, 3e5],
            "kelvin_viscosities": [1e3, 30.0],
        },
        "adhesion": {"work_of_adhesion": 0.05},
    },
    "log": {"enabled": True, "path": "/tmp/run.mcap"},
}


def scene_with(**changes) -> dict:
    """BARE with dotted keys set (value None deletes the key)."""
    scene = copy.deepcopy(BARE)
    for dotted, value in changes.items():
        *parents, leaf = dotted.split("__")
        target = scene
        for parent in parents:
            target = target.setdefault(parent, {})
        if value is None:
            del target[leaf]
        else:
            target[leaf] = value
    return scene


def test_default_scene_loads_and_round_trips(tmp_path):
    assert default_scene_path().name == "default.yaml"
    scene = load_default_scene()
    assert scene.ids == ("finger",)
    assert SceneConfig.from_dict(scene.to_dict()) == scene
    assert SceneConfig.from_parameters(scene.to_parameters()) == scene
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene.to_dict()), encoding="utf-8")
    assert SceneConfig.from_yaml(path) == scene


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_examples_load_and_round_trip(path):
    scene = SceneConfig.from_yaml(path)
    assert SceneConfig.from_dict(scene.to_dict()) == scene, path.name


def test_three_forms_give_the_same_scene():
    bare = SceneConfig.from_dict(BARE)
    wrapped = SceneConfig.from_dict({"/**": {"ros__parameters": copy.deepcopy(BARE)}})
    flat = SceneConfig.from_parameters(bare.to_parameters())
    assert bare == wrapped == flat
    assert bare.node.log_enabled and bare.node.log_path == "/tmp/run.mcap"
    contact = bare.contact("finger")
    assert contact.material.kelvin_viscosities == (1e3, 30.0)
    assert contact.adhesion.interaction_range == 1e-9  # default
    assert contact.numerics.preset == "balanced" and contact.numerics.model == "auto"


def test_to_parameters_types_are_ros_compatible():
    flat = SceneConfig.from_dict(scene_with(finger__material={"glass_shear_modulus": 1e6})).to_parameters()
    assert (
        flat["finger.material.kelvin_shear_moduli"] == []
    )  # K = 0: empty list, declared DOUBLE_ARRAY by the node
    for key, value in flat.items():
        assert isinstance(value, (bool, int, float, str, list)), key
        if isinstance(value, list) and key != "contacts":
            assert all(type(v) is float for v in value), key
    assert set(flat) <= {"contacts", *NODE_KEYS} | {f"finger.{k}" for k in CONTACT_KEYS}


def test_rclpy_value_types_are_accepted():
    """rclpy hands DOUBLE_ARRAY values as array.array and an untyped [] as a byte array."""
    flat = SceneConfig.from_dict(BARE).to_parameters()
    flat["finger.material.kelvin_shear_moduli"] = array.array("d", [1e4, 3e5])
    flat["finger.material.kelvin_viscosities"] = np.array([1e3, 30.0])
    assert SceneConfig.from_parameters(flat) == SceneConfig.from_dict(BARE)
    flat["finger.material.kelvin_shear_moduli"] = b""
    flat["finger.material.kelvin_viscosities"] = []
    assert SceneConfig.from_parameters(flat).contact("finger").material.kelvin_shear_moduli == ()


def test_yaml_floats_read_like_ros(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(
        "contacts: [c]\nc:\n  indenter: {shape: sphere, radius: 2e-3}\n"
        "  material: {glass_shear_modulus: 1.0e6}\n",
        encoding="utf-8",
    )
    contact = SceneConfig.from_yaml(path).contact("c")
    assert contact.indenter.radius == 2e-3 and contact.material.glass_shear_modulus == 1e6


def test_prony_material_is_converted_exactly_and_keeps_its_form():
    scene = SceneConfig.from_dict(
        scene_with(
            finger__material={
                "prony_long_term_modulus": 2e4,
                "prony_moduli": [5e5, 1e5],
                "prony_times": [1e-3, 2.0],
            }
        )
    )
    material = scene.contact("finger").material
    element = prony_to_creep(2e4, [5e5, 1e5], [1e-3, 2.0])
    assert material.given_as_prony
    np.testing.assert_allclose(material.glass_shear_modulus, 6.2e5, rtol=1e-14)
    np.testing.assert_allclose(material.kelvin_shear_moduli, element.kelvin_shear_moduli, rtol=1e-14)
    np.testing.assert_allclose(material.kelvin_viscosities, element.kelvin_viscosities, rtol=1e-14)
    flat = scene.to_parameters()
    assert "finger.material.prony_times" in flat and "finger.material.kelvin_shear_moduli" not in flat
    assert SceneConfig.from_parameters(flat) == scene


def test_keys_of_other_shapes_are_ignored_and_dropped():
    scene = SceneConfig.from_dict(
        scene_with(finger__indenter={"shape": "cone", "half_angle": 1.2, "radius": 5e-3})
    )
    indenter = scene.contact("finger").indenter
    assert indenter.half_angle == 1.2 and indenter.radius == 0.0
    assert "finger.indenter.radius" not in scene.to_parameters()


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        (
            {"finger__material__kelvin_viscosities": [1e3, -3.0]},
            r"^finger\.material\.kelvin_viscosities\[1\] must be in \[1e-06, 1e\+15\] Pa s \(got -3\)",
        ),
        (
            {"finger__material__kelvin_viscosities": [1e3]},
            r"finger\.material\.kelvin_shear_moduli and .* same length",
        ),
        (
            {"finger__material__glass_shear_modulus": float("nan")},
            r"^finger\.material\.glass_shear_modulus must be finite",
        ),
        (
            {"finger__material__glass_shear_modulus": "1e6"},
            r"^finger\.material\.glass_shear_modulus must be a number",
        ),
        (
            {"finger__material__glass_shear_modulus": None},
            r"^finger\.material\.glass_shear_modulus is required",
        ),
        (
            {"finger__material__poisson_ratio": 0.6},
            r"^finger\.material\.poisson_ratio must be in \[0, 0\.5\]",
        ),
        (
            {"finger__material__prony_times": [1.0]},
            r"finger\.material: give either the Kelvin chain .* not both",
        ),
        (
            {"finger__material__glass_shear_modulu": 1e6},
            r"did you mean 'finger\.material\.glass_shear_modulus'",
        ),
        ({"finger__indenter__radius": None}, r"^finger\.indenter\.radius is required for shape 'sphere'"),
        (
            {"finger__indenter": {"shape": "cone", "half_angle": 2.0}},
            r"^finger\.indenter\.half_angle must be in \[0\.001, 1\.569796\] rad \(got 2\)",
        ),
        ({"finger__indenter": {"shape": "cube"}}, r"^finger\.indenter\.shape must be one of"),
        (
            {
                "finger__indenter": {
                    "shape": "table",
                    "table_radius": [0.0, 1e-3, 2e-3],
                    "table_height": [0.0, 2e-6, 1e-6],
                }
            },
            r"^finger\.indenter\.table_height must be non-decreasing",
        ),
        (
            {"finger__adhesion__work_of_adhesion": -0.1},
            r"^finger\.adhesion\.work_of_adhesion must be in \[0, 1000\]",
        ),
        (
            {"finger__adhesion__interaction_range": 0.0},
            r"^finger\.adhesion\.interaction_range must be in \[1e-12,",
        ),
        ({"finger__numerics": {"preset": "quick"}}, r"^finger\.numerics\.preset must be one of"),
        ({"finger__numerics": {"elements": 2.5}}, r"^finger\.numerics\.elements must be an integer"),
        ({"contacts": []}, r"contacts must list at least one"),
        ({"contacts": ["finger", "finger"]}, r"contacts lists 'finger' more than once"),
        ({"contacts": ["finger", "2nd"]}, r"contacts\[1\] must be a ROS name token"),
        ({"contacts": ["finger", "a__b"]}, r"contacts\[1\] must be a ROS name token"),
        ({"contacts": ["finger", "log"]}, r"contacts\[1\] 'log' is reserved"),
        ({"contacts": "finger"}, r"^contacts must be a list"),
        ({"contacts": None}, r"^contacts is required"),
        (
            {"thumb": {"indenter": {"shape": "sphere"}}},
            r"^thumb\.indenter\.shape: contact 'thumb' is not listed in contacts",
        ),
        ({"publish_rate": 0.0}, r"^publish_rate must be in \[0.1, 10000\] Hz"),
        # The ROS descriptor's range, now also a scene file's (0.8.0 took 1e9 Hz from a file).
        ({"publish_rate": 1e9}, r"^publish_rate must be in \[0.1, 10000\] Hz \(got 1000000000.0\)"),
        ({"publish_rte": 10.0}, r"unknown parameter 'publish_rte' \(did you mean 'publish_rate'\?\)"),
        ({"markers": {"enabled": "yes"}}, r"^markers\.enabled must be true or false"),
        ({"log": {"enabled": True}}, r"^log\.path must be set"),
        ({"log": {"queue_size": 0}}, r"^log\.queue_size must be > 0"),
    ],
)
def test_bad_scenes_name_the_key(changes, match):
    with pytest.raises(ConfigError, match=match):
        SceneConfig.from_dict(scene_with(**changes))


@pytest.mark.parametrize(
    "changes, match",
    [
        (
            {"finger__material__glass_shear_modulus": 1e308},
            r"glass_shear_modulus must be in \[1, 1e\+12\] Pa \(got 1e\+308\)",
        ),
        (
            {"finger__material__glass_shear_modulus": 1e-300},
            r"glass_shear_modulus must be in \[1, 1e\+12\] Pa \(got 1e-300\)",
        ),
        (
            {"finger__material__kelvin_shear_moduli": [1e4, 1e-200]},
            r"kelvin_shear_moduli\[1\] must be in \[1,",
        ),
        ({"finger__material__kelvin_viscosities": [1e300, 30.0]}, r"kelvin_viscosities\[0\] must be in"),
        ({"finger__adhesion__work_of_adhesion": 1e300}, r"work_of_adhesion must be in \[0, 1000\] J/m\^2"),
        (
            {"finger__adhesion__interaction_range": 1e-300},
            r"interaction_range must be in \[1e-12, 0\.001\] m",
        ),
        ({"finger__indenter__radius": 1e-300}, r"indenter\.radius must be in \[1e-09, 1000\] m"),
        ({"finger__indenter__radius": 1e300}, r"indenter\.radius must be in"),
        (
            {"finger__indenter": {"shape": "power_law", "coefficient": 1.0, "exponent": 1e-300}},
            r"exponent must be in \[0\.1, 10\]",
        ),
        ({"finger__indenter": {"shape": "cone", "half_angle": 1e-300}}, r"half_angle must be in \[0\.001,"),
        (
            {
                "finger__material": {
                    "prony_long_term_modulus": 1e5,
                    "prony_moduli": [1e5],
                    "prony_times": [1e300],
                }
            },
            r"prony_times\[0\] must be in \[1e-09, 1e\+09\] s",
        ),
    ],
    ids=[
        "G0-huge",
        "G0-tiny",
        "G1-tiny",
        "eta-huge",
        "w-huge",
        "h-tiny",
        "R-tiny",
        "R-huge",
        "n-tiny",
        "cone-flat",
        "tau-huge",
    ],
)
def test_numbers_outside_the_physical_range_are_refused_with_the_range(changes, match):
    """Issue 11: G0 = 1e308 was refused naming an internal field, G0 = 1e-300 accepted (a
    contact radius of 1e98 m). Every indenter/material/adhesion number has a documented range."""
    with pytest.raises(ConfigError, match=match):
        SceneConfig.from_dict(scene_with(**changes))


def test_every_physical_range_is_documented():
    text = (Path(__file__).resolve().parents[1] / "docs" / "configuration.md").read_text()
    for key in PHYSICAL_RANGES:
        row = next((line for line in text.splitlines() if line.startswith(f"| `{key.split('.')[1]}` |")), "")
        assert range_text(key) in row, f"{key}: range {range_text(key)} not in {row!r}"


@pytest.mark.parametrize("key", sorted(PHYSICAL_RANGES))
def test_the_printed_bounds_of_every_range_are_accepted(key):
    """Outside tester: half_angle was refused at the upper bound its own error printed ('must
    be in [0.001, 1.5698] rad (got 1.5698)'; the bound is pi/2 - 0.001 = 1.5697963). Both
    bounds an error prints, and docs/configuration.md with it, pass the range check."""
    low, high, _ = PHYSICAL_RANGES[key]
    name = f"finger.{key}"
    for outside in (high * 2.0 + 1.0, low - abs(low) - 1.0):
        with pytest.raises(ConfigError, match=r"must be in \[") as refused:
            _check_range(name, outside)
        printed = re.search(r"must be in \[([^,]+), ([^\]]+)\]", str(refused.value))
        assert printed is not None and printed.group(0) == f"must be in {range_text(key)}"
        for bound in printed.groups():
            _check_range(name, float(bound))  # accepted: no ConfigError
            _check_range(name, (float(bound),))


def test_a_cone_at_the_printed_upper_half_angle_loads():
    """The tester's case end to end: the half-angle the refusal names as the upper bound loads,
    and a value just above the bound is refused with a number that is not the printed bound."""
    refusal = r"half_angle must be in \[0\.001, 1\.569796\] rad \(got 1\.5698\)"
    with pytest.raises(ConfigError, match=refusal):
        SceneConfig.from_dict(scene_with(finger__indenter={"shape": "cone", "half_angle": 1.5698}))
    scene = SceneConfig.from_dict(scene_with(finger__indenter={"shape": "cone", "half_angle": 1.569796}))
    assert scene.contact("finger").indenter.half_angle == 1.569796


def test_file_errors_are_config_errors(tmp_path):
    with pytest.raises(ConfigError, match="cannot read scene file"):
        SceneConfig.from_yaml(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("contacts: [a\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="not valid YAML"):
        SceneConfig.from_yaml(bad)
    bad.write_text("- 1\n- 2\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="must hold a mapping"):
        SceneConfig.from_yaml(bad)
    with pytest.raises(ConfigError, match=r"no contact 'thumb' in the scene \(contacts: finger\)"):
        SceneConfig.from_dict(BARE).contact("thumb")


def test_every_key_is_documented():
    text = (Path(__file__).resolve().parents[1] / "docs" / "configuration.md").read_text(encoding="utf-8")
    for key in ["contacts", *NODE_KEYS, *(k.split(".", 1)[1] for k in CONTACT_KEYS)]:
        assert f"| `{key}` |" in text, f"docs/configuration.md does not document {key}"
