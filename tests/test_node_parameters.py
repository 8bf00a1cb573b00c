"""The node's parameters: scene loading through the one schema, descriptors, typing."""

from __future__ import annotations

from typing import Any

import pytest
from rcl_interfaces.msg import ParameterType
from rclpy.parameter import Parameter

from viscoadh_ros.core.config import CONTACT_KEYS, NODE_KEYS, SceneConfig, load_default_scene
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.ros import parameters


def test_no_overrides_load_the_default_scene() -> None:
    assert parameters.load_scene({}).to_parameters() == load_default_scene().to_parameters()


def test_node_level_override_applies_on_top_of_the_default_scene() -> None:
    scene = parameters.load_scene({"publish_rate": 200.0})
    expected = dict(load_default_scene().to_parameters(), publish_rate=200.0)
    assert scene.to_parameters() == expected


def test_unknown_key_is_an_error_naming_it() -> None:
    with pytest.raises(ConfigError, match="publish_rat"):
        parameters.load_scene({"publish_rat": 10.0})


@pytest.mark.parametrize("leaf", sorted(CONTACT_KEYS))
def test_every_contact_key_has_a_description(leaf: str) -> None:
    spec = parameters.spec_for(f"finger.{leaf}")
    assert spec is not None and spec.description, f"no descriptor text for {leaf}"


@pytest.mark.parametrize("name", ["contacts", *sorted(NODE_KEYS)])
def test_every_node_key_has_a_description(name: str) -> None:
    spec = parameters.spec_for(name)
    assert spec is not None and spec.description, f"no descriptor text for {name}"


@pytest.mark.parametrize(
    "name, value, expected",
    [
        ("finger.material.kelvin_shear_moduli", [], Parameter.Type.DOUBLE_ARRAY),
        ("finger.material.glass_shear_modulus", 1000000, Parameter.Type.DOUBLE),
        ("finger.numerics.elements", 64, Parameter.Type.INTEGER),
        ("contacts", ["finger"], Parameter.Type.STRING_ARRAY),
        ("markers.enabled", True, Parameter.Type.BOOL),
    ],
)
def test_parameters_take_the_schema_type(name: str, value: Any, expected: Any) -> None:
    assert parameters.ros_parameter(name, value).type_ == expected, name


def test_node_declares_the_whole_scene_with_descriptors(ros_context: Any) -> None:
    from viscoadh_ros.ros.node import ViscoadhNode

    overrides = [
        Parameter("contacts", value=["finger"]),
        Parameter("finger.indenter.shape", value="sphere"),
        Parameter("finger.indenter.radius", value=0.01),
        # An integer in a params file is a valid modulus: the schema makes it a double.
        Parameter("finger.material.glass_shear_modulus", value=1000000),
    ]
    node = ViscoadhNode(context=ros_context, parameter_overrides=overrides)
    try:
        expected = SceneConfig.from_parameters({p.name: p.value for p in overrides}).to_parameters()
        for name, value in expected.items():
            assert node.get_parameter(name).value == value, name
        modulus = node.describe_parameter("finger.material.glass_shear_modulus")
        assert modulus.type == ParameterType.PARAMETER_DOUBLE
        assert "Pa" in modulus.description and modulus.floating_point_range
        assert node.describe_parameter("contacts").read_only
        assert node.describe_parameter("log.enabled").read_only
        chain = node.describe_parameter("finger.material.kelvin_shear_moduli")
        assert chain.type == ParameterType.PARAMETER_DOUBLE_ARRAY
    finally:
        node.destroy_node()
