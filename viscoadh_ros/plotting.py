"""Force-depth and force-radius figures with the paper's quasistatic JKR branches (matplotlib Agg).

Reference branches for a sphere (paraboloid) of radius R (physics.md section 4): JKR with the
relaxed modulus ``E_r* = 2 G_inf/(1 - nu)`` (``1/G_inf = 1/G0 + sum_k 1/G_k``), for indentation with
``w_eff1 = w G_inf/G0`` and for detachment with ``w_eff2 = w G0/G_inf`` (for one Kelvin element
these are ``w G1/(G0+G1)`` and ``w (G0+G1)/G1``). Normalised units are the paper's Figure 4:
``F/F_c``, ``a/a_c``, ``d/d_c`` with ``w_eff2`` and ``E_r*``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from viscoadh_ros.core.errors import InputError

if TYPE_CHECKING:
    from viscoadh_ros.core.config import ContactConfig


@dataclass(frozen=True)
class Curve:
    """A loop to plot, SI: depth (m), force (N, > 0 compressive), contact radius (m)."""

    depth: NDArray[np.float64]
    force: NDArray[np.float64]
    contact_radius: NDArray[np.float64]
    label: str


@dataclass(frozen=True)
class JkrReference:
    """What the reference branches need: sphere radius R (m), relaxed E_r* (Pa), w_eff1/2 (J/m^2)."""

    radius: float
    relaxed_modulus: float
    work_indentation: float
    work_detachment: float

    @classmethod
    def from_contact(cls, contact: ContactConfig) -> JkrReference | None:
        """The reference of a sphere contact with adhesion; None for other indenters."""
        if contact.indenter.shape != "sphere" or not contact.adhesion.work_of_adhesion > 0:
            return None
        from viscoadh_ros.core.criterion import work_of_adhesion_detaching, work_of_adhesion_indenting
        from viscoadh_ros.core.rheology import CreepElement

        element = CreepElement.from_config(contact.material)
        w = float(contact.adhesion.work_of_adhesion)
        return cls(
            float(contact.indenter.radius),
            element.relaxed_modulus_star,
            work_of_adhesion_indenting(w, element),
            work_of_adhesion_detaching(w, element),
        )

    def branch(
        self, work: float, radius: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """JKR (depth, force) along contact radii ``radius`` for work of adhesion ``work``."""
        from viscoadh_ros.core import reference

        args = (self.radius, self.relaxed_modulus, work)
        return reference.jkr_depth(radius, *args), reference.jkr_force(radius, *args)

    @property
    def scales(self) -> tuple[float, float, float]:
        """(F_c in N, a_c in m, d_c in m) of the paper's Figure 4."""
        from viscoadh_ros.core import reference

        units = reference.jkr_scales(self.radius, self.relaxed_modulus, self.work_detachment)
        return units.force, units.contact_radius, units.depth


def plot_loops(
    curves: list[Curve],
    output: Path,
    *,
    reference: JkrReference | None = None,
    normalised: bool = False,
    title: str = "",
) -> None:
    """Write force vs depth and force vs contact radius (PNG or SVG by suffix) to ``output``."""
    if output.suffix.lower() not in (".png", ".svg"):
        raise InputError(f"output must be a .png or .svg file (got {str(output)!r})")
    if normalised and reference is None:
        raise InputError("normalised units need a sphere scene with adhesion (--scene)")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f_s, a_s, d_s = reference.scales if normalised else (1.0, 1.0, 1.0)
    # SI values are tiny (um, mN): show them in readable multiples.
    d_unit, d_k = ("d / d_c", 1 / d_s) if normalised else ("depth d / um", 1e6)
    a_unit, a_k = ("a / a_c", 1 / a_s) if normalised else ("contact radius a / um", 1e6)
    f_unit, f_k = ("F / F_c", 1 / f_s) if normalised else ("force F / mN", 1e3)

    fig, (ax_d, ax_a) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    for curve in curves:
        ax_d.plot(curve.depth * d_k, curve.force * f_k, lw=1.6, label=curve.label)
        ax_a.plot(curve.contact_radius * a_k, curve.force * f_k, lw=1.6, label=curve.label)
    if reference is not None:
        a_max = max(float(np.nanmax(c.contact_radius)) for c in curves) * 1.15 or 1.0
        radius = np.linspace(0.0, a_max, 400)
        for work, style, name in (
            (reference.work_indentation, "--", "JKR indentation, w_eff1"),
            (reference.work_detachment, "-.", "JKR detachment, w_eff2"),
        ):
            depth, force = reference.branch(work, radius)
            ax_d.plot(depth * d_k, force * f_k, style, color="0.35", lw=1.2, label=name)
            ax_a.plot(radius * a_k, force * f_k, style, color="0.35", lw=1.2, label=name)
    for ax, xlabel in ((ax_d, d_unit), (ax_a, a_unit)):
        ax.axhline(0.0, color="0.8", lw=0.8)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f_unit + ("" if normalised else "  (> 0 compressive)"))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    ax_d.set_title("force vs depth")
    ax_a.set_title("force vs contact radius")
    if title:
        fig.suptitle(title)
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=150)
    plt.close(fig)
