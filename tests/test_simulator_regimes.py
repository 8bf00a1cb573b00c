"""The time-stepped core (numerics.model: time_stepped, default `balanced` numerics) in the
regimes between relaxed and elastic, where no closed form covers the viscoelastic path:

- a glassy body (the Kelvin element barely moves) pressed deep and pulled out must give the
  elastic JKR answer with the glass modulus, whatever depth it reached (issue 10, defect 1:
  the memory towards the edge was extrapolated linearly although it is quadratic in x);
- `energy_dissipated` never decreases, in any regime (issue 10, defect 2: it dropped for one
  row whenever the receding edge passed an element centre).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.core import reference
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.core.rheology import CreepElement
from viscoadh_ros.core.simulator import ContactSimulator, Phase

G0, G1, WORK = 1e6, 1e5, 0.05


def contact(radius: float, *, viscosity: float | None, work: float = WORK, **numerics):
    """A sphere on a standard solid (no Kelvin element if `viscosity` is None), forced onto
    the time-stepped path."""
    return one_contact(
        {"shape": "sphere", "radius": radius},
        glass_shear_modulus=G0,
        kelvin=() if viscosity is None else (G1,),
        viscosities=() if viscosity is None else (viscosity,),
        work=work,
        numerics={"model": "time_stepped", **numerics},
    )


def press_and_pull(depth_max: float, depth_min: float, rows: int) -> np.ndarray:
    half = rows // 2
    return np.concatenate([np.linspace(0.0, depth_max, half), np.linspace(depth_max, depth_min, rows - half)])


@pytest.mark.parametrize("depth_dc", [5.0, 80.0, 300.0])
def test_glassy_deep_press_pulls_off_at_elastic_jkr(depth_dc: float) -> None:
    """R = 10 mm, G0 = 1 MPa, G1 = 0.1 MPa, eta1 = 1.1e14 Pa s (creep time ~3e7 years) over a
    1 s press to `depth_dc` d_c and back out: the Kelvin element never moves, so the most
    tensile force is elastic JKR's -(3/2) pi R w with E* = 4 G0 (displacement control passes
    the force minimum before the fold). Before the fix: 3.6 % off at 300 d_c, 1.4 % at 80."""
    radius = 1e-2
    d_c = abs(reference.jkr_scales(radius, 4.0 * G0, WORK).depth)
    time = np.linspace(0.0, 1.0, 2000)
    result = simulate_history(
        contact(radius, viscosity=1.1e14), time, depth=press_and_pull(depth_dc, -3.0, 2000) * d_c
    )
    assert result.model == "time_stepped"
    exact = -1.5 * math.pi * radius * WORK
    error = abs(result.force.min() / exact - 1.0)
    assert error < 5e-3, f"pull-off {result.force.min():.6g} N vs JKR {exact:.6g} N: {error:.2%}"


@pytest.mark.parametrize(
    ("tau", "depth_dc"),
    [(1e-4, 3.0), (1e-3, 3.0), (1.0, 3.0), (10.0, 30.0), (10.0, 300.0)],
)
def test_dissipation_never_decreases(tau: float, depth_dc: float) -> None:
    """A standard solid (relaxation time tau) pressed to `depth_dc` d_c and pulled off in
    0.1 s: `energy_dissipated` is a sum of non-negative losses, so no row may lower it (a
    rounding error of 1e-9 of the total aside). Before the fix it dropped by 0.3 % of the
    total (tau = 1e-4 s) when the receding edge passed an element centre."""
    radius = 1e-3
    material = contact(radius, viscosity=tau * (G0 + G1)).material
    d_c = abs(reference.figure4_scales(radius, WORK, CreepElement.from_config(material)).depth)
    time = np.linspace(0.0, 0.1, 1001)
    result = simulate_history(
        contact(radius, viscosity=tau * (G0 + G1)), time, depth=press_and_pull(depth_dc, -3.0, 1001) * d_c
    )
    dissipated = result.energy_dissipated
    total = dissipated.max()
    assert total > 0.0
    drops = np.diff(dissipated)
    worst = int(np.argmin(drops))
    assert drops[worst] >= -1e-9 * total, (
        f"dissipation fell by {-drops[worst] / total:.2e} of the total at row {worst + 1} "
        f"(phase {result.phase[worst + 1]})"
    )


def test_force_control_pull_off_is_three_halves_pi_r_w_eff2() -> None:
    """Quasistatic (rows of 10 relaxation times) force-controlled press and pull of a standard
    solid sphere: the most tensile force held before the contact runs away is the paper's
    -(3/2) pi R w_eff2, w_eff2 = w (G0 + G1)/G1, within 0.5 % (the last rows step 0.25 % of it); the
    first row beyond is flagged unstable."""
    radius, tau = 1e-3, 1e-2
    sim = ContactSimulator(contact(radius, viscosity=tau * (G0 + G1)))
    limit = -1.5 * math.pi * radius * WORK * (G0 + G1) / G1
    # Press to 3 |F_c| (deep enough for the edge to leave the sticking zone before pull-off),
    # pull to -0.9 F_c, then creep towards the pull-off in steps of 0.25 % of it.
    forces = abs(limit) * np.concatenate(
        [np.linspace(0.0, 3.0, 10), np.linspace(3.0, -0.9, 60)[1:], np.linspace(-0.9, -1.05, 61)[1:]]
    )
    held = 0.0
    for i, target in enumerate(forces):
        out = sim.step(10.0 * tau * (i + 1), force=float(target))
        if out.unstable and i >= 10:  # (the first touch snaps in: also unstable)
            break
        held = min(held, out.force)
    else:
        raise AssertionError("force control never reported the pull-off")
    assert abs(target / limit - 1.0) < 5e-3, f"let go at {target:.6g} N, paper {limit:.6g} N"
    assert abs(held / limit - 1.0) < 5e-3, f"held {held:.6g} N, paper {limit:.6g} N"


@pytest.mark.parametrize("tau", [0.1, 1.0])
def test_indentation_branch_has_no_single_row_spikes(tau: float) -> None:
    """A blunt cone (half-angle 80 deg) pressed into a standard solid over 1 s in 1000 rows on
    one fixed grid (`numerics.domain_radius`, the fit's mode: no regridding, few elements
    across the young contact): on the indentation branch no row's force departs from the
    curve through its neighbours (the fourth difference, which cancels the curvature) by
    more than 0.5 % of the pull-off force. Before the A/B memory: 25 % at tau = 1 s, as the
    edge crossed the first centres."""
    c = one_contact(
        {"shape": "cone", "half_angle": math.radians(80.0)},
        glass_shear_modulus=G0,
        kelvin=(G1,),
        viscosities=(tau * (G0 + G1),),
        work=WORK,
        numerics={"model": "time_stepped", "domain_radius": 3e-4},
    )
    depth_max = 2e-5 * math.cos(math.radians(80.0)) / math.cos(math.radians(85.0))
    depth = np.concatenate([np.linspace(-1e-7, depth_max, 1000), np.linspace(depth_max, -depth_max, 1001)])
    result = simulate_history(c, np.linspace(0.0, 1.0, depth.size), depth=depth)
    pull_off = abs(result.force.min())
    rows = np.flatnonzero((result.phase == Phase.INDENTING) & (np.arange(depth.size) < 997))
    rows = rows[rows > rows[0] + 3]
    f = result.force

    def bend(i: np.ndarray) -> np.ndarray:
        return f[i] - 0.5 * (f[i - 1] + f[i + 1])

    spike = np.abs(bend(rows) - 0.5 * (bend(rows - 1) + bend(rows + 1))) / pull_off
    assert spike.max() < 5e-3, f"row {rows[np.argmax(spike)]}: {spike.max():.2%} of the pull-off force"


@pytest.mark.parametrize(("tau", "depth_dc"), [(1e-2, 5.0), (1.0, 30.0)])
def test_dissipation_matches_the_energy_balance(tau: float, depth_dc: float) -> None:
    """The running sum of losses agrees with input - stored - surface (the stored energy
    integrated on demand) within 1e-3 of the total at every row."""
    radius = 1e-3
    c = contact(radius, viscosity=tau * (G0 + G1))
    d_c = abs(reference.figure4_scales(radius, WORK, CreepElement.from_config(c.material)).depth)
    sim = ContactSimulator(c)
    depth = press_and_pull(depth_dc, -3.0, 401) * d_c
    gaps = []
    for t, d in zip(np.linspace(0.0, 0.1, depth.size), depth, strict=True):
        out = sim.step(float(t), depth=float(d))
        balance = (
            out.energy_input - sim._model.stored_energy(out.depth) + WORK * math.pi * out.contact_radius**2
        )
        gaps.append(out.energy_dissipated - balance)
    total = sim.output.energy_dissipated
    assert total > 0.0
    assert np.max(np.abs(gaps)) < 1e-3 * total, f"largest gap {np.max(np.abs(gaps)) / total:.2e} of the total"


def test_model_validity_says_when_slopes_are_not_small() -> None:
    """`model_validity` flags a contact edge on a steep flank (half-space theory) and a
    shallow sphere contact passes; it is a property of the state, never an error."""
    shallow = ContactSimulator(contact(1e-3, viscosity=1e4))
    shallow.step(0.1, depth=1e-6)
    validity = shallow.model_validity
    assert validity.ok and validity.small_slope_ok and validity.message == ""
    assert validity.edge_slope == pytest.approx(shallow.output.contact_radius / 1e-3, rel=1e-4)
    deep = ContactSimulator(contact(1e-3, viscosity=1e4))
    deep.step(0.1, depth=2e-4)  # a/R ~ 0.45
    assert not deep.model_validity.small_slope_ok
    assert "slope" in deep.model_validity.message
    steep = ContactSimulator(
        one_contact({"shape": "cone", "half_angle": math.radians(60.0)}, work=0.0, numerics={"model": "auto"})
    )
    steep.step(0.1, depth=1e-6)
    assert steep.model_validity.edge_slope == pytest.approx(1.0 / math.tan(math.radians(60.0)), rel=1e-4)
    assert not steep.model_validity.ok
    assert ContactSimulator(contact(1e-3, viscosity=1e4)).model_validity.ok  # no contact
