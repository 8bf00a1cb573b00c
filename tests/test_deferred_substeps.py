"""A step of many substeps updates only the trial windows' union per accepted substep and the
other elements once at the step's end (issue 13, 0.4.0 `defer`): the same outputs as the
whole-row-per-substep loop it replaced (`advance_reference`, main's loop kept test-only) to
rounding, on steps where the edge races across many elements (K = 1, 2, 4; deep and shallow;
with and without a substep cap), and bit for bit on a step taken in one substep.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from advance_reference import advance_reference
from golden_tolerance import column_failures

from viscoadh_ros.core import _kernels
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator

CHAINS = {
    1: ((1e5,), (1e3,)),
    2: ((1e5, 3e5), (1e2, 1e4)),
    4: ((2e5, 2e5, 2e5, 2e5), (2e1, 2e2, 2e3, 2e4)),
}


def _model(k: int, elements: int, max_substep: float = 0.0):
    kelvin, viscosities = CHAINS[k]
    section = {
        "indenter": {"shape": "sphere", "radius": 1e-3},
        "material": {
            "glass_shear_modulus": 1.0e6,
            "kelvin_shear_moduli": list(kelvin),
            "kelvin_viscosities": list(viscosities),
        },
        "adhesion": {"work_of_adhesion": 0.05},
        "numerics": {"model": "time_stepped", "elements": elements, "max_substep": max_substep},
    }
    contact = SceneConfig.from_dict({"contacts": ["c"], "c": section}).contact("c")
    return ContactSimulator(contact)._model


def _history(amplitude: float, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """1 kHz: a fast press to ``amplitude`` and a pull well off the surface, four times."""
    t = np.arange(1, rows + 1) * 1e-3
    return t, amplitude * np.sin(2.0 * math.pi * t / (rows * 1e-3 / 4.0)) + 0.25 * amplitude


def _run(k: int, elements: int, amplitude: float, max_substep: float = 0.0, rows: int = 200):
    """Both loops from the same state at every step (the product's state carried on)."""
    model = _model(k, elements, max_substep)
    length = 6.0 * math.sqrt(1e-3 * amplitude)
    row = model._build_row(length, None)
    ref = model._build_row(length, None)
    times, depths = _history(amplitude, rows)
    a, d_prev, t_prev = 0.0, 0.0, 0.0
    outs, ref_outs, mems, ref_mems = [], [], [], []
    for ti, di in zip(times, depths, strict=True):
        wl, wb = row.wl.copy(), row.wb.copy()
        ref.set_memory(wl, wb)
        row.set_memory(wl, wb)
        status, out = _kernels.advance(
            row, a, d_prev, di, ti - t_prev, max_substep=max_substep, max_edge_move=row.dx
        )
        ref_status, ref_out = advance_reference(
            ref, a, d_prev, di, ti - t_prev, max_substep=max_substep, max_edge_move=ref.dx
        )
        assert status == ref_status == _kernels.STATUS_OK
        outs.append(out.copy())
        ref_outs.append(ref_out.copy())
        mems.append(np.concatenate([row.wl.ravel(), row.wb.ravel()]))
        ref_mems.append(np.concatenate([ref.wl.ravel(), ref.wb.ravel()]))
        a, d_prev, t_prev = float(out[_kernels.OUT_RADIUS]), float(di), float(ti)
    return np.array(outs), np.array(ref_outs), np.array(mems), np.array(ref_mems), row.wl.shape[1]


def _compare(outs, ref_outs, mems, ref_mems, k):
    codes = [_kernels.OUT_MOTION, _kernels.OUT_SUBSTEPS]
    assert np.array_equal(outs[:, codes], ref_outs[:, codes])
    gaps = {c: _kernels.OUT_RADIUS for c in (_kernels.OUT_GAP_OUTSIDE, _kernels.OUT_GAP_INSIDE)}
    assert column_failures(ref_outs, outs, scale_of=gaps) == []
    half = mems.shape[1] // 2
    for cut in (np.s_[:, :half], np.s_[:, half:]):
        assert column_failures(ref_mems[cut].ravel(), mems[cut].ravel()) == []


@pytest.mark.parametrize(
    ("k", "elements", "amplitude", "max_substep"),
    [
        (1, 400, 3e-5, 0.0),
        (1, 400, 4e-6, 0.0),
        (2, 300, 3e-5, 0.0),
        (2, 300, 4e-6, 0.0),
        (4, 256, 3e-5, 0.0),
        (4, 256, 4e-6, 0.0),
        (1, 400, 3e-5, 2.5e-4),
        (4, 256, 3e-5, 2.5e-4),
    ],
)
def test_many_substeps_match_the_whole_row_per_substep_loop(k, elements, amplitude, max_substep) -> None:
    """Every output and the memory within `golden_tolerance.RELATIVE` of each column's largest
    value (rounding: the deferred elements' one update over the step against one per
    substep, the block's force from sums), codes equal; and the scene must race: steps of
    many substeps, with the edge several elements inside the windows' union."""
    outs, ref_outs, mems, ref_mems, kk = _run(k, elements, amplitude, max_substep)
    assert kk == k
    substeps = ref_outs[:, _kernels.OUT_SUBSTEPS]
    assert np.count_nonzero(substeps >= 4) >= 5, substeps
    assert substeps.max() >= 8
    _compare(outs, ref_outs, mems, ref_mems, k)


def test_the_differences_are_rounding() -> None:
    """The largest difference of the force and the memory over a racing K = 1 run is at the
    rounding level (far below the golden tolerance the test above allows)."""
    outs, ref_outs, mems, ref_mems, _ = _run(1, 400, 3e-5)
    force = _kernels.OUT_FORCE
    scale = np.max(np.abs(ref_outs[:, force]))
    assert np.max(np.abs(outs[:, force] - ref_outs[:, force])) <= 1e-12 * scale
    assert np.max(np.abs(mems - ref_mems)) <= 1e-12 * np.max(np.abs(ref_mems))


def test_a_step_in_one_substep_is_bit_for_bit_the_old_loop() -> None:
    """Slow steps (one substep each: nothing deferred past the step) equal the old loop exactly."""
    model = _model(1, 200)
    length = 6.0 * math.sqrt(1e-3 * 2e-5)
    row = model._build_row(length, None)
    ref = model._build_row(length, None)
    a, d_prev = 0.0, 0.0
    singles = 0
    for i in range(1, 301):
        d = 2e-5 * math.sin(math.pi * i / 300.0)
        ref.set_memory(row.wl.copy(), row.wb.copy())
        row.set_memory(row.wl.copy(), row.wb.copy())
        _, out = _kernels.advance(row, a, d_prev, d, 1e-4, max_substep=0.0, max_edge_move=row.dx)
        _, ref_out = advance_reference(ref, a, d_prev, d, 1e-4, max_substep=0.0, max_edge_move=ref.dx)
        if ref_out[_kernels.OUT_SUBSTEPS] == 1:
            singles += 1
            # (equal_nan: the let-go depth slot is NaN where the contact did not let go)
            assert np.array_equal(out, ref_out, equal_nan=True)
            assert np.array_equal(row.wl, ref.wl) and np.array_equal(row.wb, ref.wb)
        a, d_prev = float(out[_kernels.OUT_RADIUS]), d
    assert singles >= 200
