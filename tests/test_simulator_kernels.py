"""The numba kernels against their plain-numpy references (tests/naive.py)."""

from __future__ import annotations

import math

import naive
import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator


def make_contact(
    *, shape="sphere", kelvin=(), viscosities=(), work=0.0, elements=0, model="time_stepped", **indenter
):
    """One contact through the scene loader (radius 1 mm sphere unless told otherwise)."""
    indenter = {"shape": shape, **({"radius": 1e-3} if shape in ("sphere", "flat_punch") else {}), **indenter}
    numerics = {"model": model, **({"elements": elements} if elements else {})}
    return one_contact(indenter, kelvin=kelvin, viscosities=viscosities, work=work, numerics=numerics)


CHAINS = {
    "elastic": ((), ()),
    "standard": ((1e5,), (1e3,)),
    "three": ((2e5, 5e4, 1e6), (1e2, 1e4, 1e-1)),
}


def make_row(chain: str, *, work=0.05, length=2e-4, elements=24, seed=0) -> _kernels.Row:
    """A row of the scene's simulator with random (reproducible) Kelvin memory: elongations
    and unit responses B (within their range [0, E_r*/E_k*])."""
    kelvin, viscosities = CHAINS[chain]
    sim = ContactSimulator(make_contact(kelvin=kelvin, viscosities=viscosities, work=work, elements=elements))
    rng = np.random.default_rng(seed)
    memory = rng.normal(scale=2e-6, size=(elements, len(kelvin)))
    unit = rng.uniform(size=(elements, len(kelvin))) * sim._model.steady
    return sim._model._build_row(length, memory, unit)


@pytest.mark.parametrize("chain", list(CHAINS))
@pytest.mark.parametrize("dt", [1e-6, 1e-2, 1.0, 1e4])
def test_kelvin_update_matches_matrix_exponential(chain: str, dt: float) -> None:
    row = make_row(chain)
    expected, expected_b = naive.kelvin_update(row, 10, 3e-6, 5e-6, dt)
    _kernels.kelvin_update(row, 10, 3e-6, 5e-6, dt)
    scale = max(float(np.max(np.abs(expected), initial=0.0)), 1e-12)
    np.testing.assert_allclose(row.wl, expected, rtol=1e-9, atol=1e-9 * scale, err_msg=f"{chain} dt={dt}")
    np.testing.assert_allclose(row.wsum, expected.sum(axis=1), rtol=1e-9, atol=1e-9 * scale, err_msg=chain)
    np.testing.assert_allclose(row.wb, expected_b, rtol=1e-9, atol=1e-12, err_msg=f"B {chain} dt={dt}")


@pytest.mark.parametrize("chain", ["standard", "three"])
@pytest.mark.parametrize("dt", [1e-4, 1.0])
@pytest.mark.parametrize("depths", [(3e-6, 5e-6)])
def test_damper_work_is_the_energy_balance(chain: str, dt: float, depths: tuple[float, float]) -> None:
    """The kernel's closed-form damper work over a step (the dissipation's viscous part)
    equals the damper power integrated with the chain by a stiff ODE solver (three elements
    in contact, three creeping back)."""
    row = make_row(chain, elements=6)
    expected = naive.damper_work(row, 3, *depths, dt)
    got = _kernels.kelvin_update(row, 3, *depths, dt)
    assert got >= 0.0
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-24, err_msg=f"{chain} dt={dt} {depths}")


def test_phi_is_finite_and_exact_at_both_ends() -> None:
    for x in (0.0, 1e-12, 1e-5, 1e-4, 0.3, 50.0, 1e6, 1e300):
        e, f1, f2 = _kernels._phi(x)
        assert all(math.isfinite(v) for v in (e, f1, f2)), f"x={x}"
        if 1e-3 < x < 100:
            assert math.isclose(f1, -math.expm1(-x) / x, rel_tol=1e-14), f"phi1 x={x}"
            assert math.isclose(f2, (x + math.expm1(-x)) / x**2, rel_tol=1e-10), f"phi2 x={x}"
    # Either side of the series switch the two forms agree.
    below, above = _kernels._phi(0.99999e-4), _kernels._phi(1.00001e-4)
    np.testing.assert_allclose(below[1:], above[1:], rtol=1e-8, err_msg="series switch")


@pytest.mark.parametrize("chain", list(CHAINS))
@pytest.mark.parametrize("radius", [0.0, 3e-5, 7.7e-5, 1.3e-4])
def test_force_energy_and_gap_match_dense_quadrature(chain: str, radius: float) -> None:
    row = make_row(chain)
    depth = 4e-6
    case = f"{chain} a={radius}"
    # The kernel takes int g exactly at the fine points, the reference integrates the
    # linear interpolant of g: they differ at O(fine spacing^2).
    np.testing.assert_allclose(
        _kernels.force(row, radius, depth),
        naive.force(row, radius, depth),
        rtol=2e-5,
        atol=1e-12,
        err_msg=case,
    )
    # The kernel integrates the (piecewise quadratic) energy density by trapezoids on the fine
    # grid (32 points per element); random memory is rough, so allow that quadrature error.
    np.testing.assert_allclose(
        _kernels.stored_energy(row, radius, depth),
        naive.stored_energy(row, radius, depth),
        rtol=1e-3,
        atol=1e-22,
        err_msg=case,
    )
    for x in (1e-6, 0.5 * radius, radius, 1.5e-4):
        for interior in (True, False):
            np.testing.assert_allclose(
                _kernels.criterion_gap(row, x, depth, radius, interior=interior),
                naive.gap(row, np.array([x]), depth, radius, interior)[0],
                rtol=1e-9,
                atol=1e-15,
                err_msg=f"{case} x={x} interior={interior}",
            )


