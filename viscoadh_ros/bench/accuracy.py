"""Error against cost over element counts and time steps, for cases with a known answer.

Cases (all a sphere, displacement control, a piecewise-linear approach/retract cycle):
- `jkr_pull_off`: elastic JKR on the time-stepped path; the most tensile force reached is the
  JKR pull-off force `-(3/2) pi R w` (the force minimum of the JKR curve lies before the last
  stable point, so displacement control passes through it).
- `standard_solid_pull_off`: standard solid cycled slowly against its relaxation time; pull-off on
  the detachment branch `-(3/2) pi R w_eff2`, `w_eff2 = w (G0 + G1) / G1`.
- `rate_dependent`: the same material cycled in a few relaxation times, where no closed form
  exists; the reference is a converged run (finest elements and steps, measured in the same run).

The error of a run is `|F_min - F_ref| / |F_ref|`; its cost is the wall time per history row, us.
The presets (`preset_table`) and the tolerance mode (`tolerance_table`: `numerics.tolerance`
picks the element count for the scene) are measured on the same cases, for the same axes.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from viscoadh_ros.bench.timing import median_seconds
from viscoadh_ros.core import reference
from viscoadh_ros.core.config import ContactConfig, SceneConfig
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.core.presets import preset, resolve_numerics
from viscoadh_ros.core.rheology import CreepElement

# A soft silicone-like body on a millimetre sphere: moduli and work of adhesion of the order of
# the paper's examples, scaled to a size a gripper meets.
RADIUS = 5e-3  # m
GLASS_MODULUS = 1e6  # Pa
KELVIN_MODULUS = 1e5  # Pa
RELAXATION_TIME = 0.01  # s, eta1 / (G0 + G1)
WORK_OF_ADHESION = 0.05  # J/m^2
# Slow enough against the relaxation time for the quasistatic limit, fast enough to stay cheap.
QUASISTATIC_CYCLES_PER_TAU = 1e-3
RATE_DEPENDENT_CYCLE_TIME = 5.0 * RELAXATION_TIME


@dataclass(frozen=True)
class Case:
    """One benchmark case: a contact (as a ros__parameters mapping) and how to judge it.

    contact: nested `{indenter: ..., material: ..., adhesion: ...}` mapping of one contact.
    cycle_time: duration of the approach/retract cycle, s.
    closed_form: True when the quasistatic JKR pull-off of the detachment branch is the
    reference, False when a converged run is.
    """

    name: str
    contact: dict[str, Any]
    cycle_time: float
    closed_form: bool

    @property
    def scales(self) -> reference.Figure4Scales:
        """Force, contact-radius and depth scales of the detachment branch (physics.md 4)."""
        material = contact_config(self, {}).material
        return reference.figure4_scales(RADIUS, WORK_OF_ADHESION, CreepElement.from_config(material))

    @property
    def depth_scale(self) -> float:
        """The JKR characteristic depth of the detachment branch, m."""
        return self.scales.depth

    @property
    def exact_pull_off(self) -> float | None:
        """Closed-form most tensile force `-(3/2) pi R w_eff2`, N, or None (no closed form)."""
        return -self.scales.force if self.closed_form else None


def cases() -> tuple[Case, ...]:
    """The three accuracy cases, built from the constants above."""
    sphere = {"shape": "sphere", "radius": RADIUS}
    adhesion = {"work_of_adhesion": WORK_OF_ADHESION}
    elastic = {"glass_shear_modulus": GLASS_MODULUS}
    viscous = {
        "glass_shear_modulus": GLASS_MODULUS,
        "kelvin_shear_moduli": [KELVIN_MODULUS],
        "kelvin_viscosities": [RELAXATION_TIME * (GLASS_MODULUS + KELVIN_MODULUS)],
    }
    return (
        Case("jkr_pull_off", {"indenter": sphere, "material": elastic, "adhesion": adhesion}, 1.0, True),
        Case(
            "standard_solid_pull_off",
            {"indenter": sphere, "material": viscous, "adhesion": adhesion},
            RELAXATION_TIME / QUASISTATIC_CYCLES_PER_TAU,
            True,
        ),
        Case(
            "rate_dependent",
            {"indenter": sphere, "material": viscous, "adhesion": adhesion},
            RATE_DEPENDENT_CYCLE_TIME,
            False,
        ),
    )


def cycle_history(case: Case, rows: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Time (s) and depth (m) rows, shape (rows,), of the case's approach/retract cycle.

    Out of contact at `-0.5 d_c`, in to `5 d_c` at half the cycle, out to `-3 d_c` (beyond the
    displacement-control detachment point, about `-2.1 d_c`). The depth must pass `3 d_c`: the
    edge sticks after reversal, so the detachment branch only reaches its force minimum (at
    `a_c`, with `a_c^2 = 3 R d_c`) if the approach opened the contact wider than `a_c`.
    """
    time = np.linspace(0.0, case.cycle_time, rows)
    knots_t = [0.0, 0.5 * case.cycle_time, case.cycle_time]
    knots_d = [-0.5 * case.depth_scale, 5.0 * case.depth_scale, -3.0 * case.depth_scale]
    return time, np.interp(time, knots_t, knots_d)


