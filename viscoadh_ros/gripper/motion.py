"""What the arm is told to do: a pick (and optionally a place) as timed segments.

Heights are the arm's pad-tip plane above the part's resting top face, m (``-press_depth``
presses the pads ``press_depth`` into the part, as far as the servo gets them). The servo
follows the reference with its own stiffness, so the depth reached is slightly less.

Segments, in order: ``approach`` (constant speed from the start height to ``-press_depth``),
``hold``, ``peel`` (with a ``peel_speed``: a slow constant rise from ``-press_depth`` to
``PEEL_CLEARANCE`` above the part's top, so the part leaves the table while the arm moves
slowly), ``lift`` (trapezoidal velocity: ``lift_acceleration`` up to ``lift_speed``, and down
again, to ``lift_height``), ``carry`` (held up); with ``place``: ``lower`` (trapezoidal, back to
``-place_depth``), ``latch`` (the fixture's latch closes over ``latch_time``, then settles for
``LATCH_SETTLE_TIME``), ``retract`` (constant ``retract_speed`` up to ``RETRACT_TRAVEL``), ``dwell``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from viscoadh_ros.core.errors import InputError, require_positive

#: Segment names in the order they run.
SEGMENTS = ("approach", "hold", "peel", "lift", "carry", "lower", "latch", "retract", "dwell")
#: How long the arm dwells after the retraction, s.
DWELL_TIME = 0.05
#: How long the closed latch settles on the part before the retraction, s.
LATCH_SETTLE_TIME = 0.2
#: How far the retraction of a place goes up, m (a part pulled out rises with it).
RETRACT_TRAVEL = 2.0e-3
#: Where the peel ends, m above the part's resting top: past the servo's lag at the peel speed
#: (kv v / kp, 10 um at 1 mm/s in the built-in cell), the pad's stretch under the part's weight
#: (a few um) and the part's spring-back out of the table's soft contact (up to ~20 um), so
#: the part is off the table before the arm accelerates.
PEEL_CLEARANCE = 0.1e-3


@dataclass(frozen=True)
class Motion:
    """A pick (and place) plan, SI units.

    press_depth: m (> 0) the arm's reference goes below the part's top; approach_speed: m/s;
    hold_time: s (>= 0); peel_speed: m/s of the slow rise that takes the part off the table
    before the lift accelerates (None: no peel, the lift starts at once from the press, and the
    arm, already moving when the pad's tension reaches the part's weight, jerks the part off
    the table: a tension peak about twice the weight, docs/gripper.md); lift_speed: m/s;
    lift_acceleration: m/s^2 (the transport's acceleration: the pads carry m (g + a) while it
    lasts); lift_height: m; carry_time: s;
    place: lower the part back into the fixture, latch it and retract; place_depth: m the
    reference goes below the part's top when placing; retract_speed: m/s of the release
    (None: chosen at the latch by the controller passed to `ArmProgram`).
    """

    press_depth: float = 150e-6
    approach_speed: float = 5e-3
    hold_time: float = 0.3
    peel_speed: float | None = 1e-3
    lift_speed: float = 0.05
    lift_acceleration: float = 2.0
    lift_height: float = 0.01
    carry_time: float = 0.2
    place: bool = False
    place_depth: float = 50e-6
    retract_speed: float | None = 0.05

    def validated(self) -> Motion:
        """Self, or InputError naming the first bad field."""
        for name in ("press_depth", "approach_speed", "lift_speed", "lift_acceleration", "lift_height"):
            require_positive(name, getattr(self, name))
        for name in ("hold_time", "carry_time", "place_depth"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0):
                raise InputError(f"{name} must be a finite number >= 0 (got {value!r})")
        if self.retract_speed is not None:
            require_positive("retract_speed", self.retract_speed)
        if self.peel_speed is not None:
            require_positive("peel_speed", self.peel_speed)
        return self

    @property
    def lift_start_height(self) -> float:
        """Where the trapezoidal lift starts, m: the peel's end, or the press without a peel."""
        return -self.press_depth if self.peel_speed is None else PEEL_CLEARANCE

    @property
    def pad_retract_speed(self) -> float:
        """The speed the pads are pulled off the part while their tension builds up to the
        part's weight, m/s: the peel's, or (no peel) about the lift's (the arm has not reached
        ``lift_speed`` by then; this is the fastest it may be)."""
        return self.lift_speed if self.peel_speed is None else self.peel_speed


