"""The depth-control step path gives bit-equal outputs to the 0.2.0 path (golden from main).

`step_scenarios` records varied sequences (snap-in, pull-off, out of contact with memory,
depth jumps at one time, domain growth, refused calls mid-way, reset, snapshot/restore into the
same and another simulator, `advance`, `step_depths`); the golden was written from main at
fecbb5f before the lean step path and the packed kernel call.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from step_scenarios import depth_scale, run_scene, scenes

GOLDEN = Path(__file__).resolve().parent / "data" / "step_golden.npz"


@pytest.mark.parametrize("name", sorted(scenes()))
def test_step_path_is_bit_equal_to_the_golden(name: str) -> None:
    expected = np.load(GOLDEN)[name]
    got = run_scene(scenes()[name], depth_scale(name))
    assert got.shape == expected.shape
    bad = np.flatnonzero(np.any(got.view(np.uint64) != expected.view(np.uint64), axis=1))
    assert bad.size == 0, f"{name}: first differing row {bad[0]}: {got[bad[0]]} != {expected[bad[0]]}"
