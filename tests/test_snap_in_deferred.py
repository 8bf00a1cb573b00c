"""A snap-in row's substeps are deferred like any racing row's (issue 13, every step bounded;
0.6.0 `snapN`): the elements a snap-in step updates are counted, not timed.

From no contact every substep trial updates the whole row (`_first_touch` reads all of it), and
so does the jump substep that crosses the touch. The deferral of `_kernels._advance_from` used
to count its union of trial windows from the step's start, so after those whole-row substeps
every later substep of the step (the edge racing on after the jump: one substep per
``max_edge_cells`` crossed, ~N/16 of them at N elements on the tolerance mode's K = 2 scene)
updated all N elements: O(N^2 / 16) per snap-in row. It now starts the deferral again after a
substep that left every element current, and after a catch-up of every deferred element once
the union spans more than `_kernels._DEFER_SPAN` sqrt(N) elements. The count: `_advance_from`'s Python body
(``py_func``) run on the compiled per-element kernels, the element ranges its calls to
`_update_range` and `_catch_up` span summed; the same outputs as the compiled step to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest

from viscoadh_ros.core import _kernels
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.simulator import ContactSimulator

#: The outside tester's K = 2 body (benchmarks/outside_test_0.5.0/core_first_step_cost.py).
K2 = {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4, 1e5], "kelvin_viscosities": [1.05e5, 1e6]}
K1 = {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4], "kelvin_viscosities": [1.05e5]}


def _model(material: dict, elements: int):
    section = {
        "indenter": {"shape": "sphere", "radius": 5e-3},
        "material": dict(material, poisson_ratio=0.5),
        "adhesion": {"work_of_adhesion": 0.05, "interaction_range": 1e-9},
        "numerics": {"preset": "fast", "model": "time_stepped", "elements": elements},
    }
    contact = SceneConfig.from_dict({"contacts": ["c"], "c": section}).contact("c")
    return ContactSimulator(contact)._model


def _counted_step(row: _kernels.Row, a: float, d0: float, d1: float, dt: float, max_edge_move: float):
    """`_kernels.advance` through `_advance_from`'s Python body (`_advance_body`), its element
    updates counted: ``(status, out, updates)``."""
    updates = [0]
    saved = {name: getattr(_kernels, name) for name in ("_update_range", "_catch_up")}

    def update_range(*args):
        updates[0] += max(args[6] - args[5], 0)
        return saved["_update_range"](*args)

    def catch_up(*args):
        updates[0] += max(args[6] - args[5], 0)
        return saved["_catch_up"](*args)

    args = row.kernel_args
    wl, wsum, wb, bsum = args[0:4]
    dx, g_c, gf, gint, df, e0, kap = args[8], args[9], args[10], args[11], args[14], args[15], args[23]
    modes = args[18:22]  # p, p_inv, lam, beta
    force_prev = _kernels._force(a, d0, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, np.empty(0), wb, *modes)
    _kernels._update_range = update_range
    _kernels._catch_up = catch_up
    try:
        # `_advance_from`'s body (`_advance_body`, 0.11.0: inlined where it is compiled).
        status = _kernels._advance_body.py_func(
            tuple(args), a, d0, d1, dt, 0.0, max_edge_move, force_prev, wl[:0], wb[:0]
        )
    finally:
        for name, kernel in saved.items():
            setattr(_kernels, name, kernel)
    return status, row.out.copy(), updates[0]


@pytest.mark.parametrize(("material", "elements"), [(K2, 1024), (K1, 2048), (K2, 4096)])
def test_a_snap_in_row_updates_each_element_a_bounded_number_of_times(material, elements) -> None:
    """From rest to 1 um in 1 ms (the first step of the outside tester's ramp: snap-in, then
    the edge races across ~N/8 elements in ~N/16 substeps): fewer than 12 N element updates
    at every N here (a few whole-row substeps before and at the touch, per substep the trial
    windows and the union of the windows since the deferral's origin, which a catch-up keeps
    within `_kernels._DEFER_SPAN` sqrt(N), one update of the rest at the end). Every substep
    after the touch updating the whole row made ~N^2 / 16 (64 N at N = 1024); the union
    growing with the edge's travel ~N^2 / 128 (16 N at N = 2048). The compiled step gives
    the same outputs and memory to rounding."""
    model = _model(material, elements)
    template = model._template
    max_edge_move = model._max_edge_cells * template.dx
    row = template.with_memory(template.wl.copy(), template.wb.copy())
    status, out, updates = _counted_step(row, 0.0, 0.0, 1e-6, 1e-3, max_edge_move)
    assert status == _kernels.STATUS_OK
    n = row.wl.shape[0]
    substeps = int(out[_kernels.OUT_SUBSTEPS])
    assert out[_kernels.OUT_RADIUS] > 0.0
    assert substeps >= n // 32, substeps  # the edge raced: the case the deferral is for
    assert updates < 12 * n, (updates, n, substeps)

    compiled = template.with_memory(template.wl.copy(), template.wb.copy())
    compiled_status, compiled_out = _kernels.advance(
        compiled, 0.0, 0.0, 1e-6, 1e-3, max_substep=0.0, max_edge_move=max_edge_move
    )
    assert compiled_status == status
    assert compiled_out[_kernels.OUT_SUBSTEPS] == substeps
    assert compiled_out[_kernels.OUT_MOTION] == out[_kernels.OUT_MOTION]
    for slot in (_kernels.OUT_RADIUS, _kernels.OUT_FORCE, _kernels.OUT_WORK, _kernels.OUT_DISSIPATED):
        assert compiled_out[slot] == pytest.approx(out[slot], rel=1e-12, abs=0.0)
    np.testing.assert_allclose(compiled.wl, row.wl, rtol=0.0, atol=1e-12 * np.max(np.abs(row.wl)))
    np.testing.assert_allclose(compiled.wb, row.wb, rtol=0.0, atol=1e-12 * np.max(np.abs(row.wb)))
