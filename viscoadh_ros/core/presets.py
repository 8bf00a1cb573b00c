"""Numerics presets: what `numerics.preset` and the other `numerics.*` knobs mean.

A `NumericsConfig` (core/config.py) names a preset and may override single knobs (0 means
"take the preset's value"). `resolve_numerics` turns it into the concrete numbers the
simulator uses. `balanced` is the default; `fast` uses fewer elements and coarser edge
substeps, `accurate` more and finer (measure the cost with `viscoadh bench`).

Guaranteed errors on the time-stepped path, against an independent converged reference in
every regime of the convergence study (tests/test_convergence.py, BENCHMARKS.md "Convergence
against an independent reference": elastic, relaxed, partly relaxed, glassy and K = 3 bodies;
sphere, cone and power-law indenters; 5 to 300 d_c deep; slow and fast retraction). Force
errors are relative to the pull-off force (never to the peak compressive force):

    preset     pull-off   force on each branch   dissipated energy
    fast       0.5 %      7 %                    2 %
    balanced   0.5 %      1 %                    2 %
    accurate   0.5 %      0.5 %                  2 %

(measured worst cases: pull-off 0.1 % at every preset; branches 6.3 %, 0.94 %, 0.30 %; the
dissipated energy is bounded by the reference's own 1 % uncertainty in the deep elastic cases).
The branch error falls at an observed order of 1.5-2 with the element count until it meets the
reference's floor. The closed-form path (`model: auto` on elastic scenes) is exact.

Fixed-grid mode (what a fit needs): `domain_radius` > 0 gives `elements` cells over
(0, domain_radius] independent of the material and adhesion parameters, never rebuilt during a
run while the contact stays inside it (it grows by `growth_factor` only when the contact
reaches its end); the sub-element edge keeps the force continuous in every parameter.

Knobs:
- elements: N, elements of the 1D MDR row over the domain (0, L].
- fine_factor: fine profile grid points per element (the edge root and force integral use
  the profile on that grid, so it only has to resolve g, not the memory).
- max_edge_cells: a substep is halved while the edge would move more than this many
  elements in it (the memory of cells the edge crosses within one substep is updated with
  the contact set of the substep's start).
- max_substep: upper bound on a substep, s; 0 = none (the Kelvin update is exact for any
  step, so only the edge motion limits the step).
- force_tolerance: relative tolerance of the depth search under force control, scaled by
  the larger of |commanded force| and the force scale of the scene.
- domain_radius: domain length L, m; 0 = chosen from the scene; > 0 = one fixed grid (see
  above; it grows only when the contact reaches L).
- growth_factor: the domain grows by this factor when the contact needs more room.
- idle_tolerance: out of contact, memory below this fraction of the domain length counts
  as relaxed: the contact is idle, its memory is dropped and a step costs nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from .errors import ConfigError

PRESET_NAMES = ("fast", "balanced", "accurate")
MODEL_NAMES = ("auto", "closed_form", "time_stepped")


@dataclass(frozen=True)
class ResolvedNumerics:
    """Concrete numerics of one contact (see the module docstring for each knob)."""

    preset: str
    model: str
    elements: int
    fine_factor: int
    max_edge_cells: float
    max_substep: float
    force_tolerance: float
    domain_radius: float
    growth_factor: float
    idle_tolerance: float


_PRESETS = {
    "fast": ResolvedNumerics("fast", "auto", 64, 16, 2.0, 0.0, 1e-4, 0.0, 2.0, 1e-9),
    "balanced": ResolvedNumerics("balanced", "auto", 160, 32, 1.0, 0.0, 1e-6, 0.0, 2.0, 1e-10),
    "accurate": ResolvedNumerics("accurate", "auto", 400, 32, 1.0, 0.0, 1e-8, 0.0, 1.5, 1e-12),
}


def preset(name: str) -> ResolvedNumerics:
    """The numerics of preset `name` ("fast", "balanced" or "accurate")."""
    if name not in _PRESETS:
        raise ConfigError(f"numerics.preset must be one of {', '.join(PRESET_NAMES)} (got {name!r})")
    return _PRESETS[name]


def resolve_numerics(numerics: Any) -> ResolvedNumerics:
    """Resolve a `NumericsConfig` (fields preset, model, elements, domain_radius,
    max_substep, force_tolerance; 0 = from the preset) into concrete numbers."""
    base = preset(getattr(numerics, "preset", "balanced"))
    model = getattr(numerics, "model", "auto")
    if model not in MODEL_NAMES:
        raise ConfigError(f"numerics.model must be one of {', '.join(MODEL_NAMES)} (got {model!r})")
    overrides: dict[str, Any] = {"model": model}
    elements = getattr(numerics, "elements", 0)
    if isinstance(elements, bool) or not isinstance(elements, int) or elements < 0:
        raise ConfigError(f"numerics.elements must be an integer >= 0 (got {elements!r})")
    if elements:
        if elements < 4:
            raise ConfigError(f"numerics.elements must be >= 4 or 0 for the preset (got {elements!r})")
        overrides["elements"] = elements
    for key in ("domain_radius", "max_substep", "force_tolerance"):
        value = getattr(numerics, key, 0.0)
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ConfigError(f"numerics.{key} must be a number (got {value!r})") from None
        if not number >= 0.0 or number == float("inf"):
            raise ConfigError(f"numerics.{key} must be finite and >= 0 (got {value!r})")
        if number > 0.0:
            overrides[key] = number
    if overrides.get("force_tolerance", 0.0) >= 1.0:
        raise ConfigError(f"numerics.force_tolerance must be < 1 (got {overrides['force_tolerance']!r})")
    return replace(base, **overrides)
