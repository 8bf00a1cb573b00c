"""The MuJoCo model of the cell and the geometry/force exchange with the pads.

World (z up, table top at z = 0): a rigid box part resting on the table; above it the arm, a
body on one vertical slide joint under a position servo (gravity compensated), carrying the
pads: spheres of the pad radius whose lowest points (the pad tips) lie in the arm's plane
``z = q_arm`` above the part's resting top face; a latch (one body, two bars over the part's
x-edges) on its own vertical slide, whose servo force is limited to the fixture's holding force.

Who touches whom:

- pad - part: the viscoadh model only. MuJoCo's collision filter excludes the pair by the
  contype/conaffinity bits: a pair collides when ``(contype1 & conaffinity2) or (contype2 &
  conaffinity1)``. The pads have contype 2, conaffinity 0; the part has contype 1,
  conaffinity 1: both terms are 0, so MuJoCo makes no contact; the table (conaffinity 3) still
  stops a pad (2 & 3) and holds the part (1 & 3).
- part - table, part - latch: MuJoCo's own contacts (soft constraints, solref time constant
  `contact_time_constant`).
- arm body: contype 0, conaffinity 0 (it touches nothing).

Each physics step (`pad_geometry` after ``mj_step1``): the indentation of each pad is minus
MuJoCo's signed distance between the pad sphere and the part box (``mj_geomDistance``); the
force acts along the pad's axis (vertical: a top-down gripper) under the pad's centre, at the
height of the part's nearest point. `apply_pad_forces` puts
``+F n`` on the arm and ``-F n`` on the part at that point (``mj_applyFT`` into
``qfrc_applied``, cleared first), then ``mj_step2`` integrates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from .config import LATCH_WIDTH, Cell

#: Beyond this gap, m, `mj_geomDistance` stops searching (the pad is far out of touch).
DISTANCE_CAP = 0.01
#: Latch bar thickness, m, and mass, kg.
LATCH_THICKNESS = 0.002
LATCH_MASS = 0.001
#: Table and latch contact time constant, s (MuJoCo solref; at least two physics steps).
CONTACT_TIME_CONSTANT = 2.0e-3
#: The open latch waits this far above the highest the part's top is lifted to, m.
LATCH_CLEARANCE = 0.003


@dataclass(frozen=True)
class PadGeometry:
    """Per pad, this step: depth (m, > 0 presses in), unit normal from the part to the pad
    (the pad's axis, +z; shape (n, 3)) and the point the force acts at (under the pad's
    centre, on the part's nearest point's height; shape (n, 3), world frame, m)."""

    depth: NDArray[np.float64]
    normal: NDArray[np.float64]
    point: NDArray[np.float64]


def pad_positions(cell: Cell) -> NDArray[np.float64]:
    """(x, y) of each pad centre in the arm frame, m, shape (n, 2), row by row."""
    pads = cell.gripper.pads
    xs = (np.arange(pads.columns) - 0.5 * (pads.columns - 1)) * pads.pitch
    ys = (np.arange(pads.rows) - 0.5 * (pads.rows - 1)) * pads.pitch
    return np.array([(x, y) for y in ys for x in xs], dtype=np.float64)


def model_xml(cell: Cell) -> tuple[str, float]:
    """The MJCF of the cell (see the module docstring) and the latch's closed servo target, m
    (10 holding-force lengths below the rim, so on the part the servo saturates)."""
    g = cell.gripper
    radius = float(cell.pad.indenter.radius)
    sx, sy, sz = (0.5 * v for v in g.part.size)
    solref = f"{max(CONTACT_TIME_CONSTANT, 2.0 * g.timestep):.6g} 1"
    pads = "\n".join(
        f'      <geom name="pad_{i}" type="sphere" size="{radius:.9g}" pos="{x:.9g} {y:.9g} {radius:.9g}" '
        f'density="0" contype="2" conaffinity="0" rgba="0.9 0.5 0.2 1"/>'
        for i, (x, y) in enumerate(pad_positions(cell))
    )
    bar_x = sx - 0.5 * LATCH_WIDTH
    F = g.fixture
    latch_target = -10.0 * F.holding_force / F.latch_stiffness
    latch_damping = 2.0 * math.sqrt(F.latch_stiffness * LATCH_MASS)
    bars = "\n".join(
        f'      <geom name="latch_{side}" type="box" size="{0.5 * LATCH_WIDTH:.9g} {sy:.9g} '
        f'{0.5 * LATCH_THICKNESS:.9g}" pos="{sign * bar_x:.9g} 0 {0.5 * LATCH_THICKNESS:.9g}" '
        f'contype="1" conaffinity="1" solref="{solref}" rgba="0.3 0.6 0.3 1"/>'
        for side, sign in (("left", -1.0), ("right", 1.0))
    )
    arm_top = 2.0 * radius + 0.03
    xml = f"""<mujoco model="viscoadh_gripper">
  <option timestep="{g.timestep:.9g}" integrator="implicitfast" gravity="0 0 -9.81"/>
  <worldbody>
    <light pos="0 -0.1 0.3" dir="0 0.3 -1"/>
    <geom name="table" type="plane" size="0.2 0.2 0.01" contype="1" conaffinity="3"
          solref="{solref}" rgba="0.8 0.8 0.8 1"/>
    <body name="part" pos="0 0 {sz:.9g}">
      <freejoint name="part"/>
      <geom name="part" type="box" size="{sx:.9g} {sy:.9g} {sz:.9g}" mass="{g.part.mass:.9g}"
            contype="1" conaffinity="1" solref="{solref}" rgba="0.3 0.4 0.8 1"/>
    </body>
    <body name="arm" pos="0 0 {2.0 * sz:.9g}" gravcomp="1">
      <joint name="arm_z" type="slide" axis="0 0 1"/>
      <geom name="arm" type="box" size="{sx:.9g} {max(sy, 0.004):.9g} 0.002"
            pos="0 0 {2.0 * radius + 0.002:.9g}" mass="{g.arm.mass:.9g}" contype="0" conaffinity="0"
            rgba="0.5 0.5 0.5 0.6"/>
      <geom name="arm_rod" type="cylinder" size="0.003 0.015" pos="0 0 {arm_top - 0.011:.9g}"
            density="0" contype="0" conaffinity="0" rgba="0.5 0.5 0.5 0.6"/>
{pads}
    </body>
    <body name="latch" pos="0 0 {2.0 * sz:.9g}" gravcomp="1">
      <joint name="latch_z" type="slide" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{LATCH_MASS:.9g}" diaginertia="1e-6 1e-6 1e-6"/>
{bars}
    </body>
  </worldbody>
  <actuator>
    <position name="arm" joint="arm_z" kp="{g.arm.stiffness:.9g}" kv="{g.arm.damping:.9g}"/>
    <position name="latch" joint="latch_z" kp="{F.latch_stiffness:.9g}" kv="{latch_damping:.9g}"
              forcelimited="true" forcerange="{-F.holding_force:.9g} {F.holding_force:.9g}"/>
  </actuator>
