"""The snap-in out of contact is located in time directly (issue 13, every step bounded).

Out of contact (radius 0) a substep trial that touches with a jump of the edge used to be
halved down to ``JUMP_RESOLUTION dt`` (about 14 whole-row trials); now `_advance_from` finds
the touch time of the touching point in closed form (`_kernels._touch_time`: each Kelvin
element creeps back freely, so the memory at a point is a sum of decaying exponentials),
takes one substep to half a jump substep before it and crosses the touch in one substep of
``JUMP_RESOLUTION dt``. These tests pin that guarantee against the row updated for real.
"""

from __future__ import annotations

import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator

CHAINS = {
    "k0": ((), ()),
    "k1": ((1e5,), (1e3,)),
    "k3": ((2e5, 5e4, 1e6), (1e2, 1e4, 1e1)),
}


def _row(kelvin: tuple, viscosities: tuple, seed: int, *, smooth: bool) -> _kernels.Row:
    """An out-of-contact row with random memory pressed into the surface (w > 0 on average:
    the surface is still indented where a contact was, the ring of a re-contact)."""
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        kelvin=kelvin,
        viscosities=viscosities,
        work=0.05,
        numerics={"model": "time_stepped", "elements": 32},
    )
    sim = ContactSimulator(contact)
    rng = np.random.default_rng(seed)
    n, k = 32, len(kelvin)
    x = np.linspace(0.0, 1.0, n)[:, None]
    if smooth:
        memory = 2e-6 * (1.0 + rng.normal(size=(1, k)) * x + rng.normal(size=(1, k)) * x**2)
    else:
        memory = 2e-6 * (1.0 + 0.5 * rng.normal(size=(n, k)))
    unit = rng.uniform(size=(n, k)) * sim._model.steady
    return sim._model._build_row(2e-4, memory, unit)


def _gap_after(row: _kernels.Row, j: int, s: float, d_of) -> float:
    """``d - g - w`` at fine point j after the row crept back freely for s (updated for real)."""
    probe = row.with_memory(row.wl.copy(), row.wb.copy())
    _kernels.kelvin_update(probe, 0, 0.0, 0.0, s)
    x = j * row.df
    return d_of(s) - float(row.gf[j]) - _kernels.memory_at(probe, x, 0.0, interior=False)


def _touch(row: _kernels.Row, d0: float, d1: float, dt: float) -> int:
    """The first touching fine point at the end of the step, -1 if none."""
    probe = row.with_memory(row.wl.copy(), row.wb.copy())
    _kernels.kelvin_update(probe, 0, d0, d1, dt)
    return int(
        _kernels._first_touch(
            d1, probe.wsum, probe.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.reach
        )
    )


@pytest.mark.parametrize("name", sorted(CHAINS))
@pytest.mark.parametrize("smooth", [False, True])
def test_the_touch_time_brackets_the_touch_of_the_row_updated_for_real(name: str, smooth: bool) -> None:
    """`_touch_time` ends a bracket of at most 1e-3 JUMP_RESOLUTION dt across which the gap of
    the touching point, on the row crept back for real (`kelvin_update`), changes sign: the
    closed form is the row's own memory, not an approximation of it."""
    kelvin, viscosities = CHAINS[name]
    checked = 0
    for seed in range(16):
        row = _row(kelvin, viscosities, seed, smooth=smooth)
        rng = np.random.default_rng(100 + seed)
        dt = float(rng.choice([1e-4, 1e-3, 1e-2]))
        d0 = -float(rng.uniform(0.5e-6, 6e-6))
        d1 = float(rng.uniform(0.0, 6e-6))
        j = _touch(row, d0, d1, dt)
        if j < 0:
            continue
        s = _kernels._touch_time(
            j, 0.0, dt, dt, d0, d1, row.wl, row.wb, row.dx, row.g_c, row.gf, row.df, row.rate, np.empty(3)
        )
        assert 0.0 < s <= dt
        width = 1e-3 * _kernels.JUMP_RESOLUTION * dt

        def d_of(t: float, d0: float = d0, d1: float = d1, dt: float = dt) -> float:
            return d0 + (d1 - d0) * (t / dt)

        scale = 1e-12 * (abs(d0) + abs(d1) + float(np.abs(row.wsum).max()) + abs(float(row.gf[j])))
        assert _gap_after(row, j, s, d_of) >= -scale
        assert _gap_after(row, j, max(s - width, 0.0), d_of) < scale
        checked += 1
    assert checked >= 4


