"""`_kernels._psi`'s series stops once its terms no longer move its sums (0.10.0 `race`): the
same bits as all 24 terms, which this test sums in plain Python (IEEE doubles, the same
operations in the same order) over the series' whole range, including the substep lengths of
a racing edge (x = lam h ~ 1e-6) where it now takes 4 terms."""

from __future__ import annotations

import numpy as np

from viscoadh_ros.core import _kernels


def _full_series(x: float) -> tuple[float, float, float]:
    ee = ef = ff = 0.0
    power = two = f1 = 1.0
    for m in range(24):
        f1 *= m + 1
        f2 = f1 * (m + 2)
        f3 = f2 * (m + 3)
        ee += power * two / f1
        ef += power * (2.0 * two - 1.0) / f2
        ff += power * (4.0 * two - 2.0) / f3
        power *= -x
        two *= 2.0
    return ee, ef, ff


def test_psi_series_bit_for_bit_with_all_terms() -> None:
    rng = np.random.default_rng(13)
    xs = np.concatenate(
        [
            [0.0, -0.0, 5e-324, 1e-308, 1e-17, 1e-8, 1e-6, 0.125, 0.25, np.nextafter(0.5, 0.0)],
            rng.uniform(0.0, 0.5, 3000),
            10.0 ** rng.uniform(-300.0, np.log10(0.5), 3000),
            10.0 ** rng.uniform(-10.0, -4.0, 3000),
        ]
    )
    for x in xs:
        got = _kernels._psi(float(x))
        want = _full_series(float(x))
        assert np.array(got).view(np.int64).tolist() == np.array(want).view(np.int64).tolist(), x