def _trapezoid(
    h0: float, h1: float, speed: float, acceleration: float
) -> tuple[float, Callable[[float], float]]:
    """(duration s, height(t)) of a rest-to-rest move from h0 to h1 (m) with a trapezoidal
    velocity profile (triangular when too short to reach ``speed``)."""
    distance = abs(h1 - h0)
    sign = 1.0 if h1 >= h0 else -1.0
    peak = min(speed, math.sqrt(distance * acceleration))
    ramp = peak / acceleration
    cruise = (distance - peak * ramp) / peak if peak > 0.0 else 0.0
    duration = 2.0 * ramp + cruise

    def height(t: float) -> float:
        if t <= ramp:
            s = 0.5 * acceleration * t * t
        elif t <= ramp + cruise:
            s = 0.5 * peak * ramp + peak * (t - ramp)
        else:
            left = max(duration - t, 0.0)
            s = distance - 0.5 * acceleration * left * left
        return h0 + sign * s

    return duration, height


class ArmProgram:
    """The arm and latch references over time for one `Motion`.

    ``choose_retract_speed`` (used when ``motion.retract_speed`` is None) is called once, when
    the retraction starts, and returns the speed (m/s): the controller's decision point.
    """

    def __init__(
        self,
        motion: Motion,
        *,
        start_height: float,
        latch_time: float,
        choose_retract_speed: Callable[[], float] | None = None,
    ) -> None:
        self.motion = motion.validated()
        if motion.place and motion.retract_speed is None and choose_retract_speed is None:
            raise InputError("retract_speed is None: pass choose_retract_speed to decide it")
        self._choose = choose_retract_speed
        self.retract_speed = motion.retract_speed
        m = motion
        approach = (start_height + m.press_depth) / m.approach_speed
        lift, lift_height = _trapezoid(m.lift_start_height, m.lift_height, m.lift_speed, m.lift_acceleration)
        peel = 0.0 if m.peel_speed is None else (PEEL_CLEARANCE + m.press_depth) / m.peel_speed
        self._segments: list[tuple[str, float, Callable[[float], float]]] = [
            ("approach", approach, lambda t: start_height - m.approach_speed * t),
            ("hold", m.hold_time, lambda t: -m.press_depth),
            ("peel", peel, lambda t: -m.press_depth + (m.peel_speed or 0.0) * t),
            ("lift", lift, lift_height),
            ("carry", m.carry_time, lambda t: m.lift_height),
        ]
        if m.place:
            lower, lower_height = _trapezoid(m.lift_height, -m.place_depth, m.lift_speed, m.lift_acceleration)
            self._segments += [
                ("lower", lower, lower_height),
                ("latch", latch_time + LATCH_SETTLE_TIME, lambda t: -m.place_depth),
                ("retract", math.inf, self._retract_height),
            ]
        self.latch_time = latch_time
        self.starts: dict[str, float] = {}
        start = 0.0
        for name, duration, _ in self._segments:
            self.starts[name] = start
            start += duration
        self._retract_end: float | None = None

    def _retract_height(self, t: float) -> float:
        if self.retract_speed is None:
            self.retract_speed = require_positive("retract_speed", self._choose())
        return -self.motion.place_depth + self.retract_speed * t

    @property
    def duration(self) -> float:
        """Total time of the program, s (a place ends a dwell after the retraction reaches the
        lift height; its speed may be chosen later, so this may grow once it is)."""
        if not self.motion.place:
            name, duration, _ = self._segments[-1]
            return self.starts[name] + duration
        if self.retract_speed is None:
            return math.inf
        distance = RETRACT_TRAVEL + self.motion.place_depth
        return self.starts["retract"] + distance / self.retract_speed + DWELL_TIME

    def segment(self, t: float) -> str:
        """The name of the segment running at ``t``, s."""
        current = self._segments[0][0]
        for name, _, _ in self._segments:
            if t >= self.starts[name]:
                current = name
        return current

    def arm_height(self, t: float) -> float:
        """Reference pad-tip height at ``t`` (s), m."""
        name = self.segment(t)
        for seg_name, _, height in self._segments:
            if seg_name == name:
                if name == "retract":
                    local = t - self.starts[name]
                    return min(height(local), RETRACT_TRAVEL)
                return height(t - self.starts[name])
        raise AssertionError(name)

    def latch_fraction(self, t: float) -> float:
        """How far the latch is closed at ``t``: 0 open .. 1 closed (closes during ``latch``
        over ``latch_time`` and stays closed)."""
        if not self.motion.place or t < self.starts["latch"]:
            return 0.0
        return min(1.0, (t - self.starts["latch"]) / self.latch_time)
