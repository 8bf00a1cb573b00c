"""Scene builders shared by the simulator tests, and `call_service` for the node tests.

Every test contact goes through the one scene loader (`SceneConfig.from_dict`), so the tests
exercise the same validation and defaults a user's YAML file does.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from viscoadh_ros.core.config import ContactConfig, SceneConfig


def one_contact(
    indenter: dict[str, Any],
    *,
    glass_shear_modulus: float = 1e6,
    kelvin: Sequence[float] = (),
    viscosities: Sequence[float] = (),
    work: float = 0.0,
    numerics: dict[str, Any] | None = None,
) -> ContactConfig:
    """The contact of a one-contact scene: `indenter` keys as in a scene file, the glass
    modulus (Pa), Kelvin moduli (Pa) and viscosities (Pa s) (none: elastic, K = 0), the work
    of adhesion (J/m^2) and `numerics` keys (none: the scene defaults)."""
    material: dict[str, Any] = {"glass_shear_modulus": glass_shear_modulus}
    if len(kelvin):
        material.update(kelvin_shear_moduli=list(kelvin), kelvin_viscosities=list(viscosities))
    section: dict[str, Any] = {
        "indenter": dict(indenter),
        "material": material,
        "adhesion": {"work_of_adhesion": work},
    }
    if numerics:
        section["numerics"] = dict(numerics)
    return SceneConfig.from_dict({"contacts": ["c"], "c": section}).contact("c")


#: The standard-solid finger most node, replay and fault tests use, as the flat parameters a node
#: is given: a 10 mm sphere on G0 = 1 MPa, G1 = 0.2 MPa, eta1 = 2000 Pa s (retardation 10 ms),
#: w = 0.05 J/m^2, `fast` numerics, forced onto the time-stepped model.
STANDARD_SOLID_FINGER: dict[str, Any] = {
    "contacts": ["finger"],
    "finger.indenter.shape": "sphere",
    "finger.indenter.radius": 0.01,
    "finger.material.glass_shear_modulus": 1.0e6,
    "finger.material.kelvin_shear_moduli": [2.0e5],
    "finger.material.kelvin_viscosities": [2.0e3],
    "finger.adhesion.work_of_adhesion": 0.05,
    "finger.numerics.preset": "fast",
    "finger.numerics.model": "time_stepped",
}


def node_contacts_scene(count: int, *, radius_spread: float = 0.0, **node: Any) -> dict[str, Any]:
    """Node parameters of ``count`` standard-solid spheres ``c0``, ``c1``, ... (fast preset,
    commands up to 30 s ahead of the clock, 1 Hz publishing) for the node tests: contact k's
    radius is 5 mm x (1 + ``radius_spread`` k), so contacts can differ; ``node`` adds or
    overrides node parameters (e.g. ``{"command.queue_depth": 37}``)."""
    ids = [f"c{k}" for k in range(count)]
    scene: dict[str, Any] = {"contacts": ids, "publish_rate": 1.0, "command.max_future_s": 30.0, **node}
    for k, contact_id in enumerate(ids):
        scene[f"{contact_id}.indenter.shape"] = "sphere"
        scene[f"{contact_id}.indenter.radius"] = 0.005 * (1.0 + radius_spread * k)
        scene[f"{contact_id}.material.glass_shear_modulus"] = 1.0e6
        scene[f"{contact_id}.material.kelvin_shear_moduli"] = [1.0e5]
        scene[f"{contact_id}.material.kelvin_viscosities"] = [1.1e4]
        scene[f"{contact_id}.adhesion.work_of_adhesion"] = 0.05
        scene[f"{contact_id}.numerics.preset"] = "fast"
    return scene


def call_service(client: Any, request: Any, timeout: float = 10.0) -> Any:
    """The response of ``client`` (an rclpy service client whose node another thread spins,
    e.g. `demo.node_in_process`'s executor) to ``request``; fails the test after ``timeout`` s."""
    assert client.wait_for_service(timeout_sec=timeout)
    future = client.call_async(request)
    deadline = time.monotonic() + timeout
    while not future.done() and time.monotonic() < deadline:
        time.sleep(0.005)
    assert future.done()
    return future.result()
