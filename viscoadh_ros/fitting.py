"""Identify material parameters from a recorded experiment by least squares (scipy).

Parameters are named as in physics.md: ``G0`` (glass shear modulus, Pa), ``G1..GK`` (Kelvin
shear moduli, Pa), ``eta1..etaK`` (Kelvin viscosities, Pa s) and ``work_of_adhesion`` (J/m^2).
The fit works in ``u = log(p / p_start)`` (all are positive and span decades) inside a box of
``p_start / bounds_factor .. p_start * bounds_factor``, on residuals in units of the record's
noise level ``(model - measured) / sigma`` at the measured-force stamps.

How it finds the optimum from a poor start (issue 12):

1. **One grid for the whole fit.** The model's element row is sized once, from the record's
   deepest point and the box (:func:`fit_grid`: the largest contact radius any trial can reach
   is the glass-modulus JKR radius at the deepest depth with the largest work of adhesion and
   the smallest G0 of the box: elements beyond the largest radius ever in contact are fresh,
   and a fresh element attaches on the glass criterion alone). Sizing it from each trial's
   own values (the simulator's default) moved the grid with every trial and made the cost a
   sawtooth along w at the scale of a finite-difference step: the optimiser stopped where it
   started.
2. **The pull-off jump is masked**: a measured change between two samples beyond the noise
   and against the depth's change (:func:`smooth_samples`) is left out with
   :data:`JUMP_MARGIN` samples, and at least :data:`JUMP_WINDOW` of the record, either side.
3. **A coarse global stage**: on the fit's grid at the start's preset, on at most
   :data:`COARSE_SAMPLES` of the used samples (every k-th) and with the jump masks
   :data:`COARSE_JUMP_WINDOW` of the record wide (far from the optimum the model's own
   pull-off lands samples away from the measured one: each sample it crosses moves the cost
   by ``(pull-off / noise)^2``, a staircase no descent climbs). A local descent
   (``least_squares``, trust region in the box) from the start; when its fit error is above
   the noise, the cost at :data:`GLOBAL_POINTS` scrambled-Sobol points of the box (seeded:
   same record and options, same numbers) and descents from the best; the lowest cost wins.
   The descent's difference step is matched to what roughness remains
   (:func:`_difference_step`). The coarse stage runs on a thinned record
   (:func:`coarse_record`: its samples and the inputs that reach them), so each run steps
   the model once per kept stamp, not once per input: on a 5000-sample record a third of
   the time, which lets a descent crawl further along a flat valley (the K = 2 chain's
   slow retardation time) within the same CPU.
3a. **Labels of a chain**: with two or more Kelvin elements all free, the start's elements
   and the coarse stage's result are put in ascending retardation time (:func:`by_retardation`;
   the force does not depend on their order), so ``G1, eta1`` is the fastest mode. Then a
   **retardation scan** (:func:`_retardation_scan`): along a slow retardation time the cost
   falls so gently that descents stop far from the valley's floor (the K = 2 bench record:
   the slow time at half the truth's, noise-consistent by every test); each retardation time
   is moved by :data:`RETARDATION_FACTOR` either way with the moduli re-fitted, and the fit
   descends from the best move while one lowers the cost.
3c. **A medium descent** (thinned record only): on the thinned record at the polish's grid
   before the polish, whose secant steps (2p full runs each) crawl along such a valley from
   the coarse grid's optimum to the polish grid's.
3b. **The polish grid from the noise** (:func:`polish_elements`): the fit's grid with the
   element count `numerics_for_tolerance` chooses for a model error of
   :data:`MODEL_ERROR_FRACTION` of the record's noise (both relative to its pull-off force),
   so the cost near the optimum is noise-dominated and smooth at the scale of a standard
   deviation; the polish and the intervals run on it, on every used sample.
4. **A stationarity test**: at the optimum a central secant Jacobian gives the Gauss-Newton
   step; if it still proposes more than one standard deviation in any parameter the fit takes
   it and descends again, and a fit whose step stays above :data:`STATIONARY_SIGMAS` is
   reported as not converged, never as a success.
5. **Intervals**: linearised from the secant Jacobian, ``cov = s^2 (J^T J)^-1`` with the
   residual variance ``s^2``, widened where the cost along a parameter's profile direction
   rises less than the linear model says, each side on its own (:func:`_profile_inflation`,
   never narrowed: a valley steep on one side and flat on the other bounds the parameter on
   one side only, and the mean of the two sides would read it as identified), plus
   a model-error term for the discretisation: the shift of the optimum that refining the
   grid (twice the elements) would cause (its Gauss-Newton step from one model run on the
   refined grid against the polish's Jacobian), added in quadrature.
   The 95 % interval is ``u - 1.96 sigma_low .. u + 1.96 sigma_high`` (asymmetric in the
   parameter, and in u where the profile is); the stated standard deviation is the mean of
   the two. Their coverage is tested on seeded synthetic records (tests/test_fit_coverage.py).
6. **A load-cell offset** (what the load cell reads at zero force, N; the record is the model
   plus it). With ``FitOptions.fit_offset`` it is fitted beside the parameters by variable
   projection: every residual the fit sees (``_Problem.residual``: coarse, medium, polish,
   profiles, the refined grid's) is ``model - measured`` less its mean over the used samples,
   the best offset at that trial, so the secants, the covariance, the profiles and the
   model-error term all see it profiled out. Its value is ``mean(measured - model)`` at the
   optimum; its variance that of the augmented fit ``[J_raw, 1]``: ``s^2 / n + m^T C m`` (``m``
   the secant of the mean unprofiled residual, ``C`` the parameters' covariance with the
   profile widening), plus the shift the refined grid gives it, in quadrature. Without the
   option a score (Lagrange-multiplier) test for one at the optimum,
   ``z = sum(r) / (s sqrt(n - 1^T J (J^T J)^-1 J^T 1))`` (:func:`offset_score`), marks a fit
   with ``|z| >`` :data:`OFFSET_SIGMAS` as a misfit: the residual correlation subtracts the mean
   and cannot see an offset, and the parameters absorb most of one (1 % of the peak force moved
   G0 by +12 % at RMSE/noise 1.00). The test sees an offset only where it is not absorbed: one
   of 0.3 % of the peak (z about 0.6 on the standard record) still moves G0 by 5 %; a record
   from a load cell that may not be tared needs the option (tests/test_fit_offset.py).

A parameter the record cannot identify (no dependence, a flat valley with another one, or a
relative standard deviation above :data:`MAX_RELATIVE_UNCERTAINTY`) is reported as not
identified with its interval (clipped to the box), not as a point with a meaningless error
bar. A record that cannot say anything about a parameter at all (a work of adhesion without a
pull-off) is refused before fitting with a :class:`FitError` naming it.
"""

from __future__ import annotations

import dataclasses
import math
import re
import time as wallclock
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.stats import qmc

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.experiment import (
    DEPTH,
    PARAMETERS,
    Experiment,
    Restart,
    at_rest,
    changed_contact,
    run_model,
    stretch,
)

if TYPE_CHECKING:
    from viscoadh_ros.core.config import ContactConfig

_NAME = re.compile(r"^(G0|G[1-9]\d*|eta[1-9]\d*|work_of_adhesion)$")
UNITS = {"G": "Pa", "eta": "Pa s", "work_of_adhesion": "J/m^2"}
SEGMENTS = ("both", "approach", "retract")
#: Largest standard deviation of a log-parameter (about +-50 %) accepted as "identified".
MAX_RELATIVE_UNCERTAINTY = 0.5
#: Singular-value ratio of the column-scaled Jacobian beyond which parameters only act together.
MAX_CONDITION = 1e6
#: Half-width of the central secant of the stationarity test and the intervals, in u. With one
#: grid for the fit the cost is smooth at this scale (0.1.0 needed 10 % against the moving grid).
SECANT_STEP = 0.02
#: The secant of the polish and the intervals spans this many standard deviations of each
#: parameter (at least 3 difference steps): wide against the model's roughness (single samples
#: whose force flips by ~1 noise deviation as an element event crosses a stamp), narrow
#: against its curvature.
SECANT_SIGMAS = 3.0
#: Narrowest secant, in u: wide against the roughness of long records (whose standard
#: deviations are small), narrow against the curvature (its bias ~ width^2 is ~1e-5 here).
MIN_SECANT = 5e-3
#: The profile check of the intervals (`_profile_inflation`): each side of each parameter's
#: interval ends where its profile (the cost with the other parameters descended) has risen by
#: Z95^2 noise variances, searched outward from the linear interval's end by this factor per
#: trial (at most PROFILE_TRIALS); never narrower than the linear interval.
PROFILE_GROWTH = 1.6
PROFILE_TRIALS = 6
PROFILE_BENDS = 2
#: The others' descent at a profile point (scipy's least_squares, forward secants) stops when
#: a step gains less than PROFILE_GAIN noise variances, or after PROFILE_EVALUATIONS steps.
PROFILE_GAIN = 0.05
PROFILE_EVALUATIONS = 8
#: Default half-width of the search box: each free parameter within start/10 .. start*10.
BOUNDS_FACTOR = 10.0
#: Scrambled-Sobol points of the global stage, and how many of the best start local descents.
GLOBAL_POINTS = 16
GLOBAL_DESCENTS = 2
#: A descent whose reduced chi-square is within this many of its standard deviations
#: (sqrt(2/dof)) of 1 fits to the noise: no other point of the box can do significantly better.
NOISE_CONSISTENT = 3.0
#: Cost evaluations per local descent at most (each iteration also runs the model once per
#: free parameter for its Jacobian).
DESCENT_EVALUATIONS = 25
#: A fit whose Gauss-Newton step at the optimum exceeds this many standard deviations of a
#: parameter is not converged.
STATIONARY_SIGMAS = 2.0
#: Gauss-Newton steps of the polish at most, and the step (in standard deviations) it stops at.
POLISH_STEPS = 6
POLISH_SIGMAS = 0.2
#: Polish steps up to this many standard deviations are taken on the secant model's word.
POLISH_TRUST = 3.0
#: Two-sided 95 % normal quantile.
Z95 = 1.959963984540054
#: A change of the measured force between consecutive samples beyond this many noise
#: deviations of a change, against the depth's change, is a jump (`smooth_samples`).
JUMP_NOISE = 10.0
JUMP_MARGIN = 2
#: A pull-off needs a tensile force beyond this many noise deviations, then that many samples
#: in a row at zero within them.
PULL_OFF_NOISE_BAND = 5.0
PULL_OFF_FREE_SAMPLES = 5
#: ... and at least this fraction of the record's samples either side: within it the force
#: before a pull-off is so steep in the parameters that a secant of a few standard deviations
#: reads the model's pull-off crossing samples as slope (measured on 5000 samples: 0.2 % of
#: the record makes secants of 1e-3 and 5e-3 agree, and the interval of G0 6x wider, honest).
JUMP_WINDOW = 0.005
#: The retardation-time scan of a chain (`_retardation_scan`): each round moves one
#: retardation time by this factor either way, re-fits the moduli in this many evaluations,
#: and descends from the best move when it lowers the cost; at most this many rounds.
RETARDATION_FACTOR = 2.0
RETARDATION_EVALUATIONS = 6
RETARDATION_ROUNDS = 3
#: The fit's grid: this margin over the largest reachable contact radius, and at most this
#: many times the preset's elements to keep the start's contact as finely resolved.
GRID_MARGIN = 1.2
MAX_ELEMENT_FACTOR = 4
#: The polish's model error (`numerics_for_tolerance`, relative to the pull-off force) is at
#: most this fraction of the record's noise (relative to the same force): the cost near the
#: optimum is then noise-dominated and smooth at the scale of a standard deviation.
MODEL_ERROR_FRACTION = 0.5
#: The global stage and the first descents see at most this many samples (every k-th used
#: one): the coarse grid's roughness is then small against their wider standard deviations.
COARSE_SAMPLES = 1000
#: ... and their jump masks reach this fraction of the record's samples either side.
COARSE_JUMP_WINDOW = 0.02