@pytest.mark.parametrize("chain", list(CHAINS))
@pytest.mark.parametrize(("radius", "depth"), [(0.0, 2e-6), (5e-5, 1.5e-5), (1e-4, -1e-6), (8e-5, 2e-6)])
def test_edge_location_matches_dense_search(chain: str, radius: float, depth: float) -> None:
    row = make_row(chain)
    new_radius, _, grow = _kernels.locate_edge(row, radius, depth)
    assert not grow
    np.testing.assert_allclose(
        new_radius,
        naive.locate_edge(row, radius, depth),
        rtol=0,
        atol=1e-5 * row.length,
        err_msg=f"{chain} a={radius} d={depth}",
    )


def test_detachment_wins_when_both_criteria_hold() -> None:
    """Interior over-stretched and exterior memory inviting attachment at the same edge:
    the interior lets go (numba and reference agree, and the edge recedes)."""
    row = make_row("standard")
    radius, depth = 8e-5, 1.5e-6
    n_in = naive.interior_count(radius, row.dx, row.elements)
    memory = np.zeros_like(row.wl)
    memory[:n_in] = 4e-6  # crept interior: pushes its glass springs into tension
    memory[n_in:] = -4e-6  # exterior raised towards the indenter
    row.set_memory(memory, np.zeros_like(memory))
    assert _kernels.criterion_gap(row, radius, depth, radius, interior=True) < 0.0
    assert _kernels.criterion_gap(row, radius, depth, radius, interior=False) > 0.0
    new_radius, motion, _ = _kernels.locate_edge(row, radius, depth)
    assert motion == _kernels.MOTION_DETACH and new_radius < radius
    np.testing.assert_allclose(
        new_radius, naive.locate_edge(row, radius, depth), rtol=0, atol=1e-5 * row.length
    )


def test_advance_without_edge_motion_is_the_exact_chain_update() -> None:
    """One `advance` over a step in which the edge stays put: chains updated exactly, force
    and work consistent with the force kernel."""
    row = make_row("three", work=0.0)
    radius = 1.0e-4  # depth chosen so the (non-adhesive) edge stays within the cell
    depth = float(row.gf[int(radius / row.df)]) + 1e-9
    n_in = naive.interior_count(radius, row.dx, row.elements)
    expected, expected_b = naive.kelvin_update(row, n_in, depth, depth, 0.5)
    status, out = _kernels.advance(row, radius, depth, depth, 0.5, max_substep=0.0, max_edge_move=row.dx)
    assert status == _kernels.STATUS_OK
    np.testing.assert_allclose(row.wl, expected, rtol=1e-9, atol=1e-15, err_msg="chains")
    np.testing.assert_allclose(row.wb, expected_b, rtol=1e-9, atol=1e-15, err_msg="unit responses")
    np.testing.assert_allclose(
        out[_kernels.OUT_FORCE],
        _kernels.force(row, out[_kernels.OUT_RADIUS], depth),
        rtol=1e-12,
        err_msg="force",
    )
    assert out[_kernels.OUT_WORK] == 0.0


def test_wrappers_reject_bad_input_before_numba() -> None:
    row = make_row("standard")
    with pytest.raises(ValueError, match="d1"):
        _kernels.advance(row, 0.0, 0.0, math.nan, 0.1, max_substep=0.0, max_edge_move=row.dx)
    with pytest.raises(ValueError, match="dt"):
        _kernels.advance(row, 0.0, 0.0, 1e-6, -0.1, max_substep=0.0, max_edge_move=row.dx)
    with pytest.raises(ValueError, match="wl"):
        row.set_memory(np.full_like(row.wl, np.inf))
    with pytest.raises(TypeError, match="wl"):
        row.set_memory(row.wl.astype(np.float32))
    with pytest.raises(ValueError, match="n_in"):
        _kernels.kelvin_update(row, row.elements + 1, 0.0, 0.0, 1.0)


def test_warm_up_compiles_every_kernel_python_calls() -> None:
    """The kernels that simulator code calls from Python (directly or through the public
    wrappers) are compiled by `warm_up`, so a node that warms up never compiles mid-run."""
    _kernels.warm_up()
    for name in ("_advance", "_advance_rows", "_force", "_stored_energy", "_kelvin_update", "_remap"):
        assert getattr(_kernels, name).signatures, f"warm_up() left {name} uncompiled"


@pytest.mark.parametrize("chain", ["standard", "three"])
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("depth", [-3e-6, -1e-6, 0.0, 1e-6])
def test_first_touch_block_skip_finds_the_first_touching_fine_point(
    chain: str, seed: int, depth: float
) -> None:
    """The block-skipping first-touch search returns the same fine point as a point-by-point
    scan of ``d - g - w >= 0`` (exterior memory interpolated as `naive.side_values`)."""
    row = make_row(chain, seed=seed)
    x = np.arange(row.gf.shape[0]) * row.df
    touching = depth - row.gf - naive.side_values(row, x, row.wsum, row.bsum, 0, row.elements - 1) >= 0.0
    expected = int(np.argmax(touching)) if touching.any() else -1
    found = _kernels._first_touch(
        depth, row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.reach
    )
    assert found == expected, f"{chain} seed={seed} d={depth}: {found} != {expected}"