def contact_config(case: Case, numerics: dict[str, Any]) -> ContactConfig:
    """The case's contact with the given `numerics` keys, through the one scene loader."""
    contact = dict(case.contact, numerics={"model": "time_stepped", **numerics})
    scene = SceneConfig.from_dict({"contacts": ["bench"], "bench": contact})
    return scene.contact("bench")


def pull_off(contact: ContactConfig, time: npt.NDArray[np.float64], depth: npt.NDArray[np.float64]) -> float:
    """Most tensile force of a depth-controlled history, N."""
    return float(np.min(simulate_history(contact, time, depth=depth).force))


def measure(
    case: Case, numerics: dict[str, Any], rows: int, *, reference_force: float, repeats: int
) -> tuple[float, float]:
    """(relative error of the pull-off force, median wall time per row in us) of `repeats` runs."""
    contact = contact_config(case, numerics)
    time, depth = cycle_history(case, rows)
    forces = []
    seconds = median_seconds(lambda: forces.append(pull_off(contact, time, depth)), repeats=repeats)
    return abs(forces[0] - reference_force) / abs(reference_force), seconds / rows * 1e6


def reference_forces(*, elements: int, rows: int) -> dict[str, float]:
    """Reference pull-off force of every case, N: the closed form, or a converged run at
    `elements` and `rows` (choose both finer than every grid point and preset)."""
    forces = {}
    for case in cases():
        if case.exact_pull_off is not None:
            forces[case.name] = case.exact_pull_off
        else:
            time, depth = cycle_history(case, rows)
            forces[case.name] = pull_off(contact_config(case, {"elements": elements}), time, depth)
    return forces


def _row(case: Case, preset: str, elements: int, rows: int, error: float, cost: float) -> dict[str, Any]:
    return {
        "preset": preset,
        "elements": elements,
        "time_step": case.cycle_time / (rows - 1),
        "rows": rows,
        "case": case.name,
        "rel_error": error,
        "us_per_step": cost,
    }


def accuracy_grid(
    *,
    references: dict[str, float],
    preset: str,
    elements: Sequence[int],
    rows: Sequence[int],
    repeats: int,
) -> list[dict[str, Any]]:
    """Every case at every element count x row count on one preset: the `accuracy` section."""
    results = []
    for case in cases():
        for n_elements in elements:
            for n_rows in rows:
                numerics = {"preset": preset, "elements": n_elements}
                error, cost = measure(
                    case, numerics, n_rows, reference_force=references[case.name], repeats=repeats
                )
                results.append(_row(case, preset, n_elements, n_rows, error, cost))
    return results


def preset_table(
    *, references: dict[str, float], presets: Sequence[str], rows: int, repeats: int
) -> list[dict[str, Any]]:
    """Every case on every preset with the preset's own element count: the `presets` section."""
    results = []
    for case in cases():
        for name in presets:
            error, cost = measure(
                case, {"preset": name}, rows, reference_force=references[case.name], repeats=repeats
            )
            results.append(_row(case, name, preset(name).elements, rows, error, cost))
    return results


def tolerance_table(
    *, references: dict[str, float], tolerances: Sequence[float], rows: int, repeats: int
) -> list[dict[str, Any]]:
    """Every case with `numerics.tolerance` set (balanced otherwise, no time scale given):
    the element count the tolerance mode resolves for the case's scene, its error and cost."""
    results = []
    for case in cases():
        for tolerance in tolerances:
            numerics = {"tolerance": tolerance}
            elements = resolve_numerics(contact_config(case, numerics).numerics).elements
            error, cost = measure(
                case, numerics, rows, reference_force=references[case.name], repeats=repeats
            )
            row = _row(case, f"tolerance {tolerance:g}", elements, rows, error, cost)
            results.append(dict(row, tolerance=tolerance))
    return results


def pareto_front(points: Iterable[dict[str, Any]]) -> list[dict[str, Any]]:
    """The points no other point beats in both error and cost, sorted by cost."""
    ordered = sorted(points, key=lambda p: (p["us_per_step"], p["rel_error"]))
    front, best_error = [], math.inf
    for point in ordered:
        if point["rel_error"] < best_error:
            front.append(point)
            best_error = point["rel_error"]
    return front
