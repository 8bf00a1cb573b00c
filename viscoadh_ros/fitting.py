"""Identify material parameters from a recorded experiment by least squares (scipy).

Parameters are named as in physics.md: ``G0`` (glass shear modulus, Pa), ``G1..GK`` (Kelvin
shear moduli, Pa), ``eta1..etaK`` (Kelvin viscosities, Pa s) and ``work_of_adhesion`` (J/m^2).
The fit works on their logarithms (all are positive and span decades) with residuals
``(model - measured) / max|measured|`` at the measured-force stamps, in two stages
(physics.md section 7): the compressive samples first with the work of adhesion held, then
every sample with every free parameter. Uncertainties (one standard deviation) come from the
Jacobian at the optimum: ``cov = s^2 (J^T J)^-1`` with the residual variance ``s^2``.

The model force is not a smooth function of the parameters everywhere: an unstable jump
(snap-in, pull-off under displacement control) moves from one sample to the next as the
parameters change, and the MDR row's finite elements make the force step slightly as the
contact edge crosses them. So (1) the measured samples next to a jump of the measured force
are left out of the residuals, and (2) the Jacobian of the uncertainty is a central secant over
:data:`SECANT_STEP` of each log-parameter, wide against the element steps, rather than the
optimiser's local difference quotient, which a step can blow up (and the error bar shrink).

A parameter the data cannot fix (no pull-off for the work of adhesion, no rate or hold
variation for a viscosity, two parameters that only act together) makes the fit fail with a
:class:`FitError` naming it, never a value with a meaningless error bar.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult, least_squares

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.experiment import Experiment, run_model

if TYPE_CHECKING:
    from viscoadh_ros.core.config import ContactConfig

_NAME = re.compile(r"^(G0|G[1-9]\d*|eta[1-9]\d*|work_of_adhesion)$")
UNITS = {"G": "Pa", "eta": "Pa s", "work_of_adhesion": "J/m^2"}
#: Largest relative standard deviation accepted as "identified".
MAX_RELATIVE_UNCERTAINTY = 0.5
#: Condition number of the column-scaled Jacobian beyond which parameters only act together.
MAX_CONDITION = 1e6
#: Half-width of the central secant of the uncertainty Jacobian, in log-parameter (10 %).
#: At 2 % the element steps' roughness passed for curvature: on tutorial 2's record a
#: four-parameter fit stated G0 +-4.7 % while its cost was flat from 1.2e6 to 2.1e6 Pa.
SECANT_STEP = 0.1
#: Multiples of the start G0 that a fit of G0 with other parameters descends from (best kept).
G0_START_FACTORS = (1.0, 0.5, 2.0)
#: A change of the measured force between consecutive samples larger than this fraction of
#: max|F| (and than 10 median changes) is a jump; JUMP_MARGIN samples either side are left out.
JUMP_FRACTION = 0.1
JUMP_MARGIN = 2
#: A pull-off needs a tensile force beyond this many noise deviations, released within them.
PULL_OFF_NOISE_BAND = 5.0


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
class FitResult:
    """Fitted values (SI) with one-sigma uncertainties, and the fit error."""

    values: dict[str, float]  # every parameter of the chain (free and held)
    uncertainty: dict[str, float]  # free parameters only
    free: tuple[str, ...]
    rmse: float  # N, over the fitted samples
    max_error: float  # N, over the fitted samples
    samples: int  # fitted samples (measured ones minus those next to a jump)
    contact: ContactConfig  # the base contact with the fitted values


def _identify_checks(experiment: Experiment, free: Sequence[str]) -> None:
    if experiment.measured_force.size < len(free) + 2:
        raise FitError(f"{experiment.measured_force.size} force samples cannot fit {len(free)} parameters")
    if "work_of_adhesion" in free and not has_pull_off(experiment.measured_force):
        raise FitError(
            "work_of_adhesion cannot be identified: the record holds no pull-off (a tensile force "
            "released back to zero); hold it (leave it out of --free) or record a retraction"
        )
    if np.any(experiment.input_mode != 0):
        raise FitError("fit needs depth-controlled inputs; the record holds FORCE-mode commands")


def fit(
    contact: ContactConfig,
    experiment: Experiment,
    free: Sequence[str],
    *,
    kelvin: int = 1,
) -> FitResult:
    """Fit the ``free`` parameters of ``contact`` (``kelvin`` Kelvin elements) to ``experiment``.

    Raises FitError when a parameter is not identified by the data.
    """
    _identify_checks(experiment, free)
    values = initial_values(contact, kelvin)
    for name in free:
        if not values[name] > 0.0 or not math.isfinite(values[name]):
            raise InputError(f"start value of {name} must be finite and > 0 (got {values[name]})")
    usable = smooth_samples(experiment.measured_force)
    measured = experiment.measured_force[usable]
    scale = float(np.max(np.abs(measured)))

    def model(
        base: dict[str, float], theta: NDArray[np.float64], names: Sequence[str]
    ) -> NDArray[np.float64]:
        trial = dict(base)
        trial.update({n: float(math.exp(t)) for n, t in zip(names, theta, strict=True)})
        try:
            return run_model(with_parameters(contact, trial, kelvin), experiment).model_force[usable]
        except ValueError:
            # The optimiser stepped outside what the model accepts: a large residual steers it back.
            return np.full(measured.shape, 1e3 * scale)

    stage1 = [n for n in free if n != "work_of_adhesion"]
    compressive = measured > 0.0
    staged = bool(stage1) and "work_of_adhesion" in free and np.count_nonzero(compressive) > len(stage1) + 1

    def descend(start: dict[str, float]) -> tuple[OptimizeResult, dict[str, float]]:
        """Both stages from ``start``: the optimum and every parameter's value there."""
        start = dict(start)
        if staged:
            first = least_squares(
                lambda th: (model(start, th, stage1)[compressive] - measured[compressive]) / scale,
                np.log([start[n] for n in stage1]),
                diff_step=1e-4,
                x_scale=1.0,
            )
            start.update({n: float(math.exp(t)) for n, t in zip(stage1, first.x, strict=True)})
        x0 = np.log([start[n] for n in free])
        found = least_squares(
            lambda th: (model(start, th, free) - measured) / scale, x0, diff_step=1e-4, x_scale=1.0
        )
        start.update({n: float(math.exp(t)) for n, t in zip(free, found.x, strict=True)})
        return found, start

    # The glass modulus shows only in the fastest parts of a record, so with the Kelvin chain
    # free a descent can stop in a valley far from it: start also from G0 halved and doubled
    # and keep the lowest cost.
    factors = G0_START_FACTORS if "G0" in free and len(free) > 1 else (1.0,)
    descents = [descend({**values, "G0": values["G0"] * f}) for f in factors]
    result, values = min(descents, key=lambda d: d[0].cost)
    if not result.success:
        raise FitError(f"the fit did not converge: {result.message}")
    secant = np.column_stack(
        [
            (
                model(values, result.x + SECANT_STEP * e, free)
                - model(values, result.x - SECANT_STEP * e, free)
            )
            / (2 * SECANT_STEP * scale)
            for e in np.eye(len(free))
        ]
    )
    sigma = _uncertainty(secant, result.fun, free)
    residual = result.fun * scale
    return FitResult(
        values=values,
        uncertainty={n: values[n] * s for n, s in zip(free, sigma, strict=True)},
        free=tuple(free),
        rmse=float(np.sqrt(np.mean(residual**2))),
        max_error=float(np.max(np.abs(residual))),
        samples=int(measured.size),
        contact=with_parameters(contact, values, kelvin),
    )


