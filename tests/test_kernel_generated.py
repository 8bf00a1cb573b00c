"""The written-out K = 2, 3, 4 Kelvin update (0.5.0, `scripts/gen_kelvin_update.py`): the block in
`_kernels.py` is the generator's output, and it computes the same bits as the general loop
(`_update_range_k` with a runtime K) on random rows, contact and free elements, any range; the
losses' sum (four lanes since 0.7.0, `_sum_losses`) to rounding."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from viscoadh_ros.core import _kernels

ROOT = Path(__file__).resolve().parent.parent


def test_the_generated_block_is_the_generators_output() -> None:
    script = ROOT / "scripts" / "gen_kelvin_update.py"
    assert subprocess.run([sys.executable, str(script), "--check"], check=False).returncode == 0


def _row(rng: np.random.Generator, n: int, k: int):
    wl = rng.normal(scale=1e-6, size=(n, k))
    wl[rng.random((n, k)) < 0.1] = -0.0  # signed zeros: `0.0 +` must turn them the same way
    wb = rng.random((n, k))
    wb[rng.random((n, k)) < 0.05] = -0.0
    coef = _kernels.coefficient_workspace(k)
    lam = rng.uniform(1.0, 1e4, k)
    rate = rng.uniform(1.0, 1e3, k)
    _kernels._substep_coefficients(lam, rate, 1e-3, coef)
    return {
        "wl": wl,
        "wb": wb,
        "g_c": np.sort(rng.random(n)) * 1e-5,
        "p": rng.normal(size=(k, k)),
        "p_inv": rng.normal(size=(k, k)),
        "lam": lam,
        "beta": rng.uniform(0.1, 10.0, k),
        "e_kelvin": rng.uniform(1e4, 1e6, k),
        "coef": coef,
    }


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_written_out_update_equals_the_general_loop_bit_for_bit(k: int) -> None:
    """K = 1 too: `_update_range_one` (its own loops, 0.10.0 drops operations that cannot change
    a bit) against the same general loop, signed zeros included."""
    rng = np.random.default_rng(k)
    n = 37
    for trial in range(20):
        row = _row(rng, n, k)
        lo = int(rng.integers(0, n))
        hi = int(rng.integers(lo, n + 1))
        n_in = int(rng.integers(0, n + 1))
        d0, d1 = rng.normal(scale=1e-5, size=2)
        results = []
        for general in (False, True):
            wl, wb = row["wl"].copy(), row["wb"].copy()
            wsum, bsum = wl.sum(axis=1), wb.sum(axis=1)
            diss = np.full(n, np.nan)
            args = (wl, wsum, wb, bsum, diss, lo, hi, n_in, d0, d1, (d1 - d0) / 1e-3, row["g_c"])
            args += (row["p"], row["p_inv"], row["lam"], row["beta"], row["coef"], row["e_kelvin"], 2e-7)
            if general:
                total, peak = _kernels._update_range_k(*args, 0.25, 1e-9, k)
            else:
                total, peak = _kernels._update_range(*args, 0.25, 1e-9)
            results.append((wl, wb, wsum, bsum, diss, np.array([total, peak])))
        *state, sums = results[0]
        *want_state, want_sums = results[1]
        for got, want in zip(state, want_state, strict=True):
            assert got.tobytes() == want.tobytes(), (trial, lo, hi, n_in)
        # The peak exactly (a maximum in any order); the losses' sum in four lanes since 0.7.0
        # (`_sum_losses`, as K = 1's): rounded otherwise, by a few eps of it (non-negative terms).
        assert sums[1] == want_sums[1]
        assert abs(sums[0] - want_sums[0]) <= 4 * n * np.finfo(float).eps * want_sums[0], (
            trial,
            sums,
            want_sums,
        )


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_signed_zeros_everywhere_give_the_general_loops_bits(k: int) -> None:
    """Where every term is a signed zero (no memory, depth -0.0 or 0.0 at a zero profile), the
    written-out updates, which leave out ``0.0 +`` where it cannot change an output (0.10.0),
    give the general loop's bits: state, losses, peak."""
    rng = np.random.default_rng(40 + k)
    n = 24
    for trial in range(12):
        row = _row(rng, n, k)
        row["wl"] = np.where(rng.random((n, k)) < 0.5, -0.0, 0.0)
        row["wb"] = np.where(rng.random((n, k)) < 0.5, -0.0, 0.0)
        row["g_c"] = np.zeros(n)
        row["p"] = np.where(rng.random((k, k)) < 0.5, -1.0, 1.0) * rng.uniform(0.5, 2.0, (k, k))
        depth = -0.0 if trial % 2 else 0.0
        n_in = int(rng.integers(0, n + 1))
        results = []
        for general in (False, True):
            wl, wb = row["wl"].copy(), row["wb"].copy()
            wsum, bsum = wl.sum(axis=1), wb.sum(axis=1)
            diss = np.full(n, np.nan)
            args = (wl, wsum, wb, bsum, diss, 0, n, n_in, depth, depth, 0.0, row["g_c"])
            args += (row["p"], row["p_inv"], row["lam"], row["beta"], row["coef"], row["e_kelvin"], 2e-7)
            if general:
                total, peak = _kernels._update_range_k(*args, 0.0, 0.0, k)
            else:
                total, peak = _kernels._update_range(*args, 0.0, 0.0)
            results.append((wl, wb, wsum, bsum, diss, np.array([total, peak])))
        for got, want in zip(results[0], results[1], strict=True):
            assert got.tobytes() == want.tobytes(), (trial, n_in)
