"""At K = 1 a row's ``wsum`` and ``bsum`` are ``wl`` and ``wb`` themselves (0.10.0,
`_kernels._state_layout`): the K = 1 update stores each element's state once, and the one slot
holds the sum's value (``0.0 + x``). The kernels give the same outputs with the sums aliased
(a row's own views) as with separate sum arrays (any caller's), bit for bit; the memory differs
at most in the sign of a zero (the slot holds 0.0 where a separate ``wl`` kept -0.0)."""

from __future__ import annotations

import pickle

import numpy as np

from tests.scenes import one_contact
from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator


def _shares(a: np.ndarray, b: np.ndarray) -> bool:
    return a.ctypes.data == b.ctypes.data and a.size == b.size


def _row(kelvin: int) -> _kernels.Row:
    contact = one_contact(
        {"shape": "sphere", "radius": 0.01},
        kelvin=[5e4] * kelvin,
        viscosities=[1e5 * (k + 1) for k in range(kelvin)],
        work=0.05,
        numerics={"elements": 256, "model": "time_stepped"},
    )
    sim = ContactSimulator(contact)
    t = 1e-3 * np.arange(1, 201)
    sim.step_depths(t, 3e-5 * np.sin(2.0 * np.pi * t / 0.3))
    return sim._model.row


def test_the_sums_are_the_memory_at_one_kelvin_element_only() -> None:
    row = _row(1)
    assert _shares(row.wsum, row.wl) and _shares(row.bsum, row.wb)
    clone = row.with_memory(*row.memory())
    assert _shares(clone.wsum, clone.wl) and _shares(clone.bsum, clone.wb)
    loaded = pickle.loads(pickle.dumps(row))
    assert _shares(loaded.wsum, loaded.wl) and _shares(loaded.bsum, loaded.wb)
    wl, wb = row.memory()
    grown = row.regrid(
        dx=row.dx, g_c=row.g_c.copy(), gf=row.gf.copy(), gint=row.gint.copy(), df=row.df,
        reach=row.reach, wl=wl, wb=wb,
    )  # fmt: skip
    assert _shares(grown.wsum, grown.wl) and _shares(grown.bsum, grown.wb)
    assert grown._state.tobytes() == row.with_memory(wl, wb)._state.tobytes()
    two = _row(2)
    assert not np.shares_memory(two.wsum, two.wl)


def test_aliased_and_separate_sums_step_the_same() -> None:
    """One row stepped with its own (aliased) views and with separate sum arrays: the same
    outputs every step, bit for bit, and the same memory up to the sign of a zero."""
    row = _row(1)
    wl0, wb0 = row.memory()
    wl0[::7] = -0.0  # signed zeros in the memory: the slot holds 0.0, a separate wl -0.0
    wb0[::11] = -0.0
    radius = row.out[_kernels.OUT_RADIUS]
    aliased = row.with_memory(wl0, wb0)
    separate = row.with_memory(wl0, wb0)
    args = list(separate.kernel_args)
    args[0] = separate.wl.copy()
    args[2] = separate.wb.copy()
    args[0][::7] = -0.0
    args[2][::11] = -0.0
    args[1] = args[0].sum(axis=1)
    args[3] = args[2].sum(axis=1)
    assert not np.shares_memory(args[1], args[0])
    t = 1e-3 * np.arange(0, 301)
    depth = 3e-5 * np.sin(2.0 * np.pi * (t + 0.2) / 0.3)
    a_aliased = a_separate = radius
    move = 16 * row.dx
    for s in range(1, t.size):
        status = _kernels._advance(*aliased.kernel_args, a_aliased, depth[s - 1], depth[s], 1e-3, 0.0, move)
        want = _kernels._advance(*args, a_separate, depth[s - 1], depth[s], 1e-3, 0.0, move)
        assert status == want == _kernels.STATUS_OK
        assert aliased.out.tobytes() == args[-1].tobytes(), s
        a_aliased = aliased.out[_kernels.OUT_RADIUS]
        a_separate = args[-1][_kernels.OUT_RADIUS]
        assert aliased.wsum.tobytes() == args[1].tobytes(), s
        assert aliased.bsum.tobytes() == args[3].tobytes(), s
        assert np.array_equal(aliased.wl, args[0]) and np.array_equal(aliased.wb, args[2]), s
