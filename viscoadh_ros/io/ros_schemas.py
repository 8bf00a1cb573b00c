"""ROS 2 message types by name and their `ros2msg` schema text (for MCAP channels).

rosbag2 stores, per channel, the root `.msg` definition followed, for each type it depends
on (recursively, each once), by a line of 80 ``=``, ``MSG: pkg/Type`` and that definition.
The `.msg` files come from the installed interface packages: ``<prefix>/share/<pkg>/msg/``
for every prefix on ``AMENT_PREFIX_PATH``, ``sys.prefix`` (wheels in a venv, our own
`viscoadh_msgs` built into it) and the prefix the package's Python module lives under (a
colcon ``install/`` tree). Nothing here hard-codes a path.
"""

from __future__ import annotations

import functools
import importlib
import os
import re
import sys
from pathlib import Path
from typing import Any

from viscoadh_ros.core.errors import InputError

#: Built-in field types of the ROS 2 interface language (no dependency).
_PRIMITIVES = frozenset(
    {
        "bool",
        "byte",
        "char",
        "float32",
        "float64",
        "int8",
        "uint8",
        "int16",
        "uint16",
        "int32",
        "uint32",
        "int64",
        "uint64",
        "string",
        "wstring",
    }
)
_SEPARATOR = "=" * 80
_FIELD_TYPE = re.compile(r"^([A-Za-z][\w/]*)")


def split_type_name(type_name: str) -> tuple[str, str]:
    """``"pkg/msg/Type"`` (or ``"pkg/Type"``) -> ``("pkg", "Type")``; InputError otherwise."""
    parts = type_name.strip("/").split("/")
    if len(parts) == 3 and parts[1] == "msg":
        return parts[0], parts[2]
    if len(parts) == 2:
        return parts[0], parts[1]
    raise InputError(f"message type {type_name!r} is not of the form pkg/msg/Type")


def type_name_of(msg: Any) -> str:
    """The ``pkg/msg/Type`` name of a generated ROS 2 message instance or class."""
    cls = msg if isinstance(msg, type) else type(msg)
    package = cls.__module__.split(".")[0]
    return f"{package}/msg/{cls.__name__}"


def message_class(type_name: str) -> type:
    """The generated Python class of ``pkg/msg/Type``; InputError if it is not installed."""
    package, name = split_type_name(type_name)
    try:
        module = importlib.import_module(f"{package}.msg")
        return getattr(module, name)
    except (ImportError, AttributeError):
        raise InputError(
            f"message type {package}/msg/{name} is not installed (no Python module {package}.msg.{name})"
        ) from None


def _prefixes(package: str) -> list[Path]:
    """Install prefixes that may hold ``share/<package>``, most specific first."""
    prefixes = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    prefixes.append(Path(sys.prefix))
    try:
        module_file = importlib.import_module(package).__file__
    except ImportError:
        module_file = None
    if module_file:
        # <prefix>/lib/pythonX.Y/site-packages/<package>/__init__.py -> walk up to <prefix>
        prefixes.extend(Path(module_file).resolve().parents)
    return prefixes


@functools.cache
def msg_file(package: str, name: str) -> Path:
    """Path of the installed ``<package>/msg/<name>.msg``; InputError if none is found."""
    for prefix in _prefixes(package):
        candidate = prefix / "share" / package / "msg" / f"{name}.msg"
        if candidate.is_file():
            return candidate
    raise InputError(
        f"no definition file {package}/msg/{name}.msg under AMENT_PREFIX_PATH, {sys.prefix} "
        f"or the {package} Python package's prefix"
    )


def _dependencies(package: str, text: str) -> list[tuple[str, str]]:
    """Non-primitive field types of a `.msg` text, in order, as (package, Type)."""
    deps: list[tuple[str, str]] = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = _FIELD_TYPE.match(line)
        if match is None:
            continue
        field_type = match.group(1)
        if field_type in _PRIMITIVES:
            continue
        if "/" in field_type:
            deps.append(split_type_name(field_type))
        elif field_type == "Header":
            deps.append(("std_msgs", "Header"))
        else:
            deps.append((package, field_type))
    return deps


@functools.cache
def schema_text(type_name: str) -> str:
    """Full ``ros2msg`` schema text of ``pkg/msg/Type`` with every dependency appended once."""
    package, name = split_type_name(type_name)
    root = msg_file(package, name).read_text(encoding="utf-8")
    parts = [root]
    seen: set[tuple[str, str]] = set()

    def append(dep_package: str, text: str) -> None:
        for dep in _dependencies(dep_package, text):
            if dep in seen:
                continue
            seen.add(dep)
            dep_text = msg_file(*dep).read_text(encoding="utf-8")
            parts.append(f"{_SEPARATOR}\nMSG: {dep[0]}/{dep[1]}\n{dep_text}")
            append(dep[0], dep_text)

    append(package, root)
    return "\n".join(part.rstrip("\n") for part in parts) + "\n"
