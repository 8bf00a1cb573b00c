"""Numerics presets: what `numerics.preset` and the other `numerics.*` knobs mean.

A `NumericsConfig` (core/config.py) names a preset and may override single knobs (0 means
"take the preset's value"). `resolve_numerics` turns it into the concrete numbers the
simulator uses. `balanced` is the default; `fast` uses fewer elements and coarser edge
substeps, `accurate` more and finer (measure the cost with `viscoadh bench`).

Guaranteed errors on the time-stepped path, against an independent converged reference in
every regime of the convergence study (tests/test_convergence.py, BENCHMARKS.md "Convergence
against an independent reference": elastic, relaxed, partly relaxed, glassy and K = 3 bodies;
sphere, cone and power-law indenters; slow and fast retraction; elastic and glassy bodies 5 and
300 d_c deep, viscoelastic ones with G0/G_inf <= 11 at most 12 relaxed d_c deep, 100 when
relaxed, cones and power laws 5). Force errors are relative to the pull-off force (never to the
peak compressive force). A larger G0/G_inf or a deeper viscoelastic press exceeds them (0.10.0:
the paper's G0/G_inf = 101 at 10 relaxed d_c is 7.0e-2 at `balanced`; docs/configuration.md
lists the measured exceptions):

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
- elements: N, elements of the 1D MDR row over the domain (0, L]; 4..ELEMENTS_MAX.
- fine_factor: fine profile grid points per element (the edge root and force integral use
  the profile on that grid, so it only has to resolve g, not the memory).
- max_edge_cells: a substep is halved while the edge would move more than this many
  elements in it (the memory of cells the edge crosses within one substep is updated with
  the contact set of the substep's start).
- max_substep: upper bound on a substep, s; 0 = none (the Kelvin update is exact for any
  step, so only the edge motion limits the step). A step may take at most MAX_SUBSTEPS of
  them: a longer step is refused.
- force_tolerance: relative tolerance of the depth search under force control, scaled by
  the larger of |commanded force| and the force scale of the scene.
- domain_radius: domain length L, m; 0 = chosen from the scene; > 0 = one fixed grid (see
  above; it grows only when the contact reaches L), in DOMAIN_RADIUS_RANGE.
- growth_factor: the domain grows by this factor when the contact needs more room.
- idle_tolerance: out of contact, memory below this fraction of the domain length counts
  as relaxed: the contact is idle, its memory is dropped and a step costs nothing.

Tolerance mode (`numerics.tolerance` > 0, `numerics_for_tolerance`): the element count is
the first of ELEMENT_LADDER whose error predicted by ERROR_MODEL for the scene's regime
(`regime_of`: elastic, glassy over `numerics.time_scale`, one Kelvin element, K >= 2; for
the viscoelastic ones also scaled by G0/G_inf, RATIO_TERM) is at most the tolerance, with
`fast`'s step control; what that guarantees and where it was checked
is in docs/configuration.md ("Choosing numerics by tolerance").
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

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


#: Largest ``numerics.elements``. The cost of a step grows with N (a snap-in's edge races across
#: ~N/16 elements, one substep each; out of contact a substep reads the whole row): 65536
#: elements ran a 21-row press and pull in 2 s (its snap-in 1.5 s), 262144 took 137 s, and
#: 2e7 did not finish in 120 s (0.10.0's outside tester; 1e8 ran out of memory). The most any
#: accuracy needs is far below: the tolerance ladder ends at 8192, a fit's grid at 4 x 8192.
ELEMENTS_MAX = 65_536
#: Range of ``numerics.domain_radius`` when given (> 0), m: from the smallest indenter radius
#: (PHYSICAL_RANGES, core/config.py) to the longest first domain the scene may choose itself
#: (`simulator.FIRST_DOMAIN_LIMIT`); 1e300 m overflowed the profile (a traceback).
DOMAIN_RADIUS_RANGE = (1e-9, 1e3)
#: Most substeps ``numerics.max_substep`` may cut one step into: the kernel's own finest
#: substep is ``JUMP_RESOLUTION`` (1e-4) of the step, so a max_substep step costs at most
#: what the kernel's own step control may; a step longer than ``MAX_SUBSTEPS x max_substep``
#: is refused (InputError, `simulator.ContactSimulator.step`). Without it 1e-12 s cut a 10 ms
#: step into 1e10 substeps and froze the node (0.10.0's outside tester).
MAX_SUBSTEPS = 10_000


def preset(name: str) -> ResolvedNumerics:
    """The numerics of preset `name` ("fast", "balanced" or "accurate")."""
    if name not in _PRESETS:
        raise ConfigError(f"numerics.preset must be one of {', '.join(PRESET_NAMES)} (got {name!r})")
    return _PRESETS[name]


def _number(numerics: Any, key: str) -> float:
    """numerics.<key> as a finite float >= 0 (0 when absent), or ConfigError naming it."""
    value = getattr(numerics, key, 0.0)
    if isinstance(value, bool) or isinstance(value, str):
        raise ConfigError(f"numerics.{key} must be a number (got {value!r})")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"numerics.{key} must be a number (got {value!r})") from None
    if not number >= 0.0 or number == float("inf"):
        raise ConfigError(f"numerics.{key} must be finite and >= 0 (got {value!r})")
    return number


def resolve_numerics(numerics: Any) -> ResolvedNumerics:
    """Resolve a `NumericsConfig` (fields preset, model, elements, domain_radius,
    max_substep, force_tolerance, tolerance, time_scale; 0 = from the preset) into concrete
    numbers. With ``tolerance`` > 0 the element count and step control come from
    `numerics_for_tolerance` for the scene the config carries (``numerics.scene``, a
    `SceneHint` that `ContactConfig` attaches; none: the worst case of every regime);
    an explicit ``elements`` still wins."""
    base = preset(getattr(numerics, "preset", "balanced"))
    model = getattr(numerics, "model", "auto")
    if model not in MODEL_NAMES:
        raise ConfigError(f"numerics.model must be one of {', '.join(MODEL_NAMES)} (got {model!r})")
    overrides: dict[str, Any] = {"model": model}
    elements = getattr(numerics, "elements", 0)
    if isinstance(elements, bool) or not isinstance(elements, int) or elements < 0:
        raise ConfigError(f"numerics.elements must be an integer >= 0 (got {elements!r})")
    if elements and not 4 <= elements <= ELEMENTS_MAX:
        raise ConfigError(
            f"numerics.elements must be 0 (the preset's) or in 4..{ELEMENTS_MAX} (got {elements!r})"
        )
    for key in ("domain_radius", "max_substep", "force_tolerance"):
        number = _number(numerics, key)
        if number > 0.0:
            overrides[key] = number
    low, high = DOMAIN_RADIUS_RANGE
    if not low <= overrides.get("domain_radius", low) <= high:
        raise ConfigError(
            f"numerics.domain_radius must be 0 (chosen from the scene) or in [{low:g}, {high:g}] m "
            f"(got {overrides['domain_radius']!r})"
        )
    if overrides.get("force_tolerance", 0.0) >= 1.0:
        raise ConfigError(f"numerics.force_tolerance must be < 1 (got {overrides['force_tolerance']!r})")
    tolerance = check_tolerance(getattr(numerics, "tolerance", 0.0))
    time_scale = _number(numerics, "time_scale")
    if tolerance > 0.0:
        hint = getattr(numerics, "scene", None)
        chosen = numerics_for_tolerance(tolerance, hint, time_scale=time_scale)
        base = replace(
            base,
            elements=chosen.elements,
            fine_factor=chosen.fine_factor,
            max_edge_cells=chosen.max_edge_cells,
            force_tolerance=min(base.force_tolerance, chosen.force_tolerance),
        )
    if elements:
        overrides["elements"] = elements
    return replace(base, **overrides)


# --- tolerance mode --------------------------------------------------------------------------

#: The tightest and loosest tolerance accepted: (0, 1) open, 0 = use the preset.
TOLERANCE_RANGE = "0 (use the preset) or in (0, 1)"


def check_tolerance(value: Any) -> float:
    """numerics.tolerance as a float: 0, or in the open interval (0, 1); ConfigError naming
    the range otherwise (text, bool, NaN, infinity, negative, >= 1)."""
    if isinstance(value, (bool, str)) or value is None:
        raise ConfigError(f"numerics.tolerance must be a number, {TOLERANCE_RANGE} (got {value!r})")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"numerics.tolerance must be a number, {TOLERANCE_RANGE} (got {value!r})") from None
    if number != 0.0 and not 0.0 < number < 1.0:
        raise ConfigError(f"numerics.tolerance must be {TOLERANCE_RANGE} (got {value!r})")
    return number


#: G0/G_inf assumed when nothing is known of the scene (the largest of the K >= 2 measurements).
UNKNOWN_RATIO = 101.0


@dataclass(frozen=True)
class SceneHint:
    """What the tolerance mode reads of a contact's scene (`ContactConfig` attaches it to its
    numerics, so `resolve_numerics` sees it): the relaxation times of the in-contact Kelvin
    chain, s (empty: elastic), the indenter shape and the glass-to-relaxed modulus ratio
    G0/G_inf (1 for an elastic body), which scales the viscoelastic error (ERROR_MODEL);
    a hint made without it (the 0.9.0 signature) assumes UNKNOWN_RATIO (101: more elements
    than a body up to that ratio needs, fewer than a stiffer glass needs; `SceneHint.of` reads
    the true ratio)."""

    relaxation_times: tuple[float, ...]
    shape: str
    relaxed_ratio: float = UNKNOWN_RATIO

    @classmethod
    def of(cls, indenter: Any, material: Any) -> SceneHint:
        """From an `IndenterConfig` and a `MaterialConfig` (core/config.py)."""
        return cls(
            relaxation_times=relaxation_times(
                material.glass_shear_modulus, material.kelvin_shear_moduli, material.kelvin_viscosities
            ),
            shape=str(indenter.shape),
            relaxed_ratio=relaxed_ratio(material.glass_shear_modulus, material.kelvin_shear_moduli),
        )


def relaxed_ratio(glass: float, moduli: Any) -> float:
    """G0/G_inf of a Kelvin chain in series with the glass spring:
    ``1 + G0 sum(1/G_k)`` (1 for an elastic body)."""
    g = np.asarray(moduli, dtype=np.float64)
    return float(1.0 + glass * np.sum(1.0 / g)) if g.size else 1.0


def relaxation_times(glass: float, moduli: Any, viscosities: Any) -> tuple[float, ...]:
    """Relaxation times of the Kelvin chain held at a fixed displacement, s, ascending: the
    inverse eigenvalues of ``D^-1 (G0 11^T + diag(G_k))`` (one element: ``eta1 / (G0 + G1)``)."""
    g = np.asarray(moduli, dtype=np.float64)
    eta = np.asarray(viscosities, dtype=np.float64)
    if g.size == 0:
        return ()
    root = np.sqrt(eta)
    stiffness = glass * np.ones((g.size, g.size)) + np.diag(g)
    rates = np.linalg.eigvalsh(stiffness / np.outer(root, root))
    return tuple(sorted(float(1.0 / rate) for rate in rates))


@dataclass(frozen=True)
class ToleranceChoice:
    """What `numerics_for_tolerance` picked: the regime it recognised, the element count and
    step control, the error the model predicts for them (relative to the pull-off force) and
    the force-control tolerance."""

    regime: str
    elements: int
    fine_factor: int
    max_edge_cells: float
    predicted_error: float
    force_tolerance: float


#: Step control of the tolerance mode: `fast`'s (fine_factor 16, max_edge_cells 2). In the
#: convergence study it gives the same force errors as `balanced`'s (32, 1) at every element
#: count from 32 to 640 in every regime (within 11 %, the reference's noise) at about 2/3 of
#: the cost, so the element count is the only knob the tolerance has to turn.
STEP_CONTROL = (16, 2.0)
#: Element counts the tolerance mode chooses from, cheapest first (cost ~ linear in them).
ELEMENT_LADDER = (
    16, 24, 32, 40, 48, 64, 80, 96, 128, 160, 192, 256, 320, 384, 512, 640, 768, 1024,
    1280, 1536, 2048, 2560, 3072, 4096, 5120, 6144, 8192,
)  # fmt: skip
#: Observed error model per regime: the largest force error of a press-and-pull history
#: (pull-off and every row of both branches) relative to the pull-off force is at most
#: ``max(C N^-p)`` over the terms, and for a viscoelastic body also at most
#: ``RATIO_TERM[regime] * (G0/G_inf) * N^-2``; envelopes of the measured errors with a 20 % margin.
#: - elastic, glassy: against the closed form (exact for an elastic body), sphere 5 and
#:   300 d_c deep, N = 16..2048: 0.36-0.53 N^-2.
#: - viscoelastic, one Kelvin element (relaxed, partly relaxed, slow and fast retraction,
#:   sphere, cone, power law; G0/G_inf = 1.1 and 11, at most 12 relaxed d_c deep): against the
#:   independent reference (benchmarks/convergence_reference.json), N = 32..640: at most
#:   295 N^-2 (the deep case) until the reference's own uncertainty (~1e-3 of the pull-off force).
#: - K >= 2 (the Prony K = 3 case): 6.2-9.0 N^-1.3.
#: Made by `python benchmarks/tolerance_model.py` (prints the measured constants).
ERROR_MODEL: dict[str, tuple[tuple[float, float], ...]] = {
    "elastic": ((0.65, 2.0),),
    "glassy": ((0.65, 2.0),),
    "viscoelastic": ((350.0, 2.0),),
    "viscoelastic, K >= 2": ((350.0, 2.0), (11.0, 1.3)),
}
#: The viscoelastic error grows with G0/G_inf (0.10.0: the paper's material, G0/G_inf = 101,
#: 10 relaxed d_c deep, was 5x the model above). It is a discretisation error of the deepest
#: rows: ~1-2.5 (L / (a N))^2 of the force there (a the contact radius, L the domain, which
#: doubles when the contact reaches its end, so L/a is up to 2 right after a growth), i.e.
#: relative to the pull-off force ~ (F_max / |F_pull-off|) times that, and F_max / |F_pull-off|
#: grows with G0/G_inf and the depth. C = RATIO_TERM x G0/G_inf covers, with a 20 % margin,
#: every history of `benchmarks/tolerance_depth.py` (sphere, G0/G_inf 1.1-1001, presses of 0.5-50
#: retardation times) up to RATIO_DEPTH relaxed d_c deep whose peak force is at most
#: RATIO_PEAK x G0/G_inf times its pull-off force (measured at most 17.7 x G0/G_inf for one
#: element at G0/G_inf >= 11, 59 x for K = 3 at 19.3; beyond,
#: see docs/configuration.md "Choosing numerics by tolerance").
RATIO_TERM: dict[str, float] = {"viscoelastic": 22.0, "viscoelastic, K >= 2": 71.0}
#: Above G0/G_inf = RATIO_KNEE the term grows faster than G0/G_inf: by (G0/G_inf / RATIO_KNEE)
#: ** RATIO_GROWTH. A second outside tester (0.10.0) found 1.77x the tolerance at G0/G_inf =
#: 1001 inside the range above (one element, 4.75 relaxed d_c, peak 2401 x the pull-off,
#: `tolerance: 1e-2` -> 1536 elements: C/r = 42 where the grid's two histories at 1001 had
#: reached 20); the error grows with the peak-to-pull-off ratio (1.8e-2 at 2401, ~7e-6 per unit
#: of it at 1536 elements), so at the range's peak (4 x 1001) C/r ~ 70, with the 20 % margin
#: 84 = 22 (1001/101)^0.58. No measurement above G0/G_inf = 101 for K >= 2: the same growth.
RATIO_KNEE, RATIO_GROWTH = 101.0, 0.6
#: The depth (relaxed d_c of docs/concepts.md) and the peak-to-pull-off force ratio (over
#: G0/G_inf) up to which RATIO_TERM was measured to hold.
RATIO_DEPTH, RATIO_PEAK = 10.0, 4.0
#: A body counts as glassy over the time scale T when its shortest relaxation time is at least
#: T / (GLASSY_FRACTION * tolerance): its memory then moves less than a tenth of the
#: tolerance over T, relative to the peak force (relative to the pull-off force it can move
#: much more: docs/configuration.md). Anything else viscoelastic takes the viscoelastic model (relaxed bodies
#: included: the study shows no smaller error for them).
GLASSY_FRACTION = 0.1


def regime_of(hint: SceneHint | None, *, tolerance: float, time_scale: float = 0.0) -> str:
    """The error-model regime of a scene: "elastic" (K = 0), "glassy" (every relaxation time
    long against `time_scale`, see GLASSY_FRACTION), "viscoelastic" (one Kelvin element) or
    "viscoelastic, K >= 2"; the worst case, "viscoelastic, K >= 2", when nothing is known."""
    if hint is None:
        return "viscoelastic, K >= 2"
    times = hint.relaxation_times
    if not times:
        return "elastic"
    if time_scale > 0.0 and min(times) * GLASSY_FRACTION * tolerance >= time_scale:
        return "glassy"
    return "viscoelastic" if len(times) == 1 else "viscoelastic, K >= 2"


def predicted_error(regime: str, elements: int, ratio: float = UNKNOWN_RATIO) -> float:
    """The error model's bound on the force error at `elements` elements of a body with
    G0/G_inf = `ratio` (see ERROR_MODEL and RATIO_TERM)."""
    error = max(c * elements ** (-p) for c, p in ERROR_MODEL[regime])
    if regime in RATIO_TERM:
        growth = max(ratio / RATIO_KNEE, 1.0) ** RATIO_GROWTH
        error = max(error, RATIO_TERM[regime] * growth * ratio * elements**-2.0)
    return error


def numerics_for_tolerance(
    tolerance: float, hint: SceneHint | None = None, *, time_scale: float = 0.0
) -> ToleranceChoice:
    """The cheapest element count of ELEMENT_LADDER (with STEP_CONTROL) whose predicted force
    error in the scene's regime is at most `tolerance` (relative to the pull-off force).
    A tighter tolerance never gives fewer elements. ConfigError when even the last rung
    cannot meet it."""
    tolerance = check_tolerance(tolerance)
    if tolerance == 0.0:
        raise ConfigError("numerics.tolerance must be > 0 to choose numerics by it")
    regime = regime_of(hint, tolerance=tolerance, time_scale=time_scale)
    ratio = UNKNOWN_RATIO if hint is None else hint.relaxed_ratio
    for elements in ELEMENT_LADDER:
        error = predicted_error(regime, elements, ratio)
        if error <= tolerance:
            fine_factor, max_edge_cells = STEP_CONTROL
            return ToleranceChoice(
                regime=regime,
                elements=elements,
                fine_factor=fine_factor,
                max_edge_cells=max_edge_cells,
                predicted_error=error,
                force_tolerance=0.01 * tolerance,
            )
    finest = predicted_error(regime, ELEMENT_LADDER[-1], ratio)
    raise ConfigError(
        f"numerics.tolerance {tolerance:g} is tighter than this scene can be guaranteed ({regime} "
        f"body: {ELEMENT_LADDER[-1]} elements give {finest:.1g}); loosen it or set numerics.elements"
    )
