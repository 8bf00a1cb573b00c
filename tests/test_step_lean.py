"""The depth-control step path gives bit-equal outputs to the 0.2.0 path (golden from main).

`step_scenarios` records varied sequences (snap-in, pull-off, out of contact with memory,
depth jumps at one time, domain growth, refused calls mid-way, reset, snapshot/restore into the
same and another simulator, `advance`, `step_depths`); the golden was written from main at
fecbb5f before the lean step path and the packed kernel call, and written again in 0.4.0 by
the snap-in located in time directly (`step_scenarios` says why). Since the 0.3.0 edge root finder
moved edges by up to 1e-12 of an element (and the 0.4.0 kernel's K = 1 losses summed in four
lanes the energy dissipated by ~1e-15), the golden comparison allows `golden_tolerance`'s
tolerance where the bits differ (the twins below stay bit for bit).
"""

from __future__ import annotations

import copy
import math
import pickle
from pathlib import Path

import numpy as np
import pytest
from golden_tolerance import column_failures
from scenes import one_contact
from step_scenarios import depth_scale, run_scene, scenes

from viscoadh_ros.core import _kernels, simulator
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

GOLDEN = Path(__file__).resolve().parent / "data" / "step_golden.npz"


@pytest.mark.parametrize("name", sorted(scenes()))
def test_step_path_is_bit_equal_to_the_golden(name: str) -> None:
    """Bit for bit, or, since the 0.3.0 edge root finder (`edge`: a safeguarded secant in
    place of bisection, same tolerance, edges moved by up to 1e-12 of an element), within
    `golden_tolerance`'s tolerance on every output field; the memory digest (a hash of its
    bits) is then not compared: the memory is pinned within that tolerance by
    tests/test_kernel_golden.py, and the step path's handling of it (undo, snapshot, restore)
    bit for bit by the in-process twins below."""
    expected = np.load(GOLDEN)[name]
    got = run_scene(scenes()[name], depth_scale(name))
    assert got.shape == expected.shape
    bad = np.flatnonzero(np.any(got.view(np.uint64) != expected.view(np.uint64), axis=1))
    if bad.size == 0:
        return
    fields = expected[:, :-1], got[:, :-1]
    phase, speed = STEP_OUTPUT_FIELDS.index("phase"), STEP_OUTPUT_FIELDS.index("edge_speed")
    failures = column_failures(*fields, phase=phase, speed=speed)
    assert not failures, f"{name}: first differing row {bad[0]}: {failures}"


def _state(sim) -> tuple:
    """Everything a step may change, bytes for the memory."""
    model = sim._model
    row = model.row
    memory = (
        b"" if row is None else row.wl.tobytes() + row.wb.tobytes() + row.wsum.tobytes() + row.bsum.tobytes()
    )
    return (
        sim.time,
        sim._depth,
        sim.output,
        sim._energy_input,
        sim._held_force,
        sim._force_memo,
        model.radius,
        model.dissipated,
        model._memory_peak,
        model._edge,
        model._edge_depth,
        row,
        memory,
    )


def _sequence(seed: int, scale: float) -> list[tuple[str, float, float]]:
    rng = np.random.default_rng(seed)
    calls, t = [], 0.0
    for _ in range(260):
        kind = rng.choice(["depth"] * 12 + ["same_time", "force", "advance", "nan", "back"])
        t += 0.0 if kind == "same_time" else float(rng.choice([1e-3, 1e-4, 5e-3]))
        calls.append((str(kind), t, scale * float(rng.uniform(-0.6, 1.6))))
    return calls


