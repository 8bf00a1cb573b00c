"""`_kernels._deviation_integral` with a work space (0.6.0: the cells' Simpson terms in one
vectorised loop, summed in a second) equals its one loop without it, bit for bit: random rows
(signed zeros, negative memory), the fine grid on and off the element ends, every interior
count, edges on and between centres. And (0.7.0) the sum form the kernels take with a row's
force weights after ``gint`` is the same integral to rounding, and rows carry those weights."""

from __future__ import annotations

import numpy as np
import pytest

from viscoadh_ros.core import _kernels


def _one_mode(bsum: np.ndarray) -> tuple:
    """The per-mode arguments of `_force`/`_deviation_integral` for one Kelvin element (the
    centre blend's share is then read from the total unit memory alone): wb, p, p_inv, lam, beta."""
    one = np.ones(1)
    return bsum.reshape(-1, 1), np.eye(1), np.eye(1), one, one

def _grid(n: int, per_cell: int, on_grid: bool, rng: np.random.Generator):
    length = 1e-4
    dx = length / n
    m = n * per_cell + (1 if on_grid else 4)
    xf = np.linspace(0.0, length, m)
    df = xf[1]
    gf = xf**2 / 2e-3 + 1e-9 * rng.random(m)
    gint = np.concatenate([[0.0], np.cumsum(0.5 * (gf[1:] + gf[:-1]) * df)])
    g_c = np.interp((np.arange(n) + 0.5) * dx, xf, gf)
    weights = np.empty(_kernels.force_weights_size(n))
    _kernels._fill_force_weights(g_c, gf, gint, df, dx, weights)
    return length, dx, df, gf, gint, g_c, np.concatenate([gint, weights])


@pytest.mark.parametrize(("n", "per_cell", "on_grid"), [(7, 4, True), (64, 32, True), (50, 9, False)])
def test_the_buffered_sum_is_the_one_loop_bit_for_bit(n: int, per_cell: int, on_grid: bool) -> None:
    rng = np.random.default_rng(n)
    length, dx, df, gf, gint, g_c, _ = _grid(n, per_cell, on_grid, rng)
    checked = 0
    for trial in range(40):
        wsum = rng.normal(scale=1e-6, size=n)
        wsum[rng.random(n) < 0.1] = -0.0
        bsum = rng.random(n)
        kap = float(rng.uniform(0.05, 0.9))
        d = float(rng.uniform(-1e-6, 5e-6))
        for a in (rng.uniform(0.0, length), (rng.integers(1, n) + 0.5) * dx, length, 0.3 * dx):
            n_in = _kernels._interior_count(a, dx, n)
            buf = np.full(n, np.nan)
            args = (a, d, wsum, bsum, n_in, dx, g_c, gf, gint, df, kap)
            one = _kernels._deviation_integral(*args, np.empty(0), *_one_mode(bsum))
            two = _kernels._deviation_integral(*args, buf, *_one_mode(bsum))
            assert np.float64(one).tobytes() == np.float64(two).tobytes(), (trial, a, one, two)
            force = (
                _kernels._force(a, d, wsum, bsum, dx, g_c, gf, gint, df, 1e6, kap, b, *_one_mode(bsum))
                for b in (np.empty(0), buf)
            )
            assert len({np.float64(f).tobytes() for f in force}) == 1
            checked += n_in > 2
    assert checked > 40


