"""The regimes of the convergence study (issue 10): one adhesive press-and-pull history per
case, run by the core (tests/test_convergence.py, `benchmarks/convergence.py`) and by the
independent element-wise stepper (tests/reference_stepper.py).

Every history has 1001 uniform rows: from 0.5 depth units above the surface to ``depth``
units into it in the first half, then out to ``-pull`` units (past pull-off). The depth unit
is ``d_c`` of physics.md section 4 with the moduli that govern the case's pull-off (the
relaxed ones, or the glass modulus for the glassy and elastic cases).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scenes import one_contact

from viscoadh_ros.core import reference
from viscoadh_ros.core.profiles import make_profile
from viscoadh_ros.core.rheology import CreepElement

RADIUS = 1e-3  # m, sphere radius (and the power law's scale)
G0, G1 = 1e6, 1e5  # Pa
WORK = 0.05  # J/m^2
ROWS = 1001


@dataclass(frozen=True)
class Case:
    """name; indenter (scene keys); Kelvin moduli (Pa) and viscosities (Pa s); depth and
    pull in depth units; duration of the history, s; glassy: the depth unit uses E0*;
    elements, substeps: the reference's coarsest level (it runs that and twice as fine)."""

    name: str
    regime: str
    indenter: dict[str, Any]
    kelvin: tuple[float, ...]
    viscosities: tuple[float, ...]
    depth: float
    pull: float
    duration: float
    glassy_unit: bool
    elements: int
    substeps: int

    def contact(self, **numerics: Any) -> Any:
        return one_contact(
            self.indenter,
            glass_shear_modulus=G0,
            kelvin=self.kelvin,
            viscosities=self.viscosities,
            work=WORK,
            numerics={"model": "time_stepped", **numerics},
        )

    @property
    def depth_unit(self) -> float:
        creep = CreepElement.from_config(self.contact().material)
        if self.glassy_unit or not self.kelvin:
            return abs(reference.jkr_scales(RADIUS, creep.glass_modulus_star, WORK).depth)
        return abs(reference.figure4_scales(RADIUS, WORK, creep).depth)

    def history(self) -> tuple[np.ndarray, np.ndarray]:
        half = ROWS // 2
        unit = self.depth_unit
        depth = unit * np.concatenate(
            [np.linspace(-0.5, self.depth, half), np.linspace(self.depth, -self.pull, ROWS - half)]
        )
        return np.linspace(0.0, self.duration, ROWS), depth

    @property
    def length(self) -> float:
        """Reference domain, m: twice the radius where the profile reaches the deepest point
        plus room for the adhesive neck."""
        profile = make_profile(self.contact().indenter)
        deepest = self.depth * self.depth_unit
        return 2.0 * float(profile.radius_at_height(deepest)) + 4.0 * float(
            profile.radius_at_height(self.depth_unit)
        )


def _standard(tau: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """One Kelvin element G1 with relaxation time tau = eta1 / (G0 + G1), s."""
    return (G1,), (tau * (G0 + G1),)


SPHERE = {"shape": "sphere", "radius": RADIUS}
CONE = {"shape": "cone", "half_angle": math.radians(85.0)}
POWER = {"shape": "power_law", "coefficient": 0.5 / math.sqrt(RADIUS), "exponent": 1.5}

CASES = (
    Case("elastic shallow", "elastic", SPHERE, (), (), 5.0, 2.0, 1.0, True, 4000, 2),
    Case("elastic deep", "elastic", SPHERE, (), (), 300.0, 2.0, 1.0, True, 16000, 4),
    Case("glassy deep", "glassy", SPHERE, *_standard(1e8), 300.0, 2.0, 1.0, True, 16000, 4),
    Case("relaxed shallow", "relaxed", SPHERE, *_standard(1e-6), 5.0, 3.0, 1.0, False, 4000, 2),
    Case("relaxed deep", "relaxed", SPHERE, *_standard(1e-6), 100.0, 3.0, 1.0, False, 8000, 2),
    Case("slow retraction", "partly relaxed", SPHERE, *_standard(1e-2), 5.0, 3.0, 1.0, False, 4000, 4),
    Case("partly relaxed", "partly relaxed", SPHERE, *_standard(0.3), 5.0, 3.0, 1.0, False, 4000, 4),
    Case("partly relaxed deep", "partly relaxed", SPHERE, *_standard(1.0), 300.0, 3.0, 1.0, True, 16000, 4),
    Case("fast retraction", "partly relaxed", SPHERE, *_standard(3.0), 5.0, 3.0, 1.0, False, 4000, 4),
    Case(
        "Prony K=3",
        "K = 3",
        SPHERE,
        (2e5, 5e5, 1e6),
        (2e5 * 1e-3, 5e5 * 1e-2, 1e6 * 1e-1),
        10.0,
        3.0,
        0.1,
        False,
        4000,
        4,
    ),
    Case("cone", "partly relaxed", CONE, *_standard(0.3), 5.0, 3.0, 1.0, False, 4000, 4),
    Case("power law n=1.5", "partly relaxed", POWER, *_standard(0.3), 5.0, 3.0, 1.0, False, 4000, 4),
)


def branches(
    force_ref: np.ndarray, radius_ref: np.ndarray, radius: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Row indices of the indentation branch (in contact in both runs, from two rows after
    the first touch to the turn) and of the retraction branch (after the turn up to the
    reference's most tensile row; beyond it the displacement-controlled runaway to the fold
    is a jump, not a branch)."""
    half = ROWS // 2
    both = (radius_ref > 0.0) & (radius > 0.0)
    touch = int(np.argmax(radius_ref > 0.0))
    rows = np.arange(ROWS)
    pull_off = int(np.argmin(force_ref))
    indent = rows[(rows >= touch + 2) & (rows < half) & both]
    retract = rows[(rows >= half) & (rows <= pull_off) & both]
    return indent, retract


def errors(
    case: Case, force: np.ndarray, radius: np.ndarray, dissipated: np.ndarray, ref: dict
) -> dict[str, float]:
    """Errors of a core run against the reference entry `ref` (force, radius, dissipated
    lists): pull-off (most tensile force, relative), the largest force error on each branch
    relative to the pull-off force, and the final dissipated energy (relative)."""
    f_ref = np.asarray(ref["force"])
    r_ref = np.asarray(ref["radius"])
    pull_off = float(f_ref.min())
    indent, retract = branches(f_ref, r_ref, radius)
    scale = abs(pull_off)
    return {
        "pull_off": abs(float(force.min()) / pull_off - 1.0),
        "indentation": float(np.max(np.abs(force[indent] - f_ref[indent]), initial=0.0)) / scale,
        "retraction": float(np.max(np.abs(force[retract] - f_ref[retract]), initial=0.0)) / scale,
        "dissipated": abs(float(dissipated[-1]) / float(ref["dissipated"][-1]) - 1.0),
    }
