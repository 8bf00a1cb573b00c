"""Popov's energy criterion for attachment and detachment, and where it holds.

Crack opening is fast compared with relaxation, so only the energy of the *glass* springs is
released when an edge element detaches (and only they deform when a fresh element snaps
in). The edge element therefore detaches when its glass-spring elongation reaches

    l0_c(x) = -sqrt(2 pi |x| w / E0*)       (tension negative; = -sqrt(pi |x| w/(2 G0)) for nu = 1/2)

with ``w`` the work of adhesion (J/m^2) and ``E0* = 2 G0/(1 - nu)`` the glass contact modulus.

Effective works of adhesion. In the quasistatic limits the interior of the contact is fully
relaxed (modulus ``E_r* = 2 G_inf/(1 - nu)``) and the result is JKR with an effective work:

- indenting: the fresh edge element deforms only in its glass spring, so its total
  elongation equals ``l0_c``; matching ``sqrt(2 pi a w_eff/E_r*)`` gives ``w_eff1 = w G_inf/G0``
  (suppressed; ``w G1/(G0+G1)`` for K = 1);
- detaching: the edge element is relaxed, all its springs carry the same force, its total
  elongation is ``(G0/G_inf) l0_c``, giving ``w_eff2 = w G0/G_inf`` (enhanced; ``w (G0+G1)/G1``
  for K = 1).

For K > 1 Kelvin elements the same argument holds with ``G_inf`` the series modulus
``1/G_inf = 1/G0 + sum 1/G_k``: these are the limits with *all* Kelvin elements relaxed
(edge speeds slow against every retardation time).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from viscoadh_ros.core.errors import InputError, require_finite, require_positive
from viscoadh_ros.core.rheology import CreepElement

FloatArray = NDArray[np.float64]


def _work(work_of_adhesion: float) -> float:
    w = require_finite("adhesion.work_of_adhesion", work_of_adhesion)
    if w < 0.0:
        raise InputError(f"adhesion.work_of_adhesion must be >= 0 (got {w!r})")
    return w


def critical_glass_elongation(x: ArrayLike, work_of_adhesion: float, glass_modulus_star: float) -> FloatArray:
    """Magnitude of the critical glass-spring elongation ``sqrt(2 pi |x| w / E0*)``, m, at the
    edge position ``x`` (m, any shape). work_of_adhesion: ``w``, J/m^2 (>= 0);
    glass_modulus_star: ``E0*``, Pa (> 0). The edge element detaches when its glass
    elongation is below ``-`` this value. Same shape as ``x``."""
    w = _work(work_of_adhesion)
    modulus = require_positive("glass_modulus_star", glass_modulus_star)
    return np.sqrt(2.0 * math.pi * np.abs(np.asarray(x, dtype=np.float64)) * w / modulus)


def work_of_adhesion_indenting(work_of_adhesion: float, element: CreepElement) -> float:
    """Effective work of adhesion on quasistatic indentation, ``w G_inf/G0``, J/m^2."""
    return _work(work_of_adhesion) * element.relaxed_shear_modulus / element.glass_shear_modulus


def work_of_adhesion_detaching(work_of_adhesion: float, element: CreepElement) -> float:
    """Effective work of adhesion on quasistatic detachment, ``w G0/G_inf``, J/m^2."""
    return _work(work_of_adhesion) * element.glass_shear_modulus / element.relaxed_shear_modulus


def critical_edge_speeds(
    element: CreepElement, work_of_adhesion: float, interaction_range: float
) -> tuple[float, float]:
    """Edge speeds ``(v_c1, v_c2)``, m/s, above which the energy criterion holds.

    Near the edge the gap opens as ``2 sqrt(w (r - a)/(pi G0'))`` with ``G0' = E0*/4`` (``= G0``
    when incompressible), so the edge must advance ``pi G0' h^2 / w`` before the surfaces are
    ``2h`` apart (h: interaction range, m). That must take less than a relaxation time ``tau``:

        attachment  v >> v_c1 = pi G0' h^2 / (tau w)
        detachment  v >> v_c2 = v_c1 (G_inf/G0)^2     (the jump is larger by G0/G_inf)

    ``tau`` is the relaxation time at fixed elongation (``eta1/(G0+G1)`` for K = 1, shorter than
    the creep time, so the check errs on the strict side); for K > 1 the *shortest* relaxation
    time, again the strict choice. An elastic element (K = 0) or ``w = 0`` has nothing to
    separate: both speeds are 0 (the criterion holds at any speed).
    """
    w = _work(work_of_adhesion)
    h = require_positive("adhesion.interaction_range", interaction_range)
    if element.kelvin_count == 0 or w == 0.0:
        return 0.0, 0.0
    tau = float(np.min(element.relaxation_times))
    v_c1 = math.pi * (element.glass_modulus_star / 4.0) * h**2 / (tau * w)
    ratio = element.relaxed_shear_modulus / element.glass_shear_modulus
    return v_c1, v_c1 * ratio**2


def scale_separation_holds(
    edge_speed: ArrayLike, critical_speeds: tuple[float, float], *, factor: float = 1.0
) -> NDArray[np.bool_]:
    """Whether the energy criterion's scale separation holds at an edge speed (m/s, any shape).

    An advancing edge (``edge_speed > 0``, attachment) needs ``edge_speed >= factor * v_c1``, a
    receding edge (``< 0``, detachment) ``|edge_speed| >= factor * v_c2``. A pinned edge
    (``edge_speed == 0``: no contact or sticking) is not subject to the criterion: True.
    ``factor`` (>= 1 for a stricter reading of ">>") scales both thresholds.
    """
    v_c1, v_c2 = critical_speeds
    scale = require_positive("factor", factor)
    speed = np.asarray(edge_speed, dtype=np.float64)
    if not np.all(np.isfinite(speed)):
        raise InputError(f"edge_speed must be finite (got {speed!r})")
    threshold = np.where(speed > 0.0, scale * v_c1, scale * v_c2)
    return (speed == 0.0) | (np.abs(speed) >= threshold)
