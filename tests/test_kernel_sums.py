"""The K = 1 update's running sums in four lanes (0.4.0, `elem`, `_kernels._sum_losses`)
against the in-order loop they replaced (kept here as a test-only reference): the losses' sum
moves by rounding only (a few N eps of it, still >= 0), the memory peak not at all (a maximum
is the same in any order). tests/golden_tolerance.py says why that rounding is allowed;
tests/test_kernel_golden.py compares whole scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from viscoadh_ros.core import _kernels

EPS = np.finfo(float).eps


def _in_order_losses(diss, wsum, lo, hi, total, peak):
    """The 0.3.0 loop of `_update_range_one`: one chain in index order."""
    for i in range(lo, hi):
        total += diss[i]
        peak = max(peak, abs(wsum[i]))
    return total, peak


@pytest.mark.parametrize("seed", range(6))
def test_the_losses_and_the_peak_in_four_lanes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(200):
        n = int(rng.integers(1, 80))
        diss = rng.exponential(1e-9, n) * (rng.uniform(size=n) < 0.9)
        wsum = rng.normal(0.0, 1e-6, n)
        lo = int(rng.integers(0, n))
        hi = int(rng.integers(lo, n + 1))
        total0, peak0 = float(rng.exponential(1e-8)), float(rng.exponential(1e-7))
        total, peak = _kernels._sum_losses(diss, wsum, lo, hi, total0, peak0)
        want_total, want_peak = _in_order_losses(diss, wsum, lo, hi, total0, peak0)
        assert peak == want_peak  # exact: a maximum in any order
        exact = math.fsum([total0, *diss[lo:hi]])
        assert total >= 0.0
        assert abs(total - exact) <= 2.0 * (hi - lo + 2) * EPS * exact
        assert abs(want_total - exact) <= 2.0 * (hi - lo + 2) * EPS * exact


def _scalar_lanes(diss, wsum, lo, hi, total, peak):
    """The 0.7.0 `_sum_losses`: four scalar lanes (element lo + 4 j + r in lane r, the rest in
    lane 0), as the vector lanes of `_kernels._four_lanes` (0.10.0) must give them."""
    sums = [0.0] * 4
    peaks = [peak] * 4
    i = lo
    while i + 4 <= hi:
        for r in range(4):
            sums[r] += diss[i + r]
            peaks[r] = max(peaks[r], abs(wsum[i + r]))
        i += 4
    while i < hi:
        sums[0] += diss[i]
        peaks[0] = max(peaks[0], abs(wsum[i]))
        i += 1
    return total + ((sums[0] + sums[1]) + (sums[2] + sums[3])), max(
        max(peaks[0], peaks[1]), max(peaks[2], peaks[3])
    )


@pytest.mark.parametrize("seed", range(3))
def test_the_vector_lanes_are_the_scalar_lanes_bit_for_bit(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    for _ in range(300):
        n = int(rng.integers(1, 70))
        diss = rng.exponential(1e-9, n) * (rng.uniform(size=n) < 0.9)
        diss[rng.uniform(size=n) < 0.05] = -0.0
        wsum = rng.normal(0.0, 1e-6, n)
        wsum[rng.uniform(size=n) < 0.05] = -0.0
        lo = int(rng.integers(0, n + 1))
        hi = int(rng.integers(lo, n + 1))
        total0, peak0 = float(rng.exponential(1e-8)), float(rng.exponential(1e-7)) * (rng.uniform() < 0.8)
        got = _kernels._sum_losses(diss, wsum, lo, hi, total0, peak0)
        want = _scalar_lanes(diss, wsum, lo, hi, total0, peak0)
        assert np.array(got).tobytes() == np.array(want).tobytes(), (lo, hi, got, want)


def test_an_elastic_row_keeps_no_memory_so_its_peak_is_not_scanned() -> None:
    """K = 0 (no Kelvin element): `_advance_from` reports the memory peak as 0 without the O(N)
    scan of ``wsum`` (0.7.0). That is only right if nothing ever writes a non-zero ``wsum`` on
    an elastic row: press, snap in, pull off and touch again, per call and in batch, at an
    element count where the edge races (several substeps per row)."""
    from tests.scenes import one_contact
    from viscoadh_ros.core.simulator import ContactSimulator

    contact = one_contact(
        {"shape": "sphere", "radius": 0.01},
        work=0.05,
        numerics={"elements": 2048, "model": "time_stepped"},
    )
    t = 1e-3 * np.arange(1, 501)
    depth = 4e-5 * np.sin(2.0 * np.pi * t / 0.4) - 5e-6  # ends pressed, after a pull-off
    per_call = ContactSimulator(contact)
    for time, d in zip(t, depth, strict=True):
        output = per_call.step(float(time), depth=float(d))
        assert output.energy_dissipated >= 0.0
    batch = ContactSimulator(contact)
    rows = batch.step_depths(t, depth)
    radius = rows["contact_radius"]
    assert np.any((radius[:-1] > 0.0) & (radius[1:] == 0.0)) and radius[-1] > 0.0
    for sim in (per_call, batch):
        row = sim._model.row
        assert row.wl.shape[1] == 0
        assert not np.any(row.wsum) and not np.any(row.bsum)
        assert row.out[_kernels.OUT_MEMORY] == 0.0