def has_pull_off(force: NDArray[np.float64]) -> bool:
    """True if ``force`` (N, > 0 compressive) becomes tensile beyond its noise and later
    returns to zero within it: the contact was pulled off. Noise is estimated robustly from the
    sample-to-sample changes (median absolute deviation)."""
    if force.size < 3:
        return False
    change = np.diff(force)
    noise = 1.4826 * float(np.median(np.abs(change - np.median(change)))) / math.sqrt(2.0)
    band = PULL_OFF_NOISE_BAND * noise
    lowest = int(np.argmin(force))
    return bool(force[lowest] < -band and np.any(np.abs(force[lowest + 1 :]) <= band))


def smooth_samples(force: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Mask of the samples of a measured force away from its jumps (see the module docstring)."""
    keep = np.ones(force.size, dtype=bool)
    if force.size < 3:
        return keep
    change = np.abs(np.diff(force))
    threshold = max(JUMP_FRACTION * float(np.max(np.abs(force))), 10.0 * float(np.median(change)))
    for jump in np.flatnonzero(change > threshold):
        keep[max(jump - JUMP_MARGIN, 0) : jump + 1 + JUMP_MARGIN + 1] = False
    return keep


def _uncertainty(
    jac: NDArray[np.float64], fun: NDArray[np.float64], free: Sequence[str]
) -> NDArray[np.float64]:
    """Standard deviations of the log-parameters; FitError for unidentified ones."""
    norms = np.linalg.norm(jac, axis=0)
    dead = [n for n, c in zip(free, norms, strict=True) if not c > 1e-12 * max(float(np.max(norms)), 1e-300)]
    if dead:
        raise FitError(
            f"{', '.join(dead)} cannot be identified: the force does not depend on it in this record"
        )
    scaled = jac / norms
    _, singular, vt = np.linalg.svd(scaled, full_matrices=False)
    if singular[-1] <= 0 or singular[0] / singular[-1] > MAX_CONDITION:
        involved = [n for n, v in zip(free, vt[-1], strict=True) if abs(v) > 0.3]
        raise FitError(
            f"{', '.join(involved)} cannot be identified separately from this record (they only act "
            "together; a viscosity needs a change of rate or a hold); fix one of them"
        )
    dof = max(fun.size - len(free), 1)
    s2 = float(fun @ fun) / dof
    cov = s2 * np.linalg.inv(jac.T @ jac)
    sigma = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    vague = [
        f"{n} (+-{100 * s:.0f}%)" for n, s in zip(free, sigma, strict=True) if s > MAX_RELATIVE_UNCERTAINTY
    ]
    if vague:
        raise FitError(
            f"{', '.join(vague)} not identified by this record (a viscosity needs a change of rate "
            "or a hold; the work of adhesion a pull-off); fix it or record more"
        )
    return sigma
