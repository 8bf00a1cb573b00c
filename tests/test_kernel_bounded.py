"""The bounded-cost edge search (issue 13) finds exactly the edge of a point-by-point scan, and
the cheap step transaction restores exactly what the old snapshot did."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator


def _row(kelvin: tuple, viscosities: tuple, seed: int, *, smooth: bool) -> _kernels.Row:
    """A row with random Kelvin memory (rough: independent per element; smooth: a random
    low-order profile, the kind a real history leaves)."""
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        kelvin=kelvin,
        viscosities=viscosities,
        work=0.05,
        numerics={"model": "time_stepped", "elements": 24},
    )
    sim = ContactSimulator(contact)
    rng = np.random.default_rng(seed)
    n, k = 24, len(kelvin)
    if smooth:
        x = np.linspace(0.0, 1.0, n)[:, None]
        memory = 2e-6 * (
            rng.normal(size=(1, k)) + rng.normal(size=(1, k)) * x + rng.normal(size=(1, k)) * x**2
        )
    else:
        memory = rng.normal(scale=2e-6, size=(n, k))
    unit = rng.uniform(size=(n, k)) * sim._model.steady
    return sim._model._build_row(2e-4, memory, unit)


def _h(row: _kernels.Row, x: float, d: float, lo: int, hi: int) -> float:
    return _kernels._h(x, d, row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)


def _bisect(row: _kernels.Row, x_lo: float, x_hi: float, d: float, lo: int, hi: int) -> float:
    args = (row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
    return _kernels._bisect(x_lo, x_hi, d, *args)


def _point_by_point(row: _kernels.Row, a: float, d: float) -> float:
    """The 0.2.0 edge search without its block skipping (every fine point tested)."""
    n = row.elements
    m = row.gf.shape[0]
    n_in = _kernels._interior_count(a, row.dx, n)

    def scan_out(x_start: float, lo: int, hi: int) -> float:
        j = int(x_start / row.df) + 1
        prev = x_start
        while j < m:
            xj = j * row.df
            if _h(row, xj, d, lo, hi) < 0.0:
                return _bisect(row, prev, xj, d, lo, hi)
            prev = xj
            j += 1
        return prev

    if a <= 0.0:
        j = int(
            _kernels._first_touch(
                d, row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.reach
            )
        )
        return 0.0 if j < 0 else scan_out(j * row.df, 0, n - 1)
    if _h(row, a, d, 0, n_in - 1) < 0.0:
        j = int(a / row.df)
        if j * row.df >= a:
            j -= 1
        upper = a
        while j >= 0:
            xj = j * row.df
            if _h(row, xj, d, 0, n_in - 1) >= 0.0:
                return _bisect(row, xj, upper, d, 0, n_in - 1)
            upper = xj
            j -= 1
        return 0.0
    if _h(row, a, d, n_in, n - 1) > 0.0:
        return scan_out(a, n_in, n - 1)
    return a


@pytest.mark.parametrize("smooth", [False, True])
@pytest.mark.parametrize(
    ("kelvin", "viscosities"), [((), ()), ((1e5,), (1e3,)), ((2e5, 5e4, 1e6), (1e2, 1e4, 1e-1))]
)
def test_block_skipping_edge_search_equals_the_point_by_point_scan(kelvin, viscosities, smooth) -> None:
    """Bit for bit, over random memories, radii from none to most of the row and depths from
    pulled to pressed: the block bounds never skip a point the plain scan would stop at."""
    for seed in range(6):
        row = _row(kelvin, viscosities, seed, smooth=smooth)
        rng = np.random.default_rng(100 + seed)
        for _ in range(12):
            a = float(rng.choice([0.0, rng.uniform(0.0, 0.9) * row.length]))
            d = float(rng.uniform(-3e-6, 1.5e-5))
            got, _, grow = _kernels.locate_edge(row, a, d)
            if grow:
                continue
            assert got == _point_by_point(row, a, d), (seed, a, d)


def test_a_rejected_substep_stops_its_scan_beyond_the_motion_limit() -> None:
    """With a motion limit the search only proves the edge moved further (snap-in: a radius
    past the limit, not the far root); without it the far root itself."""
    row = _row((1e5,), (1e3,), 0, smooth=True)
    row.set_memory(np.zeros_like(row.wl))
    d = 1e-5
    args = (row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.c_crit, row.reach)
    far, _, _ = _kernels._locate_edge(0.0, d, *args, math.inf)
    limit = 2.0 * row.dx
    assert far > 4.0 * limit
    stopped, _, _ = _kernels._locate_edge(0.0, d, *args, limit)
    assert limit < stopped < far


def test_step_rollback_after_the_kernel_ran_restores_every_output() -> None:
    """The journalled transaction: a step interrupted after the kernel wrote the memory
    leaves the simulator as a twin that never took it (memory, radius, outputs, energies)."""
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        kelvin=(1e5,),
        viscosities=(1e3,),
        work=0.05,
        numerics={"model": "time_stepped"},
    )
    live, twin = ContactSimulator(contact), ContactSimulator(contact)
    for sim in (live, twin):
        for i, d in enumerate(np.linspace(0.0, 8e-6, 30)):
            sim.step(1e-3 * (i + 1), depth=float(d))
    real = live._model.advance

    def advance_then_fail(*args):
        real(*args)
        raise KeyboardInterrupt

    live._model.advance = advance_then_fail
    with pytest.raises(KeyboardInterrupt):
        live.step(live.time + 1e-3, depth=2e-6)
    del live._model.advance
    assert live.output == twin.output
    np.testing.assert_array_equal(live._model.row.wl, twin._model.row.wl)
    np.testing.assert_array_equal(live._model.row.wb, twin._model.row.wb)
    for sim in (live, twin):
        sim.step(sim.time + 1e-3, depth=3e-6)
    assert live.output == twin.output


def _wide_row(kelvin: tuple, viscosities: tuple, seed: int, *, smooth: bool, preset: str) -> _kernels.Row:
    """A 160-element row (`preset`'s fine grid) with random memory, like `_row`."""
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        kelvin=kelvin,
        viscosities=viscosities,
        work=0.05,
        numerics={"model": "time_stepped", "elements": 160, "preset": preset},
    )
    model = ContactSimulator(contact)._model
    rng = np.random.default_rng(seed)
    n, k = 160, len(kelvin)
    if smooth:
        x = np.linspace(0.0, 1.0, n)[:, None]
        memory = 2e-6 * (
            rng.normal(size=(1, k)) + rng.normal(size=(1, k)) * x + rng.normal(size=(1, k)) * x**2
        )
    else:
        memory = rng.normal(scale=2e-6, size=(n, k))
    unit = rng.uniform(size=(n, k)) * model.steady
    return model._build_row(2e-4, memory, unit)