class FitError(InputError):
    """The data cannot identify a free parameter, or the fit did not converge."""


def unit_of(name: str) -> str:
    """SI unit of a parameter name."""
    if name == "work_of_adhesion":
        return UNITS[name]
    return UNITS["eta"] if name.startswith("eta") else UNITS["G"]


def parameter_names(kelvin: int) -> list[str]:
    """All parameter names of a chain with ``kelvin`` Kelvin elements."""
    return [
        "G0",
        *(f"G{k}" for k in range(1, kelvin + 1)),
        *(f"eta{k}" for k in range(1, kelvin + 1)),
        "work_of_adhesion",
    ]


def parse_free(text: str, kelvin: int) -> list[str]:
    """``"G0,G1,eta1"`` -> names, checked against the chain; InputError on an unknown one."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    allowed = parameter_names(kelvin)
    for name in names:
        if not _NAME.match(name) or name not in allowed:
            raise InputError(
                f"--free: unknown parameter {name!r} for {kelvin} Kelvin element(s); known: {allowed}"
            )
    if len(set(names)) != len(names) or not names:
        raise InputError(f"--free must name each parameter once (got {text!r})")
    return names


def parameters_of(contact: ContactConfig) -> dict[str, float]:
    """Current parameter values of a contact."""
    material = contact.material
    values = {"G0": float(material.glass_shear_modulus)}
    for k, (g, eta) in enumerate(
        zip(material.kelvin_shear_moduli, material.kelvin_viscosities, strict=True), start=1
    ):
        values[f"G{k}"] = float(g)
        values[f"eta{k}"] = float(eta)
    values["work_of_adhesion"] = float(contact.adhesion.work_of_adhesion)
    return values


def with_parameters(contact: ContactConfig, values: dict[str, float], kelvin: int) -> ContactConfig:
    """``contact`` with the material and adhesion set from ``values`` (all names of the chain)."""
    # The fitted chain replaces any Prony series the base scene was given as (to_dict writes
    # the Prony fields of such a material, which would silently drop the fit).
    material = dataclasses.replace(
        contact.material,
        glass_shear_modulus=values["G0"],
        kelvin_shear_moduli=tuple(values[f"G{k}"] for k in range(1, kelvin + 1)),
        kelvin_viscosities=tuple(values[f"eta{k}"] for k in range(1, kelvin + 1)),
        prony_long_term_modulus=0.0,
        prony_moduli=(),
        prony_times=(),
    )
    adhesion = dataclasses.replace(contact.adhesion, work_of_adhesion=values["work_of_adhesion"])
    return dataclasses.replace(contact, material=material, adhesion=adhesion)


def initial_values(contact: ContactConfig, kelvin: int) -> dict[str, float]:
    """Start values from ``contact``; a chain of another length is spread over decades of
    retardation time around the base one, with the same relaxed compliance."""
    base = parameters_of(contact)
    base_k = len(contact.material.kelvin_shear_moduli)
    if base_k == kelvin:
        return base
    if base_k == 0:
        raise InputError("the base scene has no Kelvin element to start a viscoelastic fit from")
    g1, tau1 = base["G1"], base["eta1"] / base["G1"]
    values = {"G0": base["G0"], "work_of_adhesion": base["work_of_adhesion"]}
    for k in range(1, kelvin + 1):
        tau = tau1 * 10.0 ** (k - (kelvin + 1) / 2)
        values[f"G{k}"] = g1 * kelvin
        values[f"eta{k}"] = g1 * kelvin * tau
    return values


@dataclass(frozen=True)
class FitOptions:
    """How to fit (everything but the record and the start scene).

    segment: which measured samples count: ``both``, ``approach`` (the depth last moved
    down into the body) or ``retract`` (it last moved out). time_range: ``(t0, t1)`` s since
    the first input, or None for all. bounds_factor: the box, start/f .. start*f (> 1).
    seed: of the global stage's Sobol points. fit_offset: fit a constant load-cell offset
    beside the parameters (what the load cell reads at zero force, N; profiled out of every
    residual, see :func:`fit`); off, the fit tests for one (:data:`OFFSET_SIGMAS`).
    """

    segment: str = "both"
    time_range: tuple[float, float] | None = None
    bounds_factor: float = BOUNDS_FACTOR
    seed: int = 0
    fit_offset: bool = False

    def __post_init__(self) -> None:
        if self.segment not in SEGMENTS:
            raise InputError(f"segment must be one of {', '.join(SEGMENTS)} (got {self.segment!r})")
        if self.time_range is not None:
            t0, t1 = (float(v) for v in self.time_range)
            if not (math.isfinite(t0) and math.isfinite(t1) and t0 < t1):
                raise InputError(f"time range must be two finite times T0 < T1, s (got {self.time_range!r})")
        if not (math.isfinite(self.bounds_factor) and self.bounds_factor > 1.0):
            raise InputError(f"bounds factor must be a finite number > 1 (got {self.bounds_factor!r})")


@dataclass(frozen=True)
class FitResult:
    """Fitted values (SI), their 95 % intervals and standard deviations, and the fit error.

    ``uncertainty`` is one standard deviation of each free parameter (``value * sigma_u`` of
    its log); ``interval`` the 95 % interval ``(lo, hi)``; ``identified`` False for a
    parameter the record cannot fix (its interval then says what it can: the box when
    nothing). ``noise`` is the record's own noise level (N, from its second differences),
    ``rmse``/``r2`` are over the fitted samples (``used``, a mask over the measured ones).
    """

    values: dict[str, float]  # every parameter of the chain (free and held)
    uncertainty: dict[str, float]  # free parameters only, 1 sigma, SI
    interval: dict[str, tuple[float, float]]  # free parameters only, 95 %, SI
    identified: dict[str, bool]  # free parameters only
    free: tuple[str, ...]
    rmse: float  # N, over the fitted samples
    max_error: float  # N, over the fitted samples
    noise: float  # N, the record's noise level
    r2: float  # coefficient of determination over the fitted samples
    samples: int  # fitted samples
    contact: ContactConfig  # the base contact with the fitted values (its own numerics)
    model_contact: ContactConfig  # the same on the fit's grid (what the fit ran)
    used: NDArray[np.bool_]  # (m,) measured samples in the residuals
    status: str  # "ok", "unidentified" (some parameter not identified) or "misfit" (see reason)
    reason: str  # empty, or which parameters the record cannot fix and why
    model_runs: int
    wall_time: float  # s
    bounds: dict[str, tuple[float, float]] = field(default_factory=dict)  # the box, SI
    #: Largest Gauss-Newton step the secant model still proposes at the result, in standard
    #: deviations of the parameter (the stationarity test's number).
    stationarity: float = 0.0
    model_time: float = 0.0  # s of wall_time spent running the model
    #: The fitted load-cell offset (N, what the load cell reads at zero force: the model plus
    #: it is what the record is fitted to), its standard deviation and 95 % interval; None
    #: (nan) when the fit ran without one (`FitOptions.fit_offset`).
    offset: float | None = None
    offset_uncertainty: float = math.nan
    offset_interval: tuple[float, float] | None = None
    #: Without a fitted offset: the score statistic for adding one (standard deviations;
    #: |z| > OFFSET_SIGMAS is status "misfit"); nan with one.
    offset_score: float = math.nan
    #: The score statistic for a linear drift of the force in time beyond a constant
    #: (standard deviations; |z| > DRIFT_SIGMAS is status "misfit"), with or without an offset.
    drift_score: float = math.nan

    def row(self) -> dict[str, Any]:
        """One flat summary row (the batch runner's table): every value, its interval and
        standard deviation, the fit error against the noise, status and time."""
        row: dict[str, Any] = {"status": self.status, "reason": self.reason}
        for name, value in self.values.items():
            row[name] = value
            if name in self.interval:
                row[f"{name}_lo95"], row[f"{name}_hi95"] = self.interval[name]
                row[f"{name}_sigma"] = self.uncertainty[name]
                row[f"{name}_identified"] = self.identified[name]
        if self.offset is not None and self.offset_interval is not None:
            row["offset_N"] = self.offset
            row["offset_lo95_N"], row["offset_hi95_N"] = self.offset_interval
            row["offset_sigma_N"] = self.offset_uncertainty
        else:
            row["offset_z"] = self.offset_score
        row["drift_z"] = self.drift_score
        row.update(
            rmse_N=self.rmse,
            noise_N=self.noise,
            r2=self.r2,
            samples=self.samples,
            model_runs=self.model_runs,
            wall_time_s=self.wall_time,
        )
        return row


def noise_level(force: NDArray[np.float64]) -> float:
    """Standard deviation of white noise on ``force`` (N), robust to the signal: from the
    median absolute deviation of the second differences (``var(d2) = 6 sigma^2``)."""
    if force.size < 4:
        return 0.0
    d2 = np.diff(force, 2)
    return 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / math.sqrt(6.0)


#: Lag-1 autocorrelation of the residuals beyond this many of its standard errors (1/sqrt(n)
#: for white noise) marks a systematic misfit: a fit whose RMSE sits near the noise can still
#: miss the record along a smooth stretch (a local optimum, a missing Kelvin element), which
#: the RMSE cannot tell from an error in the noise estimate but correlated residuals do.
MISFIT_SIGMAS = 4.0


#: Without a fitted offset, a score (Lagrange-multiplier) statistic for adding a constant force
#: offset beyond this many standard deviations marks a misfit (`offset_score`): the residual
#: correlation cannot see an offset (it subtracts the residuals' mean), and the parameters
#: absorb most of one (an offset of 1 % of the peak force moved G0 by +12 % at RMSE/noise 1.00).
OFFSET_SIGMAS = 4.0


def offset_score(r: NDArray[np.float64], jac: NDArray[np.float64], constants: int = 0) -> float:
    """The score statistic for adding a constant to a least-squares fit at its optimum, in
    standard deviations (about N(0, 1) without an offset): ``sum(r) / (s sqrt(n - h))`` with
    ``h = 1^T J (J^T J)^-1 J^T 1`` (the part of a constant the parameters' columns ``jac``
    already span) and ``s^2 = r.r / (n - p - constants)`` the residual variance. ``r`` and
    ``jac`` in the same units (the fit's: noise deviations)."""
    n, p = r.size, jac.shape[1]
    ones = np.ones(n)
    spanned = jac @ np.linalg.lstsq(jac, ones, rcond=None)[0]
    free = float(n - ones @ spanned)
    s2 = float(r @ r) / max(n - p - constants, 1)
    if not (free > 0.0 and s2 > 0.0):
        return 0.0
    return float(np.sum(r)) / math.sqrt(s2 * free)


#: A score statistic for adding a linear drift of the force in time (beyond a constant)
#: beyond this many standard deviations marks a misfit (`drift_score`), with or without a
#: fitted offset: a load cell that drifts leaves a ramp in the residuals that a fitted offset
#: does not remove and the lag-1 correlation can miss (the second tester: a drift of 2 % of the
#: peak force over the record fitted `ok` with --fit-offset, G0 6 % low outside its interval).
DRIFT_SIGMAS = 4.0


def drift_score(
    r: NDArray[np.float64], jac: NDArray[np.float64], time: NDArray[np.float64], constants: int = 0
) -> float:
    """`offset_score` for a linear drift: the score of adding ``time`` (s, at the residuals'
    samples) as a column beside the parameters' ``jac`` and a constant, in standard deviations
    (about N(0, 1) without a drift); ``constants`` as in `offset_score`."""
    n, p = r.size, jac.shape[1]
    if n < p + 3:
        return 0.0
    ramp = time - float(np.mean(time))
    span = float(np.max(np.abs(ramp)))
    if not span > 0.0:
        return 0.0
    ramp = ramp / span
    basis = np.column_stack([jac, np.ones(n)])
    rest = ramp - basis @ np.linalg.lstsq(basis, ramp, rcond=None)[0]
    free = float(rest @ rest)
    s2 = float(r @ r) / max(n - p - constants, 1)
    if not (free > 0.0 and s2 > 0.0):
        return 0.0
    # The residual's part along the constant is left to `offset_score` (or is zero when the
    # offset is fitted): the score reads the ramp's part the parameters and a constant cannot.
    return float(rest @ r) / math.sqrt(s2 * free)


def residual_correlation(error: NDArray[np.float64]) -> float:
    """Lag-1 autocorrelation of residuals ``error`` (0 for white noise; about 1 for a smooth
    misfit), over the samples in their order."""
    if error.size < 3:
        return 0.0
    e = error - float(np.mean(error))
    denominator = float(e @ e)
    return float(e[1:] @ e[:-1]) / denominator if denominator > 0.0 else 0.0


def _noise_floor(force: NDArray[np.float64]) -> float:
    """The noise level, never below 1e-6 of max|F| (a noiseless synthetic record)."""
    return max(noise_level(force), 1e-6 * float(np.max(np.abs(force))), 1e-300)


def has_pull_off(force: NDArray[np.float64], *, offset: bool = False) -> bool:
    """True if ``force`` (N, > 0 compressive) becomes tensile beyond its noise and later
    stays at zero within it for PULL_OFF_FREE_SAMPLES samples in a row: the contact was
    pulled off (a reload that only crosses zero is not). With ``offset`` (the fit fits a
    load-cell offset) "zero" is the level the record settles at after its most tensile
    sample (the median there), whatever the offset (the second tester: a record with an
    offset over 5 noise deviations, or without noise, was refused as holding no pull-off)."""
    if force.size < 4:
        return False
    band = PULL_OFF_NOISE_BAND * _noise_floor(force)
    lowest = int(np.argmin(force))
    level = float(np.median(force[lowest + 1 :])) if offset and lowest + 1 < force.size else 0.0
    if not force[lowest] < level - band:
        return False
    free = np.abs(force[lowest + 1 :] - level) <= band
    if free.size < PULL_OFF_FREE_SAMPLES:
        return False  # the record ends at (or right after) its most tensile sample
    run = np.convolve(free.astype(np.int64), np.ones(PULL_OFF_FREE_SAMPLES, dtype=np.int64), "valid")
    return bool(run.size and np.max(run) >= PULL_OFF_FREE_SAMPLES)


def smooth_samples(
    force: NDArray[np.float64], noise: float | None = None, depth: NDArray[np.float64] | None = None
) -> NDArray[np.bool_]:
    """Mask of the samples of a measured force away from its jumps (snap-in, pull-off).

    With ``depth`` (m, at the force samples): a jump is a change beyond JUMP_NOISE noise
    deviations of a change against the depth's own change (the force rises while the depth
    falls, or falls while it rises: an unstable branch), or a release from tension to zero
    at a held depth. A steep ramp, a reversal or a fast relaxation is never one, however
    coarsely sampled. Without ``depth``: a change beyond JUMP_NOISE deviations and three
    times the median of its four neighbours' changes. JUMP_MARGIN samples either side go too.
    """
    keep = np.ones(force.size, dtype=bool)
    if force.size < 5:
        return keep
    sigma = _noise_floor(force) if noise is None else noise
    change = np.diff(force)
    large = np.abs(change) > JUMP_NOISE * math.sqrt(2.0) * sigma
    if depth is not None:
        moved = np.diff(depth)
        band = PULL_OFF_NOISE_BAND * sigma
        released = (moved == 0.0) & (force[:-1] < -band) & (np.abs(force[1:]) <= band)
        jumps = large & ((change * moved < 0.0) | released)
    else:
        padded = np.pad(np.abs(change), 2, mode="edge")
        neighbours = np.stack([padded[:-4], padded[1:-3], padded[3:-1], padded[4:]])
        jumps = large & (np.abs(change) > 3.0 * np.median(neighbours, axis=0))
    for jump in np.flatnonzero(jumps):
        keep[max(jump - JUMP_MARGIN, 0) : jump + 1 + JUMP_MARGIN + 1] = False
    return keep


def segment_samples(experiment: Experiment, options: FitOptions) -> NDArray[np.bool_]:
    """Measured samples of the chosen segment and time range (see `FitOptions`)."""
    t = experiment.time(experiment.measured_ns)
    keep = np.ones(t.size, dtype=bool)
    if options.time_range is not None:
        t0, t1 = options.time_range
        keep &= (t >= t0) & (t <= t1)
    if options.segment != "both":
        t_in = experiment.time(experiment.input_ns)
        # Direction of the last depth change before (or at) each measured stamp.
        moves = np.flatnonzero(np.diff(experiment.input_value) != 0.0)
        direction = np.zeros(t_in.size)
        direction[moves + 1] = np.sign(np.diff(experiment.input_value)[moves])
        last_move = np.maximum.accumulate(np.where(direction != 0.0, np.arange(t_in.size), 0))
        held = direction[last_move]
        at = np.searchsorted(t_in, t, side="right") - 1
        state = np.where(at >= 0, held[np.maximum(at, 0)], 0.0)
        # A sample between two inputs belongs to the move towards the next one.
        nxt = np.minimum(at + 1, t_in.size - 1)
        towards = np.sign(experiment.input_value[nxt] - experiment.input_value[np.maximum(at, 0)])
        state = np.where(towards != 0.0, towards, state)
        keep &= state > 0.0 if options.segment == "approach" else state < 0.0
    return keep


def fit_grid(
    contact: ContactConfig, experiment: Experiment, bounds: dict[str, tuple[float, float]]
) -> tuple[float, int]:
    """``(domain_radius m, elements)`` of the fit's one grid (see the module docstring):
    :data:`GRID_MARGIN` times the largest contact radius any trial in ``bounds`` can reach
    at the record's deepest point, with the preset's elements scaled up (at most
    :data:`MAX_ELEMENT_FACTOR` times) so the start's contact keeps its resolution."""
    from viscoadh_ros.core.criterion import critical_glass_elongation
    from viscoadh_ros.core.presets import DOMAIN_RADIUS_RANGE, ELEMENTS_MAX, resolve_numerics
    from viscoadh_ros.core.profiles import make_profile
    from viscoadh_ros.core.rheology import CreepElement

    profile = make_profile(contact.indenter)
    deepest = float(np.max(experiment.input_value))
    e0 = CreepElement.from_config(contact.material).glass_modulus_star
    g0 = float(contact.material.glass_shear_modulus)
    w = float(contact.adhesion.work_of_adhesion)

    def reach(g0_trial: float, w_trial: float) -> float:
        c = float(critical_glass_elongation(1.0, w_trial, e0 * g0_trial / g0)) if w_trial > 0 else 0.0

        def excess(a: float) -> float:
            return float(profile.g(a)) - deepest - c * math.sqrt(a)

        lo, hi = 1e-12, max(1e-9, float(profile.radius_at_height(max(deepest, 0.0))))
        while excess(hi) < 0.0 and hi < 1e3:
            hi *= 2.0
        for _ in range(200):
            mid = math.sqrt(lo * hi)
            lo, hi = (mid, hi) if excess(mid) < 0.0 else (lo, mid)
            if hi <= lo * (1.0 + 1e-9):
                break
        return hi

    g0_lo = bounds.get("G0", (g0, g0))[0]
    w_hi = bounds.get("work_of_adhesion", (w, w))[1]
    largest, at_start = reach(g0_lo, w_hi), reach(g0, w)
    elements = resolve_numerics(contact.numerics).elements
    factor = min(max(largest / at_start, 1.0), MAX_ELEMENT_FACTOR)
    # Within the ranges a scene may give (presets.DOMAIN_RADIUS_RANGE, ELEMENTS_MAX): a contact
    # that outgrows the domain grows it, so the upper bound costs only speed.
    domain = min(max(GRID_MARGIN * largest, DOMAIN_RADIUS_RANGE[0]), DOMAIN_RADIUS_RANGE[1])
    return domain, min(int(math.ceil(elements * factor)), ELEMENTS_MAX)


class _Problem:
    """The residuals of one fit: the model on the fit's grid at the used samples, in noise units."""

    def __init__(
        self,
        contact: ContactConfig,
        experiment: Experiment,
        free: Sequence[str],
        kelvin: int,
        start: dict[str, float],
        used: NDArray[np.bool_],
        noise: float,
        runs: int = 0,
        *,
        offset: bool = False,
    ) -> None:
        self.contact, self.experiment, self.free, self.kelvin = contact, experiment, tuple(free), kelvin
        self.start, self.used, self.noise = start, used, noise
        self.measured = experiment.measured_force[used]
        self.runs = runs
        self.model_time = 0.0  # s spent in run_model
        #: A constant load-cell offset profiled out of the residuals (variable projection: at
        #: each trial the offset that minimises the cost is the mean of measured - model, so
        #: the residuals are those of model - measured less their mean); ``constants`` is how
        #: many such fitted constants the degrees of freedom lose.
        self.offset = offset
        self.constants = int(offset)
        self.failed = False  # the last force() was refused by the model
        self.last_mean = 0.0  # mean of (model - measured) / noise at the last residual()
        self.secant_means = np.zeros(len(self.free))  # d last_mean / du at the last secant()

    def values(self, u: NDArray[np.float64]) -> dict[str, float]:
        trial = dict(self.start)
        trial.update({n: self.start[n] * math.exp(float(x)) for n, x in zip(self.free, u, strict=True)})
        return trial

    def force(self, u: NDArray[np.float64], contact: ContactConfig | None = None) -> NDArray[np.float64]:
        """Model force (N) at the used samples for log-ratios ``u``."""
        self.runs += 1
        base = self.contact if contact is None else contact
        started = wallclock.perf_counter()
        try:
            # The trial throughout: a PARAMETERS event restarts the contact but keeps the trial
            # (with the logged parameters the samples after it would not depend on the trial).
            trial = with_parameters(base, self.values(u), self.kelvin)
            run = run_model(trial, self.experiment, parameters=False)
        except ValueError:
            # Outside what the model accepts: a large residual steers the optimiser back.
            self.failed = True
            return self.measured + 1e3 * self.noise * math.sqrt(self.measured.size)
        finally:
            self.model_time += wallclock.perf_counter() - started
        self.failed = False
        return run.model_force[self.used]

    def residual(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """``(model - measured) / noise`` at the used samples; with ``offset`` less its mean
        (the best constant offset at this trial profiled out). A trial the model refuses keeps
        its large constant residual (profiled, it would vanish)."""
        r = (self.force(u) - self.measured) / self.noise
        self.last_mean = float(np.mean(r))
        if self.offset and not self.failed:
            r = r - self.last_mean
        return r

    def secant(self, u: NDArray[np.float64], steps: NDArray[np.float64]) -> NDArray[np.float64]:
        """Central-secant Jacobian of the residuals over +-``steps[j]`` in each u; the same
        secant of the mean of the unprofiled residuals goes to ``secant_means`` (the offset's
        variance needs it: the profiled columns have mean zero)."""
        columns, means = [], []
        for h, e in zip(steps, np.eye(u.size), strict=True):
            plus = self.residual(u + h * e)
            mean_plus = self.last_mean
            minus = self.residual(u - h * e)
            columns.append((plus - minus) / (2.0 * h))
            means.append((mean_plus - self.last_mean) / (2.0 * h))
        self.secant_means = np.array(means)
        return np.column_stack(columns)


def _widen(keep: NDArray[np.bool_], fraction: float) -> NDArray[np.bool_]:
    """``keep`` with every masked run widened by ``fraction`` of its samples either side
    (at least JUMP_MARGIN): a jump mask measured in time, not in samples."""
    window = max(JUMP_MARGIN, int(fraction * keep.size))
    near = np.convolve((~keep).astype(np.int64), np.ones(2 * window + 1, dtype=np.int64), "same") > 0
    return keep & ~near


def coarse_record(experiment: Experiment, picked: NDArray[np.bool_], every: int) -> Experiment:
    """The coarse stage's record: the ``picked`` measured samples only, and the inputs the
    model needs to reach them (the last input at or before each, the first and the last one,
    and every ``every``-th input across the gaps between them, e.g. the masked jumps). The
    model then steps once per kept stamp instead of once per input: on a dense input stream
    each kept input ramps (first-order hold) from the last kept one, the same piecewise-linear
    path at a coarser time step. A record the thinning cannot keep faithful (restarts,
    recording order, force inputs, inputs out of stamp order) or ``every <= 1`` is returned as
    it is."""
    if (
        every <= 1
        or experiment.restarts
        or experiment.by_arrival
        or np.any(experiment.input_mode != DEPTH)
        or np.any(np.diff(experiment.input_ns) < 0)
    ):
        return experiment
    n = experiment.input_ns.size
    at = np.searchsorted(experiment.input_ns, experiment.measured_ns[picked], side="right") - 1
    kept = np.unique(np.concatenate(([0, n - 1], at[at >= 0])))
    gaps = np.flatnonzero(np.diff(kept) > every)
    if gaps.size:
        fill = [np.arange(kept[g] + every, kept[g + 1], every) for g in gaps]
        kept = np.unique(np.concatenate([kept, *fill]))
    if kept.size >= n:
        return experiment
    return experiment.select(kept, picked, rejected_index=np.empty(0, dtype=np.int64), rejected_reason=())


def by_retardation(values: dict[str, float], kelvin: int) -> dict[str, float]:
    """``values`` with the Kelvin elements relabelled in ascending retardation time
    ``eta_k / G_k`` (the chain's force does not depend on the order of its elements)."""
    order = sorted(range(1, kelvin + 1), key=lambda k: values[f"eta{k}"] / values[f"G{k}"])
    relabelled = dict(values)
    for k, old in enumerate(order, start=1):
        relabelled[f"G{k}"], relabelled[f"eta{k}"] = values[f"G{old}"], values[f"eta{old}"]
    return relabelled


def _ordered(
    problem: _Problem, u: NDArray[np.float64], lower: NDArray[np.float64], upper: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``u`` with the chain's elements in ascending retardation time when that point lies in the
    box (the same force: the fit lands on either labelling of a valley it finds); else ``u``."""
    values = problem.values(u)
    relabelled = by_retardation(values, problem.kelvin)
    if relabelled == values:
        return u
    swapped = np.array([math.log(relabelled[n] / problem.start[n]) for n in problem.free])
    return swapped if np.all((swapped >= lower) & (swapped <= upper)) else u


def _retardation_scan(
    problem: _Problem,
    u: NDArray[np.float64],
    best: float,
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    descend: Any,
) -> tuple[NDArray[np.float64], float]:
    """Walk a chain's retardation times out of a flat valley's false stop (every element free).

    Along a slow retardation time the cost falls so gently that a descent stops (on its step
    tolerance or its budget) far from the valley's floor. Each round moves one retardation time
    ``eta_k / G_k`` by :data:`RETARDATION_FACTOR` either way with the moduli re-fitted at those
    times (a short descent over the other parameters, to which the force is nearly linear), and
    descends from the best such point when it beats ``best``; at most
    :data:`RETARDATION_ROUNDS` rounds, ``descend``'s result kept only when lower."""
    free = list(problem.free)
    kelvin = problem.kelvin
    etas = [free.index(f"eta{k}") for k in range(1, kelvin + 1)]
    moduli = [free.index(f"G{k}") for k in range(1, kelvin + 1)]
    others = [j for j in range(len(free)) if j not in etas]
    for _ in range(RETARDATION_ROUNDS):
        trials = []
        for k in range(kelvin):
            for shift in (-math.log(RETARDATION_FACTOR), math.log(RETARDATION_FACTOR)):
                times = u[etas] - u[moduli]
                times[k] += shift

                def expand(w: NDArray[np.float64], times: NDArray[np.float64] = times) -> NDArray[np.float64]:
                    full = np.empty(len(free))
                    full[others] = w
                    full[etas] = np.clip(full[moduli] + times, lower[etas], upper[etas])
                    return full

                start = np.clip(u[others], lower[others] + 1e-9, upper[others] - 1e-9)
                found = least_squares(
                    lambda w, expand=expand: problem.residual(expand(w)),
                    start,
                    bounds=(lower[others], upper[others]),
                    diff_step=1e-2,
                    x_scale=1.0,
                    max_nfev=RETARDATION_EVALUATIONS,
                )
                trials.append((float(found.cost), expand(found.x)))
        cost, point = min(trials, key=lambda t: t[0])
        if not cost < best:
            break
        descended, lowest = descend(point)
        u, best = (descended, lowest) if lowest < cost else (point, cost)
    return u, best


def polish_elements(contact: ContactConfig, noise: float, force_scale: float, coarse: int) -> int:
    """Elements of the polish's grid: the element count `numerics_for_tolerance` chooses for a
    model error of MODEL_ERROR_FRACTION of ``noise / force_scale`` (``force_scale`` the
    pull-off force, N), scaled like the fit's grid (``coarse`` elements against the preset's),
    never fewer than ``coarse``. A tolerance tighter than the ladder can meet takes its last
    rung."""
    from viscoadh_ros.core.errors import ConfigError
    from viscoadh_ros.core.presets import (
        ELEMENT_LADDER,
        ELEMENTS_MAX,
        SceneHint,
        numerics_for_tolerance,
        resolve_numerics,
    )

    tolerance = min(MODEL_ERROR_FRACTION * noise / max(force_scale, 1e-300), 0.5)
    hint = SceneHint.of(contact.indenter, contact.material)
    try:
        chosen = numerics_for_tolerance(tolerance, hint).elements
    except ConfigError:
        chosen = ELEMENT_LADDER[-1]
    preset_numerics = dataclasses.replace(contact.numerics, elements=0, tolerance=0.0)
    preset_elements = resolve_numerics(preset_numerics).elements
    factor = coarse / preset_elements
    return min(max(coarse, int(math.ceil(chosen * max(factor, 1.0)))), ELEMENTS_MAX)


def _identify_checks(
    experiment: Experiment,
    free: Sequence[str],
    used: NDArray[np.bool_],
    selected: NDArray[np.bool_],
    *,
    offset: bool = False,
) -> None:
    if np.any(experiment.input_mode != DEPTH):
        raise FitError("fit needs depth-controlled inputs; the record holds FORCE-mode commands")
    if int(np.count_nonzero(used)) < len(free) + 2:
        raise FitError(
            f"{int(np.count_nonzero(used))} force samples (after the segment, time range and jump "
            f"masks) cannot fit {len(free)} parameters"
        )
    force = experiment.measured_force[selected]
    if "work_of_adhesion" in free and not has_pull_off(force, offset=offset):
        hint = ""
        if not offset and has_pull_off(force, offset=True):
            level = float(np.median(force[int(np.argmin(force)) + 1 :]))
            hint = (
                f" (the force settles at {level:.3g} N after its most tensile sample, not at zero: "
                "a load-cell offset? tare the record or fit with --fit-offset)"
            )
        raise FitError(
            "work_of_adhesion cannot be identified: the fitted samples hold no pull-off (a tensile "
            "force released back to zero); hold it (leave it out of --free) or record a retraction"
            + hint
        )


def _difference_step(problem: _Problem, u: NDArray[np.float64]) -> float:
    """The smallest forward-difference step (in u) at which the Jacobian agrees with the one
    four times wider within 30 % in every column: below it what roughness remains (element
    and sample crossings) would read as slope."""
    base = problem.residual(u)
    for step in (1e-3, 1e-2):
        agree = True
        for e in np.eye(u.size):
            near = (problem.residual(u + step * e) - base) / step
            far = (problem.residual(u + 4.0 * step * e) - base) / (4.0 * step)
            if np.linalg.norm(near - far) > 0.3 * max(float(np.linalg.norm(far)), 1e-12):
                agree = False
                break
        if agree:
            return step
    return 3e-2


def _covariance(
    jac: NDArray[np.float64], s2: float, free: Sequence[str]
) -> tuple[NDArray[np.float64], list[str]]:
    """Covariance of u and the parameters that only act together (a null direction) or
    not at all; those get infinite variance."""
    norms = np.linalg.norm(jac, axis=0)
    top = max(float(np.max(norms)), 1e-300)
    dead = norms <= 1e-12 * top
    cov = np.full((len(free), len(free)), np.inf)
    flat: set[str] = {n for n, d in zip(free, dead, strict=True) if d}
    live = np.flatnonzero(~dead)
    if live.size:
        scaled = jac[:, live] / norms[live]
        _, singular, vt = np.linalg.svd(scaled, full_matrices=False)
        null = singular < singular[0] / MAX_CONDITION
        for vec in vt[null]:
            flat.update(free[live[j]] for j in np.flatnonzero(np.abs(vec) > 0.3))
        inv = (vt[~null].T / singular[~null] ** 2) @ vt[~null]
        sub = s2 * inv / np.outer(norms[live], norms[live])
        cov[np.ix_(live, live)] = sub
    for j, name in enumerate(free):
        if name in flat:
            cov[j, j] = np.inf
    return cov, sorted(flat, key=list(free).index)


@dataclass(frozen=True)
class _Polished:
    u: NDArray[np.float64]
    cov: NDArray[np.float64]
    flat: list[str]
    sigmas: NDArray[np.float64]  # the last proposed step, in standard deviations
    steps: NDArray[np.float64]  # the last secant's half-widths
    jac: NDArray[np.float64]  # the last secant Jacobian of the residuals
    r: NDArray[np.float64]  # the residuals at u
    #: The last secant of the mean of the unprofiled residuals (the fitted offset's column
    #: means of the raw Jacobian, `_Problem.secant_means`); zeros without an offset.
    means: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    @property
    def sigma_u(self) -> NDArray[np.float64]:
        return np.sqrt(np.diag(self.cov))


def _polish(
    problem: _Problem,
    u: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    smallest: float,
    steps: NDArray[np.float64] | None = None,
) -> _Polished:
    """Gauss-Newton on the central-secant model from ``u`` until the step it proposes is
    below POLISH_SIGMAS standard deviations (at most POLISH_STEPS). Each secant spans
    SECANT_SIGMAS standard deviations of its parameter (the last covariance's): wide against
    what roughness remains, narrow against the curvature (a central secant's fixed point is
    off the optimum by its width squared times the third derivative)."""
    free, p = problem.free, u.size
    dof = max(problem.measured.size - p - problem.constants, 1)
    r = problem.residual(u)
    steps = np.full(p, SECANT_STEP) if steps is None else steps
    sigmas = np.zeros(p)
    for _ in range(POLISH_STEPS):
        jac = problem.secant(u, steps)
        means = problem.secant_means
        cov, flat = _covariance(jac, float(r @ r) / dof, free)
        sigma_u = np.sqrt(np.diag(cov))
        narrower = np.clip(
            np.nan_to_num(SECANT_SIGMAS * sigma_u, nan=SECANT_STEP, posinf=SECANT_STEP), smallest, SECANT_STEP
        )
        if np.any(narrower < 0.5 * steps):
            steps = narrower  # the first, wide secant only sizes the next
            continue
        steps = narrower
        gn = np.linalg.lstsq(jac, -r, rcond=None)[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            sigmas = np.where(np.isfinite(sigma_u), np.abs(gn) / sigma_u, 0.0)
        if float(np.max(sigmas)) <= POLISH_SIGMAS:
            break
        if np.all((np.abs(gn) <= POLISH_TRUST * sigma_u) | (np.abs(gn) <= steps)):
            # Within a few standard deviations, or within the secant's own span, the secant
            # model is the judge: what roughness remains moves the cost at a single trial
            # point by about one unit.
            u = np.clip(u + gn, lower, upper)
            r = problem.residual(u)
            continue
        for fraction in (1.0, 0.5, 0.25):
            trial = np.clip(u + fraction * gn, lower, upper)
            r_trial = problem.residual(trial)
            if r_trial @ r_trial < r @ r:
                u, r = trial, r_trial
                break
        else:
            break
    return _Polished(u, cov, flat, sigmas, steps, jac, r, means)


def _profile_cost(
    problem: _Problem,
    trial: NDArray[np.float64],
    others: NDArray[np.intp],
    guesses: Sequence[NDArray[np.float64]],
    jac: NDArray[np.float64],
    steps: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    s2: float,
    enough: float = math.inf,
) -> tuple[float, NDArray[np.float64]]:
    """The profile's cost at ``trial`` and where it is: the parameters not in ``others`` held
    at ``trial``, the others descended to the valley's floor (or only until the cost is below
    ``enough``: the caller only needs to know that the floor is).

    The descent starts from the best of: ``trial`` itself (the linear profile direction),
    PROFILE_BENDS Gauss-Newton steps from it with the optimum's Jacobian ``jac`` (the floor,
    where the valley is straight), and the others taken from each of ``guesses`` (the last
    profile points, followed along a valley that curves); then scipy's least_squares over the
    others (forward secants of half-widths ``steps``) until a step gains less than PROFILE_GAIN
    noise variances ``s2``. In a valley that curves at the interval's scale (a spring and a
    viscosity that trade off along a banana) the linear direction leaves the floor by hundreds
    of variances, and a cost that stops short of it reads a poorly identified parameter as well
    identified (0.5.0: G1 stated 33 .. 166 kPa, the truth 200 kPa 0.9 variances above the
    minimum, tests/test_fit_cli.py)."""
    r = problem.residual(trial)
    best = (float(r @ r), trial)
    if not others.size:
        return best
    point, res = trial, r
    jac_others = jac[:, others]
    for _ in range(PROFILE_BENDS):
        point = point.copy()
        point[others] += np.linalg.lstsq(jac_others, -res, rcond=None)[0]
        point = np.clip(point, lower, upper)
        res = problem.residual(point)
        if float(res @ res) < best[0]:
            best = (float(res @ res), point)
    for guess in guesses:
        point = trial.copy()
        point[others] = np.clip(guess[others], lower[others], upper[others])
        res = problem.residual(point)
        if float(res @ res) < best[0]:
            best = (float(res @ res), point)
    cost, start = best
    if cost < enough:
        return best

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        moved = start.copy()
        moved[others] = x
        return problem.residual(moved)

    found = least_squares(
        residual,
        np.clip(start[others], lower[others] + 1e-9, upper[others] - 1e-9),
        bounds=(lower[others], upper[others]),
        diff_step=steps[others],
        x_scale=1.0,
        ftol=max(PROFILE_GAIN * s2 / max(cost, 1e-300), 1e-12),
        max_nfev=PROFILE_EVALUATIONS,
    )
    if 2.0 * float(found.cost) < cost:
        point = start.copy()
        point[others] = found.x
        best = (2.0 * float(found.cost), point)
    return best


def _profile_inflation(
    problem: _Problem, polished: _Polished, lower: NDArray[np.float64], upper: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Factors (>= 1) on each linearised standard deviation, one for each side (row 0 below
    the optimum, row 1 above), so that the 95 % interval ends where the profile does.

    Along parameter j's profile direction (``cov[:, j] / sigma_j``: u_j moves, the others
    follow its valley) the cost is measured at the linear interval's end (Z95 standard
    deviations), the others descended to the valley's floor (:func:`_profile_cost`). Where it
    has risen by Z95^2 noise variances or more the linear end stands (never narrowed); below,
    the search steps outward by PROFILE_GROWTH until it rises past that, and the end is
    interpolated in the square root of the rise (linear in k for a quadratic valley). A side
    that reaches the search box first ends there. Each side on its own: a parameter the record
    bounds on one side only has a valley steep on that side and flat on the other (0.4.0 read
    the mean of the two sides). The end, not a test at 3 standard deviations: a valley that is
    flat to its linear end and steep past it (a spring the record barely sees) passed 0.5.0's
    test and kept an interval that excluded a truth 0.9 noise variances above the minimum.
    A trial point whose cost is below the 95 % level before the descent is already inside
    (the floor is lower still): the search steps on without descending. About
    1 + PROFILE_BENDS + 2 + a few descents' p runs per trial point, one trial per side of a well
    identified parameter."""
    u, cov, r = polished.u, polished.cov, polished.r
    dof = max(r.size - u.size - problem.constants, 1)
    s2 = float(r @ r) / dof
    base = float(r @ r)
    target = Z95 * math.sqrt(s2)  # the square root of the rise at the 95 % end
    factors = np.ones((2, u.size))
    for j in range(u.size):
        sigma = math.sqrt(cov[j, j]) if math.isfinite(cov[j, j]) else math.inf
        if not math.isfinite(sigma) or sigma <= 0.0 or not np.all(np.isfinite(cov[:, j])):
            continue
        direction = cov[:, j] / sigma
        others = np.array([i for i in range(u.size) if i != j and math.isfinite(cov[i, i])], dtype=np.intp)
        for side, sign in enumerate((-1.0, 1.0)):
            bound = lower[j] if sign < 0 else upper[j]
            k_box = abs(bound - u[j]) / sigma  # where u_j reaches the box
            k_in, root_in = 0.0, 0.0
            k = Z95
            path = [(0.0, u)]  # (k, point) of the profile's floor so far on this side
            while True:
                k = min(k, k_box)
                trial = np.clip(u + sign * k * direction, lower, upper)
                guesses = [path[-1][1]]
                if len(path) > 1:  # the floor's path extrapolated to k
                    (k0, p0), (k1, p1) = path[-2], path[-1]
                    guesses.append(p1 + (p1 - p0) * (k - k1) / (k1 - k0))
                cost, floor = _profile_cost(
                    problem,
                    trial,
                    others,
                    guesses,
                    polished.jac,
                    polished.steps,
                    lower,
                    upper,
                    s2,
                    enough=base + target**2,
                )
                path.append((k, floor))
                root = math.sqrt(max(cost - base, 0.0))
                if root >= target:
                    end = k_in + (k - k_in) * (target - root_in) / (root - root_in)
                    break
                if k >= k_box or k >= Z95 * PROFILE_GROWTH ** (PROFILE_TRIALS - 1):
                    end = k  # no rise to the 95 % level before the box (or the search's end)
                    break
                k_in, root_in = k, root
                k *= PROFILE_GROWTH
            factors[side, j] = max(1.0, end / Z95)
    return factors


def _check_depths(contact: ContactConfig, experiment: Experiment) -> None:
    """InputError naming the first commanded depth beyond the scene's range (the largest
    domain, `ContactSimulator._depth_limit`, at the scene's parameters): every model run refuses it,
    so the fit used to run into a wall of refused trials and report a secant that would not
    converge (0.8.0's outside tester); `replay` names the sample."""
    from viscoadh_ros.core.simulator import ContactSimulator

    limit = ContactSimulator(contact)._depth_limit
    deep = np.flatnonzero((experiment.input_mode == DEPTH) & ~(np.abs(experiment.input_value) <= limit))
    if deep.size:
        value = float(experiment.input_value[deep[0]])
        raise InputError(
            f"depth[{int(deep[0])}]: {value!r} m is beyond the scene's range (at most {limit:.3g} m, "
            "the largest domain this contact can represent): no model run can replay the record"
        )


def _parameter_side(experiment: Experiment, selected: NDArray[np.bool_], contact: ContactConfig) -> int:
    """How many PARAMETERS events of ``experiment`` come before the ``selected`` samples (0 when
    none is selected); FitError naming the change when the selection spans one: the node ran
    one material before it and another after it, and a fit finds one (an outside tester's whole
    record fitted 0.04998 J/m^2 to a contact that ran 0.05 and 0.08)."""
    changes = [r for r in experiment.restarts if r.kind == PARAMETERS]
    if not changes or not selected.any():
        return 0
    orders = np.array([r.order for r in changes], dtype=np.int64)
    side = np.searchsorted(orders, experiment.measured_order)
    sides = np.unique(side[selected]).tolist()
    if len(sides) == 1:
        return int(sides[0])
    t = experiment.time(experiment.measured_ns)
    spanned, ranges = [], []
    before = contact
    for k, change in enumerate(changes):
        after = changed_contact(change, contact.id)
        if sides[0] <= k < sides[-1]:
            what = _changes(before, after) or "the contact's configuration"
            spanned.append(f"t = {float(experiment.time(np.array([change.ns]))[0]):.6g} s ({what})")
        before = after
    for k in sides:
        mine = t[selected & (side == k)]
        low, high = math.floor(float(mine.min()) * 1e6) / 1e6, math.ceil(float(mine.max()) * 1e6) / 1e6
        ranges.append(f"--time-range {low:.10g} {high:.10g}")
    raise FitError(
        f"the fitted samples span a parameter change of contact {contact.id!r} at "
        + ", ".join(spanned)
        + ": the node ran one material before it and another after it, and a fit finds one; fit one "
        "side at a time, e.g. " + " or ".join(ranges)
    )


def _changes(before: ContactConfig, after: ContactConfig) -> str:
    """``"work_of_adhesion 0.05 -> 0.08"``: the fit's parameters a change set, comma-separated."""
    old, new = parameters_of(before), parameters_of(after)
    changed = [name for name in new if old.get(name) != new[name]]
    return ", ".join(f"{name} {old[name]:g} -> {new[name]:g}" if name in old else name for name in changed)


def fitted_stretch(
    experiment: Experiment, options: FitOptions, contact: ContactConfig
) -> tuple[Experiment, Restart | None]:
    """The stretch of ``experiment`` between PARAMETERS events that holds the samples
    ``options`` select (`stretch`: what the fit needs to run; the model before the change it
    starts at does not matter, a restart follows), and that change, None when the stretch
    starts with the record. FitError when the selection spans a change. ``contact``: the one
    the record starts with."""
    changes = [r for r in experiment.restarts if r.kind == PARAMETERS]
    if not changes:
        return experiment, None
    selected = segment_samples(experiment, options) & ~at_rest(experiment)
    if not selected.any():
        return experiment, None
    side = _parameter_side(experiment, selected, contact)
    start = changes[side - 1] if side > 0 else None
    end = changes[side] if side < len(changes) else None
    part = stretch(experiment, None if start is None else start.order, None if end is None else end.order)
    return part, start


def fit(
    contact: ContactConfig,
    experiment: Experiment,
    free: Sequence[str],
    *,
    kelvin: int = 1,
    options: FitOptions | None = None,
) -> FitResult:
    """Fit the ``free`` parameters of ``contact`` (``kelvin`` Kelvin elements) to ``experiment``.

    Raises FitError when the record cannot say anything about a free parameter or the fit
    does not reach a stationary point; a parameter it cannot pin down is reported as not
    identified with its interval (`FitResult.identified`). The trial parameters run throughout
    the record (a PARAMETERS event restarts the contact with them), so the samples fitted must
    lie on one side of every parameter change (FitError otherwise; `fitted_stretch` cuts the
    record to that side); samples of a contact at rest after a restart are not fitted.
    """
    started = wallclock.perf_counter()
    options = options or FitOptions()
    free = list(free)
    if experiment.measured_force.size < 5:
        raise FitError(f"{experiment.measured_force.size} force samples cannot fit {len(free)} parameters")
    start = initial_values(contact, kelvin)
    chain = [f"{g}{k}" for g in ("G", "eta") for k in range(1, kelvin + 1)]
    # Every element free: the chain's labels are a convention, ascending retardation time (the
    # start's too, so each element's box is centred on the like element of the start).
    ordered = kelvin > 1 and all(name in free for name in chain)
    for name in free:
        if not start[name] > 0.0 or not math.isfinite(start[name]):
            raise InputError(f"start value of {name} must be finite and > 0 (got {start[name]})")
    if ordered:
        start = by_retardation(start, kelvin)
    _check_depths(contact, experiment)
    noise = _noise_floor(experiment.measured_force)
    depth = np.interp(
        experiment.time(experiment.measured_ns), experiment.time(experiment.input_ns), experiment.input_value
    )
    # Samples of the contact at rest after a restart (before its next input) are the fresh
    # contact's output whatever the material: nothing to fit.
    selected = segment_samples(experiment, options) & ~at_rest(experiment)
    _parameter_side(experiment, selected, contact)
    smooth = _widen(smooth_samples(experiment.measured_force, noise, depth), JUMP_WINDOW)
    used = smooth & selected
    _identify_checks(experiment, free, used, selected, offset=options.fit_offset)

    half = math.log(options.bounds_factor)
    bounds = {n: (start[n] / options.bounds_factor, start[n] * options.bounds_factor) for n in free}
    domain, elements = fit_grid(contact, experiment, bounds)
    numerics = dataclasses.replace(contact.numerics, domain_radius=domain, elements=elements)
    grid_contact = dataclasses.replace(contact, numerics=numerics)
    offset = options.fit_offset
    problem = _Problem(grid_contact, experiment, free, kelvin, start, used, noise, offset=offset)
    p = len(free)
    lower, upper = np.full(p, -half), np.full(p, half)

    def cost(u: NDArray[np.float64]) -> float:
        r = coarse.residual(u)
        return 0.5 * float(r @ r)

    # The coarse stage: the fit's grid at the start's preset, on every k-th used sample.
    # Its jump masks are COARSE_JUMP_WINDOW of the record wide on either side: far from the
    # optimum the model's own pull-off lands samples away from the measured one, and each
    # sample it crosses moves the cost by (pull-off / noise)^2, a staircase no descent climbs.
    coarse_used = used & _widen(smooth, COARSE_JUMP_WINDOW)
    if int(np.count_nonzero(coarse_used)) < len(free) + 2:
        coarse_used = used
    thin = max(1, math.ceil(int(np.count_nonzero(coarse_used)) / COARSE_SAMPLES))
    picked = np.zeros_like(used)
    picked[np.flatnonzero(coarse_used)[::thin]] = True
    thinned = coarse_record(experiment, picked, thin)
    if thinned is not experiment:
        picked = np.ones(thinned.measured_force.size, dtype=bool)
    problem = coarse = _Problem(grid_contact, thinned, free, kelvin, start, picked, noise, offset=offset)
    step = _difference_step(problem, np.zeros(p))

    def descend(u0: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        found = least_squares(
            coarse.residual,
            np.clip(u0, lower + 1e-9, upper - 1e-9),
            bounds=(lower, upper),
            diff_step=step,
            x_scale=1.0,
            max_nfev=DESCENT_EVALUATIONS,
        )
        return found.x, float(found.cost)

    # The start's descent; when its fit error is above the noise (a local valley, or model
    # error), the global stage: the cost at seeded Sobol points of the box and descents from
    # the best of them; the lowest cost wins.
    u, best = descend(np.zeros(p))

    def noisy(chi2: float, dof: int) -> bool:
        return chi2 / dof > 1.0 + NOISE_CONSISTENT * math.sqrt(2.0 / dof)

    def explore(u: NDArray[np.float64], best: float) -> tuple[NDArray[np.float64], float]:
        sobol = qmc.Sobol(d=p, scramble=True, seed=options.seed).random(GLOBAL_POINTS)
        candidates = [lower + (upper - lower) * s for s in sobol]
        costs = [cost(c) for c in candidates]
        descents = [descend(candidates[i]) for i in np.argsort(costs)[:GLOBAL_DESCENTS]]
        return min([(u, best), *descents], key=lambda d: d[1])

    explored = noisy(2.0 * best, max(coarse.measured.size - p - coarse.constants, 1))
    if explored:
        u, best = explore(u, best)
    if ordered:
        u, best = _retardation_scan(coarse, _ordered(coarse, u, lower, upper), best, lower, upper, descend)
        u = _ordered(coarse, u, lower, upper)  # a scan's move may pass one time over another

    # Polish on the secant model on every used sample and the grid whose model error sits
    # below the noise, then again on grids refined by 2 until the optimum stops moving: the
    # last shift is the discretisation's model-error term.
    smallest = max(step / 3.0, MIN_SECANT)
    model_time = problem.model_time
    pull_off = float(np.max(np.abs(np.minimum(experiment.measured_force[used], 0.0))))
    scale = pull_off if pull_off > PULL_OFF_NOISE_BAND * noise else float(np.max(np.abs(problem.measured)))
    elements = polish_elements(contact, noise, scale, elements)
    numerics = dataclasses.replace(numerics, elements=elements)
    grid_contact = dataclasses.replace(grid_contact, numerics=numerics)
    if thinned is not experiment:
        # The coarse grid's optimum sits off the polish grid's along a flat valley (a slow
        # retardation time), where the polish's secant steps crawl at 2p runs each: descend
        # first on the thinned record at the polish's grid (a third of a full run).
        medium = _Problem(
            grid_contact, thinned, free, kelvin, start, picked, noise, runs=problem.runs, offset=offset
        )
        u = least_squares(
            medium.residual,
            np.clip(u, lower + 1e-9, upper - 1e-9),
            bounds=(lower, upper),
            diff_step=_difference_step(medium, u),
            x_scale=1.0,
            max_nfev=DESCENT_EVALUATIONS,
        ).x
        problem.runs, model_time = medium.runs, model_time + medium.model_time
    problem = _Problem(
        grid_contact, experiment, free, kelvin, start, used, noise, runs=problem.runs, offset=offset
    )
    polished = _polish(problem, u, lower, upper, smallest)
    if float(np.max(polished.sigmas)) > STATIONARY_SIGMAS:
        # The polish stopped on a rough patch: descend once more from where it got to.
        polished = _polish(problem, descend(polished.u)[0], lower, upper, smallest)
    dof = max(problem.measured.size - p - problem.constants, 1)
    if not explored and noisy(float(polished.r @ polished.r), dof):
        # Above the noise on every sample though the thinned set looked noise-consistent (its
        # test is sqrt(k) looser): a local valley; the global stage decides after all.
        runs, spent = coarse.runs, coarse.model_time
        found, _ = explore(polished.u, cost(polished.u))
        if ordered:
            found = _ordered(coarse, found, lower, upper)
        problem.runs, model_time = problem.runs + coarse.runs - runs, model_time + coarse.model_time - spent
        if found is not polished.u:
            other = _polish(problem, found, lower, upper, smallest)
            if float(other.r @ other.r) < float(polished.r @ polished.r):
                polished = other
    # The model-error term: the Gauss-Newton step the grid refined by 2 proposes (its residuals
    # at the optimum against this grid's secant Jacobian, one model run) less this grid's own.
    finer = dataclasses.replace(grid_contact, numerics=dataclasses.replace(numerics, elements=2 * elements))
    refined = _Problem(finer, experiment, free, kelvin, start, used, noise, runs=problem.runs, offset=offset)
    shift = np.linalg.lstsq(polished.jac, polished.r - refined.residual(polished.u), rcond=None)[0]
    refined_mean = refined.last_mean  # mean of (model - measured) / noise on the refined grid
    problem.runs, model_time = refined.runs, model_time + refined.model_time
    u, cov, flat, sigmas = polished.u, polished.cov, polished.flat, polished.sigmas
    model_contact = problem.contact
    worst = int(np.argmax(sigmas))
    if sigmas[worst] > STATIONARY_SIGMAS:
        raise FitError(
            f"the fit did not converge: at its end the secant still proposes a step of "
            f"{sigmas[worst]:.1f} standard deviations in {free[worst]}"
        )
    inflation = _profile_inflation(problem, polished, lower, upper)
    sigma_low, sigma_high = np.sqrt(np.diag(cov) * inflation**2 + shift**2)

    values = problem.values(u)
    uncertainty, interval, identified = {}, {}, {}
    for j, name in enumerate(free):
        s_low, s_high = float(sigma_low[j]), float(sigma_high[j])
        s = 0.5 * (s_low + s_high)
        identified[name] = name not in flat and max(s_low, s_high) <= MAX_RELATIVE_UNCERTAINTY
        lo = max(u[j] - Z95 * s_low, -half) if math.isfinite(s_low) else -half
        hi = min(u[j] + Z95 * s_high, half) if math.isfinite(s_high) else half
        interval[name] = (start[name] * math.exp(lo), start[name] * math.exp(hi))
        uncertainty[name] = values[name] * s if math.isfinite(s) else math.inf
    unidentified = [n for n in free if not identified[n]]
    reason = ""
    if unidentified:
        together = [n for n in unidentified if n in flat]
        reason = (
            f"{', '.join(unidentified)} not identified by this record"
            + (f" ({', '.join(together)} only act together)" if len(together) > 1 else "")
            + ": the interval is what it can say (a viscosity needs a change of rate or a hold; "
            "G0 loading as fast as the relaxation; the work of adhesion a pull-off)"
        )
    force = problem.force(u)
    error = force - problem.measured
    status = "unidentified" if unidentified else "ok"
    offset_value, offset_sigma, offset_interval, score = None, math.nan, None, math.nan
    if offset:
        # The offset at the optimum: the mean of measured - model (N; what the load cell reads
        # at zero force). Its variance is that of the augmented fit [J_raw, 1] (block
        # inversion): s^2 / n from the noise's mean plus m^T C m from the parameters' own
        # uncertainty (m: the secant of the mean of the unprofiled residuals, C: their
        # covariance, inflation included), plus the model-error term: how far the grid refined
        # by 2 moves it (its mean residual at the optimum, and the parameters' shift through m).
        n = error.size
        offset_value = -float(np.mean(error))
        m = polished.means
        s2 = float(polished.r @ polished.r) / max(n - p - problem.constants, 1)
        inflated = cov * np.outer(np.mean(inflation, axis=0), np.mean(inflation, axis=0))
        with np.errstate(invalid="ignore", over="ignore"):
            spread = float(m @ inflated @ m) if np.all(np.isfinite(inflated)) else math.inf
        moved = (refined_mean + offset_value / noise) + float(m @ shift)
        offset_sigma = noise * math.sqrt(s2 / n + spread + moved**2)
        offset_interval = (offset_value - Z95 * offset_sigma, offset_value + Z95 * offset_sigma)
        error = error + offset_value
    else:
        score = offset_score(polished.r, polished.jac)
    correlation = residual_correlation(error)
    if correlation * math.sqrt(error.size) > MISFIT_SIGMAS:
        status = "misfit"
        misfit = (
            f"the residuals are correlated (lag-1 autocorrelation {correlation:.3f}, "
            f"{correlation * math.sqrt(error.size):.1f} standard errors of white noise): the model "
            "misses the record systematically (a local optimum, a missing Kelvin element, a wrong "
            "indenter) or the recorder filtered its noise; the values are not to be trusted as a "
            "fit and the intervals, which assume white noise, are too narrow"
        )
        reason = f"{misfit}; {reason}" if reason else misfit
    drift = drift_score(
        polished.r, polished.jac, experiment.time(experiment.measured_ns)[used], problem.constants
    )
    if abs(drift) > DRIFT_SIGMAS:
        status = "misfit"
        misfit = (
            f"the residuals drift in time (drift score z = {drift:.2f}, beyond {DRIFT_SIGMAS:g}): "
            "most likely a load cell whose zero drifts during the record (a fitted offset does not "
            "remove a drift), or a slow process the model lacks; the values and intervals are biased"
        )
        reason = f"{misfit}; {reason}" if reason else misfit
    if abs(score) > OFFSET_SIGMAS:
        status = "misfit"
        misfit = (
            f"the residuals' mean is off zero by {abs(score):.1f} standard deviations (offset score "
            f"z = {score:.2f}, beyond {OFFSET_SIGMAS:g}): most likely a constant force offset (a load "
            "cell not tared); tare the record or fit with --fit-offset (FILE_OPTIONS fit_offset); "
            "the parameters absorb most of an offset, so the values and intervals are biased"
        )
        reason = f"{misfit}; {reason}" if reason else misfit
    spread = float(np.sum((problem.measured - np.mean(problem.measured)) ** 2))
    return FitResult(
        values=values,
        uncertainty=uncertainty,
        interval=interval,
        identified=identified,
        free=tuple(free),
        rmse=float(np.sqrt(np.mean(error**2))),
        max_error=float(np.max(np.abs(error))),
        noise=noise,
        r2=1.0 - float(error @ error) / spread if spread > 0 else float("nan"),
        samples=int(problem.measured.size),
        contact=with_parameters(contact, values, kelvin),
        model_contact=with_parameters(model_contact, values, kelvin),
        used=used,
        status=status,
        reason=reason,
        model_runs=problem.runs,
        wall_time=wallclock.perf_counter() - started,
        bounds=bounds,
        stationarity=float(sigmas[worst]),
        model_time=model_time + problem.model_time,
        offset=offset_value,
        offset_uncertainty=offset_sigma,
        offset_interval=offset_interval,
        offset_score=score,
        drift_score=drift,
    )


#: Keys of `fit_file`'s options, with their defaults.
FILE_OPTIONS: dict[str, Any] = {
    "scene": None,  # start scene YAML path; None: the scene stored in the bag by the node
    "contact": None,
    "depth_topic": None,
    "force_topic": None,
    "flip_force": False,
    "recover": False,
    "free": None,  # "G0,work_of_adhesion" or a list; None: every parameter of the chain
    "kelvin": 1,
    "segment": "both",
    "time_range": None,  # [t0, t1] s since the first input
    "bounds_factor": BOUNDS_FACTOR,
    "seed": 0,
    "fit_offset": False,  # fit a constant load-cell offset beside the parameters (N, at zero force)
    "output": None,  # fitted scene YAML to write (+ its report beside it); None: write nothing
    "report": True,
}


@dataclass(frozen=True)
class FileFit:
    """What `fit_bag` fitted: the result, the record (the stretch fitted, `fitted_stretch`) and
    the scene it came from."""

    result: FitResult
    experiment: Experiment
    scene: Any  # SceneConfig with the fitted contact
    contact_id: str
    written: tuple[str, ...]  # paths written (scene, figure, table)
    #: The record's parameter change the fitted stretch starts at, s since its first input
    #: (None: the stretch starts with the record).
    changed_at: float | None = None


def fit_bag(path: str, options: dict[str, Any]) -> FileFit:
    """Fit one bag with `FILE_OPTIONS`-style ``options``; writes the fitted scene and its
    report when ``options["output"]`` is set. Raises InputError (FitError) on user errors."""
    from pathlib import Path

    import yaml

    from viscoadh_ros.core.config import SceneConfig
    from viscoadh_ros.experiment import choose_contact, load_experiment, materials
    from viscoadh_ros.io.bag import Bag
    from viscoadh_ros.io.csv_io import check_output_folder
    from viscoadh_ros.io.mcap_log import plain

    unknown = sorted(set(options) - set(FILE_OPTIONS))
    if unknown:
        raise InputError(f"unknown fit option(s) {unknown}; known: {sorted(FILE_OPTIONS)}")
    opts = {**FILE_OPTIONS, **options}
    kelvin = int(opts["kelvin"])
    if kelvin < 1:
        raise InputError(f"kelvin must be >= 1 (got {kelvin})")
    free_text = opts["free"]
    if isinstance(free_text, (list, tuple)):
        free_text = ",".join(free_text)
    free = parse_free(free_text, kelvin) if free_text else parameter_names(kelvin)
    time_range = opts["time_range"]
    fit_options = FitOptions(
        segment=opts["segment"],
        time_range=None if time_range is None else (float(time_range[0]), float(time_range[1])),
        bounds_factor=float(opts["bounds_factor"]),
        seed=int(opts["seed"]),
        fit_offset=bool(opts["fit_offset"]),
    )
    bag = Bag(path, recover=bool(opts["recover"]))
    experiment = load_experiment(
        bag,
        input_topic=opts["depth_topic"],
        force_topic=opts["force_topic"],
        contact=opts["contact"],
        flip_force=bool(opts["flip_force"]),
    )
    if experiment.force_topic is None:
        raise InputError(
            f"no measured force in {str(path)!r}: record a WrenchStamped or name a Float64 force "
            f"with --force-topic (topics: {bag.topics})"
        )
    if opts["scene"] is not None:
        scene = SceneConfig.from_yaml(opts["scene"])
    else:
        stored = bag.scene()
        if stored is None:
            raise InputError(f"{str(path)!r} stores no scene (not a log of our node); pass --scene")
        scene = SceneConfig.from_dict(stored)
    contact = choose_contact(scene, opts["contact"], experiment.input_topic)
    # A node log with a runtime parameter change: the side of it the samples are on, started
    # from the contact in force there, as `viscoadh replay` runs it (`materials`): the contact
    # the change set, or with --scene the scene's with the parameters the changes set (its held
    # parameters are then those the node ran; 0.10.0 held the scene's own).
    stretches = None
    logged_changes = [r for r in experiment.restarts if r.kind == PARAMETERS]
    if logged_changes:
        given = opts["scene"] is not None
        logged = None
        if given and bag.scene() is not None:
            try:
                logged = SceneConfig.from_dict(bag.scene()).contact(contact.id)
            except ValueError:
                logged = None
        stretches = materials(experiment, contact, logged=logged, given=given)
    experiment, change = fitted_stretch(experiment, fit_options, contact)
    if change is not None and stretches is not None:
        contact = stretches[logged_changes.index(change) + 1].contact
    result = fit(contact, experiment, free, kelvin=kelvin, options=fit_options)
    contacts = tuple(result.contact if c.id == contact.id else c for c in scene.contacts)
    fitted = dataclasses.replace(scene, contacts=contacts)
    written: list[str] = []
    if opts["output"] is not None:
        output = Path(opts["output"])
        check_output_folder(output)
        output.write_text(yaml.safe_dump(plain(fitted.to_dict()), sort_keys=False), encoding="utf-8")
        written.append(str(output))
        if opts["report"]:
            from viscoadh_ros.fit_report import write_report

            title = f"{contact.id} from {Path(path).name} ({experiment.force_topic})"
            written.extend(str(p) for p in write_report(result, experiment, output, title=title))
    since = None if change is None else float(experiment.time(np.array([change.ns]))[0])
    return FileFit(result, experiment, fitted, contact.id, tuple(written), since)


def fit_file(path: str, options: dict[str, Any]) -> dict[str, Any]:
    """One summary row for the bag at ``path`` (the batch runner's unit of work; picklable,
    top level): ``bag``, ``contact``, ``status`` (``ok``, ``unidentified``, ``misfit`` or
    ``failed``), ``reason``, every fitted value with its 95 % interval (``<name>_lo95``/``_hi95``),
    standard deviation (``<name>_sigma``) and ``<name>_identified``; with ``fit_offset`` the
    load-cell offset ``offset_N`` with ``offset_lo95_N``/``offset_hi95_N``/``offset_sigma_N``,
    without it the offset check's score ``offset_z``; ``rmse_N``, ``noise_N``, ``r2``,
    ``samples``, ``model_runs``, ``wall_time_s`` and the files written. ``options`` as
    `FILE_OPTIONS`. Never raises: a bag that cannot be fitted is a row with status
    ``failed`` and the reason."""
    started = wallclock.perf_counter()
    try:
        done = fit_bag(path, options)
    except Exception as exc:  # noqa: BLE001 - a batch row, never a lost batch
        reason = " ".join(str(exc).split()) or type(exc).__name__
        if not isinstance(exc, ValueError):
            reason = f"{type(exc).__name__}: {reason}"
        return {
            "bag": str(path),
            "contact": options.get("contact"),
            "status": "failed",
            "reason": reason,
            "wall_time_s": wallclock.perf_counter() - started,
        }
    row = {"bag": str(path), "contact": done.contact_id, **done.result.row()}
    row["wall_time_s"] = wallclock.perf_counter() - started
    row["written"] = ";".join(done.written)
    return row