@pytest.mark.parametrize(
    ("n", "per_cell", "on_grid"), [(7, 4, True), (64, 32, True), (50, 9, False), (900, 8, True)]
)
def test_the_sum_form_is_simpsons_integral_to_rounding(n: int, per_cell: int, on_grid: bool) -> None:
    """0.7.0: with the row's force weights after ``gint`` the deviation integral is taken as a
    trapezoid of the nodal deviations plus a weighted sum of B (`_fill_force_weights`), the
    same integral as the cell-by-cell Simpson form (without the weights) to rounding: within
    16 eps of the integral of the terms the deviation is a difference of, on relaxed-like
    memories (wsum = kap (d - g) plus a small deviation, B near kap: the deviation is a small
    difference of large terms) and on random ones; every interior count, edges on and between
    centres; and `_deviation_after` (the part past a deferred block) likewise."""
    rng = np.random.default_rng(n + per_cell)
    length, dx, df, gf, gint, g_c, gint_w = _grid(n, per_cell, on_grid, rng)
    worst = 0.0
    for trial in range(60):
        kap = float(rng.uniform(0.05, 0.999))
        d = float(rng.uniform(0.0, 5e-6))
        if trial % 2:
            deviation = rng.normal(scale=1e-9, size=n)
            wsum = kap * (d - g_c) + deviation
            bsum = kap + rng.normal(scale=1e-3, size=n)
        else:
            wsum = rng.normal(scale=1e-6, size=n)
            bsum = rng.random(n)
        for a in (rng.uniform(0.0, length), (rng.integers(1, n) + 0.5) * dx, length, 0.3 * dx, 1.2 * dx):
            n_in = _kernels._interior_count(a, dx, n)
            simpson = _kernels._deviation_integral(
                a, d, wsum, bsum, n_in, dx, g_c, gf, gint, df, kap, np.empty(0), *_one_mode(bsum)
            )
            summed = _kernels._deviation_integral(
                a, d, wsum, bsum, n_in, dx, g_c, gf, gint_w, df, kap, np.empty(0), *_one_mode(bsum)
            )
            f = wsum[:n_in] - kap * (d - g_c[:n_in])
            # Rounding's own scale: the terms the deviations are differences of.
            scale = dx * (
                np.sum(np.abs(f)) + np.sum(np.abs(wsum[:n_in])) + kap * np.sum(np.abs(d - g_c[:n_in]))
            )
            scale += abs(simpson)
            worst = max(worst, abs(summed - simpson) / scale)
            assert abs(summed - simpson) <= 16 * np.finfo(float).eps * scale, (trial, a, simpson, summed)
            for block in range(1, n_in - 3, max(1, (n_in - 4) // 3)):
                head = (a, d, wsum, bsum, n_in, block, dx, g_c, gf)
                after = _kernels._deviation_after(*head, gint, df, kap, *_one_mode(bsum))
                fast = _kernels._deviation_after(*head, gint_w, df, kap, *_one_mode(bsum))
                assert abs(fast - after) <= 16 * np.finfo(float).eps * scale, (trial, a, block, after, fast)
    assert worst > 0.0  # the two forms are computed differently (not the same code twice)


def test_a_row_carries_its_force_weights() -> None:
    """`Row` and `Row.regrid` write the weights of their own grid after ``gint`` in the array
    the kernels take (`Row.gint_kernel`), and `force` reads them: the same weights as
    `_fill_force_weights` computes from the row's profile."""
    rng = np.random.default_rng(3)
    n, k = 40, 1
    length, dx, df, gf, gint, g_c, gint_w = _grid(n, 8, True, rng)
    one = np.ones(k)
    row = _kernels.Row(
        dx=dx, g_c=g_c, gf=gf, gint=gint, df=df, reach=np.inf, wl=rng.normal(scale=1e-7, size=(n, k)),
        p=np.eye(k), p_inv=np.eye(k), lam=one.copy(), beta=one.copy(), rate=one.copy(),
        e_kelvin=one.copy(), steady=0.5 * one, e0=1e6, c_crit=0.1,
    )  # fmt: skip
    assert np.array_equal(row.gint_kernel, gint_w)
    assert row.kernel_args[11] is row.gint_kernel or np.shares_memory(row.kernel_args[11], row.gint_kernel)
    length2, dx2, df2, gf2, gint2, g_c2, gint_w2 = _grid(2 * n, 8, True, rng)
    grown = row.regrid(dx=dx2, g_c=g_c2, gf=gf2, gint=gint2, df=df2, reach=np.inf, wl=np.zeros((2 * n, k)))
    assert np.array_equal(grown.gint_kernel, gint_w2)
    a = 0.6 * length
    modes = row.kernel_args[18:22]  # p, p_inv, lam, beta
    wb = row.kernel_args[2]
    head = (a, 2e-6, row.wsum, row.bsum, dx, g_c, gf, gint_w, df)
    want = _kernels._force(*head, 1e6, row.kap, np.empty(0), wb, *modes)
    assert _kernels.force(row, a, 2e-6) == want