@pytest.mark.parametrize("name", ["default", "two_kelvin", "growing", "punch"])
@pytest.mark.parametrize("seed", [1, 2])
def test_the_lean_path_equals_the_general_path(name: str, seed: int) -> None:
    """`step` (lean path for float depths) and `_step_transaction` (the general path) give
    bit-equal outputs and states over random sequences with force steps, holds, jumps at one
    time and refused calls between the depth steps."""
    contact, scale = scenes()[name], depth_scale(name)
    lean, general = ContactSimulator(contact), ContactSimulator(contact)
    for kind, t, value in _sequence(seed, scale):
        results = []
        for sim, depth_step in (
            (lean, lambda s, t, d: s.step(t, depth=d)),
            (general, lambda s, t, d: s._step_transaction(t, d, None)),
        ):
            try:
                if kind in ("depth", "same_time"):
                    results.append(depth_step(sim, t, value))
                elif kind == "force":
                    results.append(sim.step(t, force=value * 1e2))
                elif kind == "advance":
                    results.append(sim.advance(t))
                elif kind == "nan":
                    results.append(depth_step(sim, t, math.nan))
                else:
                    results.append(depth_step(sim, t - 1.0, value))
            except ValueError as error:
                results.append(type(error).__name__ + str(error))
        assert results[0] == results[1], (kind, t, value)
        assert _state(lean)[:11] == _state(general)[:11]
        assert _state(lean)[12] == _state(general)[12]


class _Interrupt(BaseException):
    pass


def test_an_interrupt_inside_the_lean_step_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    contact, scale = scenes()["standard_fast"], depth_scale("standard_fast")
    sim, reference = ContactSimulator(contact), ContactSimulator(contact)
    for k in range(1, 40):
        sim.step(k * 1e-3, depth=scale * 0.03 * k)
        reference.step(k * 1e-3, depth=scale * 0.03 * k)
    assert sim._model.row is not None and sim.in_contact
    before = _state(sim)
    real = simulator._object_new

    def interrupted(*args):
        raise _Interrupt

    # After the kernel ran (the output record is the step's last work before it commits).
    monkeypatch.setattr(simulator, "_object_new", interrupted)
    with pytest.raises(_Interrupt):
        sim.step(40e-3, depth=scale * 1.3)
    assert _state(sim) == before
    monkeypatch.setattr(simulator, "_object_new", real)
    for k in range(40, 60):
        assert sim.step(k * 1e-3, depth=scale * 0.02 * (80 - k)) == reference.step(
            k * 1e-3, depth=scale * 0.02 * (80 - k)
        )
    assert _state(sim)[12] == _state(reference)[12]


@pytest.mark.parametrize("kelvin", [0, 1, 3])
def test_the_packed_views_are_the_rows_kernel_arguments(kelvin: int) -> None:
    """`_kernels._unpack` (what `_advance_packed` hands `_advance`; `_step_packed` makes the
    same views from `Row.addresses`) finds every array of `Row.kernel_args` at the same
    address with the same shape, and the same scalars; also for a `with_memory` clone and
    after pickling and deep copying."""
    contact = one_contact(
        {"shape": "sphere", "radius": 0.005},
        kelvin=[1e5 * (k + 1) for k in range(kelvin)],
        viscosities=[1e3 * 10**k for k in range(kelvin)],
        work=0.05,
        numerics={"elements": 40, "model": "time_stepped"},
    )
    sim = ContactSimulator(contact)
    for k in range(1, 20):
        sim.step(k * 1e-3, depth=k * 1e-6)
    row = sim._model.row
    assert row.addresses  # found (and kept) before the copies below are made
    clone = row.with_memory(row.wl * 0.5, row.wb)
    for candidate in (row, clone, pickle.loads(pickle.dumps(row)), copy.deepcopy(row)):
        # `Row.addresses` (what `_step_packed` takes) are the row's own buffers, never a copy's.
        assert candidate.addresses == (candidate._state.ctypes.data, candidate._const.ctypes.data)
        args, txn, txn_b = _kernels._unpack(candidate._state, candidate._const)
        expected = candidate.kernel_args
        assert len(args) == len(expected) == _kernels._advance.py_func.__code__.co_argcount - 6
        for got, want in zip(args, expected, strict=True):
            if isinstance(want, np.ndarray):
                assert got.shape == want.shape
                assert want.size == 0 or got.ctypes.data == want.ctypes.data  # (no data: any address)
                assert np.array_equal(got, want, equal_nan=True)  # coef holds NaN: no substep yet
            else:
                assert got == want
        if txn.size:
            assert txn.ctypes.data == candidate.txn.ctypes.data
            assert txn_b.ctypes.data == candidate.txn_b.ctypes.data
    assert np.array_equal(clone.wl, row.wl * 0.5) and not np.shares_memory(clone.wl, row.wl)
    assert np.shares_memory(clone.gf, row.gf)


