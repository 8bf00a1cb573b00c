"""Cost of calling a numba kernel from Python by the way its arguments are passed (issue 13).

    .venv/bin/python benchmarks/dispatch_options.py

Every option calls a compiled function that does (almost) nothing, so the figure is the
dispatch alone: numba's type check and unboxing of each argument, and for the packed options
the making of the kernel's array views inside the call. Interleaved, median of repeats, ns per
call; the row is the default-like scene's (N = 160, K = 1).
"""

from __future__ import annotations

import numba
import numpy as np

from viscoadh_ros.bench.timing import interleaved_medians
from viscoadh_ros.core import _kernels
from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.core.simulator import ContactSimulator

CALLS = 2000


@numba.njit(nogil=True)
def _args32(wl, wsum, wb, bsum, scratch, scratch_b, diss, coef, dx, g_c, gf, gint, gmin, gmax, df, e0, c_crit,
            reach, p, p_inv, lam, beta, rate, kap, e_kelvin, out, a, d0, d1, dt, ms, me):  # fmt: skip
    out[0] = a + wl.shape[0]
    return 0


@numba.njit(nogil=True)
def _tuple(args, a, d0, d1, dt, ms, me):
    args[-1][0] = a + args[0].shape[0]
    return 0


@numba.njit(nogil=True)
def _arrays_and_scalar_array(wl, wsum, wb, bsum, scratch, scratch_b, diss, coef, g_c, gf, gint, gmin, gmax, p,
                             p_inv, lam, beta, rate, e_kelvin, out, scalars):  # fmt: skip
    out[0] = scalars[0]
    return 0


@numba.njit(nogil=True)
def _two_buffers_scalar_array(state, const, scalars):
    state[0] = scalars[0] + const[0]
    return 0


@numba.njit(nogil=True)
def _two_buffers(state, const, journal, a, d0, d1, dt, ms, me):
    state[0] = a + const[0]
    return 0


@numba.njit(nogil=True)
def _two_buffers_sliced_views(state, const, journal, a, d0, d1, dt, ms, me):
    # The same views as `_kernels._unpack`, made by slicing and reshaping the buffers.
    n, k, m, blocks = int(const[0]), int(const[1]), int(const[2]), int(const[3])
    nk = n * k
    views = []
    o = 0
    for size in (nk, n, nk, n, nk, nk, n, _kernels.OUT_SIZE, nk, nk):
        views.append(state[o : o + size])
        o += size
    q = _kernels.PACK_HEADER
    for size in (n, m, m, blocks, blocks, k * k, k * k, k, k, k, k):
        views.append(const[q : q + size])
        q += size
    wl = views[0].reshape((n, k))
    wb = views[2].reshape((n, k))
    return wl.shape[0] + wb.shape[0] + len(views)


@numba.njit(nogil=True)
def _two_buffers_unpacked(state, const, journal, a, d0, d1, dt, ms, me):
    args, txn, txn_b = _kernels._unpack(state, const)
    return args[0].shape[0] + txn.shape[0]


@numba.njit(nogil=True)
def _two_addresses(state, const, journal, a, d0, d1, dt, ms, mc, fp, r0, er, v1, v2):
    # `_kernels._step_packed`'s signature up to 0.11.0 and the shape of its result (a tuple of
    # scalars).
    return (0, a, d0, d1, 1, dt, ms, (mc, fp, r0), 1, er, v1 + v2, journal)


#: `_two_addresses`'s argument types (`_kernels._STEP_SIGNATURE` up to 0.11.0).
_TWO_ADDRESSES = (numba.types.intp, numba.types.intp, numba.types.boolean) + (numba.types.float64,) * 11


@numba.njit(nogil=True)
def _three_addresses(state, const, params, journal, a, d0, d1, dt, fp, r0, e0, x0):
    # `_kernels._step_packed`'s signature since 0.12.0 (the model's constants behind a third
    # address) and the shape of its result.
    return (0, a, d0, d1 + e0, 1, dt + x0, fp, (r0, fp, r0), 1, a, d0, journal)


def main() -> None:
    sim = ContactSimulator(SceneConfig.from_yaml(default_scene_path()).contacts[0])
    for i in range(1, 60):
        sim.step(i * 1e-3, depth=i * 1e-6)
    row = sim._model.row
    args = row.kernel_args
    arrays = tuple(a for a in args if isinstance(a, np.ndarray))
    scalars = np.zeros(12)
    state, const = row._state, row._const

    def loop(call):
        def run() -> None:
            for _ in range(CALLS):
                call()

        return run

    addresses = row.addresses
    entry = _two_addresses.compile(_TWO_ADDRESSES)
    step_args = (*addresses, True, 1.0, 2.0, 3.0, 1e-3, 0.0, 1.0, 0.5, 1.0, 2.0, 3.0, 4.0)
    entry3 = _three_addresses.compile(_kernels._STEP_SIGNATURE)
    step_args3 = (*addresses, sim._model._params_address, True, 1.0, 2.0, 3.0, 1e-3, 0.5, 1.0, 2.0, 3.0)
    options = {
        "32 arguments (20 arrays, 12 floats): _advance's signature": loop(
            lambda: _args32(*args, 1.0, 2.0, 3.0, 1e-3, 0.0, 1e-6)
        ),
        "the row's 26 arguments as one tuple + 6 floats": loop(
            lambda: _tuple(args, 1.0, 2.0, 3.0, 1e-3, 0.0, 1e-6)
        ),
        "20 arrays + the scalars packed in one array": loop(
            lambda: _arrays_and_scalar_array(*arrays, scalars)
        ),
        "2 buffers + the scalars packed in one array (3 writes)": loop(
            lambda: (
                scalars.__setitem__(0, 1.0),
                scalars.__setitem__(1, 2.0),
                scalars.__setitem__(2, 3.0),
                _two_buffers_scalar_array(state, const, scalars),
            )
        ),
        "2 buffers + bool + 6 floats": loop(
            lambda: _two_buffers(state, const, True, 1.0, 2.0, 3.0, 1e-3, 0.0, 1e-6)
        ),
        "2 buffers + bool + 6 floats, views by slicing": loop(
            lambda: _two_buffers_sliced_views(state, const, True, 1.0, 2.0, 3.0, 1e-3, 0.0, 1e-6)
        ),
        "2 buffers + bool + 6 floats, views by _unpack (carray)": loop(
            lambda: _two_buffers_unpacked(state, const, True, 1.0, 2.0, 3.0, 1e-3, 0.0, 1e-6)
        ),
        "2 addresses + bool + 11 floats, a 12-tuple returned (`_step_packed` to 0.11.0), dispatcher": loop(
            lambda: _two_addresses(*step_args)
        ),
        "the same through its entry point (`_kernels.step_entry` to 0.11.0)": loop(lambda: entry(*step_args)),
        "3 addresses + bool + 8 floats, a 12-tuple returned, entry point (`_step_packed` 0.12.0)": loop(
            lambda: entry3(*step_args3)
        ),
        "empty Python loop (lambda call)": loop(lambda: None),
    }
    for run in options.values():
        run()
    medians = interleaved_medians(options, repeats=40)
    print("| how the arguments are passed | ns per call |")
    print("|---|---|")
    for name, seconds in medians.items():
        print(f"| {name} | {seconds / CALLS * 1e9:.0f} |")


if __name__ == "__main__":
    main()
