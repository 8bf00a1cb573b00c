"""The 0.4.0 step path (main at c247a78), kept test-only: the reference the one-call step is
compared with bit for bit (tests/test_step_lean.py).

0.5.0 (issue 13, round `pycall`) made a depth step one compiled call: `_kernels._step_packed`
runs the kernel with its journal and computes the phase, edge speed, effective work and
scale-separation flag that `ContactSimulator.step` computed in Python, and `_TimeStepped.advance`
calls it too. This module is the code it replaced, on the same kernels: `reference_advance`
(`_TimeStepped.advance` calling `_kernels._advance_packed`) and `reference_step`
(`ContactSimulator.step`'s lean path then). A simulator whose model's ``advance`` is
`reference_advance` (`reference_simulator`) and that is stepped by `reference_step` runs the
0.4.0 Python around the same `_advance` / `_advance_from`: whatever differs from the new
path is the new path's doing, whichever kernel the checkout has.
"""

from __future__ import annotations

import math
from types import MethodType
from typing import Any

from viscoadh_ros.core import _kernels, simulator
from viscoadh_ros.core.simulator import PREPARE_FRACTION, ContactSimulator, StepOutput, _phase


def reference_advance(self: Any, d0: float, d1: float, dt: float) -> tuple[float, float, float]:
    """`_TimeStepped.advance` of 0.4.0 (the kernel through `_advance_packed`)."""
    row = self.row
    if row is None:
        if not self._ensure_row(max(d0, d1)):
            self.substeps = 0
            return 0.0, 0.0, 0.0
        row = self.row
        assert row is not None
    journal = self._journal is not row
    start = None if journal else self.get_state()
    radius0, dissipated0 = self.radius, self.dissipated
    known = self._force_at
    if known is not None and known[0] is row and known[1] == radius0 and known[2] == d0 and d0 != 0.0:
        force_prev = known[3]
    else:
        force_prev = math.nan
    self._force_at = None
    while True:
        row = self.row
        if journal:
            self._journal = row
        status = _kernels._advance_packed(
            row._state,
            row._const,
            journal,
            self.radius,
            d0,
            d1,
            dt,
            self._max_substep,
            self._max_edge_cells * row.dx,
            force_prev,
        )
        journal = False
        if status == _kernels.STATUS_OK:
            break
        force_prev = math.nan
        if start is None:
            _kernels._restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
        else:
            self.set_state(start)
        self.radius, self.dissipated = radius0, dissipated0
        self._grow(d0)
        start = self.get_state()
    # (The slots before OUT_LET_GO, 0.10.0's, which this reference does not read.)
    radius, force, work, _, substeps, dissipated, peak, outside, inside, g_edge = row.out[
        : _kernels.OUT_LET_GO
    ].tolist()
    self.radius = radius
    self.substeps = int(substeps)
    self.dissipated += dissipated
    self._memory_peak = peak
    self._edge = (outside, inside, g_edge)
    self._edge_depth = d1
    self._force_at = (row, radius, d1, force)
    if row is not self._prepare_row:
        self._prepare_row = row
        self._prepare_radius = PREPARE_FRACTION * row.length
    if radius > self._prepare_radius:
        self._prepare_growth(row)
    return radius, force, work


def reference_simulator(contact: Any) -> ContactSimulator:
    """A simulator whose model advances by `reference_advance` (force steps, `step_depths`'
    domain creation and the general path included)."""
    sim = ContactSimulator(contact)
    if isinstance(sim._model, simulator._TimeStepped):
        sim._model.advance = MethodType(reference_advance, sim._model)
    return sim


def reference_step(self: ContactSimulator, time: Any, depth: Any) -> StepOutput:
    """``step(time, depth=depth)`` of 0.4.0: its lean path, else the general path."""
    if self._lean and isinstance(depth, float) and isinstance(time, float):
        t = time if type(time) is float else float(time)
        d = depth if type(depth) is float else float(depth)
        model = self._model
        d_prev = self._depth
        output0 = self._output
        r0 = output0.contact_radius
        time0 = self._time
        if (
            t - t == 0.0
            and d - d == 0.0
            and t >= time0
            and not (d < 0.0 and d_prev < 0.0 and r0 <= 0.0 and model.is_relaxed())
        ):
            energy0 = self._energy_input
            held0 = self._held_force
            token = model.begin()
            try:
                dt = t - time0
                radius, f, work = model.advance(d_prev, d, dt)
                energy = energy0 + work
                physics = self.physics
                g_edge = model._edge[2] if radius > 0.0 else 0.0
                phase = _phase(model, physics, d, r0, radius, g_edge)
                edge_speed = (radius - r0) / dt if dt > 0.0 else 0.0
                u = d - g_edge
                if radius > 0.0 and u < 0.0:
                    effective = physics.e_relaxed * u * u / (2.0 * math.pi * radius)
                else:
                    effective = 0.0
                if edge_speed == 0.0:
                    separated = True
                else:
                    v_c1, v_c2 = physics.critical_speeds
                    separated = abs(edge_speed) >= (v_c1 if edge_speed > 0.0 else v_c2)
                output = simulator._object_new(StepOutput)
                output.__dict__.update(
                    {
                        "time": t,
                        "depth": d,
                        "force": f,
                        "contact_radius": radius,
                        "phase": phase,
                        "edge_speed": edge_speed,
                        "effective_work_of_adhesion": effective,
                        "energy_input": energy,
                        "energy_dissipated": model.dissipated,
                        "scale_separation_ok": separated,
                        "unstable": False,
                    }
                )
                self._energy_input = energy
                self._time = t
                self._depth = d
                self._output = output
                self._held_force = None
                return output
            except BaseException:
                model.rollback(token)
                self._energy_input, self._time, self._depth = energy0, time0, d_prev
                self._output, self._held_force = output0, held0
                raise
    return self._step_transaction(time, depth, None)