@pytest.mark.parametrize("preset", ["fast", "balanced"])
@pytest.mark.parametrize("smooth", [False, True])
@pytest.mark.parametrize(("kelvin", "viscosities"), [((1e5,), (1e3,)), ((2e5, 5e4, 1e6), (1e2, 1e4, 1e-1))])
def test_the_motion_limited_edge_search_reads_only_the_trial_window(
    kelvin, viscosities, smooth, preset
) -> None:
    """A substep trial in contact updates only `_trial_window`'s elements before the
    motion-limited edge search (issue 13): whatever the memory outside the window holds
    (NaN, far above or below, noise), the search returns exactly the same radius, motion and
    grow flag, accepted or rejected, at every motion limit the presets use and beyond."""
    searched = rejected = 0
    for seed in range(4):
        row = _wide_row(kelvin, viscosities, seed, smooth=smooth, preset=preset)
        n = row.elements
        rng = np.random.default_rng(200 + seed)
        for _ in range(25):
            a = float(rng.uniform(0.01, 0.99) * row.length)
            d = float(rng.uniform(-3e-6, 1.5e-5))
            max_move = float(rng.choice([0.5, 1.0, 2.0, 5.0])) * row.dx
            tail = (row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.c_crit, row.reach, max_move)
            want = _kernels._locate_edge(a, d, row.wsum, row.bsum, *tail)
            n_in = _kernels._interior_count(a, row.dx, n)
            lo, hi = _kernels._trial_window(a, n_in, n, row.dx, row.df, max_move)
            assert 0 <= lo < hi <= n and lo <= max(n_in - 4, 0) and hi >= min(n_in + 3, n)
            if lo == 0 and hi == n:
                continue
            searched += 1
            rejected += abs(want[0] - a) > max_move
            for poison in (math.nan, 1e-3, -1e-3, None):
                wsum, bsum = row.wsum.copy(), row.bsum.copy()
                for values in (wsum, bsum):
                    fill = rng.normal(scale=1e-4, size=n) if poison is None else np.full(n, poison)
                    values[:lo] = fill[:lo]
                    values[hi:] = fill[hi:]
                got = _kernels._locate_edge(a, d, wsum, bsum, *tail)
                assert got == want, (seed, a, d, max_move, lo, hi, poison)
    assert searched >= 60 and rejected >= 5, (searched, rejected)
