"""The pads' contact model behind one interface: "step all pads" is one call.

`PadBank.step(time, depths)` advances every pad's contact to ``time`` (s) under
displacement control and returns the forces and contact radii. Two banks implement it:

- `LibraryPads`: one `ContactSimulator` per pad in this process (the fast path). The loop
  over pads lives here only, so a batched multi-contact step of the core can replace it
  without touching the cell.
- `viscoadh_ros.gripper.node_loop.NodePads`: the ``viscoadh`` node in the loop, over DDS.

Times: the cell steps at ``k * dt_ns`` integer nanoseconds (`step_time`), exactly the
simulation time the node derives from a command stamped ``start + k * dt_ns``, so both banks
see bit-identical inputs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from viscoadh_ros.core._kernels import warm_up
from viscoadh_ros.core.config import ContactConfig
from viscoadh_ros.core.history import predict_pull_off
from viscoadh_ros.core.simulator import ContactSimulator


def step_time(step: int, dt_ns: int) -> float:
    """Simulation time of physics step ``step``, s (integer ns, as the node computes it)."""
    return (step * dt_ns) * 1e-9


@dataclass
class PadStates:
    """What every pad reported at one step, shape (n,) each: force N (> 0 compressive),
    contact_radius m, phase (`Phase` values)."""

    force: NDArray[np.float64]
    contact_radius: NDArray[np.float64]
    phase: NDArray[np.uint8]


class PadBank(Protocol):
    """The pads of a gripper, stepped together."""

    count: int

    def step(self, time: float, depths: NDArray[np.float64]) -> PadStates:
        """Advance every pad to ``time`` (s) at ``depths[i]`` (m); their states."""

    def predict_pull_off(self, retract_speed: float) -> NDArray[np.float64]:
        """Pull-off force of every pad (N, < 0 adhesive; `core.history.predict_pull_off`)
        if the arm retracted now at ``retract_speed`` (m/s); the live states stay untouched."""

    def close(self) -> None:
        """Release what the bank holds (threads, the node)."""


class LibraryPads:
    """``count`` copies of ``contact``, each a `ContactSimulator` in this process."""

    def __init__(self, contact: ContactConfig, count: int) -> None:
        warm_up()
        self.count = count
        self.simulators = [ContactSimulator(contact) for _ in range(count)]
        self._states = PadStates(np.zeros(count), np.zeros(count), np.zeros(count, dtype=np.uint8))

    def step(self, time: float, depths: NDArray[np.float64]) -> PadStates:
        states = self._states
        for i, simulator in enumerate(self.simulators):
            output = simulator.step(time, depth=float(depths[i]))
            states.force[i] = output.force
            states.contact_radius[i] = output.contact_radius
            states.phase[i] = output.phase
        return states

    def predict_pull_off(self, retract_speed: float) -> NDArray[np.float64]:
        return np.array([predict_pull_off(s, retract_speed).pull_off_force for s in self.simulators])

    def close(self) -> None:
        """Nothing to release."""