def _snap_in_row(kelvin: tuple, viscosities: tuple) -> tuple[_kernels.Row, float]:
    """A default-like contact out of contact with a crept memory left by a press (a row of the
    simulator after a press and a pull-off) and the depth it ended at."""
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        kelvin=kelvin,
        viscosities=viscosities,
        work=0.05,
        numerics={"model": "time_stepped", "preset": "fast"},
    )
    sim = ContactSimulator(contact)
    t = np.linspace(1e-3, 0.3, 300)
    d = np.where(t < 0.2, 1.2e-5 * np.sin(np.pi * t / 0.2), -3e-5 * (t - 0.2) / 0.1) - 2e-6
    for ti, di in zip(t, d, strict=True):
        sim.step(float(ti), depth=float(di))
    model = sim._model
    assert model.radius == 0.0
    return model.row, float(d[-1])


@pytest.mark.parametrize("name", ["k1", "k3"])
def test_a_snap_in_step_crosses_the_touch_in_one_jump_substep(name: str) -> None:
    """One `advance` over a step that snaps in equals the same step cut by hand at the touch
    time found by bisection on the row updated for real: no contact up to half a jump
    substep before it, the jump substep of ``JUMP_RESOLUTION dt`` (located without the motion
    limit), then the rest of the step. The cut points agree to the touch bracket (1e-3 of a
    jump substep), so the outputs agree to far below the jump's own resolution."""
    kelvin, viscosities = CHAINS[name]
    row, d_end = _snap_in_row(kelvin, viscosities)
    dt = 1e-3
    d0 = d_end
    assert _touch(row, d0, d0, 0.0) < 0
    # The first depth, in steps of 1 um, that the surface reaches within the step.
    d1 = next(d0 + 1e-6 * k for k in range(1, 60) if _touch(row, d0, d0 + 1e-6 * k, dt) >= 0)
    h_min = _kernels.JUMP_RESOLUTION * dt

    def d_of(t: float) -> float:
        return d0 + (d1 - d0) * (t / dt)

    # The touch time of the whole row, by bisection on rows updated for real.
    lo, hi = 0.0, dt
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        probe = row.with_memory(row.wl.copy(), row.wb.copy())
        if _touch(probe, d0, d_of(mid), mid) >= 0:
            hi = mid
        else:
            lo = mid
    touch = hi
    assert h_min < touch < dt - h_min

    whole = row.with_memory(row.wl.copy(), row.wb.copy())
    move = whole.dx
    status, out = _kernels.advance(whole, 0.0, d0, d1, dt, max_substep=0.0, max_edge_move=move)
    assert status == _kernels.STATUS_OK and out[_kernels.OUT_RADIUS] > move
    got = out.copy()

    cut = row.with_memory(row.wl.copy(), row.wb.copy())
    t1, t2 = touch - 0.5 * h_min, touch + 0.5 * h_min
    status, out = _kernels.advance(cut, 0.0, d0, d_of(t1), t1, max_substep=0.0, max_edge_move=move)
    assert status == _kernels.STATUS_OK and out[_kernels.OUT_RADIUS] == 0.0
    work = out[_kernels.OUT_WORK]
    status, out = _kernels.advance(cut, 0.0, d_of(t1), d_of(t2), t2 - t1, max_substep=0.0, max_edge_move=1.0)
    assert status == _kernels.STATUS_OK and out[_kernels.OUT_RADIUS] > move
    work += out[_kernels.OUT_WORK]
    radius = out[_kernels.OUT_RADIUS]
    status, out = _kernels.advance(cut, radius, d_of(t2), d1, dt - t2, max_substep=0.0, max_edge_move=move)
    assert status == _kernels.STATUS_OK
    work += out[_kernels.OUT_WORK]

    # Both cut the step within 1e-3 h_min of each other: outputs within 1e-6 of their size.
    assert got[_kernels.OUT_SUBSTEPS] <= out[_kernels.OUT_SUBSTEPS] + 2
    assert got[_kernels.OUT_RADIUS] == pytest.approx(out[_kernels.OUT_RADIUS], rel=1e-6)
    assert got[_kernels.OUT_FORCE] == pytest.approx(out[_kernels.OUT_FORCE], rel=1e-6)
    work_scale = 1e-6 * abs(got[_kernels.OUT_FORCE]) * (d1 - d0)
    assert got[_kernels.OUT_WORK] == pytest.approx(work, rel=1e-6, abs=work_scale)
    wl_scale = 1e-6 * float(np.abs(cut.wl).max(initial=0.0))
    np.testing.assert_allclose(whole.wl, cut.wl, rtol=1e-6, atol=wl_scale)
