"""Property tests of the time-stepped simulator at the extremes of the parameter space:
G0/G1 1..1e6, relaxation times 1e-6..1e4 s, steps 1e-6..1 s, work of adhesion 0..10 J/m^2,
radii 1e-6..1 m. Kept quick: few rows per example, modest example counts."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scenes import one_contact

from viscoadh_ros.core import reference
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.core.rheology import CreepElement

QUICK = settings(
    max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
G0 = 1e6


def make_contact(*, radius, kelvin, viscosities, work, elements=0, shape="sphere"):
    return one_contact(
        {"shape": shape, "radius": radius},
        glass_shear_modulus=G0,
        kelvin=kelvin,
        viscosities=viscosities,
        work=work,
        numerics={"model": "time_stepped", **({"elements": elements} if elements else {})},
    )


def chain(log_ratio: float, log_tau: float, spread: float) -> tuple[list[float], list[float]]:
    """Two Kelvin elements around G0/G1 = 10^log_ratio and tau = 10^log_tau (spread decades apart)."""
    g1 = G0 / 10.0**log_ratio
    kelvin = [2.0 * g1, 2.0 * g1]
    taus = [10.0**log_tau, 10.0 ** (log_tau + spread)]
    return kelvin, [t * (G0 + k) for t, k in zip(taus, kelvin, strict=True)]


@QUICK
@given(
    log_ratio=st.floats(0.0, 6.0),
    log_tau=st.floats(-6.0, 4.0),
    spread=st.floats(0.0, 3.0),
    log_dt=st.floats(-6.0, 0.0),
    log_radius=st.floats(-6.0, 0.0),
)
def test_non_adhesive_force_between_glass_and_relaxed_hertz(
    log_ratio, log_tau, spread, log_dt, log_radius
) -> None:
    radius, dt = 10.0**log_radius, 10.0**log_dt
    kelvin, viscosities = chain(log_ratio, log_tau, spread)
    contact = make_contact(radius=radius, kelvin=kelvin, viscosities=viscosities, work=0.0)
    element = CreepElement.from_config(contact.material)
    rows = 30
    time = np.arange(rows) * dt
    depth = 1e-2 * radius * np.minimum(np.arange(rows) / 15.0, 1.0)
    result = simulate_history(contact, time, depth=depth)
    case = f"G0/G1=1e{log_ratio:.2f} tau=1e{log_tau:.2f}+{spread:.2f} dt={dt:.2g} R={radius:.2g}"
    for name, values in result.columns().items():
        assert np.all(np.isfinite(values.astype(np.float64))), f"{case}: {name} not finite"
    glass = reference.hertz_force(depth, radius, element.glass_modulus_star)
    relaxed = reference.hertz_force(depth, radius, element.relaxed_modulus_star)
    slack = 1e-9 * glass.max()
    assert np.all(result.force <= 1.005 * glass + slack), f"{case}: above the glass limit"
    assert np.all(result.force >= 0.995 * relaxed - slack), f"{case}: below the relaxed limit"


@QUICK
@given(
    log_ratio=st.floats(0.0, 6.0),
    log_tau=st.floats(-6.0, 4.0),
    log_dt=st.floats(-6.0, 0.0),
    work=st.one_of(st.just(0.0), st.floats(1e-3, 10.0)),
    log_radius=st.floats(-6.0, 0.0),
    amplitude=st.floats(0.5, 4.0),
)
def test_adhesive_cycles_stay_finite_and_dissipative(
    log_ratio, log_tau, log_dt, work, log_radius, amplitude
) -> None:
    radius, dt = 10.0**log_radius, 10.0**log_dt
    kelvin, viscosities = chain(log_ratio, log_tau, 1.0)
    contact = make_contact(radius=radius, kelvin=kelvin, viscosities=viscosities, work=work)
    element = CreepElement.from_config(contact.material)
    scale = abs(reference.figure4_scales(radius, work, element).depth) if work > 0.0 else 1e-3 * radius
    rows = 40
    time = np.arange(rows) * dt
    depth = scale * (amplitude * np.sin(2.0 * np.pi * np.arange(rows) / rows) - 0.2)
    result = simulate_history(contact, time, depth=depth)
    case = f"G0/G1=1e{log_ratio:.2f} tau=1e{log_tau:.2f} dt={dt:.2g} w={work:.3g} R={radius:.2g}"
    for name, values in result.columns().items():
        assert np.all(np.isfinite(values.astype(np.float64))), f"{case}: {name} not finite"
    assert np.all(result.contact_radius >= 0.0), case
    energy_scale = max(np.abs(result.energy_input).max(), work * math.pi * result.contact_radius.max() ** 2)
    assert result.energy_dissipated.min() >= 0.0, f"{case}: negative dissipation"
    assert np.all(np.diff(result.energy_dissipated) >= -1e-9 * energy_scale), f"{case}: dissipation decreases"


def test_converges_as_elements_double() -> None:
    """A standard-solid adhesive cycle at a finite rate: the RMS difference to a 640-element
    run shrinks as the element count doubles. (RMS, not max: where the edge runs off at
    pull-off the force falls steeply in time and one row can differ by a few percent.)"""
    work, radius = 0.05, 1e-3
    kelvin, viscosities = [1e5], [1e-2 * 1.1e6]
    element = CreepElement.from_config(
        make_contact(radius=radius, kelvin=kelvin, viscosities=viscosities, work=work).material
    )
    d_c = abs(reference.figure4_scales(radius, work, element).depth)
    time = np.linspace(0.0, 0.2, 201)
    depth = d_c * (3.0 * np.sin(np.pi * time / 0.2) - 1.0)

    def force(elements: int) -> np.ndarray:
        contact = make_contact(
            radius=radius, kelvin=kelvin, viscosities=viscosities, work=work, elements=elements
        )
        return simulate_history(contact, time, depth=depth).force

    exact = force(640)
    errors = [float(np.sqrt(np.mean((force(n) - exact) ** 2))) for n in (40, 80, 160)]
    case = f"errors={errors}"
    assert errors[2] < 0.5 * errors[0], f"no convergence: {case}"
    assert errors[2] < 1e-2 * np.abs(exact).max(), f"RMS not within 1% of the peak at 160 elements: {case}"
