"""The compiled step is bit-for-bit the 0.2.0 kernel's (issue 13: the substep trials, the
journal and the fixed per-step costs were cut without changing one output).

`tests/data/kernel_golden.npz` holds the outputs of the scenes in `tests/kernel_golden.py`
(batch, row by row, force control, and the kernel on rows with random memory) as the kernel
before those changes computed them; every float must be equal, not close.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from kernel_golden import compute

GOLDEN = Path(__file__).parent / "data" / "kernel_golden.npz"


@pytest.fixture(scope="module")
def outputs() -> dict[str, np.ndarray]:
    return compute()


def test_every_scene_and_random_row_equals_the_golden_outputs_bit_for_bit(outputs) -> None:
    golden = np.load(GOLDEN)
    assert sorted(golden.files) == sorted(outputs)
    differing = []
    for key in golden.files:
        want, got = golden[key], outputs[key]
        if want.shape != got.shape or not np.array_equal(want, got, equal_nan=True):
            worst = np.nanmax(np.abs(want - got)) if want.shape == got.shape else "shape"
            differing.append((key, worst))
    assert not differing, differing


def test_the_golden_scenes_cover_what_the_windowed_trials_must_keep(outputs) -> None:
    """The scenes exercise snap-in, pull-off, rejected substeps (many substeps in a row) and
    memory on rough rows, so that equality above says something."""
    substeps = max(float(np.max(v)) for k, v in outputs.items() if k.endswith("/substeps"))
    assert substeps >= 50
    radius = outputs["k1_fast_edge/batch_contact_radius"]
    assert np.any((radius[1:] > 0) & (radius[:-1] <= 0)) and np.any((radius[1:] <= 0) & (radius[:-1] > 0))
    assert np.any(outputs["k1_jumps_dt0/substeps"] == 0)  # zero-length rows