</mujoco>
"""
    return xml, latch_target


class CellModel:
    """The MuJoCo model and data of a cell, and the pad geometry/force exchange.

    latch_open_height: m of the open latch above the part's resting top (clear of the lift).
    ``arm_height``, ``part_rise``, ``latch_height``: m, the arm's pad-tip plane above the part's
    resting top, the part's lift above its resting height, the latch bars' underside above the
    part's resting top.
    """

    def __init__(self, cell: Cell, *, latch_open_height: float) -> None:
        self.cell = cell
        self.latch_open_height = latch_open_height
        xml, self.latch_closed_target = model_xml(cell)
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        m = self.model
        count = cell.gripper.pad_count
        self.pad_geoms = [m.geom(f"pad_{i}").id for i in range(count)]
        self.part_geom = m.geom("part").id
        self.arm_body = m.body("arm").id
        self.part_body = m.body("part").id
        self.arm_qpos = int(m.joint("arm_z").qposadr[0])
        self.latch_qpos = int(m.joint("latch_z").qposadr[0])
        self.part_qpos = int(m.joint("part").qposadr[0])
        self.arm_actuator = m.actuator("arm").id
        self.latch_actuator = m.actuator("latch").id
        self.part_rest_z = float(0.5 * cell.gripper.part.size[2])
        self._fromto = np.zeros(6)
        self._zero = np.zeros(3)
        self._depth = np.zeros(count)
        self._normal = np.tile(np.array([0.0, 0.0, 1.0]), (count, 1))
        self._point = np.zeros((count, 3))
        self.reset()

    def reset(self) -> None:
        """Back to t = 0: arm at its start height, latch open, part at rest."""
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[self.arm_qpos] = self.cell.gripper.arm.start_height
        self.data.qpos[self.latch_qpos] = self.latch_open_height
        self.set_controls(self.cell.gripper.arm.start_height, latch_closed=False)
        mujoco.mj_forward(self.model, self.data)

    def set_controls(self, arm_height: float, *, latch_closed: bool | float) -> None:
        """Servo targets: the arm's pad-tip height, m; the latch open (False), closed (True),
        or a fraction of the way (0..1, for a latch closing over `latch_time`)."""
        fraction = float(latch_closed)
        self.data.ctrl[self.arm_actuator] = arm_height
        self.data.ctrl[self.latch_actuator] = (1.0 - fraction) * self.latch_open_height + fraction * (
            self.latch_closed_target
        )

    def pad_geometry(self) -> PadGeometry:
        """Depth, normal and contact point of every pad against the part (call after
        ``mj_step1``, which brings the positions up to date). Arrays are reused each call."""
        m, d = self.model, self.data
        for i, geom in enumerate(self.pad_geoms):
            distance = mujoco.mj_geomDistance(m, d, geom, self.part_geom, DISTANCE_CAP, self._fromto)
            self._depth[i] = -distance
            # The force acts along the pad's axis (the arm's -z), through the pad's centre: the
            # model is axisymmetric and frictionless, and a normal tilted with a tilting part
            # would push it sideways with nothing (no friction) to hold it, a runaway.
            self._point[i] = d.geom_xpos[geom]
            self._point[i, 2] = self._fromto[5]
        return PadGeometry(self._depth, self._normal, self._point)

    def apply_pad_forces(self, geometry: PadGeometry, force: NDArray[np.float64]) -> None:
        """Normal force F_i (N, > 0 pushes the pad away from the part) of every pad: ``+F n``
        on the arm, ``-F n`` on the part, at the contact point. Exactly zero when F_i == 0."""
        m, d = self.model, self.data
        d.qfrc_applied[:] = 0.0
        for i in range(force.size):
            f = float(force[i])
            if f == 0.0:
                continue
            vector = f * geometry.normal[i]
            mujoco.mj_applyFT(m, d, vector, self._zero, geometry.point[i], self.arm_body, d.qfrc_applied)
            mujoco.mj_applyFT(m, d, -vector, self._zero, geometry.point[i], self.part_body, d.qfrc_applied)

    @property
    def arm_height(self) -> float:
        return float(self.data.qpos[self.arm_qpos])

    @property
    def latch_height(self) -> float:
        return float(self.data.qpos[self.latch_qpos])

    @property
    def part_rise(self) -> float:
        return float(self.data.qpos[self.part_qpos + 2]) - self.part_rest_z