def test_the_step_params_address_is_the_models_own() -> None:
    """`_step_packed` reads the model's constants at `_TimeStepped._params_address` (0.12.0): the
    model's own `_params` array (max_substep, max_edge_cells, E_r*, v_c1, v_c2 as the model and
    the physics give them), also for a pickled or deep-copied simulator, which steps as the
    original does."""
    contact = one_contact(
        {"shape": "sphere", "radius": 0.005},
        kelvin=[1e5],
        viscosities=[1e3],
        work=0.05,
        numerics={"elements": 40, "model": "time_stepped"},
    )
    sim = ContactSimulator(contact)
    for k in range(1, 20):
        sim.step(k * 1e-3, depth=k * 1e-6)
    model = sim._model
    v_c1, v_c2 = sim.physics.critical_speeds
    assert model._params.tolist() == [
        model._max_substep,
        model._max_edge_cells,
        float(sim.physics.e_relaxed),
        float(v_c1),
        float(v_c2),
    ]
    copies = [pickle.loads(pickle.dumps(sim)), copy.deepcopy(sim)]
    for candidate in (sim, *copies):
        params = candidate._model._params
        assert candidate._model._params_address == params.ctypes.data
    assert copies[0]._model._params_address != model._params_address
    assert copies[1]._model._params_address != model._params_address
    for k in range(20, 40):
        want = _bits(sim.step(k * 1e-3, depth=(40 - k) * 1e-6))
        for candidate in copies:
            assert _bits(candidate.step(k * 1e-3, depth=(40 - k) * 1e-6)) == want


def _bits(output) -> tuple:
    """An output's fields as bits (phase and flags by value)."""
    return tuple(np.array([float(getattr(output, name)) for name in STEP_OUTPUT_FIELDS]).view(np.uint64))


def _kelvin4():
    return one_contact(
        {"shape": "sphere", "radius": 0.006},
        kelvin=[3e5, 1e5, 2e5, 5e4],
        viscosities=[3e2, 4e3, 2e4, 3e5],
        work=0.06,
        numerics={"elements": 80},
    )


def _reference_sequence(seed: int, scale: float) -> list[tuple[str, float, float]]:
    """Depth steps with everything else between them: force steps, holds, jumps at one time,
    refused calls (NaN, time going back, a depth the domain cannot represent, an interrupt
    after the kernel ran), reset, snapshots restored later."""
    rng = np.random.default_rng(seed)
    kinds = ["depth"] * 14 + ["same_time", "force", "advance", "nan", "back", "huge", "interrupt"]
    kinds += ["snapshot", "restore", "reset", "above"]
    calls, t = [], 0.0
    for _ in range(240):
        kind = str(rng.choice(kinds))
        t += 0.0 if kind == "same_time" else float(rng.choice([1e-3, 1e-4, 5e-3]))
        calls.append((kind, t, scale * float(rng.uniform(-0.6, 1.6))))
    return calls


