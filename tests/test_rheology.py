"""Creep element and Prony conversion against exact solutions of the series chain."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.rheology import CreepElement, creep_to_prony, prony_to_creep, standard_solid

# (G0, G_k, eta_k): retardation times spread over many decades.
MATERIALS = {
    "K1": (1e6, [1e4], [1e3]),
    "K2": (2e6, [5e5, 3e4], [5e-1, 3e3]),
    "K3": (1e9, [1e7, 2e8, 4e6], [1e4, 2e2, 4e9]),
    "K4": (1e6, [1e4, 3e5, 2e3, 1e7], [1e3, 1e-1, 1e6, 1e2]),
}


def element(name: str) -> CreepElement:
    g0, moduli, viscosities = MATERIALS[name]
    return CreepElement(
        glass_shear_modulus=g0, kelvin_shear_moduli=np.array(moduli), kelvin_viscosities=np.array(viscosities)
    )


def relaxation_by_state_space(e: CreepElement, t: np.ndarray) -> np.ndarray:
    """Plain-numpy reference: unit strain step on the chain. Kelvin elongations obey
    eta_k dl_k/dt = G0 (1 - sum_j l_j) - G_k l_k, i.e. dl/dt = A (l - l_inf); the stress is
    G0 (1 - sum l) = G_inf + G0 * 1^T expm(A t) l_inf (written around the steady state so the
    stiff matrix exponential is not differenced against 1)."""
    g0 = e.glass_shear_modulus
    matrix = -(g0 + np.diag(e.kelvin_shear_moduli)) / e.kelvin_viscosities[:, None]
    steady = np.linalg.solve(matrix, -g0 / e.kelvin_viscosities)
    g_inf = g0 * (1.0 - np.sum(steady))
    return np.array([g_inf + g0 * np.sum(expm(matrix * time) @ steady) for time in t])


def boltzmann_identity(e: CreepElement, t: np.ndarray) -> np.ndarray:
    """G(t) J(0) + int_0^t G(t-s) J'(s) ds, which is exactly 1 for a consistent pair G, J.
    The convolution of exponentials is done in closed form, so this checks the Prony series
    of any spread of times to rounding error."""
    p = e.prony
    retard = e.retardation_times
    total = p(t) / e.glass_shear_modulus
    for g_k, t_k in zip(e.kelvin_shear_moduli, retard, strict=True):
        rate = 1.0 / (g_k * t_k)  # J'(s) = rate * exp(-s/t_k)
        total = total + p.long_term_modulus * rate * t_k * -np.expm1(-t / t_k)
        for g_i, tau_i in zip(p.moduli, p.times, strict=True):
            kernel = (np.exp(-t / t_k) - np.exp(-t / tau_i)) / (1.0 / tau_i - 1.0 / t_k)
            total = total + g_i * rate * kernel
    return total


# The matrix exponential of the reference loses ~eps * (fastest/slowest rate) relative
# accuracy, ~1e-7 for the chains with times over 9-10 decades; the Boltzmann identity below
# checks those to 1e-11.
@pytest.mark.parametrize(("name", "rtol"), [("K1", 1e-10), ("K2", 1e-9), ("K3", 1e-7), ("K4", 1e-7)])
def test_relaxation_modulus_matches_state_space(name, rtol):
    e = element(name)
    t = np.concatenate([[0.0], np.logspace(-8, 7, 46)])
    np.testing.assert_allclose(
        e.relaxation_modulus(t),
        relaxation_by_state_space(e, t),
        rtol=rtol,
        atol=1e-12 * e.glass_shear_modulus,
        err_msg=f"relaxation modulus {name}",
    )


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_relaxation_and_creep_are_inverse(name):
    e = element(name)
    t = np.concatenate([[0.0], np.logspace(-9, 8, 69)])
    np.testing.assert_allclose(boltzmann_identity(e, t), 1.0, rtol=1e-11, err_msg=f"G*dJ = 1 for {name}")
    np.testing.assert_allclose(e.relaxation_modulus(0.0), e.glass_shear_modulus, rtol=1e-12, err_msg=name)
    np.testing.assert_allclose(e.relaxation_modulus(1e12), e.relaxed_shear_modulus, rtol=1e-12, err_msg=name)
    np.testing.assert_allclose(
        e.creep_compliance(1e12), 1.0 / e.relaxed_shear_modulus, rtol=1e-12, err_msg=name
    )


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_prony_round_trip_and_interlacing(name):
    e = element(name)
    p = e.prony
    back = prony_to_creep(p.long_term_modulus, p.moduli, p.times)
    order = np.argsort(e.retardation_times)[::-1]
    np.testing.assert_allclose(back.glass_shear_modulus, e.glass_shear_modulus, rtol=1e-12, err_msg=name)
    np.testing.assert_allclose(back.retardation_times, e.retardation_times[order], rtol=1e-10, err_msg=name)
    np.testing.assert_allclose(
        back.kelvin_shear_moduli, e.kelvin_shear_moduli[order], rtol=1e-9, err_msg=name
    )
    # T_1 > tau_1 > T_2 > tau_2 > ...
    merged = np.empty(2 * e.kelvin_count)
    merged[0::2], merged[1::2] = back.retardation_times, p.times
    assert np.all(np.diff(merged) < 0), f"{name}: times do not interlace {merged}"


def test_standard_solid_matches_physics_notes():
    g0, g1, eta1 = 1e9, 1e7, 1e4
    e = CreepElement(
        glass_shear_modulus=g0, kelvin_shear_moduli=np.array([g1]), kelvin_viscosities=np.array([eta1])
    )
    g_inf, tau = g0 * g1 / (g0 + g1), eta1 / (g0 + g1)
    assert e.relaxed_shear_modulus == pytest.approx(g_inf, rel=1e-14)
    np.testing.assert_allclose(e.prony.times, [tau], rtol=1e-13)
    t = np.array([0.0, tau / 3, tau, 7 * tau])
    np.testing.assert_allclose(e.relaxation_modulus(t), g_inf + (g0 - g_inf) * np.exp(-t / tau), rtol=1e-12)
    again = standard_solid(glass_shear_modulus=g0, relaxed_shear_modulus=g_inf, relaxation_time=tau)
    np.testing.assert_allclose(again.kelvin_shear_moduli, [g1], rtol=1e-12)
    np.testing.assert_allclose(again.kelvin_viscosities, [eta1], rtol=1e-12)


def test_moduli_star_and_elastic_element():
    e = CreepElement(glass_shear_modulus=3e6, poisson_ratio=0.25)
    assert e.kelvin_count == 0
    assert e.glass_modulus_star == pytest.approx(2 * 3e6 / 0.75)
    assert e.relaxed_modulus_star == e.glass_modulus_star
    np.testing.assert_allclose(e.relaxation_modulus([0.0, 5.0]), 3e6)
    assert element("K1").glass_modulus_star == pytest.approx(4e6)
    merged = prony_to_creep(1e5, [], [])
    assert merged.kelvin_count == 0 and merged.glass_shear_modulus == 1e5


def test_equal_times_are_merged():
    twin = CreepElement(
        glass_shear_modulus=1e6,
        kelvin_shear_moduli=np.array([1e5, 3e5]),
        kelvin_viscosities=np.array([1e3, 3e3]),
    )
    single = CreepElement(
        glass_shear_modulus=1e6, kelvin_shear_moduli=np.array([7.5e4]), kelvin_viscosities=np.array([7.5e2])
    )
    t = np.logspace(-5, 1, 13)
    np.testing.assert_allclose(twin.relaxation_modulus(t), single.relaxation_modulus(t), rtol=1e-12)
    np.testing.assert_allclose(twin.creep_compliance(t), single.creep_compliance(t), rtol=1e-12)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(-3.0, 3.0), st.floats(-6.0, 4.0)),
        min_size=1,
        max_size=4,
        unique_by=lambda v: round(v[1], 2),
    ),
    st.floats(-2.0, 2.0),
)
def test_prony_conversion_reproduces_relaxation_modulus(terms, log_ratio):
    """Any Prony series (moduli over 6 decades, times 1e-6..1e4 s) -> creep element -> the same G(t)."""
    g_inf = 1e6 * 10.0**log_ratio
    moduli = np.array([1e6 * 10.0**m for m, _ in terms])
    times = np.array([10.0**t for _, t in terms])
    e = prony_to_creep(g_inf, moduli, times)
    t = np.concatenate([[0.0], np.logspace(-8, 6, 29)])
    expected = g_inf + np.exp(-t[:, None] / times) @ moduli
    np.testing.assert_allclose(
        e.relaxation_modulus(t), expected, rtol=1e-9, err_msg=f"{terms}, G_inf={g_inf}"
    )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"glass_shear_modulus": -1.0}, r"material.glass_shear_modulus must be > 0"),
        (
            {"kelvin_shear_moduli": [1e4, 1e5], "kelvin_viscosities": [1.0, -3.0]},
            r"kelvin_viscosities\[1\] must be > 0",
        ),
        (
            {"kelvin_shear_moduli": [np.nan], "kelvin_viscosities": [1.0]},
            r"kelvin_shear_moduli\[0\] must be finite",
        ),
        ({"kelvin_shear_moduli": [1e4], "kelvin_viscosities": [1.0, 2.0]}, r"same length"),
        ({"poisson_ratio": 0.6}, r"material.poisson_ratio must be in \[0, 0.5\]"),
    ],
)
def test_bad_material_names_the_key(kwargs, match):
    values = {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [], "kelvin_viscosities": [], **kwargs}
    with pytest.raises(InputError, match=match):
        CreepElement(**values)


def test_bad_prony_and_times():
    with pytest.raises(InputError, match=r"material.prony_times\[0\] must be > 0"):
        prony_to_creep(1e5, [1e5], [0.0])
    with pytest.raises(InputError, match=r"material.prony_long_term_modulus must be > 0"):
        prony_to_creep(0.0, [1e5], [1.0])
    with pytest.raises(InputError, match="must be finite and >= 0"):
        element("K1").relaxation_modulus([-1.0])
    assert creep_to_prony(element("K2")).moduli.shape == (2,)
