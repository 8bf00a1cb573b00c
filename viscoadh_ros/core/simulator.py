"""The stateful contact simulator: one axisymmetric adhesive contact, stepped in time.

`ContactSimulator(contact)` owns the state of one contact and advances it with
``step(time, depth=...)`` (displacement control) or ``step(time, force=...)`` (force
control), like scipy's ``OdeSolver.step()``. Between two commands the depth is linear in
time (a sampled history is a piecewise-linear one). ``snapshot()``/``restore()`` copy the
state cheaply, so "what if" questions never disturb the live contact.

Two model paths ("model only what the scene requires", `model` says which):

- ``closed_form``: elastic scenes (no Kelvin element) with a sphere, cone, flat punch or
  power-law indenter. The edge follows the JKR-type law ``d = g(a) - dl_c(a)`` on its
  outer (displacement-stable) branch, ``dl_c(a) = sqrt(2 pi a w / E0*)``; the contact
  snaps in when the indenter touches (d >= 0) and lets go at the fold of that law (flat
  punch: Kendall, ``d = -dl_c(a0)``). Nothing is discretised.
- ``time_stepped``: the 1D MDR row of creep elements with the energy criterion on the
  glass springs, a continuous contact radius and exact exponential integration
  (see `_kernels`). Needed whenever memory matters (K >= 1) or for a tabulated profile.

Outputs (`StepOutput`), beyond depth, force and radius:

- ``effective_work_of_adhesion`` (J/m^2): ``E_r* u(a)^2 / (2 pi a)`` with
  ``u(a) = d - g(a)`` the total elongation of the edge element and ``E_r*`` the relaxed
  modulus, 0 when the edge is compressed or out of contact. It is the work of adhesion a
  relaxed elastic JKR contact would need to hold the edge where it is: ``w G1/(G0+G1)``
  for quasistatic indentation (fresh edge elements), ``w (G0+G1)/G1`` for quasistatic
  detachment (relaxed edge elements), ``w`` for an elastic contact.
- ``energy_input`` (J): ``integral F dd`` since the last reset (trapezoidal on the
  substeps of the time-stepped path, exact on the closed-form path).
- ``energy_dissipated`` (J): viscous work plus adhesion hysteresis since the last reset.
  Closed-form path: input minus the elastic energy minus the surface energy ``-w pi a^2``
  (exact). Time-stepped path: a running sum of non-negative per-step losses (the exact
  damper work of every element, and at each element that attaches or lets go the
  difference between its glass-spring energy and its annulus' surface energy), so it never
  decreases; it agrees with input - stored - surface to the discretisation error (about
  1e-5 of the total, 0.5 % for the bluntest relaxed cases). Zero along an elastic
  equilibrium branch; it grows at snap-in, pull-off and through the dampers.
- ``scale_separation_ok``: the energy criterion assumes the edge moves fast compared
  with relaxation over the interaction range h (paper, section 5). With
  ``v_c1 = pi G0 h^2 / (tau w)`` (tau = the shortest relaxation time, the strict side)
  and ``v_c2 = v_c1 (G_inf/G0)^2`` (`criterion.critical_edge_speeds`): an advancing edge
  needs ``|edge_speed| >= v_c1``, a receding one ``|edge_speed| >= v_c2``. A pinned
  edge, no contact, an elastic material
  or ``w = 0`` are always ok.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from enum import IntEnum
from typing import Any

import numpy as np

from . import _kernels
from ._roots import brent_root
from .criterion import critical_edge_speeds, critical_glass_elongation
from .errors import ConfigError, InputError, require_finite
from .presets import DOMAIN_RADIUS_RANGE, MAX_SUBSTEPS, ResolvedNumerics, resolve_numerics
from .profiles import Profile, make_profile
from .rheology import CreepElement


class Phase(IntEnum):
    """Phase of the contact edge (values equal the ContactState message constants)."""

    NO_CONTACT = 0
    INDENTING = 1
    STICKING = 2
    DETACHING = 3


@dataclass(frozen=True)
class StepOutput:
    """The state after one step (SI units; see the module docstring for the definitions)."""

    time: float
    depth: float
    force: float
    contact_radius: float
    phase: Phase
    edge_speed: float
    effective_work_of_adhesion: float
    energy_input: float
    energy_dissipated: float
    scale_separation_ok: bool
    unstable: bool


STEP_OUTPUT_FIELDS = tuple(f.name for f in fields(StepOutput))


_object_new = object.__new__

#: `_kernels.step_entry()`, bound when the first time-stepped model is built.
_STEP: Any = None


def _new_output(
    time: float,
    depth: float,
    force: float,
    contact_radius: float,
    phase: Phase,
    edge_speed: float,
    effective_work_of_adhesion: float,
    energy_input: float,
    energy_dissipated: float,
    scale_separation_ok: bool,
    unstable: bool,
) -> StepOutput:
    """A StepOutput from its field values, without the frozen dataclass's ``__init__`` (one
    ``object.__setattr__`` per field, the larger part of a step's Python cost): the instance
    is the same (same fields, equality, hash, repr). A dict display fills the instance dict
    (about half the time of zipping the names with the values)."""
    output = _object_new(StepOutput)
    output.__dict__.update(
        {
            "time": time,
            "depth": depth,
            "force": force,
            "contact_radius": contact_radius,
            "phase": phase,
            "edge_speed": edge_speed,
            "effective_work_of_adhesion": effective_work_of_adhesion,
            "energy_input": energy_input,
            "energy_dissipated": energy_dissipated,
            "scale_separation_ok": scale_separation_ok,
            "unstable": unstable,
        }
    )
    return output


# The phases as module constants: an enum member lookup (`Phase.INDENTING`) costs several
# times a global's.
_NO_CONTACT = Phase.NO_CONTACT
_INDENTING = Phase.INDENTING
_STICKING = Phase.STICKING
_DETACHING = Phase.DETACHING
#: By their values (`_kernels.PHASE_*`).
_PHASES = (_NO_CONTACT, _INDENTING, _STICKING, _DETACHING)


#: Largest flank slope f'(a) at the contact edge for which the half-space (small-slope) theory
#: behind MDR is taken as valid: its neglected terms grow like the slope squared (a sphere at
#: a/R = 0.3 is Hertz within a few percent).
SMALL_SLOPE_LIMIT = 0.3

#: Fewest elements a time-stepped contact must span, while its edge presses or holds, for the
#: grid to resolve it (`ModelValidity.resolution_ok`). A fixed `numerics.domain_radius` far wider
#: than the contact puts it inside a few elements or one (an outside tester, 0.11.0:
#: `domain_radius: 10` on the default scene gave a pull-off 82 % low with `ok`), and so does a
#: small `numerics.elements`. Measured on the default scene pressed to 100 um in 2 s and pulled
#: to -50 um, against 8192 elements, the largest force error over the history / the pull-off
#: force: the contact spanning at least 10.9 elements (its smallest pressed state) 0.7 %, 5.5
#: elements 1.4 %, 2.7 elements 3.8 %, 1.4 elements 8.6 %, 0.7 element 13 %, 0.2 element 60 %;
#: `elements: 4, 8, 12, 16` 11 %, 12 %, 8.3 %, 5.7 %. No scene-chosen domain of any preset or
#: tolerance mode fell below 8 in 45 scenes (every indenter shape, force control). It catches a
#: grid too coarse to resolve the contact, not a breach of a preset's bound.
RESOLUTION_ELEMENTS = 8.0


@dataclass(frozen=True)
class ModelValidity:
    """Whether the model's own assumptions hold in the current state (docs/concepts.md,
    "Limits of validity"); `ContactSimulator.model_validity`.

    edge_slope: flank slope ``f'(a)`` of the indenter at the contact edge (0 out of contact;
    a flat punch's face is flat); small_slope_ok: ``edge_slope <= SMALL_SLOPE_LIMIT``;
    scale_separation_ok: as in `StepOutput` (the energy criterion's premise); ok: all hold;
    message: what fails, or "" when all hold; resolution_ok: the time-stepped grid resolves
    the contact (it spans at least `RESOLUTION_ELEMENTS` elements; always true out of
    contact, while the edge recedes, and on the closed-form path); elements_in_contact: contact
    radius over the element width (inf when there is no grid or no contact).
    """

    edge_slope: float
    small_slope_ok: bool
    scale_separation_ok: bool
    ok: bool
    message: str
    resolution_ok: bool = True
    elements_in_contact: float = math.inf


_CLOSED_FORM_EXPONENT = {"sphere": 2.0, "cone": 1.0}


class _Physics:
    """Derived constants of a scene shared by both model paths."""

    def __init__(self, contact: Any) -> None:
        self.profile: Profile = make_profile(contact.indenter)
        self.creep = CreepElement.from_config(contact.material)
        self.work_of_adhesion = require_finite("adhesion.work_of_adhesion", contact.adhesion.work_of_adhesion)
        if self.work_of_adhesion < 0.0:
            raise InputError(f"adhesion.work_of_adhesion must be >= 0 (got {self.work_of_adhesion!r})")
        self.interaction_range = require_finite(
            "adhesion.interaction_range", contact.adhesion.interaction_range
        )
        if self.interaction_range <= 0.0:
            raise InputError(f"adhesion.interaction_range must be > 0 (got {self.interaction_range!r})")
        self.e0 = self.creep.glass_modulus_star
        self.e_relaxed = self.creep.relaxed_modulus_star
        # dl_c(x) = c_crit * sqrt(x)
        self.c_crit = float(critical_glass_elongation(1.0, self.work_of_adhesion, self.e0))
        self.critical_speeds = critical_edge_speeds(self.creep, self.work_of_adhesion, self.interaction_range)

    def edge_elongation(self, depth: float, radius: float) -> float:
        """Total elongation u(a) = d - g(a) of the edge element, m."""
        return depth - float(self.profile.g(radius))

    def effective_work(self, depth: float, radius: float) -> float:
        if radius <= 0.0:
            return 0.0
        u = self.edge_elongation(depth, radius)
        return self.e_relaxed * u * u / (2.0 * math.pi * radius) if u < 0.0 else 0.0

    def scale_separation_ok(self, edge_speed: float) -> bool:
        """`criterion.scale_separation_holds` (factor 1) for one finite speed, m/s, in scalar
        math: it runs every step, where the array version's numpy overhead dominated."""
        if edge_speed == 0.0:
            return True
        v_c1, v_c2 = self.critical_speeds
        return abs(edge_speed) >= (v_c1 if edge_speed > 0.0 else v_c2)

    def adhesion_length(self) -> float:
        """First-touch neck radius, m: the root of ``g(x) = dl_c(x)`` (JKR at zero depth with
        the glass modulus), where an adhesive contact starts. Domains start from it and grow:
        a larger scale (say the relaxed detachment JKR radius, G0/G_inf times larger in
        ``w_eff``) would leave the neck inside one element for large G0/G_inf."""
        c = self.c_crit
        x = (
            max(self.profile.characteristic_radius, 1e-30)
            if math.isfinite(self.profile.characteristic_radius)
            else 1.0
        )
        # g(x) = c sqrt(x): shrink/grow x geometrically to bracket, then bisect.
        lo, hi = x, x
        while float(self.profile.g(lo)) > c * math.sqrt(lo) and lo > 1e-300:
            lo *= 0.5
        while float(self.profile.g(hi)) < c * math.sqrt(hi) and hi < 1e300:
            hi *= 2.0
        for _ in range(200):
            mid = math.sqrt(lo * hi)
            if float(self.profile.g(mid)) < c * math.sqrt(mid):
                lo = mid
            else:
                hi = mid
            if hi <= lo * (1.0 + 1e-12):
                break
        return hi


class _ClosedForm:
    """Elastic contact in closed form: state is only the contact radius (hysteresis)."""

    name = "closed_form"

    def __init__(self, physics: _Physics) -> None:
        self.physics = physics
        profile = physics.profile
        self.punch_radius = getattr(profile, "punch_radius", None)
        if profile.kind == "power_law":
            self.exponent = float(profile.exponent)
        else:
            self.exponent = _CLOSED_FORM_EXPONENT.get(profile.kind, 0.0)
        self.radius = 0.0

    @staticmethod
    def eligible(physics: _Physics) -> str:
        """Empty if the scene has a closed form, else the reason why not."""
        if physics.creep.kelvin_count:
            return "the material has Kelvin elements (memory)"
        if physics.profile.kind not in ("sphere", "cone", "flat_punch", "power_law"):
            return f"indenter.shape {physics.profile.kind!r} has no closed form"
        if (
            physics.profile.kind == "power_law"
            and physics.work_of_adhesion > 0.0
            and physics.profile.exponent <= 0.5
        ):
            return "a power law with exponent <= 0.5 has no adhesive equilibrium"
        return ""

    # -- the edge law -------------------------------------------------------------------
    def _gap(self, depth: float, radius: float) -> float:
        return depth - float(self.physics.profile.g(radius)) + self.physics.c_crit * math.sqrt(radius)

    def _fold(self) -> tuple[float, float]:
        """(radius, depth) of the fold of the edge law: the last displacement-stable point."""
        c = self.physics.c_crit
        if self.punch_radius is not None:
            return self.punch_radius, -c * math.sqrt(self.punch_radius)
        if c == 0.0:
            return 0.0, 0.0
        n = self.exponent
        k = float(self.physics.profile.g(1.0))
        radius = (c / (2.0 * n * k)) ** (1.0 / (n - 0.5))
        return radius, k * radius**n - c * math.sqrt(radius)

    def _outer_root(self, depth: float) -> float:
        """Contact radius on the outer branch at `depth`, 0 if the branch does not reach it."""
        fold_radius, fold_depth = self._fold()
        if depth < fold_depth:
            return 0.0
        if self.punch_radius is not None:
            return self.punch_radius
        if self.physics.c_crit == 0.0:
            return float(self.physics.profile.radius_at_height(depth))
        hi = max(2.0 * fold_radius, float(self.physics.profile.radius_at_height(max(depth, 0.0))))
        while self._gap(depth, hi) >= 0.0:
            hi *= 2.0
        if self._gap(depth, fold_radius) <= 0.0:
            return fold_radius
        return brent_root(lambda a: self._gap(depth, a), fold_radius, hi, xtol=1e-15 * hi, rtol=1e-15)

    def _radius_after(self, depth: float) -> float:
        if self.radius > 0.0:
            return self._outer_root(depth)
        return self._outer_root(depth) if depth >= 0.0 else 0.0

    # -- energies -----------------------------------------------------------------------
    def _potential(self, depth: float, radius: float) -> float:
        """Stored elastic energy minus surface energy w pi a^2, J."""
        if radius <= 0.0:
            return 0.0
        profile = self.physics.profile
        g = float(profile.g(radius))
        g_int = float(profile.g_integral(radius))
        g2_int = 0.0 if self.punch_radius is not None else radius * g * g / (2.0 * self.exponent + 1.0)
        stored = self.physics.e0 * (depth * depth * radius - 2.0 * depth * g_int + g2_int)
        return stored - self.physics.work_of_adhesion * math.pi * radius * radius

    def force(self, depth: float, radius: float) -> float:
        if radius <= 0.0:
            return 0.0
        return 2.0 * self.physics.e0 * (depth * radius - float(self.physics.profile.g_integral(radius)))

    # -- model interface ----------------------------------------------------------------
    def advance(self, d0: float, d1: float, dt: float) -> tuple[float, float, float]:
        """Move from depth d0 to d1; returns (radius, force, work input J). Exact work: the
        potential changes along the branch, F = 0 off it, jumps dissipate."""
        r0 = self.radius
        r1 = self._radius_after(d1)
        if r0 > 0.0 and r1 > 0.0:
            work = self._potential(d1, r1) - self._potential(d0, r0)
        elif r0 > 0.0:
            fold_radius, fold_depth = self._fold()
            work = self._potential(fold_depth, fold_radius) - self._potential(d0, r0)
        elif r1 > 0.0:
            work = self._potential(d1, r1) - self._potential(0.0, self._outer_root(0.0))
        else:
            work = 0.0
        self.radius = r1
        return r1, self.force(d1, r1), work

    def stored_energy(self, depth: float) -> float:
        return self._potential(depth, self.radius) + self.physics.work_of_adhesion * math.pi * self.radius**2

    def energy_dissipated(self, energy_input: float, depth: float) -> float:
        """Input minus the potential: exact on this path (zero along a branch, the jump's
        loss at snap-in and pull-off), J."""
        return (
            energy_input
            - self.stored_energy(depth)
            + self.physics.work_of_adhesion * math.pi * self.radius * self.radius
        )

    def edge_gaps(self, depth: float) -> tuple[float, float]:
        gap = self._gap(depth, self.radius)
        return gap, gap

    def edge_height(self, radius: float) -> float:
        """Profile g at `radius`, m."""
        return float(self.physics.profile.g(radius))

    @property
    def edge_resolution(self) -> float:
        """Radius change below which the edge counts as at rest, m: the closed form's radius
        is exact, so any change is a motion."""
        return 0.0

    def is_relaxed(self) -> bool:
        return True

    def begin(self) -> float:
        """Start a transaction (`ContactSimulator.step`): the token `rollback` takes."""
        return self.radius

    def rewind(self, state: float) -> None:
        """`set_state` for a trial of the force search (the state is one of this model's)."""
        self.radius = state

    def rollback(self, token: float) -> None:
        self.radius = token

    def prepare_ahead(self) -> None:
        """Nothing to prepare after a step: the closed form has no domain."""

    def get_state(self) -> float:
        return self.radius

    def set_state(self, state: float) -> None:
        self.radius = state

    def reset(self) -> None:
        self.radius = 0.0


#: A contact radius beyond this fraction of the domain starts computing the next domain's
#: geometry ahead, one slice of fine points per step (`_prepare_growth`): at least
#: `PREPARE_POINTS`, and enough that the points left to evaluate take at most
#: `PREPARE_STEPS` steps (a fixed slice took ~m / 4096 steps, 32 at N = 8192, more than a
#: pressed contact takes from half the domain to its end: the growth then evaluated the
#: rest inside its step).
PREPARE_FRACTION = 0.5
PREPARE_POINTS = 4096
PREPARE_STEPS = 4


class _TimeStepped:
    """The 1D MDR row of creep elements (see `_kernels`)."""

    name = "time_stepped"

    def __init__(self, physics: _Physics, numerics: ResolvedNumerics) -> None:
        self.physics = physics
        self.numerics = numerics
        # Read every kernel call (the numerics are frozen).
        self._max_substep = float(numerics.max_substep)
        self._max_edge_cells = float(numerics.max_edge_cells)
        # The longest step the kernel may take, s: MAX_SUBSTEPS substeps of max_substep (inf
        # without it). A longer step is refused before the kernel runs (`advance`, the lean
        # paths of `ContactSimulator.step` leave it to `advance`).
        self._longest_step = self._max_substep * MAX_SUBSTEPS if self._max_substep > 0.0 else math.inf
        # The constants every kernel call reads (`_kernels.step_params`: those two and, for the
        # derived outputs, E_r* and the critical edge speeds), passed as one address.
        v_c1, v_c2 = (float(v) for v in physics.critical_speeds)
        self._params = _kernels.step_params(
            self._max_substep, self._max_edge_cells, float(physics.e_relaxed), v_c1, v_c2
        )
        self._params_address = self._params.ctypes.data
        # The compiled step (`_kernels._step_packed`) called through its entry point; loaded
        # (or compiled) with the first time-stepped model.
        global _STEP
        if _STEP is None:
            _STEP = _kernels.step_entry()
        creep = physics.creep
        e_kelvin = np.array([creep.modulus_star(g) for g in creep.kelvin_shear_moduli], dtype=np.float64)
        # Dampers scale like springs: eta* = 2 eta / (1 - nu).
        eta_kelvin = np.array([creep.modulus_star(v) for v in creep.kelvin_viscosities], dtype=np.float64)
        self.e_kelvin = e_kelvin
        # Steady in-contact share of each Kelvin element in the total elongation.
        self.steady = physics.e_relaxed / e_kelvin if e_kelvin.size else np.zeros(0)
        self.rate = e_kelvin / eta_kelvin if e_kelvin.size else np.zeros(0)
        self.p, self.p_inv, self.lam, self.beta = _modal_chain(physics.e0, e_kelvin, eta_kelvin)
        self.punch_radius = getattr(physics.profile, "punch_radius", None)
        self.initial_length = _first_domain(physics, numerics)
        if numerics.domain_radius <= 0.0 and not self.initial_length <= FIRST_DOMAIN_LIMIT:
            # A profile that rises slower than the adhesive neck (a power law with exponent
            # <= 0.5 and a tiny coefficient): the neck radius search ran to 1e300 m and the
            # first row's element width overflowed (a traceback from `Row`, 0.8.0's tester).
            raise ConfigError(
                f"no first domain: the adhesive neck where contact starts has a radius of "
                f"{self.initial_length:.3g} m (over {FIRST_DOMAIN_LIMIT:g} m): adhesion beats the "
                "profile's rise; make the indenter steeper or work_of_adhesion smaller"
            )
        # The first contact's domain, built once here (about 0.1 ms: the fine profile grid and
        # its checks) rather than inside the snap-in step; each new contact takes a copy of
        # it with zero memory.
        # Index arrays of the centre and fine grids (their coordinates are these times the
        # spacing, as np.arange and np.linspace compute them), and the first row built: later
        # rows take its chain (`Row.regrid`).
        n = numerics.elements
        self._centre_index = np.arange(n) + 0.5
        self._fine_index = np.arange(0, n * numerics.fine_factor + 1, dtype=np.float64)
        self._chain_row: _kernels.Row | None = None
        # The next domain's geometry being computed ahead (`_prepare_growth`): [length,
        # fine points done, gf, gint (views into the next row's constant buffer), centre
        # profile or None, fine points per step, that buffer, and the row once built].
        self._prepared: list | None = None
        # The row `advance` last checked and the contact radius beyond which it prepares
        # (inf once the preparation for that row is complete or impossible).
        self._prepare_row: _kernels.Row | None = None
        self._prepare_radius = math.inf
        self._template: _kernels.Row | None = None
        if self.initial_length > 0.0:
            self._template = self._build_row(self.initial_length, None)
        self.row: _kernels.Row | None = None
        self.radius = 0.0
        self.substeps = 0
        # Energy dissipated since the last reset, J: a running sum of the kernel's
        # non-negative losses per step (so it never decreases).
        self.dissipated = 0.0
        # Largest |wsum| (m) the last `advance` left, None once the state changed otherwise.
        self._memory_peak: float | None = None
        # The transaction journal (`begin`/`rollback`): the row whose `txn` buffers hold its
        # memory from before the transaction's first kernel call, None before that call.
        self._journal: _kernels.Row | None = None
        # Edge outputs of the last `advance` (gaps outside/inside, g at the edge) and its depth.
        self._edge = (0.0, 0.0, 0.0)
        self._edge_depth = math.nan
        # (row, radius, depth, force) of the last `advance`: the force its kernel ended with, at
        # that radius and depth on the row's memory as it left it. The next step starts there,
        # so the kernel is handed that force instead of integrating it again (the same bits).
        # Valid while only `advance` writes the row's memory: everything else that does
        # (set_state, rewind, rollback, reset, drop_memory, advance_rows) drops it or, for a
        # rollback, puts back the one from the transaction's start.
        self._force_at: tuple | None = None
        # Rows the force search's rewinds would otherwise build again (`rewind`, `_ensure_row`,
        # `_grow`; caches only, not state): a clone of the template a trial made from no row
        # and the rewind dropped (with the buffers of a fresh clone), and the last growth
        # (source row, its radius and memory, the
        # grown row's buffers as it was built).
        self._spare: _kernels.Row | None = None
        self._fresh_state: np.ndarray | None = None
        self._grown: tuple | None = None
        if self._template is not None:
            # The first contact's row cloned now, not inside the first step that touches (a
            # snap-in, the scene's dearest step: ~40 us of it): `_ensure_row` takes the spare.
            self._spare = self._template.with_memory(np.zeros_like(self._template.wl))
            self._fresh_state = self._spare._state.copy()
        # The fine point where the glass modulus' JKR curve on the first domain has its
        # force minimum (`glass_contact`), found on first use.
        self._glass_lowest: int | None = None

    def __getstate__(self) -> dict:
        # A copy (pickle, deepcopy) has its own `_params`: its address is found again on load.
        state = dict(self.__dict__)
        del state["_params_address"]
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._params_address = self._params.ctypes.data

    # -- the domain ---------------------------------------------------------------------
    def _build_row(
        self,
        length: float,
        memory: np.ndarray | None,
        unit: np.ndarray | None = None,
        centre_profile: np.ndarray | None = None,
        fine_profile: tuple[np.ndarray, np.ndarray, float] | None = None,
        const: np.ndarray | None = None,
    ) -> _kernels.Row:
        """The row over (0, length] (capped at the reach) with Kelvin state `memory`, `unit`
        (None: zeros) and, if the caller has them, the profile at its centres and
        (`_prepare_growth`) on its fine grid with the integral and the fine spacing."""
        n = self.numerics.elements
        m = n * self.numerics.fine_factor + 1
        profile = self.physics.profile
        reach = math.inf
        if self.punch_radius is not None:
            reach = self.punch_radius
            length = min(length, reach)
        dx = length / n
        if centre_profile is None:
            centre_profile = np.asarray(profile.g(self._centre_index * dx), dtype=np.float64)
        k = self.e_kelvin.size
        wl = np.zeros((n, k)) if memory is None else memory
        if fine_profile is not None:
            gf, gint, df = fine_profile
        else:
            # np.linspace(0, length, m) by its own arithmetic (index times the step, the end
            # point set exactly) on the cached index: the same array, without its overhead.
            step = length / (m - 1)
            if step > 0.0:
                fine = self._fine_index * step
                fine[-1] = length
            else:
                fine = np.linspace(0.0, length, m)
            gf = np.asarray(profile.g(fine), dtype=np.float64)
            gint = np.asarray(profile.g_integral(fine), dtype=np.float64)
            df = fine[1]
        chain = self._chain_row
        if chain is not None:
            return chain.regrid(
                dx=dx, g_c=centre_profile, gf=gf, gint=gint, df=df, reach=reach, wl=wl, wb=unit, const=const
            )
        row = _kernels.Row(
            dx=dx,
            g_c=centre_profile,
            gf=gf,
            gint=gint,
            df=df,
            reach=reach,
            wl=wl,
            p=self.p,
            p_inv=self.p_inv,
            lam=self.lam,
            beta=self.beta,
            rate=self.rate,
            e_kelvin=self.e_kelvin,
            steady=self.steady,
            e0=self.physics.e0,
            c_crit=self.physics.c_crit,
            wb=unit,
        )
        self._chain_row = row
        return row

    def glass_contact(self, force: float) -> tuple[float, float] | None:
        """The instantaneous (glass) adhesive contact that carries `force` (N) on a body at
        rest: (depth m, stiffness dF/dd N/m) on the stable branch of the JKR curve of the
        glass modulus (MDR: F = 2 E0* (a g(a) - int_0^a g) - 2 E0* dl_c(a) a, d = g(a) -
        dl_c(a)), between the first domain's fine points (bisection over them: the curve
        falls to its minimum, then rises); None without such a domain, below the curve's
        force minimum or beyond the domain. From rest a step responds with the glass
        modulus, so this is close to where a force step from rest ends (a start for its
        search, checked by its trials)."""
        template = self._template
        if template is None:
            return None
        gf, gint, df = template.gf, template.gint, template.df
        last = gf.shape[0] - 1
        c = self.physics.c_crit
        scale = 2.0 * self.physics.e0

        def point(i: int) -> tuple[float, float]:
            x = i * df
            root = math.sqrt(x)
            g = gf.item(i)
            return scale * (x * g - gint.item(i) - c * x * root), g - c * root

        lowest = self._glass_lowest
        if lowest is None:
            # The first fine point where the curve stops falling.
            lo, hi = 0, last
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if point(mid + 1)[0] > point(mid)[0]:
                    hi = mid
                else:
                    lo = mid
            lowest = self._glass_lowest = hi
        f_lo, d_lo = point(lowest)
        f_hi, d_hi = point(last)
        if not f_lo < force < f_hi:
            return None
        lo, hi = lowest, last
        while hi - lo > 1:
            mid = (lo + hi) // 2
            f_mid, d_mid = point(mid)
            if f_mid < force:
                lo, f_lo, d_lo = mid, f_mid, d_mid
            else:
                hi, f_hi, d_hi = mid, f_mid, d_mid
        if not (f_hi > f_lo and d_hi > d_lo):
            return None
        stiffness = (f_hi - f_lo) / (d_hi - d_lo)
        return d_lo + (force - f_lo) / stiffness, stiffness

    def _prepare_growth(self, row: _kernels.Row) -> None:
        """One slice of the next domain's geometry (length L x growth_factor: its fine
        profile and integral, then its centre profile), so that a growth, when it comes,
        does not evaluate the profile inside its step. The same values as `_build_row`
        computes (the profile is elementwise: a slice of the grid gives the slice of its
        values; tests/test_row_regrid.py); a pure function of the length, so not part of
        the state (transactions and snapshots ignore it)."""
        length = row.length * self.numerics.growth_factor
        reach = self.punch_radius if self.punch_radius is not None else math.inf
        span = min(length, reach)
        prepared = self._prepared
        if prepared is None or prepared[0] != length:
            if length > _largest_domain(self.initial_length):
                self._prepare_radius = math.inf
                return
            m = self._fine_index.shape[0]
            # The fine profile is written straight into the next row's constant buffer.
            const, gf, gint = _kernels.regrid_buffer(row.wl.shape[0], row.wl.shape[1], m)
            filled = 0
            step = span / (m - 1)
            if step > 0.0 and row.gf.shape[0] == m and step == 2.0 * row.df:
                # The new fine point j is the old point 2j, bit for bit: j (2 s) and (2 j) s
                # both round the same exact product (s = row.df, the old step, exactly: the
                # old grid is index times s, `_build_row`), and the profile is elementwise.
                # So the inner half of the new grid is a strided copy of the old one; the
                # old last point (set to the old span, not computed) is not reused.
                filled = m // 2
                gf[:filled] = row.gf[: 2 * filled : 2]
                gint[:filled] = row.gint[: 2 * filled : 2]
            points = max(PREPARE_POINTS, -(-(m - filled) // PREPARE_STEPS))
            prepared = self._prepared = [length, filled, gf, gint, None, points, const]
        filled, gf, gint = prepared[1], prepared[2], prepared[3]
        if prepared[4] is not None:
            # The last step: the row itself (its constant buffer: the geometry, block
            # extremes and chain; its state with zero memory), so that a growth only remaps
            # the memory into it. A profile the row refuses (not finite) is left to the
            # growth, which raises as before.
            self._prepare_radius = math.inf
            if len(prepared) == 7:
                try:
                    zeros = np.zeros_like(row.wl)
                    built = self._build_row(
                        length,
                        zeros,
                        zeros,
                        prepared[4],
                        (gf, gint, span / (gf.shape[0] - 1)),
                        const=prepared[6],
                    )
                except ValueError:
                    return
                prepared.append(built)
            return
        m = gf.shape[0]
        step = span / (m - 1)
        if not step > 0.0:
            self._prepare_radius = math.inf
            return
        profile = self.physics.profile
        if filled < m:
            end = min(filled + prepared[5], m)
            fine = self._fine_index[filled:end] * step
            if end == m:
                fine[-1] = span
            gf[filled:end] = np.asarray(profile.g(fine), dtype=np.float64)
            gint[filled:end] = np.asarray(profile.g_integral(fine), dtype=np.float64)
            prepared[1] = end
            if end < m:
                return
        # The centres (N points, 1 / fine_factor of the fine grid's) with the last fine slice.
        dx = span / self.numerics.elements
        prepared[4] = np.asarray(profile.g(self._centre_index * dx), dtype=np.float64)

    def _grow(self, depth: float) -> None:
        """Grow the domain, remapping the memory side by side of the edge (`remap_memory`)
        at the current depth (m)."""
        row = self.row
        assert row is not None
        grown = self._grown
        if (
            grown is not None
            and grown[0] is row
            and grown[1] == self.radius
            and np.array_equal(grown[2], row.wl)
            and np.array_equal(grown[3], row.wb)
        ):
            # The same growth from the same state again (the force search's next trial after
            # a rewind): the row it built, back to the state it was built with (zeros, a
            # fresh coefficient workspace and the remapped memory, as `Row.regrid` fills it;
            # kept as the memory alone, not a copy of the whole state: ~6 N K values).
            target = grown[4]
            target._state.fill(0.0)
            target.coef[...] = _kernels.coefficient_workspace(target.wl.shape[1])
            target.set_memory(grown[5], grown[6])
            self.row = target
            return
        length = row.length * self.numerics.growth_factor
        limit = _largest_domain(self.initial_length)
        if length > limit:
            raise InputError(self._unrepresentable(limit))
        reach = self.punch_radius if self.punch_radius is not None else math.inf
        span = min(length, reach)
        dx = span / row.elements
        prepared = self._prepared
        fine_profile = None
        if prepared is not None and prepared[0] == length and len(prepared) == 8:
            # The row prepared ahead (`_prepare_growth`, zero memory, never stepped): the
            # memory remapped into its state, summed as `Row.regrid` sums it (numpy's order),
            # the same buffers as building it here.
            target = prepared[7]
            if target.wl.shape == row.wl.shape:
                memory, unit = target.wl, target.wb
                _kernels._remap(
                    row.wl, row.wb, float(self.radius), row.dx, row.g_c, target.dx, prepared[4], memory, unit
                )
                if _kernels._all_finite(memory.reshape(-1)) and _kernels._all_finite(unit.reshape(-1)):
                    np.sum(memory, axis=1, out=target.wsum)
                    np.sum(unit, axis=1, out=target.bsum)
                    self._prepared = None
                    self.row = target
                    self._grown = (
                        row,
                        self.radius,
                        row.wl.copy(),
                        row.wb.copy(),
                        target,
                        memory.copy(),
                        unit.copy(),
                    )
                    return
                memory[...] = 0.0
                unit[...] = 0.0
        if prepared is not None and prepared[0] == length and prepared[4] is not None:
            centres = prepared[4]
            fine_profile = (prepared[2], prepared[3], span / (prepared[2].shape[0] - 1))
        else:
            centres = np.asarray(self.physics.profile.g(self._centre_index * dx), dtype=np.float64)
        # `remap_memory` without its checks: the radius and span are this model's own, the
        # centre profile is checked by the new row.
        memory = np.empty_like(row.wl)
        unit = np.empty_like(row.wl)
        _kernels._remap(row.wl, row.wb, float(self.radius), row.dx, row.g_c, dx, centres, memory, unit)
        self.row = self._build_row(length, memory, unit, centres, fine_profile)
        # (`memory` and `unit` were copied into the row: kept as they are.)
        self._grown = (row, self.radius, row.wl.copy(), row.wb.copy(), self.row, memory, unit)

    def _unrepresentable(self, limit: float) -> str:
        """Why a contact that needs a domain longer than ``limit`` (m) cannot be stepped."""
        reach = float(np.asarray(self.physics.profile.g(limit)))
        return (
            "the contact would outgrow the largest domain this contact can represent (a contact "
            f"radius of {limit:.3g} m, for this indenter a depth of about {reach:.3g} m): the depth "
            "is beyond the scene's range, or adhesion beats the profile's rise"
        )

    def _ensure_row(self, depth: float) -> bool:
        """Create the row if the indenter may touch; False if the step is trivially free."""
        if self.row is not None:
            return True
        if depth < 0.0:
            return False
        template = self._template
        if template is not None:
            spare = self._spare
            if spare is not None and self._fresh_state is not None:
                # The clone a force trial made and its rewind dropped, back to the buffers of
                # a fresh clone.
                self._spare = None
                spare._state[...] = self._fresh_state
                self.row = spare
            else:
                self.row = template.with_memory(np.zeros_like(template.wl))
                self._fresh_state = self.row._state.copy()
            return True
        length = 1.25 * float(self.physics.profile.radius_at_height(depth))
        if not length > 0.0:
            return False
        self.row = self._build_row(length, None)
        return True

    # -- model interface ----------------------------------------------------------------
    def advance(self, d0: float, d1: float, dt: float) -> tuple[float, float, float]:
        row = self.row
        if row is None:
            if not self._ensure_row(max(d0, d1)):
                self.substeps = 0
                return 0.0, 0.0, 0.0
            row = self.row
            assert row is not None
        if dt > self._longest_step:
            raise _too_many_substeps(dt, self._max_substep)
        # The first kernel call of the transaction on this row journals its memory into the
        # row's `txn` buffers (inside the compiled call, before the kernel writes anything)
        # instead of a snapshot of numpy copies. `_journal` is set just before that call: no
        # Python code runs between the two, and once it returned the journal is valid.
        journal = self._journal is not row
        start = None if journal else self.get_state()
        radius0, dissipated0 = self.radius, self.dissipated
        force_prev = self._start_force(row, d0)
        self._force_at = None
        while True:
            row = self.row
            if journal:
                self._journal = row
            # The kernel itself, not the validating wrapper: the row's arrays are checked
            # when built, the step's scalars by ContactSimulator.step.
            # (`_step_packed`'s phase and speed outputs are not needed here: `_publish` makes them.)
            # The step's own work (-0.0 + work) and the dissipated energy's new total.
            state, const = row.addresses
            result = _STEP(
                state,
                const,
                self._params_address,
                journal,
                self.radius,
                d0,
                d1,
                dt,
                force_prev,
                self.radius,
                -0.0,
                dissipated0,
            )
            journal = False
            if result[0] != _kernels.STATUS_GROW:
                # (STATUS_OVERFLOW too: the caller refuses a step whose energies overflow.)
                break
            force_prev = math.nan  # a new row after the growth
            if start is None:
                _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
            else:
                self.set_state(start)
            self.radius, self.dissipated = radius0, dissipated0
            self._grow(d0)
            start = self.get_state()
        self._stepped(row, result, d1)
        return result[1], result[2], result[3]

    def let_go_depth(self) -> float:
        """Where the last kernel call's contact let go (`_kernels.OUT_LET_GO`), m; NaN when it
        did not (or no call ran on the row)."""
        row = self.row
        return float(row.out[_kernels.OUT_LET_GO]) if row is not None else math.nan

    def _start_force(self, row: _kernels.Row, d0: float) -> float:
        """The force at the start of a step from depth `d0` (m) on `row`, N, when the last
        kernel call ended there (same row, radius and depth), else NaN: the kernel integrates
        it. A signed zero depth could give the force another sign of zero: integrated then."""
        known = self._force_at
        if known is not None and known[0] is row and known[1] == self.radius and known[2] == d0 and d0 != 0.0:
            return known[3]
        return math.nan

    def _stepped(self, row: _kernels.Row, result: tuple, d1: float) -> None:
        """The model's fields after a kernel call on `row` that stepped to depth `d1` (m):
        `result` is `_STEP`'s tuple (given the energy dissipated before the call: its new
        total)."""
        radius = result[1]
        self.radius = radius
        self.substeps = result[4]
        self.dissipated = result[5]
        self._memory_peak = result[6]
        self._edge = result[7]
        self._edge_depth = d1
        self._force_at = (row, radius, d1, result[2])

    def prepare_ahead(self) -> None:
        """After a public step: one slice of the next domain's geometry when the contact has
        passed PREPARE_FRACTION of its domain (`_prepare_growth`). Once per step, not per
        kernel call: a force search's trials each prepared a slice, so a zero force from rest
        (4 snap-in trials) computed and built the whole next domain inside its one step
        (0.8.0). Changes no output (the geometry is a pure function of the length)."""
        row = self.row
        if row is None:
            return
        if row is not self._prepare_row:
            # A new row (a growth in this step: its next domain is prepared from the next step).
            self._prepare_row = row
            self._prepare_radius = PREPARE_FRACTION * row.length
        elif self.radius > self._prepare_radius:
            self._prepare_growth(row)

    def advance_rows(
        self, sim: ContactSimulator, times: np.ndarray, depths: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Advance through a depth history from ``sim``'s time and depth as `sim._trial`
        then `advance` would row by row; returns per row (radius m, force N, work J, energy
        dissipated since the last reset J, edge gaps and g at the edge (n, 3) m: exterior
        memory, interior memory, profile, and the `edge_resolution` of the row that stepped
        it, m: what `step` reads after the same step; 0 for a row without a domain).
        Rows without a row (no domain yet, or idle above the surface) cost nothing here
        either."""
        n = times.size
        rows = np.zeros((n, _kernels.ROW_SIZE))
        resolution = np.zeros(n)
        self._force_at = None
        t_prev, d_prev = sim.time, sim._depth
        radius = sim.output.contact_radius
        i = 0
        while i < n:
            if self.row is None and not self._ensure_row(max(d_prev, depths[i])):
                # No domain and nothing to touch (row i is free, as `advance` finds): free
                # rows until the indenter may touch.
                touch = np.flatnonzero(np.maximum(depths[i + 1 :], depths[i:-1]) >= 0.0)
                j = n if touch.size == 0 else i + 1 + int(touch[0])
                self.substeps = 0
                t_prev, d_prev, radius = float(times[j - 1]), float(depths[j - 1]), 0.0
                i = j
                continue
            row = self.row
            assert row is not None
            peak = self._memory_peak
            if peak is None:
                peak = float(np.max(np.abs(row.wsum), initial=0.0))
            backup = np.empty_like(row.wl)
            first = i
            i, status = _kernels._advance_rows(
                *row.kernel_args,
                backup,
                np.empty_like(row.wl),
                radius,
                t_prev,
                d_prev,
                peak,
                times,
                depths,
                i,
                self.numerics.max_substep,
                self.numerics.max_edge_cells * row.dx,
                self.numerics.idle_tolerance * row.length,
                rows,
            )
            resolution[first:i] = self.edge_resolution
            if i > 0:
                last = rows[i - 1]
                radius = float(last[_kernels.OUT_RADIUS])
                t_prev, d_prev = float(times[i - 1]), float(depths[i - 1])
                self.radius = radius
                self.substeps = int(last[_kernels.OUT_SUBSTEPS])
                self._memory_peak = float(last[_kernels.OUT_MEMORY])
            if status == _kernels.STATUS_IDLE:
                self.drop_memory()
            elif status == _kernels.STATUS_GROW:
                self._grow(d_prev)
        out = rows[:, : _kernels.OUT_SIZE]
        dissipated = self.dissipated + np.cumsum(out[:, _kernels.OUT_DISSIPATED])
        self.dissipated = float(dissipated[-1])
        return (
            out[:, _kernels.OUT_RADIUS].copy(),
            out[:, _kernels.OUT_FORCE].copy(),
            out[:, _kernels.OUT_WORK].copy(),
            dissipated,
            rows[:, _kernels.OUT_GAP_OUTSIDE : _kernels.OUT_G_EDGE + 1].copy(),
            resolution,
        )

    def stored_energy(self, depth: float) -> float:
        """Elastic energy of all springs at `depth` (m), J (computed on demand)."""
        if self.row is None:
            return 0.0
        return _kernels.stored_energy(self.row, self.radius, depth)

    def energy_dissipated(self, energy_input: float, depth: float) -> float:
        """Energy dissipated since the last reset, J: the running sum of the kernel's
        non-negative per-step losses (viscous work and adhesion hysteresis)."""
        return self.dissipated

    def edge_gaps(self, depth: float) -> tuple[float, float]:
        """h at the edge with the exterior and with the interior memory, m."""
        assert self.row is not None
        if depth == self._edge_depth:
            return self._edge[0], self._edge[1]  # the last advance computed them
        return (
            _kernels.criterion_gap(self.row, self.radius, depth, self.radius, interior=False),
            _kernels.criterion_gap(self.row, self.radius, depth, self.radius, interior=True),
        )

    @property
    def edge_resolution(self) -> float:
        """Radius change below which the edge counts as at rest, m: twice the tolerance the
        kernel locates an edge to (`_kernels.EDGE_TOLERANCE` of an element), since an edge at
        rest is located again every step and lands anywhere within it (a pinned elastic
        edge otherwise read INDENTING and DETACHING on alternate steps)."""
        row = self.row
        return 0.0 if row is None else 2.0 * _kernels.EDGE_TOLERANCE * row.dx

    def edge_height(self, radius: float) -> float:
        """Profile g at the edge `radius` (m), m, as the kernel sees it (fine grid)."""
        if radius == self.radius and self._edge_depth == self._edge_depth and radius > 0.0:
            return self._edge[2]
        if self.row is None or radius <= 0.0:
            return float(self.physics.profile.g(radius))
        return float(_kernels._g_at(radius, self.row.gf, self.row.df))

    def trial_start(self) -> tuple:
        """`get_state` without the copies of the memory, for `rewind` inside the step that
        took it (the force search): the memory comes back from the transaction's journal,
        which the step's first kernel call on the row writes."""
        return (self.radius, self.row, None, None, self.dissipated)

    def rewind(self, state: tuple) -> None:
        """Back to `state` (from `get_state` of this model, or `trial_start` in this step)
        for the next trial of the force search: the memory copied back in compiled code,
        without `set_state`'s validation (the arrays are the model's own copies) when the row
        is still the same."""
        radius, row, memory, unit, dissipated = state
        current = self.row
        if row is not None and memory is None:
            # `trial_start`: the row the step started on, the model's own.
            if self._journal is row:
                # The kernel wrote it since: its memory back from the journal, which the
                # next kernel call writes again (the same values) instead of `advance`
                # copying the state for a growth.
                _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
                self._journal = None
            # else no kernel call wrote it in this step (a trial dropped it as idle).
            self.row = row
            self.radius = radius
            self.dissipated = dissipated
            self._memory_peak = None
            self._edge_depth = math.nan
            self._force_at = None
            return
        if row is None:
            # The step started without a row: a row the trial made is this step's own; keep
            # a clone of the template for the next trial (`_ensure_row`) instead of another.
            template = self._template
            if current is not None and template is not None and current._const is template._const:
                self._spare = current
            self.set_state(state)
            return
        if row is not current and row is not self._journal:
            self.set_state(state)
            return
        # The row the step started on (the trial may have grown the domain: the transaction
        # journalled that row, the model's own), its memory copied back.
        self.row = row
        _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, memory, unit)
        self.radius = radius
        self.dissipated = dissipated
        self._memory_peak = None
        self._edge_depth = math.nan
        self._force_at = None

    def begin(self) -> tuple:
        """Start a transaction (`ContactSimulator.step`): a token of the scalars; the memory
        is journalled by the first kernel call (`advance`), so a step that succeeds copies
        nothing but that."""
        self._journal = None
        return (
            self.radius,
            self.row,
            self.dissipated,
            self._memory_peak,
            self._edge,
            self._edge_depth,
            self._force_at,
        )

    def rollback(self, token: tuple) -> None:
        """Undo everything since `begin` returned `token`."""
        journal = self._journal
        if journal is not None:
            _kernels._restore_state(
                journal.wl, journal.wsum, journal.wb, journal.bsum, journal.txn, journal.txn_b
            )
            self._journal = None
        # The memory is back to the transaction's start, so is the force known on it.
        (
            self.radius,
            self.row,
            self.dissipated,
            self._memory_peak,
            self._edge,
            self._edge_depth,
            self._force_at,
        ) = token

    def is_relaxed(self) -> bool:
        if self.row is None:
            return True
        if self.radius > 0.0:
            return False
        peak = self._memory_peak
        if peak is None:
            peak = float(np.max(np.abs(self.row.wsum), initial=0.0))
        return peak <= self.numerics.idle_tolerance * self.row.length

    def drop_memory(self) -> None:
        """Forget a relaxed, out-of-contact state: the next contact sizes a fresh domain."""
        self.row = None
        self._memory_peak = None
        self._force_at = None

    def get_state(self) -> tuple:
        if self.row is None:
            return (self.radius, None, None, None, self.dissipated)
        return (self.radius, self.row, self.row.wl.copy(), self.row.wb.copy(), self.dissipated)

    def set_state(self, state: tuple) -> None:
        radius, row, memory, unit, dissipated = state
        self.radius = radius
        self.dissipated = dissipated
        self._memory_peak = None
        self._edge_depth = math.nan
        self._force_at = None
        if row is None:
            self.row = None
        elif row is self.row:
            row.set_memory(memory, unit)
        else:
            # A snapshot of another simulator (or of a replaced domain): never share the
            # mutable arrays of a row between simulators.
            self.row = row.with_memory(memory, unit)

    def reset(self) -> None:
        self.radius = 0.0
        self.row = None
        self.dissipated = 0.0
        self._memory_peak = None
        self._journal = None
        self._edge_depth = math.nan
        self._force_at = None


def _phase(model: Any, physics: _Physics, depth: float, r0: float, radius: float, g_edge: float) -> Phase:
    """The phase of a step that moved the edge from `r0` to `radius` (m) at `depth` (m), g at
    the new edge `g_edge` (m). The one rule for `step`'s lean and general paths
    (`ContactSimulator.step_depths` applies the same rule to columns).

    An edge that moved less than the model's `edge_resolution` is at rest (a time-stepped
    edge is located again every step and lands anywhere within its tolerance); a pinned edge
    says which criterion it rests on, if any (elastic contacts at rest sit on both; a punch
    rim blocks attachment). The gaps are read only for a pinned edge (after a step the
    time-stepped model returns the ones its kernel computed)."""
    if radius <= 0.0:
        return _NO_CONTACT
    rest = model.edge_resolution
    if radius > r0 + rest:
        return _INDENTING
    if radius < r0 - rest:
        return _DETACHING
    tol = 1e-9 * (abs(depth) + physics.c_crit * math.sqrt(radius) + g_edge)
    outside, inside = model.edge_gaps(depth)
    if outside >= -tol:
        return _INDENTING
    if inside <= tol:
        return _DETACHING
    return _STICKING


#: The force search's predicted secant gives way to the bracketing search where the slope
#: dF/dd is below this fraction of the glass stiffness 2 E0* a (near the fold of F(d); away
#: from it a step's slope is 0.46 to 1 times the glass stiffness on the bench's history).
FOLD_SLOPE = 0.3

#: The largest first domain (m) a time-stepped contact starts from (`_TimeStepped`): the
#: largest `numerics.domain_radius` a scene may give, too.
FIRST_DOMAIN_LIMIT = DOMAIN_RADIUS_RANGE[1]

#: The shortest time step (s) a step takes; a shorter one (other than none: a jump at one
#: time) is refused. Below it the substep control halved steps to zero (a ZeroDivisionError
#: at 6e-322 s) and an edge speed overflowed.
MIN_TIME_STEP = 1e-300


def _first_domain(physics: Any, numerics: Any) -> float:
    """The first domain's length of a time-stepped contact, m: `numerics.domain_radius`, else
    the punch radius, else twice the adhesive neck radius, else 0 (chosen from the depth at
    first contact); never longer than a punch."""
    punch = getattr(physics.profile, "punch_radius", None)
    if numerics.domain_radius > 0.0:
        first = numerics.domain_radius
    elif punch is not None:
        first = punch
    elif physics.work_of_adhesion > 0.0:
        first = 2.0 * physics.adhesion_length()
    else:
        first = 0.0
    return min(first, punch) if punch is not None else first


def _largest_domain(first: float) -> float:
    """The longest domain a contact whose first domain is `first` m long may grow to, m."""
    return max(1e6 * first, 1e3)


def _beyond_depth_limit(depth: float, limit: float) -> InputError:
    return InputError(
        f"depth {depth!r} m is beyond the scene's range: |depth| may be at most {limit:.3g} m, "
        "the largest domain this contact can represent (a force that needs it cannot be reached)"
    )


def _too_many_substeps(dt: float, max_substep: float) -> InputError:
    """The error of a step of ``dt`` s that ``numerics.max_substep`` (s) would cut into more
    than MAX_SUBSTEPS substeps (a max_substep of 1e-12 s froze the node on a 10 ms step)."""
    return InputError(
        f"a time step of {dt:.6g} s would take {dt / max_substep:.3g} substeps of numerics.max_substep "
        f"{max_substep:g} s, more than the {MAX_SUBSTEPS} one step may take: step at most "
        f"{MAX_SUBSTEPS * max_substep:.6g} s at a time, or set numerics.max_substep to at least "
        f"{dt / MAX_SUBSTEPS:.6g} s (or 0: no bound)"
    )


def _overflow(energy_input: float, energy_dissipated: float) -> InputError:
    """The error of a step whose energy overflowed (a force or depth far beyond what the
    scene represents, e.g. 1e154 N on a flat punch, which no domain limit refuses)."""
    return InputError(
        f"the step's energy is not finite (energy input {energy_input!r} J, dissipated "
        f"{energy_dissipated!r} J): the force or depth is far beyond the scene's range"
    )


#: Converged force steps in a row the force search's first trial extrapolates its depth from.
PATH_POINTS = 4


@dataclass(frozen=True)
class _PullOff:
    """A force step that could not hold its pull and let go (`ContactSimulator._pulled_off`):
    kept in the force memo's place, tied to that step's `output`, with `shift` (m), the depth
    where the contact let go less the held depth the step started from. A pull held after a
    pull-off re-touches at the held depth as the surface creeps back and lets go again a
    nearly equal shift further (`ContactSimulator._predicted_detachment`)."""

    output: StepOutput
    shift: float


#: Weights of the last 3 / 4 points (oldest first) that extrapolate a polynomial through them
#: to the next point of the same spacing.
_EQUAL_SPACING_WEIGHTS = {3: (1.0, -3.0, 3.0), 4: (-1.0, 4.0, -6.0, 4.0)}


def _path_prediction(path: tuple, time: float, target: float, slope: float) -> float | None:
    """The force search's first trial after converged force steps in a row: the depth where
    the path of the last steps, extrapolated in time, meets `target` (N) at `time` (s).

    `path`: (time s, depth m, force N) of the last steps, oldest first. Along a smooth
    history the unloaded depth z = d - F / slope (`slope`: dF/dd of the last step, N/m)
    moves smoothly (the memory creeps), and so does the depth where the commanded force is
    met: z is extrapolated by the polynomial through the last 3 or 4 points (their spacing
    in time, or equal spacing when it is equal to 1e-6) and the commanded force added back,
    d = z(time) + target / slope. A wrong prediction costs trials, never the result (the
    trial at it is checked like any other). None: fewer than 3 points, or times not
    increasing."""
    count = len(path)
    if count < 3:
        return None
    t_last = path[-1][0]
    step = time - t_last
    if not step > 0.0:
        return None
    weights = _EQUAL_SPACING_WEIGHTS[count]
    for index in range(count - 1):
        spacing = path[index + 1][0] - path[index][0]
        if abs(spacing - step) > 1e-6 * step:
            weights = _lagrange_weights([point[0] for point in path], time)
            if weights is None:
                return None
            break
    depth = 0.0
    force = 0.0
    for weight, point in zip(weights, path, strict=True):
        depth += weight * point[1]
        force += weight * point[2]
    return depth + (target - force) / slope


def _fold_estimate(pairs: list[tuple[float, float]]) -> float:
    """Where a pull's step lets go, m, from its trials that let go: `pairs` of (the trial's
    depth, the depth along its path where it let go), m, in increasing trial depth (nearest
    the fold last). The let-go depth moves with the trial's depth about linearly near the
    fold (`ContactSimulator._detachment`): the fixed point of the line through the last two
    when its slope is in (-1, 0.5), else the last let-go depth."""
    x2, j2 = pairs[-1]
    if len(pairs) > 1:
        x1, j1 = pairs[-2]
        if x1 < x2:
            slope = (j2 - j1) / (x2 - x1)
            if -1.0 < slope < 0.5:
                return (j2 - slope * x2) / (1.0 - slope)
    return j2


def _lagrange_weights(times: list[float], time: float) -> tuple[float, ...] | None:
    """Weights of the values at `times` (s, increasing) whose sum is the polynomial through
    them at `time` (s); None when two times coincide."""
    weights = []
    for j, t_j in enumerate(times):
        weight = 1.0
        for m, t_m in enumerate(times):
            if m != j:
                if t_j == t_m:
                    return None
                weight *= (time - t_m) / (t_j - t_m)
        weights.append(weight)
    return tuple(weights)


def _bracketed_root(
    residual: Any, a: float, fa: float, b: float, fb: float, tol: float
) -> tuple[float, float]:
    """A root of `residual` in the bracket [a, b] (``fa``, ``fb`` of opposite signs):
    Illinois (regula falsi that halves the stale end's value) with a bisection whenever the
    bracket failed to halve in three steps. Stops when ``|residual| <= tol`` (N, the force
    tolerance) or the bracket is down to 1e-15 relative (a jump across the target: the
    caller flags it). Returns (x, residual(x)) of the best point (the smaller |residual|)."""
    # ra, rb: the true residuals at a and b; fa, fb: the (Illinois-weighted) ones the
    # interpolation uses.
    ra, rb = fa, fb
    side = 0
    width = abs(b - a)
    since_halved = 0
    for _ in range(200):
        if abs(ra) <= tol:
            return a, ra
        if abs(rb) <= tol:
            return b, rb
        if abs(b - a) <= 1e-15 * max(abs(a), abs(b), 1e-300):
            break
        x = (a * fb - b * fa) / (fb - fa) if since_halved < 3 else 0.5 * (a + b)
        if not min(a, b) < x < max(a, b):
            x = 0.5 * (a + b)
        fx = residual(x)
        if (fx < 0.0) == (rb < 0.0):
            b, fb, rb = x, fx, fx
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa, ra = x, fx, fx
            if side == 1:
                fb *= 0.5
            side = 1
        if abs(b - a) <= 0.5 * width:
            width = abs(b - a)
            since_halved = 0
        else:
            since_halved += 1
    return (a, ra) if abs(ra) <= abs(rb) else (b, rb)


def _columns(outputs: list[StepOutput]) -> dict[str, np.ndarray]:
    """One array per StepOutput field (phase uint8, flags bool) from a list of outputs."""
    dtypes = {"phase": np.uint8, "scale_separation_ok": np.bool_, "unstable": np.bool_}
    return {
        name: np.array([getattr(o, name) for o in outputs], dtype=dtypes.get(name, np.float64))
        for name in STEP_OUTPUT_FIELDS
    }


def _empty_columns() -> dict[str, np.ndarray]:
    return _columns([])


def _modal_chain(e0: float, e_kelvin: np.ndarray, eta_kelvin: np.ndarray) -> tuple[np.ndarray, ...]:
    """Diagonalise the in-contact Kelvin chain once.

    ``eta_k dl_k/dt = E0 (u - sum_j l_j) - E_k l_k`` is ``dl/dt = -D^-1 S l + D^-1 E0 1 u``
    with ``S = E0 11^T + diag(E)`` (SPD) and ``D = diag(eta)``. With ``y = D^1/2 l`` the
    matrix ``D^-1/2 S D^-1/2 = Q diag(lam) Q^T`` is symmetric positive definite, so the
    modes ``z = Q^T D^1/2 l`` decouple with real rates ``lam > 0``:
    ``dz/dt = -lam z + beta u``, ``beta = Q^T (E0 / sqrt(eta))``.
    Returns ``(P, P_inv, lam, beta)`` with ``z = P l`` and ``l = P_inv z``.
    """
    k = e_kelvin.size
    if k == 0:
        empty = np.zeros((0, 0))
        return empty, empty.copy(), np.zeros(0), np.zeros(0)
    root = np.sqrt(eta_kelvin)
    stiffness = e0 * np.ones((k, k)) + np.diag(e_kelvin)
    lam, q = np.linalg.eigh(stiffness / np.outer(root, root))
    p = np.ascontiguousarray(q.T * root[None, :])
    p_inv = np.ascontiguousarray(q / root[:, None])
    beta = np.ascontiguousarray(q.T @ (e0 / root))
    return p, p_inv, np.ascontiguousarray(lam), beta


@dataclass(frozen=True)
class Snapshot:
    """An opaque copy of a simulator's state (see `ContactSimulator.snapshot`); it restores
    into a simulator of the same contact (an equal ContactConfig) only."""

    model_state: Any
    time: float
    depth: float
    output: StepOutput
    energy_input: float
    held_force: float | None
    force_memo: Any = None
    contact: Any = None  # the ContactConfig it was taken of


def _rest_like(output: StepOutput) -> bool:
    """An output a contact at rest has (after a reset: no contact, no force, no energy): a
    command to its depth at its time is a command, not a repeat (`ContactSimulator._repeats`)."""
    return (
        output.contact_radius == 0.0
        and output.force == 0.0
        and output.energy_input == 0.0
        and output.energy_dissipated == 0.0
    )


class ContactSimulator:
    """One adhesive viscoelastic contact, stepped in time.

    contact: a ``ContactConfig`` (core/config.py): indenter, material, adhesion, numerics.
    """

    def __init__(self, contact: Any) -> None:
        self.contact = contact
        self.numerics = resolve_numerics(contact.numerics)
        self.physics = _Physics(contact)
        reason = _ClosedForm.eligible(self.physics)
        requested = self.numerics.model
        if requested == "closed_form" and reason:
            raise ConfigError(f"numerics.model 'closed_form' is not available for this contact: {reason}")
        if requested == "closed_form" or (requested == "auto" and not reason):
            self._model: _ClosedForm | _TimeStepped = _ClosedForm(self.physics)
        else:
            self._model = _TimeStepped(self.physics, self.numerics)
        # Depth steps may take the lean path in `step` (the time-stepped model only).
        self._lean = isinstance(self._model, _TimeStepped)
        # The deepest |depth| a step may reach, m: the largest domain a time-stepped contact
        # of this scene can represent (`_TimeStepped._grow`), on every model (a flat punch,
        # whose contact radius is fixed, and the closed forms have no domain to outgrow).
        # Beyond it a flat punch took 1.9e11 m under 1e15 N and answered the next 0.01 N with
        # 0.13 N (the memory's rounding at that scale), and the closed form took 1e10 m.
        model = self._model
        if isinstance(model, _TimeStepped):
            first = model.initial_length
        else:
            first = _first_domain(self.physics, self.numerics)
        self._depth_limit = _largest_domain(first)
        self.reset(0.0)

    # -- public state ---------------------------------------------------------------------
    @property
    def model(self) -> str:
        """ "closed_form" or "time_stepped": the model path computing this contact."""
        return self._model.name

    @property
    def time(self) -> float:
        return self._time

    @property
    def output(self) -> StepOutput:
        """The last StepOutput (after `reset`, the rest state)."""
        return self._output

    @property
    def in_contact(self) -> bool:
        return self._output.contact_radius > 0.0

    @property
    def is_idle(self) -> bool:
        """Out of contact with all memory relaxed: steps above the surface cost nothing."""
        return not self.in_contact and self._model.is_relaxed()

    @property
    def model_validity(self) -> ModelValidity:
        """Whether the model's assumptions hold in the current state: small slopes at the
        contact edge (half-space theory) and scale separation of the energy criterion."""
        radius = self._output.contact_radius
        slope = 0.0
        profile = self.physics.profile
        if radius > 0.0 and profile.kind != "flat_punch":
            step = 1e-6 * radius
            slope = abs(float(profile.f(radius + step)) - float(profile.f(radius - step))) / (2.0 * step)
        small = slope <= SMALL_SLOPE_LIMIT
        separated = bool(self._output.scale_separation_ok)
        across = math.inf
        resolved = True
        row = getattr(self._model, "row", None)
        if radius > 0.0 and row is not None:
            across = radius / row.dx
            # A receding edge shrinks through every size on its way to let-go, on a grid sized
            # for the contact it had (a non-adhesive contact ends at radius 0): judged while
            # the edge presses or holds.
            resolved = across >= RESOLUTION_ELEMENTS or self._output.phase == Phase.DETACHING
        problems = []
        if not small:
            problems.append(
                f"flank slope {slope:.3g} at the contact edge exceeds {SMALL_SLOPE_LIMIT} "
                "(the half-space theory behind MDR assumes small slopes)"
            )
        if not separated:
            problems.append(
                f"the contact edge moves at {self._output.edge_speed:.3g} m/s, slower than the "
                "energy criterion's critical speed (no scale separation)"
            )
        if not resolved:
            problems.append(
                f"the contact (radius {radius:.3g} m) spans {across:.3g} of the grid's elements "
                f"({row.dx:.3g} m wide), fewer than {RESOLUTION_ELEMENTS:g}: the force is not "
                "resolved; set numerics.domain_radius to 0 (chosen from the scene) or near the "
                "deepest contact radius, and numerics.elements to 0 (the preset's) or more"
            )
        ok = small and separated and resolved
        return ModelValidity(slope, small, separated, ok, "; ".join(problems), resolved, across)

    def reset(self, time: float = 0.0) -> None:
        """Back to the undeformed state at `time` (s), depth 0, no contact, energies zero."""
        self._time = require_finite("time", time)
        self._depth = 0.0
        self._energy_input = 0.0
        self._held_force: float | None = None
        # What the next force step predicts its root from (`_remember`): (the output it
        # belongs to, slope dF/dd N/m, drift dF/dt at a held depth N/s, the slope's change
        # along the path N/m^2, the (time, depth, force) of the last PATH_POINTS converged
        # force steps in a row, oldest first, this output's last), or None.
        self._force_memo: tuple[StepOutput, float, float, float, tuple] | None = None
        self._model.reset()
        self._output = StepOutput(
            self._time, 0.0, 0.0, 0.0, Phase.NO_CONTACT, 0.0, 0.0, 0.0, 0.0, True, False
        )

    def snapshot(self) -> Snapshot:
        return Snapshot(
            self._model.get_state(),
            self._time,
            self._depth,
            self._output,
            self._energy_input,
            self._held_force,
            self._force_memo,
            self.contact,
        )

    def restore(self, snapshot: Snapshot) -> None:
        """Back to the state `snapshot` holds. A snapshot of another contact (a different
        ContactConfig: material, indenter, adhesion or numerics) is refused with an InputError
        and changes nothing: its memory means nothing under other physics or another grid."""
        if not isinstance(snapshot, Snapshot):
            raise InputError(f"restore needs a Snapshot (got {type(snapshot).__name__})")
        theirs = snapshot.contact
        if theirs is not None and theirs is not self.contact and theirs != self.contact:
            raise InputError(
                "this snapshot was taken of another contact (its material, indenter, adhesion or "
                "numerics differ): restore it into a simulator of the same contact"
            )
        self._model.set_state(snapshot.model_state)
        self._time = snapshot.time
        self._depth = snapshot.depth
        self._output = snapshot.output
        self._energy_input = snapshot.energy_input
        self._held_force = snapshot.held_force
        self._force_memo = snapshot.force_memo

    # -- stepping -------------------------------------------------------------------------
    def _check_time(self, time: float) -> float:
        t = require_finite("time", time)
        if t < self._time:
            raise InputError(f"time must not go backwards (got {t!r} after {self._time!r})")
        if 0.0 < t - self._time < MIN_TIME_STEP:
            raise InputError(
                f"time step {t - self._time!r} s is shorter than the shortest the model takes "
                f"({MIN_TIME_STEP!r} s)"
            )
        return t

    # Every public stepping call is a transaction: on any exception (bad input, a contact the
    # domain cannot represent, an interrupt) the state is restored from a snapshot taken
    # before, bit for bit, so a refused step leaves nothing behind (the node relies on it).
    def step(self, time: float, *, depth: float | None = None, force: float | None = None) -> StepOutput:
        """Advance to `time` (s) under displacement control (`depth`, m) or force control
        (`force`, N); exactly one of them. Returns the new StepOutput. On any error the
        state is left as it was before the call."""
        # The lean path, for the common case: a finite float depth at a finite float time not
        # before the last, on the time-stepped model, not idle above the surface (the general
        # path drops that memory). It is `_step` / `_move` / `_publish` / `_make_output` in
        # this one frame, the edge outputs read from the kernel's (`edge_height` and
        # `edge_gaps` return the same values after an advance): the general path's outputs and
        # state bit for bit, and its transaction (tests/test_step_lean.py).
        if force is None and type(depth) is float and type(time) is float:
            # The common call (float time and depth) tested first: the repeat check below with
            # these types, then the lean path (0.12.0 `percall`: ~30 ns less than the general
            # order of tests).
            t = time
            d = depth
            time0 = self._time
            if t == time0 and self._repeats(d, None):
                return self._output
            lean = self._lean
        else:
            if isinstance(time, float) and time == self._time and self._repeats(depth, force):
                # The command the last step took, again at its instant (a message logged
                # twice, a controller republishing): the step as it is. A second force search
                # from the solved state could land elsewhere within the force tolerance
                # (~1e-10 m), and a zero-time depth step searched the edge again (outside
                # tester, 0.10.0; the kernel's `_advance_from` keeps the state for the batch
                # path too).
                return self._output
            lean = False
            if force is None and self._lean:
                if not (isinstance(depth, float) and isinstance(time, float)):
                    return self._step_transaction(time, depth, force)
                t, d = float(time), float(depth)
                time0 = self._time
                lean = True
        if lean:
            model = self._model
            d_prev = self._depth
            output0 = self._output
            r0 = output0.contact_radius
            dt = t - time0
            limit = self._depth_limit
            # (`-limit <= d <= limit` is `abs(d) <= limit` for every float, NaN included.)
            if (
                t - t == 0.0
                and -limit <= d <= limit
                and (t == time0 or MIN_TIME_STEP <= dt <= model._longest_step)
                and not (d < 0.0 and d_prev < 0.0 and r0 <= 0.0 and model.is_relaxed())
            ):
                row = model.row
                if row is not None and "advance" not in model.__dict__:
                    # The row exists (the common case): `begin`, `advance`, `_phase` and the
                    # derived outputs in one compiled call (`_STEP`, journal included), the
                    # transaction's token kept in locals. A step that needs a larger domain
                    # goes back to the journal and takes the path below (it grows the row),
                    # as does a model whose `advance` was replaced on the instance (the fault
                    # tests inject errors after the kernel that way), found in the instance's
                    # dict: ~70 ns a step less than making the bound method to compare its
                    # function (0.12.0 `percall`). The model's dict is a real one already
                    # (it has more attributes than CPython 3.11/3.12 keep inline, 30), so
                    # reading it deoptimises nothing; on a model with inline attributes it
                    # would (0.5.0 measured ~0.4 us a step then).
                    radius0 = model.radius
                    dissipated0 = model.dissipated
                    peak0 = model._memory_peak
                    edge0 = model._edge
                    edge_depth0 = model._edge_depth
                    known = model._force_at
                    # `_TimeStepped.advance`'s rule for the force known at the start (the
                    # tuple unpacked: four subscripts cost more).
                    if known is None:
                        force_prev = math.nan
                    else:
                        known_row, known_radius, known_depth, force_prev = known
                        if not (
                            known_row is row
                            and known_radius == radius0
                            and known_depth == d_prev
                            and d_prev != 0.0
                        ):
                            force_prev = math.nan
                    state, const = row.addresses
                    energy0 = self._energy_input
                    held0 = self._held_force
                    model._journal = None
                    try:
                        model._journal = row
                        # The energy input and dissipated energy after the step come back
                        # summed (energy0 + work, dissipated0 + the step's losses) and checked.
                        (
                            status,
                            radius,
                            f,
                            energy,
                            substeps,
                            dissipated,
                            peak,
                            edge,
                            phase,
                            edge_speed,
                            effective,
                            separated,
                        ) = _STEP(
                            state,
                            const,
                            model._params_address,
                            True,
                            radius0,
                            d_prev,
                            d,
                            dt,
                            force_prev,
                            r0,
                            energy0,
                            dissipated0,
                        )
                        if status == 0:  # _kernels.STATUS_OK
                            # The output first (nothing changed yet if it fails), then the
                            # commit. Filling the instance's dict item by item is cheaper than
                            # a dict display (`_new_output`).
                            output = _object_new(StepOutput)
                            values = output.__dict__
                            values["time"] = t
                            values["depth"] = d
                            values["force"] = f
                            values["contact_radius"] = radius
                            values["phase"] = _PHASES[phase]
                            values["edge_speed"] = edge_speed
                            values["effective_work_of_adhesion"] = effective
                            values["energy_input"] = energy
                            values["energy_dissipated"] = dissipated
                            values["scale_separation_ok"] = separated
                            values["unstable"] = False
                            model.radius = radius
                            model.substeps = substeps
                            model.dissipated = dissipated
                            model._memory_peak = peak
                            model._edge = edge
                            model._edge_depth = d
                            model._force_at = (row, radius, d, f)
                            # `_TimeStepped.prepare_ahead`, inline (a call costs this path).
                            if row is not model._prepare_row:
                                model._prepare_row = row
                                model._prepare_radius = PREPARE_FRACTION * row.length
                            elif radius > model._prepare_radius:
                                model._prepare_growth(row)
                            self._energy_input = energy
                            self._time = t
                            self._depth = d
                            self._output = output
                            self._held_force = None
                            return output
                        if status == _kernels.STATUS_OVERFLOW:
                            raise _overflow(energy, dissipated)
                        _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
                        model._journal = None
                    except BaseException:
                        # `model.rollback` of the token in the locals, and this simulator's fields.
                        if model._journal is not None:
                            _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
                            model._journal = None
                        model.radius, model.row, model.dissipated = radius0, row, dissipated0
                        model._memory_peak, model._edge, model._edge_depth = peak0, edge0, edge_depth0
                        model._force_at = known
                        self._energy_input, self._time, self._depth = energy0, time0, d_prev
                        self._output, self._held_force = output0, held0
                        raise
                energy0 = self._energy_input
                held0 = self._held_force
                token = model.begin()
                try:
                    radius, f, work = model.advance(d_prev, d, dt)
                    energy = energy0 + work
                    if not (energy - energy == 0.0 and model.dissipated - model.dissipated == 0.0):
                        raise _overflow(energy, model.dissipated)
                    physics = self.physics
                    g_edge = model._edge[2] if radius > 0.0 else 0.0
                    phase = _phase(model, physics, d, r0, radius, g_edge)
                    edge_speed = (radius - r0) / dt if dt > 0.0 else 0.0
                    u = d - g_edge
                    if radius > 0.0 and u < 0.0:
                        effective = physics.e_relaxed * u * u / (2.0 * math.pi * radius)
                    else:
                        effective = 0.0
                    if edge_speed == 0.0:
                        separated = True
                    else:
                        v_c1, v_c2 = physics.critical_speeds
                        separated = abs(edge_speed) >= (v_c1 if edge_speed > 0.0 else v_c2)
                    # `_new_output` inline (a call with 11 arguments is ~0.1 us of this path).
                    output = _object_new(StepOutput)
                    output.__dict__.update(
                        {
                            "time": t,
                            "depth": d,
                            "force": f,
                            "contact_radius": radius,
                            "phase": phase,
                            "edge_speed": edge_speed,
                            "effective_work_of_adhesion": effective,
                            "energy_input": energy,
                            "energy_dissipated": model.dissipated,
                            "scale_separation_ok": separated,
                            "unstable": False,
                        }
                    )
                    self._energy_input = energy
                    self._time = t
                    self._depth = d
                    self._output = output
                    self._held_force = None
                    return output
                except BaseException:
                    model.rollback(token)
                    self._energy_input, self._time, self._depth = energy0, time0, d_prev
                    self._output, self._held_force = output0, held0
                    raise
        elif depth is None and self._lean and type(self._force_memo) is tuple:
            # The lean force path: a force step whose predicted root holds (85 % of the
            # default scene's force rows) in one frame, else the general path below (also
            # straight away without a prediction: out of contact, after a pull-off).
            if type(force) is float and type(time) is float:
                output = self._predicted_force_step(time, force)
            elif isinstance(force, float) and isinstance(time, float):
                output = self._predicted_force_step(float(time), float(force))
            else:
                output = None
            if output is not None:
                return output
        return self._step_transaction(time, depth, force)

    def _predicted_force_step(self, t: float, target: float) -> StepOutput | None:
        """`step(t, force=target)` when its predicted root holds: `_solve_force`'s first
        branch (the path prediction and `_predicted_root`'s secant trials) with `_trial`,
        `advance`, `rewind` and `_publish` in this one frame and the kernel deriving the
        outputs (`_STEP`, as the lean depth path): the general path's trials, outputs, memo
        and state bit for bit (tests/test_step_lean.py). A prediction that does not hold (a
        trial detached, a slope unlike the last, no convergence) goes on into `_search_force`
        from the same trials, as `_solve_force` does. None, with nothing changed, when that
        branch does not apply (no valid prediction, bad input) or a trial needs a larger
        domain: the general path then runs the step from the start."""
        if not (
            t - t == 0.0 and target - target == 0.0 and (t == self._time or t - self._time >= MIN_TIME_STEP)
        ):
            return None  # the general path says what is wrong
        before = self._output
        memo = self._force_memo
        r_before = before.contact_radius
        if not (type(memo) is tuple and memo[0] is before and r_before > 0.0):
            return None
        physics = self.physics
        glass = 2.0 * physics.e0 * r_before
        slope = memo[1]
        model = self._model
        row = model.row
        if not (
            slope >= FOLD_SLOPE * glass
            and row is not None
            and "advance" not in model.__dict__  # (as the lean depth path)
            and t - self._time <= model._longest_step
        ):
            return None
        time0 = self._time
        d0 = self._depth
        f0 = before.force
        dt = t - time0
        stop = self._force_stop(target, r_before)
        first = _path_prediction(memo[4], t, target, slope)
        if first is None:
            # F(d) ~ F(d0) + slope (d - d0), F(d0) ~ f0 + drift_rate dt.
            first = d0 + (target - f0 - memo[2] * dt) / slope
        bend = memo[3]
        state, const = row.addresses
        params = model._params_address
        token = model.begin()
        start = model.trial_start()
        radius0, dissipated0 = model.radius, model.dissipated
        # The force known at the start (the first trial only: a rewind forgets it).
        force_prev = model._start_force(row, d0)
        trials: list[tuple[float, float, float]] = []
        energy0 = self._energy_input
        try:
            x = first
            r = tangent = 0.0
            shrunk = False
            result = None
            grow = False
            last: list[Any] = [None, None]
            for trial in range(1, self.PREDICTED_TRIALS_CONVERGING + 1):
                if trial > 1:
                    # `residual`'s rewind (`rewind` of `trial_start`): the memory back from
                    # the journal the last trial wrote, which the next one writes again.
                    if trial > self.PREDICTED_TRIALS and not shrunk:
                        break
                    x_new = x - r / tangent
                    if x_new == x or abs(x_new - x) * FOLD_SLOPE * glass > abs(r):
                        break
                    if not abs(x_new) <= self._depth_limit:
                        break  # `_predicted_root`: no trial beyond it, the search decides
                    _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
                    model.radius = radius0
                    model.dissipated = dissipated0
                else:
                    x_new = x
                    if not abs(x_new) <= self._depth_limit:
                        break
                model._force_at = None
                model._journal = row
                # (The trial's own work, -0.0 + work; the dissipated energy's new total.)
                result = _STEP(
                    state,
                    const,
                    params,
                    True,
                    radius0,
                    d0,
                    x_new,
                    dt,
                    force_prev,
                    r_before,
                    -0.0,
                    dissipated0,
                )
                force_prev = math.nan
                if result[0] == _kernels.STATUS_GROW:  # the domain must grow
                    # (STATUS_OVERFLOW is a step: `_publish` below refuses it as before.)
                    result = None
                    grow = True
                    break
                model._stepped(row, result, x_new)
                radius, f = result[1], result[2]
                trials.append((x_new, f, radius))
                last = [x_new, (radius, f, result[3])]
                r_new = f - target
                if not radius > 0.0:
                    result = None
                    break
                if trial == 1:
                    tangent = slope + bend * (first - d0)
                    if not 0.5 * slope < tangent < 2.0 * slope:
                        tangent = slope
                    shrunk = False
                else:
                    secant = (r_new - r) / (x_new - x)
                    if not 0.25 * slope <= secant <= 4.0 * slope:
                        result = None
                        break
                    shrunk = abs(r_new) <= 0.01 * abs(r)
                    tangent = secant
                x, r = x_new, r_new
                if abs(r) <= stop:
                    break
            else:
                result = None
            if grow:
                # A trial the domain cannot hold: nothing of this attempt stays; the general
                # path runs the step (`advance` grows the domain inside the trial).
                model.rollback(token)
                return None
            if result is None or not abs(r) <= stop:
                # The prediction did not hold: on to the general search as `_solve_force`
                # goes on after `_predicted_root`, from the same trials (its next trial
                # rewinds the model from the journal).
                trials.clear()
                output = self._search_force(t, target, start, last, trials)
                self._held_force = target
                model.prepare_ahead()
                return output
            # `_publish` of the trial at the root (the model is in its state).
            energy = energy0 + result[3]
            if not (energy - energy == 0.0 and model.dissipated - model.dissipated == 0.0):
                raise _overflow(energy, model.dissipated)
            output = _object_new(StepOutput)
            values = output.__dict__
            values["time"] = t
            values["depth"] = x
            values["force"] = result[2]
            values["contact_radius"] = result[1]
            values["phase"] = _PHASES[result[8]]
            values["edge_speed"] = result[9]
            values["effective_work_of_adhesion"] = result[10]
            values["energy_input"] = energy
            values["energy_dissipated"] = model.dissipated
            values["scale_separation_ok"] = result[11]
            values["unstable"] = False
            self._energy_input = energy
            self._time = t
            self._depth = x
            self._output = output
            self._remember(output, before, trials, d0, f0, dt, None, slope)
            self._held_force = target
            model.prepare_ahead()
            return output
        except BaseException:
            model.rollback(token)
            self._energy_input, self._time, self._depth = energy0, time0, d0
            self._output, self._force_memo = before, memo
            raise

    def _repeats(self, depth: Any, force: Any) -> bool:
        """Whether (depth, force) is the command the last step took (at its instant: the
        caller compares the times): the same depth under depth control, the same force under
        force control; floats only (other types go the general path, which checks them)."""
        if force is None:
            # Not from rest: a contact at rest (after a reset) commanded to its own depth is a
            # command, not a repeat (an adhesive contact snaps in at depth 0).
            return (
                isinstance(depth, float)
                and self._held_force is None
                and depth == self._depth
                and not _rest_like(self._output)
            )
        return depth is None and isinstance(force, float) and force == self._held_force

    def _step_transaction(self, time: float, depth: float | None, force: float | None) -> StepOutput:
        """`step` on the general path: validation, then `_step` as a transaction."""
        saved = self._undo_token()
        try:
            output = self._step(time, depth, force)
            self._model.prepare_ahead()
            return output
        except BaseException:
            self._undo(saved)
            raise

    def _undo_token(self) -> tuple:
        """Begin a transaction: the token `_undo` takes to bring back the state of now, either
        from inside the next step (its rollback) or after it succeeded (`core.hand` undoes the
        contacts of a sample that stepped before a failing one). No copies: the memory comes
        back from the journal the step's first kernel call writes (`_TimeStepped.begin`). Valid
        until the simulator's next step or restore."""
        return (
            self._model.begin(),
            self._time,
            self._depth,
            self._output,
            self._energy_input,
            self._held_force,
            self._force_memo,
        )

    def _undo(self, token: tuple) -> None:
        """Back to the state `_undo_token` saw (see there)."""
        self._model.rollback(token[0])
        (
            self._time,
            self._depth,
            self._output,
            self._energy_input,
            self._held_force,
            self._force_memo,
        ) = token[1:]

    def _step(self, time: float, depth: float | None, force: float | None) -> StepOutput:
        t = self._check_time(time)
        if (depth is None) == (force is None):
            raise InputError("step needs exactly one of depth or force")
        if depth is not None:
            d = require_finite("depth", depth)
            if t == self._time and self._repeats(d, None):
                return self._output  # `step`'s repeated sample, for any number type and model
            output = self._move(t, d, unstable=False)
            self._held_force = None
            return output
        target = require_finite("force", force)
        if t == self._time and self._repeats(None, target):
            return self._output
        output = self._solve_force(t, target)
        self._held_force = target
        return output

    def advance(self, time: float) -> StepOutput:
        """Hold the last control until `time` (s): the last commanded force under force
        control (the indenter creeps), else the current depth. On any error the state is
        left as it was before the call."""
        if self._held_force is not None:
            return self.step(time, force=self._held_force)
        return self.step(time, depth=self._depth)

    def step_depths(self, times: np.ndarray, depths: np.ndarray) -> dict[str, np.ndarray]:
        """``step(times[i], depth=depths[i])`` for every i in turn, the time-stepped rows in
        one compiled loop (`_kernels._advance_rows`); the outputs equal row-by-row stepping.

        times: s, shape (n,), non-decreasing, from `time` on; depths: m, shape (n,). Returns
        one array per `StepOutput` field (shape (n,); phase uint8, flags bool); the
        simulator ends in the state of the last row, as after stepping. On bad input or any
        other error (a row the domain cannot represent) nothing changes.
        """
        snapshot = self.snapshot()
        try:
            return self._step_depths(times, depths)
        except BaseException:
            self.restore(snapshot)
            raise

    def _step_depths(self, times: np.ndarray, depths: np.ndarray) -> dict[str, np.ndarray]:
        t = np.ascontiguousarray(times, dtype=np.float64)
        d = np.ascontiguousarray(depths, dtype=np.float64)
        if t.ndim != 1 or t.shape != d.shape:
            raise InputError(f"times and depths must be 1-D of one length (got {t.shape}, {d.shape})")
        for name, values in (("time", t), ("depth", d)):
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                raise InputError(f"{name}[{int(bad[0])}] must be finite (got {float(values[bad[0]])!r})")
        if t.size and (t[0] < self._time or np.any(np.diff(t) < 0.0)):
            raise InputError(
                "time must not go backwards (times must be non-decreasing from the current time)"
            )
        deep = np.flatnonzero(np.abs(d) > self._depth_limit)
        if deep.size:
            raise InputError(
                f"depth[{int(deep[0])}]: {_beyond_depth_limit(float(d[deep[0]]), self._depth_limit)}"
            )
        steps = np.diff(t, prepend=self._time)
        short = np.flatnonzero((steps > 0.0) & (steps < MIN_TIME_STEP))
        if short.size:
            raise InputError(
                f"time[{int(short[0])}]: a time step of {float(steps[short[0]])!r} s is shorter than the "
                f"shortest the model takes ({MIN_TIME_STEP!r} s)"
            )
        if t.size == 0:
            return _empty_columns()
        model = self._model
        if isinstance(model, _TimeStepped):
            long = np.flatnonzero(steps > model._longest_step)
            if long.size:
                return self._split_depths(t, d, long)
            radius, force, work, dissipated, gaps, rest = model.advance_rows(self, t, d)
        else:
            outputs = [self._step(float(ti), float(di), None) for ti, di in zip(t, d, strict=True)]
            return _columns(outputs)
        physics = self.physics
        # `rest`: per row, the edge resolution of the row that stepped it (the row after the
        # batch may be another one, or none: a batch that ended idle read every edge at rest
        # as moving, INDENTING and DETACHING in turn). The phase (`_phase` on columns, g at the
        # edge as the kernel saw it: 0 without contact, like `step`), edge speed, effective work
        # of adhesion, scale separation and the running energy input in one compiled pass
        # (`_kernels._batch_columns`: the numpy expressions' operations, the same bits).
        # A repeated sample (`step`'s `_repeats`: the same depth at the same instant after a
        # depth step, not from rest) publishes the step before it as it was (the kernel left
        # the state alone): `_batch_columns` copies that row's derived columns.
        v_c1, v_c2 = physics.critical_speeds
        before = self._output
        first = np.array(
            [
                self._depth,
                float(self._held_force is None and not _rest_like(before)),
                float(int(before.phase)),
                before.edge_speed,
                before.effective_work_of_adhesion,
                float(bool(before.scale_separation_ok)),
            ]
        )
        phase, edge_speed, effective, energy_input, ok = _kernels._batch_columns(
            d,
            steps,
            radius,
            gaps,
            rest,
            work,
            before.contact_radius,
            self._energy_input,
            physics.c_crit,
            physics.e_relaxed,
            v_c1,
            v_c2,
            force,
            dissipated,
            first,
        )
        bad = np.flatnonzero(~(np.isfinite(energy_input) & np.isfinite(dissipated)))
        if bad.size:
            raise _overflow(float(energy_input[bad[0]]), float(dissipated[bad[0]]))
        columns = {
            "time": t,
            "depth": d,
            "force": force,
            "contact_radius": radius,
            "phase": phase,
            "edge_speed": edge_speed,
            "effective_work_of_adhesion": effective,
            "energy_input": energy_input,
            "energy_dissipated": dissipated,
            "scale_separation_ok": ok,
            "unstable": np.zeros(t.size, dtype=np.bool_),
        }
        self._time, self._depth = float(t[-1]), float(d[-1])
        self._energy_input = float(energy_input[-1])
        self._held_force = None
        self._output = StepOutput(
            *(columns[name][-1].item() for name in STEP_OUTPUT_FIELDS[:4]),
            Phase(int(phase[-1])),
            *(columns[name][-1].item() for name in STEP_OUTPUT_FIELDS[5:]),
        )
        return columns

    def _split_depths(self, t: np.ndarray, d: np.ndarray, long: np.ndarray) -> dict[str, np.ndarray]:
        """`_step_depths` of rows of which those at ``long`` are steps longer than
        MAX_SUBSTEPS x ``numerics.max_substep``: those rows stepped one by one (where the
        contact is idle above the surface they cost nothing, else they are refused, naming
        the row), the rows between them as batches."""
        parts = []
        start = 0
        for k in (*(int(i) for i in long), t.size):
            if k > start:
                parts.append(self._step_depths(t[start:k], d[start:k]))
            if k < t.size:
                try:
                    parts.append(_columns([self._step(float(t[k]), float(d[k]), None)]))
                except InputError as error:
                    raise InputError(f"time[{k}]: {error}") from None
            start = k + 1
        return {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}

    def _trial(self, time: float, depth: float) -> tuple[float, float, float]:
        """Advance the model (only) from the current state to (time, depth); returns
        (radius m, force N, work J). An idle contact above the surface costs nothing."""
        if not abs(depth) <= self._depth_limit:
            raise _beyond_depth_limit(depth, self._depth_limit)
        if depth < 0.0 and self._depth < 0.0 and self.is_idle:
            if isinstance(self._model, _TimeStepped):
                self._model.drop_memory()
            return 0.0, 0.0, 0.0
        return self._model.advance(self._depth, depth, time - self._time)

    def _move(self, time: float, depth: float, *, unstable: bool) -> StepOutput:
        """Advance the model from the current state to (time, depth) and publish the output."""
        return self._publish(time, depth, self._trial(time, depth), unstable=unstable)

    def _publish(
        self, time: float, depth: float, result: tuple[float, float, float], *, unstable: bool
    ) -> StepOutput:
        """Take the model's trial `result` (radius, force, work) at (time, depth) as the step."""
        dt = time - self._time
        r0 = self._output.contact_radius
        radius, force, work = result
        energy = self._energy_input + work
        # The output first (it refuses a step whose energy overflowed), then the commit.
        output = self._make_output(time, depth, force, r0, radius, dt, unstable, energy)
        self._energy_input = energy
        self._time, self._depth = time, depth
        self._output = output
        return output

    def _make_output(
        self,
        time: float,
        depth: float,
        force: float,
        r0: float,
        radius: float,
        dt: float,
        unstable: bool,
        energy_input: float,
    ) -> StepOutput:
        physics = self.physics
        # Never below the last published value: the closed form's input minus potential is
        # exact but rounded, and fell by ~1e-24 J (5e-16 of it) on a force-controlled branch,
        # or below zero after a large excursion (outside testers, 0.8.0). The time-stepped
        # model's running sum never decreases, so this changes nothing there.
        dissipated = max(self._model.energy_dissipated(energy_input, depth), self._output.energy_dissipated)
        if not (math.isfinite(energy_input) and math.isfinite(dissipated)):
            raise _overflow(energy_input, dissipated)
        g_edge = self._model.edge_height(radius) if radius > 0.0 else 0.0
        phase = _phase(self._model, physics, depth, r0, radius, g_edge)
        edge_speed = (radius - r0) / dt if dt > 0.0 else 0.0
        u = depth - g_edge
        effective = physics.e_relaxed * u * u / (2.0 * math.pi * radius) if radius > 0.0 and u < 0.0 else 0.0
        return _new_output(
            time,
            depth,
            force,
            radius,
            phase,
            edge_speed,
            effective,
            energy_input,
            dissipated,
            physics.scale_separation_ok(edge_speed),
            unstable,
        )

    # -- force control ----------------------------------------------------------------------
    def _attached(self) -> bool:
        """Whether the model's current (possibly trial) state is in contact."""
        return self._model.radius > 0.0

    def _stiffness_guess(self) -> float:
        """A contact stiffness scale, N/m, to size the first bracketing step."""
        radius = self._output.contact_radius
        if radius <= 0.0:
            row = getattr(self._model, "row", None)
            radius = row.length if row is not None else getattr(self._model, "initial_length", 0.0)
        if radius <= 0.0:
            radius = max(
                self.physics.adhesion_length() if self.physics.work_of_adhesion > 0.0 else 0.0,
                abs(self._depth),
                1e-9,
            )
        return 2.0 * self.physics.e_relaxed * radius

    def _force_stop(self, target: float, radius: float) -> float:
        """Where the root search stops, N: within half the force tolerance relative to the
        commanded force, floored at 1e-6 of the contact's adhesive force scale 2 E0* a dl_c(a)
        (the JKR adhesive term at the contact radius `radius`, m): a zero force commanded to a
        contact in adhesive equilibrium is not chased down to 1e-300 N (44 trials per step)."""
        adhesive = 2.0 * self.physics.e0 * radius * self.physics.c_crit * math.sqrt(radius)
        return 0.5 * self.numerics.force_tolerance * max(abs(target), 1e-6 * adhesive, 1e-300)

    def _solve_force(self, time: float, target: float) -> StepOutput:
        """Find the depth whose step from the current state gives `target` force (N).

        Every trial is a full step of the model from the current state (rewound before each).
        When the last step was a converged force step in contact, a secant predicted from it
        (`_predicted_root`: its slope dF/dd and the force's drift at a held depth) usually
        lands within the tolerance in one or two trials and is published as it stands; when
        its checks fail (a trial detached, or a slope unlike the last one: near the fold of
        the force-depth curve), the bracketing search from the held depth runs instead."""
        # The model's state before the step (the simulator's own fields change only when the
        # result is published): every trial but the first rewinds the model to it.
        model = self._model
        start = model.trial_start() if isinstance(model, _TimeStepped) else model.get_state()
        d0 = self._depth
        before = self._output
        f0 = before.force
        dt = time - self._time
        stop = self._force_stop(target, self._output.contact_radius)
        last: list[Any] = [None, None]  # depth of the last trial and its (radius, force, work)
        trials: list[tuple[float, float, float]] = []  # (depth, force, radius) of every trial
        residual = self._residual(time, target, start, last, trials)
        memo = self._force_memo
        glass = 2.0 * self.physics.e0 * before.contact_radius
        if (
            isinstance(memo, tuple)
            and memo[0] is self._output
            and self.in_contact
            and memo[1] >= FOLD_SLOPE * glass
        ):
            slope, drift_rate, bend = memo[1], memo[2], memo[3]
            first = self._path_prediction(memo[4], time, target, slope)
            if first is None:
                # F(d) ~ F(d0) + slope (d - d0), F(d0) ~ f0 + drift_rate dt.
                first = d0 + (target - f0 - drift_rate * dt) / slope
            root = self._predicted_root(residual, d0, first, slope, bend, stop, glass)
            if root is not None:
                # The model is in the state of the trial at the root: publish it as it stands.
                output = self._publish(time, root, last[1], unstable=False)
                self._remember(output, before, trials, d0, f0, dt, None, slope)
                return output
            trials.clear()
        return self._search_force(time, target, start, last, trials, residual, stop)

    def _residual(
        self,
        time: float,
        target: float,
        start: Any,
        last: list[Any],
        trials: list[tuple[float, float, float]],
    ):
        """The force search's residual F(depth) - target (N) at `time` (s): one trial of the
        model from `start` (the model's state before the step, rewound to before every trial
        but the first), kept in `last` (its depth and (radius, force, work)) and appended to
        `trials` as (depth, force, radius)."""
        model = self._model

        def residual(depth: float) -> float:
            if last[0] is not None:
                model.rewind(start)
            result = self._trial(time, depth)
            last[0], last[1] = depth, result
            trials.append((depth, result[1], result[0]))
            return result[1] - target

        return residual

    def _search_force(
        self,
        time: float,
        target: float,
        start: Any,
        last: list[Any],
        trials: list[tuple[float, float, float]],
        residual: Any = None,
        stop: float = math.nan,
    ) -> StepOutput:
        """`_solve_force` after its predicted root (none, or it did not hold): the search from
        rest or the bracketing search from the held depth. `start`: the model's state before
        the step; `last`: the last trial (depth None when none ran yet) or the failed
        prediction's; `trials`: empty; `residual` (`_residual` over `last` and `trials`) and
        `stop` (`_force_stop`) when the caller has them."""
        model = self._model
        d0 = self._depth
        before = self._output
        f0 = before.force
        tol = self.numerics.force_tolerance * max(abs(target), abs(f0), 1e-300)
        if stop != stop:
            stop = self._force_stop(target, before.contact_radius)
        was_in_contact = self.in_contact
        memo = self._force_memo
        if residual is None:
            residual = self._residual(time, target, start, last, trials)
        cold = self._from_rest(residual, d0, target, stop) if not was_in_contact else None
        if cold is not None:
            lo, r_lo, hi, r_hi, stop = cold
            return self._finish_force(residual, time, target, lo, r_lo, hi, r_hi, stop, tol, last, trials)
        trials.clear()
        r_hold = residual(d0)
        if abs(r_hold) <= tol:
            output = self._publish(time, d0, last[1], unstable=False)
            self._force_memo = None
            return output
        hold_force = r_hold + target
        direction = 1.0 if r_hold < 0.0 else -1.0
        if direction < 0.0 and not self._attached() and not was_in_contact:
            # Out of contact and pulled away: no equilibrium, the indenter stays off.
            self._force_memo = None
            return self._publish(time, d0, last[1], unstable=target < 0.0)
        # First bracketing step: the Newton step on the contact's instantaneous (glass)
        # stiffness 2 E0* a, the stiffest the contact can answer, so the step falls short of
        # the root rather than past it and the doubling below reaches the root nearest the
        # previous depth first (the 0.1.0 lesson near the fold). Out of contact: the old
        # relaxed-stiffness scale.
        stiffness = self._stiffness_guess()
        if self._output.contact_radius > 0.0:
            stiffness *= self.physics.e0 / self.physics.e_relaxed
        elif model.radius > 0.0:
            # Out of contact, but the held depth touched (snap-in, or the surface crept back):
            # the glass stiffness of the contact that formed.
            stiffness = 2.0 * self.physics.e0 * model.radius
        elif direction > 0.0 and isinstance(model, _TimeStepped) and model.row is not None:
            # Out of contact, pushed in, with memory (a pad touching again after a pull-off):
            # the glass stiffness over the row, as in contact. The relaxed scale's first step
            # overshot the root 3x into a deep, dear trial (57 substeps, a third of the step).
            stiffness *= self.physics.e0 / self.physics.e_relaxed
        delta = max(abs(r_hold) / stiffness, 1e-12 * (abs(d0) + 1e-12))
        if direction < 0.0:
            # A pull needs no trial farther above the held depth than the domain is long (on
            # the closed form: 4x the contact radius or the held depth): the contact lets go
            # well before (its adhesive neck and the memory's depression are a fraction of the
            # contact radius, which the domain exceeds). The Newton step of an absurd pull
            # (-1e100 N over the stiffness) went to -1e71 m and published that depth,
            # non-finite energies and a contact that could not be pushed back.
            row = getattr(model, "row", None)
            reach = row.length if row is not None else 4.0 * max(self._output.contact_radius, abs(d0))
            if reach > 0.0:
                delta = min(delta, reach)
        lo, r_lo = d0, r_hold
        # Pulled to a zero force, an adhesive contact holds it before it lets go; a detached
        # trial (zero force too) is no root then: look for the attached one.
        adhesive = self.physics.work_of_adhesion > 0.0
        dip_searched = False
        probed = None
        if isinstance(memo, _PullOff) and memo.output is before and direction < 0.0 and self._attached():
            # The last step pulled off and the held depth touched again: a bracket of the
            # detachment around the depth the last step's shift predicts.
            probed = self._predicted_detachment(residual, trials, d0, memo.shift, target)
        if probed is not None:
            found, boundary = probed
            if found is None:
                return self._pulled_off(boundary, time, start, last)
            lo, r_lo, hi, r_hi = found
        for _ in range(0 if probed is not None else 200):
            hi = lo + direction * delta
            r_hi = residual(hi)
            detached = direction < 0.0 and not self._attached()
            if r_hi * direction >= 0.0 and not (detached and r_hi == 0.0 and adhesive):
                break
            if detached:
                found, boundary = self._search_dip(residual, trials, target, golden_section=not dip_searched)
                if found is None:
                    return self._pulled_off(boundary, time, start, last)
                lo, r_lo, hi, r_hi = found
                break
            if direction < 0.0 and r_hi > r_lo and not dip_searched:
                # Pulled further, the force rose: the steps passed the force minimum above
                # the target. Search the dip there now rather than after the steps reach
                # the detachment (the trials there are the step's dearest: a receding edge
                # over many cells); the same golden section, between the same neighbours of
                # the smallest trial. None found: on to the detachment as before.
                dip_searched = True
                found, _ = self._search_dip(residual, trials, target, detachment=False)
                if found is not None:
                    lo, r_lo, hi, r_hi = found
                    break
            lo, r_lo = hi, r_hi
            delta *= 2.0
        else:
            if probed is None:
                model.rewind(start)
                raise InputError(f"force {target!r} N cannot be reached from depth {d0!r} m")
        if not was_in_contact and self._attached():
            # Snapped in: the stop's floor from the contact that formed.
            stop = max(stop, self._force_stop(target, model.radius))
        return self._finish_force(
            residual, time, target, lo, r_lo, hi, r_hi, stop, tol, last, trials, hold_force
        )

    def _finish_force(
        self,
        residual,
        time: float,
        target: float,
        lo: float,
        r_lo: float,
        hi: float,
        r_hi: float,
        stop: float,
        tol: float,
        last: list[Any],
        trials: list[tuple[float, float, float]],
        hold_force: float | None = None,
    ) -> StepOutput:
        """The bracketing search's end: the root in [lo, hi] (residuals r_lo, r_hi of
        opposite signs, or one within `stop`) published as the step."""
        was_in_contact = self.in_contact
        before = self._output
        d0, f0, dt = self._depth, before.force, time - self._time
        root, r_root = _bracketed_root(residual, lo, r_lo, hi, r_hi, stop)
        if last[0] != root:
            r_root = residual(root)
        jumped_in = not was_in_contact and self._attached() and self.physics.work_of_adhesion > 0.0
        # A residual left at the root beyond where the search stops means the force jumped
        # across the target (snap-in or a discontinuous edge): no continuous equilibrium
        # path; keep the state reached.
        converged = abs(r_root) <= max(tol, stop, 1e-9 * abs(target))
        unstable = not converged or jumped_in
        # The model is in the state of the trial at the root: publish it (no second trial).
        output = self._publish(time, root, last[1], unstable=unstable)
        # A snap-in that met the target is flagged (the force jumped) but its slope is
        # good for the next step's prediction; its force at the held depth (out of contact)
        # says nothing of the drift in contact: none.
        if jumped_in:
            hold_force, f0 = output.force, output.force
        self._remember(output, before, trials, d0, f0, dt, hold_force, None, converged=converged)
        return output

    #: Secant trials of a force step from rest (`_from_rest`) before the bracketing search.
    REST_TRIALS = 6

    def _from_rest(
        self, residual, d0: float, target: float, stop: float
    ) -> tuple[float, float, float, float, float] | None:
        """A force step on a body at rest (no contact, no memory) with the held depth `d0`
        (m) at or below the surface, on the time-stepped model: the search starts at the
        glass modulus' JKR contact for `target` (N) (`_TimeStepped.glass_contact`: from
        rest the body answers with its glass modulus) and takes secant steps from it,
        instead of a trial at the held depth and doubling steps (each a snap-in from rest:
        10 trials at a zero force). Returns (lo, r_lo, hi, r_hi, stop): a bracket of the
        root (or one end within `stop`, the stop's floor from the contact that formed), or
        None (the model rewound; the caller's search runs) when that contact does not exist,
        a trial does not touch, a secant slope is not within 4x of the glass one, or
        REST_TRIALS trials neither bracketed nor met the target."""
        model = self._model
        if not (d0 >= 0.0 and isinstance(model, _TimeStepped) and model.is_relaxed()):
            return None
        glass = model.glass_contact(target)
        if glass is None:
            return None
        x, stiffness = glass
        r = residual(x)
        slope = stiffness
        for _ in range(self.REST_TRIALS):
            if not self._attached():
                return None
            stop = max(stop, self._force_stop(target, model.radius))
            if abs(r) <= stop:
                return x, r, x, r, stop
            x_new = x - r / slope
            if x_new == x:
                return None
            r_new = residual(x_new)
            if not self._attached():
                return None
            if (r_new < 0.0) != (r < 0.0):
                stop = max(stop, self._force_stop(target, model.radius))
                return x, r, x_new, r_new, stop
            secant = (r_new - r) / (x_new - x)
            if not 0.25 * stiffness <= secant <= 4.0 * stiffness:
                return None
            x, r, slope = x_new, r_new, secant
        return None

    #: Trials of the predicted secant before it gives way to the bracketing search, and up
    #: to how many it goes on while each trial cuts the residual 100-fold (converging: a
    #: jump of the commanded force, a zero force whose stop is 1e-12 of the adhesive force).
    PREDICTED_TRIALS = 4
    PREDICTED_TRIALS_CONVERGING = 7
    _path_prediction = staticmethod(_path_prediction)

    def _predicted_root(
        self, residual, d0: float, first: float, slope: float, bend: float, stop: float, glass: float
    ) -> float | None:
        """Secant steps from the predicted depth `first` (m), the first with the last step's
        slope `slope` (N/m) carried from the held depth `d0` to `first` by its change along
        the path `bend` (N/m^2). Returns the depth of the trial within `stop` (N) of the
        target (the model left in its state), or None when a trial detaches, a secant slope
        is not within a factor 4 of `slope` (the force-depth curve bends: a fold or a jump is
        near, which the bracketing search handles), a secant step is longer than a step on
        FOLD_SLOPE times the glass stiffness `glass` (N/m) (a flat F(d) near the fold: such
        steps ran to the detachment, the step's dearest trials) or PREDICTED_TRIALS trials
        (up to PREDICTED_TRIALS_CONVERGING while each cuts the residual 100-fold) did not
        converge."""
        x = first
        if not abs(x) <= self._depth_limit:
            return None  # the search decides whether the force can be reached
        r = residual(x)
        if not self._attached():
            return None
        tangent = slope + bend * (first - d0)
        if not 0.5 * slope < tangent < 2.0 * slope:
            tangent = slope
        shrunk = False
        for trial in range(2, self.PREDICTED_TRIALS_CONVERGING + 1):
            if abs(r) <= stop:
                return x
            if trial > self.PREDICTED_TRIALS and not shrunk:
                return None
            x_new = x - r / tangent
            if (
                x_new == x
                or abs(x_new - x) * FOLD_SLOPE * glass > abs(r)
                or not abs(x_new) <= self._depth_limit
            ):
                return None
            r_new = residual(x_new)
            if not self._attached():
                return None
            secant = (r_new - r) / (x_new - x)
            if not 0.25 * slope <= secant <= 4.0 * slope:
                return None
            shrunk = abs(r_new) <= 0.01 * abs(r)
            x, r, tangent = x_new, r_new, secant
        return x if abs(r) <= stop else None

    def _remember(
        self,
        output: StepOutput,
        before: StepOutput,
        trials: list[tuple[float, float, float]],
        d0: float,
        f0: float,
        dt: float,
        hold_force: float | None,
        slope: float | None,
        *,
        converged: bool = False,
    ) -> None:
        """Keep what the next force step predicts its root from: the slope dF/dd at the root
        (from the trial nearest it, else `slope`), its change along the path since the step
        that ended in `before` (the output before this step), and the rate at which the force
        drifts at a held depth (from `hold_force`, the trial at the held depth d0, else
        extrapolated along the slope), tied to `output` (stale once the simulator's output
        is another). An unstable output is not remembered unless `converged` (it met the
        target)."""
        previous = self._force_memo
        if not isinstance(previous, tuple) or previous[0] is not before:
            previous = None
        self._force_memo = None
        point = (output.time, output.depth, output.force)
        path = (point,) if previous is None else (*previous[4][1 - PATH_POINTS :], point)
        root = output.depth
        if (output.unstable and not converged) or output.contact_radius <= 0.0:
            return
        nearest = None
        for depth, force, radius in trials:
            closer = nearest is None or abs(depth - root) < abs(nearest[0] - root)
            if radius > 0.0 and depth != root and closer:
                nearest = (depth, force)
        if nearest is not None:
            slope = (output.force - nearest[1]) / (root - nearest[0])
        if slope is None or not 0.0 < slope < math.inf:
            return
        if hold_force is None:
            hold_force = output.force + slope * (d0 - root)
        drift_rate = (hold_force - f0) / dt if dt > 0.0 else 0.0
        # The slope's change along the path, from the last step's slope if it left one.
        bend = 0.0
        if previous is not None and root != d0:
            bend = (slope - previous[1]) / (root - d0)
        if math.isfinite(drift_rate) and math.isfinite(bend):
            self._force_memo = (output, slope, drift_rate, bend, path)

    def _search_dip(
        self,
        residual,
        trials: list[tuple[float, float, float]],
        target: float,
        *,
        golden_section: bool = True,
        detachment: bool = True,
        bounded: bool = False,
    ) -> tuple[tuple[float, float, float, float] | None, float]:
        """A pull's bracketing steps reached a detached trial with every attached trial above
        the target: look for an attached force at or below the target between them (the
        minimum of F(d) lies before the fold, and the steps may have skipped it). Returns
        ((lo, r_lo, hi, r_hi): a bracket of the root nearest the held depth, or None) and,
        when there is none, the depth (detached side) where the contact lets go.

        The minimum is searched by golden section between the neighbours (by depth) of the
        smallest attached trial, a detached point counting as above everything, and given up
        once the smallest attached force found is above the target by more than the force can
        drop within the bracket; only then is the detachment depth bracketed (`_detachment`:
        aimed trials, within ITP's projection of a bisection), to 1e-13 relative, to half the
        force tolerance of the depths where the contact holds, or to where the force cannot
        move by more than half the force tolerance of the largest attached force across the
        interval (0.8.0: not of the target, which no attached depth reaches, nor of the
        detached end's depth: a hard pull moved the published depth). Both use the Lipschitz
        bound 2 x the glass stiffness 2 E0* a of the largest contact tried (F(d) moves no
        faster under an instantaneous change of depth).

        `golden_section=False` skips the first part (a search before found no dip around
        the same minimum), `detachment=False` the second (returns (None, nan): the steps
        passed the minimum before they detached, see `_solve_force`). `bounded=True` skips
        the golden section when the trials made already hold the bracket above the target by
        the same Lipschitz bound (the smallest attached trial lies inside it: every depth in
        it is within its width of that trial), as the section's first check would after its
        first two trials (`_predicted_detachment`: a bracket ~1e-3 of the pull wide, whose
        interior trials were the step's dearest)."""
        radius = max((r for _, _, r in trials), default=0.0)
        lipschitz = 4.0 * self.physics.e0 * radius
        samples = sorted(trials)
        attached = [i for i, (_, _, r) in enumerate(samples) if r > 0.0]
        if attached and golden_section:
            j = min(attached, key=lambda i: samples[i][1])
            left, right = samples[max(j - 1, 0)], samples[min(j + 1, len(samples) - 1)]
            a, b = left[0], right[0]
            golden = 0.5 * (math.sqrt(5.0) - 1.0)

            def value(x: float) -> float:
                """The residual at x, +inf when detached (the minimum is attached)."""
                r_x = residual(x)
                return r_x if self._attached() else math.inf

            if bounded and lipschitz * (b - a) < samples[j][1] - target:
                attached = []
        if attached and golden_section:
            # The residuals known at the bracket's ends (+inf where detached) and at the
            # smallest attached trial j, which the bracket holds until it shrinks past it.
            x_j, r_j = samples[j][0], samples[j][1] - target
            ra, rb = (f - target if r > 0.0 else math.inf for _, f, r in (left, right))
            c = b - golden * (b - a)
            d = a + golden * (b - a)
            rc = value(c)
            if rc <= 0.0:
                return self._dip_bracket(trials, target, c, rc), math.nan
            rd = value(d)
            if rd <= 0.0:
                return self._dip_bracket(trials, target, d, rd), math.nan
            # One new trial per iteration: the interior point that stays is reused.
            for _ in range(120):
                # The smallest attached force in [a, b] is above the target unless it drops by
                # more than the bound across the bracket from an attached value known in it
                # (c, d, the ends, or trial j; 0.10.0: not only c and d, so a bracket whose
                # interior trials all let go, shrinking onto an attached trial at a depth of
                # 1e-21 m, no longer runs down to 1e-10 of that depth: 98 trials where 0.9.0
                # took 6, an outside tester).
                inside = min(rc, rd, ra, rb, r_j if a <= x_j <= b else math.inf)
                if lipschitz * (b - a) < inside < math.inf:
                    break
                if abs(b - a) <= 1e-10 * max(abs(a), abs(b), 1e-300):
                    break
                if rc < rd:
                    b, rb, d, rd = d, rd, c, rc
                    c = b - golden * (b - a)
                    rc = value(c)
                    if rc <= 0.0:
                        return self._dip_bracket(trials, target, c, rc), math.nan
                else:
                    a, ra, c, rc = c, rc, d, rd
                    d = a + golden * (b - a)
                    rd = value(d)
                    if rd <= 0.0:
                        return self._dip_bracket(trials, target, d, rd), math.nan
        if not detachment:
            return None, math.nan
        # No dip: bisect the detachment between the deepest detached trial shallower than
        # every attached one and the shallowest attached trial.
        hi = min((d for d, _, r in trials if r > 0.0), default=math.nan)
        lo = max((d for d, _, r in trials if r <= 0.0 and d < hi), default=math.nan)
        if not (math.isfinite(lo) and math.isfinite(hi)):
            return None, min(d for d, _, r in trials if r <= 0.0)
        # The width is relative to where the contact holds: the depths of the shallowest
        # attached trial and of the held depth (not the detached end, which a hard pull puts
        # far away) and the largest attached force (not the target, which no attached depth
        # reaches). Relative to the pull, the depth published after a pull-off moved with the
        # force pulled (-1.23 um at -1 N, -1.31 um at -1000 N, -4.7 um at -1e6 N on the
        # default scene, where it lets go at -1.22 um).
        tolerance = self.numerics.force_tolerance
        held = max((abs(f) for _, f, r in trials if r > 0.0), default=0.0)
        width = max(
            0.5 * tolerance * held / lipschitz if lipschitz > 0.0 else 0.0,
            0.5 * tolerance * max(abs(hi), abs(self._depth)),
        )
        return self._detachment(residual, trials, target, lo, hi, width)

    def _detachment(
        self,
        residual,
        trials: list[tuple[float, float, float]],
        target: float,
        lo: float,
        hi: float,
        width: float,
    ) -> tuple[tuple[float, float, float, float] | None, float]:
        """The detachment between the detached depth `lo` and the attached depth `hi` (m)
        (`_search_dip`'s second part): a bracket no wider than `width` (m), its detached end
        returned as (None, end); or ((lo, r_lo, hi, r_hi), nan) when a trial on the way holds
        at or below the target.

        A trial that lets go says where along its path it did (`_TimeStepped.let_go_depth`),
        and near the fold that depth moves with the trial's depth about linearly: on the
        bench's hold-and-pull pull-off the let-go depth d_j of a trial to depth d is d_c +
        k (d - d_c), d_c the fold, k from -0.04 (d 2.6e-2 of the depth below d_c) to -0.09
        (4e-5 below), other histories k -0.3 .. 0, down to the trials that let go in the
        step's last substep (the jump is located to JUMP_RESOLUTION of the step: there d_j =
        d). So each trial aims a `spread` short of the fold estimated from the trials that
        let go (`_fold_estimate`), on the side with more room: below it (the trial lets go,
        and gives a let-go depth nearer the fold) or above it (it holds: the attached end
        comes down). The spread is the larger of 0.45 of the width, FOLD_JUMP of the jump's
        resolution in depth, and FOLD_MARGIN (FOLD_MARGIN_ONE while one trial let go: its
        estimate takes k = 0) of the estimate's distance from the nearest trial that let go,
        times a factor that a trial landing on the side not aimed at multiplies by FOLD_MISS
        and one landing as aimed by FOLD_HIT (down to 1). ITP's projection keeps every trial
        within `radius` of the midpoint, so the search takes at most FOLD_EXTRA trials more
        than the bisection whatever the estimates; without let-go depths (the closed forms,
        no trial let go from a contact) it is the bisection. The estimate only places the
        trials: the bracket, its width and the end returned are the bisection's."""
        let_go = getattr(self._model, "let_go_depth", None)
        pairs: list[tuple[float, float]] = []  # (depth, let-go depth) of the trials that let go
        if let_go is not None and trials and trials[-1][0] == lo:
            # `lo` is the last trial: the model is still in its state.
            jump = let_go()
            if lo < jump:
                pairs.append((lo, jump))
        d0 = self._depth
        limit = max(1e-13 * max(abs(hi), abs(lo), 1e-300), width)
        most = max(math.ceil(math.log2(max((hi - lo) / limit, 1.0))), 0) + self.FOLD_EXTRA
        factor = 1.0
        for k in range(1, 121):
            limit = max(1e-13 * max(abs(hi), abs(lo), 1e-300), width)
            gap = hi - lo
            if gap <= limit:
                break
            mid = 0.5 * (lo + hi)
            x = mid
            aim = 0  # -1: aimed to let go, 1: to hold
            if pairs:
                fold = _fold_estimate(pairs)
                nearest = pairs[-1][0]
                margin = self.FOLD_MARGIN if len(pairs) > 1 else self.FOLD_MARGIN_ONE
                spread = factor * max(
                    0.45 * limit,
                    self.FOLD_JUMP * _kernels.JUMP_RESOLUTION * abs(nearest - d0),
                    margin * abs(fold - nearest),
                )
                below = lo < fold - spread
                above = fold + spread < hi
                if below and (not above or fold - lo >= hi - fold):
                    x, aim = fold - spread, -1
                elif above:
                    x, aim = fold + spread, 1
                # ITP's projection: within `radius` of the midpoint the bracket after trial
                # k is at most limit 2^(most - k) wide.
                radius = max(limit * 2.0 ** (most - k) - 0.5 * gap, 0.0)
                if not lo < x < hi:
                    x, aim = mid, 0
                elif not abs(x - mid) <= radius:
                    x, aim = mid + math.copysign(radius, x - mid), 0
            r_x = residual(x)
            attached = self._attached()
            if attached:
                hi = x
                if r_x <= 0.0:
                    return self._dip_bracket(trials, target, x, r_x), math.nan
            else:
                lo = x
                if let_go is not None:
                    jump = let_go()
                    if x < jump:
                        pairs.append((x, jump))
            if aim:
                missed = (aim > 0) != attached
                factor = factor * self.FOLD_MISS if missed else max(1.0, factor * self.FOLD_HIT)
        return None, lo

    #: `_detachment`: trials it may take over the bisection's count; the spread of an aimed
    #: trial as a fraction of the fold estimate's distance from the nearest trial that let go
    #: (from two such trials or more, and from one); the spread's factor after a trial that
    #: landed on the side not aimed at, and after one that landed as aimed; the spread's
    #: floor as a fraction of the let-go depth's resolution (JUMP_RESOLUTION of the trial's
    #: path: the fits came within a fraction of it; 1 cost 1-5 trials more). Chosen on the
    #: bench's and the tests' hold-and-pull histories, checked on 16 others (pull rates,
    #: time steps, K = 0/1/2): benchmarks/rounds/0.10.0-holdpull.md.
    FOLD_EXTRA = 2
    FOLD_MARGIN = 0.03
    FOLD_MARGIN_ONE = 0.5
    FOLD_MISS = 2.0
    FOLD_HIT = 0.5
    FOLD_JUMP = 0.2

    @staticmethod
    def _dip_bracket(
        trials: list[tuple[float, float, float]], target: float, dip: float, r_dip: float
    ) -> tuple[float, float, float, float]:
        """The bracket (lo, r_lo, dip, r_dip) of the root between the attached trial `dip`
        (force at or below the target) and the nearest trial on the held depth's side
        (larger depth: the search pulls) whose force is above the target (the held depth's
        trial is one)."""
        lo, r_lo = min((d, f - target) for d, f, _ in trials if d > dip and f - target > 0.0)
        return lo, r_lo, dip, r_dip

    def _pulled_off(self, detached: float, time: float, start: Any, last: list[Any]) -> StepOutput:
        """No equilibrium under force control: move to the detached state at the depth where
        the contact let go (`detached`, m, from `_search_dip`), flagged unstable; `start`:
        the model's state before the step; `last`: the depth of the last trial and its
        result (when that trial was at `detached`, the model is in that state already)."""
        self._force_memo = None
        d0 = self._depth
        if last[0] == detached:
            output = self._publish(time, detached, last[1], unstable=True)
        else:
            self._model.rewind(start)
            output = self._move(time, detached, unstable=True)
        if detached < d0:
            self._force_memo = _PullOff(output, detached - d0)
        return output

    #: Half-width of the bracket `_predicted_detachment` tries, relative to the last shift,
    #: and how many times it widens the bracket (4x each) on the side the prediction missed.
    PULL_MARGIN = 2e-3
    PULL_WIDENINGS = 5

    def _predicted_detachment(
        self,
        residual,
        trials: list[tuple[float, float, float]],
        d0: float,
        shift: float,
        target: float,
    ) -> tuple[tuple[float, float, float, float] | None, float] | None:
        """A pull after a pull-off whose held depth `d0` (m) touched again as the surface crept
        back: the contact lets go about as far below the held depth as in the last step
        (`shift`, m; on the bench's hold-and-pull history the shift changes by ~1e-11 of its
        2.4e-8 m per step). A trial PULL_MARGIN |shift| deeper than d0 + shift, then on the
        other side of it at 1, 4, 16 ... times that margin until one has the other contact
        state: a deeper trial that holds on above the target and a shallower one that has let
        go bracket the detachment, and `_search_dip` runs from them (its dip search then stops
        at once on its Lipschitz bound, its bisection starts from a bracket ~1e-3 of the shift
        wide, instead of golden-section and bisection steps from a bracket the size of the
        pull). Returns `_search_dip`'s answer, or None (the trials stay in `trials`, which the
        caller's search reads; it runs as without them) when no bracket was found."""
        margin = self.PULL_MARGIN * abs(shift)
        centre = d0 + shift
        x = centre + margin
        if not (margin > 0.0 and x < d0):
            return None
        r = residual(x)
        held = self._attached()
        if held and r <= 0.0:
            return None
        offset = margin
        for _ in range(self.PULL_WIDENINGS + 1):
            x = centre - offset if held else centre + offset * 4.0
            offset *= 4.0
            if not x < d0:
                return None
            r = residual(x)
            attached = self._attached()
            if attached and r <= 0.0:
                return None
            if attached != held:
                return self._search_dip(residual, trials, target, bounded=True)
        return None