@pytest.mark.parametrize(
    "name", ["elastic_stepped", "default", "standard_fast", "two_kelvin", "growing", "punch", "kelvin4"]
)
@pytest.mark.parametrize("seed", [3, 4])
def test_the_one_call_step_equals_the_0_4_0_step(
    name: str, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`step` (one compiled call per depth step, `_kernels._step_packed`) against the 0.4.0 step
    path kept in tests/step_reference.py on the same kernels, K = 0, 1, 2 and 4: bit-equal
    outputs, the same refusals, and bit-equal states (memory included) after every call, over
    random sequences with force steps, holds, domain growth, out-of-contact steps with
    memory, refused calls mid-way (an interrupt after the kernel ran among them), reset and
    snapshots restored later."""
    from step_reference import reference_simulator, reference_step

    if name == "kelvin4":
        contact, scale = _kelvin4(), 3e-5
    else:
        contact, scale = scenes()[name], depth_scale(name)
    new, old = ContactSimulator(contact), reference_simulator(contact)
    saved: dict[int, object] = {}
    real = simulator._object_new

    def interrupted(*args):
        raise _Interrupt

    for kind, t, value in _reference_sequence(seed, scale):
        results = []
        for label, sim in (("new", new), ("old", old)):

            def depth_step(t: float, d: float, sim=sim, label=label):
                return sim.step(t, depth=d) if label == "new" else reference_step(sim, t, d)

            try:
                if kind in ("depth", "same_time"):
                    results.append(_bits(depth_step(t, value)))
                elif kind == "above":
                    results.append(_bits(depth_step(t, -abs(value) - scale)))
                elif kind == "force":
                    results.append(_bits(sim.step(t, force=value * 1e2)))
                elif kind == "advance":
                    if sim._held_force is not None:
                        results.append(_bits(sim.step(t, force=sim._held_force)))
                    else:
                        results.append(_bits(depth_step(t, sim._depth)))
                elif kind == "nan":
                    results.append(_bits(depth_step(t, math.nan)))
                elif kind == "back":
                    results.append(_bits(depth_step(t - 1.0, value)))
                elif kind == "huge":
                    results.append(_bits(depth_step(t, 1e3)))
                elif kind == "interrupt":
                    monkeypatch.setattr(simulator, "_object_new", interrupted)
                    try:
                        depth_step(t, value)
                    except _Interrupt:
                        results.append("interrupted")
                    finally:
                        monkeypatch.setattr(simulator, "_object_new", real)
                elif kind == "snapshot":
                    saved[id(sim)] = sim.snapshot()
                    results.append("saved")
                elif kind == "restore":
                    if id(sim) in saved:
                        sim.restore(saved[id(sim)])
                    results.append("restored")
                else:
                    sim.reset(t)
                    results.append("reset")
            except ValueError as error:
                results.append(type(error).__name__ + str(error))
        assert results[0] == results[1], (kind, t, value)
        state_new, state_old = _state(new), _state(old)
        assert state_new[:2] == state_old[:2] and _bits(state_new[2]) == _bits(state_old[2])
        assert state_new[3:11] == state_old[3:11], (kind, t, value)
        assert state_new[12] == state_old[12], (kind, t, value)
        assert (state_new[11] is None) == (state_old[11] is None)
        if state_new[11] is not None:
            assert state_new[11].elements == state_old[11].elements
            assert state_new[11].dx == state_old[11].dx


def _force_history(contact, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Forces a controller commands at 1 kHz: those of a press, hold, pull past the pull-off
    and touch again under depth control (so the force path meets snap-in, creep at a held
    force, the fold and the let-go), then pulled 1.3x further than the depth run pulled."""
    t = 1e-3 * np.arange(1, 361)
    depth = scale * np.concatenate(
        [np.linspace(-0.05, 1.0, 90), np.full(60, 1.0), np.linspace(1.0, -0.4, 150), np.full(60, 0.3)]
    )
    force = ContactSimulator(contact).step_depths(t, depth)["force"]
    return t, np.where(force < 0.0, 1.3 * force, force)


@pytest.mark.parametrize("name", ["default", "two_kelvin", "growing", "standard_fast", "cone"])
def test_the_lean_force_path_equals_the_general_path(name: str) -> None:
    """`step(t, force=f)` (the lean force path where its predicted root holds, else the
    general path) and `_step_transaction` (always the general path) give bit-equal outputs,
    force memos and states over a force history with the snap-in, creep, fold and let-go,
    float and numpy-float and int commands, and refused commands between them; the lean path
    served most rows (else this compares the general path with itself), and some of them
    handed a prediction that did not hold over to the general search."""
    contact, scale = scenes()[name], depth_scale(name)
    times, forces = _force_history(contact, scale)
    lean, general = ContactSimulator(contact), ContactSimulator(contact)
    general_calls, handovers, inside = [0], [0], [False]
    transaction, search = lean._step_transaction, lean._search_force

    def counted(*args):
        general_calls[0] += 1
        inside[0] = True
        try:
            return transaction(*args)
        finally:
            inside[0] = False

    def searched(*args):
        handovers[0] += not inside[0]  # a lean step whose prediction failed goes on searching
        return search(*args)

    lean._step_transaction = counted  # type: ignore[method-assign]
    lean._search_force = searched  # type: ignore[method-assign]
    in_contact_rows = np.zeros(times.size, dtype=bool)
    for index, (t, f) in enumerate(zip(times.tolist(), forces.tolist(), strict=True)):
        calls = [(t, f)]
        if index % 37 == 5:
            calls = [(t, math.nan), (t - 1.0, f), (t, f)]  # refused, refused, then the good one
        elif index % 11 == 3:
            calls = [(np.float64(t), np.float64(f))]
        elif index % 53 == 7:
            calls = [(t, int(f))]
        for call_t, call_f in calls:
            results = []
            for step in (
                lambda t=call_t, f=call_f: lean.step(t, force=f),
                lambda t=call_t, f=call_f: general._step_transaction(t, None, f),
            ):
                try:
                    results.append(step())
                except ValueError as error:
                    results.append(type(error).__name__ + str(error))
            assert results[0] == results[1], (name, index, call_t, call_f)
            assert _state(lean)[:11] == _state(general)[:11], (name, index)
            assert _state(lean)[12] == _state(general)[12], (name, index)
        in_contact_rows[index] = lean.in_contact
    assert general.output.force == lean.output.force
    # Calls that took the lean path: every call but those counted (the refused and int ones
    # among them); most rows in contact must be such calls.
    calls = times.size + 2 * len(range(5, times.size, 37))
    lean_calls, in_contact = calls - general_calls[0], int(np.count_nonzero(in_contact_rows))
    assert handovers[0] >= 1, "no lean step handed a failed prediction over to the search"
    assert lean_calls >= 0.8 * in_contact, (
        f"the lean force path served {lean_calls} of {in_contact} rows in contact"
    )


@pytest.mark.parametrize("where", ["output", "memo"])
def test_an_interrupt_inside_the_lean_force_step_changes_nothing(
    where: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Interrupted after its trials (the output record) or after it published (the force
    memo), a lean force step leaves the state as before; the next steps equal a simulator
    that was never interrupted."""
    contact, scale = scenes()["default"], depth_scale("default")
    times, forces = _force_history(contact, scale)
    sim, reference = ContactSimulator(contact), ContactSimulator(contact)
    for k in range(100):
        sim.step(float(times[k]), force=float(forces[k]))
        reference.step(float(times[k]), force=float(forces[k]))
    assert sim.in_contact and isinstance(sim._force_memo, tuple)
    before = _state(sim)
    if where == "output":
        monkeypatch.setattr(simulator, "_object_new", lambda *args: (_ for _ in ()).throw(_Interrupt()))
    else:
        monkeypatch.setattr(
            ContactSimulator, "_remember", lambda *args, **kwargs: (_ for _ in ()).throw(_Interrupt())
        )
    with pytest.raises(_Interrupt):
        sim.step(float(times[100]), force=float(forces[100]))
    assert _state(sim) == before
    monkeypatch.undo()
    for k in range(100, 140):
        assert sim.step(float(times[k]), force=float(forces[k])) == reference.step(
            float(times[k]), force=float(forces[k])
        )
    assert _state(sim)[12] == _state(reference)[12]
