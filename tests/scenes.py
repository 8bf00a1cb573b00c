"""Scene builders shared by the simulator tests.

Every test contact goes through the one scene loader (`SceneConfig.from_dict`), so the tests
exercise the same validation and defaults a user's YAML file does.
"""

from __future__ import annotations

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
